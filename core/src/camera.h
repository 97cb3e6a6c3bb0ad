// SPDX-License-Identifier: MIT
// Pixel <-> view-space mapping of a Blender-style camera (perspective or orthographic, sensor
// fit, lens shift, pixel aspect). Pixel (px, py) has its centre at (px + 0.5, py + 0.5) in
// continuous image coordinates, with py = 0 the top row. View space looks down -Z, +Y up.
#pragma once

#include <string>

#include "vec3.h"

namespace ssao {

struct CameraParams {
  bool orthographic = false;
  double lens = 50.0;           // mm
  double sensor_width = 36.0;   // mm
  double sensor_height = 24.0;  // mm
  std::string sensor_fit = "AUTO";
  double shift_x = 0.0, shift_y = 0.0;  // in units of the fitted image side
  double ortho_scale = 6.0;
  double pixel_aspect_x = 1.0, pixel_aspect_y = 1.0;
};

// The pinhole (or orthographic) mapping as plain numbers, for vectorised kernels:
//   view x = (u - center_u) * scale_u [* depth], view y = (center_v - v) * scale_v [* depth].
struct CameraIntrinsics {
  bool orthographic;
  float scale_u, scale_v, center_u, center_v;
};

// CameraModel::depth_on_plane for the centres of whole pixels (x, y), written out once per plane
// dot(p, n) = w: the ray through pixel (x, y) meets the plane at planar depth numerator / slope,
// both affine in x and y, so a walk over many pixels needs no division to compare depths.
struct PlaneDepths {
  float slope0 = 0.0f, slope_x = 0.0f, slope_y = 0.0f;
  float numerator0 = 0.0f, numerator_x = 0.0f, numerator_y = 0.0f;

  PlaneDepths() = default;
  PlaneDepths(const CameraIntrinsics& cam, Vec3 n, float w) {
    // View x and y of pixel (x, y)'s centre at unit depth: x0 + x * scale_u, y0 - y * scale_v.
    const float x0 = (0.5f - cam.center_u) * cam.scale_u, y0 = (cam.center_v - 0.5f) * cam.scale_v;
    if (cam.orthographic) {  // from (X, Y, 0) along (0, 0, -1)
      slope0 = -n.z;
      numerator0 = w - n.x * x0 - n.y * y0;
      numerator_x = -n.x * cam.scale_u, numerator_y = n.y * cam.scale_v;
    } else {  // from the eye along (X, Y, -1)
      slope0 = n.x * x0 + n.y * y0 - n.z;
      slope_x = n.x * cam.scale_u, slope_y = -n.y * cam.scale_v;
      numerator0 = w;
    }
  }
  // Pixel (x, y)'s numerator and slope, the sign chosen so that slope >= 0 (0: along the plane).
  void at(int x, int y, float& numerator, float& slope) const {
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    slope = slope0 + slope_x * fx + slope_y * fy;
    numerator = numerator0 + numerator_x * fx + numerator_y * fy;
    if (slope < 0.0f) slope = -slope, numerator = -numerator;
  }
};

class CameraModel {
 public:
  // Mirrors Blender's viewplane computation (BKE_camera_params_compute_viewplane).
  CameraModel(const CameraParams& params, int width, int height);

  // The pinhole numbers: focal lengths in pixels (orthographic: pixels per scene unit) and the
  // principal point in continuous image coordinates (x right, y down, pixel (0, 0) centred at
  // (0.5, 0.5)). Throws invalid_argument unless fx, fy > 0 and every number is finite.
  static CameraModel from_intrinsics(bool orthographic, double fx, double fy, double cx, double cy);
  // An OpenGL-style view-to-clip matrix (row-major), perspective (last row 0 0 -1 0) or
  // orthographic (last row 0 0 0 1), on a width x height image. Throws invalid_argument for a
  // matrix of another shape (skew, a last row of neither kind, a non-positive scale).
  static CameraModel from_projection_matrix(const double* m, int width, int height);

  // The same camera on an image `factor` times coarser (pixel (i, j) covers pixels
  // [factor i, factor (i + 1)) x [factor j, factor (j + 1)) of this one).
  CameraModel coarser(int factor) const {
    CameraModel c = *this;
    c.scale_u_ *= float(factor), c.scale_v_ *= float(factor);
    c.center_u_ /= float(factor), c.center_v_ /= float(factor);
    return c;
  }

  // The same camera on a larger image that holds this one's pixel (0, 0) at pixel (dx, dy)
  // (a guard band on the same pixel grid).
  CameraModel moved_by(int dx, int dy) const {
    CameraModel c = *this;
    c.center_u_ += float(dx), c.center_v_ += float(dy);
    return c;
  }

  bool orthographic() const { return orthographic_; }
  CameraIntrinsics intrinsics() const {
    return {orthographic_, scale_u_, scale_v_, center_u_, center_v_};
  }

  // View-space position of the point at planar depth d seen through continuous image
  // coordinates (u, v).
  Vec3 view_position(float u, float v, float planar_depth) const {
    const float x = (u - center_u_) * scale_u_;
    const float y = (center_v_ - v) * scale_v_;
    if (orthographic_) return {x, y, -planar_depth};
    return {x * planar_depth, y * planar_depth, -planar_depth};
  }

  // Continuous image coordinates of a view-space point; false if it is not in front of the
  // camera (perspective).
  bool project(Vec3 p, float& u, float& v) const {
    float x = p.x, y = p.y;
    if (!orthographic_) {
      const float d = -p.z;
      if (!(d > 0.0f)) return false;
      x /= d;
      y /= d;
    }
    u = x / scale_u_ + center_u_;
    v = center_v_ - y / scale_v_;
    return true;
  }

  // Planar depth at which the ray through continuous image coordinates (u, v) meets the plane
  // dot(x, n) = w; false where the ray runs along the plane (PlaneDepths: the same over pixels).
  bool depth_on_plane(float u, float v, Vec3 n, float w, float& planar_depth) const {
    const Vec3 origin = view_position(u, v, 0.0f);
    const float slope = dot(view_position(u, v, 1.0f) - origin, n);
    if (!(std::fabs(slope) > 1e-6f)) return false;
    planar_depth = (w - dot(origin, n)) / slope;
    return true;
  }

  // Direction from the point towards the camera (unit), for orienting normals.
  Vec3 towards_camera(Vec3 p) const {
    return orthographic_ ? Vec3{0.0f, 0.0f, 1.0f} : normalize_or(-p, Vec3{0.0f, 0.0f, 1.0f});
  }

  // Height over width of one pixel in view space (1 unless the pixel aspect is not square).
  float pixel_aspect() const { return scale_v_ / scale_u_; }

  // Width in view units of one pixel at planar depth d.
  float pixel_footprint(float planar_depth) const {
    return orthographic_ ? scale_u_ : scale_u_ * planar_depth;
  }

 private:
  CameraModel() = default;

  bool orthographic_ = false;
  float scale_u_ = 1.0f, scale_v_ = 1.0f;    // view units per pixel (at unit depth if PERSP)
  float center_u_ = 0.0f, center_v_ = 0.0f;  // principal point in continuous image coordinates
};

}  // namespace ssao
