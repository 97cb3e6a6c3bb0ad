// SPDX-License-Identifier: MIT
// Extra depth layers ("depth2", "depth3", with "facing2", "facing3"): the 2nd and 3rd surface hits
// along each pixel's ray. Against ray-traced AO of analytic scenes: a sphere resting on a floor
// (the floor at the contact is occluded by the whole sphere, not only by its front shell) and a
// thin post in front of a wall (no dark halo on the wall behind it). Bad layers are refused.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include "analytic_scene.h"

using namespace test;

namespace {

constexpr double kRadius = 1.0;  // the AO distance of the runs and of the ray-traced reference

// Runs the default variant, with the scene's 2nd and 3rd hits (and facing) when `layers` is set.
std::vector<float> layered_ao(Scene& s, const Camera& cam, bool layers, bool facing = true,
                              const char* resolution = "full", const char* variant = "hemisphere",
                              int steps = 0) {
  return compute_ao(s, cam, kRadius, variant, true, [&](Job& j) {
    j.set("resolution", resolution);
    if (steps > 0) j.set("steps", steps);
    if (!layers) return;
    j.image("depth2", s.layer[0], s.width, s.height, 1);
    j.image("depth3", s.layer[1], s.width, s.height, 1);
    if (facing) {
      j.image("facing2", s.facing[0], s.width, s.height, 1);
      j.image("facing3", s.facing[1], s.width, s.height, 1);
    }
  });
}

struct Error {
  double rmse = 0, bias = 0;  // ao - reference
  int count = 0;
};

Error error_against(const std::vector<float>& ao, const std::vector<double>& reference,
                    const std::vector<size_t>& pixels) {
  Error e;
  double squared = 0, sum = 0;
  for (size_t k = 0; k < pixels.size(); ++k) {
    const double d = ao[pixels[k]] - reference[k];
    squared += d * d, sum += d;
  }
  e.count = int(pixels.size());
  e.rmse = std::sqrt(squared / e.count), e.bias = sum / e.count;
  return e;
}

// Pixels a test scores and the ray-traced AO at each (about the pixel's own normal).
struct Scored {
  std::vector<size_t> pixels;
  std::vector<double> reference;
  double mean_reference() const {
    double mean = 0;
    for (double r : reference) mean += r / double(reference.size());
    return mean;
  }
};

// The geometry pixels of `s` at least `margin_x` / `margin_y` px inside the frame, every
// `row_step`-th row, that `keep(point)` selects; `rays` rays each.
template <class Keep>
Scored score_where(const Scene& s, const std::vector<Solid>& solids, int rays, int margin_x,
                   int margin_y, int row_step, Keep keep) {
  Scored scored;
  for (int y = margin_y; y < s.height - margin_y; y += row_step) {
    for (int x = margin_x; x < s.width - margin_x; ++x) {
      const size_t i = size_t(y) * s.width + x;
      const V3 p = s.point[i];
      if (!std::isfinite(s.depth[i]) || !keep(p)) continue;
      scored.pixels.push_back(i);
      const V3 normal{s.normal[3 * i], s.normal[3 * i + 1], s.normal[3 * i + 2]};
      scored.reference.push_back(ray_traced_ao(solids, p, normal, kRadius, rays));
    }
  }
  return scored;
}

// One layer's AO of the scene `solids` make, seen by `cam`, against 512-ray AO over the pixels
// `keep` selects (8 px inside the frame's sides, `margin_y` inside its top and bottom, every
// `row_step`-th row); the ray-traced mean into `mean_reference`. A failure, and no error
// (count 0), unless there are more than `more_than` of them.
template <class Keep>
Error one_layer_error_where(const Camera& cam, const std::vector<Solid>& solids, int margin_y,
                            int row_step, size_t more_than, Keep keep,
                            double* mean_reference = nullptr) {
  Scene s = ray_cast(cam, solids);
  const Scored scored = score_where(s, solids, 512, 8, margin_y, row_step, keep);
  EXPECT_GT(scored.pixels.size(), more_than);
  if (!(scored.pixels.size() > more_than)) return Error{};
  if (mean_reference != nullptr) *mean_reference = scored.mean_reference();
  return error_against(layered_ao(s, cam, false), scored.reference, scored.pixels);
}

// A floor seen from 30 degrees above, a sphere of radius 1 resting on it in the middle of the
// view (in view space: the floor's normal tilted towards the camera).
struct SphereOnFloor {
  V3 floor_normal = normalized({0, std::cos(M_PI / 6), std::sin(M_PI / 6)});
  V3 contact{0, 0, -6};
  std::vector<Solid> solids() const {
    return {{{contact, floor_normal}}, polyhedral_sphere(contact + floor_normal * 1.0, 1.0)};
  }
  // Floor pixels within 1.5 radii of the contact point, 8 px from the frame's edge, every
  // `step`-th row and column: their indices and ray-traced AO (the floor's own normal; the
  // sphere's pixels are left out).
  void floor_near_contact(const Scene& s, int step, std::vector<size_t>& pixels,
                          std::vector<double>& reference) const {
    const auto all = solids();
    for (int y = 8; y < s.height - 8; y += step) {
      for (int x = 8; x < s.width - 8; x += step) {
        const size_t i = size_t(y) * s.width + x;
        const V3 p = s.point[i];
        if (!std::isfinite(s.depth[i]) || std::fabs(dot(p - contact, floor_normal)) > 1e-6) {
          continue;
        }
        const V3 along = p - contact;
        if (dot(along, along) > 1.5 * 1.5 * kRadius * kRadius) continue;
        pixels.push_back(i);
        reference.push_back(ray_traced_ao(all, p, floor_normal, kRadius, 256));
      }
    }
  }
};

}  // namespace

TEST(Layers, SphereOnAFloorOccludesTheFloorAsRayTraced) {
  Camera cam;
  cam.width = 160, cam.height = 120;
  const SphereOnFloor scene;
  Scene s = ray_cast(cam, scene.solids());
  std::vector<size_t> pixels;
  std::vector<double> reference;
  scene.floor_near_contact(s, 1, pixels, reference);
  ASSERT_GT(pixels.size(), 500u);
  const Error one = error_against(layered_ao(s, cam, false), reference, pixels);
  const Error three = error_against(layered_ao(s, cam, true), reference, pixels);
  const Error alternating = error_against(layered_ao(s, cam, true, false), reference, pixels);
  const Error half = error_against(layered_ao(s, cam, true, true, "half"), reference, pixels);
  std::printf(
      "[ measure  ] sphere on floor, %d floor px near the contact: one layer RMSE %.4f "
      "bias %+.4f; 3 hits RMSE %.4f bias %+.4f; without facing RMSE %.4f; half "
      "resolution RMSE %.4f\n",
      one.count, one.rmse, one.bias, three.rmse, three.bias, alternating.rmse, half.rmse);
  // One layer misses the sphere's inside beyond the assumed thickness: the floor reads too light.
  EXPECT_GT(one.bias, 0.04);
  EXPECT_LT(three.rmse, 0.7 * one.rmse);
  EXPECT_LT(std::fabs(three.bias), 0.5 * one.bias);
  // Hits alternate in and out on this closed scene: facing changes nothing.
  EXPECT_NEAR(alternating.rmse, three.rmse, 1e-6);
  EXPECT_LT(half.rmse, 0.8 * one.rmse);
}

