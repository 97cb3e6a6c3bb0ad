// SPDX-License-Identifier: MIT
// The frame the variants read: one plane of planar depth (+inf = background) and one plane of
// packed unit normals, prepared once per run from the caller's depth (and normal) images.
// Positions are reconstructed from depth on the fly: two multiplies are cheaper than the memory
// traffic of a stored position, and the two planes are 8 bytes a pixel (with one layer, two
// more for the surfaces carried on behind silhouettes: carried_depth_plane).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "camera.h"
#include "image_view.h"
#include "scratch.h"
#include "tiles.h"
#include "vec3.h"

namespace ssao {

// Extra depth layers: the 2nd, 3rd, ... surface hit along each pixel's ray (ssao.h "depth2").
constexpr int kMaxExtraLayers = 4;

struct FrameInputs {
  ImageView depth;
  ImageView normal;  // optional (data == nullptr: reconstruct from depth)
  // layers[k] is hit k + 2, in the depth image's convention; facing[k] optional (channel 0,
  // >= 0.5: a back face). The first extra_layers are attached.
  ImageView layers[kMaxExtraLayers];
  ImageView facing[kMaxExtraLayers];
  int extra_layers = 0;
  bool radial_depth = false;
  bool world_normals = true;
  double camera_to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  // The background rule (ssao.h): a planar depth d is geometry when 0 < d < background_limit.
  float background_limit = 1e9f;
  // Without extra layers, the depth assumed for the visible surfaces' solids (view units; 0:
  // none), which kAssumedThickness folds into last_thickness_plane, shaped by the silhouettes
  // where shape_thickness_by_silhouettes (Frame::shaped_thickness).
  float assumed_thickness = 0.0f;
  bool shape_thickness_by_silhouettes = false;
};

// background_limit from the parameters background_depth and clip_end (0: no clip).
float background_limit(double background_depth, double clip_end);

// What Frame::build derives from the depth and normals for the variants' sample tests; a variant
// declares the ones it reads (VariantInfo::frame_extras) and the others' scans are skipped.
enum FrameExtras : unsigned {
  kSolidThickness = 1u,      // last_thickness_plane
  kPlaneDistanceScale = 2u,  // plane_distance_scale_plane (with extra layers)
  kCarriedSurfaces = 4u,     // carried_depth_plane, carried_normal_plane (with one layer)
  kAssumedThickness = 8u,    // one layer: the assumed thickness folded into last_thickness_plane
  kAllFrameExtras = 15u,
};

// Unit vector <-> 32 bits: octahedral mapping with 16 bits per coordinate (error < 1e-4 rad).
// Both directions are branch-free (the lower half folded over the diagonals by a signed
// offset), so loops over pixels vectorise.
// v in [-1, 1] rounded to 16 bits (two's complement) in the low half of the result.
inline uint32_t snorm16(float v) {
  // NaN (an unusable normal, which the caller replaces) clamps to -1: converting NaN to an
  // integer is undefined behaviour (found by tests/fuzz/fuzz_api). Other values as before.
  const float clamped = v >= -1.0f ? (v <= 1.0f ? v : 1.0f) : -1.0f;
  const float scaled = clamped * 32767.0f;
  return uint32_t(int32_t(scaled + (scaled >= 0.0f ? 0.5f : -0.5f))) & 0xffffu;
}
inline uint32_t encode_normal(Vec3 n) {
  const float l1 = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  const float u = n.x / l1, v = n.y / l1;
  // The lower half is folded over the diagonals: (1 - |v|, 1 - |u|) with the signs of (u, v).
  const float fold_u = std::copysign(1.0f - std::fabs(v), u);
  const float fold_v = std::copysign(1.0f - std::fabs(u), v);
  const bool lower = n.z < 0.0f;
  return snorm16(lower ? fold_u : u) | (snorm16(lower ? fold_v : v) << 16);
}
inline Vec3 decode_normal(uint32_t bits) {
  // Sign-extended halves, in 32-bit arithmetic only (vectorises without AVX-512BW).
  const float u = float(int32_t(bits << 16) >> 16) * (1.0f / 32767.0f);
  const float v = float(int32_t(bits) >> 16) * (1.0f / 32767.0f);
  const float z = 1.0f - std::fabs(u) - std::fabs(v);
  const float fold = z < 0.0f ? -z : 0.0f;
  const Vec3 n{u >= 0.0f ? u - fold : u + fold, v >= 0.0f ? v - fold : v + fold, z};
  return n * (1.0f / std::sqrt(dot(n, n)));
}

// The offsets (dx, dy) of a pixel's four neighbours: right, left, below, above.
inline constexpr int kFourNeighbours[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};

class Frame {
 public:
  static constexpr float kBackground = std::numeric_limits<float>::infinity();

