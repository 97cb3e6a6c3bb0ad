// SPDX-License-Identifier: MIT
// A caller-owned float image with byte strides (see the conventions in ssao.h).
#pragma once

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
};

}  // namespace ssao
