// SPDX-License-Identifier: MIT
// Straight ports of the seed tutorials' SSAO code (see reference_ao.h). They are deliberately
// naive: they are the baseline the product is measured against, so they must stay faithful to the
// seed code rather than be improved. Conventions: view space looks down -Z (as the OpenGL
// tutorial), so a view z closer to zero is nearer the camera; a depth-buffer lookup is the
// nearest texel through a clamp-to-edge sampler; background texels read as the far plane.
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "reference_ao.h"
#include "reference_internal.h"
#include "vec3.h"

namespace ssao_ref {
namespace {

using ssao::Vec3;
using namespace detail;

constexpr int kNoise = 4;  // the tutorials' 4x4 noise texture

// Nearest texel of continuous image coordinate c in [0, size), clamped to the edge.
int clamp_texel(float c, int size) {
  if (!(c >= 0.0f)) return 0;  // also NaN
  if (c >= static_cast<float>(size)) return size - 1;
  return static_cast<int>(c);
}

// View z of the depth-buffer surface under view-space point p (projected, nearest texel, clamp).
// Returns false when p cannot be projected (behind a perspective camera).
bool lookup_surface_z(const DepthScene& s, Vec3 p, float& z) {
  float u = 0.0f, v = 0.0f;
  if (!s.camera.project(p, u, v)) return false;
  z = surface_z(s, clamp_texel(u, s.width), clamp_texel(v, s.height));
  return true;
}

int noise_index(int x, int y) { return (y % kNoise) * kNoise + (x % kNoise); }

}  // namespace

std::vector<float> seed_hemisphere_ao(const DepthScene& scene, float radius, int samples,
                                      uint32_t seed) {
  validate(scene, "seed_hemisphere_ao");
  validate_radius(radius, "seed_hemisphere_ao");
  if (samples <= 0) throw std::invalid_argument("seed_hemisphere_ao: samples must be positive");

  Pcg32 rng(seed);
  // Kernel (seed 004): points on the +z hemisphere, scaled by random(0, 1), then pulled towards
  // the origin by lerp(0.1, 1, (i / N)^2).
  std::vector<Vec3> kernel(static_cast<size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const float kx = rng.uniform(-1.0f, 1.0f);
    const float ky = rng.uniform(-1.0f, 1.0f);
    const float kz = rng.uniform(0.0f, 1.0f);
    Vec3 k = ssao::normalize_or({kx, ky, kz}, Vec3{0.0f, 0.0f, 1.0f});
    k = k * rng.uniform(0.0f, 1.0f);
    const float t = static_cast<float>(i) / static_cast<float>(samples);
    const float scale = 0.1f + (1.0f - 0.1f) * (t * t);
    kernel[static_cast<size_t>(i)] = k * scale;
  }
  // Noise texture: random rotations about the kernel's z axis, tiled over the image.
  std::vector<Vec3> noise(kNoise * kNoise);
  for (Vec3& r : noise) {
    const float rx = rng.uniform(-1.0f, 1.0f);
    const float ry = rng.uniform(-1.0f, 1.0f);
    r = ssao::normalize_or({rx, ry, 0.0f}, Vec3{1.0f, 0.0f, 0.0f});
  }

  std::vector<float> raw(scene.depth.size(), 1.0f);
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      if (!is_geometry(scene.depth[index(scene, x, y)])) continue;
      const Vec3 origin = pixel_position(scene, x, y);
      const Vec3 normal = pixel_normal(scene, x, y, /*orient_to_camera=*/false);
      // Gram-Schmidt: tangent from the noise vector, tbn = (tangent, bitangent, normal).
      const Vec3 rvec = noise[static_cast<size_t>(noise_index(x, y))];
      Vec3 fallback_t, fallback_b;
      ssao::orthonormal_basis(normal, fallback_t, fallback_b);
      const Vec3 tangent = ssao::normalize_or(rvec - normal * ssao::dot(rvec, normal), fallback_t);
      const Vec3 bitangent = ssao::cross(normal, tangent);

      float occlusion = 0.0f;
      for (const Vec3& k : kernel) {
        const Vec3 sample = origin + (tangent * k.x + bitangent * k.y + normal * k.z) * radius;
        float sample_depth = 0.0f;  // view z of the surface under the sample
        if (!lookup_surface_z(scene, sample, sample_depth)) continue;
        const float range_check = std::fabs(origin.z - sample_depth) < radius ? 1.0f : 0.0f;
        // The surface is in front of (or at) the sample: the sample is inside geometry.
        occlusion += (sample_depth >= sample.z ? 1.0f : 0.0f) * range_check;
      }
      raw[index(scene, x, y)] = 1.0f - occlusion / static_cast<float>(samples);
    }
  }
  return box_blur_4x4(scene, raw);
}

