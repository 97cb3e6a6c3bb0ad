// SPDX-License-Identifier: MIT
// The fog depth pass of one image (passes.h has the encoding): where its fogs go, the pre-pass
// that places them for a camera without look_at, and the checks of what it measured (a second
// render when the look_at guess missed the scene's depths; a refusal when no fog reached it).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pass_runner.h"
#include "passes.h"
#include "reporter.h"
#include "sdl.h"

namespace povray_ssao {

class DepthPass {
 public:
  // `given_distances`: --fog-distances. The pass is rendered at data_width x data_height (the
  // frame and its guard band); `camera` is the frame's.
  DepthPass(const std::optional<FogDistances>& given_distances, const PassRunner& povray,
            const SceneScan& scan, const ResolvedCamera& camera, int data_width, int data_height,
            const Reporter& report)
      : given_distances_(given_distances),
        povray_(povray),
        scan_(scan),
        camera_(camera),
        data_width_(data_width),
        data_height_(data_height),
        report_(report) {}

  // The fog distances: --fog-distances, else from the camera's look_at distance, else from a
  // small pre-pass rendered now.
  void choose_fogs();
  void start();
  // Waits for the pass and decodes it: the distance per pixel (radial, planar for an
  // orthographic camera; +inf on background), the band included. Renders it again with fogs
  // from its depths when the look_at guess missed them; throws when it measured nothing usable.
  std::vector<float> finish();

  double prepass_seconds = 0.0;
  double seconds = 0.0;  // the depth pass's, both renders if there were two

 private:
  void run_prepass();
  std::vector<float> read(std::vector<float>& precision) const;
  void report_depths(const DepthStats& depths, const DepthStats& errors) const;
  void check_usable(const DepthStats& errors) const;

  const std::optional<FogDistances> given_distances_;
  const PassRunner& povray_;
  const SceneScan& scan_;
  const ResolvedCamera& camera_;
  int data_width_, data_height_;
  const Reporter& report_;
  FogDistances distances_;
  bool guessed_ = false;  // placed from the look_at distance (checked against the result)
  RunningPass running_;
};

// The options of a fog depth render: +Q9 (fog needs it), no antialiasing (it would mix depths
// across silhouettes), the fogs, and the cheap radiosity for scenes that use radiosity.
std::vector<std::string> depth_pass_options(const FogDistances& fogs, const SceneScan& scan);

// "D1 = 25.2, D2 = 252"
std::string describe(const FogDistances& d);

}  // namespace povray_ssao
