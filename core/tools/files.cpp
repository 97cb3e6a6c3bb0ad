// SPDX-License-Identifier: MIT
#include "tools/files.h"

#include <unistd.h>

#include <filesystem>

#include "tools/error.h"

namespace ssao_tools {

namespace fs = std::filesystem;

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

void check_output_folder(const std::string& path) {
  const auto quoted = [](const std::string& text) { return "'" + text + "'"; };
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw Error("cannot write " + quoted(path) + ": no folder " + quoted(folder.string()));
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw Error("cannot write " + quoted(path) + ": folder " + quoted(folder.string()) +
                " is not writable");
  }
  if (fs::is_directory(path, ec)) {
    throw Error("cannot write " + quoted(path) + ": it is a directory");
  }
}

}  // namespace ssao_tools
