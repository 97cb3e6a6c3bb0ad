// SPDX-License-Identifier: MIT
// Normal-oriented hemisphere (Chapman's SSAO tutorial, seed 002/003), with cosine-weighted
// directions, a tangent-plane bias so flat and convex surfaces never occlude themselves, and a
// thickness range check against halos.
#include <algorithm>

#include "variants.h"

namespace ssao {

float hemisphere_visibility(const GBuffer& g, const Kernel& kernel, const VariantSettings& s, int x,
                            int y) {
  const int n = int(kernel.directions.size());
  const Vec3 p = g.position(x, y);
  const Vec3 normal = g.normal(x, y);
  // Depth-aware bias: one pixel footprint covers depth quantisation and pixel snapping.
  const float min_height = s.bias * s.radius + g.camera().pixel_footprint(-p.z);

  Vec3 t, b;
  orthonormal_basis(normal, t, b);
  const PixelJitter jitter = pixel_jitter(x, y, s.seed);
  const Vec3 tangent = t * jitter.cos_angle + b * jitter.sin_angle;
  const Vec3 bitangent = cross(normal, tangent);

  // Each kernel direction is followed by `steps` samples at increasing distances; the direction
  // counts as blocked by its strongest occluded sample, which is what Cycles' binary ray
  // visibility measures. steps = 1 is the classic kernel of independent points.
  const float spacing = s.steps == 1 ? 1.0f / float(n) : 1.0f / float(s.steps);
  float occlusion = 0.0f;
  int valid = 0;
  for (int k = 0; k < n; ++k) {
    const Vec3 d = kernel.directions[k];
    const Vec3 direction = tangent * d.x + bitangent * d.y + normal * d.z;
    float blocked = 0.0f;
    bool seen = false;
    for (int step = 0; step < s.steps; ++step) {
      const float stratum = float(s.steps == 1 ? kernel.stratum[k] : step) * spacing;
      const float r =
          s.radius * radial_scale(stratum + jitter.radial_offset * spacing, s.clustering);
      const Vec3 sample = p + direction * r;
      bool is_geometry = false;
      Vec3 q;
      if (!surface_behind_sample(g, sample, is_geometry, q)) continue;
      seen = true;
      if (!is_geometry) continue;
      const float behind = q.z - sample.z;  // > 0: the visible surface is in front of the sample
      if (behind <= 0.0f) continue;
      if (dot(q - p, normal) <= min_height) continue;  // at or below the tangent plane
      blocked = std::max(blocked, thickness_weight(behind, s.thickness * s.radius));
    }
    if (!seen) continue;
    ++valid;
    occlusion += blocked;
  }
  return valid > 0 ? 1.0f - occlusion / float(valid) : 1.0f;
}

}  // namespace ssao
