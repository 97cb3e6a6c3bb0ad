// SPDX-License-Identifier: MIT
// box4: the seed code's 4x4 box (offsets -1..2), one noise tile, as two 4-tap passes.
// bilateral: a cross-bilateral filter with taps (1/2, 1, 1, 1, 1/2) per axis: on a smooth
// surface every residue of the 4-periodic pattern gets the same total weight, so the pattern
// cancels exactly. Neighbours off the receiver's tangent plane or with a different normal get
// little weight, which keeps contact shadows from bleeding across silhouettes.
#include "denoise.h"

#include <algorithm>
#include <cmath>

#include "simd.h"

namespace ssao {
namespace {

// One row of a GeometryBlock from the frame's planes: a loop without calls or branches, which
// the compiler vectorises.
SSAO_VECTORIZE void fill_geometry_row(const CameraIntrinsics cam, float max_scale, float v,
                                      const float* __restrict depth,
                                      const uint32_t* __restrict normal, int x_begin, int count,
                                      float* __restrict px, float* __restrict py,
                                      float* __restrict pz, float* __restrict nx,
                                      float* __restrict ny, float* __restrict nz,
                                      float* __restrict valid, float* __restrict inv_scale) {
  // Positions scale with depth (perspective) or not (orthographic): as factors, so that the
  // branch on the camera type stays out of the loop.
  const float per_depth = cam.orthographic ? 0.0f : 1.0f, constant = 1.0f - per_depth;
  for (int i = 0; i < count; ++i) {
    const float d = depth[i];
    const bool geometry = d != Frame::kBackground;
    const float dd = geometry ? d : 1.0f;
    const float depth_scale = dd * per_depth + constant;
    px[i] = (float(x_begin + i) + 0.5f - cam.center_u) * cam.scale_u * depth_scale;
    py[i] = (cam.center_v - v) * cam.scale_v * depth_scale;
    pz[i] = -dd;
    const Vec3 n = decode_normal(normal[i]);
    nx[i] = n.x, ny[i] = n.y, nz[i] = n.z;
    valid[i] = geometry ? 1.0f : 0.0f;
    // Plane distance that halves a neighbour's weight: a few pixel footprints, at most 10% of
    // the radius, so a step of a fraction of the radius is an edge.
    const float footprints = 4.0f * cam.scale_u * depth_scale;
    inv_scale[i] = 1.0f / ((footprints < max_scale ? footprints : max_scale) + 1e-30f);
  }
}

// Positions, normals and a geometry flag (1 or 0) of the pixels [x0, x1) x [y0, y1), as planes;
// pixels outside the image are not geometry. Also the bilateral's plane scale per pixel.
struct GeometryBlock {
  int x0, y0, width, height;
  std::vector<float> px, py, pz, nx, ny, nz, valid, inv_scale;

  GeometryBlock(const Frame& f, float radius, int x0_, int y0_, int x1, int y1)
      : x0(x0_), y0(y0_), width(x1 - x0_), height(y1 - y0_) {
    const size_t n = size_t(width) * size_t(height);
    for (auto* plane : {&px, &py, &pz, &nx, &ny, &nz, &valid, &inv_scale}) plane->assign(n, 0.0f);
    const int xa = std::max(x0, 0), xb = std::min(x1, f.width());
    for (int y = std::max(y0, 0); y < std::min(y1, f.height()); ++y) {
      const size_t o = at(xa, y);
      fill_geometry_row(f.camera().intrinsics(), 0.1f * radius, float(y) + 0.5f,
                        f.depth_plane() + f.index(xa, y), f.normal_plane() + f.index(xa, y), xa,
                        xb - xa, &px[o], &py[o], &pz[o], &nx[o], &ny[o], &nz[o], &valid[o],
                        &inv_scale[o]);
    }
  }

