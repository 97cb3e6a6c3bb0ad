// SPDX-License-Identifier: MIT
// The C API contract: statuses and messages for bad handles, names, values and images; hostile
// pixel values; edge sizes; strides; progress and cancellation; thread-count invariance.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <thread>

#include "analytic_scene.h"

using namespace test;

namespace {

bool contains(const char* haystack, const char* needle) {
  return std::strstr(haystack, needle) != nullptr;
}

}  // namespace

TEST(Api, VersionAndStatusStrings) {
  EXPECT_EQ(ssao_version(), SSAO_VERSION);
  EXPECT_STREQ(ssao_status_string(SSAO_ERROR_CANCELLED), "cancelled");
}

TEST(Api, NullHandlesAndPointersAreRejected) {
  EXPECT_EQ(ssao_job_create(nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_float(nullptr, "radius", 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "NULL"));
  EXPECT_EQ(ssao_job_run(nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  ssao_job_destroy(nullptr);  // a no-op
  Job job;
  EXPECT_EQ(ssao_job_set_float(job.get(), nullptr, 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_string(job.get(), "variant", nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_get_float(job.get(), "radius", nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_param_info(0, nullptr), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Api, AnOverlongMessageIsCutAndMarked) {
  // The per-thread message has a fixed size (api.cpp says why): a longer one keeps its start and
  // ends in "...", and the next short message replaces it whole.
  Job job;
  const std::string name(10000, 'x');
  EXPECT_EQ(ssao_job_set_float(job.get(), name.c_str(), 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  const std::string cut = ssao_last_error();
  EXPECT_EQ(cut.size(), 4095u);
  EXPECT_EQ(cut.rfind("unknown parameter 'xxx", 0), 0u) << cut.substr(0, 40);
  EXPECT_EQ(cut.substr(cut.size() - 3), "...");
  EXPECT_EQ(ssao_job_set_float(job.get(), "radus", 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "unknown parameter 'radus'"));
  EXPECT_LT(std::strlen(ssao_last_error()), 200u);
}

TEST(Api, ParameterErrorsNameTheParameter) {
  Job job;
  EXPECT_EQ(ssao_job_set_float(job.get(), "radus", 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "unknown parameter 'radus'"));
  EXPECT_EQ(ssao_job_set_int(job.get(), "radius", 1), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "is a float"));
  EXPECT_EQ(ssao_job_set_float(job.get(), "radius", -1.0), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "radius"));
  EXPECT_EQ(ssao_job_set_float(job.get(), "radius", std::nan("")), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_float(job.get(), "radius", HUGE_VAL), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_int(job.get(), "samples", -1), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_string(job.get(), "variant", "gtao"), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "horizon|hemisphere|sphere"));
  const double short_matrix[3] = {1, 2, 3};
  EXPECT_EQ(ssao_job_set_floats(job.get(), "camera_to_world", short_matrix, 3),
            SSAO_ERROR_INVALID_ARGUMENT);
  double nan_matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  nan_matrix[5] = std::nan("");
  EXPECT_EQ(ssao_job_set_floats(job.get(), "camera_to_world", nan_matrix, 16),
            SSAO_ERROR_INVALID_ARGUMENT);
  // A failed set leaves the previous value.
  double radius = 0;
  EXPECT_EQ(ssao_job_get_float(job.get(), "radius", &radius), SSAO_OK);
  EXPECT_EQ(radius, 1.0);
}

TEST(Api, ParameterTableDefaultsRoundTrip) {
  Job job;
  const size_t n = ssao_param_count();
  ASSERT_GT(n, 20u);
  for (size_t i = 0; i < n; ++i) {
    ssao_param_desc d;
    ASSERT_EQ(ssao_param_info(i, &d), SSAO_OK);
    ASSERT_NE(d.name, nullptr);
    ASSERT_NE(d.description, nullptr);
    switch (d.type) {
      case SSAO_PARAM_INT: {
        int v = -1;
        EXPECT_EQ(ssao_job_get_int(job.get(), d.name, &v), SSAO_OK);
        EXPECT_EQ(v, int(d.default_value)) << d.name;
        EXPECT_EQ(ssao_job_set_int(job.get(), d.name, v), SSAO_OK) << d.name;
        EXPECT_GE(d.default_value, d.min_value);
        EXPECT_LE(d.default_value, d.max_value);
        break;
      }
      case SSAO_PARAM_FLOAT: {
        double v = -1;
        EXPECT_EQ(ssao_job_get_float(job.get(), d.name, &v), SSAO_OK);
        EXPECT_EQ(v, d.default_value) << d.name;
        EXPECT_EQ(ssao_job_set_float(job.get(), d.name, v), SSAO_OK) << d.name;
        break;
      }
      case SSAO_PARAM_STRING: {
        char buf[64];
        EXPECT_EQ(ssao_job_get_string(job.get(), d.name, buf, sizeof buf), SSAO_OK);
        EXPECT_STREQ(buf, d.default_string);
        EXPECT_TRUE(contains(d.choices, d.default_string)) << d.name;
        break;
      }
      case SSAO_PARAM_FLOATS: {
        std::vector<double> v(d.count);
        EXPECT_EQ(ssao_job_get_floats(job.get(), d.name, v.data(), v.size()), SSAO_OK);
        EXPECT_EQ(ssao_job_set_floats(job.get(), d.name, v.data(), v.size()), SSAO_OK);
        break;
      }
    }
  }
  ssao_param_desc d;
  EXPECT_EQ(ssao_param_info(n, &d), SSAO_ERROR_INVALID_ARGUMENT);
  char tiny[4];
  EXPECT_EQ(ssao_job_get_string(job.get(), "variant", tiny, sizeof tiny), SSAO_OK);
  EXPECT_STREQ(tiny, "hem");  // truncated, still terminated
}

TEST(Api, ImageErrors) {
  Job job;
  std::vector<float> depth(16, 5.0f), ao(16), small(4), rgb(48);
  EXPECT_EQ(ssao_job_set_image(job.get(), "dpeth", depth.data(), 4, 4, 1, 0, 0),
            SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "unknown image 'dpeth'"));
  EXPECT_EQ(ssao_job_set_image(job.get(), "normal", rgb.data(), 4, 4, 1, 0, 0),
            SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_image(job.get(), "depth", depth.data(), -4, 4, 1, 0, 0),
            SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_image(job.get(), "depth", depth.data(), 4, 4, 1, 2, 0),
            SSAO_ERROR_INVALID_ARGUMENT);  // pixel stride smaller than a float
  EXPECT_EQ(ssao_job_set_image(job.get(), "depth", depth.data(), 4, 4, 1, 4, 8),
            SSAO_ERROR_INVALID_ARGUMENT);  // row stride smaller than a row

  // Nothing attached, then no output, then mismatched sizes, then composite without beauty.
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_TRUE(contains(ssao_last_error(), "no depth image"));
  ASSERT_EQ(ssao_job_set_image(job.get(), "depth", depth.data(), 4, 4, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_TRUE(contains(ssao_last_error(), "no output image"));
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", small.data(), 2, 2, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "'ao' is 2x2 but depth is 4x4"));
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", nullptr, 0, 0, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", ao.data(), 4, 4, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "edge_colours", small.data(), 2, 2, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "'edge_colours' is 2x2 but depth is 4x4"));
  ASSERT_EQ(ssao_job_set_image(job.get(), "edge_colours", nullptr, 0, 0, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", nullptr, 0, 0, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "composite", rgb.data(), 4, 4, 3, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_TRUE(contains(ssao_last_error(), "needs a 'beauty'"));
  std::vector<float> rgba(64, 0.5f);
  ASSERT_EQ(ssao_job_set_image(job.get(), "beauty", rgba.data(), 4, 4, 4, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "channels"));
}

TEST(Api, EmptyAndSinglePixelImages) {
  Job job;
  float value = 5.0f, ao = -1.0f;
  ASSERT_EQ(ssao_job_set_image(job.get(), "depth", &value, 0, 0, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", &ao, 0, 0, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(ssao_job_run(job.get()), SSAO_OK);  // documented: nothing to do
  EXPECT_EQ(ao, -1.0f);
  ASSERT_EQ(ssao_job_set_image(job.get(), "depth", &value, 1, 1, 1, 0, 0), SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", &ao, 1, 1, 1, 0, 0), SSAO_OK);
  for (const char* variant : {"hemisphere", "sphere"}) {
    ASSERT_EQ(ssao_job_set_string(job.get(), "variant", variant), SSAO_OK);
    EXPECT_EQ(ssao_job_run(job.get()), SSAO_OK);
    EXPECT_EQ(ao, 1.0f) << variant;  // no neighbour can occlude
  }
}

TEST(Api, HostileDepthValuesAreBackground) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const float hostile[] = {
      std::numeric_limits<float>::quiet_NaN(), HUGE_VALF, -HUGE_VALF, -3.0f, 0.0f, 1e10f, 65504.0f,
      std::numeric_limits<float>::denorm_min()};
  const size_t n = s.depth.size();
  for (size_t i = 0; i < n; i += 7) s.depth[i] = hostile[(i / 7) % 8];
  for (const char* variant : {"hemisphere", "sphere"}) {
    const auto ao = compute_ao(s, cam, 1.0, variant, true, [](Job& j) {
      j.set("clip_end", 1000.0);  // makes 65504 (EEVEE's background) background too
    });
    for (size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(std::isfinite(ao[i])) << variant << " pixel " << i;
      ASSERT_GE(ao[i], 0.0f);
      ASSERT_LE(ao[i], 1.0f);
      const float d = s.depth[i];
      const bool background = !(d > 0) || !std::isfinite(d) || d >= 1000.0f;
      if (background) {
        ASSERT_EQ(ao[i], 1.0f) << variant << " depth " << d;
      }
    }
  }
}

TEST(Api, ZeroAndNonFiniteNormalsFallBackToReconstruction) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const auto reference = compute_ao(s, cam, 1.0, "hemisphere", false);
  std::fill(s.normal.begin(), s.normal.end(), 0.0f);
  for (size_t i = 0; i < s.normal.size(); i += 5) s.normal[i] = std::nanf("");
  const auto ao = compute_ao(s, cam, 1.0, "hemisphere", true);
  // NaN in x with zeros elsewhere is not a direction either: every pixel reconstructs.
  EXPECT_EQ(ao, reference);
}

TEST(Api, ResultsDoNotDependOnThreadCount) {
  Camera cam;
  cam.width = 301;  // several tiles across, a partial one at the edge
  cam.height = 83;
  for (const char* variant : {"horizon", "hemisphere", "sphere"}) {
    for (const char* resolution : {"full", "half"}) {
      Scene s = floor_and_wall(cam);
      const auto one = compute_ao(s, cam, 1.0, variant, true, [&](Job& j) {
        j.set("threads", 1);
        j.set("resolution", resolution);
      });
      for (int threads : {2, 3, 7, 0}) {
        const auto many = compute_ao(s, cam, 1.0, variant, true, [&](Job& j) {
          j.set("threads", threads);
          j.set("resolution", resolution);
        });
        ASSERT_EQ(std::memcmp(one.data(), many.data(), one.size() * sizeof(float)), 0)
            << variant << " " << resolution << " threads=" << threads;
      }
      EXPECT_LT(*std::min_element(one.begin(), one.end()), 0.9f)
          << "the scene must have occlusion to compare";
    }
  }
}

TEST(Api, StridedAndBottomUpImagesGiveTheSameResult) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const int w = s.width, h = s.height;
  const auto packed = compute_ao(s, cam, 1.0, "hemisphere");

  // Depth in channel 3 of an RGBA buffer with padded rows, normals in an RGBA buffer stored
  // bottom-up (negative row stride), AO written into an RGBA output.
  const int row_floats = w * 4 + 3;
  std::vector<float> depth_rgba(size_t(row_floats) * h, 0.0f), normal_up(size_t(w) * h * 4);
  std::vector<float> ao_rgba(size_t(w) * h * 4, -1.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      depth_rgba[size_t(y) * row_floats + x * 4 + 3] = s.depth[size_t(y) * w + x];
      for (int c = 0; c < 3; ++c) {
        normal_up[(size_t(h - 1 - y) * w + x) * 4 + c] = s.normal[(size_t(y) * w + x) * 3 + c];
      }
    }
  }
  Job job;
  job.camera(cam);
  job.set("normal_space", "camera");
  ASSERT_EQ(
      ssao_job_set_image(job.get(), "depth", depth_rgba.data() + 3, w, h, 1, 16, row_floats * 4),
      SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "normal", normal_up.data() + size_t(h - 1) * w * 4, w, h,
                               3, 16, -ptrdiff_t(w) * 16),
            SSAO_OK);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ao", ao_rgba.data(), w, h, 4, 0, 0), SSAO_OK);
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  for (size_t i = 0; i < packed.size(); ++i) {
    ASSERT_EQ(ao_rgba[i * 4 + 0], packed[i]);
    ASSERT_EQ(ao_rgba[i * 4 + 2], packed[i]);
    ASSERT_EQ(ao_rgba[i * 4 + 3], 1.0f);
  }
}

TEST(Api, CompositeIsBeautyTimesAoAndMayBeInPlace) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const int w = s.width, h = s.height;
  const auto ao = compute_ao(s, cam, 1.0, "hemisphere");
  std::vector<float> beauty(size_t(w) * h * 4);
  for (size_t i = 0; i < beauty.size(); ++i) beauty[i] = float(i % 13) / 13.0f;
  const std::vector<float> original = beauty;
  Job job;
  job.camera(cam);
  job.set("normal_space", "camera");
  job.image("depth", s.depth, w, h, 1);
  job.image("normal", s.normal, w, h, 3);
  job.image("beauty", beauty, w, h, 4);
  job.image("composite", beauty, w, h, 4);  // in place
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  for (size_t i = 0; i < ao.size(); ++i) {
    for (int c = 0; c < 3; ++c) ASSERT_EQ(beauty[i * 4 + c], original[i * 4 + c] * ao[i]);
    ASSERT_EQ(beauty[i * 4 + 3], original[i * 4 + 3]);  // alpha untouched
  }
}

// A pixel partly covered by sky: the normal pass averages the surface's unit normals with the
// sky's zeros, so its length is the surface's share c, and the composite darkens that share
// only, beauty x (1 - c (1 - AO)); with a transparent film (alpha c) the beauty holds only the
// surface, which AO darkens whole. The AO output does not change.
TEST(Api, CompositeDarkensOnlyTheSurfacesShareBesideTheSky) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const int w = s.width, h = s.height;
  // Sky above the row just over the crease, where the floor occludes the wall.
  const auto full = compute_ao(s, cam, 1.0, "hemisphere");
  int sky_rows = 1;
  double darkest = 2.0;
  for (int y = 1; y < h; ++y) {
    double sum = 0.0;
    for (int x = 0; x < w; ++x) sum += full[size_t(y) * w + x];
    if (sum / w < darkest) darkest = sum / w, sky_rows = y - 1;
  }
  ASSERT_GT(sky_rows, 0);
  for (int y = 0; y < sky_rows; ++y) {
    for (int x = 0; x < w; ++x) {
      s.depth[size_t(y) * w + x] = std::numeric_limits<float>::infinity();
      for (int c = 0; c < 3; ++c) s.normal[(size_t(y) * w + x) * 3 + c] = 0.0f;
    }
  }
  // The first surface row is anti-aliased against the sky: a quarter, half or all covered.
  const auto share = [](int x) { return x % 3 == 0 ? 0.25f : (x % 3 == 1 ? 0.5f : 1.0f); };
  const size_t edge = size_t(sky_rows) * w;
  for (int x = 0; x < w; ++x) {
    for (int c = 0; c < 3; ++c) s.normal[(edge + x) * 3 + c] *= share(x);
  }
  const auto ao = compute_ao(s, cam, 1.0, "hemisphere");
  for (const int channels : {3, 4}) {
    std::vector<float> beauty(size_t(w) * h * channels, 0.8f), composite(beauty.size(), -1.0f);
    if (channels == 4) {  // transparent film: alpha is the coverage
      for (size_t i = 0; i < size_t(w) * h; ++i) beauty[i * 4 + 3] = 1.0f;
      for (int x = 0; x < w; ++x) beauty[(edge + x) * 4 + 3] = share(x);
    }
    std::vector<float> ao_out(size_t(w) * h, -1.0f);
    Job job;
    job.camera(cam);
    job.set("radius", 1.0);
    job.set("normal_space", "camera");
    job.image("depth", s.depth, w, h, 1);
    job.image("normal", s.normal, w, h, 3);
    job.image("beauty", beauty, w, h, channels);
    job.image("composite", composite, w, h, channels);
    job.image("ao", ao_out, w, h, 1);
    ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
    EXPECT_EQ(ao_out, ao);
    int partial = 0;
    for (size_t i = edge - w; i < size_t(w) * h; ++i) {
      const int x = int(i % size_t(w));
      const float c = i >= edge && i < edge + w && channels == 3 ? share(x) : 1.0f;
      const float expected = i < edge ? 0.8f : 0.8f * (1.0f - c * (1.0f - ao[i]));
      ASSERT_NEAR(composite[i * channels], expected, 1e-6f) << "pixel " << i << ", " << channels;
      partial += c < 1.0f && ao[i] < 0.99f;
    }
    if (channels == 3) {
      EXPECT_GT(partial, w / 2);  // the edge row is occluded: the test bites
    }
  }
}

TEST(Api, AmbientCompositeDarkensOnlyTheAmbientPart) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const int w = s.width, h = s.height;
  const auto ao = compute_ao(s, cam, 1.0, "hemisphere");
  std::vector<float> beauty(size_t(w) * h * 4), ambient(beauty.size());
  for (size_t i = 0; i < beauty.size(); ++i) {
    beauty[i] = float(i % 13) / 13.0f;
    ambient[i] = float(i % 7) / 7.0f;  // larger than the beauty in places: clamped at 0
  }
  std::vector<float> composite(beauty.size(), -1.0f);
  Job job;
  job.camera(cam);
  job.set("normal_space", "camera");
  job.image("depth", s.depth, w, h, 1);
  job.image("normal", s.normal, w, h, 3);
  job.image("beauty", beauty, w, h, 4);
  job.image("ambient", ambient, w, h, 4);
  job.image("composite", composite, w, h, 4);
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  size_t darkened = 0, clamped = 0;
  for (size_t i = 0; i < ao.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const size_t k = i * 4 + size_t(c);
      const float expected = std::max(0.0f, beauty[k] - (1.0f - ao[i]) * ambient[k]);
      ASSERT_EQ(composite[k], expected) << "pixel " << i << " channel " << c;
      darkened += composite[k] < beauty[k];
      clamped += composite[k] == 0.0f && beauty[k] > 0.0f;
    }
    ASSERT_EQ(composite[i * 4 + 3], beauty[i * 4 + 3]);  // alpha untouched
  }
  EXPECT_GT(darkened, ao.size() / 10);  // the scene has occlusion to test
  EXPECT_GT(clamped, 0u);

  // The ambient image must have the beauty's channels.
  std::vector<float> grey(size_t(w) * h);
  ASSERT_EQ(ssao_job_set_image(job.get(), "ambient", grey.data(), w, h, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "'ambient' has 1 channels but 'beauty' has 4"));
}

TEST(Api, AutoRadiusIsATenthOfTheViewWidthAtTheMedianDepth) {
  // 60% of the columns at planar depth 2, the rest at 10, one column of sky: median 2.
  Camera cam;
  const int w = cam.width, h = cam.height;
  std::vector<float> planar(size_t(w) * h), radial(planar.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float d = x == w - 1 ? HUGE_VALF : (x < w * 6 / 10 ? 2.0f : 10.0f);
      V3 origin, direction;
      cam.ray(x, y, origin, direction);
      planar[size_t(y) * w + x] = d;
      radial[size_t(y) * w + x] = float(d * std::sqrt(dot(direction, direction)));
    }
  }
  const double expected = 0.1 * 2.0 * cam.sensor / cam.lens;  // the view is 36/35 x depth wide
  for (const bool is_radial : {false, true}) {
    Job job;
    job.camera(cam);
    job.set("depth_kind", is_radial ? "radial" : "planar");
    job.image("depth", is_radial ? radial : planar, w, h, 1);
    double radius = 0.0;
    ASSERT_EQ(ssao_job_auto_radius(job.get(), &radius), SSAO_OK) << ssao_last_error();
    EXPECT_NEAR(radius, expected, 1e-6 * expected) << (is_radial ? "radial" : "planar");
    double unchanged = 0.0;
    ASSERT_EQ(ssao_job_get_float(job.get(), "radius", &unchanged), SSAO_OK);
    EXPECT_EQ(unchanged, 1.0);  // the rule does not set the parameter
  }
  // Orthographic: a tenth of the view's width, whatever the depth.
  Camera ortho;
  ortho.ortho = true;
  Job job;
  job.camera(ortho);
  job.image("depth", planar, w, h, 1);
  double radius = 0.0;
  ASSERT_EQ(ssao_job_auto_radius(job.get(), &radius), SSAO_OK);
  EXPECT_NEAR(radius, 0.1 * ortho.ortho_scale, 1e-6);
  // A portrait image: the larger side (the height) sets the extent.
  Job portrait;
  portrait.camera(cam);
  std::vector<float> tall(size_t(w) * h, 4.0f);
  portrait.image("depth", tall, h, w, 1);
  ASSERT_EQ(ssao_job_auto_radius(portrait.get(), &radius), SSAO_OK);
  EXPECT_NEAR(radius, 0.1 * 4.0 * cam.sensor / cam.lens, 1e-5);

  // No depth, no geometry, no output pointer.
  Job empty;
  EXPECT_EQ(ssao_job_auto_radius(empty.get(), &radius), SSAO_ERROR_INVALID_OPERATION);
  std::vector<float> sky(size_t(w) * h, HUGE_VALF);
  sky[5] = std::nanf("");
  sky[6] = -1.0f;
  empty.image("depth", sky, w, h, 1);
  EXPECT_EQ(ssao_job_auto_radius(empty.get(), &radius), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_TRUE(contains(ssao_last_error(), "no geometry"));
  EXPECT_EQ(ssao_job_auto_radius(job.get(), nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_auto_radius(nullptr, &radius), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Api, LastRunReportsGeometryByTheOneBackgroundRule) {
  // A wall at planar depth 5 seen with radial depth, clip_end 5.1: towards the corners the
  // radial values exceed 5.1 but the planar depth, which the rule tests, does not. Hostile
  // values (NaN, inf, <= 0, beyond background_depth) are background.
  Camera cam;
  const int w = cam.width, h = cam.height;
  std::vector<float> radial(size_t(w) * h);
  size_t beyond_clip = 0, expected_geometry = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      V3 origin, direction;
      cam.ray(x, y, origin, direction);
      float& d = radial[size_t(y) * w + x];
      d = float(5.0 * std::sqrt(dot(direction, direction)));
      if (d >= 5.1f) ++beyond_clip;
      const size_t i = size_t(y) * w + x;
      if (i % 11 == 0) d = std::nanf("");
      if (i % 11 == 1) d = HUGE_VALF;
      if (i % 11 == 2) d = -1.0f;
      if (i % 11 == 3) d = 2e9f;  // beyond background_depth (1e9)
      if (i % 11 > 3) ++expected_geometry;
    }
  }
  ASSERT_GT(beyond_clip, 0u);
  std::vector<float> ao(size_t(w) * h, -1.0f);
  Job job;
  job.camera(cam);
  job.set("depth_kind", "radial");
  job.set("clip_end", 5.1);
  job.set("radius", 0.5);
  size_t geometry = 0;
  double mean = 0.0;
  EXPECT_EQ(ssao_job_last_run(job.get(), &geometry, &mean), SSAO_ERROR_INVALID_OPERATION);
  job.image("depth", radial, w, h, 1);
  job.image("ao", ao, w, h, 1);
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  ASSERT_EQ(ssao_job_last_run(job.get(), &geometry, &mean), SSAO_OK) << ssao_last_error();
  EXPECT_EQ(geometry, expected_geometry);
  double sum = 0.0;
  for (size_t i = 0; i < ao.size(); ++i) {
    if (i % 11 > 3) sum += ao[i];
  }
  EXPECT_NEAR(mean, sum / double(expected_geometry), 1e-6);  // float partial sums
  EXPECT_LT(mean, 1.0);  // the sky darkens nothing, but the wall's holes are corners
  // The automatic radius counts the same pixels as geometry: the median planar depth is 5.
  double radius = 0.0;
  ASSERT_EQ(ssao_job_auto_radius(job.get(), &radius), SSAO_OK);
  EXPECT_NEAR(radius, 0.1 * 5.0 * cam.sensor / cam.lens, 1e-4);

  // Every radial value at or beyond clip_end, every planar depth before it: all geometry, for
  // the automatic radius as for the run (the two once disagreed).
  std::vector<float> wall(size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      V3 origin, direction;
      cam.ray(x, y, origin, direction);
      wall[size_t(y) * w + x] = float(5.0 * std::sqrt(dot(direction, direction)));
    }
  }
  const double near_clip = 5.00002;
  ASSERT_GE(*std::min_element(wall.begin(), wall.end()), float(near_clip));
  Job clipped;
  clipped.camera(cam);
  clipped.set("depth_kind", "radial");
  clipped.set("clip_end", near_clip);
  clipped.image("depth", wall, w, h, 1);
  clipped.image("ao", ao, w, h, 1);
  ASSERT_EQ(ssao_job_auto_radius(clipped.get(), &radius), SSAO_OK) << ssao_last_error();
  EXPECT_NEAR(radius, 0.1 * 5.0 * cam.sensor / cam.lens, 1e-4);
  ASSERT_EQ(clipped.run(), SSAO_OK) << ssao_last_error();
  ASSERT_EQ(ssao_job_last_run(clipped.get(), &geometry, &mean), SSAO_OK);
  EXPECT_EQ(geometry, wall.size());

  // A window counts its own pixels only (planar depth now: the camera describes the window, so
  // the radial values above no longer fit it); a failed run leaves nothing to report.
  job.set("depth_kind", "planar");
  job.set("clip_end", 0.0);
  std::vector<float> small(size_t(10) * 10, -1.0f);
  job.image("ao", small, 10, 10, 1);
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, 20, 20), SSAO_OK);
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  ASSERT_EQ(ssao_job_last_run(job.get(), &geometry, &mean), SSAO_OK);
  size_t window_geometry = 0;
  for (int y = 20; y < 30; ++y) {
    for (int x = 20; x < 30; ++x) window_geometry += (size_t(y) * w + x) % 11 > 3;
  }
  EXPECT_EQ(geometry, window_geometry);
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, w, h), SSAO_OK);
  EXPECT_NE(job.run(), SSAO_OK);
  EXPECT_EQ(ssao_job_last_run(job.get(), &geometry, &mean), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_EQ(ssao_job_last_run(job.get(), nullptr, &mean), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Api, OneCameraContractForAnyRenderer) {
  // The same camera given three ways (Blender's lens and sensor with a lens shift, pinhole
  // intrinsics, an OpenGL projection matrix) must give the same AO, perspective and
  // orthographic. The scene is built from the analytic camera (no shift); the shift moves the
  // image, so the AO differs from the unshifted run but not between the three forms.
  for (const bool ortho : {false, true}) {
    Camera cam;
    cam.ortho = ortho;
    Scene s = floor_and_wall(cam);
    const double w = cam.width, h = cam.height, shift_x = 0.1, shift_y = -0.05;
    // Pixels per unit at depth 1 (perspective) or per scene unit (orthographic), the sensor
    // spanning the width (AUTO fit of a landscape image).
    const double f = ortho ? w / cam.ortho_scale : w * cam.lens / cam.sensor;
    const double cx = w / 2 - shift_x * w, cy = h / 2 + shift_y * w;
    const std::vector<double> intrinsics = {f, f, cx, cy};
    std::vector<double> matrix(16, 0.0);
    matrix[0] = 2 * f / w, matrix[5] = 2 * f / h;
    if (ortho) {
      matrix[3] = 1 - 2 * cx / w, matrix[7] = 2 * cy / h - 1;
      matrix[10] = -0.01, matrix[15] = 1;
    } else {
      matrix[2] = 1 - 2 * cx / w, matrix[6] = 2 * cy / h - 1;
      matrix[10] = -1.001, matrix[11] = -0.2, matrix[14] = -1;
    }
    const auto run = [&](const std::function<void(Job&)>& camera) {
      return compute_ao(s, cam, 0.5, "hemisphere", true, camera);
    };
    const std::vector<float> lens = run([&](Job& j) {
      j.set("shift_x", shift_x);
      j.set("shift_y", shift_y);
    });
    const std::vector<float> pinhole = run([&](Job& j) {
      j.set("projection", "intrinsics");
      j.set("intrinsics", intrinsics);
    });
    const std::vector<float> opengl = run([&](Job& j) {
      j.set("projection", "matrix");
      j.set("projection_matrix", matrix);
    });
    const std::vector<float> unshifted = run(nullptr);
    float worst_pinhole = 0.0f, worst_matrix = 0.0f, shift_effect = 0.0f;
    for (size_t i = 0; i < lens.size(); ++i) {
      worst_pinhole = std::max(worst_pinhole, std::fabs(pinhole[i] - lens[i]));
      worst_matrix = std::max(worst_matrix, std::fabs(opengl[i] - lens[i]));
      shift_effect = std::max(shift_effect, std::fabs(unshifted[i] - lens[i]));
    }
    EXPECT_LE(worst_pinhole, 1e-4f) << (ortho ? "ortho" : "persp");
    EXPECT_LE(worst_matrix, 1e-4f) << (ortho ? "ortho" : "persp");
    // Perspective: the shift turns the rays, so it must show (orthographic: a translation).
    if (!ortho) {
      EXPECT_GT(shift_effect, 1e-3f) << "the shift must matter for the test to mean much";
    }
  }

  // Unset intrinsics, and matrices of another shape, are refused with the parameter's name.
  Camera cam;
  Scene s = floor_and_wall(cam);
  std::vector<float> ao(s.depth.size());
  Job job;
  job.image("depth", s.depth, cam.width, cam.height, 1);
  job.image("ao", ao, cam.width, cam.height, 1);
  job.set("projection", "intrinsics");
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "intrinsics")) << ssao_last_error();
  job.set("projection", "matrix");
  std::vector<double> skewed = {1, 0.3, 0, 0, 0, 1, 0, 0, 0, 0, -1, -0.2, 0, 0, -1, 0};
  job.set("projection_matrix", skewed);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(ssao_last_error(), "projection_matrix")) << ssao_last_error();
  std::vector<double> affine_last_row = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0.5, 1};
  job.set("projection_matrix", affine_last_row);
  EXPECT_EQ(job.run(), SSAO_ERROR_INVALID_ARGUMENT);
  // The groups partition the table; the camera contract is in "camera".
  size_t camera_params = 0;
  for (size_t i = 0; i < ssao_param_count(); ++i) {
    const char* group = nullptr;
    ASSERT_EQ(ssao_param_group(i, &group), SSAO_OK);
    ssao_param_desc desc;
    ASSERT_EQ(ssao_param_info(i, &desc), SSAO_OK);
    const std::string name = desc.name, g = group;
    EXPECT_TRUE(g == "ao" || g == "quality" || g == "shaping" || g == "input" || g == "camera" ||
                g == "execution")
        << name << ": " << g;
    if (name == "projection" || name == "intrinsics" || name == "lens") {
      EXPECT_EQ(g, "camera") << name;
    }
    camera_params += g == "camera";
  }
  EXPECT_GE(camera_params, 16u);
  const char* group = nullptr;
  EXPECT_EQ(ssao_param_group(ssao_param_count(), &group), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_param_group(0, nullptr), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Api, StrengthPowerAndRemapShapeTheResult) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const auto raw = compute_ao(s, cam, 1.0, "hemisphere");
  const auto none =
      compute_ao(s, cam, 1.0, "hemisphere", true, [](Job& j) { j.set("strength", 0.0); });
  const auto shaped = compute_ao(s, cam, 1.0, "hemisphere", true, [](Job& j) {
    j.set("power", 2.0);
    j.set("strength", 0.5);
    j.set("remap_min", 0.1);
    j.set("remap_max", 0.6);
  });
  for (size_t i = 0; i < raw.size(); ++i) {
    EXPECT_EQ(none[i], 1.0f);
    if (!std::isfinite(s.depth[i])) continue;
    const float expected = 0.1f + 0.5f * (1.0f - 0.5f * (1.0f - raw[i] * raw[i]));
    EXPECT_NEAR(shaped[i], expected, 1e-6f);
  }
}

