// SPDX-License-Identifier: MIT
// Normal-oriented hemisphere (Chapman's SSAO tutorial, seed 002/003), with cosine-weighted
// directions, a tangent-plane bias so flat and convex surfaces never occlude themselves, and a
// thickness range check against halos.
//
// Two implementations of one estimator: `pixel()`, scalar, the reference the tests hold the
// fast path to; and `hemisphere_row()`, the same arithmetic on as many pixels of a row at once
// as the CPU's vectors hold (Google Highway: SSE4, AVX2 or AVX-512 chosen at run time). This
// file is compiled once per SIMD target (Highway's foreach_target); everything outside the
// per-target namespace is inside HWY_ONCE.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "variants/hemisphere.cpp"
#include <hwy/foreach_target.h>  // re-includes this file once per target
#include <hwy/highway.h>

#include "variants/frame_simd-inl.h"

#ifndef SSAO_HEMISPHERE_ROW_ARGS
#define SSAO_HEMISPHERE_ROW_ARGS
#include <algorithm>
#include <cstdint>
#include <limits>

#include "camera.h"
#include "frame.h"
#include "sampling.h"
#include "variants/lane_table.h"

namespace ssao {
struct HemisphereRowArgs {
  const float* depth;                 // the frame's depth plane
  const uint32_t* normals;            // the frame's packed normals
  const uint8_t* mixed_normals;       // Frame::mixed_normal_plane
  const float* layers;                // the frame's extra depth layers (Frame::layer_planes)
  const float* last_thickness;        // Frame::last_thickness_plane
  const float* plane_distance_scale;  // Frame::plane_distance_scale_plane
  const float* carried_depth;         // Frame::carried_depth_plane (null: none)
  const uint32_t* carried_normals;    // Frame::carried_normal_plane
  int extra_layers;
  bool surface_normals;  // the tangent-plane tests use Frame::surface_normal (else the normal)
  int width, height;
  CameraIntrinsics camera;
  float radius, min_height_bias, thickness, crossing_tolerance;
  size_t plane;  // floats per layer plane
  int directions, steps;
  // Per row class (y & 3), per sample, x/y/z of the tangent-frame offset for kLaneTable lanes
  // starting at a pixel whose x is a multiple of 4.
  const float* lane_offsets;
  // With extra layers, the same layout of each sample's cone (Hemisphere::Cone): 0.5 / its
  // width, how far the direction goes on past it for each unit from the step before, and 0.5 /
  // the width at the point halfway from the step before.
  const float* lane_cones;
  float half_inv_end_width;  // 0.5 / the cone's width at the radius
};

// A surface the crossing test finds at the crossing point, up to its tolerance behind the crossed
// plane, is that plane's own surface when its normal lies within 60 degrees of the plane's.
constexpr float kSamePlaneCos = 0.5f;
// Hemisphere::between: a solid at the halfway point's pixel thinner along the ray than this many
// times the distance between the two steps may lie anywhere between them (the crossing test).
// At 1 x the kit's 6 scenes lost 0.0008 of RMSE on `thin` against 2 x, the rest within 0.0003.
constexpr float kThinSolidSegments = 2.0f;
}  // namespace ssao
#endif

HWY_BEFORE_NAMESPACE();
namespace ssao {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Whether the packed normals at `index` lie within 60 degrees of direction (cx, cy, cz), whose
// squared length is cc (kSamePlaneCos).
template <class VF, class VI>
HWY_INLINE auto normal_agrees_lanes(const HemisphereRowArgs& a, VI index, VF cx, VF cy, VF cz,
                                    VF cc) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  VF nx, ny, nz;
  decode_directions(df, hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index), nx,
                    ny, nz);
  const VF along = hn::MulAdd(nx, cx, hn::MulAdd(ny, cy, nz * cz));
  const VF nn = hn::MulAdd(nx, nx, hn::MulAdd(ny, ny, nz * nz));
  return hn::And(hn::Gt(along, hn::Zero(df)),
                 hn::Gt(along * along, hn::Set(df, kSamePlaneCos * kSamePlaneCos) * nn * cc));
}

// Hemisphere::shows_plane on the lanes of `candidate`: where the depth image shows the plane
// dot(x, c) = w, or something in front of it, at the pixel of point (px, py, pz).
template <class M, class VF>
HWY_INLINE M plane_shown_lanes(const HemisphereRowArgs& a, const LaneProjection<VF>& project,
                               M candidate, VF px, VF py, VF pz, VF cx, VF cy, VF cz, VF w) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VI = hn::Vec<decltype(di)>;
  const CameraIntrinsics& cam = a.camera;
  const VF one = hn::Set(df, 1.0f), zero = hn::Zero(df);
  const VF tolerance = hn::Set(df, a.crossing_tolerance);
  VF cu, cv;
  const auto lanes = hn::And(candidate, project(px, py, pz, cu, cv));
  if (hn::AllFalse(df, lanes)) return lanes;
  const VI qx = hn::ConvertTo(di, hn::IfThenElseZero(lanes, cu));
  const VI qy = hn::ConvertTo(di, hn::IfThenElseZero(lanes, cv));
  // (qx, qy) are 0 on lanes outside the image: every index is in the plane.
  // The plane meets the ray through pixel (x, y)'s centre, origin o + depth * direction r, at
  // depth numerator / slope. Returns (depth - numerator / slope) * |slope|: how far the surface
  // at `depth` lies behind the plane, times |slope|.
  const auto behind_plane = [&](VI x, VI y, VF depth, VF& abs_slope) {
    VF u, v;
    project.pixel_ray(x, y, u, v);
    VF numerator = w, slope = hn::Neg(cz);  // orthographic: o = (u, v, 0), r = (0, 0, -1)
    if (cam.orthographic) {
      numerator = w - hn::MulAdd(u, cx, v * cy);
    } else {  // o = 0, r = (u, v, -1)
      slope = hn::MulAdd(u, cx, hn::MulSub(v, cy, cz));
    }
    abs_slope = hn::Abs(slope);
    return hn::NegMulAdd(numerator, hn::CopySign(one, slope), depth * abs_slope);
  };
  const VI index = qy * hn::Set(di, a.width) + qx;
  VF abs_slope;
  const VF behind = behind_plane(qx, qy, hn::GatherIndex(df, a.depth, index), abs_slope);
  const auto shown = hn::And(hn::And(lanes, hn::Gt(abs_slope, hn::Set(df, 1e-6f))),
                             hn::Le(behind, tolerance * abs_slope));
  // A surface just behind the plane may be another one that meets the plane there (the floor
  // where a box's side, carried on past the box, would meet it): it is the plane's own where its
  // normal agrees, or where a neighbouring pixel shows the plane with such a normal.
  auto unsure = hn::And(shown, hn::Gt(behind, zero));
  if (hn::AllFalse(df, unsure)) return shown;
  const VF cc = hn::MulAdd(cx, cx, hn::MulAdd(cy, cy, cz * cz));
  unsure = hn::AndNot(normal_agrees_lanes(a, index, cx, cy, cz, cc), unsure);
  if (hn::AllFalse(df, unsure)) return shown;
  auto found = hn::Lt(one, zero);  // all false
  const VI last_x = hn::Set(di, a.width - 1), last_y = hn::Set(di, a.height - 1);
  for (const auto& step : kFourNeighbours) {
    const VI nx = hn::Min(hn::Max(qx + hn::Set(di, step[0]), hn::Zero(di)), last_x);
    const VI ny = hn::Min(hn::Max(qy + hn::Set(di, step[1]), hn::Zero(di)), last_y);
    const VI neighbour =
        hn::IfThenElseZero(hn::RebindMask(di, unsure), ny * hn::Set(di, a.width) + nx);
    VF neighbour_slope;
    const VF off = behind_plane(nx, ny, hn::GatherIndex(df, a.depth, neighbour), neighbour_slope);
    const auto on_plane = hn::And(hn::And(unsure, hn::Gt(neighbour_slope, hn::Set(df, 1e-6f))),
                                  hn::Le(hn::Abs(off), tolerance * neighbour_slope));
    if (hn::AllFalse(df, on_plane)) continue;
    found = hn::Or(found, hn::And(on_plane, normal_agrees_lanes(a, neighbour, cx, cy, cz, cc)));
  }
  return hn::AndNot(hn::AndNot(found, unsure), shown);
}

// Hemisphere::sides_differ on lanes: points a and b lie on either side of the plane
// dot(x, c) = w (c of any length).
template <class VF>
HWY_INLINE auto sides_differ_lanes(VF ax, VF ay, VF az, VF bx, VF by, VF bz, VF cx, VF cy, VF cz,
                                   VF w) {
  namespace hn = hwy::HWY_NAMESPACE;
  return hn::Xor(hn::Gt(hn::MulAdd(ax, cx, hn::MulAdd(ay, cy, az * cz)), w),
                 hn::Gt(hn::MulAdd(bx, cx, hn::MulAdd(by, cy, bz * cz)), w));
}

// Hemisphere::end_part on lanes: the part of a direction's cone at the radius past a plane,
// from how far the direction's end lies past it (negative: short of it); not clamped.
template <class VF>
HWY_INLINE VF end_part_lanes(const HemisphereRowArgs& a, VF past) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  return hn::MulAdd(past, hn::Set(df, a.half_inv_end_width), hn::Set(df, 0.5f));
}

