// SPDX-License-Identifier: MIT
// The temporal filter (temporal.h). The row kernel that carries an earlier frame's values to
// this frame's pixels gathers from them: Google Highway, compiled once per SIMD target
// (foreach_target, as variants/hemisphere.cpp); the rest is inside HWY_ONCE.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "temporal.cpp"
#include <hwy/foreach_target.h>  // re-includes this file once per target
#include <hwy/highway.h>

#include "variants/frame_simd-inl.h"

#ifndef SSAO_TEMPORAL_CARRY_ARGS
#define SSAO_TEMPORAL_CARRY_ARGS
#include <algorithm>
#include <limits>

#include "camera.h"

namespace ssao {
// What the kernel reads of an earlier frame.
struct CarryArgs {
  CameraIntrinsics here, there;  // this frame's window camera, the earlier frame's
  float to_entry[12];            // this view -> the earlier frame's view (affine, 3 rows)
  const float* depth;            // the earlier frame's planar depths and values
  const float* value;
  int width, height;
  float u0, v;  // the row's first pixel centre and the row's centre, in this window's pixels
};
// A frame carries to another where its depth agrees within this fraction and its value
// differs by at most this much (TemporalHistory's constants).
constexpr float kCarryDepthAgreement = 0.005f, kCarryRejection = 0.3f;
// How far a carried value may lie outside the range of the frame's own values around it.
// Both wide: moving objects are the motion test's; tighter (0.1, 0.01) they dropped the frames
// that average out the pattern where it swings most, beside thin posts (`thin`'s occluded
// flicker 0.0357 against 0.0251).
constexpr float kCarryMargin = 0.1f;

// What the motion test reads (TemporalHistory::find_motion): this frame and an earlier one,
// both of the window's size.
struct MotionArgs {
  CameraIntrinsics here, there;
  float to_entry[12], from_entry[12];  // this view -> the earlier frame's view, and back
  const float* there_depth;            // the earlier frame's planar depths
  const float* there_nearest;          // its nearest depth around each 2 x 2 block (Entry)
  const float* here_nearest;           // the same of this frame
  int width, height, blocks_across;    // the frames' size; blocks in a row of those
  float u0, v;                         // the first pixel centre of the row and the row's centre
};
// A depth beyond every depth around where a point lands, by more than this fraction, is
// something that moved: no camera move makes a surface appear in empty space.
constexpr float kMotionDepth = 0.02f;
// Rows handed to motion_row are padded with background to a multiple of this: the most lanes
// of any x86 target (AVX-512), checked in each target's kernel.
constexpr int kMotionRowPad = 16;
}  // namespace ssao
#endif

