// SPDX-License-Identifier: MIT
#include "animation.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "tools/frames.h"
#include "tools/param_flags.h"

namespace povray_ssao {
namespace {

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

bool parse_number(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end && *end == '\0';
}

// A frame number; a fraction (0.5: half way) is recorded as unreadable.
void frame_value(const std::string& name, const std::string& text, std::optional<long>& out,
                 ClockOptions& clock) {
  double value = 0.0;
  if (!parse_number(text, value) || value != static_cast<double>(static_cast<long>(value)) ||
      (value > 0.0 && value < 1.0)) {
    if (clock.unreadable.empty()) clock.unreadable = name + "=" + text;
    return;
  }
  out = static_cast<long>(value);
}

bool truth(const std::string& text) {
  const std::string t = lower(text);
  return t == "on" || t == "true" || t == "yes" || t == "1";
}

}  // namespace

bool read_clock_option(const std::string& text, ClockOptions& clock) {
  const std::string option = trim(text);
  double value = 0.0;
  if (option.size() >= 2 && (option[0] == '+' || option[0] == '-')) {
    const std::string key = lower(option.substr(1));
    auto after = [&](size_t length) { return option.substr(1 + length); };
    if (key.rfind("kfi", 0) == 0) {
      frame_value("+KFI", after(3), clock.initial_frame, clock);
    } else if (key.rfind("kff", 0) == 0) {
      frame_value("+KFF", after(3), clock.final_frame, clock);
    } else if (key == "kc") {
      clock.cyclic = option[0] == '+';
    } else if (key.rfind("ki", 0) == 0 && parse_number(after(2), value)) {
      clock.initial_clock = value;
    } else if (key.rfind("kf", 0) == 0 && parse_number(after(2), value)) {
      clock.final_clock = value;
    } else if (key.rfind("sf", 0) == 0) {
      frame_value("+SF", after(2), clock.subset_start, clock);
    } else if (key.rfind("ef", 0) == 0) {
      frame_value("+EF", after(2), clock.subset_end, clock);
    } else if (key[0] == 'k' && parse_number(after(1), value)) {
      clock.clock = value;
    } else {
      return false;
    }
    return true;
  }
  const size_t equals = option.find('=');
  if (equals == std::string::npos) return false;
  const std::string key = lower(trim(option.substr(0, equals)));
  const std::string value_text = trim(option.substr(equals + 1));
  if (key == "initial_frame") {
    frame_value("Initial_Frame", value_text, clock.initial_frame, clock);
  } else if (key == "final_frame") {
    frame_value("Final_Frame", value_text, clock.final_frame, clock);
  } else if (key == "subset_start_frame") {
    frame_value("Subset_Start_Frame", value_text, clock.subset_start, clock);
  } else if (key == "subset_end_frame") {
    frame_value("Subset_End_Frame", value_text, clock.subset_end, clock);
  } else if (key == "cyclic_animation") {
    clock.cyclic = truth(value_text);
  } else if (key == "initial_clock" && parse_number(value_text, value)) {
    clock.initial_clock = value;
  } else if (key == "final_clock" && parse_number(value_text, value)) {
    clock.final_clock = value;
  } else if (key == "clock" && parse_number(value_text, value)) {
    clock.clock = value;
  } else {
    return false;
  }
  return true;
}

std::vector<AnimationFrame> animation_frames(const ClockOptions& clock) {
  if (!clock.animated()) return {};
  if (!clock.unreadable.empty()) {
    throw ssao_tools::UsageError(clock.unreadable +
                                 ": povray-ssao takes animation frames as whole frame numbers");
  }
  const long first = clock.initial_frame.value_or(1);
  const long last = clock.final_frame.value_or(first);
  if (last < first) {
    throw ssao_tools::UsageError("the animation runs backwards: Final_Frame (+KFF" +
                                 std::to_string(last) + ") is before Initial_Frame (+KFI" +
                                 std::to_string(first) + ")");
  }
  if (first < 0) throw ssao_tools::UsageError("povray-ssao renders frames numbered from 0 up");
  const long from = std::max(first, clock.subset_start.value_or(first));
  const long to = std::min(last, clock.subset_end.value_or(last));
  if (to < from) {
    throw ssao_tools::UsageError("the subset of frames (+SF" + std::to_string(from) + " +EF" +
                                 std::to_string(to) + ") holds no frame of " +
                                 std::to_string(first) + ".." + std::to_string(last));
  }
  if (static_cast<unsigned long>(to - from) >= ssao_tools::kMaxFrames) {
    throw ssao_tools::UsageError("more than " + std::to_string(ssao_tools::kMaxFrames) + " frames");
  }
  const double span = static_cast<double>(last - first + (clock.cyclic ? 1 : 0));
  const size_t width = std::to_string(last).size();
  std::vector<AnimationFrame> frames;
  for (long number = from; number <= to; ++number) {
    AnimationFrame frame;
    frame.number = number;
    frame.clock = span > 0.0 ? clock.initial_clock + (clock.final_clock - clock.initial_clock) *
                                                         static_cast<double>(number - first) / span
                             : clock.initial_clock;
    frame.digits = std::to_string(number);
    if (frame.digits.size() < width) frame.digits.insert(0, width - frame.digits.size(), '0');
    frames.push_back(frame);
  }
  return frames;
}

std::string frame_output(const std::string& path, const AnimationFrame& frame) {
  const ssao_tools::FramePattern pattern(path);
  if (pattern.has_frame()) return pattern.path(static_cast<int>(frame.number));
  const size_t slash = path.rfind('/');
  const size_t dot = path.rfind('.');
  const size_t at =
      dot == std::string::npos || (slash != std::string::npos && dot < slash) ? path.size() : dot;
  return path.substr(0, at) + frame.digits + path.substr(at);
}

void declare_frame(const ClockOptions& clock, const AnimationFrame& frame, Symbols& symbols) {
  const long first = clock.initial_frame.value_or(1);
  const long last = clock.final_frame.value_or(first);
  const double span = static_cast<double>(last - first + (clock.cyclic ? 1 : 0));
  const std::pair<const char*, double> values[] = {
      {"frame_number", static_cast<double>(frame.number)},
      {"initial_frame", static_cast<double>(first)},
      {"final_frame", static_cast<double>(last)},
      {"initial_clock", clock.initial_clock},
      {"final_clock", clock.final_clock},
      {"clock_delta", span > 0.0 ? (clock.final_clock - clock.initial_clock) / span : 0.0},
      {"clock_on", 1.0}};
  for (const auto& [name, value] : values) {
    Symbol symbol;
    symbol.kind = Symbol::kValue;
    symbol.value.v.x = value;
    symbol.declared_at = "POV-Ray's animation options (frame " + frame.digits + ")";
    symbols[name] = symbol;
  }
}

}  // namespace povray_ssao
