// SPDX-License-Identifier: MIT
#include "pov_camera.h"

#include <cmath>
#include <cstdio>
#include <set>

namespace povray_ssao {
namespace {

constexpr double kEpsilon = 1e-10;  // POV-Ray's EPSILON

// An affine map in POV-Ray's row-vector convention: p' = p * m + t.
struct Affine {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  V3 t{0, 0, 0};

  V3 direction(V3 p) const {
    return {p.x * m[0][0] + p.y * m[1][0] + p.z * m[2][0],
            p.x * m[0][1] + p.y * m[1][1] + p.z * m[2][1],
            p.x * m[0][2] + p.y * m[1][2] + p.z * m[2][2]};
  }
  V3 point(V3 p) const { return direction(p) + t; }

  // This map followed by `next`.
  Affine then(const Affine& next) const {
    Affine out;
    for (int r = 0; r < 3; ++r) {
      const V3 row = next.direction({m[r][0], m[r][1], m[r][2]});
      out.m[r][0] = row.x;
      out.m[r][1] = row.y;
      out.m[r][2] = row.z;
    }
    out.t = next.point(t);
    return out;
  }

  static Affine translation(V3 v) {
    Affine a;
    a.t = v;
    return a;
  }
  static Affine rotation(V3 degrees) {
    Affine a;
    const V3 rows[3] = {rotate_xyz({1, 0, 0}, degrees), rotate_xyz({0, 1, 0}, degrees),
                        rotate_xyz({0, 0, 1}, degrees)};
    for (int r = 0; r < 3; ++r) {
      a.m[r][0] = rows[r].x;
      a.m[r][1] = rows[r].y;
      a.m[r][2] = rows[r].z;
    }
    return a;
  }
  static Affine scaling(V3 s) {
    Affine a;
    a.m[0][0] = s.x;
    a.m[1][1] = s.y;
    a.m[2][2] = s.z;
    return a;
  }
};

// One modifier read from the block: its value, or why it could not be read.
template <typename T>
struct Item {
  bool present = false;
  std::optional<T> value;
  std::string error;         // non-empty: could not evaluate
  std::string location;      // "scene.pov:27"
  bool conditional = false;  // set inside #if/#switch/... of the camera block
};

// What a camera block says, before resolution.
struct Spec {
  std::string type = "perspective";
  std::string type_location;
  bool type_conditional = false;
  Item<V3> location, look_at, right, up, direction, sky;
  Item<double> angle;  // an orthographic "angle" without a value reads as 0
  std::vector<Affine> transforms;
  std::vector<std::string> errors;  // anything else that could not be read
  bool focal_blur = false;
  bool conditional_focal_blur = false;
  std::vector<std::string> notes;
  // camera { DeclaredCamera ... }: the declared camera resolved, then only transforms.
  std::optional<ResolvedCamera> base;
};

const std::set<std::string>& unsupported_types() {
  static const std::set<std::string> types = {"fisheye",     "ultra_wide_angle", "omnimax",
                                              "panoramic",   "cylinder",         "spherical",
                                              "mesh_camera", "user_defined"};
  return types;
}

const std::set<std::string>& modifier_keywords() {
  static const std::set<std::string> words = {
      "location", "look_at",      "angle",       "right",      "up",       "direction",
      "sky",      "translate",    "rotate",      "scale",      "matrix",   "transform",
      "aperture", "blur_samples", "focal_point", "confidence", "variance", "normal",
      "bokeh",    "perspective",  "orthographic"};
  return words;
}

// How deep declared cameras and transforms may refer to others: the scan keeps their tokens, not
// their values, so "#declare C = camera { C }" (or two that name each other) would recurse
// forever (a stack overflow found by tests/fuzz/fuzz_pov_scene). Real scenes use one or two.
constexpr int kMaxDeclaredDepth = 16;

class BlockParser {
 public:
  BlockParser(std::vector<Token> tokens, const Symbols& symbols, int width, int height,
              double clock, std::string block_location, int depth = 0)
      : tokens_(std::move(tokens)), block_location_(std::move(block_location)), depth_(depth) {
    Token end;
    end.kind = Token::kEnd;
    end.file = tokens_.empty() ? "" : tokens_.back().file;
    end.line = tokens_.empty() ? 0 : tokens_.back().line;
    tokens_.push_back(end);
    symbols_ = symbols;
    context_.symbols = &symbols_;
    context_.image_width = width;
    context_.image_height = height;
    context_.clock = clock;
  }

