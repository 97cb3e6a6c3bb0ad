// SPDX-License-Identifier: MIT
// Analytic geometry made in the test: flat and tilted planes, a 90-degree concave corner with its
// closed-form AO, a convex ridge, and perspective vs orthographic views of the same corner.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "analytic_scene.h"

using namespace test;

namespace {

const auto everywhere = [](int, int) { return true; };

// A ridge along the vertical line x = 0, z = -5 pointing at the camera: one solid, the
// intersection of the half-spaces behind both faces.
Scene convex_ridge(const Camera& cam) {
  const V3 ridge{0, 0, -5};
  return ray_cast(cam, {{{ridge, normalized({1, 0, 1})}, {ridge, normalized({-1, 0, 1})}}});
}

Camera perspective() { return Camera{}; }
Camera orthographic_like_perspective() {
  Camera c;
  c.ortho = true;
  c.ortho_scale = 6.0 * c.sensor / c.lens;  // same view width at the crease's depth
  return c;
}

}  // namespace

TEST(Analytic, FacingPlaneIsUnoccluded) {
  const Camera cam = perspective();
  for (const char* variant : {"horizon", "hemisphere", "sphere", "volumetric", "unsharp"}) {
    for (bool normals : {true, false}) {
      Scene s = facing_plane(cam);
      const auto ao = compute_ao(s, cam, 0.5, variant, normals);
      const Stats st = stats_over(s, ao, everywhere);
      EXPECT_EQ(st.count, s.width * s.height);
      EXPECT_GE(st.min, 0.98) << variant << " normals=" << normals;
      EXPECT_LE(st.max, 1.0);
    }
  }
}

TEST(Analytic, TiltedPlaneIsUnoccluded) {
  const Camera cam = perspective();
  for (const char* variant : {"horizon", "hemisphere", "sphere", "volumetric", "unsharp"}) {
    for (bool normals : {true, false}) {
      Scene s = tilted_plane(cam);
      const auto ao = compute_ao(s, cam, 0.5, variant, normals);
      const Stats st = stats_over(s, ao, everywhere);
      EXPECT_GT(st.count, s.width * s.height / 4);
      EXPECT_GE(st.min, 0.98) << variant << " normals=" << normals;
    }
  }
}

TEST(Analytic, ClassicSphereReadsHalfOnAFlatWall) {
  const Camera cam = perspective();
  Scene s = facing_plane(cam);
  const auto ao =
      compute_ao(s, cam, 0.5, "sphere", false, [](Job& j) { j.set("sphere_mode", "classic"); });
  // Pixels whose kernel stays inside the image (the radius covers about 9 pixels here); the
  // default bias drops the pair nearest the surface: 16 samples read 0.5625 (measured).
  const Stats st = stats_over(s, ao, [&](int x, int y) {
    return x >= 10 && y >= 10 && x < s.width - 10 && y < s.height - 10;
  });
  EXPECT_NEAR(st.mean, 0.5, 0.07);
}

// The hemisphere estimate against the closed form, as a function of the distance to the crease.
void expect_corner_matches_closed_form(const Camera& cam, const char* variant, const char* label,
                                       const char* resolution = "full") {
  const double radius = 1.0;
  Scene s = concave_corner(cam);
  const auto ao =
      compute_ao(s, cam, radius, variant, true, [&](Job& j) { j.set("resolution", resolution); });
  double squared = 0, worst = 0;
  int n = 0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const size_t i = size_t(y) * s.width + x;
      const double dist = distance_to_crease(s, x, y);
      if (!std::isfinite(s.depth[i]) || dist > 1.5 * radius) continue;
      const double err = ao[i] - corner_ao(dist, radius);
      squared += err * err;
      worst = std::max(worst, std::fabs(err));
      ++n;
    }
  }
  const double rmse = std::sqrt(squared / n);
  std::printf("[ measure  ] corner %s %s %s: %d px within 1.5 R, RMSE %.4f, max |err| %.4f\n",
              variant, resolution, label, n, rmse, worst);
  // Tolerance from measurement (docs/accuracy.md): RMSE 0.03, max 0.12 (pixels at the crease
  // see the other wall through a one-pixel-wide sliver).
  EXPECT_GT(n, 200);
  EXPECT_LT(rmse, 0.05) << label;
  EXPECT_LT(worst, 0.2) << label;

  const Stats crease =
      stats_over(s, ao, [&](int x, int y) { return distance_to_crease(s, x, y) < 0.2 * radius; });
  const Stats walls =
      stats_over(s, ao, [&](int x, int y) { return distance_to_crease(s, x, y) > 1.2 * radius; });
  EXPECT_LT(crease.mean, walls.mean - 0.3) << label;
  EXPECT_GE(walls.min, 0.95) << label;
}

TEST(Analytic, ConcaveCornerMatchesClosedFormPerspective) {
  for (const char* variant : {"horizon", "hemisphere"}) {
    expect_corner_matches_closed_form(perspective(), variant, "perspective");
  }
  // Half resolution estimates on a grid half as fine: the same grid as the full-resolution
  // check when the frame is twice as large.
  Camera twice = perspective();
  twice.width *= 2, twice.height *= 2;
  expect_corner_matches_closed_form(twice, "hemisphere", "perspective", "half");
}

TEST(Analytic, ConcaveCornerMatchesClosedFormOrthographic) {
  for (const char* variant : {"horizon", "hemisphere"}) {
    expect_corner_matches_closed_form(orthographic_like_perspective(), variant, "orthographic");
  }
  Camera twice = orthographic_like_perspective();
  twice.width *= 2, twice.height *= 2;
  expect_corner_matches_closed_form(twice, "hemisphere", "orthographic", "half");
}

