// SPDX-License-Identifier: MIT
#include "args.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "io/camera_json.h"

namespace ssao_cli {
namespace {

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

std::vector<std::string> parse_channel_list(const std::string& flag, const std::string& text,
                                            size_t min_count, size_t max_count) {
  const std::vector<std::string> names = split(text, ',');
  for (const std::string& name : names) {
    if (name.empty()) throw UsageError(flag + ": empty channel name in '" + text + "'");
  }
  if (names.size() < min_count || names.size() > max_count) {
    const std::string expected =
        min_count == max_count ? std::to_string(min_count)
                               : std::to_string(min_count) + " or " + std::to_string(max_count);
    throw UsageError(flag + " expects " + expected + " comma-separated channel names, got " +
                     std::to_string(names.size()) + " in '" + text + "'");
  }
  return names;
}

// Front-end options (not core parameters). The table drives parsing, --help and suggestions.
struct FrontOption {
  enum Group { kInputOutput, kOther };
  Group group;
  const char* flag;
  const char* alias;    // short form or nullptr
  const char* metavar;  // nullptr for a switch
  const char* help;
  void (*apply)(Options& out, const std::string& flag, const std::string& value);
};

const std::vector<FrontOption>& front_options() {
  static const std::vector<FrontOption> options = {
      {FrontOption::kInputOutput, "--output", "-o", "OUT.exr",
       "output file (required): .exr writes float data (ZIP); .png, .jpg or .tif an 8-bit sRGB "
       "preview; written to a temporary file and renamed, never over IN.exr",
       [](Options& o, const std::string&, const std::string& v) { o.output = v; }},
      {FrontOption::kInputOutput, "--camera", nullptr, "CAM.json",
       "camera description (required): Blender camera properties and matrix_world, see "
       "docs/conventions.md",
       [](Options& o, const std::string&, const std::string& v) { o.camera = v; }},
      {FrontOption::kInputOutput, "--ao-only", nullptr, nullptr,
       "write exactly one channel, AO, instead of beauty x AO + AO",
       [](Options& o, const std::string&, const std::string&) { o.ao_only = true; }},
      {FrontOption::kInputOutput, "--layer", nullptr, "NAME",
       "view layer to read when several have a Depth pass",
       [](Options& o, const std::string&, const std::string& v) { o.layer = v; }},
      {FrontOption::kInputOutput, "--depth-channel", nullptr, "NAME",
       "depth channel (default <layer>.Depth.Z, or Depth.Z, Z, depth, Depth without layers)",
       [](Options& o, const std::string&, const std::string& v) { o.depth_channel = v; }},
      {FrontOption::kInputOutput, "--normal-channels", nullptr, "X,Y,Z",
       "normal channels (default <layer>.Normal.X,Y,Z, or Normal.* / N.* without layers)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.normal_channels = parse_channel_list(f, v, 3, 3);
       }},
      {FrontOption::kInputOutput, "--beauty-channels", nullptr, "R,G,B[,A]",
       "beauty channels (default <layer>.Combined.R,G,B[,A], or Combined.* / R,G,B[,A])",
       [](Options& o, const std::string& f, const std::string& v) {
         o.beauty_channels = parse_channel_list(f, v, 3, 4);
       }},
      {FrontOption::kInputOutput, "--no-normals", nullptr, nullptr,
       "ignore the normal pass; reconstruct normals from depth",
       [](Options& o, const std::string&, const std::string&) { o.no_normals = true; }},
      {FrontOption::kOther, "--quiet", "-q", nullptr,
       "no progress, no summary, no warnings (errors are still shown)",
       [](Options& o, const std::string&, const std::string&) { o.quiet = true; }},
      {FrontOption::kOther, "--help", "-h", nullptr, "print this help and exit",
       [](Options& o, const std::string&, const std::string&) { o.help = true; }},
      {FrontOption::kOther, "--version", nullptr, nullptr, "print the library version and exit",
       [](Options& o, const std::string&, const std::string&) { o.version = true; }},
  };
  return options;
}

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

std::string unknown_option_message(const std::string& flag,
                                   const std::vector<ssao_param_desc>& table) {
  std::vector<std::string> known;
  for (const FrontOption& option : front_options()) known.push_back(option.flag);
  for (const ssao_param_desc& desc : table) known.push_back(flag_for(desc.name));
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

const FrontOption* find_front_option(const std::string& flag) {
  for (const FrontOption& option : front_options()) {
    if (flag == option.flag || (option.alias && flag == option.alias)) return &option;
  }
  return nullptr;
}

const ssao_param_desc* find_param(const std::string& flag,
                                  const std::vector<ssao_param_desc>& table) {
  for (const ssao_param_desc& desc : table) {
    if (flag == flag_for(desc.name)) return &desc;
  }
  return nullptr;
}

void require_complete(const Options& options) {
  if (options.input.empty()) throw UsageError("missing the input file IN.exr");
  if (options.output.empty()) throw UsageError("missing the output file: -o OUT.exr");
  if (options.camera.empty()) throw UsageError("missing the camera description: --camera CAM.json");
  if (options.no_normals && !options.normal_channels.empty()) {
    throw UsageError("--no-normals and --normal-channels contradict each other");
  }
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

constexpr size_t kHelpColumn = 30;
constexpr size_t kHelpWidth = 100;

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

bool is_camera_param(const char* name) {
  const auto& names = ssao_io::camera_param_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

std::string flag_for(const std::string& param_name) {
  std::string flag = "--" + param_name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table) {
  Options out;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      out.help = true;
      return out;
    }
    if (arg == "--version") {
      out.version = true;
      return out;
    }
  }

  bool only_positionals = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool is_option = !only_positionals && arg.size() > 1 && arg[0] == '-';
    if (!is_option) {
      if (!out.input.empty()) {
        throw UsageError("more than one input file: '" + out.input + "' and '" + arg + "'");
      }
      if (arg.empty()) throw UsageError("empty input file name");
      out.input = arg;
      continue;
    }
    if (arg == "--") {
      only_positionals = true;
      continue;
    }

    // --flag=value or --flag value
    std::string flag = arg;
    std::string value;
    bool has_inline_value = false;
    const size_t equals = arg.find('=');
    if (arg.rfind("--", 0) == 0 && equals != std::string::npos) {
      flag = arg.substr(0, equals);
      value = arg.substr(equals + 1);
      has_inline_value = true;
    }

    const FrontOption* option = find_front_option(flag);
    const ssao_param_desc* param = option ? nullptr : find_param(flag, table);
    if (!option && !param) throw UsageError(unknown_option_message(flag, table));

    const bool takes_value = param != nullptr || option->metavar != nullptr;
    if (!takes_value) {
      if (has_inline_value) throw UsageError(flag + " takes no value");
      option->apply(out, option->flag, "");
      continue;
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
  require_complete(out);
  return out;
}

std::string usage_text(const std::vector<ssao_param_desc>& table) {
  std::string text =
      "Usage: ssao IN.exr -o OUT.exr --camera CAM.json [options]\n"
      "\n"
      "Screen-space ambient occlusion of a rendered image. Reads Blender's multilayer EXR\n"
      "(<layer>.Depth.Z, <layer>.Normal.X/Y/Z, <layer>.Combined.R/G/B/A; other files with\n"
      "plain channel names work too) and writes OUT.exr with R,G,B[,A] = beauty x AO (alpha\n"
      "copied) and an AO channel (1 = unoccluded), or only AO with --ao-only.\n"
      "\n"
      "Input and output:\n";
  text += help_entry("IN.exr", "input image (any file OpenImageIO reads)");
  for (const FrontOption::Group group : {FrontOption::kInputOutput, FrontOption::kOther}) {
    if (group == FrontOption::kOther) text += "\nOther:\n";
    for (const FrontOption& option : front_options()) {
      if (option.group != group) continue;
      std::string left =
          option.alias ? std::string(option.alias) + ", " + option.flag : option.flag;
      if (option.metavar) left += std::string(" ") + option.metavar;
      text += help_entry(left, option.help);
    }
  }

  auto param_section = [&](const char* title, bool camera) {
    text += std::string("\n") + title + "\n";
    for (const ssao_param_desc& desc : table) {
      if (is_camera_param(desc.name) != camera) continue;
      const std::string description = desc.description ? desc.description : "";
      text += help_entry(flag_for(desc.name) + " " + param_metavar(desc),
                         description + " [" + param_facts(desc) + "]");
    }
  };
  param_section(
      "AO parameters (libssao's parameter table; --NAME_WITH_UNDERSCORES is written "
      "with dashes):",
      false);
  param_section(
      "Camera parameters (set from --camera CAM.json, matrix_world giving\n"
      "camera_to_world; a flag given here overrides the file):",
      true);

  text +=
      "\n"
      "Progress goes to stderr, then a one-line summary (size, variant, samples, time, mean AO\n"
      "over geometry pixels). Background pixels (depth NaN, infinite, <= 0, >= background_depth\n"
      "or >= clip_end) get AO 1.\n"
      "\n"
      "Exit status: 0 success, 1 failure (nothing written), 2 command-line error.\n";
  return text;
}

}  // namespace ssao_cli
