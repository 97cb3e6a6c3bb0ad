// SPDX-License-Identifier: MIT
#include "sdl.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

namespace povray_ssao {

namespace fs = std::filesystem;

std::string format_vector(V3 v) {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, "<%.6g, %.6g, %.6g>", v.x, v.y, v.z);
  return buffer;
}

V3 rotate_xyz(V3 v, V3 degrees) {
  const double to_radians = M_PI / 180.0;
  // About x: y' = y cos - z sin, z' = y sin + z cos (POV-Ray's matrix, row-vector convention).
  double c = std::cos(degrees.x * to_radians), s = std::sin(degrees.x * to_radians);
  v = {v.x, v.y * c - v.z * s, v.y * s + v.z * c};
  // About y: x' = x cos + z sin, z' = -x sin + z cos.
  c = std::cos(degrees.y * to_radians);
  s = std::sin(degrees.y * to_radians);
  v = {v.x * c + v.z * s, v.y, -v.x * s + v.z * c};
  // About z: x' = x cos - y sin, y' = x sin + y cos.
  c = std::cos(degrees.z * to_radians);
  s = std::sin(degrees.z * to_radians);
  return {v.x * c - v.y * s, v.x * s + v.y * c, v.z};
}

std::string where(const Token& token) { return token.file + ":" + std::to_string(token.line); }

// ------------------------------------------------------------------------------------------
// Tokenizer

namespace {

// The index after the block comment starting at text[i] ("/*"); POV-Ray's block comments nest.
// Counts the lines it spans into `line`. Throws for a comment left open.
size_t skip_block_comment(const std::string& text, size_t i, int& line, const std::string& file) {
  const size_t n = text.size();
  const int start_line = line;
  int depth = 0;
  while (i < n) {
    if (text[i] == '/' && i + 1 < n && text[i + 1] == '*') {
      ++depth;
      i += 2;
    } else if (text[i] == '*' && i + 1 < n && text[i + 1] == '/') {
      --depth;
      i += 2;
      if (depth == 0) break;
    } else {
      if (text[i] == '\n') ++line;
      ++i;
    }
  }
  if (depth != 0) {
    throw ssao_tools::Error(file + ":" + std::to_string(start_line) + ": unterminated /* comment");
  }
  return i;
}

// The index after the number starting at text[i]: digits, a fraction, an exponent.
size_t number_end(const std::string& text, size_t i) {
  const size_t n = text.size();
  size_t j = i;
  while (j < n && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
  if (j < n && text[j] == '.') {
    ++j;
    while (j < n && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
  }
  if (j < n && (text[j] == 'e' || text[j] == 'E')) {
    size_t k = j + 1;
    if (k < n && (text[k] == '+' || text[k] == '-')) ++k;
    if (k < n && std::isdigit(static_cast<unsigned char>(text[k]))) {
      while (k < n && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
      j = k;
    }
  }
  return j;
}

}  // namespace

std::vector<Token> tokenize(const std::string& text, const std::string& file) {
  std::vector<Token> tokens;
  int line = 1;
  size_t i = 0;
  const size_t n = text.size();
  auto make = [&](Token::Kind kind, std::string value) {
    Token token;
    token.kind = kind;
    token.text = std::move(value);
    token.file = file;
    token.line = line;
    return token;
  };
  auto is_ident_start = [](char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
  };
  auto is_ident_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  };
  while (i < n) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i < n && text[i] != '\n') ++i;
      continue;
    }
    if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      i = skip_block_comment(text, i, line, file);
      continue;
    }
    if (c == '"') {
      const int start_line = line;
      std::string value;
      ++i;
      while (i < n && text[i] != '"') {
        if (text[i] == '\\' && i + 1 < n) {
          value += text[i + 1];
          i += 2;
          continue;
        }
        if (text[i] == '\n') ++line;
        value += text[i++];
      }
      if (i >= n) {
        throw ssao_tools::Error(file + ":" + std::to_string(start_line) + ": unterminated string");
      }
      ++i;
      Token token = make(Token::kString, value);
      token.line = start_line;
      tokens.push_back(token);
      continue;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && i + 1 < n && std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      const size_t j = number_end(text, i);
      Token token = make(Token::kNumber, text.substr(i, j - i));
      token.number = std::strtod(token.text.c_str(), nullptr);
      tokens.push_back(token);
      i = j;
      continue;
    }
    if (is_ident_start(c)) {
      size_t j = i;
      while (j < n && is_ident_char(text[j])) ++j;
      tokens.push_back(make(Token::kIdent, text.substr(i, j - i)));
      i = j;
      continue;
    }
    if (c == '#') {
      size_t j = i + 1;
      while (j < n && (text[j] == ' ' || text[j] == '\t')) ++j;
      size_t k = j;
      while (k < n && is_ident_char(text[k])) ++k;
      if (k > j) {
        tokens.push_back(make(Token::kDirective, text.substr(j, k - j)));
        i = k;
        continue;
      }
      ++i;  // a '#' without a directive name: POV-Ray ignores it
      continue;
    }
    tokens.push_back(make(Token::kPunct, std::string(1, c)));
    ++i;
  }
  tokens.push_back(make(Token::kEnd, ""));
  return tokens;
}

// ------------------------------------------------------------------------------------------
// Expressions

