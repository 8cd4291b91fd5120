// SPDX-License-Identifier: Apache-2.0
/* tests/test_threshold.c: the opacity-threshold shadow map (kernels/techniques/threshold.cl) pinned
 * down:
 *  - homogeneous slab: along a light ray the factor flips from 1 to 0 at the analytic crossing
 *    d* = -ln(1 - threshold) / sigma (sigma = -ln(1 - alpha) per voxel) within one light step,
 *    for thresholds 0.2, 0.5, 0.8 and a vertical, an oblique and a point light; filtered lookups
 *    (7, 13, 21 taps) fall monotonically and pass 1/2 at the same depth;
 *  - the march's product of transparencies and its sum of optical depths (tiny steps, threshold
 *    near 1) both put the flip at the analytic crossing plus the bias, within 0.015 voxels;
 *  - a separate light transfer function drives the map (its alpha sets d*), and unsetting it
 *    returns to the view transfer function;
 *  - camera moves re-use the map; memory is map_size^2 * 4 bytes (one depth, grey or colour);
 *  - mean absolute error against the exact reference on the spheres scene within a stated bound.
 * The lights that stress the projection, the analytic slab's error bound, rebuilds and bad
 * parameters are the conformance suite's (tests/test_conformance.c).
 * Usage: test_threshold [filter] (a cmocka test-name glob). */
#include "shadow_map_test.h"

static umbra_context ctx;

static int setup(void **state)
{
    (void)state;
    ctx = test_context();
    return ctx ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    umbra_context_release(ctx);
    return 0;
}

/* Walks query points from `from` along unit direction dir in steps of ds up to length len and
 * returns the distance from `from` of the first point whose factor is at most 1/2, or -1 if there
 * is none. The factor must be grey, never rise along the ray, and with one tap be 0 or 1. With
 * several taps on a slab oblique to the light, neighbouring texels store depths shifted by the
 * slope, so the factor steps down over a few taps; the tap sets are point-symmetric about the
 * centre tap, which is therefore the median, and the factor reaches 1/2 where the centre tap
 * flips. */
static float flip_distance(umbra_renderer r, const float from[3], const float dir[3], float len,
                           float ds, int binary)
{
    size_t n = (size_t)(len / ds) + 1;
    float *p = malloc(n * 3 * sizeof *p), *f = malloc(n * 3 * sizeof *f);
    assert_non_null(p);
    assert_non_null(f);
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            p[3 * i + a] = from[a] + (float)i * ds * dir[a];
    assert_int_equal(umbra_renderer_query_shadow(r, p, n, f), UMBRA_SUCCESS);
    float flip = -1.0f;
    for (size_t i = 0; i < n; ++i) {
        float v = f[3 * i];
        if (!(v == f[3 * i + 1] && v == f[3 * i + 2]) || !(v >= 0.0f && v <= 1.0f) ||
            (binary && v != 0.0f && v != 1.0f) || (i > 0 && v > f[3 * i - 3]))
            fail_msg("factor %g at %g voxels along the ray (previous %g)", v, (float)i * ds,
                     i > 0 ? f[3 * i - 3] : 1.0f);
        if (flip < 0.0f && v <= 0.5f)
            flip = (float)i * ds;
    }
    free(p);
    free(f);
    return flip;
}

/* Entry point of the ray from the light through target into the slab box, and its direction. */
static void light_ray_into_box(const umbra_light *l, const float target[3], float entry[3],
                               float dir[3])
{
    const float half[3] = {0.5f * MT_NX, 0.5f * MT_NY, 0.5f * MT_NZ};
    float d[3], o[3];
    for (int a = 0; a < 3; ++a) {
        d[a] = l->type == UMBRA_LIGHT_POINT ? target[a] - l->position[a] : l->direction[a];
        o[a] = l->type == UMBRA_LIGHT_POINT ? l->position[a] : target[a] - 1000.0f * d[a];
    }
    float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    float t0 = -INFINITY;
    for (int a = 0; a < 3; ++a) {
        dir[a] = d[a] / len;
        if (dir[a] != 0.0f) {
            float ta = (-half[a] - o[a]) / dir[a], tb = (half[a] - o[a]) / dir[a];
            t0 = fmaxf(t0, fminf(ta, tb));
        }
    }
    for (int a = 0; a < 3; ++a)
        entry[a] = o[a] + t0 * dir[a];
}

