// SPDX-License-Identifier: MIT
// Internals against independent references: the camera model against Blender's own projection
// matrices, the variants against the brute-force ray march (tests/reference) on analytic
// scenes, and each variant's vectorised path against its scalar reference.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "analytic_scene.h"
#include "camera.h"
#include "frame.h"
#include "reference_ao.h"
#include "variants/variant.h"

using namespace test;

namespace {

struct BlenderCase {
  const char* name;
  bool ortho;
  double lens, sensor_width, sensor_height;
  const char* fit;
  double shift_x, shift_y, ortho_scale;
  int width, height;
  double aspect_x, aspect_y;
  double projection[16];  // camera.calc_matrix_camera(...), rows
};

// Printed by Blender 3.4.1: blender -b --factory-startup -P scripts/blender/camera_matrices.py
const BlenderCase kBlenderCases[] = {
    {"persp_auto_wide",
     false,
     35.0,
     36.0,
     24.0,
     "AUTO",
     0.0,
     0.0,
     6.0,
     640,
     360,
     1,
     1,
     {1.94444442, 0, 0, 0, 0, 3.45678997, 0, 0, 0, 0, -1.00019991, -0.20002, 0, 0, -1, 0}},
    {"persp_auto_tall",
     false,
     50.0,
     36.0,
     24.0,
     "AUTO",
     0.0,
     0.0,
     6.0,
     300,
     500,
     1,
     1,
     {4.62962961, 0, 0, 0, 0, 2.77777767, 0, 0, 0, 0, -1.00019991, -0.20002, 0, 0, -1, 0}},
    {"persp_shift",
     false,
     28.0,
     36.0,
     24.0,
     "AUTO",
     0.15,
     -0.1,
     6.0,
     320,
     240,
     1,
     1,
     {1.55555546, 0, 0.300000012, 0, 0, 2.07407403, -0.26666671, 0, 0, 0, -1.00019991, -0.20002, 0,
      0, -1, 0}},
    {"persp_vertical",
     false,
     40.0,
     36.0,
     24.0,
     "VERTICAL",
     0.05,
     0.2,
     6.0,
     400,
     300,
     1,
     1,
     {2.5, 0, 0.0750000104, 0, 0, 3.33333325, 0.400000006, 0, 0, 0, -1.00019991, -0.20002, 0, 0, -1,
      0}},
    {"persp_horizontal_tall",
     false,
     40.0,
     30.0,
     20.0,
     "HORIZONTAL",
     0.0,
     0.1,
     6.0,
     200,
     400,
     1,
     1,
     {2.66666651, 0, 0, 0, 0, 1.33333325, 0.100000001, 0, 0, 0, -1.00019991, -0.20002, 0, 0, -1,
      0}},
    {"persp_pixel_aspect",
     false,
     35.0,
     36.0,
     24.0,
     "AUTO",
     0.1,
     0.0,
     6.0,
     480,
     480,
     1,
     1.25,
     {2.43055534, 0, 0.25000003, 0, 0, 1.94444418, 0, 0, 0, 0, -1.00019991, -0.20002, 0, 0, -1, 0}},
    {"ortho_auto",
     true,
     50.0,
     36.0,
     24.0,
     "AUTO",
     0.0,
     0.0,
     7.5,
     640,
     360,
     1,
     1,
     {0.266666681, 0, 0, -0, 0, 0.474074066, 0, -0, 0, 0, -0.00200019986, -1.00019991, 0, 0, 0, 1}},
    {"ortho_shift_vertical",
     true,
     50.0,
     36.0,
     24.0,
     "VERTICAL",
     -0.2,
     0.1,
     4.0,
     300,
     400,
     1,
     1,
     {0.666666687, 0, 0, 0.533333302, 0, 0.50000006, 0, -0.200000003, 0, 0, -0.00200019986,
      -1.00019991, 0, 0, 0, 1}},
};

}  // namespace

