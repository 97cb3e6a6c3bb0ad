// SPDX-License-Identifier: MIT
// The front ends' rules behind the C API: the camera file's one reader
// (ssao_job_set_camera_json), the radius rule (ssao_job_choose_radius) and the check of the
// inputs (ssao_job_check_inputs), which the CLI, the evaluation tools and the Python module
// call instead of writing them again.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "ssao/ssao.hpp"

namespace {

using ssao::api::Job;

const char* const kBlenderCamera = R"({"type": "PERSP", "lens": 35.0, "sensor_width": 36.0,
  "sensor_height": 24.0, "sensor_fit": "AUTO", "shift_x": 0.1, "shift_y": 0.0,
  "clip_start": 0.1, "clip_end": 100.0,
  "matrix_world": [[1, 0, 0, 2], [0, 1, 0, 3], [0, 0, 1, 4], [0, 0, 0, 1]]})";

// `text` (a camera file) with `key` set to `value` (JSON text), or removed when value is null.
std::string edited(std::string text, const std::string& key, const char* value) {
  const std::string quoted = "\"" + key + "\": ";
  const size_t at = text.find(quoted);
  if (at == std::string::npos) {
    return value ? "{\"" + key + "\": " + value + ", " + text.substr(1) : text;
  }
  size_t end = at + quoted.size();
  int depth = 0;
  while (end < text.size() && (depth > 0 || (text[end] != ',' && text[end] != '}'))) {
    depth += text[end] == '[' ? 1 : text[end] == ']' ? -1 : 0;
    ++end;
  }
  if (value) return text.substr(0, at) + quoted + value + text.substr(end);
  if (text[end] == ',') return text.substr(0, at) + text.substr(end + 1);  // and its comma
  const size_t comma = text.rfind(',', at);  // the last key: the comma before it
  return text.substr(0, comma) + text.substr(end);
}

std::string camera_with(const std::string& key, const char* value) {
  return edited(kBlenderCamera, key, value);
}

ssao_status set_camera(Job& job, const std::string& text) {
  return ssao_job_set_camera_json(job.get(), text.data(), text.size(), "shot.camera.json");
}

}  // namespace

TEST(CameraFile, SetsTheCameraItHoldsAndOnlyThat) {
  Job job;
  ASSERT_EQ(set_camera(job, kBlenderCamera), SSAO_OK) << ssao_last_error();
  EXPECT_EQ(job.get_float("lens"), 35.0);
  EXPECT_EQ(job.get_float("shift_x"), 0.1);
  EXPECT_EQ(job.get_float("clip_end"), 100.0);
  const std::vector<double> matrix = job.get_floats("camera_to_world", 16);
  EXPECT_EQ(matrix[3], 2.0);
  EXPECT_EQ(matrix[7], 3.0);
  EXPECT_EQ(matrix[11], 4.0);
  for (const char* given :
       {"camera_type", "lens", "sensor_width", "sensor_fit", "clip_end", "camera_to_world"}) {
    EXPECT_TRUE(job.is_set(given)) << given;
  }
  for (const char* absent :
       {"ortho_scale", "pixel_aspect_x", "projection", "intrinsics", "radius"}) {
    EXPECT_FALSE(job.is_set(absent)) << absent;
  }
  EXPECT_TRUE(job.camera_unknown_keys().empty());
}

