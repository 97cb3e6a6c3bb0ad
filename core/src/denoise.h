// SPDX-License-Identifier: MIT
// Blurs that remove the 4x4 jitter pattern from the raw AO estimate. Both are separable: a
// horizontal pass in place over row bands, then a vertical pass that the job fuses with the
// output stage, so the filter needs no image-size buffer of its own.
#pragma once

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
  // The vertical pass at one geometry pixel, reading the horizontally filtered visibility.
  float vertical(const float* visibility, int x, int y) const;

 private:
  template <bool Horizontal>
  float filter(const float* visibility, int x, int y) const;

  const Frame& f_;
  DenoiseMode mode_;
  float radius_;
};

}  // namespace ssao
