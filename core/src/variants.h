// SPDX-License-Identifier: MIT
// The AO variants. Each estimates the raw visibility (1 = unoccluded) of one receiver pixel; the
// job runs them over the image, then denoises and shapes the result.
#pragma once

#include <cmath>
#include <cstdint>

#include "gbuffer.h"
#include "kernels.h"

namespace ssao {

struct VariantSettings {
  float radius = 1.0f;      // scene units
  float bias = 0.02f;       // fraction of radius
  float clustering = 1.0f;  // see radial_scale()
  int steps = 1;            // hemisphere: samples along each kernel direction
  float thickness = 1.0f;   // fraction of radius
  uint32_t seed = 0;
  bool sphere_normalized = true;
};

// Estimators for pixel (x, y), which must be a receiver (below).
using VisibilityEstimator = float (*)(const GBuffer& g, const Kernel& kernel,
                                      const VariantSettings& s, int x, int y);
float hemisphere_visibility(const GBuffer& g, const Kernel& kernel, const VariantSettings& s, int x,
                            int y);
float sphere_visibility(const GBuffer& g, const Kernel& kernel, const VariantSettings& s, int x,
                        int y);

// Pixels worth estimating: geometry whose kernel covers at least half a pixel (a smaller one
// sees no other pixel). Every other pixel has visibility 1 without any work.
inline bool is_receiver(const GBuffer& g, int x, int y, float radius) {
  return g.is_geometry(x, y) && radius >= 0.5f * g.camera().pixel_footprint(g.depth(x, y));
}

// --- helpers shared by the variants ---

// Looks up the surface seen through the pixel that view-space point s projects to. Returns false
// when s falls outside the image (or behind a perspective camera): such a sample tells nothing.
inline bool surface_behind_sample(const GBuffer& g, Vec3 s, bool& is_geometry, Vec3& surface) {
  float u, v;
  if (!g.camera().project(s, u, v)) return false;
  if (!(u >= 0.0f && v >= 0.0f && u < float(g.width()) && v < float(g.height()))) return false;
  const int qx = int(u), qy = int(v);
  is_geometry = g.is_geometry(qx, qy);
  if (is_geometry) surface = g.position(qx, qy);
  return true;
}

// Range check against halos: an occluder counts fully when the sample lies at most `thickness`
// behind the visible surface, fading out at twice that (surfaces are assumed about that thick).
inline float thickness_weight(float depth_behind_surface, float thickness) {
  return saturate(2.0f - depth_behind_surface / thickness);
}

}  // namespace ssao
