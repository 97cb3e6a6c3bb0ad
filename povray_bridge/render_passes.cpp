// SPDX-License-Identifier: MIT
#include "render_passes.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "passes.h"

namespace povray_ssao {

std::string describe(const PassTimings& t) {
  std::string out;
  char buffer[64];
  const std::pair<const char*, double> timings[] = {{"pre-pass", t.prepass},
                                                    {"beauty", t.beauty},
                                                    {"depth", t.depth},
                                                    {"ambient", t.ambient},
                                                    {"normals", t.normals}};
  for (const auto& [what, seconds] : timings) {
    if (seconds <= 0.0) continue;  // not rendered
    std::snprintf(buffer, sizeof buffer, "%s%s %.2f s", out.empty() ? "" : ", ", what, seconds);
    out += buffer;
  }
  return out;
}

ImagePasses::ImagePasses(const PassChoices& choices, const PassRunner& povray,
                         const ImageScene& scene, int width, int height, int band,
                         const Reporter& report)
    : choices_(choices),
      povray_(povray),
      scan_(scene.scan),
      camera_(scene.reading.camera),
      width_(width),
      height_(height),
      band_(band),
      report_(report),
      depth_(choices.fog_distances, povray, scene.scan, scene.reading.camera, width + 2 * band,
             height + 2 * band, report) {}

// What AO darkens: the ambient term when the scene has one that can be rendered apart.
bool ImagePasses::wants_ambient_pass() const {
  if (choices_.depth_only || choices_.apply_to == "beauty") return false;
  std::string why_not;
  if (scan_.uses_radiosity && (scan_.version == 0.0 || scan_.version >= 3.7)) {
    why_not =
        "the scene uses radiosity, which replaces the ambient term in POV-Ray 3.7 (there is no "
        "ambient light to darken)";
  } else if (!scan_.ambient_light_problem.empty()) {
    why_not =
        "povray-ssao cannot read the scene's ambient_light (" + scan_.ambient_light_problem + ")";
  }
  if (why_not.empty()) return true;
  if (choices_.apply_to == "ambient") throw ssao_tools::Error("--apply-to ambient: " + why_not);
  report_.progress("AO darkens the whole image: %s", why_not.c_str());
  return false;
}

// The basis of the camera every pass is rendered with, imposed on ssao_passes.inc (its
// SSAOCamera/SSAOCameraBasis vectors could describe another camera, e.g. with --camera-*).
void ImagePasses::start_normal_pass() {
  std::vector<std::string> options = {"+Q6", "-A", "-UA", "Declare=SSAOPass=1"};
  const std::pair<const char*, V3> axes[3] = {{"Right", normalized(camera_.right)},
                                              {"Up", normalized(camera_.up)},
                                              {"Forward", normalized(camera_.direction)}};
  for (const auto& [name, axis] : axes) {
    const double components[3] = {axis.x, axis.y, axis.z};
    for (int c = 0; c < 3; ++c) {
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, "Declare=SSAOBasis%s%c=%.17g", name, "XYZ"[c],
                    components[c]);
      options.push_back(buffer);
    }
  }
  normals_ = povray_.start("normal pass", "normals", "normals.pov", width_ + 2 * band_,
                           height_ + 2 * band_, options);
}

void ImagePasses::start() {
  ambient_pass_ = wants_ambient_pass();
  const bool normals = !choices_.depth_only && scan_.includes_ssao_passes && !choices_.no_normals;
  const char* passes = choices_.depth_only ? "the depth pass"
                       : ambient_pass_ ? (normals ? "the beauty, depth, ambient and normal passes"
                                                  : "the beauty, depth and ambient passes")
                       : normals       ? "the beauty, depth and normal passes"
                                       : "the beauty and the depth pass";
  if (povray_.one_at_a_time) {
    report_.progress(
        "the scene writes a file as it parses (%s): rendering %s (%dx%d) one after another, "
        "since side by side they would read it half-written from each other...",
        scan_.file_write.c_str(), passes, width_, height_);
  }
  if (!choices_.depth_only) {
    beauty_ = povray_.start("beauty", "beauty", "beauty.pov", width_, height_, {});
  }
  if (ambient_pass_) {
    // +Q3 skips shadows, reflection and refraction; +Q6 where +Q3 would show quick colours.
    ambient_ = povray_.start("ambient pass", "ambient", "ambient.pov", width_, height_,
                             {scan_.uses_quick_color ? "+Q6" : "+Q3", "-A", "-UA"});
  }
  if (normals) start_normal_pass();
  depth_.choose_fogs();
  depth_.start();
  const int data_width = width_ + 2 * band_, data_height = height_ + 2 * band_;
  if (band_ > 0) {
    report_.progress(
        "guard band %d pixels (--overscan): the depth%s pass%s %dx%d, cropped to %dx%d", band_,
        normals ? " and normal" : "", normals ? "es are" : " is", data_width, data_height, width_,
        height_);
  }
  if (!povray_.one_at_a_time)
    report_.progress("rendering %s (%dx%d) at once...", passes, width_, height_);
  // The image file module (OpenImageIO) loads while POV-Ray renders.
  ssao_tools::preload_image_io();
}

