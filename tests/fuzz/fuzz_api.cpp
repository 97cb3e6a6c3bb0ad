// SPDX-License-Identifier: MIT
// libFuzzer target: the C API (ssao.h) as a hostile caller would use it. Every input sets random
// parameters (names from ssao_param_info; values in range, at and past the bounds, NaN, +-Inf,
// denormals, raw bits), attaches images of random small sizes (0, 1, odd), channel counts and
// strides (padded pixels, padded rows, negative row strides), filled with random floats or a
// random scene with NaN/Inf/denormal/huge values sprinkled in, and runs the job.
//
// Aborts (a finding) when the library
// - accepts a value outside the range ssao_param_info states, or refuses one inside it;
// - returns SSAO_ERROR_INTERNAL or SSAO_ERROR_OUT_OF_MEMORY (the images are tiny);
// - refuses a run whose set-up is valid for a reason other than the camera's;
// - writes AO that is NaN, infinite or outside [0, 1], a composite that is not beauty x AO (or
//   the ambient formula), or anything into the padding between pixels and rows;
// - changes an input image, or touches the outputs of a failed or cancelled run;
// - calls the progress callback off the calling thread or with a decreasing fraction;
// - gives a non-finite or non-positive automatic radius;
// - (when the input asks for it) gives a different result with another thread count.
// Sanitizers (ASan, UBSan) catch memory errors and undefined behaviour on the way.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "ssao/ssao.h"

namespace {

// Images stay small so that one execution takes milliseconds: the fuzzer's value is in the
// number of inputs it tries.
constexpr int kMaxPixels = 2048;
constexpr int kMaxSide = 96;

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_api: %s (last error: '%s')\n", what.c_str(), ssao_last_error());
  std::abort();
}

void check(bool ok, const std::string& what) {
  if (!ok) finding(what);
}

const std::vector<ssao_param_desc>& params() {
  static const std::vector<ssao_param_desc> table = [] {
    std::vector<ssao_param_desc> t(ssao_param_count());
    for (size_t i = 0; i < t.size(); ++i) check(ssao_param_info(i, &t[i]) == SSAO_OK, "param");
    return t;
  }();
  return table;
}

std::vector<std::string> split_choices(const char* choices) {
  std::vector<std::string> out;
  std::string current;
  for (const char* p = choices; *p != '\0'; ++p) {
    if (*p == '|') {
      out.push_back(current);
      current.clear();
    } else {
      current += *p;
    }
  }
  out.push_back(current);
  return out;
}

