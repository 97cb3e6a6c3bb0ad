/* SPDX-License-Identifier: MIT
 * libssao's C++ wrapper, header-only over the stable C API (ssao/ssao.h): ssao::api::Job owns an
 * ssao_job, and every call throws ssao::api::Error, carrying the status and ssao_last_error(),
 * when the library does not return SSAO_OK. It adds no symbol to the library's ABI. */
#ifndef SSAO_SSAO_HPP
#define SSAO_SSAO_HPP

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ssao/ssao.h"

namespace ssao {
namespace api {

// The error raised for a non-OK status: its status code is kept for callers that care.
class Error : public std::runtime_error {
 public:
  Error(ssao_status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  ssao_status status() const { return status_; }

 private:
  ssao_status status_;
};

// Throws Error("<what>: <ssao_last_error()>") unless status is SSAO_OK.
inline void check_status(ssao_status status, const std::string& what) {
  if (status == SSAO_OK) return;
  std::string detail = ssao_last_error();
  if (detail.empty()) detail = ssao_status_string(status);
  throw Error(status, what.empty() ? detail : what + ": " + detail);
}

// The group of parameter number `index` (ssao_param_group): "ao", "quality", "shaping",
// "input", "camera" or "execution".
inline std::string param_group(size_t index) {
  const char* group = nullptr;
  check_status(ssao_param_group(index, &group), "");
  return group;
}

// Every parameter of the core, in table order.
inline std::vector<ssao_param_desc> param_table() {
  std::vector<ssao_param_desc> table(ssao_param_count());
  for (size_t i = 0; i < table.size(); ++i) check_status(ssao_param_info(i, &table[i]), "");
  return table;
}

// "0.1.0" from ssao_version().
inline std::string version_string(int version) {
  return std::to_string(version / 10000) + "." + std::to_string(version / 100 % 100) + "." +
         std::to_string(version % 100);
}

class Job {
 public:
  Job() { check_status(ssao_job_create(&job_), "cannot create an SSAO job"); }
  ~Job() { ssao_job_destroy(job_); }
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;
  Job(Job&& other) noexcept : job_(std::exchange(other.job_, nullptr)) {}
  Job& operator=(Job&& other) noexcept {
    std::swap(job_, other.job_);
    return *this;
  }

  ssao_job get() const { return job_; }

  void set(const std::string& name, int value) {
    check_status(ssao_job_set_int(job_, name.c_str(), value), "parameter " + name);
  }
  void set(const std::string& name, double value) {
    check_status(ssao_job_set_float(job_, name.c_str(), value), "parameter " + name);
  }
  void set(const std::string& name, const std::string& value) {
    check_status(ssao_job_set_string(job_, name.c_str(), value.c_str()), "parameter " + name);
  }
  void set(const std::string& name, const char* value) { set(name, std::string(value)); }
  void set(const std::string& name, const std::vector<double>& values) {
    check_status(ssao_job_set_floats(job_, name.c_str(), values.data(), values.size()),
                 "parameter " + name);
  }

  int get_int(const std::string& name) const {
    int value = 0;
    check_status(ssao_job_get_int(job_, name.c_str(), &value), "parameter " + name);
    return value;
  }
  double get_float(const std::string& name) const {
    double value = 0.0;
    check_status(ssao_job_get_float(job_, name.c_str(), &value), "parameter " + name);
    return value;
  }
  std::vector<double> get_floats(const std::string& name, size_t count) const {
    std::vector<double> values(count);
    check_status(ssao_job_get_floats(job_, name.c_str(), values.data(), count),
                 "parameter " + name);
    return values;
  }
  std::string get_string(const std::string& name) const {
    char buffer[256] = {};
    check_status(ssao_job_get_string(job_, name.c_str(), buffer, sizeof buffer),
                 "parameter " + name);
    return buffer;
  }

  // The core's automatic radius for the attached depth and the camera (ssao_job_auto_radius).
  double auto_radius() const {
    double radius = 0.0;
    check_status(ssao_job_auto_radius(job_, &radius), "automatic radius");
    return radius;
  }
  // The camera of a camera file's text (ssao_job_set_camera_json); `source` names it in messages,
  // which carry their own context.
  void set_camera_json(const std::string& text, const std::string& source) {
    check_status(ssao_job_set_camera_json(job_, text.data(), text.size(), source.c_str()), "");
  }
  // The keys of the last camera file that the format does not know.
  std::vector<std::string> camera_unknown_keys() const {
    char buffer[4096] = {};
    check_status(ssao_job_camera_unknown_keys(job_, buffer, sizeof buffer), "camera file");
    std::vector<std::string> keys;
    std::string key;
    for (const char* c = buffer;; ++c) {
      if (*c == ',' || *c == '\0') {
        if (!key.empty()) keys.push_back(key);
        key.clear();
        if (*c == '\0') break;
      } else {
        key += *c;
      }
    }
    return keys;
  }
  bool is_set(const std::string& name) const {
    int set = 0;
    check_status(ssao_job_is_set(job_, name.c_str(), &set), "parameter " + name);
    return set != 0;
  }
  // The radius rule without a radius from the user (ssao_job_choose_radius): the radius and
  // where it came from.
  std::pair<double, ssao_radius_source> choose_radius(bool allow_automatic) {
    double radius = 0.0;
    ssao_radius_source source = SSAO_RADIUS_SET;
    check_status(ssao_job_choose_radius(job_, allow_automatic ? 1 : 0, &radius, &source), "");
    return {radius, source};
  }
  // What a run would get wrong without a word (ssao_job_check_inputs).
  void check_inputs() const { check_status(ssao_job_check_inputs(job_), ""); }

  // "hemisphere, quality medium" plus any count set explicitly (", 16 samples"): what the
  // front ends print about a run (a count left at 0 comes from the quality preset).
  std::string settings_summary() const {
    std::string out = get_string("variant") + ", quality " + get_string("quality");
    for (const char* count : {"samples", "slices", "steps"}) {
      const int value = get_int(count);
      if (value > 0) out += ", " + std::to_string(value) + " " + count;
    }
    return out;
  }

  // Attaches a caller-owned image (see ssao_job_set_image); strides in bytes, 0 = packed.
  void set_image(const std::string& name, float* data, int width, int height, int channels,
                 std::ptrdiff_t pixel_stride = 0, std::ptrdiff_t row_stride = 0) {
    check_status(ssao_job_set_image(job_, name.c_str(), data, width, height, channels, pixel_stride,
                                    row_stride),
                 "image " + name);
  }
  // Overscan: the outputs are the window at (x, y) of the input images
  // (ssao_job_set_output_window).
  void set_output_window(bool enable, int x, int y) {
    check_status(ssao_job_set_output_window(job_, enable ? 1 : 0, x, y), "output window");
  }
  void set_progress(ssao_progress_fn fn, void* user) {
    check_status(ssao_job_set_progress(job_, fn, user), "progress callback");
  }
  void run() { check_status(ssao_job_run(job_), "SSAO failed"); }

  // What the last run saw over the frame (ssao_job_last_run).
  struct RunStats {
    size_t geometry_pixels = 0;
    double mean_ao = 1.0;
  };
  RunStats last_run() const {
    RunStats stats;
    check_status(ssao_job_last_run(job_, &stats.geometry_pixels, &stats.mean_ao), "last run");
    return stats;
  }

 private:
  ssao_job job_ = nullptr;
};

}  // namespace api
}  // namespace ssao

#endif /* SSAO_SSAO_HPP */
