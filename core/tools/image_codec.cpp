// SPDX-License-Identifier: MIT
// Image files through OpenImageIO, built as a module (libssao_image_codec.so) that ssao_tools loads
// on first use (image_io.cpp): OpenImageIO brings about 260 shared libraries, whose loading
// costs 0.2 s at start-up. Loaded later, that time overlaps other work (povray-ssao starts
// POV-Ray first). Errors cross the module boundary as messages, not exceptions.
#include "tools/image_codec.h"

#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <system_error>

namespace fs = std::filesystem;

namespace ssao_tools {
namespace {

std::string quoted(const std::string& path) { return "'" + path + "'"; }

// OIIO's messages may end with a newline or be empty.
std::string oiio_detail(std::string message) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  return message.empty() ? std::string("no details from OpenImageIO") : "OpenImageIO: " + message;
}

void require_readable_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw Error("cannot read " + quoted(path) + ": no such file");
  if (fs::is_directory(status)) throw Error("cannot read " + quoted(path) + ": it is a directory");
  if (::access(path.c_str(), R_OK) != 0) {
    throw Error("cannot read " + quoted(path) + ": " + std::strerror(errno));
  }
}

size_t checked_float_count(int width, int height, int channels, const std::string& path) {
  if (width < 0 || height < 0 || channels <= 0) {
    throw Error("cannot read " + quoted(path) + ": invalid image size " + std::to_string(width) +
                " x " + std::to_string(height) + " x " + std::to_string(channels) + " channels");
  }
  const size_t limit = std::numeric_limits<size_t>::max() / sizeof(float);
  size_t count = static_cast<size_t>(width);
  for (const int factor : {height, channels}) {
    if (factor != 0 && count > limit / static_cast<size_t>(factor)) {
      throw Error("cannot read " + quoted(path) + ": image too large");
    }
    count *= static_cast<size_t>(factor);
  }
  return count;
}

// A temporary file next to the final one, removed on destruction unless committed.
class TemporaryFile {
 public:
  explicit TemporaryFile(const std::string& final_path) {
    const fs::path final_fs(final_path);
    fs::path folder = final_fs.parent_path();
    if (folder.empty()) folder = ".";
    std::string pattern = (folder / ("." + final_fs.filename().string() + ".XXXXXX.tmp")).string();
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    fd_ = ::mkstemps(buffer.data(), 4);
    if (fd_ < 0) {
      throw Error("cannot write " + quoted(final_path) + ": cannot create a file in folder " +
                  quoted(folder.string()) + ": " + std::strerror(errno));
    }
    path_ = buffer.data();
    // mkstemps creates the file with mode 0600; give it the permissions of a normal new file.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    (void)::fchmod(fd_, static_cast<mode_t>(0666 & ~mask));
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(path_.c_str());
  }

  const std::string& path() const { return path_; }

  // Flushes the (already closed by its writer) file to disk and renames it to `final_path`.
  void commit(const std::string& final_path) {
    if (::fsync(fd_) != 0) {
      throw Error("cannot write " + quoted(final_path) + ": " + std::strerror(errno));
    }
    ::close(fd_);
    fd_ = -1;
    if (std::rename(path_.c_str(), final_path.c_str()) != 0) {
      throw Error("cannot write " + quoted(final_path) + ": " + std::strerror(errno));
    }
    committed_ = true;
  }

 private:
  std::string path_;
  int fd_ = -1;
  bool committed_ = false;
};