TEST(Analytic, SphereDarkensTheCornerToHalfAtTheCrease) {
  const Camera cam = perspective();
  Scene s = concave_corner(cam);
  // Enough samples and no blur, so that the one-pixel-wide crease keeps its own value.
  const auto ao = compute_ao(s, cam, 1.0, "sphere", false, [](Job& j) {
    j.set("samples", 64);
    j.set("denoise", "none");
  });
  // At the crease three quarters of the sphere are inside the walls: visibility 1/4, which the
  // normalized mode maps to 1/2.
  const Stats crease =
      stats_over(s, ao, [&](int x, int y) { return distance_to_crease(s, x, y) < 0.1; });
  const Stats walls =
      stats_over(s, ao, [&](int x, int y) { return distance_to_crease(s, x, y) > 1.2; });
  // Measured 0.61: the band reaches 0.1 radius from the crease and the bias margin drops the
  // samples nearest the walls.
  EXPECT_NEAR(crease.mean, 0.5, 0.15);
  EXPECT_GE(walls.mean, 0.97);
}

// The volumetric obscurance of a point on a wall of the concave corner, d radii from the crease:
// twice the part of the unit ball around it in front of both walls (clamped to 1), integrated on
// a grid; 1/2 at the crease, 1 from one radius on.
double corner_volumetric_closed_form(double d) {
  const V3 n1 = normalized({1, 0, 1}), n2 = normalized({-1, 0, 1}), along = normalized({-1, 0, 1});
  const int n = 48;
  long inside = 0, empty = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const V3 r{(i + 0.5) / n * 2 - 1, (j + 0.5) / n * 2 - 1, (k + 0.5) / n * 2 - 1};
        if (r.x * r.x + r.y * r.y + r.z * r.z > 1) continue;
        ++inside;
        const V3 q{d * along.x + r.x, d * along.y + r.y, d * along.z + r.z};
        const double a = n1.x * q.x + n1.y * q.y + n1.z * q.z;
        const double b = n2.x * q.x + n2.y * q.y + n2.z * q.z;
        if (a > 0 && b > 0) ++empty;
      }
    }
  }
  return std::min(1.0, 2.0 * double(empty) / double(inside));
}

TEST(Analytic, VolumetricMatchesTheCornersClosedForm) {
  for (const Camera& cam : {perspective(), orthographic_like_perspective()}) {
    Scene s = concave_corner(cam);
    // No fall-off (it lets the far wall's rays fade out), many rays, no blur: the estimate
    // itself against the ball's volume in front of the walls.
    const auto ao = compute_ao(s, cam, 1.0, "volumetric", false, [](Job& j) {
      j.set("samples", 128);
      j.set("thickness", 100.0);
      j.set("denoise", "none");
    });
    double previous = 0.0;
    for (double band = 0.0; band < 1.25; band += 0.25) {
      const Stats st = stats_over(s, ao, [&](int x, int y) {
        const double d = distance_to_crease(s, x, y);
        return d >= band && d < band + 0.25;
      });
      ASSERT_GT(st.count, 20) << "band " << band;
      const double expected =
          0.5 * (corner_volumetric_closed_form(band) + corner_volumetric_closed_form(band + 0.25));
      EXPECT_NEAR(st.mean, expected, 0.05) << "band " << band << (cam.ortho ? " ortho" : "");
      EXPECT_GE(st.mean, previous - 0.01) << "band " << band;
      previous = st.mean;
    }
    // The fall-off only ever lightens: rays hidden by a surface in front of the sphere fade out.
    const auto with_falloff = compute_ao(s, cam, 1.0, "volumetric", false);
    const Stats walls = stats_over(s, with_falloff,
                                   [&](int x, int y) { return distance_to_crease(s, x, y) > 1.2; });
    EXPECT_GE(walls.mean, 0.98);
  }
}

TEST(Analytic, ConvexRidgeIsNotDarkenedByTheDepthOnlyMeasures) {
  // volumetric: at a convex ridge only a quarter of the sphere is solid, and the doubled empty
  // part is clamped to 1. unsharp: the surroundings are deeper than the pixel, no deficit. Not
  // brightened either: both only darken.
  const Camera cam = perspective();
  Scene s = convex_ridge(cam);
  for (const auto& [variant, floor] : {std::pair{"volumetric", 0.97}, {"unsharp", 0.99}}) {
    const auto ao = compute_ao(s, cam, 1.0, variant, false);
    const Stats st = stats_over(s, ao, everywhere);
    EXPECT_GT(st.count, s.width * s.height / 2);
    EXPECT_GE(st.min, floor) << variant;
  }
}

TEST(Analytic, UnsharpDarkensTheCreaseAndKeepsItsLookAtAnyResolution) {
  // Viewed head-on, the walls of the corner recede at 45 degrees: around the crease the depth
  // falls by |x|, and a box of half-width one radius averages half a radius nearer: AO 1/2.
  for (const Camera& base : {perspective(), orthographic_like_perspective()}) {
    Camera twice = base;
    twice.width *= 2, twice.height *= 2;
    std::vector<double> bands[2];
    for (int i = 0; i < 2; ++i) {
      const Camera& cam = i == 0 ? base : twice;
      Scene s = concave_corner(cam);
      // The estimate's look: the pixel filter works in pixels, not scene units, by design.
      const auto ao = compute_ao(s, cam, 1.0, "unsharp", false, [](Job& j) {
        j.set("denoise", "none");
        j.set("resolution", "full");
        j.set("pixel_filter", 0.0);
      });
      for (double band = 0.0; band < 1.5; band += 0.25) {
        const Stats st = stats_over(s, ao, [&](int x, int y) {
          const double d = distance_to_crease(s, x, y);
          return d >= band && d < band + 0.25;
        });
        ASSERT_GT(st.count, 20) << "band " << band;
        bands[i].push_back(st.mean);
      }
      EXPECT_NEAR(bands[i][0], 0.55, 0.1) << (cam.ortho ? "ortho" : "persp");
      for (size_t b = 1; b < bands[i].size(); ++b) EXPECT_GE(bands[i][b], bands[i][b - 1] - 0.01);
      EXPECT_GE(bands[i].back(), 0.98);
    }
    // The box follows the radius in scene units: twice the pixels, the same look.
    for (size_t b = 0; b < bands[0].size(); ++b) {
      EXPECT_NEAR(bands[0][b], bands[1][b], 0.03) << "band " << b;
    }
  }
}

