// SPDX-License-Identifier: MIT
// Crysis sphere kernel (Mittring 2007, seed 000): depth only, samples in a full sphere around the
// point. Antipodal sample pairs make a flat surface read exactly half occluded; the normalized
// mode maps that half to 1.
#include <algorithm>

#include "variants.h"

namespace ssao {

float sphere_visibility(const GBuffer& g, const Kernel& kernel, const VariantSettings& s, int x,
                        int y) {
  const int n = int(kernel.directions.size());
  const int pairs = n / 2;
  const Vec3 p = g.position(x, y);
  // Depth-aware margin against self-occlusion: half a pixel footprint times the surface slope
  // (how far snapping a sample to its pixel centre can move the depth), plus the bias.
  const Vec3 normal = g.normal(x, y);
  const float cos_view = std::max(0.25f, dot(normal, g.camera().towards_camera(p)));
  const float slope = std::sqrt(1.0f - cos_view * cos_view) / cos_view;
  const float min_behind = s.bias * s.radius + 0.5f * g.camera().pixel_footprint(-p.z) * slope;
  const PixelJitter jitter = pixel_jitter(x, y, s.seed);

  float occlusion = 0.0f;
  int valid = 0;
  for (int k = 0; k + 1 < n; k += 2) {
    // A pair counts only when both of its points land in the image, keeping flat surfaces at
    // exactly one half near the borders too.
    const float r =
        s.radius * radial_scale((float(kernel.stratum[k]) + jitter.radial_offset) / float(pairs),
                                s.clustering);
    float pair_occlusion = 0.0f;
    bool pair_valid = true;
    for (int member = 0; member < 2 && pair_valid; ++member) {
      const Vec3 d0 = kernel.directions[k + member];
      // Rotate about the view axis: the sphere has no preferred tangent frame.
      const Vec3 d{d0.x * jitter.cos_angle - d0.y * jitter.sin_angle,
                   d0.x * jitter.sin_angle + d0.y * jitter.cos_angle, d0.z};
      const Vec3 sample = p + d * r;
      bool is_geometry = false;
      Vec3 q;
      pair_valid = surface_behind_sample(g, sample, is_geometry, q);
      if (!pair_valid || !is_geometry) continue;
      const float behind = q.z - sample.z;
      if (behind <= min_behind) continue;
      // The classic range check: occluders count within one radius of depth difference.
      pair_occlusion += thickness_weight(behind, s.radius);
    }
    if (!pair_valid) continue;
    valid += 2;
    occlusion += pair_occlusion;
  }
  if (valid == 0) return 1.0f;
  const float v = 1.0f - occlusion / float(valid);
  return s.sphere_normalized ? std::min(1.0f, 2.0f * v) : v;
}

}  // namespace ssao
