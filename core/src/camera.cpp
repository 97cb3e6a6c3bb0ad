// SPDX-License-Identifier: MIT
#include "camera.h"

#include <cmath>

#include "error.h"

namespace ssao {

CameraModel::CameraModel(const CameraParams& p, int width, int height)
    : orthographic_(p.orthographic) {
  const double w = width, h = height;
  const double aspect_x = p.pixel_aspect_x, aspect_y = p.pixel_aspect_y;
  // Which image side the sensor (or ortho_scale) spans: AUTO picks the larger one, as Blender.
  bool horizontal = true;
  if (p.sensor_fit == "AUTO") {
    horizontal = aspect_x * w >= aspect_y * h;
  } else if (p.sensor_fit == "VERTICAL") {
    horizontal = false;
  }
  const double sensor_size =
      (p.sensor_fit == "VERTICAL") ? p.sensor_height : p.sensor_width;  // AUTO uses the width
  const double view_factor = horizontal ? aspect_x * w : aspect_y * h;
  // Extent of the fitted side at unit depth (perspective) or in scene units (orthographic).
  const double extent = orthographic_ ? p.ortho_scale : sensor_size / p.lens;
  const double per_unit = extent / view_factor;  // view units per "x pixel" unit
  const double y_correction = aspect_y / aspect_x;
  if (!(per_unit > 0.0) || !std::isfinite(per_unit) || !(y_correction > 0.0)) {
    throw_invalid_argument("camera parameters give a degenerate view plane");
  }
  scale_u_ = static_cast<float>(per_unit);
  scale_v_ = static_cast<float>(per_unit * y_correction);
  center_u_ = static_cast<float>(0.5 * w - p.shift_x * view_factor);
  center_v_ = static_cast<float>(0.5 * h + p.shift_y * view_factor / y_correction);
}

CameraModel CameraModel::from_intrinsics(bool orthographic, double fx, double fy, double cx,
                                         double cy) {
  if (!(fx > 0.0 && fy > 0.0 && std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) &&
        std::isfinite(cy))) {
    throw_invalid_argument(
        "intrinsics: fx and fy must be positive (set the parameter 'intrinsics' to fx, fy, cx, "
        "cy in pixels with projection = intrinsics)");
  }
  CameraModel c;
  c.orthographic_ = orthographic;
  c.scale_u_ = static_cast<float>(1.0 / fx);
  c.scale_v_ = static_cast<float>(1.0 / fy);
  c.center_u_ = static_cast<float>(cx);
  c.center_v_ = static_cast<float>(cy);
  if (!(c.scale_u_ > 0.0f && c.scale_v_ > 0.0f)) {
    throw_invalid_argument("intrinsics: fx and fy are too large for single precision");
  }
  return c;
}

CameraModel CameraModel::from_projection_matrix(const double* m, int width, int height) {
  const auto at = [m](int row, int col) { return m[row * 4 + col]; };
  const bool perspective =
      at(3, 0) == 0.0 && at(3, 1) == 0.0 && at(3, 2) == -1.0 && at(3, 3) == 0.0;
  const bool orthographic =
      at(3, 0) == 0.0 && at(3, 1) == 0.0 && at(3, 2) == 0.0 && at(3, 3) == 1.0;
  if (!perspective && !orthographic) {
    throw_invalid_argument(
        "projection_matrix: its last row must be 0 0 -1 0 (perspective) or 0 0 0 1 "
        "(orthographic)");
  }
  // x and y must each depend on their own axis and the view axis only (no skew, no rotation).
  const int unused = perspective ? 3 : 2;
  if (at(0, 1) != 0.0 || at(1, 0) != 0.0 || at(0, unused) != 0.0 || at(1, unused) != 0.0) {
    throw_invalid_argument(
        "projection_matrix: skewed or rotated image axes, or an x/y translation in a "
        "perspective matrix (row 0 must be a 0 b 0, row 1 0 c d 0)");
  }
  if (!(at(0, 0) > 0.0 && at(1, 1) > 0.0)) {
    throw_invalid_argument("projection_matrix: its [0][0] and [1][1] must be positive");
  }
  // Perspective: NDC x = m00 x/d - m02 and NDC y = m11 y/d - m12 (d = -z, the planar depth);
  // orthographic: NDC x = m00 x + m03, NDC y = m11 y + m13. Pixels: u = (NDC x + 1) W / 2,
  // v = (1 - NDC y) H / 2 (y up in NDC, down in the image).
  const double w = width, h = height;
  const double cx = perspective ? (1.0 - at(0, 2)) * w / 2.0 : (1.0 - at(0, 3)) * w / 2.0;
  const double cy = perspective ? (1.0 + at(1, 2)) * h / 2.0 : (1.0 - at(1, 3)) * h / 2.0;
  return from_intrinsics(orthographic, at(0, 0) * w / 2.0, at(1, 1) * h / 2.0, cx, cy);
}

}  // namespace ssao
