// SPDX-License-Identifier: MIT
// ssao_eval: scores AO methods against the ray-traced AO pass of a Blender render.
//
//   ssao_eval SCENE.exr --camera CAM.json --radius R --method M [options]
//   ssao_eval SCENE.exr --camera CAM.json --radius R --run "M NAME=VALUE ..." --run ... [options]
//
// Methods: "ssao" (libssao through the C API, configured with --set name=value), the
// references of tests/reference: "seed-hemisphere", "seed-sphere" (ports of the seed tutorials'
// code) and "raymarch" (brute-force depth-buffer ray march), and "image" (an AO image from a
// file, such as Cycles' AO pass at fewer samples: scored, not timed). The score is the RMSE and
// the mean signed error (method - truth) of the AO over the pixels whose depth is finite, > 0
// and < 0.9 * clip_end, against the file's "<layer>.AO.R" channel (Cycles' AO pass), plus two
// figures of where the error lies: "band", the RMSE of the difference of the band-passes
// G(1) - G(6) of the two images (detail of 1 to 6 px: contact shadows, creases) and "edge_rmse",
// the RMSE at depth discontinuities (see kUsage for their masks). Several methods are timed in
// interleaved rounds (A B A B ...), so that their ratios share the machine's moods. Run with --help
// for the options. Exit status: 0 success, 1 a failed check
// (--max-rmse, --compare-to) or an unreadable input, 2 a command-line mistake.
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "camera.h"       // core/src (through ssao_reference): the camera model of the references
#include "camera_file.h"  // and the camera file's reader
#include "reference_ao.h"
#include "ssao/ssao.hpp"
#include "tools/blender_passes.h"
#include "tools/camera_json.h"
#include "tools/image_io.h"

namespace {

constexpr const char* kProgram = "ssao_eval";

// A command-line mistake: exit status 2.
class UsageError : public std::runtime_error {
 public:
  explicit UsageError(const std::string& message) : std::runtime_error(message) {}
};

const char* const kUsage =
    "Usage: ssao_eval SCENE.exr --camera CAM.json --radius R --method M [options]\n"
    "       ssao_eval SCENE.exr --camera CAM.json --radius R --run \"M NAME=VALUE ...\" ...\n"
    "\n"
    "Scores AO methods against the ray-traced AO pass (<layer>.AO.R) of a Blender multilayer\n"
    "EXR with Depth (and optionally Normal) passes. Prints one line per method:\n"
    "  scene=... method=... settings=... normals=pass|depth rmse=... mean_error=... time_ms=...\n"
    "  min_ms=... repeat=N threads=T pixels=P rmse_interior=... interior_pixels=P\n"
    "  band=... edge_rmse=...\n"
    "over the pixels whose depth is finite, > 0 and < 0.9 * clip_end (the geometry pixels).\n"
    "mean_error is the mean of (method - truth): positive means too little occlusion. time_ms\n"
    "is the median of --repeat runs of the AO computation alone (no file I/O), min_ms the\n"
    "fastest; the methods run in interleaved rounds (A B C A B C ...), each timed run right\n"
    "after an untimed run of the same method.\n"
    "An image method is not timed (nan). rmse_interior leaves out the pixels beside one outside\n"
    "that set: on a silhouette against the sky Cycles' pass reads coverage x AO (sky samples\n"
    "add nothing).\n"
    "band: the RMSE of the difference of the band-passes G(1) - G(6) of the method's AO and\n"
    "the truth (G(s): Gaussian blur of sigma s px, separable, truncated at 3 sigma,\n"
    "clamp-to-edge; every pixel outside the geometry set at AO 1 in both images), over the\n"
    "geometry pixels whose whole 7x7 square (the pixels within 3 px, Chebyshev distance)\n"
    "inside the frame is geometry: the error at the scale of contact shadows and creases,\n"
    "without the large-scale bias (G(1) smooths away most per-pixel noise: white noise keeps\n"
    "0.27 of its RMS). edge_rmse: the RMSE over the geometry pixels with a depth\n"
    "jump to a 4-neighbour that is geometry too, |d - d_n| > 0.05 * min(d, d_n) (edges\n"
    "against the sky do not count). Either is nan when it has no pixel. With region=, the\n"
    "pixels outside the region count as outside the geometry.\n"
    "\n"
    "Methods:\n"
    "  ssao             libssao through its C API; world-space normals from the Normal pass\n"
    "                   with the camera's matrix_world. --set takes any core parameter\n"
    "                   (variant, samples, steps, bias, denoise, threads, ...)\n"
    "  seed-hemisphere  port of the seed normal-oriented hemisphere tutorial (--set samples=N,\n"
    "                   seed=N)\n"
    "  seed-sphere      port of the seed Crysis sphere code (--set samples=N, seed=N)\n"
    "  raymarch         brute-force ray march through the depth buffer (--set rays=N,\n"
    "                   steps=N, thickness=F (fraction of radius), seed=N)\n"
    "  image            an AO image from a file, e.g. Cycles' AO pass at fewer samples\n"
    "                   (--set path=FILE; channel=NAME, default the one channel AO, AO.R\n"
    "                   or <layer>.AO.R;\n"
    "                   region=MIN_X,MAX_X,MIN_Y,MAX_Y scores only that part of the frame, in\n"
    "                   fractions measured from the bottom left, as Blender's render border)\n"
    "\n"
    "Options:\n"
    "  --camera FILE        camera JSON (required)\n"
    "  --radius R           AO distance in scene units, as Cycles' (required)\n"
    "  --method M           method to score (required unless --run is given)\n"
    "  --set NAME=VALUE     parameter of the method (repeatable); arrays as a,b,c\n"
    "  --run \"M N=V ...\"    one more method with its parameters, separated by spaces\n"
    "                       (repeatable; the first --run is the method when --method is not\n"
    "                       given)\n"
    "  --repeat N           time N runs of each method, report the median (default 1)\n"
    "  --max-rmse X         exit 1 if the RMSE is above X\n"
    "  --compare-to M2      also score M2 (with its defaults and --compare-set) and exit 1\n"
    "                       unless RMSE(M) < RMSE(M2) * (1 - margin)\n"
    "  --compare-set N=V    parameter of M2 (repeatable)\n"
    "  --margin F           relative margin of --compare-to, in [0, 1) (default 0)\n"
    "  --write-ao OUT.exr   write the AO of M (channel AO) to OUT.exr\n"
    "  --layer NAME         view layer to read when the file has several\n"
    "  --layers FILE        the scene's extra depth layers and guard band, as\n"
    "                       scripts/blender/render_layers.py writes them (same camera, pixel\n"
    "                       grid and seed); method ssao then takes layers=N (extra hits to\n"
    "                       use, default 0) and band=G (guard band pixels, default 0). As\n"
    "                       the Blender add-on does, a hit not behind the depth the library\n"
    "                       is given (the scene's in the frame) is dropped and the later\n"
    "                       ones move up; stderr says at how many pixels\n"
    "  --no-normals         ignore the Normal pass: every method reconstructs normals from depth\n"
    "  -h, --help           show this help\n"
    "\n"
    "Exit status: 0 success, 1 a failed check or an input error, 2 a usage error.\n";

struct Setting {
  std::string name;
  std::string value;
};

// A method to run and its settings.
struct RunSpec {
  std::string method;
  std::vector<Setting> settings;
  std::string flag = "--run";  // where the settings came from, for messages
};

struct Options {
  std::string scene;
  std::string camera;
  double radius = 0.0;
  std::string method;
  std::vector<Setting> settings;
  std::string method_flag = "--set";  // the option that gave the method's settings
  std::vector<RunSpec> more_runs;     // --run, after the --method one
  int repeat = 1;
  bool has_max_rmse = false;
  double max_rmse = 0.0;
  std::string compare_to;
  std::vector<Setting> compare_settings;
  double margin = 0.0;
  std::string write_ao;
  std::string layer;
  std::string layers_file;
  bool no_normals = false;
  bool help = false;
};

const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names = {"ssao", "seed-hemisphere", "seed-sphere",
                                                 "raymarch", "image"};
  return names;
}