// Hemisphere::covered on lanes: the part of a sample's cone behind a surface's plane, from how
// far behind it the sample lies (negative: in front); not clamped.
template <class VF>
HWY_INLINE VF cone_part_lanes(VF behind, VF half_inv_width) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  return hn::MulAdd(behind, half_inv_width, hn::Set(df, 0.5f));
}

// Hemisphere::crossing on the lanes of `candidate`, whose points a and b lie on either side of
// the plane dot(x, c) = w: where the depth image shows the plane, or something in front of it,
// at the point where the segment meets the plane, the part of the direction's cone past the
// plane at the radius (`extend`: the direction's length beyond b over b - a).
template <class M, class VF>
HWY_INLINE VF crossing_lanes(const HemisphereRowArgs& a, const LaneProjection<VF>& project,
                             M candidate, VF ax, VF ay, VF az, VF bx, VF by, VF bz, VF cx, VF cy,
                             VF cz, VF w, VF extend) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF side_a = hn::MulAdd(ax, cx, hn::MulAdd(ay, cy, az * cz)) - w;
  const VF side_b = hn::MulAdd(bx, cx, hn::MulAdd(by, cy, bz * cz)) - w;
  // t = side_a / (side_a - side_b) in (0, 1]: a reciprocal estimate refined by a Newton step.
  const VF span = hn::IfThenElse(candidate, side_a - side_b, one);
  const VF estimate = hn::ApproximateReciprocal(span);
  const VF t = side_a * (estimate * hn::NegMulAdd(span, estimate, hn::Set(df, 2.0f)));
  const VF px = hn::MulAdd(bx - ax, t, ax), py = hn::MulAdd(by - ay, t, ay),
           pz = hn::MulAdd(bz - az, t, az);
  const auto on_surface = plane_shown_lanes(a, project, candidate, px, py, pz, cx, cy, cz, w);
  if (hn::AllFalse(df, on_surface)) return zero;
  const VF past_end = hn::MulAdd(hn::Abs(side_a) + hn::Abs(side_b), extend, hn::Abs(side_b)) /
                      hn::Sqrt(hn::MulAdd(cx, cx, hn::MulAdd(cy, cy, cz * cz)));
  return hn::IfThenElseZero(on_surface, hn::Min(one, end_part_lanes(a, past_end)));
}

// Hemisphere::reach on the lanes of `candidate`: the last sample b lies in front of the plane
// dot(x, c) = w of the surface its pixel shows, and the direction goes on past b to its end e
// at the radius: the part of the cone's end past that plane, where the depth image shows the
// plane at the point where the direction meets it (or at its end, if short of it).
template <class M, class VF>
HWY_INLINE VF reach_lanes(const HemisphereRowArgs& a, const LaneProjection<VF>& project,
                          M candidate, VF bx, VF by, VF bz, VF ex, VF ey, VF ez, VF cx, VF cy,
                          VF cz, VF w) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF side_b = hn::MulAdd(bx, cx, hn::MulAdd(by, cy, bz * cz)) - w;
  const VF side_e = hn::MulAdd(ex, cx, hn::MulAdd(ey, cy, ez * cz)) - w;
  const VF inv_length = one / hn::Sqrt(hn::MulAdd(cx, cx, hn::MulAdd(cy, cy, cz * cz)));
  const VF part = end_part_lanes(a, hn::Neg(side_e * inv_length));
  const auto lanes = hn::And(candidate, hn::And(hn::Gt(side_b, zero), hn::Gt(part, zero)));
  if (hn::AllFalse(df, lanes)) return zero;
  const auto short_of = hn::Ge(side_e, zero);
  const VF t =
      hn::IfThenElse(short_of, one, side_b / hn::IfThenElse(short_of, one, side_b - side_e));
  const VF px = hn::MulAdd(ex - bx, t, bx), py = hn::MulAdd(ey - by, t, by),
           pz = hn::MulAdd(ez - bz, t, bz);
  const auto on_surface = plane_shown_lanes(a, project, lanes, px, py, pz, cx, cy, cz, w);
  return hn::IfThenElseZero(on_surface, hn::Min(one, part));
}

// Hemisphere::between on the lanes of `candidate`: the point halfway between two steps of a
// direction, (ax, ay, az) and (bx, by, bz), where the visible surface of its pixel is above the
// receiver's tangent plane (normal g, level `plane_level`): where the point lies behind that
// surface and in front of the ray's next hit, the part of its cone behind it or, if more, of the
// cone at the direction's end (ex, ey, ez) past its tangent plane, times the solid's weight (1
// where the next hit is a back face, else by the assumed thickness); where the ray's hits make a
// solid thinner along the ray than kThinSolidSegments x the segment, the crossing test with the
// surface's plane (`extend`: the direction's length beyond b over b - a).
template <class M, class VF>
HWY_INLINE VF between_lanes(const HemisphereRowArgs& a, const LaneProjection<VF>& project,
                            M candidate, VF ax, VF ay, VF az, VF bx, VF by, VF bz, VF ex, VF ey,
                            VF ez, VF gx, VF gy, VF gz, VF plane_level, VF half_inv_width,
                            VF extend) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f);
  const VF mx = (ax + bx) * half, my = (ay + by) * half, mz = (az + bz) * half;
  VF mu, mv;
  const auto lanes = hn::And(candidate, project(mx, my, mz, mu, mv));
  if (hn::AllFalse(df, lanes)) return zero;
  const auto qx = hn::ConvertTo(di, hn::IfThenElseZero(lanes, mu));
  const auto qy = hn::ConvertTo(di, hn::IfThenElseZero(lanes, mv));
  const auto index = qy * hn::Set(di, a.width) + qx;
  const VF qd = hn::GatherIndex(df, a.depth, index);
  VF ray_x, ray_y;
  project.pixel_ray(qx, qy, ray_x, ray_y);
  const VF q_scale = a.camera.orthographic ? one : qd;
  const VF qxv = ray_x * q_scale, qyv = ray_y * q_scale, qzv = hn::Neg(qd);
  const auto above =
      hn::And(hn::And(lanes, hn::Lt(qd, hn::Set(df, std::numeric_limits<float>::infinity()))),
              hn::Gt(hn::MulAdd(qxv, gx, hn::MulAdd(qyv, gy, qzv * gz)), plane_level));
  if (hn::AllFalse(df, above)) return zero;
  const VF next = hn::GatherIndex(df, a.layers, index);
  const VF behind = hn::Neg(mz) - qd;  // > 0: the visible surface is in front of the point
  const auto inside =
      hn::And(hn::And(above, hn::Gt(behind, zero)), hn::Le(hn::Neg(mz), hn::Abs(next)));
  const VF bax = bx - ax, bay = by - ay, baz = bz - az;
  const VF segment = hn::Sqrt(hn::MulAdd(bax, bax, hn::MulAdd(bay, bay, baz * baz)));
  const auto thin =
      hn::And(above, hn::Lt(hn::Abs(next) - qd, hn::Set(df, kThinSolidSegments) * segment));
  if (hn::AllFalse(df, hn::Or(inside, thin))) return zero;
  VF cx, cy, cz;
  decode_directions(df, hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index), cx,
                    cy, cz);
  VF weight = zero;
  if (!hn::AllFalse(df, inside)) {
    const VF scale = hn::GatherIndex(df, a.plane_distance_scale, index);
    const VF side_e = hn::MulAdd(ex - qxv, cx, hn::MulAdd(ey - qyv, cy, (ez - qzv) * cz));
    const VF past_end = hn::Neg(side_e) / hn::Sqrt(hn::MulAdd(cx, cx, hn::MulAdd(cy, cy, cz * cz)));
    const VF covered =
        hn::Min(one, hn::Max(zero, hn::Max(cone_part_lanes(behind * scale, half_inv_width),
                                           end_part_lanes(a, past_end))));
    const VF thick = thickness_weight_lanes(behind, hn::Set(df, 1.0f / a.thickness));
    weight = hn::IfThenElseZero(inside, covered * hn::IfThenElse(hn::Lt(next, zero), one, thick));
  }
  // The crossing test where a and b lie on either side of the thin solid's plane.
  const VF w = hn::MulAdd(qxv, cx, hn::MulAdd(qyv, cy, qzv * cz));
  const auto crosses = hn::And(hn::And(thin, hn::Lt(weight, one)),
                               sides_differ_lanes(ax, ay, az, bx, by, bz, cx, cy, cz, w));
  if (hn::AllFalse(df, crosses)) return weight;
  return hn::Max(
      weight, crossing_lanes(a, project, crosses, ax, ay, az, bx, by, bz, cx, cy, cz, w, extend));
}