void ImagePasses::finish_depth(AoInputs& in) {
  const std::vector<float> depth = depth_.finish();
  // Fog depth is radial for a perspective camera and planar for an orthographic one.
  in.planar_input = camera_.orthographic;
  fill_planar_and_radial(in, depth, camera_.orthographic);
}

// A pass at the frame's size (the beauty, the ambient pass), read once POV-Ray has written it.
ssao_tools::Image ImagePasses::read_frame_pass(const RunningPass& pass, const char* hint) const {
  ssao_tools::Image image = ssao_tools::read_image(pass.output);
  if (image.width != width_ || image.height != height_) {
    throw ssao_tools::Error("POV-Ray rendered the " + pass.what + " at " +
                            std::to_string(image.width) + "x" + std::to_string(image.height) +
                            " instead of " + std::to_string(width_) + "x" +
                            std::to_string(height_) + hint);
  }
  return image;
}

void ImagePasses::finish_beauty(AoInputs& in) {
  beauty_seconds_ = povray_.finish(beauty_);
  take_beauty(read_frame_pass(beauty_, " (partial render options in the INI file?)"),
              beauty_.output, in);
  report_.progress("  beauty %.2f s (the depth pass took %.2f x its time)", beauty_seconds_,
                   depth_.seconds / beauty_seconds_);
}

void ImagePasses::finish_ambient(AoInputs& in) {
  if (!ambient_pass_) return;
  ambient_seconds_ = povray_.finish(ambient_);
  const ssao_tools::Image image = read_frame_pass(ambient_, "");
  const V3 light = scan_.ambient_light.value_or(V3{1.0, 1.0, 1.0});
  size_t overflowed = 0;
  const std::vector<float> rgb = decode_ambient(image, light, ambient_.output, overflowed);
  in.working_gamma = scan_.assumed_gamma.value_or(1.0);
  if (!(in.working_gamma > 0.0)) in.working_gamma = 1.0;
  // The ambient term's share of the light, in the working space.
  double ambient_sum = 0.0, light_sum = 0.0;
  in.ambient.assign(in.frame_pixels() * 4, 0.0f);
  for (size_t p = 0; p < in.frame_pixels(); ++p) {
    for (size_t c = 0; c < 3; ++c) in.ambient[p * 4 + c] = rgb[p * 3 + c];
    if (!std::isfinite(in.radial[p])) continue;
    for (size_t c = 0; c < 3; ++c) {
      ambient_sum += rgb[p * 3 + c];
      const double b = in.beauty[p * 4 + c];
      light_sum += b > 0.0 ? std::pow(b, 1.0 / in.working_gamma) : 0.0;
    }
  }
  report_ambient_share(in, light, light_sum > 0.0 ? ambient_sum / light_sum : 0.0, overflowed);
}

// A scene whose ambient light is under 1% of the image's gets AO on the whole image instead.
void ImagePasses::report_ambient_share(AoInputs& in, const V3& light, double share,
                                       size_t overflowed) const {
  report_.progress(
      "  ambient pass %.2f s: the ambient light (ambient_light %s%s) is %.1f%% of "
      "the image's light",
      ambient_seconds_, format_vector(light).c_str(),
      scan_.ambient_light ? "" : ", POV-Ray's default", 100.0 * share);
  if (overflowed > 0) {
    report_.warning(std::to_string(overflowed) +
                    " pixels have an ambient term too bright for the ambient pass (finish "
                    "ambient x pigment above 6.5); AO leaves them unchanged");
  }
  if (share >= 0.01) return;
  if (choices_.apply_to == "ambient") {
    report_.warning("the scene has almost no ambient light: AO changes little");
  } else {
    report_.progress(
        "AO darkens the whole image: the scene has almost no ambient light "
        "(--apply-to ambient to darken only that)");
    in.ambient.clear();
  }
}

// The exact normals of scenes that opt in.
void ImagePasses::finish_normals(AoInputs& in) {
  if (!normals_.process) return;
  normal_seconds_ = povray_.finish(normals_);
  report_.progress("  normal pass %.2f s", normal_seconds_);
  const ssao_tools::Image image = ssao_tools::read_image(normals_.output);
  // decode_normals reads the depth of every pixel of the image: only a pass of its size.
  if (image.width != in.data_width() || image.height != in.data_height()) {
    throw ssao_tools::Error("POV-Ray rendered the normal pass at " + std::to_string(image.width) +
                            "x" + std::to_string(image.height) + " instead of " +
                            std::to_string(in.data_width()) + "x" +
                            std::to_string(in.data_height()));
  }
  double unit_fraction = 0.0;
  std::vector<float> normals =
      decode_normals(image, in.depth_input, normals_.output, unit_fraction);
  if (unit_fraction < 0.9) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.0f%%", 100.0 * unit_fraction);
    report_.warning(std::string("the normal pass does not decode to unit normals (") + buffer +
                    " of the pixels do); are all textures wrapped in SSAOTexture()? Using "
                    "normals reconstructed from the depth instead");
  } else {
    in.normals = std::move(normals);
  }
}

PassTimings ImagePasses::timings() const {
  PassTimings t;
  t.prepass = depth_.prepass_seconds;
  t.beauty = beauty_seconds_;
  t.depth = depth_.seconds;
  t.ambient = ambient_seconds_;
  t.normals = normal_seconds_;
  return t;
}

}  // namespace povray_ssao
