// SPDX-License-Identifier: MIT
#include "outputs.h"

#include <cstdio>
#include <filesystem>

#include "ssao/ssao.hpp"

namespace povray_ssao {
namespace {

std::vector<std::string> full_channel_names() { return {"R", "G", "B", "A", "AO", "Z", "Radial"}; }

// The 8-bit preview: the composite's R, G, B (and A when the beauty had alpha).
void write_preview(const std::string& path, const AoInputs& in,
                   const std::vector<float>& composite) {
  const size_t count = in.frame_pixels();
  const size_t channels = in.beauty_has_alpha ? 4 : 3;
  std::vector<float> preview(count * channels);
  for (size_t p = 0; p < count; ++p) {
    for (size_t c = 0; c < channels; ++c) preview[p * channels + c] = composite[p * 4 + c];
  }
  std::vector<std::string> names = {"R", "G", "B", "A"};
  names.resize(channels);
  ssao_tools::write_preview(path, in.width, in.height, names, preview);
}

}  // namespace

void write_outputs(const OutputFiles& files, const AoInputs& in,
                   const std::vector<float>& composite, const std::vector<float>& ao) {
  const size_t count = in.frame_pixels();
  std::vector<float> full(count * 7);
  for (size_t p = 0; p < count; ++p) {
    for (size_t c = 0; c < 4; ++c) full[p * 7 + c] = composite[p * 4 + c];
    full[p * 7 + 4] = ao[p];
    full[p * 7 + 5] = in.planar[p];
    full[p * 7 + 6] = in.radial[p];
  }
  auto write_main = [&]() {
    if (ssao_tools::is_preview_path(files.output)) {
      write_preview(files.output, in, composite);
    } else {
      ssao_tools::write_exr(files.output, in.width, in.height, full_channel_names(), full);
    }
  };
  if (files.exr.empty()) {
    write_main();
    return;
  }
  ssao_tools::write_exr(files.exr, in.width, in.height, full_channel_names(), full);
  try {
    write_main();
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(files.exr, ec);
    throw;
  }
}

void write_depth_only(const std::string& output, const AoInputs& in) {
  const size_t count = in.frame_pixels();
  std::vector<float> pixels(count * 2);
  for (size_t p = 0; p < count; ++p) {
    pixels[p * 2] = in.planar[p];
    pixels[p * 2 + 1] = in.radial[p];
  }
  ssao_tools::write_exr(output, in.width, in.height, {"Z", "Radial"}, pixels);
}

void print_camera(const CameraReading& reading, bool scene_camera_for_frame, int width, int height,
                  int band) {
  std::printf("camera: %s\n  read from %s\n", reading.camera.summary().c_str(),
              reading.source.c_str());
  if (scene_camera_for_frame) {
    std::printf(
        "the beauty and the ambient pass are rendered with the scene's own camera (its focal "
        "blur kept)\nthe depth and normal passes, %dx%d%s, without focal blur, with:\n%s",
        width + 2 * band, height + 2 * band,
        band > 0 ? (" with a " + std::to_string(band) + "-pixel guard band").c_str() : "",
        reading.camera.widened(width, height, band).to_sdl().c_str());
  } else if (band > 0) {
    std::printf("the beauty and the ambient pass are rendered with (after the scene):\n%s",
                reading.camera.to_sdl().c_str());
    std::printf("the depth and normal passes, %dx%d with a %d-pixel guard band, with:\n%s",
                width + 2 * band, height + 2 * band, band,
                reading.camera.widened(width, height, band).to_sdl().c_str());
  } else {
    std::printf("every pass is rendered with (after the scene):\n%s",
                reading.camera.to_sdl().c_str());
  }
  // What the library uses, read back from a job the camera was applied to.
  ssao::api::Job job;
  reading.camera.apply_to_job(job, width, height);
  const std::string type = job.get_string("camera_type");
  const std::vector<double> k = job.get_floats("intrinsics", 4);
  std::printf("libssao (%dx%d): camera_type %s, projection %s, fx %.9g fy %.9g cx %.9g cy %.9g",
              width, height, type.c_str(), job.get_string("projection").c_str(), k[0], k[1], k[2],
              k[3]);
  if (type == "ORTHO") {
    std::printf(" pixels per unit: %.9g units across\n", width / k[0]);
  } else {
    std::printf(" pixels: a %.4g mm lens on a 36 mm sensor across the width\n",
                36.0 * k[0] / width);
  }
}

}  // namespace povray_ssao
