// SPDX-License-Identifier: MIT
// What the Highway kernels of the variants read from a Frame, in vector form: the packed
// octahedral normals decoded (decode_normal in frame.h) and the view position of a pixel
// (Frame::position). Included inside a kernel file's per-target pass (Highway's -inl.h
// pattern: the guard toggles once per target).
#if defined(SSAO_FRAME_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SSAO_FRAME_SIMD_INL_H_
#undef SSAO_FRAME_SIMD_INL_H_
#else
#define SSAO_FRAME_SIMD_INL_H_
#endif

#include <hwy/highway.h>

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

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#endif  // per-target guard