TEST(Analytic, ConvexRidgeIsNotDarkenedByHemisphere) {
  const Camera cam = perspective();
  Scene s = convex_ridge(cam);
  for (bool normals : {true, false}) {
    const auto ao = compute_ao(s, cam, 1.0, "hemisphere", normals);
    // Pixels on the ridge itself have a reconstructed normal that straddles both faces.
    const Stats st = stats_over(s, ao, [&](int x, int) { return std::abs(x - s.width / 2) > 1; });
    EXPECT_GT(st.count, s.width * s.height / 2);
    EXPECT_GE(st.min, 0.97) << "normals=" << normals;
    EXPECT_GE(st.mean, 0.995) << "normals=" << normals;
  }
}

TEST(Analytic, PerspectiveAndOrthographicAgree) {
  const Camera persp = perspective(), ortho = orthographic_like_perspective();
  Scene sp = concave_corner(persp), so = concave_corner(ortho);
  const auto ap = compute_ao(sp, persp, 1.0, "hemisphere");
  const auto ao = compute_ao(so, ortho, 1.0, "hemisphere");
  // Compare the mean AO in bands of distance from the crease.
  for (double band = 0.0; band < 1.2; band += 0.2) {
    auto in_band = [&](const Scene& s) {
      return [&s, band](int x, int y) {
        const double d = distance_to_crease(s, x, y);
        return d >= band && d < band + 0.2;
      };
    };
    const Stats p = stats_over(sp, ap, in_band(sp));
    const Stats o = stats_over(so, ao, in_band(so));
    ASSERT_GT(p.count, 20);
    ASSERT_GT(o.count, 20);
    EXPECT_NEAR(p.mean, o.mean, 0.04) << "band " << band;
  }
}

// A board standing just in front of a wall, turned 20 degrees about the view axis: its slanted
// silhouettes cross the pixel grid at every phase, and the wall is darkest right beside it. A
// renderer's anti-aliased AO pass mixes the board's and the wall's AO on those pixels where the
// Depth pass holds one of them; the reference does too: ray-traced AO at 3 x 3 points a pixel,
// weighted by a Gaussian pixel filter of standard deviation 0.5 px (truncated at 1.5 px).
// `below`: how far the board's centre lies below the view axis; `wall`: the wall's depth;
// `half_height`: half the board's height; `degrees`: its turn about the view axis; `tilt`: its
// turn about its own long axis, in degrees (its front face then no longer faces the wall's way).
struct SlantedBoard {
  explicit SlantedBoard(double below = 0.0, double wall = 5.6, double half_height = 0.6,
                        double degrees = 20.0, double tilt = 0.0) {
    const double turn = degrees * M_PI / 180.0, lean = tilt * M_PI / 180.0;
    const V3 across{std::cos(turn), std::sin(turn), 0};
    const V3 up =
        V3{-std::sin(turn), std::cos(turn), 0} * std::cos(lean) + V3{0, 0, std::sin(lean)};
    const V3 towards =
        V3{0, 0, 1} * std::cos(lean) - V3{-std::sin(turn), std::cos(turn), 0} * std::sin(lean);
    const V3 centre{0, -below, -5.15};  // front face at depth 5 (untilted)
    board = {{centre + across * 1.2, across},    {centre - across * 1.2, across * -1.0},
             {centre + up * half_height, up},    {centre - up * half_height, up * -1.0},
             {centre + towards * 0.15, towards}, {centre - towards * 0.15, towards * -1.0}};
    solids = {board, {{{0, 0, -wall}, {0, 0, 1}}}};
    behind = 0.5 * (5.3 + wall);
    s = ray_cast(cam, solids);
    edge = depth_jump_pixels(s);
    sub_ao.assign(s.depth.size() * kSub * kSub, -1.0);
  }
  size_t index(int x, int y) const { return size_t(y) * s.width + x; }
  // Depth and normal of the surface at sub-pixel point (i + 0.5) / 3 on each axis.
  double hit_at(int i, int j, V3& normal) const {
    V3 o, d;
    cam.ray_at((i + 0.5) / kSub, (j + 0.5) / kSub, o, d);
    return -(o + d * first_hit(solids, o, d, normal)).z;
  }
  // Ray-traced AO at sub-pixel point (i + 0.5) / 3 on each axis (column i, row j), computed once.
  double ao_at(int i, int j) {
    double& value = sub_ao[size_t(j) * s.width * kSub + i];
    if (value < 0.0) {
      V3 o, d, normal{0, 0, 0};
      cam.ray_at((i + 0.5) / kSub, (j + 0.5) / kSub, o, d);
      const double t = first_hit(solids, o, d, normal);
      value = ray_traced_ao(solids, o + d * t, normal, radius, 144);
    }
    return value;
  }
  // `at(i, j)` over the sub-pixel points of pixel (x, y) and its 8 neighbours, weighted by a
  // Gaussian pixel filter of standard deviation 0.5 px: what a renderer's pass holds there.
  template <class F>
  double filtered(int x, int y, F&& at) const {
    constexpr double kSigma = 0.5;
    double sum = 0, weights = 0;
    for (int j = (y - 1) * kSub; j < (y + 2) * kSub; ++j) {
      for (int i = (x - 1) * kSub; i < (x + 2) * kSub; ++i) {
        const double du = (i + 0.5) / kSub - (x + 0.5), dv = (j + 0.5) / kSub - (y + 0.5);
        const double w = std::exp(-(du * du + dv * dv) / (2 * kSigma * kSigma));
        sum += w * at(i, j);
        weights += w;
      }
    }
    return sum / weights;
  }
  // RMSE of `ao` over the edge pixels (2 px from the border) against the supersampled
  // ray-traced AO through the pixel filter; `count` gets how many there are.
  double edge_rmse(const std::vector<float>& ao, int& count) { return rmse_over(ao, edge, count); }
  // The same over the pixels `mask` marks.
  double rmse_over(const std::vector<float>& ao, const std::vector<char>& mask, int& count) {
    double sum_sq = 0;
    count = 0;
    for (int y = 2; y + 2 < s.height; ++y) {
      for (int x = 2; x + 2 < s.width; ++x) {
        if (!mask[index(x, y)]) continue;
        const double reference = filtered(x, y, [&](int i, int j) { return ao_at(i, j); });
        sum_sq += std::pow(ao[index(x, y)] - reference, 2);
        ++count;
      }
    }
    return std::sqrt(sum_sq / std::max(count, 1));
  }
  static constexpr int kSub = 3;
  const Camera cam;
  const double radius = 1.0;
  Solid board;
  std::vector<Solid> solids;
  double behind = 0;  // a depth between the board's back (5.3) and the wall
  Scene s;
  std::vector<char> edge;
  std::vector<double> sub_ao;
};

