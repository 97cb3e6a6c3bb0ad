// SPDX-License-Identifier: MIT
#include "frame.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "error.h"
#include "scratch.h"
#include "simd.h"

namespace ssao {
// A layer may be this much (relative) nearer than the one before it and still be taken as the
// same depth: two renders of one surface agree to about 1e-5 (Cycles, measured), a half-float
// EXR rounds to 5e-4.
constexpr float kLayerOrderTolerance = 1e-3f;
// A renderer filters its Normal pass over each pixel like the beauty, averaging unit normals: on
// a crease or a silhouette the average of two surfaces' normals is shorter than 1 (cos(a / 2)
// for two at an angle a, half each), where the Depth pass holds one of them. Shorter than this
// is a mix: 0.99 is two surfaces 16 degrees apart, half each (a smooth-shaded surface bends far
// less within a pixel; half-float storage moves the length by 1e-3).
constexpr float kMixedNormalLength = 0.99f;
// A neighbour is on a mixed pixel's own surface when the pixel's position lies within this many
// pixel footprints of the neighbour's tangent plane.
constexpr float kOwnSurfaceFootprints = 2.0f;
// A mix is a concave crease when a neighbour lies more than this many pixel footprints above the
// chosen normal's tangent plane (the other surface rises in front of it).
constexpr float kConcaveFootprints = 0.25f;

void Frame::reset(const CameraModel& camera, int width, int height, int extra_layers) {
  camera_ = camera;
  width_ = width;
  height_ = height;
  extra_layers_ = extra_layers;
  depth_.resize(size_t(width) * size_t(height));
  // The normal plane is sized by build_normals or downsample (a full frame estimated at half
  // resolution has none).
  layers_.resize(size_t(extra_layers) * size_t(width) * size_t(height));
}

float Frame::solid_entry(int x, int y, float depth, bool& closed, bool* past_last) const {
  closed = false;
  if (past_last != nullptr) *past_last = false;
  float entry = depth_[index(x, y)];
  if (!(depth > entry)) return kBackground;  // in front of the visible surface
  bool entered = true;                       // the visible surface is taken as a front face
  for (int k = 0; k < extra_layers_; ++k) {
    const float hit = layers_[size_t(k) * pixel_count() + index(x, y)];
    const float hit_depth = std::fabs(hit);
    const bool back = hit < 0.0f;
    if (depth <= hit_depth) {  // the point lies between the last hit and this one
      if (past_last != nullptr) *past_last = hit == kBackground;
      if (!entered) return kBackground;
      closed = back;
      return entry;
    }
    entry = hit_depth;
    entered = !back;
  }
  if (past_last != nullptr) *past_last = true;
  return entered ? entry : kBackground;  // behind the last known hit
}

void Frame::measure_plane_distance_scale(TilePool& pool, Progress& progress) {
  plane_distance_scale_.resize(extra_layers_ > 0 ? pixel_count() : 0);
  if (extra_layers_ == 0) return;
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      plane_distance_scale_row(t.x0, t.x1 - t.x0, y, plane_distance_scale_.data() + index(t.x0, y));
    }
  });
}

// Pixels [x0, x0 + count) of row y: a loop without calls or branches, so that it vectorises.
SSAO_VECTORIZE void Frame::plane_distance_scale_row(int x0, int count, int y,
                                                    float* __restrict out) const {
  const CameraIntrinsics cam = camera_.intrinsics();
  // The ray through the pixel's centre at unit depth (CameraModel::view_position).
  const float ray_y = cam.orthographic ? 0.0f : (cam.center_v - (float(y) + 0.5f)) * cam.scale_v;
  const float ray_x_scale = cam.orthographic ? 0.0f : cam.scale_u;
  const float* __restrict depth = depth_.data() + index(x0, y);
  const uint32_t* __restrict normals = normal_.data() + index(x0, y);
  for (int i = 0; i < count; ++i) {
    const float ray_x = (float(x0 + i) + 0.5f - cam.center_u) * ray_x_scale;
    const Vec3 n = decode_normal(normals[i]);
    const float scale = std::fabs(n.x * ray_x + n.y * ray_y - n.z);
    out[i] = depth[i] != kBackground ? scale : 0.0f;
  }
}

namespace {
// The tangent plane of the surface beyond a stop of a walk (Frame::carried_depth): where pixels'
// rays meet it, its packed normal, and how many pixels back from the stop it is carried; `usable`
// false where the stop is not a step onto a farther surface.
struct CarriedPlane {
  bool usable = false;
  uint32_t packed = 0;
  int reach = 0;
  PlaneDepths depths;
};

// Whether neighbouring planar depths a and b lie on one surface: within Frame::kCarryJump of each
// other.
bool on_one_surface(float a, float b) {
  return a < b * Frame::kCarryJump && b < a * Frame::kCarryJump;
}

// Whether the step from depth b to c, between the steps a -> b and c -> d on either side (NaN
// where there is none), leaves the surface though by less than Frame::kCarryJump: by more than
// kOffSurfaceStep of the depth and kStepOverSlope times the surface's own step on either side.
// A slat 0.3 in front of a wall at a depth of 6.4 is 4 % nearer; a surface seen at a grazing
// angle steps as far from pixel to pixel, but steadily. A step the other way is no slope: it is
// the far side of something a pixel wide; nor is one more than kStepOverSlope times this one: a
// post one pixel wide between a nearer column and the wall 4 % behind it (`thin` on a camera
// move: the post, read as a part of the wall, kept the assumed thickness in the frames where
// the column hid the rest of it, and the wall beside it went dark and light from frame to frame).
constexpr float kOffSurfaceStep = 0.01f;
bool steps_off(float a, float b, float c, float d) {
  constexpr float kStepOverSlope = 4.0f;
  const float step = c - b;
  if (!(std::fabs(step) > kOffSurfaceStep * std::min(b, c))) return false;
  const auto slope = [&](float from, float to) {
    if (std::isnan(from + to) || from == Frame::kBackground || to == Frame::kBackground) {
      return 0.0f;
    }
    const float steady = (to - from) * step > 0.0f ? std::fabs(to - from) : 0.0f;
    return steady > kStepOverSlope * std::fabs(step) ? 0.0f : steady;
  };
  return std::fabs(step) > kStepOverSlope * std::max(slope(a, b), slope(c, d));
}

// Along a line of `count` pixels whose planar depths depth_at(i) gives: on_run(begin, end,
// drops_before, drops_after) for each run [begin, end) of geometry pixels on one surface (no
// step of kCarryJump or off the surface between neighbours, and not parted(i): pixels i - 1 and
// i parted by what the normals tell, Frame::passes_in_front); drops_*: a farther surface or
// background lies just past that end (never at the line's ends).
template <class DepthAt, class Parted, class OnRun>
void for_each_run(int count, DepthAt depth_at, Parted parted, OnRun on_run) {
  const float none = std::numeric_limits<float>::quiet_NaN();
  const auto at = [&](int i) { return i >= 0 && i < count ? depth_at(i) : none; };
  const auto joined = [&](int i) {  // pixels i - 1 and i
    return on_one_surface(depth_at(i - 1), depth_at(i)) &&
           !steps_off(at(i - 2), depth_at(i - 1), depth_at(i), at(i + 1)) && !parted(i);
  };
  int begin = 0;
  while (begin < count) {
    if (depth_at(begin) == Frame::kBackground) {
      ++begin;
      continue;
    }
    int end = begin + 1;
    while (end < count && depth_at(end) != Frame::kBackground && joined(end)) ++end;
    on_run(begin, end, begin > 0 && depth_at(begin - 1) > depth_at(begin),
           end < count && depth_at(end) > depth_at(end - 1));
    begin = end;
  }
}
}  // namespace

int Frame::carry_search() const {
  return std::max(kCarrySearch, static_cast<int>(kCarryFlatReach *
                                                 static_cast<float>(std::max(width_, height_))));
}

