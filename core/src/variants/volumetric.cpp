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
#include <algorithm>
#include <cmath>
#include <limits>

#include "sampling.h"
#include "variant.h"

namespace ssao {
namespace {

struct DiskPoint {
  float x, y;  // on the unit disk
};

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
        const DiskPoint point{r * std::cos(a), r * std::sin(a)};
        disk_[(size_t(j) * pairs_ + k) * 2] = point;
        disk_[(size_t(j) * pairs_ + k) * 2 + 1] = {-point.x, -point.y};
      }
    }
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
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
};

}  // namespace

extern const VariantInfo kVolumetricVariant;
const VariantInfo kVolumetricVariant = {
    "volumetric",
    "line-integral obscurance: the part of a sphere around the receiver behind the depth "
    "buffer, along view rays (Loos & Sloan 2010), depth only",
    "samples|thickness|seed", [](const ParamValues& v, const Frame&) -> std::unique_ptr<Variant> {
      return std::make_unique<Volumetric>(v);
    }};

}  // namespace ssao