TEST(Analytic, PixelFilterMixesBothSurfacesAtEdgesAsASupersampledRender) {
  SlantedBoard b;
  const Scene& s = b.s;
  const auto point = compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [](Job& j) {
    j.set("resolution", "full");
    j.set("pixel_filter", 0.0);
  });
  const auto filtered = compute_ao(b.s, b.cam, b.radius, "hemisphere", true,
                                   [](Job& j) { j.set("resolution", "full"); });  // the default
  // Away from edges the filter only smooths what is already smooth.
  double moved_inside = 0;
  for (int y = 2; y + 2 < s.height; ++y) {
    for (int x = 2; x + 2 < s.width; ++x) {
      bool near_edge = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) near_edge = near_edge || b.edge[b.index(x + dx, y + dy)];
      }
      if (near_edge) continue;
      const size_t i = b.index(x, y);
      moved_inside = std::max(moved_inside, double(std::fabs(filtered[i] - point[i])));
    }
  }
  int edges = 0;
  const double point_rmse = b.edge_rmse(point, edges);
  const double filtered_rmse = b.edge_rmse(filtered, edges);
  ASSERT_GT(edges, 150);
  std::printf(
      "[ measure  ] slanted board edges (%d px) against a supersampled render: RMSE %.4f "
      "per-pixel estimate, %.4f with the pixel filter; largest change away from edges %.4f\n",
      edges, point_rmse, filtered_rmse, moved_inside);
  EXPECT_LT(filtered_rmse, 0.8 * point_rmse);
  EXPECT_LT(moved_inside, 0.05);
}

// Channel c of a 3-channel pass at sub-pixel point (i, j), value_at(i, j, c), through the
// pixel filter into image's pixels 1 px from the border (the border keeps what image holds).
template <class F>
void filter_into(const SlantedBoard& b, F&& value_at, std::vector<float>& image) {
  for (int y = 1; y + 1 < b.s.height; ++y) {
    for (int x = 1; x + 1 < b.s.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image[b.index(x, y) * 3 + c] =
            float(b.filtered(x, y, [&](int i, int j) { return value_at(i, j, c); }));
      }
    }
  }
}

// The beauty a renderer would write of the board, red, before a blue wall: each surface's
// colour filtered over the pixel like the AO pass. With `highlight`, the board's pixels on its
// silhouette are white (a bevel catching the light, one pixel wide).
std::vector<float> board_beauty(const SlantedBoard& b, bool highlight) {
  const Scene& s = b.s;
  const auto colour_at = [&](int i, int j, int c) {
    V3 normal{0, 0, 0};
    const bool board = b.hit_at(i, j, normal) < b.behind;
    const size_t pixel = b.index(i / b.kSub, j / b.kSub);
    if (board && highlight && b.edge[pixel] && s.depth[pixel] < b.behind) return 1.0;
    static constexpr double kBoard[3] = {0.8, 0.25, 0.1}, kWall[3] = {0.15, 0.3, 0.7};
    return board ? kBoard[c] : kWall[c];
  };
  std::vector<float> beauty(s.depth.size() * 3, 0.0f);
  filter_into(b, colour_at, beauty);
  return beauty;
}

// The board's Normal pass as a renderer filters it, like the beauty: on an edge the average of
// the normals the pixel's footprint sees (view space, 3 per pixel).
std::vector<float> board_normals(const SlantedBoard& b) {
  std::vector<float> normals = b.s.normal;
  filter_into(
      b,
      [&](int i, int j, int c) {
        V3 normal{0, 0, 0};
        b.hit_at(i, j, normal);
        return c == 0 ? normal.x : c == 1 ? normal.y : normal.z;
      },
      normals);
  return normals;
}