TEST(CameraModel, MatchesBlendersProjection) {
  for (const BlenderCase& c : kBlenderCases) {
    ssao::CameraParams params;
    params.orthographic = c.ortho;
    params.lens = c.lens;
    params.sensor_width = c.sensor_width;
    params.sensor_height = c.sensor_height;
    params.sensor_fit = c.fit;
    params.shift_x = c.shift_x;
    params.shift_y = c.shift_y;
    params.ortho_scale = c.ortho_scale;
    params.pixel_aspect_x = c.aspect_x;
    params.pixel_aspect_y = c.aspect_y;
    const ssao::CameraModel model(params, c.width, c.height);
    const double* m = c.projection;
    // View-space points over the frustum at several depths: Blender's clip coordinates give
    // the pixel position; the model must agree, and invert it.
    for (double depth : {0.5, 3.0, 40.0}) {
      for (double a : {-0.4, 0.0, 0.3}) {
        for (double b : {-0.35, 0.1, 0.45}) {
          const double x = a * depth, y = b * depth, z = -depth;
          const double w = m[12] * x + m[13] * y + m[14] * z + m[15];
          const double ndc_x = (m[0] * x + m[1] * y + m[2] * z + m[3]) / w;
          const double ndc_y = (m[4] * x + m[5] * y + m[6] * z + m[7]) / w;
          const double u = (ndc_x + 1.0) * 0.5 * c.width;
          const double v = (1.0 - ndc_y) * 0.5 * c.height;  // row 0 on top
          float mu = 0, mv = 0;
          ASSERT_TRUE(model.project({float(x), float(y), float(z)}, mu, mv)) << c.name;
          EXPECT_NEAR(mu, u, 2e-3 * std::max(1.0, std::fabs(u))) << c.name;
          EXPECT_NEAR(mv, v, 2e-3 * std::max(1.0, std::fabs(v))) << c.name;
          const ssao::Vec3 back = model.view_position(mu, mv, float(depth));
          EXPECT_NEAR(back.x, x, 1e-4 * depth) << c.name;
          EXPECT_NEAR(back.y, y, 1e-4 * depth) << c.name;
        }
      }
    }
  }
}

namespace {

// The core's camera model of a test camera.
ssao::CameraModel camera_model(const Camera& cam, int width, int height) {
  ssao::CameraParams params;
  params.orthographic = cam.ortho;
  params.lens = cam.lens;
  params.sensor_width = cam.sensor;
  params.ortho_scale = cam.ortho_scale;
  return ssao::CameraModel(params, width, height);
}

ssao_ref::DepthScene reference_scene(const Scene& s, const Camera& cam) {
  ssao_ref::DepthScene r;
  r.width = s.width;
  r.height = s.height;
  r.depth = s.depth;
  r.view_normal = s.normal;
  r.camera = camera_model(cam, s.width, s.height);
  return r;
}

double rmse_over_geometry(const Scene& s, const std::vector<float>& a,
                          const std::vector<float>& b) {
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(s.depth[i])) continue;
    sum += double(a[i] - b[i]) * double(a[i] - b[i]);
    ++n;
  }
  return std::sqrt(sum / n);
}

// Boxes on a floor in front of a wall, seen from above at an angle: contact shadows, concave
// edges, convex box edges and a halo-prone silhouette against the distant wall.
Scene boxes_scene(const Camera& cam) {
  const double c = std::cos(0.35), s = std::sin(0.35);
  auto tilt = [&](V3 p) { return V3{p.x, c * p.y - s * p.z, s * p.y + c * p.z}; };  // look down
  std::vector<Solid> solids = {
      {{tilt({0, -1.5, 0}), tilt({0, 1, 0})}},  // floor y = -1.5
      {{tilt({0, 0, -10}), tilt({0, 0, 1})}},   // wall z = -10
  };
  for (Solid b :
       {box({-2.0, -1.5, -7.0}, {-0.8, -0.3, -5.8}), box({0.2, -1.5, -9.9}, {1.6, 0.5, -8.6}),
        box({1.0, -1.5, -6.0}, {1.5, -1.0, -5.5})}) {
    for (Plane& p : b) p = {tilt(p.point), tilt(p.normal)};
    solids.push_back(b);
  }
  return ray_cast(cam, solids);
}

}  // namespace

