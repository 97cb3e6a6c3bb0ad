// SPDX-License-Identifier: MIT
// The camera description that travels beside a rendered image (docs: conventions.md), e.g.
//   {"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
//    "sensor_fit": "AUTO", "shift_x": 0.0, "shift_y": 0.0, "ortho_scale": 6.0,
//    "clip_start": 0.1, "clip_end": 1000.0, "matrix_world": [[4 numbers] x 4 rows]}
// Keys are named after Blender's bpy.types.Camera properties. Every key the projection depends
// on is required, so that a missing value is an error rather than a default that silently
// changes the image: "type", "sensor_fit", "shift_x", "shift_y", and "lens" plus the sensor
// side the fit uses ("sensor_width", or "sensor_height" for VERTICAL) for PERSP, "ortho_scale"
// for ORTHO. "matrix_world" (camera-to-world, row-major, camera looking down its local -Z with
// +Y up) is needed only to turn world-space normals (has_matrix_world says whether it was
// given). Optional: "pixel_aspect_x"/"pixel_aspect_y" (render settings, square pixels when
// absent), "clip_start" (informational), "clip_end" (depths at or beyond it are background;
// absent: no such test, the depth pass marks its background itself), "ao_distance" (> 0, scene
// units; Blender's World > Ambient Occlusion > Distance: the AO radius the shot was made for,
// which the CLI uses when --radius is not given). Another renderer's camera: "projection":
// "intrinsics" with "intrinsics": [fx, fy, cx, cy] (pixels; "type" still PERSP or ORTHO), or
// "matrix" with "projection_matrix" (4x4, OpenGL view-to-clip); neither needs the lens keys.
// Keys the format does not know are reported in Camera::unknown_keys and otherwise ignored.
#pragma once

#include <string>
#include <vector>

#include "ssao/ssao.h"
#include "tools/error.h"

namespace ssao_tools {

struct Camera {
  std::string type = "PERSP";       // "PERSP" | "ORTHO"
  double lens = 50.0;               // mm
  double sensor_width = 36.0;       // mm
  double sensor_height = 24.0;      // mm
  std::string sensor_fit = "AUTO";  // "AUTO" | "HORIZONTAL" | "VERTICAL"
  double shift_x = 0.0;
  double shift_y = 0.0;
  double ortho_scale = 6.0;
  double clip_start = 0.1;
  double clip_end = 0.0;  // 0: no clip test
  double pixel_aspect_x = 1.0;
  double pixel_aspect_y = 1.0;
  double ao_distance = 0.0;  // the AO radius chosen for this shot (scene units); 0: none given
  std::vector<double> matrix_world = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  // The library's camera contract beyond Blender's camera (ssao.h, "The camera"): "lens" (the
  // keys above), "intrinsics" (fx, fy, cx, cy in pixels) or "matrix" (a 4x4 view-to-clip
  // matrix). Empty: not in the file.
  std::string projection = "lens";
  std::vector<double> intrinsics;
  std::vector<double> projection_matrix;
  bool has_matrix_world = false;          // the identity above is a placeholder, not the camera's
  std::vector<std::string> unknown_keys;  // present in the file, not part of the format
};

// Reads and validates a camera file. Throws Error, naming the file and the key, for a missing
// or unreadable file, malformed JSON, a root that is not an object, a missing required key, a
// value of the wrong JSON type, a non-finite number, a size or scale that is not positive, an
// unknown choice, or a matrix that is not a 4x4 affine transform. (A singular 3x3 part is
// refused by the core when world-space normals need it.)
Camera read_camera_json(const std::string& path);

// Same from the text of a file; `source` names it in messages.
Camera parse_camera_json(const std::string& text, const std::string& source);

// True if `name` is a parameter of the library's "camera" group (ssao_param_group).
bool is_camera_param(const std::string& name);

// Sets the camera parameters of `job` through the C API. `source` (the file name) prefixes the
// messages. Throws Error with ssao_last_error() when the core rejects a value.
void apply_camera(ssao_job job, const Camera& camera, const std::string& source);

}  // namespace ssao_tools