// Where the Depth pass holds one surface, the beauty says how much of the pixel each covers
// (edge_coverage = beauty).
TEST(Analytic, BeautyCoverageMixesBothSurfacesAtEdgesAsASupersampledRender) {
  SlantedBoard b;
  const Scene& s = b.s;
  std::vector<float> beauty = board_beauty(b, false);
  const auto with = [&](const char* coverage, std::vector<float>* image) {
    return compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("edge_coverage", coverage);
      if (image != nullptr) j.image("beauty", *image, s.width, s.height, 3);
    });
  };
  const auto filtered = with("none", &beauty);
  const auto mixed = with("beauty", &beauty);
  int changed_inside = 0;
  for (size_t i = 0; i < mixed.size(); ++i) changed_inside += !b.edge[i] && mixed[i] != filtered[i];
  int edges = 0;
  const double filtered_rmse = b.edge_rmse(filtered, edges);
  const double mixed_rmse = b.edge_rmse(mixed, edges);
  ASSERT_GT(edges, 150);
  std::printf(
      "[ measure  ] slanted board edges (%d px) against a supersampled render: RMSE %.4f with "
      "the pixel filter, %.4f with the beauty's coverage\n",
      edges, filtered_rmse, mixed_rmse);
  EXPECT_LT(mixed_rmse, 0.8 * filtered_rmse);
  EXPECT_EQ(changed_inside, 0) << "only pixels on a depth edge change";
  // A beauty that cannot be read, or one colour, says nothing: the depth's staircase alone mixes,
  // as without a beauty (Analytic.StaircaseCoverageMixesEdgesWhereNothingElseReadsAMix).
  const auto staircase = with("beauty", nullptr);
  EXPECT_NE(staircase, filtered);
  std::vector<float> unreadable(beauty.size(), std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(with("beauty", &unreadable), staircase);
  // Without the pixel filter the two pixels' own AO are mixed.
  const auto unfiltered = [&](const char* coverage) {
    return compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("pixel_filter", 0.0);
      j.set("edge_coverage", coverage);
      j.image("beauty", beauty, s.width, s.height, 3);
    });
  };
  const auto point = unfiltered("none"), point_mixed = unfiltered("beauty");
  int point_edges = 0;
  EXPECT_LT(b.edge_rmse(point_mixed, point_edges), 0.8 * b.edge_rmse(point, point_edges));
  std::vector<float> flat(beauty.size(), 0.5f);
  EXPECT_EQ(with("beauty", &flat), staircase) << "one colour says nothing of coverage";
  // "edge_colours" stands in for the beauty's colours: a front end whose beauty is a white
  // factor image (Blender's node) gets the same AO.
  const auto guided = [&](const char* coverage) {
    return compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("edge_coverage", coverage);
      j.image("beauty", flat, s.width, s.height, 3);
      j.image("edge_colours", beauty, s.width, s.height, 3);
    });
  };
  EXPECT_EQ(guided("beauty"), mixed);
  EXPECT_EQ(guided("none"), filtered);
}

// Where neither the colours nor the normals read a mix (no beauty, each pixel centre's normal),
// the Depth pass's staircase along a slanted edge says where the silhouette passes: the slanted
// board's long edges draw runs that step one way at one end and the other way at the other.
TEST(Analytic, StaircaseCoverageMixesEdgesWhereNothingElseReadsAMix) {
  SlantedBoard b;
  const auto with = [&](const char* coverage, double pixel_filter) {
    return compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("pixel_filter", pixel_filter);
      j.set("edge_coverage", coverage);
    });
  };
  const auto filtered = with("none", 0.5), mixed = with("beauty", 0.5);
  int changed = 0, changed_inside = 0;
  for (size_t i = 0; i < mixed.size(); ++i) {
    changed += mixed[i] != filtered[i];
    changed_inside += !b.edge[i] && mixed[i] != filtered[i];
  }
  int edges = 0;
  const double filtered_rmse = b.edge_rmse(filtered, edges);
  const double mixed_rmse = b.edge_rmse(mixed, edges);
  ASSERT_GT(edges, 150);
  const double point_rmse = b.edge_rmse(with("none", 0.0), edges);
  const double point_mixed_rmse = b.edge_rmse(with("beauty", 0.0), edges);
  std::printf(
      "[ measure  ] slanted board edges (%d px, %d mixed by the staircase) against a supersampled "
      "render: RMSE %.4f with the pixel filter, %.4f with the staircase's coverage; without the "
      "filter %.4f, %.4f\n",
      edges, changed, filtered_rmse, mixed_rmse, point_rmse, point_mixed_rmse);
  EXPECT_GT(changed, 50);
  EXPECT_EQ(changed_inside, 0) << "only pixels on a depth edge change";
  // Measured: 0.0391 -> 0.0365 and 0.0921 -> 0.0845 (the beauty's coverage, where it reads:
  // 0.0310).
  EXPECT_LT(mixed_rmse, 0.95 * filtered_rmse);
  EXPECT_LT(point_mixed_rmse, 0.95 * point_rmse);
}

// With a highlight along the board's silhouette the pixel beyond the board's edge pixel shows
// red while the edge pixel is white: the colours cannot say how much of the wall's edge pixels the
// board covers (read as red and blue, the white would pass for all board). There the pixel
// filter alone stands.
TEST(Analytic, BeautyCoverageLeavesEdgesWhoseColoursDoNotMix) {
  SlantedBoard b;
  const Scene& s = b.s;
  std::vector<float> beauty = board_beauty(b, true);
  const auto with = [&](const char* coverage) {
    return compute_ao(b.s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("edge_coverage", coverage);
      j.image("beauty", beauty, s.width, s.height, 3);
    });
  };
  int edges = 0;
  const double filtered_rmse = b.edge_rmse(with("none"), edges);
  const double mixed_rmse = b.edge_rmse(with("beauty"), edges);
  ASSERT_GT(edges, 150);
  std::printf(
      "[ measure  ] slanted board edges (%d px), highlighted silhouette: RMSE %.4f with the "
      "pixel filter, %.4f with the beauty's coverage\n",
      edges, filtered_rmse, mixed_rmse);
  EXPECT_LT(mixed_rmse, 1.02 * filtered_rmse);
}