namespace {

const std::set<std::string>& camera_keywords() {
  static const std::set<std::string> words = {"location",
                                              "look_at",
                                              "angle",
                                              "right",
                                              "up",
                                              "direction",
                                              "sky",
                                              "translate",
                                              "rotate",
                                              "scale",
                                              "matrix",
                                              "transform",
                                              "aperture",
                                              "blur_samples",
                                              "focal_point",
                                              "confidence",
                                              "variance",
                                              "normal",
                                              "bokeh",
                                              "perspective",
                                              "orthographic",
                                              "fisheye",
                                              "ultra_wide_angle",
                                              "omnimax",
                                              "panoramic",
                                              "cylinder",
                                              "spherical",
                                              "mesh_camera",
                                              "user_defined"};
  return words;
}

std::string describe(const Token& token) {
  switch (token.kind) {
    case Token::kEnd:
      return "the end of the file";
    case Token::kString:
      return "the string \"" + token.text + "\"";
    case Token::kDirective:
      return "#" + token.text;
    default:
      return "'" + token.text + "'";
  }
}

class Parser {
 public:
  Parser(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context)
      : tokens_(tokens), pos_(pos), context_(context) {}

  // Sums and products: what a vector component or a camera modifier's value may be without
  // parentheses (a '>' there ends a vector).
  SdlValue expression() {
    SdlValue left = term();
    while (is_punct(peek(), "+") || is_punct(peek(), "-")) {
      const bool plus = next().text == "+";
      left = combine(left, term(), plus ? '+' : '-');
    }
    return left;
  }

  // Also comparisons, & | ! and ?: (conditions, declarations, parentheses).
  SdlValue full_expression() {
    const SdlValue condition = logical_or();
    if (!is_punct(peek(), "?")) return condition;
    next();
    const SdlValue a = full_expression();
    expect(":");
    const SdlValue b = full_expression();
    return truth(condition) ? a : b;
  }

 private:
  const Token& peek() const { return tokens_[std::min(pos_, tokens_.size() - 1)]; }
  const Token& next() {
    const Token& token = peek();
    if (pos_ < tokens_.size() - 1) ++pos_;
    return token;
  }
  [[noreturn]] void fail(const Token& token, const std::string& message) const {
    throw EvalError(where(token) + ": " + message);
  }
  void expect(const char* punct) {
    if (!is_punct(peek(), punct)) {
      fail(peek(), std::string("expected '") + punct + "', found " + describe(peek()));
    }
    next();
  }

  static SdlValue number(double value) {
    SdlValue out;
    out.v = {value, 0.0, 0.0};
    return out;
  }
  static SdlValue vector(V3 value) {
    SdlValue out;
    out.is_vector = true;
    out.v = value;
    return out;
  }

  SdlValue combine(const SdlValue& a, const SdlValue& b, char op) const {
    if (!a.is_vector && !b.is_vector) {
      const double x = a.number(), y = b.number();
      switch (op) {
        case '+':
          return number(x + y);
        case '-':
          return number(x - y);
        case '*':
          return number(x * y);
        default:
          return number(x / y);
      }
    }
    const V3 x = a.vector(), y = b.vector();
    switch (op) {
      case '+':
        return vector(x + y);
      case '-':
        return vector(x - y);
      case '*':
        return vector({x.x * y.x, x.y * y.y, x.z * y.z});
      default:
        return vector({x.x / y.x, x.y / y.y, x.z / y.z});
    }
  }

  static bool truth(const SdlValue& v) {
    const V3 x = v.vector();
    return v.is_vector ? (x.x != 0.0 || x.y != 0.0 || x.z != 0.0) : v.number() != 0.0;
  }

  SdlValue logical_or() {
    SdlValue left = logical_and();
    while (is_punct(peek(), "|")) {
      next();
      const bool right = truth(logical_and());
      left = number(truth(left) || right ? 1.0 : 0.0);
    }
    return left;
  }

  SdlValue logical_and() {
    SdlValue left = comparison();
    while (is_punct(peek(), "&")) {
      next();
      const bool right = truth(comparison());
      left = number(truth(left) && right ? 1.0 : 0.0);
    }
    return left;
  }

  // a < b, a <= b, a = b, a != b, a >= b, a > b (POV-Ray compares numbers with a small
  // tolerance; exact comparison is enough here).
  SdlValue comparison() {
    SdlValue left = expression();
    while (true) {
      std::string op;
      if (is_punct(peek(), "<") || is_punct(peek(), ">") || is_punct(peek(), "=")) {
        op = next().text;
        if (is_punct(peek(), "=") && op != "=") op += next().text;
      } else if (is_punct(peek(), "!") && is_punct(tokens_[pos_ + 1], "=")) {
        next();
        next();
        op = "!=";
      } else {
        return left;
      }
      const double a = left.number(), b = expression().number();
      bool result = false;
      if (op == "<") result = a < b;
      if (op == "<=") result = a <= b;
      if (op == ">") result = a > b;
      if (op == ">=") result = a >= b;
      if (op == "=") result = a == b;
      if (op == "!=") result = a != b;
      left = number(result ? 1.0 : 0.0);
    }
  }

  SdlValue term() {
    SdlValue left = unary();
    while (is_punct(peek(), "*") || is_punct(peek(), "/")) {
      const char op = next().text[0];
      left = combine(left, unary(), op);
    }
    return left;
  }

  // Every nesting (parentheses, vectors, function arguments, signs and !) goes through unary():
  // its depth is bounded so that a hostile or broken scene ("((((...", "----...") is an
  // error, not a stack overflow (found by tests/fuzz/fuzz_pov_scene). Real scenes nest a few
  // levels.
  static constexpr int kMaxNesting = 200;
  struct NestingGuard {
    explicit NestingGuard(int& depth) : depth_(depth) { ++depth_; }
    ~NestingGuard() { --depth_; }
    NestingGuard(const NestingGuard&) = delete;
    NestingGuard& operator=(const NestingGuard&) = delete;
    int& depth_;
  };

