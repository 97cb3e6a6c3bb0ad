// SPDX-License-Identifier: MIT
// Float image files through OpenImageIO: read any OIIO-readable file (EXR first of all) into
// interleaved float pixels, write OpenEXR atomically. OpenImageIO stays out of this header and
// out of the programs: it lives in the module libssao_image_codec.so, loaded on the first read
// or write (or preload_image_io()).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "tools/error.h"

namespace ssao_tools {

// A whole image in memory: pixel (x, y), y = 0 the TOP row, channel c is
// pixels[(y * width + x) * channels() + c].
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::string> channel_names;
  std::vector<float> pixels;
  // How the file encodes its values, as OpenImageIO reports it ("oiio:ColorSpace": "Linear",
  // "sRGB", "GammaCorrected2.2", ...; "" if the file does not say). read_image() returns the
  // stored values as they are (an 8-bit sRGB PNG reads as its code values / 255).
  std::string color_space;
  // The frame (OpenEXR's display window) inside the pixels (its data window): pixel (0, 0) of
  // the frame is pixel (frame_x, frame_y) here. The whole image unless the file has overscan
  // (a data window larger than the display window).
  int frame_x = 0, frame_y = 0, frame_width = 0, frame_height = 0;

  bool has_overscan() const { return frame_width != width || frame_height != height; }
  size_t frame_pixel_count() const {
    return static_cast<size_t>(frame_width) * static_cast<size_t>(frame_height);
  }
  int channels() const { return static_cast<int>(channel_names.size()); }
  size_t pixel_count() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }

  // Index of the channel called exactly `name`, or -1.
  int find_channel(const std::string& name) const;
};

enum class Overscan { refuse, read };

// std::allocator, except that a vector's resize() leaves new elements uninitialised: for buffers
// that read_channels or the library fill whole, which need not be zeroed first.
template <typename T>
struct UninitializedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using FloatBuffer = std::vector<float, UninitializedAllocator<float>>;

// Where read_channels puts one channel of the file: the value of pixel (x, y) of the data window
// (x, y from 0, y = 0 the top row) goes to data[y * row_stride + x * pixel_stride], strides in
// floats. The memory belongs to the caller.
struct ChannelTarget {
  int channel;  // index in Image::channel_names
  float* data;
  std::ptrdiff_t pixel_stride, row_stride;
};
// Given the file's header (an Image without pixels), the channels to read and where; may throw
// (the exception reaches read_channels' caller as it was thrown).
using ChannelChooser = std::function<std::vector<ChannelTarget>(const Image& header)>;

// Reads the first subimage of `path` as 32-bit float. Throws Error for a missing file, a file
// that is not an image OIIO can read, a truncated or corrupt file (OIIO's message included), a
// deep image, a data window that does not cover the display window, or, unless `overscan` is
// read, a data window larger than the display window (overscan: with Overscan::read the whole
// data window is read, and frame_* locate the display window in it).
Image read_image(const std::string& path, Overscan overscan = Overscan::refuse);

// Reads only some channels of `path`, each straight into the caller's memory: the header (with
// the checks and messages of read_image, for the same `overscan`), then `choose`, then the chosen
// channels as 32-bit float, bit for bit what read_image gives for them. Nothing else of the file
// is decoded where the format allows it: of a multi-part EXR only the parts that hold a chosen
// channel are read; of a part, only the chosen channels are converted and copied (OpenEXR
// decompresses whole blocks of scanlines: the channels of a part are read block by block, so
// that each block is decompressed once). Returns the header: channel_names of every part, in
// file order (as read_image), and no pixels. Throws Error as read_image does.
Image read_channels(const std::string& path, Overscan overscan, const ChannelChooser& choose);

// Makes `buffer` hold `channels` floats a pixel of the data window of `image` (read from `path`,
// named in the message), reusing its memory when it is large enough (a sequence's frames reuse
// the buffers of the frame before: no new pages to fault in); the values are left as they are.
// Throws Error when that many floats cannot be had.
void resize_pass_buffer(FloatBuffer& buffer, const Image& image, int channels,
                        const std::string& path);

// Converts the stored values of an image read from an sRGB- or gamma-encoded file
// (color_space "sRGB", "GammaCorrected<g>" or "Gamma<g>", e.g. an 8-bit PNG) to linear light,
// every channel except alpha ("A", "Alpha"); other images are left as they are. Returns true if
// it converted anything.
bool linearize(Image& image);

// Index of channel `name` in `image` (read from `path`, used in the message); throws Error
// listing the channels that do exist when there is none.
int require_channel(const Image& image, const std::string& name, const std::string& path);

// Copies the channels `indices` (in that order) of every pixel into a tightly packed buffer
// of width * height * indices.size() floats.
std::vector<float> extract_channels(const Image& image, const std::vector<int>& indices);
// The same for channels given by name (each required, as require_channel).
std::vector<float> extract_named_channels(const Image& image, const std::vector<std::string>& names,
                                          const std::string& path);

// The frame's window (frame_*) of a pass extracted from `image` (`channels` floats a pixel,
// tightly packed): its first pixel and byte strides, as ssao_job_set_image takes them.
struct FrameView {
  float* data;
  std::ptrdiff_t pixel_stride, row_stride;
};
FrameView frame_view(const Image& image, std::vector<float>& pass, int channels);
FrameView frame_view(const Image& image, float* pass, int channels);

// Writes `pixels` (interleaved, top row first, channel_names.size() channels) as a 32-bit float,
// ZIP-compressed OpenEXR file, whatever the extension of `path`. The data go to a temporary
// file in the same folder, which is renamed to `path` only once complete, so a failed write
// never leaves a partial file under the final name. Throws Error on failure.
void write_exr(const std::string& path, int width, int height,
               const std::vector<std::string>& channel_names, const std::vector<float>& pixels);
// The same from width * height * channel_names.size() floats at `pixels`.
void write_exr_pixels(const std::string& path, int width, int height,
                      const std::vector<std::string>& channel_names, const float* pixels);

// Writes a display-referred 8-bit preview (PNG, JPEG or TIFF by the extension of `path`): R, G,
// B (and A) if those channels exist, otherwise the AO channel (or the first) as grey; colour
// and AO values clamped to [0, 1] and sRGB-encoded, alpha kept linear. Atomic like write_exr.
void write_preview(const std::string& path, int width, int height,
                   const std::vector<std::string>& channel_names, const std::vector<float>& pixels);
void write_preview_pixels(const std::string& path, int width, int height,
                          const std::vector<std::string>& channel_names, const float* pixels);

// True for the extensions write_preview handles (.png, .jpg, .jpeg, .tif, .tiff).
bool is_preview_path(const std::string& path);

// Loads the image file module now (otherwise the first read or write does): a program that has
// other work in flight calls it to overlap the loading (about 0.2 s) with that work. Throws Error
// if the module cannot be loaded.
void preload_image_io();

// Comma-separated list of the names, for messages: "R, G, B".
std::string join_names(const std::vector<std::string>& names, const char* separator = ", ");

}  // namespace ssao_tools
