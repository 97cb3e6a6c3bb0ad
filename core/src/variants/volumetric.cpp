// SPDX-License-Identifier: MIT
// Line-integral (volumetric) obscurance (Loos & Sloan 2010; the Toy Story 3 technique in the
// seeds): the fraction of a sphere of the AO radius around the receiver that lies behind the
// depth buffer, estimated along view rays that cover the sphere's silhouette, each standing for
// the volume of its cone (perspective) or cylinder (orthographic) inside the sphere.
// Each ray's chord through the sphere comes from a real ray-sphere intersection, so walls at the
// side of a perspective view read like walls in its middle (the seed's orthographic
// right-triangle chord darkens them). A flat open surface has half the sphere behind it: the
// empty fraction is doubled and clamped, so it reads 1, a concave crease 1/2 and a convex ridge
// 1 (it is not brightened).
//
// Two implementations of one estimator, as in hemisphere.cpp: `pixel()`, scalar, the reference
// the tests hold the fast path to, and `volumetric_row()`, the same arithmetic on as many
// pixels of a row at once as the CPU's vectors hold (Google Highway, chosen at run time).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "variants/volumetric.cpp"
#include <hwy/foreach_target.h>  // re-includes this file once per target
#include <hwy/highway.h>

#include "variants/frame_simd-inl.h"

#ifndef SSAO_VOLUMETRIC_ROW_ARGS
#define SSAO_VOLUMETRIC_ROW_ARGS
#include <algorithm>
#include <cstdint>
#include <limits>

#include "camera.h"
#include "sampling.h"
#include "variants/lane_table.h"

namespace ssao {
struct DiskPoint {
  float x, y;  // on the unit disk
};

struct VolumetricRowArgs {
  const float* depth;       // the frame's depth plane
  const uint32_t* normals;  // the frame's packed normals
  int width, height;
  CameraIntrinsics camera;
  float radius, thickness;
  int pairs;
  // Per row class (y & 3), per pair, x then y of the first member's disk point for kLaneTable
  // lanes starting at a pixel whose x is a multiple of 4.
  const float* lane_disk;
};
}  // namespace ssao
#endif