TEST(Reference, RayMarchMatchesTheClosedFormCorner) {
  const Camera cam;
  const V3 crease{0, 0, -6};
  Scene s = ray_cast(cam, {{{crease, normalized({1, 0, 1})}}, {{crease, normalized({-1, 0, 1})}}});
  ssao_ref::RayMarchSettings settings;
  settings.radius = 1.0f;
  const auto ao = ssao_ref::raymarch_ao(reference_scene(s, cam), settings);
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < ao.size(); ++i) {
    if (!std::isfinite(s.depth[i])) continue;
    const V3 p = s.point[i] - crease;
    const double err = ao[i] - corner_ao(std::sqrt(p.x * p.x + p.z * p.z), 1.0);
    sum += err * err;
    ++n;
  }
  const double rmse = std::sqrt(sum / n);
  std::printf("[ measure  ] ray march vs closed-form corner: RMSE %.4f over %d px\n", rmse, n);
  EXPECT_LT(rmse, 0.04);  // measured 0.018: ray noise (128 rays) and the pixel grid
}

TEST(Reference, VariantsAgreeWithTheRayMarch) {
  const Camera cam;
  Scene s = boxes_scene(cam);
  ssao_ref::RayMarchSettings settings;
  settings.radius = 0.8f;
  const auto truth = ssao_ref::raymarch_ao(reference_scene(s, cam), settings);
  const auto hemisphere = compute_ao(s, cam, 0.8, "hemisphere");
  const auto sphere = compute_ao(s, cam, 0.8, "sphere");
  const auto seed = ssao_ref::seed_hemisphere_ao(reference_scene(s, cam), 0.8f);
  std::vector<float> unoccluded(truth.size(), 1.0f);
  const double e_hemisphere = rmse_over_geometry(s, hemisphere, truth);
  const double e_sphere = rmse_over_geometry(s, sphere, truth);
  const double e_seed = rmse_over_geometry(s, seed, truth);
  const double e_none = rmse_over_geometry(s, unoccluded, truth);
  std::printf(
      "[ measure  ] RMSE vs ray march: hemisphere %.4f, sphere %.4f, seed hemisphere "
      "%.4f, AO=1 %.4f\n",
      e_hemisphere, e_sphere, e_seed, e_none);
  EXPECT_GT(e_none, 0.1) << "the scene must have occlusion";
  EXPECT_LT(e_hemisphere, 0.06);  // measured: hemisphere 0.030, sphere 0.107, seed 0.099
  EXPECT_LT(e_hemisphere, 0.6 * e_seed);
  EXPECT_LT(e_sphere, e_none);
}

TEST(Reference, RadialDepthGivesTheSameResultAsPlanar) {
  const Camera cam;
  Scene s = boxes_scene(cam);
  const auto planar = compute_ao(s, cam, 0.8, "hemisphere");
  Scene radial = s;
  for (size_t i = 0; i < s.depth.size(); ++i) {
    if (!std::isfinite(s.depth[i])) continue;
    const V3 p = s.point[i];
    radial.depth[i] = float(std::sqrt(dot(p, p)));
  }
  const auto from_radial = compute_ao(radial, cam, 0.8, "hemisphere", true,
                                      [](Job& j) { j.set("depth_kind", "radial"); });
  EXPECT_LT(rmse_over_geometry(s, planar, from_radial), 0.005);
}

// --- the vectorised fast path of each variant against its scalar reference, and tilings ---

