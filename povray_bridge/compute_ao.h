// SPDX-License-Identifier: MIT
// The AO step of both modes: libssao through its C API (ssao::api) on the frame's depth (with
// its guard band), normals, beauty and ambient term, then the output files.
#pragma once

#include <vector>

#include "ao_inputs.h"
#include "outputs.h"
#include "reporter.h"
#include "tools/param_flags.h"

namespace povray_ssao {

// Runs libssao with the user's `params` (in command-line order) and writes `files`; returns the
// seconds spent in ssao_job_run. Throws ssao_tools::Error when interrupted or when the library
// fails; nothing is written then.
double compute_and_write(const std::vector<ssao_tools::ParamSetting>& params,
                         const OutputFiles& files, AoInputs& in, const Reporter& report);

}  // namespace povray_ssao