HWY_BEFORE_NAMESPACE();
namespace ssao {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Visibility of pixels [x0, x1) of row y into out[0 .. x1 - x0): Volumetric::pixel() on as many
// pixels as a vector holds.
void volumetric_row(const VolumetricRowArgs& a, int y, int x0, int x1, float* out) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VF = hn::Vec<decltype(df)>;
  const int lanes = int(hn::Lanes(df));
  const CameraIntrinsics& cam = a.camera;
  const bool ortho = cam.orthographic;
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f);
  const VF two = hn::Set(df, 2.0f), third = hn::Set(df, 1.0f / 3.0f);
  const VF pixel_u0 = hn::Set(df, (0.5f - cam.center_u) * cam.scale_u);
  const VF pixel_v0 = hn::Set(df, (cam.center_v - 0.5f) * cam.scale_v);
  const VF scale_u = hn::Set(df, cam.scale_u), scale_v = hn::Set(df, cam.scale_v);
  const VF center_u = hn::Set(df, cam.center_u), center_v = hn::Set(df, cam.center_v);
  const VF inv_scale_u = hn::Set(df, 1.0f / cam.scale_u);
  const VF inv_scale_v = hn::Set(df, 1.0f / cam.scale_v);
  const VF last_u = hn::Set(df, float(a.width - 1)), last_v = hn::Set(df, float(a.height - 1));
  const VF radius = hn::Set(df, a.radius), radius2 = hn::Set(df, a.radius * a.radius);
  const VF inv_thickness = hn::Set(df, 1.0f / a.thickness);
  const VF edge_on = hn::Set(df, -0.05f);
  const float* row_disk = a.lane_disk + size_t(y & 3) * a.pairs * 2 * kLaneTable + (x0 & 3);
  const VF view_y_of_row = center_v - hn::Set(df, float(y) + 0.5f);

  alignas(64) float depth_in[kMaxLanes];
  alignas(64) float result[kMaxLanes];
  for (int x = x0; x < x1; x += lanes) {
    const int count = std::min(lanes, x1 - x);
    for (int i = 0; i < lanes; ++i) {
      depth_in[i] =
          i < count ? a.depth[size_t(y) * a.width + x + i] : std::numeric_limits<float>::infinity();
    }
    const VF depth = hn::Load(df, depth_in);
    const VF footprint = ortho ? scale_u : scale_u * depth;
    auto receiver = hn::And(hn::Lt(depth, inf), hn::Ge(radius, half * footprint));
    const VF safe_depth = hn::IfThenElse(receiver, depth, one);
    const VF u = hn::Iota(df, float(x) + 0.5f);
    const VF depth_scale = ortho ? one : safe_depth;
    const VF px = (u - center_u) * scale_u * depth_scale;
    const VF py = view_y_of_row * scale_v * depth_scale;
    const VF pz = hn::Neg(safe_depth);

    // The rays' frame (see pixel()): a cone around the direction to p, or a cylinder.
    VF ax = zero, ay = zero, az = hn::Neg(one), ux = one, uy = zero, uz = zero, vx = zero, vy = one,
       vz = zero, spread = radius, beyond = zero;
    if (!ortho) {
      const VF distance2 = px * px + py * py + pz * pz;
      beyond = distance2 - radius2;
      receiver = hn::And(receiver, hn::Gt(beyond, zero));  // else the camera is inside
      const VF inv_distance = one / hn::Sqrt(distance2);
      ax = px * inv_distance, ay = py * inv_distance, az = pz * inv_distance;
      // normalize_or(cross(axis, +y), +x) = (-az, 0, ax) / |.|
      const VF side2 = az * az + ax * ax;
      const auto usable = hn::Gt(side2, hn::Set(df, 1e-40f));
      const VF inv_side = one / hn::Sqrt(hn::IfThenElse(usable, side2, one));
      ux = hn::IfThenElse(usable, hn::Neg(az) * inv_side, one);
      uz = hn::IfThenElseZero(usable, ax * inv_side);
      // side_v = cross(side_u, axis), side_u.y = 0
      vx = hn::Neg(uz * ay), vy = uz * ax - ux * az, vz = ux * ay;
      spread = radius / hn::Sqrt(hn::IfThenElse(receiver, beyond, one));
    }
    if (hn::AllFalse(df, receiver)) {
      for (int i = 0; i < count; ++i) out[x - x0 + i] = 1.0f;
      continue;
    }

    // One ray: where it enters and leaves the sphere, the surface along it, its weight.
    // Returns false where it points behind the camera.
    auto ray = [&](VF dx, VF dy, VF& enter, VF& leave, VF& surface, VF& weight) {
      const VF ox = (ux * dx + vx * dy) * spread, oy = (uy * dx + vy * dy) * spread;
      const VF oz = (uz * dx + vz * dy) * spread;
      VF su, sv, rx, ry, rz;              // image position; ray direction (perspective)
      auto in_front = hn::Lt(zero, one);  // all true
      if (ortho) {
        weight = one;
        const VF inside = hn::Max(zero, radius2 - (ox * ox + oy * oy + oz * oz));
        const VF chord = hn::Sqrt(inside);
        enter = hn::Neg(pz) - chord, leave = hn::Neg(pz) + chord;
        su = hn::MulAdd(px + ox, inv_scale_u, center_u);
        sv = hn::NegMulAdd(py + oy, inv_scale_v, center_v);
        rx = zero, ry = zero, rz = hn::Neg(one);
      } else {
        const VF dirx = ax + ox, diry = ay + oy, dirz = az + oz;
        const VF scale = one / hn::Sqrt(dirx * dirx + diry * diry + dirz * dirz);
        rx = dirx * scale, ry = diry * scale, rz = dirz * scale;
        weight = scale * scale * scale;
        const VF along = rx * px + ry * py + rz * pz;
        const VF discriminant = along * along - beyond;
        const auto crosses = hn::Gt(discriminant, zero);
        weight = hn::IfThenElseZero(crosses, weight);
        const VF root = hn::Sqrt(hn::Max(discriminant, zero));
        enter = along - root, leave = along + root;
        in_front = hn::Lt(rz, zero);
        const VF inv = one / hn::IfThenElse(in_front, hn::Neg(rz), one);
        su = hn::MulAdd(rx * inv, inv_scale_u, center_u);
        sv = hn::NegMulAdd(ry * inv, inv_scale_v, center_v);
      }
      // The pixel, clamped to the image (pixel_of()).
      su = hn::Min(hn::Max(su, zero), last_u);
      sv = hn::Min(hn::Max(sv, zero), last_v);
      const auto qx = hn::ConvertTo(di, hn::IfThenElseZero(in_front, su));
      const auto qy = hn::ConvertTo(di, hn::IfThenElseZero(in_front, sv));
      const auto index = qy * hn::Set(di, a.width) + qx;
      const VF qd = hn::GatherIndex(df, a.depth, index);
      VF nx, ny, nz;
      decode_normals(df, hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index),
                     nx, ny, nz);
      const auto geometry = hn::Lt(qd, inf);
      const VF q_scale = ortho ? one : qd;
      const VF qxv = hn::MulAdd(hn::ConvertTo(df, qx), scale_u, pixel_u0) * q_scale;
      const VF qyv = hn::NegMulAdd(hn::ConvertTo(df, qy), scale_v, pixel_v0) * q_scale;
      const VF qzv = hn::Neg(qd);
      // surface_along(): on the pixel's tangent plane, the pixel centre where seen edge-on.
      const VF facing = nx * rx + ny * ry + nz * rz;
      VF at_centre, plane;
      if (ortho) {
        at_centre = qd;
        plane = (nx * (qxv - (px + ox)) + ny * (qyv - (py + oy)) + nz * qzv) /
                hn::IfThenElse(hn::Lt(facing, edge_on), facing, hn::Neg(one));
      } else {
        at_centre = qd / hn::IfThenElse(in_front, hn::Neg(rz), one);
        plane = (nx * qxv + ny * qyv + nz * qzv) /
                hn::IfThenElse(hn::Lt(facing, edge_on), facing, hn::Neg(one));
      }
      surface =
          hn::IfThenElse(geometry, hn::IfThenElse(hn::Lt(facing, edge_on), plane, at_centre), inf);
      return in_front;
    };
    // add_ray(): the ray's volume in the sphere and the part behind the depth buffer.
    auto add = [&](VF enter, VF leave, VF surface, VF weight, VF& solid, VF& total) {
      const VF fade = thickness_weight_lanes(enter - surface, inv_thickness);
      const VF w = weight * hn::IfThenElse(hn::Lt(surface, enter), fade, one);
      const VF from = hn::Min(hn::Max(surface, enter), leave);
      if (ortho) {
        solid = hn::MulAdd(w, leave - from, solid);
        total = hn::MulAdd(w, leave - enter, total);
      } else {
        const VF leave3 = leave * leave * leave;
        solid = hn::MulAdd(w * third, leave3 - from * from * from, solid);
        total = hn::MulAdd(w * third, leave3 - enter * enter * enter, total);
      }
    };

    VF solid = zero, total = zero;
    const float* disk = row_disk;
    for (int k = 0; k < a.pairs; ++k, disk += 2 * kLaneTable) {
      const VF dx = hn::LoadU(df, disk), dy = hn::LoadU(df, disk + kLaneTable);
      VF e0, l0, s0, w0, e1, l1, s1, w1;
      const auto front0 = ray(dx, dy, e0, l0, s0, w0);
      const auto front1 = ray(hn::Neg(dx), hn::Neg(dy), e1, l1, s1, w1);
      // A pair counts only when both rays are in front of the camera.
      const auto pair = hn::And(front0, front1);
      add(e0, l0, s0, hn::IfThenElseZero(pair, w0), solid, total);
      add(e1, l1, s1, hn::IfThenElseZero(pair, w1), solid, total);
    }
    const auto any = hn::Gt(total, zero);
    const VF visibility = hn::Min(one, two * (one - solid / hn::IfThenElse(any, total, one)));
    hn::Store(hn::IfThenElse(hn::And(receiver, any), visibility, one), df, result);
    std::copy_n(result, count, out + (x - x0));
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <cmath>
#include <vector>

