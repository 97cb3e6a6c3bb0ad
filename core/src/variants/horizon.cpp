// SPDX-License-Identifier: MIT
// Horizon-based AO (GTAO, Jimenez et al. 2016) with a visibility bitmask per slice (Therrien et
// al. 2023) in place of the two horizon angles, so thin occluders do not hide what lies behind.
//
// Each pixel walks `slices` screen-space lines through itself, `steps` samples on each side.
// In the plane of a slice (the view vector and the line), directions are angles beta from the
// normal's projection; the hemisphere is beta in [-pi/2, pi/2], cut into 32 equal sectors. A
// sample is a segment from the visible surface to `thickness` behind it; the sectors it spans
// are occluded. The slice's visibility is the cosine-weighted measure of the free sectors,
//   integral of cos(beta) * |sin(beta + gamma)| d beta,
// (gamma: the projected normal's angle from the view vector; |sin| is the Jacobian of slicing
// the hemisphere about the view vector), which has a closed form at the sector boundaries, so
// runs of occluded sectors cost a few multiplies. Slices are weighted by the projected normal's
// length; the ratio to the unoccluded measure makes a free surface exactly 1 for any normal.
// Consecutive points of a side whose depths differ by less than the thickness are taken as one
// surface and occlude the sectors between them; the chain starts at the receiver, so a contact
// crease is occluded down to the tangent plane however coarse the steps.
#include <algorithm>
#include <array>
#include <cmath>

#include "portable_math.h"
#include "sampling.h"
#include "variant.h"

namespace ssao {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr int kSectors = 32;
// An open surface (a card: a front face followed by another front face) is this fraction of the
// assumed thickness deep.
constexpr float kCardThickness = 0.1f;

// atan(z) for |z| <= 1, error below 2e-6 rad (minimax polynomial in z^2).
inline float atan_unit(float z) {
  const float z2 = z * z;
  return z *
         (0.99997726f +
          z2 * (-0.33262347f +
                z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f - z2 * 0.01172120f)))));
}

// atan2(y, x) from the polynomial: no libm call on the per-sample path.
inline float fast_atan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  float r = hi > 0.0f ? atan_unit(lo / hi) : 0.0f;
  if (ay > ax) r = 0.5f * kPi - r;
  if (x < 0.0f) r = kPi - r;
  return std::copysign(r, y);
}

// Antiderivative of cos(t) * sin(t + gamma) at a sector boundary t_k, as A_k cos(gamma) +
// B_k sin(gamma): -cos(2t + gamma) / 4 + t sin(gamma) / 2.
struct BoundaryTerms {
  std::array<float, kSectors + 1> a, b;
  BoundaryTerms() {
    for (int k = 0; k <= kSectors; ++k) {
      const double t = -0.5 * M_PI + M_PI * k / kSectors;
      a[k] = float(-0.25 * std::cos(2.0 * t));
      b[k] = float(0.25 * std::sin(2.0 * t) + 0.5 * t);
    }
  }
};

class Horizon final : public Variant {
 public:
  explicit Horizon(const ParamValues& v) {
    static constexpr int kSlices[4] = {2, 3, 4, 8};
    static constexpr int kSteps[4] = {4, 6, 8, 12};
    radius_ = float(v.get_float("radius"));
    bias_ = float(v.get_float("bias"));
    thickness_ = float(v.get_float("thickness")) * radius_;
    slices_ = count_or_preset(v, "slices", kSlices);
    steps_ = count_or_preset(v, "steps", kSteps);
    const auto states = jitter_states(uint32_t(v.get_int("seed")));
    // Per jitter state: each slice's line direction in pixels, and each step's distance as a
    // fraction of the projected radius (quadratic: occluders near the receiver matter most).
    lines_.resize(size_t(kJitterStates) * slices_);
    step_fractions_.resize(size_t(kJitterStates) * steps_);
    for (int j = 0; j < kJitterStates; ++j) {
      for (int s = 0; s < slices_; ++s) {
        const float angle = kPi * (float(s) + states[j].angle) / float(slices_);
        lines_[size_t(j) * slices_ + s] = {portable_cos(angle), portable_sin(angle)};
      }
      for (int k = 0; k < steps_; ++k) {
        const float f = (float(k) + states[j].radial_offset) / float(steps_);
        step_fractions_[size_t(j) * steps_ + k] = f * f;
      }
    }
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    estimate_receivers(f, t, radius_, visibility, [&](int x, int y) { return pixel(f, x, y); });
  }

 private:
  struct Line {
    float cos_angle, sin_angle;
  };

