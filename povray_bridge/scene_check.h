// SPDX-License-Identifier: MIT
// Asking POV-Ray where the scene text does not tell povray-ssao enough: whether POV-Ray can
// parse a scene the scan could not read.
#pragma once

#include <string>

#include "pass_runner.h"
#include "reporter.h"

namespace povray_ssao {

// Renders the scene once, tiny. Throws ssao_tools::Error with POV-Ray's parse error (file,
// line, message) when POV-Ray cannot parse it; returns when it can.
void check_scene_parses(const PassRunner& povray, const std::string& scene_name,
                        const Reporter& report);

}  // namespace povray_ssao
