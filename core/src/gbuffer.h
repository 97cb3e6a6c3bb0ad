// SPDX-License-Identifier: MIT
// View-space geometry of every pixel, prepared once per run from the depth (and normal) images.
#pragma once

#include <cstdint>
#include <vector>

#include "camera.h"
#include "image_view.h"
#include "parallel.h"
#include "vec3.h"

namespace ssao {

struct GBufferInputs {
  ImageView depth;
  ImageView normal;  // optional (data == nullptr: reconstruct from depth)
  bool radial_depth = false;
  bool world_normals = true;
  double camera_to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  float background_depth = 1e9f;  // depth >= this (or >= clip_end when > 0) is background
  float clip_end = 0.0f;
};

class GBuffer {
 public:
  GBuffer(const CameraModel& camera, int width, int height);

  // Fills positions, then normals (from the normal image or reconstructed), in parallel.
  void build(const GBufferInputs& in, int threads, Progress& progress);

  int width() const { return width_; }
  int height() const { return height_; }
  const CameraModel& camera() const { return camera_; }
  bool is_geometry(int x, int y) const { return geometry_[index(x, y)] != 0; }
  // Planar depth (positive); only meaningful where is_geometry().
  float depth(int x, int y) const { return -position_[index(x, y)].z; }
  Vec3 position(int x, int y) const { return position_[index(x, y)]; }
  Vec3 normal(int x, int y) const { return normal_[index(x, y)]; }
  size_t geometry_count() const;

 private:
  size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }
  Vec3 reconstructed_normal(int x, int y) const;

  CameraModel camera_;
  int width_, height_;
  std::vector<Vec3> position_;
  std::vector<Vec3> normal_;
  std::vector<uint8_t> geometry_;
};

}  // namespace ssao