TEST(Layers, TheSpheresUndersideShadesWithoutBands) {
  // The sphere's own lower part, which the floor occludes more and more towards the contact. A
  // direction is blocked once a step passes below the floor: with point samples each of the
  // pattern's 64 directions (4 per pixel x 16 states) switched at once as the surface turned,
  // and the AO fell in steps, bands along the sphere's parallels that denoising does not remove
  // (the kit's `contact`, docs/variants.md). With the layers the samples are cones, which a
  // surface covers gradually (Hemisphere::Cone).
  Camera cam;
  cam.width = 240, cam.height = 180, cam.lens = 80;  // the sphere 90 px across
  const SphereOnFloor scene;
  const auto solids = scene.solids();
  Scene s = ray_cast(cam, solids);
  const V3 center = scene.contact + scene.floor_normal * 1.0;
  const Scored scored = score_where(s, solids, 256, 8, 8, 1, [&](const V3& p) {
    return length(p - center) < 1.01 && dot(p - center, scene.floor_normal) < -0.3;
  });
  const std::vector<size_t>& pixels = scored.pixels;
  const std::vector<double>& reference = scored.reference;
  ASSERT_GT(pixels.size(), 400u);
  // The bands run along the sphere's parallels, which cross the frame's rows near the bottom:
  // the error's mean per row, less its mean over the 7 rows around, RMS over the rows.
  const auto bands = [&](const std::vector<float>& ao) {
    std::vector<double> sum(size_t(s.height), 0.0), count(size_t(s.height), 0.0);
    for (size_t k = 0; k < pixels.size(); ++k) {
      const size_t row = pixels[k] / size_t(s.width);
      sum[row] += ao[pixels[k]] - reference[k], count[row] += 1;
    }
    double squared = 0;
    int rows = 0;
    for (int y = 3; y < s.height - 3; ++y) {
      double around = 0;
      bool full = true;
      for (int d = -3; d <= 3; ++d) {
        full = full && count[size_t(y + d)] >= 8;
        if (full) around += sum[size_t(y + d)] / count[size_t(y + d)] / 7.0;
      }
      if (!full) continue;
      const double residual = sum[size_t(y)] / count[size_t(y)] - around;
      squared += residual * residual, ++rows;
    }
    return std::sqrt(squared / std::max(rows, 1));
  };
  const auto one = layered_ao(s, cam, false), three = layered_ao(s, cam, true);
  const Error one_error = error_against(one, reference, pixels);
  const Error three_error = error_against(three, reference, pixels);
  const double one_bands = bands(one), three_bands = bands(three);
  std::printf(
      "[ measure  ] sphere's underside, %zu px: one layer RMSE %.4f, bands %.4f; 3 hits RMSE "
      "%.4f, bands %.4f (bands: the error's mean per row less its mean over 7 rows, RMS)\n",
      pixels.size(), one_error.rmse, one_bands, three_error.rmse, three_bands);
  // Measured with point samples: 3 hits RMSE 0.0394, bands 0.0050 (one layer 0.0592, 0.0050).
  EXPECT_LT(three_error.rmse, 0.035);
  EXPECT_LT(three_bands, 0.0045);
}

// World coordinates (y up) seen by a camera at (0, eye_height, 0) looking along -z, pitched down
// by `degrees`: solids into view space and view-space points back.
struct PitchedView {
  double c, sn;
  V3 eye;
  PitchedView(double degrees, double eye_height)
      : c(std::cos(degrees * M_PI / 180.0)),
        sn(std::sin(degrees * M_PI / 180.0)),
        eye{0, eye_height, 0} {}
  V3 rotate(V3 v) const { return V3{v.x, v.y * c - v.z * sn, v.y * sn + v.z * c}; }
  Solid to_view(const Solid& solid) const {
    Solid out;
    for (const Plane& plane : solid)
      out.push_back({rotate(plane.point - eye), rotate(plane.normal)});
    return out;
  }
  V3 to_world(V3 p) const { return V3{p.x, p.y * c + p.z * sn, -p.y * sn + p.z * c} + eye; }
};

// A ball on a floor 7 before a wall, seen from low down: on screen it hides the crease where
// the floor meets the wall. The wall just above the crease beside the ball's top is darkened by
// the floor running on behind the ball. Of the surfaces seen beside the ball's silhouettes,
// carried on behind it (Frame::carried_depth), the floor, seen beside its lower half, is the one
// the rays through it meet first; the nearest silhouette's, the wall above the ball, carried the
// wall down behind it and left the floor out: RMSE 0.1408, bias +0.1110 against ray-traced AO.
TEST(Layers, OneLayerCarriesTheCreaseBehindABall) {
  Camera cam;
  cam.width = 160, cam.height = 120;
  const PitchedView view(7.0, 1.5);
  const double radius = 0.5, wall = -12.0, ball_z = wall + 7.0 + radius;
  const std::vector<Solid> solids = {view.to_view({{{0, 0, 0}, {0, 1, 0}}}),
                                     view.to_view(box({-40, -1, -60}, {40, 20, wall})),
                                     view.to_view(polyhedral_sphere({0, radius, ball_z}, radius))};
  Scene s = ray_cast(cam, solids);
  // The wall within the radius above the crease, as wide as the ball on either side of it.
  const Scored crease = score_where(s, solids, 256, 8, 8, 1, [&](const V3& p) {
    const V3 world = view.to_world(p);
    return std::fabs(world.z - wall) < 1e-6 && std::fabs(world.x) < 2.0 * radius && world.y < 1.0;
  });
  ASSERT_GT(crease.pixels.size(), 200u);
  const Error error = error_against(layered_ao(s, cam, false), crease.reference, crease.pixels);
  std::printf(
      "[ measure  ] wall above the crease behind a ball, %zu px: one layer RMSE %.4f bias "
      "%+.4f\n",
      crease.pixels.size(), error.rmse, error.bias);
  EXPECT_LT(error.rmse, 0.08);
  EXPECT_LT(error.bias, 0.07);
}

TEST(Layers, OneLayerCarriesASurfaceOnBehindAPost) {
  // A post in front of a deep block standing on a floor, seen from above. The block's base
  // behind the post is hidden: without extra layers a sample from the floor in front of the
  // block that lands there lies behind the post's front, beyond the assumed thickness, and
  // counted as open. The block's face beside the post, carried on behind it as its tangent
  // plane (Frame::carried_depth), closes it.
  Camera cam;
  cam.width = 160, cam.height = 120;
  const PitchedView view(25.0, 3.0);
  const std::vector<Solid> solids = {view.to_view({{{0, 0, 0}, {0, 1, 0}}}),
                                     view.to_view(box({-20, -1, -30}, {20, 4, -9})),
                                     view.to_view(box({-0.3, -1, -6.6}, {0.3, 4, -6.0}))};
  Scene s = ray_cast(cam, solids);
  // The floor in front of the block's base, within the radius of it, beside and behind the post.
  const Scored base = score_where(s, solids, 256, 8, 8, 1, [&](const V3& p) {
    const V3 world = view.to_world(p);
    return std::fabs(world.y) < 1e-6 && world.z > -9.0 && world.z < -8.0 &&
           std::fabs(world.x) < 1.5;
  });
  ASSERT_GT(base.pixels.size(), 100u);
  const auto ao = layered_ao(s, cam, false);
  const Error error = error_against(ao, base.reference, base.pixels);
  std::printf(
      "[ measure  ] one layer, floor at a block's base behind a post (%d px): RMSE %.4f bias "
      "%+.4f\n",
      error.count, error.rmse, error.bias);
  // Measured: RMSE 0.0680 bias +0.0476; with the hidden base counted as open 0.0910 +0.0635.
  EXPECT_LT(error.rmse, 0.08);
}

