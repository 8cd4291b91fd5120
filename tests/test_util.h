// SPDX-License-Identifier: Apache-2.0
/* tests/test_util.h: helpers every umbra test shares: a context on the CPU (PoCL), a scratch
 * directory, and message checks. */
#ifndef UMBRA_TEST_UTIL_H
#define UMBRA_TEST_UTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "umbra/io.h"

/* A context on PoCL's CPU device (or $UMBRA_DEVICE); fails the test if none can be made. The
 * PoCL cache goes to the build tree when ctest sets POCL_CACHE_DIR. */
umbra_context test_context(void);

/* Group setup and teardown for cmocka_run_group_tests: a test_context() in *state, released at
 * the end. */
int test_group_setup(void **state);
int test_group_teardown(void **state);

/* A fresh mkdtemp directory for this process, removed at exit. */
const char *test_tmpdir(void);

/* Nonzero if the context's last error message contains needle. */
int test_message_contains(umbra_context ctx, const char *needle);

/* A call failed with status expected and a message containing needle (and needle2 if not NULL);
 * the sticky error held that status, and the context still creates a small volume. */
void test_assert_failed(umbra_context ctx, umbra_status got, umbra_status expected,
                        const char *needle, const char *needle2);

/* Length of the part of the segment p + t dir, t in [0, t_max], inside the box [-half, half], in
 * double precision (dir unit): the analytic path for exp(-sigma d) checks. */
double test_path_in_box(const double p[3], const double dir[3], const double half[3],
                        double t_max);

/* A volume's normalised voxels read back from the device (malloc'ed; the caller frees them). */
float *test_read_voxels(umbra_volume vol);

/* vol has dims, spacing, value range [lo, hi] and voxels (want[i] - lo) / (hi - lo) to 1e-6. */
void test_assert_volume(umbra_volume vol, const uint32_t dims[3], const float spacing[3],
                        const double *want, double lo, double hi);

/* buf (size bytes) = test_tmpdir()/name; fails the test if it does not fit. Returns buf. */
const char *test_tmp_path(char *buf, size_t size, const char *name);
/* Writes size bytes (or a string) to path, failing the test on any error. */
void test_write_bytes(const char *path, const void *data, size_t size);
void test_write_text(const char *path, const char *text);
/* Reads a whole non-empty file into a malloc'ed buffer (the caller frees it). */
void *test_read_bytes(const char *path, size_t *size);

/* A float32 volume of nx x ny x nz voxels (x fastest) copied from data, unit spacing, value
 * range [0, 1]. */
umbra_volume test_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                         const float *data);

/* A float32 volume of dims filled with value, value range [0, 1]. */
umbra_volume test_constant_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                  float value);

/* A white directional light travelling along (x, y, z). */
umbra_light test_directional_light(float x, float y, float z);

/* A white point light at (x, y, z). */
umbra_light test_point_light(float x, float y, float z);

/* A renderer on volume and tf lit by light, with the camera and options given (umbra's defaults
 * where NULL); every step asserted. */
umbra_renderer test_renderer(umbra_context ctx, umbra_volume volume, umbra_transfer_function tf,
                             const umbra_camera *camera, const umbra_light *light,
                             const umbra_render_desc *options);

/* test_renderer without a camera, with default options but the given transmission. */
umbra_renderer test_renderer_transmission(umbra_context ctx, umbra_volume volume,
                                          umbra_transfer_function tf, umbra_light light,
                                          umbra_transmission transmission);

/* A float32 volume as test_volume with the given brick edge (0: umbra's default). */
umbra_volume test_volume_bricks(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                const float *data, uint32_t brick_size);

/* A grey transfer function with constant alpha (per voxel) everywhere. */
umbra_transfer_function test_constant_tf(umbra_context ctx, float grey, float alpha);

/* Runs umbra-render (./umbra-render in ctest's working directory, or $UMBRA_RENDER) with
 * --volume volume --tf "Cool to Warm" (an installed preset, by name) --technique cssm at 48x48
 * into test_tmpdir()/out_name, and asserts exit 0, the default background in a corner and the
 * lit volume (not the background) in the centre. */
void test_cli_renders_with_named_preset(umbra_context ctx, const char *volume,
                                        const char *out_name);

/* A w x h render of r into a new image (free it), failing the test with the context's message
 * where the render fails. */
float *test_render_image(umbra_renderer r, uint32_t w, uint32_t h);

/* The largest |a[i] - b[i]| over n floats, and their mean into *mean where mean is not NULL. */
float test_max_diff(const float *a, const float *b, size_t n, double *mean);

#endif