float bits_to_float(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
uint32_t float_bits(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}
double bits_to_double(uint64_t bits) {
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

// A parameter value from the input: often a bound or just past it, a non-finite or a denormal.
double pick_number(FuzzedDataProvider& in, const ssao_param_desc& d) {
  const double inf = std::numeric_limits<double>::infinity();
  switch (in.ConsumeIntegralInRange<int>(0, 11)) {
    case 0:
      return std::numeric_limits<double>::quiet_NaN();
    case 1:
      return inf;
    case 2:
      return -inf;
    case 3:
      return d.min_value;
    case 4:
      return d.max_value;
    case 5:
      return std::nextafter(d.min_value, -inf);
    case 6:
      return std::nextafter(d.max_value, inf);
    case 7:
      return in.ConsumeBool() ? std::numeric_limits<double>::denorm_min()
                              : -std::numeric_limits<double>::denorm_min();
    case 8:
      return bits_to_double(in.ConsumeIntegral<uint64_t>());
    case 9:
      return d.default_value;
    default: {
      const double lo = d.min_value;
      const double hi = std::isfinite(d.max_value) ? d.max_value : lo + 1e12;
      return lo + (hi - lo) * in.ConsumeProbability<double>();
    }
  }
}

bool in_range(const ssao_param_desc& d, double v) {
  const bool finite_or_allowed_inf = std::isfinite(v) || (v > 0 && std::isinf(d.max_value));
  return finite_or_allowed_inf && v >= d.min_value && v <= d.max_value;
}

// Parameters whose valid values can make a run slow: accepted values are capped afterwards
// (the capping value is itself in range), so the fuzzer still tests that the bounds are checked.
void cap_cost(ssao_job job, const char* name) {
  struct Cap {
    const char* name;
    int max;
  };
  static const Cap caps[] = {{"threads", 3}, {"samples", 64}, {"slices", 16}, {"steps", 16}};
  for (const Cap& cap : caps) {
    if (std::strcmp(name, cap.name) != 0) continue;
    int value = 0;
    check(ssao_job_get_int(job, name, &value) == SSAO_OK, "get_int after set");
    if (value > cap.max) check(ssao_job_set_int(job, name, cap.max) == SSAO_OK, "cap");
  }
}

// One parameter call with a random name, type and value; the status must agree with the table.
void set_random_parameter(FuzzedDataProvider& in, ssao_job job) {
  const auto& table = params();
  const ssao_param_desc& d = table[in.ConsumeIntegralInRange<size_t>(0, table.size() - 1)];
  const int how = in.ConsumeIntegralInRange<int>(0, 15);
  if (how == 0) {  // an unknown name, or a known name through the wrong setter
    // (Cut at a NUL, as the library sees it.)
    const std::string name = (in.ConsumeBool() ? in.ConsumeRandomLengthString(12) : d.name).c_str();
    const bool known = std::any_of(table.begin(), table.end(), [&](const ssao_param_desc& p) {
      return name == p.name && p.type == SSAO_PARAM_FLOAT;
    });
    const ssao_status s = ssao_job_set_float(job, name.c_str(), 0.5);
    if (!known) check(s == SSAO_ERROR_INVALID_ARGUMENT, "unknown/wrong-type name accepted");
    if (s != SSAO_OK) check(std::strlen(ssao_last_error()) > 0, "error without a message");
    return;
  }
  switch (d.type) {
    case SSAO_PARAM_INT: {
      // A bound, one past it, or any int.
      const int lo = static_cast<int>(d.min_value), hi = static_cast<int>(d.max_value);
      int value = in.ConsumeIntegral<int>();
      switch (in.ConsumeIntegralInRange<int>(0, 4)) {
        case 0:
          value = lo;
          break;
        case 1:
          value = hi;
          break;
        case 2:
          value = lo > std::numeric_limits<int>::min() ? lo - 1 : lo;
          break;
        case 3:
          value = hi < std::numeric_limits<int>::max() ? hi + 1 : hi;
          break;
        default:
          break;
      }
      const ssao_status s = ssao_job_set_int(job, d.name, value);
      const bool valid = value >= d.min_value && value <= d.max_value;
      check(s == (valid ? SSAO_OK : SSAO_ERROR_INVALID_ARGUMENT),
            std::string("int parameter ") + d.name + " = " + std::to_string(value) +
                (valid ? " refused" : " accepted"));
      if (s == SSAO_OK) {
        int back = 0;
        check(ssao_job_get_int(job, d.name, &back) == SSAO_OK && back == value, "int round trip");
        cap_cost(job, d.name);
      }
      break;
    }
    case SSAO_PARAM_FLOAT: {
      const double value = pick_number(in, d);
      const ssao_status s = ssao_job_set_float(job, d.name, value);
      const bool valid = in_range(d, value);
      char text[64];
      std::snprintf(text, sizeof text, "%.17g", value);
      check(s == (valid ? SSAO_OK : SSAO_ERROR_INVALID_ARGUMENT),
            std::string("float parameter ") + d.name + " = " + text +
                (valid ? " refused" : " accepted"));
      if (s == SSAO_OK) {
        double back = 0.0;
        check(ssao_job_get_float(job, d.name, &back) == SSAO_OK && back == value,
              "float round trip");
      }
      break;
    }
    case SSAO_PARAM_STRING: {
      const std::vector<std::string> choices = split_choices(d.choices);
      std::string value;
      const int kind = in.ConsumeIntegralInRange<int>(0, 5);
      if (kind == 0) {
        check(ssao_job_set_string(job, d.name, nullptr) == SSAO_ERROR_INVALID_ARGUMENT,
              "NULL string accepted");
        return;
      }
      if (kind == 1) {
        value = in.ConsumeRandomLengthString(16).c_str();
      } else {
        value = choices[in.ConsumeIntegralInRange<size_t>(0, choices.size() - 1)];
        if (kind == 2) value += 'x';  // a choice with a suffix: not a choice
        if (kind == 3 && !value.empty()) value.pop_back();
      }
      const bool valid = std::find(choices.begin(), choices.end(), value) != choices.end();
      const ssao_status s = ssao_job_set_string(job, d.name, value.c_str());
      check(s == (valid ? SSAO_OK : SSAO_ERROR_INVALID_ARGUMENT),
            std::string("string parameter ") + d.name + " = '" + value + "'" +
                (valid ? " refused" : " accepted"));
      if (s == SSAO_OK) {
        char back[64];
        check(ssao_job_get_string(job, d.name, back, sizeof back) == SSAO_OK && value == back,
              "string round trip");
      }
      break;
    }
    case SSAO_PARAM_FLOATS: {
      const size_t count = in.ConsumeIntegralInRange<int>(0, 7) == 0
                               ? in.ConsumeIntegralInRange<size_t>(0, d.count + 1)
                               : d.count;
      std::vector<double> values(std::max<size_t>(count, 1));
      const bool identity_like = in.ConsumeBool();
      bool all_finite = true;
      for (size_t k = 0; k < count; ++k) {
        if (identity_like) {
          // A rotation-like matrix with an occasional hostile element.
          values[k] = (k % 5 == 0 ? 1.0 : 0.0) + in.ConsumeFloatingPointInRange(-0.5, 0.5);
          if (in.ConsumeIntegralInRange<int>(0, 31) == 0) values[k] = pick_number(in, d);
        } else {
          values[k] = bits_to_double(in.ConsumeIntegral<uint64_t>());
        }
        all_finite = all_finite && std::isfinite(values[k]);
      }
      const ssao_status s = ssao_job_set_floats(job, d.name, values.data(), count);
      const bool valid = count == d.count && all_finite;
      check(s == (valid ? SSAO_OK : SSAO_ERROR_INVALID_ARGUMENT),
            std::string("float array ") + d.name + (valid ? " refused" : " accepted"));
      if (s == SSAO_OK) {
        std::vector<double> back(count);
        check(ssao_job_get_floats(job, d.name, back.data(), count) == SSAO_OK &&
                  std::equal(back.begin(), back.end(), values.begin()),
              "float array round trip");
      }
      break;
    }
  }
}

// Canary for the bytes between pixels and rows (a NaN with a payload nothing computes).
constexpr uint32_t kCanary = 0x7fc0dea5u;

struct Buffer {
  std::vector<float> storage;  // whole rows, padding included
  float* top = nullptr;        // the top row (the last row in memory when bottom-up)
  int width = 0, height = 0, channels = 0;
  std::ptrdiff_t pixel_stride = 0, row_stride = 0;              // resolved byte strides
  std::ptrdiff_t given_pixel_stride = 0, given_row_stride = 0;  // what set_image gets (0: packed)

  float* at(int x, int y, int c) {
    return reinterpret_cast<float*>(reinterpret_cast<char*>(top) + y * row_stride +
                                    x * pixel_stride) +
           c;
  }
  // The padding must be exactly as it was: canaries only.
  bool padding_intact() {
    std::vector<bool> used(storage.size(), false);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int c = 0; c < channels; ++c) used[size_t(at(x, y, c) - storage.data())] = true;
      }
    }
    for (size_t i = 0; i < storage.size(); ++i) {
      if (!used[i] && float_bits(storage[i]) != kCanary) return false;
    }
    return true;
  }
  std::vector<uint32_t> snapshot() const {
    std::vector<uint32_t> bits(storage.size());
    if (!storage.empty()) std::memcpy(bits.data(), storage.data(), storage.size() * sizeof(float));
    return bits;
  }
  bool equals(const std::vector<uint32_t>& bits) const {
    return bits.size() == storage.size() &&
           (storage.empty() ||
            std::memcmp(bits.data(), storage.data(), storage.size() * sizeof(float)) == 0);
  }
};