  Spec parse(bool only_transforms) {
    Spec spec;
    size_t pos = 0;
    if (!only_transforms && tokens_[0].kind == Token::kIdent) {
      const auto found = symbols_.find(tokens_[0].text);
      if (found != symbols_.end() && found->second.kind == Symbol::kCamera) {
        // camera { Declared ... }: POV-Ray 3.5+ copies the declared camera and then accepts
        // only transformations.
        check_depth(tokens_[0]);
        BlockParser inner(found->second.tokens, symbols_, context_.image_width,
                          context_.image_height, context_.clock, found->second.declared_at,
                          depth_ + 1);
        Spec declared = inner.parse(false);
        spec.base = resolve_declared(declared, found->second.declared_at);
        spec.focal_blur = declared.focal_blur;
        spec.conditional_focal_blur = declared.conditional_focal_blur;
        spec.notes = declared.notes;
        pos = 1;
        only_transforms = true;
      }
    }
    while (tokens_[pos].kind != Token::kEnd) pos = modifier(spec, pos, only_transforms);
    return spec;
  }

 private:
  // Declared cameras must be fully readable; their errors are reported as they are.
  static ResolvedCamera resolve_declared(const Spec& spec, const std::string& declared_at);

  [[noreturn]] void fail_at(const Token& token, const std::string& message) {
    throw EvalError(where(token) + ": " + message);
  }

  void check_depth(const Token& token) {
    if (depth_ >= kMaxDeclaredDepth) {
      fail_at(token, "'" + token.text + "' is a declared camera or transform that refers to " +
                         "itself (or declared ones nest deeper than " +
                         std::to_string(kMaxDeclaredDepth) + " levels)");
    }
  }

  // Skips to the next modifier keyword or directive after an unreadable value.
  size_t resync(size_t pos) {
    while (tokens_[pos].kind != Token::kEnd) {
      if (tokens_[pos].kind == Token::kDirective) return pos;
      if (tokens_[pos].kind == Token::kIdent && (modifier_keywords().count(tokens_[pos].text) ||
                                                 unsupported_types().count(tokens_[pos].text))) {
        return pos;
      }
      if (is_punct(tokens_[pos], "(") || is_punct(tokens_[pos], "{") ||
          is_punct(tokens_[pos], "[")) {
        pos = skip_group(tokens_, pos);
      } else {
        ++pos;
      }
    }
    return pos;
  }

  template <typename T>
  size_t read_item(Item<T>& item, size_t pos, bool vector) {
    const Token& keyword = tokens_[pos];
    item.present = true;
    item.location = where(keyword);
    item.conditional = item.conditional || conditional() > 0;
    item.error.clear();
    item.value.reset();
    ++pos;
    try {
      const SdlValue value = evaluate(tokens_, pos, context_);
      if constexpr (std::is_same_v<T, V3>) {
        item.value = value.vector();
      } else {
        if (value.is_vector) fail_at(keyword, keyword.text + " expects a number, got a vector");
        item.value = value.number();
      }
      (void)vector;
      return pos;
    } catch (const EvalError& e) {
      item.error = std::string("cannot read the camera's ") + keyword.text + ": " + e.what();
      return resync(pos);
    }
  }

  // Reads a number, ignoring it; returns the position after it.
  size_t skip_value(Spec& spec, size_t pos, double* out = nullptr) {
    const Token& keyword = tokens_[pos - 1];
    try {
      const double value = evaluate(tokens_, pos, context_).number();
      if (out) *out = value;
      return pos;
    } catch (const EvalError& e) {
      if (out) *out = NAN;
      spec.notes.push_back("could not read the camera's " + keyword.text + " (" + e.what() + ")");
      return resync(pos);
    }
  }

