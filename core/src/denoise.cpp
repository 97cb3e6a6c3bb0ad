// SPDX-License-Identifier: MIT
#include "denoise.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ssao {

// box4: the seed code's 4x4 box (offsets -1..2), one noise tile, as two 4-tap passes.
// bilateral: a cross-bilateral filter with taps (1/2, 1, 1, 1, 1/2) per axis: on a smooth
// surface every residue of the 4-periodic pattern gets the same total weight, so the pattern
// cancels exactly. Neighbours off the receiver's tangent plane or with a different normal get
// little weight, which keeps contact shadows from bleeding across silhouettes.
template <bool Horizontal>
float Denoiser::filter(const float* visibility, int x, int y) const {
  const int size = Horizontal ? f_.width() : f_.height();
  const int centre = Horizontal ? x : y;
  auto at = [&](int offset) {
    return Horizontal ? f_.index(x + offset, y) : f_.index(x, y + offset);
  };
  if (mode_ == DenoiseMode::box4) {
    float sum = 0.0f;
    int count = 0;
    for (int d = -1; d <= 2; ++d) {
      const int c = centre + d;
      if (c < 0 || c >= size || f_.depth_plane()[at(d)] == Frame::kBackground) continue;
      sum += visibility[at(d)];
      ++count;
    }
    return sum / float(count);  // count >= 1: the centre is geometry
  }
  static constexpr float kTap[5] = {0.5f, 1.0f, 1.0f, 1.0f, 0.5f};
  const Vec3 p = f_.position(x, y);
  const Vec3 n = f_.normal(x, y);
  // Plane distance that halves a neighbour's weight: a few pixel footprints, at most 10% of the
  // radius, so a step of a fraction of the radius is an edge.
  const float plane_scale =
      std::min(0.1f * radius_, 4.0f * f_.camera().pixel_footprint(-p.z)) + 1e-30f;
  const float inv_scale = 1.0f / plane_scale;
  float sum = 0.0f, weight_sum = 0.0f;
  for (int d = -2; d <= 2; ++d) {
    const int c = centre + d;
    if (c < 0 || c >= size) continue;
    const int sx = Horizontal ? c : x, sy = Horizontal ? y : c;
    if (!f_.is_geometry(sx, sy)) continue;
    const float plane_distance = std::fabs(dot(f_.position(sx, sy) - p, n)) * inv_scale;
    const float agreement = std::max(0.0f, dot(f_.normal(sx, sy), n));
    const float a2 = agreement * agreement;
    const float w = kTap[d + 2] * a2 * a2 / (1.0f + plane_distance * plane_distance);
    sum += w * visibility[at(d)];
    weight_sum += w;
  }
  return weight_sum > 0.0f ? sum / weight_sum : visibility[at(0)];
}

void Denoiser::horizontal_pass(float* visibility, TilePool& pool, Progress& progress) const {
  if (mode_ == DenoiseMode::none) return;
  pool.for_each_row_band(f_.width(), f_.height(), 8, progress, [&](const Tile& t) {
    std::vector<float> row(size_t(f_.width()));
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = 0; x < f_.width(); ++x) {
        row[x] = f_.is_geometry(x, y) ? filter<true>(visibility, x, y) : visibility[f_.index(x, y)];
      }
      std::copy(row.begin(), row.end(), visibility + f_.index(0, y));
    }
  });
}

float Denoiser::vertical(const float* visibility, int x, int y) const {
  if (mode_ == DenoiseMode::none) return visibility[f_.index(x, y)];
  return filter<false>(visibility, x, y);
}

}  // namespace ssao