Buffer make_buffer(FuzzedDataProvider& in, int width, int height, int channels) {
  Buffer b;
  b.width = width;
  b.height = height;
  b.channels = channels;
  const int pixel_padding =
      in.ConsumeIntegralInRange<int>(0, 7) < 5 ? 0 : in.ConsumeIntegralInRange<int>(1, 2);
  const int row_padding =
      in.ConsumeIntegralInRange<int>(0, 7) < 5 ? 0 : in.ConsumeIntegralInRange<int>(1, 3);
  const bool bottom_up = in.ConsumeIntegralInRange<int>(0, 3) == 0;
  b.pixel_stride = std::ptrdiff_t(channels + pixel_padding) * 4;
  const std::ptrdiff_t row_bytes = b.pixel_stride * width + row_padding * 4;
  b.row_stride = bottom_up ? -row_bytes : row_bytes;
  b.given_pixel_stride = pixel_padding == 0 && in.ConsumeBool() ? 0 : b.pixel_stride;
  b.given_row_stride =
      row_padding == 0 && !bottom_up && b.given_pixel_stride == 0 && in.ConsumeBool()
          ? 0
          : b.row_stride;
  b.storage.assign(std::max<size_t>(1, size_t(row_bytes / 4) * size_t(height)),
                   bits_to_float(kCanary));
  b.top = b.storage.data() + (bottom_up && height > 0 ? size_t(row_bytes / 4) * (height - 1) : 0);
  return b;
}

