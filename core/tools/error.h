// SPDX-License-Identifier: MIT
// The one exception type of the front-end helpers (ssao_tools). Its message is meant for the user:
// it names the file, the channel or the key concerned and what is wrong with it.
#pragma once

#include <stdexcept>
#include <string>

namespace ssao_tools {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace ssao_tools
