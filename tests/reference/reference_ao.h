// SPDX-License-Identifier: MIT
// Reference AO implementations used only by tests and benchmarks, never by the product:
//  - a brute-force ray march through the depth buffer (the accuracy floor of screen-space AO),
//  - straight ports of the seed tutorials' code (the baseline the product must beat).
// They take a depth buffer plus the core's camera model, and write visibility (1 = unoccluded).
#pragma once

#include <cstdint>
#include <vector>

#include "camera.h"  // core/src: the Blender camera model (tested against Blender's own matrix)

namespace ssao_ref {

struct DepthScene {
  int width = 0, height = 0;
  std::vector<float> depth;  // planar depth, row 0 = top; background = +inf or >= 1e9
  std::vector<float>
      view_normal;  // 3 floats per pixel, view space (-Z forward), unit; may be empty
  ssao::CameraModel camera{ssao::CameraParams{}, 1, 1};
};

struct RayMarchSettings {
  float radius = 1.0f;     // scene units (Cycles' AO distance)
  int rays = 128;          // cosine-weighted rays per pixel
  int steps = 24;          // steps along each ray
  float thickness = 0.5f;  // occluders are assumed this many radii thick
  uint32_t seed = 1;
};

// Cosine-weighted binary visibility within `radius`, marching each ray through the depth buffer
// (a step is blocked when it lies behind the visible surface by less than the thickness).
std::vector<float> raymarch_ao(const DepthScene& scene, const RayMarchSettings& settings);

// Line-for-line port of the seed "normal-oriented hemisphere" tutorial (Chapman; seeds 002/003):
// 16 random kernel samples scaled lerp(0.1, 1, s^2), a 4x4 random rotation texture, binary range
// check |origin.z - sampleDepth| < radius, no bias, then the 4x4 box blur.
std::vector<float> seed_hemisphere_ao(const DepthScene& scene, float radius, int samples = 16,
                                      uint32_t seed = 1);

// Port of the seed Crysis sphere method (seed 000 kernel shape, reflected by a 4x4 random-vector
// texture), counting samples behind the depth surface within range, normalised so that a flat
// surface reads 1 (visibility = min(1, 2 * (1 - occluded fraction))), then the 4x4 box blur.
std::vector<float> seed_sphere_ao(const DepthScene& scene, float radius, int samples = 16,
                                  uint32_t seed = 1);

}  // namespace ssao_ref