// Pixel values: a random scene (planes and boxes at a random scale) or raw bits, with hostile
// values sprinkled in.
struct Filler {
  uint64_t state;
  int mode;          // 0: scene, 1: raw bits
  double scale;      // depth scale of the scene
  int specials;      // how many hostile values to sprinkle per image
  uint64_t next() {  // splitmix64
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float unit() { return float(next() >> 40) * (1.0f / 16777216.0f); }
};

float hostile(FuzzedDataProvider& in) {
  static const float values[] = {std::numeric_limits<float>::quiet_NaN(),
                                 std::numeric_limits<float>::infinity(),
                                 -std::numeric_limits<float>::infinity(),
                                 0.0f,
                                 -0.0f,
                                 std::numeric_limits<float>::denorm_min(),
                                 std::numeric_limits<float>::min(),
                                 std::numeric_limits<float>::max(),
                                 -std::numeric_limits<float>::max(),
                                 65504.0f,
                                 1e10f,
                                 -1.0f,
                                 1e-20f,
                                 1e20f};
  const size_t pick = in.ConsumeIntegralInRange<size_t>(0, std::size(values));
  return pick < std::size(values) ? values[pick] : bits_to_float(in.ConsumeIntegral<uint32_t>());
}

enum class Kind { depth, normal, colour };

void fill(FuzzedDataProvider& in, Filler& f, Buffer& b, Kind kind) {
  const float tilt_x = f.unit() - 0.5f, tilt_y = f.unit() - 0.5f;
  const int box_x = int(f.next() % 97), box_y = int(f.next() % 97), box_size = int(f.next() % 24);
  for (int y = 0; y < b.height; ++y) {
    for (int x = 0; x < b.width; ++x) {
      for (int c = 0; c < b.channels; ++c) {
        float v;
        if (f.mode == 1) {
          v = bits_to_float(uint32_t(f.next()));
        } else if (kind == Kind::depth) {
          const bool in_box =
              x >= box_x && x < box_x + box_size && y >= box_y && y < box_y + box_size;
          const double d = f.scale * (1.0 + 0.02 * (tilt_x * float(x) + tilt_y * float(y))) *
                           (in_box ? 0.7 : 1.0);
          // Some sky at the top; depths past the float range are infinite (a double to float
          // conversion out of range is undefined).
          const bool sky = y < b.height / 8 || d > double(std::numeric_limits<float>::max());
          v = sky ? std::numeric_limits<float>::infinity() : float(d);
        } else if (kind == Kind::normal) {
          v = 2.0f * f.unit() - 1.0f;
        } else {
          v = 2.0f * f.unit();
        }
        *b.at(x, y, c) = v;
      }
    }
  }
  if (b.width == 0 || b.height == 0) return;
  for (int k = 0; k < f.specials; ++k) {
    const int x = in.ConsumeIntegralInRange<int>(0, b.width - 1);
    const int y = in.ConsumeIntegralInRange<int>(0, b.height - 1);
    const int c = in.ConsumeIntegralInRange<int>(0, b.channels - 1);
    *b.at(x, y, c) = hostile(in);
  }
}

// set_image with hostile sizes and strides: refused or accepted, never undefined behaviour.
// An accepted view is detached at once (its memory does not exist).
void hostile_set_image(FuzzedDataProvider& in, ssao_job job, const char* name) {
  static float dummy[4];
  float* data =
      in.ConsumeBool() ? dummy : reinterpret_cast<float*>(reinterpret_cast<char*>(dummy) + 1);
  const int width = in.ConsumeIntegral<int>(), height = in.ConsumeIntegral<int>();
  const int channels = in.ConsumeIntegralInRange<int>(-1, 6);
  const std::ptrdiff_t pixel_stride = in.ConsumeIntegral<std::ptrdiff_t>();
  const std::ptrdiff_t row_stride = in.ConsumeIntegral<std::ptrdiff_t>();
  const ssao_status s =
      ssao_job_set_image(job, name, data, width, height, channels, pixel_stride, row_stride);
  check(s == SSAO_OK || s == SSAO_ERROR_INVALID_ARGUMENT, "hostile set_image: unexpected status");
  if (s == SSAO_OK) {
    // What was accepted must describe a real layout: rows at least one row of pixels apart.
    const __int128 ps = pixel_stride == 0 ? __int128(channels) * 4 : pixel_stride;
    const __int128 rs = row_stride == 0 ? ps * width : row_stride;
    check(width >= 0 && height >= 0 && ps >= __int128(channels) * 4 && ps % 4 == 0 &&
              (rs < 0 ? -rs : rs) >= ps * width && rs % 4 == 0,
          "hostile set_image: impossible layout accepted");
  }
  check(ssao_job_set_image(job, name, nullptr, 0, 0, 0, 0, 0) == SSAO_OK, "detach");
}

struct ProgressLog {
  std::thread::id caller;
  double last = 0.0;
  int calls = 0;
  int cancel_after = -1;  // -1: never
  bool cancelled = false;
};

int on_progress(void* user, double fraction) {
  auto* log = static_cast<ProgressLog*>(user);
  check(std::this_thread::get_id() == log->caller, "progress called off the calling thread");
  check(fraction >= 0.0 && fraction <= 1.0 && fraction >= log->last,
        "progress fraction outside [0, 1] or decreasing");
  log->last = fraction;
  if (log->cancel_after >= 0 && log->calls++ >= log->cancel_after) {
    log->cancelled = true;
    return 0;
  }
  return 1;
}

const char* const kImageNames[] = {"depth", "normal", "beauty", "ambient", "ao", "composite"};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  ssao_job job = nullptr;
  check(ssao_job_create(&job) == SSAO_OK && job != nullptr, "create");
  // A new job uses every core; the fuzzer's runs use at most 3 threads.
  check(ssao_job_set_int(job, "threads", in.ConsumeIntegralInRange<int>(1, 3)) == SSAO_OK, "");

