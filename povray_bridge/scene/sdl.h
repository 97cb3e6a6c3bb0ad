// SPDX-License-Identifier: MIT
// Just enough of POV-Ray's scene description language to find the scene's camera: a tokenizer,
// an evaluator of number and vector expressions (<a,b,c>, + - * /, parentheses, x y z,
// image_width, image_height, pi, common functions, .x/.y/.z, identifiers declared earlier as
// numbers or vectors) and a scan of the scene text that records #declare/#local constants and
// every camera { } block in the order POV-Ray would parse them. POV-Ray's SDL cannot report the
// camera it used, so this is how povray-ssao learns it (see pov_camera.h).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "src/vec3.h"  // core/ is on the include path (ssao_tools)
#include "tools/error.h"

namespace povray_ssao {

// A 3-vector in doubles (POV-Ray's coordinates: left-handed, +y up): the project's one vector
// type (core/src/vec3.h, header only), with dot, cross, length and normalized.
using V3 = ssao::Vector3<double>;
std::string format_vector(V3 v);  // "<1, 2.5, -3>"

// POV-Ray's "rotate <a, b, c>": about x by a degrees, then y by b, then z by c, each as POV-Ray's
// Compute_Rotation_Transform applies it to a point (row vector times matrix).
V3 rotate_xyz(V3 v, V3 degrees);

// A number or a vector, as SDL expressions produce them. A number used as a vector is promoted
// to <n, n, n>, as in POV-Ray.
struct SdlValue {
  bool is_vector = false;
  V3 v;  // a number is v.x
  double number() const { return v.x; }
  V3 vector() const { return is_vector ? v : V3{v.x, v.x, v.x}; }
};

struct Token {
  enum Kind { kNumber, kIdent, kString, kDirective, kPunct, kEnd };
  Kind kind = kEnd;
  std::string text;  // identifier, punctuation, directive name without '#', string contents
  double number = 0.0;
  std::string file;  // for messages
  int line = 0;
};

// Splits SDL text into tokens; comments (// and nested /* */) and whitespace dropped. The last
// token is kEnd. Throws ssao_tools::Error for an unterminated string or comment.
std::vector<Token> tokenize(const std::string& text, const std::string& file);

// True if `token` is the punctuation `text`.
bool is_punct(const Token& token, const char* text);

// Index of the token after the group that opens at tokens[open] ('{', '(' or '['), matching
// the same kind of bracket; tokens.size() - 1 (kEnd) if unbalanced.
size_t skip_group(const std::vector<Token>& tokens, size_t open);

// "scene.pov:12"
std::string where(const Token& token);

// What an identifier was declared as.
struct Symbol {
  enum Kind { kValue, kCamera, kTransform, kOther };
  Kind kind = kOther;
  SdlValue value;             // kValue
  std::vector<Token> tokens;  // kCamera, kTransform: the block's contents, without the braces
  std::string description;    // kOther: what it is ("an object", "an expression with ...")
  std::string declared_at;    // "scene.pov:12"
};
using Symbols = std::map<std::string, Symbol>;

// What the evaluator may need besides the symbols.
struct EvalContext {
  const Symbols* symbols = nullptr;
  int image_width = 0;
  int image_height = 0;
  double clock = 0.0;
};

// Thrown when an expression uses something the evaluator cannot evaluate; the message names it.
class EvalError : public ssao_tools::Error {
 public:
  using ssao_tools::Error::Error;
};

// Evaluates the expression starting at tokens[pos] (a number or vector expression); on return
// pos is the first token after it. Throws EvalError naming the identifier, function or token it
// could not read.
SdlValue evaluate(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context);

// The same with comparisons (< <= = != >= >), & | ! and ?: at the top level, as in #if (...),
// #declare and parentheses.
SdlValue evaluate_full(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context);

// A colour expression as global_settings' ambient_light takes it: [color|colour] followed by
// "rgb EXPR", "srgb EXPR" (decoded to linear), "red A green B blue C" (any of them, any order),
// or a number, vector or identifier declared as one of these. Colours with filter or
// transmit (rgbf, rgbt, 4- and 5-vectors) are not read: EvalError.
SdlValue evaluate_colour(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context);

// True if tokens[pos] starts a colour expression with a keyword (color, colour, rgb, srgb, red,
// green, blue, rgbf, ...).
bool starts_colour_keyword(const Token& token);

// True if tokens[pos] can start an expression (a number, '<', '(', '-', '+' or an identifier
// that is not one of the camera's keywords).
bool starts_expression(const std::vector<Token>& tokens, size_t pos);

// The state of the conditional directives (#if ... #end, #switch, loops, #macro bodies) while
// reading tokens: which parts POV-Ray would parse. Conditions that cannot be evaluated make
// every branch active and count in unknown_depth().
class Conditionals {
 public:
  // If tokens[i] is #if, #ifdef, #ifndef, #elseif, #else, #switch, #case, #range, #break,
  // #while, #for, #macro or #end, updates the state and returns the index after it and its
  // parenthesised argument; otherwise returns i.
  size_t handle(const std::vector<Token>& tokens, size_t i, const EvalContext& context);
  // True if tokens here are parsed by POV-Ray (as far as the conditions could be evaluated).
  bool active() const;
  // How many enclosing conditionals could not be evaluated (or are loops).
  int unknown_depth() const;

