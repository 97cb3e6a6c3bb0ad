// SPDX-License-Identifier: MIT
// The camera file (docs/conventions.md, "Camera file"): the JSON that travels beside a render,
// with Blender's camera property names. The one reader of the format (ssao.h,
// ssao_job_set_camera_json): the CLI, the evaluation tools and the Python module all call it.
//   {"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
//    "sensor_fit": "AUTO", "shift_x": 0.0, "shift_y": 0.0, "ortho_scale": 6.0,
//    "clip_start": 0.1, "clip_end": 1000.0, "matrix_world": [[4 numbers] x 4 rows]}
// Every key the projection depends on is required, so that a missing value is an error rather
// than a default that silently changes the image: "type", "sensor_fit", "shift_x", "shift_y",
// and "lens" plus the sensor side the fit uses ("sensor_width", or "sensor_height" for
// VERTICAL) for PERSP, "ortho_scale" for ORTHO. "matrix_world" (camera-to-world, row-major,
// looking down local -Z, +Y up) sets camera_to_world, which world-space normals need. Optional:
// "pixel_aspect_x"/"pixel_aspect_y", "clip_start", "clip_end" (> 0: depths at or beyond it are
// background), "ao_distance" (> 0, scene units: the AO radius the shot was made for, Blender's
// World > Ambient Occlusion > Distance). Another renderer's camera: "projection": "intrinsics"
// with "intrinsics": [fx, fy, cx, cy] (pixels), or "matrix" with "projection_matrix" (4x4,
// OpenGL view-to-clip); neither needs the lens keys. Unknown keys are listed, not refused.
#pragma once

#include <string>
#include <vector>

#include "camera.h"
#include "params.h"

namespace ssao {

// What a camera file says beyond the camera parameters it sets.
struct CameraFile {
  double ao_distance = 0.0;               // the shot's AO radius; 0: not in the file
  std::vector<std::string> unknown_keys;  // in the file, not part of the format
};

// Checks `text` against every rule of the format and sets the camera parameters it holds on
// `params` (only the keys present: the others keep their values). Throws an invalid-argument
// Error naming `source` and the key; `params` may then hold some of the values (the caller
// works on a copy).
CameraFile apply_camera_json(const std::string& text, const std::string& source,
                             ParamValues& params);

// The lens camera (Blender's lens and sensor) the camera parameters describe.
CameraParams camera_params(const ParamValues& params);

}  // namespace ssao