// Each of the four walks scans a whole row or column towards the pixels, keeping the nearest stop
// seen so far (a step onto a farther surface, or background) with its surface's plane: O(pixels)
// however far the planes reach, one plane per stop (and a walk of up to carry_search() pixels
// beyond it along its surface, for its reach), and per pixel where its ray meets the plane; of
// the four walks' planes, the one the ray meets first.
void Frame::find_carried_surfaces(TilePool& pool, Progress& progress) {
  const int search = carry_search();
  if (extra_layers_ > 0 || normal_.empty()) {
    std::vector<float>().swap(carried_depth_);
    std::vector<uint32_t>().swap(carried_normal_);
    return;
  }
  carried_depth_.resize(pixel_count());
  carried_normal_.resize(pixel_count());
  // The plane of the surface a walk in direction (dx, dy) steps onto at (x, y): that of the pixel
  // past it where the surface goes on there (the first pixel across is often a mix of both in
  // the Normal pass).
  const auto plane_at = [&](int x, int y, int dx, int dy) {
    const float far_side = depth(x, y);
    if (far_side == kBackground) return CarriedPlane();
    const int gx = x + dx, gy = y + dy;
    if (gx >= 0 && gy >= 0 && gx < width_ && gy < height_ &&
        on_one_surface(depth(gx, gy), far_side)) {
      x = gx, y = gy;
    }
    const uint32_t packed = normal_[index(x, y)];
    const Vec3 n = decode_normal(packed), q = position(x, y);
    CarriedPlane plane{true, packed, 0, PlaneDepths(camera_.intrinsics(), n, dot(q, n))};
    // Carried as far as the surface was seen on its plane beyond the step (the floor beside a
    // sphere, not a tube's side), and at least kCarrySearch; a surface that runs out of the
    // frame as far as the search goes.
    plane.reach = kCarrySearch;
    for (int k = 1; k <= search; ++k) {
      const int px = x + k * dx, py = y + k * dy;
      if (px < 0 || py < 0 || px >= width_ || py >= height_) {
        plane.reach = search;
        break;
      }
      const float d = depth(px, py);
      float numerator, slope;
      plane.depths.at(px, py, numerator, slope);
      if (d == kBackground ||
          !(std::fabs(numerator - d * slope) <= kCarryFlatTolerance * d * slope)) {
        break;
      }
      plane.reach = std::max(plane.reach, k);
    }
    return plane;
  };
  // Pixel (x, y) of depth d, within the reach of the stop whose plane is `plane`: where its ray
  // meets the plane, if farther than its surface by kCarryJump and nearer than the planes of the
  // other stops (behind a sphere on a floor before a wall, the floor's plane from beside it,
  // before the wall's from above it: the crease they make behind it).
  const auto consider = [&](int x, int y, float d, const CarriedPlane& plane) {
    if (!plane.usable || d == kBackground) return;
    const size_t slot = index(x, y);
    // meets = numerator / slope > d * kCarryJump and < the nearest so far, without the division.
    float numerator, slope;
    plane.depths.at(x, y, numerator, slope);
    if (!(slope > 1e-6f) || !(numerator > d * kCarryJump * slope) ||
        !(numerator < carried_depth_[slot] * slope)) {
      return;
    }
    carried_depth_[slot] = numerator / slope;
    carried_normal_[slot] = plane.packed;
  };
  // Along rows, right then left, scanning against the walk: the nearest stop ahead (a pixel of
  // background, or a step from the pixel before onto a surface farther by kCarryJump).
  constexpr int kCarryBandRows = 64;
  pool.for_each_row_band(width_, height_, kCarryBandRows, progress, [&](const Tile& t) {
    const int w = width_;
    std::fill(carried_depth_.begin() + index(0, t.y0), carried_depth_.begin() + index(0, t.y1),
              kBackground);
    for (int y = t.y0; y < t.y1; ++y) {
      const float* row = depth_.data() + index(0, y);
      for (const int dx : {1, -1}) {
        int stop = -1;
        CarriedPlane plane;
        for (int x = dx > 0 ? w - 1 : 0; x >= 0 && x < w; x -= dx) {
          if (stop >= 0 && std::abs(stop - x) <= plane.reach) {
            consider(x, y, row[x], plane);
          }
          const int before = x - dx;
          if (row[x] == kBackground ||
              (before >= 0 && before < w && row[x] > row[before] * kCarryJump)) {
            stop = x, plane = plane_at(x, y, dx, 0);
          }
        }
      }
    }
  });
  // Along columns, down then up, the same with one stop per column: strips of whole columns,
  // after every row (each pixel meets the four walks' planes in the same order as ever).
  constexpr int kCarryStripColumns = 64;
  pool.for_each_column_strip(width_, height_, kCarryStripColumns, progress, [&](const Tile& t) {
    const int w = t.x1 - t.x0;
    ScratchVector<int> stop(static_cast<size_t>(w));
    ScratchVector<CarriedPlane> plane(static_cast<size_t>(w));
    for (const int dy : {1, -1}) {
      std::fill(stop.begin(), stop.end(), -1);
      for (int y = dy > 0 ? height_ - 1 : 0; y >= 0 && y < height_; y -= dy) {
        const float* row = depth_.data() + index(t.x0, y);
        const int before = y - dy;
        const float* row_before =
            before >= 0 && before < height_ ? depth_.data() + index(t.x0, before) : nullptr;
        for (int i = 0; i < w; ++i) {
          if (stop[size_t(i)] >= 0 && std::abs(stop[size_t(i)] - y) <= plane[size_t(i)].reach) {
            consider(t.x0 + i, y, row[i], plane[size_t(i)]);
          }
          if (row[i] == kBackground ||
              (row_before != nullptr && row[i] > row_before[i] * kCarryJump)) {
            stop[size_t(i)] = y, plane[size_t(i)] = plane_at(t.x0 + i, y, 0, dy);
          }
        }
      }
    }
  });
}

namespace {
// How many pixels the run [begin, end) of `row` may go on behind the nearer surface past its end
// in direction `dir` (1: after it, -1: before it): up to where a surface shows that is farther
// than the run would be there, receding at its mean steepness (either way it slopes: the run is
// never taken to end where it might only have turned away), by more than steps_off's least step
// off a surface (or background). -1 where it may go on further: the frame's edge, a surface about
// as deep as the run (the run showing again), or none within kHiddenSearch pixels.
int hidden_past(const float* row, int width, int begin, int end, int dir) {
  constexpr int kHiddenSearch = 64;
  const int last = dir > 0 ? end - 1 : begin;
  const float beside = row[last], margin = kOffSurfaceStep * beside;
  const float slope = std::fabs(row[end - 1] - row[begin]) / float(std::max(end - begin - 1, 1));
  for (int k = 1; k <= kHiddenSearch; ++k) {
    const int x = last + k * dir;
    if (x < 0 || x >= width) return -1;
    const float gone_on = beside + slope * float(k);
    if (row[x] > gone_on + margin) return k - 1;
    if (!(row[x] < gone_on - margin)) return -1;
  }
  return -1;
}

// A solid's thickness from how wide it is: the thickness fade counts a point fully up to the
// thickness and not at all past twice it, so 2/3 of a round solid's depth.
constexpr float kDepthPerWidth = 2.0f / 3.0f;

// How deep a rounded solid is at each pixel i of a run [begin, end) on its surface, from the
// run's drops to a farther surface (a silhouette) before and after it, into out[i - begin] (view
// units, times kDepthPerWidth; `footprint_at(i)`: pixel i's width in view units). A circle's
// chord: 2 sqrt(a b) pixels for a pixel a from one drop and b from the other; with one drop (the
// run may go on behind a nearer surface at its other end), 2 sqrt(a w) for a run w long: near
// the drop, the chord of a circle as wide as the run. Not called without a drop.
template <class FootprintAt>
void rounded_depths(int begin, int end, bool drop_before, bool drop_after, FootprintAt footprint_at,
                    float* out) {
  const int n = end - begin;
  const float run = float(n);
  const auto put = [&](int k, float pixels_squared) {
    out[k] = kDepthPerWidth * 2.0f * std::sqrt(pixels_squared) * footprint_at(begin + k);
  };
  if (drop_before && drop_after) {
    for (int k = 0; k < n; ++k) put(k, (float(k) + 0.5f) * (run - float(k) - 0.5f));
  } else if (drop_before) {
    for (int k = 0; k < n; ++k) put(k, (float(k) + 0.5f) * run);
  } else {
    for (int k = 0; k < n; ++k) put(k, (run - float(k) - 0.5f) * run);
  }
}
}  // namespace