TEST(CameraFile, RefusesWhatTheFormatForbidsAndLeavesTheJobAsItWas) {
  struct Case {
    std::string text;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"", "malformed JSON"},
      {std::string(kBlenderCamera) + '\0' + "}", "it holds a NUL byte"},
      {"[1, 2]", "expected a JSON object, got an array"},
      {"{\"type\": \"PERSP\",", "malformed JSON"},
      {camera_with("type", nullptr), "missing key 'type'"},
      {camera_with("lens", nullptr), "missing key 'lens'"},
      {camera_with("sensor_width", nullptr), "missing key 'sensor_width'"},
      {camera_with("sensor_fit", nullptr), "missing key 'sensor_fit'"},
      {camera_with("shift_y", nullptr), "missing key 'shift_y'"},
      {camera_with("type", "\"ORTHO\""), "missing key 'ortho_scale'"},
      {camera_with("type", "\"FISHEYE\""), "key 'type' must be one of PERSP|ORTHO"},
      {camera_with("type", "1"), "key 'type' must be a string, got a number"},
      {camera_with("lens", "0"), "key 'lens' must be positive, got 0"},
      {camera_with("lens", "\"35\""), "key 'lens' must be a number, got a string"},
      {camera_with("lens", "true"), "key 'lens' must be a number, got a boolean"},
      {camera_with("lens", "1e999"), "out of range"},
      {camera_with("lens", "2e9"), "lens: parameter 'lens' must be in"},  // the library's range
      {camera_with("clip_end", "0"), "key 'clip_end' must be positive"},
      {camera_with("clip_start", "-1"), "key 'clip_start' must not be negative"},
      {camera_with("ao_distance", "-2"), "key 'ao_distance' must be positive"},
      {camera_with("matrix_world", "[[1, 0, 0, 0]]"), "key 'matrix_world' must be a 4x4 matrix"},
      {camera_with("matrix_world", "[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]"),
       "must be an affine transform"},
      {camera_with("matrix_world", "[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,\"1\"]]"),
       "key 'matrix_world[3][3]' must be a number"},
      {camera_with("projection", "\"pinhole\""), "key 'projection' must be one of"},
      {camera_with("projection", "\"intrinsics\""), "missing key 'intrinsics'"},
      {camera_with("intrinsics", "[100, 100, 120]"), "key 'intrinsics' must be an array of 4"},
      {"{\"projection\": \"matrix\"}", "missing key 'projection_matrix'"},
  };
  for (const Case& c : cases) {
    Job job;
    job.set("lens", 80.0);
    const ssao_status status = set_camera(job, c.text);
    EXPECT_EQ(status, SSAO_ERROR_INVALID_ARGUMENT) << c.text;
    const std::string message = ssao_last_error();
    EXPECT_NE(message.find("camera file 'shot.camera.json'"), std::string::npos) << message;
    EXPECT_NE(message.find(c.message), std::string::npos) << c.message << " in: " << message;
    EXPECT_EQ(job.get_float("lens"), 80.0) << "a refused file changed the job: " << c.text;
    EXPECT_TRUE(job.is_set("lens"));
    EXPECT_FALSE(job.is_set("camera_type"));
  }
}

TEST(CameraFile, OnlyTheKeysTheProjectionReadsAreRequired) {
  const std::vector<std::string> accepted = {
      edited(camera_with("sensor_width", nullptr), "sensor_fit", "\"VERTICAL\""),
      edited(camera_with("lens", nullptr), "type", "\"ORTHO\"").insert(1, "\"ortho_scale\": 6, "),
      R"({"projection": "intrinsics", "type": "PERSP", "intrinsics": [100, 100, 120, 67.5]})",
      R"({"projection": "matrix", "projection_matrix": [[1, 0, 0, 0], [0, 1, 0, 0],
          [0, 0, -1, -0.2], [0, 0, -1, 0]]})",
  };
  for (const std::string& text : accepted) {
    Job job;
    EXPECT_EQ(set_camera(job, text), SSAO_OK) << text << ": " << ssao_last_error();
  }
}

TEST(CameraFile, DescribesTheWholeCamera) {
  // A second file does not inherit what the first set: the CLI reuses one job for a sequence.
  Job job;
  ASSERT_EQ(set_camera(job, camera_with("pixel_aspect_x", "2.0")), SSAO_OK) << ssao_last_error();
  EXPECT_EQ(job.get_float("pixel_aspect_x"), 2.0);
  ASSERT_EQ(set_camera(job, camera_with("matrix_world", nullptr)), SSAO_OK);
  EXPECT_EQ(job.get_float("pixel_aspect_x"), 1.0);
  EXPECT_FALSE(job.is_set("pixel_aspect_x"));
  EXPECT_FALSE(job.is_set("camera_to_world"));
  EXPECT_EQ(job.get_floats("camera_to_world", 16)[3], 0.0);  // the identity again
  job.set("radius", 0.5);                                    // not a camera parameter: kept
  ASSERT_EQ(set_camera(job, kBlenderCamera), SSAO_OK);
  EXPECT_TRUE(job.is_set("radius"));
}

