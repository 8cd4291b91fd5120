// SPDX-License-Identifier: Apache-2.0
/* tests/test_hardening.c: inputs that used to hang the renderer or give a wrong image with
 * success (issue 11), each pinned down by the case that showed it:
 *
 *  - rows 3/4: an anisotropic volume (spacing 1 1 1e6, or 1e10) whose rays would take millions
 *    of samples (minutes) or overflow the kernels' int sample count (a background-only image)
 *    is refused before any work, for view, shadow and light rays, and the renderer still works;
 *  - row 5: a light direction or camera vector whose squared length overflows a float works as
 *    its unit vector; points beyond UMBRA_MAX_COORDINATE are refused;
 *  - row 6: a float volume holding +-3e38 maps its values (not all to 0), and a constant volume
 *    above 2^24 gets a non-empty value range;
 *  - row 7: a volume whose world extent is beyond UMBRA_MAX_EXTENT (or infinite) is refused at
 *    creation, from the API and from a NRRD file, naming the extent;
 *  - a float volume holding NaN or infinity is refused naming the first such voxel (index, x, y,
 *    z and value) whether the value range is given or computed (with a given range the voxels
 *    used to go unscanned, and NaN reached the device as 0).
 *
 * Usage: test_hardening [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

enum { W = 32, H = 32 };

static umbra_volume aniso_volume(umbra_context ctx, float sz, umbra_status *st)
{
    float data[16 * 16 * 16];
    for (int i = 0; i < 16 * 16 * 16; ++i)
        data[i] = 0.5f;
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = 16;
    d.spacing[2] = sz;
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    umbra_volume v = NULL;
    *st = umbra_volume_create(ctx, &d, &v);
    return v;
}

static int any_nan(const float *rgba, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (isnan(rgba[i]))
            return 1;
    return 0;
}

/* The renderer still renders a plain volume after a refusal. */
static void assert_renders(umbra_context ctx, umbra_renderer r, umbra_transfer_function tf)
{
    umbra_volume ok = test_constant_volume(ctx, 8, 8, 8, 0.5f);
    float *rgba = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(rgba);
    assert_int_equal(umbra_renderer_set_volume(r, ok), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, rgba), UMBRA_SUCCESS);
    assert_false(any_nan(rgba, 4 * W * H));
    umbra_volume_release(ok);
    free(rgba);
}

/* ---- rows 3 and 4: samples per ray -------------------------------------------------------- */

static void refuse_aniso_render(umbra_context ctx, float sz)
{
    umbra_status st;
    umbra_volume v = aniso_volume(ctx, sz, &st);
    assert_int_equal(st, UMBRA_SUCCESS);
    /* Near-transparent: no early termination, no empty-space skipping. */
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 1e-6f);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    float *rgba = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(rgba);
    assert_int_equal(umbra_renderer_render(r, W, H, rgba), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "view ray"));
    assert_true(test_message_contains(ctx, "UMBRA_MAX_RAY_SAMPLES"));
    assert_true(test_message_contains(ctx, "1048576"));
    assert_renders(ctx, r, tf);
    free(rgba);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_spacing_1e6_view_rays_are_refused_not_run_for_minutes(void **state)
{
    refuse_aniso_render(*state, 1e6f);
}

static void test_spacing_1e10_sample_count_does_not_overflow_into_a_blank_image(void **state)
{
    refuse_aniso_render(*state, 1e10f);
}