namespace {
struct ProgressLog {
  std::vector<double> values;
  int cancel_after = -1;
};
int record_progress(void* user, double fraction) {
  auto* log = static_cast<ProgressLog*>(user);
  log->values.push_back(fraction);
  return log->cancel_after >= 0 && int(log->values.size()) > log->cancel_after ? 0 : 1;
}
}  // namespace

TEST(Api, ProgressIsMonotoneAndCancelLeavesOutputsUntouched) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  std::vector<float> ao(s.depth.size(), -1.0f);
  Job job;
  job.camera(cam);
  job.set("threads", 2);
  job.image("depth", s.depth, s.width, s.height, 1);
  job.image("ao", ao, s.width, s.height, 1);
  ProgressLog log;
  ASSERT_EQ(ssao_job_set_progress(job.get(), record_progress, &log), SSAO_OK);
  ASSERT_EQ(job.run(), SSAO_OK);
  ASSERT_GT(log.values.size(), 3u);
  for (size_t i = 1; i < log.values.size(); ++i) EXPECT_GE(log.values[i], log.values[i - 1]);
  EXPECT_EQ(log.values.back(), 1.0);

  std::vector<float> untouched(s.depth.size(), -1.0f);
  job.image("ao", untouched, s.width, s.height, 1);
  ProgressLog cancel;
  cancel.cancel_after = 3;
  ASSERT_EQ(ssao_job_set_progress(job.get(), record_progress, &cancel), SSAO_OK);
  EXPECT_EQ(job.run(), SSAO_ERROR_CANCELLED);
  for (float v : untouched) ASSERT_EQ(v, -1.0f);
}