  size_t transform(Spec& spec, size_t pos) {
    const Token& keyword = tokens_[pos];
    ++pos;
    try {
      if (keyword.text == "matrix") {
        if (!is_punct(tokens_[pos], "<")) fail_at(keyword, "matrix expects <12 numbers>");
        ++pos;
        double v[12];
        for (int k = 0; k < 12; ++k) {
          // Each element is a full expression; stop the vector parser at ',' and '>'.
          v[k] = evaluate(tokens_, pos, context_).number();
          if (k < 11) {
            if (!is_punct(tokens_[pos], ",")) fail_at(tokens_[pos], "matrix expects 12 numbers");
            ++pos;
          }
        }
        if (!is_punct(tokens_[pos], ">")) fail_at(tokens_[pos], "matrix expects 12 numbers");
        ++pos;
        Affine a;
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) a.m[r][c] = v[r * 3 + c];
        }
        a.t = {v[9], v[10], v[11]};
        add_transform(spec, a, keyword);
        return pos;
      }
      if (keyword.text == "transform" && tokens_[pos].kind == Token::kIdent) {
        // transform Declared: its translate/rotate/scale/matrix, in order.
        const auto found = symbols_.find(tokens_[pos].text);
        if (found == symbols_.end() || found->second.kind != Symbol::kTransform) {
          fail_at(tokens_[pos],
                  "'" + tokens_[pos].text + "' is not a transform { } declared before the camera");
        }
        check_depth(tokens_[pos]);
        BlockParser inner(found->second.tokens, symbols_, context_.image_width,
                          context_.image_height, context_.clock, found->second.declared_at,
                          depth_ + 1);
        const Spec declared = inner.parse(true);
        if (!declared.errors.empty()) throw EvalError(declared.errors.front());
        for (const Affine& a : declared.transforms) add_transform(spec, a, keyword);
        return pos + 1;
      }
      if (keyword.text == "transform") {
        // transform { translate .. rotate .. scale .. matrix .. }
        if (!is_punct(tokens_[pos], "{")) {
          fail_at(keyword, "cannot read this 'transform'");
        }
        const size_t end = skip_group(tokens_, pos) - 1;
        ++pos;
        while (pos < end) {
          const std::string& word = tokens_[pos].text;
          if (tokens_[pos].kind != Token::kIdent ||
              (word != "translate" && word != "rotate" && word != "scale" && word != "matrix")) {
            fail_at(tokens_[pos], "cannot read " + tokens_[pos].text + " in a camera transform");
          }
          pos = transform(spec, pos);
        }
        return end + 1;
      }
      const SdlValue value = evaluate(tokens_, pos, context_);
      if (keyword.text == "translate") {
        add_transform(spec, Affine::translation(value.vector()), keyword);
      } else if (keyword.text == "rotate") {
        add_transform(spec, Affine::rotation(value.vector()), keyword);
      } else {
        add_transform(spec, Affine::scaling(value.vector()), keyword);
      }
      return pos;
    } catch (const EvalError& e) {
      spec.errors.push_back(std::string("cannot read the camera's ") + keyword.text + ": " +
                            e.what());
      return resync(pos);
    }
  }

  void add_transform(Spec& spec, const Affine& a, const Token& keyword) {
    if (conditional() > 0) {
      spec.errors.push_back(where(keyword) + ": the camera's " + keyword.text +
                            " is inside a conditional directive, which povray-ssao does not "
                            "evaluate");
    }
    spec.transforms.push_back(a);
  }

  size_t directive(Spec& spec, size_t pos) {
    const size_t next = conditionals_.handle(tokens_, pos, context_);
    if (next != pos) return next;
    if (!conditionals_.active()) return pos + 1;
    const Token& token = tokens_[pos];
    const std::string& name = token.text;
    ++pos;
    if (name == "debug" || name == "warning") {
      // A string expression: skip a string or a parenthesised concat(...).
      if (tokens_[pos].kind == Token::kString) return pos + 1;
      if (tokens_[pos].kind == Token::kIdent && is_punct(tokens_[pos + 1], "(")) {
        return skip_group(tokens_, pos + 1);
      }
      return pos;
    }
    if (name == "declare" || name == "local") {
      // A constant declared inside the block: evaluate it if we can.
      if (tokens_[pos].kind == Token::kIdent && is_punct(tokens_[pos + 1], "=")) {
        const std::string identifier = tokens_[pos].text;
        size_t value_pos = pos + 2;
        Symbol symbol;
        symbol.declared_at = where(tokens_[pos]);
        try {
          symbol.value = evaluate(tokens_, value_pos, context_);
          symbol.kind = Symbol::kValue;
        } catch (const EvalError& e) {
          symbol.kind = Symbol::kOther;
          symbol.description =
              std::string("an expression povray-ssao cannot evaluate (") + e.what() + ")";
          value_pos = resync(value_pos);
        }
        symbols_[identifier] = symbol;
        if (is_punct(tokens_[value_pos], ";")) ++value_pos;
        return value_pos;
      }
    }
    spec.errors.push_back(where(token) + ": cannot read the directive #" + name +
                          " inside the camera block");
    return resync(pos);
  }

