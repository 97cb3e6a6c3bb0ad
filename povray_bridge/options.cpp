// SPDX-License-Identifier: MIT
#include "options.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "tools/camera_json.h"
#include "tools/image_io.h"

namespace povray_ssao {
namespace {

using ssao_tools::help_entry;
using ssao_tools::parse_float;
using ssao_tools::parse_int;

V3 parse_vector(const std::string& flag, const std::string& text) {
  const std::vector<std::string> parts = ssao_tools::split(text, ',');
  if (parts.size() != 3) {
    throw UsageError(flag + " expects X,Y,Z (three comma-separated numbers), got '" + text + "'");
  }
  return {parse_float(flag, parts[0]), parse_float(flag, parts[1]), parse_float(flag, parts[2])};
}

int parse_size(const std::string& flag, const std::string& text) {
  const int value = parse_int(flag, text);
  if (value < 1 || value > 65536) throw UsageError(flag + " must be 1..65536, got " + text);
  return value;
}

double parse_positive(const std::string& flag, const std::string& text) {
  const double value = parse_float(flag, text);
  if (!(value > 0.0)) throw UsageError(flag + " must be positive, got " + text);
  return value;
}

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return text;
}

// Front-end options (not library parameters): the table drives parsing, --help and
// suggestions.
enum Group { kRender, kCamera, kPost, kOther };
using FrontOption = ssao_tools::FrontOption<Options, Group>;

// The render mode's options (kRender).
std::vector<FrontOption> render_options() {
  return {
      {kRender, "--output", "-o", "OUT.png",
       "output (required): .png, .jpg or .tif: an 8-bit sRGB image of the result; .exr: the "
       "channels of --exr (with --depth-only: Z and Radial)",
       [](Options& o, const std::string&, const std::string& v) { o.output = v; }},
      {kRender, "--width", nullptr, "W",
       "image width, as +W640 or -W640 (default: the INI file's, else POV-Ray's default, see "
       "below)",
       [](Options& o, const std::string& f, const std::string& v) { o.width = parse_size(f, v); }},
      {kRender, "--height", nullptr, "H", "image height, as +H480 or -H480",
       [](Options& o, const std::string& f, const std::string& v) { o.height = parse_size(f, v); }},
      {kRender, "--ini", nullptr, "FILE.ini",
       "INI file given to every povray run before povray-ssao's own options (quality, "
       "antialiasing, Declare=...); its Width and Height set the size unless given here",
       [](Options& o, const std::string&, const std::string& v) { o.ini = v; }},
      {kRender, "--exr", nullptr, "OUT.exr",
       "also write 32-bit float channels R,G,B,A (the output, linear; A = 1 without alpha), "
       "AO, Z (planar depth along the view axis; background inf) and Radial (distance from the "
       "camera; background inf)",
       [](Options& o, const std::string&, const std::string& v) { o.exr = v; }},
      {kRender, "--keep", nullptr, "DIR",
       "keep the generated wrappers, the povray logs and every pass in DIR (created if needed; "
       "kept on failure too)",
       [](Options& o, const std::string&, const std::string& v) { o.keep = v; }},
      {kRender, "--apply-to", nullptr, "auto|ambient|beauty",
       "what AO darkens. ambient: only the scene's ambient light (pigment x finish ambient x "
       "ambient_light, rendered as its own pass), so light straight from a light source stays; "
       "beauty: the whole image (multiplied by AO); auto (default): ambient where the scene has "
       "ambient light (at least 1% of the image's light), else beauty",
       [](Options& o, const std::string& f, const std::string& v) {
         if (v != "auto" && v != "ambient" && v != "beauty") {
           throw UsageError(f + " must be auto, ambient or beauty, got '" + v + "'");
         }
         o.apply_to = v;
       }},
      {kRender, "--overscan", nullptr, "PIXELS",
       "guard band of the data passes: the depth (and normal) pass is rendered PIXELS larger on "
       "every side, on the same pixel grid (a wider camera), so that AO at the frame's edges "
       "sees occluders just outside it; the beauty and the outputs keep their size. 0 turns it "
       "off; default: 10% of the image's larger side",
       [](Options& o, const std::string& f, const std::string& v) {
         const int value = parse_int(f, v);
         // Bounded again against the image size once that is known (scene_setup.cpp).
         if (value < 0 || value > 65536) throw UsageError(f + " must be 0..65536, got " + v);
         o.overscan = value;
       }},
      {kRender, "--depth-only", nullptr, nullptr,
       "render only the depth pass (and the pre-pass, when the camera has no look_at) and "
       "write -o OUT.exr with channels Z and Radial",
       [](Options& o, const std::string&, const std::string&) { o.depth_only = true; }},
      {kRender, "--povray", nullptr, "PATH", "POV-Ray 3.7 executable (default: povray in PATH)",
       [](Options& o, const std::string&, const std::string& v) { o.povray = v; }},
      {kRender, "--fog-distances", nullptr, "D1,D2[,D3]",
       "use these fog distances for the depth pass (scene units; D3 adds a third fog on B for "
       "far depths) instead of the camera's look_at distance or a pre-pass",
       [](Options& o, const std::string& f, const std::string& v) {
         const std::vector<std::string> parts = ssao_tools::split(v, ',');
         if (parts.size() != 2 && parts.size() != 3) {
           throw UsageError(f + " expects D1,D2 or D1,D2,D3, got '" + v + "'");
         }
         FogDistances d;
         d.d1 = parse_positive(f, parts[0]);
         d.d2 = parse_positive(f, parts[1]);
         if (parts.size() == 3) d.d3 = parse_positive(f, parts[2]);
         if (!(d.d1 < d.d2) || (d.d3 > 0.0 && !(d.d2 < d.d3))) {
           throw UsageError(f + " must increase: D1 < D2 < D3, got '" + v + "'");
         }
         o.fog_distances = d;
       }},
      {kRender, "--no-normals", nullptr, nullptr,
       "skip the normal pass of scenes that include ssao_passes.inc: reconstruct normals from "
       "the depth",
       [](Options& o, const std::string&, const std::string&) { o.no_normals = true; }},
      {kRender, "--print-camera", nullptr, nullptr,
       "print the camera read from the scene, the camera block every pass is rendered with and "
       "libssao's camera parameters, then exit (no rendering)",
       [](Options& o, const std::string&, const std::string&) { o.print_camera = true; }},
  };
}

// The camera overrides, the post-process mode's options and the others.
std::vector<FrontOption> camera_post_and_other_options() {
  return {
      {kCamera, "--camera-location", nullptr, "X,Y,Z", "camera location",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.location = parse_vector(f, v);
       }},
      {kCamera, "--camera-look-at", nullptr, "X,Y,Z", "point looked at",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.look_at = parse_vector(f, v);
       }},
      {kCamera, "--camera-angle", nullptr, "DEG",
       "horizontal field of view in degrees (POV-Ray's angle); in post-process mode the "
       "perspective camera's",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.angle = parse_float(f, v);
       }},
      {kCamera, "--camera-right", nullptr, "X,Y,Z", "right vector",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.right = parse_vector(f, v);
       }},
      {kCamera, "--camera-up", nullptr, "X,Y,Z", "up vector",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.up = parse_vector(f, v);
       }},
      {kCamera, "--camera-sky", nullptr, "X,Y,Z", "sky vector (used by look_at)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.sky = parse_vector(f, v);
       }},
      {kCamera, "--camera-direction", nullptr, "X,Y,Z", "direction vector",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera.direction = parse_vector(f, v);
       }},
      {kCamera, "--camera-orthographic", nullptr, nullptr,
       "an orthographic camera (in post-process mode with --camera-width)",
       [](Options& o, const std::string&, const std::string&) { o.camera.orthographic = true; }},
      {kPost, "--beauty", nullptr, "IMAGE",
       "the rendered image: EXR (linear) or PNG/TIFF/... (sRGB-encoded files are linearised)",
       [](Options& o, const std::string&, const std::string& v) { o.beauty = v; }},
      {kPost, "--depth", nullptr, "DEPTH.exr",
       "the depth image, e.g. from --depth-only or --exr (a PNG must hold linear values: "
       "POV-Ray's File_Gamma=1.0; scale them with --depth-scale)",
       [](Options& o, const std::string&, const std::string& v) { o.depth = v; }},
      {kPost, "--depth-channel", nullptr, "NAME",
       "depth channel (default: Radial, else Z, else R, Y, depth or the only channel)",
       [](Options& o, const std::string&, const std::string& v) { o.depth_channel = v; }},
      {kPost, "--depth-scale", nullptr, "S", "multiply the depth values by S (default 1)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.depth_scale = parse_positive(f, v);
       }},
      {kPost, "--camera-aspect", nullptr, "R",
       "|right| / |up| of the camera (default: the image's width / height, square pixels)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera_aspect = parse_positive(f, v);
       }},
      {kPost, "--camera-width", nullptr, "W",
       "view width in scene units of the orthographic camera (|right|)",
       [](Options& o, const std::string& f, const std::string& v) {
         o.camera_width = parse_positive(f, v);
       }},
      {kOther, "--quiet", "-q", nullptr, "no progress and no warnings (errors are still shown)",
       [](Options& o, const std::string&, const std::string&) { o.quiet = true; }},
      {kOther, "--help", "-h", nullptr, "print this help and exit",
       [](Options& o, const std::string&, const std::string&) { o.help = true; }},
      {kOther, "--version", nullptr, nullptr, "print the library version and exit",
       [](Options& o, const std::string&, const std::string&) { o.version = true; }},
  };
}