  SdlValue unary() {
    const NestingGuard guard(nesting_);
    if (nesting_ > kMaxNesting) {
      fail(peek(), "the expression nests deeper than " + std::to_string(kMaxNesting) + " levels");
    }
    if (is_punct(peek(), "-")) {
      next();
      return combine(number(0.0), unary(), '-');
    }
    if (is_punct(peek(), "+")) {
      next();
      return unary();
    }
    if (is_punct(peek(), "!")) {
      next();
      return number(truth(unary()) ? 0.0 : 1.0);
    }
    return postfix(primary());
  }

  // V.x, V.y, V.z (also .u, .v, .red, .green, .blue).
  SdlValue postfix(SdlValue value) {
    while (is_punct(peek(), ".") && tokens_[pos_ + 1].kind == Token::kIdent) {
      next();
      const Token& member = next();
      const V3 v = value.vector();
      const std::string& m = member.text;
      if (m == "x" || m == "u" || m == "red") {
        value = number(v.x);
      } else if (m == "y" || m == "v" || m == "green") {
        value = number(v.y);
      } else if (m == "z" || m == "blue") {
        value = number(v.z);
      } else {
        fail(member, "cannot read the component '." + m + "'");
      }
    }
    return value;
  }

  std::vector<SdlValue> arguments() {
    std::vector<SdlValue> args;
    expect("(");
    if (is_punct(peek(), ")")) {
      next();
      return args;
    }
    while (true) {
      args.push_back(full_expression());
      if (is_punct(peek(), ",")) {
        next();
        continue;
      }
      expect(")");
      return args;
    }
  }

  SdlValue primary() {
    const Token& token = peek();
    if (token.kind == Token::kNumber) {
      next();
      return number(token.number);
    }
    if (is_punct(token, "(")) {
      next();
      SdlValue value = full_expression();
      expect(")");
      return value;
    }
    if (is_punct(token, "<")) {
      next();
      std::vector<double> parts;
      while (true) {
        const SdlValue part = expression();
        if (part.is_vector) fail(token, "a vector inside a vector literal");
        parts.push_back(part.number());
        if (is_punct(peek(), ",")) {
          next();
          continue;
        }
        if (is_punct(peek(), ">")) {
          next();
          break;
        }
        // POV-Ray also reads <0 20 0>: the commas are optional.
        if (parts.size() < 5 && starts_expression(tokens_, pos_)) continue;
        expect(">");
      }
      if (parts.size() < 2 || parts.size() > 3) {
        fail(token, "a vector of " + std::to_string(parts.size()) +
                        " components where a 3-vector is expected");
      }
      return vector({parts[0], parts[1], parts.size() > 2 ? parts[2] : 0.0});
    }
    if (token.kind == Token::kIdent) return identifier();
    fail(token, "cannot read " + describe(token) + " in an expression");
  }

  SdlValue identifier() {
    const Token& token = next();
    const std::string& name = token.text;
    if (name == "x") return vector({1, 0, 0});
    if (name == "y") return vector({0, 1, 0});
    if (name == "z") return vector({0, 0, 1});
    if (name == "pi") return number(M_PI);
    if (name == "tau") return number(2.0 * M_PI);
    if (name == "true" || name == "yes" || name == "on") return number(1.0);
    if (name == "false" || name == "no" || name == "off") return number(0.0);
    if (name == "clock") return number(context_.clock);
    if (name == "image_width" || name == "image_height") {
      if (context_.image_width <= 0) fail(token, name + " is unknown here");
      return number(name == "image_width" ? context_.image_width : context_.image_height);
    }
    if (is_punct(peek(), "(")) return function(token);
    if (context_.symbols) {
      const auto found = context_.symbols->find(name);
      if (found != context_.symbols->end()) {
        const Symbol& symbol = found->second;
        if (symbol.kind == Symbol::kValue) return symbol.value;
        fail(token,
             "'" + name + "' (declared at " + symbol.declared_at + ") is " +
                 (symbol.kind == Symbol::kCamera ? std::string("a camera") : symbol.description) +
                 ", not a number or vector povray-ssao can evaluate");
      }
    }
    // The animation identifiers of a still (an animation frame's are predeclared symbols).
    if (name == "clock_on" || name == "frame_number" || name == "initial_frame" ||
        name == "final_frame" || name == "initial_clock" || name == "final_clock" ||
        name == "clock_delta") {
      return number(0.0);
    }
    if (camera_keywords().count(name)) fail(token, "expected a value, found '" + name + "'");
    fail(token, "'" + name +
                    "' is not declared before this point (povray-ssao reads #declare and #local "
                    "of numbers and vectors in the scene file and the include files it finds)");
  }

