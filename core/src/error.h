// SPDX-License-Identifier: MIT
// The error core code throws: the public C++ wrapper's (a status and a message), which api.cpp
// turns into the C API's status and ssao_last_error(). It never crosses the C API.
#pragma once

#include <string>

#include "ssao/ssao.hpp"

namespace ssao {

using Error = api::Error;

[[noreturn]] inline void throw_invalid_argument(const std::string& message) {
  throw Error(SSAO_ERROR_INVALID_ARGUMENT, message);
}

[[noreturn]] inline void throw_invalid_operation(const std::string& message) {
  throw Error(SSAO_ERROR_INVALID_OPERATION, message);
}

}  // namespace ssao