HWY_BEFORE_NAMESPACE();
namespace ssao {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// (ox, oy, oz) = m (x, y, z, 1) for m the top 3 rows of an affine map, broadcast on lanes.
template <class VF>
HWY_INLINE void transform_affine(const VF* m, VF x, VF y, VF z, VF& ox, VF& oy, VF& oz) {
  ox = hn::MulAdd(m[0], x, hn::MulAdd(m[1], y, hn::MulAdd(m[2], z, m[3])));
  oy = hn::MulAdd(m[4], x, hn::MulAdd(m[5], y, hn::MulAdd(m[6], z, m[7])));
  oz = hn::MulAdd(m[8], x, hn::MulAdd(m[9], y, hn::MulAdd(m[10], z, m[11])));
}

// base[index] per lane. Where the lanes read consecutive floats, as the carry does on a still
// camera or a move of a few pixels a frame, one load reads them: the gathers took most of
// carry_row's time (1920x1080 sequence frames 35 -> 29 ms on 2 threads).
template <class DF, class VI>
HWY_INLINE hn::Vec<DF> gather_or_load(DF df, const float* base, VI index) {
  const hn::RebindToSigned<DF> di;
  const int first = hn::GetLane(index);
  if (hn::AllTrue(di, hn::Eq(index, hn::Iota(di, first)))) return hn::LoadU(df, base + first);
  return hn::GatherIndex(df, base, index);
}

// Pixels i < count of a row (planar depths depth[i], background skipped; values own[i]): each
// one's value in the earlier frame, that of the pixel the point lands in there, added to sum[i]
// (and 1 to n[i]) where that pixel shows the same surface (depth within kCarryDepthAgreement)
// and the value is within kCarryRejection of its own, unless moved[i] says the scene moved
// near the pixel (find_motion). The nearest pixel rather than a bilinear mix of four: a
// quarter of the gathers, and on the kit's camera moves less flicker (contact, occluded
// pixels: 0.0062 against 0.0074).
HWY_NOINLINE void carry_row(const CarryArgs& a, const float* depth, const float* own,
                            const float* low, const float* high, const float* moved, int count,
                            float* sum, float* n) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VF = hn::Vec<decltype(df)>;
  const int lanes = int(hn::Lanes(df));
  const VF one = hn::Set(df, 1.0f);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF per_depth = hn::Set(df, a.here.orthographic ? 0.0f : 1.0f);
  VF m[12];
  for (int k = 0; k < 12; ++k) m[k] = hn::Set(df, a.to_entry[k]);
  const VF y_unit = hn::Set(df, (a.here.center_v - a.v) * a.here.scale_v);
  const LaneProjection<VF> there(a.there, a.width, a.height);
  const auto width = hn::Set(di, a.width);
  alignas(64) float stage[7][16];
  for (int i = 0; i < count; i += lanes) {
    const int here = std::min(lanes, count - i);
    const float *d_at = depth + i, *own_at = own + i, *sum_at = sum + i, *n_at = n + i;
    const float *low_at = low + i, *high_at = high + i, *moved_at = moved + i;
    if (here < lanes) {  // stage the last lanes, padded with background
      for (int k = 0; k < lanes; ++k) {
        stage[0][k] = k < here ? depth[i + k] : std::numeric_limits<float>::infinity();
        stage[1][k] = k < here ? own[i + k] : 0.0f;
        stage[2][k] = k < here ? sum[i + k] : 0.0f;
        stage[3][k] = k < here ? n[i + k] : 0.0f;
        stage[4][k] = k < here ? low[i + k] : 0.0f;
        stage[5][k] = k < here ? high[i + k] : 0.0f;
        stage[6][k] = k < here ? moved[i + k] : 0.0f;
      }
      d_at = stage[0], own_at = stage[1], sum_at = stage[2], n_at = stage[3];
      low_at = stage[4], high_at = stage[5], moved_at = stage[6];
    }
    const VF d = hn::LoadU(df, d_at);
    const auto geometry = hn::Lt(d, inf);
    const VF safe = hn::IfThenElse(geometry, d, one);
    const VF scale = hn::MulAdd(per_depth, safe, one - per_depth);
    const VF u = hn::Iota(df, a.u0 + float(i));
    const VF px = (u - hn::Set(df, a.here.center_u)) * hn::Set(df, a.here.scale_u) * scale;
    const VF py = y_unit * scale, pz = hn::Neg(safe);
    VF qx, qy, qz;
    transform_affine(m, px, py, pz, qx, qy, qz);
    const VF z = hn::Neg(qz);  // planar depth there
    // The point's continuous image coordinates in the earlier frame, and the pixel there.
    VF fx, fy;
    const auto inside = hn::And(there(qx, qy, qz, fx, fy), geometry);
    const auto x = hn::ConvertTo(di, hn::IfThenElseZero(inside, fx));
    const auto y = hn::ConvertTo(di, hn::IfThenElseZero(inside, fy));
    const auto index = y * width + x;
    const VF depth_there = gather_or_load(df, a.depth, index);
    const VF value_there = gather_or_load(df, a.value, index);
    const VF tolerance = hn::Set(df, kCarryDepthAgreement) * z;
    const auto same_surface = hn::Le(hn::Abs(depth_there - z), tolerance);
    // Clamped to the range of this frame's own values around the pixel (plus a margin): a
    // value an earlier frame had where something has since moved does not trail.
    const VF margin = hn::Set(df, kCarryMargin);
    const VF carried =
        hn::Clamp(value_there, hn::LoadU(df, low_at) - margin, hn::LoadU(df, high_at) + margin);
    const VF own_v = hn::LoadU(df, own_at);
    const auto close = hn::Le(hn::Abs(carried - own_v), hn::Set(df, kCarryRejection));
    const auto still = hn::Eq(hn::LoadU(df, moved_at), hn::Zero(df));
    const auto takes = hn::And(hn::And(hn::And(inside, same_surface), close), still);
    const VF new_sum = hn::LoadU(df, sum_at) + hn::IfThenElseZero(takes, carried);
    const VF new_n = hn::LoadU(df, n_at) + hn::IfThenElseZero(takes, one);
    if (here < lanes) {
      hn::Store(new_sum, df, stage[2]);
      hn::Store(new_n, df, stage[3]);
      std::copy_n(stage[2], here, sum + i);
      std::copy_n(stage[3], here, n + i);
    } else {
      hn::StoreU(new_sum, df, sum + i);
      hn::StoreU(new_n, df, n + i);
    }
  }
}

