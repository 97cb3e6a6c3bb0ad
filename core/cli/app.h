// SPDX-License-Identifier: MIT
// What the ssao tool does once its command line is parsed.
#pragma once

#include <vector>

#include "args.h"

namespace ssao_cli {

// Reads the input and the camera, computes AO and writes the output. Throws UsageError for
// command-line mistakes found late (output = input, a value the core rejects), ssao_io::Error for
// any other failure; in both cases nothing has been written under the output name.
void run_ssao(const Options& options);

}  // namespace ssao_cli
