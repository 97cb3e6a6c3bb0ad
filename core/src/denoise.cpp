// SPDX-License-Identifier: MIT
// box4: the seed code's 4x4 box (offsets -1..2), one noise tile, as two 4-tap passes.
// bilateral: a cross-bilateral filter with taps (1/2, 1, 1, 1, 1/2) per axis: on a smooth
// surface every residue of the 4-periodic pattern gets the same total weight, so the pattern
// cancels exactly. Neighbours off the receiver's tangent plane or with a different normal get
// little weight, which keeps contact shadows from bleeding across silhouettes.
#include "denoise.h"

#include <algorithm>
#include <cmath>

#include "scratch.h"
#include "simd.h"

namespace ssao {
namespace {

// Where pixel centre (u, v) at planar depth d lies in view space, and the inverse of the plane
// distance that halves a neighbour's weight there: a few pixel footprints, at most 10% of the
// radius (max_scale), so a step of a fraction of the radius is an edge. Positions scale with
// depth (per_depth = 1, perspective) or not (0, orthographic): as factors, so that the branch on
// the camera type stays out of the callers' loops, which vectorise.
struct PixelGeometry {
  float x, y, z, inv_scale;
};
inline PixelGeometry pixel_geometry(const CameraIntrinsics& cam, float per_depth, float max_scale,
                                    float u, float v, float d) {
  const float depth_scale = d * per_depth + (1.0f - per_depth);
  const float footprints = 4.0f * cam.scale_u * depth_scale;
  return {(u - cam.center_u) * cam.scale_u * depth_scale,
          (cam.center_v - v) * cam.scale_v * depth_scale, -d,
          1.0f / ((footprints < max_scale ? footprints : max_scale) + 1e-30f)};
}

// One row of a GeometryBlock from the frame's planes: a loop without calls or branches, which
// the compiler vectorises.
SSAO_VECTORIZE void fill_geometry_row(const CameraIntrinsics cam, float max_scale, float v,
                                      const float* __restrict depth,
                                      const uint32_t* __restrict normal, int x_begin, int count,
                                      float* __restrict px, float* __restrict py,
                                      float* __restrict pz, float* __restrict nx,
                                      float* __restrict ny, float* __restrict nz,
                                      float* __restrict valid, float* __restrict inv_scale) {
  const float per_depth = cam.orthographic ? 0.0f : 1.0f;
  for (int i = 0; i < count; ++i) {
    const float d = depth[i];
    const bool geometry = d != Frame::kBackground;
    const PixelGeometry p = pixel_geometry(cam, per_depth, max_scale, float(x_begin + i) + 0.5f, v,
                                           geometry ? d : 1.0f);
    px[i] = p.x, py[i] = p.y, pz[i] = p.z, inv_scale[i] = p.inv_scale;
    const Vec3 n = decode_normal(normal[i]);
    nx[i] = n.x, ny[i] = n.y, nz[i] = n.z;
    valid[i] = geometry ? 1.0f : 0.0f;
  }
}

// Positions, normals and a geometry flag (1 or 0) of the pixels [x0, x1) x [y0, y1), as planes;
// pixels outside the image are not geometry. Also the bilateral's plane scale per pixel.
struct GeometryBlock {
  int x0, y0, width, height;
  ScratchVector<float> px, py, pz, nx, ny, nz, valid, inv_scale;

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

// How near point q lies to the plane through p with normal n: 1 on it, 1/2 at one plane scale
// (1 / inv_scale) off it. Inline and branch-free, so the callers' loops vectorise.
inline float plane_weight(float px, float py, float pz, float nx, float ny, float nz,
                          float inv_scale, float qx, float qy, float qz) {
  const float plane = ((qx - px) * nx + (qy - py) * ny + (qz - pz) * nz) * inv_scale;
  return 1.0f / (1.0f + plane * plane);
}

// How much neighbour q may speak for centre p (the bilateral's weight): low when q lies off
// p's tangent plane (in units of p's plane scale) or when their normals disagree; 0 when q is
// not geometry.
inline float surface_weight(float px, float py, float pz, float nx, float ny, float nz,
                            float inv_scale, float qx, float qy, float qz, float qnx, float qny,
                            float qnz, float q_valid) {
  const float cosine = qnx * nx + qny * ny + qnz * nz;
  const float agreement = cosine > 0.0f ? cosine : 0.0f;
  const float a2 = agreement * agreement;
  return q_valid * a2 * a2 * plane_weight(px, py, pz, nx, ny, nz, inv_scale, qx, qy, qz);
}

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
      const float w = kBilateralTaps[d + 2] * surface_weight(px[i], py[i], pz[i], nx[i], ny[i],
                                                             nz[i], inv_scale[i], px[q], py[q],
                                                             pz[q], nx[q], ny[q], nz[q], valid[q]);
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

// Pointers into the planes of one row of a GeometryBlock, plus the visibility of that row.
struct RowPlanes {
  const float *px, *py, *pz, *nx, *ny, *nz, *valid, *value;
};

RowPlanes row_planes(const GeometryBlock& g, int x, int y, const float* values) {
  const size_t i = g.at(x, y);
  return {&g.px[i], &g.py[i], &g.pz[i], &g.nx[i], &g.ny[i], &g.nz[i], &g.valid[i], values};
}

// The full-resolution pixels x = 2 k + parity (k = 0 .. count - 1) of one row (depths
// depth[k], pixel centres u_first + 2 k, v), from the two half-resolution rows around it.
// Half-resolution column c has its centre at full-resolution 2 c + 1, so pixel 2 k + parity
// lies between half columns k - 1 + parity and k + parity, weighted 3/4 : 1/4 toward the nearer;
// `low` and `high` are indexed so that [k] is column k (and [-1] exists). A neighbour's weight
// also falls with the pixel's distance from the neighbour's tangent plane: the neighbour's
// plane, so the pixel needs only its depth (a full frame estimated at half resolution keeps no
// normals). Contiguous loads only (a stride-2 load would leave the last vector to a scalar
// epilogue): the loop vectorises.
SSAO_VECTORIZE void upsample_run(const CameraIntrinsics cam, float max_scale,
                                 const float* __restrict depth, float u_first, float v,
                                 const RowPlanes low, const RowPlanes high, float high_weight,
                                 int parity, int count, float* __restrict out) {
  const float per_depth = cam.orthographic ? 0.0f : 1.0f;
  const float low_weight = 1.0f - high_weight;
  const float right_weight = parity ? 0.25f : 0.75f;
  const RowPlanes rows[2] = {low, high};
  const float row_weights[2] = {low_weight, high_weight};
  // No neighbour on this surface (a one-pixel feature): the pixel's own block, k.
  const float* __restrict own = high_weight > 0.5f ? high.value : low.value;
  for (int k = 0; k < count; ++k) {
    const float d = depth[k];
    const bool geometry = d != Frame::kBackground;
    const PixelGeometry p = pixel_geometry(cam, per_depth, max_scale, u_first + 2.0f * float(k), v,
                                           geometry ? d : 1.0f);
    const int left = k - 1 + parity, right = k + parity;
    float sum = 0.0f, weight_sum = 0.0f;
    // Local restrict pointers: without them the compiler must assume `out` aliases the planes
    // read, and leaves the loop scalar.
#pragma GCC unroll 2
    for (int r = 0; r < 2; ++r) {
      const float* __restrict qx = rows[r].px;
      const float* __restrict qy = rows[r].py;
      const float* __restrict qz = rows[r].pz;
      const float* __restrict qnx = rows[r].nx;
      const float* __restrict qny = rows[r].ny;
      const float* __restrict qnz = rows[r].nz;
      const float* __restrict qvalid = rows[r].valid;
      const float* __restrict qvalue = rows[r].value;
#pragma GCC unroll 2
      for (int side = 0; side < 2; ++side) {
        const int c = side ? right : left;
        const float bilinear = row_weights[r] * (side ? right_weight : 1.0f - right_weight);
        const float w =
            (bilinear + 1e-3f) * qvalid[c] *
            plane_weight(qx[c], qy[c], qz[c], qnx[c], qny[c], qnz[c], p.inv_scale, p.x, p.y, p.z);
        sum += w * qvalue[c];
        weight_sum += w;
      }
    }
    const float upsampled = weight_sum > 1e-6f ? sum / weight_sum : own[k];
    out[k] = geometry ? upsampled : 1.0f;
  }
}

void Denoiser::horizontal_pass(float* visibility, TilePool& pool, Progress& progress) const {
  if (mode_ == DenoiseMode::none) return;
  const int width = f_.width();
  pool.for_each_row_band(width, f_.height(), 8, progress, [&](const Tile& t) {
    if (!f_.has_geometry(0, t.y0, width, t.y1)) return;  // sky keeps its value
    const GeometryBlock g(f_, radius_, -kApron, t.y0, width + kApron, t.y1);
    // The row with an apron of background on either side, and its filtered copy.
    ScratchVector<float> row(size_t(width) + 2 * kApron, 1.0f);
    ScratchVector<float> filtered(static_cast<size_t>(width));
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
  if (mode_ == DenoiseMode::none || !f_.has_geometry(t.x0, t.y0, t.x1, t.y1)) {
    for (int y = t.y0; y < t.y1; ++y) {
      std::copy_n(visibility + f_.index(t.x0, y), width, out + size_t(y - t.y0) * width);
    }
    return;
  }
  const GeometryBlock g(f_, radius_, t.x0, t.y0 - kApron, t.x1, t.y1 + kApron);
  // Rows outside the image are not geometry (weight 0); their values are a placeholder 1.
  ScratchVector<float> column_apron(size_t(width) * (t.y1 - t.y0 + 2 * kApron), 1.0f);
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

// in[0], in[2], ... in[2 (count - 1)] into out[0 .. count): a loop the compiler vectorises.
SSAO_VECTORIZE void every_other(const float* __restrict in, int count, float* __restrict out) {
  for (int k = 0; k < count; ++k) out[k] = in[2 * k];
}

// out[2 k] = first[k], out[2 k + 1] = second[k], for the `count` values of out.
SSAO_VECTORIZE void interleave(const float* __restrict first, const float* __restrict second,
                               int count, float* __restrict out) {
  for (int k = 0; k < count / 2; ++k) out[2 * k] = first[k], out[2 * k + 1] = second[k];
  if (count % 2 != 0) out[count - 1] = first[count / 2];
}

void upsample(const Frame& full, const Frame& half, const float* half_visibility,
              const Denoiser& vertical, float radius, const Tile& t, float* out) {
  const int width = t.x1 - t.x0;
  // Half-resolution planes of the columns around the tile with one column of apron either side
  // (outside the image: not geometry, weight 0).
  const int half_x0 = (t.x0 >> 1) - 1, half_x1 = ((t.x1 - 1) >> 1) + 2;
  const int low_row0 = std::max(0, (t.y0 - 1) >> 1);
  const int high_row1 = std::min(half.height(), ((t.y1 - 1) >> 1) + 2);
  const GeometryBlock around(half, radius, half_x0, low_row0, half_x1, high_row1);
  // The vertical pass of the half-resolution visibility, over what this tile reads: one pass
  // over the image less, for the few rows two tiles both read.
  const Tile read{std::max(half_x0, 0), low_row0, std::min(half_x1, half.width()), high_row1};
  const int read_width = read.x1 - read.x0;
  ScratchVector<float> filtered(size_t(read_width) * size_t(read.y1 - read.y0));
  vertical.vertical_pass(half_visibility, read, filtered.data());
  ScratchVector<float> values(size_t(half_x1 - half_x0) * size_t(high_row1 - low_row0), 1.0f);
  for (int y = read.y0; y < read.y1; ++y) {
    std::copy_n(filtered.data() + size_t(y - read.y0) * read_width, read_width,
                values.data() + around.at(read.x0, y));
  }
  const size_t per_parity = size_t(width) / 2 + 1;
  ScratchVector<float> by_parity[2] = {ScratchVector<float>(per_parity),
                                       ScratchVector<float>(per_parity)};
  ScratchVector<float> depth_of_parity(per_parity);
  for (int y = t.y0; y < t.y1; ++y) {
    const int low_raw = (y - 1) >> 1;
    const int low = std::max(low_raw, 0), high = std::min(low_raw + 1, half.height() - 1);
    for (int parity = 0; parity < 2; ++parity) {
      // The first pixel of this parity, and its k = 0 half column.
      const int x_first = t.x0 + ((t.x0 & 1) != parity ? 1 : 0);
      const int count = x_first < t.x1 ? (t.x1 - x_first + 1) / 2 : 0;
      if (count == 0) continue;
      const int k0 = x_first >> 1;
      every_other(full.depth_plane() + full.index(x_first, y), count, depth_of_parity.data());
      upsample_run(full.camera().intrinsics(), 0.1f * radius, depth_of_parity.data(),
                   float(x_first) + 0.5f, float(y) + 0.5f,
                   row_planes(around, k0, low, &values[around.at(k0, low)]),
                   row_planes(around, k0, high, &values[around.at(k0, high)]),
                   (y & 1) ? 0.25f : 0.75f, parity, count, by_parity[parity].data());
    }
    interleave(by_parity[(t.x0 & 1) != 0].data(), by_parity[(t.x0 & 1) == 0].data(), width,
               out + size_t(y - t.y0) * width);
  }
}

}  // namespace ssao