const std::vector<FrontOption>& front_options() {
  static const std::vector<FrontOption> options = [] {
    std::vector<FrontOption> all = render_options();
    for (FrontOption& option : camera_post_and_other_options()) all.push_back(std::move(option));
    return all;
  }();
  return options;
}

// Library parameters povray-ssao sets itself from the POV-Ray camera and the passes.
bool set_by_bridge(const std::string& name, bool post_process) {
  if (ssao_tools::is_camera_param(name)) return true;  // the library's "camera" group
  if (name == "normal_space") return true;
  return name == "depth_kind" && !post_process;
}

// +W640, -W640, +H480, -H480 (POV-Ray's switches, either sign).
bool size_switch(const std::string& arg, Options& out) {
  if (arg.size() < 3 || (arg[0] != '+' && arg[0] != '-')) return false;
  const char key = static_cast<char>(std::toupper(static_cast<unsigned char>(arg[1])));
  if (key != 'W' && key != 'H') return false;
  // A size with a sign or a fraction (+H-5, +W1.5) is a bad size, not another POV-Ray switch
  // (+HI, Include_Header, starts with a letter).
  const unsigned char first = static_cast<unsigned char>(arg[2]);
  if (!std::isdigit(first) && first != '-' && first != '+' && first != '.') return false;
  const int value = parse_size(arg, arg.substr(2));
  (key == 'W' ? out.width : out.height) = value;
  return true;
}