std::string join(const std::vector<std::string>& items, const char* separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

double parse_double(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE ||
      !std::isfinite(value)) {
    throw UsageError(what + ": expected a finite number, got '" + text + "'");
  }
  return value;
}

std::vector<double> parse_double_list(const std::string& text, const std::string& what) {
  std::vector<double> values;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) values.push_back(parse_double(item, what));
  return values;
}

long long parse_integer(const std::string& text, const std::string& what, long long lo,
                        long long hi) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) {
    throw UsageError(what + ": expected an integer, got '" + text + "'");
  }
  if (value < lo || value > hi) {
    throw UsageError(what + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got " + text);
  }
  return value;
}

Setting parse_setting(const std::string& text, const std::string& flag) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw UsageError(flag + " '" + text + "': expected NAME=VALUE");
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

void check_method(const std::string& method, const std::string& flag) {
  const auto& names = method_names();
  if (std::find(names.begin(), names.end(), method) == names.end()) {
    throw UsageError(flag + ": unknown method '" + method + "' (methods: " + join(names, ", ") +
                     ")");
  }
}

Options parse_args(int argc, char** argv) {
  Options o;
  bool has_radius = false;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      o.help = true;
      return o;
    }
    if (arg == "--") {
      for (++i; i < argc; ++i) positional.emplace_back(argv[i]);
      break;
    }
    if (arg.size() < 2 || arg[0] != '-') {
      positional.push_back(arg);
      continue;
    }
    // --flag value or --flag=value.
    std::string inline_value;
    bool has_inline = false;
    const size_t eq = arg.find('=');
    if (arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      inline_value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_inline = true;
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (i + 1 >= argc) throw UsageError(arg + " needs a value");
      return argv[++i];
    };
    auto no_value = [&] {
      if (has_inline) throw UsageError(arg + " takes no value");
    };
    if (arg == "--camera") {
      o.camera = value();
    } else if (arg == "--radius") {
      o.radius = parse_double(value(), "--radius");
      if (!(o.radius > 0.0)) throw UsageError("--radius must be positive");
      has_radius = true;
    } else if (arg == "--method") {
      o.method = value();
      check_method(o.method, "--method");
    } else if (arg == "--set") {
      o.settings.push_back(parse_setting(value(), "--set"));
    } else if (arg == "--run") {
      std::istringstream words(value());
      RunSpec run;
      std::string word;
      if (!(words >> run.method)) throw UsageError("--run needs a method");
      check_method(run.method, "--run");
      while (words >> word) run.settings.push_back(parse_setting(word, "--run"));
      o.more_runs.push_back(run);
    } else if (arg == "--repeat") {
      o.repeat = static_cast<int>(parse_integer(value(), "--repeat", 1, 1000));
    } else if (arg == "--max-rmse") {
      o.max_rmse = parse_double(value(), "--max-rmse");
      if (o.max_rmse < 0.0) throw UsageError("--max-rmse must not be negative");
      o.has_max_rmse = true;
    } else if (arg == "--compare-to") {
      o.compare_to = value();
      check_method(o.compare_to, "--compare-to");
    } else if (arg == "--compare-set") {
      o.compare_settings.push_back(parse_setting(value(), "--compare-set"));
    } else if (arg == "--margin") {
      o.margin = parse_double(value(), "--margin");
      if (!(o.margin >= 0.0 && o.margin < 1.0)) throw UsageError("--margin must be in [0, 1)");
    } else if (arg == "--write-ao") {
      o.write_ao = value();
    } else if (arg == "--layer") {
      o.layer = value();
    } else if (arg == "--layers") {
      o.layers_file = value();
    } else if (arg == "--no-normals") {
      no_value();
      o.no_normals = true;
    } else {
      throw UsageError("unknown option '" + arg + "'");
    }
  }
  if (positional.empty()) throw UsageError("no scene EXR given");
  if (positional.size() > 1) {
    throw UsageError("one scene EXR expected, got " + std::to_string(positional.size()) + ": " +
                     join(positional, " "));
  }
  o.scene = positional.front();
  if (o.camera.empty()) throw UsageError("--camera CAM.json is required");
  if (!has_radius) throw UsageError("--radius R is required");
  if (o.method.empty()) {
    if (o.more_runs.empty()) throw UsageError("--method M is required (or give --run)");
    if (!o.settings.empty()) throw UsageError("--set needs --method (use --run \"M N=V\")");
    o.method = o.more_runs.front().method;
    o.settings = o.more_runs.front().settings;
    o.method_flag = "--run";
    o.more_runs.erase(o.more_runs.begin());
  }
  if (o.compare_to.empty() && !o.compare_settings.empty()) {
    throw UsageError("--compare-set needs --compare-to");
  }
  if (o.compare_to.empty() && o.margin != 0.0) throw UsageError("--margin needs --compare-to");
  return o;
}

