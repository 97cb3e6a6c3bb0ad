// SPDX-License-Identifier: MIT
#include "scene_check.h"

#include <algorithm>
#include <cmath>

#include "depth_pass.h"
#include "passes.h"

namespace povray_ssao {
namespace {

// Two renders of the same view differ only by a scene colour that leaks into the fog (jittered
// area lights): a few half-float steps of K, under 1% of the decoded depth. Another camera
// moves nearly every pixel.
constexpr double kSameDepth = 1e-2;
constexpr double kDifferentPixels = 0.01;

// True when the two depth images show the same view.
bool same_view(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  size_t different = 0;
  for (size_t p = 0; p < a.size(); ++p) {
    const bool background_a = !std::isfinite(a[p]), background_b = !std::isfinite(b[p]);
    if (background_a && background_b) continue;
    if (background_a != background_b ||
        std::fabs(a[p] - b[p]) > kSameDepth * std::max(a[p], b[p])) {
      ++different;
    }
  }
  return static_cast<double>(different) <= kDifferentPixels * static_cast<double>(a.size());
}

std::vector<float> decoded_depth(const PassRunner& povray, const std::string& name) {
  const ssao_tools::Image image = ssao_tools::read_image(povray.output(name));
  return decode_fog(image, prepass_distances(), povray.output(name));
}

}  // namespace

void check_scene_parses(const PassRunner& povray, const std::string& scene_name,
                        const Reporter& report) {
  write_check_wrappers(povray.scratch->path(), scene_name, ResolvedCamera{});
  report.begin("asking POV-Ray whether it can parse the scene... ");
  // +Q0: the parse is what is checked, not the image.
  const double seconds =
      povray.render("parse check", "scene_camera", "scene_camera.pov", 1, 1, {"+Q0", "-A", "-UA"});
  report.end("%.2f s: it can", seconds);
}

void check_default_camera(const PassRunner& povray, const std::string& scene_name,
                          const SceneScan& scan, const ResolvedCamera& default_camera, int width,
                          int height, const Reporter& report) {
  write_check_wrappers(povray.scratch->path(), scene_name, default_camera);
  // The size of the depth pre-pass: enough pixels to see the view, in a fraction of a second.
  const int pw = std::min(width, std::clamp(width / 8, 16, 80));
  const int ph =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(pw) * height / width)));
  report.begin(
      "the scene text has no camera: checking that POV-Ray renders it with its default "
      "camera (%dx%d)... ",
      pw, ph);
  const std::vector<std::string> options = depth_pass_options(prepass_distances(), scan);
  RunningPass scene_camera =
      povray.start("default-camera check", "scene_camera", "scene_camera.pov", pw, ph, options);
  RunningPass declared = povray.start("default-camera check, camera declared", "declared_camera",
                                      "declared_camera.pov", pw, ph, options);
  // The scene as POV-Ray renders it first: its parse error, if any, is the user's to see.
  const double scene_seconds = povray.finish(scene_camera);
  const double seconds = std::max(scene_seconds, povray.finish(declared));
  if (!same_view(decoded_depth(povray, "scene_camera"), decoded_depth(povray, "declared_camera"))) {
    report.end("%.2f s: it does not", seconds);
    throw ssao_tools::Error(
        "povray-ssao finds no camera { } block in the scene text, yet POV-Ray renders the scene "
        "with another camera than its default one (a camera made by a macro, or in a file the "
        "scan could not read?). Give the camera on the command line instead, e.g. "
        "--camera-location X,Y,Z --camera-look-at X,Y,Z --camera-angle DEG (also "
        "--camera-right, --camera-up, --camera-sky, --camera-direction, "
        "--camera-orthographic)");
  }
  report.end("%.2f s: it does", seconds);
}

}  // namespace povray_ssao
