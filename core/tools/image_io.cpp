// SPDX-License-Identifier: MIT
#include "tools/image_io.h"

#include <dlfcn.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "tools/image_codec.h"

namespace fs = std::filesystem;

namespace ssao_tools {
namespace {

std::string quoted(const std::string& path) { return "'" + path + "'"; }

// libssao_image_codec.so: found through the executable's run path (build/lib), else in
// <executable>/../lib. Bound lazily: OpenImageIO brings about 260 libraries, and resolving all
// their functions up front (RTLD_NOW) cost about 120 ms of every single-frame process (0.52 ->
// 0.40 s for a 640x360 frame); the few that the codec calls are resolved on first use.
const ImageCodec& codec() {
  static std::once_flag once;
  static const ImageCodec* loaded = nullptr;
  static std::string problem;
  std::call_once(once, [] {
    const char* const name = "libssao_image_codec.so";
    void* handle = ::dlopen(name, RTLD_LAZY | RTLD_LOCAL);
    if (handle == nullptr) {
      problem = ::dlerror();
      std::error_code ec;
      const fs::path self = fs::read_symlink("/proc/self/exe", ec);
      if (!ec) {
        const fs::path beside = self.parent_path().parent_path() / "lib" / name;
        handle = ::dlopen(beside.c_str(), RTLD_LAZY | RTLD_LOCAL);
        if (handle == nullptr) problem += "; " + std::string(::dlerror());
      }
    }
    if (handle == nullptr) return;
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "ssao_tools_image_codec"));
    if (entry == nullptr) {
      problem = std::string("no entry point: ") + ::dlerror();
      return;
    }
    loaded = entry();
  });
  if (loaded == nullptr) {
    throw Error("cannot load the image file module libssao_image_codec.so (" + problem +
                "); it is built next to libssao.so");
  }
  return *loaded;
}

}  // namespace

void preload_image_io() { (void)codec(); }

int Image::find_channel(const std::string& name) const {
  for (size_t i = 0; i < channel_names.size(); ++i) {
    if (channel_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::string join_names(const std::vector<std::string>& names, const char* separator) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += separator;
    out += names[i];
  }
  return out;
}

namespace {

void check_overscan(const Image& image, Overscan overscan, const std::string& path) {
  if (image.has_overscan() && overscan == Overscan::refuse) {
    throw Error("cannot read " + quoted(path) + ": its data window (" +
                std::to_string(image.width) + " x " + std::to_string(image.height) +
                ") is larger than its display window (" + std::to_string(image.frame_width) +
                " x " + std::to_string(image.frame_height) +
                "); crop it to the display window first");
  }
}

}  // namespace

Image read_image(const std::string& path, Overscan overscan) {
  Image image;
  std::string error;
  if (!codec().read(path, image, error)) throw Error(error);
  check_overscan(image, overscan, path);
  return image;
}

Image read_channels(const std::string& path, Overscan overscan, const ChannelChooser& choose) {
  // What `choose` throws crosses the module as a message; it is thrown again here as it was.
  std::exception_ptr failure;
  const ChannelChooser checked = [&](const Image& header) {
    try {
      check_overscan(header, overscan, path);
      return choose(header);
    } catch (...) {
      failure = std::current_exception();
      throw;
    }
  };
  Image header;
  std::string error;
  if (!codec().read_channels(path, header, checked, error)) {
    if (failure) std::rethrow_exception(failure);
    throw Error(error);
  }
  return header;
}

void resize_pass_buffer(FloatBuffer& buffer, const Image& image, int channels,
                        const std::string& path) {
  const size_t pixels = image.pixel_count();
  const size_t per_pixel = static_cast<size_t>(channels > 0 ? channels : 0);
  const auto too_large = [&](const char* what) {
    return Error("cannot read " + quoted(path) + ": " + what + " for " +
                 std::to_string(image.width) + " x " + std::to_string(image.height) + " x " +
                 std::to_string(channels) + " floats");
  };
  if (per_pixel != 0 && pixels > std::numeric_limits<size_t>::max() / sizeof(float) / per_pixel) {
    throw too_large("image too large");
  }
  const size_t count = pixels * per_pixel;
  try {
    if (count > buffer.capacity()) buffer = FloatBuffer();  // no copy of the old values
    buffer.resize(count);
  } catch (const std::bad_alloc&) {
    throw too_large("out of memory");
  } catch (const std::length_error&) {
    throw too_large("image too large");
  }
}

bool linearize(Image& image) {
  const std::string& space = image.color_space;
  double gamma = 0.0;  // 0: the sRGB curve
  if (space == "sRGB") {
    gamma = 0.0;
  } else if (space.rfind("GammaCorrected", 0) == 0 || space.rfind("Gamma", 0) == 0) {
    const std::string value = space.substr(space.rfind("GammaCorrected", 0) == 0 ? 14 : 5);
    gamma = std::strtod(value.c_str(), nullptr);
    if (!(gamma > 0.0) || gamma == 1.0) return false;
  } else {
    return false;
  }
  const size_t channels = static_cast<size_t>(image.channels());
  std::vector<bool> colour(channels);
  for (size_t c = 0; c < channels; ++c) {
    const std::string& name = image.channel_names[c];
    colour[c] = name != "A" && name != "Alpha" && name != "alpha";
  }
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    if (!colour[i % channels]) continue;
    const float v = image.pixels[i];
    if (gamma > 0.0) {
      image.pixels[i] = v > 0.0f ? static_cast<float>(std::pow(v, gamma)) : v;
    } else {
      image.pixels[i] =
          v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // IEC 61966-2-1
    }
  }
  image.color_space = "Linear";
  return true;
}

