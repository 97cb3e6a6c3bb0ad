// SPDX-License-Identifier: MIT
// libFuzzer target: the camera file's one reader, ssao_job_set_camera_json (core/src/
// camera_file.cpp, nlohmann-json), on random text, as the CLI, the evaluation tools and the
// Python module call it. It must either set a camera that holds what the format promises
// (known choices, finite numbers, an affine camera_to_world) or refuse with a message and
// leave every parameter of the job as it was.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "ssao/ssao.hpp"

namespace {

using fuzz::check;

// Every parameter's value as text, to compare a job before and after a refused file.
std::string snapshot(const ssao::api::Job& job) {
  std::string out;
  for (const ssao_param_desc& d : ssao::api::param_table()) {
    out += d.name;
    out += '=';
    if (d.type == SSAO_PARAM_STRING) {
      out += job.get_string(d.name);
    } else if (d.type == SSAO_PARAM_FLOATS) {
      for (double v : job.get_floats(d.name, d.count)) out += std::to_string(v) + ",";
    } else if (d.type == SSAO_PARAM_INT) {
      out += std::to_string(job.get_int(d.name));
    } else {
      out += std::to_string(job.get_float(d.name));
    }
    out += job.is_set(d.name) ? " set;" : ";";
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ssao::api::Job job;
  job.set("lens", 35.0);  // a job that is not all defaults: a refusal must keep it
  const std::string before = snapshot(job);
  if (ssao_job_set_camera_json(job.get(), reinterpret_cast<const char*>(data), size,
                               "fuzz.camera.json") != SSAO_OK) {
    check(std::strlen(ssao_last_error()) > 0, "refused without a message");
    check(snapshot(job) == before, "a refused camera file changed the job");
    return 0;
  }
  const std::string type = job.get_string("camera_type");
  check(type == "PERSP" || type == "ORTHO", "unknown type accepted");
  for (const char* name : {"lens", "sensor_width", "sensor_height", "ortho_scale", "pixel_aspect_x",
                           "pixel_aspect_y"}) {
    check(job.get_float(name) > 0.0 && std::isfinite(job.get_float(name)),
          "a size that is not positive and finite accepted");
  }
  const std::vector<double> matrix = job.get_floats("camera_to_world", 16);
  for (double v : matrix) check(std::isfinite(v), "a non-finite matrix accepted");
  check(matrix[12] == 0.0 && matrix[13] == 0.0 && matrix[14] == 0.0 && matrix[15] == 1.0,
        "a non-affine matrix accepted");
  job.camera_unknown_keys();
  return 0;
}
