// SPDX-License-Identifier: MIT
// Image sequences as oiiotool writes them: frame numbers from a --frames specification, and
// file name patterns with one frame placeholder.
//   frames:   "1001", "1001-1100", "1001-1100x4" (every 4th), lists "1,5,9-12"; negative
//             numbers allowed ("-5-5"); at most kMaxFrames frames, no frame twice.
//   patterns: "#" is one digit of padding ("render.####.exr" -> render.0042.exr), "@" the same,
//             "%04d" printf-style ("%d": no padding), in the file name only (folders are taken
//             as written). Negative frames keep their sign in front of the padded digits.
#pragma once

#include <string>
#include <vector>

#include "tools/error.h"

namespace ssao_tools {

constexpr size_t kMaxFrames = 1000000;

// The frames of a specification, in the order given. Throws Error naming the part it cannot
// read: an empty part, a range that runs backwards, a step that is not positive, a number out
// of int range, more than kMaxFrames frames, or a frame given twice.
std::vector<int> parse_frames(const std::string& spec);

// A specification that parse_frames reads back as `frames`: runs with one step are written
// "A-B" or "A-BxN", other frames one by one ("1001-1010,1013,1020-1040x10").
std::string format_frames(const std::vector<int>& frames);

// Farm chunks: `frames`, in the order given, cut into chunks of `chunk_size` frames (the last one
// shorter when the count is not a multiple). Chunks are numbered from 0, so a job array's task
// index picks its chunk from the whole frame list, and no task needs the range's last index.
size_t chunk_count(size_t frame_count, size_t chunk_size);
// Throws Error when `index` is not below chunk_count().
std::vector<int> chunk_frames(const std::vector<int>& frames, size_t chunk_size, size_t index);

// A file name with at most one frame placeholder.
class FramePattern {
 public:
  // Throws Error for a pattern with two placeholders ("a.##.b.##.exr") or a malformed "%d".
  explicit FramePattern(const std::string& text);
  // The same name for every frame, placeholder characters included.
  static FramePattern literal(const std::string& text);
  bool has_frame() const { return width_ >= 0; }
  // The name of `frame`; the text itself when it has no placeholder.
  std::string path(int frame) const;
  const std::string& text() const { return text_; }

 private:
  std::string text_, prefix_, suffix_;
  int width_ = -1;  // digits of padding; -1: no placeholder
};

}  // namespace ssao_tools