// OpenEXR 3.1 (Debian 12) allocates every header attribute at the size the file claims before
// reading it: a damaged or hostile 300-byte file claiming a 2 GB string costs 2 GB and seconds
// before "unexpected end of file" (found by tests/fuzz/fuzz_exr). The header is walked here first
// and an attribute larger than what is left of the file refused; anything else is left to
// OpenEXR, so a file this walk does not understand still gets OpenEXR's own verdict.
// Layout: magic, version (flag 0x1000: multi-part), then per header the attributes
// (name\0 type\0 int32 size, value) ended by an empty name; multi-part files end the list of
// headers with an empty header.
void check_exr_header_sizes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  unsigned char start[8];
  if (!file.read(reinterpret_cast<char*>(start), sizeof start)) return;
  if (start[0] != 0x76 || start[1] != 0x2f || start[2] != 0x31 || start[3] != 0x01) return;
  std::error_code ec;
  const auto file_size = fs::file_size(path, ec);
  if (ec) return;
  const bool multipart = (start[5] & 0x10) != 0;
  // A name or type: up to 255 characters and a NUL; false at the end of the file.
  auto read_name = [&](std::string& out) {
    out.clear();
    for (int c = file.get(); c != EOF; c = file.get()) {
      if (c == 0) return true;
      if (out.size() >= 255) return false;
      out += static_cast<char>(c);
    }
    return false;
  };
  std::string name, type;
  while (true) {  // headers
    for (int attribute = 0;; ++attribute) {
      if (!read_name(name)) return;
      if (name.empty()) {
        // The end of a header; a multi-part file's list of headers ends with an empty one.
        if (!multipart || attribute == 0) return;
        break;
      }
      unsigned char size_bytes[4];
      if (!read_name(type) || !file.read(reinterpret_cast<char*>(size_bytes), 4)) return;
      const int32_t size =
          static_cast<int32_t>(uint32_t(size_bytes[0]) | uint32_t(size_bytes[1]) << 8 |
                               uint32_t(size_bytes[2]) << 16 | uint32_t(size_bytes[3]) << 24);
      const std::streamoff position = file.tellg();
      if (position < 0) return;
      const auto left = file_size - static_cast<std::uintmax_t>(position);
      if (size < 0 || static_cast<std::uintmax_t>(size) > left) {
        throw Error("cannot read " + quoted(path) + ": its header is damaged (the attribute '" +
                    name + "' claims " + std::to_string(size) + " bytes, the file has " +
                    std::to_string(left) + " left)");
      }
      file.seekg(size, std::ios::cur);
    }
  }
}

// Opens `path` and checks its first part: deep and volume images are refused, and so is a data
// window that leaves part of the display window out. Fills everything of `image` but its pixels
// from the first part.
std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path, Image& image) {
  require_readable_file(path);
  check_exr_header_sizes(path);
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    throw Error("cannot read " + quoted(path) + ": not an image file OpenImageIO can read, or " +
                "its header is damaged (" + oiio_detail(OIIO::geterror()) + ")");
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.deep) throw Error("cannot read " + quoted(path) + ": deep images are not supported");
  if (spec.depth > 1)
    throw Error("cannot read " + quoted(path) + ": volume images are not supported");
  // Overscan (a data window larger than the display window) is read whole; a data window that
  // leaves part of the display window out has no pixels for it.
  if (spec.x > spec.full_x || spec.y > spec.full_y ||
      int64_t(spec.x) + spec.width < int64_t(spec.full_x) + spec.full_width ||
      int64_t(spec.y) + spec.height < int64_t(spec.full_y) + spec.full_height) {
    throw Error("cannot read " + quoted(path) + ": its data window (" + std::to_string(spec.width) +
                " x " + std::to_string(spec.height) + " at " + std::to_string(spec.x) + ", " +
                std::to_string(spec.y) + ") does not cover its display window (" +
                std::to_string(spec.full_width) + " x " + std::to_string(spec.full_height) +
                " at " + std::to_string(spec.full_x) + ", " + std::to_string(spec.full_y) +
                "); pad it to the full frame first");
  }
  image.width = spec.width;
  image.height = spec.height;
  image.frame_x = spec.full_x - spec.x;
  image.frame_y = spec.full_y - spec.y;
  image.frame_width = spec.full_width;
  image.frame_height = spec.full_height;
  image.color_space = spec.get_string_attribute("oiio:ColorSpace");
  image.channel_names.clear();
  for (int c = 0; c < spec.nchannels; ++c) image.channel_names.push_back(spec.channel_name(c));
  return input;
}

bool is_exr(OIIO::ImageInput& input) { return std::string(input.format_name()) == "openexr"; }

// A multi-part EXR (Blender 5.x writes a multilayer file as one part per layer) reads as one
// image with the channels of every part, in file order. Parts of another size are refused.
void check_part(const OIIO::ImageSpec& spec, const OIIO::ImageSpec& first, int part,
                const std::string& path) {
  if (spec.width != first.width || spec.height != first.height || spec.x != first.x ||
      spec.y != first.y || spec.deep || spec.depth > 1) {
    throw Error("cannot read " + quoted(path) + ": its part " + std::to_string(part) + " (" +
                std::string(spec.get_string_attribute("name")) + ") is not the size of the first");
  }
}