// Without extra layers: 1 / the depth of the visible surface's solid at pixel `index` (point q)
// for the receiver p: the frame's (Frame::last_thickness_seen_from, with kAssumedThickness: the
// assumed thickness as the silhouettes shape it, or a bound where less; a side-face bound, stored
// negated, holds for a receiver behind the face's tangent plane only), else the assumed one. Read
// on the lanes `needed` only, those whose point lies behind the surface: in front of it the
// thickness weight is 1 whatever the depth.
template <class M, class VF, class VI>
HWY_INLINE VF inv_visible_thickness_lanes(const HemisphereRowArgs& a, M needed, VI index, VF px,
                                          VF py, VF pz, VF qx, VF qy, VF qz) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  const VF inv_assumed = hn::Set(df, 1.0f / a.thickness);
  if (a.last_thickness == nullptr || hn::AllFalse(df, needed)) return inv_assumed;
  const VF signed_measure = hn::GatherIndex(df, a.last_thickness, index);
  auto known = hn::Gt(signed_measure, hn::Zero(df));
  const auto sided = hn::And(needed, hn::Lt(signed_measure, hn::Zero(df)));
  if (!hn::AllFalse(df, sided)) {
    VF nx, ny, nz;
    decode_directions(df, hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index),
                      nx, ny, nz);
    const VF side = hn::MulAdd(px - qx, nx, hn::MulAdd(py - qy, ny, (pz - qz) * nz));
    known = hn::Or(known, hn::And(sided, hn::Lt(side, hn::Zero(df))));
  }
  return hn::IfThenElse(
      known, hn::Set(df, 1.0f) / hn::IfThenElse(known, hn::Abs(signed_measure), hn::Set(df, 1.0f)),
      inv_assumed);
}

// Frame::solid_entry on the lanes of `hidden`, points at planar depth `depth` behind the visible
// surface (depth qd) of the pixels at `index`: walks the hits behind the visible one until the one
// the point lies in front of. `entry`: the depth of the front face the point lies behind;
// `entered`: it lies behind a front face at all; `closed`: a back face follows it on the ray.
// Returns how much that solid occludes the point: 1 inside a solid a back face closes, else by
// the solid's thickness (measured beside the foreground for the ray's last hit,
// Frame::last_thickness, else assumed).
template <class M, class VF, class VI>
HWY_INLINE VF solid_weight_lanes(const HemisphereRowArgs& a, VI index, M hidden, VF qd, VF depth,
                                 VF& entry, M& entered, M& closed) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF inv_thickness = hn::Set(df, 1.0f / a.thickness);
  const auto none = hn::Lt(one, zero);
  entry = qd;
  entered = hidden;    // the visible surface is a front face
  auto open = hidden;  // not yet placed between two hits
  closed = none;
  auto past_last = none;  // behind the last hit the ray knows
  for (int layer = 0; layer < a.extra_layers; ++layer) {
    const VF hit = hn::GatherIndex(df, a.layers + size_t(layer) * a.plane, index);
    const VF hit_depth = hn::Abs(hit);
    const auto back = hn::Lt(hit, zero);
    const auto here = hn::And(open, hn::Le(depth, hit_depth));
    closed = hn::Or(closed, hn::And(here, hn::And(entered, back)));
    past_last = hn::Or(past_last, hn::And(here, hn::Eq(hit, inf)));
    const auto past = hn::AndNot(here, open);  // open lanes behind this hit
    entry = hn::IfThenElse(past, hit_depth, entry);
    entered = hn::Or(hn::AndNot(past, entered), hn::AndNot(back, past));
    open = past;
    if (hn::AllFalse(df, open)) break;
  }
  past_last = hn::Or(past_last, open);
  // Behind the last known hit, a front face: the solid's thickness where the frame measured it
  // beside the foreground, else the assumed one.
  VF inv_depth_of_solid = inv_thickness;
  const auto measured_lanes = hn::And(hn::And(past_last, entered), hn::AndNot(closed, hidden));
  if (!hn::AllFalse(df, measured_lanes)) {
    const VF measured = hn::GatherIndex(df, a.last_thickness, index);
    const auto known = hn::And(measured_lanes, hn::Gt(measured, zero));
    inv_depth_of_solid =
        hn::IfThenElse(known, one / hn::IfThenElse(known, measured, one), inv_thickness);
  }
  return hn::IfThenElse(closed, one, thickness_weight_lanes(depth - entry, inv_depth_of_solid));
}

// Hemisphere::beyond_frame on the lanes of `outside`, samples (sx, sy, sz) in front of the camera
// whose image coordinates (su, sv) fall outside the frame: the weight with which the surface of
// the nearest pixel on the frame's border, carried on beyond it as its tangent plane, occludes
// them (0 where it does not).
template <class M, class VF>
HWY_INLINE VF beyond_frame_lanes(const HemisphereRowArgs& a, const LaneProjection<VF>& project,
                                 M outside, VF su, VF sv, VF sx, VF sy, VF sz, VF gx, VF gy, VF gz,
                                 VF plane_level, VF px, VF py, VF pz) {
  namespace hn = hwy::HWY_NAMESPACE;
  const hn::DFromV<VF> df;
  const hn::RebindToSigned<decltype(df)> di;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  // The nearest border pixel (NaN coordinates, from a sample at the camera's plane, go to 0).
  const VF u = hn::Min(hn::Max(hn::IfThenElseZero(hn::And(outside, hn::Eq(su, su)), su), zero),
                       hn::Set(df, float(a.width - 1)));
  const VF v = hn::Min(hn::Max(hn::IfThenElseZero(hn::And(outside, hn::Eq(sv, sv)), sv), zero),
                       hn::Set(df, float(a.height - 1)));
  const auto qx = hn::ConvertTo(di, u), qy = hn::ConvertTo(di, v);
  const auto index = qy * hn::Set(di, a.width) + qx;
  const VF qd = hn::GatherIndex(df, a.depth, index);
  auto counts = hn::And(outside, hn::Lt(qd, hn::Set(df, std::numeric_limits<float>::infinity())));
  if (hn::AllFalse(df, counts)) return zero;
  // Its surface's plane dot(x, n) = w (n of any length).
  VF ray_x, ray_y;
  project.pixel_ray(qx, qy, ray_x, ray_y);
  const VF q_scale = a.camera.orthographic ? one : qd;
  VF nx, ny, nz;
  decode_directions(df, hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index), nx,
                    ny, nz);
  const VF w = hn::MulAdd(ray_x * q_scale, nx, hn::MulAdd(ray_y * q_scale, ny, hn::Neg(qd) * nz));
  // Where the sample's ray meets it: t x the sample (perspective), or the sample moved along z
  // (orthographic); `ahead`: how far that point lies in front of the sample.
  VF ex, ey, ez;
  if (a.camera.orthographic) {
    counts = hn::And(counts, hn::Gt(hn::Abs(nz), hn::Set(df, 1e-6f)));
    ex = sx, ey = sy;
    ez = (w - hn::MulAdd(sx, nx, sy * ny)) / hn::IfThenElse(counts, nz, one);
  } else {
    const VF along = hn::MulAdd(sx, nx, hn::MulAdd(sy, ny, sz * nz));
    counts = hn::And(counts, hn::Gt(hn::Abs(along), hn::Set(df, 1e-12f)));
    const VF span = hn::IfThenElse(counts, along, one);
    const VF estimate = hn::ApproximateReciprocal(span);  // refined by a Newton step
    const VF t = w * (estimate * hn::NegMulAdd(span, estimate, hn::Set(df, 2.0f)));
    counts = hn::And(counts, hn::Gt(t, zero));
    ex = t * sx, ey = t * sy, ez = t * sz;
  }
  const VF ahead = ez - sz;
  const VF level = hn::MulAdd(ex, gx, hn::MulAdd(ey, gy, ez * gz));
  counts = hn::And(counts, hn::And(hn::Gt(ahead, zero), hn::Gt(level, plane_level)));
  if (hn::AllFalse(df, counts)) return zero;
  if (a.extra_layers == 0) {  // the visible surface, within its solid's depth
    return hn::IfThenElseZero(
        counts, thickness_weight_lanes(ahead, inv_visible_thickness_lanes(
                                                  a, counts, index, px, py, pz, ray_x * q_scale,
                                                  ray_y * q_scale, hn::Neg(qd))));
  }
  // The border pixel's hits go on beyond the frame too: the sample, `ahead` behind the plane,
  // stands where a point that far behind the border pixel's visible surface stands among them.
  VF entry;
  auto entered = counts, closed = counts;
  const VF solid = solid_weight_lanes(a, index, counts, qd, qd + ahead, entry, entered, closed);
  return hn::IfThenElseZero(hn::And(counts, entered), solid);
}

// What a point's pixel shows (hemisphere_row_of's visible_surface): the pixel's index, the
// visible surface's depth, its pixel's ray (x, y at unit depth) and view position, how far it
// lies in front of the point (`behind` > 0: the point is hidden), whether it lies above the
// receiver's tangent plane, and the weight with which it occludes the point.
template <class VF, class VI, class M>
struct VisibleSurface {
  VI index;
  VF depth, ray_x, ray_y, x, y, z, behind, weight;
  M above;
};

