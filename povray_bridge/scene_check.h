// SPDX-License-Identifier: MIT
// Asking POV-Ray where the scene text does not tell povray-ssao enough: whether POV-Ray can
// parse a scene the scan could not read, and whether a scene whose text has no camera is
// rendered with POV-Ray's default camera (not with one the scan cannot see).
#pragma once

#include <string>

#include "pass_runner.h"
#include "pov_camera.h"
#include "reporter.h"
#include "sdl.h"

namespace povray_ssao {

// Renders the scene once, tiny. Throws ssao_tools::Error with POV-Ray's parse error (file,
// line, message) when POV-Ray cannot parse it; returns when it can.
void check_scene_parses(const PassRunner& povray, const std::string& scene_name,
                        const Reporter& report);

// For a scene whose text has no camera: renders its depth small, as POV-Ray renders the scene
// and with `default_camera` declared after it, at once. They must agree, or the scene has a
// camera the scan cannot see (made by a macro, in a file it could not read) which the passes
// would silently replace: then throws, asking for --camera-* flags. Throws POV-Ray's parse
// error when it cannot parse the scene.
void check_default_camera(const PassRunner& povray, const std::string& scene_name,
                          const SceneScan& scan, const ResolvedCamera& default_camera, int width,
                          int height, const Reporter& report);

}  // namespace povray_ssao
