/* SPDX-License-Identifier: MIT
 * libssao: screen-space ambient occlusion for offline renders. The stable C API. */
#ifndef SSAO_SSAO_H
#define SSAO_SSAO_H

#include <stddef.h>
#include <stdint.h>

/* -------------------------------------------------------------------------------------------
 * Conventions
 *
 * - Every function that can fail returns an ssao_status: SSAO_OK (0) or an error. The message
 *   of the last failure on the calling thread is returned by ssao_last_error().
 * - A job (ssao_job) holds parameters and image views. Set parameters by name, attach caller-owned
 *   float images, then call ssao_job_run(). Parameters keep their values between runs.
 * - Parameter names, types, defaults, ranges and units are listed by ssao_param_info() and in
 *   docs/api.md. Unknown names, wrong types and out-of-range values are errors, never ignored.
 * - Images are 32-bit float, caller-owned, and read or written in place. Pixel (x, y), with
 *   y = 0 the TOP row, channel c, is the float at
 *       (char*)data + y * row_stride + x * pixel_stride + c * sizeof(float)
 *   Strides are in bytes; 0 means tightly packed (pixel_stride = channels * 4,
 *   row_stride = width * pixel_stride). A negative row_stride reads bottom-up buffers (such as
 *   Blender's): pass a pointer to the top row, which is the LAST row in memory.
 *   Image memory must stay valid until ssao_job_run() returns.
 * - Coordinates: view space looks down -Z with +Y up and +X right (Blender/OpenGL cameras).
 *   Depth is the positive distance along the view axis ("planar", Blender's Depth pass) or
 *   along the pixel's ray ("radial"). A depth that is NaN, infinite, <= 0, >= background_depth
 *   or >= clip_end (when clip_end > 0) marks a background pixel: it is never an occluder and its
 *   AO is 1 (unoccluded).
 * - The camera: one contract for any renderer, chosen by the parameter "projection" (all in
 *   the "camera" group): "lens" (the default) is Blender's camera (camera_type, lens,
 *   sensor_width/height, sensor_fit, shift_x/y, ortho_scale, pixel_aspect_x/y); "intrinsics"
 *   takes fx, fy, cx, cy in pixels ("intrinsics", camera_type choosing perspective or
 *   orthographic); "matrix" takes an OpenGL-style view-to-clip matrix ("projection_matrix").
 *   Every form describes the frame (the output window, with overscan); depth may be planar or
 *   radial ("depth_kind") with any of them.
 * - AO is visibility: 1 = unoccluded, 0 = fully occluded.
 * - Results are bitwise identical for any thread count.
 *
 * Thread safety: functions may be called from any thread. Distinct jobs may be used concurrently;
 * one job must not be used by two threads at once. ssao_job_run() runs on the calling thread
 * plus "threads" - 1 worker threads; the progress callback is only ever called on the calling
 * thread.
 * ------------------------------------------------------------------------------------------- */

#if defined(_WIN32)
#if defined(SSAO_BUILDING_LIBRARY)
#define SSAO_API __declspec(dllexport)
#else
#define SSAO_API __declspec(dllimport)
#endif
#else
#define SSAO_API __attribute__((visibility("default")))
#endif

#define SSAO_VERSION_MAJOR 0
#define SSAO_VERSION_MINOR 1
#define SSAO_VERSION_PATCH 0
/* MAJOR * 10000 + MINOR * 100 + PATCH; compare with ssao_version() at run time. */
#define SSAO_VERSION (SSAO_VERSION_MAJOR * 10000 + SSAO_VERSION_MINOR * 100 + SSAO_VERSION_PATCH)

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ssao_status {
  SSAO_OK = 0,                      /* success */
  SSAO_ERROR_INVALID_ARGUMENT = 1,  /* bad handle, name, type, value, size or stride */
  SSAO_ERROR_INVALID_OPERATION = 2, /* e.g. run without a depth image or without any output */
  SSAO_ERROR_OUT_OF_MEMORY = 3,     /* an allocation failed */
  SSAO_ERROR_CANCELLED = 4,         /* the progress callback asked to stop */
  SSAO_ERROR_INTERNAL = 5           /* unexpected internal error (a bug: please report it) */
} ssao_status;

