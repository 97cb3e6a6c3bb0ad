// SPDX-License-Identifier: MIT
#include "tools/frames.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <set>

namespace ssao_tools {
namespace {

std::string quoted(const std::string& text) { return "'" + text + "'"; }

// Reads an optionally signed integer at text[pos]; advances pos.
bool read_int(const std::string& text, size_t& pos, long long& value) {
  const size_t start = pos;
  if (pos < text.size() && (text[pos] == '-' || text[pos] == '+')) ++pos;
  const size_t digits = pos;
  while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) ++pos;
  if (pos == digits || pos - digits > 12) {
    pos = start;
    return false;
  }
  value = std::strtoll(text.c_str() + start, nullptr, 10);
  return value >= INT_MIN && value <= INT_MAX;
}

}  // namespace

std::vector<int> parse_frames(const std::string& spec) {
  std::vector<int> frames;
  std::set<int> seen;
  size_t begin = 0;
  while (true) {
    const size_t comma = spec.find(',', begin);
    const std::string part =
        spec.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    const std::string where = "--frames " + quoted(spec) + ": " + quoted(part);
    size_t pos = 0;
    long long first = 0, last = 0, step = 1;
    if (!read_int(part, pos, first)) {
      throw Error(where + " is not a frame number or range (A, A-B or A-BxN)");
    }
    last = first;
    if (pos < part.size() && part[pos] == '-') {
      ++pos;
      if (!read_int(part, pos, last)) throw Error(where + ": the range has no valid end");
      if (pos < part.size() && part[pos] == 'x') {
        ++pos;
        if (!read_int(part, pos, step) || step <= 0) {
          throw Error(where + ": the step after 'x' must be a positive number");
        }
      }
    }
    if (pos != part.size()) throw Error(where + " has extra characters");
    if (last < first) throw Error(where + " runs backwards");
    if (static_cast<unsigned long long>((last - first) / step + 1) > kMaxFrames - frames.size()) {
      throw Error("--frames " + quoted(spec) + ": more than " + std::to_string(kMaxFrames) +
                  " frames");
    }
    for (long long frame = first; frame <= last; frame += step) {
      if (!seen.insert(int(frame)).second) {
        throw Error("--frames " + quoted(spec) + ": frame " + std::to_string(frame) +
                    " is given twice");
      }
      frames.push_back(int(frame));
    }
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  return frames;
}

std::string format_frames(const std::vector<int>& frames) {
  std::string spec;
  for (size_t i = 0; i < frames.size();) {
    // The longest run from frames[i] with one positive step; three frames at least, so that a
    // pair of unrelated frames is not written as a range (a step-1 pair is: "7-8").
    size_t end = i + 1;
    const long long step = end < frames.size() ? (long long)frames[end] - frames[i] : 0;
    if (step > 0) {
      while (end < frames.size() && (long long)frames[end] - frames[end - 1] == step) ++end;
    }
    const size_t length = end - i;
    if (!spec.empty()) spec += ',';
    if (step > 0 && (length >= 3 || (length == 2 && step == 1))) {
      spec += std::to_string(frames[i]) + "-" + std::to_string(frames[end - 1]);
      if (step > 1) spec += "x" + std::to_string(step);
      i = end;
    } else {
      spec += std::to_string(frames[i]);
      ++i;
    }
  }
  return spec;
}

size_t chunk_count(size_t frame_count, size_t chunk_size) {
  return chunk_size == 0 ? 0 : (frame_count + chunk_size - 1) / chunk_size;
}

std::vector<int> chunk_frames(const std::vector<int>& frames, size_t chunk_size, size_t index) {
  const size_t count = chunk_count(frames.size(), chunk_size);
  if (index >= count) {
    throw Error("chunk " + std::to_string(index) +
                " does not exist: " + std::to_string(frames.size()) + " frames in chunks of " +
                std::to_string(chunk_size) + " make " + std::to_string(count) + " chunks (0-" +
                std::to_string(count == 0 ? 0 : count - 1) + ")");
  }
  const size_t first = index * chunk_size;
  const size_t last = std::min(frames.size(), first + chunk_size);
  return std::vector<int>(frames.begin() + long(first), frames.begin() + long(last));
}

FramePattern::FramePattern(const std::string& text) : text_(text) {
  size_t start = std::string::npos, end = 0;
  // Only the file name holds the placeholder: folders keep their '#', '@' and '%' as they are.
  const size_t slash = text.rfind('/');
  for (size_t i = slash == std::string::npos ? 0 : slash + 1; i < text.size();) {
    size_t run_end = i;
    int width = -1;
    if (text[i] == '#' || text[i] == '@') {
      while (run_end < text.size() && text[run_end] == text[i]) ++run_end;
      width = int(run_end - i);
    } else if (text[i] == '%') {
      size_t j = i + 1;
      const bool zero = j < text.size() && text[j] == '0';
      if (zero) ++j;
      const size_t digits = j;
      while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
      if (j < text.size() && text[j] == 'd' && (j > digits || !zero) && j - digits <= 2) {
        width = j > digits ? std::atoi(text.substr(digits, j - digits).c_str()) : 0;
        run_end = j + 1;
      }
    }
    if (width < 0) {
      ++i;
      continue;
    }
    if (start != std::string::npos) {
      throw Error("the file name " + quoted(text) + " has more than one frame placeholder");
    }
    start = i, end = run_end, width_ = width;
    i = run_end;
  }
  if (start != std::string::npos) {
    prefix_ = text.substr(0, start);
    suffix_ = text.substr(end);
  }
}

FramePattern FramePattern::literal(const std::string& text) {
  FramePattern pattern("");
  pattern.text_ = text;
  return pattern;
}

std::string FramePattern::path(int frame) const {
  if (!has_frame()) return text_;
  std::string digits = std::to_string(frame < 0 ? -static_cast<long long>(frame) : frame);
  if (int(digits.size()) < width_) digits.insert(0, size_t(width_) - digits.size(), '0');
  return prefix_ + (frame < 0 ? "-" : "") + digits + suffix_;
}

}  // namespace ssao_tools