// Name=value: a POV-Ray INI option (Declare=Quality=2, Antialias_Threshold=0.1, ...).
bool ini_option(const std::string& arg, Options& out) {
  const size_t equals = arg.find('=');
  if (equals == std::string::npos || equals == 0) return false;
  const std::string name = arg.substr(0, equals);
  if (!std::isalpha(static_cast<unsigned char>(name[0])) ||
      !std::all_of(name.begin(), name.end(),
                   [](unsigned char c) { return std::isalnum(c) || c == '_'; })) {
    return false;
  }
  const std::string key = upper(name);
  if (key == "WIDTH" || key == "HEIGHT") {
    (key == "WIDTH" ? out.width : out.height) = parse_size(name, arg.substr(equals + 1));
    return true;
  }
  if (key == "INPUT_FILE_NAME" || key == "OUTPUT_FILE_NAME" || key == "OUTPUT_FILE_TYPE" ||
      key == "OUTPUT_TO_FILE") {
    throw UsageError(arg +
                     ": povray-ssao sets the input and output files of every povray run; "
                     "give the scene as SCENE.pov and the output with -o");
  }
  out.povray_options.push_back(arg);
  return true;
}

void pov_switch(const std::string& arg, Options& out) {
  const char key = static_cast<char>(std::toupper(static_cast<unsigned char>(arg[1])));
  if (key == 'I' || key == 'O' || key == 'F') {
    throw UsageError(arg +
                     ": povray-ssao sets the input file, the output file and its type of "
                     "every povray run; give the scene as SCENE.pov and the output with -o");
  }
  out.povray_options.push_back(arg);
}

