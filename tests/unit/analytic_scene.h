// SPDX-License-Identifier: MIT
// Depth and normal buffers ray-cast from analytic geometry, with their own camera maths
// (independent of the core's camera model), the scenes the unit and stress tests share, and a
// small RAII wrapper over the C API.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "../../core/src/vec3.h"  // the project's 3-vector, header only
#include "ssao/ssao.h"

namespace test {

using V3 = ssao::Vector3<double>;
// Not a template: takes a braced {x, y, z}.
inline V3 normalized(V3 a) { return ssao::normalized(a); }

// A plane bounding a solid: points p with dot(normal, p - point) < 0 are inside.
struct Plane {
  V3 point, normal;  // normal: unit, pointing into free space
};

// A convex solid: the intersection of the half-spaces behind its planes. A scene is the union
// of its solids (one plane: a half-space such as a floor; two planes facing apart: a convex
// ridge; six: a box).
using Solid = std::vector<Plane>;

struct Camera {
  bool ortho = false;
  double lens = 35.0, sensor = 36.0;  // PERSP, horizontal fit (width >= height)
  double ortho_scale = 6.0;           // ORTHO
  int width = 96, height = 64;

  // Ray through the centre of pixel (x, y), y = 0 on top, in view space (-Z forward). The
  // sensor (or ortho_scale) spans the larger image side, as the library's sensor_fit AUTO.
  void ray(int x, int y, V3& origin, V3& direction) const {
    ray_at(x + 0.5, y + 0.5, origin, direction);
  }
  // Ray through image point (u, v): pixel (x, y) spans [x, x + 1) x [y, y + 1).
  void ray_at(double u, double v, V3& origin, V3& direction) const {
    const double fit = width >= height ? 1.0 : double(width) / height;  // portrait: fit height
    const double nx = (u / width - 0.5) * fit;                          // -0.5 .. 0.5 on the fit
    const double ny = (0.5 - v / height) * height / width * fit;        // same units as nx
    if (ortho) {
      origin = {nx * ortho_scale, ny * ortho_scale, 0.0};
      direction = {0.0, 0.0, -1.0};
    } else {
      origin = {0.0, 0.0, 0.0};
      direction = {nx * sensor / lens, ny * sensor / lens, -1.0};
    }
  }
};

struct Scene {
  int width = 0, height = 0;
  std::vector<float> depth;   // planar depth; +inf where nothing is hit
  std::vector<float> normal;  // view-space normals, 3 per pixel
  std::vector<V3> point;      // hit points (view space)
  // The 2nd and 3rd surface hits along each pixel's ray (libssao's "depth2", "depth3"): planar
  // depth, +inf where there is no such hit; facing 1 on a back face (leaving a solid), else 0.
  std::vector<float> layer[2];
  std::vector<float> facing[2];
};

// 1 on the pixels (off the frame's border) with a depth jump of more than 5 % to a 4-neighbour,
// the benchmark's edge pixels (a background neighbour counts as a jump), else 0.
inline std::vector<char> depth_jump_pixels(const Scene& s) {
  std::vector<char> jump(s.depth.size(), 0);
  for (int y = 1; y + 1 < s.height; ++y) {
    for (int x = 1; x + 1 < s.width; ++x) {
      const size_t i = size_t(y) * s.width + x;
      for (const size_t n : {i - 1, i + 1, i - s.width, i + s.width}) {
        if (std::fabs(s.depth[i] - s.depth[n]) > 0.05f * std::min(s.depth[i], s.depth[n])) {
          jump[i] = 1;
        }
      }
    }
  }
  return jump;
}

// Ray / convex solid: the ray is inside between the last plane it enters and the first it leaves.
inline bool enter_solid(const Solid& solid, V3 o, V3 d, double& t_hit, V3& normal) {
  double t_enter = 0.0, t_exit = std::numeric_limits<double>::infinity();
  bool entered = false;
  for (const Plane& pl : solid) {
    const double denom = dot(pl.normal, d);
    const double dist = dot(pl.normal, o - pl.point);  // > 0: origin on the free side
    if (std::fabs(denom) < 1e-12) {
      if (dist > 0) return false;  // parallel and outside
      continue;
    }
    const double t = -dist / denom;
    if (denom < 0) {  // entering this half-space
      if (t > t_enter || !entered) t_enter = std::max(t_enter, t), normal = pl.normal;
      entered = true;
    } else {
      t_exit = std::min(t_exit, t);
    }
  }
  if (!entered || t_enter >= t_exit || t_enter <= 0) return false;
  t_hit = t_enter;
  return true;
}

// Where the ray leaves a solid it enters (enter_solid): +inf for an unbounded one.
inline double exit_solid(const Solid& solid, V3 o, V3 d) {
  double t_exit = std::numeric_limits<double>::infinity();
  for (const Plane& pl : solid) {
    const double denom = dot(pl.normal, d);
    if (denom > 1e-12) t_exit = std::min(t_exit, -dot(pl.normal, o - pl.point) / denom);
  }
  return t_exit;
}

// The nearest solid a ray enters: its distance along the ray (+inf: none) and the entered face's
// normal.
inline double first_hit(const std::vector<Solid>& solids, V3 o, V3 d, V3& normal) {
  double best = std::numeric_limits<double>::infinity();
  for (const Solid& solid : solids) {
    double t = 0;
    V3 n{0, 0, 0};
    if (enter_solid(solid, o, d, t, n) && t < best) best = t, normal = n;
  }
  return best;
}

inline Scene ray_cast(const Camera& cam, const std::vector<Solid>& solids) {
  Scene s;
  s.width = cam.width;
  s.height = cam.height;
  const size_t n = size_t(cam.width) * cam.height;
  s.depth.assign(n, std::numeric_limits<float>::infinity());
  s.normal.assign(3 * n, 0.0f);
  s.point.assign(n, V3{0, 0, 0});
  for (int k = 0; k < 2; ++k) {
    s.layer[k].assign(n, std::numeric_limits<float>::infinity());
    s.facing[k].assign(n, 0.0f);
  }
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      V3 o, d;
      cam.ray(x, y, o, d);
      V3 best_normal{0, 0, 0};
      const double best_t = first_hit(solids, o, d, best_normal);
      if (!std::isfinite(best_t)) continue;
      const V3 p = o + d * best_t;
      const size_t i = size_t(y) * cam.width + x;
      // Every surface the ray crosses, in order: each solid's entry (front) and exit (back).
      std::vector<std::pair<double, bool>> hits;
      for (const Solid& solid : solids) {
        double t = 0;
        V3 unused{0, 0, 0};
        if (!enter_solid(solid, o, d, t, unused)) continue;
        hits.push_back({t, false});
        const double t_exit = exit_solid(solid, o, d);
        if (std::isfinite(t_exit)) hits.push_back({t_exit, true});
      }
      std::sort(hits.begin(), hits.end());
      for (size_t k = 0; k < 2 && k + 1 < hits.size(); ++k) {
        s.layer[k][i] = float(-(o + d * hits[k + 1].first).z);
        s.facing[k][i] = hits[k + 1].second ? 1.0f : 0.0f;
      }
      s.depth[i] = float(-p.z);
      s.point[i] = p;
      s.normal[3 * i + 0] = float(best_normal.x);
      s.normal[3 * i + 1] = float(best_normal.y);
      s.normal[3 * i + 2] = float(best_normal.z);
    }
  }
  return s;
}