  float pixel(const Frame& f, int x, int y) const {
    const CameraModel& cam = f.camera();
    const float depth = f.depth(x, y);
    const Vec3 p = f.position(x, y);
    const Vec3 n = f.normal(x, y);
    const Vec3 view = cam.towards_camera(p);
    const float min_height = bias_ * radius_ + cam.pixel_footprint(depth);
    // The radius in pixels along u and v (they differ with a non-square pixel aspect).
    const float footprint = cam.pixel_footprint(depth);
    const float radius_u = radius_ / footprint;
    const float radius_v = radius_ / (footprint * cam.pixel_aspect());
    const float radius2 = radius_ * radius_;
    const int j = jitter_index(x, y);
    const Line* line = lines_.data() + size_t(j) * slices_;
    const float* fractions = step_fractions_.data() + size_t(j) * steps_;
    const float u0 = float(x) + 0.5f, v0 = float(y) + 0.5f;
    const bool layered = f.extra_layers() > 0;

    float visible_sum = 0.0f, total_sum = 0.0f;
    for (int s = 0; s < slices_; ++s) {
      // The slice plane holds the view vector and the line's direction in view space.
      const Vec3 along_line{line[s].cos_angle, -line[s].sin_angle * cam.pixel_aspect(), 0.0f};
      const Vec3 axis = normalize_or(along_line - view * dot(along_line, view), {1, 0, 0});
      const Vec3 slice_normal = cross(axis, view);
      const Vec3 projected = n - slice_normal * dot(n, slice_normal);
      const float projected_length = length(projected);
      if (!(projected_length > 1e-6f)) continue;
      // In-plane frame: e_n along the projected normal, e_t perpendicular, towards +axis.
      const Vec3 e_n = projected * (1.0f / projected_length);
      const float cos_gamma = dot(e_n, view), sin_gamma = dot(e_n, axis);
      const Vec3 e_t = axis * cos_gamma - view * sin_gamma;

      // Pixel step of the whole radius along this line, and the first step's minimum of one
      // pixel along the line's major axis, so no sample reads the receiver itself.
      const float du = line[s].cos_angle * radius_u, dv = line[s].sin_angle * radius_v;
      const float major = std::max(std::fabs(du), std::fabs(dv));
      const float min_fraction = 1.0f / major;

      uint32_t occluded = 0;
      for (int side = -1; side <= 1; side += 2) {
        // The previous point on this side, to join to the next one when both lie on one
        // surface; the chain starts at the receiver, on its tangent plane.
        bool chained = true;
        float previous_beta = 0.5f * kPi * float(side), previous_depth = depth;
        for (int k = 0; k < steps_; ++k) {
          const float fraction = std::max(fractions[k], min_fraction) * float(side);
          const float su = u0 + fraction * du, sv = v0 + fraction * dv;
          if (!(su >= 0.0f && sv >= 0.0f && su < float(f.width()) && sv < float(f.height()))) {
            break;  // the rest of this side is outside the image too
          }
          const int qx = int(su), qy = int(sv);
          const float qd = f.depth(qx, qy);
          chained = chained && std::fabs(qd - previous_depth) < thickness_;
          if (qd == Frame::kBackground) continue;
          const Vec3 q = cam.view_position(float(qx) + 0.5f, float(qy) + 0.5f, qd);
          const Vec3 front = q - p;
          if (layered) occluded |= solid_sectors(f, qx, qy, p, n, min_height, e_n, e_t);
          if (dot(front, front) > radius2) {
            chained = false;
            continue;
          }
          const float beta_front = fast_atan2(dot(front, e_t), dot(front, e_n));
          const bool occluder = dot(front, n) > min_height;  // above the receiver's surface
          // Two points on one surface (depths within the thickness) occlude what lies between.
          if (chained && occluder) occluded |= sector_mask(previous_beta, beta_front);
          chained = true;
          previous_beta = beta_front;
          previous_depth = qd;
          if (!occluder || layered) continue;
          // The occluder is assumed `thickness` deep along the ray through q.
          const Vec3 back = front - cam.towards_camera(q) * thickness_;
          occluded |= sector_mask(beta_front, fast_atan2(dot(back, e_t), dot(back, e_n)));
        }
      }
      const float total = cos_gamma + portable_atan2(sin_gamma, cos_gamma) * sin_gamma;
      const float blocked = occluded_measure(occluded, cos_gamma, sin_gamma);
      visible_sum += projected_length * (total - blocked);
      total_sum += projected_length * total;
    }
    return total_sum > 0.0f ? saturate(visible_sum / total_sum) : 1.0f;
  }