TEST(Layers, ThinPostCastsNoHaloOnTheWallBehindIt) {
  Camera cam;
  cam.width = 128, cam.height = 96;
  // A post 0.3 wide, 1.05 in front of a wall: farther than the radius, so the wall's AO is 1.
  const std::vector<Solid> solids = {{{{0, 0, -6}, {0, 0, 1}}},
                                     box({-0.15, -10, -4.95}, {0.15, 10, -4.65})};
  Scene s = ray_cast(cam, solids);
  const auto wall_near_post = [&](int x, int y) {
    const size_t i = size_t(y) * s.width + x;
    return s.depth[i] > 5.9f && std::fabs(s.point[i].x) < 0.7 && y > 4 && y < s.height - 4;
  };
  const Stats one = stats_over(s, layered_ao(s, cam, false), wall_near_post);
  const Stats three = stats_over(s, layered_ao(s, cam, true), wall_near_post);
  std::printf(
      "[ measure  ] thin post: wall within 0.7 of it (%d px): one layer mean %.4f min "
      "%.4f; 3 hits mean %.4f min %.4f (ray-traced: 1)\n",
      one.count, one.mean, one.min, three.mean, three.min);
  ASSERT_GT(one.count, 200);
  // One layer: as deep as wide (0.3, Frame::last_thickness), the post stops 0.75 short of the
  // wall; with the assumed thickness (0.5) it drew a halo there, min 0.82 (the extra layers'
  // case; OneLayerTakesAPostsDepthFromItsWidth tests the measure within the radius).
  EXPECT_GE(one.min, 0.97);
  EXPECT_GE(three.min, 0.97);
  EXPECT_GE(three.mean, 0.995);
}

// Two posts 0.2 wide and deep, 0.3 in front of a wall (within the radius), seen at the given
// size: the one-layer AO of the wall beside and behind them against ray-traced AO.
Error two_posts_before_a_wall(int width, int height) {
  Camera cam;
  cam.width = width, cam.height = height;
  const double wall_z = -6.0, front = -5.5, back = -5.7;
  const std::vector<Solid> solids = {{{{0, 0, wall_z}, {0, 0, 1}}},
                                     box({-0.7, -10, back}, {-0.5, 10, front}),
                                     box({0.5, -10, back}, {0.7, 10, front})};
  const bool large = width >= 128;  // every other row scored, 8 px from the top and bottom
  const Error one = one_layer_error_where(
      cam, solids, large ? 8 : 4, large ? 2 : 1, large ? 500 : 400,
      [&](const V3& p) { return std::fabs(p.z - wall_z) < 1e-6 && std::fabs(p.x) < 1.2; });
  std::printf(
      "[ measure  ] two posts before a wall, %dx%d, %d wall px: one layer RMSE %.4f bias %+.4f\n",
      width, height, one.count, one.rmse, one.bias);
  return one;
}

// Without extra layers the depth of a post is taken from its width (Frame::last_thickness): the
// posts (4.5 px wide) darken the wall beside and behind them only as much as something 0.2 deep
// does, where the assumed thickness (half the radius) drew a halo as deep as a wall: RMSE
// 0.0947, bias -0.0849 before the measure (512 rays a pixel; measured after it: 0.0242,
// +0.0169).
TEST(Layers, OneLayerTakesAPostsDepthFromItsWidth) {
  const Error one = two_posts_before_a_wall(128, 96);
  EXPECT_LT(one.rmse, 0.05);
  EXPECT_GT(one.bias, -0.04);
}

// At 64x48 the posts are 2.3 px wide: runs of 2 or 3 pixels, taken as 4 px wide (the widest
// they can be) rather than as deep as the assumed thickness: RMSE 0.0717, bias -0.0579 when
// such runs were left out (measured with them: 0.0635, -0.0511).
TEST(Layers, OneLayerTakesANarrowPostAsFourPixelsWide) {
  const Error one = two_posts_before_a_wall(64, 48);
  EXPECT_LT(one.rmse, 0.068);
  EXPECT_GT(one.bias, -0.055);
}

// Two posts 0.1 wide and deep, 0.45 in front of a wall, each with a column 0.08 wide at a depth
// of 3.5 hiding its inner half: the post's visible pixel has the nearer column past one end and
// the wall past the column's other side, so the post ends behind the column and is no wider
// than both (Frame::measure_post_thickness). Read as a run that may go on behind the column,
// the post kept the assumed thickness (half the radius), reaching the wall: RMSE 0.0711, bias
// -0.0426 on the wall (measured with the measure: 0.0593, +0.0534; the hidden half's own shade
// on the wall beside the column is what one layer cannot see).
TEST(Layers, OneLayerMeasuresAPostPartlyHiddenByAColumn) {
  Camera cam;
  cam.width = 128, cam.height = 96;
  const double wall_z = -6.0, front = -5.45, back = -5.55;
  const std::vector<Solid> solids = {{{{0, 0, wall_z}, {0, 0, 1}}},
                                     box({-0.65, -10, back}, {-0.55, 10, front}),
                                     box({0.55, -10, back}, {0.65, 10, front}),
                                     box({-0.385, -10, -3.58}, {-0.309, 10, -3.5}),
                                     box({0.309, -10, -3.58}, {0.385, 10, -3.5})};
  const Error one = one_layer_error_where(cam, solids, 8, 2, 500, [&](const V3& p) {
    return std::fabs(p.z - wall_z) < 1e-6 && std::fabs(p.x) < 1.2;
  });
  std::printf(
      "[ measure  ] posts half hidden by columns before a wall, %d wall px: one layer RMSE %.4f "
      "bias %+.4f\n",
      one.count, one.rmse, one.bias);
  EXPECT_LT(one.rmse, 0.065);
}

// A shelf board 2 cm thick and 0.3 deep out of a wall, seen from the front a little above its
// level: the wall just above the board sees the board's top face as a sliver a pixel or two tall.
// A direction down from a receiver there meets the board before its first step, which lies past
// the board's front edge, in front of what its pixel shows: neither point is hidden, so neither
// the steps nor the crossing test see the board (Hemisphere::halfway).
TEST(Layers, OneLayerSeesABoardBeforeTheFirstStep) {
  Camera cam;
  cam.width = 128, cam.height = 96;
  const double wall_z = -3.0, board_top = -0.28;
  const std::vector<Solid> solids = {{{{0, 0, wall_z}, {0, 0, 1}}},
                                     box({-10, board_top - 0.02, wall_z}, {10, board_top, -2.7})};
  double mean_reference = 0;
  const Error one = one_layer_error_where(
      cam, solids, 4, 1, 300,
      [&](const V3& p) {
        return std::fabs(p.z - wall_z) < 1e-6 && p.y > board_top && p.y < board_top + 0.3;
      },
      &mean_reference);
  std::printf(
      "[ measure  ] wall above a shelf board, %d px (ray-traced mean %.4f): one layer RMSE %.4f "
      "bias %+.4f\n",
      one.count, mean_reference, one.rmse, one.bias);
  EXPECT_LT(mean_reference, 0.9);  // the board occludes: the test measures something
  // Without the point halfway to the first step: RMSE 0.1683, bias +0.1666; with it 0.1419,
  // +0.1399. Still light: one layer sees neither the board's underside nor its depth.
  EXPECT_LT(one.rmse, 0.155);
  EXPECT_LT(one.bias, 0.155);
}

// Without extra layers a face bounds its solid's depth by the side face a deeper solid would
// show (Frame::bound_by_side_face): a rail 0.2 tall and 0.05 deep, above the eye and 0.3 in
// front of a wall, shows its front and a pixel or so of its underside; were it deeper, more of
// the underside would show below it where the wall does. The wall above and below it is
// darkened only as much as by something that thin, where the assumed thickness (half the
// radius) made it a block reaching the wall.
TEST(Layers, OneLayerBoundsARailByTheSideItDoesNotShow) {
  Camera cam;
  cam.width = 128, cam.height = 96;
  const double wall_z = -6.0, front = -5.7, back = -5.65, rail_y = 1.2;
  const std::vector<Solid> solids = {{{{0, 0, wall_z}, {0, 0, 1}}},
                                     box({-10, rail_y, front}, {10, rail_y + 0.2, back})};
  const Error one = one_layer_error_where(cam, solids, 4, 1, 500, [&](const V3& p) {
    return std::fabs(p.z - wall_z) < 1e-6 && std::fabs(p.y - rail_y - 0.1) < 0.7;
  });
  std::printf("[ measure  ] a rail before a wall, %d wall px: one layer RMSE %.4f bias %+.4f\n",
              one.count, one.rmse, one.bias);
  EXPECT_LT(one.rmse, 0.05);
  EXPECT_GT(one.bias, -0.04);
}

