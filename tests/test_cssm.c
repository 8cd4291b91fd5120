// SPDX-License-Identifier: Apache-2.0
/* tests/test_cssm.c: colored stochastic shadow maps (kernels/shadow_cssm.cl) pinned down.
 *
 * Statistics. A texel's photon is stopped in segment i with probability rho_i given that it got
 * there, so a sample at depth s is lit by that texel with probability P = prod (1 - rho_i) over
 * the segments whose midpoint (the stored depth) lies in front of s: a Bernoulli(P) draw. Texels
 * draw independent random numbers. Query points placed one per texel centre over an N-texel
 * region, m taps each, use every texel of the region's interior exactly m times: the mean factor
 * is a weighted mean of texel draws with weights <= 1/N summing to 1, so its standard deviation
 * is at most sqrt(P (1 - P) / N) whatever m is. The tests allow 5 of those (a false failure once
 * in 1.7 million runs). On a homogeneous slab (alpha a per voxel, step h, a_h = 1 - (1 - a)^h),
 * at depth D = K h below the top face exactly K midpoints lie in front: P = (1 - a_h)^K =
 * (1 - a)^D = exp(-sigma D) exactly. At other depths the count is rounded to the nearest
 * midpoint: P lies within a factor exp(+-sigma h / 2) of exp(-sigma D), and that discretisation
 * error is added to the bound there.
 *
 * Also: a coloured light stores three depths from one shared random number per segment, so where
 * t_R >= t_G >= t_B every lookup has l_R >= l_G >= l_B; a separate light transfer function drives
 * generation; the same seed gives the same image bit for bit and another seed a different one;
 * empty-space skipping changes no bit; stress lights, caching, memory (3 or 1 values per texel)
 * and the error against the exact reference on the spheres scene are bounded.
 * Usage: test_cssm [filter] (a cmocka test-name glob). */
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

enum { MAP = 256, LO = 24, HI = 232 }; /* texels LO..HI-1 lie >= 20 texels inside the box */
#define REGION ((size_t)(HI - LO) * (HI - LO))

/* Mean factor per channel over one query point per texel centre of the region, on the plane
 * D voxels below the slab's top face (light straight down). */
static void region_mean(umbra_renderer r, float depth, double mean[3])
{
    float probe[3] = {0, 0, 0}, f[3];
    assert_int_equal(umbra_renderer_query_shadow(r, probe, 1, f), UMBRA_SUCCESS); /* builds */
    float *p = malloc(REGION * 3 * sizeof *p), *v = malloc(REGION * 3 * sizeof *v);
    assert_non_null(p);
    assert_non_null(v);
    size_t k = 0;
    for (uint32_t j = LO; j < HI; ++j)
        for (uint32_t i = LO; i < HI; ++i, ++k)
            mt_texel_point(r, i, j, -0.5f * MT_NY + depth, p + 3 * k);
    assert_int_equal(umbra_renderer_query_shadow(r, p, REGION, v), UMBRA_SUCCESS);
    mean[0] = mean[1] = mean[2] = 0.0;
    for (size_t i = 0; i < REGION; ++i)
        for (int c = 0; c < 3; ++c)
            mean[c] += v[3 * i + c] / (double)REGION;
    free(p);
    free(v);
}

static double stat_bound(double p) { return 5.0 * sqrt(p * (1.0 - p) / (double)REGION) + 1e-4; }

