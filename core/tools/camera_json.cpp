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
#include "tools/param_flags.h"

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

  // A rows x columns matrix (rows == 1: a flat array of `columns` numbers). An affine one (a
  // transform) must end in the row 0 0 0 1; a projection's last row is checked by the library.
  void matrix(const char* key, std::vector<double>& out, size_t rows, size_t columns,
              bool affine) const {
    const auto it = root_.find(key);
    if (it == root_.end()) return;
    const std::string shape =
        rows == 1 ? "must be an array of " + std::to_string(columns) + " numbers"
                  : "must be a " + std::to_string(rows) + "x" + std::to_string(columns) +
                        " matrix: an array of " + std::to_string(rows) + " rows of " +
                        std::to_string(columns) + " numbers";
    out.assign(rows * columns, 0.0);
    if (rows == 1) {
      if (!it->is_array() || it->size() != columns) fail(key, shape);
      for (size_t col = 0; col < columns; ++col) {
        out[col] = finite_number((*it)[col], std::string(key) + "[" + std::to_string(col) + "]");
      }
      return;
    }
    if (!it->is_array() || it->size() != rows) fail(key, shape);
    for (size_t row = 0; row < rows; ++row) {
      const Json& r = (*it)[row];
      if (!r.is_array() || r.size() != columns) fail(key, shape);
      for (size_t col = 0; col < columns; ++col) {
        out[row * columns + col] =
            finite_number(r[col], std::string(key) + "[" + std::to_string(row) + "][" +
                                      std::to_string(col) + "]");
      }
    }
    if (affine && (out[12] != 0.0 || out[13] != 0.0 || out[14] != 0.0 || out[15] != 1.0)) {
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

// A key of the file: the Camera member it fills, the library parameter it sets (nullptr: none),
// and the check its value gets. The one list of the format's fields.
enum class Check { any, positive, not_negative };
struct NumberField {
  const char* key;
  double Camera::*member;
  const char* param;
  Check check;
};
struct ChoiceField {
  const char* key;
  std::string Camera::*member;
  const char* param;
  std::vector<std::string> choices;
};
struct MatrixField {
  const char* key;
  std::vector<double> Camera::*member;
  const char* param;
  size_t rows, columns;
  bool affine;  // a transform: last row 0 0 0 1
};

const std::vector<ChoiceField>& choice_fields() {
  static const std::vector<ChoiceField> fields = {
      {"type", &Camera::type, "camera_type", {"PERSP", "ORTHO"}},
      {"sensor_fit", &Camera::sensor_fit, "sensor_fit", {"AUTO", "HORIZONTAL", "VERTICAL"}},
      {"projection", &Camera::projection, "projection", {"lens", "intrinsics", "matrix"}}};
  return fields;
}

const std::vector<NumberField>& number_fields() {
  static const std::vector<NumberField> fields = {
      {"lens", &Camera::lens, "lens", Check::positive},
      {"sensor_width", &Camera::sensor_width, "sensor_width", Check::positive},
      {"sensor_height", &Camera::sensor_height, "sensor_height", Check::positive},
      {"shift_x", &Camera::shift_x, "shift_x", Check::any},
      {"shift_y", &Camera::shift_y, "shift_y", Check::any},
      {"ortho_scale", &Camera::ortho_scale, "ortho_scale", Check::positive},
      {"clip_start", &Camera::clip_start, "clip_start", Check::not_negative},
      {"clip_end", &Camera::clip_end, "clip_end", Check::positive},
      {"pixel_aspect_x", &Camera::pixel_aspect_x, "pixel_aspect_x", Check::positive},
      {"pixel_aspect_y", &Camera::pixel_aspect_y, "pixel_aspect_y", Check::positive},
      {"ao_distance", &Camera::ao_distance, nullptr, Check::positive}};
  return fields;
}

const std::vector<MatrixField>& matrix_fields() {
  static const std::vector<MatrixField> fields = {
      {"matrix_world", &Camera::matrix_world, "camera_to_world", 4, 4, true},
      {"intrinsics", &Camera::intrinsics, "intrinsics", 1, 4, false},
      {"projection_matrix", &Camera::projection_matrix, "projection_matrix", 4, 4, false}};
  return fields;
}

bool is_known_key(const std::string& key) {
  for (const ChoiceField& f : choice_fields()) {
    if (key == f.key) return true;
  }
  for (const NumberField& f : number_fields()) {
    if (key == f.key) return true;
  }
  for (const MatrixField& f : matrix_fields()) {
    if (key == f.key) return true;
  }
  return false;
}

// The "projection" key's value when it is a string ("lens" when absent; a wrong one is
// reported by the choice check).
std::string projection_of(const Json& root) {
  const auto it = root.find("projection");
  return it != root.end() && it->is_string() ? it->get<std::string>() : "lens";
}

// Only the keys this camera's projection reads are required (Blender's own rule for lens: AUTO
// and HORIZONTAL fit sensor_width, VERTICAL fits sensor_height; ORTHO reads ortho_scale).
void require_projection_keys(const Reader& read, const Camera& camera) {
  if (camera.projection == "intrinsics") {
    read.require("intrinsics", "fx, fy, cx, cy in pixels, which projection intrinsics needs");
    return;
  }
  if (camera.projection == "matrix") {
    read.require("projection_matrix",
                 "the 4x4 view-to-clip matrix, which projection matrix "
                 "needs");
    return;
  }
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
  // "projection" (default lens) decides what else is required: "type" unless a matrix gives
  // it, "sensor_fit" for Blender's lens and sensor.
  const std::string projection = projection_of(root);
  for (const ChoiceField& f : choice_fields()) {
    const bool required = (f.member == &Camera::type && projection != "matrix") ||
                          (f.member == &Camera::sensor_fit && projection == "lens");
    read.choice(f.key, camera.*f.member, f.choices, required);
  }
  for (const NumberField& f : number_fields()) {
    read.number(f.key, camera.*f.member);
    if (f.check == Check::positive) read.positive(f.key, camera.*f.member);
    if (f.check == Check::not_negative) read.not_negative(f.key, camera.*f.member);
  }
  for (const MatrixField& f : matrix_fields())
    read.matrix(f.key, camera.*f.member, f.rows, f.columns, f.affine);
  camera.has_matrix_world = root.contains("matrix_world");
  require_projection_keys(read, camera);

  for (const auto& item : root.items()) {
    if (!is_known_key(item.key())) camera.unknown_keys.push_back(item.key());
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

bool is_camera_param(const std::string& name) { return param_group_of(name) == "camera"; }

void apply_camera(ssao_job job, const Camera& camera, const std::string& source) {
  const std::string where = "camera file '" + source + "': ";
  for (const ChoiceField& f : choice_fields()) {
    ssao::api::check_status(ssao_job_set_string(job, f.param, (camera.*f.member).c_str()),
                            where + f.key);
  }
  for (const NumberField& f : number_fields()) {
    if (f.param == nullptr) continue;
    ssao::api::check_status(ssao_job_set_float(job, f.param, camera.*f.member), where + f.key);
  }
  for (const MatrixField& f : matrix_fields()) {
    const std::vector<double>& values = camera.*f.member;
    if (values.empty()) continue;  // not in the file: the library's default
    ssao::api::check_status(ssao_job_set_floats(job, f.param, values.data(), values.size()),
                            where + f.key);
  }
}

}  // namespace ssao_tools
