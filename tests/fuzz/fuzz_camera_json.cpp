// SPDX-License-Identifier: MIT
// libFuzzer target: the camera file of the command-line tool (--camera) on random text:
// ssao_tools::parse_camera_json (nlohmann-json), then apply_camera onto a job as the CLI does. Both
// must either work or throw ssao_tools::Error. A camera that parses must hold what the format
// promises (core/tools/camera_json.h): finite numbers, known choices, an affine matrix.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_common.h"
#include "ssao/ssao.hpp"
#include "tools/camera_json.h"

namespace {

using fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  ssao_tools::Camera camera;
  try {
    camera = ssao_tools::parse_camera_json(text, "fuzz.camera.json");
  } catch (const ssao_tools::Error&) {
    return 0;  // refused with a message: what the CLI prints
  }
  check(camera.type == "PERSP" || camera.type == "ORTHO", "unknown type accepted");
  check(camera.sensor_fit == "AUTO" || camera.sensor_fit == "HORIZONTAL" ||
            camera.sensor_fit == "VERTICAL",
        "unknown sensor_fit accepted");
  for (double v : {camera.lens, camera.sensor_width, camera.sensor_height, camera.shift_x,
                   camera.shift_y, camera.ortho_scale, camera.clip_start, camera.clip_end,
                   camera.pixel_aspect_x, camera.pixel_aspect_y, camera.ao_distance}) {
    check(std::isfinite(v), "a non-finite number accepted");
  }
  for (double v : camera.matrix_world) check(std::isfinite(v), "a non-finite matrix accepted");
  check(camera.projection == "lens" || camera.projection == "intrinsics" ||
            camera.projection == "matrix",
        "unknown projection accepted");
  check(camera.intrinsics.empty() || camera.intrinsics.size() == 4, "intrinsics not 4 values");
  check(camera.projection_matrix.empty() || camera.projection_matrix.size() == 16,
        "projection_matrix not 16 values");
  for (double v : camera.intrinsics) check(std::isfinite(v), "non-finite intrinsics accepted");
  for (double v : camera.projection_matrix) check(std::isfinite(v), "non-finite matrix accepted");
  check(camera.matrix_world[12] == 0.0 && camera.matrix_world[13] == 0.0 &&
            camera.matrix_world[14] == 0.0 && camera.matrix_world[15] == 1.0,
        "a non-affine matrix accepted");
  ssao::api::Job job;
  try {
    ssao_tools::apply_camera(job.get(), camera, "fuzz.camera.json");
  } catch (const ssao::api::Error&) {
    // The core refused a value (e.g. a lens outside its range): the CLI reports it.
  }
  return 0;
}