// Pixels (u0 + 2 i, v), i < count, of this frame (planar depths depth[i]; the row padded with
// background to a multiple of kMotionRowPad): moved[i] > 0 where the earlier frame shows
// something a camera move does not explain, else 0; returns how many are > 0. moved[i] is the
// depth here of what moved: the point, or the surface that left from in front of it. Either the
// point lies in front of everything the earlier frame saw around where it lands there (it appeared:
// an object moved in), or the earlier frame saw a surface in front of it which this frame no longer
// shows around where that surface lands here (it vanished: an object moved away and uncovered this
// point). Both compare against the nearest depth around the pixel (of the 4 x 4 square around
// its 2 x 2 block, which holds its 3 x 3 square), so a surface seen at a grazing angle or an
// edge a pixel away is not taken for motion; an uncovering by the camera's move finds its
// occluder still there.
HWY_NOINLINE size_t motion_row(const MotionArgs& a, const float* depth, int count, float* moved) {
  static_assert(HWY_LANES(float) <= kMotionRowPad, "the rows' padding is a whole vector");
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VF = hn::Vec<decltype(df)>;
  const int lanes = int(hn::Lanes(df));
  const VF one = hn::Set(df, 1.0f), two = hn::Set(df, 2.0f);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF beyond = hn::Set(df, 1.0f + kMotionDepth), before = hn::Set(df, 1.0f - kMotionDepth);
  const VF per_depth = hn::Set(df, a.here.orthographic ? 0.0f : 1.0f);
  const VF there_per_depth = hn::Set(df, a.there.orthographic ? 0.0f : 1.0f);
  VF to[12], from[12];
  for (int k = 0; k < 12; ++k) to[k] = hn::Set(df, a.to_entry[k]);
  for (int k = 0; k < 12; ++k) from[k] = hn::Set(df, a.from_entry[k]);
  const VF y_unit = hn::Set(df, (a.here.center_v - a.v) * a.here.scale_v);
  const LaneProjection<VF> here(a.here, a.width, a.height);
  const LaneProjection<VF> there(a.there, a.width, a.height);
  const auto width = hn::Set(di, a.width), blocks_across = hn::Set(di, a.blocks_across);
  const auto block = [&](auto x, auto y) {
    return hn::ShiftRight<1>(y) * blocks_across + hn::ShiftRight<1>(x);
  };
  size_t total = 0;
  for (int i = 0; i < count; i += lanes) {
    const VF d = hn::LoadU(df, depth + i);
    const auto geometry = hn::Lt(d, inf);
    const VF safe = hn::IfThenElse(geometry, d, one);
    const VF scale = hn::MulAdd(per_depth, safe, one - per_depth);
    const VF u = hn::MulAdd(hn::Iota(df, 0.0f), two, hn::Set(df, a.u0 + 2.0f * float(i)));
    const VF px = (u - hn::Set(df, a.here.center_u)) * hn::Set(df, a.here.scale_u) * scale;
    VF qx, qy, qz;
    transform_affine(to, px, y_unit * scale, hn::Neg(safe), qx, qy, qz);
    const VF z = hn::Neg(qz);
    VF fx, fy;
    const auto inside = hn::And(there(qx, qy, qz, fx, fy), geometry);
    const auto x = hn::ConvertTo(di, hn::IfThenElseZero(inside, fx));
    const auto y = hn::ConvertTo(di, hn::IfThenElseZero(inside, fy));
    const auto appeared =
        hn::And(inside, hn::Gt(gather_or_load(df, a.there_nearest, block(x, y)), z * beyond));
    // The surface the earlier frame saw in front of the point, back in this frame.
    const VF seen = hn::GatherIndex(df, a.there_depth, y * width + x);
    const auto hidden = hn::And(inside, hn::Lt(seen, z * before));
    auto found = appeared;
    VF nearest_moved = safe;          // the point, or what moved away from in front of it if nearer
    if (!hn::AllFalse(df, hidden)) {  // rare but where the view was uncovered
      const VF seen_safe = hn::IfThenElse(hidden, seen, one);
      VF rx, ry;
      there.pixel_ray(x, y, rx, ry);
      const VF there_scale = hn::MulAdd(there_per_depth, seen_safe, one - there_per_depth);
      VF hx, hy, hz;
      transform_affine(from, rx * there_scale, ry * there_scale, hn::Neg(seen_safe), hx, hy, hz);
      VF gx, gy;
      const auto back_inside = hn::And(here(hx, hy, hz, gx, gy), hidden);
      const auto back_index = block(hn::ConvertTo(di, hn::IfThenElseZero(back_inside, gx)),
                                    hn::ConvertTo(di, hn::IfThenElseZero(back_inside, gy)));
      const VF nearest_here = hn::GatherIndex(df, a.here_nearest, back_index);
      const auto vanished = hn::And(back_inside, hn::Gt(nearest_here, hn::Neg(hz) * beyond));
      found = hn::Or(found, vanished);
      nearest_moved = hn::IfThenElse(vanished, hn::Min(safe, hn::Neg(hz)), safe);
    }
    hn::StoreU(hn::IfThenElseZero(found, nearest_moved), df, moved + i);
    total += hn::CountTrue(df, found);
  }
  return total;
}

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>
#include <cmath>

