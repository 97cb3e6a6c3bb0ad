/* SPDX-License-Identifier: MIT
 * raw_ao: AO of raw float32 buffers through the public C API only, so that one source built for
 * Linux and for Windows (MinGW-w64) can be compared bit for bit (tests/windows/compare_ao.py).
 * Raw little-endian float32 instead of EXR keeps image libraries out of the comparison (both
 * targets are x86-64, so the bytes are read as is).
 *
 *   raw_ao WIDTH HEIGHT DEPTH.f32 NORMAL.f32|- OUT.f32 [name=value ...]
 *
 * Every failure prints one line on stderr and exits 1 with no OUT.f32 left behind. */
#include <errno.h>
#include <limits.h>
#include <ssao/ssao.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* g_out; /* removed on failure: a stale result must not pass for this run's */
static char g_part[4096];

static int fail(const char* format, ...) {
  va_list args;
  va_start(args, format);
  fputs("raw_ao: ", stderr);
  vfprintf(stderr, format, args);
  fputc('\n', stderr);
  va_end(args);
  if (g_part[0]) remove(g_part);
  if (g_out) remove(g_out);
  return 1;
}

static int fail_lib(const char* what, ssao_status s) {
  return fail("%s: %s: %s", what, ssao_status_string(s), ssao_last_error());
}

static int parse_size(const char* text, int* out) {
  char* end;
  errno = 0;
  const long v = strtol(text, &end, 10);
  if (end == text || *end || errno || v <= 0 || v > INT_MAX) return 0;
  *out = (int)v;
  return 1;
}

/* Reads exactly count floats: a file of another size is the wrong image, not a usable one.
   Returns NULL and says why in *why. */
static float* read_floats(const char* path, size_t count, const char** why) {
  FILE* f = fopen(path, "rb");
  if (!f) {
    *why = strerror(errno);
    return NULL;
  }
  float* data = malloc(count * sizeof(float));
  const size_t got = data ? fread(data, sizeof(float), count, f) : 0;
  const int longer = data && got == count && fgetc(f) != EOF;
  const int error = ferror(f);
  fclose(f);
  *why = !data          ? "out of memory"
         : error        ? "read error"
         : got != count ? "file too short"
         : longer       ? "file too long"
                        : NULL;
  if (*why) {
    free(data);
    data = NULL;
  }
  return data;
}

/* Parses "a,b,c" into a malloc'ed array of doubles; returns the count, 0 if malformed. */
static size_t parse_floats(const char* text, double** out) {
  size_t n = 1;
  for (const char* p = text; *p; ++p) {
    if (*p == ',') ++n;
  }
  double* v = malloc(n * sizeof(double));
  if (!v) return 0;
  const char* p = text;
  for (size_t i = 0; i < n; ++i) {
    char* end;
    v[i] = strtod(p, &end);
    if (end == p || (*end != ',' && *end != '\0')) {
      free(v);
      return 0;
    }
    p = end + 1;
  }
  *out = v;
  return n;
}

/* Sets one name=value with the setter of the parameter's type, as the library describes it. */
static int set_param(ssao_job job, const char* arg) {
  char name[256];
  const char* eq = strchr(arg, '=');
  if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof name)
    return fail("expected name=value, got '%s'", arg);
  memcpy(name, arg, (size_t)(eq - arg));
  name[eq - arg] = '\0';
  const char* value = eq + 1;

  ssao_param_desc desc;
  size_t i = 0;
  const size_t count = ssao_param_count();
  while (i < count && !(ssao_param_info(i, &desc) == SSAO_OK && strcmp(desc.name, name) == 0)) ++i;
  if (i == count) return fail("unknown parameter '%s'", name);

  ssao_status s;
  char* end;
  errno = 0;
  if (desc.type == SSAO_PARAM_INT) {
    const long v = strtol(value, &end, 10);
    if (end == value || *end || errno || v < INT_MIN || v > INT_MAX)
      return fail("'%s': not an integer", arg);
    s = ssao_job_set_int(job, name, (int)v);
  } else if (desc.type == SSAO_PARAM_FLOAT) {
    const double v = strtod(value, &end);
    if (end == value || *end) return fail("'%s': not a number", arg);
    s = ssao_job_set_float(job, name, v);
  } else if (desc.type == SSAO_PARAM_STRING) {
    s = ssao_job_set_string(job, name, value);
  } else if (desc.type == SSAO_PARAM_FLOATS) {
    double* values = NULL;
    const size_t n = parse_floats(value, &values);
    if (!n) return fail("'%s': not a comma-separated list of numbers", arg);
    s = ssao_job_set_floats(job, name, values, n);
    free(values);
  } else {
    return fail("parameter '%s' has a type this program does not know", name);
  }
  return s == SSAO_OK ? 0 : fail_lib(arg, s);
}

