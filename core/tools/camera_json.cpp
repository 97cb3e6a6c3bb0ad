// SPDX-License-Identifier: MIT
#include "tools/camera_json.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tools/param_flags.h"

namespace ssao_tools {

std::string read_camera_text(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error("camera file '" + path + "': no such file");
  if (std::filesystem::is_directory(path, ec)) {
    throw Error("camera file '" + path + "': it is a directory");
  }
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file || !text) throw Error("camera file '" + path + "': cannot read it");
  return text.str();
}

std::vector<std::string> apply_camera_text(ssao::api::Job& job, const std::string& text,
                                           const std::string& path) {
  try {
    job.set_camera_json(text, path);
    return job.camera_unknown_keys();
  } catch (const ssao::api::Error& e) {
    throw Error(e.what());
  }
}

bool is_camera_param(const std::string& name) { return param_group_of(name) == "camera"; }

}  // namespace ssao_tools