#include "portable_math.h"
#include "variant.h"
#include "variants/simd_dispatch.h"

namespace ssao {
namespace {

// The widest compiled volumetric_row this CPU runs (simd_dispatch.h), chosen on first use.
decltype(&HWY_STATIC_DISPATCH(volumetric_row)) best_volumetric_row() {
  static const auto row = SSAO_BEST_TARGET(volumetric_row);
  return row;
}

class Volumetric final : public Variant {
 public:
  explicit Volumetric(const ParamValues& v) {
    static constexpr int kSamples[4] = {8, 12, 16, 32};
    radius_ = float(v.get_float("radius"));
    thickness_ = float(v.get_float("thickness")) * radius_;
    pairs_ = (count_or_preset(v, "samples", kSamples) + 1) / 2;
    // A Vogel (golden-angle) spiral of equal-area rings over the unit disk, rotated and shifted
    // by each pixel's jitter state, each point with its mirror image through the centre.
    const auto states = jitter_states(uint32_t(v.get_int("seed")));
    const float golden_angle = float(M_PI) * (3.0f - std::sqrt(5.0f));
    disk_.resize(size_t(kJitterStates) * pairs_ * 2);
    for (int j = 0; j < kJitterStates; ++j) {
      const JitterState& js = states[j];
      for (int k = 0; k < pairs_; ++k) {
        const float r = std::sqrt((float(k) + js.radial_offset) / float(pairs_));
        const float a = float(k) * golden_angle + 2.0f * float(M_PI) * js.angle;
        const DiskPoint point{r * portable_cos(a), r * portable_sin(a)};
        disk_[(size_t(j) * pairs_ + k) * 2] = point;
        disk_[(size_t(j) * pairs_ + k) * 2 + 1] = {-point.x, -point.y};
      }
    }
    // The same points for the vector path: [y & 3][pair][x, y][lane] (the mirror is -point).
    lane_disk_ = lane_table<2>(pairs_, [&](int jitter, int k) {
      const DiskPoint point = disk_[(size_t(jitter) * pairs_ + k) * 2];
      return std::array<float, 2>{point.x, point.y};
    });
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    const VolumetricRowArgs args{f.depth_plane(),         f.normal_plane(), f.width(),  f.height(),
                                 f.camera().intrinsics(), radius_,          thickness_, pairs_,
                                 lane_disk_.data()};
    for (int y = t.y0; y < t.y1; ++y) {
      best_volumetric_row()(args, y, t.x0, t.x1, visibility + f.index(t.x0, y));
    }
  }

