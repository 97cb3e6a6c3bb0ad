// SPDX-License-Identifier: MIT
// POV-Ray animations: the clock and animation options (as POV-Ray reads them from INI files and
// the command line) and the frames povray-ssao renders for them, numbered and named as POV-Ray
// numbers its own output files.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sdl.h"

namespace povray_ssao {

// Clock=/+K, Initial_Frame=/+KFI, Final_Frame=/+KFF, Initial_Clock=/+KI, Final_Clock=/+KF,
// Subset_Start_Frame=/+SF, Subset_End_Frame=/+EF and Cyclic_Animation=/+KC/-KC; a later setting
// wins, as in POV-Ray.
struct ClockOptions {
  double clock = 0.0;  // a still's clock
  std::optional<long> initial_frame, final_frame, subset_start, subset_end;
  double initial_clock = 0.0, final_clock = 1.0;
  bool cyclic = false;
  std::string unreadable;  // the first animation option povray-ssao cannot use, or ""
  bool animated() const { return initial_frame || final_frame; }
};

// Reads one INI line or command-line option into `clock` if it is a clock or animation option;
// returns whether it was one.
bool read_clock_option(const std::string& option, ClockOptions& clock);

struct AnimationFrame {
  long number = 0;     // POV-Ray's frame_number
  double clock = 0.0;  // POV-Ray's clock for it
  std::string digits;  // the number as POV-Ray appends it to output names: zero-padded to the
                       // final frame's digits ("03" of 1..24)
};

// The frames POV-Ray renders: Initial_Frame (default 1) to Final_Frame (default the initial
// frame), limited to Subset_Start_Frame..Subset_End_Frame; clock = Initial_Clock + (Final_Clock -
// Initial_Clock) (frame - Initial_Frame) / (Final_Frame - Initial_Frame), with one more frame in
// the divisor for Cyclic_Animation, and Initial_Clock when there is a single frame. Throws
// ssao_tools::UsageError for a range that runs backwards, negative frame numbers, an empty subset
// or an option povray-ssao cannot use (a subset given as a fraction).
std::vector<AnimationFrame> animation_frames(const ClockOptions& clock);

// The output of one frame: a frame placeholder in the file name (#### = 4 digits, @, %04d) takes
// the frame number; else the number goes before the extension, as POV-Ray names its frames
// ("out.png" -> "out03.png").
std::string frame_output(const std::string& path, const AnimationFrame& frame);

// The animation identifiers of one frame (frame_number, initial_frame, final_frame,
// initial_clock, final_clock, clock_delta, clock_on) as values the scene scanner reads.
void declare_frame(const ClockOptions& clock, const AnimationFrame& frame, Symbols& symbols);

}  // namespace povray_ssao
