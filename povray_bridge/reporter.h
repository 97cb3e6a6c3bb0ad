// SPDX-License-Identifier: MIT
// What povray-ssao tells the user while it works: progress on stdout, warnings on stderr (both
// silenced by --quiet), and the small formatting helpers its messages share.
#pragma once

#include <chrono>
#include <string>

namespace povray_ssao {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

// 'path', as every message quotes file names.
std::string in_quotes(const std::string& path);

// Progress lines are "povray-ssao: ..."; a step can be begun ("... ") and ended later with its
// result on the same line. A step left open by an exception ends with "failed".
class Reporter {
 public:
  explicit Reporter(bool quiet) : quiet_(quiet) {}
  ~Reporter();
  Reporter(const Reporter&) = delete;
  Reporter& operator=(const Reporter&) = delete;

  void progress(const char* format, ...) const __attribute__((format(printf, 2, 3)));
  // Starts a progress line that end() completes.
  void begin(const char* format, ...) const __attribute__((format(printf, 2, 3)));
  void end(const char* format, ...) const __attribute__((format(printf, 2, 3)));
  void warning(const std::string& message) const;

 private:
  void close_open_line() const;
  bool quiet_;
  mutable bool open_ = false;  // a begin() line waits for its end()
};

}  // namespace povray_ssao
