// SPDX-License-Identifier: MIT
// Depth and normal buffers ray-cast from analytic geometry, with their own camera maths
// (independent of the core's camera model), plus a small RAII wrapper over the C API.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "ssao/ssao.h"

namespace test {

struct V3 {
  double x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 normalized(V3 a) { return a * (1.0 / std::sqrt(dot(a, a))); }

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

  // Ray through the centre of pixel (x, y), y = 0 on top, in view space (-Z forward).
  void ray(int x, int y, V3& origin, V3& direction) const {
    const double nx = (x + 0.5) / width - 0.5;                      // -0.5 .. 0.5
    const double ny = (0.5 - (y + 0.5) / height) * height / width;  // same units as nx
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
};

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

inline Scene ray_cast(const Camera& cam, const std::vector<Solid>& solids) {
  Scene s;
  s.width = cam.width;
  s.height = cam.height;
  const size_t n = size_t(cam.width) * cam.height;
  s.depth.assign(n, std::numeric_limits<float>::infinity());
  s.normal.assign(3 * n, 0.0f);
  s.point.assign(n, V3{0, 0, 0});
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      V3 o, d;
      cam.ray(x, y, o, d);
      double best_t = std::numeric_limits<double>::infinity();
      V3 best_normal{0, 0, 0};
      for (const Solid& solid : solids) {
        double t = 0;
        V3 normal{0, 0, 0};
        if (enter_solid(solid, o, d, t, normal) && t < best_t) best_t = t, best_normal = normal;
      }
      if (!std::isfinite(best_t)) continue;
      const V3 p = o + d * best_t;
      const size_t i = size_t(y) * cam.width + x;
      s.depth[i] = float(-p.z);
      s.point[i] = p;
      s.normal[3 * i + 0] = float(best_normal.x);
      s.normal[3 * i + 1] = float(best_normal.y);
      s.normal[3 * i + 2] = float(best_normal.z);
    }
  }
  return s;
}

// An axis-aligned box [lo, hi] as a solid.
inline Solid box(V3 lo, V3 hi) {
  return {{lo, {-1, 0, 0}}, {lo, {0, -1, 0}}, {lo, {0, 0, -1}},
          {hi, {1, 0, 0}},  {hi, {0, 1, 0}},  {hi, {0, 0, 1}}};
}

// Cosine-weighted visibility within distance r of a point on a plane at distance x from a
// perpendicular wall (the 90-degree concave corner): with a = x / r, the blocked directions are
// the part of the projected unit disk beyond a, so AO = 1 - (acos a - a sqrt(1 - a^2)) / pi.
inline double corner_ao(double x, double r) {
  const double a = std::min(1.0, std::max(0.0, x / r));
  return 1.0 - (std::acos(a) - a * std::sqrt(1.0 - a * a)) / M_PI;
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
