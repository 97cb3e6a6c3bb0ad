// SPDX-License-Identifier: MIT
// The parameter table (the single source of names, defaults, ranges and units) and a job's
// current values. settings.h turns the values into typed settings for one run.
#pragma once

#include <string>
#include <vector>

#include "ssao/ssao.h"

namespace ssao {

size_t param_count();
const ssao_param_desc& param_desc(size_t index);
// "ao", "quality", "shaping", "input", "camera" or "execution" (ssao.h, ssao_param_group).
const char* param_group(size_t index);

// Current values of every parameter of one job, validated on every set.
class ParamValues {
 public:
  ParamValues();

  void set_int(const char* name, int value);
  void set_float(const char* name, double value);
  void set_string(const char* name, const char* value);
  void set_floats(const char* name, const double* values, size_t count);

  int get_int(const char* name) const;
  double get_float(const char* name) const;
  const std::string& get_string(const char* name) const;
  const std::vector<double>& get_floats(const char* name) const;
  // Whether a set_* call (or a camera file) gave the parameter its value on this job: the
  // front ends' rules ask whether the radius and the camera's matrix were given.
  bool is_set(const char* name) const;
  // A value a rule chose, not the caller: it keeps is_set() false, so the rule chooses again
  // next time (Job::choose_radius).
  void set_float_default(const char* name, double value);
  // Every parameter of `group` (param_group) back to its default, not set.
  void reset_group(const char* group);

 private:
  struct Value {
    double number = 0.0;
    std::string text;
    std::vector<double> floats;
    bool set = false;  // given by a set_* call, not the table's default
  };
  size_t index_of(const char* name) const;
  size_t index_of(const char* name, ssao_param_type expected) const;
  std::vector<Value> values_;
};

}  // namespace ssao