static void test_threshold_slab_crossing_matches_analytic(void **state)
{
    (void)state;
    const float alpha = 0.08f, sigma = -logf(1.0f - alpha), step = 0.5f;
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, 0.7f, 0.7f, 0.7f, alpha);
    const umbra_light lights[] = {test_directional_light(0, -1, 0), test_directional_light(0.3f, -1, 0.2f),
                                  test_point_light(4, 70, -3)};
    const float thresholds[] = {0.2f, 0.5f, 0.8f};
    const float target[3] = {1.3f, 0.0f, -0.7f};
    for (size_t li = 0; li < 3; ++li) {
        umbra_renderer r = test_renderer_transmission(
            ctx, vol, tf, lights[li], UMBRA_TRANSMISSION_GREY);
        for (size_t ti = 0; ti < 3; ++ti) {
            umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_THRESHOLD, 256, 1);
            s.threshold.threshold = thresholds[ti];
            s.map.step = step;
            assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
            float entry[3], dir[3];
            light_ray_into_box(&lights[li], target, entry, dir);
            float expect = -logf(1.0f - thresholds[ti]) / sigma;
            float flip = flip_distance(r, entry, dir, 30.0f, 0.02f, 1);
            if (!(fabsf(flip - expect) <= step))
                fail_msg("light %zu, threshold %g: flips at %g voxels, analytic %g (+-%g)", li,
                         thresholds[ti], flip, expect, step);
            /* Filtered: the centre tap is the median of the point-symmetric tap set. */
            for (uint32_t taps = 7; taps <= 21; taps += taps == 7 ? 6 : 8) {
                s.threshold.taps = taps;
                assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
                float f2 = flip_distance(r, entry, dir, 30.0f, 0.02f, 0);
                if (!(fabsf(f2 - expect) <= step))
                    fail_msg("light %zu, threshold %g, %u taps: flips at %g, analytic %g", li,
                             thresholds[ti], taps, f2, expect);
            }
        }
        umbra_renderer_release(r);
    }
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

/* The march keeps the product of the segments' transparencies where the threshold's
 * transmittance over a step, p_thr = (1 - threshold)^(1 / step), stays above 1e-30, and sums
 * their optical depths below that (a float product would underflow): both find the analytic
 * crossing of a homogeneous slab lit straight down (every texel's ray enters the top face), so
 * the factor flips half a light step (the depth bias) behind it, to within the query spacing.
 * Cases: step 0.5 at 0.5 and 0.9 (products), step 0.05 at 0.9 (p_thr 1e-20, product), step 0.02
 * at 0.99 (p_thr 1e-100: the sum). */