// ---------------------------------------------------------------------------------------------
// The scene: the passes every method reads, and the ground truth.

struct Scene {
  std::string name;  // file name without folder and extension
  std::string path;
  int width = 0, height = 0;
  // The camera file's text (the library reads it for the core) and what the references need of
  // it, read back from a job it was applied to.
  std::string camera_text;
  ssao::CameraParams camera;
  double clip_end = 0.0;             // 0: no clip test
  std::vector<double> matrix_world;  // camera-to-world, row-major, 16 values
  std::vector<float> depth;          // planar, 1 channel
  std::vector<float> world_normal;   // 3 channels or empty
  std::vector<float> beauty;         // the Combined pass's R, G, B, or empty
  std::vector<float> truth;          // the AO pass
  std::vector<unsigned char> mask;   // pixels that are scored
  size_t scored = 0;
  // From --layers: the same render's passes on a frame grown by `band` pixels a side (the
  // display window at (band, band)), and its 2nd, 3rd, ... hits with their facing.
  int band = 0;
  std::vector<float> band_depth, band_normal;
  std::vector<std::vector<float>> layer_depth, layer_facing;
};

// Blender's depth where a ray hits nothing (the layers file's "no hit").
constexpr float kNoHit = 1e10f;

// Whether the library takes `depth` for a surface: its default background rule (finite, > 0,
// below background_depth 1e9 and clip_end; docs/conventions.md, "Depth").
bool is_surface(float depth, double clip_end) {
  return std::isfinite(depth) && depth > 0.0f && depth < 1e9f &&
         (clip_end <= 0.0 || static_cast<double>(depth) < clip_end);
}

