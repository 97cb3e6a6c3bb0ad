// SPDX-License-Identifier: MIT
#include "bridge.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "animation.h"
#include "passes.h"
#include "pov_camera.h"
#include "povray_run.h"
#include "sdl.h"
#include "ssao/ssao.hpp"
#include "tools/files.h"
#include "tools/image_io.h"
#include "tools/param_flags.h"

#ifndef POVRAY_SSAO_SOURCE_INCLUDES
#define POVRAY_SSAO_SOURCE_INCLUDES ""
#endif

namespace povray_ssao {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// A depth pass whose median estimated relative error exceeds this measured nothing (a good pass:
// about 4e-4; one without fog: 1).
constexpr double kUnusableDepthError = 0.1;
// POV-Ray would render a size this large for hours before anything failed; each of the passes,
// the AO buffers and the outputs hold it as float (about 64 bytes a pixel in all).
constexpr double kMaxPixels = 8192.0 * 8192.0;
constexpr int kMaxSide = 65536;

// Progress on stdout, warnings on stderr; both silenced by --quiet.
class Reporter {
 public:
  explicit Reporter(bool quiet) : quiet_(quiet) {}
  ~Reporter() {
    if (open_) std::fputs("failed\n", stdout);  // a step ended by an exception
    std::fflush(stdout);
  }
  Reporter(const Reporter&) = delete;
  Reporter& operator=(const Reporter&) = delete;
  void progress(const char* format, ...) const __attribute__((format(printf, 2, 3))) {
    if (quiet_) return;
    if (open_) std::fputs("failed\n", stdout);
    open_ = false;
    std::va_list args;
    va_start(args, format);
    std::fputs("povray-ssao: ", stdout);
    std::vfprintf(stdout, format, args);
    std::fputc('\n', stdout);
    std::fflush(stdout);
    va_end(args);
  }
  // Continues a progress line started with begin() ("...") with its result.
  void begin(const char* format, ...) const __attribute__((format(printf, 2, 3))) {
    if (quiet_) return;
    std::va_list args;
    va_start(args, format);
    std::fputs("povray-ssao: ", stdout);
    std::vfprintf(stdout, format, args);
    std::fflush(stdout);
    va_end(args);
    open_ = true;
  }
  void end(const char* format, ...) const __attribute__((format(printf, 2, 3))) {
    if (quiet_) return;
    std::va_list args;
    va_start(args, format);
    std::vfprintf(stdout, format, args);
    std::fputc('\n', stdout);
    std::fflush(stdout);
    va_end(args);
    open_ = false;
  }
  void warning(const std::string& message) const {
    if (quiet_) return;
    if (open_) std::fputs("failed\n", stdout);
    open_ = false;
    std::fflush(stdout);
    std::fprintf(stderr, "povray-ssao: warning: %s\n", message.c_str());
  }

 private:
  bool quiet_;
  mutable bool open_ = false;  // a begin() line waits for its end()
};

std::string in_quotes(const std::string& path) { return "'" + path + "'"; }

using ssao_tools::check_output_folder;
using ssao_tools::same_file;

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

// "D1 = 25.2, D2 = 252"
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

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Everything the AO step needs, whichever mode produced it.
struct AoInputs {
  int width = 0, height = 0;  // the frame: the beauty's and the outputs' size
  // Guard band, pixels on every side: depth_input and normals cover the data passes'
  // (width + 2 band) x (height + 2 band) pixels, the frame at (band, band) inside them.
  int band = 0;
  std::vector<float> beauty;  // R, G, B, A (linear; A = 1 when the beauty has none)
  bool beauty_has_alpha = false;
  std::vector<float> radial;       // the frame's distance from the camera; +inf on background
  std::vector<float> planar;       // the frame's depth along the view axis; +inf on background
  bool planar_input = false;       // give libssao the planar depth (orthographic, planar files)
  std::vector<float> depth_input;  // what libssao reads: planar or radial, the band included
  std::vector<float> normals;      // libssao camera space, 3 per pixel, the band included; or empty
  std::vector<float> ambient;      // R, G, B, 0 per pixel in the scene's working space, or empty:
                                   // AO darkens only this part of the beauty
  double working_gamma = 1.0;      // the scene's assumed_gamma: beauty = working value ^ gamma
  ResolvedCamera camera;           // the frame's (libssao's camera describes the output window)

  int data_width() const { return width + 2 * band; }
  int data_height() const { return height + 2 * band; }
};

// Copies the channels R, G, B (and A) of `image` into RGBA; a grey image (Y or one channel)
// gives R = G = B.
void take_beauty(const ssao_tools::Image& image, const std::string& path, AoInputs& in) {
  int rgb[3] = {image.find_channel("R"), image.find_channel("G"), image.find_channel("B")};
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
    int grey = image.find_channel("Y");
    if (grey < 0 && image.channels() <= 2) grey = 0;
    if (grey < 0) {
      throw ssao_tools::Error(in_quotes(path) + " has no R, G, B channels; its channels are: " +
                              ssao_tools::join_names(image.channel_names));
    }
    rgb[0] = rgb[1] = rgb[2] = grey;
  }
  const int alpha = image.find_channel("A");
  in.beauty_has_alpha = alpha >= 0;
  const size_t stride = static_cast<size_t>(image.channels());
  in.beauty.assign(image.pixel_count() * 4, 1.0f);
  for (size_t p = 0; p < image.pixel_count(); ++p) {
    for (int c = 0; c < 3; ++c) {
      in.beauty[p * 4 + static_cast<size_t>(c)] =
          image.pixels[p * stride + static_cast<size_t>(rgb[c])];
    }
    if (alpha >= 0) in.beauty[p * 4 + 3] = image.pixels[p * stride + static_cast<size_t>(alpha)];
  }
}

