// SPDX-License-Identifier: MIT
// The entry point of libssao_image_codec.so, the OpenImageIO part of image_io (see
// image_codec.cpp): read and write functions that report failure as a message.
#pragma once

#include <string>
#include <vector>

#include "tools/image_io.h"

namespace ssao_tools {

struct ImageCodec {
  bool (*read)(const std::string& path, Image& image, std::string& error);
  bool (*write_exr)(const std::string& path, int width, int height,
                    const std::vector<std::string>& channel_names, const std::vector<float>& pixels,
                    std::string& error);
  bool (*write_preview)(const std::string& path, int width, int height,
                        const std::vector<std::string>& channel_names,
                        const std::vector<float>& pixels, std::string& error);
};

}  // namespace ssao_tools

// Exported by the module (looked up with dlsym).
extern "C" const ssao_tools::ImageCodec* ssao_tools_image_codec();
