// SPDX-License-Identifier: MIT
// Overscan (ssao_job_set_output_window): input images larger than the output, the frame a window
// inside them. Its AO must be the AO of a run on the whole input with the camera widened to it,
// cropped; occluders in the guard band must count; bad windows must be refused.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "analytic_scene.h"

using namespace test;

namespace {

constexpr int kWidth = 96, kHeight = 64, kBand = 24;

// AO of the frame's window from the widened scene, through the output window.
std::vector<float> windowed_ao(Scene& big, const Camera& frame, int band, double radius,
                               const char* variant, const char* resolution) {
  Job job;
  job.camera(frame);
  job.set("radius", radius);
  job.set("variant", variant);
  job.set("resolution", resolution);
  job.set("normal_space", "camera");
  std::vector<float> ao(size_t(frame.width) * frame.height, -1.0f);
  job.image("depth", big.depth, big.width, big.height, 1);
  job.image("normal", big.normal, big.width, big.height, 3);
  job.image("ao", ao, frame.width, frame.height, 1);
  EXPECT_EQ(ssao_job_set_output_window(job.get(), 1, band, band), SSAO_OK) << ssao_last_error();
  EXPECT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  return ao;
}

std::vector<float> crop(const std::vector<float>& image, int width, int x0, int y0, int w, int h) {
  std::vector<float> out(size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    std::copy_n(image.begin() + std::ptrdiff_t(size_t(y + y0) * width + x0), w,
                out.begin() + std::ptrdiff_t(size_t(y) * w));
  }
  return out;
}

std::vector<std::string> variants() {
  std::vector<std::string> names;
  for (size_t i = 0; i < ssao_variant_count(); ++i) {
    ssao_variant_desc d{};
    EXPECT_EQ(ssao_variant_info(i, &d), SSAO_OK);
    names.emplace_back(d.name);
  }
  return names;
}

}  // namespace

TEST(Overscan, EqualsTheWidenedFrameCropped) {
  for (const bool ortho : {false, true}) {
    Camera frame;
    frame.width = kWidth, frame.height = kHeight, frame.ortho = ortho;
    const Camera big_camera = widened(frame, kBand);
    Scene big = concave_corner(big_camera);
    for (const std::string& variant : variants()) {
      for (const char* resolution : {"full", "half"}) {
        const auto whole = compute_ao(big, big_camera, 1.0, variant.c_str(), true,
                                      [&](Job& j) { j.set("resolution", resolution); });
        const auto expected = crop(whole, big.width, kBand, kBand, kWidth, kHeight);
        const auto ao = windowed_ao(big, frame, kBand, 1.0, variant.c_str(), resolution);
        // The two cameras agree up to float rounding of the widened sensor (measured: equal bit
        // for bit, every variant, both resolutions, both projections).
        double worst = 0.0;
        for (size_t i = 0; i < ao.size(); ++i) {
          worst = std::max(worst, double(std::fabs(ao[i] - expected[i])));
        }
        EXPECT_LE(worst, 1e-6) << variant << " " << resolution << (ortho ? " ortho" : "");
        EXPECT_LT(*std::min_element(ao.begin(), ao.end()), 0.9f)
            << variant << ": the frame must have occlusion to compare";
      }
    }
  }
}

TEST(Overscan, OccludersInTheGuardBandCount) {
  // A concave corner whose crease lies just left of the frame: the wall beyond the edge darkens
  // the frame's first columns. With the guard band the AO there follows the corner's closed form;
  // cropped at the frame edge, it misses the wall.
  Camera frame;
  frame.width = kWidth, frame.height = kHeight;
  const Camera big_camera = widened(frame, kBand);
  Corner corner;
  corner.crease = {-3.3, 0.0, -6.0};  // the frame's left edge is at x = -3.09 at depth 6
  Scene big = concave_corner(big_camera, corner);
  Scene cropped = concave_corner(frame, corner);
  const double radius = 1.0;
  const auto with_band = windowed_ao(big, frame, kBand, radius, "hemisphere", "full");
  const auto without_band = compute_ao(cropped, frame, radius, "hemisphere");
  double error_with = 0.0, error_without = 0.0;
  int count = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double distance = distance_to_crease(cropped, x, y, corner);
      if (!std::isfinite(cropped.depth[size_t(y) * kWidth + x]) || distance > radius) continue;
      const double truth = corner_ao(distance, radius);
      const size_t i = size_t(y) * kWidth + x;
      error_with += std::fabs(with_band[i] - truth);
      error_without += std::fabs(without_band[i] - truth);
      ++count;
    }
  }
  ASSERT_GT(count, 100) << "pixels within the radius of the crease";
  error_with /= count;
  error_without /= count;
  std::printf(
      "[measure] corner beyond the frame edge: mean |AO - closed form| %.4f with a %d px "
      "guard band, %.4f without, over %d px\n",
      error_with, kBand, error_without, count);
  EXPECT_LT(error_with, 0.6 * error_without);
}

