// SPDX-License-Identifier: MIT
// Ctrl-C (SIGINT) and SIGTERM as a request to stop, for every tool: while a guard exists the
// signals only set a flag, which long work polls (progress callbacks cancel the library's run,
// child processes are sent SIGTERM) so that nothing half-written is left behind.
#pragma once

#include <signal.h>

namespace ssao_tools {

class InterruptGuard {
 public:
  InterruptGuard();   // installs the handlers (no SA_RESTART: a blocked waitpid returns EINTR)
  ~InterruptGuard();  // puts back the handlers that were there before
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  // True once SIGINT or SIGTERM was received while a guard existed.
  static bool interrupted();
  // A progress callback for ssao_job_set_progress that only cancels on an interruption.
  static int cancel_if_interrupted(void* user, double fraction);

 private:
  // Per guard, so that nested guards (a sequence and its frames) unwind in order.
  struct sigaction previous_sigint_ {};
  struct sigaction previous_sigterm_ {};
};

}  // namespace ssao_tools
