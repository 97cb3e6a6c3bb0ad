// SPDX-License-Identifier: MIT
#include "compute_ao.h"

#include <cmath>

#include "outputs.h"
#include "ssao/ssao.hpp"
#include "tools/interrupt.h"
#include "tools/param_flags.h"

namespace povray_ssao {
namespace {

// value^exponent on the R, G, B channels of an RGBA buffer (positive values only).
void raise_rgb(std::vector<float>& rgba, double exponent) {
  for (size_t p = 0; p < rgba.size() / 4; ++p) {
    for (size_t c = 0; c < 3; ++c) {
      float& v = rgba[p * 4 + c];
      if (v > 0.0f) v = static_cast<float>(std::pow(v, exponent));
    }
  }
}

// libssao's result images, and the beauty in the scene's working space when the composite is
// made there; the job points into them.
struct JobImages {
  std::vector<float> ao, composite, working;
};

// The camera, the depth kind and the user's parameters; the inputs and outputs. With a guard
// band, depth and normals are larger than the frame: the outputs are the window at (band,
// band), and the camera is the frame's, as libssao wants it.
void set_up_job(ssao::api::Job& job, const std::vector<ssao_tools::ParamSetting>& params,
                AoInputs& in, bool gamma, JobImages& images) {
  in.camera.apply_to_job(job, in.width, in.height);
  job.set("depth_kind", in.planar_input ? "planar" : "radial");
  if (!in.normals.empty()) job.set("normal_space", "camera");
  // A blurred beauty cannot say where a sharp depth edge lies (an --edge-coverage flag still
  // wins).
  if (in.beauty_blurred) job.set("edge_coverage", "none");
  ssao_tools::apply_params(job, params);

  images.ao.assign(in.frame_pixels(), 1.0f);
  images.composite.assign(in.frame_pixels() * 4, 0.0f);
  job.set_image("depth", in.depth_input.data(), in.data_width(), in.data_height(), 1);
  if (!in.normals.empty()) {
    job.set_image("normal", in.normals.data(), in.data_width(), in.data_height(), 3);
  }
  if (in.band > 0) job.set_output_window(true, in.band, in.band);
  if (gamma) {
    images.working = in.beauty;
    raise_rgb(images.working, 1.0 / in.working_gamma);
  }
  job.set_image("beauty", gamma ? images.working.data() : in.beauty.data(), in.width, in.height, 4);
  if (!in.ambient.empty()) job.set_image("ambient", in.ambient.data(), in.width, in.height, 4);
  job.set_image("composite", images.composite.data(), in.width, in.height, 4);
  job.set_image("ao", images.ao.data(), in.width, in.height, 1);
  job.set_progress(&ssao_tools::InterruptGuard::cancel_if_interrupted, nullptr);
}

// Without --radius: libssao's radius rule (no camera file here: the automatic radius), printed
// so that the user can fix it.
void choose_default_radius(ssao::api::Job& job, const AoInputs& in, const Reporter& report) {
  double radius = 0.0;
  ssao_radius_source source = SSAO_RADIUS_SET;
  // Failing only without a geometry pixel: AO is 1 whatever the radius.
  if (ssao_job_choose_radius(job.get(), 1, &radius, &source) != SSAO_OK) return;
  if (source != SSAO_RADIUS_AUTOMATIC) return;
  report.progress("radius %.4g scene units (10%% of the view's width%s; --radius to change)",
                  radius, in.camera.orthographic ? "" : " at the median depth");
}

}  // namespace

double compute_and_write(const std::vector<ssao_tools::ParamSetting>& params,
                         const OutputFiles& files, AoInputs& in, const Reporter& report) {
  // In ambient mode the composite is made in the scene's working space, where the ambient term
  // adds to the rest of the light: beauty^(1/gamma) - (1 - AO) ambient, then ^gamma again.
  const bool gamma = !in.ambient.empty() && in.working_gamma != 1.0;
  ssao::api::Job job;
  JobImages images;
  set_up_job(job, params, in, gamma, images);
  choose_default_radius(job, in, report);

  report.begin("AO (%s, normals %s, %s)... ", job.settings_summary().c_str(),
               in.normals.empty() ? "from depth" : "from the normal pass",
               in.ambient.empty() ? "applied to the whole image" : "applied to the ambient light");
  const auto start = Clock::now();
  const ssao_status status = ssao_job_run(job.get());
  const double seconds = seconds_since(start);
  if (status == SSAO_ERROR_CANCELLED || ssao_tools::InterruptGuard::interrupted()) {
    report.end("interrupted");
    throw ssao_tools::Error("interrupted; nothing written");
  }
  ssao::api::check_status(status, "SSAO failed");
  if (gamma) raise_rgb(images.composite, in.working_gamma);
  const ssao::api::Job::RunStats stats = job.last_run();  // the library's background rule
  report.end("%.2f s, mean AO %.3f over %zu geometry pixels", seconds, stats.mean_ao,
             stats.geometry_pixels);
  write_outputs(files, in, images.composite, images.ao);
  return seconds;
}

}  // namespace povray_ssao