// A shelf board 11 cm high below the eye, 2 cm before a wall, turned 5 degrees: its top face,
// in the crease against the wall, shows only as a sliver of the wall's pixels above the board
// (under a pixel), red like the front face. The colours read such a pixel as part board, and
// the board's AO there (its open front face) makes it too light; the Normal pass, filtered over
// the pixel like the beauty, holds the top face's normal too, which is no mix of the front's and
// the wall's: there the pixel filter alone stands. Where a pixel holds the two surfaces alone
// (the slanted board of the tests above, its faces parallel to the wall), the filtered Normal
// pass leaves the colours' coverage as it was.
TEST(Analytic, BeautyCoverageLeavesPixelsThatHoldAThirdSurface) {
  SlantedBoard b(0.5, 5.32, 0.055, 5.0);
  Scene& s = b.s;
  const std::vector<float> beauty = board_beauty(b, false), normals = board_normals(b);
  std::vector<char> sliver(s.depth.size(), 0);  // wall pixels that hold some of the top face
  for (int y = 1; y + 1 < s.height; ++y) {
    for (int x = 1; x + 1 < s.width; ++x) {
      if (!b.edge[b.index(x, y)] || !(s.depth[b.index(x, y)] > b.behind)) continue;
      for (int j = y * b.kSub; j < (y + 1) * b.kSub; ++j) {
        for (int i = x * b.kSub; i < (x + 1) * b.kSub; ++i) {
          V3 normal{0, 0, 0};
          b.hit_at(i, j, normal);
          if (dot(normal, b.board[2].normal) > 0.99) sliver[b.index(x, y)] = 1;
        }
      }
    }
  }
  const auto with = [&](SlantedBoard& board, const char* coverage, std::vector<float> colours,
                        const std::vector<float>& normal) {
    board.s.normal = normal;
    return compute_ao(board.s, board.cam, board.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("edge_coverage", coverage);
      j.image("beauty", colours, board.s.width, board.s.height, 3);
    });
  };
  const std::vector<float> centre_normals = s.normal;
  const auto sliver_rmse = [&](const std::vector<float>& ao) {
    int count = 0;
    const double rmse = b.rmse_over(ao, sliver, count);
    EXPECT_GE(count, 12);
    return rmse;
  };
  const double filter_rmse = sliver_rmse(with(b, "none", beauty, normals));
  const double mixed_rmse = sliver_rmse(with(b, "beauty", beauty, normals));
  // With the normal of each pixel's centre the third surface does not show: the colours decide.
  const double colours_rmse = sliver_rmse(with(b, "beauty", beauty, centre_normals));
  std::printf(
      "[ measure  ] wall pixels holding a sliver of a shelf's top face, against a supersampled "
      "render: RMSE %.4f with the pixel filter, %.4f with the beauty's coverage and the Normal "
      "pass, %.4f with the beauty's coverage and each pixel centre's normal\n",
      filter_rmse, mixed_rmse, colours_rmse);
  EXPECT_LT(mixed_rmse, 0.8 * colours_rmse);
  EXPECT_LT(mixed_rmse, 1.1 * filter_rmse);

  SlantedBoard slanted;
  const std::vector<float> slanted_beauty = board_beauty(slanted, false);
  const std::vector<float> slanted_normals = board_normals(slanted);
  int edges = 0;
  const double slanted_filter =
      slanted.edge_rmse(with(slanted, "none", slanted_beauty, slanted_normals), edges);
  const double slanted_mixed =
      slanted.edge_rmse(with(slanted, "beauty", slanted_beauty, slanted_normals), edges);
  std::printf(
      "[ measure  ] slanted board edges (%d px), filtered Normal pass: RMSE %.4f with the pixel "
      "filter, %.4f with the beauty's coverage\n",
      edges, slanted_filter, slanted_mixed);
  EXPECT_LT(slanted_mixed, 0.8 * slanted_filter);
}