// Seen from above, a rail shows its top face as well as its front: the top, shown to its back
// edge where the wall behind appears, is the side of the solid behind the front face and bounds
// its depth (Frame::bound_by_shown_side). A rail 0.2 tall and 0.15 deep, 0.45 before a wall,
// seen from 30 degrees above (its top about 3 px tall): the wall around it is darkened as by
// something that thin (bounded over the front and over the top: rays through either cross the
// same slab), where the assumed thickness (half the radius) made it a block reaching the wall:
// RMSE 0.2011, bias -0.1512 (bounding the front face alone: 0.1187, -0.0850).
TEST(Layers, OneLayerBoundsARailByTheTopItShows) {
  Camera cam;
  cam.width = 160, cam.height = 120;
  const PitchedView view(30.0, 2.0);
  const double wall_z = -3.6, rail_bottom = 0.1, rail_top = 0.3;
  const std::vector<Solid> solids = {
      view.to_view(box({-40, -20, -60}, {40, 20, wall_z})),
      view.to_view(box({-10, rail_bottom, -3.15}, {10, rail_top, -3.0}))};
  const Error one = one_layer_error_where(cam, solids, 8, 1, 500, [&](const V3& p) {
    const V3 world = view.to_world(p);
    return std::fabs(world.z - wall_z) < 1e-6 &&
           std::fabs(world.y - 0.5 * (rail_bottom + rail_top)) < 0.8;
  });
  std::printf("[ measure  ] a rail seen from above, %d wall px: one layer RMSE %.4f bias %+.4f\n",
              one.count, one.rmse, one.bias);
  // Measured: RMSE 0.0590, bias -0.0308.
  EXPECT_LT(one.rmse, 0.075);
  EXPECT_GT(one.bias, -0.05);
}

// A bench of slats 0.12 deep and 0.06 thick with gaps of 0.06, 0.9 above a floor, seen from 20
// degrees above: each slat's top runs back to the next slat's front face a few centimetres
// behind it, a step in depth no larger than the grazing top's own from pixel to pixel, so the
// bench read as one surface as deep as the assumed thickness (half the radius), and the floor
// under and before it came out far too dark: RMSE 0.2196, bias -0.2083 against ray-traced AO.
// The normals and the depths part the slats (Frame::passes_in_front); each is as deep as its top
// shows (measured: 0.0491, +0.0145).
TEST(Layers, OneLayerPartsABenchsSlatsSeenFromAbove) {
  Camera cam;
  cam.width = 320, cam.height = 180;
  const PitchedView view(20.0, 2.1);
  const double floor_y = 0.0, front = -3.0, top = 0.9;
  std::vector<Solid> solids = {view.to_view(box({-40, -20, -60}, {40, floor_y, 20}))};
  for (int k = 0; k < 6; ++k) {
    solids.push_back(view.to_view(
        box({-1.0, top - 0.06, front - 0.12 - 0.18 * k}, {1.0, top, front - 0.18 * k})));
  }
  double mean_reference = 1.0;
  const Error one = one_layer_error_where(
      cam, solids, 8, 2, 500,
      [&](const V3& p) {
        const V3 world = view.to_world(p);
        return std::fabs(world.y - floor_y) < 1e-6 && std::fabs(world.x) < 1.0 &&
               world.z < front + 0.3 && world.z > front - 1.32;
      },
      &mean_reference);
  std::printf(
      "[ measure  ] the floor under a slatted bench, %d px (ray-traced mean %.4f): one layer "
      "RMSE %.4f bias %+.4f\n",
      one.count, mean_reference, one.rmse, one.bias);
  EXPECT_LT(mean_reference, 0.9);  // the slats occlude: the test measures something
  EXPECT_LT(one.rmse, 0.07);
  EXPECT_GT(one.bias, -0.05);
}

// Slats 0.4 wide and 0.1 deep, 0.5 in front of a wall 13 away: 4 % nearer than the wall, less
// than the depth jump that ends a run of one surface (Frame::kCarryJump, 5 %), yet far more than
// the slats' and the wall's own steps from pixel to pixel, so each slat's run ends at its edges
// and its width bounds its depth (Frame::measure_post_thickness). The wall between them is then
// darkened about as by something that thin, where the assumed thickness (half the radius) made
// each slat a block reaching the wall: RMSE 0.151, bias -0.144 against ray-traced AO.
TEST(Layers, OneLayerTellsSlatsFromTheWallJustBehindThem) {
  Camera cam;
  cam.width = 128, cam.height = 96;
  const double wall_z = -13.0, back = -12.5, front = -12.4;
  std::vector<Solid> solids = {{{{0, 0, wall_z}, {0, 0, 1}}}};
  for (int k = -5; k <= 5; ++k) {
    solids.push_back(box({k * 1.2 - 0.2, -10, back}, {k * 1.2 + 0.2, 10, front}));
  }
  const Error one = one_layer_error_where(
      cam, solids, 4, 1, 500, [&](const V3& p) { return std::fabs(p.z - wall_z) < 1e-6; });
  std::printf("[ measure  ] slats 4 %% before a wall, %d wall px: one layer RMSE %.4f bias %+.4f\n",
              one.count, one.rmse, one.bias);
  EXPECT_LT(one.rmse, 0.11);
  EXPECT_GT(one.bias, -0.08);
}

// The bound holds for a receiver behind the face only: a board 0.02 thick standing on a floor,
// its top well below the eye, shows no top face (so it is bounded), yet the floor in front
// of it reaches the points behind the board through its face and stays as dark as a ray
// tracer's.
TEST(Layers, ABoundedBoardStillShadesTheFloorBeforeIt) {
  Camera cam;
  cam.width = 96, cam.height = 128;  // portrait: the floor before the board is in the frame
  const double floor_y = -1.5, board_z = -4.0, board_top = -0.9;
  const std::vector<Solid> solids = {{{{0, floor_y, 0}, {0, 1, 0}}},
                                     box({-10, floor_y, board_z - 0.02}, {10, board_top, board_z})};
  double mean_reference = 1.0;
  const Error one = one_layer_error_where(
      cam, solids, 4, 1, 300,
      [&](const V3& p) {
        return std::fabs(p.y - floor_y) < 1e-6 && p.z > board_z && p.z < board_z + 0.6;
      },
      &mean_reference);
  std::printf(
      "[ measure  ] floor before a board, %d px (ray-traced mean %.4f): one layer RMSE %.4f "
      "bias %+.4f\n",
      one.count, mean_reference, one.rmse, one.bias);
  EXPECT_LT(mean_reference, 0.85);  // the board occludes: the test measures something
  EXPECT_LT(one.rmse, 0.06);
  EXPECT_LT(one.bias, 0.04);
}

