// SPDX-License-Identifier: MIT
#include "job.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "camera.h"
#include "denoise.h"
#include "error.h"
#include "frame.h"
#include "pixel_filter.h"
#include "scratch.h"
#include "simd.h"
#include "temporal.h"
#include "variants/variant.h"

namespace ssao {
namespace {

// Images "depth2" ... "depth5" and "facing2" ... "facing5": the number after the prefix (2 to
// kMaxExtraLayers + 1), 0 for any other name.
int layer_number(const char* name, const char* prefix) {
  const size_t length = std::strlen(prefix);
  if (std::strncmp(name, prefix, length) != 0 || name[length] == '\0' || name[length + 1] != '\0') {
    return 0;
  }
  const int number = name[length] - '0';
  return number >= 2 && number <= kMaxExtraLayers + 1 ? number : 0;
}

// The camera of a width x height frame as the parameter "projection" says it is given.
CameraModel frame_camera(const ParamValues& v, int width, int height) {
  const std::string& projection = v.get_string("projection");
  if (projection == "intrinsics") {
    const std::vector<double>& k = v.get_floats("intrinsics");
    return CameraModel::from_intrinsics(v.get_string("camera_type") == "ORTHO", k[0], k[1], k[2],
                                        k[3]);
  }
  if (projection == "matrix") {
    return CameraModel::from_projection_matrix(v.get_floats("projection_matrix").data(), width,
                                               height);
  }
  return CameraModel(camera_params(v), width, height);
}

// World-space normals are turned into view space through camera_to_world's 3x3 part; a
// singular one (zero or parallel axes) would flatten them into wrong normals without a word.
// The determinant is compared with the product of the column lengths: scale does not matter.
void require_invertible_rotation(const std::vector<double>& m) {
  const auto column = [&](int c) {
    return std::sqrt(m[c] * m[c] + m[4 + c] * m[4 + c] + m[8 + c] * m[8 + c]);
  };
  const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                     m[2] * (m[4] * m[9] - m[5] * m[8]);
  if (!(std::fabs(det) > 1e-6 * column(0) * column(1) * column(2))) {
    throw_invalid_argument(
        "camera_to_world has a singular 3x3 part (zero or parallel axes): world-space normals "
        "cannot be turned into view space; give the camera's matrix or normal_space = camera");
  }
}

DenoiseMode denoise_mode(const std::string& name) {
  if (name == "none") return DenoiseMode::none;
  if (name == "box4") return DenoiseMode::box4;
  return DenoiseMode::bilateral;
}

// Final AO from raw visibility: power, then strength, then the optional min/max remap.
// Applied to a row in place; background (depth +inf) becomes 1. The part after the power is a
// loop without calls or branches, which the compiler vectorises.
struct Shaping {
  float power, strength, remap_min, remap_max;
  void apply(const float* depth, float* values, int count) const {
    if (power != 1.0f) {
      // The C library's powf: in double (portable_pow) it cost 22 % of a 1080p frame. So with
      // power != 1 the Windows and Linux builds may differ in the last bit (docs/install.md).
      for (int i = 0; i < count; ++i) values[i] = std::pow(values[i], power);
    }
    finish(depth, values, count, strength, remap_min, remap_max);
  }
  SSAO_VECTORIZE static void finish(const float* __restrict depth, float* __restrict values,
                                    int count, float strength, float remap_min, float remap_max) {
    for (int i = 0; i < count; ++i) {
      const float strong = 1.0f - strength * (1.0f - values[i]);
      const float mapped = remap_min + (remap_max - remap_min) * strong;
      const float ao = mapped < 0.0f ? 0.0f : (mapped > 1.0f ? 1.0f : mapped);
      values[i] = depth[i] != Frame::kBackground ? ao : 1.0f;
    }
  }
};

// The geometry pixels (depth not background) of a tile's rows and the sum of their AO, for
// ssao_job_last_run. Eight float lanes as a GNU vector (one AVX register, two SSE ones): a fixed
// lane structure, so the sums do not depend on the instruction set, and no reassociation.
class GeometryCounter {
 public:
  SSAO_VECTORIZE void add_row(const float* depth, const float* ao, int count) {
    int i = 0;
    for (; i + kLanes <= count; i += kLanes) {
      Floats d, value;
      std::memcpy(&d, depth + i, sizeof d);
      std::memcpy(&value, ao + i, sizeof value);
      const Ints surface = d < Frame::kBackground;                // -1 (all bits) or 0 per lane
      sum_ += value * __builtin_convertvector(-surface, Floats);  // AO is finite: x * 0 = 0
      count_ -= surface;
    }
    for (int k = 0; i < count; ++i, ++k) {
      const bool surface = depth[i] < Frame::kBackground;
      sum_[k] += surface ? ao[i] : 0.0f;
      count_[k] += surface ? 1 : 0;
    }
  }
  // Adds the lanes, in lane order, to a run's totals.
  void add_to(size_t& geometry, double& sum) const {
    for (int k = 0; k < kLanes; ++k) {
      sum += double(sum_[k]);
      geometry += size_t(count_[k]);
    }
  }

