// SPDX-License-Identifier: Apache-2.0
/* tests/test_util.c: see test_util.h. */
#define _POSIX_C_SOURCE 200809L
#include "renderer_internal.h" /* test_read_voxels reads the volume's device copy;
                                 test_render_image the renderer's context */
#include "conformance.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

umbra_context test_context(void)
{
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    if (!getenv("UMBRA_DEVICE"))
        d.device_name = "pthread"; /* PoCL's CPU device: the tests' target */
    umbra_context ctx = NULL;
    if (umbra_context_create(&d, &ctx) != UMBRA_SUCCESS) {
        umbra_context_desc_init(&d);
        if (umbra_context_create(&d, &ctx) != UMBRA_SUCCESS)
            fail_msg("test_context: no OpenCL device (is pocl-opencl-icd installed?)");
    }
    return ctx;
}

static char tmpdir[256];

static void remove_tmpdir(void)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "test_util: could not remove %s\n", tmpdir);
}

const char *test_tmpdir(void)
{
    if (!tmpdir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(tmpdir, sizeof tmpdir, "%s/umbra-test-XXXXXX", base && *base ? base : "/tmp");
        if (!mkdtemp(tmpdir))
            fail_msg("test_tmpdir: mkdtemp(%s) failed", tmpdir);
        atexit(remove_tmpdir);
    }
    return tmpdir;
}

void test_assert_failed(umbra_context ctx, umbra_status got, umbra_status expected,
                        const char *needle, const char *needle2)
{
    static const uint8_t voxels[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    umbra_volume_desc desc;
    umbra_volume vol = NULL;
    if (got != expected || !test_message_contains(ctx, needle) ||
        (needle2 && !test_message_contains(ctx, needle2))) {
        print_message("got %s, expected %s; message \"%s\"; looked for \"%s\" and \"%s\"\n",
                      umbra_status_to_string(got), umbra_status_to_string(expected),
                      umbra_context_last_message(ctx), needle, needle2 ? needle2 : "");
    }
    assert_int_equal(got, expected);
    assert_true(test_message_contains(ctx, needle));
    if (needle2)
        assert_true(test_message_contains(ctx, needle2));
    assert_int_equal(umbra_context_take_error(ctx, NULL), expected);
    umbra_volume_desc_init(&desc);
    desc.data = voxels;
    desc.type = UMBRA_UINT8;
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    assert_int_equal(umbra_volume_create(ctx, &desc, &vol), UMBRA_SUCCESS);
    assert_non_null(vol);
    umbra_volume_release(vol);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_SUCCESS);
}

double test_path_in_box(const double p[3], const double dir[3], const double half[3],
                        double t_max)
{
    return conf_path_in_box(p, dir, half, t_max);
}

float *test_read_voxels(umbra_volume vol)
{
    const size_t count = (size_t)vol->dims[0] * vol->dims[1] * vol->dims[2];
    float *out = malloc(count * sizeof *out);
    assert_non_null(out);
    assert_int_equal(umbra__volume_read_normalised(vol, out), UMBRA_SUCCESS);
    return out;
}

void test_assert_volume(umbra_volume vol, const uint32_t dims[3], const float spacing[3],
                        const double *want, double lo, double hi)
{
    umbra_volume_info info;
    size_t count = (size_t)dims[0] * dims[1] * dims[2], i;
    float *vox;
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    for (i = 0; i < 3; ++i) {
        assert_int_equal(info.dims[i], dims[i]);
        assert_float_equal(info.spacing[i], spacing[i], 1e-6);
    }
    assert_float_equal(info.value_min, lo, 1e-3);
    assert_float_equal(info.value_max, hi, 1e-3);
    vox = test_read_voxels(vol);
    for (i = 0; i < count; ++i) {
        double w = (want[i] - lo) / (hi - lo);
        if (fabs(vox[i] - w) > 1e-6) {
            print_message("voxel %zu: %.9g, expected %.9g\n", i, (double)vox[i], w);
        }
        assert_float_equal(vox[i], w, 1e-6);
    }
    free(vox);
}

const char *test_tmp_path(char *buf, size_t size, const char *name)
{
    int n = snprintf(buf, size, "%s/%s", test_tmpdir(), name);
    assert_true(n > 0 && (size_t)n < size);
    return buf;
}

void test_write_bytes(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    assert_int_equal(fclose(f), 0);
}

void test_write_text(const char *path, const char *text)
{
    test_write_bytes(path, text, strlen(text));
}