typedef enum ssao_param_type {
  SSAO_PARAM_INT = 0,    /* set with ssao_job_set_int */
  SSAO_PARAM_FLOAT = 1,  /* set with ssao_job_set_float */
  SSAO_PARAM_STRING = 2, /* one of a fixed set of choices; set with ssao_job_set_string */
  SSAO_PARAM_FLOATS = 3  /* fixed-length float array; set with ssao_job_set_floats */
} ssao_param_type;

/* Describes one parameter. Strings are static and never freed. */
typedef struct ssao_param_desc {
  const char* name;           /* e.g. "radius" */
  ssao_param_type type;       /* how to set it */
  double default_value;       /* INT and FLOAT */
  double min_value;           /* INT and FLOAT: inclusive lower bound */
  double max_value;           /* INT and FLOAT: inclusive upper bound */
  const char* default_string; /* STRING: the default choice; FLOATS: NULL */
  const char* choices;        /* STRING: choices separated by '|'; others: NULL */
  size_t count;               /* FLOATS: number of values; others: 1 */
  const char* unit;           /* e.g. "scene units", "fraction of radius", "" */
  const char* description;    /* one sentence */
} ssao_param_desc;

/* Describes one AO variant (the "variant" parameter's choices). Strings are static. */
typedef struct ssao_variant_desc {
  const char* name;        /* the value of the "variant" parameter, e.g. "horizon" */
  const char* description; /* one sentence */
  /* The parameters this variant reads, '|'-separated, beyond those every variant reads (the
     ones no variant lists). A front end shows these only while the variant is selected. */
  const char* parameters;
} ssao_variant_desc;

/* Called with the fraction done in [0, 1], non-decreasing. Return 0 to cancel the run. */
typedef int (*ssao_progress_fn)(void* user, double fraction);

typedef struct ssao_job_impl* ssao_job;

/* Returns the library version as SSAO_VERSION encodes it. */
SSAO_API int ssao_version(void);
/* Returns a static description of a status code. */
SSAO_API const char* ssao_status_string(ssao_status status);
/* Returns the message of the last failed call on this thread, "" if none. Valid until the next
   failing call on this thread. At most 4095 characters: a longer message is cut, ending in "...".
 */
SSAO_API const char* ssao_last_error(void);

/* Returns the number of parameters; index them with ssao_param_info(). */
SSAO_API size_t ssao_param_count(void);
/* Describes parameter number "index" (0 <= index < ssao_param_count()). */
SSAO_API ssao_status ssao_param_info(size_t index, ssao_param_desc* out);
/* The group of parameter number "index" (a static string), so that front ends select
 * parameters by group instead of keeping lists of names:
 *   "ao"        what the estimate computes (variant, radius, bias, thickness, ...)
 *   "quality"   how much work it does (quality, samples, resolution, denoise, seed, ...)
 *   "shaping"   the final look (strength, power, remap_min, remap_max)
 *   "input"     how the caller's passes are to be read (depth_kind, normal_space, ...)
 *   "camera"    the camera the passes were rendered with (see "The camera" below)
 *   "execution" how the run is executed (threads); results do not depend on it
 * A front end that shows "ao", "quality" and "shaping" shows every parameter that changes the
 * look; new parameters join one of these groups. */
SSAO_API ssao_status ssao_param_group(size_t index, const char** group);

/* Returns the number of variants; index them with ssao_variant_info(). */
SSAO_API size_t ssao_variant_count(void);
/* Describes variant number "index" (0 <= index < ssao_variant_count()). */
SSAO_API ssao_status ssao_variant_info(size_t index, ssao_variant_desc* out);

/* Creates a job with every parameter at its default and no images attached. */
SSAO_API ssao_status ssao_job_create(ssao_job* out);
/* Destroys a job. NULL is a no-op. */
SSAO_API void ssao_job_destroy(ssao_job job);

SSAO_API ssao_status ssao_job_set_int(ssao_job job, const char* name, int value);
SSAO_API ssao_status ssao_job_set_float(ssao_job job, const char* name, double value);
SSAO_API ssao_status ssao_job_set_string(ssao_job job, const char* name, const char* value);
SSAO_API ssao_status ssao_job_set_floats(ssao_job job, const char* name, const double* values,
                                         size_t count);
SSAO_API ssao_status ssao_job_get_int(ssao_job job, const char* name, int* out);
SSAO_API ssao_status ssao_job_get_float(ssao_job job, const char* name, double* out);
/* Copies the value (NUL-terminated, truncated to size) into out. */
SSAO_API ssao_status ssao_job_get_string(ssao_job job, const char* name, char* out, size_t size);
SSAO_API ssao_status ssao_job_get_floats(ssao_job job, const char* name, double* out, size_t count);

