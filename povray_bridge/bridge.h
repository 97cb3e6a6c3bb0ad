// SPDX-License-Identifier: MIT
// What povray-ssao does once its command line is parsed: the render mode (povray passes, AO,
// outputs) and the post-process mode (existing beauty + depth, AO, outputs).
#pragma once

#include "options.h"

namespace povray_ssao {

// Both throw UsageError for command-line mistakes found late and ssao_tools::Error for any other
// failure; in both cases no output file is left behind.
void run_render(const Options& options);
void run_post_process(const Options& options);

}  // namespace povray_ssao
