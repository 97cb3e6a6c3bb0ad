// SPDX-License-Identifier: MIT
// povray-ssao's scene reader (povray_bridge/scene/), table by table: tokens, expressions,
// conditionals, camera forms and the cameras it refuses. Expected values come from POV-Ray
// 3.7's documented rules (the SDL reference, Parse_Camera), computed here by hand, never read
// back from the reader. The whole reader on POV-Ray's own example scenes:
// tests/povray/scene_corpus.py.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pov_camera.h"
#include "sdl.h"

namespace povray_ssao {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The tokens of `text` as "kind:text" (numbers as their value), without the final kEnd.
std::vector<std::string> token_list(const std::string& text) {
  std::vector<std::string> out;
  for (const Token& t : tokenize(text, "test.pov")) {
    if (t.kind == Token::kEnd) break;
    static const char* const kinds[] = {"num", "id", "str", "dir", "punct", "end"};
    char number[32];
    std::snprintf(number, sizeof number, "%g", t.number);
    out.push_back(std::string(kinds[t.kind]) + ":" + (t.kind == Token::kNumber ? number : t.text));
  }
  return out;
}

TEST(SceneTokens, Table) {
  struct Case {
    const char* text;
    std::vector<std::string> tokens;
  };
  const std::vector<Case> cases = {
      {"1 2.5 .5 1e3 2.5E-1", {"num:1", "num:2.5", "num:0.5", "num:1000", "num:0.25"}},
      {"location<0,1,-3>",
       {"id:location", "punct:<", "num:0", "punct:,", "num:1", "punct:,", "punct:-", "num:3",
        "punct:>"}},
      {"#declare Cam_1 = 3;", {"dir:declare", "id:Cam_1", "punct:=", "num:3", "punct:;"}},
      {"# include \"colors.inc\"", {"dir:include", "str:colors.inc"}},
      {"a // comment <1>\nb", {"id:a", "id:b"}},
      {"a /* outer /* nested */ still */ b", {"id:a", "id:b"}},
      // Comparisons are single characters here; the evaluator reads "<=" as '<' then '=':
      {"x<=y != z", {"id:x", "punct:<", "punct:=", "id:y", "punct:!", "punct:=", "id:z"}},
      {"{ ( [ ] ) }", {"punct:{", "punct:(", "punct:[", "punct:]", "punct:)", "punct:}"}},
  };
  for (const Case& c : cases) EXPECT_EQ(token_list(c.text), c.tokens) << c.text;
  for (const char* bad : {"\"open string", "/* open comment", "a /* /* */ b"}) {
    EXPECT_THROW(tokenize(bad, "test.pov"), ssao_tools::Error) << bad;
  }
  const std::vector<Token> lines = tokenize("a\n\nb", "scene.pov");
  EXPECT_EQ(where(lines[1]), "scene.pov:3");
}

// `text` evaluated as a full expression (comparisons, logic, ?:) with `symbols`.
SdlValue value_of(const std::string& text, const Symbols& symbols = {}) {
  const std::vector<Token> tokens = tokenize(text, "test.pov");
  EvalContext context;
  context.symbols = &symbols;
  context.image_width = 640;
  context.image_height = 480;
  context.clock = 0.25;
  size_t pos = 0;
  const SdlValue value = evaluate_full(tokens, pos, context);
  EXPECT_EQ(tokens[pos].kind, Token::kEnd) << text << ": not all read";
  return value;
}

TEST(SceneExpressions, NumbersTable) {
  struct Case {
    const char* text;
    double value;
  };
  const std::vector<Case> cases = {
      {"1 + 2 * 3", 7},
      {"(1 + 2) * 3", 9},
      {"-2 - -3", 1},
      {"10 / 4", 2.5},
      {"pi", kPi},
      {"tau / 2", kPi},
      {"sqrt(16) + abs(-2)", 6},
      {"pow(2, 10)", 1024},
      {"mod(7, 3)", 1},
      {"int(-2.5)", -2},
      {"floor(-2.5)", -3},
      {"max(1, 5, 3) - min(4, 2)", 3},
      {"degrees(pi / 2)", 90},
      {"radians(180)", kPi},
      {"tan(radians(45))", 1},
      {"atan(1) * 4", kPi},
      {"vlength(<3, 4, 0>)", 5},
      {"vdot(<1, 2, 3>, <4, 5, 6>)", 32},
      {"image_width / image_height", 640.0 / 480.0},
      {"clock * 4", 1},
      {"1 < 2", 1},
      {"2 <= 1", 0},
      {"3 = 3", 1},
      {"3 != 3", 0},
      {"1 & 0 | 1", 1},
      {"!0", 1},
      {"0 ? 5 : 7", 7},
      {"true + yes + on", 3},
      {"false + no + off", 0},
  };
  for (const Case& c : cases) {
    const SdlValue v = value_of(c.text);
    EXPECT_FALSE(v.is_vector) << c.text;
    EXPECT_NEAR(v.number(), c.value, 1e-12) << c.text;
  }
}

TEST(SceneExpressions, VectorsTable) {
  struct Case {
    const char* text;
    V3 value;
  };
  const double s = std::sqrt(0.5);
  const std::vector<Case> cases = {
      {"<1, 2, 3> * 2", {2, 4, 6}},
      {"-<1, 0, 0>", {-1, 0, 0}},
      {"x + 2 * y - z", {1, 2, -1}},
      {"<1, 2, 3> + 1", {2, 3, 4}},  // a number used as a vector: <n, n, n>
      {"vcross(x, y)", {0, 0, 1}},
      {"vnormalize(<1, 1, 0>)", {s, s, 0}},
      {"vrotate(x, <0, 0, 90>)", {0, 1, 0}},
      {"vrotate(z, <0, 90, 0>)", {1, 0, 0}},  // left-handed: +y rotates +z towards +x
      {"Base + <0, Height, 0>", {1, 5, 1}},
      {"<image_width, image_height, 0> / 160", {4, 3, 0}},
  };
  Symbols symbols;
  symbols["Base"].kind = Symbol::kValue;
  symbols["Base"].value = {true, {1, 1, 1}};
  symbols["Height"].kind = Symbol::kValue;
  symbols["Height"].value = {false, {4, 4, 4}};
  for (const Case& c : cases) {
    const SdlValue v = value_of(c.text, symbols);
    EXPECT_TRUE(v.is_vector) << c.text;
    EXPECT_NEAR(v.v.x, c.value.x, 1e-12) << c.text;
    EXPECT_NEAR(v.v.y, c.value.y, 1e-12) << c.text;
    EXPECT_NEAR(v.v.z, c.value.z, 1e-12) << c.text;
  }
}

TEST(SceneExpressions, WhatCannotBeEvaluatedIsNamed) {
  struct Case {
    const char* text;
    const char* named;
  };
  const std::vector<Case> cases = {
      {"Undeclared + 1", "Undeclared"},
      {"seed(3)", "seed"},
      {"1 + ", "test.pov:1"},
  };
  for (const Case& c : cases) {
    try {
      value_of(c.text);
      ADD_FAILURE() << c.text << " evaluated";
    } catch (const EvalError& e) {
      EXPECT_NE(std::string(e.what()).find(c.named), std::string::npos)
          << c.text << ": " << e.what();
    }
  }
}

// A scene file in a folder of its own, scanned and its camera read at 640x480.
class SceneFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ = std::filesystem::temp_directory_path() /
              ("ssao-scene-reader-" + std::to_string(::getpid()) + "-" + info->name());
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(folder_ / name) << text;
  }
  SceneScan scan(const std::string& text) {
    write("scene.pov", text);
    ScanSettings settings;
    settings.directory = folder_.string();
    settings.image_width = 640;
    settings.image_height = 480;
    return scan_scene((folder_ / "scene.pov").string(), settings);
  }
  CameraReading camera(const std::string& text) { return read_camera(scan(text), {}, 640, 480); }

  std::filesystem::path folder_;
};