 private:
  static constexpr int kLanes = 8;
  typedef float Floats __attribute__((vector_size(kLanes * sizeof(float))));
  typedef int32_t Ints __attribute__((vector_size(kLanes * sizeof(int32_t))));
  Floats sum_ = {};
  Ints count_ = {};
};

// Pixels [x, x + count) of row y of `out` from the AO of a row: grey in the first three
// channels, alpha 1. The pointer steps by the pixel stride (a multiple of 4 bytes).
void write_ao_row(const float* ao, int count, const ImageView& out, int x, int y) {
  float* dst = out.pixel(x, y);
  const std::ptrdiff_t step = out.pixel_stride / std::ptrdiff_t(sizeof(float));
  if (step == 1) {  // one packed channel
    std::copy_n(ao, count, dst);
    return;
  }
  const int grey = std::min(out.channels, 3);
  for (int i = 0; i < count; ++i, dst += step) {
    for (int c = 0; c < grey; ++c) dst[c] = ao[i];
    if (out.channels == 4) dst[3] = 1.0f;
  }
}

// What the composite multiplies a pixel's colour by: AO itself where the surface covers the
// pixel (1 - (1 - AO) need not round back to AO), else 1 - c (1 - AO).
inline float composite_factor(float ao, float coverage) {
  return coverage < 1.0f ? 1.0f - coverage * (1.0f - ao) : ao;
}

// composite_row's plain case on packed RGB or RGBA pixels (alpha copied): a loop the compiler
// vectorises, where the general one's channel count and strides are known only at run time.
// src and dst may be the same pixels (a composite in place): no __restrict on them.
template <int kChannels>
SSAO_VECTORIZE void composite_packed(const float* __restrict ao, const float* __restrict coverage,
                                     int count, const float* src, float* dst) {
  for (int i = 0; i < count; ++i) {
    const float factor = composite_factor(ao[i], coverage[i]);
    for (int c = 0; c < 3; ++c) dst[i * kChannels + c] = src[i * kChannels + c] * factor;
    if (kChannels == 4) dst[i * kChannels + 3] = src[i * kChannels + 3];
  }
}

// The composite of pixels [x, x + count) of row y: the beauty darkened on the share c of each
// pixel that the surface covers, beauty x (1 - c (1 - AO)), or, with an ambient image, the beauty
// less c (1 - AO) of the ambient light (never below 0 where the beauty is not). Colour channels
// only; alpha is copied. coverage[i] is c.
void composite_row(const float* ao, const float* coverage, int count, const ImageView& beauty,
                   const ImageView& ambient, const ImageView& out, int x, int y) {
  const float* src = beauty.pixel(x, y);
  float* dst = out.pixel(x, y);
  const std::ptrdiff_t src_step = beauty.pixel_stride / std::ptrdiff_t(sizeof(float));
  const std::ptrdiff_t dst_step = out.pixel_stride / std::ptrdiff_t(sizeof(float));
  const int channels = out.channels, colour = std::min(channels, 3);
  if (ambient.attached()) {
    const float* light = ambient.pixel(x, y);
    const std::ptrdiff_t light_step = ambient.pixel_stride / std::ptrdiff_t(sizeof(float));
    for (int i = 0; i < count; ++i, src += src_step, dst += dst_step, light += light_step) {
      const float occluded = coverage[i] * (1.0f - ao[i]);
      for (int c = 0; c < colour; ++c) {
        const float darker = src[c] - occluded * light[c];
        dst[c] = darker < 0.0f && src[c] >= 0.0f ? 0.0f : darker;
      }
      for (int c = colour; c < channels; ++c) dst[c] = src[c];
    }
    return;
  }
  if (src_step == channels && dst_step == channels && channels == 3) {
    composite_packed<3>(ao, coverage, count, src, dst);
  } else if (src_step == channels && dst_step == channels && channels == 4) {
    composite_packed<4>(ao, coverage, count, src, dst);
  } else {
    for (int i = 0; i < count; ++i, src += src_step, dst += dst_step) {
      const float factor = composite_factor(ao[i], coverage[i]);
      for (int c = 0; c < colour; ++c) dst[c] = src[c] * factor;
      for (int c = colour; c < channels; ++c) dst[c] = src[c];
    }
  }
}

// The share of pixels [x0, x1) of frame row y that the surface covers, for the composite. 1
// except on geometry pixels beside the background: there an anti-aliased normal pass is the
// average of the surface's unit normals and the sky's zeros, so its length is the surface's
// share of the pixel. A beauty with alpha below 1 (a transparent film) holds only what is not
// transparent, premultiplied: the surface's share of that is length / alpha. Normals from
// elsewhere than a pass (reconstructed) say nothing: 1.
// beside: scratch for x1 - x0 flags.
void coverage_row(const Frame& frame, const ImageView& normal, const ImageView& beauty, int x0,
                  int x1, int y, int dx, int dy, uint8_t* beside, float* coverage) {
  if (normal.attached()) frame.beside_background_row(y, x0, x1, beside);
  for (int x = x0; x < x1; ++x) {
    float c = 1.0f;
    if (normal.attached() && beside[x - x0] && frame.is_geometry(x, y)) {
      const float* n = normal.pixel(x, y);
      const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      c = length < 1.0f ? length : 1.0f;  // NaN fails the test: 1
      if (beauty.channels == 4) {
        const float alpha = beauty.pixel(x - dx, y - dy)[3];
        if (alpha > 0.0f && alpha < 1.0f) c = c < alpha ? c / alpha : 1.0f;
      }
    }
    coverage[x - x0] = c;
  }
}

// resolution = auto estimates at half resolution from this many pixels on. Measured with the
// benchmark against Cycles' AO pass: at 1920x1080 half resolution costs 0.0005 of mean RMSE
// (at 1.6x the speed); at 640x360, 0.002 (pixels there are large next to contact shadows).
constexpr double kHalfResolutionPixels = 1e6;

// The automatic radius is this fraction of the view's extent (along the image's larger side) at
// the median depth. Calibrated on the artist-chosen AO distances of the nine benchmark and
// development scenes (docs/parameters.md): their ratio is 0.06 to 0.14, geometric mean 0.100.
constexpr double kAutoRadiusFraction = 0.1;

// Pixels around the output window (in the estimated frame's pixels) whose estimates reach it:
// each denoise pass reads 2 pixels to either side, the upsampling 1 half-resolution pixel; with
// room to spare. tests/unit/test_overscan.cpp holds the result to the whole frame's, bit for bit.
constexpr int kDenoiseReach = 8;

// Depth samples read for the median: every pixel up to this many, else a regular subset.
constexpr size_t kAutoRadiusSamples = 1u << 20;

}  // namespace

void Job::set_output_window(bool enable, int x, int y) {
  if (enable && (x < 0 || y < 0)) {
    throw_invalid_argument("output window at (" + std::to_string(x) + ", " + std::to_string(y) +
                           "): the window's top-left pixel must not be left of or above the "
                           "depth image");
  }
  windowed_ = enable;
  window_x_ = enable ? x : 0;
  window_y_ = enable ? y : 0;
}

Tile Job::output_window() const {
  const ImageView& out = ao_out_.attached() ? ao_out_ : composite_out_;
  if (!windowed_ || !out.attached()) return {0, 0, depth_.width, depth_.height};
  // In 64 bits: a window far beyond the image must not overflow on the way to its refusal.
  if (int64_t(window_x_) + out.width > depth_.width ||
      int64_t(window_y_) + out.height > depth_.height) {
    throw_invalid_argument("the output window " + std::to_string(out.width) + "x" +
                           std::to_string(out.height) + " at (" + std::to_string(window_x_) + ", " +
                           std::to_string(window_y_) + ") does not fit in the " +
                           std::to_string(depth_.width) + "x" + std::to_string(depth_.height) +
                           " depth image");
  }
  return {window_x_, window_y_, window_x_ + out.width, window_y_ + out.height};
}

CameraModel Job::input_camera(const Tile& w) const {
  const int width = std::max(w.x1 - w.x0, 1), height = std::max(w.y1 - w.y0, 1);
  return frame_camera(params_, width, height).moved_by(w.x0, w.y0);
}

double Job::auto_radius() const {
  if (!depth_.attached()) throw_invalid_operation("no depth image: attach one with set_image");
  // Over the output window (the frame as rendered): a guard band does not change the radius.
  const Tile window = output_window();
  const int width = window.x1 - window.x0, height = window.y1 - window.y0;
  const ParamValues& v = params_;
  const CameraModel camera = input_camera(window);
  const bool radial = v.get_string("depth_kind") == "radial";
  const float limit = background_limit(v.get_float("background_depth"), v.get_float("clip_end"));
  const size_t pixels = size_t(width) * size_t(height);
  const size_t step = std::max<size_t>(1, pixels / kAutoRadiusSamples);
  std::vector<float> planar;
  planar.reserve(std::min(pixels, kAutoRadiusSamples + 1));
  for (size_t i = 0; i < pixels; i += step) {
    const int x = window.x0 + int(i % size_t(width)), y = window.y0 + int(i / size_t(width));
    float d = depth_.pixel(x, y)[0];
    Frame::planar_depth_row(camera.intrinsics(), &d, x, 1, float(y) + 0.5f, radial, limit);
    if (d != Frame::kBackground) planar.push_back(d);
  }
  if (planar.empty()) {
    throw_invalid_operation(
        "the depth image has no geometry pixel: no depth to size the radius by");
  }
  auto middle = planar.begin() + std::ptrdiff_t(planar.size() / 2);
  std::nth_element(planar.begin(), middle, planar.end());
  const double median = *middle;
  const CameraIntrinsics k = camera.intrinsics();
  const double extent = std::max(double(k.scale_u) * width, double(k.scale_v) * height);
  return kAutoRadiusFraction * extent * (camera.orthographic() ? 1.0 : median);
}

void Job::set_image(const char* name, float* data, int width, int height, int channels,
                    std::ptrdiff_t pixel_stride, std::ptrdiff_t row_stride) {
  if (name == nullptr) throw_invalid_argument("image name is NULL");
  ImageView* slot = image_slot(name);
  if (slot == nullptr) {
    throw_invalid_argument(
        std::string("unknown image '") + name +
        "' (expected depth, normal, beauty, edge_colours, ambient, ao, composite, "
        "depth2 to "
        "depth" +
        std::to_string(kMaxExtraLayers + 1) + " or facing2 to facing" +
        std::to_string(kMaxExtraLayers + 1) + ")");
  }
  const int min_channels = slot == &normal_ ? 3 : 1, max_channels = 4;
  if (data == nullptr) {
    *slot = ImageView{};
    return;
  }
  const std::string what = std::string("image '") + name + "': ";
  if (width < 0 || height < 0) throw_invalid_argument(what + "negative width or height");
  if (channels < min_channels || channels > max_channels) {
    throw_invalid_argument(what + "needs " + std::to_string(min_channels) + " to " +
                           std::to_string(max_channels) + " channels, got " +
                           std::to_string(channels));
  }
  const std::ptrdiff_t pixel_bytes = std::ptrdiff_t(channels) * std::ptrdiff_t(sizeof(float));
  if (pixel_stride == 0) pixel_stride = pixel_bytes;
  if (pixel_stride < pixel_bytes) {
    throw_invalid_argument(what + "pixel stride " + std::to_string(pixel_stride) +
                           " is smaller than one pixel (" + std::to_string(pixel_bytes) +
                           " bytes)");
  }
  if (pixel_stride % std::ptrdiff_t(sizeof(float)) != 0) {
    throw_invalid_argument(what + "pixel stride must be a multiple of 4 bytes");
  }
  // Strides and sizes whose byte extent does not fit in a ptrdiff_t describe no memory, and
  // computing their offsets would overflow (undefined behaviour; found by tests/fuzz/fuzz_api):
  // refused before any product is formed unchecked.
  const std::string too_large = what +
                                "pixel stride, row stride and size span more bytes than "
                                "an address space has";
  std::ptrdiff_t row_bytes = 0;
  if (__builtin_mul_overflow(pixel_stride, std::ptrdiff_t(width), &row_bytes)) {
    throw_invalid_argument(too_large);
  }
  if (row_stride == 0) row_stride = row_bytes;
  if (row_stride == std::numeric_limits<std::ptrdiff_t>::min() ||
      std::abs(row_stride) < row_bytes || row_stride % std::ptrdiff_t(sizeof(float)) != 0) {
    throw_invalid_argument(what + "row stride " + std::to_string(row_stride) +
                           " is not a multiple of 4 of at least one row (" +
                           std::to_string(row_bytes) + " bytes)");
  }
  std::ptrdiff_t extent = 0;
  if (__builtin_mul_overflow(std::abs(row_stride), std::ptrdiff_t(height), &extent)) {
    throw_invalid_argument(too_large);
  }
  if (reinterpret_cast<std::uintptr_t>(data) % alignof(float) != 0) {
    throw_invalid_argument(what + "data is not aligned to 4 bytes");
  }
  *slot = ImageView{data, width, height, channels, pixel_stride, row_stride};
}

ImageView* Job::image_slot(const char* name) {
  const std::pair<const char*, ImageView*> named[] = {{"depth", &depth_},
                                                      {"normal", &normal_},
                                                      {"beauty", &beauty_},
                                                      {"edge_colours", &edge_colours_},
                                                      {"ambient", &ambient_},
                                                      {"ao", &ao_out_},
                                                      {"composite", &composite_out_}};
  for (const auto& [image, slot] : named) {
    if (std::strcmp(name, image) == 0) return slot;
  }
  if (const int n = layer_number(name, "depth")) return &layers_[n - 2];
  if (const int n = layer_number(name, "facing")) return &facing_[n - 2];
  return nullptr;
}

int Job::extra_layers() const {
  int count = 0;
  while (count < kMaxExtraLayers && layers_[count].attached()) ++count;
  return count;
}

void Job::validate_images() const {
  if (!depth_.attached()) throw_invalid_operation("no depth image: attach one with set_image");
  if (!ao_out_.attached() && !composite_out_.attached()) {
    throw_invalid_operation("no output image: attach 'ao' or 'composite'");
  }
  const auto size = [](const ImageView& view) {
    return std::to_string(view.width) + "x" + std::to_string(view.height);
  };
  // Input images have the depth image's size; the others, the output window's (the same
  // without a window).
  std::vector<std::pair<std::string, const ImageView*>> inputs = {{"normal", &normal_}};
  const int layers = extra_layers();
  for (int k = 0; k < kMaxExtraLayers; ++k) {
    const std::string number = std::to_string(k + 2);
    if (k >= layers && layers_[k].attached()) {
      throw_invalid_argument("image 'depth" + number + "' is attached without 'depth" +
                             std::to_string(k + 1) +
                             "': extra depth layers are the hits in order, without a gap");
    }
    if (facing_[k].attached() && !layers_[k].attached()) {
      throw_invalid_argument("image 'facing" + number + "' is attached without 'depth" + number +
                             "'");
    }
    inputs.push_back({"depth" + number, &layers_[k]});
    inputs.push_back({"facing" + number, &facing_[k]});
  }
  const std::pair<const char*, const ImageView*> outputs[] = {{"beauty", &beauty_},
                                                              {"edge_colours", &edge_colours_},
                                                              {"ambient", &ambient_},
                                                              {"ao", &ao_out_},
                                                              {"composite", &composite_out_}};
  for (const auto& [name, view] : inputs) {
    if (view->attached() && (view->width != depth_.width || view->height != depth_.height)) {
      throw_invalid_argument("image '" + name + "' is " + size(*view) + " but depth is " +
                             size(depth_));
    }
  }
  const Tile window = output_window();
  const int window_width = window.x1 - window.x0, window_height = window.y1 - window.y0;
  for (const auto& [name, view] : outputs) {
    if (!view->attached() || (view->width == window_width && view->height == window_height)) {
      continue;
    }
    throw_invalid_argument(std::string("image '") + name + "' is " + size(*view) + " but " +
                           (windowed_ ? "the output window is " + std::to_string(window_width) +
                                            "x" + std::to_string(window_height)
                                      : "depth is " + size(depth_)));
  }
  if (composite_out_.attached()) {
    if (!beauty_.attached()) throw_invalid_operation("'composite' output needs a 'beauty' image");
    if (composite_out_.channels != beauty_.channels) {
      throw_invalid_argument("'composite' has " + std::to_string(composite_out_.channels) +
                             " channels but 'beauty' has " + std::to_string(beauty_.channels));
    }
    if (ambient_.attached() && ambient_.channels != beauty_.channels) {
      throw_invalid_argument("'ambient' has " + std::to_string(ambient_.channels) +
                             " channels but 'beauty' has " + std::to_string(beauty_.channels));
    }
  }
}

TilePool& Job::pool(int threads) {
  if (!pool_ || pool_->threads() != resolve_thread_count(threads)) {
    pool_ = std::make_unique<TilePool>(threads);
  }
  return *pool_;
}

void Job::set_camera_json(const std::string& text, const std::string& source) {
  ParamValues params = params_;  // an error leaves the job as it was
  params.reset_group("camera");  // the file describes the whole camera
  CameraFile file = apply_camera_json(text, source, params);
  params_ = std::move(params);
  camera_file_ = std::move(file);
}

Job::RadiusSource Job::choose_radius(bool allow_automatic) {
  if (params_.is_set("radius")) return RadiusSource::set;
  // Chosen, not set: the next call (a new camera file, a new depth) chooses again.
  if (camera_file_.ao_distance > 0.0) {
    params_.set_float_default("radius", camera_file_.ao_distance);
    return RadiusSource::camera_file;
  }
  if (!allow_automatic) {
    throw_invalid_operation(
        "no radius: set the parameter radius, or give \"ao_distance\" in the camera file");
  }
  params_.set_float_default("radius", auto_radius());
  return RadiusSource::automatic;
}

void Job::check_inputs() const {
  // World-space normals are turned into view space through camera_to_world: its identity
  // default would turn them wrong without a word.
  if (normal_.attached() && params_.get_string("normal_space") == "world" &&
      !params_.is_set("camera_to_world")) {
    throw_invalid_argument(
        "missing key 'matrix_world' (or the parameter camera_to_world): the camera's matrix, "
        "which world-space normals need; add it, or set normal_space to camera for view-space "
        "normals, or give no normal pass (normals rebuilt from depth)");
  }
}

Job::RunStats Job::last_run() const {
  if (!has_run_) throw_invalid_operation("no successful run yet: call ssao_job_run first");
  return last_run_;
}

void Job::run() {
  has_run_ = false;
  validate_images();
  const int width = depth_.width, height = depth_.height;
  // An empty window (an empty depth image among them: the window lies inside it) does nothing.
  const Tile window = output_window();
  if (window.x1 == window.x0 || window.y1 == window.y0) {
    last_run_ = RunStats{}, has_run_ = true;
    return;
  }

  const ParamValues& v = params_;
  const CameraModel camera = input_camera(window);
  TilePool& tiles = pool(v.get_int("threads"));
  Progress progress(progress_callback_, progress_user_);

  FrameInputs in;
  in.depth = depth_;
  in.normal = normal_;
  in.extra_layers = extra_layers();
  for (int k = 0; k < in.extra_layers; ++k) in.layers[k] = layers_[k], in.facing[k] = facing_[k];
  in.radial_depth = v.get_string("depth_kind") == "radial";
  in.world_normals = v.get_string("normal_space") == "world";
  const std::vector<double>& matrix = v.get_floats("camera_to_world");
  if (in.normal.attached() && in.world_normals) require_invertible_rotation(matrix);
  std::copy(matrix.begin(), matrix.end(), in.camera_to_world);
  in.background_limit = background_limit(v.get_float("background_depth"), v.get_float("clip_end"));
  in.assumed_thickness = float(v.get_float("thickness")) * float(v.get_float("radius"));
  in.shape_thickness_by_silhouettes = v.get_string("thickness_profile") == "silhouettes";

  progress.set_stage(0.0, 0.05);
  // The frame the variant sees: the input's, or a half-resolution copy (a quarter of the work;
  // the result is upsampled at the output, which needs the full frame's depths only).
  const std::string& resolution = v.get_string("resolution");
  const bool half_resolution =
      resolution == "half" ||
      (resolution == "auto" && double(width) * double(height) >= kHalfResolutionPixels);
  Frame& frame = frame_;
  frame.reset(camera, width, height, in.extra_layers);
  const VariantInfo& variant_info = find_variant(v.get_string("variant"));
  if (half_resolution) {
    frame.build_depth(in, tiles, progress);
    half_frame_.downsample(frame, in, tiles, progress, variant_info.frame_extras);
  } else {
    frame.build(in, tiles, progress, variant_info.frame_extras);
  }
  const Frame& seen = half_resolution ? half_frame_ : frame;
  // With one layer at most five image-size buffers: the full frame's four planes (depth, normal,
  // carried depth and normal) and one of visibility (or the full frame's depth plane, and the
  // half frame's planes and visibility, a quarter each). What the other mode kept is freed
  // (build_depth frees the full frame's other planes).
  if (!half_resolution) half_frame_ = Frame();
  const size_t estimates = size_t(seen.width()) * size_t(seen.height());
  if (visibility_.capacity() > estimates) std::vector<float>().swap(visibility_);

  const std::unique_ptr<Variant> variant = variant_info.create(v, seen);
  progress.set_stage(0.05, 0.95);
  std::vector<float>& visibility = visibility_;
  visibility.assign(estimates, 1.0f);
  // With overscan, estimates are needed only where the denoise and the upsampling reach the
  // output window from; the rest of the guard band is context that samples read.
  const int scale = half_resolution ? 2 : 1;
  const Tile needed{std::max(window.x0 / scale - kDenoiseReach, 0),
                    std::max(window.y0 / scale - kDenoiseReach, 0),
                    std::min((window.x1 + scale - 1) / scale + kDenoiseReach, seen.width()),
                    std::min((window.y1 + scale - 1) / scale + kDenoiseReach, seen.height())};
  tiles.for_each_tile(seen.width(), seen.height(), progress, [&](const Tile& tile) {
    const Tile t{std::max(tile.x0, needed.x0), std::max(tile.y0, needed.y0),
                 std::min(tile.x1, needed.x1), std::min(tile.y1, needed.y1)};
    // A tile of background costs one pass over its depths.
    if (t.x0 >= t.x1 || t.y0 >= t.y1 || !seen.has_geometry(t.x0, t.y0, t.x1, t.y1)) return;
    variant->estimate(seen, t, visibility.data());
  });

  const float radius = static_cast<float>(v.get_float("radius"));
  const Denoiser denoiser(seen, denoise_mode(v.get_string("denoise")), radius);
  const float filter_sigma = static_cast<float>(v.get_float("pixel_filter"));
  const float filter_weight = pixel_filter_weight(filter_sigma);
  // The colours that tell each surface's share of an edge pixel: the beauty's, unless the front
  // end gave others (its beauty is not the picture).
  const ImageView& edge_colours = edge_colours_.attached() ? edge_colours_ : beauty_;
  // Mixed by the colours where given (and the normals with them), else by the depth's staircase.
  const bool mix_edges = v.get_string("edge_coverage") == "beauty";
  // A frame of a sequence (frame >= 0) averages the frames before it that this job computed.
  const int frame_number = v.get_int("frame");
  temporal_.begin(frame_number, frame_number >= 0 ? v.get_int("temporal_frames") : 1, camera,
                  in.camera_to_world, window);
  temporal_.find_motion(frame, radius, tiles);
  progress.set_stage(0.95, 1.0);
  denoiser.horizontal_pass(visibility.data(), tiles, progress);

  // Outputs are written only now, after every cancellable stage succeeded: a failed or
  // cancelled run leaves the caller's buffers untouched. This last stage cannot be cancelled.
  const Shaping shaping{
      static_cast<float>(v.get_float("power")), static_cast<float>(v.get_float("strength")),
      static_cast<float>(v.get_float("remap_min")), static_cast<float>(v.get_float("remap_max"))};
  Progress uncancellable(nullptr, nullptr);
  const int dx = window.x0, dy = window.y0;  // output pixel (x - dx, y - dy) is frame pixel (x, y)
  // The statistics per output tile, summed in tile order afterwards: the same for any thread
  // count.
  const int tiles_across = (window.x1 - dx + kTileWidth - 1) / kTileWidth;
  const int tiles_down = (window.y1 - dy + kTileHeight - 1) / kTileHeight;
  struct Totals {
    size_t geometry_pixels = 0;
    double ao_sum = 0.0;
  };
  std::vector<Totals> tile_totals(size_t(tiles_across) * size_t(tiles_down));
  tiles.for_each_tile(window.x1 - dx, window.y1 - dy, uncancellable, [&](const Tile& output) {
    Totals& totals = tile_totals[size_t(output.y0 / kTileHeight) * size_t(tiles_across) +
                                 size_t(output.x0 / kTileWidth)];
    const Tile t{output.x0 + dx, output.y0 + dy, output.x1 + dx, output.y1 + dy};
    ScratchVector<float> denoised(size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0));
    ScratchVector<float> coverage(composite_out_.attached() ? size_t(t.x1 - t.x0) : 0);
    ScratchVector<uint8_t> beside(normal_.attached() ? coverage.size() : 0);  // coverage_row's
    const bool sky = !frame.has_geometry(t.x0, t.y0, t.x1, t.y1);
    // The visibility resolved at full resolution over `resolved` (the tile, or with the pixel
    // filter the tile and the pixels around it that the filter reads).
    const auto resolve = [&](const Tile& resolved, float* into) {
      if (half_resolution) {
        upsample(frame, half_frame_, visibility.data(), denoiser, radius, resolved, into);
      } else {
        denoiser.vertical_pass(visibility.data(), resolved, into);
      }
    };
    if (sky) {
      std::fill(denoised.begin(), denoised.end(), 1.0f);
    } else if (filter_weight > 0.0f || mix_edges) {
      const Tile around = pixel_filter_source(frame, t);
      ScratchVector<float> resolved(size_t(around.x1 - around.x0) * size_t(around.y1 - around.y0));
      resolve(around, resolved.data());
      if (filter_weight > 0.0f) {
        pixel_filter(frame, around, resolved.data(), t, filter_weight, denoised.data());
      } else {
        for (int y = t.y0; y < t.y1; ++y) {
          std::copy_n(resolved.data() + size_t(y - around.y0) * size_t(around.x1 - around.x0) +
                          (t.x0 - around.x0),
                      t.x1 - t.x0, denoised.data() + size_t(y - t.y0) * size_t(t.x1 - t.x0));
        }
      }
      if (mix_edges) {
        mix_edges_by_beauty(frame, edge_colours, normal_, dx, dy, around, resolved.data(), t,
                            filter_weight, filter_sigma, denoised.data());
      }
    } else {
      resolve(t, denoised.data());
    }
    temporal_.blend(frame, t, denoised.data());
    const int count = t.x1 - t.x0;
    GeometryCounter geometry;  // on the stack: its lanes are one aligned vector register
    for (int y = t.y0; y < t.y1; ++y) {
      float* values = denoised.data() + size_t(y - t.y0) * count;
      const float* depth = frame.depth_plane() + frame.index(t.x0, y);
      shaping.apply(depth, values, count);
      if (!sky) geometry.add_row(depth, values, count);
      if (ao_out_.attached()) write_ao_row(values, count, ao_out_, t.x0 - dx, y - dy);
      if (composite_out_.attached()) {
        coverage_row(frame, normal_, beauty_, t.x0, t.x1, y, dx, dy, beside.data(),
                     coverage.data());
        composite_row(values, coverage.data(), count, beauty_, ambient_, composite_out_, t.x0 - dx,
                      y - dy);
      }
    }
    geometry.add_to(totals.geometry_pixels, totals.ao_sum);
  });
  Totals run{};
  for (const Totals& tile : tile_totals) {
    run.geometry_pixels += tile.geometry_pixels;
    run.ao_sum += tile.ao_sum;
  }
  last_run_ = {run.geometry_pixels,
               run.geometry_pixels > 0 ? run.ao_sum / double(run.geometry_pixels) : 1.0};
  temporal_.commit();
  has_run_ = true;
  progress.report(1.0);
}

}  // namespace ssao