TEST(Overscan, WithoutABandSurfacesCutByTheFrameEdgeGoOnBeyondIt) {
  // A concave corner whose crease runs from the frame's top edge to its bottom edge: near those
  // edges half a receiver's samples fall outside the frame. Taken to meet the walls carried on
  // beyond it (the border pixels' planes), they find the occlusion the closed form has, as in
  // the middle rows; skipped, the edge rows came out lighter (mean error in the 6 rows at either
  // edge against the others: 0.039 / 0.018 perspective, 0.058 / 0.032 orthographic; carried on:
  // 0.017 / 0.016 and 0.030 / 0.031).
  for (const bool ortho : {false, true}) {
    Camera frame;
    frame.width = kWidth, frame.height = kHeight, frame.ortho = ortho;
    Corner corner;
    Scene scene = concave_corner(frame, corner);
    const double radius = 1.0;
    const auto ao = compute_ao(scene, frame, radius, "hemisphere");
    double edge_error = 0.0, middle_error = 0.0;
    int edge_count = 0, middle_count = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double distance = distance_to_crease(scene, x, y, corner);
        if (!std::isfinite(scene.depth[size_t(y) * kWidth + x]) || distance > radius) continue;
        const double error = std::fabs(ao[size_t(y) * kWidth + x] - corner_ao(distance, radius));
        const bool edge = y < 6 || y >= kHeight - 6;
        (edge ? edge_error : middle_error) += error;
        ++(edge ? edge_count : middle_count);
      }
    }
    ASSERT_GT(edge_count, 50);
    ASSERT_GT(middle_count, 200);
    edge_error /= edge_count;
    middle_error /= middle_count;
    std::printf(
        "[measure] %s corner across the frame's top and bottom edges: mean |AO - closed form| "
        "%.4f in the 6 rows at either edge (%d px), %.4f in the others (%d px)\n",
        ortho ? "ortho" : "persp", edge_error, edge_count, middle_error, middle_count);
    EXPECT_LT(edge_error, 1.5 * middle_error + 0.005) << (ortho ? "ortho" : "persp");
  }
}

TEST(Overscan, BadWindowsAreRefused) {
  Camera frame;
  frame.width = kWidth, frame.height = kHeight;
  const Camera big_camera = widened(frame, kBand);
  Scene big = floor_and_wall(big_camera);
  std::vector<float> ao(size_t(kWidth) * kHeight), beauty(size_t(kWidth) * kHeight * 3),
      composite(beauty.size()), wrong(size_t(big.width) * big.height * 3);
  Job job;
  job.camera(frame);
  job.image("depth", big.depth, big.width, big.height, 1);
  job.image("ao", ao, kWidth, kHeight, 1);
  // Without a window, an output of another size is refused as before.
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "image 'ao' is 96x64 but depth is 144x112"), nullptr)
      << ssao_last_error();
  // Left of or above the depth image.
  EXPECT_EQ(ssao_job_set_output_window(job.get(), 1, -1, 0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "must not be left of or above"), nullptr);
  // Beyond its right or bottom edge.
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, 2 * kBand + 1, 0), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "does not fit in the 144x112 depth image"), nullptr)
      << ssao_last_error();
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, 0, 2 * kBand + 1), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  // Far beyond (no overflow on the way: UBSan), also for the automatic radius, which reads the
  // window's depths.
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, 2147483647, 2147483647), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  double radius = 0.0;
  EXPECT_EQ(ssao_job_auto_radius(job.get(), &radius), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "does not fit in the 144x112 depth image"), nullptr)
      << ssao_last_error();
  // The last pixel fits.
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, 2 * kBand, 2 * kBand), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  // Outputs and the beauty have the window's size; normals the depth's.
  job.image("beauty", wrong, big.width, big.height, 3);
  job.image("composite", composite, kWidth, kHeight, 3);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(),
                        "image 'beauty' is 144x112 but the output window is "
                        "96x64"),
            nullptr)
      << ssao_last_error();
  job.image("beauty", beauty, kWidth, kHeight, 3);
  EXPECT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  std::vector<float> small_normals(size_t(kWidth) * kHeight * 3);
  job.image("normal", small_normals, kWidth, kHeight, 3);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "image 'normal' is 96x64 but depth is 144x112"), nullptr)
      << ssao_last_error();
  // Turned off: back to one size for every image.
  job.image("normal", big.normal, big.width, big.height, 3);
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 0, 0, 0), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Overscan, AutoRadiusIsTheFramesNotTheBands) {
  Camera frame;
  frame.width = kWidth, frame.height = kHeight;
  const Camera big_camera = widened(frame, kBand);
  Scene big = floor_and_wall(big_camera);
  Scene plain = floor_and_wall(frame);
  std::vector<float> ao(size_t(kWidth) * kHeight);
  double frame_radius = 0.0, band_radius = 0.0;
  {
    Job job;
    job.camera(frame);
    job.image("depth", plain.depth, kWidth, kHeight, 1);
    ASSERT_EQ(ssao_job_auto_radius(job.get(), &frame_radius), SSAO_OK) << ssao_last_error();
  }
  {
    Job job;
    job.camera(frame);
    job.image("depth", big.depth, big.width, big.height, 1);
    job.image("ao", ao, kWidth, kHeight, 1);
    ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, kBand, kBand), SSAO_OK);
    ASSERT_EQ(ssao_job_auto_radius(job.get(), &band_radius), SSAO_OK) << ssao_last_error();
  }
  EXPECT_NEAR(band_radius, frame_radius, 1e-4 * frame_radius);
}