// From `depth` (data_width() x data_height(), planar or radial): libssao's depth_input (the
// kind in.planar_input says) and the frame's radial and planar depth. A band pixel is the frame
// camera's ray through pixel (x - band, y - band), outside [0, W) x [0, H).
void fill_planar_and_radial(AoInputs& in, const std::vector<float>& depth, bool depth_is_planar) {
  const int data_width = in.data_width(), data_height = in.data_height();
  const size_t frame_count = static_cast<size_t>(in.width) * static_cast<size_t>(in.height);
  in.radial.assign(frame_count, kInfinity);
  in.planar.assign(frame_count, kInfinity);
  in.depth_input.assign(static_cast<size_t>(data_width) * static_cast<size_t>(data_height),
                        kInfinity);
  for (int y = 0; y < data_height; ++y) {
    for (int x = 0; x < data_width; ++x) {
      const size_t p =
          static_cast<size_t>(y) * static_cast<size_t>(data_width) + static_cast<size_t>(x);
      const float d = depth[p];
      if (!(std::isfinite(d) && d > 0.0f)) continue;
      const int fx = x - in.band, fy = y - in.band;  // the frame's pixel coordinates
      const double factor = in.camera.radial_factor(fx, fy, in.width, in.height);
      const float planar = depth_is_planar ? d : static_cast<float>(d / factor);
      const float radial = depth_is_planar ? static_cast<float>(d * factor) : d;
      in.depth_input[p] = in.planar_input ? planar : radial;
      if (fx < 0 || fy < 0 || fx >= in.width || fy >= in.height) continue;
      const size_t f =
          static_cast<size_t>(fy) * static_cast<size_t>(in.width) + static_cast<size_t>(fx);
      in.planar[f] = planar;
      in.radial[f] = radial;
    }
  }
}

std::vector<std::string> full_channel_names() { return {"R", "G", "B", "A", "AO", "Z", "Radial"}; }

// Writes -o (and --exr): an 8-bit sRGB preview of the composite, or every channel as float EXR.
// If the second file cannot be written the first is removed again.
void write_outputs(const Options& o, const AoInputs& in, const std::vector<float>& composite,
                   const std::vector<float>& ao) {
  const size_t count = static_cast<size_t>(in.width) * static_cast<size_t>(in.height);
  std::vector<float> full(count * 7);
  for (size_t p = 0; p < count; ++p) {
    for (size_t c = 0; c < 4; ++c) full[p * 7 + c] = composite[p * 4 + c];
    full[p * 7 + 4] = ao[p];
    full[p * 7 + 5] = in.planar[p];
    full[p * 7 + 6] = in.radial[p];
  }
  auto write_main = [&]() {
    if (!ssao_tools::is_preview_path(o.output)) {
      ssao_tools::write_exr(o.output, in.width, in.height, full_channel_names(), full);
      return;
    }
    const size_t channels = in.beauty_has_alpha ? 4 : 3;
    std::vector<float> preview(count * channels);
    for (size_t p = 0; p < count; ++p) {
      for (size_t c = 0; c < channels; ++c) preview[p * channels + c] = composite[p * 4 + c];
    }
    std::vector<std::string> names = {"R", "G", "B", "A"};
    names.resize(channels);
    ssao_tools::write_preview(o.output, in.width, in.height, names, preview);
  };
  if (o.exr.empty()) {
    write_main();
    return;
  }
  ssao_tools::write_exr(o.exr, in.width, in.height, full_channel_names(), full);
  try {
    write_main();
  } catch (...) {
    std::error_code ec;
    fs::remove(o.exr, ec);
    throw;
  }
}

// Runs libssao and writes the outputs; returns the seconds spent in ssao_job_run.
double compute_and_write(const Options& o, AoInputs& in, const Reporter& report) {
  ssao::api::Job job;
  in.camera.apply_to_job(job, in.width, in.height);
  job.set("depth_kind", in.planar_input ? "planar" : "radial");
  if (!in.normals.empty()) job.set("normal_space", "camera");
  ssao_tools::apply_params(job, o.params);

  const size_t count = static_cast<size_t>(in.width) * static_cast<size_t>(in.height);
  std::vector<float> ao(count, 1.0f);
  std::vector<float> composite(count * 4, 0.0f);
  // With a guard band, depth and normals are larger than the frame: the outputs are the window
  // at (band, band), and the camera set above is the frame's, as libssao wants it.
  job.set_image("depth", in.depth_input.data(), in.data_width(), in.data_height(), 1);
  if (!in.normals.empty()) {
    job.set_image("normal", in.normals.data(), in.data_width(), in.data_height(), 3);
  }
  if (in.band > 0) job.set_output_window(true, in.band, in.band);
  // In ambient mode the composite is made in the scene's working space, where the ambient term
  // adds to the rest of the light: beauty^(1/gamma) - (1 - AO) ambient, then ^gamma again.
  const bool gamma = !in.ambient.empty() && in.working_gamma != 1.0;
  std::vector<float> working;
  if (gamma) {
    working = in.beauty;
    for (size_t p = 0; p < count; ++p) {
      for (size_t c = 0; c < 3; ++c) {
        float& v = working[p * 4 + c];
        if (v > 0.0f) v = static_cast<float>(std::pow(v, 1.0 / in.working_gamma));
      }
    }
  }
  job.set_image("beauty", gamma ? working.data() : in.beauty.data(), in.width, in.height, 4);
  if (!in.ambient.empty()) job.set_image("ambient", in.ambient.data(), in.width, in.height, 4);
  job.set_image("composite", composite.data(), in.width, in.height, 4);
  job.set_image("ao", ao.data(), in.width, in.height, 1);
  job.set_progress(&InterruptGuard::cancel_if_interrupted, nullptr);
  if (!o.param("radius")) {
    double radius = 0.0;
    if (ssao_job_auto_radius(job.get(), &radius) == SSAO_OK) {
      job.set("radius", radius);
      report.progress("radius %.4g scene units (10%% of the view's width%s; --radius to change)",
                      radius, in.camera.orthographic ? "" : " at the median depth");
    }
  }

  report.begin("AO (%s, normals %s, %s)... ", job.settings_summary().c_str(),
               in.normals.empty() ? "from depth" : "from the normal pass",
               in.ambient.empty() ? "applied to the whole image" : "applied to the ambient light");
  const auto start = Clock::now();
  const ssao_status status = ssao_job_run(job.get());
  const double seconds = seconds_since(start);
  if (status == SSAO_ERROR_CANCELLED || InterruptGuard::interrupted()) {
    report.end("interrupted");
    throw ssao_tools::Error("interrupted; nothing written");
  }
  ssao::api::check_status(status, "SSAO failed");
  if (gamma) {
    for (size_t p = 0; p < count; ++p) {
      for (size_t c = 0; c < 3; ++c) {
        float& v = composite[p * 4 + c];
        if (v > 0.0f) v = static_cast<float>(std::pow(v, in.working_gamma));
      }
    }
  }
  double sum = 0.0;
  size_t geometry = 0;
  for (size_t p = 0; p < count; ++p) {
    if (!std::isfinite(in.radial[p])) continue;
    sum += ao[p];
    ++geometry;
  }
  report.end("%.2f s, mean AO %.3f over %zu geometry pixels", seconds,
             geometry ? sum / static_cast<double>(geometry) : 1.0, geometry);
  write_outputs(o, in, composite, ao);
  return seconds;
}