namespace {

struct PreparedFrame {
  ssao::Frame frame;
  ssao::ParamValues values;
};

// A corner (two walls) on a floor: creases, silhouettes and open floor in one frame. 101 pixels
// wide, so rows end in a partial vector on every SIMD width.
// A box floats in front of the corner, a slab behind it. With `layers` the frame gets the 2nd and
// 3rd hits: `facing` says whether their facing images are given or taken to alternate.
void prepare(PreparedFrame& out, const Camera& cam, const char* variant, bool layers = false,
             bool facing = true, bool tilted = false, unsigned extras = ssao::kAllFrameExtras) {
  Camera c = cam;
  c.width = 101;
  c.height = 67;
  std::vector<Solid> solids = {
      {{{0, -1.0, 0}, {0, 1, 0}}},
      {{{0.3, 0, -6}, normalized({1, 0, 1})}, {{0.3, 0, -6}, normalized({-1, 0, 1})}},
      box({-0.9, -0.8, -5.2}, {-0.1, 0.2, -4.6}),
      // A thin slab behind the box that shows beside it: where the box hides it, its front is
      // the 3rd hit and its thickness is measured beside the box (Frame::last_thickness).
      box({-0.6, -0.9, -5.6}, {0.2, 0.5, -5.5})};
  static Scene s;  // the frame's images must outlive build(): kept until the next prepare()
  s = ray_cast(c, solids);
  if (tilted) {  // the floor's normals tilted as a smooth-shaded mesh's (Frame::surface_normal)
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        float* n = &s.normal[3 * (size_t(y) * s.width + x)];
        if (!(n[1] > 0.9f)) continue;
        const double a = 0.5 * std::sin(x / 25.0), ny = n[1], nz = n[2];
        n[1] = float(ny * std::cos(a) + nz * std::sin(a));
        n[2] = float(-ny * std::sin(a) + nz * std::cos(a));
      }
    }
  }
  out.values.set_string("variant", variant);
  out.values.set_string("camera_type", c.ortho ? "ORTHO" : "PERSP");
  out.values.set_float("lens", c.lens);
  out.values.set_float("sensor_width", c.sensor);
  out.values.set_float("ortho_scale", c.ortho_scale);
  out.values.set_string("normal_space", "camera");
  ssao::FrameInputs in;
  in.depth = {s.depth.data(), s.width, s.height, 1, 4, 4 * std::ptrdiff_t(s.width)};
  in.normal = {s.normal.data(), s.width, s.height, 3, 12, 12 * std::ptrdiff_t(s.width)};
  in.world_normals = false;
  for (int k = 0; layers && k < 2; ++k) {
    in.layers[k] = {s.layer[k].data(), s.width, s.height, 1, 4, 4 * std::ptrdiff_t(s.width)};
    if (facing) {
      in.facing[k] = {s.facing[k].data(), s.width, s.height, 1, 4, 4 * std::ptrdiff_t(s.width)};
    }
  }
  in.extra_layers = layers ? 2 : 0;
  // As Job::run: the assumed thickness shaped by the silhouettes (one layer, kAssumedThickness).
  in.assumed_thickness =
      float(out.values.get_float("thickness")) * float(out.values.get_float("radius"));
  in.shape_thickness_by_silhouettes = true;
  ssao::TilePool pool(2);
  ssao::Progress progress(nullptr, nullptr);
  out.frame.reset(camera_model(c, s.width, s.height), s.width, s.height, in.extra_layers);
  out.frame.build(in, pool, progress, extras);
}

std::vector<float> estimate(const PreparedFrame& p, bool reference,
                            const std::vector<ssao::Tile>& tiles) {
  const auto variant = ssao::find_variant(p.values.get_string("variant")).create(p.values, p.frame);
  std::vector<float> out(size_t(p.frame.width()) * p.frame.height(), -1.0f);
  for (const ssao::Tile& t : tiles) {
    if (reference) {
      variant->estimate_reference(p.frame, t, out.data());
    } else {
      variant->estimate(p.frame, t, out.data());
    }
  }
  return out;
}

std::vector<ssao::Tile> whole(const ssao::Frame& f) { return {{0, 0, f.width(), f.height()}}; }

}  // namespace

