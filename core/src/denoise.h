// SPDX-License-Identifier: MIT
// Blurs that remove the 4x4 jitter pattern from the raw AO estimate. Both are separable: a
// horizontal pass in place over row bands, then a vertical pass per tile that the job fuses with
// the output stage, so the filter needs no image-size buffer of its own. Each pass first decodes
// the positions and normals it reads into planes of floats, so its inner loop is contiguous
// loads that the compiler vectorises.
#pragma once

#include <vector>

#include "frame.h"
#include "tiles.h"

namespace ssao {

enum class DenoiseMode { none, box4, bilateral };

class Denoiser {
 public:
  Denoiser(const Frame& frame, DenoiseMode mode, float radius)
      : f_(frame), mode_(mode), radius_(radius) {}

  // Filters the rows of `visibility` in place. Background pixels keep their value and are never
  // read.
  void horizontal_pass(float* visibility, TilePool& pool, Progress& progress) const;
  // The vertical pass over one tile, reading the horizontally filtered visibility; writes
  // out[(y - t.y0) * (t.x1 - t.x0) + (x - t.x0)].
  void vertical_pass(const float* visibility, const Tile& t, float* out) const;

 private:
  const Frame& f_;
  DenoiseMode mode_;
  float radius_;
};

// Joint bilateral upsampling of a half-resolution estimate (resolution = half): the visibility
// of the full-resolution pixels of tile t into out (tile-local rows), from the horizontally
// filtered visibility of `half` (made by Frame::downsample of `full`), whose vertical pass
// `vertical` runs here on the rows the tile reads. Each pixel takes the four half-resolution
// pixels around it, weighted bilinearly and by its distance from their tangent planes, so AO
// does not leak across silhouettes. Background pixels get 1.
void upsample(const Frame& full, const Frame& half, const float* half_visibility,
              const Denoiser& vertical, float radius, const Tile& t, float* out);

}  // namespace ssao
