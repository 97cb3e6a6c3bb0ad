// SPDX-License-Identifier: MIT
// Writes the seed corpus of fuzz_exr with the project's own writer (ssao_tools::write_exr): small
// EXR files as Blender writes them (a multilayer file's <layer>.<pass>.<channel> names) and as
// other tools do (Z, R, G, B, A), a few hundred bytes to a few KB each, so no binary is kept in
// the repository. Usage: make_exr_seeds FOLDER
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tools/image_io.h"

namespace {

// A floor seen at an angle with a box on it: depth, a normal and a colour per pixel.
void write_scene(const std::string& path, int width, int height,
                 const std::vector<std::string>& names) {
  std::vector<float> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool box = x > width / 3 && x < 2 * width / 3 && y > height / 3;
      const float depth = y == 0 ? 1e10f : (box ? 3.0f : 4.0f + 0.5f * float(height - y));
      for (const std::string& name : names) {
        const char c = name.back();
        float v = 0.0f;
        if (c == 'Z') v = name.find("Normal") != std::string::npos ? (box ? 1.0f : 0.0f) : depth;
        if (c == 'X') v = 0.0f;
        if (c == 'Y') v = box ? 0.0f : 1.0f;
        if (c == 'R' || c == 'G' || c == 'B') v = 0.2f + 0.1f * float((x + y) % 5);
        if (c == 'A') v = 1.0f;
        pixels.push_back(v);
      }
    }
  }
  ssao_tools::write_exr(path, width, height, names, pixels);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
    return 2;
  }
  const std::string folder = argv[1];
  try {
    write_scene(folder + "/blender_layers.exr", 8, 6,
                {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                 "ViewLayer.Combined.A", "ViewLayer.Depth.Z", "ViewLayer.Normal.X",
                 "ViewLayer.Normal.Y", "ViewLayer.Normal.Z"});
    write_scene(folder + "/flat_names.exr", 5, 3, {"R", "G", "B", "A", "Z"});
    write_scene(folder + "/depth_only.exr", 1, 1, {"Depth.Z"});
  } catch (const ssao_tools::Error& e) {
    std::fprintf(stderr, "make_exr_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