bool has_extension(const std::string& path, const std::string& extension) {
  if (path.size() < extension.size()) return false;
  std::string tail = path.substr(path.size() - extension.size());
  std::transform(tail.begin(), tail.end(), tail.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == extension;
}

void check_output_name(const std::string& flag, const std::string& path, bool allow_preview) {
  if (has_extension(path, ".exr")) return;
  if (allow_preview && ssao_tools::is_preview_path(path)) return;
  throw UsageError(flag + " " + path +
                   (allow_preview ? ": use .png, .jpg or .tif (8-bit sRGB) or .exr (float)"
                                  : ": must be an OpenEXR file (.exr)"));
}

void validate(const Options& o) {
  if (o.output.empty() && !o.print_camera) throw UsageError("missing the output: -o OUT.png");
  if (!o.exr.empty()) {
    check_output_name("--exr", o.exr, false);
    if (o.exr == o.output) throw UsageError("-o and --exr name the same file");
  }
  const bool post = o.post_process();
  for (const ssao_tools::ParamSetting& p : o.params) {
    if (set_by_bridge(p.name, post)) {
      throw UsageError(p.flag + ": povray-ssao sets " + p.name +
                       " itself from the POV-Ray camera and passes" +
                       (post ? std::string(" (give the camera with --camera-angle, "
                                           "--camera-aspect or --camera-orthographic "
                                           "--camera-width)")
                             : std::string(" (use the --camera-* flags to change the camera)")));
    }
  }
  if (post) {
    if (!o.scene.empty()) {
      throw UsageError("a scene file ('" + o.scene +
                       "') and --beauty/--depth: choose the render mode or the post-process "
                       "mode");
    }
    if (o.beauty.empty()) throw UsageError("post-process mode needs --beauty IMAGE");
    if (o.depth.empty()) throw UsageError("post-process mode needs --depth DEPTH.exr");
    check_output_name("-o", o.output, true);
    if (o.width || o.height || !o.ini.empty() || !o.keep.empty() || o.depth_only ||
        o.fog_distances || o.print_camera || o.no_normals || !o.povray_options.empty() ||
        o.povray != "povray" || o.apply_to != "auto" || o.overscan) {
      throw UsageError(
          "post-process mode (--beauty, --depth) runs no povray: size, --ini, "
          "--keep, --depth-only, --fog-distances, --print-camera, --povray, --apply-to, "
          "--overscan and POV-Ray options do not apply (it multiplies the beauty by AO)");
    }
    const CameraOverrides& c = o.camera;
    if (c.location || c.look_at || c.right || c.up || c.sky || c.direction) {
      throw UsageError(
          "post-process mode takes the camera as --camera-angle DEG "
          "[--camera-aspect R] or --camera-orthographic --camera-width W");
    }
    if (c.orthographic) {
      if (!o.camera_width) throw UsageError("--camera-orthographic needs --camera-width W");
      if (c.angle) throw UsageError("--camera-angle and --camera-orthographic contradict");
    } else {
      if (!c.angle) {
        throw UsageError(
            "post-process mode needs the camera: --camera-angle DEG (horizontal "
            "field of view) or --camera-orthographic --camera-width W");
      }
      if (!(*c.angle > 0.0 && *c.angle < 180.0)) {
        throw UsageError("--camera-angle must be in (0, 180) degrees");
      }
      if (o.camera_width) throw UsageError("--camera-width needs --camera-orthographic");
    }
    return;
  }
  if (o.scene.empty()) throw UsageError("missing the scene file SCENE.pov");
  if (o.camera_aspect || o.camera_width || !o.depth_channel.empty() || o.depth_scale != 1.0) {
    throw UsageError(
        "--camera-aspect, --camera-width, --depth-channel and --depth-scale belong "
        "to the post-process mode (--beauty, --depth)");
  }
  if (o.depth_only) {
    if (!has_extension(o.output, ".exr")) {
      throw UsageError(
          "--depth-only writes float depth (channels Z and Radial): -o must be an "
          ".exr file, got '" +
          o.output + "'");
    }
    if (!o.exr.empty()) throw UsageError("--depth-only writes -o only; drop --exr");
    if (o.overscan.value_or(0) > 0) {
      throw UsageError(
          "--depth-only writes the frame's depth and computes no AO: --overscan "
          "does not apply");
    }
    if (!o.params.empty()) {
      throw UsageError(o.params.front().flag + ": --depth-only computes no AO");
    }
  } else if (!o.print_camera) {
    check_output_name("-o", o.output, true);
  }
}

}  // namespace

