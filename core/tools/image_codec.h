// SPDX-License-Identifier: MIT
// The entry point of libssao_image_codec.so, the OpenImageIO part of image_io (see
// image_codec.cpp): read and write functions that report failure as a message.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "tools/image_io.h"

namespace ssao_tools {

// `pixels` holds width * height * channel_names.size() floats (`count`, checked).
struct ImageCodec {
  bool (*read)(const std::string& path, Image& image, std::string& error);
  // read_channels (image_io.h) without the overscan check, which the caller's `choose` makes.
  bool (*read_channels)(const std::string& path, Image& header, const ChannelChooser& choose,
                        std::string& error);
  bool (*write_exr)(const std::string& path, int width, int height,
                    const std::vector<std::string>& channel_names, const float* pixels,
                    size_t count, std::string& error);
  bool (*write_preview)(const std::string& path, int width, int height,
                        const std::vector<std::string>& channel_names, const float* pixels,
                        size_t count, std::string& error);
};

}  // namespace ssao_tools

// Exported by the module (looked up with dlsym).
extern "C" const ssao_tools::ImageCodec* ssao_tools_image_codec();