void *test_read_bytes(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    long n;
    void *buf;
    assert_non_null(f);
    assert_int_equal(fseek(f, 0, SEEK_END), 0);
    n = ftell(f);
    assert_true(n > 0);
    rewind(f);
    buf = malloc((size_t)n);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *size = (size_t)n;
    return buf;
}

int test_message_contains(umbra_context ctx, const char *needle)
{
    const char *m = umbra_context_last_message(ctx);
    if (!strstr(m, needle)) {
        print_message("message '%s' lacks '%s'\n", m, needle);
        return 0;
    }
    return 1;
}

int test_group_setup(void **state)
{
    *state = test_context();
    return *state ? 0 : -1;
}

int test_group_teardown(void **state)
{
    umbra_context_release(*state);
    return 0;
}

umbra_volume test_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                         const float *data)
{
    return test_volume_bricks(ctx, nx, ny, nz, data, 0);
}

umbra_volume test_volume_bricks(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                const float *data, uint32_t brick_size)
{
    umbra_volume v = NULL;
    assert_int_equal(conf_volume_of(ctx, nx, ny, nz, data, brick_size, &v), UMBRA_SUCCESS);
    return v;
}

umbra_volume test_constant_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                  float value)
{
    size_t n = (size_t)nx * ny * nz;
    float *data = malloc(n * sizeof *data);
    assert_non_null(data);
    for (size_t i = 0; i < n; ++i)
        data[i] = value;
    umbra_volume v = test_volume(ctx, nx, ny, nz, data);
    free(data);
    return v;
}

umbra_renderer test_renderer(umbra_context ctx, umbra_volume volume, umbra_transfer_function tf,
                             const umbra_camera *camera, const umbra_light *light,
                             const umbra_render_desc *options)
{
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_volume(r, volume), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf), UMBRA_SUCCESS);
    if (camera)
        assert_int_equal(umbra_renderer_set_camera(r, camera), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_light(r, light), UMBRA_SUCCESS);
    if (options)
        assert_int_equal(umbra_renderer_set_options(r, options), UMBRA_SUCCESS);
    return r;
}

umbra_renderer test_renderer_transmission(umbra_context ctx, umbra_volume volume,
                                          umbra_transfer_function tf, umbra_light light,
                                          umbra_transmission transmission)
{
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = transmission;
    return test_renderer(ctx, volume, tf, NULL, &light, &o);
}

umbra_light test_directional_light(float x, float y, float z)
{
    return conf_directional(x, y, z);
}

umbra_light test_point_light(float x, float y, float z)
{
    return conf_point(x, y, z);
}

umbra_transfer_function test_constant_tf(umbra_context ctx, float grey, float alpha)
{
    float rgba[8] = {grey, grey, grey, alpha, grey, grey, grey, alpha};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    return tf;
}

void test_cli_renders_with_named_preset(umbra_context ctx, const char *volume,
                                        const char *out_name)
{
    const char *exe = getenv("UMBRA_RENDER") ? getenv("UMBRA_RENDER") : "./umbra-render";
    char out[1024], cmd[4096];
    uint32_t w = 0, h = 0;
    float *rgba = NULL;
    test_tmp_path(out, sizeof out, out_name);
    assert_int_equal(access(exe, X_OK), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' --volume '%s' --tf 'Cool to Warm' --technique cssm --size 48x48 --no-ground "
             "--out '%s' 2>/dev/null",
             exe, volume, out);
    assert_int_equal(system(cmd), 0);
    assert_int_equal(umbra_image_read(ctx, out, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 48);
    {
        const float *centre = rgba + 4 * (24 * 48 + 24), *corner = rgba;
        print_message("centre %g %g %g, corner %g %g %g\n", (double)centre[0],
                      (double)centre[1], (double)centre[2], (double)corner[0], (double)corner[1],
                      (double)corner[2]);
        assert_float_equal(corner[0], 0.08, 0.01);
        assert_true(fabsf(centre[0] - corner[0]) + fabsf(centre[2] - corner[2]) > 0.05f);
    }
    free(rgba);
}

float *test_render_image(umbra_renderer r, uint32_t w, uint32_t h)
{
    float *img = malloc((size_t)w * h * 4 * sizeof *img);
    assert_non_null(img);
    if (umbra_renderer_render(r, w, h, img) != UMBRA_SUCCESS)
        fail_msg("render: %s", umbra_context_last_message(r->ctx));
    return img;
}

float test_max_diff(const float *a, const float *b, size_t n, double *mean)
{
    float m = 0.0f;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const float e = fabsf(a[i] - b[i]);
        m = e > m ? e : m;
        sum += e;
    }
    if (mean)
        *mean = sum / (double)n;
    return m;
}
