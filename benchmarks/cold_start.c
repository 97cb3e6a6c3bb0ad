/* SPDX-License-Identifier: MIT
 * What the first frame of a process pays: the run times of libssao's first, second and third
 * runs of one job, and of a second job's first run, in one process, on a synthetic frame (a
 * room corner with a floor, planar depth and view-space normals; no file I/O).
 *
 *   build/bin/cold_start [WIDTH HEIGHT [THREADS]]       (default 640 360 2)
 *
 * Prints one line: create_ms run1_ms run2_ms run3_ms job2_run1_ms. run1 - run3 is what a
 * single-frame process (build/bin/ssao on one file) pays on top of a warm run; job2_run1 -
 * run3 is the part of it that a new job pays again in a warm process. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <ssao/ssao.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static const double kHalfRoot2 = 0.70710678118654752;

static double now_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static ssao_job make_job(float* depth, float* normal, float* ao, int width, int height,
                         int threads) {
  ssao_job job;
  if (ssao_job_create(&job) != SSAO_OK) return NULL;
  ssao_status s = ssao_job_set_float(job, "radius", 0.8);
  if (!s) s = ssao_job_set_float(job, "lens", 35.0);
  if (!s) s = ssao_job_set_int(job, "threads", threads);
  if (!s) s = ssao_job_set_string(job, "normal_space", "camera");
  if (!s) s = ssao_job_set_image(job, "depth", depth, width, height, 1, 0, 0);
  if (!s) s = ssao_job_set_image(job, "normal", normal, width, height, 3, 0, 0);
  if (!s) s = ssao_job_set_image(job, "ao", ao, width, height, 1, 0, 0);
  if (s) {
    fprintf(stderr, "cold_start: %s: %s\n", ssao_status_string(s), ssao_last_error());
    ssao_job_destroy(job);
    return NULL;
  }
  return job;
}

static double timed_run(ssao_job job) {
  const double start = now_ms();
  if (ssao_job_run(job) != SSAO_OK) {
    fprintf(stderr, "cold_start: run failed: %s\n", ssao_last_error());
    exit(1);
  }
  return now_ms() - start;
}

int main(int argc, char** argv) {
  const int width = argc > 2 ? atoi(argv[1]) : 640, height = argc > 2 ? atoi(argv[2]) : 360;
  const int threads = argc > 3 ? atoi(argv[3]) : 2;
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384 || threads < 0) {
    fprintf(stderr, "usage: cold_start [WIDTH HEIGHT [THREADS]]\n");
    return 2;
  }
  const size_t pixels = (size_t)width * (size_t)height;
  float* depth = malloc(pixels * sizeof(float));
  float* normal = malloc(pixels * 3 * sizeof(float));
  float* ao = malloc(pixels * sizeof(float));
  if (!depth || !normal || !ao) return 1;
  /* Camera at the origin looking down -z, 36 mm sensor across the width; the floor y = -1.5 and
   * the walls x - z = 8 and -x - z = 8 (a corner 8 units ahead), the nearest along each ray;
   * planar depth t, so a point is t (rx, ry, -1). Normals face the camera. */
  const double focal = 35.0 / 36.0 * width;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double rx = (x + 0.5 - 0.5 * width) / focal, ry = (0.5 * height - y - 0.5) / focal;
      double d = 1e9, nx = 0, ny = 0, nz = 1;
      if (ry < 0 && -1.5 / ry < d) d = -1.5 / ry, nx = 0, ny = 1, nz = 0;
      if (rx > -1 && 8.0 / (1.0 + rx) < d) d = 8.0 / (1.0 + rx), nx = -kHalfRoot2, ny = 0, nz = kHalfRoot2;
      if (rx < 1 && 8.0 / (1.0 - rx) < d) d = 8.0 / (1.0 - rx), nx = kHalfRoot2, ny = 0, nz = kHalfRoot2;
      depth[(size_t)y * width + x] = (float)d;
      float* n = normal + ((size_t)y * width + x) * 3;
      n[0] = (float)nx, n[1] = (float)ny, n[2] = (float)nz;
    }
  }
  double start = now_ms();
  ssao_job job = make_job(depth, normal, ao, width, height, threads);
  const double create = now_ms() - start;
  if (!job) return 1;
  const double run1 = timed_run(job), run2 = timed_run(job), run3 = timed_run(job);
  ssao_job second = make_job(depth, normal, ao, width, height, threads);
  if (!second) return 1;
  const double job2 = timed_run(second);
  ssao_job_destroy(second);
  ssao_job_destroy(job);
  printf("%dx%d threads %d: create_ms %.2f run1_ms %.2f run2_ms %.2f run3_ms %.2f "
         "job2_run1_ms %.2f\n",
         width, height, threads, create, run1, run2, run3, job2);
  free(depth), free(normal), free(ao);
  return 0;
}
