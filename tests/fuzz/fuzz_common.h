// SPDX-License-Identifier: MIT
// Shared by the fuzz targets: check(), and for those that feed files, a private scratch folder
// per process (libFuzzer's -jobs and -fork run several), removed at exit, and writing the input
// into it.
#pragma once

#include <cerrno>  // program_invocation_short_name (glibc)
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fuzz {

// A property the target asserts: when it does not hold, says which (after the target's name)
// and aborts, which libFuzzer reports as a crash and keeps the input of.
inline void check(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "%s: %s\n", program_invocation_short_name, what);
  std::abort();
}

inline const std::filesystem::path& scratch_folder() {
  // Never destroyed: the exit handler that removes the folder runs after static destructors.
  static const std::filesystem::path* const folder = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "ssao-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      std::perror("mkdtemp");
      std::abort();
    }
    return new std::filesystem::path(pattern);
  }();
  static const int registered = std::atexit([] {
    std::error_code ec;
    std::filesystem::remove_all(*folder, ec);
  });
  (void)registered;
  return *folder;
}

// Writes the input to `name` in the scratch folder and returns its path.
inline std::string write_input(const char* name, const uint8_t* data, size_t size) {
  const std::string path = (scratch_folder() / name).string();
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  file.close();
  if (!file) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

}  // namespace fuzz
