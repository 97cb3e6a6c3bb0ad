// SPDX-License-Identifier: MIT
#include "depth_pass.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace povray_ssao {
namespace {

// A depth pass whose median estimated relative error exceeds this measured nothing (a good pass:
// about 4e-4; one without fog: 1).
constexpr double kUnusableDepthError = 0.1;

}  // namespace

std::string describe(const FogDistances& d) {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, "D1 = %.4g, D2 = %.4g", d.d1, d.d2);
  std::string out = buffer;
  if (d.d3 > 0.0) {
    std::snprintf(buffer, sizeof buffer, ", D3 = %.4g", d.d3);
    out += buffer;
  }
  return out;
}

std::vector<std::string> depth_pass_options(const FogDistances& fogs, const SceneScan& scan) {
  std::vector<std::string> extra = {"+Q9", "-A", "-UA"};
  for (const std::string& d : fog_declares(fogs)) extra.push_back(d);
  if (scan.uses_radiosity) extra.push_back("Declare=SSAODepthCheapRadiosity=1");
  return extra;
}

void DepthPass::choose_fogs() {
  if (given_distances_) {
    distances_ = *given_distances_;
  } else if (camera_.look_at_distance > 0.0 && !camera_.orthographic) {
    distances_ = camera_distances(camera_.look_at_distance);
    guessed_ = true;
  } else {
    run_prepass();
  }
}

void DepthPass::run_prepass() {
  // depth.pov's camera sees the band too: keep its aspect.
  const int pw = std::min(data_width_, std::clamp(data_width_ / 8, 16, 80));
  const int ph = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(pw) * data_height_ / data_width_)));
  report_.begin("depth-range pre-pass (%dx%d)... ", pw, ph);
  prepass_seconds = povray_.render("depth-range pre-pass", "prepass", "depth.pov", pw, ph,
                                   depth_pass_options(prepass_distances(), scan_));
  const ssao_tools::Image image = ssao_tools::read_image(povray_.output("prepass"));
  const DepthStats stats =
      depth_stats(decode_fog(image, prepass_distances(), povray_.output("prepass")));
  distances_ = choose_distances(stats);
  if (stats.geometry == 0) {
    report_.end("%.2f s", prepass_seconds);
    report_.warning(
        "the pre-pass saw no geometry (every ray missed); fog distances "
        "D1 = 10, D2 = 100");
  } else {
    report_.end("%.2f s: depths %.4g .. %.4g, median %.4g, 99%% below %.4g -> %s", prepass_seconds,
                stats.min, stats.max, stats.median, stats.p99, describe(distances_).c_str());
  }
}

void DepthPass::start() {
  running_ = povray_.start("depth pass", "depth", "depth.pov", data_width_, data_height_,
                           depth_pass_options(distances_, scan_));
}

std::vector<float> DepthPass::read(std::vector<float>& precision) const {
  const ssao_tools::Image image = ssao_tools::read_image(running_.output);
  if (image.width != data_width_ || image.height != data_height_) {
    throw ssao_tools::Error("POV-Ray rendered the depth pass at " + std::to_string(image.width) +
                            "x" + std::to_string(image.height) + " instead of " +
                            std::to_string(data_width_) + "x" + std::to_string(data_height_));
  }
  return decode_fog(image, distances_, running_.output, &precision);
}

void DepthPass::report_depths(const DepthStats& depths, const DepthStats& errors) const {
  report_.progress(
      "  depth pass %.2f s (%s): depth %.4g .. %.4g (median %.4g) on %.1f%% of the pixels; "
      "estimated error (half-float rounding%s): median %.1e, 99%% %.1e, max %.1e of the depth",
      seconds, describe(distances_).c_str(), depths.min, depths.max, depths.median,
      100.0 * static_cast<double>(depths.geometry) / static_cast<double>(depths.total),
      distances_.d3 > 0.0 ? "" : " + leaked colour", errors.median, errors.p99, errors.max);
}

// Fog that never reached the pixels reads as the scene's own colour: the depths are then noise
// (a measured median error of 1), and AO from them would be silently wrong.
void DepthPass::check_usable(const DepthStats& errors) const {
  if (errors.median <= kUnusableDepthError) return;
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2g", errors.median);
  throw ssao_tools::Error(
      std::string("the depth pass measured no usable distances (median estimated error ") + buffer +
      " of the depth). POV-Ray renders no fog for a camera inside a non-hollow object, "
      "most often a plane whose normal points away from the camera (plane { z, 10 } "
      "behind the scene puts the camera inside it): add 'hollow' to that object (the "
      "render does not change) or turn its normal towards the camera" +
      (given_distances_ ? "; or choose --fog-distances near the scene's depths" : ""));
}

std::vector<float> DepthPass::finish() {
  for (int attempt = 0;; ++attempt) {
    seconds += povray_.finish(running_);
    std::vector<float> precision;
    std::vector<float> depth = read(precision);
    const DepthStats stats = depth_stats(depth);
    if (stats.geometry == 0) {
      report_.progress("  depth pass %.2f s (%s): no geometry, AO is 1 everywhere", seconds,
                       describe(distances_).c_str());
      report_.warning("the depth pass saw no geometry: AO is 1 everywhere");
      return depth;
    }
    std::vector<float> errors;
    for (size_t p = 0; p < depth.size(); ++p) {
      if (std::isfinite(depth[p])) errors.push_back(precision[p]);
    }
    const DepthStats e = depth_stats(errors);
    report_depths(stats, e);
    // The look_at guess covers 0.02 L .. 300 L; a scene mostly outside gets a second pass.
    if (!guessed_ || attempt > 0 || (e.p99 <= 2e-3 && stats.median >= 0.02 * distances_.d1)) {
      check_usable(e);
      return depth;
    }
    distances_ = choose_distances(stats);
    report_.warning(
        "the depths are far from the camera's look_at distance; rendering the depth "
        "pass again with " +
        describe(distances_));
    start();
  }
}

}  // namespace povray_ssao