// Channels [begin, end) of a part (OpenImageIO's channel order), consecutive in the caller's
// memory: channel begin + k of pixel (x, y) at data[y * row_stride + x * pixel_stride + k].
struct Run {
  int part;
  int begin, end;
  float* data;
  std::ptrdiff_t pixel_stride, row_stride;  // floats
};

// Scanlines in one block of an OpenEXR file with this compression.
int exr_block_rows(const std::string& compression) {
  if (compression == "none" || compression == "rle" || compression == "zips") return 1;
  if (compression == "piz" || compression == "b44" || compression == "b44a" ||
      compression == "dwaa") {
    return 32;
  }
  if (compression == "dwab") return 256;
  return 16;  // zip, pxr24
}

[[noreturn]] void throw_corrupt(OIIO::ImageInput& input, const std::string& path) {
  throw Error("cannot read " + quoted(path) + ": the file is truncated or corrupt (" +
              oiio_detail(input.geterror()) + ")");
}

// Reads the runs of one part. A single run is one read of the part. Several runs of an OpenEXR
// part in scanlines are read band by band, every run of a band before the next band: OpenEXR
// keeps the last 2 x its threads (at least 1) blocks of scanlines it decompressed, so a band of
// as many blocks as it has threads is decompressed once, for its first run, however many follow.
// Other files (tiled, other formats) with several runs: the channels the runs span are read in
// one go into a temporary and copied out.
void read_part_runs(OIIO::ImageInput& input, const OIIO::ImageSpec& spec, int subimage,
                    const std::vector<Run>& runs, const std::string& path) {
  const OIIO::TypeDesc f = OIIO::TypeDesc::FLOAT;
  const auto bytes = [](std::ptrdiff_t floats) {
    return static_cast<OIIO::stride_t>(floats) * static_cast<OIIO::stride_t>(sizeof(float));
  };
  if (runs.size() == 1) {
    const Run& r = runs.front();
    if (!input.read_image(subimage, 0, r.begin, r.end, f, r.data, bytes(r.pixel_stride),
                          bytes(r.row_stride))) {
      throw_corrupt(input, path);
    }
    return;
  }
  if (is_exr(input) && spec.tile_width == 0) {
    int threads = 0;
    OIIO::getattribute("exr_threads", threads);
    const int band =
        exr_block_rows(spec.get_string_attribute("compression")) * std::max(1, threads);
    for (int y = 0; y < spec.height; y += band) {
      const int rows = std::min(band, spec.height - y);
      for (const Run& r : runs) {
        if (!input.read_scanlines(subimage, 0, spec.y + y, spec.y + y + rows, 0, r.begin, r.end, f,
                                  r.data + std::ptrdiff_t(y) * r.row_stride, bytes(r.pixel_stride),
                                  bytes(r.row_stride))) {
          throw_corrupt(input, path);
        }
      }
    }
    return;
  }
  int begin = runs.front().begin, end = runs.front().end;
  for (const Run& r : runs) {
    begin = std::min(begin, r.begin);
    end = std::max(end, r.end);
  }
  const int span = end - begin;
  std::vector<float> pixels(checked_float_count(spec.width, spec.height, span, path));
  if (!input.read_image(subimage, 0, begin, end, f, pixels.data())) throw_corrupt(input, path);
  for (const Run& r : runs) {
    for (int y = 0; y < spec.height; ++y) {
      for (int x = 0; x < spec.width; ++x) {
        const float* in = &pixels[(size_t(y) * size_t(spec.width) + size_t(x)) * size_t(span) +
                                  size_t(r.begin - begin)];
        std::copy_n(in, r.end - r.begin,
                    r.data + std::ptrdiff_t(y) * r.row_stride + std::ptrdiff_t(x) * r.pixel_stride);
      }
    }
  }
}

