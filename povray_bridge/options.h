// SPDX-License-Identifier: MIT
// povray-ssao's command line. Library parameters are not listed here: every parameter of the
// core's table is accepted as --NAME-WITH-DASHES VALUE through io/param_flags.h, the code the
// ssao tool uses.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "passes.h"
#include "pov_camera.h"
#include "tools/param_flags.h"

namespace povray_ssao {

using ssao_tools::UsageError;

struct Options {
  bool help = false;
  bool version = false;
  bool quiet = false;
  bool depth_only = false;
  bool print_camera = false;
  bool no_normals = false;

  // Render mode.
  std::string scene;
  int width = 0, height = 0;  // 0: not given
  std::string ini;
  std::string keep;
  std::string povray = "povray";
  std::vector<std::string> povray_options;  // +X switches and Name=value options, in order
  std::optional<FogDistances> fog_distances;
  std::string apply_to = "auto";  // auto | ambient | beauty
  // Guard band of the data passes, pixels per side; unset: default_guard_band().
  std::optional<int> overscan;
  CameraOverrides camera;

  // Post-process mode.
  std::string beauty;
  std::string depth;
  std::string depth_channel;
  double depth_scale = 1.0;
  std::optional<double> camera_aspect;
  std::optional<double> camera_width;

  // Both.
  std::string output;
  std::string exr;
  std::vector<ssao_tools::ParamSetting> params;  // in command-line order

  bool post_process() const { return !beauty.empty() || !depth.empty(); }
  // The value given for a library parameter, or nullptr.
  const ssao_tools::ParamSetting* param(const std::string& name) const;
};

// The guard band povray-ssao renders around a W x H frame without --overscan (docs/povray.md,
// "Guard band", has the measurements behind it).
int default_guard_band(int width, int height);

// Parses argv. With --help or --version anywhere, only that flag is honoured. Throws UsageError
// for anything wrong or missing, and for combinations that contradict each other.
Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table);

// The --help text, library parameters taken from `table`.
std::string usage_text(const std::vector<ssao_param_desc>& table);

}  // namespace povray_ssao