// The frame's camera widened by `band` pixels on every side, on the same pixel grid (a guard
// band's camera).
inline Camera widened(const Camera& frame, int band) {
  Camera big = frame;
  big.width = frame.width + 2 * band;
  big.height = frame.height + 2 * band;
  big.sensor = frame.sensor * big.width / frame.width;  // horizontal fit: the sensor spans width
  big.ortho_scale = frame.ortho_scale * big.width / frame.width;
  return big;
}

// An axis-aligned box [lo, hi] as a solid.
inline Solid box(V3 lo, V3 hi) {
  return {{lo, {-1, 0, 0}}, {lo, {0, -1, 0}}, {lo, {0, 0, -1}},
          {hi, {1, 0, 0}},  {hi, {0, 1, 0}},  {hi, {0, 0, 1}}};
}

// A sphere as a convex solid: the planes tangent to it at `planes` directions spread evenly
// (a Fibonacci lattice). 400 planes keep the solid within 0.6 % of the radius of the sphere.
inline Solid polyhedral_sphere(V3 center, double radius, int planes = 400) {
  Solid solid;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < planes; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / planes, r = std::sqrt(1.0 - z * z);
    const V3 n{r * std::cos(golden * i), r * std::sin(golden * i), z};
    solid.push_back({center + n * radius, n});
  }
  return solid;
}

// Ray-traced AO, the way Cycles' AO pass measures it: the fraction of `rays` cosine-weighted
// directions about `normal` from `point` that hit no solid within `distance` (a regular
// stratified pattern, so the reference itself is smooth).
inline double ray_traced_ao(const std::vector<Solid>& solids, V3 point, V3 normal, double distance,
                            int rays = 1024) {
  const V3 helper = std::fabs(normal.x) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0};
  const auto cross = [](V3 a, V3 b) {
    return V3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const V3 t = normalized(cross(normal, helper)), b = cross(normal, t);
  const V3 origin = point + normal * 1e-6;
  const int side = int(std::sqrt(double(rays)));
  int open = 0;
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      const double u = (i + 0.5) / side, v = (j + 0.5) / side;
      const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
      const V3 dir = normalized(t * (r * std::cos(phi)) + b * (r * std::sin(phi)) +
                                normal * std::sqrt(std::max(0.0, 1.0 - u)));
      bool blocked = false;
      for (const Solid& solid : solids) {
        double hit = 0;
        V3 unused{0, 0, 0};
        if (enter_solid(solid, origin, dir, hit, unused) && hit < distance) blocked = true;
      }
      open += blocked ? 0 : 1;
    }
  }
  return double(open) / (side * side);
}

