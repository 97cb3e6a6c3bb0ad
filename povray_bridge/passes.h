// SPDX-License-Identifier: MIT
// The passes povray-ssao renders and how it decodes them.
//
// Depth ("additive fog", docs/povray.md and /work/shared/docs/povray-notes.md): the wrapper
//   #include "ssao_depth_pre.inc"    global_settings { assumed_gamma 1.0 } (the first one wins)
//   #include "SCENE.pov"
//   camera { ... }                   the resolved camera (the last camera wins; no focal blur)
//   #include "ssao_depth_post.inc"   max_trace_level 1, ambient_light 0, cheap radiosity, and
//                                    fogs of colour K on R (distance D1) and G (distance D2)
// rendered +Q9 -A +FE gives R = K (1 - exp(-d / D1)) + (a leaked scene colour attenuated by
// the fogs), so d = -D1 log1p(-R / K): the radial distance from the camera (for orthographic
// cameras the distance from the image plane, i.e. planar depth). EXR output is half-float, so
// the precision depends on x = d / D: povray-ssao picks D from a small pre-pass.
#pragma once

#include <string>
#include <vector>

#include "pov_camera.h"
#include "tools/image_io.h"

namespace povray_ssao {

constexpr double kFogColour = 60000.0;  // K: below half's maximum 65504, exact in half

struct FogDistances {
  double d1 = 0.0;
  double d2 = 0.0;
  double d3 = 0.0;      // 0: no third fog (on B)
  bool coarse = false;  // the pre-pass: each channel read up to x = 4
};

// The ambient pass (docs/povray.md): the scene under ambient_light S (ssao_ambient_post.inc).
constexpr double kAmbientScale = 10000.0;

// The wrapper files, written into `folder`: beauty.pov, depth.pov, ambient.pov and normals.pov.
// `scene_name` is the scene's file name (POV-Ray runs in the scene's folder). The beauty and
// the ambient pass (composited per pixel with it) get `frame_camera`, or with nullptr the
// scene's own camera (its focal blur kept); the data passes libssao reads (depth, normals) get
// `data_camera`, the frame's camera or one widened for a guard band, never blurred.
void write_wrappers(const std::string& folder, const std::string& scene_name,
                    const ResolvedCamera* frame_camera, const ResolvedCamera& data_camera);

// The wrappers of the default-camera check (scene_check.h), written into `folder`: the scene's
// depth as POV-Ray renders it (scene_camera.pov: no camera declared after the scene) and with
// `camera` declared after it (declared_camera.pov).
void write_check_wrappers(const std::string& folder, const std::string& scene_name,
                          const ResolvedCamera& camera);

// POV-Ray's Declare= options for the fog distances (and K).
std::vector<std::string> fog_declares(const FogDistances& distances);

// The fog distances for a camera that looks at a point L away: D1 = 1.5 L, D2 = 10 D1 and
// D3 = 100 D1 read depths from about 0.02 L to 300 L within 2e-3 without a pre-pass.
FogDistances camera_distances(double look_distance);

// The fog distances of the pre-pass: three fogs 1, 100 and 10000 scene units apart, which
// read depths from about 0.002 to 40000 scene units to better than 1%.
FogDistances prepass_distances();

// Distance per pixel (row 0 at the top) from a fog render: R while x = d / D1 < 0.7, then G
// (while x < 2 if there is a third fog), then B (when d3 > 0); +inf where every channel reads K
// (nothing hit, or farther than about 8 x the last fog's distance) or the pixel is not finite.
// `precision`, if given, receives the estimated relative error of each pixel (half-float
// rounding of the channel used, plus the leaked scene colour estimated from B when B carries no
// fog; 0 on background).
std::vector<float> decode_fog(const ssao_tools::Image& image, const FogDistances& distances,
                              const std::string& path, std::vector<float>* precision = nullptr);

// Statistics of the finite, positive values.
struct DepthStats {
  size_t geometry = 0;  // pixels with a finite depth
  size_t total = 0;
  double min = 0.0, median = 0.0, p99 = 0.0, max = 0.0;
};
DepthStats depth_stats(const std::vector<float>& depth);

// The rule (see --help): D1 = 1.5 x the median depth; D2 = the 99th percentile / 2, at least
// 10 x D1 and at most 40 x D1; if the farthest depth exceeds 2 x D2, a third fog on B with
// D3 = the farthest depth, at least 10 x D2. Without geometry: D1 = 10, D2 = 100.
FogDistances choose_distances(const DepthStats& stats);

// The ambient term of each pixel (R, G, B; linear, the scene's working space) from the ambient
// pass: value / kAmbientScale x `ambient_light`. Pixels that overflowed half-float (a finish
// ambient x pigment above 6.5) or are not finite get 0 and are counted in `overflowed`.
std::vector<float> decode_ambient(const ssao_tools::Image& image, V3 ambient_light,
                                  const std::string& path, size_t& overflowed);

// Decodes the opt-in normal pass (ssao_passes.inc, SSAOPass=1): per channel
// n = sin(pi (v - 1/2)) in POV-Ray's camera basis (x right, y up, z forward), returned in
// libssao's camera space (x, y, -z), 3 floats per pixel; 0 where `depth` is background.
// Sets `unit_fraction` to the fraction of geometry pixels whose decoded normal has unit length
// within 2% (a check of the encoding).
std::vector<float> decode_normals(const ssao_tools::Image& image, const std::vector<float>& depth,
                                  const std::string& path, double& unit_fraction);

}  // namespace povray_ssao