// The extra hits of the layers file as the Blender add-on gives them to the library
// (blender_addon/compute.py, _extra_layers): behind the depth the library is given (the scene's
// in the frame, the layers file's in the band). The helper render's first hit can differ from
// the reference's depth (on a silhouette its one sample need not be the reference's), so a hit
// not strictly behind that depth is dropped and the later ones move up, in depth order; the
// empty places are "no hit" (facing 0). Prints on stderr at how many surface pixels a hit moved
// or went.
void drop_hits_not_behind(const Options& o, Scene& s) {
  const size_t layers = s.layer_depth.size();
  if (layers == 0) return;
  const int band = s.band, grid_width = s.width + 2 * band, grid_height = s.height + 2 * band;
  std::vector<std::pair<float, float>> hits;  // (depth, facing) of one pixel
  size_t in_frame = 0, in_band = 0;
  for (int y = 0; y < grid_height; ++y) {
    for (int x = 0; x < grid_width; ++x) {
      const size_t p = size_t(y) * size_t(grid_width) + size_t(x);
      const int fx = x - band, fy = y - band;
      const bool inside = fx >= 0 && fy >= 0 && fx < s.width && fy < s.height;
      const float depth =
          inside ? s.depth[size_t(fy) * size_t(s.width) + size_t(fx)] : s.band_depth[p];
      hits.clear();
      for (size_t k = 0; k < layers; ++k) {
        const float d = s.layer_depth[k][p];
        if (d > depth) {  // false for NaN
          hits.emplace_back(d, s.layer_facing[k].empty() ? 0.0f : s.layer_facing[k][p]);
        }
      }
      std::stable_sort(hits.begin(), hits.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      bool changed = false;
      for (size_t k = 0; k < layers; ++k) {
        const std::pair<float, float> hit =
            k < hits.size() ? hits[k] : std::make_pair(kNoHit, 0.0f);
        // NaN compares unequal: a NaN hit (dropped) counts as a change.
        changed = changed || !(s.layer_depth[k][p] == hit.first);
        s.layer_depth[k][p] = hit.first;
        if (!s.layer_facing[k].empty()) s.layer_facing[k][p] = hit.second;
      }
      if (changed && is_surface(depth, s.clip_end)) ++(inside ? in_frame : in_band);
    }
  }
  std::fprintf(stderr,
               "%s: --layers '%s': hits not behind the depth dropped (the later ones moved up, "
               "as the Blender add-on does) at %zu pixel(s): %zu in the frame, %zu in the band\n",
               kProgram, o.layers_file.c_str(), in_frame + in_band, in_frame, in_band);
}

// Reads --layers FILE into the scene: a data window grown by the same band on every side.
void load_layers(const Options& o, Scene& s) {
  ssao_tools::Image image = ssao_tools::read_image(o.layers_file, ssao_tools::Overscan::read);
  const int band = image.frame_x;
  if (image.frame_width != s.width || image.frame_height != s.height || image.frame_y != band ||
      image.width != s.width + 2 * band || image.height != s.height + 2 * band) {
    throw ssao_tools::Error("'" + o.layers_file + "' is not the scene's frame (" +
                            std::to_string(s.width) + "x" + std::to_string(s.height) +
                            ") with the same guard band on every side");
  }
  ssao_tools::PassOverrides overrides;
  overrides.layer = o.layer;
  const ssao_tools::PassChannels passes =
      ssao_tools::detect_passes(image.channel_names, overrides, o.layers_file);
  const auto channel = [&](const std::string& name) {
    return ssao_tools::extract_named_channels(image, {name}, o.layers_file);
  };
  s.band = band;
  s.band_depth = channel(passes.depth);
  if (passes.normal.size() == 3) {
    s.band_normal = ssao_tools::extract_named_channels(image, passes.normal, o.layers_file);
  }
  for (const ssao_tools::DepthLayerChannels& layer : passes.depth_layers) {
    s.layer_depth.push_back(channel(layer.depth));
    s.layer_facing.push_back(layer.facing.empty() ? std::vector<float>() : channel(layer.facing));
  }
  drop_hits_not_behind(o, s);
}

Scene load_scene(const Options& o) {
  Scene s;
  s.path = o.scene;
  s.name = std::filesystem::path(o.scene).stem().string();
  // The camera first: it is small and a mistake there is cheaper to find.
  s.camera_text = ssao_tools::read_camera_text(o.camera);
  {
    // The library's own reader (core/src/camera_file.h, which the C API calls), into
    // parameters the references read from.
    ssao::ParamValues params;
    ssao::CameraFile file;
    try {
      file = ssao::apply_camera_json(s.camera_text, o.camera, params);
    } catch (const ssao::api::Error& e) {
      throw ssao_tools::Error(e.what());
    }
    for (const std::string& key : file.unknown_keys) {
      std::fprintf(stderr, "%s: warning: camera file '%s': unknown key '%s' ignored\n", kProgram,
                   o.camera.c_str(), key.c_str());
    }
    s.camera = ssao::camera_params(params);
    s.clip_end = params.get_float("clip_end");
    s.matrix_world = params.get_floats("camera_to_world");
  }

  ssao_tools::Image image = ssao_tools::read_image(o.scene);
  ssao_tools::PassOverrides overrides;
  overrides.layer = o.layer;
  overrides.no_normals = o.no_normals;
  const ssao_tools::PassChannels passes =
      ssao_tools::detect_passes(image.channel_names, overrides, o.scene);
  const std::string ao_channel = passes.layer.empty() ? "AO.R" : passes.layer + ".AO.R";
  const int ao_index = image.find_channel(ao_channel);
  if (ao_index < 0) {
    throw ssao_tools::Error("'" + o.scene + "' has no AO pass (no channel '" + ao_channel +
                            "'): render it with the Ambient Occlusion pass enabled; its channels "
                            "are: " +
                            ssao_tools::join_names(image.channel_names));
  }
  s.width = image.width;
  s.height = image.height;
  s.depth = ssao_tools::extract_named_channels(image, {passes.depth}, o.scene);
  if (!passes.normal.empty()) {
    s.world_normal = ssao_tools::extract_named_channels(image, passes.normal, o.scene);
  }
  if (passes.beauty.size() >= 3) {
    s.beauty = ssao_tools::extract_named_channels(
        image, {passes.beauty[0], passes.beauty[1], passes.beauty[2]}, o.scene);
  }
  s.truth = ssao_tools::extract_channels(image, {ao_index});

  const double limit = 0.9 * s.clip_end;
  s.mask.assign(s.depth.size(), 0);
  for (size_t p = 0; p < s.depth.size(); ++p) {
    const float d = s.depth[p];
    if (std::isfinite(d) && d > 0.0f && static_cast<double>(d) < limit &&
        std::isfinite(s.truth[p])) {
      s.mask[p] = 1;
      ++s.scored;
    }
  }
  if (s.scored == 0) {
    throw ssao_tools::Error("'" + o.scene +
                            "' has no pixel to score (none with a finite depth in (0, " +
                            std::to_string(limit) + "), 0.9 x the camera's clip_end)");
  }
  if (!o.layers_file.empty()) load_layers(o, s);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Methods. Each is prepared once (settings checked, inputs converted), then run --repeat times.

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// The value of a core parameter as set by --set, typed after the parameter table.
void set_core_param(ssao::api::Job& job, const std::vector<ssao_param_desc>& table,
                    const Setting& s, const std::string& flag) {
  const auto it = std::find_if(table.begin(), table.end(),
                               [&](const ssao_param_desc& d) { return s.name == d.name; });
  const std::string where = flag + " " + s.name + "=" + s.value;
  if (it == table.end()) {
    std::vector<std::string> names;
    for (const ssao_param_desc& d : table) names.emplace_back(d.name);
    throw UsageError(where + ": unknown parameter (parameters: " + join(names, ", ") + ")");
  }
  if (s.name == "radius") throw UsageError(where + ": give the radius with --radius");
  try {
    switch (it->type) {
      case SSAO_PARAM_INT:
        job.set(s.name,
                static_cast<int>(parse_integer(s.value, where, std::numeric_limits<int>::min(),
                                               std::numeric_limits<int>::max())));
        break;
      case SSAO_PARAM_FLOAT:
        job.set(s.name, parse_double(s.value, where));
        break;
      case SSAO_PARAM_STRING:
        job.set(s.name, s.value);
        break;
      case SSAO_PARAM_FLOATS:
        job.set(s.name, parse_double_list(s.value, where));
        break;
    }
  } catch (const ssao::api::Error&) {
    throw UsageError(where + ": " + ssao_last_error());
  }
}

// The references' view of the scene: planar depth with the core's background rule (at or beyond
// clip_end is background), view-space normals, and the core's camera model.
ssao_ref::DepthScene reference_scene(const Scene& s) {
  ssao_ref::DepthScene d;
  d.width = s.width;
  d.height = s.height;
  d.camera = ssao::CameraModel(s.camera, s.width, s.height);

  d.depth = s.depth;
  const double clip_end = s.clip_end;
  for (float& depth : d.depth) {
    if (clip_end > 0.0 && static_cast<double>(depth) >= clip_end) {
      depth = std::numeric_limits<float>::infinity();
    }
  }

  if (!s.world_normal.empty()) {
    // World to view for normals: the inverse transpose of the world-to-camera linear part, that
    // is the transpose of camera_to_world's 3x3 (exact even if the camera is scaled).
    const std::vector<double>& m = s.matrix_world;  // row-major, 16 values
    d.view_normal.resize(s.world_normal.size());
    for (size_t p3 = 0; p3 < s.world_normal.size(); p3 += 3) {
      const double wx = s.world_normal[p3], wy = s.world_normal[p3 + 1],
                   wz = s.world_normal[p3 + 2];
      double v[3];
      for (int c = 0; c < 3; ++c) v[c] = m[0 * 4 + c] * wx + m[1 * 4 + c] * wy + m[2 * 4 + c] * wz;
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      const double inv = len > 1e-20 && std::isfinite(len) ? 1.0 / len : 0.0;
      for (int c = 0; c < 3; ++c) d.view_normal[p3 + c] = static_cast<float>(v[c] * inv);
    }
  }
  return d;
}

// The part of the frame that is scored: columns [x0, x1), rows [y0, y1), top row 0.
struct Window {
  int x0 = 0, x1 = std::numeric_limits<int>::max();
  int y0 = 0, y1 = std::numeric_limits<int>::max();
};

// A method ready to run: run() writes the AO (1 channel, top row first) into *ao. An untimed
// method (an image from a file) has its AO from the start and no run().
struct Method {
  std::string name;
  std::string settings;  // "name=value,..." as reported
  int threads = 1;
  std::shared_ptr<std::vector<float>> ao = std::make_shared<std::vector<float>>();
  std::function<void()> run;
  Window window;
};

// The "image" method: settings path=FILE, channel=NAME, region=MIN_X,MAX_X,MIN_Y,MAX_Y
// (fractions from the bottom left, Blender's render border; the edge pixels are left out).
Method make_image_method(const std::vector<Setting>& settings, const std::string& flag,
                         const Scene* scene) {
  Method m;
  m.name = "image";
  m.threads = 0;
  std::string path, channel;
  std::vector<double> region;
  for (const Setting& s : settings) {
    const std::string where = flag + " " + s.name + "=" + s.value;
    if (s.name == "path") {
      path = s.value;
    } else if (s.name == "channel") {
      channel = s.value;
    } else if (s.name == "region") {
      region = parse_double_list(s.value, where);
      if (region.size() != 4 || region[0] >= region[1] || region[2] >= region[3] ||
          *std::min_element(region.begin(), region.end()) < 0.0 ||
          *std::max_element(region.begin(), region.end()) > 1.0) {
        throw UsageError(where + ": expected MIN_X,MAX_X,MIN_Y,MAX_Y, fractions in [0, 1]");
      }
    } else {
      throw UsageError(where + ": method image has no parameter '" + s.name +
                       "' (its parameters: path, channel, region)");
    }
  }
  if (path.empty()) throw UsageError(flag + " image: path=FILE is required");
  m.settings = "path=" + path;
  if (scene == nullptr) return m;

  const ssao_tools::Image image = ssao_tools::read_image(path);
  if (image.width != scene->width || image.height != scene->height) {
    throw ssao_tools::Error("'" + path + "' is " + std::to_string(image.width) + "x" +
                            std::to_string(image.height) + ", the scene " +
                            std::to_string(scene->width) + "x" + std::to_string(scene->height));
  }
  int index = -1;
  if (!channel.empty()) {
    index = ssao_tools::require_channel(image, channel, path);
  } else {
    // The AO: a channel "AO", "AO.R" or "<layer>.AO.R"; with several, channel= must choose.
    std::vector<int> found;
    for (int c = 0; c < image.channels(); ++c) {
      const std::string& name = image.channel_names[static_cast<size_t>(c)];
      if (name == "AO" || name == "AO.R" ||
          (name.size() > 5 && name.compare(name.size() - 5, 5, ".AO.R") == 0)) {
        found.push_back(c);
      }
    }
    if (found.size() != 1) {
      throw ssao_tools::Error("'" + path + "' has " + (found.empty() ? "no" : "more than one") +
                              " AO channel (AO, AO.R or <layer>.AO.R): choose one with "
                              "channel=NAME; its channels: " +
                              ssao_tools::join_names(image.channel_names));
    }
    index = found.front();
  }
  *m.ao = ssao_tools::extract_channels(image, {index});
  if (!region.empty()) {
    const double w = scene->width, h = scene->height;
    m.window.x0 = static_cast<int>(std::ceil(region[0] * w)) + 1;
    m.window.x1 = static_cast<int>(std::floor(region[1] * w)) - 1;
    m.window.y0 = static_cast<int>(std::ceil((1.0 - region[3]) * h)) + 1;
    m.window.y1 = static_cast<int>(std::floor((1.0 - region[2]) * h)) - 1;
  }
  return m;
}

// The reference methods' settings: name -> value, checked against the allowed names.
struct ReferenceSettings {
  int samples = 16;
  uint32_t seed = 1;
  ssao_ref::RayMarchSettings march;
};

ReferenceSettings parse_reference_settings(const std::string& method,
                                           const std::vector<Setting>& settings,
                                           const std::string& flag) {
  ReferenceSettings r;
  const bool march = method == "raymarch";
  const std::vector<std::string> allowed =
      march ? std::vector<std::string>{"rays", "steps", "thickness", "seed"}
            : std::vector<std::string>{"samples", "seed"};
  for (const Setting& s : settings) {
    const std::string where = flag + " " + s.name + "=" + s.value;
    if (std::find(allowed.begin(), allowed.end(), s.name) == allowed.end()) {
      throw UsageError(where + ": method " + method + " has no parameter '" + s.name +
                       "' (its parameters: " + join(allowed, ", ") + ")");
    }
    if (s.name == "seed") {
      r.seed = static_cast<uint32_t>(parse_integer(s.value, where, 0, 4294967295LL));
      r.march.seed = r.seed;
    } else if (s.name == "samples") {
      r.samples = static_cast<int>(parse_integer(s.value, where, 1, 4096));
    } else if (s.name == "rays") {
      r.march.rays = static_cast<int>(parse_integer(s.value, where, 1, 65536));
    } else if (s.name == "steps") {
      r.march.steps = static_cast<int>(parse_integer(s.value, where, 1, 4096));
    } else if (s.name == "thickness") {
      const double t = parse_double(s.value, where);
      if (!(t > 0.0)) throw UsageError(where + ": must be positive");
      r.march.thickness = static_cast<float>(t);
    }
  }
  return r;
}

// Everything the ssao method keeps between runs.
struct CoreState {
  ssao::api::Job job;
  std::vector<float> depth, normal, beauty;
  std::vector<std::vector<float>> layer_depth, layer_facing;
};

// The window of `plane` (`channels` floats a pixel, `width` wide with a `from_band` guard band)
// grown by `band` pixels a side; the display window's pixels come from `frame` when given.
std::vector<float> with_band(const std::vector<float>& plane, int width, int height, int from_band,
                             int band, int channels, const std::vector<float>* frame) {
  const int padded_width = width + 2 * band, padded_height = height + 2 * band;
  const int from_width = width + 2 * from_band;
  std::vector<float> out(size_t(padded_width) * size_t(padded_height) * size_t(channels));
  for (int y = 0; y < padded_height; ++y) {
    for (int x = 0; x < padded_width; ++x) {
      const int fx = x - band, fy = y - band;  // frame coordinates
      const bool inside = fx >= 0 && fy >= 0 && fx < width && fy < height;
      const float* src =
          frame != nullptr && inside
              ? frame->data() + (size_t(fy) * size_t(width) + size_t(fx)) * size_t(channels)
              : plane.data() +
                    (size_t(fy + from_band) * size_t(from_width) + size_t(fx + from_band)) *
                        size_t(channels);
      std::copy_n(src, channels,
                  out.begin() + std::ptrdiff_t((size_t(y) * size_t(padded_width) + size_t(x)) *
                                               size_t(channels)));
    }
  }
  return out;
}

// Prepares `name` with `settings` (from `flag`). With scene == nullptr only checks the settings
// (so that command-line mistakes are found before any file is read).
Method make_method(const std::string& name, const std::vector<Setting>& settings,
                   const std::string& flag, const Scene* scene, double radius) {
  if (name == "image") return make_image_method(settings, flag, scene);
  Method m;
  m.name = name;
  if (name == "ssao") {
    const std::vector<ssao_param_desc> table = ssao::api::param_table();
    auto state = std::make_shared<CoreState>();
    ssao::api::Job& job = state->job;
    if (scene != nullptr) ssao_tools::apply_camera_text(job, scene->camera_text, scene->path);
    try {
      job.set("radius", radius);
    } catch (const ssao::api::Error&) {
      throw UsageError(std::string("--radius: ") + ssao_last_error());
    }
    // layers=N and band=G (with --layers) are the evaluation's; the rest are core parameters,
    // set after the camera: a --set camera parameter overrides the file.
    int layers = 0, band = 0;
    for (const Setting& s : settings) {
      const std::string where = flag + " " + s.name + "=" + s.value;
      if (s.name == "layers") {
        layers = static_cast<int>(parse_integer(s.value, where, 0, 4));
      } else if (s.name == "band") {
        band = static_cast<int>(parse_integer(s.value, where, 0, 4096));
      } else {
        set_core_param(job, table, s, flag);
      }
    }
    if (scene != nullptr && (layers > int(scene->layer_depth.size()) || band > scene->band)) {
      throw UsageError(flag + " layers=" + std::to_string(layers) +
                       " band=" + std::to_string(band) + ": --layers gives " +
                       std::to_string(scene->layer_depth.size()) + " extra layers and a " +
                       std::to_string(scene->band) + " px band");
    }
    std::vector<std::string> shown = {"variant=" + job.get_string("variant"),
                                      "samples=" + std::to_string(job.get_int("samples"))};
    for (const Setting& s : settings) {
      if (s.name != "variant" && s.name != "samples") shown.push_back(s.name + "=" + s.value);
    }
    m.settings = join(shown, ",");
    const int requested = job.get_int("threads");
    const unsigned hw = std::thread::hardware_concurrency();
    m.threads = requested > 0 ? requested : (hw == 0 ? 1 : static_cast<int>(hw));
    if (scene == nullptr) return m;

    const int w = scene->width, h = scene->height;
    const int input_w = w + 2 * band, input_h = h + 2 * band;
    const bool from_layers_file = layers > 0 || band > 0;
    // The scene's own passes in the frame; the layers file's in the band.
    state->depth = from_layers_file
                       ? with_band(scene->band_depth, w, h, scene->band, band, 1, &scene->depth)
                       : scene->depth;
    job.set_image("depth", state->depth.data(), input_w, input_h, 1);
    if (!scene->world_normal.empty() && (!from_layers_file || !scene->band_normal.empty())) {
      state->normal = from_layers_file ? with_band(scene->band_normal, w, h, scene->band, band, 3,
                                                   &scene->world_normal)
                                       : scene->world_normal;
      job.set_image("normal", state->normal.data(), input_w, input_h, 3);
    }
    for (int k = 0; k < layers; ++k) {
      const std::string hit = std::to_string(k + 2);
      state->layer_depth.push_back(
          with_band(scene->layer_depth[size_t(k)], w, h, scene->band, band, 1, nullptr));
      job.set_image("depth" + hit, state->layer_depth.back().data(), input_w, input_h, 1);
      if (scene->layer_facing[size_t(k)].empty()) continue;
      state->layer_facing.push_back(
          with_band(scene->layer_facing[size_t(k)], w, h, scene->band, band, 1, nullptr));
      job.set_image("facing" + hit, state->layer_facing.back().data(), input_w, input_h, 1);
    }
    m.ao->assign(scene->depth.size(), 0.0f);
    job.set_output_window(band > 0, band, band);
    // The Combined pass, which edge_coverage=beauty reads (the AO is the same without it).
    if (!scene->beauty.empty()) {
      state->beauty = scene->beauty;
      job.set_image("beauty", state->beauty.data(), w, h, 3);
    }
    job.set_image("ao", m.ao->data(), w, h, 1);
    m.run = [state] { state->job.run(); };
    return m;
  }

  const ReferenceSettings r = parse_reference_settings(name, settings, flag);
  if (name == "raymarch") {
    m.settings =
        "rays=" + std::to_string(r.march.rays) + ",steps=" + std::to_string(r.march.steps) +
        ",thickness=" + format_number(r.march.thickness) + ",seed=" + std::to_string(r.march.seed);
    const unsigned hw = std::thread::hardware_concurrency();
    m.threads = std::max(1, hw == 0 ? 1 : static_cast<int>(hw));
    if (scene != nullptr) m.threads = std::min(m.threads, scene->height);
  } else {
    m.settings = "samples=" + std::to_string(r.samples) + ",seed=" + std::to_string(r.seed);
    m.threads = 1;
  }
  if (scene == nullptr) return m;

  auto depth_scene = std::make_shared<ssao_ref::DepthScene>(reference_scene(*scene));
  const float rad = static_cast<float>(radius);
  auto out = m.ao;
  if (name == "raymarch") {
    ssao_ref::RayMarchSettings march = r.march;
    march.radius = rad;
    m.run = [depth_scene, march, out] { *out = ssao_ref::raymarch_ao(*depth_scene, march); };
  } else if (name == "seed-hemisphere") {
    m.run = [depth_scene, rad, r, out] {
      *out = ssao_ref::seed_hemisphere_ao(*depth_scene, rad, r.samples, r.seed);
    };
  } else {
    m.run = [depth_scene, rad, r, out] {
      *out = ssao_ref::seed_sphere_ao(*depth_scene, rad, r.samples, r.seed);
    };
  }
  return m;
}

// Wall times in milliseconds of `repeat` runs of every timed method, in interleaved rounds.
// Each timed run follows an untimed run of the same method, which also takes the first-touch
// page faults and the thread start-up: the first run with two threads after a method on one
// thread (the seed ports) took 1.6x as long on this 2-core VM (the idle core waking), which made
// the default, first in each round, look slower than `resolution=half`, the same settings.
std::vector<std::vector<double>> time_interleaved(const std::vector<Method>& methods, int repeat) {
  std::vector<std::vector<double>> times(methods.size());
  for (int round = 0; round < repeat; ++round) {
    for (size_t i = 0; i < methods.size(); ++i) {
      if (!methods[i].run) continue;
      methods[i].run();  // untimed: the same state for every method (see above)
      const auto start = std::chrono::steady_clock::now();
      methods[i].run();
      const auto stop = std::chrono::steady_clock::now();
      times[i].push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    }
  }
  return times;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct Score {
  double rmse = 0.0;
  double mean_error = 0.0;
  size_t pixels = 0;
  double rmse_interior = 0.0;  // over the scored pixels none of whose 8 neighbours is unscored
  size_t interior_pixels = 0;
  double band = 0.0;       // RMSE of the difference of the band-passes G(1) - G(6)
  double edge_rmse = 0.0;  // RMSE at depth discontinuities
};

// The band-pass G(1) - G(6): sigmas in pixels, each Gaussian separable, truncated at 3 sigma and
// normalised, with clamp-to-edge.
constexpr double kBandFine = 1.0, kBandCoarse = 6.0;
constexpr int kBandErosion = 3;          // the band's pixels: geometry within 3 px (7x7 square)
constexpr double kEdgeDepthJump = 0.05;  // an edge: |d - d_n| > 5 % of the nearer depth

// One pass of a separable filter over `image` (w x h): each pixel folds the pixels up to
// `radius` away along its row (along_rows) or column, i = -radius .. radius in order, clamped to
// the edge: fold(accumulated, i, value), starting from `start`.
template <class T, class Fold>
std::vector<T> separable_pass(const std::vector<T>& image, int w, int h, int radius,
                              bool along_rows, T start, Fold fold) {
  std::vector<T> out(image.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      T accumulated = start;
      for (int i = -radius; i <= radius; ++i) {
        const int nx = along_rows ? std::clamp(x + i, 0, w - 1) : x;
        const int ny = along_rows ? y : std::clamp(y + i, 0, h - 1);
        accumulated = fold(accumulated, i, image[size_t(ny) * size_t(w) + size_t(nx)]);
      }
      out[size_t(y) * size_t(w) + size_t(x)] = accumulated;
    }
  }
  return out;
}

// `image` (w x h) blurred by a Gaussian of `sigma` pixels (see kBandFine).
std::vector<double> gaussian_blur(const std::vector<double>& image, int w, int h, double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> kernel(size_t(2 * radius + 1));
  double total = 0.0;
  for (int i = -radius; i <= radius; ++i) {
    total += kernel[size_t(i + radius)] = std::exp(-0.5 * double(i * i) / (sigma * sigma));
  }
  for (double& k : kernel) k /= total;
  const auto weigh = [&](double sum, int i, double value) {
    return sum + kernel[size_t(i + radius)] * value;
  };
  return separable_pass(separable_pass(image, w, h, radius, true, 0.0, weigh), w, h, radius, false,
                        0.0, weigh);
}

// `set` (w x h, 0 or 1) eroded by the (2 r + 1)^2 square: 1 where every pixel of the square that
// lies inside the frame is 1 (the minimum along rows, then along columns; clamping to the edge
// repeats pixels of the frame, which leaves a minimum as it is).
std::vector<unsigned char> erode(const std::vector<unsigned char>& set, int w, int h, int r) {
  const auto minimum = [](unsigned char all, int, unsigned char value) {
    return std::min(all, value);
  };
  return separable_pass(separable_pass(set, w, h, r, true, (unsigned char)1, minimum), w, h, r,
                        false, (unsigned char)1, minimum);
}

// Whether the scored pixel p = (x, y) has a depth jump of more than kEdgeDepthJump to a
// 4-neighbour that shows geometry (an edge against the sky is not one).
bool depth_edge(const Scene& s, int x, int y) {
  const size_t p = size_t(y) * size_t(s.width) + size_t(x);
  const double d = s.depth[p];
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int i = 0; i < 4; ++i) {
    const int nx = x + dx[i], ny = y + dy[i];
    if (nx < 0 || ny < 0 || nx >= s.width || ny >= s.height) continue;
    const size_t n = size_t(ny) * size_t(s.width) + size_t(nx);
    if (!s.mask[n]) continue;
    const double dn = s.depth[n];
    if (std::fabs(d - dn) > kEdgeDepthJump * std::min(d, dn)) return true;
  }
  return false;
}

// band and edge_rmse of `ao` against the scene's truth over `scored` (the geometry pixels in the
// method's window). Outside `scored` both images read AO 1 (Cycles' pass reads 0 in the sky):
// the band-pass is linear, so the band-passes' difference is the band-pass of the difference,
// which is 0 there.
void score_detail(const Scene& s, const std::vector<float>& ao,
                  const std::vector<unsigned char>& scored, Score& sc) {
  const int w = s.width, h = s.height;
  std::vector<double> diff(scored.size(), 0.0);
  for (size_t p = 0; p < scored.size(); ++p) {
    if (scored[p]) diff[p] = static_cast<double>(ao[p]) - static_cast<double>(s.truth[p]);
  }
  const std::vector<double> fine = gaussian_blur(diff, w, h, kBandFine);
  const std::vector<double> coarse = gaussian_blur(diff, w, h, kBandCoarse);
  const std::vector<unsigned char> inner = erode(scored, w, h, kBandErosion);
  double band_sq = 0.0, edge_sq = 0.0;
  size_t band_pixels = 0, edge_pixels = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * size_t(w) + size_t(x);
      if (!scored[p]) continue;
      if (inner[p]) {
        const double b = fine[p] - coarse[p];
        band_sq += b * b;
        ++band_pixels;
      }
      if (depth_edge(s, x, y)) edge_sq += diff[p] * diff[p], ++edge_pixels;
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  sc.band = band_pixels > 0 ? std::sqrt(band_sq / double(band_pixels)) : nan;
  sc.edge_rmse = edge_pixels > 0 ? std::sqrt(edge_sq / double(edge_pixels)) : nan;
}

// Whether every pixel around (x, y) inside the image is scored.
bool interior(const Scene& s, int x, int y) {
  for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, s.height - 1); ++ny) {
    for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, s.width - 1); ++nx) {
      if (!s.mask[static_cast<size_t>(ny) * static_cast<size_t>(s.width) + nx]) return false;
    }
  }
  return true;
}

