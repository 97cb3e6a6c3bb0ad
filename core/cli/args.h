// SPDX-License-Identifier: MIT
// Command-line parsing of the ssao tool. The AO and camera parameters are not listed here: every
// parameter of the core's table (ssao_param_info) is accepted as --NAME-WITH-DASHES VALUE and
// parsed according to its type, and --help prints the table.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "ssao/ssao.h"

namespace ssao_cli {

// A wrong command line: reported with a hint to --help, exit status 2.
class UsageError : public std::runtime_error {
 public:
  explicit UsageError(const std::string& message) : std::runtime_error(message) {}
};

// One core parameter given on the command line, already parsed to its type.
struct ParamSetting {
  std::string name;  // the core's name, with underscores
  std::string flag;  // as written, e.g. "--sphere-mode"
  std::string text;  // the value as written
  ssao_param_type type = SSAO_PARAM_FLOAT;
  int int_value = 0;
  double float_value = 0.0;
  std::string string_value;
  std::vector<double> float_values;
};

struct Options {
  bool help = false;
  bool version = false;
  bool quiet = false;
  bool ao_only = false;
  bool no_normals = false;
  std::string input;
  std::string output;
  std::string camera;
  std::string layer;
  std::string depth_channel;
  std::vector<std::string> normal_channels;
  std::vector<std::string> beauty_channels;
  std::vector<ParamSetting> params;  // in command-line order
};

// Parses argv. With --help or --version anywhere, only that flag is honoured. Throws UsageError
// for an unknown option, a missing value, a value of the wrong type (e.g. "--samples abc",
// "--radius nan"), a choice that does not exist, or a missing input, -o or --camera.
Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table);

// The text --help prints, parameters (defaults, units, ranges, choices) taken from `table`.
std::string usage_text(const std::vector<ssao_param_desc>& table);

// "sphere_mode" -> "--sphere-mode".
std::string flag_for(const std::string& param_name);

}  // namespace ssao_cli