  // The caller's depths of pixels [x0, x0 + count) of a row (v: the row's centre) as planar
  // depth in place, kBackground where the background rule says so: the library's one test of
  // what is geometry (ssao.h), for the frame and for the automatic radius.
  static void planar_depth_row(const CameraIntrinsics& camera, float* depth, int x0, int count,
                               float v, bool radial, float limit);

  Frame() = default;
  // Sizes the planes for a frame (keeping their memory when the size is unchanged, so a job
  // that runs frame after frame allocates once).
  void reset(const CameraModel& camera, int width, int height, int extra_layers = 0);

  // Fills the depth plane, then the normals (from the normal image or reconstructed from depth),
  // then the `extras` (FrameExtras) asked for; the planes of the others are left empty.
  void build(const FrameInputs& in, TilePool& pool, Progress& progress,
             unsigned extras = kAllFrameExtras);
  // The depth plane (and extra layers) alone: what a frame estimated at half resolution needs
  // of the full one. It has no normal plane (one a previous run kept is freed).
  void build_depth(const FrameInputs& in, TilePool& pool, Progress& progress);

  // This frame at half resolution: each 2x2 block becomes one pixel with the depth and normal
  // of its nearest geometry pixel (background if it has none), seen through full.camera()
  // made twice as coarse. `full` needs its depth only; the normals are read from `in`. `extras`
  // as for build.
  void downsample(const Frame& full, const FrameInputs& in, TilePool& pool, Progress& progress,
                  unsigned extras = kAllFrameExtras);

  int width() const { return width_; }
  int height() const { return height_; }
  const CameraModel& camera() const { return camera_; }
  size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }

  // Planar depth plane, row-major; kBackground where there is no geometry.
  const float* depth_plane() const { return depth_.data(); }
  float depth(int x, int y) const { return depth_[index(x, y)]; }
  bool is_geometry(int x, int y) const { return depth_[index(x, y)] != kBackground; }
  // Inside the frame and geometry.
  bool geometry_at(int x, int y) const {
    return x >= 0 && y >= 0 && x < width_ && y < height_ && is_geometry(x, y);
  }
  Vec3 position(int x, int y) const {
    return camera_.view_position(float(x) + 0.5f, float(y) + 0.5f, depth(x, y));
  }
  Vec3 normal(int x, int y) const { return decode_normal(normal_[index(x, y)]); }
  const uint32_t* normal_plane() const { return normal_.data(); }
  // The normal of the surface the depth shows, for the tests of what lies above a receiver's
  // tangent plane: the normal, except where a normal image's tilts across a straight stretch of
  // the surface (a smooth-shaded mesh interpolates its vertex normals over each face; see
  // frame.cpp). Computed when asked; the hemisphere's vector path computes the same on its lanes.
  Vec3 surface_normal(int x, int y) const;
  // 1 where the normal image's normal was a mix of surfaces (a crease or a silhouette: left to
  // unmix_normals), else 0.
  const uint8_t* mixed_normal_plane() const { return mixed_normal_.data(); }
  // Whether the normals came from a normal image (else from the depth: on its surface already).
  bool normals_from_image() const { return normals_from_image_; }
  // surface_normal's thresholds: a tilt of more than 10 degrees (sin^2), across a stretch of three
  // pixels turning by less than 10 degrees (cos^2) and at most 8 footprints long, whose ends'
  // normals lie within 6 degrees of each other (cos).
  static constexpr float kSurfaceTiltSin2 = 0.0301536896f;
  static constexpr float kStraightCos2 = 0.9698463104f;
  static constexpr float kStretchFootprints = 8.0f;
  static constexpr float kSmoothNormalsCos = 0.9945218954f;