Score score(const Scene& s, const Method& m) {
  const std::vector<float>& ao = *m.ao;
  if (ao.size() != s.truth.size()) {
    throw std::logic_error("AO of " + std::to_string(ao.size()) + " pixels, expected " +
                           std::to_string(s.truth.size()));
  }
  Score sc;
  double sum = 0.0, sum_sq = 0.0, interior_sq = 0.0;
  std::vector<unsigned char> scored(s.mask.size(), 0);
  for (int y = std::max(0, m.window.y0); y < std::min(s.height, m.window.y1); ++y) {
    for (int x = std::max(0, m.window.x0); x < std::min(s.width, m.window.x1); ++x) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(s.width) + x;
      if (!s.mask[p]) continue;
      scored[p] = 1;
      const double diff = static_cast<double>(ao[p]) - static_cast<double>(s.truth[p]);
      sum += diff;
      sum_sq += diff * diff;
      ++sc.pixels;
      if (interior(s, x, y)) interior_sq += diff * diff, ++sc.interior_pixels;
    }
  }
  sc.rmse_interior = sc.interior_pixels > 0
                         ? std::sqrt(interior_sq / static_cast<double>(sc.interior_pixels))
                         : std::numeric_limits<double>::quiet_NaN();
  if (sc.pixels == 0) throw ssao_tools::Error(m.name + " " + m.settings + ": no pixel to score");
  const double n = static_cast<double>(sc.pixels);
  sc.rmse = std::sqrt(sum_sq / n);
  sc.mean_error = sum / n;
  score_detail(s, ao, scored, sc);
  return sc;
}

