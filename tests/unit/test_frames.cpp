// SPDX-License-Identifier: MIT
// Frame specifications and file name patterns of image sequences (core/tools/frames.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tools/frames.h"

using ssao_tools::FramePattern;
using ssao_tools::parse_frames;

namespace {

// The message of the Error `spec` throws, or "" if it parses.
std::string frames_error(const std::string& spec) {
  try {
    parse_frames(spec);
  } catch (const ssao_tools::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Frames, SingleRangesStepsAndLists) {
  EXPECT_EQ(parse_frames("1001"), std::vector<int>({1001}));
  EXPECT_EQ(parse_frames("1-4"), std::vector<int>({1, 2, 3, 4}));
  EXPECT_EQ(parse_frames("1-10x4"), std::vector<int>({1, 5, 9}));
  EXPECT_EQ(parse_frames("1,5,9-12"), std::vector<int>({1, 5, 9, 10, 11, 12}));
  EXPECT_EQ(parse_frames("-2-1"), std::vector<int>({-2, -1, 0, 1}));
  EXPECT_EQ(parse_frames("-5--4"), std::vector<int>({-5, -4}));
  EXPECT_EQ(parse_frames("7-7"), std::vector<int>({7}));
  EXPECT_EQ(parse_frames("1001-1100").size(), 100u);
}

TEST(Frames, BadSpecificationsNameTheirPart) {
  EXPECT_NE(frames_error("").find("is not a frame number"), std::string::npos);
  EXPECT_NE(frames_error("1,,2").find("'' is not a frame number"), std::string::npos);
  EXPECT_NE(frames_error("10-1").find("'10-1' runs backwards"), std::string::npos);
  EXPECT_NE(frames_error("1-10x0").find("step"), std::string::npos);
  EXPECT_NE(frames_error("1-10x-2").find("step"), std::string::npos);
  EXPECT_NE(frames_error("1-").find("no valid end"), std::string::npos);
  EXPECT_NE(frames_error("1-5y").find("extra characters"), std::string::npos);
  EXPECT_NE(frames_error("abc").find("'abc'"), std::string::npos);
  EXPECT_NE(frames_error("99999999999").find("is not a frame number"), std::string::npos);
  EXPECT_NE(frames_error("1-3,2").find("frame 2 is given twice"), std::string::npos);
  EXPECT_NE(frames_error("0-2000000").find("more than 1000000 frames"), std::string::npos);
}

TEST(Frames, PatternsPadTheFrameNumber) {
  EXPECT_EQ(FramePattern("shot/render.####.exr").path(42), "shot/render.0042.exr");
  EXPECT_EQ(FramePattern("render.@@@.exr").path(7), "render.007.exr");
  EXPECT_EQ(FramePattern("render.%04d.exr").path(1001), "render.1001.exr");
  EXPECT_EQ(FramePattern("render.%d.exr").path(5), "render.5.exr");
  EXPECT_EQ(FramePattern("render.##.exr").path(12345), "render.12345.exr");  // never cut
  EXPECT_EQ(FramePattern("render.####.exr").path(-42), "render.-0042.exr");
  // No placeholder: one file for every frame (a static camera's).
  const FramePattern still("shot/camera.json");
  EXPECT_FALSE(still.has_frame());
  EXPECT_EQ(still.path(3), "shot/camera.json");
  // A percent sign that is not a placeholder stays as it is.
  EXPECT_EQ(FramePattern("50%.####.exr").path(1), "50%.0001.exr");
  // Folders are taken as written; a literal pattern has no placeholder at all.
  EXPECT_EQ(FramePattern("shots@v2/#1/render.##.exr").path(3), "shots@v2/#1/render.03.exr");
  EXPECT_EQ(FramePattern::literal("cam@1080.json").path(3), "cam@1080.json");
  EXPECT_FALSE(FramePattern::literal("r.####.exr").has_frame());
  EXPECT_THROW(FramePattern("a.##.b.##.exr"), ssao_tools::Error);
  EXPECT_THROW(FramePattern("a.%04d.#.exr"), ssao_tools::Error);
}

TEST(Frames, FormatIsReadBackAsTheSameFrames) {
  using ssao_tools::format_frames;
  EXPECT_EQ(format_frames({1001, 1002, 1003}), "1001-1003");
  EXPECT_EQ(format_frames({1, 5, 9, 10, 11, 12}), "1-9x4,10-12");
  EXPECT_EQ(format_frames({7, 8}), "7-8");
  EXPECT_EQ(format_frames({7, 9}), "7,9");
  EXPECT_EQ(format_frames({-5, -4, -3, 10}), "-5--3,10");
  EXPECT_EQ(format_frames({3}), "3");
  // Random lists (a fixed seed, so a failure repeats): unordered, gaps, runs, negatives.
  unsigned state = 12345u;
  auto next = [&state](int n) {
    state = state * 1103515245u + 12345u;
    return int((state >> 16) % unsigned(n));
  };
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<int> frames;
    std::vector<bool> used(400, false);
    const int count = 1 + next(40);
    for (int k = 0; k < count; ++k) {
      int frame = next(400);
      const int run = next(3) == 0 ? next(6) : 0;  // sometimes a run of consecutive frames
      for (int r = 0; r <= run && frame < 400; ++r, ++frame) {
        if (!used[size_t(frame)]) {
          used[size_t(frame)] = true;
          frames.push_back(frame - 200);
        }
      }
    }
    const std::string spec = format_frames(frames);
    EXPECT_EQ(parse_frames(spec), frames) << spec;
  }
}

TEST(Frames, ChunksCoverEveryFrameOnceInOrder) {
  using ssao_tools::chunk_count;
  using ssao_tools::chunk_frames;
  // 11 frames in chunks of 4: the last chunk is short (the Slurm trap: an array 1001-1011:4
  // reports 1009 as its last index, and frames 1010-1011 must not be lost).
  const std::vector<int> frames = parse_frames("1001-1011");
  ASSERT_EQ(chunk_count(frames.size(), 4), 3u);
  EXPECT_EQ(chunk_frames(frames, 4, 0), parse_frames("1001-1004"));
  EXPECT_EQ(chunk_frames(frames, 4, 1), parse_frames("1005-1008"));
  EXPECT_EQ(chunk_frames(frames, 4, 2), parse_frames("1009-1011"));
  for (size_t size : {1u, 2u, 3u, 5u, 10u, 11u, 100u}) {
    std::vector<int> joined;
    for (size_t i = 0; i < chunk_count(frames.size(), size); ++i) {
      const std::vector<int> chunk = chunk_frames(frames, size, i);
      EXPECT_LE(chunk.size(), size);
      EXPECT_FALSE(chunk.empty());
      joined.insert(joined.end(), chunk.begin(), chunk.end());
    }
    EXPECT_EQ(joined, frames) << "chunks of " << size;
  }
  EXPECT_EQ(chunk_count(0, 4), 0u);
  try {
    chunk_frames(frames, 4, 3);
    FAIL() << "chunk 3 of 3 was accepted";
  } catch (const ssao_tools::Error& e) {
    EXPECT_NE(std::string(e.what()).find("make 3 chunks (0-2)"), std::string::npos) << e.what();
  }
}
