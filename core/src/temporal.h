// SPDX-License-Identifier: MIT
// The temporal filter (parameters temporal_frames and frame): a frame's AO averaged with the AO
// the same job computed for the frames just before it, each carried to this frame's pixels
// through its depth and both cameras. A screen-fixed sampling pattern makes each frame's error
// a pattern fixed to the screen, which crawls over the surfaces as the camera moves; averaged
// over a few frames it no longer does. What cannot be carried takes no part: a pixel the
// earlier frame did not see (its depth disagrees by more than 0.5 %); a pixel within the AO's
// radius of where the depths show the scene itself moved (find_motion: what occludes it may
// have changed, so an object's shadow leaves no trail); a pixel whose AO changed by more than
// noise does (0.1: a cut, a change no depth shows); a carried value is also clamped to the
// range of this frame's own values around the pixel (+- 0.01).
//
// Each earlier frame enters with its own estimate, not its filtered result: a frame's output
// depends on the estimates of the frames in its window and nothing older, so a chunk of a
// sequence that computes the frames before it first (without writing them) is bit for bit what
// a serial run writes.
#pragma once

#include <deque>
#include <vector>

#include "camera.h"
#include "frame.h"
#include "tiles.h"

namespace ssao {

class TemporalHistory {
 public:
  // Starts the run of frame number `frame` averaging up to `frames` frames (1: this one only).
  // Keeps the earlier frames this one can use: numbers frame - frames + 1 .. frame - 1, the
  // same output size; the others are dropped (frames come in increasing order: a frame this one
  // cannot use, no later one can). `camera`: the full input's camera, `window` the
  // output window in its pixels, `camera_to_world` 16 values row by row.
  void begin(int frame, int frames, const CameraModel& camera, const double* camera_to_world,
             const Tile& window);
  // Finds where the scene itself moved since the earlier frames (not the camera): history is
  // not carried within `radius` (scene units, the AO's) of a point that moved, since what
  // occludes there changed. Also records this frame's depths for the frames after it. Call
  // after begin and before any blend; the work is shared by the pool's threads.
  void find_motion(const Frame& frame, float radius, TilePool& tiles);
  // Tile t's values (frame pixels, rows of t's width; depth from `frame`) averaged with the
  // earlier frames in place; the values before averaging are recorded for the frames after.
  void blend(const Frame& frame, const Tile& t, float* values);
  // Makes this run's frame one of the earlier frames of the next runs (after a successful run).
  void commit();

 private:
  struct Entry {
    int frame = 0;
    int width = 0, height = 0;                 // the output window's size
    CameraModel camera{CameraParams{}, 1, 1};  // of the window's pixels
    double camera_to_world[16] = {};
    std::vector<float> depth, visibility;  // the window's, row-major
    std::vector<float> nearest;  // per 2 x 2 block, the nearest depth of the 4 x 4 around it
    // From this run's view space to the entry's (set by begin for the earlier frames).
    double to_entry[12] = {};
  };
  int frames_ = 1;
  std::deque<Entry> earlier_;
  Entry current_;
  Tile window_{0, 0, 0, 0};
  // 1 where the scene moved near the pixel, per 2 x 2 block of the window (empty: it
  // moved nowhere).
  std::vector<float> moved_;
  int moved_width_ = 0;
};

}  // namespace ssao