  size_t at(int x, int y) const { return size_t(y - y0) * size_t(width) + size_t(x - x0); }
};

constexpr float kBilateralTaps[5] = {0.5f, 1.0f, 1.0f, 1.0f, 0.5f};

// Filters `count` pixels starting at block index `centre`; the taps are `stride` apart in the
// block and in `in` (whose first centre value is in[0]). Loops without calls or branches, which
// the compiler vectorises.
SSAO_VECTORIZE void bilateral_run(const GeometryBlock& g, size_t centre, ptrdiff_t stride,
                                  const float* __restrict in, ptrdiff_t in_stride, int count,
                                  float* __restrict out) {
  const float* __restrict px = g.px.data() + centre;
  const float* __restrict py = g.py.data() + centre;
  const float* __restrict pz = g.pz.data() + centre;
  const float* __restrict nx = g.nx.data() + centre;
  const float* __restrict ny = g.ny.data() + centre;
  const float* __restrict nz = g.nz.data() + centre;
  const float* __restrict valid = g.valid.data() + centre;
  const float* __restrict inv_scale = g.inv_scale.data() + centre;
  for (int i = 0; i < count; ++i) {
    float sum = 0.0f, weight_sum = 0.0f;
#pragma GCC unroll 5
    for (int d = -2; d <= 2; ++d) {
      const ptrdiff_t q = i + d * stride;
      const float plane =
          (px[q] - px[i]) * nx[i] + (py[q] - py[i]) * ny[i] + (pz[q] - pz[i]) * nz[i];
      const float plane_distance = (plane < 0.0f ? -plane : plane) * inv_scale[i];
      const float cosine = nx[q] * nx[i] + ny[q] * ny[i] + nz[q] * nz[i];
      const float agreement = cosine > 0.0f ? cosine : 0.0f;
      const float a2 = agreement * agreement;
      const float w =
          valid[q] * kBilateralTaps[d + 2] * a2 * a2 / (1.0f + plane_distance * plane_distance);
      sum += w * in[i + d * in_stride];
      weight_sum += w;
    }
    // A geometry centre always has weight; background keeps its value.
    out[i] = valid[i] > 0.0f ? sum / weight_sum : in[i];
  }
}

SSAO_VECTORIZE void box4_run(const GeometryBlock& g, size_t centre, ptrdiff_t stride,
                             const float* __restrict in, ptrdiff_t in_stride, int count,
                             float* __restrict out) {
  const float* __restrict valid = g.valid.data() + centre;
  for (int i = 0; i < count; ++i) {
    float sum = 0.0f, weight_sum = 0.0f;
#pragma GCC unroll 4
    for (int d = -1; d <= 2; ++d) {
      sum += valid[i + d * stride] * in[i + d * in_stride];
      weight_sum += valid[i + d * stride];
    }
    out[i] = valid[i] > 0.0f ? sum / weight_sum : in[i];
  }
}

void filter_run(DenoiseMode mode, const GeometryBlock& g, size_t centre, ptrdiff_t stride,
                const float* in, ptrdiff_t in_stride, int count, float* out) {
  if (mode == DenoiseMode::box4) {
    box4_run(g, centre, stride, in, in_stride, count, out);
  } else {
    bilateral_run(g, centre, stride, in, in_stride, count, out);
  }
}

// The taps read 2 pixels either side.
constexpr int kApron = 2;

}  // namespace

void Denoiser::horizontal_pass(float* visibility, TilePool& pool, Progress& progress) const {
  if (mode_ == DenoiseMode::none) return;
  const int width = f_.width();
  pool.for_each_row_band(width, f_.height(), 8, progress, [&](const Tile& t) {
    if (f_.geometry_count(0, t.y0, width, t.y1) == 0) return;  // sky keeps its value
    const GeometryBlock g(f_, radius_, -kApron, t.y0, width + kApron, t.y1);
    // The row with an apron of background on either side, and its filtered copy.
    std::vector<float> row(size_t(width) + 2 * kApron, 1.0f);
    std::vector<float> filtered(static_cast<size_t>(width));
    for (int y = t.y0; y < t.y1; ++y) {
      float* line = visibility + f_.index(0, y);
      std::copy(line, line + width, row.begin() + kApron);
      filter_run(mode_, g, g.at(0, y), 1, row.data() + kApron, 1, width, filtered.data());
      std::copy(filtered.begin(), filtered.end(), line);
    }
  });
}

void Denoiser::vertical_pass(const float* visibility, const Tile& t, float* out) const {
  const int width = t.x1 - t.x0;
  if (mode_ == DenoiseMode::none || f_.geometry_count(t.x0, t.y0, t.x1, t.y1) == 0) {
    for (int y = t.y0; y < t.y1; ++y) {
      std::copy_n(visibility + f_.index(t.x0, y), width, out + size_t(y - t.y0) * width);
    }
    return;
  }
  const GeometryBlock g(f_, radius_, t.x0, t.y0 - kApron, t.x1, t.y1 + kApron);
  // Rows outside the image are read with weight 0: point them at a valid row.
  std::vector<float> column_apron(size_t(width) * (t.y1 - t.y0 + 2 * kApron), 1.0f);
  for (int y = t.y0 - kApron; y < t.y1 + kApron; ++y) {
    if (y < 0 || y >= f_.height()) continue;
    std::copy_n(visibility + f_.index(t.x0, y), width,
                column_apron.data() + size_t(y - t.y0 + kApron) * width);
  }
  for (int y = t.y0; y < t.y1; ++y) {
    filter_run(mode_, g, g.at(t.x0, y), width,
               column_apron.data() + size_t(y - t.y0 + kApron) * width, width, width,
               out + size_t(y - t.y0) * width);
  }
}

}  // namespace ssao
