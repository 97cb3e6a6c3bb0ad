// SPDX-License-Identifier: MIT
#include "camera_file.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "error.h"

namespace ssao {
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

std::string text_of(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? "|" : "") + names[i];
  return out;
}

// A key of the file, the library parameter it sets (nullptr: none) and its check. The one list
// of the format's fields.
enum class Check { any, positive, not_negative };
struct NumberField {
  const char* key;
  const char* param;
  Check check;
};
struct ChoiceField {
  const char* key;
  const char* param;
  std::vector<std::string> choices;
};
struct MatrixField {
  const char* key;
  const char* param;
  size_t rows, columns;
  bool affine;  // a transform: last row 0 0 0 1
};

const std::vector<ChoiceField>& choice_fields() {
  static const std::vector<ChoiceField> fields = {
      {"type", "camera_type", {"PERSP", "ORTHO"}},
      {"sensor_fit", "sensor_fit", {"AUTO", "HORIZONTAL", "VERTICAL"}},
      {"projection", "projection", {"lens", "intrinsics", "matrix"}}};
  return fields;
}

// The library's ranges allow clip_end 0 ("no clip test"), which a file cannot say: a file's
// checks are its own.
const std::vector<NumberField>& number_fields() {
  static const std::vector<NumberField> fields = {
      {"lens", "lens", Check::positive},
      {"sensor_width", "sensor_width", Check::positive},
      {"sensor_height", "sensor_height", Check::positive},
      {"shift_x", "shift_x", Check::any},
      {"shift_y", "shift_y", Check::any},
      {"ortho_scale", "ortho_scale", Check::positive},
      {"clip_start", "clip_start", Check::not_negative},
      {"clip_end", "clip_end", Check::positive},
      {"pixel_aspect_x", "pixel_aspect_x", Check::positive},
      {"pixel_aspect_y", "pixel_aspect_y", Check::positive},
      {"ao_distance", nullptr, Check::positive}};
  return fields;
}

const std::vector<MatrixField>& matrix_fields() {
  static const std::vector<MatrixField> fields = {
      {"matrix_world", "camera_to_world", 4, 4, true},
      {"intrinsics", "intrinsics", 1, 4, false},
      {"projection_matrix", "projection_matrix", 4, 4, false}};
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

class Reader {
 public:
  Reader(const Json& root, const std::string& source) : root_(root), source_(source) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw_invalid_argument("camera file '" + source_ + "': key '" + key + "' " + what);
  }

  bool has(const char* key) const { return root_.contains(key); }

  double finite_number(const Json& value, const std::string& key) const {
    if (!value.is_number())
      fail(key, std::string("must be a number, got ") + json_type_name(value));
    const double number = value.get<double>();
    if (!std::isfinite(number)) fail(key, "must be a finite number");
    return number;
  }

  double number(const NumberField& field) const {
    const double value = finite_number(root_.at(field.key), field.key);
    if (field.check == Check::positive && !(value > 0.0))
      fail(field.key, "must be positive, got " + text_of(value));
    if (field.check == Check::not_negative && value < 0.0)
      fail(field.key, "must not be negative, got " + text_of(value));
    return value;
  }

  std::string choice(const ChoiceField& field) const {
    const Json& value = root_.at(field.key);
    if (!value.is_string())
      fail(field.key, std::string("must be a string, got ") + json_type_name(value));
    const std::string text = value.get<std::string>();
    for (const std::string& c : field.choices) {
      if (text == c) return text;
    }
    fail(field.key, "must be one of " + join(field.choices) + ", got '" + text + "'");
  }

  // A rows x columns matrix, row-major (rows == 1: a flat array of `columns` numbers). An
  // affine one (a transform) must end in the row 0 0 0 1; a projection's last row is checked
  // by the library's parameter.
  std::vector<double> matrix(const MatrixField& field) const {
    const Json& value = root_.at(field.key);
    const size_t rows = field.rows, columns = field.columns;
    const std::string shape =
        rows == 1 ? "must be an array of " + std::to_string(columns) + " numbers"
                  : "must be a " + std::to_string(rows) + "x" + std::to_string(columns) +
                        " matrix: an array of " + std::to_string(rows) + " rows of " +
                        std::to_string(columns) + " numbers";
    std::vector<double> out(rows * columns, 0.0);
    const std::string key = field.key;
    if (rows == 1) {
      if (!value.is_array() || value.size() != columns) fail(key, shape);
      for (size_t col = 0; col < columns; ++col)
        out[col] = finite_number(value[col], key + "[" + std::to_string(col) + "]");
      return out;
    }
    if (!value.is_array() || value.size() != rows) fail(key, shape);
    for (size_t row = 0; row < rows; ++row) {
      const Json& r = value[row];
      if (!r.is_array() || r.size() != columns) fail(key, shape);
      for (size_t col = 0; col < columns; ++col) {
        out[row * columns + col] = finite_number(
            r[col], key + "[" + std::to_string(row) + "][" + std::to_string(col) + "]");
      }
    }
    if (field.affine && (out[12] != 0.0 || out[13] != 0.0 || out[14] != 0.0 || out[15] != 1.0))
      fail(key, "must be an affine transform: its last row must be [0, 0, 0, 1]");
    return out;
  }

  // A key the projection depends on: absent is an error, never a default (a default would
  // give a plausible but wrong image). `what` says what the key is, for the message.
  void require(const char* key, const std::string& what) const {
    if (!has(key)) {
      throw_invalid_argument("camera file '" + source_ + "': missing key '" + key + "' (" + what +
                             "); scripts/blender/export_cameras.py writes every key");
    }
  }

 private:
  const Json& root_;
  const std::string& source_;
};