// Along each row, a run of pixels on one surface (for_each_run) with a farther surface or
// background just past both ends is something narrow standing in front: a post, a leg, a
// column. Its depth is taken from its width, as a round or square post's: the thickness fade
// counts a point fully up to the thickness and not at all past twice it, so the thickness is
// 2/3 of the larger of the run's width (view units, at its mean depth) and its depth span (a
// surface seen at a grazing angle is as deep as it recedes). Rows only: a narrow run down a
// column is more often a horizontal slab seen edge-on (a shelf at the eye's height), as deep as
// the furniture it belongs to (`cavity`'s bookcase: RMSE 0.0522 -> 0.0632 with columns read
// too). A run of fewer than kPostWidthPixels is taken as that wide: the pixel grid sets its
// width more than the post does (a post 2.5 px wide covers 2 or 3 pixel centres as the camera
// moves), and it is narrower than that. Measuring such runs as they are flickered (`thin`'s
// 320x180 camera move, occluded flicker 0.0251 without the measure, 0.0313 reading every run),
// and leaving them out switched a 3 px slat between that depth and the assumed thickness from
// frame to frame (0.0349; 0.0265 taking them as 4 px wide). A run with a nearer surface past an
// end may go on behind it; where a farther surface than the run would be there shows past the
// nearer one (hidden_past), the run ends behind it and is at most that much wider: a post partly
// hidden by a column before it (`thin` on a camera move, occluded flicker 0.0267 -> 0.0176 with
// steps_off's steadiness: read as unmeasured, such a post kept the assumed thickness, reaching
// the wall 22 cm behind it, in the frames where the column hid part of it). A run at the frame's
// edge, or that may go on behind a nearer surface, says nothing (0).
// Where a run along a row or a column ends in a drop, the face there bounds its solid's depth
// besides (bound_by_side_face): a rail or a board whose side a deeper solid would show.
void Frame::measure_post_thickness(TilePool& pool, Progress& progress, bool assumed_in_plane) {
  constexpr int kPostBandRows = 64, kPostWidthPixels = 4;
  const bool shaped = assumed_in_plane && shape_by_silhouettes_;
  // Each pixel's rounded depth along its row (shaped only), for the columns' pass.
  ScratchVector<float> across(shaped ? pixel_count() : 0);
  pool.for_each_row_band(width_, height_, kPostBandRows, progress, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      const float* row = depth_.data() + index(0, y);
      float* out = last_thickness_.data() + index(0, y);
      std::fill_n(out, width_, 0.0f);
      float* rounded = shaped ? across.data() + index(0, y) : nullptr;
      if (shaped) std::fill_n(rounded, width_, 0.0f);
      const auto depth_at = [&](int x) { return row[x]; };
      const auto parted = [&](int x) { return passes_in_front(x - 1, y, 1, 0); };
      for_each_run(width_, depth_at, parted, [&](int x, int end, bool left, bool right) {
        const int before = left ? 0 : hidden_past(row, width_, x, end, -1);
        const int after = right ? 0 : hidden_past(row, width_, x, end, 1);
        if (before >= 0 && after >= 0) {
          const auto [nearest, farthest] = std::minmax_element(row + x, row + end);
          const float width = float(std::max(end - x + before + after, kPostWidthPixels)) *
                              camera_.pixel_footprint(0.5f * (*nearest + *farthest));
          std::fill(out + x, out + end, kDepthPerWidth * std::max(width, *farthest - *nearest));
        }
        if (shaped && (left || right)) {
          rounded_depths(
              x, end, left, right, [&](int i) { return camera_.pixel_footprint(row[i]); },
              rounded + x);
        }
        if (left) bound_by_side_face(x, y, -1, 0, end - x);
        if (right) bound_by_side_face(end - 1, y, 1, 0, end - x);
      });
    }
  });
  // Down the columns, bands of columns (the tile's rows are columns here).
  pool.for_each_row_band(height_, width_, kPostBandRows, progress, [&](const Tile& t) {
    ScratchVector<float> down(shaped ? static_cast<size_t>(height_) : 0);
    for (int x = t.y0; x < t.y1; ++x) {
      if (shaped) std::fill(down.begin(), down.end(), 0.0f);
      const auto depth_at = [&](int y) { return depth(x, y); };
      const auto parted = [&](int y) { return passes_in_front(x, y - 1, 0, 1); };
      for_each_run(height_, depth_at, parted, [&](int y, int end, bool top, bool bottom) {
        if (shaped && (top || bottom)) {
          rounded_depths(
              y, end, top, bottom,
              [&](int i) { return camera_.pixel_footprint(depth(x, i)) * camera_.pixel_aspect(); },
              down.data() + y);
        }
        if (top) bound_by_side_face(x, y, 0, -1, end - y);
        if (bottom) bound_by_side_face(x, end - 1, 0, 1, end - y);
      });
      if (!assumed_in_plane) continue;
      for (int y = 0; y < height_; ++y) {
        const float assumed =
            shaped ? shaped_thickness(across[index(x, y)], down[size_t(y)]) : assumed_thickness_;
        float& cell = last_thickness_[index(x, y)];
        if (cell > 0.0f) {
          cell = std::min(cell, assumed);
        } else if (cell < 0.0f) {
          // A side-face bound less than the assumed depth stays (a receiver in front of the face
          // then takes the unshaped assumed thickness); else it changes nothing.
          if (!(-cell < assumed)) cell = assumed;
        } else if (assumed != assumed_thickness_) {
          cell = assumed;
        }
      }
    }
  });
}

// A surface passing in front of another by less than the depth steps that end a run
// (on_one_surface, steps_off): a bench's slats seen from above, each slat's top running back to
// the next slat's front face 3 cm behind it, a step of 1 % of the depth, no larger than the
// grazing top's own from pixel to pixel. The whole bench was one run, its slats as deep as the
// assumed thickness, and the floor under it too dark (`thin` at 640x360: RMSE 0.0453, 0.0376
// parted). Two tests, each more than kPartedFootprints pixel footprints: the farther point lies
// behind the nearer surface's tangent plane (also by kPartedSlope times their distance), and the
// nearer point in front of the farther surface carried on to it (its depth from the farther pixel
// and the next one beyond). A convex corner fails the second (a shelf's front face and its
// underside seen from below: the underside carried on runs in front of the front face's edge);
// a concave one fails the first (a floor meeting a wall). The nearer surface's normal comes from
// the first pixel in from the edge whose inner neighbour shares it and on whose plane the edge
// pixel lies: the Normal pass mixes the faces at an edge, and a mixed normal, or one of the face
// before a one-pixel underside, would part a shelf from the back panel it meets.
bool Frame::parted_by_normals(int x, int y, int dx, int dy) const {
  const float a = depth(x, y), b = depth(x + dx, y + dy);
  if (a == kBackground || b == kBackground) return false;
  const float footprint = camera_.pixel_footprint(std::min(a, b));
  const bool a_nearer = a < b;
  const int near_x = a_nearer ? x : x + dx, near_y = a_nearer ? y : y + dy;
  const int far_x = a_nearer ? x + dx : x, far_y = a_nearer ? y + dy : y;
  const int step_x = near_x - far_x, step_y = near_y - far_y;  // from the far pixel to the near
  // The farther surface carried on to the near pixel.
  const int beyond_x = far_x - step_x, beyond_y = far_y - step_y;
  if (!geometry_at(beyond_x, beyond_y)) return false;
  const float far_depth = depth(far_x, far_y), beyond = depth(beyond_x, beyond_y);
  const float carried_on = 2.0f * far_depth - beyond;
  if (!(carried_on - depth(near_x, near_y) >
        std::max(kPartedFootprints * footprint, 0.5f * std::fabs(far_depth - beyond)))) {
    return false;
  }
  const Vec3 near_point = position(near_x, near_y), far_point = position(far_x, far_y);
  for (int k = 1; k <= 2; ++k) {
    const int px = near_x + k * step_x, py = near_y + k * step_y;
    if (!geometry_at(px + step_x, py + step_y)) return false;
    const Vec3 n = normal(px, py);
    if (!(dot(n, normal(px + step_x, py + step_y)) > kSameFaceCos) ||
        !(std::fabs(dot(near_point - position(px, py), n)) < 0.5f * footprint)) {
      continue;
    }
    const Vec3 facing = turned_towards(n, camera_.towards_camera(near_point));
    const Vec3 apart = far_point - near_point;
    return dot(apart, facing) <
           -std::max(kPartedFootprints * footprint, kPartedSlope * length(apart));
  }
  return false;
}