  // With extra depth layers: the sectors covered by the solids that pixel (qx, qy)'s ray crosses,
  // each the stretch of the ray from a front face to the back face that closes it, cut to the
  // sphere of `radius` around p. A front face followed by another front face is an open surface
  // (a card), taken as thin; a front face that nothing closes is as deep as the frame measured
  // it beside the foreground (Frame::last_thickness), else `thickness`.
  uint32_t solid_sectors(const Frame& f, int qx, int qy, Vec3 p, Vec3 n, float min_height, Vec3 e_n,
                         Vec3 e_t) const {
    const CameraModel& cam = f.camera();
    const float u = float(qx) + 0.5f, v = float(qy) + 0.5f;
    uint32_t bits = 0;
    const auto add = [&](float near_depth, float far_depth) {
      Vec3 a = cam.view_position(u, v, near_depth) - p;
      Vec3 b = cam.view_position(u, v, far_depth) - p;
      // Cut the segment a..b to |x| <= radius: t^2 |d|^2 + 2 t a.d + |a|^2 - r^2 = 0.
      const Vec3 d = b - a;
      const float dd = dot(d, d), ad = dot(a, d), c = dot(a, a) - radius_ * radius_;
      const float disc = ad * ad - dd * c;
      if (!(disc > 0.0f) || !(dd > 0.0f)) return;
      const float root = std::sqrt(disc);
      const float t0 = std::max(0.0f, (-ad - root) / dd), t1 = std::min(1.0f, (-ad + root) / dd);
      if (!(t0 < t1)) return;
      const Vec3 a_cut = a + d * t0, b_cut = a + d * t1;
      if (dot(a_cut, n) <= min_height && dot(b_cut, n) <= min_height) return;
      bits |= sector_mask(fast_atan2(dot(a_cut, e_t), dot(a_cut, e_n)),
                          fast_atan2(dot(b_cut, e_t), dot(b_cut, e_n)));
    };
    const size_t index = f.index(qx, qy);
    const float* layers = f.layer_planes();
    float entry = f.depth(qx, qy);
    bool inside = true;  // the visible surface is taken as a front face
    for (int k = 0; k < f.extra_layers(); ++k) {
      const float hit = layers[size_t(k) * f.pixel_count() + index];
      if (hit == Frame::kBackground) break;
      const float depth = std::fabs(hit);
      const bool back = hit < 0.0f;
      if (inside && back) {
        add(entry, depth);
        inside = false;
      } else if (inside) {  // an open surface at `entry`: thin
        add(entry, entry + kCardThickness * thickness_);
        entry = depth;
      } else if (!back) {
        entry = depth;
        inside = true;
      }
    }
    if (inside) {  // nothing closes the last front face: its measured depth, else assumed
      const float measured = f.last_thickness(qx, qy);
      add(entry, entry + (measured > 0.0f ? measured : thickness_));
    }
    return bits;
  }

  // Sectors between two angles (either order), each clamped to the hemisphere; a sector counts
  // when the segment covers its centre.
  static uint32_t sector_mask(float beta_a, float beta_b) {
    const float scale = float(kSectors) / kPi;
    const float lo =
        std::clamp((std::min(beta_a, beta_b) + 0.5f * kPi) * scale, 0.0f, float(kSectors));
    const float hi =
        std::clamp((std::max(beta_a, beta_b) + 0.5f * kPi) * scale, 0.0f, float(kSectors));
    const int first = int(lo), end = int(std::ceil(hi));
    if (end <= first) return 0;
    const uint64_t run = ((uint64_t(1) << (end - first)) - 1) << first;
    return uint32_t(run);
  }

  // Cosine-weighted measure of the occluded sectors: sum over runs of set bits of the closed
  // form, with the sign of sin(beta + gamma) flipping at beta = -gamma.
  float occluded_measure(uint32_t bits, float cos_gamma, float sin_gamma) const {
    if (bits == 0) return 0.0f;
    const float gamma = portable_atan2(sin_gamma, cos_gamma);
    const float split_beta = -gamma;
    const float split_value = -0.25f * cos_gamma - 0.5f * gamma * sin_gamma;
    const float sector = kPi / float(kSectors);
    float measure = 0.0f;
    while (bits != 0) {
      const int first = __builtin_ctz(bits);
      const uint32_t shifted = bits >> first;
      const int count = shifted == 0xffffffffu ? 32 : __builtin_ctz(~shifted);
      const int end = first + count;
      bits &= ~uint32_t(((uint64_t(1) << count) - 1) << first);
      const float value_a = terms_.a[first] * cos_gamma + terms_.b[first] * sin_gamma;
      const float value_b = terms_.a[end] * cos_gamma + terms_.b[end] * sin_gamma;
      const float beta_a = -0.5f * kPi + float(first) * sector;
      const float beta_b = -0.5f * kPi + float(end) * sector;
      if (beta_a >= split_beta) {
        measure += value_b - value_a;
      } else if (beta_b <= split_beta) {
        measure += value_a - value_b;
      } else {
        measure += value_a + value_b - 2.0f * split_value;
      }
    }
    return measure;
  }

  float radius_, bias_, thickness_;
  int slices_, steps_;
  std::vector<Line> lines_;            // [jitter state][slice]
  std::vector<float> step_fractions_;  // [jitter state][step]
  BoundaryTerms terms_;
};

}  // namespace

extern const VariantInfo kHorizonVariant;
const VariantInfo kHorizonVariant = {
    "horizon",
    "horizon-based (GTAO) slices with a visibility bitmask: cosine-weighted like Cycles' AO, "
    "thin occluders do not hide what is behind them; kept for comparison (slower and, but for "
    "thin occluders, less accurate than hemisphere: docs/variants.md)",
    "slices|steps|thickness|bias|seed",
    [](const ParamValues& v, const Frame&) -> std::unique_ptr<Variant> {
      return std::make_unique<Horizon>(v);
    },
    kSolidThickness};

}  // namespace ssao