 private:
  struct Frame {
    bool known = true;   // the condition could be evaluated
    bool active = true;  // the current branch is parsed
    bool taken = false;  // a branch was taken already
    bool is_switch = false;
    bool switch_done = false;  // a #break ended the taken case
    double switch_value = 0.0;
  };
  static std::optional<bool> condition(const std::vector<Token>& tokens, size_t i,
                                       const EvalContext& context);
  static std::optional<double> value(const std::vector<Token>& tokens, size_t i,
                                     const EvalContext& context, int index);
  std::vector<Frame> frames_;
};

// A camera found in the scene text.
struct CameraSource {
  // kMacroCall: a call of a macro of the scene whose body makes a camera (not expanded).
  enum Kind { kBlock, kSSAOCameraMacro, kMacroCall };
  Kind kind = kBlock;
  std::string macro, macro_camera_at;  // kMacroCall: the macro, where its camera block is
  std::vector<Token> tokens;  // block contents without the braces, or the macro's arguments
  std::string location;       // "scene.pov:25"
  bool conditional = false;   // inside a conditional that could not be evaluated, or a loop
  Symbols symbols;            // the constants declared before it
};

// The result of scanning a scene file and the local files it includes.
struct SceneScan {
  std::vector<CameraSource> cameras;          // in parse order; POV-Ray uses the last one
  double version = 0.0;                       // the scene file's last readable #version (0: none)
  bool includes_ssao_passes = false;          // #include "ssao_passes.inc"
  double clock = 0.0;                         // the settings' clock, for evaluating the camera
  std::vector<std::string> notes;             // things worth a warning (unreadable includes, ...)
  std::vector<std::string> missing_includes;  // #include files not found (not read)
  // global_settings, as far as the text tells (povray-ssao's ambient pass needs them):
  std::optional<double> assumed_gamma;  // the first assumed_gamma (POV-Ray keeps the first)
  std::optional<V3> ambient_light;      // the last readable ambient_light (default rgb 1)
  std::string ambient_light_problem;    // why the last ambient_light could not be read, or ""
  bool uses_radiosity = false;          // a radiosity { } block in global_settings
  bool uses_quick_color = false;        // quick_color/quick_colour appears (used below +Q6)
  // Where parsing the scene writes a file, or "": an #fopen ... write/append, or a call of a
  // macro that makes one (strings.inc's Parse_String). Passes rendered at once would share it.
  std::string file_write;
};

struct ScanSettings {
  std::string directory;                   // the scene's folder (POV-Ray's working directory)
  std::vector<std::string> library_paths;  // +L and Library_Path folders, in order
  int image_width = 0, image_height = 0;
  double clock = 0.0;
  Symbols predeclared;  // Declare=NAME=VALUE of the command line and INI files, and an
                        // animation frame's frame_number, clock_on, ... (animation.h)
};

// Reads `path` and follows its #include files as POV-Ray finds them: in the scene's folder, then
// in the library paths, with ".inc" appended if needed (includes that cannot be found are
// skipped). #if/#ifdef/#ifndef/#elseif/#else/#switch/#case/#range conditions that can be
// evaluated select their branch as POV-Ray would; the others, and loops, are read entirely
// (cameras found there are marked conditional). Macro bodies are not read, but the macros
// that make a camera or write a file are known where they are called. Throws
// ssao_tools::Error if `path` cannot be read or tokenized.
SceneScan scan_scene(const std::string& path, const ScanSettings& settings);

}  // namespace povray_ssao
