// SPDX-License-Identifier: MIT
#include "tools/param_flags.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace ssao_tools {
namespace {

constexpr size_t kHelpColumn = 30;
constexpr size_t kHelpWidth = 100;

// Integers as integers (2147483647, not 2.14748e+09), other numbers in %g.
std::string format_number(double value, bool integer) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  if (integer || (value == std::floor(value) && std::fabs(value) < 1e6)) {
    std::snprintf(buffer, sizeof buffer, "%.0f", value);
  } else {
    std::snprintf(buffer, sizeof buffer, "%g", value);
  }
  return buffer;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// Word-wraps `text` to `width` columns, every line but the first indented by `indent`.
std::string wrap(const std::string& text, size_t indent, size_t width) {
  std::string out;
  size_t column = indent;
  for (const std::string& word : split(text, ' ')) {
    if (word.empty()) continue;
    if (column > indent && column + 1 + word.size() > width) {
      out += "\n" + std::string(indent, ' ');
      column = indent;
    } else if (column > indent) {
      out += ' ';
      ++column;
    }
    out += word;
    column += word.size();
  }
  return out;
}

}  // namespace

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

std::string param_group_of(const std::string& name) {
  for (size_t i = 0; i < ssao_param_count(); ++i) {
    ssao_param_desc desc;
    if (ssao_param_info(i, &desc) == SSAO_OK && name == desc.name) {
      return ssao::api::param_group(i);
    }
  }
  return "";
}

std::string flag_for(const std::string& param_name) {
  std::string flag = "--" + param_name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

const ssao_param_desc* find_param(const std::string& flag,
                                  const std::vector<ssao_param_desc>& table) {
  for (const ssao_param_desc& desc : table) {
    if (flag == flag_for(desc.name)) return &desc;
  }
  return nullptr;
}

int parse_int(const std::string& flag, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0])) || *end != '\0') {
    throw UsageError(flag + " expects an integer, got '" + text + "'");
  }
  if (errno == ERANGE || value < INT_MIN || value > INT_MAX) {
    throw UsageError(flag + ": integer out of range: '" + text + "'");
  }
  return static_cast<int>(value);
}

double parse_float(const std::string& flag, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0])) || *end != '\0') {
    throw UsageError(flag + " expects a number, got '" + text + "'");
  }
  if (!std::isfinite(value))
    throw UsageError(flag + " expects a finite number, got '" + text + "'");
  return value;
}

ParamSetting parse_param(const ssao_param_desc& desc, const std::string& flag,
                         const std::string& text) {
  ParamSetting setting;
  setting.name = desc.name;
  setting.flag = flag;
  setting.text = text;
  setting.type = desc.type;
  switch (desc.type) {
    case SSAO_PARAM_INT:
      setting.int_value = parse_int(flag, text);
      break;
    case SSAO_PARAM_FLOAT:
      setting.float_value = parse_float(flag, text);
      break;
    case SSAO_PARAM_STRING: {
      const std::vector<std::string> choices = split(desc.choices ? desc.choices : "", '|');
      if (std::find(choices.begin(), choices.end(), text) == choices.end()) {
        throw UsageError(flag + " must be one of " + (desc.choices ? desc.choices : "") +
                         ", got '" + text + "'");
      }
      setting.string_value = text;
      break;
    }
    case SSAO_PARAM_FLOATS: {
      const std::vector<std::string> parts = split(text, ',');
      if (parts.size() != desc.count) {
        throw UsageError(flag + " expects " + std::to_string(desc.count) +
                         " comma-separated numbers, got " + std::to_string(parts.size()));
      }
      for (const std::string& part : parts) setting.float_values.push_back(parse_float(flag, part));
      break;
    }
  }
  return setting;
}

void apply_params(ssao::api::Job& job, const std::vector<ParamSetting>& settings) {
  for (const ParamSetting& setting : settings) {
    try {
      switch (setting.type) {
        case SSAO_PARAM_INT:
          job.set(setting.name, setting.int_value);
          break;
        case SSAO_PARAM_FLOAT:
          job.set(setting.name, setting.float_value);
          break;
        case SSAO_PARAM_STRING:
          job.set(setting.name, setting.string_value);
          break;
        case SSAO_PARAM_FLOATS:
          job.set(setting.name, setting.float_values);
          break;
      }
    } catch (const ssao::api::Error&) {
      throw UsageError(setting.flag + " " + setting.text + ": " + ssao_last_error());
    }
  }
}

std::string unknown_option_message(const std::string& flag, const std::vector<std::string>& known) {
  std::string best;
  size_t best_distance = 3;  // suggest only close matches
  for (const std::string& candidate : known) {
    const size_t distance = edit_distance(flag, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  std::string message = "unknown option '" + flag + "'";
  if (!best.empty()) message += " (did you mean " + best + "?)";
  return message;
}

std::string help_entry(const std::string& left, const std::string& text) {
  std::string line = "  " + left;
  if (line.size() + 2 > kHelpColumn) {
    line += "\n" + std::string(kHelpColumn, ' ');
  } else {
    line += std::string(kHelpColumn - line.size(), ' ');
  }
  return line + wrap(text, kHelpColumn, kHelpWidth) + "\n";
}

std::string param_metavar(const ssao_param_desc& desc) {
  switch (desc.type) {
    case SSAO_PARAM_INT:
      return "N";
    case SSAO_PARAM_FLOAT:
      return "X";
    case SSAO_PARAM_STRING:
      return desc.choices ? desc.choices : "S";
    case SSAO_PARAM_FLOATS:
      return "X1,...,X" + std::to_string(desc.count);
  }
  return "VALUE";
}

std::string param_facts(const ssao_param_desc& desc) {
  std::string facts;
  const std::string unit = desc.unit ? desc.unit : "";
  const bool integer = desc.type == SSAO_PARAM_INT;
  switch (desc.type) {
    case SSAO_PARAM_INT:
    case SSAO_PARAM_FLOAT:
      facts = "default " + format_number(desc.default_value, integer);
      if (!unit.empty()) facts += " (" + unit + ")";
      if (std::isinf(desc.max_value)) {
        facts += ", range >= " + format_number(desc.min_value, integer);
      } else {
        facts += ", range " + format_number(desc.min_value, integer) + ".." +
                 format_number(desc.max_value, integer);
      }
      break;
    case SSAO_PARAM_STRING:
      facts = std::string("default ") + (desc.default_string ? desc.default_string : "");
      break;
    case SSAO_PARAM_FLOATS:
      facts = std::to_string(desc.count) + " values";
      if (!unit.empty()) facts += " (" + unit + ")";
      break;
  }
  return facts;
}

}  // namespace ssao_tools