std::string string_or(const Json& root, const char* key, const char* absent) {
  const auto it = root.find(key);
  return it != root.end() && it->is_string() ? it->get<std::string>() : absent;
}

// Only the keys this camera's projection reads are required (Blender's own rule for lens: AUTO
// and HORIZONTAL fit sensor_width, VERTICAL fits sensor_height; ORTHO reads ortho_scale).
// Called after the values were checked, so "projection", "type" and "sensor_fit" are valid.
void require_projection_keys(const Reader& read, const Json& root) {
  const std::string projection = string_or(root, "projection", "lens");
  if (projection == "intrinsics") {
    read.require("type", "one of PERSP|ORTHO");
    read.require("intrinsics", "fx, fy, cx, cy in pixels, which projection intrinsics needs");
    return;
  }
  if (projection == "matrix") {
    read.require("projection_matrix", "the 4x4 view-to-clip matrix, which projection matrix needs");
    return;
  }
  read.require("type", "one of PERSP|ORTHO");
  read.require("sensor_fit", "one of AUTO|HORIZONTAL|VERTICAL");
  if (string_or(root, "type", "PERSP") == "PERSP") {
    read.require("lens", "the focal length in mm");
    if (string_or(root, "sensor_fit", "AUTO") == "VERTICAL") {
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

// The library's own check of a value (its range), with the file and the key in the message.
template <typename Set>
void set_param(const std::string& source, const char* key, Set&& set) {
  try {
    set();
  } catch (const Error& e) {
    throw Error(e.status(), "camera file '" + source + "': " + key + ": " + e.what());
  }
}

}  // namespace

CameraFile apply_camera_json(const std::string& text, const std::string& source,
                             ParamValues& params) {
  if (text.find('\0') != std::string::npos) {  // JSON text has none; the parser would stop there
    throw_invalid_argument("camera file '" + source + "': malformed JSON: it holds a NUL byte");
  }
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::out_of_range& e) {
    throw_invalid_argument("camera file '" + source + "': a number is out of range: " + e.what());
  } catch (const Json::exception& e) {
    throw_invalid_argument("camera file '" + source + "': malformed JSON: " + e.what());
  }
  if (!root.is_object()) {
    throw_invalid_argument("camera file '" + source + "': expected a JSON object, got " +
                           json_type_name(root));
  }

  const Reader read(root, source);
  CameraFile file;
  for (const ChoiceField& f : choice_fields()) {
    if (!read.has(f.key)) continue;
    const std::string value = read.choice(f);
    set_param(source, f.key, [&] { params.set_string(f.param, value.c_str()); });
  }
  for (const NumberField& f : number_fields()) {
    if (!read.has(f.key)) continue;
    const double value = read.number(f);
    if (f.param == nullptr) {
      file.ao_distance = value;  // "ao_distance", the only key that is not a parameter
      continue;
    }
    set_param(source, f.key, [&] { params.set_float(f.param, value); });
  }
  for (const MatrixField& f : matrix_fields()) {
    if (!read.has(f.key)) continue;
    const std::vector<double> values = read.matrix(f);
    set_param(source, f.key, [&] { params.set_floats(f.param, values.data(), values.size()); });
  }
  require_projection_keys(read, root);
  for (const auto& item : root.items()) {
    if (!is_known_key(item.key())) file.unknown_keys.push_back(item.key());
  }
  return file;
}

CameraParams camera_params(const ParamValues& v) {
  CameraParams c;
  c.orthographic = v.get_string("camera_type") == "ORTHO";
  c.lens = v.get_float("lens");
  c.sensor_width = v.get_float("sensor_width");
  c.sensor_height = v.get_float("sensor_height");
  c.sensor_fit = v.get_string("sensor_fit");
  c.shift_x = v.get_float("shift_x");
  c.shift_y = v.get_float("shift_y");
  c.ortho_scale = v.get_float("ortho_scale");
  c.pixel_aspect_x = v.get_float("pixel_aspect_x");
  c.pixel_aspect_y = v.get_float("pixel_aspect_y");
  return c;
}

}  // namespace ssao
