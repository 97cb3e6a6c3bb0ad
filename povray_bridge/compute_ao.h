// SPDX-License-Identifier: MIT
// The AO step of both modes: libssao through its C API (ssao::api) on the frame's depth (with
// its guard band), normals, beauty and ambient term, then the output files.
#pragma once

#include "ao_inputs.h"
#include "options.h"
#include "reporter.h"

namespace povray_ssao {

// Runs libssao and writes the outputs (-o, --exr); returns the seconds spent in ssao_job_run.
// Throws ssao_tools::Error when interrupted or when the library fails; nothing is written then.
double compute_and_write(const Options& o, AoInputs& in, const Reporter& report);

}  // namespace povray_ssao
