/* SPDX-License-Identifier: MIT
 * The smallest use of libssao from C: AO of a 90-degree corner seen by a 35 mm camera.
 * Built and run by the tests (it also proves the header is valid C). */
#include <math.h>
#include <ssao/ssao.h>
#include <stdio.h>
#include <stdlib.h>

enum { WIDTH = 64, HEIGHT = 48 };

int main(void) {
  static float depth[HEIGHT][WIDTH], ao[HEIGHT][WIDTH];
  /* Two walls meeting 6 units ahead; planar depth along each pixel's ray. */
  for (int y = 0; y < HEIGHT; ++y) {
    for (int x = 0; x < WIDTH; ++x) {
      const double slope = ((x + 0.5) / WIDTH - 0.5) * 36.0 / 35.0;
      depth[y][x] = (float)fmin(6.0 / (1.0 - slope), 6.0 / (1.0 + slope));
    }
  }

  ssao_job job;
  if (ssao_job_create(&job) != SSAO_OK) return 1;
  ssao_status s = ssao_job_set_float(job, "radius", 1.0); /* scene units */
  if (!s) s = ssao_job_set_float(job, "lens", 35.0);      /* mm, sensor 36 mm by default */
  if (!s) s = ssao_job_set_image(job, "depth", &depth[0][0], WIDTH, HEIGHT, 1, 0, 0);
  if (!s) s = ssao_job_set_image(job, "ao", &ao[0][0], WIDTH, HEIGHT, 1, 0, 0);
  if (!s) s = ssao_job_run(job);
  if (s) fprintf(stderr, "ssao: %s: %s\n", ssao_status_string(s), ssao_last_error());
  ssao_job_destroy(job);
  if (s) return 1;

  printf("AO at the crease %.3f, on the walls %.3f\n", ao[24][32], ao[24][2]);
  return ao[24][32] < 0.75f && ao[24][2] > 0.97f ? 0 : 1;
}
