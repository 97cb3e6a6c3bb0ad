// SPDX-License-Identifier: MIT
#include "frame.h"

#include <cmath>

namespace ssao {
namespace {

bool is_background_depth(float d, const FrameInputs& in) {
  if (!std::isfinite(d) || !(d > 0.0f)) return true;
  if (d >= in.background_depth) return true;
  return in.clip_end > 0.0f && d >= in.clip_end;
}

// Normals transform with the transpose of the camera's rotation (inverse-transpose of the
// world-to-camera map), so a scaled camera matrix is handled too; the result is renormalised.
Vec3 world_to_view_normal(const double* m, Vec3 n) {
  return {static_cast<float>(m[0] * n.x + m[4] * n.y + m[8] * n.z),
          static_cast<float>(m[1] * n.x + m[5] * n.y + m[9] * n.z),
          static_cast<float>(m[2] * n.x + m[6] * n.y + m[10] * n.z)};
}

int16_t snorm16(float v) {
  return int16_t(std::lround(std::fmax(-1.0f, std::fmin(1.0f, v)) * 32767.0f));
}

}  // namespace

uint32_t encode_normal(Vec3 n) {
  const float l1 = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  float u = n.x / l1, v = n.y / l1;
  if (n.z < 0.0f) {
    const float fu = (1.0f - std::fabs(v)) * std::copysign(1.0f, u);
    const float fv = (1.0f - std::fabs(u)) * std::copysign(1.0f, v);
    u = fu;
    v = fv;
  }
  return uint32_t(uint16_t(snorm16(u))) | (uint32_t(uint16_t(snorm16(v))) << 16);
}

Frame::Frame(const CameraModel& camera, int width, int height)
    : camera_(camera),
      width_(width),
      height_(height),
      depth_(size_t(width) * size_t(height)),
      normal_(size_t(width) * size_t(height)) {}

size_t Frame::geometry_count(int x0, int y0, int x1, int y1) const {
  size_t count = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) count += is_geometry(x, y) ? 1 : 0;
  }
  return count;
}

void Frame::build(const FrameInputs& in, TilePool& pool, Progress& progress) {
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        float d = in.depth.pixel(x, y)[0];
        if (in.radial_depth && std::isfinite(d)) {
          d /= camera_.radial_factor(float(x) + 0.5f, float(y) + 0.5f);
        }
        depth_[index(x, y)] = is_background_depth(d, in) ? kBackground : d;
      }
    }
  });

  // Normals need the neighbours' depths, so they come after every depth is known.
  pool.for_each_tile(width_, height_, progress, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const size_t i = index(x, y);
        if (depth_[i] == kBackground) {
          normal_[i] = encode_normal({0.0f, 0.0f, 1.0f});
          continue;
        }
        const Vec3 towards_camera = camera_.towards_camera(position(x, y));
        Vec3 n{0.0f, 0.0f, 0.0f};
        if (in.normal.attached()) {
          const float* p = in.normal.pixel(x, y);
          n = {p[0], p[1], p[2]};
          if (in.world_normals) n = world_to_view_normal(in.camera_to_world, n);
        }
        // A missing, zero or non-finite normal (Blender writes 0 on background and blends on
        // silhouettes) falls back to the depth-reconstructed one.
        n = normalize_or(n, Vec3{0.0f, 0.0f, 0.0f});
        if (dot(n, n) == 0.0f) n = reconstructed_normal(x, y);
        // Shading normals of back faces point away from the camera; AO is about the visible side.
        if (dot(n, towards_camera) < 0.0f) n = -n;
        normal_[i] = encode_normal(n);
      }
    }
  });
}

// Cross product of the screen-space tangents, each taken on the side whose depth is closer to
// the centre's, so that silhouettes do not bend the normal of the surface behind them.
Vec3 Frame::reconstructed_normal(int x, int y) const {
  const Vec3 p = position(x, y);
  const float d = depth(x, y);
  auto tangent = [&](int dx, int dy, Vec3& out) {
    const int xa = x - dx, ya = y - dy, xb = x + dx, yb = y + dy;
    const bool a_ok = xa >= 0 && ya >= 0 && xa < width_ && ya < height_ && is_geometry(xa, ya);
    const bool b_ok = xb >= 0 && yb >= 0 && xb < width_ && yb < height_ && is_geometry(xb, yb);
    if (!a_ok && !b_ok) return false;
    bool use_b = b_ok;
    if (a_ok && b_ok) use_b = std::fabs(depth(xb, yb) - d) < std::fabs(depth(xa, ya) - d);
    out = use_b ? position(xb, yb) - p : p - position(xa, ya);
    return true;
  };
  Vec3 along_x, along_down;
  const Vec3 towards_camera = camera_.towards_camera(p);
  if (!tangent(1, 0, along_x) || !tangent(0, 1, along_down)) return towards_camera;
  // x grows to the right and y grows downwards, so cross(down, right) faces the camera.
  Vec3 n = normalize_or(cross(along_down, along_x), towards_camera);
  if (dot(n, towards_camera) < 0.0f) n = -n;
  return n;
}

}  // namespace ssao
