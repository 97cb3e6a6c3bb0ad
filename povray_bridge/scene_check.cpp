// SPDX-License-Identifier: MIT
#include "scene_check.h"

#include "passes.h"

namespace povray_ssao {

void check_scene_parses(const PassRunner& povray, const std::string& scene_name,
                        const Reporter& report) {
  write_check_wrappers(povray.scratch->path(), scene_name);
  report.begin("asking POV-Ray whether it can parse the scene... ");
  // +Q0: the parse is what is checked, not the image.
  const double seconds =
      povray.render("parse check", "scene_camera", "scene_camera.pov", 1, 1, {"+Q0", "-A", "-UA"});
  report.end("%.2f s: it can", seconds);
}

}  // namespace povray_ssao
