// SPDX-License-Identifier: MIT
#include "app.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <set>
#include <string>

#include "ssao/ssao.hpp"
#include "tools/blender_passes.h"
#include "tools/camera_json.h"
#include "tools/files.h"
#include "tools/frames.h"
#include "tools/image_io.h"
#include "tools/progress.h"

namespace ssao_cli {
namespace {

namespace fs = std::filesystem;

// The input image's header and the passes the core reads, each tightly packed, read from the
// file straight into these buffers (the file's other channels are not read). With overscan (an
// EXR whose data window is larger than its display window) the passes hold the whole data
// window: the AO of the frame (image.frame_*) is computed from all of it.
struct Inputs {
  ssao_tools::Image image;  // no pixels
  ssao_tools::PassChannels passes;
  ssao_tools::FloatBuffer depth;   // 1 channel
  ssao_tools::FloatBuffer normal;  // 3 channels or empty
  ssao_tools::FloatBuffer beauty;  // 3 or 4 channels or empty
  bool composite = true;           // false with --ao-only: the beauty only guides edge coverage
  // The 2nd, 3rd, ... hit's depth, 1 channel each, and its facing (empty when not given).
  std::vector<ssao_tools::FloatBuffer> layer_depth, layer_facing;
  int beauty_channels() const { return static_cast<int>(passes.beauty.size()); }
  int composite_channels() const { return composite ? beauty_channels() : 0; }
};

// What the core writes, straight into the layout of the output file: R, G, B[, A] (the
// composite, as many channels as the beauty) then AO, interleaved; AO alone with --ao-only.
// Kept from one frame of a sequence to the next.
struct Outputs {
  ssao_tools::FloatBuffer pixels;
  std::vector<std::string> names;
};

using ssao_tools::ProgressReporter;
using ssao_tools::same_file;

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
  ssao_tools::check_output_folder(options.output);
  const std::string extension = fs::path(options.output).extension().string();
  if (extension != ".exr" && !ssao_tools::is_preview_path(options.output)) {
    throw ssao_tools::Error("cannot write '" + options.output + "': use .exr (linear float data) " +
                            "or .png, .jpg, .tif (an 8-bit sRGB preview)");
  }
}

// Sets the job's camera from the camera file's text (the library reads the format), warning
// about keys the format does not know.
void apply_camera(ssao::api::Job& job, const std::string& text, const Options& options) {
  const std::vector<std::string> unknown = ssao_tools::apply_camera_text(job, text, options.camera);
  if (options.quiet) return;
  for (const std::string& key : unknown) {
    std::fprintf(stderr, "ssao: warning: camera file '%s': unknown key '%s' ignored\n",
                 options.camera.c_str(), key.c_str());
  }
}

// The channels the run reads: the passes found (or named) among the file's channels.
ssao_tools::PassChannels choose_passes(const Options& options, const ssao_tools::Image& header,
                                       const ssao_tools::PassOverrides& overrides) {
  ssao_tools::PassChannels passes =
      ssao_tools::detect_passes(header.channel_names, overrides, options.input);
  // With --ao-only a beauty found is still read: edge_coverage = beauty takes each surface's
  // share of an edge pixel from its colours, so the AO is the same as with a composite.
  if (!options.ao_only && passes.beauty.empty()) {
    throw ssao_tools::Error(
        "'" + options.input + "' has no beauty pass (looked for " +
        (passes.layer.empty() ? "" : passes.layer + ".") +
        "Combined.R/G/B); use --ao-only to write AO alone, or name the beauty " +
        "channels with --beauty-channels R,G,B[,A]");
  }
  return passes;
}

// Reads the passes the run needs from options.input, each into its own buffer of `in`; the
// buffers of `recycled` (a frame before) are used again where they are large enough.
Inputs load_inputs(const Options& options, Inputs recycled = Inputs()) {
  Inputs in = std::move(recycled);
  ssao_tools::PassOverrides overrides;
  overrides.layer = options.layer;
  overrides.depth_channel = options.depth_channel;
  overrides.normal_channels = options.normal_channels;
  overrides.beauty_channels = options.beauty_channels;
  overrides.no_normals = options.no_normals;
  overrides.depth_layers = options.depth_layers;
  overrides.no_depth_layers = options.no_depth_layers;
  const auto choose = [&](const ssao_tools::Image& header) {
    in.image = header;
    in.composite = !options.ao_only;
    in.passes = choose_passes(options, header, overrides);
    std::vector<ssao_tools::ChannelTarget> targets;
    const auto pass = [&](const std::vector<std::string>& names, ssao_tools::FloatBuffer& buffer) {
      const int channels = static_cast<int>(names.size());
      ssao_tools::resize_pass_buffer(buffer, header, channels, options.input);
      for (int c = 0; c < channels; ++c) {
        targets.push_back({ssao_tools::require_channel(header, names[size_t(c)], options.input),
                           buffer.data() + c, channels, std::ptrdiff_t(channels) * header.width});
      }
    };
    pass({in.passes.depth}, in.depth);
    in.normal.clear();
    in.beauty.clear();
    if (!in.passes.normal.empty()) pass(in.passes.normal, in.normal);
    if (!in.passes.beauty.empty()) pass(in.passes.beauty, in.beauty);
    in.layer_depth.resize(in.passes.depth_layers.size());
    in.layer_facing.resize(in.passes.depth_layers.size());
    for (size_t k = 0; k < in.passes.depth_layers.size(); ++k) {
      const ssao_tools::DepthLayerChannels& layer = in.passes.depth_layers[k];
      pass({layer.depth}, in.layer_depth[k]);
      in.layer_facing[k].clear();
      if (!layer.facing.empty()) pass({layer.facing}, in.layer_facing[k]);
    }
    return targets;
  };
  ssao_tools::read_channels(options.input, ssao_tools::Overscan::read, choose);
  return in;
}

// Attaches the inputs and the outputs (allocated here, or kept from the frame before) to the job;
// every image the job may still hold from a frame before and this one lacks is detached.
void attach_images(ssao::api::Job& job, Inputs& in, Outputs& out) {
  const ssao_tools::Image& image = in.image;
  job.set_image("depth", in.depth.data(), image.width, image.height, 1);
  job.set_image("normal", in.normal.empty() ? nullptr : in.normal.data(), image.width, image.height,
                3);
  for (size_t k = 0; k < ssao_tools::kMaxDepthLayers; ++k) {
    const std::string hit = std::to_string(k + 2);
    const bool has_layer = k < in.layer_depth.size();
    const bool has_facing = has_layer && !in.layer_facing[k].empty();
    job.set_image(("depth" + hit).c_str(), has_layer ? in.layer_depth[k].data() : nullptr,
                  image.width, image.height, 1);
    job.set_image(("facing" + hit).c_str(), has_facing ? in.layer_facing[k].data() : nullptr,
                  image.width, image.height, 1);
  }
  // The outputs are the frame, written by the core into the output file's layout; the beauty is
  // read in place, the frame's window of the data.
  const int w = image.frame_width, h = image.frame_height;
  job.set_output_window(image.has_overscan(), image.frame_x, image.frame_y);
  const int colour = in.composite_channels();  // 0 with --ao-only
  const size_t stride = size_t(colour) + 1;
  out.names = {"R", "G", "B", "A"};
  out.names.resize(size_t(colour));
  out.names.push_back("AO");
  const size_t count = image.frame_pixel_count() * stride;
  if (count > out.pixels.capacity()) out.pixels = ssao_tools::FloatBuffer();  // nothing to copy
  out.pixels.resize(count);  // the core writes every value
  const std::ptrdiff_t pixel_bytes = std::ptrdiff_t(stride * sizeof(float));
  job.set_image("ao", out.pixels.data() + colour, w, h, 1, pixel_bytes, pixel_bytes * w);
  const int beauty_channels = in.beauty_channels();
  const auto attach_beauty = [&](const char* name, bool attach) {
    if (!attach) {
      job.set_image(name, nullptr, 0, 0, 1);
      return;
    }
    const ssao_tools::FrameView beauty =
        ssao_tools::frame_view(image, in.beauty.data(), beauty_channels);
    job.set_image(name, beauty.data, w, h, beauty_channels, beauty.pixel_stride, beauty.row_stride);
  };
  attach_beauty("beauty", colour > 0);
  attach_beauty("edge_colours", colour == 0 && beauty_channels > 0);
  if (colour > 0) {
    job.set_image("composite", out.pixels.data(), w, h, colour, pixel_bytes, pixel_bytes * w);
  } else {
    job.set_image("composite", nullptr, 0, 0, 1);
  }
}

// What a run would get wrong without a word (the library's rule: world-space normals without
// the camera's matrix), with this tool's flags for the way out.
void check_inputs(const ssao::api::Job& job, const std::string& camera_path) {
  if (ssao_job_check_inputs(job.get()) == SSAO_OK) return;
  throw ssao_tools::Error("camera file '" + camera_path + "': " + ssao_last_error() +
                          " (--normal-space camera, --no-normals)");
}

// Runs the job with progress on stderr; returns the time spent in milliseconds.
double compute_ao(ssao::api::Job& job, bool quiet) {
  ProgressReporter progress(quiet);
  job.set_progress(&ProgressReporter::callback, &progress);
  const auto start = std::chrono::steady_clock::now();
  const ssao_status status = ssao_job_run(job.get());
  const auto stop = std::chrono::steady_clock::now();
  progress.finish();
  job.set_progress(nullptr, nullptr);
  if (status == SSAO_ERROR_CANCELLED || ProgressReporter::interrupted()) {
    throw ssao_tools::Error("interrupted; nothing written");
  }
  ssao::api::check_status(status, "SSAO failed");
  return std::chrono::duration<double, std::milli>(stop - start).count();
}

// The output file's channels: beauty's (named R, G, B[, A]) x AO then AO, or AO alone; the core
// wrote them in the file's layout.
void write_output(const Options& options, const Inputs& in, const Outputs& out) {
  const int width = in.image.frame_width, height = in.image.frame_height;
  if (ssao_tools::is_preview_path(options.output)) {
    ssao_tools::write_preview_pixels(options.output, width, height, out.names, out.pixels.data());
  } else {
    ssao_tools::write_exr_pixels(options.output, width, height, out.names, out.pixels.data());
  }
}

// Mean AO over the frame's geometry pixels ("n/a" without any) and their count: what the
// library's background rule counted in the last run (ssao_job_last_run).
std::string mean_ao(const ssao::api::Job& job, size_t& count) {
  const ssao::api::Job::RunStats stats = job.last_run();
  count = stats.geometry_pixels;
  char mean[64] = "n/a";
  if (count > 0) std::snprintf(mean, sizeof mean, "%.4f", stats.mean_ao);
  return mean;
}

void print_summary(const Options& options, const ssao::api::Job& job, const Inputs& in,
                   double milliseconds) {
  size_t count = 0;
  const std::string mean = mean_ao(job, count);
  std::fprintf(stderr,
               "ssao: %s: %dx%d, variant %s, normals %s, depth layers %zu, %.1f ms, mean AO %s "
               "over %zu geometry pixels\n",
               options.output.c_str(), in.image.frame_width, in.image.frame_height,
               job.settings_summary().c_str(), in.normal.empty() ? "from depth" : "from pass",
               1 + in.layer_depth.size(), milliseconds, mean.c_str(), count);
}

// Without --radius: the library's rule (the camera file's ao_distance, else the automatic
// radius), said on stderr with how to change it.
void choose_radius(const Options& options, ssao::api::Job& job) {
  double radius = 0.0;
  ssao_radius_source source = SSAO_RADIUS_SET;
  // Failing only without a geometry pixel: AO is 1 whatever the radius.
  if (ssao_job_choose_radius(job.get(), 1, &radius, &source) != SSAO_OK) return;
  if (options.quiet || source == SSAO_RADIUS_SET) return;
  const std::string why = source == SSAO_RADIUS_CAMERA_FILE
                              ? "ao_distance of " + options.camera
                              : "10% of the view's width at the median depth";
  std::fprintf(stderr, "ssao: radius %.4g scene units (%s; --radius to change)\n", radius,
               why.c_str());
}

// One frame of a sequence, read ahead while the previous one computes.
struct FrameInputs {
  std::string camera_text;
  Inputs in;
};

Options frame_options(const Options& options, const ssao_tools::FramePattern& input,
                      const ssao_tools::FramePattern& output,
                      const ssao_tools::FramePattern& camera, int frame) {
  Options o = options;
  o.input = input.path(frame);
  o.output = output.path(frame);
  o.camera = camera.path(frame);
  o.quiet = true;  // per-frame warnings would interleave with the frame lines
  return o;
}

std::string duration_text(double seconds) {
  char buffer[64];
  const long total = std::lround(seconds);
  if (total >= 3600) {
    std::snprintf(buffer, sizeof buffer, "%ldh %02ldm", total / 3600, total / 60 % 60);
  } else if (total >= 60) {
    std::snprintf(buffer, sizeof buffer, "%ldm %02lds", total / 60, total % 60);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.1fs", seconds);
  }
  return buffer;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// --frames: every frame independently; the failures are reported and listed at the end.
void run_sequence(const Options& options) {
  const ssao_tools::FramePattern input(options.input), output(options.output);
  // A camera file that exists under its own name serves every frame (its name may hold '@').
  const ssao_tools::FramePattern camera = fs::is_regular_file(options.camera)
                                              ? ssao_tools::FramePattern::literal(options.camera)
                                              : ssao_tools::FramePattern(options.camera);
  if (!input.has_frame() || !output.has_frame()) {
    throw UsageError(std::string("with --frames, ") + (input.has_frame() ? "-o" : "the input") +
                     " needs a frame placeholder (#### for 4 digits, @, or %04d)");
  }
  {
    // Every frame must get the same radius, whichever machine or chunk renders it: --radius or
    // the camera file's, never the automatic one.
    const Options first = frame_options(options, input, output, camera, options.frames.front());
    ssao::api::Job probe;
    apply_camera(probe, ssao_tools::read_camera_text(first.camera), first);
    ssao_tools::apply_params(probe, options.params);
    if (ssao_job_choose_radius(probe.get(), 0, nullptr, nullptr) != SSAO_OK) {
      throw UsageError("a sequence needs --radius R, or \"ao_distance\" in its camera file ('" +
                       first.camera + "'): the automatic radius follows each frame's depth");
    }
  }

  ProgressReporter interrupt(true);  // Ctrl-C stops after the frame in progress
  ssao::api::Job job;
  Outputs out;  // its buffer serves every frame of the size
  const size_t total = options.frames.size();
  std::vector<int> failed;
  size_t written = 0, skipped = 0;
  const auto start = std::chrono::steady_clock::now();
  double compute_seconds = 0.0;

  // A frame's buffers serve the frame after next (the next one is read while this one computes):
  // the same memory, no new pages to fault in. The job points at them until attach_images
  // replaces every image of the frame after, before it runs again.
  Inputs spare;
  auto load = [](Options o, Inputs recycled) {
    FrameInputs f;
    f.camera_text = ssao_tools::read_camera_text(o.camera);
    f.in = load_inputs(o, std::move(recycled));
    return f;
  };
  auto wanted = [&](size_t i) {
    return !(options.skip_existing && fs::exists(output.path(options.frames[i])));
  };
  std::future<FrameInputs> next;
  auto prefetch = [&](size_t i) {
    while (i < total && !wanted(i)) ++i;  // skipped frames are not read
    if (i < total) {
      next = std::async(std::launch::async, load,
                        frame_options(options, input, output, camera, options.frames[i]),
                        std::move(spare));
      spare = Inputs();
    }
    return i;
  };
  size_t next_index = prefetch(0);

  // The temporal filter (temporal_frames) averages each frame with the frames just before it
  // that the job computed; in increasing order (the library's rule) the frames of the list
  // within its reach come before it. A frame whose predecessors this run did not compute (the
  // first of a chunk, one after a skipped frame) gets them computed first, not written, so that
  // every frame is what a serial run writes.
  const bool increasing =
      std::adjacent_find(options.sequence.begin(), options.sequence.end(),
                         [](int a, int b) { return a >= b; }) == options.sequence.end();
  std::set<int> estimated;  // the frames this job holds an estimate of
  auto run_frame = [&](int frame, FrameInputs& f, const Options& o) {
    apply_camera(job, f.camera_text, o);
    ssao_tools::apply_params(job, o.params);
    // Counted from the list's first frame: the library's frame numbers start at 0.
    job.set("frame", increasing ? frame - options.sequence.front() : -1);
    attach_images(job, f.in, out);
    check_inputs(job, o.camera);
    choose_radius(o, job);
    job.set_progress(&ProgressReporter::callback, &interrupt);
    const ssao_status result = ssao_job_run(job.get());
    job.set_progress(nullptr, nullptr);
    if (result == SSAO_ERROR_CANCELLED || ProgressReporter::interrupted()) {
      throw ssao_tools::Error("interrupted");
    }
    ssao::api::check_status(result, "SSAO failed");
    estimated.insert(frame);
  };
  auto warm_up = [&](int frame, const Options& o) {
    if (!increasing) return;
    ssao_tools::apply_params(job, o.params);
    const int reach = job.get_int("temporal_frames");
    for (const int earlier : options.sequence) {
      if (earlier <= frame - reach || earlier >= frame || estimated.count(earlier)) continue;
      const Options w = frame_options(options, input, output, camera, earlier);
      try {
        FrameInputs inputs = load(w, Inputs());
        run_frame(earlier, inputs, w);
        if (!options.quiet && !options.json_progress) {
          std::fprintf(stderr,
                       "ssao: frame %d computed first (not written): frame %d averages "
                       "it in (temporal_frames %d)\n",
                       earlier, frame, reach);
        }
      } catch (const std::exception&) {
        if (ProgressReporter::interrupted()) throw;
        // A serial run failed on it too (and said so); this frame goes without it, as there.
      }
    }
  };

  for (size_t i = 0; i < total; ++i) {
    const int frame = options.frames[i];
    const Options o = frame_options(options, input, output, camera, frame);
    std::string status = "ok", error, mean = "n/a";
    double seconds = 0.0;
    if (i != next_index) {  // prefetch() passed over it: its output exists
      status = "skipped";
      ++skipped;
    } else {
      const auto frame_start = std::chrono::steady_clock::now();
      try {
        FrameInputs f = next.get();
        next_index = prefetch(i + 1);  // read the next frame while this one computes
        refuse_overwriting_inputs(o);
        check_output_folder(o);
        warm_up(frame, o);
        run_frame(frame, f, o);
        write_output(o, f.in, out);
        size_t count = 0;
        mean = mean_ao(job, count);
        ++written;
        spare = std::move(f.in);
      } catch (const std::exception& e) {
        status = "failed";
        error = e.what();
        failed.push_back(frame);
        if (i + 1 < total && next_index <= i) next_index = prefetch(i + 1);
      }
      seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
      compute_seconds += seconds;
    }
    const size_t done = i + 1;
    const size_t computed = written + failed.size();
    // Frames still to do, at the mean time of those computed so far.
    const double left =
        computed > 0 ? compute_seconds / double(computed) * double(total - done) : 0.0;
    if (options.json_progress) {
      std::fprintf(
          stderr,
          "{\"frame\": %d, \"index\": %zu, \"total\": %zu, \"status\": \"%s\", "
          "\"seconds\": %.3f, \"mean_ao\": %s, \"eta_seconds\": %.1f, \"output\": %s%s%s}\n",
          frame, done, total, status.c_str(), seconds, mean == "n/a" ? "null" : mean.c_str(), left,
          json_string(o.output).c_str(),
          error.empty() ? "" : ", \"error\": ", error.empty() ? "" : json_string(error).c_str());
    } else if (!options.quiet || status == "failed") {
      if (status == "failed") {
        std::fprintf(stderr, "ssao: frame %d (%zu/%zu): error: %s\n", frame, done, total,
                     error.c_str());
      } else if (status == "skipped") {
        std::fprintf(stderr, "ssao: frame %d (%zu/%zu): skipped, %s exists\n", frame, done, total,
                     o.output.c_str());
      } else {
        std::fprintf(stderr, "ssao: frame %d (%zu/%zu): %s in %.2f s, mean AO %s; %s left\n", frame,
                     done, total, o.output.c_str(), seconds, mean.c_str(),
                     duration_text(left).c_str());
      }
    }
    std::fflush(stderr);
    if (ProgressReporter::interrupted()) {
      if (next.valid()) next.wait();
      throw ssao_tools::Error("interrupted after frame " + std::to_string(frame) + ": " +
                              std::to_string(written) + " frames written");
    }
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!options.quiet || !failed.empty()) {
    std::string list;
    for (size_t k = 0; k < failed.size() && k < 50; ++k) {
      list += (k ? "," : "") + std::to_string(failed[k]);
    }
    if (failed.size() > 50) list += ",...";
    std::fprintf(stderr, "ssao: %zu of %zu frames written in %s (%.1f frames per minute)%s%s%s\n",
                 written, total, duration_text(wall).c_str(),
                 wall > 0.0 ? 60.0 * double(written) / wall : 0.0,
                 skipped ? (", " + std::to_string(skipped) + " skipped").c_str() : "",
                 failed.empty() ? "" : "; failed: ", list.c_str());
  }
  if (!failed.empty()) {
    throw SequenceFailed(std::to_string(failed.size()) + " of " + std::to_string(total) +
                         " frames failed");
  }
}

}  // namespace

void list_chunks(const Options& options) {
  const size_t count = ssao_tools::chunk_count(options.frames.size(), options.chunk_size);
  for (size_t index = 0; index < count; ++index) {
    const std::vector<int> chunk =
        ssao_tools::chunk_frames(options.frames, options.chunk_size, index);
    std::printf("%zu %s\n", index, ssao_tools::format_frames(chunk).c_str());
  }
}

void run_ssao(const Options& options) {
  if (!options.frames.empty()) {
    run_sequence(options);
    return;
  }
  refuse_overwriting_inputs(options);
  check_output_folder(options);
  const std::string camera_text = ssao_tools::read_camera_text(options.camera);

  ssao::api::Job job;
  apply_camera(job, camera_text, options);
  ssao_tools::apply_params(job, options.params);  // after the camera: a flag overrides the file

  Inputs in = load_inputs(options);
  Outputs out;
  attach_images(job, in, out);
  check_inputs(job, options.camera);
  choose_radius(options, job);
  const double milliseconds = compute_ao(job, options.quiet);
  write_output(options, in, out);
  if (!options.quiet) print_summary(options, job, in, milliseconds);
}

}  // namespace ssao_cli