// A rounded solid (a post, a sphere, a limb, a box seen at its corner) is deep where the view
// crosses its middle and thin toward its silhouettes, where the view only grazes it; a constant
// thickness darkened the surfaces just beyond a silhouette (halos) and left the middle of a big
// solid too shallow to reach what stands behind it (docs/variants.md). A run with a drop at an end
// is taken as such a solid's cross-section (rounded_depths): `across` along the pixel's row, `down`
// its column (0: no drop). Where the row's depth is less than the assumed thickness it thins it,
// down to kThinnestProfile times it; it thickens it, up to kThickestProfile times, only where the
// column's is deeper too: a horizontal slab (a shelf, a bench's slat) is wide along its row but no
// deeper than the furniture it belongs to, and its column tells nothing of that either (as the post
// measure reads rows only).
float Frame::shaped_thickness(float across, float down) const {
  const float assumed = assumed_thickness_;
  if (!(across > 0.0f)) return assumed;
  if (across < assumed) return std::max(across, kThinnestProfile * assumed);
  if (down > assumed) return std::min({across, down, kThickestProfile * assumed});
  return assumed;
}

// A solid behind a face, as deep as t, has a side face from the face's edge t back along the
// face's normal. Where the edge is one the camera sees that side across (the side, moved back
// from the edge, lands past it on screen), the pixel past the edge would show it; it shows a
// farther surface instead, so the solid is no deeper than the side that fits between the edge
// and that pixel's centre: a fence rail above the eye seen from below, a post beside the view's
// centre, a board whose end shows no end face. A shelf seen edge-on at the eye's height, or a
// round post's silhouette (its normal along the edge), gives no bound. The bound holds over the
// face: up to where another face begins along the run. One measure for every kind of edge, where
// the row-only post measure could not read columns (a shelf edge-on was taken for a rail).
void Frame::bound_by_side_face(int x, int y, int dx, int dy, int run) {
  // The face's orientation: the normal of the first pixel from the end whose normal its inner
  // neighbour shares (a renderer's Normal pass mixes the faces at a corner's pixels). normal_in:
  // k pixels in from the end; shares_next: the pixel after it (k + 1 < run) has its normal.
  const auto normal_in = [&](int k) { return normal(x - k * dx, y - k * dy); };
  const auto shares_next = [&](int k) {
    return dot(normal_in(k), normal_in(k + 1)) > kSameFaceCos;
  };
  int first = -1;
  for (int k = 0; k < 2 && k + 1 < run && first < 0; ++k) {
    if (shares_next(k)) first = k;
  }
  if (first < 0) return;
  const Vec3 n = normal_in(first);
  const Vec3 p = position(x, y), towards = camera_.towards_camera(p);
  const Vec3 facing = turned_towards(n, towards);
  // A face seen at more than about 45 degrees says nothing: what samples reach behind it is a
  // part of the scene out of sight (a bookcase's next cell behind a divider's side), which the
  // assumed thickness stands for (`cavity` at 320x180: RMSE 0.0566 -> 0.0647 with such faces
  // bounded too, 0.0567 without). It may be the side of the face before it, though.
  if (!(dot(facing, towards) > kSideFaceFacingCos)) {
    bound_by_shown_side(x, y, dx, dy, run, first, n);
    return;
  }
  // Where the side's points land on screen per unit of depth behind the face (8 pixels' worth:
  // projection is near linear over that).
  const float probe = camera_.pixel_footprint(depth(x, y)) * 8.0f;
  float u, v;
  if (!camera_.project(p - facing * probe, u, v)) return;
  const float moved = (u - (float(x) + 0.5f)) * float(dx) + (v - (float(y) + 0.5f)) * float(dy);
  if (!(moved > 1e-3f)) return;
  // That far behind the face along its normal; the caller compares planar depths along the
  // pixel's ray, which crosses the solid obliquely where the face is seen at an angle.
  const float along_ray = std::fabs(towards.z) / dot(facing, towards);
  const float bound = probe * kSideFacePixels / moved * along_ray;
  bound_up_to_next_face(x, y, dx, dy, run, first, n, bound);
}

// Over the face with normal n from pixel `face` of the run on: the end's pixels before it, then
// inward until another face begins (a pixel whose normal differs and that its inner neighbour
// shares; mixed pixels pass). Stored negated (for receivers behind the tangent plane), where it
// is less than what the pixel has.
void Frame::bound_up_to_next_face(int x, int y, int dx, int dy, int run, int face, Vec3 n,
                                  float bound) {
  for (int k = 0; k < run; ++k) {
    if (k > face && k + 1 < run && face_begins(x, y, dx, dy, k, n)) break;
    float& cell = last_thickness_[index(x - k * dx, y - k * dy)];
    if (cell == 0.0f || bound < std::fabs(cell)) cell = -bound;
  }
}

bool Frame::face_begins(int x, int y, int dx, int dy, int k, Vec3 n) const {
  const Vec3 here = normal(x - k * dx, y - k * dy);
  return !(dot(here, n) > kSameFaceCos) &&
         dot(here, normal(x - (k + 1) * dx, y - (k + 1) * dy)) > kSameFaceCos;
}

// The run's last face (normal n from pixel `first` on) is seen at a grazing angle and ends in a
// drop: where the face before it is seen near face-on, that last face is its solid's side, shown
// to its end (a rail or a box seen from above, its top face ending where the wall behind shows):
// the solid is no deeper behind the front face than that side reaches, to half a pixel past the
// run's end. Measured (docs/variants.md, item 10): `thin` at 640x360 RMSE 0.0611 -> 0.0533; the
// shelf of the development scenes, whose canisters' tops end at the back panel, 0.0903 -> 0.0917
// (the step march skips over a thin solid more often than a thicker one's doubles it up).
void Frame::bound_by_shown_side(int x, int y, int dx, int dy, int run, int first, Vec3 n) {
  // The front face: from the first pixel inward whose normal differs from the side's and that its
  // inner neighbour shares, within kShownSidePixels of the end.
  int corner = -1;
  for (int k = first + 1; k + 1 < run && k <= kShownSidePixels && corner < 0; ++k) {
    if (face_begins(x, y, dx, dy, k, n)) corner = k;
  }
  if (corner < 0) return;
  const Vec3 front = normal(x - corner * dx, y - corner * dy);
  const Vec3 c = position(x - corner * dx, y - corner * dy), towards = camera_.towards_camera(c);
  const Vec3 facing = turned_towards(front, towards);
  if (!(dot(facing, towards) > kSideFaceFacingCos)) return;
  // How far the end pixel lies behind the front face's plane; the side spans about `corner` - 0.5
  // pixels to it from the corner and goes on half a pixel past it.
  const float behind_end = dot(c - position(x, y), facing);
  if (!(behind_end > 0.0f)) return;
  const float reach = behind_end * float(corner) / (float(corner) - 0.5f);
  // Along the ray the solid spans at most the slab between the front face and the side's end:
  // over the front face, and over the side, whose rays cross the same slab.
  bound_up_to_next_face(x, y, dx, dy, run, corner, front,
                        reach * std::fabs(towards.z) / dot(facing, towards));
}

