// SPDX-License-Identifier: MIT
// Blurs that remove the 4x4 rotation pattern from the raw AO estimate.
#pragma once

#include <vector>

#include "gbuffer.h"
#include "parallel.h"

namespace ssao {

enum class DenoiseMode { none, box4, bilateral };

// Returns the filtered visibility; background pixels keep their value and are never read.
std::vector<float> denoise(const GBuffer& g, const std::vector<float>& visibility, DenoiseMode mode,
                           float radius, int threads, Progress& progress);

}  // namespace ssao
