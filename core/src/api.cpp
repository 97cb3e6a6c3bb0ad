// SPDX-License-Identifier: MIT
// The C boundary: every entry point checks its handle, calls into C++, and turns exceptions into
// a status plus a per-thread message. Nothing else in the library knows about C.
#include <algorithm>
#include <cstring>
#include <new>
#include <string>
#include <string_view>

#include "error.h"
#include "job.h"
#include "params.h"
#include "ssao/ssao.h"
#include "variants/variant.h"

namespace {

// A plain array, not a std::string: no destructor for MinGW's emulated TLS to run at thread
// exit. Under Wine 8, with a std::string, tests/unit/test_concurrency.cpp's error test run 10
// times in one process hung at exit in 12 of 60 processes and once in 300 rounds a thread read
// another's message; with the array, 0 of 100 and 0 of 1000. Longer messages end in "...".
constexpr size_t kLastErrorSize = 4096;
thread_local char last_error[kLastErrorSize];

// A C string of at most size - 1 characters (size > 0).
void copy_truncated(std::string_view value, char* out, size_t size) {
  const size_t n = std::min(size - 1, value.size());
  std::memcpy(out, value.data(), n);
  out[n] = '\0';
}

ssao_status fail(ssao_status status, std::string_view message) {
  copy_truncated(message, last_error, kLastErrorSize);
  if (message.size() >= kLastErrorSize) std::memcpy(last_error + kLastErrorSize - 4, "...", 4);
  return status;
}

template <typename Fn>
ssao_status guarded(Fn&& fn) {
  try {
    fn();
    return SSAO_OK;
  } catch (const ssao::Error& e) {
    return fail(e.status(), e.what());
  } catch (const std::bad_alloc&) {
    return fail(SSAO_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(SSAO_ERROR_INTERNAL, e.what());
  } catch (...) {
    return fail(SSAO_ERROR_INTERNAL, "unknown internal error");
  }
}

ssao::Job& checked(ssao_job job) {
  if (job == nullptr) ssao::throw_invalid_argument("job handle is NULL");
  return *job;
}

}  // namespace

extern "C" {

SSAO_API int ssao_version(void) { return SSAO_VERSION; }

SSAO_API const char* ssao_status_string(ssao_status status) {
  switch (status) {
    case SSAO_OK:
      return "success";
    case SSAO_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case SSAO_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case SSAO_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case SSAO_ERROR_CANCELLED:
      return "cancelled";
    case SSAO_ERROR_INTERNAL:
      return "internal error";
  }
  return "unknown status";
}

SSAO_API const char* ssao_last_error(void) { return last_error; }

SSAO_API size_t ssao_param_count(void) { return ssao::param_count(); }

SSAO_API ssao_status ssao_param_info(size_t index, ssao_param_desc* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = ssao::param_desc(index);
  });
}

SSAO_API ssao_status ssao_param_group(size_t index, const char** group) {
  return guarded([&] {
    if (group == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *group = ssao::param_group(index);
  });
}

SSAO_API size_t ssao_variant_count(void) { return ssao::variant_registry().size(); }

SSAO_API ssao_status ssao_variant_info(size_t index, ssao_variant_desc* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    const auto& variants = ssao::variant_registry();
    if (index >= variants.size()) {
      ssao::throw_invalid_argument("variant index " + std::to_string(index) + " out of range (" +
                                   std::to_string(variants.size()) + " variants)");
    }
    *out = {variants[index].name, variants[index].description, variants[index].parameters};
  });
}

SSAO_API ssao_status ssao_job_create(ssao_job* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = nullptr;
    *out = new ssao_job_impl();
  });
}

SSAO_API void ssao_job_destroy(ssao_job job) { delete job; }

SSAO_API ssao_status ssao_job_set_int(ssao_job job, const char* name, int value) {
  return guarded([&] { checked(job).params().set_int(name, value); });
}

SSAO_API ssao_status ssao_job_set_float(ssao_job job, const char* name, double value) {
  return guarded([&] { checked(job).params().set_float(name, value); });
}

SSAO_API ssao_status ssao_job_set_string(ssao_job job, const char* name, const char* value) {
  return guarded([&] { checked(job).params().set_string(name, value); });
}

SSAO_API ssao_status ssao_job_set_floats(ssao_job job, const char* name, const double* values,
                                         size_t count) {
  return guarded([&] { checked(job).params().set_floats(name, values, count); });
}