TEST(Frame, LastThicknessIsMeasuredBesideTheForeground) {
  // prepare()'s layered frame: where the floating box hides the 10 cm slab behind it, the slab's
  // front is the last known hit; within kThicknessSearch pixels of where the slab shows, the
  // slab's chord along a neighbour's ray is read there. The truth: the chord along the pixel's
  // own ray, from a frame without the box (there the slab is the 1st hit and its back the 2nd).
  Camera c;
  c.width = 101, c.height = 67;
  const Scene unhidden =
      ray_cast(c, {{{{0, -1.0, 0}, {0, 1, 0}}},
                   {{{0.3, 0, -6}, normalized({1, 0, 1})}, {{0.3, 0, -6}, normalized({-1, 0, 1})}},
                   box({-0.6, -0.9, -5.6}, {0.2, 0.5, -5.5})});
  for (bool facing : {true, false}) {
    PreparedFrame p;
    prepare(p, c, "hemisphere", true, facing);
    const ssao::Frame& f = p.frame;
    int slab = 0, measured = 0, exact = 0;
    for (int y = 0; y < f.height(); ++y) {
      for (int x = 0; x < f.width(); ++x) {
        const size_t i = f.index(x, y);
        const float third = f.layer_planes()[f.pixel_count() + i];
        if (std::fabs(third - 5.5f) > 1e-3f) continue;  // the slab's front as the 3rd hit
        ++slab;
        const float t = f.last_thickness(x, y);
        if (!(t > 0.0f)) continue;
        ++measured;
        const float chord = unhidden.layer[0][i] - unhidden.depth[i];
        exact += std::fabs(t - chord) <= 1e-3f ? 1 : 0;
        // Never more than the slab is deep.
        EXPECT_LE(t, 0.1f + 1e-3f) << x << ", " << y << " chord " << chord;
      }
    }
    std::printf(
        "[ measure  ] facing %s: slab hidden behind the box at %d px, its thickness "
        "measured at %d, equal to its own chord at %d\n",
        facing ? "given" : "alternating", slab, measured, exact);
    EXPECT_GT(measured, slab / 2);
    EXPECT_GE(exact, measured * 9 / 10);
  }
}

TEST(Frame, SurfacesAreCarriedAsFarAsTheyWereSeenFlat) {
  // A board 5 before the camera, in front of a flat wall 10 away, alone or framed by a ring of
  // boxes 7 away that leaves the wall showing in a gap of about 8 pixels around the board. One
  // layer: the surface beyond each silhouette is carried on behind the board
  // (Frame::carried_depth) as far as it was seen on its plane beyond the step, at least
  // kCarrySearch pixels: the open wall's across the board, the framed wall's a band of
  // kCarrySearch pixels along its edges.
  Camera c;
  c.width = 320, c.height = 240;
  for (const bool open : {true, false}) {
    std::vector<Solid> solids = {{{{0, 0, -10}, {0, 0, 1}}},
                                 box({-0.8, -0.6, -5.2}, {0.8, 0.6, -5.0})};
    if (!open) {
      solids.push_back(box({-4, -4, -7.2}, {-1.27, 4, -7.0}));
      solids.push_back(box({1.27, -4, -7.2}, {4, 4, -7.0}));
      solids.push_back(box({-1.27, 0.99, -7.2}, {1.27, 4, -7.0}));
      solids.push_back(box({-1.27, -4, -7.2}, {1.27, -0.99, -7.0}));
    }
    Scene s = ray_cast(c, solids);
    ssao::FrameInputs in;
    in.depth = {s.depth.data(), s.width, s.height, 1, 4, 4 * std::ptrdiff_t(s.width)};
    in.normal = {s.normal.data(), s.width, s.height, 3, 12, 12 * std::ptrdiff_t(s.width)};
    in.world_normals = false;
    in.assumed_thickness = 0.5f;
    ssao::TilePool pool(2);
    ssao::Progress progress(nullptr, nullptr);
    ssao::Frame f;
    f.reset(camera_model(c, s.width, s.height), s.width, s.height, 0);
    f.build(in, pool, progress, ssao::kAllFrameExtras);
    ASSERT_NE(f.carried_depth_plane(), nullptr);
    // The board's pixels farther than kCarrySearch from its silhouette on every side, those of
    // them the wall's plane reaches, and those nearer its edges that it reaches.
    int board = 0, deep = 0, carried = 0, on_the_wall = 0, band_on_the_wall = 0;
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        if (!(std::fabs(f.depth(x, y) - 5.0f) < 0.01f)) continue;
        ++board;
        bool inside = true;
        for (const auto& step : {std::array<int, 2>{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const int ex = x + step[0] * (ssao::Frame::kCarrySearch + 1);
          const int ey = y + step[1] * (ssao::Frame::kCarrySearch + 1);
          inside = inside && ex >= 0 && ey >= 0 && ex < s.width && ey < s.height &&
                   std::fabs(f.depth(ex, ey) - 5.0f) < 0.01f;
        }
        const float d = f.carried_depth(x, y);
        if (!inside) {
          band_on_the_wall += std::fabs(d - 10.0f) < 0.01f ? 1 : 0;
          continue;
        }
        ++deep;
        if (!std::isfinite(d)) continue;
        ++carried;
        on_the_wall += std::fabs(d - 10.0f) < 0.01f ? 1 : 0;
      }
    }
    std::printf(
        "[ measure  ] %s: board %d px, %d beyond kCarrySearch of its edges, %d of them "
        "with a carried surface (%d at the wall's depth); %d nearer its edges at the "
        "wall's depth\n",
        open ? "open wall" : "framed wall", board, deep, carried, on_the_wall, band_on_the_wall);
    ASSERT_GT(deep, 1000);
    EXPECT_GT(band_on_the_wall, (board - deep) * 9 / 10);
    if (open) {
      EXPECT_EQ(on_the_wall, deep);
    } else {
      EXPECT_EQ(carried, 0);
    }
  }
}