/* The view step is fine (64 voxels) but the shadow or light step (0.01) is not. */
static void refuse_light_step(umbra_context ctx, umbra_shadow_technique technique,
                              const char *what)
{
    umbra_status st;
    umbra_volume v = aniso_volume(ctx, 1e4f, &st);
    assert_int_equal(st, UMBRA_SUCCESS);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 1e-6f);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.step = 64.0f;
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = technique;
    s.reference.step = 0.01f;
    s.map.step = 0.01f;
    s.map.size = 16;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    float *rgba = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(rgba);
    assert_int_equal(umbra_renderer_render(r, W, H, rgba), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, what));
    assert_true(test_message_contains(ctx, "UMBRA_MAX_RAY_SAMPLES"));
    const float p[3] = {0.0f, 0.0f, 0.0f};
    float rgb[3];
    assert_int_equal(umbra_renderer_query_shadow(r, p, 1, rgb), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_renders(ctx, r, tf);
    free(rgba);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_reference_shadow_ray_samples_are_bounded(void **state)
{
    refuse_light_step(*state, UMBRA_SHADOW_REFERENCE, "shadow ray");
}

static void test_map_light_ray_samples_are_bounded(void **state)
{
    refuse_light_step(*state, UMBRA_SHADOW_THRESHOLD, "light ray");
    refuse_light_step(*state, UMBRA_SHADOW_DEEP, "light ray");
}

/* ---- row 5: vectors whose squared length overflows ---------------------------------------- */

static void render_with_light(umbra_context ctx, umbra_light light, float *rgba)
{
    umbra_volume v = test_constant_volume(ctx, 8, 8, 8, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.ground_plane = 1;
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, rgba), UMBRA_SUCCESS);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_light_direction_1e20_lights_as_its_unit_vector(void **state)
{
    umbra_context ctx = *state;
    float *big = malloc(sizeof(float) * 4 * W * H), *unit = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(big);
    assert_non_null(unit);
    render_with_light(ctx, test_directional_light(0.0f, -1e20f, 0.0f), big);
    render_with_light(ctx, test_directional_light(0.0f, -1.0f, 0.0f), unit);
    assert_false(any_nan(big, 4 * W * H));
    assert_memory_equal(big, unit, sizeof(float) * 4 * W * H);
    /* The smallest float too: its square underflows a float to 0. */
    render_with_light(ctx, test_directional_light(0.0f, -1e-45f, 0.0f), big);
    assert_memory_equal(big, unit, sizeof(float) * 4 * W * H);
    free(big);
    free(unit);
}

static void test_points_beyond_max_coordinate_are_refused(void **state)
{
    umbra_context ctx = *state;
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    umbra_light l = test_point_light(0.0f, 3e30f, 0.0f);
    assert_int_equal(umbra_renderer_set_light(r, &l), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "3e+30"));
    l = test_point_light(0.0f, 1e18f, 0.0f);
    assert_int_equal(umbra_renderer_set_light(r, &l), UMBRA_SUCCESS);

    umbra_camera c;
    memset(&c, 0, sizeof c);
    c.projection = UMBRA_PERSPECTIVE;
    c.fovy_degrees = 30.0f;
    c.eye[2] = -2e20f;
    c.up[1] = 1.0f;
    assert_int_equal(umbra_renderer_set_camera(r, &c), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "2e+20"));
    assert_true(test_message_contains(ctx, "1e+18"));
    umbra_renderer_release(r);
}

static void test_camera_up_1e30_frames_as_unit_up(void **state)
{
    umbra_context ctx = *state;
    float *big = malloc(sizeof(float) * 4 * W * H), *unit = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(big);
    assert_non_null(unit);
    umbra_volume v = test_constant_volume(ctx, 8, 8, 8, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    const float dir[3] = {0.6f, 0.45f, 1.0f};
    umbra_camera c = umbra_camera_orbit(dir, 14.0f, 30.0f);
    /* eye - target is about 26: its cross product with up = 1e30 overflows a float. */
    umbra_renderer r = test_renderer(ctx, v, tf, &c, &light, NULL);
    assert_int_equal(umbra_renderer_render(r, W, H, unit), UMBRA_SUCCESS);
    c.up[1] = 1e30f;
    assert_int_equal(umbra_renderer_set_camera(r, &c), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, big), UMBRA_SUCCESS);
    assert_false(any_nan(big, 4 * W * H));
    assert_memory_equal(big, unit, sizeof(float) * 4 * W * H);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
    free(big);
    free(unit);
}

/* ---- row 6: value ranges ------------------------------------------------------------------ */

static void test_float_volume_of_plus_minus_3e38_is_not_empty(void **state)
{
    umbra_context ctx = *state;
    enum { N = 8 };
    float data[N * N * N];
    for (int i = 0; i < N * N * N; ++i)
        data[i] = (i % N) < N / 2 ? -3e38f : 3e38f;
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = N;
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_true(info.value_min == -3e38f && info.value_max == 3e38f);
    /* Opaque at the top of the range only: the +3e38 half must show. */
    const float rgba[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    float *img = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(img);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    int opaque = 0;
    for (int i = 0; i < W * H; ++i)
        opaque += img[4 * i + 3] > 0.5f;
    print_message("%d of %d pixels opaque\n", opaque, W * H);
    assert_true(opaque > W * H / 8);
    free(img);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_constant_volume_above_2_24_has_a_value_range(void **state)
{
    umbra_context ctx = *state;
    const float values[] = {3e7f, -3e7f, 0.0f, 3.4e38f, -3.4e38f};
    for (size_t k = 0; k < sizeof values / sizeof values[0]; ++k) {
        float data[8];
        for (int i = 0; i < 8; ++i)
            data[i] = values[k];
        umbra_volume_desc d;
        umbra_volume_desc_init(&d);
        d.data = data;
        d.type = UMBRA_FLOAT32;
        d.dims[0] = d.dims[1] = d.dims[2] = 2;
        umbra_volume v = NULL;
        assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
        umbra_volume_info info;
        assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
        print_message("constant %g: range [%.9g, %.9g]\n", values[k], info.value_min,
                      info.value_max);
        assert_true(isfinite(info.value_min) && isfinite(info.value_max));
        assert_true(info.value_max > info.value_min);
        assert_true(info.value_min <= values[k] && values[k] <= info.value_max);
        umbra_volume_release(v);
    }
}

/* ---- row 7: world extent ------------------------------------------------------------------ */

static void test_volume_extent_beyond_limit_is_refused(void **state)
{
    umbra_context ctx = *state;
    umbra_status st;
    /* 16 x 3e37 is infinite in float. */
    umbra_volume v = aniso_volume(ctx, 3e37f, &st);
    assert_null(v);
    assert_int_equal(st, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "extent 4.8e+38"));
    assert_true(test_message_contains(ctx, "UMBRA_MAX_EXTENT"));
    v = aniso_volume(ctx, 1e20f, &st);
    assert_null(v);
    assert_int_equal(st, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "extent 1.6e+21"));
    /* At the limit it is accepted. */
    v = aniso_volume(ctx, 6e13f, &st);
    assert_int_equal(st, UMBRA_SUCCESS);
    umbra_volume_release(v);
}

