// SPDX-License-Identifier: MIT
// Progress of a library run on stderr, and Ctrl-C as cancellation (tools/interrupt.h).
#pragma once

#include "ssao/ssao.h"
#include "tools/interrupt.h"

namespace ssao_tools {

// The percentage of a library run on stderr (ssao_job_set_progress). On a terminal: "ssao: 42%"
// rewritten in place. Otherwise: one line as each of 25, 50, 75 and 100% is reached. Nothing when
// quiet. SIGINT and SIGTERM, while an instance exists, make the callback cancel the run
// (SSAO_ERROR_CANCELLED).
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
  static bool interrupted() { return InterruptGuard::interrupted(); }

 private:
  void report(double fraction);

  InterruptGuard interrupt_guard_;
  bool quiet_;
  bool terminal_;
  int last_percent_ = -1;
  bool line_open_ = false;
};

}  // namespace ssao_tools
