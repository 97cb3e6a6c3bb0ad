// SPDX-License-Identifier: MIT
// A deliberate data race for the ThreadSanitizer build (build-tsan): tiles of the library's tile
// pool all increment one plain int. scripts/test.sh runs this with tests/tsan.supp and expects
// ThreadSanitizer to report the race: proof that the suppressions for oneTBB's internals and
// the happens-before edges stated in core/src/tiles.cpp do not hide races between tiles, the
// kind the library's own code could have. Exit 0 (no report) fails the check.
#include <chrono>
#include <cstdio>
#include <thread>

#include "tiles.h"

int main() {
  ssao::TilePool pool(2);
  ssao::Progress progress(nullptr, nullptr);
  int shared = 0;  // written by every tile without synchronisation: the race
  // 64 tiles that take a moment each, so that both threads run some.
  pool.for_each_tile(8 * ssao::kTileWidth, 8 * ssao::kTileHeight, progress, [&](const ssao::Tile&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    shared = shared + 1;
  });
  std::printf("tsan canary: %d tiles counted\n", shared);
  return 0;
}
