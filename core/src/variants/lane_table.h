// SPDX-License-Identifier: MIT
// The per-pixel jitter tables of the vector kernels (hemisphere, volumetric) laid out for SIMD
// loads: the jitter pattern repeats every 4 pixels of a row (jitter_index), so for each row
// class (y & 3), sample and component a row of kLaneTable lanes starting at a pixel whose x is
// a multiple of 4 serves a vector of up to kMaxLanes starting at any x (read from lane x & 3).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "sampling.h"

namespace ssao {

constexpr int kMaxLanes = 16;  // AVX-512 floats
constexpr int kLaneTable = kMaxLanes + 3;

// [y & 3][sample][component][lane]: table[((row * samples + s) * Components + c) * kLaneTable
// + lane] = value(jitter_index(lane, row), s)[c].
template <int Components, class Value>
std::vector<float> lane_table(int samples, Value value) {
  std::vector<float> table(size_t(4) * samples * Components * kLaneTable);
  for (int row = 0; row < 4; ++row) {
    for (int s = 0; s < samples; ++s) {
      for (int lane = 0; lane < kLaneTable; ++lane) {
        const std::array<float, Components> v = value(jitter_index(lane, row), s);
        float* dst = table.data() + (size_t(row) * samples + s) * Components * kLaneTable + lane;
        for (int c = 0; c < Components; ++c) dst[c * kLaneTable] = v[c];
      }
    }
  }
  return table;
}

}  // namespace ssao
