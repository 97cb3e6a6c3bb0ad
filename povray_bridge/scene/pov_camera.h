// SPDX-License-Identifier: MIT
// POV-Ray 3.7's camera: what povray-ssao reads from the scene text (the last camera { } block,
// or an SSAOCamera(...) call of ssao_passes.inc), the --camera-* overrides, the resolution of
// location/look_at/angle/right/up/direction/sky/transforms into four vectors exactly as POV-Ray's
// Parse_Camera does (3.5+ rules), the camera block povray-ssao writes after the scene in every
// pass, and the mapping to libssao's Blender-style camera parameters.
//
// POV-Ray's camera model (tracepixel.cpp): the ray of pixel (i, j), row 0 at the top, is
// D + x0 R + y0 U with x0 = (i + 0.5) / W - 0.5 and y0 = 0.5 - (j + 0.5) / H, so |R| / |D| is
// the view width at unit distance: angle A (horizontal) gives |D| = |R| / (2 tan(A / 2)).
// Orthographic rays start at location + x0 R + y0 U and travel along D.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sdl.h"
#include "ssao/ssao.hpp"

namespace povray_ssao {

// The --camera-* flags (each optional).
struct CameraOverrides {
  std::optional<V3> location, look_at, right, up, direction, sky;
  std::optional<double> angle;
  bool orthographic = false;
  bool any() const {
    return location || look_at || right || up || direction || sky || angle || orthographic;
  }
  // Enough to define a camera without the scene's block.
  bool complete() const { return location && (look_at || direction); }
};

// A camera as four vectors: what POV-Ray traces with.
struct ResolvedCamera {
  bool orthographic = false;
  V3 location{0, 0, 0};
  V3 direction{0, 0, 1};
  V3 right{1.33, 0, 0};
  V3 up{0, 1, 0};
  // |look_at - location| when the camera was given a look_at (0 otherwise): where the scene's
  // subject is, which places the depth pass's fogs without a pre-pass.
  double look_at_distance = 0.0;

  // Horizontal field of view in degrees (perspective).
  double horizontal_fov() const;
  // |right| / |up|: the image aspect ratio the camera is made for.
  double aspect() const;

  // A camera { } block that reproduces this camera whatever the #version in effect.
  std::string to_sdl() const;

  // One line for the progress output.
  std::string summary() const;

  // Sets camera_type and the pinhole intrinsics (projection intrinsics: fx, fy, cx, cy) of a
  // W x H image so that libssao's pixel <-> view mapping is POV-Ray's.
  void apply_to_job(ssao::api::Job& job, int width, int height) const;

  // radial distance / planar depth of pixel (px, py): 1 for orthographic cameras.
  double radial_factor(int px, int py, int width, int height) const;

  // The camera of a guard band: a (W + 2 band) x (H + 2 band) image on the same pixel grid,
  // whose inner W x H pixels trace exactly this camera's rays. Pixel i' = i + band of the wider
  // image has x0' = (i + band + 0.5) / (W + 2 band) - 0.5 = (i + 0.5 - W / 2) / (W + 2 band),
  // so right' = right (W + 2 band) / W gives x0' right' = x0 right (up likewise with H); the
  // location and direction stay. The same holds for orthographic cameras (ray origins).
  ResolvedCamera widened(int width, int height, int band) const;

 private:
  void set_job_camera(ssao::api::Job& job, int width, int height) const;
};

struct CameraReading {
  ResolvedCamera camera;
  std::string source;                 // "scene.pov:25", "--camera-* flags", ...
  bool had_focal_blur = false;        // the block sets a non-zero aperture (or may, under #if)
  bool default_camera = false;        // the scene text has no camera: POV-Ray's default one
  std::vector<std::string> warnings;  // for the user
};

// The camera of a scan with the overrides applied on top. A scan without any camera gives
// POV-Ray's default camera (perspective, location <0,0,0>, direction <0,0,1>, right
// <1.33,0,0>, up <0,1,0>: looking along +z) with `default_camera` set. Throws
// ssao_tools::Error with a message naming what could not be read and suggesting the --camera-*
// flags, when the camera is of another type (fisheye, panoramic, ...) or when an expression
// cannot be evaluated (unless the overrides are complete: location and look_at or direction).
CameraReading read_camera(const SceneScan& scan, const CameraOverrides& overrides, int width,
                          int height);

// Camera for a post-process run: perspective with horizontal FOV `angle` (degrees), or
// orthographic `ortho_width` wide; `aspect` = |right| / |up| (the image's W/H for square pixels).
ResolvedCamera make_camera(bool orthographic, double angle, double ortho_width, double aspect);

}  // namespace povray_ssao
