// SPDX-License-Identifier: MIT
#include "sampling.h"

#include <cmath>
#include <numeric>

#include "portable_math.h"

namespace ssao {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kGoldenAngle = 2.39996322972865332f;  // pi * (3 - sqrt(5))

// A step coprime with n near n / golden ratio: (k * step) % n visits every stratum once while
// decorrelating radius from direction.
int stratum_step(int n) {
  int step = std::max(1, static_cast<int>(std::lround(n * 0.6180339887)));
  while (std::gcd(step, n) != 1) ++step;
  return step;
}

uint32_t hash_u32(uint32_t v) {  // "lowbias32" by Chris Wellons
  v ^= v >> 16;
  v *= 0x7feb352dU;
  v ^= v >> 15;
  v *= 0x846ca68bU;
  v ^= v >> 16;
  return v;
}

float unit_float(uint32_t v) { return float(v >> 8) * (1.0f / 16777216.0f); }

}  // namespace

Kernel make_hemisphere_kernel(int samples) {
  Kernel kernel;
  const int step = stratum_step(samples);
  for (int k = 0; k < samples; ++k) {
    const float disk_radius = std::sqrt((float(k) + 0.5f) / float(samples));
    const float angle = float(k) * kGoldenAngle;
    const float z = std::sqrt(std::max(0.0f, 1.0f - disk_radius * disk_radius));
    kernel.directions.push_back(
        {disk_radius * portable_cos(angle), disk_radius * portable_sin(angle), z});
    kernel.stratum.push_back(int((long(k) * step) % samples));
  }
  return kernel;
}

Kernel make_sphere_kernel(int samples) {
  Kernel kernel;
  const int pairs = (samples + 1) / 2;
  const int step = stratum_step(pairs);
  for (int k = 0; k < pairs; ++k) {
    // Uniform in solid angle over a hemisphere; the pair's mirror covers the other half.
    const float z = (float(k) + 0.5f) / float(pairs);
    const float ring = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float angle = float(k) * kGoldenAngle;
    const Vec3 d{ring * portable_cos(angle), ring * portable_sin(angle), z};
    const int stratum = int((long(k) * step) % pairs);
    kernel.directions.push_back(d);
    kernel.stratum.push_back(stratum);
    kernel.directions.push_back(-d);
    kernel.stratum.push_back(stratum);
  }
  return kernel;
}

float radial_scale(float s, float clustering) {
  const float shaped = clustering == 0.0f ? 1.0f : portable_pow(s, clustering);
  return 0.1f + 0.9f * shaped;
}

std::array<JitterState, kJitterStates> jitter_states(uint32_t seed) {
  const uint32_t h = hash_u32(seed * 0x9e3779b9U + 0x632be5abU);
  const float angle_offset = unit_float(h);
  const float radial_seed = unit_float(hash_u32(h));
  std::array<JitterState, kJitterStates> states{};
  for (int index = 0; index < kJitterStates; ++index) {
    const float angle = (float(index) + angle_offset) / float(kJitterStates);
    // A second, differently ordered index for the radius: 7 is coprime with 16.
    const int radial_index = (index * 7 + 3) & 15;
    float radial = (float(radial_index) + radial_seed) / float(kJitterStates);
    if (radial >= 1.0f) radial -= 1.0f;
    states[index] = {angle, portable_cos(2.0f * kPi * angle), portable_sin(2.0f * kPi * angle),
                     radial};
  }
  return states;
}

}  // namespace ssao
