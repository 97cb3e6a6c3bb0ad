// SPDX-License-Identifier: MIT
#include "pixel_filter.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "scratch.h"
#include "simd.h"
#include "vec3.h"

namespace ssao {

float pixel_filter_weight(double sigma) {
  if (!(sigma > 0.0)) return 0.0f;
  return float(0.5 * std::erfc(0.5 / (sigma * std::sqrt(2.0))));
}

Tile pixel_filter_source(const Frame& frame, const Tile& t) {
  return {std::max(t.x0 - 1, 0), std::max(t.y0 - 1, 0), std::min(t.x1 + 1, frame.width()),
          std::min(t.y1 + 1, frame.height())};
}

namespace {

// Row pieces of the filter, each a plain loop of loads, selects and multiplies that the compiler
// vectorises.

// A row's visibility where it is geometry, 0 elsewhere, and the geometry mask.
SSAO_VECTORIZE void masked_row(const float* __restrict depth, const float* __restrict visibility,
                               int count, float* __restrict value, float* __restrict mask) {
  for (int i = 0; i < count; ++i) {
    const bool geometry = depth[i] != Frame::kBackground;
    mask[i] = geometry ? 1.0f : 0.0f;
    value[i] = geometry ? visibility[i] : 0.0f;
  }
}

// The horizontal pass over a padded row (index -1 and count exist): weighted values and weights.
SSAO_VECTORIZE void horizontal_row(const float* __restrict value, const float* __restrict mask,
                                   int count, float side, float centre, float* __restrict value_out,
                                   float* __restrict mask_out) {
  for (int i = 0; i < count; ++i) {
    value_out[i] = side * (value[i - 1] + value[i + 1]) + centre * value[i];
    mask_out[i] = side * (mask[i - 1] + mask[i + 1]) + centre * mask[i];
  }
}

// The vertical pass over three horizontally filtered rows (above, the row, below; `stride` apart)
// and the normalisation; pixels that are not geometry keep their own value.
SSAO_VECTORIZE void vertical_row(const float* __restrict value, const float* __restrict mask,
                                 size_t stride, const float* __restrict own,
                                 const float* __restrict own_mask, int count, float side,
                                 float centre, float* __restrict out) {
  for (int i = 0; i < count; ++i) {
    const float sum = side * (value[i] + value[i + 2 * stride]) + centre * value[i + stride];
    const float total = side * (mask[i] + mask[i + 2 * stride]) + centre * mask[i + stride];
    // A geometry pixel's own weight is centre^2 > 0.14 (w <= 0.31), so total > 0 there.
    const bool geometry = own_mask[i] > 0.0f;
    out[i] = geometry ? sum / (geometry ? total : 1.0f) : own[i];
  }
}

}  // namespace

void pixel_filter(const Frame& frame, const Tile& around, const float* source, const Tile& t,
                  float weight, float* out) {
  const int width = t.x1 - t.x0, height = t.y1 - t.y0;
  const int source_width = around.x1 - around.x0;
  const float side = weight, centre = 1.0f - 2.0f * weight;
  // Rows t.y0 - 1 .. t.y1 with a column either side: geometry-weighted values and the geometry
  // mask, 0 outside the frame.
  const size_t padded = size_t(width) + 2;
  const int rows = height + 2;
  ScratchVector<float> value(padded * rows, 0.0f), mask(padded * rows, 0.0f);
  for (int y = around.y0; y < around.y1; ++y) {
    const size_t at = size_t(y - (t.y0 - 1)) * padded + size_t(around.x0 - (t.x0 - 1));
    masked_row(frame.depth_plane() + frame.index(around.x0, y),
               source + size_t(y - around.y0) * source_width, source_width, value.data() + at,
               mask.data() + at);
  }
  ScratchVector<float> row_value(size_t(width) * rows), row_mask(size_t(width) * rows);
  for (int r = 0; r < rows; ++r) {
    horizontal_row(value.data() + r * padded + 1, mask.data() + r * padded + 1, width, side, centre,
                   row_value.data() + size_t(r) * width, row_mask.data() + size_t(r) * width);
  }
  for (int y = 0; y < height; ++y) {
    vertical_row(row_value.data() + size_t(y) * width, row_mask.data() + size_t(y) * width,
                 size_t(width),
                 source + size_t(y + t.y0 - around.y0) * source_width + (t.x0 - around.x0),
                 mask.data() + (y + 1) * padded + 1, width, side, centre, out + size_t(y) * width);
  }
}

namespace {

// Two depths of different surfaces: a jump of more than kEdgeDepthJump of the nearer.
inline bool depth_jump(float a, float b) {
  return std::fabs(a - b) > kEdgeDepthJump * std::min(a, b);
}

// The beauty's colour of pixel (x, y) of the beauty, if it is inside it and finite.
bool beauty_colour(const ImageView& beauty, int x, int y, Vec3& rgb) {
  if (x < 0 || y < 0 || x >= beauty.width || y >= beauty.height) return false;
  const float* p = beauty.pixel(x, y);
  const bool grey = beauty.channels < 3;
  rgb = {p[0], p[grey ? 0 : 1], p[grey ? 0 : 2]};
  return std::isfinite(rgb.x) && std::isfinite(rgb.y) && std::isfinite(rgb.z);
}

// 1 where pixel i of a row has a depth jump to its right neighbour or to the pixel below it
// (`below`: the next row, or the row itself on the last), else 0; background pixels read
// Frame::kBackground, so a jump to or from the sky is flagged too (the caller tells them
// apart). `depth` has count + 1 readable values. A plain loop the compiler vectorises: most
// pixels are on no edge, and this is what finds the few that are.
SSAO_VECTORIZE void jump_row(const float* __restrict depth, const float* __restrict below,
                             int count, unsigned char* __restrict flags) {
  for (int i = 0; i < count; ++i) {
    // | on ints rather than ||: both tests always run, so the loop has no branch to keep it
    // scalar (the SSE build vectorises it).
    flags[i] = static_cast<unsigned char>(int(depth_jump(depth[i], depth[i + 1])) |
                                          int(depth_jump(depth[i], below[i])));
  }
}

// The pixels of a row that may lie on an edge: 1 where the pixel's own flag (own[i], jump_row's),
// its left neighbour's (own[i - 1], for i >= 1) or its upper neighbour's (above[i]) is set. A
// plain loop the compiler vectorises, so that the caller skips the rest a word at a time.
SSAO_VECTORIZE void edge_candidate_row(const unsigned char* __restrict own,
                                       const unsigned char* __restrict above, int count,
                                       unsigned char* __restrict candidates) {
  for (int i = 0; i < count; ++i) candidates[i] = static_cast<unsigned char>(own[i] | above[i]);
  for (int i = 1; i < count; ++i) candidates[i] |= own[i - 1];
}

// The first index from i on (below count) whose byte is set, else count: eight at a time over
// the zeros.
int next_set(const unsigned char* bytes, int i, int count) {
  for (; i + 8 <= count; i += 8) {
    uint64_t word;
    std::memcpy(&word, bytes + i, sizeof word);
    if (word != 0) break;
  }
  while (i < count && bytes[i] == 0) ++i;
  return i;
}

// Where point m lies along the line from b to a: `share` such that b + share (a - b) is its
// nearest point. True if m lies within tolerance x |a - b| of that line (false for a == b, NaN).
bool share_on_line(const Vec3& m, const Vec3& a, const Vec3& b, float tolerance, float& share) {
  const Vec3 ab = a - b;
  const float length_squared = dot(ab, ab);
  if (!(length_squared > 0.0f)) return false;
  share = dot(m - b, ab) / length_squared;
  const Vec3 off = m - b - ab * share;
  return dot(off, off) <= tolerance * tolerance * length_squared;
}

// Pixel p's share of its own surface read from the beauty's colours (see mix_edges_by_beauty):
// own, other: the colours beyond p and beyond n; mixed, neighbour: p's and n's.
bool own_share_from_colours(const Vec3& own, const Vec3& other, const Vec3& mixed,
                            const Vec3& neighbour, float& share) {
  const Vec3 difference = own - other;
  const float contrast = dot(difference, difference);
  const float larger = std::max(dot(own, own), dot(other, other));
  if (!(contrast > 0.0f) || contrast < kEdgeColourContrast * kEdgeColourContrast * larger) {
    return false;
  }
  // p and n are mixes of the two surfaces (n mostly B's), so their colours lie on the line
  // from B to A, and n's between them. Where one lies well off (a highlight on a board's
  // front edge, another face of the same object beyond n), A and B are not the colours of
  // p's and n's surfaces: no mix.
  float neighbour_share = 0.0f;
  return share_on_line(neighbour, own, other, kEdgeColourTolerance, neighbour_share) &&
         share_on_line(mixed, own, other, kEdgeColourTolerance, share) &&
         neighbour_share >= -kEdgeColourTolerance && neighbour_share <= 1.0f + kEdgeColourTolerance;
}

// The same from the Normal pass, filtered over the pixel like the beauty: own and other are the
// normals beyond p and beyond n, own_next and other_next those one pixel further out, mixed and
// neighbour p's and n's. The two surfaces' normals must differ by kEdgeNormalContrast or more
// and each be steady (its next pixel out within kEdgeNormalSteady of it: a face, not a crease or
// a curve that p's own normal would not follow), and p's and n's normals lie on the line
// between them as the colours must. A pass filtered over the pixel shows a mix in p or in n
// (the filter straddles the edge); one that holds each pixel centre's normal (POV-Ray's, without
// anti-aliasing) shows none, and says nothing of coverage.
bool own_share_from_normals(const Vec3& own, const Vec3& own_next, const Vec3& other,
                            const Vec3& other_next, const Vec3& mixed, const Vec3& neighbour,
                            float& share) {
  const Vec3 difference = own - other, own_step = own_next - own, other_step = other_next - other;
  if (!(dot(difference, difference) >= kEdgeNormalContrast * kEdgeNormalContrast) ||
      !(dot(own_step, own_step) <= kEdgeNormalSteady * kEdgeNormalSteady) ||
      !(dot(other_step, other_step) <= kEdgeNormalSteady * kEdgeNormalSteady)) {
    return false;
  }
  float neighbour_share = 0.0f;
  return share_on_line(neighbour, own, other, kEdgeColourTolerance, neighbour_share) &&
         share_on_line(mixed, own, other, kEdgeColourTolerance, share) &&
         neighbour_share >= -kEdgeColourTolerance &&
         neighbour_share <= 1.0f + kEdgeColourTolerance && share >= -kEdgeColourTolerance &&
         share <= 1.0f + kEdgeColourTolerance &&
         (share < 1.0f - kEdgeNormalMixShown || neighbour_share > kEdgeNormalMixShown);
}

// Whether normal m (of a pixel of the Normal pass, filtered over it like the beauty) is a mix of
// normals a and b: within kEdgeNormalTolerance of the segment between them. NaN: no.
bool normal_is_mix(const Vec3& m, const Vec3& a, const Vec3& b) {
  const Vec3 ab = a - b;
  const float length_squared = dot(ab, ab);
  const float share = length_squared > 1e-12f ? dot(m - b, ab) / length_squared : 0.0f;
  const Vec3 off = m - b - ab * std::min(1.0f, std::max(0.0f, share));
  return dot(off, off) <= kEdgeNormalTolerance * kEdgeNormalTolerance;
}

// Whether pixel (x, y) lies in the frame and shows geometry.
bool geometry_at(const Frame& frame, int x, int y) {
  return x >= 0 && y >= 0 && x < frame.width() && y < frame.height() && frame.is_geometry(x, y);
}

// Whether pixel a and its neighbour a + s straddle the edge followed so far: both geometry, a on
// the surface whose depth next to it is `own`, a + s on the one at `other`, a jump between them
// and a the nearer exactly when the edge's first pixel was. Moves own and other on to theirs.
bool continues_edge(const Frame& frame, int ax, int ay, int sx, int sy, bool own_nearer, float& own,
                    float& other) {
  const int bx = ax + sx, by = ay + sy;
  if (!geometry_at(frame, ax, ay) || !geometry_at(frame, bx, by)) return false;
  const float a = frame.depth(ax, ay), b = frame.depth(bx, by);
  if (depth_jump(a, own) || depth_jump(b, other) || !depth_jump(a, b) || (a < b) != own_nearer) {
    return false;
  }
  own = a, other = b;
  return true;
}

// Pixel p's share of its own surface read from the staircase the edge between p = (x, y) and its
// neighbour n = p + (sx, sy) draws in the depth image (morphological anti-aliasing, Reshetov
// 2009). The Depth pass holds the surface at each pixel's centre, so a straight silhouette at a
// slant draws runs of pixels along the edge, each one pixel over from the last; the line crosses
// the row of centres where a run steps. Only a run whose two ends step opposite ways (a Z: the
// edge goes on one pixel toward n at one end and toward p at the other) is read: the line then
// goes from half a pixel on p's side at one end to half a pixel on n's at the other, and its
// place at p gives p's share through the pixel filter (Gaussian of standard deviation sigma;
// without one, p's square). A run that steps the same way at both ends (the top of a curve)
// or at one end only (an edge that ends at a corner) does not say where the line lies: false,
// as for a run longer than kStaircaseReach each way.
bool own_share_from_staircase(const Frame& frame, int x, int y, int sx, int sy, float sigma,
                              float& share) {
  const int tx = sy != 0 ? 1 : 0, ty = sx != 0 ? 1 : 0;  // along the edge
  const bool own_nearer = frame.depth(x, y) < frame.depth(x + sx, y + sy);
  int steps[2] = {0, 0}, reach[2] = {0, 0};  // before p (k < 0) and after it (k > 0)
  for (int side = 0; side < 2; ++side) {
    const int dir = side == 0 ? -1 : 1;
    float own = frame.depth(x, y), other = frame.depth(x + sx, y + sy);
    int k = 1;
    while (k <= kStaircaseReach && continues_edge(frame, x + dir * k * tx, y + dir * k * ty, sx, sy,
                                                  own_nearer, own, other)) {
      ++k;
    }
    if (k > kStaircaseReach) return false;
    reach[side] = k - 1;
    // The first pixel e past the run, on p's side of the edge.
    const int ex = x + dir * k * tx, ey = y + dir * k * ty;
    if (!geometry_at(frame, ex, ey)) return false;
    const float e = frame.depth(ex, ey);
    float step_own = e, step_other = other;
    if (!depth_jump(e, own) &&
        continues_edge(frame, ex + sx, ey + sy, sx, sy, own_nearer, step_own, step_other)) {
      steps[side] = 1;  // p's surface covers e and the pixel beyond it toward n
    }
    step_own = own, step_other = other;
    if (continues_edge(frame, ex - sx, ey - sy, sx, sy, own_nearer, step_own, step_other)) {
      steps[side] = -1;  // n's surface covers e: the edge steps toward p
    }
  }
  if (steps[0] == 0 || steps[0] != -steps[1]) return false;
  // The line's offset from the p/n boundary toward n at p's place along the run, from half a
  // pixel either way at the run's ends (k = -reach[0] - 0.5 and k = reach[1] + 0.5).
  const float from = -float(reach[0]) - 0.5f, to = float(reach[1]) + 0.5f;
  const float at_start = 0.5f * float(steps[0]), at_end = 0.5f * float(steps[1]);
  const float offset = at_start + (at_end - at_start) * (0.0f - from) / (to - from);
  // p's centre lies half a pixel from the boundary, on its own side; the Gaussian's share
  // across the slanted line goes by the distance square to it.
  const float distance = offset + 0.5f;
  const float slope = (at_end - at_start) / (to - from);
  share = sigma > 0.0f
              ? 0.5f * std::erfc(-distance / (sigma * std::sqrt(2.0f * (1.0f + slope * slope))))
              : std::min(1.0f, std::max(0.0f, distance + 0.5f));
  return true;
}

}  // namespace

void mix_edges_by_beauty(const Frame& frame, const ImageView& beauty, const ImageView& normal,
                         int dx, int dy, const Tile& around, const float* source, const Tile& t,
                         float weight, float sigma, float* out) {
  const auto normal_at = [&](int x, int y) {
    const float* n = normal.pixel(x, y);
    return Vec3{n[0], n[1], n[2]};
  };
  const int width = t.x1 - t.x0;
  const auto source_at = [&](int x, int y) {
    return source[size_t(y - around.y0) * size_t(around.x1 - around.x0) + size_t(x - around.x0)];
  };
  // Jumps to the right and below of the pixels in rows t.y0 - 1 .. t.y1 - 1 and columns
  // t.x0 - 1 .. t.x1 - 1 (clipped to the frame): a pixel is a candidate when it, its left or its
  // upper neighbour has a flag.
  const int x_first = std::max(t.x0 - 1, 0), y_first = std::max(t.y0 - 1, 0);
  const int columns = t.x1 - x_first, rows = t.y1 - y_first;
  // The frame's last column has no right neighbour: its flag is for the pixel below alone.
  const bool last_column = t.x1 == frame.width();
  ScratchVector<unsigned char> flags(size_t(columns) * size_t(rows), 0);
  for (int r = 0; r < rows; ++r) {
    const int y = y_first + r;
    const float* row = frame.depth_plane() + frame.index(x_first, y);
    const float* below =
        frame.depth_plane() + frame.index(x_first, std::min(y + 1, frame.height() - 1));
    unsigned char* out_flags = flags.data() + size_t(r) * size_t(columns);
    jump_row(row, below, columns - (last_column ? 1 : 0), out_flags);
    if (last_column) {
      out_flags[columns - 1] = depth_jump(row[columns - 1], below[columns - 1]) ? 1 : 0;
    }
  }
  // The candidates, a row at a time (none outside the flags' rows and columns).
  ScratchVector<unsigned char> candidates(static_cast<size_t>(width));
  const int left_column = t.x0 - x_first;  // 1 where column t.x0 - 1 has flags, else 0
  for (int y = t.y0; y < t.y1; ++y) {
    const unsigned char* row_flags =
        flags.data() + size_t(y - y_first) * size_t(columns) + left_column;
    const unsigned char* above_flags = y > y_first ? row_flags - columns : row_flags;
    edge_candidate_row(row_flags, above_flags, width, candidates.data());
    if (left_column == 1) candidates[0] |= row_flags[-1];
    for (int i = next_set(candidates.data(), 0, width); i < width;
         i = next_set(candidates.data(), i + 1, width)) {
      const int x = t.x0 + i;
      if (!frame.is_geometry(x, y)) continue;
      const float depth = frame.depth(x, y);
      // The neighbour across the largest jump.
      int sx = 0, sy = 0;
      float largest = 0.0f;
      for (const auto& s : kFourNeighbours) {
        if (!geometry_at(frame, x + s[0], y + s[1])) continue;
        const float other = frame.depth(x + s[0], y + s[1]);
        const float jump = std::fabs(depth - other) / std::min(depth, other);
        if (depth_jump(depth, other) && jump > largest) largest = jump, sx = s[0], sy = s[1];
      }
      if (largest == 0.0f) continue;
      const int nx = x + sx, ny = y + sy;
      // The pixels beyond either side must lie on the same surfaces as p and n.
      if (!geometry_at(frame, x - sx, y - sy) || !geometry_at(frame, nx + sx, ny + sy) ||
          depth_jump(depth, frame.depth(x - sx, y - sy)) ||
          depth_jump(frame.depth(nx, ny), frame.depth(nx + sx, ny + sy))) {
        continue;
      }
      Vec3 own, other, mixed, neighbour;
      float colour_share = 0.0f, normal_share = 0.0f;
      const bool by_colours = beauty_colour(beauty, x - sx - dx, y - sy - dy, own) &&
                              beauty_colour(beauty, nx + sx - dx, ny + sy - dy, other) &&
                              beauty_colour(beauty, x - dx, y - dy, mixed) &&
                              beauty_colour(beauty, nx - dx, ny - dy, neighbour) &&
                              own_share_from_colours(own, other, mixed, neighbour, colour_share);
      // The normals are read only along with colours: alone (no beauty) they made the layered
      // AO on camera moves worse (docs/variants.md, "Coverage from the depth's staircase").
      bool by_normals = false;
      if (normal.attached() && beauty.attached()) {
        const Vec3 own_normal = normal_at(x - sx, y - sy),
                   other_normal = normal_at(nx + sx, ny + sy);
        const Vec3 mixed_normal = normal_at(x, y);
        if (!normal_is_mix(mixed_normal, own_normal, other_normal)) continue;
        const int ox = x - 2 * sx, oy = y - 2 * sy, fx = nx + 2 * sx, fy = ny + 2 * sy;
        by_normals =
            ox >= 0 && oy >= 0 && ox < frame.width() && oy < frame.height() && fx >= 0 && fy >= 0 &&
            fx < frame.width() && fy < frame.height() &&
            own_share_from_normals(own_normal, normal_at(ox, oy), other_normal, normal_at(fx, fy),
                                   mixed_normal, normal_at(nx, ny), normal_share);
      }
      float staircase_share = 0.0f;
      const bool by_staircase =
          !by_colours && !by_normals &&
          own_share_from_staircase(frame, x, y, sx, sy, sigma, staircase_share);
      if (!by_colours && !by_normals && !by_staircase) continue;
      // Where both read a mix, as little of one as either reads (a shadow's gradient makes the
      // colours read more of the other surface, a crease in it the normals). The Depth pass's
      // sample at p's centre is on p's surface: for a straight edge through a symmetric pixel
      // filter that side holds at least half of the pixel.
      float beta = by_colours && by_normals ? std::max(colour_share, normal_share)
                   : by_colours             ? colour_share
                   : by_normals             ? normal_share
                                            : staircase_share;
      beta = std::min(1.0f, std::max(kEdgeMinOwnShare, beta));
      // Each surface's AO through the pixel filter, over the pixels around p on that surface
      // (without the filter, p's and n's own).
      const float side = weight, centre = 1.0f - 2.0f * weight;
      if (!(weight > 0.0f)) {
        out[size_t(y - t.y0) * width + (x - t.x0)] =
            beta * source_at(x, y) + (1.0f - beta) * source_at(nx, ny);
        continue;
      }
      float own_sum = 0.0f, own_weight = 0.0f, other_sum = 0.0f, other_weight = 0.0f;
      const float other_depth = frame.depth(nx, ny);
      for (int qy = std::max(y - 1, around.y0); qy < std::min(y + 2, around.y1); ++qy) {
        for (int qx = std::max(x - 1, around.x0); qx < std::min(x + 2, around.x1); ++qx) {
          if (!frame.is_geometry(qx, qy)) continue;
          const float w = (qx == x ? centre : side) * (qy == y ? centre : side);
          const float ao = source_at(qx, qy);
          const float d = frame.depth(qx, qy);
          if (!depth_jump(d, depth)) {
            own_sum += w * ao, own_weight += w;
          } else if (!depth_jump(d, other_depth)) {
            other_sum += w * ao, other_weight += w;
          }
        }
      }
      if (!(own_weight > 0.0f) || !(other_weight > 0.0f)) continue;
      out[size_t(y - t.y0) * width + (x - t.x0)] =
          beta * (own_sum / own_weight) + (1.0f - beta) * (other_sum / other_weight);
    }
  }
}

}  // namespace ssao
