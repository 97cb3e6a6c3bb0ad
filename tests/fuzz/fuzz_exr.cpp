// SPDX-License-Identifier: MIT
// libFuzzer target: the command-line tool's input path on EXR files. The file goes the way
// build/bin/ssao takes its --input (core/cli/app.cpp load_inputs): ssao_tools::read_channels
// (OpenImageIO in the module libssao_image_codec.so) of the passes detect_passes chooses, each
// straight into its buffer, and, for small images, a run of the library on them. Its oracle is
// the whole image: read_image (every channel), linearize, detect_passes on its channel names,
// extract_channels of depth, normal and beauty; read_channels must give these bit for bit.
// Everything must either work or throw ssao_tools::Error; an image that reads must be
// consistent (as many floats as width x height x channels, the passes chosen exist).
//
// The file is made from the input, in one of two ways:
// - structured (what the fuzzer explores): the input chooses what an EXR can hold and
//   OpenImageIO writes it: sizes, 1 to 3 parts (of equal or different sizes), channel names
//   (Blender's <layer>.<pass>.<channel>, plain R/G/B/A/Z, duplicates, random strings), half or
//   float, tiles, compression, a data window that is not the display window (short of it, or
//   larger: overscan, which the CLI reads), a colour-space
//   attribute, pixel values as raw bits (NaN, Inf, denormals);
// - raw (SSAO_FUZZ_RAW=1, how scripts/fuzz.sh replays the *.exr files of
//   tests/fuzz/regressions/fuzz_exr/ and the seeds make_exr_seeds writes): the input's bytes are
//   the file.
// Raw bytes are not fuzzed: Debian's OpenEXR 3.1, not instrumented and not this project's,
// allocates what a damaged header claims (gigabytes for a 300-byte file) in more places than
// core/tools/image_codec.cpp's header check can cover without rewriting OpenEXR's parser, and under
// AddressSanitizer an allocation that large ends the process instead of throwing bad_alloc.
// Every mutated header would be an OpenEXR finding, not one of this project's code.
#include <OpenImageIO/imageio.h>
#include <fuzzer/FuzzedDataProvider.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "ssao/ssao.hpp"
#include "tools/blender_passes.h"
#include "tools/image_io.h"

