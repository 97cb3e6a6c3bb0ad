// SPDX-License-Identifier: MIT
// The pixel filter (parameter pixel_filter): the resolved AO seen through a renderer's
// anti-aliasing. A renderer's passes are filtered over each pixel's footprint, so Cycles' AO pass
// at a pixel on a silhouette mixes the AO of both surfaces by their share of it, where the Depth
// pass (one sample) holds one surface and a per-pixel estimate draws a staircase. Each pixel's
// value spread over its square and blurred by a Gaussian of standard deviation sigma gives a
// 3 x 3 kernel k(dx) k(dy), k = {w, 1 - 2 w, w}, w the Gaussian's mass beyond half a pixel.
#pragma once

#include "frame.h"
#include "tiles.h"

namespace ssao {

// w for a Gaussian of standard deviation sigma pixels (0: no filter); sigma <= 1 keeps the
// mass beyond 1.5 pixels, which the kernel leaves out, below 7 %.
float pixel_filter_weight(double sigma);

// Tile t's visibility through the filter into out (tile-local rows): `source` holds the
// visibility of tile `around` (t grown by one pixel on every side, clipped to the frame) in rows
// of around's width. Only geometry pixels are filtered and only geometry pixels take part (the
// weights renormalised): AO does not bleed into the sky or the sky's 1 into the AO.
void pixel_filter(const Frame& frame, const Tile& around, const float* source, const Tile& t,
                  float weight, float* out);

// Tile t grown by one pixel on every side, clipped to the frame: what pixel_filter reads.
Tile pixel_filter_source(const Frame& frame, const Tile& t);

}  // namespace ssao