static void test_cssm_slab_mean_matches_transmittance(void **state)
{
    (void)state;
    const float a = 0.05f, h = 0.5f;
    const double sigma = -log(1.0 - a);
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, 0.7f, 0.7f, 0.7f, a);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, l, UMBRA_TRANSMISSION_GREY);
    const uint32_t taps[] = {1, 7, 13, 21};
    /* On segment boundaries (exact), inside a segment (discretised), below the slab (exact). */
    const float depths[] = {10.0f, 20.0f, 10.3f, 40.0f};
    for (int t = 0; t < 4; ++t) {
        umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, taps[t]);
        s.map_step = h;
        s.seed = 11;
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        for (int d = 0; d < 4; ++d) {
            double D = fmin(depths[d], (double)MT_NY);
            double expect = exp(-sigma * D), bound = stat_bound(expect);
            double k = depths[d] / h;
            if (k != floor(k))
                bound += expect * (exp(0.5 * sigma * h) - 1.0);
            double m[3];
            region_mean(r, depths[d], m);
            printf("%2u taps, depth %4.1f: mean %.5f, exp(-sigma d) %.5f, bound %.5f\n", taps[t],
                   depths[d], m[0], expect, bound);
            assert_true(m[0] == m[1] && m[1] == m[2]);
            if (!(fabs(m[0] - expect) <= bound))
                fail_msg("%u taps, depth %g: mean factor %.5f, analytic %.5f, bound %.5f",
                         taps[t], depths[d], m[0], expect, bound);
        }
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_cssm_colored_channels_share_random_numbers(void **state)
{
    (void)state;
    const float a = 0.06f, h = 0.5f, t[3] = {0.9f, 0.5f, 0.1f};
    const int K = 24; /* depth K h = 12 voxels */
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, t[0], t[1], t[2], a);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, l, UMBRA_TRANSMISSION_COLORED);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, 13);
    s.map_step = h;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    double m[3];
    region_mean(r, (float)K * h, m);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.light_channels, 3);
    const double a_h = 1.0 - pow(1.0 - a, h);
    for (int c = 0; c < 3; ++c) {
        double expect = pow(1.0 - a_h * (1.0 - t[c]), K);
        printf("channel %d: mean %.5f, analytic %.5f, bound %.5f\n", c, m[c], expect,
               stat_bound(expect));
        if (!(fabs(m[c] - expect) <= stat_bound(expect)))
            fail_msg("channel %d: mean %.5f, analytic %.5f", c, m[c], expect);
    }
    /* One r_i for all channels and rho_R <= rho_G <= rho_B: a photon stopped in red is stopped
     * in green and blue no later, at every texel, so every lookup is ordered. */
    float p[3 * 64], f[3 * 64];
    for (int i = 0; i < 64; ++i) {
        p[3 * i] = -15.0f + 0.47f * (float)i;
        p[3 * i + 1] = 12.0f - 0.3f * (float)i;
        p[3 * i + 2] = 3.0f - 0.2f * (float)i;
    }
    assert_int_equal(umbra_renderer_query_shadow(r, p, 64, f), UMBRA_SUCCESS);
    for (int i = 0; i < 64; ++i)
        if (!(f[3 * i] >= f[3 * i + 1] && f[3 * i + 1] >= f[3 * i + 2]))
            fail_msg("point %d: factors %g %g %g are not ordered like the transmission", i,
                     f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_cssm_light_transfer_function_drives_generation(void **state)
{
    (void)state;
    const float a_view = 0.02f, a_light = 0.08f, D = 8.0f;
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function view = mt_tf(ctx, 0.7f, 0.7f, 0.7f, a_view);
    umbra_transfer_function light = mt_tf(ctx, 0.3f, 0.3f, 0.3f, a_light);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, view, l, UMBRA_TRANSMISSION_GREY);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, 7);
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    const umbra_transfer_function tfs[] = {view, light, NULL};
    const float alphas[] = {a_view, a_light, a_view};
    for (int i = 0; i < 3; ++i) {
        if (i > 0)
            assert_int_equal(umbra_renderer_set_light_transfer_function(r, tfs[i]),
                             UMBRA_SUCCESS);
        double m[3], expect = pow(1.0 - alphas[i], D);
        region_mean(r, D, m);
        if (!(fabs(m[0] - expect) <= stat_bound(expect)))
            fail_msg("light tf %d: mean %.5f, analytic %.5f", i, m[0], expect);
        umbra_render_stats st;
        assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
        assert_int_equal(st.light_channels, 1);
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(view);
    umbra_transfer_function_release(light);
    umbra_volume_release(vol);
}

/* Spheres 48^3 at 64x64, 13 taps, 128^2 map. */
static void render_spheres(umbra_scene *scene, uint32_t seed, int skip, float *img)
{
    umbra_renderer r = test_renderer_transmission(
        ctx, scene->volume, scene->tf, scene->light, UMBRA_TRANSMISSION_COLORED);
    umbra_render_desc o = scene->options;
    o.empty_space_skipping = skip;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_camera(r, &scene->camera), UMBRA_SUCCESS);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, 128, 13);
    s.seed = seed;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 64, 64, img), UMBRA_SUCCESS);
    umbra_renderer_release(r);
}