int default_guard_band(int width, int height) {
  // 10% of the larger side: the default radius is 10% of the view's width at the median depth,
  // so an occluder up to one radius beyond the edge lands in the band.
  const int larger = std::max(width, height);
  return static_cast<int>((static_cast<long long>(larger) + 9) / 10);
}

const ssao_tools::ParamSetting* Options::param(const std::string& name) const {
  const ssao_tools::ParamSetting* found = nullptr;
  for (const ssao_tools::ParamSetting& p : params) {
    if (p.name == name) found = &p;
  }
  return found;
}

Options parse_args(int argc, const char* const* argv, const std::vector<ssao_param_desc>& table) {
  Options out;
  if (ssao_tools::scan_help_and_version(argc, argv, out)) return out;
  bool only_positionals = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!only_positionals && arg == "--") {
      only_positionals = true;
      continue;
    }
    if (!only_positionals && size_switch(arg, out)) continue;
    if (!only_positionals && arg.size() > 1 && arg[0] == '+') {
      pov_switch(arg, out);
      continue;
    }
    const bool is_option = !only_positionals && arg.size() > 1 && arg[0] == '-';
    if (!is_option) {
      if (!only_positionals && ini_option(arg, out)) continue;
      if (arg.empty()) throw UsageError("empty scene file name");
      if (!out.scene.empty()) {
        throw UsageError("more than one scene file: '" + out.scene + "' and '" + arg + "'");
      }
      out.scene = arg;
      continue;
    }
    ssao_tools::parse_option(argc, argv, i, front_options(), table, out);
  }
  validate(out);
  return out;
}