  // For pixels [x0, x1) of row y: 1 where one of the (up to 8) pixels around is background, else
  // 0. A row at a time: the composite asks it of every pixel.
  void beside_background_row(int y, int x0, int x1, uint8_t* beside) const;

  // Whether rows [y0, y1) x columns [x0, x1) show any geometry (false: all sky).
  bool has_geometry(int x0, int y0, int x1, int y1) const;

  // Extra depth layers: extra_layers() planes of pixel_count() floats, hit k + 2 in plane k:
  // the planar depth, negated on a back face, +inf where the ray has no such hit (and on
  // background pixels). Hits are in order along the ray.
  int extra_layers() const { return extra_layers_; }
  const float* layer_planes() const { return layers_.data(); }
  size_t pixel_count() const { return size_t(width_) * size_t(height_); }
  // Where a point at planar depth `depth` on pixel (x, y)'s ray stands among the surfaces the
  // ray crosses: returns the depth of the front face it lies behind (the entry into a solid),
  // +inf when it is in front of the visible surface or in free space behind a back face.
  // `closed`: a back face follows the point on the ray, so the point is inside the solid; else
  // nothing closes it and the caller assumes a thickness. Without extra layers: the visible
  // surface's depth (closed = false) when the point is behind it. `past_last` (optional): the
  // point lies behind the ray's last known hit.
  float solid_entry(int x, int y, float depth, bool& closed, bool* past_last = nullptr) const;

  // Per pixel: how deep the solid entered at the ray's last known hit is; 0 where nothing says
  // (the caller's assumed thickness applies). With extra layers, where that hit is a front face
  // hidden behind the visible surface and no later hit closes it (a column behind a fence post
  // whose back would be hit 4), as measured where a neighbour within kThicknessSearch pixels
  // sees a surface at that depth with its back face. Without them the last hit is the visible
  // surface, and the plane holds bounds on the assumed thickness: on something narrow
  // across its row (a post), a depth taken from its width (measure_post_thickness); stored
  // negated, how deep the face can be without showing the side face a deeper solid would
  // (bound_by_side_face), which holds for a receiver behind the face's tangent plane only (one
  // in front reaches a point behind the face through it, whatever its depth). With
  // kAssumedThickness those are folded with the assumed thickness (FrameInputs, shaped by the
  // silhouettes where asked), so that the plane holds the depth itself: a bound where less than
  // the assumed depth (a side-face bound stays negated; a receiver in front of its face takes
  // FrameInputs's thickness), else the assumed depth where it is not FrameInputs's, else 0.
  const float* last_thickness_plane() const {
    return last_thickness_.empty() ? nullptr : last_thickness_.data();
  }
  // The depth that holds for every receiver (0: none).
  float last_thickness(int x, int y) const {
    return last_thickness_.empty() ? 0.0f : std::max(last_thickness_[index(x, y)], 0.0f);
  }
  // The depth that holds for a receiver at p (0: none).
  float last_thickness_seen_from(int x, int y, Vec3 p) const {
    const float t = last_thickness_.empty() ? 0.0f : last_thickness_[index(x, y)];
    if (!(t < 0.0f)) return t;
    return dot(p - position(x, y), normal(x, y)) < 0.0f ? -t : 0.0f;
  }
  static constexpr int kThicknessSearch = 8;

  // FrameInputs::assumed_thickness shaped by the silhouettes stays within these multiples of it
  // (shaped_thickness).
  static constexpr float kThinnestProfile = 0.5f, kThickestProfile = 1.5f;