// A povray run under way: what it renders, where its image and log go.
struct Render {
  std::string what;  // "depth pass", for messages
  std::string output, log;
  std::unique_ptr<RunningProcess> process;
};

// povray runs in the scene's folder with povray-ssao's includes on the library path.
struct Povray {
  std::string executable;
  std::string scene_folder;
  std::string include_folder;
  std::vector<std::string> user_options;  // --ini and the pass-through options, in order
  const ScratchFolder* scratch = nullptr;
  bool keep = false;
  const AnimationFrame* frame = nullptr;  // an animation's frame: rendered alone (+SF +EF)

  // Where POV-Ray writes +O<name>.exr: an animation frame's number goes before the extension.
  std::string output(const std::string& name) const {
    return scratch->file(name + (frame ? frame->digits : "") + ".exr");
  }

  // Starts rendering `wrapper` to output(name); finish() waits for it.
  Render start(const std::string& what, const std::string& name, const std::string& wrapper,
               int width, int height, const std::vector<std::string>& extra) const {
    Render render;
    render.what = what;
    render.output = output(name);
    render.log = scratch->file(name + ".log");
    std::vector<std::string> args = user_options;
    if (frame) {
      args.push_back("+SF" + std::to_string(frame->number));
      args.push_back("+EF" + std::to_string(frame->number));
    }
    args.push_back("+I" + scratch->file(wrapper));
    args.push_back("+O" + scratch->file(name + ".exr"));
    args.push_back("+W" + std::to_string(width));
    args.push_back("+H" + std::to_string(height));
    args.push_back("-D");
    args.push_back("-P");
    args.push_back("+FE");
    args.push_back("+L" + scene_folder);
    args.push_back("+L" + include_folder);
    args.insert(args.end(), extra.begin(), extra.end());
    {
      FILE* file = std::fopen(render.log.c_str(), "w");
      if (file) {
        std::fprintf(file, "povray-ssao: %s", executable.c_str());
        for (const std::string& arg : args) std::fprintf(file, " %s", arg.c_str());
        std::fprintf(file, "\n(in %s)\n\n", scene_folder.c_str());
        std::fclose(file);
      }
    }
    render.process =
        std::make_unique<RunningProcess>(executable, args, scene_folder, render.log, render.output);
    return render;
  }

  // Waits for the run; returns its wall-clock seconds. Throws with POV-Ray's last messages when
  // it failed or wrote no image.
  double finish(Render& render) const {
    // The image is complete once POV-Ray closes it; its shutdown after that is not waited for.
    const RenderResult result = render.process->wait_for_output();
    if (result.output_written) return result.seconds;
    std::error_code ec;
    if (result.exit_status != 0 || !fs::is_regular_file(render.output, ec)) {
      std::string message = "POV-Ray failed on the " + render.what;
      message += result.exit_status != 0
                     ? " (exit status " + std::to_string(result.exit_status) + ")"
                     : " (no image written)";
      message += ". Its last messages:\n" + povray_error_lines(render.log);
      if (!keep) message += "(--keep DIR keeps the wrappers and the full logs)";
      while (!message.empty() && message.back() == '\n') message.pop_back();
      throw ssao_tools::Error(message);
    }
    return result.seconds;
  }

  double render(const std::string& what, const std::string& name, const std::string& wrapper,
                int width, int height, const std::vector<std::string>& extra) const {
    Render running = start(what, name, wrapper, width, height, extra);
    return finish(running);
  }
};

// Copies the scratch folder's files to --keep DIR when it goes out of scope (also on failure).
class KeepFiles {
 public:
  KeepFiles(const ScratchFolder& scratch, std::string target, const Reporter& report)
      : scratch_(scratch), target_(std::move(target)), report_(report) {}
  ~KeepFiles() {
    if (target_.empty()) return;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(scratch_.path(), ec)) {
      fs::copy_file(entry.path(), fs::path(target_) / entry.path().filename(),
                    fs::copy_options::overwrite_existing, ec);
      if (ec) {
        report_.warning("--keep: cannot copy " + entry.path().filename().string() + " to " +
                        in_quotes(target_) + ": " + ec.message());
        return;
      }
    }
    report_.progress("kept the wrappers, logs and passes in %s", target_.c_str());
  }
  KeepFiles(const KeepFiles&) = delete;
  KeepFiles& operator=(const KeepFiles&) = delete;

 private:
  const ScratchFolder& scratch_;
  std::string target_;
  const Reporter& report_;
};

void print_camera(const CameraReading& reading, int width, int height, int band) {
  std::printf("camera: %s\n  read from %s\n", reading.camera.summary().c_str(),
              reading.source.c_str());
  if (band > 0) {
    std::printf("the beauty and the ambient pass are rendered with (after the scene):\n%s",
                reading.camera.to_sdl().c_str());
    std::printf("the depth and normal passes, %dx%d with a %d-pixel guard band, with:\n%s",
                width + 2 * band, height + 2 * band, band,
                reading.camera.widened(width, height, band).to_sdl().c_str());
  } else {
    std::printf("every pass is rendered with (after the scene):\n%s",
                reading.camera.to_sdl().c_str());
  }
  ssao::api::Job job;
  reading.camera.apply_to_job(job, width, height);
  if (reading.camera.orthographic) {
    std::printf("libssao (%dx%d): camera_type ORTHO, ortho_scale %.9g", width, height,
                job.get_float("ortho_scale"));
  } else {
    std::printf("libssao (%dx%d): camera_type PERSP, lens %.9g mm, sensor_width 36 mm", width,
                height, job.get_float("lens"));
  }
  std::printf(", sensor_fit HORIZONTAL, pixel_aspect %.9g:%.9g\n", job.get_float("pixel_aspect_x"),
              job.get_float("pixel_aspect_y"));
}

