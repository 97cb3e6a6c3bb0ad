// SPDX-License-Identifier: MIT
// What the Highway kernels read from a Frame, in vector form: the packed octahedral normals
// decoded (decode_normal in frame.h) and the camera model on lanes (LaneProjection: projection
// and pixel rays). Included inside a kernel file's per-target pass (Highway's -inl.h
// pattern: the guard toggles once per target).
#if defined(SSAO_FRAME_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SSAO_FRAME_SIMD_INL_H_
#undef SSAO_FRAME_SIMD_INL_H_
#else
#define SSAO_FRAME_SIMD_INL_H_
#endif

#include <hwy/highway.h>

#include "camera.h"

HWY_BEFORE_NAMESPACE();
namespace ssao {
namespace HWY_NAMESPACE {

// Directions (not of unit length) from packed snorm16 octahedral coordinates: what a test that
// only compares sides of a plane needs (decode_normal in frame.h without its normalisation).
template <class DF, class VI, class VF = hwy::HWY_NAMESPACE::Vec<DF>>
HWY_INLINE void decode_directions(DF df, VI packed, VF& nx, VF& ny, VF& nz) {
  namespace hn = hwy::HWY_NAMESPACE;
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  const VF scale16 = hn::Set(df, 1.0f / 32767.0f);
  const VF ou = hn::ConvertTo(df, hn::ShiftRight<16>(hn::ShiftLeft<16>(packed))) * scale16;
  const VF ov = hn::ConvertTo(df, hn::ShiftRight<16>(packed)) * scale16;
  nz = one - hn::Abs(ou) - hn::Abs(ov);
  const auto folded = hn::Lt(nz, zero);
  nx = hn::IfThenElse(folded, hn::CopySign(one - hn::Abs(ov), ou), ou);
  ny = hn::IfThenElse(folded, hn::CopySign(one - hn::Abs(ou), ov), ov);
}

// Unit normals from packed snorm16 octahedral coordinates (decode_normal in frame.h).
template <class DF, class VI, class VF = hwy::HWY_NAMESPACE::Vec<DF>>
HWY_INLINE void decode_normals(DF df, VI packed, VF& nx, VF& ny, VF& nz) {
  namespace hn = hwy::HWY_NAMESPACE;
  decode_directions(df, packed, nx, ny, nz);
  const VF inv_length = hn::Set(df, 1.0f) / hn::Sqrt(nx * nx + ny * ny + nz * nz);
  nx = nx * inv_length, ny = ny * inv_length, nz = nz * inv_length;
}

// The camera model on lanes, its constants broadcast once per row: CameraModel::project (the
// call operator) and the rays through pixel centres (pixel_ray).
template <class VF>
struct LaneProjection {
  bool orthographic;
  VF center_u, center_v, inv_scale_u, inv_scale_v, width, height;
  VF scale_u, scale_v, pixel_u0, pixel_v0;
  LaneProjection(const CameraIntrinsics& cam, int width_px, int height_px) {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::DFromV<VF> df;
    orthographic = cam.orthographic;
    center_u = hn::Set(df, cam.center_u), center_v = hn::Set(df, cam.center_v);
    inv_scale_u = hn::Set(df, 1.0f / cam.scale_u), inv_scale_v = hn::Set(df, 1.0f / cam.scale_v);
    width = hn::Set(df, float(width_px)), height = hn::Set(df, float(height_px));
    scale_u = hn::Set(df, cam.scale_u), scale_v = hn::Set(df, cam.scale_v);
    // View x of pixel column qx at unit depth is qx * scale_u + pixel_u0 (its centre), view y
    // of row qy is pixel_v0 - qy * scale_v.
    pixel_u0 = hn::Set(df, (0.5f - cam.center_u) * cam.scale_u);
    pixel_v0 = hn::Set(df, (cam.center_v - 0.5f) * cam.scale_v);
  }
  // View x and y of the centre of pixel (qx, qy) at unit planar depth (perspective: the ray's
  // direction, z = -1) or at any depth (orthographic).
  template <class VI>
  HWY_INLINE void pixel_ray(VI qx, VI qy, VF& x, VF& y) const {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::DFromV<VF> df;
    x = hn::MulAdd(hn::ConvertTo(df, qx), scale_u, pixel_u0);
    y = hn::NegMulAdd(hn::ConvertTo(df, qy), scale_v, pixel_v0);
  }
  // Continuous image coordinates (u, v) of view-space points (x, y, z), and the lanes where they
  // fall inside the image in front of the camera (pixel_of_sample in variant.h).
  HWY_INLINE auto operator()(VF x, VF y, VF z, VF& u, VF& v) const {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::DFromV<VF> df;
    const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
    auto in_image = hn::Gt(hn::Neg(z), zero);
    if (orthographic) {
      u = hn::MulAdd(x, inv_scale_u, center_u);
      v = hn::NegMulAdd(y, inv_scale_v, center_v);
      in_image = hn::Lt(zero, one);  // all true
    } else {
      // 1 / depth: the hardware estimate refined by one Newton step (relative error below
      // 1e-7, as a division's, at a fraction of its cost).
      const VF depth = hn::Neg(z);
      const VF estimate = hn::ApproximateReciprocal(depth);
      const VF inv = estimate * hn::NegMulAdd(depth, estimate, hn::Set(df, 2.0f));
      u = hn::MulAdd(x * inv, inv_scale_u, center_u);
      v = hn::NegMulAdd(y * inv, inv_scale_v, center_v);
    }
    return hn::And(in_image, hn::And(hn::And(hn::Ge(u, zero), hn::Ge(v, zero)),
                                     hn::And(hn::Lt(u, width), hn::Lt(v, height))));
  }
};

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#endif  // per-target guard