TEST(Layers, ThinBoardOverAWallIsNoLighterWithLayers) {
  // A shelf board 2 cm thick sticking out of a wall (a bookcase's back panel), seen from below
  // its level: the camera sees the wall under it and the board's underside; above the board is
  // open. A point sample rarely lands inside the board, and with layers a sample above it is
  // free space behind its back face: the steps must see the board between them
  // (Hemisphere::crossing). The frame is rendered with a guard band and scored inside it (the
  // AO of an output window: OverscanWithLayersEqualsTheWidenedFrameCropped), as the layers are
  // used: without it the samples above the board leave the top of a 128 px frame and both
  // readings are +0.05 too light for that reason alone.
  constexpr int kBand = 96;
  Camera frame;
  frame.width = 128, frame.height = 128;
  const Camera cam = widened(frame, kBand);
  const double wall_z = -2.0, board_y = 0.4, thickness = 0.02;
  const std::vector<Solid> solids = {
      {{{0, 0, wall_z}, {0, 0, 1}}},
      box({-4, board_y, wall_z - 0.5}, {4, board_y + thickness, -1})};
  Scene s = ray_cast(cam, solids);
  // The wall within 0.6 below the board; 1024 rays: the reference's own noise (0.014 RMS at AO
  // 0.7) stays below the errors.
  const Scored scored = score_where(s, solids, 1024, kBand + 4, kBand + 4, 1, [&](const V3& p) {
    return std::fabs(p.z - wall_z) < 1e-6 && p.y <= board_y && p.y >= board_y - 0.6;
  });
  const std::vector<size_t>& pixels = scored.pixels;
  const std::vector<double>& reference = scored.reference;
  ASSERT_GT(pixels.size(), 500u);
  const Error one = error_against(layered_ao(s, cam, false), reference, pixels);
  const Error three = error_against(layered_ao(s, cam, true), reference, pixels);
  const Error three_6 =
      error_against(layered_ao(s, cam, true, true, "full", "hemisphere", 6), reference, pixels);
  const double mean_reference = scored.mean_reference();
  std::printf(
      "[ measure  ] 2 cm board over a wall, %d wall px under it (ray-traced mean %.4f), %d px "
      "band: one layer RMSE %.4f bias %+.4f; 3 hits RMSE %.4f bias %+.4f (4 x 6 steps: %.4f "
      "%+.4f)\n",
      one.count, mean_reference, kBand, one.rmse, one.bias, three.rmse, three.bias, three_6.rmse,
      three_6.bias);
  EXPECT_LT(mean_reference, 0.8);  // the board occludes: the test measures something
  // Without the crossing test the layers read this wall far too light (RMSE 0.140, bias +0.121
  // without the band). With it the board is seen, once per direction, at the pair of steps
  // around it; with point samples the layers stayed lighter than one layer (RMSE 0.0246, bias
  // +0.015), the crossings missed where the upper step's pixel shows the wall beside the
  // board's underside. As cones, samples just below the underside count in part: within 0.02 of
  // ray-traced AO, and better than one layer (issue 31).
  EXPECT_LT(three.rmse, 0.02);
  EXPECT_LE(three.rmse, one.rmse);
  EXPECT_LT(std::fabs(three.bias), 0.02);
  EXPECT_LT(std::fabs(one.bias), 0.02);
}

// A 2 cm board standing `depth` out of a wall at z = -4, from x = board_x to board_x + 0.02, seen
// by a 256 x 192 camera at the origin: one layer's and 3 hits' error (and the ray-traced mean, 512
// rays) over the wall pixels near the centre rows for which `scored_wall` holds (their count:
// `one.count`).
struct BoardOnAWall {
  Error one, three;
  double mean_reference = 0;
};

BoardOnAWall board_on_a_wall(double board_x, double depth,
                             const std::function<bool(const V3&)>& scored_wall) {
  Camera cam;
  cam.width = 256, cam.height = 192;
  const double wall_z = -4.0, thickness = 0.02;
  const std::vector<Solid> solids = {
      {{{0, 0, wall_z}, {0, 0, 1}}},
      box({board_x, -10, wall_z - 0.5}, {board_x + thickness, 10, wall_z + depth})};
  Scene s = ray_cast(cam, solids);
  const Scored scored = score_where(s, solids, 512, 8, 80, 2, [&](const V3& p) {
    return std::fabs(p.z - wall_z) < 1e-6 && scored_wall(p);
  });
  BoardOnAWall result;
  result.one = error_against(layered_ao(s, cam, false), scored.reference, scored.pixels);
  result.three = error_against(layered_ao(s, cam, true), scored.reference, scored.pixels);
  result.mean_reference = scored.mean_reference();
  return result;
}

TEST(Layers, ABoardSeenEdgeOnDarkensTheWallBesideIt) {
  // A 2 cm board standing out of a wall, 1 deep, seen nearly edge-on (a bookcase's side panel
  // from in front): 2 px wide on screen, where the steps of a direction lie about 5 px apart.
  // With layers a step beyond the board is free space, so the wall beside it reads light unless
  // a test between the steps lands on the board (Hemisphere::between).
  // The wall within 0.5 of the board on either side.
  const double board_x = 0.1;
  const BoardOnAWall b =
      board_on_a_wall(board_x, 1.0, [&](const V3& p) { return std::fabs(p.x - board_x) < 0.5; });
  ASSERT_GT(b.one.count, 300);
  const Error &one = b.one, &three = b.three;
  const double mean_reference = b.mean_reference;
  std::printf(
      "[ measure  ] 2 cm board seen edge-on, %d wall px beside it (ray-traced mean %.4f): one "
      "layer RMSE %.4f bias %+.4f; 3 hits RMSE %.4f bias %+.4f\n",
      one.count, mean_reference, one.rmse, one.bias, three.rmse, three.bias);
  EXPECT_LT(mean_reference, 0.85);  // the board occludes: the test measures something
  // Now 0.0714. Before the test between steps: one layer 0.1913 (bias +0.187), 3 hits 0.1386
  // (+0.132); 24 steps without it 0.0766. What is left is mostly the directions whose steps and
  // halfway points all miss the board's 2 px on screen (48 steps with it: 0.0440).
  EXPECT_LT(three.rmse, 0.1);
  EXPECT_LT(three.rmse, 0.5 * one.rmse);
  EXPECT_LT(three.bias, 0.1);
}

TEST(Layers, ABoardSeenAtAnAngleDarkensTheWallOnItsHiddenSide) {
  // A 2 cm board standing out of a wall (a bookcase's divider), seen from its right: the camera
  // sees its right face, the wall right of it, and the wall left of it but for the strip the
  // board hides. From the wall on its left, a direction's steps on either side of the board both
  // lie in free space, in front of what their pixels show, so neither sees the board; the
  // point halfway between lands on its right face, a solid 2 cm deep along the ray
  // (Hemisphere::between): the crossing test with that face's plane.
  // The wall within the radius left of the board's right face, at x = -0.5.
  const double right_face = -0.5;
  const BoardOnAWall b = board_on_a_wall(right_face - 0.02, 0.6, [&](const V3& p) {
    return p.x < right_face && p.x > right_face - kRadius;
  });
  ASSERT_GT(b.one.count, 300);
  const Error &one = b.one, &three = b.three;
  const double mean_reference = b.mean_reference;
  std::printf(
      "[ measure  ] 2 cm board seen at an angle, %d wall px on its hidden side (ray-traced mean "
      "%.4f): one layer RMSE %.4f bias %+.4f; 3 hits RMSE %.4f bias %+.4f\n",
      one.count, mean_reference, one.rmse, one.bias, three.rmse, three.bias);
  EXPECT_LT(mean_reference, 0.85);  // the board occludes: the test measures something
  // Now 0.0209 (bias +0.0139); one layer 0.0656 (+0.0554). With the halfway point as a point
  // sample only, 3 hits read 0.0280 (+0.0228).
  EXPECT_LT(three.rmse, 0.024);
  EXPECT_LT(three.bias, 0.018);
  EXPECT_LT(three.rmse, 0.5 * one.rmse);
}