/* Attaches (or, with data == NULL, detaches) an image. Names:
 *   "depth"     input, required, channel 0 read
 *   "normal"    input, optional, channels 0..2 read (space given by "normal_space"); without it,
 *               normals are reconstructed from depth
 *   "beauty"    input, 1..4 channels, needed by "composite"; with edge_coverage = beauty its
 *               colours (channels 0..2, or 0 as grey) also say how much of a pixel on a depth
 *               edge each surface covers (docs/variants.md, "Edge coverage from the beauty")
 *   "edge_colours"
 *               input, optional, 1..4 channels, the beauty's size: the colours edge_coverage =
 *               beauty reads in place of the beauty's (a front end whose "beauty" is not the
 *               picture, e.g. a white image whose composite is a factor)
 *   "ambient"   input, optional, as many channels as "beauty": the part of the beauty that AO
 *               darkens (light that does not come straight from a light source)
 *   "ao"        output: AO written to channels 0..min(channels,3)-1, channel 3 (if any) set to 1
 *   "composite" output: beauty with its first min(channels,3) channels multiplied by AO, or,
 *               with "ambient", beauty - (1 - AO) x ambient (not below 0 where the beauty is
 *               not); the rest copied; needs as many channels as "beauty" (may be the beauty
 *               buffer itself). On a silhouette against the background only the surface's
 *               share c of the pixel is darkened: beauty x (1 - c (1 - AO)) (ambient: c (1 -
 *               AO) x ambient), c the length of the "normal" image's vector (an anti-aliased
 *               normal pass averages the surface's unit normals with the background's zeros),
 *               divided by the beauty's alpha (channel 3) when that is below 1 (a transparent
 *               film: the beauty holds only the surface's light); c = 1 elsewhere, and
 *               without a normal image. The "ao" output is not changed by it.
 *   "depth2" ... "depth5"
 *               input, optional, channel 0 read: extra depth layers, the depth of the 2nd, 3rd,
 *               ... surface hit along each pixel's ray, in "depth"'s convention (a background
 *               value: no such hit). Attached in order without a gap ("depth3" needs "depth2").
 *               A hit nearer than the one before it (by more than 0.1 %) is an error; the
 *               layers of a background pixel are not read.
 *   "facing2" ... "facing5"
 *               input, optional, channel 0 read: 1 where hit k is a back face (the ray leaves a
 *               solid), 0 where it is a front face (>= 0.5 counts as back). Without it the hits
 *               are taken to alternate: the 2nd a back face, the 3rd a front face, ...
 *               A sample point counts as occluded inside a solid (behind a front face and in
 *               front of the back face that follows it); behind the last front face the ray
 *               knows, the "thickness" rule applies as with one layer, with that solid's own
 *               thickness where a pixel nearby sees it whole (docs/variants.md, "Measured
 *               thickness of hidden solids"). Variants that read the
 *               layers: "hemisphere" and "horizon" (docs/variants.md); the others ignore them.
 * All images of a job must have the depth image's width and height, unless an output window
 * is set (ssao_job_set_output_window). */
SSAO_API ssao_status ssao_job_set_image(ssao_job job, const char* name, float* data, int width,
                                        int height, int channels, ptrdiff_t pixel_stride,
                                        ptrdiff_t row_stride);
/* Overscan: the depth, normal and extra layer images extend beyond the frame (a guard band rendered
 * with the same camera on the same pixel grid), and the frame is the window of the outputs' size
 * whose top-left pixel is pixel (x, y) of the depth image. "beauty", "edge_colours", "ambient",
 * "ao" and "composite" then have the window's size (all the same), the window must lie inside the
 * depth image, and the camera parameters describe the window (the frame as rendered without the
 * band). The AO of the window is computed from every pixel of the depth image: it equals a run on
 * the whole depth image with the camera widened to it, cropped. Call with enable = 0 to go back to
 * the default: every image of the depth image's size. */
