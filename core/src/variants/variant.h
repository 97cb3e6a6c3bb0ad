// SPDX-License-Identifier: MIT
// The variant interface. A variant is one file: it reads its settings from the parameter values
// once per run, precomputes its constant tables (no pow, sin, cos or hash per sample), and
// estimates the raw visibility (1 = unoccluded) of the pixels of a tile. The job runs it over
// the tiles, then denoises and shapes the result.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "frame.h"
#include "params.h"
#include "tiles.h"

namespace ssao {

class Variant {
 public:
  virtual ~Variant() = default;
  // Writes the raw visibility of every pixel of the tile to visibility[frame.index(x, y)]; a
  // pixel that is not a receiver (below) gets 1.
  virtual void estimate(const Frame& frame, const Tile& tile, float* visibility) const = 0;
  // The same with the scalar reference code, where the variant has a vectorised fast path:
  // the tests' oracle for it.
  virtual void estimate_reference(const Frame& frame, const Tile& tile, float* visibility) const {
    estimate(frame, tile, visibility);
  }
};

struct VariantInfo {
  const char* name;
  const char* description;
  // The parameters this variant reads beyond the ones every variant reads, '|'-separated.
  const char* parameters;
  std::unique_ptr<Variant> (*create)(const ParamValues& values, const Frame& frame);
  // The planes it reads beyond depth and normals (FrameExtras): the job builds only these.
  unsigned frame_extras;
};

// Every variant, in the order front ends list them.
const std::vector<VariantInfo>& variant_registry();
const VariantInfo& find_variant(const std::string& name);

// Sample counts of a quality preset; a count parameter left at 0 takes the preset's.
enum class Quality { low, medium, high, ultra };
Quality quality_of(const ParamValues& values);
// values.get_int(name), or presets[quality] when it is 0 (auto).
int count_or_preset(const ParamValues& values, const char* name, const int (&presets)[4]);

// --- helpers shared by the variants ---

// Pixels worth estimating: geometry whose kernel covers at least half a pixel (a smaller one
// sees no other pixel). Every other pixel has visibility 1 without any work.
inline bool is_receiver(const Frame& f, int x, int y, float radius) {
  return f.is_geometry(x, y) && radius >= 0.5f * f.camera().pixel_footprint(f.depth(x, y));
}

// Writes pixel(x, y) for every receiver of the tile and 1 for every other pixel: the scalar loop
// of every variant.
template <typename PixelFn>
void estimate_receivers(const Frame& f, const Tile& t, float radius, float* visibility,
                        PixelFn&& pixel) {
  for (int y = t.y0; y < t.y1; ++y) {
    for (int x = t.x0; x < t.x1; ++x) {
      visibility[f.index(x, y)] = is_receiver(f, x, y, radius) ? pixel(x, y) : 1.0f;
    }
  }
}

// Looks up the surface seen through the pixel that view-space point s projects to. Returns false
// when s falls outside the image (or behind a perspective camera): such a sample tells nothing.
// The pixel (qx, qy) that view-space point s projects to; false when s falls outside the image
// (or behind a perspective camera).
inline bool pixel_of_sample(const Frame& f, Vec3 s, int& qx, int& qy) {
  float u, v;
  if (!f.camera().project(s, u, v)) return false;
  if (!(u >= 0.0f && v >= 0.0f && u < float(f.width()) && v < float(f.height()))) return false;
  qx = int(u), qy = int(v);
  return true;
}

inline bool surface_behind_sample(const Frame& f, Vec3 s, bool& is_geometry, Vec3& surface) {
  int qx, qy;
  if (!pixel_of_sample(f, s, qx, qy)) return false;
  is_geometry = f.is_geometry(qx, qy);
  if (is_geometry) surface = f.position(qx, qy);
  return true;
}

// Range check against halos: an occluder counts fully when the sample lies at most `thickness`
// behind the visible surface, fading out at twice that (surfaces are assumed about that thick).
inline float thickness_weight(float depth_behind_surface, float thickness) {
  return saturate(2.0f - depth_behind_surface / thickness);
}

}  // namespace ssao
