// SPDX-License-Identifier: MIT
// The library's parameters on a command line, shared by every front end (build/bin/ssao,
// build/bin/povray-ssao): each entry of the core's table (ssao_param_info) is accepted as
// --NAME-WITH-DASHES VALUE, parsed according to its type, applied to a job, and described in
// --help, so no front end repeats a parameter list, a default or a range. Also the small
// pieces of command-line handling the front ends share (number parsing, help layout,
// "did you mean" suggestions).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "ssao/ssao.h"
#include "ssao/ssao.hpp"

namespace ssao_tools {

// A wrong command line: front ends report it with a hint to --help and exit status 2.
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

// "sphere_mode" -> "--sphere-mode".
std::string flag_for(const std::string& param_name);

// The library's group of the parameter called `name` (ssao_param_group: "ao", "camera", ...);
// "" for no such parameter.
std::string param_group_of(const std::string& name);

// The parameter whose flag is `flag` ("--sphere-mode"), or nullptr.
const ssao_param_desc* find_param(const std::string& flag,
                                  const std::vector<ssao_param_desc>& table);

// Parses `text` as the value of `desc` (given as `flag`). Throws UsageError for a value of the
// wrong type ("--samples abc"), a non-finite number, a choice that does not exist or a wrong
// count of comma-separated numbers. Ranges are the core's to check (apply_params).
ParamSetting parse_param(const ssao_param_desc& desc, const std::string& flag,
                         const std::string& text);

// Sets every setting on `job`, in order. A value the core rejects (out of range) is a
// UsageError naming the flag and the core's message.
void apply_params(ssao::api::Job& job, const std::vector<ParamSetting>& settings);

// Strict number parsing for flags: the whole text must be the number. UsageError otherwise.
int parse_int(const std::string& flag, const std::string& text);
double parse_float(const std::string& flag, const std::string& text);  // finite only

// Splits at every `separator` (empty parts kept).
std::vector<std::string> split(const std::string& text, char separator);

// "unknown option '--radiu' (did you mean --radius?)": the closest of `known` within an edit
// distance of 2, if any.
std::string unknown_option_message(const std::string& flag, const std::vector<std::string>& known);

// Help layout: "  LEFT" padded to column 30, then `text` word-wrapped to 100 columns.
std::string help_entry(const std::string& left, const std::string& text);

// The value placeholder of a parameter in --help: N, X, one|two, X1,...,X16.
std::string param_metavar(const ssao_param_desc& desc);

// "default 1 (scene units), range 1e-06..1e+09" and the like, for --help.
std::string param_facts(const ssao_param_desc& desc);

// One help_entry per parameter of `table` for which `include(desc)` is true.
template <typename Predicate>
std::string param_help(const std::vector<ssao_param_desc>& table, Predicate include) {
  std::string text;
  for (const ssao_param_desc& desc : table) {
    if (!include(desc)) continue;
    const std::string description = desc.description ? desc.description : "";
    text += help_entry(flag_for(desc.name) + " " + param_metavar(desc),
                       description + " [" + param_facts(desc) + "]");
  }
  return text;
}

// An option of a front end itself (not a library parameter). Each front end keeps a table of
// them, which drives its parsing, --help and "did you mean" suggestions. Options is the front
// end's result type (with a `params` vector of ParamSetting); Group orders its --help.
template <typename Options, typename Group>
struct FrontOption {
  Group group;
  const char* flag;
  const char* alias;    // short form or nullptr
  const char* metavar;  // nullptr for a switch
  const char* help;
  void (*apply)(Options& out, const std::string& flag, const std::string& value);
};

// Sets out.help (for --help or -h) or out.version (--version) when either appears anywhere on
// the command line, which then means nothing else; returns whether one did.
template <typename Options>
bool scan_help_and_version(int argc, const char* const* argv, Options& out) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      out.help = true;
      return true;
    }
    if (arg == "--version") {
      out.version = true;
      return true;
    }
  }
  return false;
}

// Parses the option at argv[i], written "--flag", "--flag=value" or "--flag value" (then i is
// left on the value): a front option is applied to `out`, a library parameter is parsed into
// out.params. Throws UsageError for an unknown flag (suggesting the closest), a missing value
// or a value given to a switch.
template <typename Options, typename Group>
void parse_option(int argc, const char* const* argv, int& i,
                  const std::vector<FrontOption<Options, Group>>& options,
                  const std::vector<ssao_param_desc>& table, Options& out) {
  const std::string arg = argv[i];
  std::string flag = arg;
  std::string value;
  bool has_inline_value = false;
  const size_t equals = arg.find('=');
  if (arg.rfind("--", 0) == 0 && equals != std::string::npos) {
    flag = arg.substr(0, equals);
    value = arg.substr(equals + 1);
    has_inline_value = true;
  }
  const FrontOption<Options, Group>* option = nullptr;
  for (const auto& candidate : options) {
    if (flag == candidate.flag || (candidate.alias && flag == candidate.alias)) {
      option = &candidate;
      break;
    }
  }
  const ssao_param_desc* param = option ? nullptr : find_param(flag, table);
  if (!option && !param) {
    std::vector<std::string> known;
    for (const auto& candidate : options) known.push_back(candidate.flag);
    for (const ssao_param_desc& desc : table) known.push_back(flag_for(desc.name));
    throw UsageError(unknown_option_message(flag, known));
  }
  const bool takes_value = param != nullptr || option->metavar != nullptr;
  if (!takes_value) {
    if (has_inline_value) throw UsageError(flag + " takes no value");
    option->apply(out, option->flag, "");
    return;
  }
  if (!has_inline_value) {
    if (i + 1 >= argc) throw UsageError(flag + " requires a value");
    value = argv[++i];
  }
  if (param) {
    out.params.push_back(parse_param(*param, flag, value));
  } else {
    if (value.empty()) throw UsageError(flag + " requires a non-empty value");
    option->apply(out, option->flag, value);
  }
}

}  // namespace ssao_tools