// Visibility of pixels [x0, x1) of row y into out[0 .. x1 - x0); kLayers: the frame has extra
// depth layers (compiled apart, so that the one-layer loop carries none of their state).
template <bool kLayers>
HWY_NOINLINE void hemisphere_row_of(const HemisphereRowArgs& a, int y, int x0, int x1, float* out) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  using VF = hn::Vec<decltype(df)>;
  using VI = hn::Vec<decltype(di)>;
  const int lanes = int(hn::Lanes(df));
  const CameraIntrinsics& cam = a.camera;
  const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f);
  using Mask = hn::Mask<decltype(df)>;
  const VF inv_thickness = hn::Set(df, 1.0f / a.thickness);
  const VF radius = hn::Set(df, a.radius);
  const LaneProjection<VF> project(cam, a.width, a.height);
  const VF scale_u = project.scale_u, scale_v = project.scale_v;
  // Vectors start at x0 + a multiple of `lanes` (itself a multiple of 4): one phase.
  const float* row_offsets =
      a.lane_offsets + size_t(y & 3) * a.directions * a.steps * 3 * kLaneTable + (x0 & 3);
  const float* row_cones =
      a.lane_cones + size_t(y & 3) * a.directions * a.steps * 3 * kLaneTable + (x0 & 3);
  const VF view_y_of_row = project.center_v - hn::Set(df, float(y) + 0.5f);

  alignas(64) float depth_in[kMaxLanes];
  alignas(64) int32_t normal_in[kMaxLanes];
  alignas(64) uint8_t mixed_in[kMaxLanes];
  alignas(64) float result[kMaxLanes];
  for (int x = x0; x < x1; x += lanes) {
    const int count = std::min(lanes, x1 - x);
    const float* depth_at = a.depth + size_t(y) * a.width + x;
    const uint32_t* normal_at = a.normals + size_t(y) * a.width + x;
    const uint8_t* mixed_at = a.mixed_normals + size_t(y) * a.width + x;
    if (count < lanes) {  // stage the lanes, padding past the row's end with background
      for (int i = 0; i < lanes; ++i) {
        depth_in[i] = i < count ? depth_at[i] : std::numeric_limits<float>::infinity();
        normal_in[i] = i < count ? int32_t(normal_at[i]) : 0;
        mixed_in[i] = i < count ? mixed_at[i] : 0;
      }
      depth_at = depth_in;
      normal_at = reinterpret_cast<const uint32_t*>(normal_in);
      mixed_at = mixed_in;
    }
    const VF depth = hn::LoadU(df, depth_at);
    const VF footprint = cam.orthographic ? scale_u : scale_u * depth;
    const auto receiver = hn::And(hn::Lt(depth, inf), hn::Ge(radius, half * footprint));
    if (hn::AllFalse(df, receiver)) {
      for (int i = 0; i < count; ++i) out[x - x0 + i] = 1.0f;
      continue;
    }
    const VF safe_depth = hn::IfThenElse(receiver, depth, one);

    // Position of the receivers.
    const VF u = hn::Iota(df, float(x) + 0.5f);
    const VF depth_scale = cam.orthographic ? one : safe_depth;
    const VF px = (u - project.center_u) * scale_u * depth_scale;
    const VF py = view_y_of_row * scale_v * depth_scale;
    const VF pz = hn::Neg(safe_depth);

    VF nx, ny, nz;
    decode_normals(df, hn::LoadU(di, reinterpret_cast<const int32_t*>(normal_at)), nx, ny, nz);

    // Tangent frame (orthonormal_basis in vec3.h).
    const VF sign = hn::CopySign(one, nz);
    const VF basis_a = hn::Neg(one / (sign + nz));
    const VF basis_c = nx * ny * basis_a;
    const VF tx = one + sign * nx * nx * basis_a, ty = sign * basis_c, tz = hn::Neg(sign * nx);
    const VF bx = basis_c, by = sign + ny * ny * basis_a, bz = hn::Neg(ny);

    // An occluder counts above the tangent plane of the surface (normal g): dot(q, g) >
    // dot(p, g) + min_height.
    VF gx = nx, gy = ny, gz = nz;
    if (a.surface_normals) {
      const hn::Rebind<uint8_t, decltype(di)> d8;
      const auto mixed =
          hn::RebindMask(df, hn::Ne(hn::PromoteTo(di, hn::LoadU(d8, mixed_at)), hn::Zero(di)));
      surface_normal_lanes(project, a.depth, a.normals, a.width, a.height, x, y, depth, nx, ny, nz,
                           mixed, gx, gy, gz);
    }
    const VF min_height = hn::Set(df, a.min_height_bias) + footprint;
    const VF plane_level = hn::MulAdd(px, gx, hn::MulAdd(py, gy, hn::MulAdd(pz, gz, min_height)));
    VF occlusion = zero, valid = zero;
    const float* offset = row_offsets;
    const float* cone = row_cones;
    const auto none = hn::Lt(one, zero);  // all false
    // One layer: the visible surface at the pixel (pu, pv) of a point at view z on lanes `on`
    // (Frame::position), and the weight with which it occludes the point where it lies above
    // the tangent plane: the part of the point's cone behind it (Hemisphere::covered, by the
    // depth difference; 0.5 / the cone's width: half_inv_width) within its solid's depth (the
    // assumed thickness, or a post's).
    const auto visible_surface = [&](Mask on, VF pu, VF pv, VF z, VF half_inv_width) {
      VisibleSurface<VF, VI, Mask> q;
      const VI qx = hn::ConvertTo(di, hn::IfThenElseZero(on, pu));
      const VI qy = hn::ConvertTo(di, hn::IfThenElseZero(on, pv));
      q.index = qy * hn::Set(di, a.width) + qx;
      q.depth = hn::GatherIndex(df, a.depth, q.index);
      const VF q_scale = cam.orthographic ? one : q.depth;
      project.pixel_ray(qx, qy, q.ray_x, q.ray_y);
      q.x = q.ray_x * q_scale, q.y = q.ray_y * q_scale, q.z = hn::Neg(q.depth);
      q.behind = q.z - z;  // > 0: the visible surface is in front of the point
      const VF level = hn::MulAdd(q.x, gx, hn::MulAdd(q.y, gy, q.z * gz));
      q.above = hn::And(hn::And(on, hn::Lt(q.depth, inf)), hn::Gt(level, plane_level));
      const VF covered = hn::Min(one, hn::Max(zero, cone_part_lanes(q.behind, half_inv_width)));
      const VF thick = thickness_weight_lanes(
          q.behind, inv_visible_thickness_lanes(a, hn::And(q.above, hn::Gt(q.behind, zero)),
                                                q.index, px, py, pz, q.x, q.y, q.z));
      q.weight = hn::IfThenElseZero(q.above, covered * thick);
      return q;
    };
    for (int k = 0; k < a.directions; ++k) {
      VF blocked = zero;
      auto seen = none;
      // The previous point of the direction (the receiver first) and, on lanes where it lay
      // hidden behind the visible surface of its pixel, that surface's tangent plane
      // dot(x, n) = w (Hemisphere::crossing).
      VF ax = px, ay = py, az = pz;
      auto previous_hidden = none;
      VF pnx = zero, pny = zero, pnz = zero, pw = zero;
      // Between the previous point and sample (sx, sy, sz) the direction may have passed through
      // a surface that neither lies in (a 2 cm board between two steps): the plane of the
      // surface the sample is hidden behind (lanes `hidden`, above the tangent plane), else the
      // previous point's (Hemisphere::crossing). The plane of the sample's surface (q, at
      // `index`) is read into (hnx, hny, hnz, hw) on the lanes `planes`.
      const auto cross = [&](auto hidden, auto planes, VI index, VF qxv, VF qyv, VF qzv, VF sx,
                             VF sy, VF sz, VF extend, VF& hnx, VF& hny, VF& hnz, VF& hw) {
        if (hn::AllFalse(df, hn::Or(planes, hn::And(previous_hidden, hn::Lt(blocked, one))))) {
          return;
        }
        if (!hn::AllFalse(df, planes)) {
          const VI packed = hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.normals), index);
          decode_directions(df, packed, hnx, hny, hnz);  // sides of a plane: any length
          hw = hn::MulAdd(qxv, hnx, hn::MulAdd(qyv, hny, qzv * hnz));
        }
        const auto flips = [&](VF cx, VF cy, VF cz, VF w) {
          return sides_differ_lanes(ax, ay, az, sx, sy, sz, cx, cy, cz, w);
        };
        const auto here = hn::And(hidden, flips(hnx, hny, hnz, hw));
        const VF cnx = hn::IfThenElse(here, hnx, pnx), cny = hn::IfThenElse(here, hny, pny),
                 cnz = hn::IfThenElse(here, hnz, pnz), cw = hn::IfThenElse(here, hw, pw);
        const auto candidate = hn::And(
            hn::And(hn::Or(here, previous_hidden), flips(cnx, cny, cnz, cw)), hn::Lt(blocked, one));
        if (!hn::AllFalse(df, candidate)) {
          blocked = hn::Max(blocked, crossing_lanes(a, project, candidate, ax, ay, az, sx, sy, sz,
                                                    cnx, cny, cnz, cw, extend));
        }
      };
      // The sample becomes the previous point.
      const auto advance = [&](VF sx, VF sy, VF sz, auto hidden, VF hnx, VF hny, VF hnz, VF hw) {
        ax = sx, ay = sy, az = sz;
        previous_hidden = hidden;
        pnx = hnx, pny = hny, pnz = hnz, pw = hw;
      };
      // One layer: on lanes `unhidden` the receiver's first step (sx, sy, sz) lies in front of
      // what its pixel shows, or outside the frame: a board nearer than it, between the two, is
      // seen from neither, and the crossing test has no plane to try. The point halfway to it,
      // as a sample (Hemisphere::halfway).
      const auto halfway_to_first_step = [&](Mask unhidden, VF sx, VF sy, VF sz) {
        const auto open = hn::And(unhidden, hn::And(receiver, hn::Lt(blocked, one)));
        if (hn::AllFalse(df, open)) return;
        VF mu, mv;
        const VF mz = (pz + sz) * half;
        const auto shown = hn::And(open, project((px + sx) * half, (py + sy) * half, mz, mu, mv));
        if (hn::AllFalse(df, shown)) return;
        blocked = hn::Max(
            blocked,
            visible_surface(shown, mu, mv, mz, hn::LoadU(df, cone + 2 * kLaneTable)).weight);
      };
      const float* const direction_end = offset + size_t(a.steps) * 3 * kLaneTable;
      const float* const cone_end = cone + size_t(a.steps) * 3 * kLaneTable;
      for (int step = 0; step < a.steps; ++step, offset += 3 * kLaneTable, cone += 3 * kLaneTable) {
        // A direction fully blocked on every lane stays so (it counts its strongest occluder,
        // and a weight is at most 1): its remaining steps cannot change the result.
        if (step > 0 && hn::AllTrue(df, hn::Or(hn::Ge(blocked, one), hn::Not(receiver)))) break;
        const VF ox = hn::LoadU(df, offset), oy = hn::LoadU(df, offset + kLaneTable),
                 oz = hn::LoadU(df, offset + 2 * kLaneTable);
        const VF sx = hn::MulAdd(tx, ox, hn::MulAdd(bx, oy, hn::MulAdd(nx, oz, px)));
        const VF sy = hn::MulAdd(ty, ox, hn::MulAdd(by, oy, hn::MulAdd(ny, oz, py)));
        const VF sz = hn::MulAdd(tz, ox, hn::MulAdd(bz, oy, hn::MulAdd(nz, oz, pz)));
        VF su, sv;
        const auto in_image = hn::And(project(sx, sy, sz, su, sv), receiver);
        // A sample whose pixel lies outside the frame, in front of the camera, meets the surfaces
        // at the frame's border carried on beyond it (Hemisphere::beyond_frame).
        const auto in_front = cam.orthographic ? receiver : hn::And(receiver, hn::Lt(sz, zero));
        const auto outside = hn::AndNot(in_image, in_front);
        if (!hn::AllFalse(df, outside)) {
          blocked = hn::Max(blocked, beyond_frame_lanes(a, project, outside, su, sv, sx, sy, sz, gx,
                                                        gy, gz, plane_level, px, py, pz));
        }
        seen = hn::Or(seen, in_front);
        if constexpr (!kLayers) {
          if (hn::AllFalse(df, in_image)) {
            if (step == 0) halfway_to_first_step(hn::Not(none), sx, sy, sz);
            advance(sx, sy, sz, none, zero, zero, zero, zero);
            continue;
          }
          const VisibleSurface<VF, VI, Mask> q =
              visible_surface(in_image, su, sv, sz, hn::LoadU(df, cone));
          const VI index = q.index;
          const VF qd = q.depth, qxv = q.x, qyv = q.y, qzv = q.z, behind = q.behind;
          const VF ray_x = q.ray_x, ray_y = q.ray_y;
          const auto above = q.above;
          blocked = hn::Max(blocked, q.weight);
          if (step == 0) {
            halfway_to_first_step(hn::Or(hn::Not(in_image), hn::Not(hn::Gt(behind, zero))), sx, sy,
                                  sz);
          }
          // Hidden beyond that solid's reach: the surface beyond the nearest silhouette, carried
          // on behind the object (Frame::carried_depth), occludes within the assumed thickness
          // when the receiver lies in front of it and it is above the tangent plane.
          if (a.carried_depth != nullptr) {
            const auto deeper = hn::And(hn::And(in_image, hn::Lt(qd, inf)),
                                        hn::And(hn::Gt(behind, zero), hn::Lt(blocked, one)));
            if (!hn::AllFalse(df, deeper)) {
              const VF carried = hn::GatherIndex(df, a.carried_depth, index);
              const VF past = hn::Neg(sz) - carried;  // > 0: the sample lies behind it
              const VF c_scale = cam.orthographic ? one : carried;
              const VF cxv = ray_x * c_scale, cyv = ray_y * c_scale, czv = hn::Neg(carried);
              const VF carried_level = hn::MulAdd(cxv, gx, hn::MulAdd(cyv, gy, czv * gz));
              const auto carries =
                  hn::And(hn::And(deeper, hn::Gt(past, zero)), hn::Gt(carried_level, plane_level));
              if (!hn::AllFalse(df, carries)) {
                VF cnx, cny, cnz;
                decode_directions(
                    df,
                    hn::GatherIndex(di, reinterpret_cast<const int32_t*>(a.carried_normals), index),
                    cnx, cny, cnz);
                const VF side =
                    hn::MulAdd(px - cxv, cnx, hn::MulAdd(py - cyv, cny, (pz - czv) * cnz));
                const VF carried_weight = thickness_weight_lanes(past, inv_thickness);
                blocked = hn::Max(blocked, hn::IfThenElseZero(hn::And(carries, hn::Gt(side, zero)),
                                                              carried_weight));
              }
            }
          }
          // A board between the two points, as with extra layers (below), where the direction
          // passes from in front of the surface this sample is hidden behind to behind it. Not
          // from behind the previous point's: which side of its solid that point lies on one
          // layer cannot say (the wall behind a rail darkened: analytic test RMSE 0.039 ->
          // 0.052, docs/variants.md).
          const auto hidden = hn::And(hn::And(above, hn::Gt(behind, zero)), hn::Lt(blocked, one));
          VF hnx = zero, hny = zero, hnz = zero, hw = zero;
          cross(hidden, hidden, index, qxv, qyv, qzv, sx, sy, sz, hn::LoadU(df, cone + kLaneTable),
                hnx, hny, hnz, hw);
          advance(sx, sy, sz, none, hnx, hny, hnz, hw);
        } else {
          const VI qx = hn::ConvertTo(di, hn::IfThenElseZero(in_image, su));
          const VI qy = hn::ConvertTo(di, hn::IfThenElseZero(in_image, sv));
          const VF half_inv_width = hn::LoadU(df, cone), extend = hn::LoadU(df, cone + kLaneTable);
          const VF half_inv_width_between = hn::LoadU(df, cone + 2 * kLaneTable);
          // The direction's end at the radius.
          const VF end_x = hn::MulAdd(sx - ax, extend, sx), end_y = hn::MulAdd(sy - ay, extend, sy),
                   end_z = hn::MulAdd(sz - az, extend, sz);
          // Halfway from the previous point (Hemisphere::between).
          const auto open_lanes = hn::And(receiver, hn::Lt(blocked, one));
          if (!hn::AllFalse(df, open_lanes)) {
            blocked = hn::Max(blocked, between_lanes(a, project, open_lanes, ax, ay, az, sx, sy, sz,
                                                     end_x, end_y, end_z, gx, gy, gz, plane_level,
                                                     half_inv_width_between, extend));
          }
          auto hidden = none;
          auto above = none;  // the visible surface lies above the tangent plane: it may occlude
          VF qxv = zero, qyv = zero, qzv = zero;
          VI index = hn::Zero(di);
          if (!hn::AllFalse(df, in_image)) {
            index = qy * hn::Set(di, a.width) + qx;
            const VF qd = hn::GatherIndex(df, a.depth, index);
            // The visible surface at that pixel (Frame::position).
            const VF q_scale = cam.orthographic ? one : qd;
            VF ray_x, ray_y;  // of this pixel, for the visible surface and the one entered
            project.pixel_ray(qx, qy, ray_x, ray_y);
            qxv = ray_x * q_scale, qyv = ray_y * q_scale;
            qzv = hn::Neg(qd);
            const VF behind = qzv - sz;  // > 0: the visible surface is in front of the sample
            const auto surface = hn::And(in_image, hn::Lt(qd, inf));
            hidden = hn::And(surface, hn::Gt(behind, zero));
            above = hn::And(
                surface, hn::Gt(hn::MulAdd(qxv, gx, hn::MulAdd(qyv, gy, qzv * gz)), plane_level));
            // The part of the sample's cone behind the visible surface (Hemisphere::covered): a
            // sample just in front of a surface above the tangent plane counts in part, one just
            // behind it not yet fully.
            VF covered = zero;
            if (!hn::AllFalse(df, above)) {
              const VF scale = hn::GatherIndex(df, a.plane_distance_scale, index);
              covered =
                  hn::Min(one, hn::Max(zero, cone_part_lanes(behind * scale, half_inv_width)));
              blocked = hn::Max(blocked, hn::IfThenElseZero(hn::AndNot(hidden, above), covered));
            }
            if (!hn::AllFalse(df, hidden)) {
              VF entry;
              auto entered = hidden, closed = none;
              const VF solid =
                  solid_weight_lanes(a, index, hidden, qd, hn::Neg(sz), entry, entered, closed);
              // Occluded by the solid entered at `entry`, when that surface is above the tangent
              // plane.
              const VF entry_scale = cam.orthographic ? one : entry;
              const VF ex = ray_x * entry_scale, ey = ray_y * entry_scale;
              const VF entry_level = hn::MulAdd(ex, gx, hn::MulAdd(ey, gy, hn::Neg(entry) * gz));
              const auto counts =
                  hn::And(hn::And(hidden, entered), hn::Gt(entry_level, plane_level));
              const VF weight = hn::IfThenElse(hn::Eq(entry, qd), covered, one) * solid;
              blocked = hn::Max(blocked, hn::IfThenElseZero(counts, weight));
            }
          }
          // Between the previous point and this one the direction may have passed through a
          // surface that neither lies in (a 2 cm board between two steps): the plane of the
          // surface this sample is hidden behind, else the previous point's (Hemisphere::pixel);
          // surfaces above the tangent plane only. The last sample in front of such a surface:
          // the direction may reach it beyond (Hemisphere::reach).
          const auto ends =
              step == a.steps - 1 ? hn::And(hn::AndNot(hidden, above), hn::Lt(blocked, one)) : none;
          hidden = hn::And(hn::And(hidden, hn::Lt(blocked, one)), above);
          VF hnx = zero, hny = zero, hnz = zero, hw = zero;
          cross(hidden, hn::Or(hidden, ends), index, qxv, qyv, qzv, sx, sy, sz, extend, hnx, hny,
                hnz, hw);
          if (!hn::AllFalse(df, ends)) {
            blocked = hn::Max(blocked, reach_lanes(a, project, ends, sx, sy, sz, end_x, end_y,
                                                   end_z, hnx, hny, hnz, hw));
          }
          advance(sx, sy, sz, hidden, hnx, hny, hnz, hw);
        }
      }
      offset = direction_end;
      cone = cone_end;
      valid = valid + hn::IfThenElseZero(seen, one);
      occlusion = occlusion + hn::IfThenElseZero(seen, blocked);
    }
    const auto any = hn::Gt(valid, zero);
    const VF visibility =
        hn::IfThenElse(any, one - occlusion / hn::IfThenElse(any, valid, one), one);
    hn::Store(hn::IfThenElse(receiver, visibility, one), df, result);
    std::copy_n(result, count, out + (x - x0));
  }
}