// Cosine-weighted visibility within distance r of a point on a plane at distance x from a
// perpendicular wall (the 90-degree concave corner): with a = x / r, the blocked directions are
// the part of the projected unit disk beyond a, so AO = 1 - (acos a - a sqrt(1 - a^2)) / pi.
inline double corner_ao(double x, double r) {
  const double a = std::min(1.0, std::max(0.0, x / r));
  return 1.0 - (std::acos(a) - a * std::sqrt(1.0 - a * a)) / M_PI;
}

// Mean, min and max of the AO over the geometry pixels that `include` accepts.
struct Stats {
  double mean = 0, min = 1, max = 0;
  int count = 0;
};

inline Stats stats_over(const Scene& s, const std::vector<float>& ao,
                        const std::function<bool(int x, int y)>& include) {
  Stats st;
  double sum = 0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const size_t i = size_t(y) * s.width + x;
      if (!std::isfinite(s.depth[i]) || !include(x, y)) continue;
      sum += ao[i];
      st.min = std::min(st.min, double(ao[i]));
      st.max = std::max(st.max, double(ao[i]));
      ++st.count;
    }
  }
  st.mean = st.count ? sum / st.count : 0;
  return st;
}

// A plane facing the camera at distance `depth`.
inline Scene facing_plane(const Camera& cam, double depth = 5.0) {
  return ray_cast(cam, {{{{0, 0, -depth}, {0, 0, 1}}}});
}

// A plane through (0, 0, -depth) turned `degrees` from facing the camera, rising away from it.
inline Scene tilted_plane(const Camera& cam, double degrees = 60.0, double depth = 5.0) {
  const double a = degrees * M_PI / 180.0;
  return ray_cast(cam, {{{{0, 0, -depth}, {0, std::sin(a), std::cos(a)}}}});
}

// A 90-degree concave corner: two walls meeting along the line through `crease` in direction
// `axis` (a unit vector across the view: {0, 1, 0} is a vertical crease), opening to the camera.
struct Corner {
  V3 crease{0, 0, -6};
  V3 axis{0, 1, 0};
};

inline Scene concave_corner(const Camera& cam, const Corner& c = {}) {
  // The union of the two half-spaces behind the walls; `side` is across the crease.
  const V3 side{c.axis.y, -c.axis.x, 0.0};  // cross(axis, +z)
  const V3 forward{0, 0, 1};
  return ray_cast(cam, {{{c.crease, normalized(side + forward)}},
                        {{c.crease, normalized(side * -1.0 + forward)}}});
}

inline double distance_to_crease(const Scene& s, int x, int y, const Corner& c = {}) {
  const V3 p = s.point[size_t(y) * s.width + x] - c.crease;
  const V3 across = p - c.axis * dot(p, c.axis);
  return std::sqrt(dot(across, across));
}

// A floor with a wall behind it, seen from above at an angle: enough occlusion to compare runs.
inline Scene floor_and_wall(const Camera& cam) {
  return ray_cast(
      cam, {{{{0, -1, -6}, normalized({0, 1, 0.0})}}, {{{0, 0, -8}, normalized({0, 0.2, 1})}}});
}

// RAII job over the C API; every call is checked with the library's message on failure.
class Job {
 public:
  Job() { EXPECT_EQ(ssao_job_create(&job_), SSAO_OK); }
  ~Job() { ssao_job_destroy(job_); }
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;
  ssao_job get() const { return job_; }

  void set(const char* name, int v) { check(ssao_job_set_int(job_, name, v), name); }
  void set(const char* name, double v) { check(ssao_job_set_float(job_, name, v), name); }
  void set(const char* name, const char* v) { check(ssao_job_set_string(job_, name, v), name); }
  void set(const char* name, const std::vector<double>& v) {
    check(ssao_job_set_floats(job_, name, v.data(), v.size()), name);
  }
  void camera(const Camera& c) {
    set("camera_type", c.ortho ? "ORTHO" : "PERSP");
    set("lens", c.lens);
    set("sensor_width", c.sensor);
    set("ortho_scale", c.ortho_scale);
  }
  void image(const char* name, std::vector<float>& data, int w, int h, int channels) {
    check(ssao_job_set_image(job_, name, data.data(), w, h, channels, 0, 0), name);
  }
  ssao_status run() { return ssao_job_run(job_); }

 private:
  static void check(ssao_status s, const char* what) {
    EXPECT_EQ(s, SSAO_OK) << what << ": " << ssao_last_error();
  }
  ssao_job job_ = nullptr;
};

// Runs AO on a scene (view-space normals unless use_normals is false) and returns it.
inline std::vector<float> compute_ao(Scene& scene, const Camera& cam, double radius,
                                     const char* variant, bool use_normals = true,
                                     const std::function<void(Job&)>& extra = nullptr) {
  Job job;
  job.camera(cam);
  job.set("radius", radius);
  job.set("variant", variant);
  job.set("normal_space", "camera");
  if (extra) extra(job);
  std::vector<float> ao(scene.depth.size(), -1.0f);
  job.image("depth", scene.depth, scene.width, scene.height, 1);
  if (use_normals) job.image("normal", scene.normal, scene.width, scene.height, 3);
  job.image("ao", ao, scene.width, scene.height, 1);
  EXPECT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  return ao;
}

}  // namespace test
