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
constexpr float kCarryDepthAgreement = 0.005f, kCarryRejection = 0.1f;
// How far a carried value may lie outside the range of the frame's own values around it.
constexpr float kCarryMargin = 0.01f;
}  // namespace ssao
#endif

HWY_BEFORE_NAMESPACE();
namespace ssao {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Pixels i < count of a row (planar depths depth[i], background skipped; values own[i]): each
// one's value in the earlier frame, that of the pixel the point lands in there, added to sum[i]
// (and 1 to n[i]) where that pixel shows the same surface (depth within kCarryDepthAgreement)
// and the value is within kCarryRejection of its own. The nearest pixel rather than a bilinear
// mix of four: a quarter of the gathers, and on the kit's camera moves less flicker (contact,
// occluded pixels: 0.0062 against 0.0074).
HWY_NOINLINE void carry_row(const CarryArgs& a, const float* depth, const float* own,
                            const float* low, const float* high, int count, float* sum, float* n) {
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
  alignas(64) float stage[6][16];
  for (int i = 0; i < count; i += lanes) {
    const int here = std::min(lanes, count - i);
    const float *d_at = depth + i, *own_at = own + i, *sum_at = sum + i, *n_at = n + i;
    const float *low_at = low + i, *high_at = high + i;
    if (here < lanes) {  // stage the last lanes, padded with background
      for (int k = 0; k < lanes; ++k) {
        stage[0][k] = k < here ? depth[i + k] : std::numeric_limits<float>::infinity();
        stage[1][k] = k < here ? own[i + k] : 0.0f;
        stage[2][k] = k < here ? sum[i + k] : 0.0f;
        stage[3][k] = k < here ? n[i + k] : 0.0f;
        stage[4][k] = k < here ? low[i + k] : 0.0f;
        stage[5][k] = k < here ? high[i + k] : 0.0f;
      }
      d_at = stage[0], own_at = stage[1], sum_at = stage[2], n_at = stage[3];
      low_at = stage[4], high_at = stage[5];
    }
    const VF d = hn::LoadU(df, d_at);
    const auto geometry = hn::Lt(d, inf);
    const VF safe = hn::IfThenElse(geometry, d, one);
    const VF scale = hn::MulAdd(per_depth, safe, one - per_depth);
    const VF u = hn::Iota(df, a.u0 + float(i));
    const VF px = (u - hn::Set(df, a.here.center_u)) * hn::Set(df, a.here.scale_u) * scale;
    const VF py = y_unit * scale, pz = hn::Neg(safe);
    const VF qx = hn::MulAdd(m[0], px, hn::MulAdd(m[1], py, hn::MulAdd(m[2], pz, m[3])));
    const VF qy = hn::MulAdd(m[4], px, hn::MulAdd(m[5], py, hn::MulAdd(m[6], pz, m[7])));
    const VF qz = hn::MulAdd(m[8], px, hn::MulAdd(m[9], py, hn::MulAdd(m[10], pz, m[11])));
    const VF z = hn::Neg(qz);  // planar depth there
    // The point's continuous image coordinates in the earlier frame, and the pixel there.
    VF fx, fy;
    const auto inside = hn::And(there(qx, qy, qz, fx, fy), geometry);
    const auto x = hn::ConvertTo(di, hn::IfThenElseZero(inside, fx));
    const auto y = hn::ConvertTo(di, hn::IfThenElseZero(inside, fy));
    const auto index = y * width + x;
    const VF tolerance = hn::Set(df, kCarryDepthAgreement) * z;
    const auto same_surface = hn::Le(hn::Abs(hn::GatherIndex(df, a.depth, index) - z), tolerance);
    // Clamped to the range of this frame's own values around the pixel (plus a margin): a
    // value an earlier frame had where something has since moved does not trail.
    const VF margin = hn::Set(df, kCarryMargin);
    const VF carried = hn::Clamp(hn::GatherIndex(df, a.value, index),
                                 hn::LoadU(df, low_at) - margin, hn::LoadU(df, high_at) + margin);
    const VF own_v = hn::LoadU(df, own_at);
    const auto close = hn::Le(hn::Abs(carried - own_v), hn::Set(df, kCarryRejection));
    const auto takes = hn::And(hn::And(inside, same_surface), close);
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
    }
  }
  earlier_ = std::move(usable);
  current_.depth.resize(size_t(width) * size_t(height));
  current_.visibility.resize(size_t(width) * size_t(height));
}

void TemporalHistory::blend(const Frame& frame, const Tile& t, float* values) {
  if (frames_ <= 1) return;
  const int width = t.x1 - t.x0, height = t.y1 - t.y0;
  const auto at = [&](int y) {  // row y's place in this frame's record
    return size_t(y - window_.y0) * size_t(current_.width) + size_t(t.x0 - window_.x0);
  };
  // This frame's values before averaging, for the frames after it.
  for (int y = t.y0; y < t.y1; ++y) {
    std::copy_n(frame.depth_plane() + frame.index(t.x0, y), width, current_.depth.data() + at(y));
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
  ScratchVector<float> sum(width), count(width), low(width), high(width);
  for (int y = t.y0; y < t.y1; ++y) {
    const float* depth = frame.depth_plane() + frame.index(t.x0, y);
    float* row = values + size_t(y - t.y0) * width;
    const int above = std::max(y - 1, t.y0) - t.y0, below = std::min(y + 1, t.y1 - 1) - t.y0;
    column_range(row_low.data(), row_high.data(), size_t(width), above, y - t.y0, below, width,
                 low.data(), high.data());
    std::copy_n(row, width, sum.data());
    std::fill_n(count.data(), width, 1.0f);
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
      best_carry_row()(args, depth, row, low.data(), high.data(), width, sum.data(), count.data());
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
