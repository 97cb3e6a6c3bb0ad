// SPDX-License-Identifier: MIT
// What povray-ssao writes: the output files of an image (-o, --exr), the depth of --depth-only,
// and the camera report of --print-camera.
#pragma once

#include <string>
#include <vector>

#include "ao_inputs.h"
#include "pov_camera.h"

namespace povray_ssao {

// The files an image is written to.
struct OutputFiles {
  std::string output;  // -o
  std::string exr;     // --exr, or empty
};

// Writes -o (and --exr): an 8-bit sRGB preview of the composite, or every channel as float EXR
// (R, G, B, A, AO, Z, Radial). If the second file cannot be written the first is removed again.
void write_outputs(const OutputFiles& files, const AoInputs& in,
                   const std::vector<float>& composite, const std::vector<float>& ao);

// --depth-only: the frame's Z and Radial channels to `output` (-o).
void write_depth_only(const std::string& output, const AoInputs& in);

// --print-camera: the camera read, the camera blocks the passes are rendered with (the beauty
// and the ambient pass: the scene's own camera when `scene_camera_for_frame`), and libssao's
// camera parameters, on stdout.
void print_camera(const CameraReading& reading, bool scene_camera_for_frame, int width, int height,
                  int band);

}  // namespace povray_ssao
