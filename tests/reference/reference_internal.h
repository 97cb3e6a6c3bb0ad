// SPDX-License-Identifier: MIT
// Helpers shared by the reference AO implementations (raymarch_ao.cpp, seed_ports.cpp): a small
// deterministic PRNG, input validation, view-space positions and normals from a DepthScene, and
// the seed tutorials' 4x4 box blur. Internal to the ssao_reference library.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "reference_ao.h"
#include "vec3.h"

namespace ssao_ref {
namespace detail {

// Depths at or beyond this (or non-finite, or not positive) are background.
constexpr float kBackgroundDepth = 1e9f;
// The planar depth a background pixel reads as when a sample looks it up ("the far plane").
constexpr float kFarDepth = 1e10f;

inline uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// PCG32 (O'Neill, pcg32_random_r with the XSH-RR output), seeded through splitmix64.
class Pcg32 {
 public:
  explicit Pcg32(uint64_t seed, uint64_t stream = 0xDA3E39CB94B95BDBULL)
      : inc_((stream << 1) | 1u) {
    next();
    state_ += splitmix64(seed);
    next();
  }

  uint32_t next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<uint32_t>(((old >> 18) ^ old) >> 27);
    const auto rot = static_cast<uint32_t>(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1) with 24 bits.
  float uniform() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }
  // The tutorials' random(lo, hi): uniform in [lo, hi).
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }

 private:
  uint64_t state_ = 0;
  uint64_t inc_;
};

// A per-pixel seed, independent of the order pixels are processed in.
inline uint64_t pixel_seed(uint32_t seed, int x, int y) {
  const uint64_t xy = (static_cast<uint64_t>(static_cast<uint32_t>(y)) << 32) |
                      static_cast<uint64_t>(static_cast<uint32_t>(x));
  return splitmix64(splitmix64(static_cast<uint64_t>(seed) ^ 0x5EED5EED5EED5EEDULL) ^ xy);
}

inline bool is_geometry(float depth) {
  return std::isfinite(depth) && depth > 0.0f && depth < kBackgroundDepth;
}

inline void validate(const DepthScene& scene, const char* who) {
  const std::string name(who);
  if (scene.width <= 0 || scene.height <= 0) {
    throw std::invalid_argument(name + ": the image size must be positive");
  }
  const size_t n = static_cast<size_t>(scene.width) * static_cast<size_t>(scene.height);
  if (scene.depth.size() != n) {
    throw std::invalid_argument(name + ": depth must hold width * height values");
  }
  if (!scene.view_normal.empty() && scene.view_normal.size() != 3 * n) {
    throw std::invalid_argument(name + ": view_normal must be empty or hold 3 floats per pixel");
  }
}

inline void validate_radius(float radius, const char* who) {
  if (!(radius > 0.0f) || !std::isfinite(radius)) {
    throw std::invalid_argument(std::string(who) + ": radius must be positive and finite");
  }
}

inline size_t index(const DepthScene& s, int x, int y) {
  return static_cast<size_t>(y) * static_cast<size_t>(s.width) + static_cast<size_t>(x);
}

// View-space position of the centre of pixel (x, y) (which must be geometry).
inline ssao::Vec3 pixel_position(const DepthScene& s, int x, int y) {
  return s.camera.view_position(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f,
                                s.depth[index(s, x, y)]);
}

// View-space z of the surface seen through pixel (x, y); background reads as the far plane.
// (view_position gives z = -planar depth for both projections.)
inline float surface_z(const DepthScene& s, int x, int y) {
  const float d = s.depth[index(s, x, y)];
  return is_geometry(d) ? -d : -kFarDepth;
}

// Normal from the depth buffer: the cross product of the differences to the right/left and
// lower/upper neighbours, taking on each axis the neighbour whose depth is closer (so that a
// silhouette edge does not bend the normal), oriented towards the camera.
inline ssao::Vec3 reconstruct_normal(const DepthScene& s, int x, int y) {
  using ssao::Vec3;
  const Vec3 p = pixel_position(s, x, y);
  const float d = s.depth[index(s, x, y)];
  const Vec3 fallback = s.camera.towards_camera(p);
  auto diff = [&](int dx, int dy, Vec3& out) -> bool {
    const float best_plus = [&] {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= s.width || ny >= s.height) return -1.0f;
      const float nd = s.depth[index(s, nx, ny)];
      return is_geometry(nd) ? std::fabs(nd - d) : -1.0f;
    }();
    const float best_minus = [&] {
      const int nx = x - dx, ny = y - dy;
      if (nx < 0 || ny < 0 || nx >= s.width || ny >= s.height) return -1.0f;
      const float nd = s.depth[index(s, nx, ny)];
      return is_geometry(nd) ? std::fabs(nd - d) : -1.0f;
    }();
    if (best_plus < 0.0f && best_minus < 0.0f) return false;
    if (best_plus >= 0.0f && (best_minus < 0.0f || best_plus <= best_minus)) {
      out = pixel_position(s, x + dx, y + dy) - p;
    } else {
      out = p - pixel_position(s, x - dx, y - dy);
    }
    return true;
  };
  Vec3 du, dv;
  if (!diff(1, 0, du) || !diff(0, 1, dv)) return fallback;
  Vec3 n = ssao::normalize_or(ssao::cross(du, dv), fallback);
  if (ssao::dot(n, fallback) < 0.0f) n = -n;
  return n;
}

// The pixel's view-space normal: scene.view_normal as given (normalised), or reconstructed from
// depth when the scene has none. With orient_to_camera, a normal facing away from the camera is
// flipped (as Cycles does for back faces).
inline ssao::Vec3 pixel_normal(const DepthScene& s, int x, int y, bool orient_to_camera) {
  if (s.view_normal.empty()) return reconstruct_normal(s, x, y);
  const size_t i = 3 * index(s, x, y);
  const ssao::Vec3 p = pixel_position(s, x, y);
  const ssao::Vec3 towards = s.camera.towards_camera(p);
  ssao::Vec3 n =
      ssao::normalize_or({s.view_normal[i], s.view_normal[i + 1], s.view_normal[i + 2]}, towards);
  if (orient_to_camera && ssao::dot(n, towards) < 0.0f) n = -n;
  return n;
}

// The seed tutorial's blur pass: the mean of the 4x4 block of texels at offsets -2..1 around each
// pixel (uBlurSize = 4), reading through a clamp-to-edge sampler. The raw AO of background pixels
// is 1 (as the SSAO pass writes for them) and takes part in the blur; background pixels output 1.
inline std::vector<float> box_blur_4x4(const DepthScene& s, const std::vector<float>& raw) {
  std::vector<float> out(raw.size(), 1.0f);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      if (!is_geometry(s.depth[index(s, x, y)])) continue;
      float sum = 0.0f;
      for (int j = -2; j < 2; ++j) {
        const int sy = y + j < 0 ? 0 : (y + j >= s.height ? s.height - 1 : y + j);
        for (int i = -2; i < 2; ++i) {
          const int sx = x + i < 0 ? 0 : (x + i >= s.width ? s.width - 1 : x + i);
          sum += raw[index(s, sx, sy)];
        }
      }
      out[index(s, x, y)] = sum / 16.0f;
    }
  }
  return out;
}

}  // namespace detail
}  // namespace ssao_ref