// The --help section that explains povray-ssao's choices (size, camera, depth, ...).
const char* how_values_are_chosen() {
  return "\n"
         "How povray-ssao chooses its values:\n"
         "  Size      --width/--height or +W/+H, else Width/Height of --ini, else of the first\n"
         "            povray.ini POV-Ray reads ($POVINI, ./povray.ini, ~/.povray/3.7/povray.ini,\n"
         "            /etc/povray/3.7/povray.ini), else 160x120. Every povray run gets +W +H.\n"
         "  Camera    POV-Ray's SDL cannot report its camera, so povray-ssao reads the scene's\n"
         "            last camera { } block: location, look_at, angle, right, up, direction, sky,\n"
         "            perspective/orthographic, translate/rotate/scale/matrix, with numbers,\n"
         "            vectors <a,b,c>, + - * / ( ), x y z, image_width, image_height, functions\n"
         "            (sqrt, sin, vnormalize, ...) and identifiers #declared/#local earlier as\n"
         "            numbers or vectors. Include files are read where POV-Ray finds them, and\n"
         "            #if/#switch conditions that can be evaluated (Declare= values included)\n"
         "            choose their branch. Other camera types (fisheye, panoramic, ...) and\n"
         "            macro-made cameras are refused; a scene without a camera gets POV-Ray's\n"
         "            default one (checked with two tiny renders). The resolved camera is\n"
         "            declared again after the scene in every pass, the beauty included, so all\n"
         "            passes agree; with focal blur (aperture) the beauty and the ambient pass\n"
         "            keep the scene's own camera (blurred), the depth and normal passes are\n"
         "            sharp (with --camera-* flags every pass is sharp).\n"
         "            libssao gets its pinhole intrinsics (projection intrinsics): fx = W |D| /\n"
         "            |right|, fy = H |D| / |up|, D the direction (orthographic: W / |right|, H /\n"
         "            |up| pixels per unit), centre (W / 2, H / 2): a 60-degree angle is a\n"
         "            31.2 mm lens on a 36 mm sensor.\n"
         "  Depth     d = -D log1p(-R / 60000) from the fog on R, or from the fog on G once\n"
         "            d >= 0.7 D1 (then B once d >= 2 D2); rays that hit nothing are background\n"
         "            (AO 1, Z = inf). EXR output is half-float, so the error depends on\n"
         "            x = d / D: about 4e-4 of d for x up to 0.7. A camera with look_at at\n"
         "            distance L gets D1 = 1.5 L, D2 = 10 D1, D3 = 100 D1 (0.02 L .. 300 L within\n"
         "            2e-3; rendered again with fogs from the measured depths when they fall\n"
         "            outside). Without look_at, a pre-pass (1/8 of the size, at most 80 pixels\n"
         "            wide, fogs 1, 100 and 10000) measures the depths; then D1 = 1.5 x the\n"
         "            median depth and D2 = the 99th percentile / 2, kept within 10..40 x D1; if\n"
         "            the farthest depth exceeds 2 x D2, a third fog on B with D3 = the farthest\n"
         "            depth (at least 10 x D2). Depths beyond about 8 x the last fog's distance\n"
         "            read as background.\n"
         "            The estimated error of the depth is printed. Glass and mirrors give the\n"
         "            depth of their own surface; no_image objects are not seen.\n"
         "  Band      --overscan G, default 10% of the image's larger side (rounded up; less\n"
         "            if the padded passes would exceed the size limit): the depth and normal\n"
         "            passes are rendered (W + 2G) x (H + 2G) with the camera's right x (W + 2G)\n"
         "            / W and up x (H + 2G) / H, so that their inner W x H pixels trace the\n"
         "            frame's rays; libssao reads the band as context for the frame's edges\n"
         "            (ssao_job_set_output_window). The beauty and the ambient pass stay W x H.\n"
         "  Radius    without --radius: 10% of the view's width at the median depth\n"
         "            (orthographic: of the view's width |right|), in scene units; printed.\n"
         "  Ambient   the ambient pass sets ambient_light rgb 10000 after the scene; divided by\n"
         "            10000 and multiplied by the scene's ambient_light (read from its\n"
         "            global_settings, default rgb 1) it is the ambient term of the beauty. Not\n"
         "            rendered for scenes with radiosity (POV-Ray 3.7 then ignores ambient) or an\n"
         "            ambient_light povray-ssao cannot read; --apply-to auto multiplies when the\n"
         "            ambient light is under 1% of the image's light.\n"
         "  Animation +KFI/+KFF (Initial_Frame/Final_Frame, with +KI +KF +KC +SF +EF, in an INI\n"
         "            file too): every frame is rendered on its own, each pass at that frame's\n"
         "            clock (POV-Ray's own: frame_number, clock, clock_delta as POV-Ray sets\n"
         "            them), with the camera and fogs read again for it. Outputs are numbered as\n"
         "            POV-Ray numbers its frames (-o out.png -> out01.png .. out24.png for "
         "+KFF24),\n"
         "            or fill a placeholder in the name (-o 'out.####.png'). --radius is\n"
         "            required (one radius for every frame). A frame that fails is reported, the\n"
         "            others are written, and the exit status is 1; --keep DIR keeps each frame's\n"
         "            files in DIR/frameNN.\n"
         "  Normals   reconstructed from the depth by libssao, except for scenes that include\n"
         "            \"ssao_passes.inc\": their exact normal pass (Declare=SSAOPass=1 +Q6, the\n"
         "            rendered camera's basis given as Declare=SSAOBasis...).\n"
         "  Includes  +L<the scene's folder> and +L<povray-ssao's includes: ssao_depth_pre.inc,\n"
         "            ssao_depth_post.inc, ssao_ambient_post.inc, ssao_passes.inc>\n"
         "            (<bin>/../share/povray-ssao, else the\n"
         "            source tree's povray_bridge/pov) on every povray run.\n"
         "\n"
         "Progress and timings go to stdout; warnings, errors and POV-Ray's error lines to "
         "stderr.\n"
         "Outputs are written to a temporary name and renamed when complete.\n"
         "Exit status: 0 success, 1 failure (nothing written), 2 command-line error.\n";
}