TEST(Layers, HorizonReadsThemAsSolidsInItsSlices) {
  // The visibility bitmask marks, per slice, the sectors a solid covers from its front face to
  // the back face that closes it, instead of an assumed thickness.
  Camera cam;
  cam.width = 160, cam.height = 120;
  const SphereOnFloor scene;
  Scene s = ray_cast(cam, scene.solids());
  std::vector<size_t> pixels;
  std::vector<double> reference;
  scene.floor_near_contact(s, 2, pixels, reference);
  ASSERT_GT(pixels.size(), 200u);
  const Error one =
      error_against(layered_ao(s, cam, false, true, "full", "horizon"), reference, pixels);
  const Error three =
      error_against(layered_ao(s, cam, true, true, "full", "horizon"), reference, pixels);
  // The thin post: no halo on the wall behind it.
  Camera post_cam;
  post_cam.width = 128, post_cam.height = 96;
  Scene post =
      ray_cast(post_cam, {{{{0, 0, -6}, {0, 0, 1}}}, box({-0.15, -10, -4.95}, {0.15, 10, -4.65})});
  const auto wall_near_post = [&](int x, int y) {
    const size_t i = size_t(y) * post.width + x;
    return post.depth[i] > 5.9f && std::fabs(post.point[i].x) < 0.7 && y > 4 && y < post.height - 4;
  };
  const Stats halo =
      stats_over(post, layered_ao(post, post_cam, true, true, "full", "horizon"), wall_near_post);
  std::printf(
      "[ measure  ] horizon: sphere on floor, one layer RMSE %.4f bias %+.4f; 3 hits RMSE %.4f "
      "bias %+.4f; wall behind a thin post with 3 hits: min %.4f (ray-traced 1)\n",
      one.rmse, one.bias, three.rmse, three.bias, halo.min);
  EXPECT_LT(three.rmse, 0.7 * one.rmse);
  EXPECT_GE(halo.min, 0.97);
}

TEST(Layers, FacingTellsAnOpenSurfaceFromASolid) {
  // A card 1 in front of a wall, made an open (one-sided) surface below: the wall behind it is
  // its 2nd hit, a front face.
  Camera cam;
  cam.width = 96, cam.height = 64;
  const std::vector<Solid> solids = {{{{0, 0, -6}, {0, 0, 1}}},
                                     box({-0.5, -10, -5.0}, {0.5, 10, -4.9})};
  Scene s = ray_cast(cam, solids);
  // Drop the card's back face, as an open mesh has none: the wall becomes hit 2, a front face.
  for (size_t i = 0; i < s.depth.size(); ++i) {
    if (s.facing[0][i] == 1.0f && s.layer[1][i] > 5.9f) {
      s.layer[0][i] = s.layer[1][i], s.facing[0][i] = 0.0f;
      s.layer[1][i] = std::numeric_limits<float>::infinity(), s.facing[1][i] = 0.0f;
    }
  }
  const auto wall_beside_card = [&](int x, int y) {
    const size_t i = size_t(y) * s.width + x;
    return s.depth[i] > 5.9f && std::fabs(s.point[i].x) < 1.0 && y > 4 && y < s.height - 4;
  };
  // The same steps with and without layers (their presets differ), so that only the reading of
  // the hits differs.
  const auto layered = [&](bool facing) {
    return layered_ao(s, cam, true, facing, "full", "hemisphere", 6);
  };
  // One layer with the thickness the layered reading assumes: the same everywhere.
  const std::vector<float> flat = compute_ao(s, cam, kRadius, "hemisphere", true, [&](Job& j) {
    j.set("resolution", "full");
    j.set("steps", 6);
    j.set("thickness_profile", "constant");
  });
  const Stats one = stats_over(s, flat, wall_beside_card);
  const Stats faced = stats_over(s, layered(true), wall_beside_card);
  const Stats alternating = stats_over(s, layered(false), wall_beside_card);
  std::printf(
      "[ measure  ] open card: wall beside it: one layer %.5f, facing given %.5f, "
      "alternating %.5f\n",
      one.mean, faced.mean, alternating.mean);
  // With its facing, a front-facing 2nd hit leaves the card to the thickness rule, as one layer
  // does (the same up to the layered estimator's cones, measured 1e-5); taken as alternating,
  // the gap up to the wall would be the inside of a solid.
  EXPECT_NEAR(faced.mean, one.mean, 0.002);
  EXPECT_LT(alternating.mean, one.mean - 0.02);
}

TEST(Layers, OneLayerShapesTheThicknessByTheSilhouettes) {
  // A ball before a wall, one layer, the wall around it against ray-traced AO. A small ball
  // standing off the wall: beyond its rim the view only grazes it, and a constant thickness
  // drew a halo on the wall there. A big ball almost touching the wall: its middle, deeper than
  // the assumed thickness, reaches the wall beside it.
  struct Case {
    double ball, gap;
  };
  for (const Case c : {Case{0.3, 0.3}, Case{1.0, 0.05}}) {
    Camera cam;
    cam.width = 160, cam.height = 120;
    const V3 centre{0.0, 0.0, -6.0 + c.gap + c.ball};
    const std::vector<Solid> solids = {{{{0, 0, -6}, {0, 0, 1}}},
                                       polyhedral_sphere(centre, c.ball)};
    Scene s = ray_cast(cam, solids);
    const Scored around = score_where(s, solids, 256, 4, 4, 1, [&](const V3& p) {
      return p.z < -5.99 && std::hypot(p.x - centre.x, p.y - centre.y) < c.ball + kRadius;
    });
    ASSERT_GT(around.pixels.size(), 1000u);
    const auto one_layer = [&](const char* profile) {
      return error_against(compute_ao(s, cam, kRadius, "hemisphere", true,
                                      [&](Job& j) {
                                        j.set("resolution", "full");
                                        j.set("thickness_profile", profile);
                                      }),
                           around.reference, around.pixels);
    };
    const Error shaped = one_layer("silhouettes"), flat = one_layer("constant");
    std::printf(
        "[ measure  ] wall around a ball of radius %.1f, %.2f off it, %zu px: one layer RMSE "
        "%.4f bias %+.4f (constant thickness: %.4f, %+.4f)\n",
        c.ball, c.gap, around.pixels.size(), shaped.rmse, shaped.bias, flat.rmse, flat.bias);
    EXPECT_LT(shaped.rmse, 0.9 * flat.rmse) << c.ball;
  }
}

