// SPDX-License-Identifier: MIT
// Depth unsharp masking (Luft, Colditz & Deussen 2006; the course project in the seeds): the
// difference between the depth around a pixel (a box average over the AO radius) and the
// pixel's own depth. Where the surroundings are nearer than the pixel, it lies in a hollow and
// darkens: AO = 1 - (local mean depth deficit) / radius. Depth only. The box covers the radius
// in scene units at the pixel's depth, so the look does not change with the resolution, and a
// summed-area table built once per frame makes its cost independent of the radius.
#include <algorithm>
#include <cmath>

#include "variant.h"

namespace ssao {
namespace {

class Unsharp final : public Variant {
 public:
  Unsharp(const ParamValues& v, const Frame& f) : width_(f.width()), height_(f.height()) {
    radius_ = float(v.get_float("radius"));
    // Sums over the geometry pixels of [0, x) x [0, y): depth in double (a frame's sum of
    // depths needs more than a float's 24 bits to difference exactly), count in int32.
    const size_t stride = size_t(width_) + 1;
    depth_sum_.assign(stride * (size_t(height_) + 1), 0.0);
    count_sum_.assign(stride * (size_t(height_) + 1), 0);
    for (int y = 0; y < height_; ++y) {
      double row_depth = 0.0;
      int32_t row_count = 0;
      for (int x = 0; x < width_; ++x) {
        if (f.is_geometry(x, y)) {
          row_depth += double(f.depth(x, y));
          ++row_count;
        }
        const size_t at = (size_t(y) + 1) * stride + size_t(x) + 1;
        depth_sum_[at] = depth_sum_[at - stride] + row_depth;
        count_sum_[at] = count_sum_[at - stride] + row_count;
      }
    }
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    estimate_receivers(f, t, radius_, visibility, [&](int x, int y) { return pixel(f, x, y); });
  }

 private:
  float pixel(const Frame& f, int x, int y) const {
    const float depth = f.depth(x, y);
    // The radius in pixels at this depth; the box shrinks evenly at the image's edges so that
    // it stays centred on the pixel (a linear depth ramp then averages to its centre).
    const float reach_u = radius_ / f.camera().pixel_footprint(depth);
    const float reach_v = reach_u / f.camera().pixel_aspect();
    // Capped at the image's size before the conversion to int: a tiny depth (a denormal one
    // gives infinity) or a huge radius puts the reach beyond int's range, where the conversion
    // is undefined. The cap changes no result: the box is clipped to the image anyway.
    const int half_u = std::min({int(std::min(reach_u, float(width_)) + 0.5f), x, width_ - 1 - x});
    const int half_v =
        std::min({int(std::min(reach_v, float(height_)) + 0.5f), y, height_ - 1 - y});
    if (half_u < 1 && half_v < 1) return 1.0f;
    const int x0 = x - half_u, x1 = x + half_u + 1, y0 = y - half_v, y1 = y + half_v + 1;
    const int32_t count = box(count_sum_, x0, y0, x1, y1);
    // Too little geometry around (a pixel at the edge of the sky) tells nothing.
    if (count * 2 < (x1 - x0) * (y1 - y0)) return 1.0f;
    const double mean = box(depth_sum_, x0, y0, x1, y1) / double(count);
    const float deficit = float(double(depth) - mean);  // > 0: the surroundings are nearer
    if (!(deficit > 0.0f)) return 1.0f;
    // Depth-difference threshold against halos: a deficit of more than one radius is a
    // silhouette (a nearer object beside the pixel, not a hollow around it); it fades out by
    // two radii.
    const float occlusion = std::min(1.0f, deficit / radius_) * thickness_weight(deficit, radius_);
    return 1.0f - occlusion;
  }

  template <typename T>
  T box(const std::vector<T>& sums, int x0, int y0, int x1, int y1) const {
    const size_t stride = size_t(width_) + 1;
    return sums[size_t(y1) * stride + x1] - sums[size_t(y0) * stride + x1] -
           sums[size_t(y1) * stride + x0] + sums[size_t(y0) * stride + x0];
  }

  int width_, height_;
  float radius_;
  std::vector<double> depth_sum_;   // summed-area table of geometry depth, (w + 1) x (h + 1)
  std::vector<int32_t> count_sum_;  // summed-area table of geometry pixels
};

}  // namespace

extern const VariantInfo kUnsharpVariant;
const VariantInfo kUnsharpVariant = {
    "unsharp",
    "depth unsharp masking: the depth around the pixel against its own (Luft et al. 2006), "
    "depth only, cost independent of the radius",
    "",
    [](const ParamValues& v, const Frame& f) -> std::unique_ptr<Variant> {
      return std::make_unique<Unsharp>(v, f);
    },
    0u};

}  // namespace ssao