// A solid whose front face is the ray's last known hit, hidden behind the visible surface, has
// its back beyond the layers; the thickness rule would make a 6 cm column behind a fence post
// as deep as `thickness` (25 cm on the benchmark's `thin`). Where the same surface is visible
// beside the foreground, its 2nd hit is its back face: that stretch is the thickness. "The same
// surface": walking from the pixel along a row or column, every pixel up to the match (within
// kThicknessSearch) has a hit at the hidden front's depth, within 1 % plus 0.5 % a pixel of
// distance (surfaces seen at an angle), and the match shows it as its visible surface with a
// back face behind. The deepest of the four directions' matches counts, so that a thin
// neighbour does not thin a thick solid.
void Frame::infer_last_thickness(TilePool& pool, Progress& progress, bool assumed_in_plane) {
  last_thickness_.resize(pixel_count());
  if (extra_layers_ == 0) {
    measure_post_thickness(pool, progress, assumed_in_plane && assumed_thickness_ > 0.0f);
    return;
  }
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    const int count = t.x1 - t.x0;
    ScratchVector<float> last(count), stopped(count);
    for (int y = t.y0; y < t.y1; ++y) {
      float* best = last_thickness_.data() + index(t.x0, y);
      hidden_last_fronts(layers_.data() + index(t.x0, y), pixel_count(), extra_layers_, count,
                         last.data());
      std::fill_n(best, count, 0.0f);
      // Only the span of pixels with a hidden last front searches (often none of a row).
      const auto has_front = [](float l) { return l > 0.0f; };
      const int first = int(std::find_if(last.begin(), last.end(), has_front) - last.begin());
      if (first == count) continue;
      const int end =
          count - int(std::find_if(last.rbegin(), last.rend(), has_front) - last.rbegin());
      for (const auto& direction : kFourNeighbours) {
        std::fill_n(stopped.data(), count, 0.0f);
        // The span [from, to) of the pixels that may still walk: a pixel outside it has stopped,
        // has no hidden front, or has its neighbour outside the row from now on (the shift grows).
        int from = first, to = end;
        for (int d = 1; d <= kThicknessSearch; ++d) {
          const int qy = y + direction[1] * d, shift = direction[0] * d;
          if (qy < 0 || qy >= height_) break;
          // The pixels whose neighbour x + shift is inside the row.
          const int lo = std::max(from, -shift - t.x0), hi = std::min(to, width_ - shift - t.x0);
          if (lo >= hi) break;
          const size_t q = size_t(qy) * size_t(width_) + size_t(t.x0 + lo + shift);
          const float tolerance = 0.01f + 0.005f * float(d);
          if (!search_step(last.data() + lo, depth_.data() + q, layers_.data() + q, pixel_count(),
                           extra_layers_, hi - lo, tolerance, stopped.data() + lo, best + lo)) {
            break;  // every pixel of the span has stopped
          }
          for (from = lo; stopped[size_t(from)] != 0.0f;) ++from;  // search_step: one walks on
          for (to = hi; stopped[size_t(to - 1)] != 0.0f;) --to;
        }
      }
    }
  });
}

// The last known hit of each pixel when it is a front face behind the visible surface (> 0),
// else 0. Hits are in order, background after the last one.
SSAO_VECTORIZE void Frame::hidden_last_fronts(const float* layers, size_t plane, int extra_layers,
                                              int count, float* __restrict last) {
  // One pass per hit and no branch, so that each loop vectorises.
  std::fill_n(last, count, kBackground);
  for (int k = 0; k < extra_layers; ++k) {
    const float* __restrict hits = layers + size_t(k) * plane;
    for (int i = 0; i < count; ++i) last[i] = hits[i] != kBackground ? hits[i] : last[i];
  }
  for (int i = 0; i < count; ++i) {
    last[i] = ((last[i] > 0.0f) & (last[i] != kBackground)) ? last[i] : 0.0f;
  }
}

// One step of the search for pixels [0, count) of a row, their neighbours' visible depths and
// extra hits at `visible`, `layers` (planes `plane` apart). A pixel still walking its surface
// (not stopped) whose neighbour shows it as a front face closed by a back face as the next hit
// (the visible surface and the 2nd hit, or hidden as the 2nd, 3rd or 4th hit: a 5th hit is often
// a solid the neighbours see only through the same foreground) takes that solid's thickness if
// it is the deepest so far, and stops; so does one whose neighbour's ray meets no surface at its
// depth among its hits (the surface ended: beyond lies another one). Returns whether any pixel
// walks on.
SSAO_VECTORIZE bool Frame::search_step(const float* __restrict last,
                                       const float* __restrict visible, const float* layers,
                                       size_t plane, int extra_layers, int count, float tolerance,
                                       float* __restrict stopped, float* __restrict best) {
  // Hits 2 to 5; beyond the frame's extra layers, the last one again: it can neither add a
  // surface nor close a solid (a hit and the same hit behind it cannot be a front face and a
  // back face), so no match needs to know how many layers there are.
  const auto hit_plane = [&](int k) {
    return layers + size_t(std::max(0, std::min(k, extra_layers - 1))) * plane;
  };
  const float* __restrict second = hit_plane(0);
  const float* __restrict third = hit_plane(1);
  const float* __restrict fourth = hit_plane(2);
  const float* __restrict fifth = hit_plane(3);
  int walking_on = 0;
  for (int i = 0; i < count; ++i) {
    // & rather than &&: no branch, so the loop vectorises.
    const float reach = last[i] * tolerance;
    const bool on_visible = std::fabs(visible[i] - last[i]) <= reach;
    const bool on_second = std::fabs(std::fabs(second[i]) - last[i]) <= reach;
    const bool on_third = std::fabs(std::fabs(third[i]) - last[i]) <= reach;
    const bool on_fourth = std::fabs(std::fabs(fourth[i]) - last[i]) <= reach;
    const bool on_fifth = std::fabs(std::fabs(fifth[i]) - last[i]) <= reach;
    const bool near = on_visible | on_second | on_third | on_fourth | on_fifth;
    const bool walking = (stopped[i] == 0.0f) & (last[i] > 0.0f) & near;
    // A front face (positive, not background) on the searched surface, and a back face behind.
    const bool visible_match = on_visible & (visible[i] != kBackground) & (second[i] < 0.0f);
    const bool second_match =
        on_second & (second[i] > 0.0f) & (second[i] != kBackground) & (third[i] < 0.0f);
    const bool third_match =
        on_third & (third[i] > 0.0f) & (third[i] != kBackground) & (fourth[i] < 0.0f);
    const bool fourth_match =
        on_fourth & (fourth[i] > 0.0f) & (fourth[i] != kBackground) & (fifth[i] < 0.0f);
    const float thickness = visible_match  ? -second[i] - visible[i]
                            : second_match ? -third[i] - second[i]
                            : third_match  ? -fourth[i] - third[i]
                                           : -fifth[i] - fourth[i];
    // A stretch too short to take the reciprocal of (hostile, subnormal depths) says nothing.
    const bool measurable = thickness > 1e-30f;
    const bool match =
        walking & (visible_match | second_match | third_match | fourth_match) & measurable;
    best[i] = match ? std::max(best[i], thickness) : best[i];
    stopped[i] = (walking & !match) ? stopped[i] : 1.0f;
    walking_on |= int(walking & !match);
  }
  return walking_on != 0;
}

SSAO_VECTORIZE void Frame::beside_background_row(int y, int x0, int x1,
                                                 uint8_t* __restrict beside) const {
  const float* above = depth_.data() + index(0, std::max(y - 1, 0));
  const float* row = depth_.data() + index(0, y);
  const float* below = depth_.data() + index(0, std::min(y + 1, height_ - 1));
  const auto sky = [&](int x) {
    return int(above[x] == kBackground) | int(row[x] == kBackground) | int(below[x] == kBackground);
  };
  // The first and last columns have one neighbour column; the loop between reads x - 1 .. x + 1.
  const int inner0 = std::max(x0, 1), inner1 = std::max(inner0, std::min(x1, width_ - 1));
  for (int x = x0; x < inner0; ++x) {
    beside[x - x0] = uint8_t(sky(x) | sky(std::min(x + 1, width_ - 1)));
  }
  for (int x = inner0; x < inner1; ++x) {
    beside[x - x0] = uint8_t(sky(x - 1) | sky(x) | sky(x + 1));
  }
  for (int x = inner1; x < x1; ++x) beside[x - x0] = uint8_t(sky(x - 1) | sky(x));
}

bool Frame::has_geometry(int x0, int y0, int x1, int y1) const {
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      if (is_geometry(x, y)) return true;
    }
  }
  return false;
}

namespace {
// View-space normals from world-space ones: the transpose of the camera's rotation (the
// inverse-transpose of world-to-camera, so a scaled camera matrix works too; renormalised).
void normal_rotation(const FrameInputs& in, float rotation[9]) {
  const double* m = in.camera_to_world;
  const float to_view[9] = {float(m[0]), float(m[4]), float(m[8]), float(m[1]), float(m[5]),
                            float(m[9]), float(m[2]), float(m[6]), float(m[10])};
  const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::copy_n(in.world_normals ? to_view : identity, 9, rotation);
}
}  // namespace

