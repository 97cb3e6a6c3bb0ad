// SPDX-License-Identifier: MIT
// Frame specifications and file name patterns of image sequences (core/io/frames.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io/frames.h"

using ssao_io::FramePattern;
using ssao_io::parse_frames;

namespace {

// The message of the Error `spec` throws, or "" if it parses.
std::string frames_error(const std::string& spec) {
  try {
    parse_frames(spec);
  } catch (const ssao_io::Error& e) {
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
  EXPECT_THROW(FramePattern("a.##.b.##.exr"), ssao_io::Error);
  EXPECT_THROW(FramePattern("a.%04d.#.exr"), ssao_io::Error);
}