std::string usage_text(const std::vector<ssao_param_desc>& table) {
  std::string text =
      "Usage: povray-ssao SCENE.pov -o OUT.png [+W640 +H480] [--ini FILE.ini] [--exr OUT.exr]\n"
      "                   [--apply-to auto|ambient|beauty] [--overscan PIXELS] [--keep DIR]\n"
      "                   [--depth-only] [--povray PATH] [--quiet]\n"
      "                   [--camera-* overrides] [AO parameters: --radius X, --samples N, ...]\n"
      "       povray-ssao --beauty IMAGE --depth DEPTH.exr [--depth-channel NAME]\n"
      "                   [--depth-kind radial|planar] (--camera-angle DEG [--camera-aspect R] |\n"
      "                   --camera-orthographic --camera-width W) -o OUT.png [--exr OUT.exr]\n"
      "\n"
      "Screen-space ambient occlusion for POV-Ray 3.7 scenes. POV-Ray has no depth output, so\n"
      "povray-ssao renders the scene several times, all at once (one after another if the\n"
      "scene writes files as it parses, e.g. strings.inc's Parse_String): the beauty (with\n"
      "your quality settings), a depth pass (the scene wrapped so that additive fogs encode\n"
      "the distance: +Q9 -A +FE), an ambient pass (the scene's ambient term alone: +Q3 -A\n"
      "+FE) and, for scenes that include ssao_passes.inc, an exact normal pass. It computes AO\n"
      "with libssao and writes OUT.png = beauty - (1 - AO) x ambient (--apply-to ambient, the\n"
      "default where the scene has ambient light) or beauty x AO (--apply-to beauty), in\n"
      "linear light; the background is left unchanged.\n"
      "\n"
      "Render mode:\n";
  text += help_entry("SCENE.pov",
                     "the scene; every povray run works in its folder, with +L for that folder");
  auto section = [&](Group group) {
    for (const FrontOption& option : front_options()) {
      if (option.group != group) continue;
      std::string left =
          option.alias ? std::string(option.alias) + ", " + option.flag : option.flag;
      if (option.metavar) left += std::string(" ") + option.metavar;
      text += help_entry(left, option.help);
    }
  };
  section(kRender);
  text += help_entry("+SWITCH, NAME=VALUE",
                     "any other POV-Ray option (+A0.3, +R3, +K0.5, Declare=Detail=2, ...) goes "
                     "to every povray run before povray-ssao's own options, which override it in "
                     "the data passes (+Q9 -A -UA +FE for depth, +Q3 -A -UA +FE for the ambient "
                     "term, +Q6 -A -UA +FE for normals); +I, "
                     "+O and +F are povray-ssao's");
  text +=
      "\nCamera (read from the scene: the last camera { } block, or SSAOCamera(...) of\n"
      "ssao_passes.inc; a flag replaces the value read, and location with look_at or direction\n"
      "replaces a camera that cannot be read):\n";
  section(kCamera);
  text += "\nPost-process mode (no povray run; the camera from flags):\n";
  section(kPost);
  text += help_entry("--depth-kind radial|planar",
                     "libssao's depth_kind: radial, the distance along the pixel's ray (POV-Ray's "
                     "fog depth, the Radial channel), or planar, along the view axis (the Z "
                     "channel); default planar for a channel named Z, radial otherwise");
  text += "\nOther:\n";
  section(kOther);
  text +=
      "\nAO parameters (libssao's parameter table; --NAME_WITH_UNDERSCORES is written with\n"
      "dashes; the camera parameters, depth_kind and normal_space are set by povray-ssao):\n";
  text += ssao_tools::param_help(
      table, [](const ssao_param_desc& desc) { return !set_by_bridge(desc.name, false); });
  text += how_values_are_chosen();
  return text;
}

}  // namespace povray_ssao
