// SPDX-License-Identifier: MIT
// A caller-owned float image with byte strides (see the conventions in ssao.h).
#pragma once

#include <algorithm>
#include <cstddef>

namespace ssao {

struct ImageView {
  float* data = nullptr;
  int width = 0, height = 0, channels = 0;
  std::ptrdiff_t pixel_stride = 0, row_stride = 0;  // bytes, already resolved (never 0)

  bool attached() const { return data != nullptr; }
  float* pixel(int x, int y) const {
    return reinterpret_cast<float*>(reinterpret_cast<char*>(data) + y * row_stride +
                                    x * pixel_stride);
  }
  // Channel 0 of pixels [x, x + count) of row y into out (one copy when the channel is packed).
  void read_channel0(int x, int y, int count, float* out) const {
    const float* p = pixel(x, y);
    const std::ptrdiff_t step = pixel_stride / std::ptrdiff_t(sizeof(float));
    if (step == 1) {
      std::copy_n(p, count, out);
      return;
    }
    for (int i = 0; i < count; ++i, p += step) out[i] = p[0];
  }
};

}  // namespace ssao