  // With extra layers, per pixel: how far from the visible surface's tangent plane a point on
  // the pixel's ray lies per unit of planar depth it lies behind or in front of the surface
  // (|normal . ray| with the ray's z = -1); 0 on background. Null without extra layers.
  const float* plane_distance_scale_plane() const {
    return plane_distance_scale_.empty() ? nullptr : plane_distance_scale_.data();
  }
  float plane_distance_scale(int x, int y) const {
    return plane_distance_scale_.empty() ? 0.0f : plane_distance_scale_[index(x, y)];
  }

  // Without extra layers, per pixel: the planar depth at which the pixel's ray meets the surfaces
  // beyond the silhouettes around it, carried on behind the object as their tangent planes (the
  // floor going on under a sphere): walking from the pixel along its row and its column, the
  // first step onto a surface more than kCarryJump farther, on each of the four sides, within
  // kCarrySearch pixels or as far as that surface was seen on its plane beyond the step
  // (kCarryFlatReach); of their planes that the ray meets more than kCarryJump behind the pixel's
  // own surface, the nearest; kBackground where none. Null with extra layers (they show the hidden
  // surfaces) or without normals.
  const float* carried_depth_plane() const {
    return carried_depth_.empty() ? nullptr : carried_depth_.data();
  }
  float carried_depth(int x, int y) const {
    return carried_depth_.empty() ? kBackground : carried_depth_[index(x, y)];
  }
  // The carried surface's packed normal (encode_normal), where carried_depth is not background.
  const uint32_t* carried_normal_plane() const {
    return carried_normal_.empty() ? nullptr : carried_normal_.data();
  }
  Vec3 carried_normal(int x, int y) const { return decode_normal(carried_normal_[index(x, y)]); }
  static constexpr int kCarrySearch = 24;
  // How far a surface is carried at most, as a fraction of the frame's larger side; within that,
  // as far as the surface was seen beyond the step on its plane, to within kCarryFlatTolerance of
  // the depth.
  static constexpr float kCarryFlatReach = 0.15f;
  static constexpr float kCarryFlatTolerance = 0.01f;
  // The farthest a plane is carried, in pixels: kCarryFlatReach of the frame, at least
  // kCarrySearch.
  int carry_search() const;
  static constexpr float kCarryJump = 1.05f;

 private:
  Vec3 reconstructed_normal(int x, int y) const;
  void fill_depth(const FrameInputs& in, TilePool& pool, Progress& progress);
  void build_normals(const FrameInputs& in, TilePool& pool, Progress& progress);
  // Gives each pixel whose normal is a mix of surfaces (mixed_normal_) on a concave crease the
  // normal of the neighbour on its own surface that the mix leans to most (see frame.cpp).
  void unmix_normals(TilePool& pool, Progress& progress);
  // A row's normal image values, as planes, before they are packed.
  struct NormalRow {
    explicit NormalRow(int count);
    ScratchVector<float> nx, ny, nz;
    ScratchVector<uint32_t> usable, mixed;
  };
  void pack_normals_row(const FrameInputs& in, const float* rotation, const Frame& source,
                        const int32_t* xs, const int32_t* ys, int x0, int y, int count,
                        NormalRow& scratch);
  static void nearest_of_blocks(const float* top, const float* bottom, int count, float* depth,
                                int32_t* corner);
  void encode_normal_row(const float* rotation, float v, int x0, int count, const float* nx,
                         const float* ny, const float* nz, uint32_t* usable, uint32_t* mixed,
                         uint32_t* out) const;

