// SPDX-License-Identifier: MIT
// The two modes from start to end. Render mode: prepare (scene_setup), per image the passes
// (render_passes, depth_pass), AO and the outputs (compute_ao, outputs); animations render
// every frame that way. Post-process mode: the user's beauty and depth, AO, the outputs.
#include "bridge.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "animation.h"
#include "ao_inputs.h"
#include "compute_ao.h"
#include "outputs.h"
#include "pass_runner.h"
#include "passes.h"
#include "render_passes.h"
#include "reporter.h"
#include "scene_setup.h"
#include "tools/files.h"
#include "tools/image_io.h"
#include "tools/interrupt.h"

namespace povray_ssao {
namespace {

namespace fs = std::filesystem;
using ssao_tools::InterruptGuard;

// What the stages take of the command line.
OutputFiles output_files(const Options& o) { return {o.output, o.exr}; }

PovrayArguments povray_arguments(const Options& o) { return {o.ini, o.povray_options}; }

PassRunnerSettings pass_runner_settings(const Options& o) {
  return {o.povray, povray_arguments(o), !o.keep.empty()};
}

PassChoices pass_choices(const Options& o) {
  return {o.depth_only, o.apply_to, o.no_normals, o.fog_distances};
}

RenderRequest render_request(const Options& o) {
  RenderRequest request;
  request.scene = o.scene;
  request.width = o.width;
  request.height = o.height;
  request.povray_arguments = povray_arguments(o);
  request.outputs = output_files(o);
  request.print_camera = o.print_camera;
  request.keep = o.keep;
  request.overscan = o.overscan;
  request.depth_only = o.depth_only;
  return request;
}

// The beauty and the ambient pass keep the scene's own camera when it has focal blur: POV-Ray
// blurs them as the user asked, while the depth and normal passes, rendered with the resolved
// camera, stay sharp (a blurred depth would mix distances). Camera flags replace the camera.
bool scene_camera_for_frame(const Options& o, const CameraReading& reading) {
  return reading.had_focal_blur && !o.camera.any();
}

// The camera's warnings, and what the passes cannot reproduce of it.
void report_camera(const Options& o, const ImageScene& scene, int width, int height,
                   const Reporter& report) {
  const CameraReading& reading = scene.reading;
  report.progress("camera: %s (%s)", reading.camera.summary().c_str(), reading.source.c_str());
  for (const std::string& note : scene.scan.notes) report.warning(note);
  for (const std::string& warning : reading.warnings) report.warning(warning);
  if (scene_camera_for_frame(o, reading)) {
    report.progress(
        "focal blur: the beauty and the ambient pass keep the scene's camera and its blur; AO "
        "comes from sharp depth%s passes, so it is sharp where the image is blurred (and its "
        "edges are not read from the beauty: edge_coverage none)",
        scene.scan.includes_ssao_passes && !o.no_normals ? " and normal" : "");
  } else if (reading.had_focal_blur) {
    report.warning(
        "the scene's camera has focal blur (aperture), which the --camera-* flags replace: "
        "every pass, the beauty included, is rendered without it");
  }
  const double pixel_ratio =
      reading.camera.aspect() / (static_cast<double>(width) / static_cast<double>(height));
  if (std::fabs(pixel_ratio - 1.0) > 0.01) {
    report.warning("the camera's |right|/|up| (" + std::to_string(reading.camera.aspect()) +
                   ") differs from the image's width/height: non-square pixels, as POV-Ray "
                   "renders them");
  }
}

// One image (a still, or one frame of an animation): the passes, AO and the outputs.
void render_image(const Options& o, const RenderSetup& setup, const AnimationFrame* frame,
                  const Reporter& report) {
  const auto start = Clock::now();
  const int width = setup.width, height = setup.height;
  if (!o.keep.empty()) {
    std::error_code ec;
    fs::create_directories(o.keep, ec);
    if (!fs::is_directory(o.keep, ec)) {
      throw ssao_tools::Error("--keep: cannot create the folder " + in_quotes(o.keep));
    }
  }
  const PassRunnerSettings povray_settings = pass_runner_settings(o);
  const ImageScene scene =
      read_image_scene(o.camera, o.print_camera, povray_settings, setup, frame, report);
  const CameraReading& reading = scene.reading;
  const int band = guard_band(o.overscan, o.depth_only, width, height);
  if (o.print_camera) {
    for (const std::string& note : scene.scan.notes) report.warning(note);
    for (const std::string& warning : reading.warnings) report.warning(warning);
    print_camera(reading, scene_camera_for_frame(o, reading), width, height, band);
    return;
  }
  report_camera(o, scene, width, height, report);

  ScratchFolder scratch;
  const PassRunner povray = make_pass_runner(povray_settings, setup, frame, scratch, &scene.scan);
  KeepFiles keep(scratch, o.keep, report);
  // The data passes libssao reads (depth, normals) see a band around the frame: occluders just
  // outside it darken its edges. The beauty and the ambient pass are the frame.
  write_wrappers(scratch.path(), setup.scene_name,
                 scene_camera_for_frame(o, reading) ? nullptr : &reading.camera,
                 band > 0 ? reading.camera.widened(width, height, band) : reading.camera);
  ImagePasses passes(pass_choices(o), povray, scene, width, height, band, report);
  passes.start();

  AoInputs in;
  in.width = width;
  in.height = height;
  in.band = band;
  in.camera = reading.camera;
  in.beauty_blurred = scene_camera_for_frame(o, reading);
  passes.finish_depth(in);
  if (o.depth_only) {
    write_depth_only(o.output, in);
    const PassTimings t = passes.timings();
    if (t.prepass > 0.0) {
      report.progress("wrote %s (Z, Radial) in %.2f s: pre-pass %.2f s, depth %.2f s",
                      o.output.c_str(), seconds_since(start), t.prepass, t.depth);
    } else {
      report.progress("wrote %s (Z, Radial) in %.2f s: depth %.2f s", o.output.c_str(),
                      seconds_since(start), t.depth);
    }
    return;
  }
  passes.finish_beauty(in);
  passes.finish_ambient(in);
  passes.finish_normals(in);

  const double ao_seconds = compute_and_write(o.params, output_files(o), in, report);
  const std::string written = o.output + (o.exr.empty() ? "" : " and " + o.exr);
  report.progress("wrote %s in %.2f s (passes %s: %s; AO %.2f s)", written.c_str(),
                  seconds_since(start), povray.one_at_a_time ? "one after another" : "at once",
                  describe(passes.timings()).c_str(), ao_seconds);
}

// "1,5,7" (at most 50 numbers).
std::string frame_list(const std::vector<long>& frames) {
  std::string list;
  for (size_t k = 0; k < frames.size() && k < 50; ++k) {
    list += (k ? "," : "") + std::to_string(frames[k]);
  }
  if (frames.size() > 50) list += ",...";
  return list;
}

// One frame's options: its outputs named as POV-Ray names its frames, its own --keep folder.
Options frame_options(const Options& o, const AnimationFrame& frame) {
  Options options = o;
  if (!o.print_camera) options.output = frame_output(o.output, frame);
  if (!o.exr.empty()) options.exr = frame_output(o.exr, frame);
  if (!o.keep.empty()) options.keep = (fs::path(o.keep) / ("frame" + frame.digits)).string();
  return options;
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
    report.progress("frame %ld (%zu/%zu), clock %.6g:", frame.number, i + 1, frames.size(),
                    frame.clock);
    const auto frame_start = Clock::now();
    try {
      render_image(frame_options(o, frame), setup, &frame, report);
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
  report.progress("%zu of %zu frames written in %.1f s (%.1f frames per minute)", written,
                  frames.size(), wall, wall > 0.0 ? 60.0 * double(written) / wall : 0.0);
  if (!failed.empty()) {
    throw ssao_tools::Error(std::to_string(failed.size()) + " of " + std::to_string(frames.size()) +
                            " frames failed: " + frame_list(failed));
  }
}

// --beauty, --depth: the user's images, checked against each other and the outputs.
void read_post_process_inputs(const Options& o, const Reporter& report, ssao_tools::Image& beauty,
                              ssao_tools::Image& depth) {
  ssao_tools::check_output_folder(o.output);
  if (!o.exr.empty()) ssao_tools::check_output_folder(o.exr);
  for (const std::string& input : {o.beauty, o.depth}) {
    if (ssao_tools::same_file(o.output, input) ||
        (!o.exr.empty() && ssao_tools::same_file(o.exr, input))) {
      throw UsageError("the output " + in_quotes(input) + " is an input file; choose another name");
    }
  }
  beauty = ssao_tools::read_image(o.beauty);
  const std::string encoding = beauty.color_space;
  if (ssao_tools::linearize(beauty)) {
    report.progress("beauty %s is %s-encoded: linearised before the multiplication",
                    o.beauty.c_str(), encoding.c_str());
  }
  depth = ssao_tools::read_image(o.depth);
  if (beauty.width != depth.width || beauty.height != depth.height) {
    throw ssao_tools::Error("the beauty is " + std::to_string(beauty.width) + "x" +
                            std::to_string(beauty.height) + " but the depth is " +
                            std::to_string(depth.width) + "x" + std::to_string(depth.height));
  }
}

// --depth-channel, else the first of the usual names, else a file's only channel.
std::string depth_channel(const Options& o, const ssao_tools::Image& depth) {
  if (!o.depth_channel.empty()) return o.depth_channel;
  for (const char* candidate : {"Radial", "Z", "R", "Y", "depth", "Depth"}) {
    if (depth.find_channel(candidate) >= 0) return candidate;
  }
  if (depth.channels() == 1) return depth.channel_names[0];
  throw UsageError("cannot tell which channel of " + in_quotes(o.depth) +
                   " holds the depth; name it with --depth-channel (channels: " +
                   ssao_tools::join_names(depth.channel_names) + ")");
}

}  // namespace

void run_render(const Options& o) {
  InterruptGuard interrupt_guard;
  const Reporter report(o.quiet);
  const RenderSetup setup = prepare_render(render_request(o));
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
  ssao_tools::Image beauty, depth_image;
  read_post_process_inputs(o, report, beauty, depth_image);
  const std::string channel = depth_channel(o, depth_image);
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
  compute_and_write(o.params, output_files(o), in, report);
  report.progress("wrote %s%s in %.2f s", o.output.c_str(),
                  o.exr.empty() ? "" : (" and " + o.exr).c_str(), seconds_since(start));
}

}  // namespace povray_ssao
