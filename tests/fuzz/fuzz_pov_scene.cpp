// SPDX-License-Identifier: MIT
// libFuzzer target: povray-ssao's scene reader (povray_bridge/sdl.cpp, pov_camera.cpp) on random
// scene text, the way read_image_scene() in scene_setup.cpp uses it: scan_scene on a scene file
// (written to a scratch folder; its #include files resolve there and in povray_bridge/pov),
// read_camera on the scan (a scan without a camera gives POV-Ray's default one), then the
// camera's SDL, summary, pixel mapping and the library's camera parameters. Also tokenize +
// evaluate_full from every token of the text (the evaluator behind #declare, #if and the
// camera's values). Everything must work or throw ssao_tools::Error (the evaluator's EvalError
// is one); a camera that reads must have finite vectors, since povray-ssao writes them into
// every pass's scene.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "pov_camera.h"
#include "sdl.h"
#include "ssao/ssao.hpp"

namespace {

using fuzz::check;

bool finite(povray_ssao::V3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace povray_ssao;
  const std::string text(reinterpret_cast<const char*>(data), size);
  constexpr int kWidth = 64, kHeight = 48;

  // The evaluator from 32 positions spread over the text (every position would cost n^2, and a
  // refused deep expression unwinds hundreds of frames).
  try {
    const std::vector<Token> tokens = tokenize(text, "fuzz.pov");
    check(!tokens.empty() && tokens.back().kind == Token::kEnd, "tokens do not end with kEnd");
    Symbols symbols;
    EvalContext context;
    context.symbols = &symbols;
    context.image_width = kWidth;
    context.image_height = kHeight;
    Conditionals conditionals;
    const size_t stride = tokens.size() / 32 + 1;
    for (size_t start = 0; start + 1 < tokens.size(); start += stride) {
      size_t pos = start;
      try {
        (void)evaluate_full(tokens, pos, context);
        check(pos < tokens.size(), "evaluate_full went past the end");
      } catch (const EvalError&) {
      }
    }
    // The conditional directives' state machine over the tokens, as the scan steps through it.
    for (size_t i = 0; i + 1 < tokens.size();) {
      const size_t next = conditionals.handle(tokens, i, context);
      check(next < tokens.size(), "Conditionals::handle went past the end");
      i = next == i ? i + 1 : next;
    }
  } catch (const ssao_tools::Error&) {
    // An unterminated string or comment.
  }

  const std::string path = fuzz::write_input("scene.pov", data, size);
  ScanSettings settings;
  settings.directory = fuzz::scratch_folder().string();
  settings.library_paths = {POVRAY_SSAO_SOURCE_INCLUDES};
  settings.image_width = kWidth;
  settings.image_height = kHeight;
  SceneScan scan;
  try {
    scan = scan_scene(path, settings);
  } catch (const ssao_tools::Error&) {
    return 0;
  }
  CameraReading reading;
  try {
    reading = read_camera(scan, CameraOverrides{}, kWidth, kHeight);
  } catch (const ssao_tools::Error&) {
    return 0;
  }
  const ResolvedCamera& camera = reading.camera;
  check(finite(camera.location) && finite(camera.direction) && finite(camera.right) &&
            finite(camera.up),
        "read_camera gave a camera with non-finite vectors");
  (void)camera.to_sdl();
  (void)camera.summary();
  for (int y : {0, kHeight - 1}) {
    for (int x : {0, kWidth - 1}) (void)camera.radial_factor(x, y, kWidth, kHeight);
  }
  try {
    ssao::api::Job job;
    camera.apply_to_job(job, kWidth, kHeight);
  } catch (const ssao::api::Error&) {
    // A camera libssao cannot model (e.g. a lens beyond its range): povray-ssao says so.
  }
  return 0;
}