  size_t modifier(Spec& spec, size_t pos, bool only_transforms) {
    const Token& token = tokens_[pos];
    if (token.kind == Token::kDirective) return directive(spec, pos);
    if (!conditionals_.active()) return pos + 1;  // a branch POV-Ray skips
    const std::string& word = token.text;
    if (token.kind == Token::kIdent &&
        (word == "translate" || word == "rotate" || word == "scale" || word == "matrix" ||
         word == "transform")) {
      return transform(spec, pos);
    }
    if (only_transforms) {
      spec.errors.push_back(where(token) + ": cannot read " + word +
                            " after a declared camera (POV-Ray allows only transformations "
                            "there)");
      return resync(pos + 1);
    }
    if (token.kind == Token::kIdent) {
      if (word == "perspective" || word == "orthographic") {
        spec.type = word;
        spec.type_location = where(token);
        spec.type_conditional = spec.type_conditional || conditional() > 0;
        return pos + 1;
      }
      if (unsupported_types().count(word)) {
        spec.type = word;
        spec.type_location = where(token);
        if (word == "cylinder") return skip_value(spec, pos + 1);
        if (is_punct(tokens_[pos + 1], "{")) return skip_group(tokens_, pos + 1);
        return pos + 1;
      }
      if (word == "location") return read_item(spec.location, pos, true);
      if (word == "look_at") return read_item(spec.look_at, pos, true);
      if (word == "right") return read_item(spec.right, pos, true);
      if (word == "up") return read_item(spec.up, pos, true);
      if (word == "direction") return read_item(spec.direction, pos, true);
      if (word == "sky") return read_item(spec.sky, pos, true);
      if (word == "angle") {
        if (spec.type == "orthographic" && !starts_expression(tokens_, pos + 1)) {
          // POV-Ray: "angle" without a value on an orthographic camera reads as 0.
          spec.angle.present = true;
          spec.angle.value = 0.0;
          spec.angle.location = where(token);
          spec.angle.conditional = spec.angle.conditional || conditional() > 0;
          return pos + 1;
        }
        return read_item(spec.angle, pos, false);
      }
      if (word == "aperture") {
        double value = 0.0;
        const size_t next = skip_value(spec, pos + 1, &value);
        if (conditional() > 0) {
          spec.conditional_focal_blur = spec.conditional_focal_blur || value != 0.0;
        } else {
          spec.focal_blur = value != 0.0;  // NaN (unreadable) counts as blur
        }
        return next;
      }
      if (word == "blur_samples") {
        size_t next = skip_value(spec, pos + 1);
        if (is_punct(tokens_[next], ",")) next = skip_value(spec, next + 1);
        return next;
      }
      if (word == "confidence" || word == "variance") return skip_value(spec, pos + 1);
      if (word == "focal_point") {
        Item<V3> ignored;
        return read_item(ignored, pos, true);
      }
      if (word == "normal" || word == "bokeh") {
        if (word == "normal") {
          spec.notes.push_back(where(token) +
                               ": the camera's normal { } (ray perturbation) is not reproduced "
                               "in the passes");
        }
        return is_punct(tokens_[pos + 1], "{") ? skip_group(tokens_, pos + 1) : pos + 1;
      }
    }
    spec.errors.push_back(where(token) + ": cannot read '" + word +
                          "' in the camera block (a macro call or an unknown camera modifier)");
    return resync(pos + 1);
  }

  std::vector<Token> tokens_;
  std::string block_location_;
  int depth_ = 0;  // how many declared cameras or transforms enclose this block
  Symbols symbols_;
  EvalContext context_;
  Conditionals conditionals_;
  int conditional() const { return conditionals_.unknown_depth(); }
};