  // The extras (FrameExtras) from the finished depth, normal and layer planes; the planes of
  // the others are freed.
  void derive_extras(unsigned extras, TilePool& pool, Progress& progress);
  // Fills last_thickness_ from the finished depth and layer planes; `assumed_in_plane`: with one
  // layer, folds the assumed thickness in (kAssumedThickness).
  void infer_last_thickness(TilePool& pool, Progress& progress, bool assumed_in_plane);
  void measure_post_thickness(TilePool& pool, Progress& progress, bool assumed_in_plane);
  // The assumed thickness at a pixel whose rounded depths along its row and column are `across`
  // and `down` (0: no silhouette).
  float shaped_thickness(float across, float down) const;
  // Whether, of pixel (x, y) and its neighbour (x + dx, y + dy), the nearer passes in front of
  // the farther by what the normals and the depths beyond tell, where the depth step alone is too
  // small to end a run (see frame.cpp). Called for every pair of neighbours a run joins: the
  // common case, a step of less than the margin, is answered inline.
  bool passes_in_front(int x, int y, int dx, int dy) const {
    const float a = depth(x, y), b = depth(x + dx, y + dy);
    return std::fabs(a - b) > kPartedFootprints * camera_.pixel_footprint(std::min(a, b)) &&
           parted_by_normals(x, y, dx, dy);
  }
  bool parted_by_normals(int x, int y, int dx, int dy) const;
  // passes_in_front's margins: in pixel footprints, and over the two points' distance.
  static constexpr float kPartedFootprints = 1.0f, kPartedSlope = 0.1f;
  // Where a run of pixels on one surface ends at (x, y), the surface dropping away to (x + dx,
  // y + dy): bounds the depth of its last face's solid (last_thickness_plane, negated).
  void bound_by_side_face(int x, int y, int dx, int dy, int run);
  // The same where the run's last face, seen at a grazing angle, is the side of the face before it
  // (from pixel `first` on, normal n), shown up to the end.
  void bound_by_shown_side(int x, int y, int dx, int dy, int run, int first, Vec3 n);
  void bound_up_to_next_face(int x, int y, int dx, int dy, int run, int face, Vec3 n, float bound);
  // Whether pixel k in from a run's end (x, y) begins a face other than n's: its normal differs
  // and its inner neighbour (k + 1, inside the run) shares it.
  bool face_begins(int x, int y, int dx, int dy, int k, Vec3 n) const;
  // How far in from the run's end the face before the side is looked for.
  static constexpr int kShownSidePixels = 16;
  // A side face this deep would reach this far past the face's edge on screen: half the way to
  // the next pixel's centre, the edge's expected place between the two.
  static constexpr float kSideFacePixels = 0.5f;
  // Two normals within about 6 degrees: one face (a corner's pixels mix two faces' normals).
  static constexpr float kSameFaceCos = 0.995f;
  // Faces seen within about 45 degrees of face-on are bounded.
  static constexpr float kSideFaceFacingCos = 0.7f;
  // Fills plane_distance_scale_ from the finished depth and normal planes.
  void measure_plane_distance_scale(TilePool& pool, Progress& progress);
  void plane_distance_scale_row(int x0, int count, int y, float* out) const;
  // Fills carried_depth_ from the finished depth and normal planes.
  void find_carried_surfaces(TilePool& pool, Progress& progress);
  static void hidden_last_fronts(const float* layers, size_t plane, int extra_layers, int count,
                                 float* last);
  static bool search_step(const float* last, const float* visible, const float* layers,
                          size_t plane, int extra_layers, int count, float tolerance,
                          float* stopped, float* best);

  // Hit k of pixels [x0, x0 + count) of row y into its plane; `facing`: scratch of count floats.
  void layer_row(const FrameInputs& in, int k, int x0, int count, int y, float limit,
                 float* facing);
  static int pack_layer_row(const float* depth, const float* before, const float* facing, int count,
                            float* row);

  CameraModel camera_{CameraParams{}, 1, 1};
  int width_ = 0, height_ = 0, extra_layers_ = 0;
  std::vector<float> depth_;
  std::vector<uint32_t> normal_;
  // 1 where the normal image's normal was shorter than kMixedNormalLength (a pixel filtered over
  // two surfaces), else 0 (background pixels may have either); sized with normal_.
  std::vector<uint8_t> mixed_normal_;
  bool normals_from_image_ = false;  // the normals came from a normal image, not the depth
  std::vector<float> layers_;
  std::vector<float> last_thickness_;
  float assumed_thickness_ = 0.0f;     // FrameInputs::assumed_thickness
  bool shape_by_silhouettes_ = false;  // FrameInputs::shape_thickness_by_silhouettes
  std::vector<float> plane_distance_scale_;
  std::vector<float> carried_depth_;
  std::vector<uint32_t> carried_normal_;
};

}  // namespace ssao