void expect_near(V3 a, V3 b, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, 1e-9) << what;
  EXPECT_NEAR(a.y, b.y, 1e-9) << what;
  EXPECT_NEAR(a.z, b.z, 1e-9) << what;
}

TEST_F(SceneFile, ConditionalsSelectTheBranchPovRayParses) {
  struct Case {
    const char* text;
    double location_x;  // the camera POV-Ray uses is at <location_x, 0, -5>
  };
  const char* const cam1 = " camera { location <1, 0, -5> look_at 0 } ";
  const char* const cam2 = " camera { location <2, 0, -5> look_at 0 } ";
  const std::vector<Case> cases = {
      {"#if (1) %1 #else %2 #end", 1},
      {"#if (0) %1 #else %2 #end", 2},
      {"#declare A = 3; #if (A > 2 & A < 4) %1 #else %2 #end", 1},
      {"#if (0) %1 #elseif (1) %2 #end", 2},
      {"#declare Q = 1; #ifdef (Q) %2 #else %1 #end", 2},
      {"#ifndef (Q) %2 #end %1", 1},  // the last camera wins
      {"#declare S = 2; #switch (S) #case (1) %1 #break #case (2) %2 #break #end", 2},
      {"#switch (5) #range (0, 4) %2 #break #else %1 #end", 1},
      {"#if (image_width > 600) %2 #else %1 #end", 2},
      {"#if (0) #if (1) %2 #end #else %1 #end", 1},
      {"%2 #macro Unused() %1 #end", 2},  // a macro body is not parsed where it is declared
  };
  for (const Case& c : cases) {
    std::string text = c.text;
    for (size_t at; (at = text.find("%1")) != std::string::npos;) text.replace(at, 2, cam1);
    for (size_t at; (at = text.find("%2")) != std::string::npos;) text.replace(at, 2, cam2);
    const CameraReading reading = camera(text);
    EXPECT_NEAR(reading.camera.location.x, c.location_x, 0.0) << c.text;
  }
  // A loop cannot be followed: its cameras are read, and marked as uncertain.
  const SceneScan looped =
      scan(std::string("#declare I = 0; #while (I < 2) ") + cam1 + "#declare I = I + 1; #end");
  ASSERT_FALSE(looped.cameras.empty());
  EXPECT_TRUE(looped.cameras.back().conditional);
}

