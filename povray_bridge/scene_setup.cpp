// SPDX-License-Identifier: MIT
#include "scene_setup.h"

#include <unistd.h>

#include <cstdlib>
#include <vector>

#include "options.h"  // default_guard_band
#include "povray_run.h"
#include "scene_check.h"
#include "tools/files.h"

#ifndef POVRAY_SSAO_SOURCE_INCLUDES
#define POVRAY_SSAO_SOURCE_INCLUDES ""
#endif

namespace povray_ssao {
namespace {

namespace fs = std::filesystem;

// The folder of the shipped includes: next to the binary (<bin>/../share/povray-ssao), else
// the source tree's povray_bridge/pov.
std::string include_folder() {
  std::vector<fs::path> candidates;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(self.parent_path().parent_path() / "share" / "povray-ssao");
  if (*POVRAY_SSAO_SOURCE_INCLUDES) candidates.emplace_back(POVRAY_SSAO_SOURCE_INCLUDES);
  std::string tried;
  for (const fs::path& candidate : candidates) {
    if (fs::is_regular_file(candidate / "ssao_depth_post.inc", ec) &&
        fs::is_regular_file(candidate / "ssao_depth_pre.inc", ec) &&
        fs::is_regular_file(candidate / "ssao_ambient_post.inc", ec)) {
      return fs::absolute(candidate).lexically_normal().string();
    }
    tried += (tried.empty() ? "" : ", ") + in_quotes(candidate.string());
  }
  throw ssao_tools::Error(
      "cannot find povray-ssao's include files ssao_depth_pre.inc, "
      "ssao_depth_post.inc and ssao_ambient_post.inc (looked in " +
      tried + ")");
}

// The scene must be a readable file.
void check_scene(const std::string& scene) {
  std::error_code ec;
  if (!fs::exists(scene, ec)) throw ssao_tools::Error("no scene file " + in_quotes(scene));
  if (!fs::is_regular_file(scene, ec)) {
    throw ssao_tools::Error("the scene " + in_quotes(scene) + " is not a file");
  }
  if (::access(scene.c_str(), R_OK) != 0) {
    throw ssao_tools::Error("cannot read the scene file " + in_quotes(scene));
  }
}

// The outputs, --ini and --keep: refused now rather than after the rendering.
void check_outputs_and_folders(const RenderRequest& r) {
  std::error_code ec;
  if (!r.print_camera) {
    const OutputFiles& out = r.outputs;
    ssao_tools::check_output_folder(out.output);
    if (!out.exr.empty()) ssao_tools::check_output_folder(out.exr);
    if (ssao_tools::same_file(out.output, r.scene) ||
        (!out.exr.empty() && ssao_tools::same_file(out.exr, r.scene))) {
      throw UsageError("the output is the scene file; choose another -o");
    }
  }
  const std::string& ini = r.povray_arguments.ini;
  if (!ini.empty() && !fs::is_regular_file(ini, ec)) {
    throw ssao_tools::Error("no INI file " + in_quotes(ini));
  }
  if (!r.keep.empty()) {
    fs::create_directories(r.keep, ec);
    if (!fs::is_directory(r.keep, ec)) {
      throw ssao_tools::Error("--keep: cannot create the folder " + in_quotes(r.keep));
    }
  }
}

// The size POV-Ray will render: the command line's, else the INI file's, else povray.ini's, else
// its built-in 160x120. Throws when it is over povray-ssao's limit.
void frame_size(const RenderRequest& r, const std::string& scene_folder, int& width, int& height) {
  width = r.width;
  height = r.height;
  const std::string& ini = r.povray_arguments.ini;
  if (!ini.empty() && (width == 0 || height == 0)) {
    int w = 0, h = 0;
    ini_size(ini, w, h);
    if (width == 0) width = w;
    if (height == 0) height = h;
  }
  default_size(scene_folder, width, height);
  if (width > kMaxSide || height > kMaxSide || double(width) * double(height) > kMaxPixels) {
    throw ssao_tools::Error("the image size " + std::to_string(width) + "x" +
                            std::to_string(height) + " is over povray-ssao's limit of " +
                            "67108864 pixels (8192 x 8192, about 4 GB of passes)");
  }
}

// Where POV-Ray looks for include files, in its order: povray.ini's and --ini's Library_Path,
// the command line's +L, the scene's folder, povray-ssao's includes (relative to the scene).
std::vector<std::string> library_paths(const PovrayArguments& user, const std::string& startup_ini,
                                       const std::string& scene_folder,
                                       const std::string& includes) {
  std::vector<std::string> paths;
  if (!startup_ini.empty()) ini_library_paths(startup_ini, paths);
  if (!user.ini.empty()) ini_library_paths(user.ini, paths);
  for (const std::string& option : user.options) {
    if (option.size() > 2 && (option[1] == 'L' || option[1] == 'l')) {
      paths.push_back(option.substr(2));
    } else if (option.size() > 13 &&
               (option.rfind("Library_Path=", 0) == 0 || option.rfind("library_path=", 0) == 0)) {
      paths.push_back(option.substr(13));
    }
  }
  paths.push_back(scene_folder);
  paths.push_back(includes);
  for (std::string& path : paths) {
    if (fs::path(path).is_relative()) path = (fs::path(scene_folder) / path).string();
  }
  return paths;
}

// The Declare=NAME=VALUE settings of povray.ini, --ini and the command line, as the numbers the
// scan knows (POV-Ray's Declare= takes floats only); reads the clock options on the way.
Symbols declared_values(const PovrayArguments& user, const std::string& startup_ini,
                        ClockOptions& clock) {
  std::vector<std::string> declares;
  if (!startup_ini.empty()) ini_declares(startup_ini, declares, clock);
  if (!user.ini.empty()) ini_declares(user.ini, declares, clock);
  option_declares(user.options, declares, clock);
  Symbols symbols;
  for (const std::string& declare : declares) {
    const size_t equals = declare.find('=');
    Symbol symbol;
    symbol.kind = Symbol::kValue;
    symbol.declared_at = "Declare=" + declare;
    char* end = nullptr;
    symbol.value.v.x = std::strtod(declare.c_str() + equals + 1, &end);
    if (equals != std::string::npos && end && *end == '\0') {
      symbols[declare.substr(0, equals)] = symbol;
    }
  }
  return symbols;
}

}  // namespace

RenderSetup prepare_render(const RenderRequest& request) {
  check_scene(request.scene);
  RenderSetup setup;
  setup.scene_path = fs::absolute(request.scene).lexically_normal();
  setup.scene_folder = setup.scene_path.parent_path().string();
  setup.scene_name = setup.scene_path.filename().string();
  if (setup.scene_name.find('"') != std::string::npos) {
    throw ssao_tools::Error(
        "the scene's file name contains '\"', which POV-Ray's #include cannot "
        "take");
  }
  check_outputs_and_folders(request);
  frame_size(request, setup.scene_folder, setup.width, setup.height);
  // A band too large is every frame's mistake.
  guard_band(request.overscan, request.depth_only, setup.width, setup.height);

  // The camera is read from the scene text and its include files, found as POV-Ray finds them.
  setup.includes = include_folder();
  const std::string startup_ini = system_ini(setup.scene_folder);
  ScanSettings& settings = setup.settings;
  settings.directory = setup.scene_folder;
  settings.library_paths =
      library_paths(request.povray_arguments, startup_ini, setup.scene_folder, setup.includes);
  settings.image_width = setup.width;
  settings.image_height = setup.height;
  settings.predeclared = declared_values(request.povray_arguments, startup_ini, setup.clock);
  settings.clock = setup.clock.clock;
  return setup;
}

int guard_band(const std::optional<int>& overscan, bool depth_only, int width, int height) {
  if (depth_only) return 0;
  auto fits = [&](int band) {
    const long long data_width = static_cast<long long>(width) + 2LL * band;
    const long long data_height = static_cast<long long>(height) + 2LL * band;
    return band >= 0 && data_width <= kMaxSide && data_height <= kMaxSide &&
           double(data_width) * double(data_height) <= kMaxPixels;
  };
  if (!overscan) {
    // The default shrinks near the size limits rather than refusing a frame that fits.
    int band = default_guard_band(width, height);
    while (band > 0 && !fits(band)) --band;
    return band;
  }
  const int band = *overscan;
  if (!fits(band)) {
    const long long data_width = static_cast<long long>(width) + 2LL * band;
    const long long data_height = static_cast<long long>(height) + 2LL * band;
    throw ssao_tools::Error(
        "--overscan " + std::to_string(band) + ": the data passes would be " +
        std::to_string(data_width) + "x" + std::to_string(data_height) +
        ", over povray-ssao's limit of 65536 pixels a side and 67108864 pixels (8192 x 8192); "
        "choose a smaller band");
  }
  return band;
}

PassRunner make_pass_runner(const PassRunnerSettings& settings, const RenderSetup& setup,
                            const AnimationFrame* frame, const ScratchFolder& scratch,
                            const SceneScan* scan) {
  const PovrayArguments& user = settings.arguments;
  PassRunner povray;
  povray.executable = find_executable(settings.executable);
  povray.scene_folder = setup.scene_folder;
  povray.scene_name = setup.scene_name;
  povray.include_folder = setup.includes;
  if (!user.ini.empty()) povray.user_options.push_back(fs::absolute(user.ini).string());
  povray.user_options.insert(povray.user_options.end(), user.options.begin(), user.options.end());
  povray.scratch = &scratch;
  povray.frame = frame;
  povray.keep = settings.keep;
  // Runs of a scene that writes files while it parses share them: one after another.
  povray.one_at_a_time = scan != nullptr && !scan->file_write.empty();
  return povray;
}

ImageScene read_image_scene(const CameraOverrides& camera_flags, bool print_camera,
                            const PassRunnerSettings& povray, const RenderSetup& setup,
                            const AnimationFrame* frame, const Reporter& report) {
  ScanSettings settings = setup.settings;
  if (frame) {
    settings.clock = frame->clock;
    declare_frame(setup.clock, *frame, settings.predeclared);
  }
  ImageScene scene;
  try {
    scene.scan = scan_scene(setup.scene_path.string(), settings);
    scene.reading = read_camera(scene.scan, camera_flags, setup.width, setup.height);
  } catch (const ssao_tools::Error&) {
    // A syntax error often looks like a missing or unreadable camera to the scan: POV-Ray's
    // own message says what is wrong, and where. --print-camera renders nothing.
    if (!print_camera) {
      ScratchFolder scratch;
      check_scene_parses(make_pass_runner(povray, setup, frame, scratch, nullptr), setup.scene_name,
                         report);
    }
    throw;
  }
  if (scene.reading.default_camera && !camera_flags.any() && !print_camera) {
    ScratchFolder scratch;
    check_default_camera(make_pass_runner(povray, setup, frame, scratch, &scene.scan),
                         setup.scene_name, scene.scan, scene.reading.camera, setup.width,
                         setup.height, report);
  }
  return scene;
}

}  // namespace povray_ssao