// What every image of a render shares: the scene, the size, the scan settings, the clock.
struct RenderSetup {
  fs::path scene_path;
  std::string scene_folder, scene_name, includes;
  int width = 0, height = 0;
  ScanSettings settings;
  ClockOptions clock;
};

// The guard band of the data passes (pixels per side): --overscan, else the default; none for
// --depth-only (the frame's depth is its output). The padded passes must stay within the size
// limits of the frame itself.
int guard_band(const Options& o, int width, int height) {
  if (o.depth_only) return 0;
  auto fits = [&](int band) {
    const long long data_width = static_cast<long long>(width) + 2LL * band;
    const long long data_height = static_cast<long long>(height) + 2LL * band;
    return band >= 0 && data_width <= kMaxSide && data_height <= kMaxSide &&
           double(data_width) * double(data_height) <= kMaxPixels;
  };
  if (!o.overscan) {
    // The default shrinks near the size limits rather than refusing a frame that fits.
    int band = default_guard_band(width, height);
    while (band > 0 && !fits(band)) --band;
    return band;
  }
  const int band = *o.overscan;
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

// One image (a still, or one frame of an animation): the passes, AO and the outputs.
void render_image(const Options& o, const RenderSetup& setup, const AnimationFrame* frame,
                  const Reporter& report) {
  const auto start = Clock::now();
  const std::string& scene_folder = setup.scene_folder;
  const std::string& scene_name = setup.scene_name;
  const std::string& includes = setup.includes;
  const int width = setup.width, height = setup.height;
  std::error_code ec;
  if (!o.keep.empty()) {
    fs::create_directories(o.keep, ec);
    if (!fs::is_directory(o.keep, ec)) {
      throw ssao_tools::Error("--keep: cannot create the folder " + in_quotes(o.keep));
    }
  }
  ScanSettings settings = setup.settings;
  if (frame) {
    settings.clock = frame->clock;
    declare_frame(setup.clock, *frame, settings.predeclared);
  }
  const SceneScan scan = scan_scene(setup.scene_path.string(), settings);

  const CameraReading reading = read_camera(scan, o.camera, width, height);
  const int band = guard_band(o, width, height);
  if (o.print_camera) {
    for (const std::string& note : scan.notes) report.warning(note);
    for (const std::string& warning : reading.warnings) report.warning(warning);
    print_camera(reading, width, height, band);
    return;
  }
  report.progress("camera: %s (%s)", reading.camera.summary().c_str(), reading.source.c_str());
  for (const std::string& note : scan.notes) report.warning(note);
  for (const std::string& warning : reading.warnings) report.warning(warning);
  if (reading.had_focal_blur) {
    report.warning(
        "the scene's camera has focal blur (aperture); povray-ssao renders every "
        "pass, the beauty included, without it (a blurred depth pass would be wrong, "
        "and far slower)");
  }
  const double pixel_ratio =
      reading.camera.aspect() / (static_cast<double>(width) / static_cast<double>(height));
  if (std::fabs(pixel_ratio - 1.0) > 0.01) {
    report.warning("the camera's |right|/|up| (" + std::to_string(reading.camera.aspect()) +
                   ") differs from the image's width/height: non-square pixels, as POV-Ray "
                   "renders them");
  }

  Povray povray;
  povray.executable = find_executable(o.povray);
  povray.scene_folder = scene_folder;
  povray.include_folder = includes;
  if (!o.ini.empty()) povray.user_options.push_back(fs::absolute(o.ini).string());
  povray.user_options.insert(povray.user_options.end(), o.povray_options.begin(),
                             o.povray_options.end());
  ScratchFolder scratch;
  povray.scratch = &scratch;
  povray.frame = frame;
  povray.keep = !o.keep.empty();
  KeepFiles keep(scratch, o.keep, report);
  // The data passes libssao reads (depth, normals) see a band around the frame: occluders just
  // outside it darken its edges. The beauty and the ambient pass are the frame.
  const int data_width = width + 2 * band, data_height = height + 2 * band;
  write_wrappers(scratch.path(), scene_name, reading.camera,
                 band > 0 ? reading.camera.widened(width, height, band) : reading.camera);
  const std::vector<std::string> data_pass = {"+Q9", "-A", "-UA"};

  // What AO darkens: the ambient term when the scene has one that can be rendered apart.
  bool ambient_pass = !o.depth_only && o.apply_to != "beauty";
  if (ambient_pass) {
    std::string why_not;
    if (scan.uses_radiosity && (scan.version == 0.0 || scan.version >= 3.7)) {
      why_not =
          "the scene uses radiosity, which replaces the ambient term in POV-Ray 3.7 (there is no "
          "ambient light to darken)";
    } else if (!scan.ambient_light_problem.empty()) {
      why_not =
          "povray-ssao cannot read the scene's ambient_light (" + scan.ambient_light_problem + ")";
    }
    if (!why_not.empty()) {
      if (o.apply_to == "ambient") throw ssao_tools::Error("--apply-to ambient: " + why_not);
      report.progress("AO darkens the whole image: %s", why_not.c_str());
      ambient_pass = false;
    }
  }

  // Every pass is started at once: POV-Ray spends about 0.65 s of each run waiting (start-up and
  // its message polling), which overlaps, and the 2 cores share the rendering.
  AoInputs in;
  in.width = width;
  in.height = height;
  in.band = band;
  in.camera = reading.camera;
  Render beauty_render, ambient_render, normal_render;
  if (!o.depth_only) {
    beauty_render = povray.start("beauty", "beauty", "beauty.pov", width, height, {});
  }
  if (ambient_pass) {
    // +Q3 skips shadows, reflection and refraction; +Q6 where +Q3 would show quick colours.
    ambient_render = povray.start("ambient pass", "ambient", "ambient.pov", width, height,
                                  {scan.uses_quick_color ? "+Q6" : "+Q3", "-A", "-UA"});
  }
  if (!o.depth_only && scan.includes_ssao_passes && !o.no_normals) {
    // The basis of the camera every pass is rendered with, imposed on ssao_passes.inc (its
    // SSAOCamera/SSAOCameraBasis vectors could describe another camera, e.g. with --camera-*).
    std::vector<std::string> normal_pass = {"+Q6", "-A", "-UA", "Declare=SSAOPass=1"};
    const std::pair<const char*, V3> axes[3] = {{"Right", normalized(reading.camera.right)},
                                                {"Up", normalized(reading.camera.up)},
                                                {"Forward", normalized(reading.camera.direction)}};
    for (const auto& [name, axis] : axes) {
      const double components[3] = {axis.x, axis.y, axis.z};
      for (int c = 0; c < 3; ++c) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "Declare=SSAOBasis%s%c=%.17g", name, "XYZ"[c],
                      components[c]);
        normal_pass.push_back(buffer);
      }
    }
    normal_render =
        povray.start("normal pass", "normals", "normals.pov", data_width, data_height, normal_pass);
  }

  // The fog distances: given, from the camera's look_at distance, else from a small pre-pass.
  FogDistances distances;
  double prepass_seconds = 0.0;
  bool guessed = false;
  if (o.fog_distances) {
    distances = *o.fog_distances;
  } else if (reading.camera.look_at_distance > 0.0 && !reading.camera.orthographic) {
    distances = camera_distances(reading.camera.look_at_distance);
    guessed = true;
  } else {
    // depth.pov's camera sees the band too: keep its aspect.
    const int pw = std::min(data_width, std::clamp(data_width / 8, 16, 80));
    const int ph = std::max(
        1, static_cast<int>(std::lround(static_cast<double>(pw) * data_height / data_width)));
    report.begin("depth-range pre-pass (%dx%d)... ", pw, ph);
    std::vector<std::string> extra = data_pass;
    for (const std::string& d : fog_declares(prepass_distances())) extra.push_back(d);
    if (scan.uses_radiosity) extra.push_back("Declare=SSAODepthCheapRadiosity=1");
    prepass_seconds = povray.render("depth-range pre-pass", "prepass", "depth.pov", pw, ph, extra);
    const ssao_tools::Image image = ssao_tools::read_image(povray.output("prepass"));
    const DepthStats stats =
        depth_stats(decode_fog(image, prepass_distances(), povray.output("prepass")));
    distances = choose_distances(stats);
    if (stats.geometry == 0) {
      report.end("%.2f s", prepass_seconds);
      report.warning(
          "the pre-pass saw no geometry (every ray missed); fog distances "
          "D1 = 10, D2 = 100");
    } else {
      report.end("%.2f s: depths %.4g .. %.4g, median %.4g, 99%% below %.4g -> %s", prepass_seconds,
                 stats.min, stats.max, stats.median, stats.p99, describe(distances).c_str());
    }
  }
  auto start_depth = [&](const FogDistances& fogs) {
    std::vector<std::string> extra = data_pass;
    for (const std::string& d : fog_declares(fogs)) extra.push_back(d);
    if (scan.uses_radiosity) extra.push_back("Declare=SSAODepthCheapRadiosity=1");
    return povray.start("depth pass", "depth", "depth.pov", data_width, data_height, extra);
  };
  Render depth_render = start_depth(distances);
  if (band > 0) {
    report.progress("guard band %d pixels (--overscan): the depth%s pass%s %dx%d, cropped to %dx%d",
                    band, normal_render.process ? " and normal" : "",
                    normal_render.process ? "es are" : " is", data_width, data_height, width,
                    height);
  }
  report.progress("rendering %s (%dx%d) at once...",
                  o.depth_only   ? "the depth pass"
                  : ambient_pass ? (normal_render.process ? "the beauty, depth, ambient and "
                                                            "normal passes"
                                                          : "the beauty, depth and ambient "
                                                            "passes")
                  : normal_render.process ? "the beauty, depth and normal passes"
                                          : "the beauty and the depth pass",
                  width, height);
  // The image file module (OpenImageIO) loads while POV-Ray renders.
  ssao_tools::preload_image_io();

  // The depth pass.
  double depth_seconds = 0.0;
  std::vector<float> depth;
  for (int attempt = 0;; ++attempt) {
    depth_seconds += povray.finish(depth_render);
    const ssao_tools::Image image = ssao_tools::read_image(depth_render.output);
    if (image.width != data_width || image.height != data_height) {
      throw ssao_tools::Error("POV-Ray rendered the depth pass at " + std::to_string(image.width) +
                              "x" + std::to_string(image.height) + " instead of " +
                              std::to_string(data_width) + "x" + std::to_string(data_height));
    }
    std::vector<float> precision;
    depth = decode_fog(image, distances, depth_render.output, &precision);
    const DepthStats stats = depth_stats(depth);
    if (stats.geometry == 0) {
      report.progress("  depth pass %.2f s (%s): no geometry, AO is 1 everywhere", depth_seconds,
                      describe(distances).c_str());
      report.warning("the depth pass saw no geometry: AO is 1 everywhere");
      break;
    }
    std::vector<float> errors;
    for (size_t p = 0; p < depth.size(); ++p) {
      if (std::isfinite(depth[p])) errors.push_back(precision[p]);
    }
    const DepthStats e = depth_stats(errors);
    report.progress(
        "  depth pass %.2f s (%s): depth %.4g .. %.4g (median %.4g) on %.1f%% of the pixels; "
        "estimated error (half-float rounding%s): median %.1e, 99%% %.1e, max %.1e of the depth",
        depth_seconds, describe(distances).c_str(), stats.min, stats.max, stats.median,
        100.0 * static_cast<double>(stats.geometry) / static_cast<double>(stats.total),
        distances.d3 > 0.0 ? "" : " + leaked colour", e.median, e.p99, e.max);
    // The look_at guess covers 0.02 L .. 300 L; a scene mostly outside gets a second pass.
    if (!guessed || attempt > 0 || (e.p99 <= 2e-3 && stats.median >= 0.02 * distances.d1)) {
      // Fog that never reached the pixels reads as the scene's own colour: the depths are then
      // noise (a measured median error of 1), and AO from them would be silently wrong.
      if (e.median > kUnusableDepthError) {
        char buffer[32];
        std::snprintf(buffer, sizeof buffer, "%.2g", e.median);
        throw ssao_tools::Error(
            std::string("the depth pass measured no usable distances (median estimated error ") +
            buffer +
            " of the depth). POV-Ray renders no fog for a camera inside a non-hollow object, "
            "most often a plane whose normal points away from the camera (plane { z, 10 } "
            "behind the scene puts the camera inside it): add 'hollow' to that object (the "
            "render does not change) or turn its normal towards the camera" +
            (o.fog_distances ? "; or choose --fog-distances near the scene's depths" : ""));
      }
      break;
    }
    distances = choose_distances(stats);
    report.warning(
        "the depths are far from the camera's look_at distance; rendering the depth "
        "pass again with " +
        describe(distances));
    depth_render = start_depth(distances);
  }
  // Fog depth is radial for a perspective camera and planar for an orthographic one.
  in.planar_input = reading.camera.orthographic;
  fill_planar_and_radial(in, depth, reading.camera.orthographic);
  depth = {};

  if (o.depth_only) {
    const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
    std::vector<float> pixels(count * 2);
    for (size_t p = 0; p < count; ++p) {
      pixels[p * 2] = in.planar[p];
      pixels[p * 2 + 1] = in.radial[p];
    }
    ssao_tools::write_exr(o.output, width, height, {"Z", "Radial"}, pixels);
    if (prepass_seconds > 0.0) {
      report.progress("wrote %s (Z, Radial) in %.2f s: pre-pass %.2f s, depth %.2f s",
                      o.output.c_str(), seconds_since(start), prepass_seconds, depth_seconds);
    } else {
      report.progress("wrote %s (Z, Radial) in %.2f s: depth %.2f s", o.output.c_str(),
                      seconds_since(start), depth_seconds);
    }
    return;
  }

  // The beauty.
  const double beauty_seconds = povray.finish(beauty_render);
  {
    const ssao_tools::Image beauty = ssao_tools::read_image(beauty_render.output);
    if (beauty.width != width || beauty.height != height) {
      throw ssao_tools::Error("POV-Ray rendered the beauty at " + std::to_string(beauty.width) +
                              "x" + std::to_string(beauty.height) + " instead of " +
                              std::to_string(width) + "x" + std::to_string(height) +
                              " (partial render options in the INI file?)");
    }
    take_beauty(beauty, beauty_render.output, in);
  }
  report.progress("  beauty %.2f s (the depth pass took %.2f x its time)", beauty_seconds,
                  depth_seconds / beauty_seconds);

  // The ambient term.
  double ambient_seconds = 0.0;
  if (ambient_pass) {
    ambient_seconds = povray.finish(ambient_render);
    const ssao_tools::Image image = ssao_tools::read_image(ambient_render.output);
    if (image.width != width || image.height != height) {
      throw ssao_tools::Error("POV-Ray rendered the ambient pass at " +
                              std::to_string(image.width) + "x" + std::to_string(image.height) +
                              " instead of " + std::to_string(width) + "x" +
                              std::to_string(height));
    }
    const V3 light = scan.ambient_light.value_or(V3{1.0, 1.0, 1.0});
    size_t overflowed = 0;
    const std::vector<float> rgb = decode_ambient(image, light, ambient_render.output, overflowed);
    in.working_gamma = scan.assumed_gamma.value_or(1.0);
    if (!(in.working_gamma > 0.0)) in.working_gamma = 1.0;
    // The ambient term's share of the light, in the working space.
    const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
    double ambient_sum = 0.0, light_sum = 0.0;
    in.ambient.assign(count * 4, 0.0f);
    for (size_t p = 0; p < count; ++p) {
      for (size_t c = 0; c < 3; ++c) in.ambient[p * 4 + c] = rgb[p * 3 + c];
      if (!std::isfinite(in.radial[p])) continue;
      for (size_t c = 0; c < 3; ++c) {
        ambient_sum += rgb[p * 3 + c];
        const double b = in.beauty[p * 4 + c];
        light_sum += b > 0.0 ? std::pow(b, 1.0 / in.working_gamma) : 0.0;
      }
    }
    const double share = light_sum > 0.0 ? ambient_sum / light_sum : 0.0;
    report.progress(
        "  ambient pass %.2f s: the ambient light (ambient_light %s%s) is %.1f%% of "
        "the image's light",
        ambient_seconds, format_vector(light).c_str(),
        scan.ambient_light ? "" : ", POV-Ray's default", 100.0 * share);
    if (overflowed > 0) {
      report.warning(std::to_string(overflowed) +
                     " pixels have an ambient term too bright for the ambient pass (finish "
                     "ambient x pigment above 6.5); AO leaves them unchanged");
    }
    if (share < 0.01) {
      if (o.apply_to == "ambient") {
        report.warning("the scene has almost no ambient light: AO changes little");
      } else {
        report.progress(
            "AO darkens the whole image: the scene has almost no ambient light "
            "(--apply-to ambient to darken only that)");
        in.ambient.clear();
      }
    }
  }

  // The exact normals of scenes that opt in.
  double normal_seconds = 0.0;
  if (normal_render.process) {
    normal_seconds = povray.finish(normal_render);
    report.progress("  normal pass %.2f s", normal_seconds);
    const ssao_tools::Image image = ssao_tools::read_image(normal_render.output);
    double unit_fraction = 0.0;
    // decode_normals reads the depth of every pixel of the image: only a pass of its size.
    if (image.width != data_width || image.height != data_height) {
      throw ssao_tools::Error("POV-Ray rendered the normal pass at " + std::to_string(image.width) +
                              "x" + std::to_string(image.height) + " instead of " +
                              std::to_string(data_width) + "x" + std::to_string(data_height));
    }
    std::vector<float> normals =
        decode_normals(image, in.depth_input, normal_render.output, unit_fraction);
    if (unit_fraction < 0.9) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%.0f%%", 100.0 * unit_fraction);
      report.warning(std::string("the normal pass does not decode to unit normals (") + buffer +
                     " of the pixels do); are all textures wrapped in SSAOTexture()? Using "
                     "normals reconstructed from the depth instead");
    } else {
      in.normals = std::move(normals);
    }
  }

  // AO and the outputs.
  const double ao_seconds = compute_and_write(o, in, report);
  std::string written = o.output + (o.exr.empty() ? "" : " and " + o.exr);
  std::string passes;
  char buffer[64];
  const std::pair<const char*, double> timings[] = {{"pre-pass", prepass_seconds},
                                                    {"beauty", beauty_seconds},
                                                    {"depth", depth_seconds},
                                                    {"ambient", ambient_seconds},
                                                    {"normals", normal_seconds}};
  for (const auto& [what, seconds] : timings) {
    if (seconds <= 0.0) continue;  // not rendered
    std::snprintf(buffer, sizeof buffer, "%s%s %.2f s", passes.empty() ? "" : ", ", what, seconds);
    passes += buffer;
  }
  report.progress("wrote %s in %.2f s (passes at once: %s; AO %.2f s)", written.c_str(),
                  seconds_since(start), passes.c_str(), ao_seconds);
}