  const int parameter_calls = in.ConsumeIntegralInRange<int>(0, 12);
  for (int i = 0; i < parameter_calls; ++i) set_random_parameter(in, job);

  // Sizes: 0, 1, odd and even, never more than kMaxPixels.
  const int width = in.ConsumeIntegralInRange<int>(0, kMaxSide);
  int height = in.ConsumeIntegralInRange<int>(0, kMaxSide);
  if (width * height > kMaxPixels) height = kMaxPixels / width;

  if (in.ConsumeIntegralInRange<int>(0, 3) == 0) {
    for (int k = in.ConsumeIntegralInRange<int>(1, 3); k > 0; --k) {
      hostile_set_image(in, job, kImageNames[in.ConsumeIntegralInRange<int>(0, 5)]);
    }
  }

  const uint8_t attach = in.ConsumeIntegral<uint8_t>();
  const bool with_depth = in.ConsumeIntegralInRange<int>(0, 15) != 0;
  const bool with_normal = attach & 1, with_beauty = attach & 2, with_ambient = attach & 4;
  const bool with_ao = attach & 8, with_composite = attach & 16;
  const bool composite_in_place = attach & 32;

  Filler filler;
  filler.state = in.ConsumeIntegral<uint64_t>();
  filler.mode = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? 1 : 0;
  static const double scales[] = {1e-30, 1e-3, 1.0, 7.0, 1e3, 9e8, 1e20, 3e38};
  filler.scale = in.PickValueInArray(scales) * (0.5 + in.ConsumeProbability<double>());
  filler.specials = in.ConsumeIntegralInRange<int>(0, 8);