// Camera types povray-ssao cannot model, types chosen under #if, and items that could not be
// read: EvalError. An orthographic override makes any type orthographic.
void check_type_and_errors(const Spec& spec, const CameraOverrides& overrides) {
  if (!overrides.orthographic) {
    if (unsupported_types().count(spec.type)) {
      throw EvalError(spec.type_location + ": the camera is of type '" + spec.type +
                      "'; povray-ssao supports only perspective and orthographic cameras");
    }
    if (spec.type_conditional) {
      throw EvalError(spec.type_location +
                      ": the camera's type is chosen inside a conditional "
                      "directive, which povray-ssao does not evaluate");
    }
  }
  if (!spec.errors.empty()) throw EvalError(spec.errors.front());
}

// look_at as POV-Ray applies it: direction towards the point, right = sky x direction, up =
// direction x right, each keeping its length (right its handedness too).
void point_at(V3 look_at, V3 location, V3 sky, V3& direction, V3& right, V3& up,
              std::vector<std::string>& warnings) {
  const double direction_length = length(direction);
  const double up_length = length(up);
  const double right_length = length(right);
  const double handedness = dot(cross(up, direction), right);
  direction = look_at - location;
  if (dot(direction, direction) < kEpsilon) {
    throw EvalError("the camera's location and look_at coincide");
  }
  direction = normalized(direction);
  const V3 saved_right = right;
  right = cross(sky, direction);
  if (std::fabs(right.x) < kEpsilon && std::fabs(right.y) < kEpsilon &&
      std::fabs(right.z) < kEpsilon) {
    warnings.push_back(
        "the camera looks along its sky vector; POV-Ray then keeps the "
        "given right vector");
    right = saved_right;
  }
  right = normalized(right);
  up = cross(direction, right);
  direction = direction * direction_length;
  right = right * (handedness > 0.0 ? right_length : -right_length);
  up = up * up_length;
}

// povray-ssao writes the vectors into every pass's scene and libssao's camera: a value that
// overflowed (e.g. location <1e308 * 10, 0, 0>) would reach them as inf or nan (found by
// tests/fuzz/fuzz_pov_scene). Vectors that are not perpendicular only get a warning.
void check_resolved(const ResolvedCamera& camera, std::vector<std::string>& warnings) {
  auto finite = [](V3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(camera.location) || !finite(camera.direction) || !finite(camera.right) ||
      !finite(camera.up) || !std::isfinite(camera.look_at_distance)) {
    throw EvalError(
        "the camera's location, direction, right or up vector is not finite (a value "
        "overflows)");
  }
  if (!(length(camera.direction) > 0.0) || !(length(camera.right) > 0.0) ||
      !(length(camera.up) > 0.0)) {
    throw EvalError("the camera's direction, right or up vector has zero length");
  }
  const double k1 = dot(normalized(camera.right), normalized(camera.up));
  const double k2 = dot(normalized(camera.right), normalized(camera.direction));
  const double k3 = dot(normalized(camera.up), normalized(camera.direction));
  if (std::fabs(k1) > 1e-6 || std::fabs(k2) > 1e-6 || std::fabs(k3) > 1e-6) {
    warnings.push_back(
        "the camera's right, up and direction vectors are not perpendicular; "
        "libssao assumes they are, so AO is approximate");
  }
}