  SdlValue function(const Token& token) {
    const std::string& name = token.text;
    const std::vector<SdlValue> args = arguments();
    auto need = [&](size_t count) {
      if (args.size() != count) {
        fail(token, name + "() takes " + std::to_string(count) + " argument(s), got " +
                        std::to_string(args.size()));
      }
    };
    auto f = [&](size_t i) { return args[i].number(); };
    using Fn = double (*)(double);
    static const std::map<std::string, Fn> unary_fns = {
        {"abs", [](double v) { return std::fabs(v); }},
        {"sqrt", [](double v) { return std::sqrt(v); }},
        {"sin", [](double v) { return std::sin(v); }},
        {"cos", [](double v) { return std::cos(v); }},
        {"tan", [](double v) { return std::tan(v); }},
        {"asin", [](double v) { return std::asin(v); }},
        {"acos", [](double v) { return std::acos(v); }},
        {"atan", [](double v) { return std::atan(v); }},
        {"exp", [](double v) { return std::exp(v); }},
        {"ln", [](double v) { return std::log(v); }},
        {"log", [](double v) { return std::log10(v); }},
        {"floor", [](double v) { return std::floor(v); }},
        {"ceil", [](double v) { return std::ceil(v); }},
        {"int", [](double v) { return std::trunc(v); }},
        {"radians", [](double v) { return v * M_PI / 180.0; }},
        {"degrees", [](double v) { return v * 180.0 / M_PI; }},
    };
    const auto unary_fn = unary_fns.find(name);
    if (unary_fn != unary_fns.end()) {
      need(1);
      return number(unary_fn->second(f(0)));
    }
    if (name == "pow") {
      need(2);
      return number(std::pow(f(0), f(1)));
    }
    if (name == "atan2") {
      need(2);
      return number(std::atan2(f(0), f(1)));
    }
    if (name == "mod") {
      need(2);
      return number(std::fmod(f(0), f(1)));
    }
    if (name == "min" || name == "max") {
      if (args.empty()) fail(token, name + "() needs arguments");
      double value = f(0);
      for (size_t i = 1; i < args.size(); ++i) {
        value = name == "min" ? std::min(value, f(i)) : std::max(value, f(i));
      }
      return number(value);
    }
    if (name == "vlength") {
      need(1);
      return number(length(args[0].vector()));
    }
    if (name == "vnormalize") {
      need(1);
      return vector(normalized(args[0].vector()));
    }
    if (name == "vcross") {
      need(2);
      return vector(cross(args[0].vector(), args[1].vector()));
    }
    if (name == "vdot") {
      need(2);
      return number(dot(args[0].vector(), args[1].vector()));
    }
    if (name == "vrotate") {
      need(2);
      return vector(rotate_xyz(args[0].vector(), args[1].vector()));
    }
    fail(token, "cannot evaluate '" + name + "(...)' (a macro or a function povray-ssao does not " +
                    "know)");
  }

  const std::vector<Token>& tokens_;
  size_t& pos_;
  const EvalContext& context_;
  int nesting_ = 0;
};

}  // namespace

SdlValue evaluate(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context) {
  Parser parser(tokens, pos, context);
  return parser.expression();
}

SdlValue evaluate_full(const std::vector<Token>& tokens, size_t& pos, const EvalContext& context) {
  Parser parser(tokens, pos, context);
  return parser.full_expression();
}

bool starts_colour_keyword(const Token& token) {
  static const std::set<std::string> keywords = {"color", "colour", "rgb",   "rgbf",   "rgbt",
                                                 "rgbft", "srgb",   "srgbf", "srgbt",  "srgbft",
                                                 "red",   "green",  "blue",  "filter", "transmit"};
  return token.kind == Token::kIdent && keywords.count(token.text) > 0;
}

SdlValue evaluate_colour(const std::vector<Token>& tokens, size_t& pos,
                         const EvalContext& context) {
  auto is_ident = [&](const char* text) {
    return tokens[pos].kind == Token::kIdent && tokens[pos].text == text;
  };
  if (is_ident("color") || is_ident("colour")) ++pos;
  const Token& first = tokens[pos];
  if (first.kind == Token::kIdent &&
      (first.text == "rgbf" || first.text == "rgbt" || first.text == "rgbft" ||
       first.text == "srgbf" || first.text == "srgbt" || first.text == "srgbft" ||
       first.text == "filter" || first.text == "transmit")) {
    throw EvalError(where(first) + ": '" + first.text + "' colours are not read by povray-ssao");
  }
  if (is_ident("rgb") || is_ident("srgb")) {
    const bool srgb = is_ident("srgb");
    ++pos;
    SdlValue value;
    value.is_vector = true;
    value.v = evaluate(tokens, pos, context).vector();
    if (srgb) {
      for (double* c : {&value.v.x, &value.v.y, &value.v.z}) {
        *c = *c <= 0.04045 ? *c / 12.92 : std::pow((*c + 0.055) / 1.055, 2.4);
      }
    }
    return value;
  }
  if (is_ident("red") || is_ident("green") || is_ident("blue")) {
    SdlValue value;
    value.is_vector = true;
    while (is_ident("red") || is_ident("green") || is_ident("blue")) {
      const std::string component = tokens[pos++].text;
      const double number = evaluate(tokens, pos, context).number();
      (component == "red" ? value.v.x : component == "green" ? value.v.y : value.v.z) = number;
    }
    return value;
  }
  return evaluate(tokens, pos, context);
}

bool starts_expression(const std::vector<Token>& tokens, size_t pos) {
  const Token& token = tokens[pos];
  if (token.kind == Token::kNumber) return true;
  if (token.kind == Token::kPunct) {
    return token.text == "<" || token.text == "(" || token.text == "-" || token.text == "+";
  }
  return token.kind == Token::kIdent && !camera_keywords().count(token.text);
}

// ------------------------------------------------------------------------------------------
// Conditional directives

namespace {

// The index after the parenthesised argument of a directive at tokens[i] (if any).
size_t after_argument(const std::vector<Token>& tokens, size_t i) {
  return is_punct(tokens[i + 1], "(") ? skip_group(tokens, i + 1) : i + 1;
}

// A directive whose block an #end closes.
bool opens_block(const std::string& directive) {
  return directive == "if" || directive == "ifdef" || directive == "ifndef" ||
         directive == "switch" || directive == "while" || directive == "for" ||
         directive == "macro";
}

}  // namespace

bool Conditionals::active() const {
  for (const Frame& frame : frames_) {
    if (frame.known && !frame.active) return false;
  }
  return true;
}

int Conditionals::unknown_depth() const {
  int depth = 0;
  for (const Frame& frame : frames_) depth += frame.known ? 0 : 1;
  return depth;
}

std::optional<bool> Conditionals::condition(const std::vector<Token>& tokens, size_t i,
                                            const EvalContext& context) {
  if (!is_punct(tokens[i + 1], "(")) return std::nullopt;
  size_t pos = i + 1;
  try {
    const SdlValue value = evaluate_full(tokens, pos, context);
    if (pos != skip_group(tokens, i + 1)) return std::nullopt;
    const V3 v = value.vector();
    return value.is_vector ? (v.x != 0.0 || v.y != 0.0 || v.z != 0.0) : value.number() != 0.0;
  } catch (const EvalError&) {
    return std::nullopt;
  }
}

