// SPDX-License-Identifier: Apache-2.0
/* tests/test_gradient_volume.c: the ray caster's gradient volume (kernels/common/sampling.cl,
 * gradient_volume_entry; host/gradient_volume.c), pinned down.
 *
 *  - a shaded frame from the gradient volume equals, bit for bit, the same frame shaded from the
 *    32-voxel stencil (the gradient volume refused by a lowered allocation limit), on uint8 and
 *    uint16 volumes with anisotropic spacing, jitter and rays reaching the box's faces and
 *    corners, where the stencil repeats the border voxels;
 *  - it is made only for shaded frames of volumes it is exact for: released for an unshaded
 *    frame, not made for float voxels or 16-bit voxels spanning more than 32767;
 *  - after a volume update the gradients are made again: the frame equals the stencil's of the
 *    updated voxels and differs from the frame before.
 *
 * Usage: test_gradient_volume [filter] (a cmocka test-name glob). */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "test_util.h"

enum { GV_W = 72, GV_H = 64 };

/* A smooth pattern with noise and a flat run (zero gradients), x fastest, in [0, 1]. */
static double pattern(uint32_t x, uint32_t y, uint32_t z, uint32_t *seed, const uint32_t d[3])
{
    *seed = *seed * 1664525u + 1013904223u;
    const double noise = (double)(*seed >> 8) / 16777216.0 - 0.5;
    double v = 0.5 + 0.3 * sin(0.45 * x) * cos(0.35 * y + 0.2 * z) + 0.15 * noise;
    if (x > d[0] / 2 && y < d[1] / 3)
        v = 0.6;
    return v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
}

/* A volume of type t (uint8, uint16 or float32) whose values span [0, top], the range given. */
static umbra_volume make_volume(umbra_context ctx, umbra_scalar_type t, double top,
                                uint32_t phase)
{
    const uint32_t d[3] = {21, 18, 26};
    const size_t n = (size_t)d[0] * d[1] * d[2];
    void *data = malloc(n * 4);
    assert_non_null(data);
    uint32_t seed = 777u + phase;
    size_t i = 0;
    for (uint32_t z = 0; z < d[2]; ++z)
        for (uint32_t y = 0; y < d[1]; ++y)
            for (uint32_t x = 0; x < d[0]; ++x, ++i) {
                const double v = pattern(x + phase, y, z, &seed, d) * top;
                if (t == UMBRA_UINT8)
                    ((uint8_t *)data)[i] = (uint8_t)lrint(v);
                else if (t == UMBRA_UINT16)
                    ((uint16_t *)data)[i] = (uint16_t)lrint(v);
                else
                    ((float *)data)[i] = (float)v;
            }
    umbra_volume_desc desc;
    umbra_volume_desc_init(&desc);
    desc.data = data;
    desc.type = t;
    memcpy(desc.dims, d, sizeof d);
    desc.spacing[0] = 1.0f;
    desc.spacing[1] = 0.8f;
    desc.spacing[2] = 1.25f;
    desc.value_range_given = 1;
    desc.value_min = 0.0f;
    desc.value_max = (float)top;
    desc.brick_size = 8;
    umbra_volume v = NULL;
    const umbra_status st = umbra_volume_create(ctx, &desc, &v);
    free(data);
    assert_int_equal(st, UMBRA_SUCCESS);
    return v;
}

/* A shaded renderer of v: jittered, a camera close enough that rays enter through faces and
 * corners of the box, a ramp transfer function with a transparent low end. */
static umbra_renderer make_renderer(umbra_context ctx, umbra_volume v, umbra_transfer_function *tf,
                                    umbra_render_desc *opts)
{
    static const umbra_tf_point ramp[] = {{0.0f, {0.2f, 0.5f, 0.9f, 0.0f}},
                                          {0.4f, {0.2f, 0.5f, 0.9f, 0.0f}},
                                          {0.6f, {0.9f, 0.6f, 0.3f, 0.3f}},
                                          {1.0f, {1.0f, 1.0f, 1.0f, 0.9f}}};
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, ramp, 4, 256, tf),
                     UMBRA_SUCCESS);
    const float dir[3] = {1.3f, 0.9f, 1.6f};
    const umbra_camera cam = umbra_camera_orbit(dir, 30.0f, 60.0f);
    const umbra_light light = test_directional_light(-0.3f, -1.0f, -0.5f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    o.ks = 0.6f;
    o.shininess = 32.0f;
    o.jitter = 1;
    o.seed = 5u;
    umbra_renderer r = test_renderer(ctx, v, *tf, &cam, &light, &o);
    if (opts)
        *opts = o;
    umbra_shadow_desc sh;
    umbra_shadow_desc_init(&sh);
    sh.technique = UMBRA_SHADOW_NONE;
    assert_int_equal(umbra_renderer_set_shadow(r, &sh), UMBRA_SUCCESS);
    return r;
}

static void render(umbra_renderer r, float *rgba)
{
    assert_int_equal(umbra_renderer_render(r, GV_W, GV_H, rgba), UMBRA_SUCCESS);
}

/* r's frame from the stencil: the allocation limit set below the gradient volume's size. */
static void render_stencil(umbra_context ctx, umbra_renderer r, float *rgba)
{
    umbra__context_limit_alloc(ctx, 4096);
    render(r, rgba);
    assert_null(r->grad_buf);
    umbra__context_limit_alloc(ctx, 0);
}