// Resolves a spec with POV-Ray 3.5+'s rules (Parse_Camera): right, direction, angle (sets
// |direction| from |right|), up, sky, location, look_at (re-orients right, up, direction keeping
// their lengths), the orthographic resize, then the transformations in order. Overrides replace
// the block's values. Throws EvalError (message naming the item) for an item that cannot be used.
ResolvedCamera resolve(const Spec& spec, const CameraOverrides& overrides,
                       std::vector<std::string>& warnings) {
  auto pick = [&](const Item<V3>& item, const std::optional<V3>& override_value,
                  const char* flag) -> std::optional<V3> {
    if (override_value) return override_value;
    if (!item.present) return std::nullopt;
    if (!item.error.empty()) throw EvalError(item.error);
    if (item.conditional) {
      throw EvalError(item.location +
                      ": the camera's value is set inside a conditional "
                      "directive (#if, #switch, ...), which povray-ssao does not evaluate; "
                      "give it with " +
                      std::string(flag));
    }
    return item.value;
  };

  ResolvedCamera camera;
  check_type_and_errors(spec, overrides);
  camera.orthographic = overrides.orthographic || spec.type == "orthographic";

  V3 location{0, 0, 0}, direction{0, 0, 1}, up{0, 1, 0}, right{1.33, 0, 0}, sky{0, 1, 0};
  V3 look_at{0, 0, 1};
  bool has_look_at = false;
  if (spec.base && !overrides.any()) {
    ResolvedCamera base = *spec.base;
    location = base.location;
    direction = base.direction;
    right = base.right;
    up = base.up;
    camera = base;
  } else {
    if (spec.base) {
      location = spec.base->location;
      direction = spec.base->direction;
      right = spec.base->right;
      up = spec.base->up;
      camera.orthographic = overrides.orthographic || spec.base->orthographic;
    }
    const std::optional<V3> given_right = pick(spec.right, overrides.right, "--camera-right");
    const std::optional<V3> given_up = pick(spec.up, overrides.up, "--camera-up");
    const std::optional<V3> given_direction =
        pick(spec.direction, overrides.direction, "--camera-direction");
    const std::optional<V3> given_sky = pick(spec.sky, overrides.sky, "--camera-sky");
    const std::optional<V3> given_location =
        pick(spec.location, overrides.location, "--camera-location");
    const std::optional<V3> given_look_at =
        pick(spec.look_at, overrides.look_at, "--camera-look-at");
    std::optional<double> given_angle = overrides.angle;
    if (!given_angle && spec.angle.present) {
      if (!spec.angle.error.empty()) throw EvalError(spec.angle.error);
      if (spec.angle.conditional) {
        throw EvalError(spec.angle.location +
                        ": the camera's angle is set inside a "
                        "conditional directive, which povray-ssao does not evaluate; give it "
                        "with --camera-angle");
      }
      given_angle = spec.angle.value;
    }
    if (given_right) right = *given_right;
    if (given_up) up = *given_up;
    if (given_direction) direction = *given_direction;
    if (given_sky) sky = *given_sky;
    if (given_location) location = *given_location;

    if (given_angle &&
        (*given_angle < 0.0 || *given_angle >= 180.0 || !std::isfinite(*given_angle))) {
      throw EvalError("the camera's angle must be in [0, 180) degrees, got " +
                      std::to_string(*given_angle));
    }
    if (given_angle && *given_angle > 0.0) {
      direction =
          normalized(direction) * (length(right) / std::tan(*given_angle * M_PI / 360.0) / 2.0);
    }
    if (given_look_at) {
      has_look_at = true;
      look_at = *given_look_at;
      point_at(look_at, location, sky, direction, right, up, warnings);
    }
    if (camera.orthographic && ((!given_up && !given_right) || given_angle)) {
      // POV-Ray sizes an orthographic view like the perspective one at the look_at distance.
      const double k1 = length(look_at - location);
      const double k2 = length(direction);
      if (k1 > kEpsilon && k2 > kEpsilon) {
        right = right * (k1 / k2);
        up = up * (k1 / k2);
      }
    }
  }
  Affine all;
  for (const Affine& a : spec.transforms) all = all.then(a);
  camera.location = all.point(location);
  if (has_look_at) camera.look_at_distance = length(all.point(look_at) - camera.location);
  camera.direction = all.direction(direction);
  camera.right = all.direction(right);
  camera.up = all.direction(up);

  check_resolved(camera, warnings);
  return camera;
}

ResolvedCamera BlockParser::resolve_declared(const Spec& spec, const std::string& declared_at) {
  std::vector<std::string> ignored;
  try {
    return resolve(spec, CameraOverrides{}, ignored);
  } catch (const EvalError& e) {
    throw EvalError(std::string(e.what()) + " (in the camera declared at " + declared_at + ")");
  }
}