std::optional<double> Conditionals::value(const std::vector<Token>& tokens, size_t i,
                                          const EvalContext& context, int index) {
  // #case (V) or #range (A, B): the index-th value.
  if (!is_punct(tokens[i + 1], "(")) return std::nullopt;
  size_t pos = i + 2;
  try {
    for (int k = 0; k <= index; ++k) {
      const double v = evaluate_full(tokens, pos, context).number();
      if (k == index) return v;
      if (!is_punct(tokens[pos], ",")) return std::nullopt;
      ++pos;
    }
  } catch (const EvalError&) {
  }
  return std::nullopt;
}

size_t Conditionals::handle(const std::vector<Token>& tokens, size_t i,
                            const EvalContext& context) {
  const Token& token = tokens[i];
  if (token.kind != Token::kDirective) return i;
  const std::string& name = token.text;
  const bool was_active = active();
  if (opens_block(name)) {
    Frame frame;
    if (!was_active || name == "macro") {
      // Nothing in here runs: a skipped branch, or a macro's body (run only when called).
      frame.known = true;
      frame.active = false;
    } else if (name == "if") {
      const std::optional<bool> c = condition(tokens, i, context);
      frame.known = c.has_value();
      frame.active = c.value_or(true);
      frame.taken = frame.active;
    } else if (name == "ifdef" || name == "ifndef") {
      if (is_punct(tokens[i + 1], "(") && tokens[i + 2].kind == Token::kIdent &&
          is_punct(tokens[i + 3], ")")) {
        const bool defined = context.symbols && context.symbols->count(tokens[i + 2].text) > 0;
        frame.active = name == "ifdef" ? defined : !defined;
        frame.taken = frame.active;
      } else {
        frame.known = false;
      }
    } else if (name == "switch") {
      frame.is_switch = true;
      size_t pos = i + 1;
      try {
        frame.switch_value = evaluate_full(tokens, pos, context).number();
        frame.active = false;  // until a #case matches
      } catch (const EvalError&) {
        frame.known = false;
      }
    } else {
      frame.known = false;  // loops: their body is read once
    }
    frames_.push_back(frame);
    return name == "macro" ? i + 1 : after_argument(tokens, i);
  }
  if (name == "end") {
    if (!frames_.empty()) frames_.pop_back();
    return i + 1;
  }
  const bool branch =
      name == "else" || name == "elseif" || name == "case" || name == "range" || name == "break";
  if (!branch) return i;
  if (frames_.empty()) return after_argument(tokens, i);
  // Only the innermost frame changes, and only if everything around it is active.
  Frame frame = frames_.back();
  frames_.pop_back();
  const bool outer_active = active();
  if (outer_active && frame.known) {
    if (name == "elseif") {
      if (frame.taken) {
        frame.active = false;
      } else {
        const std::optional<bool> c = condition(tokens, i, context);
        if (!c) {
          frame.known = false;
          frame.active = true;
        } else {
          frame.active = *c;
          frame.taken = *c;
        }
      }
    } else if (name == "else") {
      frame.active = !frame.taken && !frame.switch_done;
      frame.taken = true;
    } else if (frame.is_switch && (name == "case" || name == "range")) {
      if (frame.switch_done) {
        frame.active = false;
      } else if (!frame.active) {
        const std::optional<double> a = value(tokens, i, context, 0);
        const std::optional<double> b = name == "range" ? value(tokens, i, context, 1) : a;
        if (!a || !b) {
          frame.known = false;
          frame.active = true;
        } else {
          frame.active = name == "case" ? frame.switch_value == *a
                                        : (*a <= frame.switch_value && frame.switch_value <= *b);
          frame.taken = frame.taken || frame.active;
        }
      }
    } else if (name == "break" && frame.is_switch && frame.active) {
      frame.active = false;
      frame.switch_done = true;
    }
  } else if (outer_active && !frame.known) {
    frame.active = true;
  }
  frames_.push_back(frame);
  return name == "else" || name == "break" ? i + 1 : after_argument(tokens, i);
}

// ------------------------------------------------------------------------------------------
// Scene scan

namespace {

class Scanner {
 public:
  explicit Scanner(const ScanSettings& settings) : settings_(settings) {
    symbols_ = settings.predeclared;
    context_.symbols = &symbols_;
    context_.image_width = settings.image_width;
    context_.image_height = settings.image_height;
    context_.clock = settings.clock;
  }

  void scan_file(const std::string& path, const std::string& display, int depth) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw ssao_tools::Error("cannot read the scene file '" + path + "'");
    std::ostringstream text;
    text << file.rdbuf();
    const std::vector<Token> tokens = tokenize(text.str(), display);
    scan_tokens(tokens, depth);
  }

  SceneScan result;