  const int beauty_channels = in.ConsumeIntegralInRange<int>(1, 4);
  Buffer depth = make_buffer(in, width, height, in.ConsumeIntegralInRange<int>(1, 4));
  Buffer normal = make_buffer(in, width, height, in.ConsumeIntegralInRange<int>(3, 4));
  Buffer beauty = make_buffer(in, width, height, beauty_channels);
  Buffer ambient = make_buffer(in, width, height, beauty_channels);
  Buffer ao = make_buffer(in, width, height, in.ConsumeIntegralInRange<int>(1, 4));
  Buffer composite = make_buffer(in, width, height, beauty_channels);
  fill(in, filler, depth, Kind::depth);
  fill(in, filler, normal, Kind::normal);
  fill(in, filler, beauty, Kind::colour);
  fill(in, filler, ambient, Kind::colour);

  // What is attached under each name (kImageNames order); nullptr: nothing.
  Buffer* attached[6] = {with_depth ? &depth : nullptr,
                         with_normal ? &normal : nullptr,
                         with_beauty ? &beauty : nullptr,
                         with_ambient ? &ambient : nullptr,
                         with_ao ? &ao : nullptr,
                         with_composite ? (composite_in_place ? &beauty : &composite) : nullptr};
  // Occasionally an image of another size or channel count replaces one: the run must not
  // write through it (another size is always refused).
  Buffer wrong;
  bool wrong_size = false;
  if (in.ConsumeIntegralInRange<int>(0, 15) == 0) {
    const int slot = in.ConsumeIntegralInRange<int>(1, 5);
    wrong_size = slot == 1 || slot == 4 || in.ConsumeBool();
    const int channels = slot == 1 ? 3 : (wrong_size ? 1 : beauty_channels % 4 + 1);
    wrong = make_buffer(in, wrong_size ? width + 1 : width, height, channels);
    attached[slot] = &wrong;
  }
  const bool mismatch = attached[1] == &wrong || attached[2] == &wrong || attached[3] == &wrong ||
                        attached[4] == &wrong || attached[5] == &wrong;
  for (int i = 0; i < 6; ++i) {
    Buffer* b = attached[i];
    if (b == nullptr) continue;
    const ssao_status s =
        ssao_job_set_image(job, kImageNames[i], b->top, b->width, b->height, b->channels,
                           b->given_pixel_stride, b->given_row_stride);
    check(s == SSAO_OK, std::string("valid image '") + kImageNames[i] + "' refused");
  }