// Every frame of an animation, each on its own: a frame that fails is reported and the others
// are still rendered; the failures are listed at the end.
void render_animation(const Options& o, const RenderSetup& setup,
                      const std::vector<AnimationFrame>& frames, const Reporter& report) {
  const auto start = Clock::now();
  std::vector<long> failed;
  size_t written = 0;
  double seconds_done = 0.0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const AnimationFrame& frame = frames[i];
    Options frame_options = o;
    if (!o.print_camera) frame_options.output = frame_output(o.output, frame);
    if (!o.exr.empty()) frame_options.exr = frame_output(o.exr, frame);
    if (!o.keep.empty())
      frame_options.keep = (fs::path(o.keep) / ("frame" + frame.digits)).string();
    report.progress("frame %ld (%zu/%zu), clock %.6g:", frame.number, i + 1, frames.size(),
                    frame.clock);
    const auto frame_start = Clock::now();
    try {
      render_image(frame_options, setup, &frame, report);
      ++written;
    } catch (const UsageError&) {
      throw;                                 // a command-line mistake is every frame's
    } catch (const std::runtime_error& e) {  // ours or the library's (ssao::api::Error)
      if (InterruptGuard::interrupted()) throw;
      std::fprintf(stderr, "povray-ssao: frame %ld: error: %s\n", frame.number, e.what());
      std::fflush(stderr);
      failed.push_back(frame.number);
    }
    seconds_done += seconds_since(frame_start);
    const double left = seconds_done / double(i + 1) * double(frames.size() - i - 1);
    if (i + 1 < frames.size()) {
      report.progress("frame %ld done (%zu/%zu) in %.2f s; about %.0f s left", frame.number, i + 1,
                      frames.size(), seconds_since(frame_start), left);
    }
  }
  if (o.print_camera) return;
  const double wall = seconds_since(start);
  std::string list;
  for (size_t k = 0; k < failed.size() && k < 50; ++k) {
    list += (k ? "," : "") + std::to_string(failed[k]);
  }
  if (failed.size() > 50) list += ",...";
  report.progress("%zu of %zu frames written in %.1f s (%.1f frames per minute)", written,
                  frames.size(), wall, wall > 0.0 ? 60.0 * double(written) / wall : 0.0);
  if (!failed.empty()) {
    throw ssao_tools::Error(std::to_string(failed.size()) + " of " + std::to_string(frames.size()) +
                            " frames failed: " + list);
  }
}
}  // namespace