static void test_nrrd_spacing_1e20_is_refused_at_load(void **state)
{
    umbra_context ctx = *state;
    char path[512];
    snprintf(path, sizeof path, "%s/spacing_1e20.nrrd", test_tmpdir());
    static const char header[] = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n"
                                 "spacings: 1 1 1e20\nencoding: raw\n\n";
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite(header, 1, sizeof header - 1, f);
    const unsigned char voxels[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    fwrite(voxels, 1, sizeof voxels, f);
    fclose(f);
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_load(ctx, path, &v), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_null(v);
    assert_true(test_message_contains(ctx, "extent 2e+20"));
    remove(path);
}

/* ---- non-finite voxels ------------------------------------------------------------------- */

static void test_non_finite_voxels_are_refused_with_or_without_a_range(void **state)
{
    umbra_context ctx = *state;
    const float bad[] = {NAN, INFINITY, -INFINITY};
    const char *names[] = {"nan", "inf", "-inf"};
    float data[4 * 3 * 2];
    for (size_t k = 0; k < 3; ++k)
        for (int given = 0; given <= 1; ++given) {
            for (int i = 0; i < 24; ++i)
                data[i] = 0.25f * (float)i;
            data[17] = bad[k]; /* x 1, y 1, z 1 of 4 x 3 x 2 */
            data[20] = bad[k]; /* a later one is not the one named */
            umbra_volume_desc d;
            umbra_volume_desc_init(&d);
            d.data = data;
            d.type = UMBRA_FLOAT32;
            d.dims[0] = 4;
            d.dims[1] = 3;
            d.dims[2] = 2;
            d.value_range_given = given;
            d.value_min = 0.0f;
            d.value_max = 1.0f;
            umbra_volume v = (umbra_volume)&d; /* must come back NULL */
            assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT);
            assert_null(v);
            char want[64];
            snprintf(want, sizeof want, "voxel 17 is %s (x 1, y 1, z 1)", names[k]);
            print_message("range %s: %s\n", given ? "given" : "computed",
                          umbra_context_last_message(ctx));
            assert_true(test_message_contains(ctx, want));
            umbra_context_take_error(ctx, NULL);
            /* The context stays usable, and the same data made finite is accepted. */
            data[17] = data[20] = 0.5f;
            assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
            umbra_volume_release(v);
        }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spacing_1e6_view_rays_are_refused_not_run_for_minutes),
        cmocka_unit_test(test_spacing_1e10_sample_count_does_not_overflow_into_a_blank_image),
        cmocka_unit_test(test_reference_shadow_ray_samples_are_bounded),
        cmocka_unit_test(test_map_light_ray_samples_are_bounded),
        cmocka_unit_test(test_light_direction_1e20_lights_as_its_unit_vector),
        cmocka_unit_test(test_points_beyond_max_coordinate_are_refused),
        cmocka_unit_test(test_camera_up_1e30_frames_as_unit_up),
        cmocka_unit_test(test_float_volume_of_plus_minus_3e38_is_not_empty),
        cmocka_unit_test(test_constant_volume_above_2_24_has_a_value_range),
        cmocka_unit_test(test_volume_extent_beyond_limit_is_refused),
        cmocka_unit_test(test_nrrd_spacing_1e20_is_refused_at_load),
        cmocka_unit_test(test_non_finite_voxels_are_refused_with_or_without_a_range),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