TEST(Layers, ACardIsReadTheSameFromEitherSideWhenHandedOnAsATwin) {
  // A card (a single plane: leaves, a fence, paper) 1 in front of a wall, and a post in front
  // of the card. Behind the post the card is the ray's 3rd surface; rendered without knowing it
  // is open, it is a front face or a back face depending on which way its normal points, and a
  // back face reads as leaving a solid entered at the post: the gap between them a solid. The
  // Blender add-on's helper knows a card from a closed mesh and hands it on as a front face and
  // a back face at its depth (docs/conventions.md, "Open surfaces"): a solid of no thickness,
  // the same whichever way it faces.
  Camera cam;
  cam.width = 128, cam.height = 96;
  const Solid wall = {{{0, 0, -6}, {0, 0, 1}}};
  const Solid card = box({-0.6, -10, -5.001}, {0.6, 10, -5.0});  // 1 mm, for the rays
  const Solid post = box({-0.15, -10, -4.3}, {0.15, 10, -4.0});
  const std::vector<Solid> solids = {wall, card, post};
  Scene s = ray_cast(cam, solids);
  enum class Card { kTwin, kFront, kBack };
  const auto ao_with = [&](Card reading) {
    constexpr int kLayers = 4;
    const size_t n = s.depth.size();
    std::vector<std::vector<float>> depth(kLayers, std::vector<float>(n, INFINITY));
    std::vector<std::vector<float>> facing(kLayers, std::vector<float>(n, 0.0f));
    for (int y = 0; y < cam.height; ++y) {
      for (int x = 0; x < cam.width; ++x) {
        V3 o, d;
        cam.ray(x, y, o, d);
        std::vector<std::pair<double, float>> hits;  // (t, facing)
        for (const Solid* solid : {&wall, &post}) {
          double t = 0;
          V3 unused{0, 0, 0};
          if (!enter_solid(*solid, o, d, t, unused)) continue;
          hits.push_back({t, 0.0f});
          const double t_exit = exit_solid(*solid, o, d);
          if (std::isfinite(t_exit)) hits.push_back({t_exit, 1.0f});
        }
        double t = 0;
        V3 unused{0, 0, 0};
        if (enter_solid(card, o, d, t, unused)) {
          if (reading == Card::kTwin) {
            hits.push_back({t, 0.0f});
            hits.push_back({t * (1 + 1e-9), 1.0f});
          } else {
            hits.push_back({t, reading == Card::kBack ? 1.0f : 0.0f});
          }
        }
        std::sort(hits.begin(), hits.end());
        const size_t i = size_t(y) * cam.width + x;
        for (size_t k = 1; k < hits.size() && k <= kLayers; ++k) {
          depth[k - 1][i] = float(-(o + d * hits[k].first).z);
          facing[k - 1][i] = hits[k].second;
        }
      }
    }
    return compute_ao(s, cam, kRadius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      for (int k = 0; k < kLayers; ++k) {
        const std::string number = std::to_string(k + 2);
        j.image(("depth" + number).c_str(), depth[k], s.width, s.height, 1);
        j.image(("facing" + number).c_str(), facing[k], s.width, s.height, 1);
      }
    });
  };
  // The wall and the card within 0.7 of the post, away from the frame's top and bottom.
  std::vector<size_t> pixels;
  std::vector<double> reference;
  for (int y = 6; y < cam.height - 6; y += 2) {
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = size_t(y) * cam.width + x;
      const V3 p = s.point[i];
      if (!std::isfinite(s.depth[i]) || s.depth[i] < 4.9f || std::fabs(p.x) > 0.85 ||
          std::fabs(p.x) < 0.16) {
        continue;
      }
      pixels.push_back(i);
      const V3 normal{s.normal[3 * i], s.normal[3 * i + 1], s.normal[3 * i + 2]};
      reference.push_back(ray_traced_ao(solids, p, normal, kRadius, 512));
    }
  }
  ASSERT_GT(pixels.size(), 300u);
  const Error twin = error_against(ao_with(Card::kTwin), reference, pixels);
  const Error front = error_against(ao_with(Card::kFront), reference, pixels);
  const Error back = error_against(ao_with(Card::kBack), reference, pixels);
  std::printf(
      "[ measure  ] card behind a post, %d px of wall and card: handed on as a twin RMSE %.4f "
      "bias %+.4f; one hit facing the camera RMSE %.4f bias %+.4f; facing away RMSE %.4f bias "
      "%+.4f\n",
      twin.count, twin.rmse, twin.bias, front.rmse, front.bias, back.rmse, back.bias);
  // Read from its facing, either way the card is too dark around: the visible card is a solid
  // of the assumed thickness reaching towards the wall (measured: bias -0.074 facing the
  // camera, -0.069 facing away; behind the post the two readings differ).
  EXPECT_LT(front.bias, -0.04);
  EXPECT_LT(back.bias, -0.04);
  // As a twin the gap between card and wall is free space: close to the ray-traced AO.
  EXPECT_LT(twin.rmse, 0.5 * std::min(front.rmse, back.rmse));
  EXPECT_LT(std::fabs(twin.bias), 0.02);
}

TEST(Layers, OverscanWithLayersEqualsTheWidenedFrameCropped) {
  constexpr int kBand = 16;
  Camera frame;
  frame.width = 80, frame.height = 60;
  const Camera big_camera = widened(frame, kBand);
  Scene big = ray_cast(big_camera, SphereOnFloor{}.solids());
  const auto whole = layered_ao(big, big_camera, true);
  Job job;
  job.camera(frame);
  job.set("radius", kRadius);
  job.set("resolution", "full");
  job.set("normal_space", "camera");
  std::vector<float> ao(size_t(frame.width) * frame.height, -1.0f);
  job.image("depth", big.depth, big.width, big.height, 1);
  job.image("normal", big.normal, big.width, big.height, 3);
  job.image("depth2", big.layer[0], big.width, big.height, 1);
  job.image("facing2", big.facing[0], big.width, big.height, 1);
  job.image("depth3", big.layer[1], big.width, big.height, 1);
  job.image("facing3", big.facing[1], big.width, big.height, 1);
  job.image("ao", ao, frame.width, frame.height, 1);
  ASSERT_EQ(ssao_job_set_output_window(job.get(), 1, kBand, kBand), SSAO_OK);
  ASSERT_EQ(job.run(), SSAO_OK) << ssao_last_error();
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      ASSERT_EQ(ao[size_t(y) * frame.width + x], whole[size_t(y + kBand) * big.width + x + kBand])
          << "pixel " << x << ", " << y;
    }
  }
}

// --- bad layers are refused with a message, never a wrong image ---

namespace {

struct SmallFrame {
  static constexpr int kSize = 8;
  std::vector<float> depth = std::vector<float>(kSize * kSize, 5.0f);
  std::vector<float> behind = std::vector<float>(kSize * kSize, 6.0f);
  std::vector<float> facing = std::vector<float>(kSize * kSize, 1.0f);
  std::vector<float> ao = std::vector<float>(kSize * kSize, -1.0f);
  ssao_job job = nullptr;
  SmallFrame() {
    EXPECT_EQ(ssao_job_create(&job), SSAO_OK);
    attach("depth", depth);
    attach("ao", ao);
  }
  ~SmallFrame() { ssao_job_destroy(job); }
  ssao_status attach(const char* name, std::vector<float>& data, int size = kSize) {
    return ssao_job_set_image(job, name, data.data(), size, size, 1, 0, 0);
  }
  // Runs and returns the status; a failed run must leave the output untouched.
  ssao_status run() {
    const ssao_status status = ssao_job_run(job);
    if (status != SSAO_OK) {
      for (float v : ao) EXPECT_EQ(v, -1.0f) << "a failed run wrote its output";
    }
    return status;
  }
};

}  // namespace

