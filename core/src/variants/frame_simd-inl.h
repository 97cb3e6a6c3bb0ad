// SPDX-License-Identifier: MIT
// What the Highway kernels read from a Frame, in vector form: the packed octahedral normals
// decoded (decode_normal in frame.h), the camera model on lanes (LaneProjection: projection
// and pixel rays) and Frame::surface_normal (surface_normal_lanes). Included inside a kernel file's
// per-target pass (Highway's -inl.h pattern: the guard toggles once per target).
#if defined(SSAO_FRAME_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SSAO_FRAME_SIMD_INL_H_
#undef SSAO_FRAME_SIMD_INL_H_
#else
#define SSAO_FRAME_SIMD_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>

#include "camera.h"
#include "frame.h"

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

// thickness_weight (variant.h) on lanes: 1 up to the assumed depth of the solid behind its
// surface, fading to 0 at twice that; `inv_thickness` is 1 / that depth.
template <class VF>
HWY_INLINE VF thickness_weight_lanes(VF depth_behind_surface, VF inv_thickness) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  return hn::Min(
      hn::Set(df, 1.0f),
      hn::Max(hn::Zero(df), hn::NegMulAdd(depth_behind_surface, inv_thickness, hn::Set(df, 2.0f))));
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

// Frame::surface_normal of pixels x .. x + lanes - 1 of row y (the lanes past the row's end are
// background: their normal is kept), from the frame's depth plane `depth` (width x height, at
// least 3 x 3) and packed normals, their depth d, normal n and mixed-normal flags: (gx, gy, gz).
// Most lanes' normals do not tilt across the surface: the first test costs a few operations per
// stretch, on chords written with the middle pixel's ray (no positions).
template <class VF, class M>
HWY_INLINE void surface_normal_lanes(const LaneProjection<VF>& project, const float* depth,
                                     const uint32_t* normals, int width, int height, int x, int y,
                                     VF d, VF nx, VF ny, VF nz, M mixed, VF& gx, VF& gy, VF& gz) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VI = hn::Vec<decltype(di)>;
  const int lanes = int(hn::Lanes(df));
  gx = nx, gy = ny, gz = nz;
  // The stretches along the row and the column, centred on the pixel or, on the frame's border,
  // on its neighbour: depths a, m, b of each, and the indices of their ends.
  const int cy = std::clamp(y, 1, height - 2);
  const VI column = hn::Iota(di, x);
  const VI cx = hn::Min(hn::Max(column, hn::Set(di, 1)), hn::Set(di, width - 2));
  const VI inside_column = hn::Min(column, hn::Set(di, width - 1));
  const bool interior = x >= 1 && x + lanes <= width - 1 && y == cy;
  const VI across_a = hn::Set(di, y * width) + cx - hn::Set(di, 1);
  const VI down_a = hn::Set(di, (cy - 1) * width) + inside_column;
  VF ax_d, mx_d, bx_d, ay_d, my_d, by_d;
  if (interior) {
    const float* at = depth + size_t(y) * width + x;
    ax_d = hn::LoadU(df, at - 1), mx_d = d, bx_d = hn::LoadU(df, at + 1);
    ay_d = hn::LoadU(df, at - width), my_d = d, by_d = hn::LoadU(df, at + width);
  } else {
    ax_d = hn::GatherIndex(df, depth, across_a);
    mx_d = hn::GatherIndex(df, depth, across_a + hn::Set(di, 1));
    bx_d = hn::GatherIndex(df, depth, across_a + hn::Set(di, 2));
    ay_d = hn::GatherIndex(df, depth, down_a);
    my_d = hn::GatherIndex(df, depth, down_a + hn::Set(di, width));
    by_d = hn::GatherIndex(df, depth, down_a + hn::Set(di, 2 * width));
  }
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  // Rays (pixel_ray) through the stretches' middle pixels; the ends' rays are one pixel's step
  // to either side. A point is its ray times its depth at z = -depth (perspective) or its ray
  // at z = -depth (orthographic): the differences below are written in rays and depths.
  VF rx_across, ry_across, rx_down, ry_down;
  project.pixel_ray(cx, hn::Set(di, y), rx_across, ry_across);
  if (interior) {
    rx_down = rx_across, ry_down = ry_across;
  } else {
    project.pixel_ray(inside_column, hn::Set(di, cy), rx_down, ry_down);
  }
  const bool ortho = project.orthographic;
  const VF reach = hn::Set(df, Frame::kStretchFootprints) * project.scale_u * (ortho ? one : d);
  const VF reach2 = reach * reach;
  // tilt_across in frame.cpp, in two parts: first whether n tilts across the chord a -> b
  // (most lanes do not: nothing more is computed), then whether a -> m -> b is straight.
  struct Stretch {
    VF rx, ry, step_x, step_y;  // the middle's ray and the step to b's (a's is minus it)
    VF a_d, m_d;
    VF chord_x, chord_y, chord_z, tilt, ab2, along;
    hn::Mask<decltype(df)> straight, tilts;
  };
  // q - a for a point q whose depth is `delta` more than a's: rx delta + step base, where `base`
  // (a's depth plus q's, or a's) and the ortho base (2 or 1) count the steps from a's ray.
  const auto from_a = [&](const Stretch& s, VF delta, VF base, VF& ox, VF& oy, VF& oz) {
    const VF moved = ortho ? zero : delta;
    ox = hn::MulAdd(s.rx, moved, s.step_x * base), oy = hn::MulAdd(s.ry, moved, s.step_y * base);
    oz = hn::Neg(delta);
  };
  const auto chord = [&](VF rx, VF ry, VF step_x, VF step_y, VF a_d, VF m_d, VF b_d) {
    Stretch s;
    s.rx = rx, s.ry = ry, s.step_x = step_x, s.step_y = step_y;
    s.a_d = a_d, s.m_d = m_d;
    // b - a: b's ray is twice the step from a's (rx - step).
    from_a(s, b_d - a_d, ortho ? hn::Set(df, 2.0f) : b_d + a_d, s.chord_x, s.chord_y, s.chord_z);
    s.tilt = hn::MulAdd(s.chord_x, nx, hn::MulAdd(s.chord_y, ny, s.chord_z * nz));
    s.ab2 =
        hn::MulAdd(s.chord_x, s.chord_x, hn::MulAdd(s.chord_y, s.chord_y, s.chord_z * s.chord_z));
    // A straight stretch's halves are shorter than the reach, so its chord shorter than twice it.
    s.tilts = hn::And(hn::Gt(s.tilt * s.tilt, hn::Set(df, Frame::kSurfaceTiltSin2) * s.ab2),
                      hn::Lt(s.ab2, hn::Set(df, 4.0f) * reach2));
    return s;
  };
  Stretch across = chord(rx_across, ry_across, project.scale_u, zero, ax_d, mx_d, bx_d);
  Stretch down = chord(rx_down, ry_down, zero, hn::Neg(project.scale_v), ay_d, my_d, by_d);
  const auto candidate = hn::AndNot(mixed, hn::Or(across.tilts, down.tilts));
  if (hn::AllFalse(df, candidate)) return;
  const int32_t* packed = reinterpret_cast<const int32_t*>(normals);
  // The ends' packed normals: in the frame's interior, contiguous from the first lane's a (at a
  // pixel's index `first_a`, only valid there).
  const auto end_normals = [&](VI a_index, int b_offset, size_t first_a, VI& na, VI& nb) {
    if (interior) {
      na = hn::LoadU(di, packed + first_a), nb = hn::LoadU(di, packed + first_a + b_offset);
    } else {
      na = hn::GatherIndex(di, packed, a_index);
      nb = hn::GatherIndex(di, packed, a_index + hn::Set(di, b_offset));
    }
  };
  const auto straight = [&](Stretch& s, VI a_index, int b_offset, size_t first_a) {
    // m - a: m's ray is one step from a's.
    VF max_, may, maz;
    from_a(s, s.m_d - s.a_d, ortho ? one : s.a_d, max_, may, maz);
    const VF bmx = s.chord_x - max_, bmy = s.chord_y - may, bmz = s.chord_z - maz;  // b - m
    const VF la2 = max_ * max_ + may * may + maz * maz, lb2 = bmx * bmx + bmy * bmy + bmz * bmz;
    const VF turn = max_ * bmx + may * bmy + maz * bmz;
    const VF longer = hn::Max(la2, lb2), shorter = hn::Min(la2, lb2);
    s.straight =
        hn::And(hn::And(hn::Gt(turn, zero),
                        hn::Gt(turn * turn, hn::Set(df, Frame::kStraightCos2) * la2 * lb2)),
                hn::And(hn::Lt(longer, hn::Set(df, 4.0f) * shorter), hn::Lt(longer, reach2)));
    // The normals at both ends agree: the slow turn of interpolated vertex normals, not a bump.
    VI na, nb;
    end_normals(a_index, b_offset, first_a, na, nb);
    VF anx, any, anz, bnx, bny, bnz;
    decode_normals(df, na, anx, any, anz);
    decode_normals(df, nb, bnx, bny, bnz);
    const auto agree =
        hn::Gt(anx * bnx + any * bny + anz * bnz, hn::Set(df, Frame::kSmoothNormalsCos));
    s.tilts = hn::And(hn::And(s.straight, s.tilts), agree);
    s.along = hn::IfThenElseZero(s.tilts, s.tilt / hn::IfThenElse(s.tilts, s.ab2, one));
  };
  const size_t at = size_t(y) * width + x;
  straight(across, across_a, 2, at - 1);
  straight(down, down_a, 2 * width, at - width);
  const auto tilted = hn::And(candidate, hn::Or(across.tilts, down.tilts));
  if (hn::AllFalse(df, tilted)) return;
  VF tx = nx - across.chord_x * across.along - down.chord_x * down.along;
  VF ty = ny - across.chord_y * across.along - down.chord_y * down.along;
  VF tz = nz - across.chord_z * across.along - down.chord_z * down.along;
  // cross(down.chord, across.chord), turned to n's side.
  VF px = down.chord_y * across.chord_z - down.chord_z * across.chord_y;
  VF py = down.chord_z * across.chord_x - down.chord_x * across.chord_z;
  VF pz = down.chord_x * across.chord_y - down.chord_y * across.chord_x;
  const auto away = hn::Lt(px * nx + py * ny + pz * nz, zero);
  px = hn::IfThenElse(away, hn::Neg(px), px), py = hn::IfThenElse(away, hn::Neg(py), py);
  pz = hn::IfThenElse(away, hn::Neg(pz), pz);
  const auto both = hn::And(across.straight, down.straight);
  tx = hn::IfThenElse(both, px, tx), ty = hn::IfThenElse(both, py, ty);
  tz = hn::IfThenElse(both, pz, tz);
  const VF length2 = tx * tx + ty * ty + tz * tz;
  const auto turned = hn::And(tilted, hn::Gt(length2, zero));
  const VF inv = one / hn::Sqrt(hn::IfThenElse(turned, length2, one));
  gx = hn::IfThenElse(turned, tx * inv, nx), gy = hn::IfThenElse(turned, ty * inv, ny);
  gz = hn::IfThenElse(turned, tz * inv, nz);
}

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#endif  // per-target guard