SSAO_API ssao_status ssao_job_set_output_window(ssao_job job, int enable, int x, int y);
/* Sets (or, with fn == NULL, clears) the progress callback. */
SSAO_API ssao_status ssao_job_set_progress(ssao_job job, ssao_progress_fn fn, void* user);
/* The automatic radius (scene units) for the attached depth image and the job's camera
 * parameters, depth_kind, background_depth and clip_end: 10% of the view's extent along the
 * image's larger side at the median depth of the geometry pixels (orthographic: 10% of that
 * extent). It does not set "radius". SSAO_ERROR_INVALID_OPERATION without a depth image or
 * when no pixel has geometry. Calibration: docs/parameters.md. */
SSAO_API ssao_status ssao_job_auto_radius(ssao_job job, double* out);
/* Computes AO and writes the attached outputs. A 0 x 0 image is valid and does nothing. */
SSAO_API ssao_status ssao_job_run(ssao_job job);
/* What the last successful ssao_job_run() of this job saw over the frame (the output window, or
 * the whole image without one): how many pixels the background rule above took as geometry,
 * and the mean of their final AO (after strength, power and remap: what "ao" holds; 1 when
 * there is no geometry pixel). Front ends report these instead of testing depths themselves.
 * SSAO_ERROR_INVALID_OPERATION when the job has not run, or its last run failed. */
SSAO_API ssao_status ssao_job_last_run(ssao_job job, size_t* geometry_pixels, double* mean_ao);

/* The front ends' rules, in one place: the CLI, the POV-Ray bridge, the Python module and the
 * Blender add-on call these rather than writing them again. */

/* Sets the camera from the text of a camera file, `length` bytes of JSON (docs/conventions.md,
 * "Camera file":
 * Blender's camera property names, or another renderer's intrinsics or projection matrix). The
 * one reader of the format: it checks every rule (the keys the projection needs, the types of
 * the values, finite numbers, positive sizes, matrix shapes, the library's ranges) and sets the
 * camera parameters the file holds; the job's other camera parameters go back to their defaults
 * (the file describes the whole camera: set overrides after it). On an error nothing is set
 * and ssao_last_error() names `source` (NULL: "camera") and the key. The file's "ao_distance"
 * is remembered for ssao_job_choose_radius(); keys the format does not know are ignored and
 * listed by ssao_job_camera_unknown_keys(). */
SSAO_API ssao_status ssao_job_set_camera_json(ssao_job job, const char* json_text, size_t length,
                                              const char* source);
/* The keys of the last camera file that the format does not know, comma-separated ("" for none),
 * truncated to size - 1 characters as ssao_job_get_string truncates. */
SSAO_API ssao_status ssao_job_camera_unknown_keys(ssao_job job, char* out, size_t size);
/* 1 in *out if a set call or a camera file gave the parameter its value on this job, else 0 (it
 * holds the default). */
SSAO_API ssao_status ssao_job_is_set(ssao_job job, const char* name, int* out);

/* Where ssao_job_choose_radius() took the radius from. */
typedef enum {
  SSAO_RADIUS_SET = 0,         /* "radius" was set on the job: kept */
  SSAO_RADIUS_CAMERA_FILE = 1, /* the camera file's "ao_distance" */
  SSAO_RADIUS_AUTOMATIC = 2    /* ssao_job_auto_radius() */
} ssao_radius_source;
/* The radius rule when the user gave none: a radius set on the job stays; else the camera
 * file's "ao_distance"; else, if allow_automatic is non-zero, the automatic radius (which needs
 * the depth image, and fails as ssao_job_auto_radius() fails when no pixel has geometry). Sets
 * "radius" (as chosen, not set: a later call, after a new camera file or depth, chooses again)
 * and writes it to *radius and the rule to *source (either may be NULL). With allow_automatic = 0
 * and neither: SSAO_ERROR_INVALID_OPERATION (a sequence wants one radius for every frame, which the
 * automatic rule does not give). */
SSAO_API ssao_status ssao_job_choose_radius(ssao_job job, int allow_automatic, double* radius,
                                            ssao_radius_source* source);
/* Checks the inputs for what a run would take without a word and get wrong: world-space normals
 * (a "normal" image with normal_space "world") without the camera's matrix (camera_to_world,
 * or a camera file's "matrix_world"), which its identity default would turn wrong. Call it before
 * ssao_job_run(), after the images and parameters: SSAO_OK, or SSAO_ERROR_INVALID_ARGUMENT with
 * the message. (ssao_job_run() does not call it: a caller may mean the identity.) */
SSAO_API ssao_status ssao_job_check_inputs(ssao_job job);

#ifdef __cplusplus
}
#endif

#endif /* SSAO_SSAO_H */
