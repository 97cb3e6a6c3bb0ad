// SPDX-License-Identifier: MIT
#include "tools/camera_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "ssao/ssao.hpp"

namespace ssao_tools {
namespace {

using Json = nlohmann::json;

const char* json_type_name(const Json& value) {
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_null()) return "null";
  if (value.is_array()) return "an array";
  return "an object";
}

class Reader {
 public:
  Reader(const Json& root, const std::string& source) : root_(root), source_(source) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw Error("camera file '" + source_ + "': key '" + key + "' " + what);
  }

  double finite_number(const Json& value, const std::string& key) const {
    if (!value.is_number())
      fail(key, std::string("must be a number, got ") + json_type_name(value));
    const double number = value.get<double>();
    if (!std::isfinite(number)) fail(key, "must be a finite number");
    return number;
  }

  void number(const char* key, double& out) const {
    const auto it = root_.find(key);
    if (it != root_.end()) out = finite_number(*it, key);
  }

  // A key the projection depends on: absent is an error, never a default (a default would
  // give a plausible but wrong image). `what` says what the key is, for the message.
  void require(const char* key, const char* what) const {
    if (!root_.contains(key)) {
      throw Error("camera file '" + source_ + "': missing key '" + key + "' (" + what +
                  "); scripts/blender/export_cameras.py writes every key");
    }
  }

  void positive(const char* key, double value) const {
    if (root_.contains(key) && !(value > 0.0)) fail(key, "must be positive, got " + text(value));
  }

  void not_negative(const char* key, double value) const {
    if (root_.contains(key) && value < 0.0) fail(key, "must not be negative, got " + text(value));
  }

  static std::string text(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  }

  void choice(const char* key, std::string& out, const std::vector<std::string>& choices,
              bool required) const {
    const auto it = root_.find(key);
    if (it == root_.end()) {
      if (required) {
        throw Error("camera file '" + source_ + "': missing key '" + key + "' (one of " +
                    join(choices) + ")");
      }
      return;
    }
    if (!it->is_string()) fail(key, std::string("must be a string, got ") + json_type_name(*it));
    const std::string value = it->get<std::string>();
    for (const std::string& c : choices) {
      if (value == c) {
        out = value;
        return;
      }
    }
    fail(key, "must be one of " + join(choices) + ", got '" + value + "'");
  }

  void matrix(const char* key, std::array<double, 16>& out) const {
    const auto it = root_.find(key);
    if (it == root_.end()) return;
    const char* const shape = "must be a 4x4 matrix: an array of 4 rows of 4 numbers";
    if (!it->is_array() || it->size() != 4) fail(key, shape);
    for (size_t row = 0; row < 4; ++row) {
      const Json& r = (*it)[row];
      if (!r.is_array() || r.size() != 4) fail(key, shape);
      for (size_t col = 0; col < 4; ++col) {
        out[row * 4 + col] = finite_number(r[col], std::string(key) + "[" + std::to_string(row) +
                                                       "][" + std::to_string(col) + "]");
      }
    }
    if (out[12] != 0.0 || out[13] != 0.0 || out[14] != 0.0 || out[15] != 1.0) {
      fail(key, "must be an affine transform: its last row must be [0, 0, 0, 1]");
    }
  }

 private:
  static std::string join(const std::vector<std::string>& names) {
    std::string out;
    for (size_t i = 0; i < names.size(); ++i) out += (i ? "|" : "") + names[i];
    return out;
  }

  const Json& root_;
  const std::string& source_;
};

const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = {
      "type",         "lens",           "sensor_width",   "sensor_height", "sensor_fit",
      "shift_x",      "shift_y",        "ortho_scale",    "clip_start",    "clip_end",
      "matrix_world", "pixel_aspect_x", "pixel_aspect_y", "ao_distance"};
  return keys;
}

}  // namespace