TEST(CameraFile, ListsTheKeysItDoesNotKnow) {
  Job job;
  ASSERT_EQ(set_camera(job, camera_with("focus", "3").insert(1, "\"dof\": true, ")), SSAO_OK);
  EXPECT_EQ(job.camera_unknown_keys(), (std::vector<std::string>{"dof", "focus"}));
  char small[5];
  ASSERT_EQ(ssao_job_camera_unknown_keys(job.get(), small, sizeof small), SSAO_OK);
  EXPECT_STREQ(small, "dof,");
  EXPECT_EQ(ssao_job_camera_unknown_keys(job.get(), nullptr, 4), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_camera_json(job.get(), nullptr, 0, "x"), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(ssao_job_set_camera_json(nullptr, kBlenderCamera, 10, "x"),
            SSAO_ERROR_INVALID_ARGUMENT);
  // Without a source the messages say "camera".
  EXPECT_EQ(ssao_job_set_camera_json(job.get(), "{", 1, nullptr), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "camera file 'camera'"), nullptr);
}

TEST(RadiusRule, SetThenCameraFileThenAutomatic) {
  const int w = 16, h = 8;
  std::vector<float> depth(size_t(w) * h, 4.0f);
  Job job;
  ASSERT_EQ(set_camera(job, kBlenderCamera), SSAO_OK);
  job.set_image("depth", depth.data(), w, h, 1);
  double radius = 0.0;
  ssao_radius_source source = SSAO_RADIUS_SET;
  ASSERT_EQ(ssao_job_choose_radius(job.get(), 1, &radius, &source), SSAO_OK);
  EXPECT_EQ(source, SSAO_RADIUS_AUTOMATIC);
  EXPECT_EQ(radius, job.auto_radius());
  EXPECT_EQ(job.get_float("radius"), radius);
  EXPECT_FALSE(job.is_set("radius"));  // chosen, not set: chosen again next time
  EXPECT_EQ(ssao_job_choose_radius(job.get(), 0, nullptr, nullptr), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_NE(std::strstr(ssao_last_error(), "ao_distance"), nullptr);

  ASSERT_EQ(set_camera(job, camera_with("ao_distance", "0.75")), SSAO_OK);
  ASSERT_EQ(ssao_job_choose_radius(job.get(), 0, &radius, &source), SSAO_OK);
  EXPECT_EQ(source, SSAO_RADIUS_CAMERA_FILE);
  EXPECT_EQ(radius, 0.75);
  ASSERT_EQ(set_camera(job, camera_with("ao_distance", "1.25")), SSAO_OK);
  EXPECT_EQ(job.choose_radius(false).first, 1.25);  // the new file's, not the last choice

  job.set("radius", 0.3);
  EXPECT_EQ(job.choose_radius(true), std::make_pair(0.3, SSAO_RADIUS_SET));

  // Without a geometry pixel the automatic rule has no depth to go by.
  Job sky;
  std::vector<float> nothing(size_t(w) * h, HUGE_VALF);
  sky.set_image("depth", nothing.data(), w, h, 1);
  EXPECT_EQ(ssao_job_choose_radius(sky.get(), 1, &radius, nullptr), SSAO_ERROR_INVALID_OPERATION);
  EXPECT_NE(std::strstr(ssao_last_error(), "no geometry pixel"), nullptr);
}

TEST(InputCheck, WorldNormalsNeedTheCameraMatrix) {
  const int w = 4, h = 4;
  std::vector<float> depth(size_t(w) * h, 2.0f), normal(size_t(w) * h * 3, 0.0f);
  for (size_t i = 2; i < normal.size(); i += 3) normal[i] = 1.0f;
  Job job;
  job.set_image("depth", depth.data(), w, h, 1);
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_OK);  // no normal pass: nothing to turn
  job.set_image("normal", normal.data(), w, h, 3);
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::strstr(ssao_last_error(), "missing key 'matrix_world'"), nullptr);
  ASSERT_EQ(set_camera(job, camera_with("matrix_world", nullptr)), SSAO_OK);
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_ERROR_INVALID_ARGUMENT);
  job.set("normal_space", "camera");
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_OK);
  job.set("normal_space", "world");
  ASSERT_EQ(set_camera(job, kBlenderCamera), SSAO_OK);
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_OK);
  ASSERT_EQ(set_camera(job, camera_with("matrix_world", nullptr)), SSAO_OK);
  job.set("camera_to_world", std::vector<double>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
  EXPECT_EQ(ssao_job_check_inputs(job.get()), SSAO_OK);  // the identity, given on purpose
  EXPECT_EQ(ssao_job_check_inputs(nullptr), SSAO_ERROR_INVALID_ARGUMENT);
}
