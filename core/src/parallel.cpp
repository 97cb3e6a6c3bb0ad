// SPDX-License-Identifier: MIT
#include "parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "error.h"

namespace ssao {

bool Progress::report(double stage_fraction) {
  if (cancelled_) return false;
  const double fraction = std::clamp(begin_ + (end_ - begin_) * stage_fraction, 0.0, 1.0);
  if (fraction < last_) return true;  // keep the reported values non-decreasing
  last_ = fraction;
  if (callback_ != nullptr && callback_(user_, fraction) == 0) cancelled_ = true;
  return !cancelled_;
}

int resolve_thread_count(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

void parallel_rows(int height, int threads, Progress& progress,
                   const std::function<void(int y)>& row_fn) {
  if (height <= 0) return;
  threads = std::clamp(threads, 1, height);
  std::atomic<int> next_row{0};
  std::atomic<int> rows_done{0};
  std::atomic<bool> stop{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;

  auto work = [&](bool is_caller) {
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) return;
      const int y = next_row.fetch_add(1);
      if (y >= height) return;
      try {
        row_fn(y);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        stop = true;
        return;
      }
      const int done = rows_done.fetch_add(1) + 1;
      // Only the caller's thread talks to the progress callback.
      if (is_caller && !progress.report(double(done) / height)) stop = true;
    }
  };

  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) {
    try {
      workers.emplace_back(work, false);
    } catch (const std::exception&) {
      break;  // fewer threads only costs time: every row is still computed exactly once
    }
  }
  work(true);
  for (std::thread& w : workers) w.join();

  if (first_error) std::rethrow_exception(first_error);
  if (progress.cancelled()) throw Error(SSAO_ERROR_CANCELLED, "cancelled by the progress callback");
  progress.report(1.0);
  if (progress.cancelled()) throw Error(SSAO_ERROR_CANCELLED, "cancelled by the progress callback");
}

}  // namespace ssao