TEST_F(SceneFile, CameraFormsTable) {
  // Every camera as POV-Ray resolves it (3.7 rules): direction along look_at - location with
  // length |right| / (2 tan(angle / 2)), right and up turned with it; right <1.33, 0, 0> and up
  // <0, 1, 0> by default, direction <0, 0, 1>.
  struct Case {
    const char* text;
    V3 location, direction_unit;
    double horizontal_fov;  // degrees (0: orthographic, not checked)
    double aspect;          // |right| / |up|
  };
  const double fov_default = 2 * std::atan(1.33 / 2) * 180 / kPi;  // |direction| = 1
  const double s = std::sqrt(0.5);
  const std::vector<Case> cases = {
      {"camera { }", {0, 0, 0}, {0, 0, 1}, fov_default, 1.33},
      {"camera { location <0, 1, -3> look_at <0, 1, 0> angle 60 }",
       {0, 1, -3},
       {0, 0, 1},
       60,
       1.33},
      {"camera { location <0, 0, -5> look_at <5, 0, 0> angle 90 }",
       {0, 0, -5},
       {s, 0, s},
       90,
       1.33},
      {"camera { location 0 direction <0, 0, 2> right x * image_width / image_height }",
       {0, 0, 0},
       {0, 0, 1},
       2 * std::atan(640.0 / 480 / 4) * 180 / kPi,
       640.0 / 480},
      {"camera { right <4/3, 0, 0> up <0, 1, 0> angle 45 location <0, 0, -1> look_at 0 }",
       {0, 0, -1},
       {0, 0, 1},
       45,
       4.0 / 3},
      {"#declare C = camera { location <3, 0, 0> look_at <0, 0, 0> angle 30 } camera { C }",
       {3, 0, 0},
       {-1, 0, 0},
       30,
       1.33},
      {"camera { location <0, 0, -4> look_at 0 angle 50 rotate <0, 90, 0> }",
       {-4, 0, 0},
       {1, 0, 0},
       50,
       1.33},
      {"camera { location <0, 0, -4> look_at 0 angle 50 translate <1, 2, 3> }",
       {1, 2, -1},
       {0, 0, 1},
       50,
       1.33},
      {"#declare P = <0, 2, -6>; camera { location P look_at P + z angle 2 * 20 }",
       {0, 2, -6},
       {0, 0, 1},
       40,
       1.33},
      {"camera { sky z location <0, -5, 0> look_at 0 angle 60 }", {0, -5, 0}, {0, 1, 0}, 60, 1.33},
      // An array declared without ';' ends at the next directive (incdemo/glasses/glass.pov).
      {"#declare T = 5; #declare A = array[3] #if (0) #declare T = 1; #end "
       "camera { location -T * z look_at 0 angle 60 }",
       {0, 0, -5},
       {0, 0, 1},
       60,
       1.33},
      {"camera { orthographic location <0, 0, -5> look_at 0 right 8 * x up 6 * y }",
       {0, 0, -5},
       {0, 0, 1},
       0,
       8.0 / 6},
  };
  for (const Case& c : cases) {
    const CameraReading reading = camera(c.text);
    const ResolvedCamera& cam = reading.camera;
    expect_near(cam.location, c.location, c.text);
    expect_near(normalized(cam.direction), c.direction_unit, c.text);
    if (c.horizontal_fov > 0) {
      EXPECT_NEAR(cam.horizontal_fov(), c.horizontal_fov, 1e-9) << c.text;
    }
    EXPECT_EQ(cam.orthographic, c.horizontal_fov == 0) << c.text;
    EXPECT_NEAR(cam.aspect(), c.aspect, 1e-9) << c.text;
    // The four vectors are a camera: right and up perpendicular to the direction.
    EXPECT_NEAR(dot(cam.right, cam.direction), 0, 1e-9) << c.text;
    EXPECT_NEAR(dot(cam.up, cam.direction), 0, 1e-9) << c.text;
  }
  EXPECT_TRUE(camera("sphere { 0, 1 }").default_camera);
}