Image read_channels(const std::string& path, const ChannelChooser& choose) {
  Image image;
  auto input = open_image(path, image);
  struct Part {
    int subimage, first;  // first: its first channel's index in image.channel_names
    OIIO::ImageSpec spec;
  };
  std::vector<Part> parts = {{0, 0, input->spec()}};
  if (is_exr(*input)) {
    for (int part = 1; input->seek_subimage(part, 0); ++part) {
      const OIIO::ImageSpec spec = input->spec();
      check_part(spec, parts.front().spec, part, path);
      parts.push_back({part, image.channels(), spec});
      for (int c = 0; c < spec.nchannels; ++c) image.channel_names.push_back(spec.channel_name(c));
    }
  }

  // Consecutive targets that continue each other (the next channel of the same part, the next
  // float of the same pixel) make one run.
  std::vector<Run> runs;
  for (const ChannelTarget& t : choose(image)) {
    if (t.channel < 0 || t.channel >= image.channels() || t.data == nullptr) {
      throw Error("cannot read " + quoted(path) + ": internal error: no channel " +
                  std::to_string(t.channel) + " or no memory for it");
    }
    size_t p = parts.size() - 1;
    while (parts[p].first > t.channel) --p;
    const int local = t.channel - parts[p].first;
    if (!runs.empty()) {
      Run& r = runs.back();
      if (r.part == int(p) && r.end == local && r.data + (r.end - r.begin) == t.data &&
          r.pixel_stride == t.pixel_stride && r.row_stride == t.row_stride) {
        ++r.end;
        continue;
      }
    }
    runs.push_back({int(p), local, local + 1, t.data, t.pixel_stride, t.row_stride});
  }
  for (const Part& part : parts) {
    std::vector<Run> mine;
    for (const Run& r : runs) {
      if (r.part == part.subimage) mine.push_back(r);
    }
    if (!mine.empty()) read_part_runs(*input, part.spec, part.subimage, mine, path);
  }
  input->close();
  return image;
}

// Every channel, interleaved: read_channels with one target per channel (a multi-part file's
// parts are read straight into their place).
Image read(const std::string& path) {
  std::vector<float> pixels;
  Image image = read_channels(path, [&](const Image& header) {
    const int channels = header.channels();
    const size_t count = checked_float_count(header.width, header.height, channels, path);
    try {
      pixels.resize(count);
    } catch (const std::bad_alloc&) {
      throw Error("cannot read " + quoted(path) + ": out of memory for " +
                  std::to_string(header.width) + " x " + std::to_string(header.height) + " x " +
                  std::to_string(channels) + " floats");
    }
    std::vector<ChannelTarget> targets;
    for (int c = 0; c < channels; ++c) {
      targets.push_back({c, pixels.data() + c, channels, std::ptrdiff_t(channels) * header.width});
    }
    return targets;
  });
  image.pixels = std::move(pixels);
  return image;
}

void check_image_buffer(const std::string& path, int width, int height, int channels,
                        size_t float_count) {
  if (width <= 0 || height <= 0 || channels <= 0) {
    throw Error("cannot write " + quoted(path) + ": empty image (" + std::to_string(width) + " x " +
                std::to_string(height) + " x " + std::to_string(channels) + " channels)");
  }
  if (float_count != checked_float_count(width, height, channels, path)) {
    throw Error("cannot write " + quoted(path) + ": internal error: pixel buffer has " +
                std::to_string(float_count) + " floats for " + std::to_string(width) + " x " +
                std::to_string(height) + " x " + std::to_string(channels));
  }
  if (fs::is_directory(path)) throw Error("cannot write " + quoted(path) + ": it is a directory");
}

// Writes through a temporary file in the same folder, renamed into place once complete.
void write_atomically(const std::string& path, const char* format, const OIIO::ImageSpec& spec,
                      OIIO::TypeDesc data_type, const void* data) {
  TemporaryFile temporary(path);
  auto output = OIIO::ImageOutput::create(format);
  if (!output) {
    throw Error("cannot write " + quoted(path) + ": no " + format + " writer (" +
                oiio_detail(OIIO::geterror()) + ")");
  }
  bool ok = output->open(temporary.path(), spec) && output->write_image(data_type, data);
  ok = output->close() && ok;
  if (!ok) {
    throw Error("cannot write " + quoted(path) + ": " + oiio_detail(output->geterror()));
  }
  temporary.commit(path);
}