 private:
  void scan_tokens(const std::vector<Token>& tokens, int depth) {
    find_macros(tokens);
    size_t i = 0;
    while (tokens[i].kind != Token::kEnd) {
      const Token& token = tokens[i];
      if (token.kind == Token::kDirective) {
        const size_t next = conditionals_.handle(tokens, i, context_);
        if (next != i) {
          i = next;
          continue;
        }
        i = conditionals_.active() ? directive(tokens, i, depth) : i + 1;
        continue;
      }
      if (!conditionals_.active()) {
        ++i;
        continue;
      }
      note_file_writes(tokens, i, i + 1);
      if (token.kind == Token::kIdent) {
        const size_t next = global_setting(tokens, i);
        if (next != i) {
          i = next;
          continue;
        }
      }
      const bool block =
          token.kind == Token::kIdent && token.text == "camera" && is_punct(tokens[i + 1], "{");
      const bool macro =
          token.kind == Token::kIdent && token.text == "SSAOCamera" && is_punct(tokens[i + 1], "(");
      if (block || macro) {
        const size_t end = skip_group(tokens, i + 1);
        CameraSource camera;
        camera.kind = block ? CameraSource::kBlock : CameraSource::kSSAOCameraMacro;
        // A block without its braces; the macro's arguments with their parentheses.
        // An unclosed group ends at the end of the tokens, without a closing brace to drop:
        // never a range that ends before it starts (found by fuzz_pov_scene: "camera {").
        const size_t first = i + (block ? 2 : 1);
        const size_t last = std::max(first, end - (block ? 1 : 0));
        camera.tokens.assign(tokens.begin() + static_cast<long>(first),
                             tokens.begin() + static_cast<long>(last));
        camera.location = where(token);
        camera.conditional = conditionals_.unknown_depth() > 0;
        camera.symbols = symbols_;
        result.cameras.push_back(std::move(camera));
        i = end;
        continue;
      }
      if (const std::string made_at = call_holds(tokens, i, &Macro::camera_at); !made_at.empty()) {
        // A call of a macro that makes a camera: not expanded, but never passed over (the
        // camera POV-Ray uses would silently be another).
        CameraSource camera;
        camera.kind = CameraSource::kMacroCall;
        camera.macro = token.text;
        camera.macro_camera_at = made_at;
        camera.location = where(token);
        camera.conditional = conditionals_.unknown_depth() > 0;
        result.cameras.push_back(std::move(camera));
        i = skip_group(tokens, i + 1);
        continue;
      }
      ++i;
    }
  }

  // What the scan knows of a macro's body (which it does not run).
  struct Macro {
    std::string camera_at;           // where a camera { } block in it is, or ""
    std::string fopen_at;            // where an #fopen ... write/append in it is, or ""
    std::vector<std::string> calls;  // the NAME( it holds: the macros it may call
  };

  // Records the macros `tokens` declares. A later declaration replaces an earlier one, as in
  // POV-Ray. (SSAOCamera, ssao_passes.inc's, is read from its arguments instead.)
  void find_macros(const std::vector<Token>& tokens) {
    for (size_t i = 0; tokens[i].kind != Token::kEnd; ++i) {
      if (tokens[i].kind != Token::kDirective || tokens[i].text != "macro" ||
          tokens[i + 1].kind != Token::kIdent || !is_punct(tokens[i + 2], "(")) {
        continue;
      }
      Macro macro;
      int open = 1;
      for (size_t k = skip_group(tokens, i + 2); tokens[k].kind != Token::kEnd; ++k) {
        const Token& t = tokens[k];
        if (t.kind == Token::kDirective && opens_block(t.text)) ++open;
        if (t.kind == Token::kDirective && t.text == "end" && --open == 0) break;
        if (t.kind == Token::kIdent && t.text == "camera" && is_punct(tokens[k + 1], "{")) {
          if (macro.camera_at.empty()) macro.camera_at = where(t);
        } else if (t.kind == Token::kIdent && is_punct(tokens[k + 1], "(")) {
          macro.calls.push_back(t.text);
        } else if (opens_file_for_writing(tokens, k) && macro.fopen_at.empty()) {
          macro.fopen_at = where(t);
        }
      }
      if (tokens[i + 1].text != "SSAOCamera") macros_[tokens[i + 1].text] = std::move(macro);
      holds_.clear();
    }
  }

  // Where the macro `name` makes a camera (found = &Macro::camera_at) or writes a file
  // (&Macro::fopen_at), itself or through the macros it calls (screen.inc's Set_Camera calls
  // Update_Camera); "" if it does not, or is not a macro the scan has read.
  std::string macro_holds(const std::string& name, std::string Macro::*found) {
    // Remembered until a macro is declared: a scene calls the same macros many times.
    const std::string key = name + (found == &Macro::camera_at ? " camera" : " fopen");
    if (const auto known = holds_.find(key); known != holds_.end()) return known->second;
    return holds_[key] = search_calls(name, found);
  }

  // macro_holds()'s search through the calls, each macro once (macros may recurse).
  std::string search_calls(const std::string& name, std::string Macro::*found) const {
    std::set<std::string> seen;
    std::vector<std::string> pending = {name};
    while (!pending.empty()) {
      const std::string next = std::move(pending.back());
      pending.pop_back();
      const auto macro = macros_.find(next);
      if (macro == macros_.end() || !seen.insert(next).second) continue;
      if (!(macro->second.*found).empty()) return macro->second.*found;
      pending.insert(pending.end(), macro->second.calls.begin(), macro->second.calls.end());
    }
    return "";
  }

  // macro_holds() for a call NAME( at tokens[k]; "" for any other token.
  std::string call_holds(const std::vector<Token>& tokens, size_t k, std::string Macro::*found) {
    if (tokens[k].kind != Token::kIdent || !is_punct(tokens[k + 1], "(")) return "";
    return macro_holds(tokens[k].text, found);
  }

  // #fopen NAME "file" write|append at tokens[k] (the file name may be an expression).
  static bool opens_file_for_writing(const std::vector<Token>& tokens, size_t k) {
    if (tokens[k].kind != Token::kDirective || tokens[k].text != "fopen") return false;
    for (size_t j = k + 1; tokens[j].kind != Token::kEnd && tokens[j].kind != Token::kDirective;
         ++j) {
      if (tokens[j].kind != Token::kIdent) continue;
      if (tokens[j].text == "write" || tokens[j].text == "append") return true;
      if (tokens[j].text == "read") return false;
    }
    return false;
  }