// Where the two surfaces' colours are alike (one material) the Normal pass, filtered over the
// pixel like the beauty, says how much of the pixel each covers if their normals differ: the
// slanted board tilted 20 degrees about its long axis, one grey everywhere. Tilted, it shows its
// top face along its upper silhouette, a third surface there: the test is over the edge pixels
// whose filter sees the front face and the wall alone.
TEST(Analytic, NormalPassCoverageMixesEdgesWhoseColoursAreAlike) {
  SlantedBoard b(0.0, 5.6, 0.6, 20.0, 20.0);
  Scene& s = b.s;
  std::vector<float> grey(s.depth.size() * 3, 0.5f);
  const std::vector<float> normals = board_normals(b), centre_normals = s.normal;
  std::vector<char> two_surfaces(s.depth.size(), 0);
  const V3 front = b.board[4].normal, wall{0, 0, 1};
  for (int y = 1; y + 1 < s.height; ++y) {
    for (int x = 1; x + 1 < s.width; ++x) {
      bool only_two = b.edge[b.index(x, y)];
      for (int j = (y - 1) * b.kSub; only_two && j < (y + 2) * b.kSub; ++j) {
        for (int i = (x - 1) * b.kSub; only_two && i < (x + 2) * b.kSub; ++i) {
          V3 normal{0, 0, 0};
          b.hit_at(i, j, normal);
          only_two = dot(normal, front) > 0.999 || dot(normal, wall) > 0.999;
        }
      }
      two_surfaces[b.index(x, y)] = only_two;
    }
  }
  const auto with = [&](const char* coverage, const std::vector<float>& normal) {
    s.normal = normal;
    return compute_ao(s, b.cam, b.radius, "hemisphere", true, [&](Job& j) {
      j.set("resolution", "full");
      j.set("edge_coverage", coverage);
      j.image("beauty", grey, s.width, s.height, 3);
    });
  };
  const auto filtered = with("none", normals);
  const auto mixed = with("beauty", normals);
  int count = 0, edges = 0;
  const double filtered_rmse = b.rmse_over(filtered, two_surfaces, count);
  const double mixed_rmse = b.rmse_over(mixed, two_surfaces, count);
  const double filtered_all = b.edge_rmse(filtered, edges), mixed_all = b.edge_rmse(mixed, edges);
  ASSERT_GT(count, 80);
  std::printf(
      "[ measure  ] tilted board, one grey, filtered Normal pass: edges of the front face and the "
      "wall alone (%d px) RMSE %.4f with the pixel filter, %.4f with the Normal pass's "
      "coverage; all edges (%d px) %.4f, %.4f\n",
      count, filtered_rmse, mixed_rmse, edges, filtered_all, mixed_all);
  EXPECT_LT(mixed_rmse, 0.85 * filtered_rmse);
  EXPECT_LT(mixed_all, filtered_all);
  int changed_inside = 0;
  for (size_t i = 0; i < mixed.size(); ++i) changed_inside += !b.edge[i] && mixed[i] != filtered[i];
  EXPECT_EQ(changed_inside, 0) << "only pixels on a depth edge change";
  // Each pixel centre's normal, not filtered, says nothing of coverage: there only the depth's
  // staircase reads a mix, on fewer pixels and less well.
  const auto centre_mixed = with("beauty", centre_normals);
  const double centre_rmse = b.rmse_over(centre_mixed, two_surfaces, count);
  std::printf("[ measure  ] the same with each pixel centre's normal: %.4f\n", centre_rmse);
  EXPECT_GT(centre_rmse, mixed_rmse);
}

// A renderer's Normal pass is filtered over each pixel like the beauty: on a crease it holds the
// average of both walls' unit normals, shorter than 1, while the Depth pass holds one wall. A
// 90-degree concave corner with its crease turned 25 degrees from the vertical (every phase of
// the pixel grid), normals averaged over 4 x 4 points a pixel: on the crease pixels the AO must
// read as with each pixel's own wall's normal (both walls see the closed form's 1/2 there), not
// as a wall tilted halfway, which sees past the other wall and reads light.
void expect_anti_aliased_normals_keep_the_crease(const Camera& cam, const char* label,
                                                 const char* resolution) {
  const double turn = 25.0 * M_PI / 180.0;
  Corner corner;
  corner.axis = {std::sin(turn), std::cos(turn), 0};
  Scene s = concave_corner(cam, corner);
  const V3 side{corner.axis.y, -corner.axis.x, 0.0}, forward{0, 0, 1};
  const std::vector<Solid> walls = {{{corner.crease, normalized(side + forward)}},
                                    {{corner.crease, normalized(side * -1.0 + forward)}}};
  Scene filtered = s;
  std::vector<char> mixed(s.depth.size(), 0);
  constexpr int kSub = 4;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const size_t i = size_t(y) * s.width + x;
      V3 sum{0, 0, 0};
      for (int j = 0; j < kSub; ++j) {
        for (int k = 0; k < kSub; ++k) {
          V3 o, d, normal{0, 0, 0};
          cam.ray_at(x + (k + 0.5) / kSub, y + (j + 0.5) / kSub, o, d);
          if (std::isfinite(first_hit(walls, o, d, normal))) {
            sum = sum + normal * (1.0 / (kSub * kSub));
          }
        }
      }
      filtered.normal[3 * i + 0] = float(sum.x);
      filtered.normal[3 * i + 1] = float(sum.y);
      filtered.normal[3 * i + 2] = float(sum.z);
      mixed[i] = std::sqrt(dot(sum, sum)) < 0.99;
    }
  }
  const auto with_resolution = [&](Job& j) { j.set("resolution", resolution); };
  const auto ao_own = compute_ao(s, cam, 1.0, "hemisphere", true, with_resolution);
  const auto ao_filtered = compute_ao(filtered, cam, 1.0, "hemisphere", true, with_resolution);
  double lighter = 0, squared = 0;
  int n = 0;
  for (size_t i = 0; i < s.depth.size(); ++i) {
    if (!mixed[i] || !std::isfinite(s.depth[i])) continue;
    lighter += ao_filtered[i] - ao_own[i];
    squared += std::pow(ao_filtered[i] - ao_own[i], 2);
    ++n;
  }
  ASSERT_GT(n, 40) << label;
  std::printf(
      "[ measure  ] crease with anti-aliased normals, %s %s (%d px): mean AO change %+.4f, "
      "RMS %.4f against each pixel's own normal\n",
      label, resolution, n, lighter / n, std::sqrt(squared / n));
  EXPECT_LT(std::fabs(lighter / n), 0.02) << label << " " << resolution;
  EXPECT_LT(std::sqrt(squared / n), 0.04) << label << " " << resolution;
}

// Runs check(camera, label, resolution) in perspective and orthographic at full resolution, and
// in perspective at half resolution on a frame twice the size.
void in_each_view(const std::function<void(const Camera&, const char*, const char*)>& check) {
  check(perspective(), "perspective", "full");
  check(orthographic_like_perspective(), "orthographic", "full");
  Camera twice = perspective();
  twice.width *= 2, twice.height *= 2;
  check(twice, "perspective", "half");
}

