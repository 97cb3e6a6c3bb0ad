// SPDX-License-Identifier: MIT
#include "params.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "error.h"
#include "variants/variant.h"

namespace ssao {
namespace {

constexpr double kInf = HUGE_VAL;

// A parameter and its group (ssao_param_group): what front ends select by.
struct Param {
  const char* group;
  ssao_param_desc desc;
};

Param int_param(const char* group, const char* name, int def, int lo, int hi, const char* unit,
                const char* description) {
  return {group,
          {name, SSAO_PARAM_INT, double(def), double(lo), double(hi), nullptr, nullptr, 1, unit,
           description}};
}
Param float_param(const char* group, const char* name, double def, double lo, double hi,
                  const char* unit, const char* description) {
  return {group, {name, SSAO_PARAM_FLOAT, def, lo, hi, nullptr, nullptr, 1, unit, description}};
}
Param string_param(const char* group, const char* name, const char* def, const char* choices,
                   const char* description) {
  return {group, {name, SSAO_PARAM_STRING, 0.0, 0.0, 0.0, def, choices, 1, "", description}};
}
Param matrix_param(const char* group, const char* name, const char* description) {
  return {group, {name, SSAO_PARAM_FLOATS, 0.0, 0.0, 0.0, nullptr, nullptr, 16, "", description}};
}

// The variant parameter's choices: the registry's names, in its order (not written again here).
const char* variant_choices() {
  static const std::string choices = [] {
    std::string out;
    for (const VariantInfo& v : variant_registry())
      out += (out.empty() ? "" : "|") + std::string(v.name);
    return out;
  }();
  return choices.c_str();
}

// Groups, in the order front ends show them.
constexpr const char* kAo = "ao";            // what the estimate computes
constexpr const char* kQuality = "quality";  // how much work it does
constexpr const char* kShaping = "shaping";  // the AO's final look
constexpr const char* kInput = "input";      // how the caller's passes are to be read
constexpr const char* kCamera = "camera";    // the camera the passes were rendered with
constexpr const char* kExecution = "execution";

// Defaults marked "measured" were chosen by the run-time-vs-error benchmark against Cycles'
// AO pass (benchmarks/, docs/accuracy.md).
const std::vector<Param>& params() {
  static const std::vector<Param> params = {
      // --- algorithm ---
      string_param(kAo, "variant", "hemisphere", variant_choices(),
                   "horizon: horizon-based slices with a visibility bitmask (GTAO), kept for "
                   "comparison: 7-15x the default's time and less accurate on the benchmark "
                   "scenes but the one with thin occluders (docs/variants.md); hemisphere: "
                   "normal-oriented hemisphere kernel; sphere: Crysis sphere kernel (depth only); "
                   "volumetric: line-integral obscurance of a sphere along view rays (depth "
                   "only); unsharp: depth unsharp masking, the local mean depth against the "
                   "pixel's (depth only)"),
      float_param(kAo, "radius", 1.0, 1e-6, 1e9, "scene units",
                  "distance within which geometry occludes, as Cycles' AO distance"),
      string_param(kQuality, "quality", "medium", "low|medium|high|ultra",
                   "sample counts of the variant (samples, slices, steps) that are left at 0; "
                   "medium is the measured balance of time and error"),
      int_param(kQuality, "samples", 0, 0, 1024, "directions per pixel",
                "hemisphere: kernel directions per pixel; sphere: points per pixel; volumetric: "
                "view rays per pixel; 0: from quality"),
      int_param(kQuality, "slices", 0, 0, 64, "slices per pixel",
                "horizon: screen-space lines through each pixel; 0: from quality"),
      int_param(kQuality, "steps", 0, 0, 64, "samples per direction",
                "hemisphere: samples along each direction, the strongest occluder counts (1 is "
                "the classic kernel of independent points; 0: from quality, twice the preset's "
                "with extra depth layers); horizon: samples on each side of a slice; 0: from "
                "quality"),
      float_param(kAo, "bias", 0.02, 0.0, 1.0, "fraction of radius",
                  "height above the receiver's tangent plane (hemisphere, horizon) or behind the "
                  "sample (sphere) an occluder needs to count; one pixel footprint is added"),
      float_param(kAo, "sample_clustering", 1.0, 0.0, 4.0, "exponent",
                  "samples sit at radius * lerp(0.1, 1, s^p) for s uniform in [0,1): 0 puts all "
                  "on the kernel's surface, 2 clusters them toward the centre as the seed code "
                  "does (measured)"),
      float_param(
          kAo, "thickness", 0.5, 0.01, 100.0, "fraction of radius",
          "assumed thickness of surfaces: horizon: an occluder spans this far behind the visible "
          "surface; hemisphere: a sample this far behind the visible surface counts fully, "
          "fading out at twice the distance (range check against halos; without extra layers "
          "shaped as thickness_profile says, and a post's depth taken from its width, or a "
          "face's from the side a deeper solid would show, where that is less); volumetric: a "
          "ray "
          "whose visible surface is this far in front of the sphere counts fully, fading out "
          "at twice the distance"),
      string_param(kAo, "thickness_profile", "silhouettes", "silhouettes|constant",
                   "hemisphere without extra layers: silhouettes: the assumed thickness is that "
                   "of a rounded solid, thinner toward the silhouettes of the surface in front "
                   "(down to half), thicker inside one as wide down its column as along its row "
                   "(up to 1.5x); constant: the same everywhere"),
      string_param(kAo, "sphere_mode", "normalized", "normalized|classic",
                   "sphere variant: classic reads about 0.5 on a flat wall; normalized maps an "
                   "unoccluded flat surface to 1"),
      int_param(kQuality, "seed", 0, 0, 2147483647, "", "seed of the kernel rotation pattern"),
      string_param(kQuality, "resolution", "auto", "auto|full|half",
                   "full: AO estimated at every pixel; half: at half resolution in each axis (a "
                   "quarter of the work), then upsampled guided by depth and normals; auto: half "
                   "for frames of at least 1 megapixel, where it costs almost no accuracy "
                   "(measured)"),
      // --- denoising ---
      string_param(kQuality, "denoise", "bilateral", "bilateral|box4|none",
                   "bilateral: depth- and normal-aware blur; box4: the seed code's 4x4 box blur; "
                   "none: raw estimate"),
      float_param(kAo, "pixel_filter", 0.5, 0.0, 1.0, "pixels",
                  "standard deviation of the Gaussian pixel filter the AO is seen through, as a "
                  "renderer anti-aliases its passes: on a silhouette the AO mixes both surfaces' "
                  "by their share of the pixel (Cycles' AO pass does; the Depth pass holds one "
                  "surface); 0: one surface per pixel, a staircase along edges; 0.5: fitted to "
                  "Cycles' default 1.5 px Blackman-Harris filter (measured)"),
      int_param(kExecution, "temporal_frames", 3, 1, 8, "frames",
                "in a sequence (frame >= 0), the AO averages this many frames: this one and the "
                "frames numbered just before it that the same job computed, each carried to "
                "this frame's pixels through its depth and camera_to_world; a pixel the earlier "
                "frame did not see, one within radius of where the depths show that something "
                "moved, or one whose AO changed by more than 0.1 takes no part. Steadies the "
                "sampling pattern's crawl on camera moves (measured: "
                "docs/performance.md); 1: each frame alone"),
      int_param(kExecution, "frame", -1, -1, 2147483647, "",
                "this frame's number in its sequence, for temporal_frames; a job's frames must "
                "come in increasing order (the command line's --frames sets it); -1: a frame on "
                "its own"),
      // --- output shaping: ao = remap_min + (remap_max - remap_min) * mix(1, raw^power, strength)
      float_param(kShaping, "strength", 1.0, 0.0, 1.0, "",
                  "0 leaves the image unchanged, 1 applies the full AO"),
      float_param(kShaping, "power", 1.0, 0.1, 10.0, "",
                  "AO is raised to this power before strength"),
      float_param(kShaping, "remap_min", 0.0, 0.0, 1.0, "", "AO value that full occlusion maps to"),
      float_param(kShaping, "remap_max", 1.0, 0.0, 1.0, "", "AO value that no occlusion maps to"),
      // --- input conventions ---
      string_param(kInput, "depth_kind", "planar", "planar|radial",
                   "planar: distance along the view axis (Blender's Depth pass); radial: distance "
                   "along the pixel's ray"),
      string_param(kInput, "normal_space", "world", "world|camera",
                   "space of the normal image; world needs camera_to_world"),
      float_param(kInput, "background_depth", 1e9, 0.0, kInf, "scene units",
                  "depths at or beyond this are background (Blender writes 1e10)"),
      string_param(kInput, "edge_coverage", "beauty", "none|beauty",
                   "beauty: at a depth edge the pixel's AO is the two surfaces' AO (each through "
                   "the pixel filter) mixed by the share of the pixel each covers, as a "
                   "renderer's AO pass mixes them (the Depth pass holds one surface, at the "
                   "pixel's centre: the other gets at most half), read where the edge's pixels "
                   "show mixes of the two surfaces in their colours (the \"beauty\" image, or "
                   "the \"edge_colours\" image in its place; the colours must differ enough) or "
                   "in their normals (the \"normal\" image with a beauty, filtered over the "
                   "pixel like the beauty; the two surfaces' normals must differ enough; where "
                   "both read a mix, "
                   "the smaller share), else from the depth's staircase (a run of edge pixels "
                   "that steps one pixel toward each surface at its two ends places a straight "
                   "silhouette inside the pixels); a pixel whose normal is no mix of the two "
                   "surfaces' holds a third and keeps the pixel filter, as does any edge none of "
                   "these reads; not for a beauty whose edges are not the depth's (depth of "
                   "field or motion blur rendered into it). none: the pixel filter alone"),
      // --- camera (Blender's bpy.types.Camera names) ---
      string_param(kCamera, "camera_type", "PERSP", "PERSP|ORTHO",
                   "perspective or orthographic camera"),
      float_param(kCamera, "lens", 50.0, 1e-6, 1e9, "mm", "focal length (PERSP)"),
      float_param(kCamera, "sensor_width", 36.0, 1e-6, 1e9, "mm", "sensor width"),
      float_param(kCamera, "sensor_height", 24.0, 1e-6, 1e9, "mm", "sensor height"),
      string_param(kCamera, "sensor_fit", "AUTO", "AUTO|HORIZONTAL|VERTICAL",
                   "AUTO fits sensor_width to the larger image side"),
      float_param(kCamera, "shift_x", 0.0, -1e3, 1e3, "fitted image side", "horizontal lens shift"),
      float_param(kCamera, "shift_y", 0.0, -1e3, 1e3, "fitted image side", "vertical lens shift"),
      float_param(kCamera, "ortho_scale", 6.0, 1e-9, 1e12, "scene units",
                  "width of the view along the fitted side (ORTHO)"),
      float_param(kCamera, "clip_start", 0.1, 0.0, kInf, "scene units",
                  "near clip (informational)"),
      float_param(kCamera, "clip_end", 0.0, 0.0, kInf, "scene units",
                  "depths at or beyond this are background; 0 disables the test"),
      float_param(kCamera, "pixel_aspect_x", 1.0, 1e-6, 1e6, "", "pixel aspect ratio, x"),
      float_param(kCamera, "pixel_aspect_y", 1.0, 1e-6, 1e6, "", "pixel aspect ratio, y"),
      matrix_param(kCamera, "camera_to_world",
                   "camera-to-world matrix, 16 values row by row (Blender's matrix_world); "
                   "identity by default; used to bring world-space normals into view space"),
      // --- execution ---
      int_param(kExecution, "threads", 0, 0, 1024, "threads",
                "0 uses every core; results do not depend on it"),
      // --- camera contract: any renderer's camera, beside Blender's lens and sensor above ---
      string_param(kCamera, "projection", "lens", "lens|intrinsics|matrix",
                   "how the camera is given: lens: Blender's camera (camera_type, lens, sensor, "
                   "sensor_fit, shift, ortho_scale, pixel aspect); intrinsics: the pinhole "
                   "numbers fx, fy, cx, cy of the intrinsics parameter (camera_type still "
                   "chooses perspective or orthographic); matrix: an OpenGL-style projection "
                   "matrix (projection_matrix; perspective or orthographic from its last row)"),
      {kCamera,
       {"intrinsics", SSAO_PARAM_FLOATS, 0.0, 0.0, 0.0, nullptr, nullptr, 4, "pixels",
        "fx, fy, cx, cy (projection = intrinsics): focal lengths in pixels (orthographic: "
        "pixels per scene unit) and the principal point in image coordinates, x right and y "
        "down from the top-left corner, pixel (0, 0) centred at (0.5, 0.5) (OpenCV's cx + "
        "0.5); describe the frame (the output window with overscan)"}},
      matrix_param(kCamera, "projection_matrix",
                   "projection = matrix: the view-to-clip matrix, 16 values row by row (OpenGL: "
                   "view space looks down -Z, clip space to NDC [-1, 1], +Y up; Blender's "
                   "camera.calc_matrix_camera()); no skew; describes the frame"),
  };
  return params;
}

// The descriptions alone, in table order: what ssao_param_info hands out.
const std::vector<ssao_param_desc>& table() {
  static const std::vector<ssao_param_desc> descs = [] {
    std::vector<ssao_param_desc> out;
    for (const Param& p : params()) out.push_back(p.desc);
    return out;
  }();
  return descs;
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

const char* param_group(size_t index) {
  param_desc(index);  // the range check and its message
  return params()[index].group;
}

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
      // 4x4 matrices are the identity by default; the intrinsics, zeros (unset: refused).
      if (d.count == 16) {
        for (size_t k = 0; k < d.count; k += 5) values_[i].floats[k] = 1.0;
      }
    }
  }
}

