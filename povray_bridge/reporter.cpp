// SPDX-License-Identifier: MIT
#include "reporter.h"

#include <cstdarg>
#include <cstdio>

namespace povray_ssao {

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string in_quotes(const std::string& path) { return "'" + path + "'"; }

Reporter::~Reporter() {
  if (open_) std::fputs("failed\n", stdout);  // a step ended by an exception
  std::fflush(stdout);
}

void Reporter::close_open_line() const {
  if (open_) std::fputs("failed\n", stdout);
  open_ = false;
}

void Reporter::progress(const char* format, ...) const {
  if (quiet_) return;
  close_open_line();
  std::va_list args;
  va_start(args, format);
  std::fputs("povray-ssao: ", stdout);
  std::vfprintf(stdout, format, args);
  std::fputc('\n', stdout);
  std::fflush(stdout);
  va_end(args);
}

void Reporter::begin(const char* format, ...) const {
  if (quiet_) return;
  std::va_list args;
  va_start(args, format);
  std::fputs("povray-ssao: ", stdout);
  std::vfprintf(stdout, format, args);
  std::fflush(stdout);
  va_end(args);
  open_ = true;
}

void Reporter::end(const char* format, ...) const {
  if (quiet_) return;
  std::va_list args;
  va_start(args, format);
  std::vfprintf(stdout, format, args);
  std::fputc('\n', stdout);
  std::fflush(stdout);
  va_end(args);
  open_ = false;
}

void Reporter::warning(const std::string& message) const {
  if (quiet_) return;
  close_open_line();
  std::fflush(stdout);
  std::fprintf(stderr, "povray-ssao: warning: %s\n", message.c_str());
}

}  // namespace povray_ssao
