// SPDX-License-Identifier: MIT
// The pixel filter (parameter pixel_filter): the resolved AO seen through a renderer's
// anti-aliasing. A renderer's passes are filtered over each pixel's footprint, so Cycles' AO pass
// at a pixel on a silhouette mixes the AO of both surfaces by their share of it, where the Depth
// pass (one sample) holds one surface and a per-pixel estimate draws a staircase. Each pixel's
// value spread over its square and blurred by a Gaussian of standard deviation sigma gives a
// 3 x 3 kernel k(dx) k(dy), k = {w, 1 - 2 w, w}, w the Gaussian's mass beyond half a pixel.
#pragma once

#include "frame.h"
#include "image_view.h"
#include "tiles.h"

namespace ssao {

// w for a Gaussian of standard deviation sigma pixels (0: no filter); sigma <= 1 keeps the
// mass beyond 1.5 pixels, which the kernel leaves out, below 7 %.
float pixel_filter_weight(double sigma);

// Tile t's visibility through the filter into out (tile-local rows): `source` holds the
// visibility of tile `around` (t grown by one pixel on every side, clipped to the frame) in rows
// of around's width. Only geometry pixels are filtered and only geometry pixels take part (the
// weights renormalised): AO does not bleed into the sky or the sky's 1 into the AO.
void pixel_filter(const Frame& frame, const Tile& around, const float* source, const Tile& t,
                  float weight, float* out);

// Tile t grown by one pixel on every side, clipped to the frame: what pixel_filter reads.
Tile pixel_filter_source(const Frame& frame, const Tile& t);

// Parameter edge_coverage = beauty (measured in docs/variants.md). At a depth edge the Depth pass
// holds the surface at the pixel's centre, but a renderer's anti-aliased beauty is the
// coverage-weighted mix of both surfaces' colours, and so is its AO pass. Where pixel p of tile t
// has a depth jump (more than kEdgeDepthJump relative) to a 4-neighbour n, p's share beta of its
// own surface is read from the colours and from the normals:
// - colours: the pixel beyond p on its own surface and the one beyond n on n's show colours A and
//   B that differ enough to read a mix (|A - B| at least kEdgeColourContrast x the larger of |A|,
//   |B|), and the colours C of p and N of n lie on the line through B and A, N between them (each
//   within kEdgeColourTolerance x |A - B| of it; else A and B are not the colours of p's and n's
//   surfaces, e.g. a highlight on n): beta = (C - B) . (A - B) / |A - B|^2;
// - normals, where the Normal pass is given with a beauty (`normal`, the depth image's size:
//   frame pixel (x, y) is its pixel (x, y)) and filtered over the pixel like the beauty: the same
//   with the normals,
//   where the two surfaces' differ by kEdgeNormalContrast or more, each is steady one pixel
//   further out (within kEdgeNormalSteady) and p or n shows a mix (by more than
//   kEdgeNormalMixShown; a pass of pixel-centre normals shows none);
// - where neither reads a mix (no beauty, one colour, pixel-centre normals), the depth's
//   staircase: along a straight slanted silhouette the Depth pass draws runs of pixels, and a run
//   that steps one pixel toward n at one end and toward p at the other (followed up to
//   kStaircaseReach pixels each way) places the line between them; beta is the share of the
//   pixel filter (standard deviation `sigma`; 0: p's square) on p's side of it.
// Where both colours and normals read a mix beta is the larger (the smaller share of the other
// surface), and never under kEdgeMinOwnShare (p's centre is on its own surface); out(p) = beta AO_p
// + (1 - beta) AO_n, where AO_p and AO_n are the pixel filter (weight w) over the pixels around p
// on p's and on n's surface alone, from `source` (tile `around`, as for pixel_filter). Where the
// Normal pass is given, p's normal must also be a mix of the normals beyond p and beyond n (within
// kEdgeNormalTolerance of the segment between them): else p holds a third surface too small to
// show elsewhere (the top of a board seen at a grazing angle, a sliver in a pixel), whose colour
// the two-colour model would read as one of the two. Elsewhere out is left as it is. `beauty`
// has the output window's size: frame pixel (x, y) is its pixel (x - dx, y - dy); its first
// three channels are read (one channel: grey). A jump to the sky does not count (the normal
// pass's coverage handles it). `beauty` and `normal` may be empty (not attached).
void mix_edges_by_beauty(const Frame& frame, const ImageView& beauty, const ImageView& normal,
                         int dx, int dy, const Tile& around, const float* source, const Tile& t,
                         float weight, float sigma, float* out);
constexpr float kEdgeDepthJump = 0.05f;
constexpr float kEdgeColourContrast = 0.5f;
constexpr float kEdgeColourTolerance = 0.25f;
constexpr float kEdgeNormalTolerance = 0.3f;
constexpr float kEdgeNormalContrast = 0.15f;
constexpr float kEdgeNormalSteady = 0.05f;
constexpr float kEdgeNormalMixShown = 0.02f;
constexpr float kEdgeMinOwnShare = 0.5f;
constexpr int kStaircaseReach = 16;

}  // namespace ssao