std::vector<float> seed_sphere_ao(const DepthScene& scene, float radius, int samples,
                                  uint32_t seed) {
  validate(scene, "seed_sphere_ao");
  validate_radius(radius, "seed_sphere_ao");
  if (samples <= 0) throw std::invalid_argument("seed_sphere_ao: samples must be positive");

  // Seed 000's kernel: the 8 cube diagonals with lengths 0.125 .. 1.0.
  const float d = 1.0f / std::sqrt(3.0f);
  const Vec3 kernel[8] = {
      Vec3{1, 1, 1} * (d * 0.125f),   Vec3{-1, -1, -1} * (d * 0.250f),
      Vec3{-1, -1, 1} * (d * 0.375f), Vec3{-1, 1, -1} * (d * 0.500f),
      Vec3{-1, 1, 1} * (d * 0.625f),  Vec3{1, -1, -1} * (d * 0.750f),
      Vec3{1, -1, 1} * (d * 0.875f),  Vec3{1, 1, -1} * (d * 1.000f),
  };
  // The seed code runs the 8-vector kernel twice (j = 1, 2), each pass reflecting it about a
  // random vector looked up from the noise texture at a different scale. Here every pass p of 8
  // samples has its own 4x4 layer of random unit vectors, tiled over the image (so the 4x4 blur
  // still averages each pass over all 16 of its vectors); samples = 16 gives the seed's two
  // passes, other counts repeat the kernel (the last pass may be partial).
  const int passes = (samples + 7) / 8;
  Pcg32 rng(seed);
  std::vector<Vec3> noise(static_cast<size_t>(passes) * kNoise * kNoise);
  for (Vec3& r : noise) {
    const float rx = rng.uniform(-1.0f, 1.0f);
    const float ry = rng.uniform(-1.0f, 1.0f);
    const float rz = rng.uniform(-1.0f, 1.0f);
    r = ssao::normalize_or({rx, ry, rz}, Vec3{0.0f, 0.0f, 1.0f});
  }

  std::vector<float> raw(scene.depth.size(), 1.0f);
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      if (!is_geometry(scene.depth[index(scene, x, y)])) continue;
      const Vec3 origin = pixel_position(scene, x, y);
      int occluded = 0;
      for (int i = 0; i < samples; ++i) {
        const int pass = i / 8;
        const Vec3 r = noise[static_cast<size_t>(pass * kNoise * kNoise + noise_index(x, y))];
        const Vec3 k = kernel[i % 8];
        const Vec3 reflected = k - r * (2.0f * ssao::dot(k, r));  // HLSL reflect(k, r)
        // Our depth is linear in scene units, so the kernel is scaled in view space rather
        // than through the seed's normalised-depth kernel scale (same sample points).
        const Vec3 sample = origin + reflected * radius;
        float surface = 0.0f;
        if (!lookup_surface_z(scene, sample, surface)) continue;
        // The seed's fDelta = max(sampleDepth - (pixelDepth - kernel.z), 0): how far the surface
        // lies in front of the sample point. Its lerp(fDelta * w, x, saturate(fRange)) with the
        // demo's parameters amounts to counting occluders within range, so this port counts a
        // sample when 0 < delta < radius (binary range check on the depth difference).
        const float delta = surface - sample.z;
        if (delta > 0.0f && delta < radius) ++occluded;
      }
      const float o = static_cast<float>(occluded) / static_cast<float>(samples);
      // Flat = 1.0: half of a sphere kernel lies behind a flat surface.
      const float visibility = 2.0f * (1.0f - o);
      raw[index(scene, x, y)] = visibility < 1.0f ? visibility : 1.0f;
    }
  }
  return box_blur_4x4(scene, raw);
}

}  // namespace ssao_ref
