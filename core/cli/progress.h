// SPDX-License-Identifier: MIT
// Progress on stderr for ssao_job_set_progress, and Ctrl-C as cancellation.
#pragma once

#include "ssao/ssao.h"

namespace ssao_cli {

// On a terminal: "ssao: 42%" rewritten in place. Otherwise: one line as each of 25, 50, 75 and
// 100% is reached. Nothing when quiet. SIGINT and SIGTERM, while an instance exists, make the
// callback cancel the run (SSAO_ERROR_CANCELLED).
class ProgressReporter {
 public:
  explicit ProgressReporter(bool quiet);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  // The callback and its user pointer (this).
  static int callback(void* user, double fraction);

  // Ends the progress line (on a terminal) before other messages are printed.
  void finish();

  // True once SIGINT or SIGTERM was received.
  static bool interrupted();

 private:
  void report(double fraction);

  bool quiet_;
  bool terminal_;
  int last_percent_ = -1;
  bool line_open_ = false;
};

}  // namespace ssao_cli