void Frame::build(const FrameInputs& in, TilePool& pool, Progress& progress, unsigned extras) {
  assumed_thickness_ = in.assumed_thickness;
  shape_by_silhouettes_ = in.shape_thickness_by_silhouettes;
  fill_depth(in, pool, progress);
  build_normals(in, pool, progress);
  unmix_normals(pool, progress);
  derive_extras(extras, pool, progress);
}

void Frame::derive_extras(unsigned extras, TilePool& pool, Progress& progress) {
  if ((extras & kSolidThickness) != 0) {
    infer_last_thickness(pool, progress, (extras & kAssumedThickness) != 0);
  } else {
    std::vector<float>().swap(last_thickness_);
  }
  if ((extras & kPlaneDistanceScale) != 0) {
    measure_plane_distance_scale(pool, progress);
  } else {
    std::vector<float>().swap(plane_distance_scale_);
  }
  if ((extras & kCarriedSurfaces) != 0) {
    find_carried_surfaces(pool, progress);
  } else {
    std::vector<float>().swap(carried_depth_);
    std::vector<uint32_t>().swap(carried_normal_);
  }
}

void Frame::build_depth(const FrameInputs& in, TilePool& pool, Progress& progress) {
  fill_depth(in, pool, progress);
  std::vector<uint32_t>().swap(normal_);  // what a run at full resolution kept
  std::vector<uint8_t>().swap(mixed_normal_);
  derive_extras(0u, pool, progress);  // frees them all
}

void Frame::fill_depth(const FrameInputs& in, TilePool& pool, Progress& progress) {
  const float limit = in.background_limit;
  // Whole rows, so that each input plane (seven with three layers) is read as one stream: in
  // 128 x 32 tiles a layered 2048x1208 run without its kernel took 1.2x as long.
  pool.for_each_row_band(width_, height_, 8, progress, [&](const Tile& t) {
    ScratchVector<float> facing(extra_layers_ > 0 ? size_t(t.x1 - t.x0) : 0);
    for (int y = t.y0; y < t.y1; ++y) {
      float* row = depth_.data() + index(t.x0, y);
      in.depth.read_channel0(t.x0, y, t.x1 - t.x0, row);
      planar_depth_row(camera_.intrinsics(), row, t.x0, t.x1 - t.x0, float(y) + 0.5f,
                       in.radial_depth, limit);
      for (int k = 0; k < extra_layers_; ++k) {
        layer_row(in, k, t.x0, t.x1 - t.x0, y, limit, facing.data());
      }
    }
  });
}

// Normals need the neighbours' depths, so they come after every depth is known.
void Frame::build_normals(const FrameInputs& in, TilePool& pool, Progress& progress) {
  normals_from_image_ = in.normal.attached();
  normal_.resize(pixel_count());
  mixed_normal_.resize(pixel_count());
  float rotation[9];
  normal_rotation(in, rotation);
  const uint32_t facing = encode_normal({0.0f, 0.0f, 1.0f});
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    const int count = t.x1 - t.x0;
    if (!has_geometry(t.x0, t.y0, t.x1, t.y1)) {  // sky: nothing to orient
      for (int y = t.y0; y < t.y1; ++y) {
        std::fill_n(normal_.data() + index(t.x0, y), count, facing);
        std::fill_n(mixed_normal_.data() + index(t.x0, y), count, uint8_t(0));
      }
      return;
    }
    NormalRow scratch(count);
    for (int y = t.y0; y < t.y1; ++y) {
      pack_normals_row(in, rotation, *this, nullptr, nullptr, t.x0, y, count, scratch);
    }
  });
}

// On a concave crease a mixed pixel's AO must be its own surface's: with the average normal the
// estimate sees the hemisphere of a surface tilted halfway between both, which looks past the
// other wall and reads light (a light line along every wall-floor junction). Of the four
// neighbours whose normal is not mixed and on whose tangent plane the pixel lies (within
// kOwnSurfaceFootprints), the one whose normal the mix leans to most gives its normal (the
// diagonal ones as well changed the benchmark's errors by less than 1e-4), when the crease is
// concave. On a convex edge the average normal sees about the mix of both faces' AO and keeps
// it: there a switch to one face's normal as the edge moves across the pixel made the AO
// flicker on camera moves. A pixel without such a neighbour keeps its own. Only mixed pixels
// are written and only unmixed ones read, so tiles run in place and in any order.
void Frame::unmix_normals(TilePool& pool, Progress& progress) {
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < width_ && y < height_; };
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      const uint8_t* mixed = mixed_normal_.data() + index(0, y);
      for (int x = t.x0; x < t.x1; ++x) {
        if (x + 8 <= t.x1) {  // most pixels are not mixed: 8 flags at a time
          uint64_t flags;
          std::memcpy(&flags, mixed + x, sizeof flags);
          if (flags == 0) {
            x += 7;
            continue;
          }
        }
        if (!mixed[x] || !is_geometry(x, y)) continue;
        const Vec3 mix = normal(x, y), p = position(x, y);
        const float footprint = camera_.pixel_footprint(depth(x, y));
        const int neighbours[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
        float best = -2.0f;
        uint32_t chosen = 0;
        for (const auto& [qx, qy] : neighbours) {
          if (!inside(qx, qy) || mixed_normal_[index(qx, qy)] || !is_geometry(qx, qy)) continue;
          const Vec3 n = normal(qx, qy);
          if (!(std::fabs(dot(p - position(qx, qy), n)) <= kOwnSurfaceFootprints * footprint)) {
            continue;
          }
          const float lean = dot(mix, n);
          if (lean > best) best = lean, chosen = normal_[index(qx, qy)];
        }
        if (best < -1.0f) continue;  // no neighbour on the pixel's own surface
        const Vec3 own = decode_normal(chosen);
        bool concave = false;
        for (const auto& [qx, qy] : neighbours) {
          if (!inside(qx, qy) || !is_geometry(qx, qy)) continue;
          concave = concave || dot(position(qx, qy) - p, own) > kConcaveFootprints * footprint;
        }
        if (concave) normal_[index(x, y)] = chosen;
      }
    }
  });
}

// A smooth-shaded mesh's Normal pass interpolates its vertex normals over each face: on a capped
// cylinder or a box with "Shade Smooth" the normals tilt up to 45 degrees from the faces the
// depth shows. The tilt orients the hemisphere (Cycles samples its AO around it too), but as the
// surface's tangent plane it puts the surface itself above the plane: the estimate occluded the
// upper part of the benchmark's `thin` columns by 0.05 where Cycles reads 1. Along the pixel's
// row and column, the stretch of the three pixels nearest it (centred on it, or on its neighbour
// at the frame's border) is the surface's where it is straight (its halves turn by less than 10
// degrees, neither is more than twice as long as the other nor longer than kStretchFootprints
// footprints: not a crease, not a silhouette; a 32-segment sphere's normals bend by 6 degrees
// within a face) and the normals at its ends lie within 6 degrees of each other (interpolated
// vertex normals turn slowly; a bump map's turn from pixel to pixel, and there Cycles does
// occlude a closed object's face by itself: its rays below the face meet the object's inside,
// where a smooth-shaded mesh's start on the shadow terminator's offset surface).
// Where the normal tilts across one by more than 10 degrees, the surface normal
// is the normal of the plane of both stretches when both are straight, else the normal without
// its component along the one it tilts across (the surface curves across the other). Mixed
// normals (creases, silhouettes) are unmix_normals' business.
namespace {
// The stretch a -> m -> b: n's component along it over |b - a| where n tilts across it (else
// 0), whether it is straight and whether n tilts across it (1 or 0). A non-finite point
// (background) fails every comparison.
struct Tilt {
  float along, straight, tilts;
};
Tilt tilt_across(Vec3 a, Vec3 m, Vec3 b, Vec3 n, Vec3 na, Vec3 nb, float reach2) {
  const Vec3 ma = m - a, bm = b - m, ab = b - a;
  const float la2 = dot(ma, ma), lb2 = dot(bm, bm), turn = dot(ma, bm);
  const float longer = std::max(la2, lb2), shorter = std::min(la2, lb2);
  const float tilt = dot(ab, n), ab2 = dot(ab, ab);
  const bool straight = turn > 0.0f && turn * turn > Frame::kStraightCos2 * la2 * lb2 &&
                        longer < 4.0f * shorter && longer < reach2;
  // The normals na, nb at both ends agree: the slow turn of interpolated vertex normals, not a
  // bump map's.
  const bool tilts = straight && tilt * tilt > Frame::kSurfaceTiltSin2 * ab2 &&
                     dot(na, nb) > Frame::kSmoothNormalsCos;
  return {tilts ? tilt / ab2 : 0.0f, straight ? 1.0f : 0.0f, tilts ? 1.0f : 0.0f};
}
}  // namespace