static void test_cssm_same_seed_same_image_bitwise(void **state)
{
    (void)state;
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &scene), UMBRA_SUCCESS);
    static float a[64 * 64 * 4], b[64 * 64 * 4], c[64 * 64 * 4], d[64 * 64 * 4];
    render_spheres(&scene, 7, 1, a);
    render_spheres(&scene, 7, 1, b);
    render_spheres(&scene, 8, 1, c);
    render_spheres(&scene, 7, 0, d);
    assert_memory_equal(a, b, sizeof a);
    assert_memory_equal(a, d, sizeof a); /* skipped segments draw no number that matters */
    size_t differ = 0;
    for (size_t i = 0; i < 64 * 64 * 4; ++i)
        differ += a[i] != c[i];
    printf("seed 7 vs 8: %zu of %d values differ\n", differ, 64 * 64 * 4);
    assert_true(differ > 100);
    umbra_scene_release(&scene);
}

static void test_cssm_stress_lights_finite_and_lit(void **state)
{
    (void)state;
    mt_check_stress_lights(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 13));
    mt_check_stress_lights(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 21));
}

static void test_cssm_skipping_changes_nothing(void **state)
{
    (void)state;
    mt_check_skipping_changes_nothing(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 13));
}

static void test_cssm_camera_move_reuses_map(void **state)
{
    (void)state;
    mt_check_reuse_and_memory(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 13), 3, 1);
}

static void test_cssm_taps_read_their_texels(void **state)
{
    (void)state;
    mt_check_taps_read_their_texels(ctx, UMBRA_SHADOW_CSSM);
}

/* Measured on PoCL (spheres 48^3, its light, 96x96, map 256^2, step 0.5, seed 1; seeds 2-4
 * within 0.0001): 1 tap 0.0193, 7 taps 0.0076, 13 taps 0.0062, 21 taps 0.0056; no shadows at all
 * is 0.0252 away, the threshold map 0.030 (13 taps). The error left is noise (1 tap) and the
 * taps' blur. Bounds: 1.25x. */
static void test_cssm_error_vs_reference_bounded(void **state)
{
    (void)state;
    const uint32_t taps[] = {1, 7, 13, 21};
    const double bound[] = {0.024, 0.0095, 0.0078, 0.007};
    for (int i = 0; i < 4; ++i) {
        double e = mt_error_vs_reference(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 256, taps[i]));
        printf("cssm, %u taps, map 256^2: mean abs error vs reference %.4f (bound %.3f)\n",
               taps[i], e, bound[i]);
        assert_true(e <= bound[i]);
    }
}

static void test_cssm_invalid_parameters_rejected(void **state)
{
    (void)state;
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, 256, 13);
    const uint32_t bad_taps[] = {0, 2, 12, 22, 64};
    for (int i = 0; i < 5; ++i) {
        s.taps = bad_taps[i];
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_ERROR_INVALID_ARGUMENT);
        assert_true(test_message_contains(ctx, "taps"));
    }
    s.taps = 21;
    s.map_size = 15;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "map_size 15"));
    s.map_size = 8193;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_ERROR_INVALID_ARGUMENT);
    s.map_size = 16;
    s.map_step = NAN;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_ERROR_INVALID_ARGUMENT);
    s.map_step = 0.5f;
    s.threshold = 7.0f; /* the threshold map's parameter: CSSM ignores it */
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    umbra_context_take_error(ctx, NULL);
    umbra_renderer_release(r);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cssm_slab_mean_matches_transmittance),
        cmocka_unit_test(test_cssm_colored_channels_share_random_numbers),
        cmocka_unit_test(test_cssm_light_transfer_function_drives_generation),
        cmocka_unit_test(test_cssm_same_seed_same_image_bitwise),
        cmocka_unit_test(test_cssm_stress_lights_finite_and_lit),
        cmocka_unit_test(test_cssm_camera_move_reuses_map),
        cmocka_unit_test(test_cssm_skipping_changes_nothing),
        cmocka_unit_test(test_cssm_taps_read_their_texels),
        cmocka_unit_test(test_cssm_error_vs_reference_bounded),
        cmocka_unit_test(test_cssm_invalid_parameters_rejected),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
