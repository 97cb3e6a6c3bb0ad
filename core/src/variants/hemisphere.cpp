// SPDX-License-Identifier: MIT
// Normal-oriented hemisphere (Chapman's SSAO tutorial, seed 002/003), with cosine-weighted
// directions, a tangent-plane bias so flat and convex surfaces never occlude themselves, and a
// thickness range check against halos.
#include <algorithm>

#include "sampling.h"
#include "variant.h"

namespace ssao {
namespace {

class Hemisphere final : public Variant {
 public:
  explicit Hemisphere(const ParamValues& v) {
    static constexpr int kSamples[4] = {8, 16, 16, 32};
    static constexpr int kSteps[4] = {3, 6, 8, 8};
    radius_ = float(v.get_float("radius"));
    bias_ = float(v.get_float("bias"));
    thickness_ = float(v.get_float("thickness")) * radius_;
    directions_ = count_or_preset(v, "samples", kSamples);
    steps_ = count_or_preset(v, "steps", kSteps);
    // Each kernel direction is followed by `steps` samples at increasing distances;
    // steps = 1 is the classic kernel of independent points. The table holds, per jitter
    // state, every sample's offset in the receiver's tangent frame, rotated and scaled.
    const Kernel kernel = make_hemisphere_kernel(directions_);
    const float clustering = float(v.get_float("sample_clustering"));
    const float spacing = steps_ == 1 ? 1.0f / float(directions_) : 1.0f / float(steps_);
    const auto states = jitter_states(uint32_t(v.get_int("seed")));
    offsets_.resize(size_t(kJitterStates) * directions_ * steps_);
    for (int j = 0; j < kJitterStates; ++j) {
      const JitterState& js = states[j];
      for (int k = 0; k < directions_; ++k) {
        const Vec3 d = kernel.directions[k];
        const Vec3 rotated{d.x * js.cos_angle - d.y * js.sin_angle,
                           d.x * js.sin_angle + d.y * js.cos_angle, d.z};
        for (int step = 0; step < steps_; ++step) {
          const float stratum = float(steps_ == 1 ? kernel.stratum[k] : step) * spacing;
          const float r = radius_ * radial_scale(stratum + js.radial_offset * spacing, clustering);
          offsets_[(size_t(j) * directions_ + k) * steps_ + step] = rotated * r;
        }
      }
    }
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        visibility[f.index(x, y)] = is_receiver(f, x, y, radius_) ? pixel(f, x, y) : 1.0f;
      }
    }
  }

 private:
  float pixel(const Frame& f, int x, int y) const {
    const Vec3 p = f.position(x, y);
    const Vec3 normal = f.normal(x, y);
    // Depth-aware bias: one pixel footprint covers depth quantisation and pixel snapping.
    const float min_height = bias_ * radius_ + f.camera().pixel_footprint(-p.z);
    Vec3 tangent, bitangent;
    orthonormal_basis(normal, tangent, bitangent);
    const Vec3* offset = offsets_.data() + size_t(jitter_index(x, y)) * directions_ * steps_;

    // A direction counts as blocked by its strongest occluded sample, which is what Cycles'
    // binary ray visibility measures.
    float occlusion = 0.0f;
    int valid = 0;
    for (int k = 0; k < directions_; ++k) {
      float blocked = 0.0f;
      bool seen = false;
      for (int step = 0; step < steps_; ++step, ++offset) {
        const Vec3 sample = p + tangent * offset->x + bitangent * offset->y + normal * offset->z;
        bool is_geometry = false;
        Vec3 q;
        if (!surface_behind_sample(f, sample, is_geometry, q)) continue;
        seen = true;
        if (!is_geometry) continue;
        const float behind = q.z - sample.z;  // > 0: the visible surface is in front of the sample
        if (behind <= 0.0f) continue;
        if (dot(q - p, normal) <= min_height) continue;  // at or below the tangent plane
        blocked = std::max(blocked, thickness_weight(behind, thickness_));
      }
      if (!seen) continue;
      ++valid;
      occlusion += blocked;
    }
    return valid > 0 ? 1.0f - occlusion / float(valid) : 1.0f;
  }

  float radius_, bias_, thickness_;
  int directions_, steps_;
  std::vector<Vec3> offsets_;  // [jitter state][direction][step]
};

}  // namespace

extern const VariantInfo kHemisphereVariant;
const VariantInfo kHemisphereVariant = {
    "hemisphere",
    "normal-oriented hemisphere kernel: directions cosine-weighted about the normal, each "
    "marched in steps",
    "samples|steps|sample_clustering|thickness|bias|seed",
    [](const ParamValues& v, const Frame&) -> std::unique_ptr<Variant> {
      return std::make_unique<Hemisphere>(v);
    }};

}  // namespace ssao