SSAO_API ssao_status ssao_job_get_int(ssao_job job, const char* name, int* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = checked(job).params().get_int(name);
  });
}

SSAO_API ssao_status ssao_job_get_float(ssao_job job, const char* name, double* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = checked(job).params().get_float(name);
  });
}

SSAO_API ssao_status ssao_job_get_string(ssao_job job, const char* name, char* out, size_t size) {
  return guarded([&] {
    if (out == nullptr || size == 0) ssao::throw_invalid_argument("output buffer is NULL or empty");
    copy_truncated(checked(job).params().get_string(name), out, size);
  });
}

SSAO_API ssao_status ssao_job_get_floats(ssao_job job, const char* name, double* out,
                                         size_t count) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    const std::vector<double>& values = checked(job).params().get_floats(name);
    if (count != values.size()) {
      ssao::throw_invalid_argument(std::string("parameter '") + name + "' has " +
                                   std::to_string(values.size()) + " values, not " +
                                   std::to_string(count));
    }
    std::copy(values.begin(), values.end(), out);
  });
}

SSAO_API ssao_status ssao_job_set_image(ssao_job job, const char* name, float* data, int width,
                                        int height, int channels, ptrdiff_t pixel_stride,
                                        ptrdiff_t row_stride) {
  return guarded([&] {
    checked(job).set_image(name, data, width, height, channels, pixel_stride, row_stride);
  });
}

SSAO_API ssao_status ssao_job_set_progress(ssao_job job, ssao_progress_fn fn, void* user) {
  return guarded([&] { checked(job).set_progress(fn, user); });
}

SSAO_API ssao_status ssao_job_set_output_window(ssao_job job, int enable, int x, int y) {
  return guarded([&] { checked(job).set_output_window(enable != 0, x, y); });
}

SSAO_API ssao_status ssao_job_auto_radius(ssao_job job, double* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = checked(job).auto_radius();
  });
}

SSAO_API ssao_status ssao_job_run(ssao_job job) {
  return guarded([&] { checked(job).run(); });
}

SSAO_API ssao_status ssao_job_last_run(ssao_job job, size_t* geometry_pixels, double* mean_ao) {
  return guarded([&] {
    if (geometry_pixels == nullptr || mean_ao == nullptr) {
      ssao::throw_invalid_argument("output pointer is NULL");
    }
    const ssao::Job::RunStats stats = checked(job).last_run();
    *geometry_pixels = stats.geometry_pixels;
    *mean_ao = stats.mean_ao;
  });
}

SSAO_API ssao_status ssao_job_set_camera_json(ssao_job job, const char* json_text, size_t length,
                                              const char* source) {
  return guarded([&] {
    if (json_text == nullptr) ssao::throw_invalid_argument("camera file text is NULL");
    checked(job).set_camera_json(std::string(json_text, length),
                                 source != nullptr ? source : "camera");
  });
}

SSAO_API ssao_status ssao_job_camera_unknown_keys(ssao_job job, char* out, size_t size) {
  return guarded([&] {
    if (out == nullptr || size == 0) ssao::throw_invalid_argument("output buffer is NULL or empty");
    std::string keys;
    for (const std::string& key : checked(job).camera_file().unknown_keys)
      keys += (keys.empty() ? "" : ",") + key;
    copy_truncated(keys, out, size);
  });
}

SSAO_API ssao_status ssao_job_is_set(ssao_job job, const char* name, int* out) {
  return guarded([&] {
    if (out == nullptr) ssao::throw_invalid_argument("output pointer is NULL");
    *out = checked(job).params().is_set(name) ? 1 : 0;
  });
}

SSAO_API ssao_status ssao_job_choose_radius(ssao_job job, int allow_automatic, double* radius,
                                            ssao_radius_source* source) {
  return guarded([&] {
    const ssao::Job::RadiusSource chosen = checked(job).choose_radius(allow_automatic != 0);
    if (radius != nullptr) *radius = job->params().get_float("radius");
    if (source != nullptr) *source = static_cast<ssao_radius_source>(chosen);
  });
}

SSAO_API ssao_status ssao_job_check_inputs(ssao_job job) {
  return guarded([&] { checked(job).check_inputs(); });
}

}  // extern "C"