// The sRGB transfer function (IEC 61966-2-1) applied to linear scene values clamped to [0, 1].
float srgb_encode(float linear) {
  const float v = std::clamp(std::isfinite(linear) ? linear : 0.0f, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

void write_exr_file(const std::string& path, int width, int height,
                    const std::vector<std::string>& channel_names, const float* pixels,
                    size_t count) {
  const int channels = static_cast<int>(channel_names.size());
  check_image_buffer(path, width, height, channels, count);
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames = channel_names;
  spec.alpha_channel = -1;
  for (int c = 0; c < channels; ++c) {
    if (channel_names[static_cast<size_t>(c)] == "A") spec.alpha_channel = c;
  }
  spec.attribute("compression", "zip");
  write_atomically(path, "openexr", spec, OIIO::TypeDesc::FLOAT, pixels);
}

void write_preview_file(const std::string& path, int width, int height,
                        const std::vector<std::string>& channel_names, const float* pixels,
                        size_t float_count) {
  const int channels = static_cast<int>(channel_names.size());
  check_image_buffer(path, width, height, channels, float_count);
  auto index_of = [&](const char* name) {
    const auto it = std::find(channel_names.begin(), channel_names.end(), name);
    return it == channel_names.end() ? -1 : static_cast<int>(it - channel_names.begin());
  };
  // Colour if there is R, G, B (and A); otherwise the AO (or first) channel as grey.
  std::vector<int> picked;
  for (const char* name : {"R", "G", "B"}) {
    if (index_of(name) >= 0) picked.push_back(index_of(name));
  }
  if (picked.size() != 3) picked = {std::max(0, index_of("AO"))};
  const int alpha = picked.size() == 3 ? index_of("A") : -1;
  const int out_channels = static_cast<int>(picked.size()) + (alpha >= 0 ? 1 : 0);

  const std::string extension = fs::path(path).extension().string();
  std::string format = extension.empty() ? "" : extension.substr(1);
  std::transform(format.begin(), format.end(), format.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (format == "jpg") format = "jpeg";
  if (format == "tif") format = "tiff";

  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<unsigned char> bytes(count * static_cast<size_t>(out_channels));
  for (size_t p = 0; p < count; ++p) {
    const float* in = pixels + p * static_cast<size_t>(channels);
    unsigned char* out = bytes.data() + p * static_cast<size_t>(out_channels);
    for (size_t k = 0; k < picked.size(); ++k) {
      out[k] = static_cast<unsigned char>(std::lround(255.0f * srgb_encode(in[picked[k]])));
    }
    if (alpha >= 0) {
      const float a = std::isfinite(in[alpha]) ? std::clamp(in[alpha], 0.0f, 1.0f) : 1.0f;
      out[picked.size()] = static_cast<unsigned char>(std::lround(255.0f * a));
    }
  }
  OIIO::ImageSpec spec(width, height, out_channels, OIIO::TypeDesc::UINT8);
  spec.alpha_channel = alpha >= 0 ? out_channels - 1 : -1;
  spec.attribute("oiio:ColorSpace", "sRGB");
  write_atomically(path, format.c_str(), spec, OIIO::TypeDesc::UINT8, bytes.data());
}

// Runs `work`, turning any exception into a message.
template <typename Work>
bool guarded(std::string& error, Work&& work) {
  try {
    work();
    return true;
  } catch (const std::bad_alloc&) {
    error = "out of memory";
  } catch (const std::exception& e) {
    error = e.what();
  }
  return false;
}

const ImageCodec kCodec = {
    [](const std::string& path, Image& image, std::string& error) {
      return guarded(error, [&] { image = read(path); });
    },
    [](const std::string& path, Image& header, const ChannelChooser& choose, std::string& error) {
      return guarded(error, [&] { header = read_channels(path, choose); });
    },
    [](const std::string& path, int width, int height, const std::vector<std::string>& names,
       const float* pixels, size_t count, std::string& error) {
      return guarded(error, [&] { write_exr_file(path, width, height, names, pixels, count); });
    },
    [](const std::string& path, int width, int height, const std::vector<std::string>& names,
       const float* pixels, size_t count, std::string& error) {
      return guarded(error, [&] { write_preview_file(path, width, height, names, pixels, count); });
    },
};

}  // namespace
}  // namespace ssao_tools

extern "C" __attribute__((visibility("default"))) const ssao_tools::ImageCodec*
ssao_tools_image_codec() {
  return &ssao_tools::kCodec;
}
