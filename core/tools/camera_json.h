// SPDX-License-Identifier: MIT
// The camera file beside a rendered image (docs/conventions.md, "Camera file"). Its format has
// one reader, in the library (ssao_job_set_camera_json); the tools only read the file's text.
#pragma once

#include <string>
#include <vector>

#include "ssao/ssao.hpp"
#include "tools/error.h"

namespace ssao_tools {

// The text of the camera file at `path`. Throws Error, naming the file, when it does not exist,
// is a folder or cannot be read.
std::string read_camera_text(const std::string& path);

// Sets the camera of `job` from the file's text (the library checks every rule of the format
// and names the file and the key); returns the keys the format does not know, which the
// caller warns about. Throws Error.
std::vector<std::string> apply_camera_text(ssao::api::Job& job, const std::string& text,
                                           const std::string& path);

// True if `name` is a parameter of the library's "camera" group (ssao_param_group).
bool is_camera_param(const std::string& name);

}  // namespace ssao_tools