void run_render(const Options& o) {
  InterruptGuard interrupt_guard;
  const Reporter report(o.quiet);

  // Everything that can be checked before POV-Ray runs.
  std::error_code ec;
  if (!fs::exists(o.scene, ec)) throw ssao_tools::Error("no scene file " + in_quotes(o.scene));
  if (!fs::is_regular_file(o.scene, ec)) {
    throw ssao_tools::Error("the scene " + in_quotes(o.scene) + " is not a file");
  }
  if (::access(o.scene.c_str(), R_OK) != 0) {
    throw ssao_tools::Error("cannot read the scene file " + in_quotes(o.scene));
  }
  const fs::path scene_path = fs::absolute(o.scene).lexically_normal();
  const std::string scene_folder = scene_path.parent_path().string();
  const std::string scene_name = scene_path.filename().string();
  if (scene_name.find('"') != std::string::npos) {
    throw ssao_tools::Error(
        "the scene's file name contains '\"', which POV-Ray's #include cannot "
        "take");
  }
  if (!o.print_camera) {
    check_output_folder(o.output);
    if (!o.exr.empty()) check_output_folder(o.exr);
    if (same_file(o.output, o.scene) || (!o.exr.empty() && same_file(o.exr, o.scene))) {
      throw UsageError("the output is the scene file; choose another -o");
    }
  }
  if (!o.ini.empty() && !fs::is_regular_file(o.ini, ec)) {
    throw ssao_tools::Error("no INI file " + in_quotes(o.ini));
  }
  if (!o.keep.empty()) {
    fs::create_directories(o.keep, ec);
    if (!fs::is_directory(o.keep, ec)) {
      throw ssao_tools::Error("--keep: cannot create the folder " + in_quotes(o.keep));
    }
  }

  int width = o.width, height = o.height;
  if (!o.ini.empty() && (width == 0 || height == 0)) {
    int w = 0, h = 0;
    ini_size(o.ini, w, h);
    if (width == 0) width = w;
    if (height == 0) height = h;
  }
  default_size(scene_folder, width, height);
  if (width > kMaxSide || height > kMaxSide || double(width) * double(height) > kMaxPixels) {
    throw ssao_tools::Error("the image size " + std::to_string(width) + "x" +
                            std::to_string(height) + " is over povray-ssao's limit of " +
                            "67108864 pixels (8192 x 8192, about 4 GB of passes)");
  }
  guard_band(o, width, height);  // a band too large is every frame's mistake: refuse it now

  // The camera, from the scene text (and its include files, found as POV-Ray finds them).
  const std::string includes = include_folder();
  std::vector<std::string> library_paths;
  const std::string startup_ini = system_ini(scene_folder);
  if (!startup_ini.empty()) ini_library_paths(startup_ini, library_paths);
  if (!o.ini.empty()) ini_library_paths(o.ini, library_paths);
  for (const std::string& option : o.povray_options) {
    if (option.size() > 2 && (option[1] == 'L' || option[1] == 'l')) {
      library_paths.push_back(option.substr(2));
    } else if (option.size() > 13 &&
               (option.rfind("Library_Path=", 0) == 0 || option.rfind("library_path=", 0) == 0)) {
      library_paths.push_back(option.substr(13));
    }
  }
  library_paths.push_back(scene_folder);
  library_paths.push_back(includes);
  for (std::string& path : library_paths) {
    if (fs::path(path).is_relative()) path = (fs::path(scene_folder) / path).string();
  }
  RenderSetup setup;
  ScanSettings settings;
  settings.directory = scene_folder;
  settings.library_paths = library_paths;
  settings.image_width = width;
  settings.image_height = height;
  std::vector<std::string> declares;
  if (!startup_ini.empty()) ini_declares(startup_ini, declares, setup.clock);
  if (!o.ini.empty()) ini_declares(o.ini, declares, setup.clock);
  option_declares(o.povray_options, declares, setup.clock);
  settings.clock = setup.clock.clock;
  for (const std::string& declare : declares) {
    // NAME=VALUE with a number (POV-Ray's Declare= takes floats only).
    const size_t equals = declare.find('=');
    Symbol symbol;
    symbol.kind = Symbol::kValue;
    symbol.declared_at = "Declare=" + declare;
    char* end = nullptr;
    symbol.value.v.x = std::strtod(declare.c_str() + equals + 1, &end);
    if (equals != std::string::npos && end && *end == '\0') {
      settings.predeclared[declare.substr(0, equals)] = symbol;
    }
  }
  setup.settings = settings;
  setup.scene_path = scene_path;
  setup.scene_folder = scene_folder;
  setup.scene_name = scene_name;
  setup.includes = includes;
  setup.width = width;
  setup.height = height;
  const std::vector<AnimationFrame> frames = animation_frames(setup.clock);
  if (!frames.empty() && !o.param("radius") && !o.depth_only && !o.print_camera) {
    throw UsageError(
        "an animation needs --radius R (scene units), so that its frames share one radius: the "
        "automatic radius follows each frame's depth (a still prints the radius it chooses)");
  }
  if (frames.empty()) {
    render_image(o, setup, nullptr, report);
    return;
  }
  render_animation(o, setup, frames, report);
}

