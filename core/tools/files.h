// SPDX-License-Identifier: MIT
// Output paths, checked before any work: what every tool refuses rather than fail at the end.
#pragma once

#include <string>

namespace ssao_tools {

// True when a and b name the same file (or, if either does not exist yet, the same path).
bool same_file(const std::string& a, const std::string& b);

// Throws Error when `path` cannot be created: its folder is missing or not writable, or the
// path is a directory.
void check_output_folder(const std::string& path);

}  // namespace ssao_tools