TEST(Frame, BesideBackgroundRowMatchesTheNeighboursOneByOne) {
  // Sky scattered over frames from 1x1 up, every row asked whole and in windows that start and
  // end at the frame's borders and inside it: each flag must say whether one of the (up to 8)
  // pixels around is sky, as a walk over the neighbours says.
  uint32_t seed = 12345;
  const auto random = [&] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 24);
  };
  for (const auto& size : {std::pair{1, 1}, {2, 3}, {3, 2}, {7, 5}, {40, 6}}) {
    Camera c;
    c.width = size.first, c.height = size.second;
    const int w = c.width, h = c.height;
    std::vector<float> depth(size_t(w) * h);
    for (float& d : depth) d = random() < 0.15f ? std::numeric_limits<float>::infinity() : 2.0f;
    ssao::FrameInputs in;
    in.depth = ssao::ImageView{depth.data(), w, h, 1, 4, 4 * std::ptrdiff_t(w)};
    ssao::TilePool pool(1);
    ssao::Progress progress(nullptr, nullptr);
    ssao::Frame f;
    f.reset(camera_model(c, w, h), w, h, 0);
    f.build(in, pool, progress);
    size_t beside_count = 0;
    for (int y = 0; y < h; ++y) {
      for (const auto& window : {std::pair{0, w}, {0, w / 2}, {w / 2, w}, {1, w - 1}}) {
        const int x0 = window.first, x1 = window.second;
        if (x1 <= x0) continue;
        std::vector<uint8_t> beside(size_t(x1 - x0), 7);
        f.beside_background_row(y, x0, x1, beside.data());
        for (int x = x0; x < x1; ++x) {
          bool expected = false;
          for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, h - 1); ++ny) {
            for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, w - 1); ++nx) {
              expected = expected || !f.is_geometry(nx, ny);
            }
          }
          EXPECT_EQ(beside[x - x0], expected ? 1 : 0) << w << "x" << h << " at " << x << ", " << y;
          beside_count += expected ? 1 : 0;
        }
      }
    }
    if (w * h > 20) {
      EXPECT_GT(beside_count, 0u) << w << "x" << h;  // the sky is there
    }
  }
}

