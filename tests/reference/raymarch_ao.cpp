// SPDX-License-Identifier: MIT
// Brute-force screen-space ray march (see reference_ao.h): for every geometry pixel, `rays`
// cosine-weighted rays around the normal are marched through the depth buffer up to `radius`.
// A ray is blocked when one of its points lies behind the visible surface (by less than the
// assumed occluder thickness); visibility is the unblocked fraction, which estimates Cycles' AO
// (cosine-weighted binary visibility within the AO distance) as far as a depth buffer can.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <vector>

#include "reference_ao.h"
#include "reference_internal.h"
#include "vec3.h"

namespace ssao_ref {
namespace {

using ssao::Vec3;
using namespace detail;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kGoldenAngle = 2.39996322972865332f;  // pi * (3 - sqrt(5))

// Visibility of geometry pixel (x, y).
float march_pixel(const DepthScene& s, const RayMarchSettings& cfg, int x, int y) {
  const Vec3 origin = pixel_position(s, x, y);
  // Cycles shades back faces with the flipped normal, so the hemisphere faces the camera.
  const Vec3 n = pixel_normal(s, x, y, /*orient_to_camera=*/true);
  Vec3 t, b;
  ssao::orthonormal_basis(n, t, b);

  // Deterministic per-pixel randomness: the disk rotation, then one step jitter per ray.
  Pcg32 rng(pixel_seed(cfg.seed, x, y));
  const float rotation = 2.0f * kPi * rng.uniform();

  const float radius = cfg.radius;
  // Start a little off the surface so that a ray does not hit the pixel it starts from.
  const float start = std::min(0.02f * radius + s.camera.pixel_footprint(-origin.z), 0.5f * radius);
  const float span = radius - start;
  const float max_behind = cfg.thickness * radius;
  const float inv_rays = 1.0f / static_cast<float>(cfg.rays);
  const float inv_steps = 1.0f / static_cast<float>(cfg.steps);
  const float width = static_cast<float>(s.width), height = static_cast<float>(s.height);

  int blocked = 0;
  for (int k = 0; k < cfg.rays; ++k) {
    // Vogel spiral on the unit disk (stratified in area), lifted onto the hemisphere: a
    // cosine-weighted direction (Malley's method).
    const float r2 = (static_cast<float>(k) + 0.5f) * inv_rays;
    const float r = std::sqrt(r2);
    const float phi = static_cast<float>(k) * kGoldenAngle + rotation;
    const float lx = r * std::cos(phi), ly = r * std::sin(phi);
    const float lz = std::sqrt(std::max(0.0f, 1.0f - r2));
    const Vec3 dir = t * lx + b * ly + n * lz;
    const float jitter = rng.uniform();

    for (int step = 0; step < cfg.steps; ++step) {
      const float dist = start + span * ((static_cast<float>(step) + jitter) * inv_steps);
      const Vec3 p = origin + dir * dist;
      float u = 0.0f, v = 0.0f;
      if (!s.camera.project(p, u, v)) continue;  // behind the camera: nothing hides it
      if (!(u >= 0.0f && u < width && v >= 0.0f && v < height)) continue;  // off screen
      const int px = std::min(static_cast<int>(u), s.width - 1);
      const int py = std::min(static_cast<int>(v), s.height - 1);
      const float surface_depth = s.depth[index(s, px, py)];
      if (!is_geometry(surface_depth)) continue;
      const float behind = -p.z - surface_depth;  // planar depth of the point past the surface
      if (behind > 0.0f && behind < max_behind) {
        ++blocked;
        break;
      }
    }
  }
  return 1.0f - static_cast<float>(blocked) * inv_rays;
}

}  // namespace

std::vector<float> raymarch_ao(const DepthScene& scene, const RayMarchSettings& settings) {
  validate(scene, "raymarch_ao");
  validate_radius(settings.radius, "raymarch_ao");
  if (settings.rays <= 0 || settings.steps <= 0) {
    throw std::invalid_argument("raymarch_ao: rays and steps must be positive");
  }
  if (!(settings.thickness > 0.0f) || !std::isfinite(settings.thickness)) {
    throw std::invalid_argument("raymarch_ao: thickness must be positive and finite");
  }

  std::vector<float> out(scene.depth.size(), 1.0f);
  // Rows are handed out dynamically; every pixel's result depends only on its own coordinates
  // and the seed, so the output does not depend on the thread count or the schedule.
  std::atomic<int> next_row{0};
  auto worker = [&] {
    for (int y = next_row.fetch_add(1); y < scene.height; y = next_row.fetch_add(1)) {
      for (int x = 0; x < scene.width; ++x) {
        if (!is_geometry(scene.depth[index(scene, x, y)])) continue;
        out[index(scene, x, y)] = march_pixel(scene, settings, x, y);
      }
    }
  };
  const unsigned hardware = std::thread::hardware_concurrency();
  const int threads =
      std::max(1, std::min(static_cast<int>(hardware == 0 ? 1 : hardware), scene.height));
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;  // fewer threads: the rows are shared out among those that did start
    }
  }
  worker();
  for (std::thread& th : pool) th.join();
  return out;
}

}  // namespace ssao_ref
