// SPDX-License-Identifier: MIT
// The render mode's setup: what is checked before POV-Ray runs (the scene, the outputs, the
// size, the guard band), what every image of a render shares (RenderSetup), and the scene as
// one image sees it (scanned at its clock, its camera read).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "animation.h"
#include "outputs.h"
#include "pass_runner.h"
#include "pov_camera.h"
#include "reporter.h"
#include "sdl.h"

namespace povray_ssao {

// POV-Ray would render a size this large for hours before anything failed; each of the passes,
// the AO buffers and the outputs hold it as float (about 64 bytes a pixel in all).
constexpr double kMaxPixels = 8192.0 * 8192.0;
constexpr int kMaxSide = 65536;

// What every image of a render shares: the scene, the size, the scan settings, the clock.
struct RenderSetup {
  std::filesystem::path scene_path;
  std::string scene_folder, scene_name;
  std::string includes;  // the folder of povray-ssao's shipped include files
  int width = 0, height = 0;
  ScanSettings settings;
  ClockOptions clock;
};

// --ini and the options passed through to POV-Ray (+X switches, Name=value), in order: the scan
// reads their Library_Path and Declare= settings, and every povray run gets them.
struct PovrayArguments {
  std::string ini;
  std::vector<std::string> options;
};

// The render the command line asks for, as prepare_render checks it.
struct RenderRequest {
  std::string scene;
  int width = 0, height = 0;  // 0: not given
  PovrayArguments povray_arguments;
  OutputFiles outputs;
  bool print_camera = false;  // writes no output, so the outputs are not checked
  std::string keep;           // --keep's folder, or empty
  std::optional<int> overscan;
  bool depth_only = false;
};

// Checks the scene file, the outputs, --ini, --keep and the image size, and gathers what the
// scan needs: the library paths and Declare= values POV-Ray will see. Throws ssao_tools::Error
// (UsageError for an output that is the scene) before anything is rendered.
RenderSetup prepare_render(const RenderRequest& request);

// The guard band of the data passes (pixels per side): `overscan` (--overscan), else the
// default; none for --depth-only (the frame's depth is its output). Throws when `overscan`
// would take the data passes over the size limits.
int guard_band(const std::optional<int>& overscan, bool depth_only, int width, int height);

// How an image's povray runs are made: the executable (--povray), the user's arguments, and
// whether --keep copies their files.
struct PassRunnerSettings {
  std::string executable;
  PovrayArguments arguments;
  bool keep = false;
};

// The runner of an image's povray runs: in the scene's folder, with the user's --ini and
// options, an animation frame alone, the files in `scratch`; one run after another when the
// scan found that parsing the scene writes a file (null: a single run, nothing shared).
PassRunner make_pass_runner(const PassRunnerSettings& settings, const RenderSetup& setup,
                            const AnimationFrame* frame, const ScratchFolder& scratch,
                            const SceneScan* scan);

// The scene as one image (a still, or an animation's frame) sees it.
struct ImageScene {
  SceneScan scan;
  CameraReading reading;
};

// Scans the scene text at the frame's clock and reads its camera (with `camera_flags`, the
// --camera-* flags). Where the text fails (a scan error, an unreadable camera), POV-Ray's
// parser is asked first, so that a syntax error is reported as POV-Ray reports it; a scene
// without a camera gets POV-Ray's default camera once POV-Ray is seen to render it with that
// (scene_check.h). With --print-camera (`print_camera`) POV-Ray is not run.
ImageScene read_image_scene(const CameraOverrides& camera_flags, bool print_camera,
                            const PassRunnerSettings& povray, const RenderSetup& setup,
                            const AnimationFrame* frame, const Reporter& report);

}  // namespace povray_ssao
