// SPDX-License-Identifier: MIT
// Command-line parsing of the ssao tool. The AO and camera parameters are not listed here: every
// parameter of the core's table (ssao_param_info) is accepted as --NAME-WITH-DASHES VALUE and
// parsed according to its type, and --help prints the table.
#pragma once

#include <string>
#include <vector>

#include "ssao/ssao.h"
#include "tools/blender_passes.h"
#include "tools/param_flags.h"

namespace ssao_cli {

// A wrong command line: reported with a hint to --help, exit status 2. The parameter flags
// (--NAME-WITH-DASHES, parsing, help) are shared with the other front ends: io/param_flags.h.
using ssao_tools::flag_for;
using ssao_tools::ParamSetting;
using ssao_tools::UsageError;

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
  // --depth-layer DEPTH[:FACING], in hit order (the first names the 2nd hit).
  std::vector<ssao_tools::DepthLayerChannels> depth_layers;
  bool no_depth_layers = false;
  std::vector<ParamSetting> params;  // in command-line order
  // Sequences: IN, -o and --camera are patterns (#, @, %04d) with --frames.
  std::vector<int> frames;  // empty: one file
  std::string frames_text;
  bool skip_existing = false;
  bool json_progress = false;
  // The whole --frames list, also when `frames` holds one chunk of it: the frames before a
  // chunk that the temporal filter reads.
  std::vector<int> sequence;
  // Farm chunks: with chunk_index >= 0, `frames` holds only that chunk once parsed.
  size_t chunk_size = 0;  // 0: no chunking
  int chunk_index = -1;
  bool list_chunks = false;
};

// Parses argv. With --help or --version anywhere, only that flag is honoured. Throws UsageError
// for an unknown option, a missing value, a value of the wrong type (e.g. "--samples abc",
// "--radius nan"), a choice that does not exist, or a missing input, -o or --camera.
Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table);

// The text --help prints, parameters (defaults, units, ranges, choices) taken from `table`.
std::string usage_text(const std::vector<ssao_param_desc>& table);

}  // namespace ssao_cli