TEST_F(SceneFile, RefusalsNameTheConstruct) {
  struct Case {
    const char* text;
    const char* named;
  };
  const std::vector<Case> cases = {
      {"camera { fisheye location 0 look_at z angle 180 }", "'fisheye'"},
      {"camera { panoramic location 0 look_at z }", "'panoramic'"},
      {"camera { spherical location 0 look_at z }", "'spherical'"},
      {"camera { mesh_camera { 1 0 mesh { triangle { 0, x, y } } } location 0 }", "'mesh_camera'"},
      {"camera { location <1, 2, 3> look_at <1, 2, 3> }", "location and look_at coincide"},
      {"camera { location 0 look_at z angle 180 }", "angle"},
      {"camera { location <0, 0, -5> look_at Target }", "Target"},
      {"camera { location 0 look_at z angle Fov(3) }", "Fov"},
      // A macro that makes the camera is not expanded, but never passed over (povray-examples'
      // incdemo/math.pov; screen.inc's Set_Camera calls Update_Camera).
      {"#macro Cam(D) camera { location <0, 2, -D> look_at 0 } #end Cam(5)", "macro 'Cam'"},
      {"#macro In() camera { location -z look_at 0 } #end #macro Out() In() #end Out()",
       "macro 'Out' (its camera { } block at scene.pov:1)"},
  };
  for (const Case& c : cases) {
    try {
      camera(c.text);
      ADD_FAILURE() << c.text << " was read";
    } catch (const ssao_tools::Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.named), std::string::npos)
          << c.text << ": " << e.what();
    }
  }
}

