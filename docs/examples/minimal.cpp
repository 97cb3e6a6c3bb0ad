// SPDX-License-Identifier: MIT
// The smallest use of libssao from C++ (ssao/ssao.hpp, the header-only wrapper of the C API):
// the corner of examples/minimal.c, given the camera as pinhole intrinsics, with the run's
// statistics. Built and run by the tests.
#include <algorithm>
#include <cstdio>
#include <ssao/ssao.hpp>
#include <vector>

int main() {
  constexpr int width = 64, height = 48;
  const double focal = width * 35.0 / 36.0;  // a 35 mm lens on a 36 mm sensor, in pixels
  std::vector<float> depth(width * height), ao(width * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double slope = (x + 0.5 - width / 2.0) / focal;
      depth[y * width + x] = float(std::min(6.0 / (1.0 - slope), 6.0 / (1.0 + slope)));
    }
  }
  try {
    ssao::api::Job job;
    job.set("radius", 1.0);  // scene units
    job.set("projection", "intrinsics");
    job.set("intrinsics", std::vector<double>{focal, focal, width / 2.0, height / 2.0});
    job.set_image("depth", depth.data(), width, height, 1);
    job.set_image("ao", ao.data(), width, height, 1);
    job.run();
    const ssao::api::Job::RunStats stats = job.last_run();
    std::printf("AO at the crease %.3f, on the walls %.3f; mean %.3f over %zu pixels\n",
                ao[24 * width + 32], ao[24 * width + 2], stats.mean_ao, stats.geometry_pixels);
    return ao[24 * width + 32] < 0.75f && ao[24 * width + 2] > 0.97f &&
                   stats.geometry_pixels == depth.size()
               ? 0
               : 1;
  } catch (const ssao::api::Error& e) {
    std::fprintf(stderr, "ssao: %s\n", e.what());
    return 1;
  }
}
