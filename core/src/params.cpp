// SPDX-License-Identifier: MIT
#include "params.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "error.h"

namespace ssao {
namespace {

constexpr double kInf = HUGE_VAL;

ssao_param_desc int_param(const char* name, int def, int lo, int hi, const char* unit,
                          const char* description) {
  return {name,    SSAO_PARAM_INT, double(def), double(lo), double(hi),
          nullptr, nullptr,        1,           unit,       description};
}
ssao_param_desc float_param(const char* name, double def, double lo, double hi, const char* unit,
                            const char* description) {
  return {name, SSAO_PARAM_FLOAT, def, lo, hi, nullptr, nullptr, 1, unit, description};
}
ssao_param_desc string_param(const char* name, const char* def, const char* choices,
                             const char* description) {
  return {name, SSAO_PARAM_STRING, 0.0, 0.0, 0.0, def, choices, 1, "", description};
}

// Defaults marked "measured" were chosen by the run-time-vs-error benchmark against Cycles'
// AO pass (benchmarks/, docs/accuracy.md).
const std::vector<ssao_param_desc>& table() {
  static const std::vector<ssao_param_desc> params = {
      // --- algorithm ---
      string_param("variant", "hemisphere", "horizon|hemisphere|sphere|volumetric|unsharp",
                   "horizon: horizon-based slices with a visibility bitmask (GTAO), kept for "
                   "comparison: 7-15x the default's time and less accurate on the benchmark "
                   "scenes but the one with thin occluders (docs/variants.md); hemisphere: "
                   "normal-oriented hemisphere kernel; sphere: Crysis sphere kernel (depth only); "
                   "volumetric: line-integral obscurance of a sphere along view rays (depth "
                   "only); unsharp: depth unsharp masking, the local mean depth against the "
                   "pixel's (depth only)"),
      float_param("radius", 1.0, 1e-6, 1e9, "scene units",
                  "distance within which geometry occludes, as Cycles' AO distance"),
      string_param("quality", "medium", "low|medium|high|ultra",
                   "sample counts of the variant (samples, slices, steps) that are left at 0; "
                   "medium is the measured balance of time and error"),
      int_param("samples", 0, 0, 1024, "directions per pixel",
                "hemisphere: kernel directions per pixel; sphere: points per pixel; volumetric: "
                "view rays per pixel; 0: from quality"),
      int_param("slices", 0, 0, 64, "slices per pixel",
                "horizon: screen-space lines through each pixel; 0: from quality"),
      int_param("steps", 0, 0, 64, "samples per direction",
                "hemisphere: samples along each direction, the strongest occluder counts (1 is "
                "the classic kernel of independent points); horizon: samples on each side of a "
                "slice; 0: from quality"),
      float_param("bias", 0.02, 0.0, 1.0, "fraction of radius",
                  "height above the receiver's tangent plane (hemisphere, horizon) or behind the "
                  "sample (sphere) an occluder needs to count; one pixel footprint is added"),
      float_param("sample_clustering", 1.0, 0.0, 4.0, "exponent",
                  "samples sit at radius * lerp(0.1, 1, s^p) for s uniform in [0,1): 0 puts all "
                  "on the kernel's surface, 2 clusters them toward the centre as the seed code "
                  "does (measured)"),
      float_param(
          "thickness", 0.5, 0.01, 100.0, "fraction of radius",
          "assumed thickness of surfaces: horizon: an occluder spans this far behind the visible "
          "surface; hemisphere: a sample this far behind the visible surface counts fully, "
          "fading out at twice the distance (range check against halos); volumetric: a ray "
          "whose visible surface is this far in front of the sphere counts fully, fading out "
          "at twice the distance"),
      string_param("sphere_mode", "normalized", "normalized|classic",
                   "sphere variant: classic reads about 0.5 on a flat wall; normalized maps an "
                   "unoccluded flat surface to 1"),
      int_param("seed", 0, 0, 2147483647, "", "seed of the kernel rotation pattern"),
      string_param("resolution", "auto", "auto|full|half",
                   "full: AO estimated at every pixel; half: at half resolution in each axis (a "
                   "quarter of the work), then upsampled guided by depth and normals; auto: half "
                   "for frames of at least 1 megapixel, where it costs almost no accuracy "
                   "(measured)"),
      // --- denoising ---
      string_param("denoise", "bilateral", "bilateral|box4|none",
                   "bilateral: depth- and normal-aware blur; box4: the seed code's 4x4 box blur; "
                   "none: raw estimate"),
      // --- output shaping: ao = remap_min + (remap_max - remap_min) * mix(1, raw^power, strength)
      float_param("strength", 1.0, 0.0, 1.0, "",
                  "0 leaves the image unchanged, 1 applies the full AO"),
      float_param("power", 1.0, 0.1, 10.0, "", "AO is raised to this power before strength"),
      float_param("remap_min", 0.0, 0.0, 1.0, "", "AO value that full occlusion maps to"),
      float_param("remap_max", 1.0, 0.0, 1.0, "", "AO value that no occlusion maps to"),
      // --- input conventions ---
      string_param("depth_kind", "planar", "planar|radial",
                   "planar: distance along the view axis (Blender's Depth pass); radial: distance "
                   "along the pixel's ray"),
      string_param("normal_space", "world", "world|camera",
                   "space of the normal image; world needs camera_to_world"),
      float_param("background_depth", 1e9, 0.0, kInf, "scene units",
                  "depths at or beyond this are background (Blender writes 1e10)"),
      // --- camera (Blender's bpy.types.Camera names) ---
      string_param("camera_type", "PERSP", "PERSP|ORTHO", "perspective or orthographic camera"),
      float_param("lens", 50.0, 1e-6, 1e9, "mm", "focal length (PERSP)"),
      float_param("sensor_width", 36.0, 1e-6, 1e9, "mm", "sensor width"),
      float_param("sensor_height", 24.0, 1e-6, 1e9, "mm", "sensor height"),
      string_param("sensor_fit", "AUTO", "AUTO|HORIZONTAL|VERTICAL",
                   "AUTO fits sensor_width to the larger image side"),
      float_param("shift_x", 0.0, -1e3, 1e3, "fitted image side", "horizontal lens shift"),
      float_param("shift_y", 0.0, -1e3, 1e3, "fitted image side", "vertical lens shift"),
      float_param("ortho_scale", 6.0, 1e-9, 1e12, "scene units",
                  "width of the view along the fitted side (ORTHO)"),
      float_param("clip_start", 0.1, 0.0, kInf, "scene units", "near clip (informational)"),
      float_param("clip_end", 0.0, 0.0, kInf, "scene units",
                  "depths at or beyond this are background; 0 disables the test"),
      float_param("pixel_aspect_x", 1.0, 1e-6, 1e6, "", "pixel aspect ratio, x"),
      float_param("pixel_aspect_y", 1.0, 1e-6, 1e6, "", "pixel aspect ratio, y"),
      {"camera_to_world", SSAO_PARAM_FLOATS, 0.0, 0.0, 0.0, nullptr, nullptr, 16, "",
       "camera-to-world matrix, 16 values row by row (Blender's matrix_world); identity by "
       "default; used to bring world-space normals into view space"},
      // --- execution ---
      int_param("threads", 0, 0, 1024, "threads", "0 uses every core; results do not depend on it"),
  };
  return params;
}

bool is_choice(const ssao_param_desc& d, const char* value) {
  const std::string choices = d.choices;
  size_t start = 0;
  while (start <= choices.size()) {
    const size_t end = choices.find('|', start);
    const std::string choice =
        choices.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (choice == value) return true;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return false;
}

const char* type_name(ssao_param_type type) {
  switch (type) {
    case SSAO_PARAM_INT:
      return "an integer";
    case SSAO_PARAM_FLOAT:
      return "a float";
    case SSAO_PARAM_STRING:
      return "a string";
    case SSAO_PARAM_FLOATS:
      return "a float array";
  }
  return "unknown";
}

void check_range(const ssao_param_desc& d, double value) {
  if (!std::isfinite(value) && !(value == kInf && d.max_value == kInf)) {
    std::ostringstream msg;
    msg << "parameter '" << d.name << "' must be finite, got " << value;
    throw_invalid_argument(msg.str());
  }
  if (value < d.min_value || value > d.max_value) {
    std::ostringstream msg;
    msg << "parameter '" << d.name << "' must be in [" << d.min_value << ", " << d.max_value
        << "], got " << value;
    throw_invalid_argument(msg.str());
  }
}

}  // namespace

size_t param_count() { return table().size(); }

const ssao_param_desc& param_desc(size_t index) {
  if (index >= table().size()) {
    throw_invalid_argument("parameter index " + std::to_string(index) + " out of range (" +
                           std::to_string(table().size()) + " parameters)");
  }
  return table()[index];
}

ParamValues::ParamValues() : values_(table().size()) {
  for (size_t i = 0; i < table().size(); ++i) {
    const ssao_param_desc& d = table()[i];
    values_[i].number = d.default_value;
    if (d.type == SSAO_PARAM_STRING) values_[i].text = d.default_string;
    if (d.type == SSAO_PARAM_FLOATS) {
      values_[i].floats.assign(d.count, 0.0);
      // The only array parameter is a 4x4 matrix: identity by default.
      for (size_t k = 0; k < d.count; k += 5) values_[i].floats[k] = 1.0;
    }
  }
}

size_t ParamValues::index_of(const char* name, ssao_param_type expected) const {
  if (name == nullptr) throw_invalid_argument("parameter name is NULL");
  for (size_t i = 0; i < table().size(); ++i) {
    if (std::strcmp(table()[i].name, name) != 0) continue;
    if (table()[i].type != expected) {
      throw_invalid_argument(std::string("parameter '") + name + "' is " +
                             type_name(table()[i].type) + ", not " + type_name(expected));
    }
    return i;
  }
  throw_invalid_argument(std::string("unknown parameter '") + name + "'");
}

void ParamValues::set_int(const char* name, int value) {
  const size_t i = index_of(name, SSAO_PARAM_INT);
  check_range(table()[i], value);
  values_[i].number = value;
}

void ParamValues::set_float(const char* name, double value) {
  const size_t i = index_of(name, SSAO_PARAM_FLOAT);
  check_range(table()[i], value);
  values_[i].number = value;
}

void ParamValues::set_string(const char* name, const char* value) {
  const size_t i = index_of(name, SSAO_PARAM_STRING);
  if (value == nullptr) throw_invalid_argument(std::string("value of '") + name + "' is NULL");
  if (!is_choice(table()[i], value)) {
    throw_invalid_argument(std::string("parameter '") + name + "' must be one of " +
                           table()[i].choices + ", got '" + value + "'");
  }
  values_[i].text = value;
}

void ParamValues::set_floats(const char* name, const double* values, size_t count) {
  const size_t i = index_of(name, SSAO_PARAM_FLOATS);
  const ssao_param_desc& d = table()[i];
  if (values == nullptr) throw_invalid_argument(std::string("values of '") + name + "' are NULL");
  if (count != d.count) {
    throw_invalid_argument(std::string("parameter '") + name + "' takes " +
                           std::to_string(d.count) + " values, got " + std::to_string(count));
  }
  for (size_t k = 0; k < count; ++k) {
    if (!std::isfinite(values[k])) {
      throw_invalid_argument(std::string("parameter '") + name + "' value " + std::to_string(k) +
                             " is not finite");
    }
  }
  values_[i].floats.assign(values, values + count);
}

int ParamValues::get_int(const char* name) const {
  return static_cast<int>(values_[index_of(name, SSAO_PARAM_INT)].number);
}
double ParamValues::get_float(const char* name) const {
  return values_[index_of(name, SSAO_PARAM_FLOAT)].number;
}
const std::string& ParamValues::get_string(const char* name) const {
  return values_[index_of(name, SSAO_PARAM_STRING)].text;
}
const std::vector<double>& ParamValues::get_floats(const char* name) const {
  return values_[index_of(name, SSAO_PARAM_FLOATS)].floats;
}

}  // namespace ssao