TEST(Layers, UnknownOrGappedLayersAreRefused) {
  SmallFrame f;
  EXPECT_EQ(f.attach("depth6", f.behind), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(f.attach("depth1", f.behind), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(f.attach("facing", f.facing), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(f.attach("depth3", f.behind), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(ssao_last_error()).find("without 'depth2'"), std::string::npos)
      << ssao_last_error();
  ASSERT_EQ(ssao_job_set_image(f.job, "depth3", nullptr, 0, 0, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(f.attach("facing2", f.facing), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(ssao_last_error()).find("'facing2' is attached without 'depth2'"),
            std::string::npos)
      << ssao_last_error();
}

TEST(Layers, MismatchedSizesAreRefused) {
  SmallFrame f;
  std::vector<float> bigger(100, 6.0f);
  ASSERT_EQ(f.attach("depth2", bigger, 10), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(ssao_last_error()).find("'depth2' is 10x10 but depth is 8x8"),
            std::string::npos)
      << ssao_last_error();
  ASSERT_EQ(f.attach("depth2", f.behind), SSAO_OK);
  ASSERT_EQ(f.attach("facing2", bigger, 10), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
}

TEST(Layers, ALayerNearerThanTheOneBeforeIsRefused) {
  SmallFrame f;
  ASSERT_EQ(f.attach("depth2", f.behind), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_OK) << ssao_last_error();
  std::fill(f.ao.begin(), f.ao.end(), -1.0f);
  f.behind[3 * SmallFrame::kSize + 2] = 4.0f;  // in front of the visible surface at 5
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(ssao_last_error()).find("'depth2' at pixel (2, 3) is nearer than 'depth'"),
            std::string::npos)
      << ssao_last_error();
  // Within the tolerance (two renders of one surface differ by rounding): accepted.
  f.behind[3 * SmallFrame::kSize + 2] = 5.0f * (1.0f - 1e-4f);
  EXPECT_EQ(f.run(), SSAO_OK) << ssao_last_error();
  // A hit behind "no hit" is out of order too.
  std::fill(f.ao.begin(), f.ao.end(), -1.0f);
  std::vector<float> third(f.behind.size(), 7.0f);
  f.behind[5] = std::numeric_limits<float>::quiet_NaN();  // NaN: no hit, as for depth
  ASSERT_EQ(f.attach("depth3", third), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(ssao_last_error())
                .find("'depth3' at pixel (5, 0) is nearer than "
                      "'depth2' (no hit"),
            std::string::npos)
      << ssao_last_error();
  // Without the 3rd layer the NaN is just a missing 2nd hit.
  ASSERT_EQ(ssao_job_set_image(f.job, "depth3", nullptr, 0, 0, 1, 0, 0), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_OK) << ssao_last_error();
  for (float v : f.ao) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
}

TEST(Layers, LayersOfBackgroundPixelsAreNotRead) {
  SmallFrame f;
  std::fill(f.depth.begin(), f.depth.begin() + SmallFrame::kSize, 1e10f);  // a row of sky
  std::fill(f.behind.begin(), f.behind.begin() + SmallFrame::kSize, 3.0f);
  ASSERT_EQ(f.attach("depth2", f.behind), SSAO_OK);
  EXPECT_EQ(f.run(), SSAO_OK) << ssao_last_error();
  for (int x = 0; x < SmallFrame::kSize; ++x) EXPECT_EQ(f.ao[size_t(x)], 1.0f);
}

TEST(Layers, ColumnBehindAPostKeepsItsMeasuredThickness) {
  // A 6 cm column 44 cm in front of a wall, and a 10 cm post 2 m in front of it: where the post
  // hides the column the hits are the post's front and back and the column's front, and the
  // column's back would be the 4th. Beside the post the column is seen with its back face, so
  // the frame takes its 6 cm from there (Frame::last_thickness) instead of assuming `thickness`
  // (0.5 here), which filled the gap behind the column and darkened the wall around it. The
  // post is more than the AO distance from the wall: the wall's ray-traced AO is the same with
  // or without it.
  Camera cam;
  cam.width = 256, cam.height = 128;
  const double wall_z = -4.0;
  const Solid wall = {{{0, 0, wall_z}, {0, 0, 1}}};
  const Solid column = box({-0.15, -10, -3.56}, {0.15, 10, -3.5});
  const Solid post = box({-0.05, -10, -2.02}, {0.05, 10, -2.0});
  Scene with_post = ray_cast(cam, {wall, column, post});
  Scene without_post = ray_cast(cam, {wall, column});
  // The wall within 1 of the column's axis, seen in both frames.
  const Scored scored = score_where(with_post, {wall, column}, 512, 4, 4, 1, [&](const V3& p) {
    return std::fabs(p.z - wall_z) < 1e-6 && std::fabs(p.x) <= 1.0;
  });
  const std::vector<size_t>& pixels = scored.pixels;
  const std::vector<double>& reference = scored.reference;
  ASSERT_GT(pixels.size(), 5000u);
  const Error one = error_against(layered_ao(with_post, cam, false), reference, pixels);
  const Error three = error_against(layered_ao(with_post, cam, true), reference, pixels);
  const Error unhidden = error_against(layered_ao(without_post, cam, true), reference, pixels);
  std::printf(
      "[ measure  ] wall around a column behind a post, %d px: one layer RMSE %.4f bias %+.4f; "
      "3 hits %.4f %+.4f; 3 hits without the post %.4f %+.4f\n",
      three.count, one.rmse, one.bias, three.rmse, three.bias, unhidden.rmse, unhidden.bias);
  // As if the post were not there (with the assumed thickness instead: RMSE 0.0797, bias
  // -0.056, against 0.0389 / +0.030 without the post).
  EXPECT_NEAR(three.rmse, unhidden.rmse, 0.005);
  EXPECT_NEAR(three.bias, unhidden.bias, 0.005);
  EXPECT_LT(three.rmse, one.rmse);
}

TEST(Layers, ABoxCornerDrawsNoWedgeOnTheFloorBesideIt) {
  // A unit cube on a floor seen from 30 degrees above, turned 30 degrees about the floor's
  // normal so that its left side is seen at a grazing angle. That side's plane, carried on past
  // the cube's silhouette edge, meets the floor along a line out from the edge's foot; floor
  // pixels near the line lie within the crossing test's tolerance of the plane. Segments from
  // the floor there that pass the plane beside the cube must not count as crossing the side:
  // they drew a dark wedge with a hard edge on the floor (docs/variants.md, crossing test).
  Camera cam;
  cam.width = 384, cam.height = 288;
  const V3 up = normalized({0, std::cos(M_PI / 6), std::sin(M_PI / 6)}), across{1, 0, 0};
  const V3 away = ssao::cross(up, across);  // in the floor
  const double turn = M_PI / 6;
  const V3 side_a = across * std::cos(turn) + away * std::sin(turn);
  const V3 side_b = across * -std::sin(turn) + away * std::cos(turn);
  const V3 contact{0, 0, -3.5};
  const V3 base = contact + across * -0.5;  // the middle of the cube's foot
  Solid cube;
  for (const V3& n : {side_a, side_b, up}) {
    cube.push_back({base + up * 0.5 + n * 0.5, n});
    cube.push_back({base + up * 0.5 - n * 0.5, n * -1.0});
  }
  const std::vector<Solid> solids = {{{contact, up}}, cube};
  Scene s = ray_cast(cam, solids);
  // Floor pixels within 2 of the foot and more than 0.1 from it (the contact shadow itself is
  // the estimator's to get right, not this test's), 256 rays each.
  const auto from_foot = [&](const V3& p) {
    const double u = std::max(std::fabs(dot(p - base, side_a)) - 0.5, 0.0);
    const double v = std::max(std::fabs(dot(p - base, side_b)) - 0.5, 0.0);
    return std::sqrt(u * u + v * v);
  };
  Scored scored = score_where(s, solids, 256, 8, 8, 1, [&](const V3& p) {
    if (std::fabs(dot(p - contact, up)) > 1e-6) return false;
    const double d = from_foot(p);
    return d > 0.1 && d < 2.0;
  });
  // Nor the pixels on the cube's silhouette: there the AO mixes both surfaces, as a renderer's
  // anti-aliased pass does (pixel filter, edge coverage), where this reference holds the floor's
  // at the pixel's centre.
  Scored off_silhouette;
  const std::vector<char> silhouette = depth_jump_pixels(s);
  for (size_t k = 0; k < scored.pixels.size(); ++k) {
    const size_t i = scored.pixels[k];
    if (silhouette[i]) continue;
    off_silhouette.pixels.push_back(i);
    off_silhouette.reference.push_back(scored.reference[k]);
  }
  scored = off_silhouette;
  ASSERT_GT(scored.pixels.size(), 5000u);
  const std::vector<float> ao = layered_ao(s, cam, true);
  const Error three = error_against(ao, scored.reference, scored.pixels);
  int dark = 0;
  for (size_t k = 0; k < scored.pixels.size(); ++k) {
    dark += ao[scored.pixels[k]] < scored.reference[k] - 0.08 ? 1 : 0;
  }
  std::printf(
      "[ measure  ] cube on a floor, %d floor px 0.1 to 2 from its foot: 3 hits RMSE %.4f bias "
      "%+.4f; %d px more than 0.08 darker than ray-traced\n",
      three.count, three.rmse, three.bias, dark);
  // Before the crossing test asked the shown surface's normal: RMSE 0.0139, 32 px more than
  // 0.08 darker (the wedge); then 0.0134 and 1. Since the edge coverage reads the depth's
  // staircase the silhouette's 142 px are left out (with them 6 px, mixed with the cube's AO):
  // 0.0126 and 1.
  EXPECT_LE(dark, 4);
  EXPECT_LT(three.rmse, 0.016);
}