Camera parse_camera_json(const std::string& text, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::out_of_range& e) {
    throw Error("camera file '" + source + "': a number is out of range: " + e.what());
  } catch (const Json::exception& e) {
    throw Error("camera file '" + source + "': malformed JSON: " + e.what());
  }
  if (!root.is_object()) {
    throw Error("camera file '" + source + "': expected a JSON object, got " +
                json_type_name(root));
  }

  Camera camera;
  const Reader read(root, source);
  read.choice("type", camera.type, {"PERSP", "ORTHO"}, true);
  read.choice("sensor_fit", camera.sensor_fit, {"AUTO", "HORIZONTAL", "VERTICAL"}, true);
  read.number("lens", camera.lens);
  read.number("sensor_width", camera.sensor_width);
  read.number("sensor_height", camera.sensor_height);
  read.number("shift_x", camera.shift_x);
  read.number("shift_y", camera.shift_y);
  read.number("ortho_scale", camera.ortho_scale);
  read.number("clip_start", camera.clip_start);
  read.number("clip_end", camera.clip_end);
  read.number("pixel_aspect_x", camera.pixel_aspect_x);
  read.number("pixel_aspect_y", camera.pixel_aspect_y);
  read.matrix("matrix_world", camera.matrix_world);
  camera.has_matrix_world = root.contains("matrix_world");
  read.number("ao_distance", camera.ao_distance);
  // Only the keys this camera's projection reads are required (Blender's own rule: AUTO and
  // HORIZONTAL fit sensor_width, VERTICAL fits sensor_height; ORTHO reads ortho_scale instead).
  if (camera.type == "PERSP") {
    read.require("lens", "the focal length in mm");
    if (camera.sensor_fit == "VERTICAL") {
      read.require("sensor_height", "the sensor height in mm, which a VERTICAL fit uses");
    } else {
      read.require("sensor_width", "the sensor width in mm");
    }
  } else {
    read.require("ortho_scale", "the view's width in scene units, which an ORTHO camera needs");
  }
  read.require("shift_x", "the horizontal lens shift; 0 for none");
  read.require("shift_y", "the vertical lens shift; 0 for none");
  const std::pair<const char*, double> sizes[] = {{"lens", camera.lens},
                                                  {"sensor_width", camera.sensor_width},
                                                  {"sensor_height", camera.sensor_height},
                                                  {"ortho_scale", camera.ortho_scale},
                                                  {"clip_end", camera.clip_end},
                                                  {"pixel_aspect_x", camera.pixel_aspect_x},
                                                  {"pixel_aspect_y", camera.pixel_aspect_y},
                                                  {"ao_distance", camera.ao_distance}};
  for (const auto& [key, value] : sizes) read.positive(key, value);
  read.not_negative("clip_start", camera.clip_start);

  for (const auto& item : root.items()) {
    bool known = false;
    for (const std::string& key : known_keys()) known = known || item.key() == key;
    if (!known) camera.unknown_keys.push_back(item.key());
  }
  return camera;
}

Camera read_camera_json(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error("camera file '" + path + "': no such file");
  if (std::filesystem::is_directory(path, ec)) {
    throw Error("camera file '" + path + "': it is a directory");
  }
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file || !text) throw Error("camera file '" + path + "': cannot read it");
  return parse_camera_json(text.str(), path);
}

const std::vector<std::string>& camera_param_names() {
  static const std::vector<std::string> names = {
      "camera_type",    "lens",           "sensor_width",   "sensor_height", "sensor_fit",
      "shift_x",        "shift_y",        "ortho_scale",    "clip_start",    "clip_end",
      "pixel_aspect_x", "pixel_aspect_y", "camera_to_world"};
  return names;
}

bool is_camera_param(const std::string& name) {
  const auto& names = camera_param_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void apply_camera(ssao_job job, const Camera& camera, const std::string& source) {
  const std::string where = "camera file '" + source + "': ";
  auto set_float = [&](const char* name, double value) {
    ssao::api::check_status(ssao_job_set_float(job, name, value), where + name);
  };
  auto set_string = [&](const char* name, const std::string& value) {
    ssao::api::check_status(ssao_job_set_string(job, name, value.c_str()), where + name);
  };
  set_string("camera_type", camera.type);
  set_float("lens", camera.lens);
  set_float("sensor_width", camera.sensor_width);
  set_float("sensor_height", camera.sensor_height);
  set_string("sensor_fit", camera.sensor_fit);
  set_float("shift_x", camera.shift_x);
  set_float("shift_y", camera.shift_y);
  set_float("ortho_scale", camera.ortho_scale);
  set_float("clip_start", camera.clip_start);
  set_float("clip_end", camera.clip_end);
  set_float("pixel_aspect_x", camera.pixel_aspect_x);
  set_float("pixel_aspect_y", camera.pixel_aspect_y);
  ssao::api::check_status(ssao_job_set_floats(job, "camera_to_world", camera.matrix_world.data(),
                                              camera.matrix_world.size()),
                          where + "matrix_world");
}

}  // namespace ssao_tools