TEST(Api, ErrorMessagesArePerThread) {
  Job job;
  ASSERT_EQ(ssao_job_set_float(job.get(), "nope", 1.0), SSAO_ERROR_INVALID_ARGUMENT);
  std::string other;
  std::thread t([&] { other = ssao_last_error(); });
  t.join();
  EXPECT_EQ(other, "");
  EXPECT_TRUE(contains(ssao_last_error(), "nope"));
}

TEST(Api, WorldSpaceNormalsUseTheCameraMatrix) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  const auto view = compute_ao(s, cam, 1.0, "hemisphere");
  // Camera rotated 90 degrees about world Z: view-space n = R^T n_world, so world = R n_view.
  const double m[16] = {0, -1, 0, 3, 1, 0, 0, -2, 0, 0, 1, 1, 0, 0, 0, 1};
  std::vector<float> world(s.normal.size());
  for (size_t i = 0; i < world.size(); i += 3) {
    for (int r = 0; r < 3; ++r) {
      world[i + r] = float(m[r * 4 + 0] * s.normal[i] + m[r * 4 + 1] * s.normal[i + 1] +
                           m[r * 4 + 2] * s.normal[i + 2]);
    }
  }
  std::swap(world, s.normal);
  const auto from_world = compute_ao(s, cam, 1.0, "hemisphere", true, [&](Job& j) {
    j.set("normal_space", "world");
    EXPECT_EQ(ssao_job_set_floats(j.get(), "camera_to_world", m, 16), SSAO_OK);
  });
  for (size_t i = 0; i < view.size(); ++i) EXPECT_NEAR(from_world[i], view[i], 1e-5f);
}