size_t ParamValues::index_of(const char* name) const {
  if (name == nullptr) throw_invalid_argument("parameter name is NULL");
  for (size_t i = 0; i < table().size(); ++i) {
    if (std::strcmp(table()[i].name, name) == 0) return i;
  }
  throw_invalid_argument(std::string("unknown parameter '") + name + "'");
}

size_t ParamValues::index_of(const char* name, ssao_param_type expected) const {
  const size_t i = index_of(name);
  if (table()[i].type != expected) {
    throw_invalid_argument(std::string("parameter '") + name + "' is " +
                           type_name(table()[i].type) + ", not " + type_name(expected));
  }
  return i;
}

bool ParamValues::is_set(const char* name) const { return values_[index_of(name)].set; }

void ParamValues::set_float_default(const char* name, double value) {
  set_float(name, value);
  values_[index_of(name)].set = false;
}

void ParamValues::reset_group(const char* group) {
  const ParamValues defaults;
  for (size_t i = 0; i < table().size(); ++i) {
    if (std::strcmp(param_group(i), group) == 0) values_[i] = defaults.values_[i];
  }
}

void ParamValues::set_int(const char* name, int value) {
  const size_t i = index_of(name, SSAO_PARAM_INT);
  check_range(table()[i], value);
  values_[i].number = value;
  values_[i].set = true;
}

void ParamValues::set_float(const char* name, double value) {
  const size_t i = index_of(name, SSAO_PARAM_FLOAT);
  check_range(table()[i], value);
  values_[i].number = value;
  values_[i].set = true;
}

void ParamValues::set_string(const char* name, const char* value) {
  const size_t i = index_of(name, SSAO_PARAM_STRING);
  if (value == nullptr) throw_invalid_argument(std::string("value of '") + name + "' is NULL");
  if (!is_choice(table()[i], value)) {
    throw_invalid_argument(std::string("parameter '") + name + "' must be one of " +
                           table()[i].choices + ", got '" + value + "'");
  }
  values_[i].text = value;
  values_[i].set = true;
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
  values_[i].set = true;
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
