// SPDX-License-Identifier: MIT
// The povray runs of one image, all started at once: the beauty, the fog depth pass
// (depth_pass.h), the ambient pass (for AO on the ambient light) and the normal pass (scenes
// that include ssao_passes.inc); each finished pass fills its part of the AO step's inputs.
#pragma once

#include <optional>
#include <string>

#include "ao_inputs.h"
#include "depth_pass.h"
#include "pass_runner.h"
#include "passes.h"
#include "reporter.h"
#include "scene_setup.h"

namespace povray_ssao {

// Wall-clock seconds of each pass; 0 for a pass not rendered.
struct PassTimings {
  double prepass = 0.0, beauty = 0.0, depth = 0.0, ambient = 0.0, normals = 0.0;
};

// "beauty 1.20 s, depth 0.80 s, ambient 0.55 s": the passes rendered.
std::string describe(const PassTimings& timings);

// What the command line decides about an image's passes.
struct PassChoices {
  bool depth_only = false;  // --depth-only: the depth pass alone
  std::string apply_to;     // --apply-to: auto | ambient | beauty (whether the ambient pass)
  bool no_normals = false;  // --no-normals: no normal pass even where the scene has one
  std::optional<FogDistances> fog_distances;  // --fog-distances
};

class ImagePasses {
 public:
  // The wrappers (passes.h: write_wrappers) must be in the runner's scratch folder.
  ImagePasses(const PassChoices& choices, const PassRunner& povray, const ImageScene& scene,
              int width, int height, int band, const Reporter& report);

  // Decides whether the ambient pass is rendered and starts every pass (after the depth
  // pre-pass, when the fogs need one): POV-Ray spends about 0.65 s of each run waiting
  // (start-up and its message polling), which overlaps, and the cores share the rendering.
  void start();

  // Each waits for its pass and puts what it decoded into `in` (finish_depth: the depth and
  // the frame's Z and Radial; the others: beauty, ambient term, normals).
  void finish_depth(AoInputs& in);
  void finish_beauty(AoInputs& in);
  void finish_ambient(AoInputs& in);
  void finish_normals(AoInputs& in);

  PassTimings timings() const;

 private:
  bool wants_ambient_pass() const;
  void start_normal_pass();
  ssao_tools::Image read_frame_pass(const RunningPass& pass, const char* hint) const;
  void report_ambient_share(AoInputs& in, const V3& light, double share, size_t overflowed) const;

  const PassChoices choices_;
  const PassRunner& povray_;
  const SceneScan& scan_;
  const ResolvedCamera& camera_;
  int width_, height_, band_;
  const Reporter& report_;
  DepthPass depth_;
  bool ambient_pass_ = false;
  RunningPass beauty_, ambient_, normals_;
  double beauty_seconds_ = 0.0, ambient_seconds_ = 0.0, normal_seconds_ = 0.0;
};

}  // namespace povray_ssao