TEST(Frame, LastThicknessIsMeasuredWhereNeighboursSeeTheSolidHiddenToo) {
  // A row of rays (orthographic: every ray the same chord) through two boxes and a 10 cm slab
  // behind them. Left of column 10 a ray meets both boxes, so the slab's front is its 5th hit,
  // the last it knows; from column 10 on only the second box, so the slab is the 3rd hit, closed
  // by the 4th. The neighbours that see the slab at all see it hidden, never as the visible
  // surface: the search must walk through the pixels that see it as their 5th hit and measure
  // it where a neighbour shows it closed, at any depth of the stack.
  Camera c;
  c.ortho = true;
  c.width = 20, c.height = 3;
  const int w = c.width, h = c.height;
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> depth(size_t(w) * h), normal(size_t(w) * h * 3, 0.0f);
  std::vector<std::vector<float>> hits(4, std::vector<float>(size_t(w) * h, inf));
  std::vector<std::vector<float>> facing(4, std::vector<float>(size_t(w) * h, 0.0f));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      normal[3 * i + 2] = 1.0f;
      const std::vector<float> stack = x < 10 ? std::vector<float>{2.0f, 2.1f, 3.0f, 3.1f, 5.0f}
                                              : std::vector<float>{3.0f, 3.1f, 5.0f, 5.1f};
      depth[i] = stack[0];
      for (size_t k = 1; k < stack.size(); ++k) {
        hits[k - 1][i] = stack[k];
        facing[k - 1][i] = k % 2 == 1 ? 1.0f : 0.0f;  // back, front, back, front
      }
    }
  }
  ssao::FrameInputs in;
  const auto plane = [&](std::vector<float>& v, int channels) {
    return ssao::ImageView{
        v.data(), w, h, channels, 4 * std::ptrdiff_t(channels), 4 * std::ptrdiff_t(channels) * w};
  };
  in.depth = plane(depth, 1);
  in.normal = plane(normal, 3);
  in.world_normals = false;
  for (int k = 0; k < 4; ++k) {
    in.layers[k] = plane(hits[k], 1);
    in.facing[k] = plane(facing[k], 1);
  }
  in.extra_layers = 4;
  ssao::TilePool pool(2);
  ssao::Progress progress(nullptr, nullptr);
  ssao::Frame f;
  f.reset(camera_model(c, w, h), w, h, in.extra_layers);
  f.build(in, pool, progress);
  for (int y = 0; y < h; ++y) {
    // Within kThicknessSearch of column 10, the slab's chord; farther, nothing is known.
    for (int x = 0; x < 10; ++x) {
      const float expected = 10 - x <= ssao::Frame::kThicknessSearch ? 0.1f : 0.0f;
      EXPECT_NEAR(f.last_thickness(x, y), expected, 1e-5f) << x << ", " << y;
    }
    // The slab is closed where it is the 3rd hit: no last front to measure.
    for (int x = 10; x < w; ++x) EXPECT_EQ(f.last_thickness(x, y), 0.0f) << x << ", " << y;
  }
}

