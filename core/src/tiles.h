// SPDX-License-Identifier: MIT
// Image tiles on a persistent oneTBB arena, or on std::threads where the library is built
// without oneTBB (tiles.cpp). Every tile is computed by exactly one thread and written to its own
// pixels only, so results never depend on the thread count, the tiling or the scheduling.
// Progress is reported, and cancellation asked, on the calling thread only.
#pragma once

#include <functional>
#include <memory>

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
  // Throws Error(SSAO_ERROR_CANCELLED) once the callback asked to stop.
  void throw_if_cancelled() const;

 private:
  Callback callback_;
  void* user_;
  double begin_ = 0.0, end_ = 1.0, last_ = 0.0;
  bool cancelled_ = false;
};

// Pixels [x0, x1) x [y0, y1).
struct Tile {
  int x0, y0, x1, y1;
};

constexpr int kTileWidth = 128, kTileHeight = 32;

class TilePool {
 public:
  // threads = 0 uses every core.
  explicit TilePool(int threads);
  ~TilePool();
  TilePool(const TilePool&) = delete;
  TilePool& operator=(const TilePool&) = delete;

  int threads() const { return threads_; }

  // Runs fn on every kTileWidth x kTileHeight tile of a width x height image. Throws
  // Error(SSAO_ERROR_CANCELLED) if progress is cancelled; rethrows the first exception of a tile.
  void for_each_tile(int width, int height, Progress& progress,
                     const std::function<void(const Tile&)>& fn);
  // Same over whole rows (tiles of full width and `rows` height), for row-wise filters.
  void for_each_row_band(int width, int height, int rows, Progress& progress,
                         const std::function<void(const Tile&)>& fn);
  // Same over whole columns (tiles of full height and `columns` width), for column-wise walks.
  void for_each_column_strip(int width, int height, int columns, Progress& progress,
                             const std::function<void(const Tile&)>& fn);

 private:
  void run(int width, int height, int tile_width, int tile_height, Progress& progress,
           const std::function<void(const Tile&)>& fn);

  struct Arena;
  int threads_;
  std::unique_ptr<Arena> arena_;
};

// Number of threads to use for a "threads" parameter value (0 = all cores).
int resolve_thread_count(int requested);

}  // namespace ssao
