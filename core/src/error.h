// SPDX-License-Identifier: MIT
// Internal error type: core code throws it, api.cpp turns it into a status and a message.
#pragma once

#include <stdexcept>
#include <string>

#include "ssao/ssao.h"

namespace ssao {

class Error : public std::runtime_error {
 public:
  Error(ssao_status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  ssao_status status() const { return status_; }

 private:
  ssao_status status_;
};

[[noreturn]] inline void throw_invalid_argument(const std::string& message) {
  throw Error(SSAO_ERROR_INVALID_ARGUMENT, message);
}

[[noreturn]] inline void throw_invalid_operation(const std::string& message) {
  throw Error(SSAO_ERROR_INVALID_OPERATION, message);
}

}  // namespace ssao
