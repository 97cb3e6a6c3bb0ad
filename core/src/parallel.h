// SPDX-License-Identifier: MIT
// Row-parallel loops. Each row is computed by exactly one thread with no shared accumulation, so
// results never depend on the thread count or on scheduling.
#pragma once

#include <functional>

namespace ssao {

// Reports progress for one stage of a run and remembers cancellation.
class Progress {
 public:
  using Callback = int (*)(void* user, double fraction);
  Progress(Callback callback, void* user) : callback_(callback), user_(user) {}

  // Maps the next stage's [0, 1] onto [begin, end] of the whole run.
  void set_stage(double begin, double end) { begin_ = begin, end_ = end; }
  // Called on the calling thread only. Returns false once the callback asked to stop.
  bool report(double stage_fraction);
  bool cancelled() const { return cancelled_; }

 private:
  Callback callback_;
  void* user_;
  double begin_ = 0.0, end_ = 1.0, last_ = 0.0;
  bool cancelled_ = false;
};

// Runs row_fn(y) for y in [0, height) on `threads` threads (the caller's included). Throws
// Error(SSAO_ERROR_CANCELLED) if progress is cancelled; rethrows the first exception of a row.
void parallel_rows(int height, int threads, Progress& progress,
                   const std::function<void(int y)>& row_fn);

// Number of threads to use for a "threads" parameter value (0 = all cores).
int resolve_thread_count(int requested);

}  // namespace ssao