  // Notes the first place where parsing the scene writes a file: an #fopen for writing, or a
  // call of a macro that makes one, among tokens[begin, end).
  void note_file_writes(const std::vector<Token>& tokens, size_t begin, size_t end) {
    for (size_t k = begin; k < end && result.file_write.empty(); ++k) {
      if (opens_file_for_writing(tokens, k)) {
        result.file_write = where(tokens[k]) + ": #fopen for writing";
      } else if (const std::string at = call_holds(tokens, k, &Macro::fopen_at); !at.empty()) {
        result.file_write = where(tokens[k]) + " calls " + tokens[k].text +
                            "(), which opens a file for writing at " + at;
      }
    }
  }

  // The global_settings items povray-ssao's passes depend on, and quick colours. Returns the
  // index after what it read, or i for any other token.
  size_t global_setting(const std::vector<Token>& tokens, size_t i) {
    const std::string& name = tokens[i].text;
    if (name == "quick_color" || name == "quick_colour") {
      result.uses_quick_color = true;
      return i;
    }
    if (name == "global_settings" && is_punct(tokens[i + 1], "{")) {
      settings_end_ = skip_group(tokens, i + 1);
      return i + 2;
    }
    if (i >= settings_end_) return i;
    if (name == "radiosity" && is_punct(tokens[i + 1], "{")) {
      result.uses_radiosity = true;
      return skip_group(tokens, i + 1);
    }
    if (name == "assumed_gamma") {
      size_t pos = i + 1;
      try {
        const double gamma = evaluate(tokens, pos, context_).number();
        if (!result.assumed_gamma) result.assumed_gamma = gamma;
      } catch (const EvalError& e) {
        if (!result.assumed_gamma) {
          result.notes.push_back(std::string("cannot read the scene's assumed_gamma (") + e.what() +
                                 ")");
        }
        return i + 1;
      }
      return pos;
    }
    if (name == "ambient_light") {
      size_t pos = i + 1;
      try {
        result.ambient_light = evaluate_colour(tokens, pos, context_).vector();
        result.ambient_light_problem.clear();
      } catch (const EvalError& e) {
        result.ambient_light.reset();
        result.ambient_light_problem = where(tokens[i]) + ": " + e.what();
        return i + 1;
      }
      return pos;
    }
    return i;
  }

  // Handles the (non-conditional) directive at tokens[i] in an active region; returns the
  // index of the next token to look at.
  size_t directive(const std::vector<Token>& tokens, size_t i, int depth) {
    const std::string& name = tokens[i].text;
    if (name == "declare" || name == "local") {
      const size_t next = declaration(tokens, i + 1);
      note_file_writes(tokens, i, next);  // #declare M = MakeMesh(...)
      return next;
    }
    if (name == "fopen") note_file_writes(tokens, i, i + 1);
    if (name == "undef" && tokens[i + 1].kind == Token::kIdent) {
      symbols_.erase(tokens[i + 1].text);
      return i + 2;
    }
    if (name == "version") {
      size_t pos = i + 1;
      try {
        const double version = evaluate_full(tokens, pos, context_).number();
        if (depth == 0) result.version = version;
      } catch (const EvalError&) {
        // "#version Saved_Version;" (include files restoring the caller's): not needed.
      }
      return pos;
    }
    if (name == "include" && tokens[i + 1].kind == Token::kString) {
      include(tokens[i + 1], depth);
      return i + 2;
    }
    return i + 1;
  }

  void include(const Token& token, int depth) {
    const std::string& name = token.text;
    if (fs::path(name).filename() == "ssao_passes.inc") result.includes_ssao_passes = true;
    if (depth >= 16) return;
    std::vector<fs::path> folders;
    if (fs::path(name).is_absolute()) {
      folders.emplace_back();
    } else {
      folders.emplace_back(settings_.directory);
      for (const std::string& folder : settings_.library_paths) folders.emplace_back(folder);
    }
    fs::path path;
    std::error_code ec;
    for (const fs::path& folder : folders) {
      for (const char* extension : {"", ".inc"}) {
        fs::path candidate = folder.empty() ? fs::path(name) : folder / name;
        candidate += extension;
        if (fs::is_regular_file(candidate, ec)) {
          path = candidate;
          break;
        }
      }
      if (!path.empty()) break;
    }
    if (path.empty()) {  // POV-Ray will say so if it cannot find it either
      result.missing_includes.push_back(name);
      return;
    }
    // Include files read in all: a file that includes itself twice (or two that include each
    // other) would otherwise be read 2^16 times down to the depth limit, a scan of minutes
    // where POV-Ray stops at once (found by tests/fuzz/fuzz_pov_scene). Real scenes read tens.
    if (++includes_read_ > kMaxIncludesRead) {
      if (includes_read_ == kMaxIncludesRead + 1) {
        result.notes.push_back("more than " + std::to_string(kMaxIncludesRead) +
                               " include files read (files that include each other?); the "
                               "others, from '" +
                               name + "' on, are not read");
      }
      return;
    }
    // An include starts and ends outside any conditional of its own.
    Conditionals saved = conditionals_;
    const size_t saved_settings_end = settings_end_;
    settings_end_ = 0;
    try {
      scan_file(path.string(), name, depth + 1);
    } catch (const ssao_tools::Error& e) {
      result.notes.push_back(std::string("could not read the include file '") + name + "' (" +
                             e.what() + ")");
    }
    conditionals_ = saved;
    settings_end_ = saved_settings_end;
  }

