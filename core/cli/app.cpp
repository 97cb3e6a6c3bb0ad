// SPDX-License-Identifier: MIT
#include "app.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "io/blender_passes.h"
#include "io/camera_json.h"
#include "io/image_io.h"
#include "io/job.h"
#include "progress.h"

namespace ssao_cli {
namespace {

namespace fs = std::filesystem;

// The input image with the passes the core reads, each tightly packed.
struct Inputs {
  ssao_io::Image image;
  ssao_io::PassChannels passes;
  std::vector<float> depth;   // 1 channel
  std::vector<float> normal;  // 3 channels or empty
  std::vector<float> beauty;  // 3 or 4 channels or empty
  int beauty_channels() const { return static_cast<int>(passes.beauty.size()); }
};

// What the core writes.
struct Outputs {
  std::vector<float> ao;         // 1 channel
  std::vector<float> composite;  // as many channels as the beauty, empty with --ao-only
};

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

void refuse_overwriting_inputs(const Options& options) {
  if (same_file(options.output, options.input)) {
    throw UsageError("the output '" + options.output + "' is the input file; choose another -o");
  }
  if (same_file(options.output, options.camera)) {
    throw UsageError("the output '" + options.output + "' is the camera file; choose another -o");
  }
}

// Fails before any work when the output cannot be created (the final write would fail anyway).
void check_output_folder(const Options& options) {
  fs::path folder = fs::path(options.output).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw ssao_io::Error("cannot write '" + options.output + "': no folder '" + folder.string() +
                         "'");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw ssao_io::Error("cannot write '" + options.output + "': folder '" + folder.string() +
                         "' is not writable");
  }
  const std::string extension = fs::path(options.output).extension().string();
  if (extension != ".exr" && !ssao_io::is_preview_path(options.output)) {
    throw ssao_io::Error("cannot write '" + options.output + "': use .exr (linear float data) " +
                         "or .png, .jpg, .tif (an 8-bit sRGB preview)");
  }
}

ssao_io::Camera load_camera(const Options& options) {
  ssao_io::Camera camera = ssao_io::read_camera_json(options.camera);
  if (!options.quiet) {
    for (const std::string& key : camera.unknown_keys) {
      std::fprintf(stderr, "ssao: warning: camera file '%s': unknown key '%s' ignored\n",
                   options.camera.c_str(), key.c_str());
    }
  }
  return camera;
}

std::vector<int> channel_indices(const ssao_io::Image& image, const std::vector<std::string>& names,
                                 const std::string& path) {
  std::vector<int> indices;
  for (const std::string& name : names)
    indices.push_back(ssao_io::require_channel(image, name, path));
  return indices;
}

Inputs load_inputs(const Options& options) {
  Inputs in;
  in.image = ssao_io::read_image(options.input);
  ssao_io::PassOverrides overrides;
  overrides.layer = options.layer;
  overrides.depth_channel = options.depth_channel;
  overrides.normal_channels = options.normal_channels;
  overrides.beauty_channels = options.beauty_channels;
  overrides.no_normals = options.no_normals;
  in.passes = ssao_io::detect_passes(in.image.channel_names, overrides, options.input);
  if (options.ao_only) in.passes.beauty.clear();
  if (!options.ao_only && in.passes.beauty.empty()) {
    throw ssao_io::Error("'" + options.input + "' has no beauty pass (looked for " +
                         (in.passes.layer.empty() ? "" : in.passes.layer + ".") +
                         "Combined.R/G/B); use --ao-only to write AO alone, or name the beauty " +
                         "channels with --beauty-channels R,G,B[,A]");
  }

  in.depth = ssao_io::extract_channels(in.image,
                                       channel_indices(in.image, {in.passes.depth}, options.input));
  if (!in.passes.normal.empty()) {
    in.normal = ssao_io::extract_channels(
        in.image, channel_indices(in.image, in.passes.normal, options.input));
  }
  if (!in.passes.beauty.empty()) {
    in.beauty = ssao_io::extract_channels(
        in.image, channel_indices(in.image, in.passes.beauty, options.input));
  }
  in.image.pixels.clear();
  in.image.pixels.shrink_to_fit();
  return in;
}

void attach_images(ssao_io::Job& job, Inputs& in, Outputs& out) {
  const int w = in.image.width;
  const int h = in.image.height;
  job.set_image("depth", in.depth.data(), w, h, 1);
  if (!in.normal.empty()) job.set_image("normal", in.normal.data(), w, h, 3);
  out.ao.assign(in.image.pixel_count(), 0.0f);
  job.set_image("ao", out.ao.data(), w, h, 1);
  if (!in.beauty.empty()) {
    out.composite.assign(in.beauty.size(), 0.0f);
    job.set_image("beauty", in.beauty.data(), w, h, in.beauty_channels());
    job.set_image("composite", out.composite.data(), w, h, in.beauty_channels());
  }
}

// Runs the job with progress on stderr; returns the time spent in milliseconds.
double compute_ao(ssao_io::Job& job, bool quiet) {
  ProgressReporter progress(quiet);
  job.set_progress(&ProgressReporter::callback, &progress);
  const auto start = std::chrono::steady_clock::now();
  const ssao_status status = ssao_job_run(job.get());
  const auto stop = std::chrono::steady_clock::now();
  progress.finish();
  job.set_progress(nullptr, nullptr);
  if (status == SSAO_ERROR_CANCELLED || ProgressReporter::interrupted()) {
    throw ssao_io::Error("interrupted; nothing written");
  }
  ssao_io::check_status(status, "SSAO failed");
  return std::chrono::duration<double, std::milli>(stop - start).count();
}

// The output file's channels: beauty's (named R, G, B[, A]) x AO then AO, or AO alone.
void write_output(const Options& options, const Inputs& in, const Outputs& out) {
  const auto write =
      ssao_io::is_preview_path(options.output) ? ssao_io::write_preview : ssao_io::write_exr;
  const size_t pixels = in.image.pixel_count();
  if (out.composite.empty()) {
    write(options.output, in.image.width, in.image.height, {"AO"}, out.ao);
    return;
  }
  std::vector<std::string> names = {"R", "G", "B", "A"};
  const size_t beauty = static_cast<size_t>(in.beauty_channels());
  names.resize(beauty);
  names.push_back("AO");
  const size_t stride = beauty + 1;
  std::vector<float> interleaved(pixels * stride);
  for (size_t p = 0; p < pixels; ++p) {
    for (size_t c = 0; c < beauty; ++c) interleaved[p * stride + c] = out.composite[p * beauty + c];
    interleaved[p * stride + beauty] = out.ao[p];
  }
  write(options.output, in.image.width, in.image.height, names, interleaved);
}

// The same test as the core's: finite, > 0, below background_depth and clip_end (when > 0).
bool is_geometry(float depth, double background_depth, double clip_end) {
  return std::isfinite(depth) && depth > 0.0f && depth < background_depth &&
         (clip_end <= 0.0 || depth < clip_end);
}

void print_summary(const Options& options, const ssao_io::Job& job, const Inputs& in,
                   const Outputs& out, double milliseconds) {
  const double background_depth = job.get_float("background_depth");
  const double clip_end = job.get_float("clip_end");
  double sum = 0.0;
  size_t count = 0;
  for (size_t p = 0; p < in.depth.size(); ++p) {
    if (!is_geometry(in.depth[p], background_depth, clip_end)) continue;
    sum += out.ao[p];
    ++count;
  }
  char mean[64] = "n/a";
  if (count > 0) std::snprintf(mean, sizeof mean, "%.4f", sum / static_cast<double>(count));
  std::fprintf(stderr,
               "ssao: %s: %dx%d, variant %s, normals %s, %.1f ms, mean AO %s over "
               "%zu geometry pixels\n",
               options.output.c_str(), in.image.width, in.image.height,
               job.settings_summary().c_str(), in.normal.empty() ? "from depth" : "from pass",
               milliseconds, mean, count);
}

// Without --radius: the camera file's ao_distance, else the core's automatic rule; said on
// stderr with how to change it.
void choose_radius(const Options& options, const ssao_io::Camera& camera, ssao_io::Job& job) {
  for (const ssao_io::ParamSetting& setting : options.params) {
    if (setting.name == "radius") return;
  }
  std::string why;
  if (camera.ao_distance > 0.0) {
    job.set("radius", camera.ao_distance);
    why = "ao_distance of " + options.camera;
  } else {
    double radius = 0.0;
    const ssao_status status = ssao_job_auto_radius(job.get(), &radius);
    if (status != SSAO_OK) return;  // no geometry: AO is 1 whatever the radius
    job.set("radius", radius);
    why = "10% of the view's width at the median depth";
  }
  if (!options.quiet) {
    std::fprintf(stderr, "ssao: radius %.4g scene units (%s; --radius to change)\n",
                 job.get_float("radius"), why.c_str());
  }
}

}  // namespace

void run_ssao(const Options& options) {
  refuse_overwriting_inputs(options);
  check_output_folder(options);
  const ssao_io::Camera camera = load_camera(options);

  ssao_io::Job job;
  ssao_io::apply_camera(job.get(), camera, options.camera);
  ssao_io::apply_params(job, options.params);  // after the camera: a flag overrides the file

  Inputs in = load_inputs(options);
  Outputs out;
  attach_images(job, in, out);
  choose_radius(options, camera, job);
  const double milliseconds = compute_ao(job, options.quiet);
  write_output(options, in, out);
  if (!options.quiet) print_summary(options, job, in, out, milliseconds);
}

}  // namespace ssao_cli
