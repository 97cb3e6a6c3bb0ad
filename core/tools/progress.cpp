// SPDX-License-Identifier: MIT
#include "tools/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ssao_tools {

ProgressReporter::ProgressReporter(bool quiet)
    : quiet_(quiet), terminal_(::isatty(STDERR_FILENO) == 1) {}

ProgressReporter::~ProgressReporter() { finish(); }

int ProgressReporter::callback(void* user, double fraction) {
  static_cast<ProgressReporter*>(user)->report(fraction);
  return interrupted() ? 0 : 1;
}

void ProgressReporter::report(double fraction) {
  if (quiet_ || !std::isfinite(fraction)) return;
  const int percent = static_cast<int>(std::floor(std::clamp(fraction, 0.0, 1.0) * 100.0));
  if (terminal_) {
    if (percent != last_percent_) {
      std::fprintf(stderr, "\rssao: %3d%%", percent);
      std::fflush(stderr);
      line_open_ = true;
    }
    last_percent_ = percent;
    return;
  }
  // Not a terminal (a log file, a pipe): the highest quarter reached since the last line.
  const int quarter = percent / 25 * 25;
  if (quarter > 0 && quarter > last_percent_) {
    std::fprintf(stderr, "ssao: %d%%\n", quarter);
    last_percent_ = quarter;
  }
}

void ProgressReporter::finish() {
  if (line_open_) {
    std::fputc('\n', stderr);
    line_open_ = false;
  }
}

}  // namespace ssao_tools