Score report(const Scene& s, const Options& o, const Method& m, const std::vector<double>& ms) {
  const Score sc = score(s, m);
  const double min_ms = ms.empty() ? std::numeric_limits<double>::quiet_NaN()
                                   : *std::min_element(ms.begin(), ms.end());
  std::printf(
      "scene=%s method=%s settings=%s normals=%s rmse=%.5f mean_error=%+.5f "
      "time_ms=%.2f min_ms=%.2f repeat=%d threads=%d pixels=%zu rmse_interior=%.5f "
      "interior_pixels=%zu band=%.5f edge_rmse=%.5f\n",
      s.name.c_str(), m.name.c_str(), m.settings.c_str(), s.world_normal.empty() ? "depth" : "pass",
      sc.rmse, sc.mean_error, median(ms), min_ms, o.repeat, m.threads, sc.pixels, sc.rmse_interior,
      sc.interior_pixels, sc.band, sc.edge_rmse);
  std::fflush(stdout);
  return sc;
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    return std::filesystem::equivalent(a, b, ec);
  }
  return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec);
}

// --write-ao must not overwrite an input, and its folder must exist (checked before any work).
void check_output(const Options& o) {
  if (same_file(o.write_ao, o.scene) || same_file(o.write_ao, o.camera)) {
    throw UsageError("--write-ao '" + o.write_ao + "' is an input file; choose another name");
  }
  std::filesystem::path folder = std::filesystem::path(o.write_ao).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throw ssao_tools::Error("cannot write '" + o.write_ao + "': no folder '" + folder.string() +
                            "'");
  }
}