// At half resolution each 2x2 block takes its nearest pixel, which on a concave crease is rarely
// the crease's own: there the check is that the half frame's normals stay right.
TEST(Analytic, AntiAliasedNormalsOnACreaseDoNotLightenIt) {
  in_each_view(expect_anti_aliased_normals_keep_the_crease);
}

// A smooth-shaded mesh's Normal pass interpolates vertex normals over each face, so on a box or
// a capped cylinder with "Shade Smooth" the normals tilt by up to 45 degrees from the face the
// depth shows (in Blender 3.4, a capped 16-segment cylinder's side: 30 to 40 degrees near its
// top). Cycles samples its AO around the tilted normal, but its own face does not occlude it: on
// an open face tilted away from anything it reads 1. The tilt must orient the hemisphere and not
// put the face above its own tangent plane.
// Turns normal n (3 floats) about the view x axis by `degrees` (positive: towards -y).
void turn_down(float* n, double degrees) {
  const double a = degrees * M_PI / 180, ny = n[1], nz = n[2];
  n[1] = float(ny * std::cos(a) + nz * std::sin(a));
  n[2] = float(-ny * std::sin(a) + nz * std::cos(a));
}

void tilt_rows(Scene& s, double top_degrees, double bottom_degrees) {
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      turn_down(&s.normal[3 * (size_t(y) * s.width + x)],
                top_degrees + (bottom_degrees - top_degrees) * y / (s.height - 1));
    }
  }
}

void expect_tilted_normals_leave_an_open_face_open(const Camera& cam, const char* label,
                                                   const char* resolution) {
  const auto with_resolution = [&](Job& j) { j.set("resolution", resolution); };
  for (double face : {0.0, 40.0}) {  // facing the camera, and turned 40 degrees down
    Scene s = tilted_plane(cam, face);
    tilt_rows(s, -40.0, 40.0);
    const auto ao = compute_ao(s, cam, 1.0, "hemisphere", true, with_resolution);
    const Stats st = stats_over(s, ao, everywhere);
    std::printf(
        "[ measure  ] open face at %.0f degrees, normals tilted -40..40 degrees, %s %s: "
        "AO min %.4f mean %.4f (true AO 1)\n",
        face, label, resolution, st.min, st.mean);
    ASSERT_GT(st.count, s.width * s.height / 4) << label;
    EXPECT_GE(st.min, 0.98) << label << " " << resolution << " face " << face;
  }
}

TEST(Analytic, SmoothShadingTiltsDoNotOccludeTheirOwnFace) {
  in_each_view(expect_tilted_normals_leave_an_open_face_open);
}

// ... while a tilt towards an occluder still orients the hemisphere towards it (Cycles: the
// bottom of that smooth-shaded cylinder, its normals tilted down to the floor, reads 0.30 where
// a flat-shaded twin reads 0.62).
TEST(Analytic, SmoothShadingTiltsStillTurnTheHemisphere) {
  const Camera cam = perspective();
  Scene flat = floor_and_wall(cam);
  Scene tilted = flat;
  // The wall's normals (the upper rows) tilted 30 degrees down, towards the floor.
  for (int y = 0; y < tilted.height; ++y) {
    for (int x = 0; x < tilted.width; ++x) {
      const size_t i = size_t(y) * tilted.width + x;
      if (!std::isfinite(tilted.depth[i]) || tilted.normal[3 * i + 1] > 0.5f) continue;
      turn_down(&tilted.normal[3 * i], -30.0);
    }
  }
  const auto ao_flat = compute_ao(flat, cam, 1.0, "hemisphere");
  const auto ao_tilted = compute_ao(tilted, cam, 1.0, "hemisphere");
  const auto on_wall = [&](int x, int y) {
    const size_t i = size_t(y) * flat.width + x;
    return std::isfinite(flat.depth[i]) && flat.normal[3 * i + 1] <= 0.5f;
  };
  const Stats f = stats_over(flat, ao_flat, on_wall), t = stats_over(tilted, ao_tilted, on_wall);
  std::printf(
      "[ measure  ] wall above a floor: mean AO %.4f, normals tilted 30 degrees down "
      "%.4f\n",
      f.mean, t.mean);
  ASSERT_GT(f.count, 100);
  EXPECT_LT(t.mean, f.mean - 0.02);
}

// A bump map's normals turn from pixel to pixel, and there Cycles does occlude a closed object's
// face by itself (Blender 3.4, a bumped cube: its faces mottled down to 0.7): tilts that change
// by more than 6 degrees between a pixel's two neighbours keep the normal's tangent plane.
TEST(Analytic, BumpMapTiltsStillOccludeTheirOwnFace) {
  const Camera cam = perspective();
  Scene smooth = tilted_plane(cam, 0.0), bumped = smooth;
  for (int y = 0; y < bumped.height; ++y) {
    for (int x = 0; x < bumped.width; ++x) {
      turn_down(&bumped.normal[3 * (size_t(y) * bumped.width + x)], (y / 2) % 2 ? 30.0 : -30.0);
    }
  }
  tilt_rows(smooth, 30.0, 30.0);  // the same tilt, everywhere: a smooth-shaded face's
  const Stats b = stats_over(bumped, compute_ao(bumped, cam, 1.0, "hemisphere"), everywhere);
  const Stats s = stats_over(smooth, compute_ao(smooth, cam, 1.0, "hemisphere"), everywhere);
  std::printf(
      "[ measure  ] open face, normals tilted 30 degrees: uniformly AO mean %.4f, "
      "alternating every 2 rows (a bump) %.4f\n",
      s.mean, b.mean);
  EXPECT_GE(s.min, 0.98);
  EXPECT_LT(b.mean, 0.97);
}
