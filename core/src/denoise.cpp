// SPDX-License-Identifier: MIT
#include "denoise.h"

#include <cmath>

namespace ssao {
namespace {

// The seed code's blur: the mean of a 4x4 window (offsets -1..2), one noise tile.
float box4_pixel(const GBuffer& g, const std::vector<float>& in, int x, int y) {
  float sum = 0.0f;
  int count = 0;
  for (int dy = -1; dy <= 2; ++dy) {
    for (int dx = -1; dx <= 2; ++dx) {
      const int sx = x + dx, sy = y + dy;
      if (sx < 0 || sy < 0 || sx >= g.width() || sy >= g.height() || !g.is_geometry(sx, sy)) {
        continue;
      }
      sum += in[size_t(sy) * g.width() + sx];
      ++count;
    }
  }
  return sum / float(count);  // count >= 1: the centre is geometry
}

// Cross-bilateral filter over a 5x5 window with tap weights (1/2, 1, 1, 1, 1/2) per axis: on a
// smooth surface every residue of the 4-periodic rotation pattern gets the same total weight, so
// the pattern cancels exactly. Neighbours off the receiver's tangent plane or with a different
// normal get little weight, which keeps contact shadows from bleeding across silhouettes.
float bilateral_pixel(const GBuffer& g, const std::vector<float>& in, float radius, int x, int y) {
  static const float tap[5] = {0.5f, 1.0f, 1.0f, 1.0f, 0.5f};
  const Vec3 p = g.position(x, y);
  const Vec3 n = g.normal(x, y);
  // Plane distance that halves a neighbour's weight: a few pixel footprints, at most 10% of the
  // radius, so a step of a fraction of the radius is an edge.
  const float plane_scale =
      std::min(0.1f * radius, 4.0f * g.camera().pixel_footprint(-p.z)) + 1e-30f;
  float sum = 0.0f, weight_sum = 0.0f;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const int sx = x + dx, sy = y + dy;
      if (sx < 0 || sy < 0 || sx >= g.width() || sy >= g.height() || !g.is_geometry(sx, sy)) {
        continue;
      }
      const float plane_distance = std::fabs(dot(g.position(sx, sy) - p, n)) / plane_scale;
      const float normal_agreement = std::max(0.0f, dot(g.normal(sx, sy), n));
      const float n2 = normal_agreement * normal_agreement;
      const float w =
          tap[dx + 2] * tap[dy + 2] * n2 * n2 / (1.0f + plane_distance * plane_distance);
      sum += w * in[size_t(sy) * g.width() + sx];
      weight_sum += w;
    }
  }
  return weight_sum > 0.0f ? sum / weight_sum : in[size_t(y) * g.width() + x];
}

}  // namespace

std::vector<float> denoise(const GBuffer& g, const std::vector<float>& visibility, DenoiseMode mode,
                           float radius, int threads, Progress& progress) {
  if (mode == DenoiseMode::none) return visibility;
  std::vector<float> out(visibility.size());
  parallel_rows(g.height(), threads, progress, [&](int y) {
    for (int x = 0; x < g.width(); ++x) {
      const size_t i = size_t(y) * g.width() + x;
      if (!g.is_geometry(x, y)) {
        out[i] = visibility[i];
      } else if (mode == DenoiseMode::box4) {
        out[i] = box4_pixel(g, visibility, x, y);
      } else {
        out[i] = bilateral_pixel(g, visibility, radius, x, y);
      }
    }
  });
  return out;
}

}  // namespace ssao
