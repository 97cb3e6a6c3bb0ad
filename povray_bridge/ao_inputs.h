// SPDX-License-Identifier: MIT
// What the AO step needs, whichever mode produced it: the render mode fills it from POV-Ray's
// passes, the post-process mode from the user's beauty and depth files.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "pov_camera.h"
#include "tools/image_io.h"

namespace povray_ssao {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct AoInputs {
  int width = 0, height = 0;  // the frame: the beauty's and the outputs' size
  // Guard band, pixels on every side: depth_input and normals cover the data passes'
  // (width + 2 band) x (height + 2 band) pixels, the frame at (band, band) inside them.
  int band = 0;
  std::vector<float> beauty;  // R, G, B, A (linear; A = 1 when the beauty has none)
  bool beauty_has_alpha = false;
  bool beauty_blurred = false;     // focal blur rendered into it: its edges are not the depth's
  std::vector<float> radial;       // the frame's distance from the camera; +inf on background
  std::vector<float> planar;       // the frame's depth along the view axis; +inf on background
  bool planar_input = false;       // give libssao the planar depth (orthographic, planar files)
  std::vector<float> depth_input;  // what libssao reads: planar or radial, the band included
  std::vector<float> normals;      // libssao camera space, 3 per pixel, the band included; or empty
  std::vector<float> ambient;      // R, G, B, 0 per pixel in the scene's working space, or empty:
                                   // AO darkens only this part of the beauty
  double working_gamma = 1.0;      // the scene's assumed_gamma: beauty = working value ^ gamma
  ResolvedCamera camera;           // the frame's (libssao's camera describes the output window)

  int data_width() const { return width + 2 * band; }
  int data_height() const { return height + 2 * band; }
  size_t frame_pixels() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
};

// Copies the channels R, G, B (and A) of `image` into in.beauty as RGBA; a grey image (Y or one
// channel) gives R = G = B.
void take_beauty(const ssao_tools::Image& image, const std::string& path, AoInputs& in);

// From `depth` (data_width() x data_height(), planar or radial): libssao's depth_input (the
// kind in.planar_input says) and the frame's radial and planar depth. A band pixel is the frame
// camera's ray through pixel (x - band, y - band), outside [0, W) x [0, H).
void fill_planar_and_radial(AoInputs& in, const std::vector<float>& depth, bool depth_is_planar);

}  // namespace povray_ssao