namespace {

using fuzz::check;

std::vector<int> indices_of(const ssao_tools::Image& image, const std::vector<std::string>& names,
                            const std::string& path) {
  std::vector<int> indices;
  for (const std::string& name : names) {
    indices.push_back(ssao_tools::require_channel(image, name, path));
  }
  return indices;
}

std::string channel_name(FuzzedDataProvider& in) {
  static const char* const names[] = {"R",
                                      "G",
                                      "B",
                                      "A",
                                      "Z",
                                      "depth",
                                      "Depth",
                                      "Depth.Z",
                                      "N.X",
                                      "N.Y",
                                      "N.Z",
                                      "Normal.X",
                                      "Normal.Y",
                                      "Normal.Z",
                                      "Combined.R",
                                      "Combined.G",
                                      "Combined.B",
                                      "Combined.A",
                                      "ViewLayer.Depth.Z",
                                      "ViewLayer.Normal.X",
                                      "ViewLayer.Normal.Y",
                                      "ViewLayer.Normal.Z",
                                      "ViewLayer.Combined.R",
                                      "ViewLayer.Combined.G",
                                      "ViewLayer.Combined.B",
                                      "ViewLayer.Combined.A",
                                      "Other.Layer.Depth.Z",
                                      "Other.Layer.Combined.R",
                                      ".Depth.Z",
                                      "Depth.Z.",
                                      "AO"};
  const size_t pick = in.ConsumeIntegralInRange<size_t>(0, std::size(names));
  if (pick < std::size(names)) return names[pick];
  return in.ConsumeRandomLengthString(16);
}

// Writes the EXR the input describes; false if OpenImageIO refuses to write it (then there is
// nothing to read).
bool write_structured(FuzzedDataProvider& in, const std::string& path) {
  const int parts = in.ConsumeIntegralInRange<int>(1, 3);
  const int width = in.ConsumeIntegralInRange<int>(1, 24);
  const int height = in.ConsumeIntegralInRange<int>(1, 24);
  static const char* const compressions[] = {"none", "zip",   "zips", "rle",
                                             "piz",  "pxr24", "b44",  "dwaa"};
  static const char* const spaces[] = {"",       "Linear", "sRGB",  "GammaCorrected2.2",
                                       "Gamma0", "Gamma1", "Gamma", "GammaCorrected-3"};
  // Tiles for the whole file or not at all, and only in single-part files: OpenEXR 3.1 crashes
  // writing some multi-part files with tiled parts (a writer this project does not use).
  const bool tiled = parts == 1 && in.ConsumeIntegralInRange<int>(0, 7) == 0;
  std::vector<OIIO::ImageSpec> specs;
  for (int p = 0; p < parts; ++p) {
    const bool other_size = p > 0 && in.ConsumeIntegralInRange<int>(0, 7) == 0;
    const int channels = in.ConsumeIntegralInRange<int>(1, 8);
    OIIO::ImageSpec spec(other_size ? width + 1 : width, height, channels,
                         in.ConsumeBool() ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
    spec.channelnames.clear();
    for (int c = 0; c < channels; ++c) spec.channelnames.push_back(channel_name(in));
    spec.alpha_channel = -1;
    spec.attribute("compression", in.PickValueInArray(compressions));
    if (tiled) spec.tile_width = spec.tile_height = 16;
    const int window = in.ConsumeIntegralInRange<int>(0, 15);
    if (window == 0) {  // data window inside a larger display
      spec.x = 1;
      spec.full_width = spec.width + 2;
      spec.full_height = spec.height;
    } else if (window == 1 && spec.width > 2 && spec.height > 1) {  // overscan around the display
      spec.x = -1;
      spec.full_width = spec.width - 2;
      spec.full_height = spec.height - 1;
    }
    const size_t space = in.ConsumeIntegralInRange<size_t>(0, std::size(spaces));
    const std::string colour_space =
        space < std::size(spaces) ? spaces[space] : in.ConsumeRandomLengthString(20);
    if (!colour_space.empty()) spec.attribute("oiio:ColorSpace", colour_space);
    spec.attribute("name", "part" + std::to_string(p));
    specs.push_back(spec);
  }
  auto out = OIIO::ImageOutput::create("openexr");
  if (!out) return false;
  bool ok = parts == 1 ? out->open(path, specs[0]) : out->open(path, parts, specs.data());
  for (int p = 0; ok && p < parts; ++p) {
    if (p > 0) ok = out->open(path, specs[size_t(p)], OIIO::ImageOutput::AppendSubimage);
    const OIIO::ImageSpec& spec = specs[size_t(p)];
    std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    const bool raw_bits = in.ConsumeBool();
    for (size_t i = 0; i < pixels.size(); ++i) {
      if (raw_bits) {
        const uint32_t bits = in.ConsumeIntegral<uint32_t>();
        std::memcpy(&pixels[i], &bits, sizeof bits);
      } else {
        pixels[i] = 0.5f + float(i % 7);  // plausible depths and colours
      }
    }
    ok = ok && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
  }
  ok = out->close() && ok;
  (void)out->geterror();  // a refused spec (e.g. duplicate channel names): nothing to read
  return ok;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool raw = std::getenv("SSAO_FUZZ_RAW") != nullptr;
  std::string path;
  if (raw) {
    path = fuzz::write_input("input.exr", data, size);
  } else {
    path = (fuzz::scratch_folder() / "input.exr").string();
    FuzzedDataProvider in(data, size);
    try {
      if (!write_structured(in, path)) return 0;
    } catch (const std::exception&) {
      return 0;  // OpenEXR refused the spec by throwing (e.g. an empty channel name)
    }
  }

  ssao_tools::Image image;
  try {
    image = ssao_tools::read_image(path, ssao_tools::Overscan::read);
  } catch (const ssao_tools::Error&) {
    return 0;  // refused with a message: what the CLI prints
  }
  check(image.width >= 0 && image.height >= 0, "negative size");
  check(image.frame_x >= 0 && image.frame_y >= 0 && image.frame_width >= 0 &&
            image.frame_height >= 0 && image.frame_x + image.frame_width <= image.width &&
            image.frame_y + image.frame_height <= image.height,
        "the display window is not inside the data window read");
  check(image.pixels.size() == image.pixel_count() * size_t(image.channels()),
        "pixel buffer does not match width x height x channels");
  const bool linearized = ssao_tools::linearize(image);

  ssao_tools::PassChannels passes;
  try {
    passes = ssao_tools::detect_passes(image.channel_names, ssao_tools::PassOverrides{}, path);
  } catch (const ssao_tools::Error&) {
    return 0;
  }
  check(!passes.depth.empty(), "detect_passes returned no depth channel");
  check(passes.normal.empty() || passes.normal.size() == 3, "normal pass is not 3 channels");
  check(passes.beauty.empty() || passes.beauty.size() == 3 || passes.beauty.size() == 4,
        "beauty pass is not 3 or 4 channels");
  std::vector<float> depth, normal, beauty;
  try {
    depth = ssao_tools::extract_channels(image, indices_of(image, {passes.depth}, path));
    if (!passes.normal.empty()) {
      normal = ssao_tools::extract_channels(image, indices_of(image, passes.normal, path));
    }
    if (!passes.beauty.empty()) {
      beauty = ssao_tools::extract_channels(image, indices_of(image, passes.beauty, path));
    }
  } catch (const ssao_tools::Error&) {
    check(false, "a channel detect_passes chose does not exist");
  }
  check(depth.size() == image.pixel_count(), "depth size");

  // The CLI's way: only those channels, each pass into its own buffer.
  ssao_tools::FloatBuffer read_depth, read_normal, read_beauty;
  try {
    const ssao_tools::Image header = ssao_tools::read_channels(
        path, ssao_tools::Overscan::read, [&](const ssao_tools::Image& h) {
          check(h.channel_names == image.channel_names, "read_channels: other channel names");
          std::vector<ssao_tools::ChannelTarget> targets;
          const auto pass = [&](const std::vector<std::string>& names,
                                ssao_tools::FloatBuffer& buffer) {
            const int n = static_cast<int>(names.size());
            ssao_tools::resize_pass_buffer(buffer, h, n, path);
            for (int c = 0; c < n; ++c) {
              targets.push_back({ssao_tools::require_channel(h, names[size_t(c)], path),
                                 buffer.data() + c, n, std::ptrdiff_t(n) * h.width});
            }
          };
          pass({passes.depth}, read_depth);
          if (!passes.normal.empty()) pass(passes.normal, read_normal);
          if (!passes.beauty.empty()) pass(passes.beauty, read_beauty);
          return targets;
        });
    check(header.width == image.width && header.height == image.height &&
              header.frame_x == image.frame_x && header.frame_y == image.frame_y &&
              header.frame_width == image.frame_width &&
              header.frame_height == image.frame_height && header.pixels.empty(),
          "read_channels: another header than read_image's");
  } catch (const ssao_tools::Error& e) {
    std::fprintf(stderr, "fuzz_exr: read_channels refused what read_image read: %s\n", e.what());
    std::abort();
  }
  const auto same_bits = [](const std::vector<float>& a, const ssao_tools::FloatBuffer& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
  };
  // linearize() changed every channel but alpha (the CLI reads them as stored): compared for a
  // file stored linear only.
  if (!linearized) {
    check(same_bits(depth, read_depth) && same_bits(normal, read_normal) &&
              same_bits(beauty, read_beauty),
          "read_channels: a pass differs from read_image's");
  }

  // The library on what was read, as the CLI attaches it (small images only: speed).
  if (image.frame_pixel_count() == 0 || image.pixel_count() > 4096) return 0;
  const int w = image.width, h = image.height;
  const int fw = image.frame_width, fh = image.frame_height;
  try {
    ssao::api::Job job;
    job.set("threads", 1);
    job.set_image("depth", depth.data(), w, h, 1);
    if (!normal.empty()) job.set_image("normal", normal.data(), w, h, 3);
    job.set_output_window(image.has_overscan(), image.frame_x, image.frame_y);
    const int beauty_channels = static_cast<int>(passes.beauty.size());
    std::vector<float> ao(image.frame_pixel_count(), -1.0f),
        composite(image.frame_pixel_count() * size_t(beauty_channels));
    job.set_image("ao", ao.data(), fw, fh, 1);
    if (!beauty.empty()) {
      const ssao_tools::FrameView view = ssao_tools::frame_view(image, beauty, beauty_channels);
      job.set_image("beauty", view.data, fw, fh, beauty_channels, view.pixel_stride,
                    view.row_stride);
      job.set_image("composite", composite.data(), fw, fh, beauty_channels);
    }
    job.run();
    for (float v : ao) check(v >= 0.0f && v <= 1.0f, "AO outside [0, 1] or NaN");
  } catch (const ssao::api::Error& e) {
    // The images are valid for the library whatever their values (the camera is the default).
    std::fprintf(stderr, "fuzz_exr: the library refused a readable image: %s\n", e.what());
    std::abort();
  }
  return 0;
}