int require_channel(const Image& image, const std::string& name, const std::string& path) {
  const int index = image.find_channel(name);
  if (index < 0) {
    throw Error(quoted(path) + " has no channel " + quoted(name) +
                "; its channels are: " + join_names(image.channel_names));
  }
  return index;
}

std::vector<float> extract_named_channels(const Image& image, const std::vector<std::string>& names,
                                          const std::string& path) {
  std::vector<int> indices;
  for (const std::string& name : names) indices.push_back(require_channel(image, name, path));
  return extract_channels(image, indices);
}

std::vector<float> extract_channels(const Image& image, const std::vector<int>& indices) {
  const size_t n = indices.size();
  const size_t stride = static_cast<size_t>(image.channels());
  std::vector<float> out(image.pixel_count() * n);
  for (size_t p = 0; p < image.pixel_count(); ++p) {
    for (size_t k = 0; k < n; ++k) {
      out[p * n + k] = image.pixels[p * stride + static_cast<size_t>(indices[k])];
    }
  }
  return out;
}

FrameView frame_view(const Image& image, float* pass, int channels) {
  const size_t first = static_cast<size_t>(image.frame_y) * static_cast<size_t>(image.width) +
                       static_cast<size_t>(image.frame_x);
  const std::ptrdiff_t pixel_bytes = std::ptrdiff_t(channels) * std::ptrdiff_t(sizeof(float));
  return {pass + first * static_cast<size_t>(channels), pixel_bytes, pixel_bytes * image.width};
}

FrameView frame_view(const Image& image, std::vector<float>& pass, int channels) {
  return frame_view(image, pass.data(), channels);
}

namespace {

size_t float_count(int width, int height, const std::vector<std::string>& channel_names) {
  if (width <= 0 || height <= 0) return 0;  // refused by the codec, which says why
  return static_cast<size_t>(width) * static_cast<size_t>(height) * channel_names.size();
}

}  // namespace

void write_exr(const std::string& path, int width, int height,
               const std::vector<std::string>& channel_names, const std::vector<float>& pixels) {
  std::string error;
  if (!codec().write_exr(path, width, height, channel_names, pixels.data(), pixels.size(), error)) {
    throw Error(error);
  }
}

void write_exr_pixels(const std::string& path, int width, int height,
                      const std::vector<std::string>& channel_names, const float* pixels) {
  std::string error;
  if (!codec().write_exr(path, width, height, channel_names, pixels,
                         float_count(width, height, channel_names), error)) {
    throw Error(error);
  }
}

void write_preview(const std::string& path, int width, int height,
                   const std::vector<std::string>& channel_names,
                   const std::vector<float>& pixels) {
  std::string error;
  if (!codec().write_preview(path, width, height, channel_names, pixels.data(), pixels.size(),
                             error)) {
    throw Error(error);
  }
}

void write_preview_pixels(const std::string& path, int width, int height,
                          const std::vector<std::string>& channel_names, const float* pixels) {
  std::string error;
  if (!codec().write_preview(path, width, height, channel_names, pixels,
                             float_count(width, height, channel_names), error)) {
    throw Error(error);
  }
}

bool is_preview_path(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".png" || extension == ".jpg" || extension == ".jpeg" ||
         extension == ".tif" || extension == ".tiff";
}

}  // namespace ssao_tools
