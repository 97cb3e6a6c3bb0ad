// SPDX-License-Identifier: MIT
// Sample kernels and the per-pixel kernel rotation pattern shared by the variants.
#pragma once

#include <cstdint>
#include <vector>

#include "vec3.h"

namespace ssao {

// Unit directions (z = up for the hemisphere, any for the sphere) plus, per sample, the index of
// its radial stratum: sample k sits at radius * radial_scale((stratum[k] + pixel offset) / N).
struct Kernel {
  std::vector<Vec3> directions;
  std::vector<int> stratum;
};

// Cosine-weighted directions over the +z hemisphere: a Vogel (golden-angle) spiral on the unit
// disk lifted onto the hemisphere (Malley's method), so the kernel itself carries the cosine
// weighting of Cycles' AO.
Kernel make_hemisphere_kernel(int samples);

// Uniform directions over the sphere in antipodal pairs (d, -d) sharing a radius, so that a flat
// surface sees exactly half of every pair behind it.
Kernel make_sphere_kernel(int samples);

// Distance from the kernel centre, as a fraction of the radius, for a stratified s in [0, 1):
// lerp(0.1, 1, s^clustering). Clustering 2 is the seed code's curve; 0 puts all samples at 1.
float radial_scale(float s, float clustering);

// Per-pixel rotation and radial offset from a 4x4 tile: the 16 pixels of a tile see 16 distinct
// rotations (an ordered-dither pattern), so a 4-pixel-periodic blur averages them all.
struct PixelJitter {
  float cos_angle, sin_angle;  // rotation about the kernel's axis
  float radial_offset;         // in [0, 1): sub-stratum position of the radial samples
};
PixelJitter pixel_jitter(int x, int y, uint32_t seed);

constexpr int kNoiseTileSize = 4;

}  // namespace ssao