void run_post_process(const Options& o) {
  InterruptGuard interrupt_guard;
  const Reporter report(o.quiet);
  const auto start = Clock::now();
  check_output_folder(o.output);
  if (!o.exr.empty()) check_output_folder(o.exr);
  for (const std::string& input : {o.beauty, o.depth}) {
    if (same_file(o.output, input) || (!o.exr.empty() && same_file(o.exr, input))) {
      throw UsageError("the output " + in_quotes(input) + " is an input file; choose another name");
    }
  }

  ssao_tools::Image beauty = ssao_tools::read_image(o.beauty);
  const std::string encoding = beauty.color_space;
  if (ssao_tools::linearize(beauty)) {
    report.progress("beauty %s is %s-encoded: linearised before the multiplication",
                    o.beauty.c_str(), encoding.c_str());
  }
  ssao_tools::Image depth_image = ssao_tools::read_image(o.depth);
  if (beauty.width != depth_image.width || beauty.height != depth_image.height) {
    throw ssao_tools::Error("the beauty is " + std::to_string(beauty.width) + "x" +
                            std::to_string(beauty.height) + " but the depth is " +
                            std::to_string(depth_image.width) + "x" +
                            std::to_string(depth_image.height));
  }
  std::string channel = o.depth_channel;
  if (channel.empty()) {
    for (const char* candidate : {"Radial", "Z", "R", "Y", "depth", "Depth"}) {
      if (depth_image.find_channel(candidate) >= 0) {
        channel = candidate;
        break;
      }
    }
    if (channel.empty() && depth_image.channels() == 1) channel = depth_image.channel_names[0];
    if (channel.empty()) {
      throw UsageError("cannot tell which channel of " + in_quotes(o.depth) +
                       " holds the depth; name it with --depth-channel (channels: " +
                       ssao_tools::join_names(depth_image.channel_names) + ")");
    }
  }
  const int index = ssao_tools::require_channel(depth_image, channel, o.depth);
  const ssao_tools::ParamSetting* kind = o.param("depth_kind");
  const bool planar = kind ? kind->string_value == "planar" : channel == "Z";

  AoInputs in;
  in.width = beauty.width;
  in.height = beauty.height;
  take_beauty(beauty, o.beauty, in);
  const double aspect = o.camera_aspect
                            ? *o.camera_aspect
                            : static_cast<double>(in.width) / static_cast<double>(in.height);
  in.camera = make_camera(o.camera.orthographic, o.camera.angle.value_or(0.0),
                          o.camera_width.value_or(0.0), aspect);
  std::vector<float> depth = ssao_tools::extract_channels(depth_image, {index});
  for (float& d : depth) {
    d = static_cast<float>(d * o.depth_scale);
    if (!(std::isfinite(d) && d > 0.0f)) d = kInfinity;
  }
  const bool depth_is_planar = planar || in.camera.orthographic;
  in.planar_input = depth_is_planar;
  fill_planar_and_radial(in, depth, depth_is_planar);
  report.progress("%dx%d, depth channel %s (%s), camera %s", in.width, in.height, channel.c_str(),
                  depth_is_planar ? "planar" : "radial", in.camera.summary().c_str());
  compute_and_write(o, in, report);
  report.progress("wrote %s%s in %.2f s", o.output.c_str(),
                  o.exr.empty() ? "" : (" and " + o.exr).c_str(), seconds_since(start));
}

}  // namespace povray_ssao