void hemisphere_row(const HemisphereRowArgs& a, int y, int x0, int x1, float* out) {
  if (a.extra_layers > 0) {
    hemisphere_row_of<true>(a, y, x0, x1, out);
  } else {
    hemisphere_row_of<false>(a, y, x0, x1, out);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace ssao
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <cmath>
#include <vector>

#include "variant.h"
#include "variants/simd_dispatch.h"

namespace ssao {
namespace {

// The widest compiled hemisphere_row this CPU runs (simd_dispatch.h), chosen on first use.
decltype(&HWY_STATIC_DISPATCH(hemisphere_row)) best_hemisphere_row() {
  static const auto row = SSAO_BEST_TARGET(hemisphere_row);
  return row;
}

class Hemisphere final : public Variant {
 public:
  Hemisphere(const ParamValues& v, const Frame& f) {
    static constexpr int kSamples[4] = {4, 4, 8, 16};
    static constexpr int kSteps[4] = {4, 6, 6, 6};
    // With extra depth layers a sample behind a solid's back face is free space, so a solid
    // counts only where a step lands inside it or the crossing test catches the segment: twice
    // the steps halve the gap a thin board can fall into (docs/variants.md, issue 31).
    static constexpr int kLayeredSteps[4] = {8, 12, 12, 12};
    radius_ = float(v.get_float("radius"));
    bias_ = float(v.get_float("bias"));
    thickness_ = float(v.get_float("thickness")) * radius_;
    // How far behind the crossed plane the depth image may show a surface at the crossing point
    // and still have it taken as that surface (tangent planes of curved surfaces drift).
    crossing_tolerance_ = 0.25f * thickness_;
    directions_ = count_or_preset(v, "samples", kSamples);
    steps_ = count_or_preset(v, "steps", f.extra_layers() > 0 ? kLayeredSteps : kSteps);
    // Each kernel direction is followed by `steps` samples at increasing distances;
    // steps = 1 is the classic kernel of independent points. The table holds, per jitter
    // state, every sample's offset in the receiver's tangent frame, rotated and scaled.
    const Kernel kernel = make_hemisphere_kernel(directions_);
    const float clustering = float(v.get_float("sample_clustering"));
    const float spacing = steps_ == 1 ? 1.0f / float(directions_) : 1.0f / float(steps_);
    const auto states = jitter_states(uint32_t(v.get_int("seed")));
    const int samples = directions_ * steps_;
    // The sub-stratum of the radii per tile position (x, y): 4 * L3 + L1 with L1 = x ^ y and
    // L3 = x ^ 3y, orthogonal Latin squares over GF(4), so that every row and every column of
    // the tile holds one offset from each quarter (mean 7.5 / 16 each). jitter_states' own
    // order gives the four row classes means 6, 10, 5 and 9 / 16: rows y & 3 = 1, 3 reached
    // farther than rows 0, 2, alternate rows streaked where denoise=none leaves them.
    int radial_index[kJitterStates] = {};
    for (int ty = 0; ty < kNoiseTileSize; ++ty) {
      for (int tx = 0; tx < kNoiseTileSize; ++tx) {
        static constexpr int kTimes3[4] = {0, 3, 1, 2};  // multiplication by 3 in GF(4)
        radial_index[jitter_index(tx, ty)] = 4 * (tx ^ kTimes3[ty]) + (tx ^ ty);
      }
    }
    offsets_.resize(size_t(kJitterStates) * samples);
    for (int j = 0; j < kJitterStates; ++j) {
      const JitterState& js = states[j];
      // The seed's shift of the sub-stratum, kept.
      const float seed_shift = js.radial_offset * float(kJitterStates) -
                               std::floor(js.radial_offset * float(kJitterStates));
      const float radial_offset = (float(radial_index[j]) + seed_shift) / float(kJitterStates);
      for (int k = 0; k < directions_; ++k) {
        const Vec3 d = kernel.directions[k];
        const Vec3 rotated{d.x * js.cos_angle - d.y * js.sin_angle,
                           d.x * js.sin_angle + d.y * js.cos_angle, d.z};
        for (int step = 0; step < steps_; ++step) {
          const float stratum = float(steps_ == 1 ? kernel.stratum[k] : step) * spacing;
          const float r = radius_ * radial_scale(stratum + radial_offset * spacing, clustering);
          offsets_[(size_t(j) * directions_ + k) * steps_ + step] = rotated * r;
        }
      }
    }
    // The same offsets laid out for the vector path: [y & 3][sample][x, y, z][lane].
    lane_offsets_ = lane_table<3>(samples, [&](int jitter, int s) {
      const Vec3 o = offsets_[size_t(jitter) * samples + s];
      return std::array<float, 3>{o.x, o.y, o.z};
    });
    make_cones(samples);
  }

  void estimate(const Frame& f, const Tile& t, float* visibility) const override {
    const HemisphereRowArgs args{f.depth_plane(),
                                 f.normal_plane(),
                                 f.mixed_normal_plane(),
                                 f.layer_planes(),
                                 f.last_thickness_plane(),
                                 f.plane_distance_scale_plane(),
                                 f.carried_depth_plane(),
                                 f.carried_normal_plane(),
                                 f.extra_layers(),
                                 f.normals_from_image() && f.width() >= 3 && f.height() >= 3,
                                 f.width(),
                                 f.height(),
                                 f.camera().intrinsics(),
                                 radius_,
                                 bias_ * radius_,
                                 thickness_,
                                 crossing_tolerance_,
                                 f.pixel_count(),
                                 directions_,
                                 steps_,
                                 lane_offsets_.data(),
                                 lane_cones_.data(),
                                 half_inv_end_width_};
    for (int y = t.y0; y < t.y1; ++y) {
      best_hemisphere_row()(args, y, t.x0, t.x1, visibility + f.index(t.x0, y));
    }
  }

  void estimate_reference(const Frame& f, const Tile& t, float* visibility) const override {
    estimate_receivers(f, t, radius_, visibility, [&](int x, int y) { return pixel(f, x, y); });
  }

 private:
  // A sample stands for the cone of directions around it that its share of the hemisphere
  // covers: the 4x4 pattern gives directions x 16 directions to the pixels a denoised value
  // averages, so a cone of half-angle sqrt(2 / (directions x 16)) each. A direction then turns
  // blocked gradually as a surface moves across its cone, instead of at once where its point
  // crosses the surface, which drew bands of equal AO across smooth surfaces under a large
  // occluder (the floor below a sphere) and made the pattern crawl over surfaces on camera
  // moves (docs/variants.md). One layer reads only half_inv_width.
  struct Cone {
    float half_inv_width;  // 0.5 / the cone's width at the sample
    float extend;          // the direction's length beyond the sample over the length from the step
                           // before (the receiver for the first)
    float half_inv_width_between;  // the same at the point halfway from the step before
  };
  void make_cones(int samples) {
    const float angle = std::sqrt(2.0f / float(directions_ * kJitterStates));
    half_inv_end_width_ = 0.5f / (angle * radius_);
    cones_.resize(offsets_.size());
    for (size_t i = 0; i < offsets_.size(); ++i) {
      const int step = int(i % size_t(steps_));
      const float distance = length(offsets_[i]);
      const float before = step > 0 ? length(offsets_[i - 1]) : 0.0f;
      const Vec3 halfway = (offsets_[i] + (step > 0 ? offsets_[i - 1] : Vec3{})) * 0.5f;
      cones_[i] = {
          0.5f / (angle * distance),
          distance > before ? std::max(0.0f, radius_ - distance) / (distance - before) : 0.0f,
          0.5f / (angle * length(halfway))};
    }
    lane_cones_ = lane_table<3>(samples, [&](int jitter, int s) {
      const Cone c = cones_[size_t(jitter) * samples + s];
      return std::array<float, 3>{c.half_inv_width, c.extend, c.half_inv_width_between};
    });
  }

  // The part of a sample's cone (0.5 / its width: half_inv_width) behind the tangent plane of the
  // visible surface q of its pixel (qx, qy): by how far the sample lies behind that plane (in
  // front: < 0). One layer takes the
  // depth difference for that distance: the frame measures the factor between them only with
  // layers, and reading it per sample cost one layer 9-34 % of its time.
  static float covered(const Frame& f, int qx, int qy, Vec3 sample, Vec3 q, float half_inv_width) {
    const float scale = f.extra_layers() > 0 ? f.plane_distance_scale(qx, qy) : 1.0f;
    return saturate((q.z - sample.z) * scale * half_inv_width + 0.5f);
  }

  float pixel(const Frame& f, int x, int y) const {
    const Vec3 p = f.position(x, y);
    const Vec3 normal = f.normal(x, y);
    const Vec3 geometric_normal = f.surface_normal(x, y);  // for the tangent-plane tests
    // Depth-aware bias: one pixel footprint covers depth quantisation and pixel snapping.
    const float min_height = bias_ * radius_ + f.camera().pixel_footprint(-p.z);
    Vec3 tangent, bitangent;
    orthonormal_basis(normal, tangent, bitangent);
    const Vec3* offset = offsets_.data() + size_t(jitter_index(x, y)) * directions_ * steps_;
    const bool layered = f.extra_layers() > 0;
    const Cone* cone = cones_.data() + (offset - offsets_.data());

    // A direction counts as blocked by its strongest occluded sample, which is what Cycles'
    // binary ray visibility measures.
    float occlusion = 0.0f;
    int valid = 0;
    for (int k = 0; k < directions_; ++k) {
      float blocked = 0.0f;
      bool seen = false;
      // The previous point of the direction (the receiver first) and, when it lay hidden behind
      // the visible surface of its pixel, that surface's tangent plane: see crossing().
      Vec3 previous = p;
      bool previous_hidden = false;
      Vec3 previous_surface{}, previous_normal{};
      for (int step = 0; step < steps_; ++step, ++offset, ++cone) {
        const Vec3 sample = p + tangent * offset->x + bitangent * offset->y + normal * offset->z;
        // The direction's end at the radius (with extra layers).
        const Vec3 end = layered ? sample + (sample - previous) * cone->extend : Vec3{};
        if (layered && blocked < 1.0f) {
          blocked = std::max(
              blocked, between(f, p, geometric_normal, min_height, previous, sample, end, *cone));
        }
        int qx = -1, qy = -1;
        bool hidden = false, above = false;
        Vec3 surface{}, surface_normal{};
        const bool in_front = f.camera().intrinsics().orthographic || sample.z < 0.0f;
        if (!pixel_of_sample(f, sample, qx, qy)) {
          // Outside the frame: the surfaces at its border carried on beyond it.
          if (in_front) {
            seen = true;
            blocked = std::max(blocked, beyond_frame(f, geometric_normal, min_height, p, sample));
          }
        } else {
          seen = true;
          if (f.is_geometry(qx, qy)) {
            surface = f.position(qx, qy);
            hidden = -sample.z > -surface.z;
            above = dot(surface - p, geometric_normal) > min_height;
            const float part = covered(f, qx, qy, sample, surface, cone->half_inv_width);
            if (!hidden && above) {
              blocked = std::max(blocked, part);
            }
            // The surface the sample lies behind (the visible one without extra layers), if any,
            // when above the tangent plane.
            float entry = Frame::kBackground;
            const float weight = solid_weight(f, qx, qy, -sample.z, p, entry);
            if (entry != Frame::kBackground) {
              const Vec3 q = f.camera().view_position(float(qx) + 0.5f, float(qy) + 0.5f, entry);
              if (dot(q - p, geometric_normal) > min_height) {
                blocked = std::max(blocked, entry == f.depth(qx, qy) ? part * weight : weight);
              }
            }
            if (hidden && !layered && blocked < 1.0f) {
              blocked =
                  std::max(blocked, carried(f, qx, qy, p, geometric_normal, min_height, sample));
            }
          }
        }
        // One layer: the receiver's first step lies in front of what its pixel shows (or outside
        // the frame), so a board nearer than it is seen from neither: the point halfway to it.
        if (!layered && step == 0 && !hidden && blocked < 1.0f) {
          blocked = std::max(blocked, halfway(f, p, geometric_normal, min_height,
                                              (p + sample) * 0.5f, cone->half_inv_width_between));
        }
        // The last sample in front of a surface above the tangent plane: the direction goes on
        // to the radius, and may reach that surface beyond it.
        const bool ends = layered && step == steps_ - 1 && above && !hidden;
        // The crossing test (below) takes surfaces above the tangent plane only, as the test
        // above.
        hidden = hidden && above;
        if (hidden || ends) surface_normal = f.normal(qx, qy);
        // Between the two points the direction may have passed through a surface that neither
        // point lies in (a 2 cm board between two steps): the plane of the surface this sample
        // is hidden behind, else (with extra layers) that of the one the previous point was
        // hidden behind. With one layer the first only: which side of its solid a hidden point
        // lies on one layer cannot say.
        const bool here = hidden && sides_differ(previous, sample, surface, surface_normal);
        if (blocked < 1.0f && (here || (layered && previous_hidden))) {
          blocked =
              std::max(blocked, crossing(f, previous, sample, here ? surface : previous_surface,
                                         here ? surface_normal : previous_normal, cone->extend));
        }
        if (ends && blocked < 1.0f) {
          blocked = std::max(blocked, reach(f, sample, end, surface, surface_normal));
        }
        previous = sample;
        previous_hidden = hidden;
        previous_surface = surface;
        previous_normal = surface_normal;
      }
      if (!seen) continue;
      ++valid;
      occlusion += blocked;
    }
    return valid > 0 ? 1.0f - occlusion / float(valid) : 1.0f;
  }

  // A sample in front of the camera whose pixel lies outside the frame: nothing in the images
  // says what it meets, so the surfaces at the frame's border are taken to go on beyond it, each
  // as its tangent plane (a floor or a wall cut by the frame's edge: what a guard band would
  // show). The plane of the nearest border pixel's surface, where the sample's ray meets it,
  // stands for the visible surface; it occludes within the assumed thickness when above the
  // receiver's tangent plane (normal g, through p); with extra layers, the border pixel's hits
  // say how deep its solids are. Returns the sample's weight, 0 if none.
  float beyond_frame(const Frame& f, Vec3 g, float min_height, Vec3 p, Vec3 sample) const {
    float u = 0.0f, v = 0.0f;
    f.camera().project(sample, u, v);
    // NaN (a sample at the camera's plane) goes to 0, as on the vector path.
    const int qx = int(std::min(std::max(u >= 0.0f ? u : 0.0f, 0.0f), float(f.width() - 1)));
    const int qy = int(std::min(std::max(v >= 0.0f ? v : 0.0f, 0.0f), float(f.height() - 1)));
    if (!f.is_geometry(qx, qy)) return 0.0f;
    const Vec3 q = f.position(qx, qy), n = f.normal(qx, qy);
    const float w = dot(q, n);
    Vec3 meets;
    if (f.camera().intrinsics().orthographic) {
      if (!(std::fabs(n.z) > 1e-6f)) return 0.0f;
      meets = {sample.x, sample.y, (w - sample.x * n.x - sample.y * n.y) / n.z};
    } else {
      const float along = dot(sample, n);
      if (!(std::fabs(along) > 1e-12f)) return 0.0f;
      const float t = w / along;
      if (!(t > 0.0f)) return 0.0f;
      meets = sample * t;
    }
    const float ahead = meets.z - sample.z;
    if (!(ahead > 0.0f) || !(dot(meets - p, g) > min_height)) return 0.0f;
    // The border pixel's hits go on beyond the frame too: the sample, `ahead` behind the plane,
    // stands where a point that far behind the border pixel's visible surface stands among them.
    float entry = Frame::kBackground;
    return solid_weight(f, qx, qy, f.depth(qx, qy) + ahead, p, entry);
  }

  // A sample hidden behind the visible surface of pixel (qx, qy), without extra layers: the
  // weight with which the surface beyond the nearest silhouette, carried on behind the object
  // (Frame::carried_depth), occludes it within the assumed thickness, when the receiver p lies
  // in front of it and it is above the tangent plane (normal g); else 0.
  float carried(const Frame& f, int qx, int qy, Vec3 p, Vec3 g, float min_height,
                Vec3 sample) const {
    const float depth = f.carried_depth(qx, qy);
    if (depth == Frame::kBackground) return 0.0f;
    const float past = -sample.z - depth;
    const Vec3 c = f.camera().view_position(float(qx) + 0.5f, float(qy) + 0.5f, depth);
    if (!(past > 0.0f) || !(dot(c - p, g) > min_height) ||
        !(dot(p - c, f.carried_normal(qx, qy)) > 0.0f)) {
      return 0.0f;
    }
    return thickness_weight(past, thickness_);
  }

  // Frame::solid_entry for a point at planar depth `depth` on the ray of pixel (qx, qy), into
  // `entry`, and how much the solid it lies in occludes it: 1 inside a solid that a back face
  // closes, else by the solid's thickness (measured beside the foreground for the ray's last
  // hit, or bounded for the receiver p, Frame::last_thickness_seen_from, else assumed); 0 where
  // entry is kBackground (the point is in front of the visible surface or in free space). The
  // vector path's solid_weight_lanes.
  float solid_weight(const Frame& f, int qx, int qy, float depth, Vec3 p, float& entry) const {
    bool closed = false, past_last = false;
    entry = f.solid_entry(qx, qy, depth, closed, &past_last);
    if (entry == Frame::kBackground) return 0.0f;
    const float measured = past_last ? f.last_thickness_seen_from(qx, qy, p) : 0.0f;
    // Without extra layers the frame folded the assumed thickness in (kAssumedThickness).
    const float depth_of_solid = measured > 0.0f ? measured : thickness_;
    return closed ? 1.0f : thickness_weight(depth - entry, depth_of_solid);
  }

  static bool sides_differ(Vec3 a, Vec3 b, Vec3 q, Vec3 nq) {
    return (dot(a - q, nq) > 0.0f) != (dot(b - q, nq) > 0.0f);
  }

  // When the segment from a to b passes through the visible surface of a pixel that one of
  // them lies hidden behind (it goes from one side of that surface's tangent plane, point q,
  // normal nq, to the other, and where it meets the plane the depth image shows that plane or
  // something in front of it, so the crossing point is on a surface, not in open air beside
  // one): the part of the direction's cone past the plane at the radius, the direction going
  // on beyond b by `extend` times b - a. Else 0.
  float crossing(const Frame& f, Vec3 a, Vec3 b, Vec3 q, Vec3 nq, float extend) const {
    const float side_a = dot(a - q, nq), side_b = dot(b - q, nq);
    if ((side_a > 0.0f) == (side_b > 0.0f)) return 0.0f;
    const Vec3 c = a + (b - a) * (side_a / (side_a - side_b));
    if (!shows_plane(f, c, q, nq)) return 0.0f;
    const float past_end = (std::fabs(side_a) + std::fabs(side_b)) * extend + std::fabs(side_b);
    return std::min(1.0f, end_part(past_end / length(nq)));
  }

  // The part of a direction's cone at the radius past a plane, from how far the direction's end
  // lies past it (negative: short of it): half where the end lies on it, none half the cone's
  // width short of it. Not clamped.
  float end_part(float past) const { return past * half_inv_end_width_ + 0.5f; }

  // A point halfway between two steps of a direction, `previous` and `sample` (a 2 cm board seen
  // edge-on is a pixel or two wide on screen and falls between steps that lie several pixels
  // apart), where the visible surface of its pixel is above the receiver's tangent plane (p,
  // normal, min_height):
  // - when it lies behind that surface and in front of the ray's next hit, the part of the
  //   point's cone (0.5 / its width: cone.half_inv_width_between) behind the surface or, if more,
  //   of the cone at the direction's end past the surface's tangent plane, times the solid's
  //   weight: 1 when the next hit is a back face that closes it, else by the assumed thickness;
  // - when the ray's hits there make a solid thinner along the ray than kThinSolidSegments x the
  //   segment, the segment may pass through it anywhere, not at its midpoint only: the crossing
  //   test with the surface's plane (a board beside the midpoint, both points in free space in
  //   front of what their pixels show, is seen by neither).
  // Cheaper than a step: no deeper hits.
  float between(const Frame& f, Vec3 p, Vec3 normal, float min_height, Vec3 previous, Vec3 sample,
                Vec3 end, const Cone& cone) const {
    const Vec3 point = (previous + sample) * 0.5f;
    int qx, qy;
    if (!pixel_of_sample(f, point, qx, qy) || !f.is_geometry(qx, qy)) return 0.0f;
    const Vec3 q = f.position(qx, qy);
    if (!(dot(q - p, normal) > min_height)) return 0.0f;
    const float depth = f.depth(qx, qy);
    const float behind = -point.z - depth;
    const float next = f.layer_planes()[f.index(qx, qy)];  // the ray's 2nd hit
    const Vec3 nq = f.normal(qx, qy);
    float weight = 0.0f;
    if (behind > 0.0f && -point.z <= std::fabs(next)) {
      const float solid = next < 0.0f ? 1.0f : thickness_weight(behind, thickness_);
      // The direction goes on to `end`: the part of its cone there past the surface's tangent
      // plane, if more (a board the direction pierces blocks the whole cone, however thin).
      const float past_end = -dot(end - q, nq) / length(nq);
      weight = saturate(std::max(
                   behind * f.plane_distance_scale(qx, qy) * cone.half_inv_width_between + 0.5f,
                   end_part(past_end))) *
               solid;
    }
    if (weight < 1.0f && std::fabs(next) - depth < kThinSolidSegments * length(sample - previous)) {
      weight = std::max(weight, crossing(f, previous, sample, q, nq, cone.extend));
    }
    return weight;
  }

  // One layer: the point halfway between the receiver and its first step, when that step lies in
  // front of what its pixel shows, as a sample (a board between them, seen from neither, that
  // the crossing test cannot find: it takes the plane of a surface a step lies behind). The
  // visible surface at its pixel, above the receiver's tangent plane (p, normal, min_height),
  // occludes it by the part of the point's cone (0.5 / its width: half_inv_width) behind it,
  // within its solid's depth (solid_weight). The vector path's probe in hemisphere_row_of.
  float halfway(const Frame& f, Vec3 p, Vec3 normal, float min_height, Vec3 point,
                float half_inv_width) const {
    int qx, qy;
    if (!pixel_of_sample(f, point, qx, qy) || !f.is_geometry(qx, qy)) return 0.0f;
    const Vec3 q = f.position(qx, qy);
    if (!(dot(q - p, normal) > min_height)) return 0.0f;
    const float part = covered(f, qx, qy, point, q, half_inv_width);
    float entry = Frame::kBackground;
    const float weight = solid_weight(f, qx, qy, -point.z, p, entry);
    return entry == Frame::kBackground ? part : part * weight;
  }

  // When the last sample b of a direction lies in front of the tangent plane (point q, normal
  // nq) of the surface its pixel shows, and the direction goes on beyond b to its end at the
  // radius: the part of the cone's end past that plane (end_part), if the depth image shows the
  // plane where the direction meets it (at its end, when short of it). Else 0.
  float reach(const Frame& f, Vec3 b, Vec3 end, Vec3 q, Vec3 nq) const {
    const float side_b = dot(b - q, nq), side_end = dot(end - q, nq);
    const float part = end_part(-side_end / length(nq));
    if (!(side_b > 0.0f) || !(part > 0.0f)) return 0.0f;
    const Vec3 c = side_end >= 0.0f ? end : b + (end - b) * (side_b / (side_b - side_end));
    return shows_plane(f, c, q, nq) ? std::min(1.0f, part) : 0.0f;
  }

  // Whether the depth image, at the pixel of point c (on the plane through q with normal nq),
  // shows that plane or something in front of it. A surface up to the tolerance behind the plane
  // may be another one that meets the plane there (the floor where a box's side, carried on past
  // the box, would meet it): it counts where its normal agrees with the plane's, or where a
  // neighbouring pixel shows the plane with such a normal.
  bool shows_plane(const Frame& f, Vec3 c, Vec3 q, Vec3 nq) const {
    int cx, cy;
    float behind = 0.0f;
    if (!pixel_of_sample(f, c, cx, cy) || !behind_plane(f, cx, cy, q, nq, behind) ||
        behind > crossing_tolerance_) {
      return false;
    }
    if (behind <= 0.0f || same_plane(f.normal(cx, cy), nq)) return true;
    for (const auto& step : kFourNeighbours) {
      const int nx = std::clamp(cx + step[0], 0, f.width() - 1);
      const int ny = std::clamp(cy + step[1], 0, f.height() - 1);
      float off = 0.0f;
      if (behind_plane(f, nx, ny, q, nq, off) && std::fabs(off) <= crossing_tolerance_ &&
          same_plane(f.normal(nx, ny), nq)) {
        return true;
      }
    }
    return false;
  }

  // How far the surface pixel (x, y) shows lies behind the plane through q with normal nq, along
  // the ray through the pixel's centre; false on background or a ray along the plane.
  static bool behind_plane(const Frame& f, int x, int y, Vec3 q, Vec3 nq, float& behind) {
    float meets;
    if (!f.is_geometry(x, y) ||
        !f.camera().depth_on_plane(float(x) + 0.5f, float(y) + 0.5f, nq, dot(q, nq), meets)) {
      return false;
    }
    behind = f.depth(x, y) - meets;
    return true;
  }

  static bool same_plane(Vec3 n, Vec3 nq) {
    return dot(n, nq) > kSamePlaneCos * length(n) * length(nq);
  }

  float radius_, bias_, thickness_, crossing_tolerance_;
  int directions_, steps_;
  std::vector<Vec3> offsets_;        // [jitter state][direction][step]
  std::vector<float> lane_offsets_;  // [y & 3][sample][x, y, z][lane]
  // With extra layers: per offset its cone, and the same for the vector path ([y & 3][sample]
  // [half_inv_width, extend][lane]).
  std::vector<Cone> cones_;
  std::vector<float> lane_cones_;
  float half_inv_end_width_ = 0.0f;
};

}  // namespace

extern const VariantInfo kHemisphereVariant;
const VariantInfo kHemisphereVariant = {
    "hemisphere",
    "normal-oriented hemisphere kernel: directions cosine-weighted about the normal, each "
    "marched in steps",
    "samples|steps|sample_clustering|thickness|thickness_profile|bias|seed",
    [](const ParamValues& v, const Frame& f) -> std::unique_ptr<Variant> {
      return std::make_unique<Hemisphere>(v, f);
    },
    kSolidThickness | kPlaneDistanceScale | kCarriedSurfaces | kAssumedThickness};

}  // namespace ssao
#endif  // HWY_ONCE
