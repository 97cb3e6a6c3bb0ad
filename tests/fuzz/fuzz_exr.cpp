// SPDX-License-Identifier: MIT
// libFuzzer target: the command-line tool's input path on a random file. The input is written to
// a file and goes the way build/bin/ssao takes its --input (core/cli/app.cpp load_inputs):
// ssao_io::read_image (OpenImageIO in the module libssao_image_codec.so), detect_passes on its
// channel names, extract_channels of depth, normal and beauty, and, for small images, a run of
// the library on them. Everything must either work or throw ssao_io::Error; an image that reads
// must be consistent (as many floats as width x height x channels).
//
// OpenImageIO and OpenEXR are Debian's builds, not instrumented: the fuzzer is guided by the
// project's code only, and a crash inside them is reported as a finding of those libraries.
#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "io/blender_passes.h"
#include "io/image_io.h"
#include "io/job.h"

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_exr: %s\n", what);
    std::abort();
  }
}

std::vector<int> indices_of(const ssao_io::Image& image, const std::vector<std::string>& names,
                            const std::string& path) {
  std::vector<int> indices;
  for (const std::string& name : names) indices.push_back(ssao_io::require_channel(image, name, path));
  return indices;
}

}  // namespace

// A header may claim any size, and a legitimate reader allocates what it claims before finding
// the file truncated (the CLI does so up to OpenImageIO's default limit, 32 GB): the fuzzer's
// mutations of the size fields would spend every execution allocating. Images over 1 MB are
// refused at open here (the same error path the CLI takes over its limit), so an execution
// takes milliseconds. The codec module, loaded later, shares this OpenImageIO instance.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  OIIO::attribute("limits:imagesize_MB", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = fuzz::write_input("input.exr", data, size);
  ssao_io::Image image;
  try {
    image = ssao_io::read_image(path);
  } catch (const ssao_io::Error&) {
    return 0;  // refused with a message: what the CLI prints
  }
  check(image.width >= 0 && image.height >= 0, "negative size");
  check(image.pixels.size() == image.pixel_count() * size_t(image.channels()),
        "pixel buffer does not match width x height x channels");
  ssao_io::linearize(image);

  ssao_io::PassChannels passes;
  try {
    passes = ssao_io::detect_passes(image.channel_names, ssao_io::PassOverrides{}, path);
  } catch (const ssao_io::Error&) {
    return 0;
  }
  check(!passes.depth.empty(), "detect_passes returned no depth channel");
  check(passes.normal.empty() || passes.normal.size() == 3, "normal pass is not 3 channels");
  check(passes.beauty.empty() || passes.beauty.size() == 3 || passes.beauty.size() == 4,
        "beauty pass is not 3 or 4 channels");
  std::vector<float> depth, normal, beauty;
  try {
    depth = ssao_io::extract_channels(image, indices_of(image, {passes.depth}, path));
    if (!passes.normal.empty()) {
      normal = ssao_io::extract_channels(image, indices_of(image, passes.normal, path));
    }
    if (!passes.beauty.empty()) {
      beauty = ssao_io::extract_channels(image, indices_of(image, passes.beauty, path));
    }
  } catch (const ssao_io::Error&) {
    check(false, "a channel detect_passes chose does not exist");
  }
  check(depth.size() == image.pixel_count(), "depth size");

  // The library on what was read, as the CLI attaches it (small images only: speed).
  if (image.pixel_count() == 0 || image.pixel_count() > 4096) return 0;
  const int w = image.width, h = image.height;
  try {
    ssao_io::Job job;
    job.set("threads", 1);
    job.set_image("depth", depth.data(), w, h, 1);
    if (!normal.empty()) job.set_image("normal", normal.data(), w, h, 3);
    std::vector<float> ao(image.pixel_count(), -1.0f), composite(beauty.size());
    job.set_image("ao", ao.data(), w, h, 1);
    const int beauty_channels = static_cast<int>(passes.beauty.size());
    if (!beauty.empty()) {
      job.set_image("beauty", beauty.data(), w, h, beauty_channels);
      job.set_image("composite", composite.data(), w, h, beauty_channels);
    }
    job.run();
    for (float v : ao) check(v >= 0.0f && v <= 1.0f, "AO outside [0, 1] or NaN");
  } catch (const ssao_io::CoreError& e) {
    // Only the camera-independent checks can refuse here, and none applies to these images.
    std::fprintf(stderr, "fuzz_exr: the library refused a readable image: %s\n", e.what());
    std::abort();
  }
  return 0;
}