  void estimate_reference(const Frame& f, const Tile& t, float* visibility) const override {
    estimate_receivers(f, t, radius_, visibility, [&](int x, int y) { return pixel(f, x, y); });
  }

 private:
  float pixel(const Frame& f, int x, int y) const {
    const CameraModel& camera = f.camera();
    const Vec3 p = f.position(x, y);
    // The rays: through the sphere's whole silhouette. Perspective: a cone around the direction
    // to p of half-angle asin(radius / |p|), sampled on its tangent plane; orthographic: a
    // cylinder of the radius along the view axis.
    Vec3 axis{0.0f, 0.0f, -1.0f}, side_u{1.0f, 0.0f, 0.0f}, side_v{0.0f, 1.0f, 0.0f};
    float spread = radius_;
    if (!camera.orthographic()) {
      const float distance = length(p);
      const float beyond = distance * distance - radius_ * radius_;
      if (!(beyond > 0.0f)) return 1.0f;  // the camera is inside the sphere
      axis = p * (1.0f / distance);
      side_u = normalize_or(cross(axis, Vec3{0.0f, 1.0f, 0.0f}), Vec3{1.0f, 0.0f, 0.0f});
      side_v = cross(side_u, axis);
      spread = radius_ / std::sqrt(beyond);  // tan of the half-angle
    }
    const DiskPoint* disk = disk_.data() + size_t(jitter_index(x, y)) * pairs_ * 2;
    float solid = 0.0f, total = 0.0f;
    for (int k = 0; k < pairs_; ++k, disk += 2) {
      // Mirror-image rays: on a tilted surface their errors cancel. A pair counts only when
      // both rays are in front of the camera.
      Ray rays[2];
      bool in_front = true;
      for (int m = 0; m < 2 && in_front; ++m) {
        const Vec3 offset = (side_u * disk[m].x + side_v * disk[m].y) * spread;
        in_front = camera.orthographic() ? orthographic_ray(f, p, offset, rays[m])
                                         : perspective_ray(f, p, axis + offset, rays[m]);
      }
      if (!in_front) continue;
      for (const Ray& ray : rays) add_ray(ray, solid, total);
    }
    if (!(total > 0.0f)) return 1.0f;
    return std::min(1.0f, 2.0f * (1.0f - solid / total));
  }

  // One ray through the sphere: where it enters and leaves it, where the depth buffer's surface
  // is along it (all in the ray's own measure: distance from the camera, or planar depth for an
  // orthographic camera), and the volume weight of its solid angle.
  struct Ray {
    float enter = 0.0f, leave = 0.0f, surface = 0.0f, weight = 0.0f;
    bool perspective = true;
  };