TEST(FastPath, EveryVariantMatchesItsScalarReference) {
  struct Case {
    const char* name;
    bool layers, facing, tilted = false;
  };
  std::vector<Case> cases;
  for (const ssao::VariantInfo& info : ssao::variant_registry())
    cases.push_back({info.name, false, false});
  // The variants that read extra depth layers, with and without facing images.
  cases.push_back({"hemisphere", true, true});
  cases.push_back({"hemisphere", true, false});
  // Normals that tilt across their surface: the tangent-plane tests read the surface's.
  cases.push_back({"hemisphere", false, false, true});
  cases.push_back({"hemisphere", true, true, true});
  for (const Case& info : cases) {
    for (const Camera& cam : {Camera{}, Camera{true}}) {
      PreparedFrame p;
      prepare(p, cam, info.name, info.layers, info.facing, info.tilted);
      const auto fast = estimate(p, false, whole(p.frame));
      const auto reference = estimate(p, true, whole(p.frame));
      size_t differ = 0, geometry = 0;
      double worst = 0.0;
      for (size_t i = 0; i < fast.size(); ++i) {
        ASSERT_GE(fast[i], 0.0f) << info.name << ": pixel " << i << " not written";
        const double d = std::fabs(double(fast[i]) - reference[i]);
        worst = std::max(worst, d);
        differ += d > 1e-3 ? 1 : 0;
        geometry += std::isfinite(p.frame.depth_plane()[i]) ? 1 : 0;
      }
      std::printf("[ measure  ] %s%s%s %s: %zu of %zu geometry pixels differ by > 1e-3, max %.5f\n",
                  info.name,
                  info.layers ? (info.facing ? " +layers" : " +layers (alternating)") : "",
                  info.tilted ? " +tilted normals" : "", cam.ortho ? "ortho" : "persp", differ,
                  geometry, worst);
      // The fast path fuses multiply-adds and refines a reciprocal estimate: rounding can move a
      // sample across a test's threshold, which changes one direction of one pixel (measured:
      // at most a handful of pixels), or move volumetric's chords a little (measured: at most
      // 1e-4). A real divergence changes most pixels, and by far more.
      EXPECT_LE(differ, geometry / 200) << info.name;
      EXPECT_LE(worst, 0.5) << info.name;
    }
  }
}

TEST(Frame, EachVariantReadsOnlyTheExtrasItDeclares) {
  // The job builds only the planes a variant declares (VariantInfo::frame_extras): its AO must be
  // the same bits as from a frame with every plane, and the skipped planes must be absent.
  for (const ssao::VariantInfo& info : ssao::variant_registry()) {
    for (const bool layers : {false, true}) {
      for (const Camera& cam : {Camera{}, Camera{true}}) {
        PreparedFrame all, declared;
        prepare(all, cam, info.name, layers);
        prepare(declared, cam, info.name, layers, true, false, info.frame_extras);
        const ssao::Frame& f = declared.frame;
        if ((info.frame_extras & ssao::kSolidThickness) == 0) {
          EXPECT_EQ(f.last_thickness_plane(), nullptr) << info.name;
        }
        if ((info.frame_extras & ssao::kPlaneDistanceScale) == 0) {
          EXPECT_EQ(f.plane_distance_scale_plane(), nullptr) << info.name;
        }
        if ((info.frame_extras & ssao::kCarriedSurfaces) == 0) {
          EXPECT_EQ(f.carried_depth_plane(), nullptr) << info.name;
        }
        for (const bool reference : {false, true}) {
          const auto expected = estimate(all, reference, whole(all.frame));
          const auto got = estimate(declared, reference, whole(f));
          EXPECT_EQ(std::memcmp(expected.data(), got.data(), expected.size() * sizeof(float)), 0)
              << info.name << (layers ? " +layers" : "") << (cam.ortho ? " ortho" : " persp")
              << (reference ? " (scalar reference)" : "");
        }
      }
    }
  }
}

TEST(FastPath, AnyTilingGivesTheSameBits) {
  for (const ssao::VariantInfo& info : ssao::variant_registry()) {
    PreparedFrame p;
    prepare(p, Camera{}, info.name);
    const auto reference = estimate(p, false, whole(p.frame));
    // Odd tile sizes: vectors start at every phase of the 4-pixel jitter pattern.
    std::vector<ssao::Tile> tiles;
    for (int y = 0; y < p.frame.height(); y += 13) {
      for (int x = 0; x < p.frame.width(); x += 7) {
        tiles.push_back(
            {x, y, std::min(x + 7, p.frame.width()), std::min(y + 13, p.frame.height())});
      }
    }
    const auto tiled = estimate(p, false, tiles);
    EXPECT_EQ(std::memcmp(reference.data(), tiled.data(), reference.size() * sizeof(float)), 0)
        << info.name;
  }
}
