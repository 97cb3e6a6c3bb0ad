// SPDX-License-Identifier: MIT
#include "tiles.h"

// The tiles run on oneTBB (SSAO_THREADS_TBB, the Linux build: the pool Blender and OpenImageIO
// share) or on std::thread (where no oneTBB is built for the target: the Windows DLL). Either
// way each tile is computed by one thread into its own pixels: the same bits.
#if SSAO_THREADS_TBB
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#else
#include <exception>
#include <mutex>
#include <system_error>
#include <vector>
#endif

#include <algorithm>
#include <atomic>
#include <thread>

#include "error.h"

// ThreadSanitizer (build-tsan) does not see oneTBB's synchronisation: libtbb is not instrumented,
// so a task handed to a worker through its queues looks unordered with the thread that created
// it. TilePool::run states the two edges parallel_for guarantees: what the caller did before
// happens before every tile, and every tile happens before the caller goes on. Tiles get no
// edge between each other, so two tiles touching the same memory are still reported.
#if defined(__SANITIZE_THREAD__)
#define SSAO_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SSAO_TSAN 1
#endif
#endif
#ifdef SSAO_TSAN
#include <sanitizer/tsan_interface.h>
#define SSAO_TSAN_RELEASE(address) __tsan_release(address)
#define SSAO_TSAN_ACQUIRE(address) __tsan_acquire(address)
#else
#define SSAO_TSAN_RELEASE(address) static_cast<void>(address)
#define SSAO_TSAN_ACQUIRE(address) static_cast<void>(address)
#endif

namespace ssao {

bool Progress::report(double stage_fraction) {
  if (cancelled_) return false;
  const double fraction = std::clamp(begin_ + (end_ - begin_) * stage_fraction, 0.0, 1.0);
  if (fraction < last_) return true;  // keep the reported values non-decreasing
  last_ = fraction;
  if (callback_ != nullptr && callback_(user_, fraction) == 0) cancelled_ = true;
  return !cancelled_;
}

void Progress::throw_if_cancelled() const {
  if (cancelled_) throw Error(SSAO_ERROR_CANCELLED, "cancelled by the progress callback");
}

int resolve_thread_count(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

#if SSAO_THREADS_TBB
struct TilePool::Arena {
  explicit Arena(int threads) : arena(threads) {}
  // body(i) for every i in [0, count), on the arena's threads (the caller's among them).
  void parallel(int count, const std::function<void(int)>& body) {
    // Only ThreadSanitizer reads these (see SSAO_TSAN_RELEASE above).
    char before_tiles = 0, after_tiles = 0;
    SSAO_TSAN_RELEASE(&before_tiles);
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<int>(0, count, 1),
          [&](const tbb::blocked_range<int>& r) {
            SSAO_TSAN_ACQUIRE(&before_tiles);
            for (int i = r.begin(); i != r.end(); ++i) body(i);
            SSAO_TSAN_RELEASE(&after_tiles);
          },
          tbb::simple_partitioner());
    });
    SSAO_TSAN_ACQUIRE(&after_tiles);
  }
  tbb::task_arena arena;
};
#else
struct TilePool::Arena {
  explicit Arena(int thread_count) : threads(thread_count) {}
  // body(i) for every i in [0, count), on the caller's thread and threads - 1 others started for
  // the run (a few tens of microseconds each, against milliseconds of tiles). The first
  // exception stops the handing out of indices and is rethrown here, as tbb::parallel_for does.
  void parallel(int count, const std::function<void(int)>& body) {
    std::atomic<int> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
      for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
        try {
          body(i);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
          next.store(count);
        }
      }
    };
    std::vector<std::thread> others;
    const int wanted = std::min(threads, count) - 1;
    others.reserve(static_cast<size_t>(std::max(wanted, 0)));
    for (int t = 0; t < wanted; ++t) {
      try {
        others.emplace_back(work);
      } catch (const std::system_error&) {
        break;  // no more threads to be had: the ones started (and the caller) do the rest
      }
    }
    work();
    for (std::thread& other : others) other.join();
    if (error) std::rethrow_exception(error);
  }
  int threads;
};
#endif

TilePool::TilePool(int threads)
    : threads_(resolve_thread_count(threads)), arena_(std::make_unique<Arena>(threads_)) {}

TilePool::~TilePool() = default;

void TilePool::for_each_tile(int width, int height, Progress& progress,
                             const std::function<void(const Tile&)>& fn) {
  run(width, height, kTileWidth, kTileHeight, progress, fn);
}

void TilePool::for_each_row_band(int width, int height, int rows, Progress& progress,
                                 const std::function<void(const Tile&)>& fn) {
  run(width, height, std::max(1, width), std::max(1, rows), progress, fn);
}

void TilePool::for_each_column_strip(int width, int height, int columns, Progress& progress,
                                     const std::function<void(const Tile&)>& fn) {
  run(width, height, std::max(1, columns), std::max(1, height), progress, fn);
}

void TilePool::run(int width, int height, int tile_width, int tile_height, Progress& progress,
                   const std::function<void(const Tile&)>& fn) {
  if (width <= 0 || height <= 0) return;
  progress.throw_if_cancelled();
  const int columns = (width + tile_width - 1) / tile_width;
  const int rows = (height + tile_height - 1) / tile_height;
  const int count = columns * rows;
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> done{0};
  std::atomic<bool> stop{false};

  auto one_tile = [&](int index) {
    if (stop.load(std::memory_order_relaxed)) return;
    const int tx = index % columns, ty = index / columns;
    const Tile tile{tx * tile_width, ty * tile_height, std::min(width, (tx + 1) * tile_width),
                    std::min(height, (ty + 1) * tile_height)};
    fn(tile);
    const int finished = done.fetch_add(1) + 1;
    // Only the caller's thread talks to the progress callback.
    if (std::this_thread::get_id() == caller && !progress.report(double(finished) / count)) {
      stop = true;
    }
  };
  arena_->parallel(count, one_tile);
  progress.throw_if_cancelled();
  progress.report(1.0);
  progress.throw_if_cancelled();
}

}  // namespace ssao
