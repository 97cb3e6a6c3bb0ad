// SPDX-License-Identifier: MIT
#include "pixel_filter.h"

#include <algorithm>
#include <cmath>

#include "scratch.h"
#include "simd.h"

namespace ssao {

float pixel_filter_weight(double sigma) {
  if (!(sigma > 0.0)) return 0.0f;
  return float(0.5 * std::erfc(0.5 / (sigma * std::sqrt(2.0))));
}

Tile pixel_filter_source(const Frame& frame, const Tile& t) {
  return {std::max(t.x0 - 1, 0), std::max(t.y0 - 1, 0), std::min(t.x1 + 1, frame.width()),
          std::min(t.y1 + 1, frame.height())};
}

namespace {

// Row pieces of the filter, each a plain loop of loads, selects and multiplies that the compiler
// vectorises.

// A row's visibility where it is geometry, 0 elsewhere, and the geometry mask.
SSAO_VECTORIZE void masked_row(const float* __restrict depth, const float* __restrict visibility,
                               int count, float* __restrict value, float* __restrict mask) {
  for (int i = 0; i < count; ++i) {
    const bool geometry = depth[i] != Frame::kBackground;
    mask[i] = geometry ? 1.0f : 0.0f;
    value[i] = geometry ? visibility[i] : 0.0f;
  }
}

// The horizontal pass over a padded row (index -1 and count exist): weighted values and weights.
SSAO_VECTORIZE void horizontal_row(const float* __restrict value, const float* __restrict mask,
                                   int count, float side, float centre, float* __restrict value_out,
                                   float* __restrict mask_out) {
  for (int i = 0; i < count; ++i) {
    value_out[i] = side * (value[i - 1] + value[i + 1]) + centre * value[i];
    mask_out[i] = side * (mask[i - 1] + mask[i + 1]) + centre * mask[i];
  }
}

// The vertical pass over three horizontally filtered rows (above, the row, below; `stride` apart)
// and the normalisation; pixels that are not geometry keep their own value.
SSAO_VECTORIZE void vertical_row(const float* __restrict value, const float* __restrict mask,
                                 size_t stride, const float* __restrict own,
                                 const float* __restrict own_mask, int count, float side,
                                 float centre, float* __restrict out) {
  for (int i = 0; i < count; ++i) {
    const float sum = side * (value[i] + value[i + 2 * stride]) + centre * value[i + stride];
    const float total = side * (mask[i] + mask[i + 2 * stride]) + centre * mask[i + stride];
    // A geometry pixel's own weight is centre^2 > 0.14 (w <= 0.31), so total > 0 there.
    const bool geometry = own_mask[i] > 0.0f;
    out[i] = geometry ? sum / (geometry ? total : 1.0f) : own[i];
  }
}

}  // namespace

void pixel_filter(const Frame& frame, const Tile& around, const float* source, const Tile& t,
                  float weight, float* out) {
  const int width = t.x1 - t.x0, height = t.y1 - t.y0;
  const int source_width = around.x1 - around.x0;
  const float side = weight, centre = 1.0f - 2.0f * weight;
  // Rows t.y0 - 1 .. t.y1 with a column either side: geometry-weighted values and the geometry
  // mask, 0 outside the frame.
  const size_t padded = size_t(width) + 2;
  const int rows = height + 2;
  ScratchVector<float> value(padded * rows, 0.0f), mask(padded * rows, 0.0f);
  for (int y = around.y0; y < around.y1; ++y) {
    const size_t at = size_t(y - (t.y0 - 1)) * padded + size_t(around.x0 - (t.x0 - 1));
    masked_row(frame.depth_plane() + frame.index(around.x0, y),
               source + size_t(y - around.y0) * source_width, source_width, value.data() + at,
               mask.data() + at);
  }
  ScratchVector<float> row_value(size_t(width) * rows), row_mask(size_t(width) * rows);
  for (int r = 0; r < rows; ++r) {
    horizontal_row(value.data() + r * padded + 1, mask.data() + r * padded + 1, width, side, centre,
                   row_value.data() + size_t(r) * width, row_mask.data() + size_t(r) * width);
  }
  for (int y = 0; y < height; ++y) {
    vertical_row(row_value.data() + size_t(y) * width, row_mask.data() + size_t(y) * width,
                 size_t(width),
                 source + size_t(y + t.y0 - around.y0) * source_width + (t.x0 - around.x0),
                 mask.data() + (y + 1) * padded + 1, width, side, centre, out + size_t(y) * width);
  }
}

}  // namespace ssao
