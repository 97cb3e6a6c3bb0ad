// SPDX-License-Identifier: MIT
// Crysis sphere kernel (Mittring 2007, seed 000): depth only, samples in a full sphere around the
// point. Antipodal sample pairs make a flat surface read exactly half occluded; the normalized
// mode maps that half to 1.
#include <algorithm>

#include "sampling.h"
#include "variant.h"

namespace ssao {
namespace {

class Sphere final : public Variant {
 public:
  explicit Sphere(const ParamValues& v) {
    static constexpr int kSamples[4] = {8, 16, 32, 64};
    radius_ = float(v.get_float("radius"));
    bias_ = float(v.get_float("bias"));
    normalized_ = v.get_string("sphere_mode") == "normalized";
    const Kernel kernel = make_sphere_kernel(count_or_preset(v, "samples", kSamples));
    pairs_ = int(kernel.directions.size()) / 2;
    const float clustering = float(v.get_float("sample_clustering"));
    const auto states = jitter_states(uint32_t(v.get_int("seed")));
    // Per jitter state, both points of every pair, rotated about the view axis (the sphere has
    // no preferred tangent frame) and scaled to their radius.
    offsets_.resize(size_t(kJitterStates) * pairs_ * 2);
    for (int j = 0; j < kJitterStates; ++j) {
      const JitterState& js = states[j];
      for (int k = 0; k < 2 * pairs_; ++k) {
        const Vec3 d0 = kernel.directions[k];
        const Vec3 d{d0.x * js.cos_angle - d0.y * js.sin_angle,
                     d0.x * js.sin_angle + d0.y * js.cos_angle, d0.z};
        const float r =
            radius_ *
            radial_scale((float(kernel.stratum[k]) + js.radial_offset) / float(pairs_), clustering);
        offsets_[size_t(j) * pairs_ * 2 + k] = d * r;
      }
    }
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    estimate_receivers(f, t, radius_, visibility, [&](int x, int y) { return pixel(f, x, y); });
  }

 private:
  float pixel(const Frame& f, int x, int y) const {
    const Vec3 p = f.position(x, y);
    // Depth-aware margin against self-occlusion: half a pixel footprint times the surface slope
    // (how far snapping a sample to its pixel centre can move the depth), plus the bias.
    const Vec3 normal = f.normal(x, y);
    const float cos_view = std::max(0.25f, dot(normal, f.camera().towards_camera(p)));
    const float slope = std::sqrt(1.0f - cos_view * cos_view) / cos_view;
    const float min_behind = bias_ * radius_ + 0.5f * f.camera().pixel_footprint(-p.z) * slope;
    const Vec3* offset = offsets_.data() + size_t(jitter_index(x, y)) * pairs_ * 2;

    float occlusion = 0.0f;
    int valid = 0;
    for (int k = 0; k < pairs_; ++k, offset += 2) {
      // A pair counts only when both of its points land in the image, keeping flat surfaces at
      // exactly one half near the borders too.
      float pair_occlusion = 0.0f;
      bool pair_valid = true;
      for (int member = 0; member < 2 && pair_valid; ++member) {
        const Vec3 sample = p + offset[member];
        bool is_geometry = false;
        Vec3 q;
        pair_valid = surface_behind_sample(f, sample, is_geometry, q);
        if (!pair_valid || !is_geometry) continue;
        const float behind = q.z - sample.z;
        if (behind <= min_behind) continue;
        // The classic range check: occluders count within one radius of depth difference.
        pair_occlusion += thickness_weight(behind, radius_);
      }
      if (!pair_valid) continue;
      valid += 2;
      occlusion += pair_occlusion;
    }
    if (valid == 0) return 1.0f;
    const float v = 1.0f - occlusion / float(valid);
    return normalized_ ? std::min(1.0f, 2.0f * v) : v;
  }

  float radius_, bias_;
  bool normalized_;
  int pairs_;
  std::vector<Vec3> offsets_;  // [jitter state][pair][member]
};

}  // namespace

extern const VariantInfo kSphereVariant;
const VariantInfo kSphereVariant = {
    "sphere", "Crysis sphere kernel: points in a sphere around the receiver, depth only",
    "samples|sample_clustering|sphere_mode|bias|seed",
    [](const ParamValues& v, const Frame&) -> std::unique_ptr<Variant> {
      return std::make_unique<Sphere>(v);
    },
    0u};

}  // namespace ssao