  // After "#declare" / "#local": NAME = VALUE [;]
  size_t declaration(const std::vector<Token>& tokens, size_t i) {
    if (tokens[i].kind == Token::kIdent && tokens[i].text == "deprecated") ++i;
    if (tokens[i].kind != Token::kIdent) return i;
    const Token& name = tokens[i++];
    if (is_punct(tokens[i], "[")) {
      // An array element: not a camera constant; skip to the end of the statement.
      while (tokens[i].kind != Token::kEnd && !is_punct(tokens[i], ";") &&
             tokens[i].kind != Token::kDirective) {
        ++i;
      }
      return i;
    }
    if (!is_punct(tokens[i], "=")) return i;
    ++i;
    Symbol symbol;
    symbol.declared_at = where(name);
    const Token& first = tokens[i];
    // A braced item: camera { }, transform { }, sphere { }, texture { }, function { }, ...
    if (first.kind == Token::kIdent &&
        (is_punct(tokens[i + 1], "{") ||
         (first.text == "array" &&
          (is_punct(tokens[i + 1], "[") || is_punct(tokens[i + 1], "{"))) ||
         (first.text == "function" && is_punct(tokens[i + 1], "(")))) {
      size_t j = i + 1;
      // "#declare A = array[3]" may end without ';': a directive ends it too (found on
      // povray-examples' incdemo/glasses/glass.pov, whose next #declare was swallowed).
      while (!is_punct(tokens[j], "{") && !is_punct(tokens[j], ";") &&
             tokens[j].kind != Token::kEnd && tokens[j].kind != Token::kDirective) {
        j = is_punct(tokens[j], "[") || is_punct(tokens[j], "(") ? skip_group(tokens, j) : j + 1;
      }
      size_t end = is_punct(tokens[j], "{") ? skip_group(tokens, j) : j;
      if (first.text == "camera" || first.text == "transform") {
        symbol.kind = first.text == "camera" ? Symbol::kCamera : Symbol::kTransform;
        // Never a range that ends before it starts: an unclosed "{" last in the file has no
        // closing brace to drop (found by fuzz_pov_scene: "#declare C = camera {").
        const size_t last = std::max(j + 1, end - 1);
        symbol.tokens.assign(tokens.begin() + static_cast<long>(j) + 1,
                             tokens.begin() + static_cast<long>(last));
      } else {
        symbol.kind = Symbol::kOther;
        symbol.description = "a " + first.text;
      }
      symbols_[name.text] = symbol;
      if (is_punct(tokens[end], ";")) ++end;
      return end;
    }
    // Another camera's or transform's name: #declare C2 = C1;
    if (first.kind == Token::kIdent && is_punct(tokens[i + 1], ";")) {
      const auto found = symbols_.find(first.text);
      if (found != symbols_.end() &&
          (found->second.kind == Symbol::kCamera || found->second.kind == Symbol::kTransform)) {
        symbol = found->second;
        symbol.declared_at = where(name);
        symbols_[name.text] = symbol;
        return i + 2;
      }
    }
    // A number, a vector or a colour, ended by ';'.
    size_t pos = i;
    try {
      symbol.value = starts_colour_keyword(first) ? evaluate_colour(tokens, pos, context_)
                                                  : evaluate_full(tokens, pos, context_);
      if (is_punct(tokens[pos], ";") || tokens[pos].kind == Token::kDirective ||
          tokens[pos].kind == Token::kEnd) {
        symbol.kind = Symbol::kValue;
        symbols_[name.text] = symbol;
        return is_punct(tokens[pos], ";") ? pos + 1 : pos;
      }
      symbol.description =
          "an expression povray-ssao cannot evaluate (it stops at " + describe(tokens[pos]) + ")";
    } catch (const EvalError& e) {
      symbol.description =
          std::string("an expression povray-ssao cannot evaluate (") + e.what() + ")";
      if (first.kind == Token::kString) symbol.description = "a string";
    }
    symbol.kind = Symbol::kOther;
    symbols_[name.text] = symbol;
    // Skip the rest of the statement: up to ';', a directive or the start of the next
    // statement (an identifier opening a block, e.g. camera {), since POV-Ray lets some
    // declarations (strings, for one) end without ';'.
    size_t j = i;
    while (tokens[j].kind != Token::kEnd && !is_punct(tokens[j], ";") &&
           tokens[j].kind != Token::kDirective && !is_punct(tokens[j], "}") &&
           !(j > i && tokens[j].kind == Token::kIdent && is_punct(tokens[j + 1], "{"))) {
      j = (is_punct(tokens[j], "(") || is_punct(tokens[j], "[") || is_punct(tokens[j], "{"))
              ? skip_group(tokens, j)
              : j + 1;
    }
    return is_punct(tokens[j], ";") ? j + 1 : j;
  }

  static constexpr int kMaxIncludesRead = 256;
  const ScanSettings& settings_;
  int includes_read_ = 0;
  size_t settings_end_ = 0;  // index after the global_settings block being read (this file)
  Symbols symbols_;
  std::map<std::string, Macro> macros_;       // the macros read so far, by name
  std::map<std::string, std::string> holds_;  // macro_holds(), by "NAME camera|fopen"
  EvalContext context_;
  Conditionals conditionals_;
};

}  // namespace

SceneScan scan_scene(const std::string& path, const ScanSettings& settings) {
  Scanner scanner(settings);
  scanner.result.clock = settings.clock;
  scanner.scan_file(path, fs::path(path).filename().string(), 0);
  return scanner.result;
}

bool is_punct(const Token& token, const char* text) {
  return token.kind == Token::kPunct && token.text == text;
}

size_t skip_group(const std::vector<Token>& tokens, size_t open) {
  const std::string opening = tokens[open].text;
  const std::string closing = opening == "{" ? "}" : opening == "(" ? ")" : "]";
  int depth = 0;
  for (size_t i = open; i < tokens.size(); ++i) {
    if (tokens[i].kind != Token::kPunct) continue;
    if (tokens[i].text == opening) ++depth;
    if (tokens[i].text == closing && --depth == 0) return i + 1;
  }
  return tokens.size() - 1;
}

}  // namespace povray_ssao