Spec parse_macro_camera(const CameraSource& source, int width, int height, double clock) {
  // SSAOCamera(Location, LookAt, Angle): perspective, right x * image_width / image_height,
  // up y, sky y, angle, look_at (ssao_passes.inc).
  std::vector<Token> tokens = source.tokens;
  Token end;
  end.kind = Token::kEnd;
  tokens.push_back(end);
  EvalContext context;
  context.symbols = &source.symbols;
  context.image_width = width;
  context.image_height = height;
  context.clock = clock;
  Spec spec;
  spec.type_location = source.location;
  auto set = [&](Item<V3>& item, V3 value) {
    item.present = true;
    item.value = value;
    item.location = source.location;
  };
  set(spec.right, V3{static_cast<double>(width) / height, 0, 0});
  set(spec.up, V3{0, 1, 0});
  set(spec.sky, V3{0, 1, 0});
  size_t pos = 1;  // after '('
  try {
    const V3 location = evaluate(tokens, pos, context).vector();
    if (!is_punct(tokens[pos], ",")) throw EvalError(where(tokens[pos]) + ": expected ','");
    ++pos;
    const V3 look_at = evaluate(tokens, pos, context).vector();
    if (!is_punct(tokens[pos], ",")) throw EvalError(where(tokens[pos]) + ": expected ','");
    ++pos;
    const double angle = evaluate(tokens, pos, context).number();
    set(spec.location, location);
    set(spec.look_at, look_at);
    spec.angle.present = true;
    spec.angle.value = angle;
  } catch (const EvalError& e) {
    spec.errors.push_back(std::string("cannot read the arguments of SSAOCamera(...): ") + e.what());
  }
  return spec;
}

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string exact_vector(V3 v) {
  return "<" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + ">";
}

}  // namespace

double ResolvedCamera::horizontal_fov() const {
  return 2.0 * std::atan(length(right) / (2.0 * length(direction))) * 180.0 / M_PI;
}

double ResolvedCamera::aspect() const { return length(right) / length(up); }

std::string ResolvedCamera::to_sdl() const {
  // Explicit vectors and no look_at/angle: POV-Ray uses them as given (any #version), and an
  // orthographic camera with both right and up given is not resized. No aperture: no focal blur.
  return std::string("camera {\n  ") + (orthographic ? "orthographic" : "perspective") +
         "\n  location " + exact_vector(location) + "\n  direction " + exact_vector(direction) +
         "\n  right " + exact_vector(right) + "\n  up " + exact_vector(up) + "\n}\n";
}

std::string ResolvedCamera::summary() const {
  char buffer[512];
  if (orthographic) {
    std::snprintf(buffer, sizeof buffer,
                  "orthographic, location %s, direction %s, view %.6g x %.6g scene units",
                  format_vector(location).c_str(), format_vector(normalized(direction)).c_str(),
                  length(right), length(up));
  } else {
    std::snprintf(buffer, sizeof buffer,
                  "perspective, location %s, direction %s, horizontal FOV %.4g deg, "
                  "|right|/|up| %.4g",
                  format_vector(location).c_str(), format_vector(normalized(direction)).c_str(),
                  horizontal_fov(), aspect());
  }
  return buffer;
}

void ResolvedCamera::apply_to_job(ssao::api::Job& job, int width, int height) const {
  try {
    set_job_camera(job, width, height);
  } catch (const ssao::api::Error& e) {
    throw ssao_tools::Error("libssao cannot model this camera (" + summary() + "): " + e.what());
  }
}

// POV-Ray's image plane lies at |direction| from the eye and spans |right| across the width and
// |up| down the height, centred on the view axis: in libssao's pinhole intrinsics, W |direction|
// / |right| pixels per unit of x at unit depth (orthographic: W / |right| pixels per scene unit).
void ResolvedCamera::set_job_camera(ssao::api::Job& job, int width, int height) const {
  const double r = length(right), u = length(up), d = length(direction);
  const double w = width, h = height, distance = orthographic ? 1.0 : d;
  job.set("projection", "intrinsics");
  job.set("camera_type", orthographic ? "ORTHO" : "PERSP");
  job.set("intrinsics", std::vector<double>{w * distance / r, h * distance / u, w / 2.0, h / 2.0});
}

double ResolvedCamera::radial_factor(int px, int py, int width, int height) const {
  if (orthographic) return 1.0;
  const double x0 = (px + 0.5) / width - 0.5;
  const double y0 = 0.5 - (py + 0.5) / height;
  return length(direction + right * x0 + up * y0) / length(direction);
}

