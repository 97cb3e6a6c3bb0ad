// SPDX-License-Identifier: MIT
#include "ao_inputs.h"

#include <cmath>

#include "reporter.h"

namespace povray_ssao {

void take_beauty(const ssao_tools::Image& image, const std::string& path, AoInputs& in) {
  int rgb[3] = {image.find_channel("R"), image.find_channel("G"), image.find_channel("B")};
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
    int grey = image.find_channel("Y");
    if (grey < 0 && image.channels() <= 2) grey = 0;
    if (grey < 0) {
      throw ssao_tools::Error(in_quotes(path) + " has no R, G, B channels; its channels are: " +
                              ssao_tools::join_names(image.channel_names));
    }
    rgb[0] = rgb[1] = rgb[2] = grey;
  }
  const int alpha = image.find_channel("A");
  in.beauty_has_alpha = alpha >= 0;
  const size_t stride = static_cast<size_t>(image.channels());
  in.beauty.assign(image.pixel_count() * 4, 1.0f);
  for (size_t p = 0; p < image.pixel_count(); ++p) {
    for (int c = 0; c < 3; ++c) {
      in.beauty[p * 4 + static_cast<size_t>(c)] =
          image.pixels[p * stride + static_cast<size_t>(rgb[c])];
    }
    if (alpha >= 0) in.beauty[p * 4 + 3] = image.pixels[p * stride + static_cast<size_t>(alpha)];
  }
}

void fill_planar_and_radial(AoInputs& in, const std::vector<float>& depth, bool depth_is_planar) {
  const int data_width = in.data_width(), data_height = in.data_height();
  in.radial.assign(in.frame_pixels(), kInfinity);
  in.planar.assign(in.frame_pixels(), kInfinity);
  in.depth_input.assign(static_cast<size_t>(data_width) * static_cast<size_t>(data_height),
                        kInfinity);
  for (int y = 0; y < data_height; ++y) {
    for (int x = 0; x < data_width; ++x) {
      const size_t p =
          static_cast<size_t>(y) * static_cast<size_t>(data_width) + static_cast<size_t>(x);
      const float d = depth[p];
      if (!(std::isfinite(d) && d > 0.0f)) continue;
      const int fx = x - in.band, fy = y - in.band;  // the frame's pixel coordinates
      const double factor = in.camera.radial_factor(fx, fy, in.width, in.height);
      const float planar = depth_is_planar ? d : static_cast<float>(d / factor);
      const float radial = depth_is_planar ? static_cast<float>(d * factor) : d;
      in.depth_input[p] = in.planar_input ? planar : radial;
      if (fx < 0 || fy < 0 || fx >= in.width || fy >= in.height) continue;
      const size_t f =
          static_cast<size_t>(fy) * static_cast<size_t>(in.width) + static_cast<size_t>(fx);
      in.planar[f] = planar;
      in.radial[f] = radial;
    }
  }
}

}  // namespace povray_ssao