static void test_threshold_product_and_sum_marches_exact(void **state)
{
    (void)state;
    const float alpha = 0.3f, sigma = -logf(1.0f - alpha), ds = 0.01f;
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, 0.7f, 0.7f, 0.7f, alpha);
    const umbra_light light = test_directional_light(0, -1, 0);
    const struct {
        float step, threshold;
    } cases[] = {{0.5f, 0.5f}, {0.5f, 0.9f}, {0.05f, 0.9f}, {0.02f, 0.99f}};
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, light, UMBRA_TRANSMISSION_GREY);
    const float target[3] = {1.3f, 0.0f, -0.7f};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_THRESHOLD, 64, 1);
        s.threshold.threshold = cases[i].threshold;
        s.map.step = cases[i].step;
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        float entry[3], dir[3];
        light_ray_into_box(&light, target, entry, dir);
        float expect = -logf(1.0f - cases[i].threshold) / sigma + 0.5f * cases[i].step;
        float flip = flip_distance(r, entry, dir, 30.0f, ds, 1);
        if (!(fabsf(flip - expect) <= 1.5f * ds))
            fail_msg("step %g, threshold %g: flips at %g voxels, expected %g (+-%g)",
                     cases[i].step, cases[i].threshold, flip, expect, 1.5f * ds);
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_threshold_light_transfer_function_drives_map(void **state)
{
    (void)state;
    const float a_view = 0.02f, a_light = 0.1f, step = 0.5f;
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function view = mt_tf(ctx, 0.7f, 0.7f, 0.7f, a_view);
    umbra_transfer_function light = mt_tf(ctx, 0.2f, 0.2f, 0.2f, a_light);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, view, l, UMBRA_TRANSMISSION_GREY);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_THRESHOLD, 128, 1);
    s.map.step = step; /* the bound below is this light step */
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    const float top[3] = {0.4f, 0.5f * MT_NY, 0.3f}, down[3] = {0, -1, 0};
    float flip = flip_distance(r, top, down, 31.0f, 0.02f, 1);
    float expect = -logf(0.5f) / -logf(1.0f - a_view); /* 34.3: below the slab */
    assert_true(flip < 0.0f && expect > (float)MT_NY);

    assert_int_equal(umbra_renderer_set_light_transfer_function(r, light), UMBRA_SUCCESS);
    flip = flip_distance(r, top, down, 31.0f, 0.02f, 1);
    expect = -logf(0.5f) / -logf(1.0f - a_light);
    if (!(fabsf(flip - expect) <= step))
        fail_msg("light transfer function: flips at %g, analytic %g", flip, expect);

    assert_int_equal(umbra_renderer_set_light_transfer_function(r, NULL), UMBRA_SUCCESS);
    assert_true(flip_distance(r, top, down, 31.0f, 0.02f, 1) < 0.0f);
    umbra_renderer_release(r);
    umbra_transfer_function_release(view);
    umbra_transfer_function_release(light);
    umbra_volume_release(vol);
}

static void test_threshold_skipping_changes_nothing(void **state)
{
    (void)state;
    mt_check_skipping_changes_nothing(ctx, mt_shadow(UMBRA_SHADOW_THRESHOLD, 128, 13));
}

static void test_threshold_camera_move_reuses_map(void **state)
{
    (void)state;
    mt_check_reuse_and_memory(ctx, mt_shadow(UMBRA_SHADOW_THRESHOLD, 128, 7), 1, 1);
}

static void test_threshold_taps_read_their_texels(void **state)
{
    (void)state;
    mt_check_taps_read_their_texels(ctx, UMBRA_SHADOW_THRESHOLD);
}

/* Measured on PoCL (spheres 48^3, its light, 96x96, map 256^2, step 0.5): 1 tap 0.0357, 7 taps
 * 0.0313, 13 taps 0.0300, 21 taps 0.0282; no shadows at all ("none") is 0.0252 away. The hard
 * threshold turns the translucent spheres' partial shadows into full ones, so it is further from
 * the reference than no shadow on this scene; filtering softens the edges. Bounds: 1.25x. */
static void test_threshold_error_vs_reference_bounded(void **state)
{
    (void)state;
    const uint32_t taps[] = {1, 7, 13, 21};
    const double bound[] = {0.045, 0.040, 0.038, 0.036};
    for (int i = 0; i < 4; ++i) {
        double e = mt_error_vs_reference(ctx, mt_shadow(UMBRA_SHADOW_THRESHOLD, 256, taps[i]));
        printf("threshold, %u taps, map 256^2: mean abs error vs reference %.4f (bound %.3f)\n",
               taps[i], e, bound[i]);
        assert_true(e <= bound[i]);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threshold_slab_crossing_matches_analytic),
        cmocka_unit_test(test_threshold_product_and_sum_marches_exact),
        cmocka_unit_test(test_threshold_light_transfer_function_drives_map),
        cmocka_unit_test(test_threshold_camera_move_reuses_map),
        cmocka_unit_test(test_threshold_skipping_changes_nothing),
        cmocka_unit_test(test_threshold_taps_read_their_texels),
        cmocka_unit_test(test_threshold_error_vs_reference_bounded),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
