// SPDX-License-Identifier: MIT
// Sampling patterns shared by the variants: point kernels and the per-pixel jitter pattern. All
// of it is computed once per run into tables; nothing here runs per sample.
#pragma once

#include <array>
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

// Per-pixel rotation and offset from a 4x4 tile: the 16 pixels of a tile see 16 distinct states
// (an ordered-dither pattern), so a 4-pixel-periodic blur averages them all.
constexpr int kNoiseTileSize = 4;
constexpr int kJitterStates = kNoiseTileSize * kNoiseTileSize;
inline int jitter_index(int x, int y) {
  // 4x4 ordered-dither (Bayer) indices: neighbours get states far apart.
  static constexpr int bayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
  return bayer[y & 3][x & 3];
}

struct JitterState {
  float angle;                 // in [0, 1): a fraction of the full turn (or of the slice range)
  float cos_angle, sin_angle;  // of 2 * pi * angle
  float radial_offset;         // in [0, 1): sub-stratum position of the radial samples
};
// The 16 states for a seed, indexed by jitter_index().
std::array<JitterState, kJitterStates> jitter_states(uint32_t seed);

}  // namespace ssao