static int run(int argc, char** argv, float** bufs, ssao_job* job) {
  int w, h;
  if (!parse_size(argv[1], &w) || !parse_size(argv[2], &h))
    return fail("WIDTH and HEIGHT must be positive integers, got '%s' '%s'", argv[1], argv[2]);
  if ((size_t)w > (size_t)-1 / 3 / sizeof(float) / (size_t)h) return fail("image too large");
  const size_t pixels = (size_t)w * (size_t)h;
  const int with_normals = strcmp(argv[4], "-") != 0;
  if (snprintf(g_part, sizeof g_part, "%s.part", g_out) >= (int)sizeof g_part) {
    g_part[0] = '\0';
    return fail("output path too long");
  }

  const char* why;
  if (!(bufs[0] = read_floats(argv[3], pixels, &why)))
    return fail("depth '%s' (%dx%d float32): %s", argv[3], w, h, why);
  if (with_normals && !(bufs[1] = read_floats(argv[4], pixels * 3, &why)))
    return fail("normals '%s' (%dx%dx3 float32): %s", argv[4], w, h, why);
  if (!(bufs[2] = malloc(pixels * sizeof(float)))) return fail("out of memory");

  ssao_status s = ssao_job_create(job);
  if (s) return fail_lib("ssao_job_create", s);
  for (int i = 6; i < argc; ++i) {
    if (set_param(*job, argv[i])) return 1;
  }
  s = ssao_job_set_image(*job, "depth", bufs[0], w, h, 1, 0, 0); /* 0, 0: tightly packed */
  if (!s && with_normals) s = ssao_job_set_image(*job, "normal", bufs[1], w, h, 3, 0, 0);
  if (!s) s = ssao_job_set_image(*job, "ao", bufs[2], w, h, 1, 0, 0);
  if (s) return fail_lib("ssao_job_set_image", s);
  if ((s = ssao_job_run(*job))) return fail_lib("ssao_job_run", s);

  /* Written beside OUT, then renamed: a reader never sees a partial file. */
  FILE* f = fopen(g_part, "wb");
  if (!f) return fail("cannot create '%s': %s", g_part, strerror(errno));
  const size_t put = fwrite(bufs[2], sizeof(float), pixels, f);
  if (fclose(f) != 0 || put != pixels) return fail("cannot write '%s'", g_part);
  remove(g_out); /* Windows' rename() fails when the target exists */
  if (rename(g_part, g_out) != 0) return fail("cannot rename '%s' to '%s'", g_part, g_out);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 6) {
    fputs("usage: raw_ao WIDTH HEIGHT DEPTH.f32 NORMAL.f32|- OUT.f32 [name=value ...]\n", stderr);
    return 1;
  }
  g_out = argv[5];
  float* bufs[3] = {NULL, NULL, NULL}; /* depth, normals, ao */
  ssao_job job = NULL;
  const int rc = run(argc, argv, bufs, &job);
  ssao_job_destroy(job);
  for (int i = 0; i < 3; ++i) free(bufs[i]);
  return rc;
}