int run(const Options& o) {
  // Every method in the order reported: --method, each --run, then --compare-to.
  std::vector<RunSpec> specs = {{o.method, o.settings, o.method_flag}};
  specs.insert(specs.end(), o.more_runs.begin(), o.more_runs.end());
  if (!o.compare_to.empty()) specs.push_back({o.compare_to, o.compare_settings, "--compare-set"});
  // Command-line mistakes first, before reading anything.
  for (const RunSpec& spec : specs) {
    make_method(spec.method, spec.settings, spec.flag, nullptr, o.radius);
  }

  if (!o.write_ao.empty()) check_output(o);
  const Scene scene = load_scene(o);
  std::vector<Method> methods;
  for (const RunSpec& spec : specs) {
    methods.push_back(make_method(spec.method, spec.settings, spec.flag, &scene, o.radius));
  }
  const std::vector<std::vector<double>> times = time_interleaved(methods, o.repeat);
  std::vector<Score> scores;
  for (size_t i = 0; i < methods.size(); ++i) {
    scores.push_back(report(scene, o, methods[i], times[i]));
  }
  if (!o.write_ao.empty()) {
    ssao_tools::write_exr(o.write_ao, scene.width, scene.height, {"AO"}, *methods.front().ao);
  }

  int status = 0;
  const Score& primary = scores.front();
  if (o.has_max_rmse) {
    const bool pass = primary.rmse <= o.max_rmse;  // false for NaN
    std::printf("check max-rmse: %s rmse %.5f %s %.5f: %s\n", o.method.c_str(), primary.rmse,
                pass ? "<=" : ">", o.max_rmse, pass ? "PASS" : "FAIL");
    if (!pass) status = 1;
  }
  if (!o.compare_to.empty()) {
    const Score& other = scores.back();
    const double bound = other.rmse * (1.0 - o.margin);
    const bool pass = primary.rmse < bound;
    const double lower = other.rmse > 0.0 ? 100.0 * (1.0 - primary.rmse / other.rmse) : 0.0;
    std::printf(
        "check compare-to: %s rmse %.5f vs %s rmse %.5f: %.1f%% %s (required: more "
        "than %.1f%% lower, rmse < %.5f): %s\n",
        o.method.c_str(), primary.rmse, o.compare_to.c_str(), other.rmse, std::fabs(lower),
        lower >= 0.0 ? "lower" : "higher", 100.0 * o.margin, bound, pass ? "PASS" : "FAIL");
    if (!pass) status = 1;
  }
  std::fflush(stdout);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse_args(argc, argv);
    if (options.help) {
      std::fputs(kUsage, stdout);
      return 0;
    }
    return run(options);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: error: %s\nTry '%s --help' for more information.\n", kProgram,
                 e.what(), kProgram);
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: error: out of memory\n", kProgram);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", kProgram, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: error: unexpected exception\n", kProgram);
  }
  return 1;
}