static void check_same(const float *a, const float *b, const char *what)
{
    const size_t n = (size_t)GV_W * GV_H * 4;
    size_t differ = 0, at = 0;
    double lit = 0.0;
    for (size_t k = 0; k < n; ++k) {
        if (memcmp(&a[k], &b[k], sizeof a[k]) != 0 && differ++ == 0)
            at = k;
        if (k % 4 == 0)
            lit = fmax(lit, a[k]);
    }
    print_message("  %-28s: %zu of %zu values differ, brightest red %.2f\n", what, differ, n, lit);
    assert_true(lit > 0.2); /* lit and shaded, or the comparison says nothing */
    if (differ)
        fail_msg("%s: value %zu: gradient volume %.9g, stencil %.9g", what, at, a[at], b[at]);
}

static void test_same_bits_as_stencil(void **state)
{
    umbra_context ctx = *state;
    float *a = malloc((size_t)GV_W * GV_H * 4 * sizeof *a);
    float *b = malloc((size_t)GV_W * GV_H * 4 * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    const struct {
        umbra_scalar_type t;
        double top;
        const char *name;
    } cases[] = {{UMBRA_UINT8, 255.0, "uint8"}, {UMBRA_UINT16, 32767.0, "uint16 spanning 32767"},
                 {UMBRA_UINT16, 1000.0, "uint16 spanning 1000"}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        umbra_volume v = make_volume(ctx, cases[c].t, cases[c].top, 0);
        umbra_transfer_function tf;
        umbra_render_desc o;
        umbra_renderer r = make_renderer(ctx, v, &tf, &o);
        render(r, a);
        assert_non_null(r->grad_buf);
        render_stencil(ctx, r, b);
        check_same(a, b, cases[c].name);
        /* unshaded: released; shaded again: made again, the same frame */
        o.shading = 0;
        assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
        render(r, b);
        assert_null(r->grad_buf);
        o.shading = 1;
        assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
        render(r, b);
        assert_non_null(r->grad_buf);
        check_same(b, a, "shaded after unshaded");
        umbra_renderer_release(r);
        umbra_transfer_function_release(tf);
        umbra_volume_release(v);
    }
    free(a);
    free(b);
}

static void test_made_only_where_exact(void **state)
{
    umbra_context ctx = *state;
    float *a = malloc((size_t)GV_W * GV_H * 4 * sizeof *a);
    assert_non_null(a);
    const struct {
        umbra_scalar_type t;
        double top;
    } cases[] = {{UMBRA_FLOAT32, 1.0}, {UMBRA_UINT16, 40000.0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        umbra_volume v = make_volume(ctx, cases[c].t, cases[c].top, 0);
        umbra_transfer_function tf;
        umbra_renderer r = make_renderer(ctx, v, &tf, NULL);
        render(r, a);
        assert_null(r->grad_buf);
        umbra_renderer_release(r);
        umbra_transfer_function_release(tf);
        umbra_volume_release(v);
    }
    free(a);
}

static void test_remade_after_update(void **state)
{
    umbra_context ctx = *state;
    const size_t n = (size_t)GV_W * GV_H * 4;
    float *before = malloc(n * sizeof *before), *a = malloc(n * sizeof *a);
    float *b = malloc(n * sizeof *b);
    assert_non_null(before);
    assert_non_null(a);
    assert_non_null(b);
    umbra_volume v = make_volume(ctx, UMBRA_UINT8, 255.0, 0);
    umbra_transfer_function tf;
    umbra_renderer r = make_renderer(ctx, v, &tf, NULL);
    render(r, before);
    /* the whole volume again, shifted by 3 voxels along x */
    umbra_volume other = make_volume(ctx, UMBRA_UINT8, 255.0, 3);
    uint8_t *voxels = malloc((size_t)21 * 18 * 26);
    assert_non_null(voxels);
    uint32_t seed = 777u + 3u;
    const uint32_t d[3] = {21, 18, 26};
    size_t i = 0;
    for (uint32_t z = 0; z < d[2]; ++z)
        for (uint32_t y = 0; y < d[1]; ++y)
            for (uint32_t x = 0; x < d[0]; ++x, ++i)
                voxels[i] = (uint8_t)lrint(pattern(x + 3u, y, z, &seed, d) * 255.0);
    umbra_volume_update_desc u;
    umbra_volume_update_desc_init(&u);
    u.data = voxels;
    assert_int_equal(umbra_volume_update(v, &u), UMBRA_SUCCESS);
    free(voxels);
    render(r, a);
    assert_non_null(r->grad_buf);
    render_stencil(ctx, r, b);
    check_same(a, b, "after an update");
    assert_true(memcmp(a, before, n * sizeof *a) != 0);
    /* and it is the frame of a volume made from the updated voxels */
    umbra_transfer_function tf2;
    umbra_renderer r2 = make_renderer(ctx, other, &tf2, NULL);
    render(r2, b);
    check_same(a, b, "a fresh volume of them");
    umbra_renderer_release(r2);
    umbra_transfer_function_release(tf2);
    umbra_volume_release(other);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
    free(before);
    free(a);
    free(b);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_bits_as_stencil),
        cmocka_unit_test(test_made_only_where_exact),
        cmocka_unit_test(test_remade_after_update),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
