// SPDX-License-Identifier: MIT
#include "args.h"

#include <string>
#include <vector>

#include "tools/frames.h"

namespace ssao_cli {
namespace {

using ssao_tools::find_param;
using ssao_tools::help_entry;
using ssao_tools::parse_param;
using ssao_tools::split;

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
enum Group { kInputOutput, kOther };
using FrontOption = ssao_tools::FrontOption<Options, Group>;

const std::vector<FrontOption>& front_options() {
  static const std::vector<FrontOption> options = {
      {kInputOutput, "--output", "-o", "OUT.exr",
       "output file (required): .exr writes float data (ZIP); .png, .jpg or .tif an 8-bit sRGB "
       "preview; written to a temporary file and renamed, never over IN.exr",
       [](Options& o, const std::string&, const std::string& v) { o.output = v; }},
      {kInputOutput, "--camera", nullptr, "CAM.json",
       "camera description (required): Blender camera properties and matrix_world, see "
       "docs/conventions.md",
       [](Options& o, const std::string&, const std::string& v) { o.camera = v; }},
      {kInputOutput, "--frames", nullptr, "SPEC",
       "process a sequence: IN.exr, -o and --camera are patterns with one frame placeholder "
       "(#### = 4 digits, @ = 1 digit, %04d; a camera without one serves every frame); SPEC is "
       "A, A-B, A-BxN (every Nth) or a comma-separated list of those, e.g. 1001-1100 or "
       "1,5,9-12. A frame that fails is reported and the others are still written",
       [](Options& o, const std::string& f, const std::string& v) {
         try {
           o.frames = ssao_tools::parse_frames(v);
         } catch (const ssao_tools::Error& e) {
           throw UsageError(std::string(e.what()) + " (" + f + ")");
         }
         o.frames_text = v;
       }},
      {kInputOutput, "--skip-existing", nullptr, nullptr,
       "with --frames: leave frames whose output exists (outputs are written atomically, so a "
       "killed run leaves no half frame)",
       [](Options& o, const std::string&, const std::string&) { o.skip_existing = true; }},
      {kInputOutput, "--chunk-size", nullptr, "N",
       "with --frames, for farms: cut the frame list, in order, into chunks of N frames (the "
       "last one may be shorter); see --chunk-index, --list-chunks and docs/farm.md",
       [](Options& o, const std::string& f, const std::string& v) {
         const int size = ssao_tools::parse_int(f, v);
         if (size < 1) throw UsageError(f + " must be at least 1, got " + v);
         o.chunk_size = size_t(size);
       }},
      {kInputOutput, "--chunk-index", nullptr, "I",
       "with --chunk-size: process only chunk I (0 is the first), e.g. $SLURM_ARRAY_TASK_ID",
       [](Options& o, const std::string& f, const std::string& v) {
         const int index = ssao_tools::parse_int(f, v);
         if (index < 0) throw UsageError(f + " must be 0 or more, got " + v);
         o.chunk_index = index;
       }},
      {kInputOutput, "--list-chunks", nullptr, nullptr,
       "with --chunk-size: print one line per chunk, 'INDEX FRAMES' (FRAMES as --frames reads "
       "them), and exit; IN.exr, -o and --camera may be left out (if IN.exr is given, the whole "
       "command line is checked)",
       [](Options& o, const std::string&, const std::string&) { o.list_chunks = true; }},
      {kOther, "--progress", nullptr, "text|json",
       "with --frames: a line per frame on stderr, as text (default) or one JSON object per line",
       [](Options& o, const std::string& f, const std::string& v) {
         if (v != "text" && v != "json")
           throw UsageError(f + " must be text or json, got '" + v + "'");
         o.json_progress = v == "json";
       }},
      {kInputOutput, "--ao-only", nullptr, nullptr,
       "write exactly one channel, AO, instead of beauty x AO + AO",
       [](Options& o, const std::string&, const std::string&) { o.ao_only = true; }},
      {kInputOutput, "--layer", nullptr, "NAME",
       "view layer to read when several have a Depth pass",
       [](Options& o, const std::string&, const std::string& v) { o.layer = v; }},
      {kInputOutput, "--depth-channel", nullptr, "NAME",
       "depth channel (default <layer>.Depth.Z, or Depth.Z, Z, depth, Depth without layers)",
       [](Options& o, const std::string&, const std::string& v) { o.depth_channel = v; }},
      {kInputOutput, "--normal-channels", nullptr, "X,Y,Z",
       "normal channels (default <layer>.Normal.X,Y,Z, or Normal.* / N.* without layers)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.normal_channels = parse_channel_list(f, v, 3, 3);
       }},
      {kInputOutput, "--beauty-channels", nullptr, "R,G,B[,A]",
       "beauty channels (default <layer>.Combined.R,G,B[,A], or Combined.* / R,G,B[,A])",
       [](Options& o, const std::string& f, const std::string& v) {
         o.beauty_channels = parse_channel_list(f, v, 3, 4);
       }},
      {kInputOutput, "--depth-layer", nullptr, "DEPTH[:FACING]",
       "repeatable, in hit order: the channel of the depth of the 2nd surface hit along each "
       "pixel's ray, then the 3rd, ... (up to the 5th), each with its facing channel (1 = back "
       "face) "
       "if any (default <layer>.Depth2.Z with <layer>.Facing2.V, Depth3.Z, ... when present); "
       "see docs/cli.md",
       [](Options& o, const std::string& f, const std::string& v) {
         const size_t colon = v.find(':');
         const std::string depth = v.substr(0, colon);
         const std::string facing = colon == std::string::npos ? "" : v.substr(colon + 1);
         if (depth.empty() || (colon != std::string::npos && facing.empty())) {
           throw UsageError(f + ": expected DEPTH_CHANNEL or DEPTH_CHANNEL:FACING_CHANNEL, got '" +
                            v + "'");
         }
         if (o.depth_layers.size() == ssao_tools::kMaxDepthLayers) {
           throw UsageError(f + " is given more than " +
                            std::to_string(ssao_tools::kMaxDepthLayers) +
                            " times: the library takes the 2nd to the 5th hit");
         }
         o.depth_layers.push_back({depth, facing});
       }},
      {kInputOutput, "--no-depth-layers", nullptr, nullptr,
       "ignore the extra depth layers a file has (one depth layer, as without them)",
       [](Options& o, const std::string&, const std::string&) { o.no_depth_layers = true; }},
      {kInputOutput, "--no-normals", nullptr, nullptr,
       "ignore the normal pass; reconstruct normals from depth",
       [](Options& o, const std::string&, const std::string&) { o.no_normals = true; }},
      {kOther, "--quiet", "-q", nullptr,
       "no progress, no summary, no warnings (errors are still shown)",
       [](Options& o, const std::string&, const std::string&) { o.quiet = true; }},
      {kOther, "--help", "-h", nullptr, "print this help and exit",
       [](Options& o, const std::string&, const std::string&) { o.help = true; }},
      {kOther, "--version", nullptr, nullptr, "print the library version and exit",
       [](Options& o, const std::string&, const std::string&) { o.version = true; }},
  };
  return options;
}

// --chunk-size / --chunk-index / --list-chunks: checked, and --frames narrowed to the chunk.
void apply_chunking(Options& options) {
  options.sequence = options.frames;
  if (options.chunk_size == 0) {
    if (options.chunk_index >= 0 || options.list_chunks) {
      throw UsageError("--chunk-index and --list-chunks need --chunk-size N");
    }
    return;
  }
  if (options.frames.empty()) throw UsageError("--chunk-size applies to sequences (--frames)");
  if (options.list_chunks && options.chunk_index >= 0) {
    throw UsageError("--list-chunks lists every chunk: leave out --chunk-index");
  }
  if (options.chunk_index >= 0) {
    try {
      options.frames =
          ssao_tools::chunk_frames(options.frames, options.chunk_size, size_t(options.chunk_index));
    } catch (const ssao_tools::Error& e) {
      throw UsageError(std::string("--chunk-index: ") + e.what() + " (--frames " +
                       options.frames_text + ")");
    }
  }
}

void require_complete(const Options& options) {
  // --list-chunks needs only --frames and --chunk-size; a full command line is checked whole.
  if (options.list_chunks && options.input.empty()) return;
  if (options.input.empty()) throw UsageError("missing the input file IN.exr");
  if (options.output.empty()) throw UsageError("missing the output file: -o OUT.exr");
  if (options.camera.empty()) throw UsageError("missing the camera description: --camera CAM.json");
  if (options.no_normals && !options.normal_channels.empty()) {
    throw UsageError("--no-normals and --normal-channels contradict each other");
  }
  if (options.no_depth_layers && !options.depth_layers.empty()) {
    throw UsageError("--no-depth-layers and --depth-layer contradict each other");
  }
  if (options.frames.empty() && (options.skip_existing || options.json_progress)) {
    throw UsageError("--skip-existing and --progress apply to sequences (--frames)");
  }
}

}  // namespace

Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table) {
  Options out;
  if (ssao_tools::scan_help_and_version(argc, argv, out)) return out;

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

    ssao_tools::parse_option(argc, argv, i, front_options(), table, out);
  }
  apply_chunking(out);
  require_complete(out);
  return out;
}

