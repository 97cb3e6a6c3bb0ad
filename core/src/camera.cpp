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

}  // namespace ssao