ResolvedCamera ResolvedCamera::widened(int width, int height, int band) const {
  ResolvedCamera wide = *this;
  wide.right = right * ((static_cast<double>(width) + 2.0 * band) / width);
  wide.up = up * ((static_cast<double>(height) + 2.0 * band) / height);
  return wide;
}

CameraReading read_camera(const SceneScan& scan, const CameraOverrides& overrides, int width,
                          int height) {
  CameraReading reading;
  std::string problem;
  if (scan.cameras.empty()) {
    // POV-Ray renders a scene without a camera with its default one, which resolve() starts
    // from (the flags apply on top of it, as on a scene's camera).
    try {
      reading.camera = resolve(Spec{}, overrides, reading.warnings);
      reading.default_camera = true;
      reading.source = "POV-Ray's default camera: the scene text has no camera { } block";
      if (overrides.any()) reading.source += "; with the --camera-* flags";
    } catch (const EvalError& e) {
      problem = e.what();
    }
  } else {
    const CameraSource& source = scan.cameras.back();
    try {
      Spec spec;
      if (source.kind == CameraSource::kMacroCall) {
        throw EvalError(source.location + ": the camera is made by the macro '" + source.macro +
                        "' (its camera { } block at " + source.macro_camera_at +
                        "), which povray-ssao does not expand");
      }
      if (source.kind == CameraSource::kSSAOCameraMacro) {
        spec = parse_macro_camera(source, width, height, scan.clock);
      } else {
        BlockParser parser(source.tokens, source.symbols, width, height, scan.clock,
                           source.location);
        spec = parser.parse(false);
      }
      reading.camera = resolve(spec, overrides, reading.warnings);
      reading.source = "the camera at " + source.location;
      if (overrides.any()) reading.source += " with the --camera-* flags";
      reading.had_focal_blur = spec.focal_blur || spec.conditional_focal_blur;
      for (const std::string& note : spec.notes) reading.warnings.push_back(note);
      if (source.conditional && scan.cameras.size() > 1) {
        reading.warnings.push_back(
            "the scene has several cameras and the last one (" + source.location +
            ") is inside a conditional directive; povray-ssao uses it and renders every pass "
            "with it. Give --camera-* flags if POV-Ray would choose another");
      }
    } catch (const EvalError& e) {
      problem = e.what();
    }
  }
  if (scan.version > 0.0 && scan.version < 3.5) {
    reading.warnings.push_back("the scene declares #version " + std::to_string(scan.version) +
                               "; povray-ssao reads cameras with the rules of POV-Ray 3.5 and "
                               "later");
  }
  if (problem.empty()) return reading;
  if (overrides.complete()) {
    reading = CameraReading{};
    std::vector<std::string> warnings;
    reading.camera = resolve(Spec{}, overrides, warnings);
    reading.warnings = warnings;
    reading.warnings.insert(reading.warnings.begin(),
                            problem + "; using the --camera-* flags alone");
    reading.source = "the --camera-* flags";
    return reading;
  }
  if (!scan.missing_includes.empty()) {
    std::string names;
    for (const std::string& name : scan.missing_includes) {
      names += (names.empty() ? "'" : ", '") + name + "'";
    }
    problem += " (include files not found, so not read: " + names + ")";
  }
  throw ssao_tools::Error(problem +
                          ".\nGive the camera on the command line instead, e.g. --camera-location "
                          "X,Y,Z --camera-look-at X,Y,Z --camera-angle DEG (also --camera-right, "
                          "--camera-up, --camera-sky, --camera-direction, --camera-orthographic); "
                          "flags replace the values read from the scene");
}

ResolvedCamera make_camera(bool orthographic, double angle, double ortho_width, double aspect) {
  ResolvedCamera camera;
  camera.orthographic = orthographic;
  camera.location = {0, 0, 0};
  if (orthographic) {
    camera.right = {ortho_width, 0, 0};
    camera.up = {0, ortho_width / aspect, 0};
    camera.direction = {0, 0, 1};
  } else {
    camera.right = {aspect, 0, 0};
    camera.up = {0, 1, 0};
    camera.direction = {0, 0, aspect / (2.0 * std::tan(angle * M_PI / 360.0))};
  }
  return camera;
}

}  // namespace povray_ssao