  // Extra depth layers (depth2, depth3 with their facing): hostile values, or hits in order
  // (each the one before plus a hostile distance), which must be accepted.
  const int extra_layers =
      in.ConsumeIntegralInRange<int>(0, 5) == 0 ? 0 : in.ConsumeIntegralInRange<int>(0, 2);
  const bool ordered_layers = in.ConsumeBool();
  Buffer layers[2], facings[2];
  for (int k = 0; k < extra_layers; ++k) {
    layers[k] = make_buffer(in, width, height, in.ConsumeIntegralInRange<int>(1, 2));
    facings[k] = make_buffer(in, width, height, 1);
    fill(in, filler, layers[k], Kind::depth);
    fill(in, filler, facings[k], Kind::colour);
    for (int y = 0; ordered_layers && y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float before = *(k == 0 ? depth : layers[k - 1]).at(x, y, 0);
        float& hit = *layers[k].at(x, y, 0);
        hit = std::isnan(before) ? before : before + std::fabs(hit);
      }
    }
    const std::string number = std::to_string(k + 2);
    check(ssao_job_set_image(job, ("depth" + number).c_str(), layers[k].top, width, height,
                             layers[k].channels, layers[k].given_pixel_stride,
                             layers[k].given_row_stride) == SSAO_OK,
          "valid depth layer refused");
    if (in.ConsumeBool()) {
      check(
          ssao_job_set_image(job, ("facing" + number).c_str(), facings[k].top, width, height, 1,
                             facings[k].given_pixel_stride, facings[k].given_row_stride) == SSAO_OK,
          "valid facing image refused");
    }
  }

  // Overscan: now and then the outputs are a window inside the inputs (at a hostile place).
  bool windowed = false;
  if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
    const int x = in.ConsumeIntegralInRange<int>(-2, 3), y = in.ConsumeIntegralInRange<int>(-2, 3);
    const ssao_status s = ssao_job_set_output_window(job, 1, x, y);
    check(s == (x < 0 || y < 0 ? SSAO_ERROR_INVALID_ARGUMENT : SSAO_OK), "set_output_window");
    windowed = s == SSAO_OK;
  }

  // auto_radius: an error (no depth, no geometry) or a usable radius.
  double radius = 0.0;
  const ssao_status radius_status = ssao_job_auto_radius(job, &radius);
  check(radius_status == SSAO_OK || radius_status == SSAO_ERROR_INVALID_OPERATION ||
            radius_status == SSAO_ERROR_INVALID_ARGUMENT,
        "auto_radius: unexpected status");
  if (radius_status == SSAO_OK) check(std::isfinite(radius) && radius > 0.0, "auto_radius value");
  if (radius_status == SSAO_OK && radius >= 1e-6 && radius <= 1e9 && in.ConsumeBool()) {
    check(ssao_job_set_float(job, "radius", radius) == SSAO_OK, "auto radius refused as radius");
  }

  ProgressLog log;
  log.caller = std::this_thread::get_id();
  if (in.ConsumeBool()) {
    log.cancel_after = in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(0, 20) : -1;
    check(ssao_job_set_progress(job, on_progress, &log) == SSAO_OK, "set_progress");
  }
  const bool compare_threads = in.ConsumeIntegralInRange<int>(0, 7) == 0;

  Buffer* const everything[] = {&depth, &normal,    &beauty,    &ambient,    &ao,        &composite,
                                &wrong, &layers[0], &layers[1], &facings[0], &facings[1]};
  std::vector<std::vector<uint32_t>> before;
  for (Buffer* b : everything) before.push_back(b->snapshot());

  const ssao_status status = ssao_job_run(job);
  check(status != SSAO_ERROR_INTERNAL && status != SSAO_ERROR_OUT_OF_MEMORY,
        "run: internal error or out of memory");
  if (status != SSAO_OK) check(std::strlen(ssao_last_error()) > 0, "run: error without message");
  if (status == SSAO_ERROR_CANCELLED) check(log.cancelled, "cancelled without a cancel");

  Buffer* const out_ao = attached[4];
  Buffer* const out_composite = attached[5];
  const bool has_inputs =
      with_depth && (out_ao || out_composite) && (!out_composite || with_beauty);
  if (!has_inputs) {
    // (The sizes, a window's among them, are compared before the composite asks for its
    // beauty.)
    const bool window_refused =
        windowed && status == SSAO_ERROR_INVALID_ARGUMENT &&
        std::string(ssao_last_error()).find("output window") != std::string::npos;
    check(status == SSAO_ERROR_INVALID_OPERATION ||
              (mismatch && status == SSAO_ERROR_INVALID_ARGUMENT) || window_refused,
          "run without depth/output/beauty not refused");
  } else if (mismatch && wrong_size) {
    check(status == SSAO_ERROR_INVALID_ARGUMENT, "an image of another size was not refused");
  } else if (!mismatch && !log.cancelled) {
    // Refusals that valid images can get: a camera the parameters make impossible, hits out of
    // order (unordered layers, or a sum of hostile distances rounded below the hit before), a
    // window whose outputs do not fit.
    const std::string message = ssao_last_error();
    check(status == SSAO_OK ||
              (status == SSAO_ERROR_INVALID_ARGUMENT &&
               (message.find("camera") != std::string::npos ||
                (extra_layers > 0 && message.find("nearer than") != std::string::npos) ||
                message.find("output window") != std::string::npos)),
          "a valid run was refused: " + message);
  }

  // Inputs are read only; a failed or cancelled run leaves every buffer as it was.
  for (size_t i = 0; i < std::size(everything); ++i) {
    Buffer* b = everything[i];
    if (status == SSAO_OK && (b == out_ao || b == out_composite)) continue;
    check(b->equals(before[i]), status == SSAO_OK
                                    ? "an input image was modified"
                                    : "a failed or cancelled run touched its outputs");
  }
  if (status != SSAO_OK || width == 0 || height == 0) {
    ssao_job_destroy(job);
    return 0;
  }

  for (Buffer* b : {out_ao, out_composite}) {
    if (b) check(b->padding_intact(), "the run wrote into the padding between pixels or rows");
  }
  if (out_ao) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float v = *out_ao->at(x, y, 0);
        check(v >= 0.0f && v <= 1.0f, "AO outside [0, 1] or NaN: " + std::to_string(v) + " at " +
                                          std::to_string(x) + "," + std::to_string(y));
        for (int c = 1; c < std::min(out_ao->channels, 3); ++c) {
          check(float_bits(*out_ao->at(x, y, c)) == float_bits(v), "AO channels differ");
        }
        if (out_ao->channels == 4) check(*out_ao->at(x, y, 3) == 1.0f, "AO alpha is not 1");
      }
    }
  }
  if (out_ao && out_composite && !mismatch) {
    // The composite against the AO written beside it, from the beauty as it was before the run.
    // A pixel beside the background may darken only the surface's share c (ssao.h): the
    // normal's length, over the beauty's alpha when that is below 1; which pixels those are is
    // the unit tests' to check, so either c or 1 is accepted here, each bit for bit.
    const auto& beauty_before = before[2];
    const auto source = [&](int x, int y, int c) {
      return bits_to_float(beauty_before[size_t(beauty.at(x, y, c) - beauty.storage.data())]);
    };
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float a = *out_ao->at(x, y, 0);
        float share = 1.0f;
        if (attached[1] != nullptr) {
          const float n0 = *normal.at(x, y, 0), n1 = *normal.at(x, y, 1), n2 = *normal.at(x, y, 2);
          const float length = std::sqrt(n0 * n0 + n1 * n1 + n2 * n2);
          share = length < 1.0f ? length : 1.0f;
          if (beauty_channels == 4) {
            const float alpha = source(x, y, 3);
            if (alpha > 0.0f && alpha < 1.0f) share = share < alpha ? share / alpha : 1.0f;
          }
        }
        for (int c = 0; c < beauty_channels; ++c) {
          const float src = source(x, y, c);
          const float got = *out_composite->at(x, y, c);
          bool matches = false;
          for (const float coverage : {1.0f, share}) {
            float expected = src;
            if (c < 3 && with_ambient) {
              const float darker = src - coverage * (1.0f - a) * *ambient.at(x, y, c);
              expected = darker < 0.0f && src >= 0.0f ? 0.0f : darker;
            } else if (c < 3) {
              expected = src * (coverage < 1.0f ? 1.0f - coverage * (1.0f - a) : a);
            }
            matches = matches || float_bits(got) == float_bits(expected) ||
                      (got != got && expected != expected);
          }
          check(matches, "composite is not the formula of beauty and AO");
        }
      }
    }
  }
  if (compare_threads && out_ao) {
    // Results do not depend on the thread count (ssao.h).
    int threads = 1;
    check(ssao_job_get_int(job, "threads", &threads) == SSAO_OK, "get threads");
    const std::vector<uint32_t> first = out_ao->snapshot();
    check(ssao_job_set_int(job, "threads", threads == 1 ? 3 : 1) == SSAO_OK, "set threads");
    check(ssao_job_set_progress(job, nullptr, nullptr) == SSAO_OK, "clear progress");
    // In place, the second run would composite the composite: give it the beauty back.
    std::memcpy(beauty.storage.data(), before[2].data(), before[2].size() * sizeof(float));
    check(ssao_job_run(job) == SSAO_OK, "second run with another thread count failed");
    check(out_ao->equals(first), "AO depends on the thread count");
  }
  ssao_job_destroy(job);
  return 0;
}