  // The ray from the camera along `direction` (not unit); false if it points behind.
  bool perspective_ray(const Frame& f, Vec3 p, Vec3 direction, Ray& ray) const {
    const float scale = 1.0f / length(direction);
    const Vec3 d = direction * scale;
    // The tangent plane's area element seen from the camera: d(solid angle) = cos^3 dA.
    ray.weight = scale * scale * scale;
    ray.perspective = true;
    const float along = dot(d, p);
    const float discriminant = along * along - (dot(p, p) - radius_ * radius_);
    if (!(discriminant > 0.0f)) {
      ray.weight = 0.0f;  // grazes the sphere: nothing to measure
    } else {
      const float root = std::sqrt(discriminant);
      ray.enter = along - root, ray.leave = along + root;
    }
    int qx, qy;
    if (!pixel_of(f, d, qx, qy)) return false;
    ray.surface = surface_along(f, qx, qy, Vec3{}, d, f.depth(qx, qy) / -d.z);
    return true;
  }

  // The view-axis ray at `offset` (in the image plane) from p.
  bool orthographic_ray(const Frame& f, Vec3 p, Vec3 offset, Ray& ray) const {
    ray.weight = 1.0f;
    ray.perspective = false;
    const float half = std::sqrt(std::max(0.0f, radius_ * radius_ - dot(offset, offset)));
    ray.enter = -p.z - half, ray.leave = -p.z + half;
    int qx, qy;
    if (!pixel_of(f, p + offset, qx, qy)) return false;
    const Vec3 origin{p.x + offset.x, p.y + offset.y, 0.0f};
    ray.surface = surface_along(f, qx, qy, origin, Vec3{0.0f, 0.0f, -1.0f}, f.depth(qx, qy));
    return true;
  }

  // Where the ray origin + t * direction meets the surface seen in pixel (qx, qy): on that
  // pixel's tangent plane, so that a plane is measured exactly between pixel centres and past
  // the image's edge; `at_centre` (the pixel centre's depth along the ray) where the plane is
  // seen edge-on. Infinity through the background.
  static float surface_along(const Frame& f, int qx, int qy, Vec3 origin, Vec3 direction,
                             float at_centre) {
    if (!f.is_geometry(qx, qy)) return std::numeric_limits<float>::infinity();
    const Vec3 n = f.normal(qx, qy);
    const float facing = dot(n, direction);
    if (!(facing < -0.05f)) return at_centre;
    return dot(n, f.position(qx, qy) - origin) / facing;
  }

  // The pixel a view-space point projects to; beyond the image's edge, the edge's pixel (the
  // depth buffer continued outward: exact for a surface facing the camera, and without it the
  // rays that stay inside would all lean one way). False only behind the camera.
  static bool pixel_of(const Frame& f, Vec3 view_point, int& qx, int& qy) {
    float u, v;
    if (!f.camera().project(view_point, u, v) || !(std::isfinite(u) && std::isfinite(v))) {
      return false;
    }
    qx = int(std::clamp(u, 0.0f, float(f.width() - 1)));
    qy = int(std::clamp(v, 0.0f, float(f.height() - 1)));
    return true;
  }

  // Adds the ray's volume inside the sphere, and the part of it behind the depth buffer.
  void add_ray(const Ray& ray, float& solid, float& total) const {
    if (!(ray.weight > 0.0f)) return;
    // Behind the depth buffer counts as solid. A surface far in front of the sphere hides what
    // is there: that ray fades out of the estimate (distance fall-off against halos).
    const float weight =
        ray.weight *
        (ray.surface < ray.enter ? thickness_weight(ray.enter - ray.surface, thickness_) : 1.0f);
    if (!(weight > 0.0f)) return;
    const float solid_from = std::clamp(ray.surface, ray.enter, ray.leave);
    solid += weight * volume_between(ray, solid_from, ray.leave);
    total += weight * volume_between(ray, ray.enter, ray.leave);
  }

  // A cone's volume grows with the square of the distance; a cylinder's does not.
  static float volume_between(const Ray& ray, float t0, float t1) {
    if (!ray.perspective) return t1 - t0;
    return (t1 * t1 * t1 - t0 * t0 * t0) * (1.0f / 3.0f);
  }

  float radius_, thickness_;
  int pairs_;
  std::vector<DiskPoint> disk_;  // [jitter state][pair][member]
  std::vector<float> lane_disk_;
};

}  // namespace

extern const VariantInfo kVolumetricVariant;
const VariantInfo kVolumetricVariant = {
    "volumetric",
    "line-integral obscurance: the part of a sphere around the receiver behind the depth "
    "buffer, along view rays (Loos & Sloan 2010), depth only",
    "samples|thickness|seed",
    [](const ParamValues& v, const Frame&) -> std::unique_ptr<Variant> {
      return std::make_unique<Volumetric>(v);
    },
    0u};

}  // namespace ssao
#endif  // HWY_ONCE