#include "scratch.h"
#include "simd.h"
#include "temporal.h"
#include "variants/simd_dispatch.h"

namespace ssao {
namespace {

// The widest compiled carry_row this CPU runs, chosen on first use.
decltype(&HWY_STATIC_DISPATCH(carry_row)) best_carry_row() {
  static const auto row = SSAO_BEST_TARGET(carry_row);
  return row;
}

// The widest compiled motion_row this CPU runs.
decltype(&HWY_STATIC_DISPATCH(motion_row)) best_motion_row() {
  static const auto row = SSAO_BEST_TARGET(motion_row);
  return row;
}

// The inverse of an affine 4x4 (row-major; last row 0 0 0 1) as its top 3 rows; false when its
// 3x3 part is singular.
bool invert_affine(const double* m, double* out) {
  const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
               i = m[10];
  const double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  if (!(std::fabs(det) > 1e-300) || !std::isfinite(det)) return false;
  const double r[9] = {(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det,
                       (f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det,
                       (d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det};
  for (int row = 0; row < 3; ++row) {
    out[4 * row + 0] = r[3 * row + 0];
    out[4 * row + 1] = r[3 * row + 1];
    out[4 * row + 2] = r[3 * row + 2];
    out[4 * row + 3] = -(r[3 * row + 0] * m[3] + r[3 * row + 1] * m[7] + r[3 * row + 2] * m[11]);
  }
  return true;
}

// a x b for the top 3 rows of affine matrices (the last rows 0 0 0 1).
void multiply_affine(const double* a, const double* b, double* out) {
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      double sum = col == 3 ? a[4 * row + 3] : 0.0;
      for (int k = 0; k < 3; ++k) sum += a[4 * row + k] * b[4 * k + col];
      out[4 * row + col] = sum;
    }
  }
}

// The smallest and largest of each value and its two neighbours in a row (the row's ends
// repeated). Selects only: the loops vectorise.
SSAO_VECTORIZE void row_range(const float* __restrict values, int count, float* __restrict low,
                              float* __restrict high) {
  if (count == 1) {
    low[0] = high[0] = values[0];
    return;
  }
  low[0] = std::min(values[0], values[1]), high[0] = std::max(values[0], values[1]);
  for (int i = 1; i + 1 < count; ++i) {
    const float a = values[i - 1], b = values[i], c = values[i + 1];
    const float ab_low = a < b ? a : b, ab_high = a < b ? b : a;
    low[i] = ab_low < c ? ab_low : c;
    high[i] = ab_high < c ? c : ab_high;
  }
  low[count - 1] = std::min(values[count - 2], values[count - 1]);
  high[count - 1] = std::max(values[count - 2], values[count - 1]);
}

// Rows a, b and c (indices into planes of `stride` floats a row) of row_range's results
// combined.
SSAO_VECTORIZE void column_range(const float* row_low, const float* row_high, size_t stride, int a,
                                 int b, int c, int count, float* __restrict low,
                                 float* __restrict high) {
  const float* __restrict la = row_low + size_t(a) * stride;
  const float* __restrict lb = row_low + size_t(b) * stride;
  const float* __restrict lc = row_low + size_t(c) * stride;
  const float* __restrict ha = row_high + size_t(a) * stride;
  const float* __restrict hb = row_high + size_t(b) * stride;
  const float* __restrict hc = row_high + size_t(c) * stride;
  for (int i = 0; i < count; ++i) {
    const float l = la[i] < lb[i] ? la[i] : lb[i], h = ha[i] < hb[i] ? hb[i] : ha[i];
    low[i] = l < lc[i] ? l : lc[i];
    high[i] = h < hc[i] ? hc[i] : h;
  }
}

// For each 2 x 2 block i < blocks of a row of `count` depths, the nearest of the depths
// 2 i - 1 .. 2 i + 2 (those in the row). The blocks whose four depths are all in the row take a
// loop without branches, which the compiler vectorises.
SSAO_VECTORIZE void nearest_in_blocks(const float* __restrict row, int count, int blocks,
                                      float* __restrict out) {
  const auto edge = [&](int i) {
    float m = std::numeric_limits<float>::infinity();
    for (int x = std::max(2 * i - 1, 0); x <= std::min(2 * i + 2, count - 1); ++x) {
      m = std::min(m, row[x]);
    }
    out[i] = m;
  };
  const int last_inner = (count - 3) / 2;  // 2 i + 2 <= count - 1
  edge(0);
  for (int i = 1; i <= last_inner; ++i) {
    const float a = row[2 * i - 1], b = row[2 * i], c = row[2 * i + 1], d = row[2 * i + 2];
    const float ab = a < b ? a : b, cd = c < d ? c : d;
    out[i] = ab < cd ? ab : cd;
  }
  for (int i = std::max(last_inner + 1, 1); i < blocks; ++i) edge(i);
}

// out[i] = 1 for every cell of a width x height grid within r cells (a square) of a cell
// marked in `marks`, else 0: running counts along the rows, then along the columns.
void dilate_marks(const std::vector<uint8_t>& marks, int width, int height, int r,
                  std::vector<float>& out) {
  std::vector<int> along(size_t(width) * height), prefix(size_t(std::max(width, height)) + 1);
  const auto spread = [&](int n, const auto& read, const auto& write) {
    prefix[0] = 0;
    for (int k = 0; k < n; ++k) prefix[k + 1] = prefix[k] + (read(k) ? 1 : 0);
    for (int k = 0; k < n; ++k)
      write(k, prefix[std::min(k + r + 1, n)] > prefix[std::max(k - r, 0)]);
  };
  for (int y = 0; y < height; ++y) {
    const size_t row = size_t(y) * width;
    spread(
        width, [&](int x) { return marks[row + x] != 0; },
        [&](int x, bool hit) { along[row + x] = hit; });
  }
  for (int x = 0; x < width; ++x) {
    spread(
        height, [&](int y) { return along[size_t(y) * width + x] != 0; },
        [&](int y, bool hit) { out[size_t(y) * width + x] = hit ? 1.0f : 0.0f; });
  }
}

}  // namespace

void TemporalHistory::begin(int frame, int frames, const CameraModel& camera,
                            const double* camera_to_world, const Tile& window) {
  frames_ = std::max(frames, 1);
  window_ = window;
  const int width = window.x1 - window.x0, height = window.y1 - window.y0;
  current_.frame = frame;
  current_.width = width, current_.height = height;
  // The window's own pixels: pixel (0, 0) of the entry is (x0, y0) of the input.
  current_.camera = camera.moved_by(-window.x0, -window.y0);
  std::copy_n(camera_to_world, 16, current_.camera_to_world);
  if (frames_ <= 1) {
    earlier_.clear();
    current_.depth.clear(), current_.visibility.clear();
    return;
  }
  // The earlier frames this one can use, each with the map from this view to its own. Frames
  // come in increasing order (the caller's promise), so one this frame cannot use no later
  // frame can; it lends its buffers to this one.
  std::deque<Entry> usable;
  for (Entry& e : earlier_) {
    double world_to_entry[12];
    const bool in_window = e.frame < frame && e.frame >= frame - (frames_ - 1);
    if (in_window && e.width == width && e.height == height &&
        invert_affine(e.camera_to_world, world_to_entry)) {
      multiply_affine(world_to_entry, camera_to_world, e.to_entry);
      usable.push_back(std::move(e));
    } else if (current_.depth.capacity() < e.depth.capacity()) {
      current_.depth.swap(e.depth);
      current_.visibility.swap(e.visibility);
      current_.nearest.swap(e.nearest);
    }
  }
  earlier_ = std::move(usable);
  current_.depth.resize(size_t(width) * size_t(height));
  current_.visibility.resize(size_t(width) * size_t(height));
  current_.nearest.resize(size_t((width + 1) / 2) * size_t((height + 1) / 2));
}

void TemporalHistory::find_motion(const Frame& frame, float radius, TilePool& tiles) {
  moved_.clear();
  if (frames_ <= 1) return;
  const int width = current_.width, height = current_.height;
  const size_t stride = size_t(width);
  Progress uncancellable(nullptr, nullptr);
  // This frame's depths over the window, and its nearest depth around each 2 x 2 block: over
  // the 4 x 4 square centred on it (rows 2 j - 1 .. 2 j + 2 of nearest_in_blocks's).
  const int blocks_across = (width + 1) / 2, blocks_down = (height + 1) / 2;
  tiles.for_each_row_band(
      blocks_across, blocks_down, kTileHeight, uncancellable, [&](const Tile& band) {
        const int y0 = std::max(2 * band.y0 - 1, 0), y1 = std::min(2 * band.y1 + 2, height);
        ScratchVector<float> rows(size_t(y1 - y0) * size_t(blocks_across));
        for (int y = y0; y < y1; ++y) {
          const float* depth = frame.depth_plane() + frame.index(window_.x0, window_.y0 + y);
          if (y >= 2 * band.y0 && y < std::min(2 * band.y1, height)) {
            std::copy_n(depth, width, current_.depth.data() + size_t(y) * stride);
          }
          nearest_in_blocks(depth, width, blocks_across,
                            rows.data() + size_t(y - y0) * blocks_across);
        }
        for (int j = band.y0; j < band.y1; ++j) {
          const float* r[4];
          for (int k = 0; k < 4; ++k) {
            r[k] =
                rows.data() + size_t(std::clamp(2 * j - 1 + k, 0, height - 1) - y0) * blocks_across;
          }
          float* out = current_.nearest.data() + size_t(j) * blocks_across;
          for (int i = 0; i < blocks_across; ++i) {
            out[i] = std::min(std::min(r[0][i], r[1][i]), std::min(r[2][i], r[3][i]));
          }
        }
      });
  if (earlier_.empty()) return;
  std::vector<MotionArgs> entries;
  const CameraIntrinsics here = current_.camera.intrinsics();
  for (const Entry& e : earlier_) {
    MotionArgs args{};
    args.here = here, args.there = e.camera.intrinsics();
    args.there_depth = e.depth.data();
    args.there_nearest = e.nearest.data(), args.here_nearest = current_.nearest.data();
    args.width = width, args.height = height, args.blocks_across = blocks_across;
    args.u0 = 0.5f;
    double from_entry[12];
    if (!invert_affine(e.to_entry, from_entry)) continue;  // the inverse of an inverse
    for (int k = 0; k < 12; ++k) {
      args.to_entry[k] = float(e.to_entry[k]);
      args.from_entry[k] = float(from_entry[k]);
    }
    entries.push_back(args);
  }
  // The test runs on one pixel of each 2 x 2 block: what it finds is widened by the radius
  // below, several pixels.
  const int padded = (blocks_across + kMotionRowPad - 1) / kMotionRowPad * kMotionRowPad;
  std::vector<uint8_t> marks(size_t(blocks_across) * size_t(blocks_down), 0);
  // Per band, the widest radius on screen of a point that moved, in pixels.
  std::vector<float> reaches(size_t((blocks_down + kTileHeight - 1) / kTileHeight), 0.0f);
  tiles.for_each_row_band(
      blocks_across, blocks_down, kTileHeight, uncancellable, [&](const Tile& band) {
        ScratchVector<float> depths(padded), found(padded);
        std::vector<MotionArgs> band_entries = entries;  // each band sets its own row centre
        float reach = 0.0f;
        for (int j = band.y0; j < band.y1; ++j) {
          const float* row = current_.depth.data() + size_t(2 * j) * stride;
          for (int i = 0; i < padded; ++i) {
            depths[i] = i < blocks_across ? row[2 * i] : std::numeric_limits<float>::infinity();
          }
          for (MotionArgs& args : band_entries) {
            args.v = float(2 * j) + 0.5f;
            if (best_motion_row()(args, depths.data(), blocks_across, found.data()) == 0) {
              continue;
            }
            for (int i = 0; i < blocks_across; ++i) {
              if (found[i] == 0.0f) continue;
              marks[size_t(j) * blocks_across + i] = 1;
              // Receivers up to a radius in front of what moved see it: their radius on
              // screen.
              const float z = std::max(found[i] - radius, 0.5f * found[i]);
              reach = std::max(
                  reach, here.orthographic ? radius / here.scale_u : radius / (here.scale_u * z));
            }
          }
        }
        reaches[size_t(band.y0 / kTileHeight)] = reach;
      });
  const float reach = *std::max_element(reaches.begin(), reaches.end());
  if (reach == 0.0f) return;
  // Every block within that reach of a mark (a square).
  const int r =
      int(std::min(std::ceil(reach / 2.0f) + 1.0f, float(std::max(blocks_across, blocks_down))));
  moved_width_ = blocks_across;
  moved_.assign(size_t(blocks_across) * size_t(blocks_down), 0.0f);
  dilate_marks(marks, blocks_across, blocks_down, r, moved_);
}

void TemporalHistory::blend(const Frame& frame, const Tile& t, float* values) {
  if (frames_ <= 1) return;
  const int width = t.x1 - t.x0, height = t.y1 - t.y0;
  const auto at = [&](int y) {  // row y's place in this frame's record
    return size_t(y - window_.y0) * size_t(current_.width) + size_t(t.x0 - window_.x0);
  };
  // This frame's values before averaging, for the frames after it (find_motion recorded its
  // depths).
  for (int y = t.y0; y < t.y1; ++y) {
    std::copy_n(values + size_t(y - t.y0) * width, width, current_.visibility.data() + at(y));
  }
  if (earlier_.empty()) return;
  // The range of this frame's values around each pixel (3 x 3 within the tile): each row's
  // 3-wide range first, then three rows of those.
  ScratchVector<float> row_low(size_t(width) * height), row_high(size_t(width) * height);
  for (int y = t.y0; y < t.y1; ++y) {
    row_range(current_.visibility.data() + at(y), width, row_low.data() + size_t(y - t.y0) * width,
              row_high.data() + size_t(y - t.y0) * width);
  }
  ScratchVector<float> sum(width), count(width), low(width), high(width), moved(width);
  for (int y = t.y0; y < t.y1; ++y) {
    const float* depth = frame.depth_plane() + frame.index(t.x0, y);
    float* row = values + size_t(y - t.y0) * width;
    const int above = std::max(y - 1, t.y0) - t.y0, below = std::min(y + 1, t.y1 - 1) - t.y0;
    column_range(row_low.data(), row_high.data(), size_t(width), above, y - t.y0, below, width,
                 low.data(), high.data());
    std::copy_n(row, width, sum.data());
    std::fill_n(count.data(), width, 1.0f);
    // Whether the scene moved near each pixel (find_motion's half grid).
    if (moved_.empty()) {
      std::fill_n(moved.data(), width, 0.0f);
    } else {
      const float* cells = moved_.data() + size_t((y - window_.y0) / 2) * size_t(moved_width_);
      for (int i = 0; i < width; ++i) moved[i] = cells[(t.x0 - window_.x0 + i) / 2];
    }
    const float u0 = float(t.x0 - window_.x0) + 0.5f, v = float(y - window_.y0) + 0.5f;
    for (const Entry& e : earlier_) {
      CarryArgs args{current_.camera.intrinsics(),
                     e.camera.intrinsics(),
                     {},
                     e.depth.data(),
                     e.visibility.data(),
                     e.width,
                     e.height,
                     u0,
                     v};
      for (int k = 0; k < 12; ++k) args.to_entry[k] = float(e.to_entry[k]);
      best_carry_row()(args, depth, row, low.data(), high.data(), moved.data(), width, sum.data(),
                       count.data());
    }
    for (int i = 0; i < width; ++i) row[i] = sum[i] / count[i];
  }
}

void TemporalHistory::commit() {
  if (frames_ <= 1) return;
  earlier_.push_back(std::move(current_));
  current_ = Entry{};
}

}  // namespace ssao
#endif  // HWY_ONCE