Vec3 Frame::surface_normal(int x, int y) const {
  const Vec3 n = normal(x, y);
  if (!normals_from_image_ || width_ < 3 || height_ < 3 || !is_geometry(x, y) ||
      mixed_normal_[index(x, y)]) {
    return n;
  }
  const float reach = kStretchFootprints * camera_.pixel_footprint(depth(x, y));
  const int cx = std::clamp(x, 1, width_ - 2), cy = std::clamp(y, 1, height_ - 2);
  const Vec3 ax = position(cx - 1, y), bx = position(cx + 1, y);
  const Vec3 ay = position(x, cy - 1), by = position(x, cy + 1);
  const Tilt across =
      tilt_across(ax, position(cx, y), bx, n, normal(cx - 1, y), normal(cx + 1, y), reach * reach);
  const Tilt down =
      tilt_across(ay, position(x, cy), by, n, normal(x, cy - 1), normal(x, cy + 1), reach * reach);
  if (across.tilts == 0.0f && down.tilts == 0.0f) return n;
  const Vec3 chord_x = bx - ax, chord_y = by - ay;
  Vec3 turned = n - chord_x * across.along - chord_y * down.along;
  if (across.straight > 0.0f && down.straight > 0.0f) {
    const Vec3 plane = cross(chord_y, chord_x);
    turned = turned_towards(plane, n);
  }
  const float length2 = dot(turned, turned);
  return length2 > 0.0f ? turned * (1.0f / std::sqrt(length2)) : n;
}

Frame::NormalRow::NormalRow(int count)
    : nx(count, 0.0f), ny(count, 0.0f), nz(count, 0.0f), usable(count), mixed(count) {}

// Normals of pixels [x0, x0 + count) of row y, packed into this frame's plane: the normal
// image's at (xs[i], ys[i]) of `source`'s pixel grid (this row's own pixels when xs is null),
// rotated to view space and turned to the camera along this frame's rays. A missing, zero or
// non-finite normal (Blender writes 0 on background and blends on silhouettes) falls back to
// the one reconstructed from `source`'s depth, on geometry pixels.
void Frame::pack_normals_row(const FrameInputs& in, const float* rotation, const Frame& source,
                             const int32_t* xs, const int32_t* ys, int x0, int y, int count,
                             NormalRow& scratch) {
  const auto source_x = [&](int i) { return xs != nullptr ? xs[i] : x0 + i; };
  const auto source_y = [&](int i) { return ys != nullptr ? ys[i] : y; };
  if (in.normal.attached()) {
    for (int i = 0; i < count; ++i) {
      const float* p = in.normal.pixel(source_x(i), source_y(i));
      scratch.nx[i] = p[0], scratch.ny[i] = p[1], scratch.nz[i] = p[2];
    }
  }
  const size_t row = index(x0, y);
  encode_normal_row(rotation, float(y) + 0.5f, x0, count, scratch.nx.data(), scratch.ny.data(),
                    scratch.nz.data(), scratch.usable.data(), scratch.mixed.data(),
                    normal_.data() + row);
  // Flags of 32 bits in encode_normal_row (one width for all its lanes: it vectorises), 8 here.
  std::copy_n(scratch.mixed.data(), count, mixed_normal_.data() + row);
  for (int i = 0; i < count; ++i) {
    if (scratch.usable[i] || depth_[row + i] == kBackground) continue;
    normal_[row + i] = encode_normal(source.reconstructed_normal(source_x(i), source_y(i)));
  }
}

// Normals of one row: rotated to view space, normalised, turned towards the camera (shading
// normals of back faces point away from it; AO is about the visible side) and packed. A loop
// without calls or branches, which the compiler vectorises; usable[i] = 0 where the normal is
// zero or not finite, mixed[i] = 1 where it is usable and shorter than kMixedNormalLength.
SSAO_VECTORIZE void Frame::encode_normal_row(const float* rotation, float v, int x0, int count,
                                             const float* __restrict nx, const float* __restrict ny,
                                             const float* __restrict nz,
                                             uint32_t* __restrict usable,
                                             uint32_t* __restrict mixed,
                                             uint32_t* __restrict out) const {
  const CameraIntrinsics cam = camera_.intrinsics();
  const float r0 = rotation[0], r1 = rotation[1], r2 = rotation[2], r3 = rotation[3],
              r4 = rotation[4], r5 = rotation[5], r6 = rotation[6], r7 = rotation[7],
              r8 = rotation[8];
  // The direction towards the camera, per unit of depth (branches on the camera type stay out of
  // the loop, so it vectorises).
  const float towards_x = cam.orthographic ? 0.0f : -cam.scale_u;
  const float towards_y = cam.orthographic ? 0.0f : -(cam.center_v - v) * cam.scale_v;
  for (int i = 0; i < count; ++i) {
    float x = r0 * nx[i] + r1 * ny[i] + r2 * nz[i];
    float y = r3 * nx[i] + r4 * ny[i] + r5 * nz[i];
    float z = r6 * nx[i] + r7 * ny[i] + r8 * nz[i];
    const float length2 = x * x + y * y + z * z;
    const bool ok = length2 > 1e-40f && length2 <= 3.4e38f;  // false for NaN and infinity
    const float inv = ok ? 1.0f / std::sqrt(ok ? length2 : 1.0f) : 0.0f;
    x *= inv, y *= inv, z *= inv;
    // Towards the camera is -position (perspective) or +z (orthographic).
    const float facing = x * (float(x0 + i) + 0.5f - cam.center_u) * towards_x + y * towards_y + z;
    const float flip = facing < 0.0f ? -1.0f : 1.0f;
    usable[i] = ok ? 1 : 0;
    // The image's own length: a scaled camera matrix scales the rotated one.
    const float input_length2 = nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i];
    mixed[i] = ok && input_length2 < kMixedNormalLength * kMixedNormalLength ? 1 : 0;
    out[i] = encode_normal({x * flip, y * flip, ok ? z * flip : 1.0f});
  }
}

// Hit k + 2 of a row, after the row's visible depths: planar, checked to lie behind the hit
// before it, the facing folded into the sign. Without a facing image the hits are taken to
// alternate: the 2nd a back face, the 3rd a front face, ...
void Frame::layer_row(const FrameInputs& in, int k, int x0, int count, int y, float limit,
                      float* facing) {
  float* row = layers_.data() + size_t(k) * pixel_count() + index(x0, y);
  const float* before = k == 0 ? depth_.data() + index(x0, y) : row - pixel_count();
  in.layers[k].read_channel0(x0, y, count, row);
  planar_depth_row(camera_.intrinsics(), row, x0, count, float(y) + 0.5f, in.radial_depth, limit);
  // Hit k as the facing image says, else alternating (the 2nd a back face, the 3rd a front...).
  if (in.facing[k].attached()) {
    in.facing[k].read_channel0(x0, y, count, facing);
  } else {
    std::fill_n(facing, count, k % 2 == 0 ? 1.0f : 0.0f);
  }
  const int out_of_order = pack_layer_row(depth_.data() + index(x0, y), before, facing, count, row);
  if (out_of_order >= 0) {
    const auto name = [](int layer) {
      return layer == 1 ? std::string("depth") : "depth" + std::to_string(layer);
    };
    const float previous = std::fabs(before[out_of_order]);
    throw_invalid_argument(
        "image '" + name(k + 2) + "' at pixel (" + std::to_string(x0 + out_of_order) + ", " +
        std::to_string(y) + ") is nearer than '" + name(k + 1) + "' (" +
        (previous == kBackground ? std::string("no hit") : std::to_string(previous)) +
        " planar): extra depth layers must be the hits behind the visible surface, in order");
  }
}