TEST(Api, SingularCameraMatrixIsRefusedOnlyWhenWorldNormalsNeedIt) {
  const Camera cam;
  Scene s = floor_and_wall(cam);
  // Two parallel axes: world-space normals would be flattened into wrong ones.
  const double singular[16] = {1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (const char* space : {"world", "camera"}) {
    for (const bool with_normals : {true, false}) {
      Job job;
      job.camera(cam);
      job.set("normal_space", space);
      ASSERT_EQ(ssao_job_set_floats(job.get(), "camera_to_world", singular, 16), SSAO_OK);
      std::vector<float> ao(s.depth.size(), -1.0f);
      job.image("depth", s.depth, s.width, s.height, 1);
      if (with_normals) job.image("normal", s.normal, s.width, s.height, 3);
      job.image("ao", ao, s.width, s.height, 1);
      const bool needed = with_normals && std::string(space) == "world";
      EXPECT_EQ(job.run(), needed ? SSAO_ERROR_INVALID_ARGUMENT : SSAO_OK) << space;
      if (needed) {
        EXPECT_NE(std::string(ssao_last_error()).find("singular"), std::string::npos);
        EXPECT_EQ(ao, std::vector<float>(s.depth.size(), -1.0f)) << "outputs touched";
      }
    }
  }
  // A scaled camera (scale 1e-3) is not singular.
  const double scaled[16] = {1e-3, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 1e-3, 0, 0, 0, 0, 1};
  const auto view = compute_ao(s, cam, 1.0, "hemisphere");
  const auto world = compute_ao(s, cam, 1.0, "hemisphere", true, [&](Job& j) {
    j.set("normal_space", "world");
    EXPECT_EQ(ssao_job_set_floats(j.get(), "camera_to_world", scaled, 16), SSAO_OK);
  });
  for (size_t i = 0; i < view.size(); ++i) EXPECT_NEAR(world[i], view[i], 1e-5f);
}