std::string usage_text(const std::vector<ssao_param_desc>& table) {
  std::string text =
      "Usage: ssao IN.exr -o OUT.exr --camera CAM.json [options]\n"
      "       ssao 'IN.####.exr' -o 'OUT.####.exr' --camera 'CAM[.####].json' --frames A-B\n"
      "            --radius R [options]\n"
      "\n"
      "Screen-space ambient occlusion of a rendered image. Reads Blender's multilayer EXR\n"
      "(<layer>.Depth.Z, <layer>.Normal.X/Y/Z, <layer>.Combined.R/G/B/A; other files with\n"
      "plain channel names work too) and writes OUT.exr with R,G,B[,A] = beauty x AO (alpha\n"
      "copied; on a silhouette against the sky only the surface's share of the pixel, the\n"
      "Normal pass's length, is darkened) and an AO channel (1 = unoccluded), or only AO with\n"
      "--ao-only.\n"
      "Without --radius, the radius is the camera file's \"ao_distance\", else 10% of the\n"
      "view's width at the median depth (printed); a sequence needs --radius or ao_distance,\n"
      "so that its frames share one radius.\n"
      "\n"
      "Input and output:\n";
  text += help_entry("IN.exr", "input image (any file OpenImageIO reads)");
  for (const Group group : {kInputOutput, kOther}) {
    if (group == kOther) text += "\nOther:\n";
    for (const FrontOption& option : front_options()) {
      if (option.group != group) continue;
      std::string left =
          option.alias ? std::string(option.alias) + ", " + option.flag : option.flag;
      if (option.metavar) left += std::string(" ") + option.metavar;
      text += help_entry(left, option.help);
    }
  }

  // The library's parameters, a section per group (ssao_param_group), in the table's order.
  const auto param_section = [&](const char* group, const char* title) {
    text += std::string("\n") + title + "\n";
    text += ssao_tools::param_help(table, [&](const ssao_param_desc& desc) {
      return ssao_tools::param_group_of(desc.name) == group;
    });
  };
  param_section("ao",
                "AO parameters (libssao's parameter table; --NAME_WITH_UNDERSCORES is written "
                "with dashes):");
  param_section("quality", "Quality parameters (how much work: time against noise):");
  param_section("shaping", "Shaping parameters (the final look of the AO):");
  param_section("input", "Input conventions (how the passes are read):");
  param_section("camera",
                "Camera parameters (set from --camera CAM.json, matrix_world giving\n"
                "camera_to_world; a flag given here overrides the file):");
  param_section("execution",
                "Execution and sequences (threads: results do not depend on it; frame and\n"
                "temporal_frames: the temporal filter of --frames sequences):");

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