// A row of hit k in place: planar depth, negated on a back face (facing >= 0.5), background
// where the pixel is. Returns the first pixel whose hit is nearer than the hit before it (by
// more than kLayerOrderTolerance), or -1. Branch-free, so the loop vectorises.
SSAO_VECTORIZE int Frame::pack_layer_row(const float* __restrict depth,
                                         const float* __restrict before,
                                         const float* __restrict facing, int count,
                                         float* __restrict row) {
  // `&`, not `&&`: unconditional loads. With `&&` GCC loads `before` under a mask that keeps
  // stale lanes, and a stale denormal in the multiply cost a microcode assist per vector: 80 %
  // of the loop's time (the same run with denormals-are-zero set was as fast as this one).
  const auto out_of_order = [&](int i) {
    return (depth[i] != kBackground) & (row[i] != kBackground) &
           !(row[i] >= std::fabs(before[i]) * (1.0f - kLayerOrderTolerance));
  };
  int any = 0;
  for (int i = 0; i < count; ++i) any |= int(out_of_order(i));
  if (any != 0) {
    for (int i = 0; i < count; ++i) {
      if (out_of_order(i)) return i;
    }
  }
  for (int i = 0; i < count; ++i) {
    const float hit = std::max(row[i], std::fabs(before[i]));
    const bool back = facing[i] >= 0.5f && hit != kBackground;
    row[i] = depth[i] != kBackground ? (back ? -hit : hit) : kBackground;
  }
  return -1;
}

// The nearest of each 2x2 block of two full-resolution rows: `count` blocks of columns 2 i and
// 2 i + 1; its depth, and which corner it is (0, 1 on the top row, 2, 3 on the bottom; the first
// on ties). Selects only, so the loop vectorises.
SSAO_VECTORIZE void Frame::nearest_of_blocks(const float* __restrict top,
                                             const float* __restrict bottom, int count,
                                             float* __restrict depth, int32_t* __restrict corner) {
  for (int i = 0; i < count; ++i) {
    float nearest = top[2 * i];
    int32_t which = 0;
    const float candidates[3] = {top[2 * i + 1], bottom[2 * i], bottom[2 * i + 1]};
    for (int c = 0; c < 3; ++c) {
      which = candidates[c] < nearest ? c + 1 : which;
      nearest = candidates[c] < nearest ? candidates[c] : nearest;
    }
    depth[i] = nearest;
    corner[i] = which;
  }
}

void Frame::downsample(const Frame& full, const FrameInputs& in, TilePool& pool, Progress& progress,
                       unsigned extras) {
  reset(full.camera().coarser(2), (full.width() + 1) / 2, (full.height() + 1) / 2,
        full.extra_layers());
  assumed_thickness_ = in.assumed_thickness;
  shape_by_silhouettes_ = in.shape_thickness_by_silhouettes;
  normals_from_image_ = in.normal.attached();
  normal_.resize(pixel_count());
  mixed_normal_.resize(pixel_count());
  float rotation[9];
  normal_rotation(in, rotation);
  const uint32_t facing = encode_normal({0.0f, 0.0f, 1.0f});
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    const int count = t.x1 - t.x0;
    NormalRow scratch(count);
    ScratchVector<int32_t> corner(count), chosen_x(count), chosen_y(count);
    for (int y = t.y0; y < t.y1; ++y) {
      // The nearest pixel of each block: thin foreground survives, and a block on a silhouette
      // takes one surface's depth and normal, never a blend of two. A last row or column past
      // the full frame's edge repeats the one before it (it cannot win: ties keep the first).
      const int top = 2 * y, bottom = std::min(2 * y + 1, full.height() - 1);
      const int pairs = std::min(t.x1, full.width() / 2) - t.x0;  // blocks with two columns
      float* depth = depth_.data() + index(t.x0, y);
      nearest_of_blocks(full.depth_.data() + full.index(2 * t.x0, top),
                        full.depth_.data() + full.index(2 * t.x0, bottom), pairs, depth,
                        corner.data());
      for (int i = std::max(pairs, 0); i < count; ++i) {  // the odd last column
        const float a = full.depth(2 * (t.x0 + i), top), b = full.depth(2 * (t.x0 + i), bottom);
        depth[i] = b < a ? b : a;
        corner[i] = b < a ? 2 : 0;
      }
      for (int i = 0; i < count; ++i) {
        chosen_x[i] = 2 * (t.x0 + i) + (corner[i] & 1);
        chosen_y[i] = corner[i] >= 2 ? bottom : top;
      }
      for (int k = 0; k < extra_layers_; ++k) {
        const float* hits = full.layers_.data() + size_t(k) * full.pixel_count();
        float* row = layers_.data() + size_t(k) * pixel_count() + index(t.x0, y);
        for (int i = 0; i < count; ++i) {
          row[i] =
              depth[i] == kBackground ? kBackground : hits[full.index(chosen_x[i], chosen_y[i])];
        }
      }
      // Only the chosen pixels' normals are read and packed: a quarter of the full frame's.
      // They are turned towards the camera along this frame's pixel rays, the rays on which
      // the variants place them.
      pack_normals_row(in, rotation, full, chosen_x.data(), chosen_y.data(), t.x0, y, count,
                       scratch);
      uint32_t* normals = normal_.data() + index(t.x0, y);
      for (int i = 0; i < count; ++i) {
        if (depth[i] == kBackground) normals[i] = facing;
      }
    }
  });
  unmix_normals(pool, progress);
  derive_extras(extras, pool, progress);
}

float background_limit(double background_depth, double clip_end) {
  const double limit = clip_end > 0.0 ? std::min(background_depth, clip_end) : background_depth;
  return static_cast<float>(std::min(limit, double(std::numeric_limits<float>::max())));
}

// Planar depth from the caller's values in place: radial ones divided by the ray length per unit
// of planar depth, background marked. A loop without calls or branches, which the compiler
// vectorises (NaN fails every comparison, so it is background).

SSAO_VECTORIZE void Frame::planar_depth_row(const CameraIntrinsics& cam, float* __restrict depth,
                                            int x0, int count, float v, bool radial, float limit) {
  const float perspective_radial = radial && !cam.orthographic ? 1.0f : 0.0f;
  const float y = (cam.center_v - v) * cam.scale_v;
  for (int i = 0; i < count; ++i) {
    const float x = (float(x0 + i) + 0.5f - cam.center_u) * cam.scale_u;
    // radial = planar * sqrt(x^2 + y^2 + 1) at unit depth; 1 when not converting.
    const float factor = std::sqrt(perspective_radial * (x * x + y * y) + 1.0f);
    const float d = depth[i] / factor;
    depth[i] = d > 0.0f && d < limit ? d : kBackground;
  }
}

// Cross product of the screen-space tangents, each taken on the side whose depth is closer to
// the centre's, so that silhouettes do not bend the normal of the surface behind them.
Vec3 Frame::reconstructed_normal(int x, int y) const {
  const Vec3 p = position(x, y);
  const float d = depth(x, y);
  auto tangent = [&](int dx, int dy, Vec3& out) {
    const int xa = x - dx, ya = y - dy, xb = x + dx, yb = y + dy;
    const bool a_ok = geometry_at(xa, ya), b_ok = geometry_at(xb, yb);
    if (!a_ok && !b_ok) return false;
    bool use_b = b_ok;
    if (a_ok && b_ok) use_b = std::fabs(depth(xb, yb) - d) < std::fabs(depth(xa, ya) - d);
    out = use_b ? position(xb, yb) - p : p - position(xa, ya);
    return true;
  };
  Vec3 along_x, along_down;
  const Vec3 towards_camera = camera_.towards_camera(p);
  if (!tangent(1, 0, along_x) || !tangent(0, 1, along_down)) return towards_camera;
  // x grows to the right and y grows downwards, so cross(down, right) faces the camera.
  Vec3 n = normalize_or(cross(along_down, along_x), towards_camera);
  if (dot(n, towards_camera) < 0.0f) n = -n;
  return n;
}

}  // namespace ssao