TEST_F(SceneFile, FileWritesAreFoundWherePovRayParsesThem) {
  // Passes rendered at once would share such a file (povray-ssao renders them one after
  // another): an #fopen for writing, or a call of a macro that opens one, itself or through
  // another, in whatever order their files are read.
  write("strings2.inc",
        "#macro Parse(S) #fopen F \"tmp.inc\" write #write(F, S) #fclose F "
        "#include \"tmp.inc\" #end");
  write("reader.inc", "#macro Load() #fopen F \"data.txt\" read #read(F, N) #fclose F #end");
  struct Case {
    const char* text;
    const char* found;  // where file_write points, or "" for none
  };
  const std::vector<Case> cases = {
      {"#fopen Log \"log.txt\" write", "scene.pov:1: #fopen"},
      {"#fopen Log concat(\"log\", str(clock, 0, 0)) append", "scene.pov:1: #fopen"},
      {"#fopen In \"in.txt\" read", ""},
      {"#include \"reader.inc\"\nLoad()", ""},
      {"#include \"strings2.inc\"\n", ""},  // declared, never called
      {"#include \"strings2.inc\"\nParse(\"#declare A = 1;\")",
       "scene.pov:2 calls Parse(), which opens a file for writing at strings2.inc:1"},
      // The caller is declared before the include that declares what it calls.
      {"#macro Cam() Parse(\"camera { }\") #end\n#include \"strings2.inc\"\nCam()",
       "scene.pov:3 calls Cam(), which opens a file for writing at strings2.inc:1"},
      {"#include \"strings2.inc\"\n#declare M = Parse(\"sphere { 0, 1 }\");",
       "scene.pov:2 calls Parse()"},
      {"#include \"strings2.inc\"\n#if (0) Parse(\"\") #end", ""},
      {"#if (0) #fopen Log \"log.txt\" write #end", ""},
      {"#macro Log() #fopen L \"log.txt\" write #end", ""},
  };
  for (const Case& c : cases) {
    const std::string found = scan(c.text).file_write;
    if (*c.found == '\0') {
      EXPECT_EQ(found, "") << c.text;
    } else {
      EXPECT_EQ(found.rfind(c.found, 0), 0u) << c.text << ": " << found;
    }
  }
  // The same lookup finds a camera macro through an include read after its caller.
  write("cams.inc", "#macro In() camera { location -z look_at 0 } #end");
  try {
    camera("#macro Out() In() #end\n#include \"cams.inc\"\nOut()");
    ADD_FAILURE() << "a camera made by a macro was read";
  } catch (const ssao_tools::Error& e) {
    EXPECT_NE(std::string(e.what()).find("macro 'Out' (its camera { } block at cams.inc:1)"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(SceneFile, IncludesAreFollowedAsPovRayFindsThem) {
  write("shot.inc", "#declare Shot = camera { location <0, 0, -7> look_at 0 angle 40 }");
  const CameraReading reading = camera("#include \"shot\" camera { Shot }");  // .inc appended
  EXPECT_NEAR(reading.camera.location.z, -7, 0);
  EXPECT_NEAR(reading.camera.horizontal_fov(), 40, 1e-9);
  const SceneScan missing = scan("#include \"nowhere.inc\" camera { location 0 look_at z }");
  EXPECT_EQ(missing.missing_includes, std::vector<std::string>{"nowhere.inc"});
}

}  // namespace
}  // namespace povray_ssao
