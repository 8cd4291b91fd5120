// SPDX-License-Identifier: Apache-2.0
/* tests/test_deep_budget.c: the deep shadow map under a fixed node budget (shadow max_nodes),
 * held against the exact reference technique on the two cases that made the old streaming merge
 * leak light (issue 10, failure 6):
 *
 *  - a "head": nested spherical shells (translucent tissue inside, a nearly opaque bone shell,
 *    translucent skin outside) around a point light, coloured transmission. Every light ray
 *    crosses tissue, bone and skin, so its visibility has two gentle stretches and one cliff;
 *  - a thick bone shell lit obliquely by a directional light, grey: rays graze it, cross it once
 *    or cross it twice with the hollow between.
 *
 * For budgets 16, 8, 4, 3 and 2 nodes the rendered image's RMSE against the reference stays within
 * a stated bound and grows as the budget shrinks (no cliff, no inversion), and every stored
 * function is well formed: depths non-decreasing, visibility in [0, 1] and non-increasing, the
 * end value the same as with 64 nodes, which hold every node of these scenes (the budget never
 * changes what lies behind the volume); from 3 nodes up at most 1% of the pixels are off by more
 * than 0.1.
 *
 * And a one-voxel board lit obliquely (failure 7): the nearest-texel lookup aliases at the board's
 * edges, within a stated bound that shrinks as the map grows.
 *
 * Usage: test_deep_budget [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "techniques/deep.h"
#include "test_util.h"

enum { N_VOX = 48, W = 96, H = 96 };

/* Radial profile of the head, in voxels from the centre: tissue 0.25 inside r 12, bone 0.85 in
 * [12, 15], skin 0.55 in [15, 19], air outside; 1-voxel smooth transitions so the trilinear
 * volume has the same shells at every step. */
static float head_value(double r)
{
    const double edge[3] = {12.0, 15.0, 19.0}, level[4] = {0.25, 0.85, 0.55, 0.0};
    double v = level[0];
    for (int i = 0; i < 3; ++i) {
        double w = fmin(fmax(r - edge[i] + 0.5, 0.0), 1.0);
        v += w * (level[i + 1] - level[i]);
    }
    return (float)v;
}

/* A thick shell: 0.8 for r in [11, 18], 0 elsewhere, 1-voxel transitions. */
static float shell_value(double r)
{
    double in = fmin(fmax(r - 11.0 + 0.5, 0.0), 1.0), out = fmin(fmax(r - 18.0 + 0.5, 0.0), 1.0);
    return (float)(0.8 * (in - out));
}

static umbra_volume radial_volume(umbra_context ctx, float (*f)(double), double noise)
{
    float *data = malloc((size_t)N_VOX * N_VOX * N_VOX * sizeof *data);
    assert_non_null(data);
    const double c = 0.5 * N_VOX - 0.5;
    for (int k = 0; k < N_VOX; ++k)
        for (int j = 0; j < N_VOX; ++j)
            for (int i = 0; i < N_VOX; ++i)
            {
                double v = f(sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)));
                if (v > 0.0)
                    v = fmin(fmax(v + noise * test_voxel_noise(i, j, k), 0.0), 1.0);
                data[((size_t)k * N_VOX + j) * N_VOX + i] = (float)v;
            }
    umbra_volume v = test_volume_bricks(ctx, N_VOX, N_VOX, N_VOX, data, 8);
    free(data);
    return v;
}

/* The head's light and view table: tissue reddish and faint, bone near white and dense, skin
 * pale and translucent (alpha per voxel). */
static umbra_transfer_function head_tf(umbra_context ctx)
{
    const umbra_tf_point p[] = {
        {0.00f, {0.0f, 0.0f, 0.0f, 0.0f}},    {0.10f, {0.0f, 0.0f, 0.0f, 0.0f}},
        {0.25f, {0.8f, 0.3f, 0.2f, 0.05f}},   {0.45f, {0.85f, 0.55f, 0.45f, 0.1f}},
        {0.55f, {0.85f, 0.55f, 0.45f, 0.12f}}, {0.70f, {0.7f, 0.6f, 0.5f, 0.5f}},
        {0.85f, {0.5f, 0.45f, 0.4f, 0.8f}},   {1.00f, {0.5f, 0.45f, 0.4f, 0.8f}},
    };
    umbra_transfer_function tf = NULL;
    assert_int_equal(
        umbra_transfer_function_create_from_points(ctx, p, sizeof p / sizeof p[0], 256, &tf),
        UMBRA_SUCCESS);
    return tf;
}

static umbra_transfer_function shell_tf(umbra_context ctx)
{
    const umbra_tf_point p[] = {
        {0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
        {0.2f, {0.9f, 0.9f, 0.85f, 0.0f}},
        {0.8f, {0.9f, 0.9f, 0.85f, 0.3f}},
        {1.0f, {0.9f, 0.9f, 0.85f, 0.3f}},
    };
    umbra_transfer_function tf = NULL;
    assert_int_equal(
        umbra_transfer_function_create_from_points(ctx, p, sizeof p / sizeof p[0], 256, &tf),
        UMBRA_SUCCESS);
    return tf;
}

static umbra_shadow_desc deep_budget(uint32_t max_nodes)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_DEEP;
    d.map.size = 128;
    d.map.step = 0.5f;
    d.deep.epsilon = 0.02f;
    d.deep.max_nodes = max_nodes;
    return d;
}

static void render(umbra_renderer r, const umbra_shadow_desc *d, float *img)
{
    assert_int_equal(umbra_renderer_set_shadow(r, d), UMBRA_SUCCESS);
    if (umbra_renderer_render(r, W, H, img) != UMBRA_SUCCESS)
        fail_msg("render: %s", umbra_context_last_message(r->ctx));
}

/* RMSE over the RGB of every pixel, and the fraction of pixels off by more than 0.1 in some
 * channel. */
static double image_rmse(const float *a, const float *b, double *frac_off)
{
    double s = 0.0;
    int off = 0;
    for (int i = 0; i < W * H; ++i) {
        double m = 0.0;
        for (int k = 0; k < 3; ++k) {
            double e = (double)a[4 * i + k] - b[4 * i + k];
            s += e * e;
            m = fmax(m, fabs(e));
        }
        off += m > 0.1;
    }
    *frac_off = (double)off / (W * H);
    return sqrt(s / (3.0 * W * H));
}

/* Every stored function of the fixed-budget map: depths non-decreasing, visibility per channel
 * in [0, 1] and non-increasing, and the last node's visibility equal to end[texel] (the value
 * behind the volume, from the unbounded map). Returns the largest end-value difference. */
static double check_functions(umbra_renderer r, const float *end, double *rise)
{
    umbra__deep_info info;
    assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_SUCCESS);
    const uint32_t n = r->shadow.map.size, N = info.max_nodes, c = info.channels, f = 1 + c;
    assert_true(N >= 2);
    float *nodes = malloc((size_t)n * n * N * f * sizeof *nodes);
    assert_non_null(nodes);
    assert_int_equal(umbra__deep_read(r, NULL, NULL, NULL, nodes), UMBRA_SUCCESS);
    double worst_end = 0.0;
    *rise = 0.0;
    for (size_t t = 0; t < (size_t)n * n; ++t) {
        const float *o = nodes + t * N * f;
        for (uint32_t j = 0; j < N; ++j) {
            for (uint32_t k = 1; k <= c; ++k) {
                assert_true(o[j * f + k] >= 0.0f && o[j * f + k] <= 1.0f);
                if (j > 0)
                    *rise = fmax(*rise, (double)o[j * f + k] - o[(j - 1) * f + k]);
            }
            if (j > 0)
                assert_true(o[j * f] >= o[(j - 1) * f]);
        }
        for (uint32_t k = 1; k <= c; ++k)
            worst_end = fmax(worst_end, fabs((double)o[(N - 1) * f + k] - end[t * c + k - 1]));
    }
    free(nodes);
    return worst_end;
}

/* The end visibility per texel and channel of the map just built with a budget large enough to
 * hold every node of these scenes (64, the limit), as the yardstick for the budgets' end values. */
static float *end_values(umbra_renderer r)
{
    umbra__deep_info info;
    assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_SUCCESS);
    const uint32_t n = r->shadow.map.size, N = info.max_nodes, c = info.channels, f = 1 + c;
    float *nodes = malloc((size_t)n * n * N * f * sizeof *nodes);
    float *end = malloc((size_t)n * n * c * sizeof *end);
    assert_true(nodes && end);
    assert_int_equal(umbra__deep_read(r, NULL, NULL, NULL, nodes), UMBRA_SUCCESS);
    for (size_t t = 0; t < (size_t)n * n; ++t)
        for (uint32_t k = 0; k < c; ++k)
            end[t * c + k] = nodes[(t * N + N - 1) * f + 1 + k];
    free(nodes);
    return end;
}

/* Renders the reference and the budgets (in decreasing order), checks each map (monotone, end
 * value exact) and the bounds: RMSE <= bound[i] for budget[i], at most 1% of the pixels off by
 * more than 0.1 from 3 nodes up, and the RMSE never falls as the budget shrinks. */
static void check_budgets(umbra_renderer r, const char *name, const uint32_t *budget,
                          const double *bound, int nb)
{
    float *ref = malloc(W * H * 4 * sizeof *ref), *img = malloc(W * H * 4 * sizeof *img);
    assert_true(ref && img);
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_REFERENCE;
    render(r, &d, ref);
    d = deep_budget(64);
    render(r, &d, img);
    float *end = end_values(r);
    double frac;
    print_message("%s: 64 nodes RMSE %.4f\n", name, image_rmse(img, ref, &frac));
    double prev = 0.0;
    for (int i = 0; i < nb; ++i) {
        d = deep_budget(budget[i]);
        render(r, &d, img);
        double e = image_rmse(img, ref, &frac), rise, end_err = check_functions(r, end, &rise);
        print_message("%s: %2u nodes RMSE %.4f (bound %.3f), %.1f%% of pixels off by > 0.1, end "
                      "value off by %.2g, largest rise %.2g\n",
                      name, budget[i], e, bound[i], 100.0 * frac, end_err, rise);
        assert_true(rise <= 1e-6);
        assert_true(end_err <= 1e-6);
        assert_true(e <= bound[i]);
        /* No leak: from 3 nodes up, hardly a pixel off by more than 0.1. */
        if (budget[i] >= 3)
            assert_true(frac <= 0.01);
        /* Graceful: the error grows as the budget shrinks (1e-3: texel noise between budgets
         * that are nearly equally good, such as 4 and 3 nodes on the shells). */
        assert_true(e >= prev - 1e-3);
        prev = e;
    }
    free(end);
    free(ref);
    free(img);
}

/* ---- the cases ------------------------------------------------------------------------------ */

static void test_budget_nested_shells_point_light_inside(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = radial_volume(ctx, head_value, 0.06);
    umbra_transfer_function tf = head_tf(ctx);
    const float dir[3] = {0.4f, 0.3f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, sqrtf(3.0f) * N_VOX, 30.0f);
    umbra_light light = test_point_light(1.5f, -2.0f, 1.0f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &light, &o);
    /* Measured on PoCL (2026-12-02: the span error integrated through sign changes, weight 1
     * for a light inside, candidates from a finer fit, no node for the flat tail,
     * kernels/techniques/deep_budget.cl): RMSE 0.0019, 0.0028, 0.0106, 0.0101, 0.030. Before,
     * against the exact reference of the extinction model (issue 10): RMSE 0.0031, 0.0031,
     * 0.0121, 0.0123, 0.064 (before that model, against the midpoint reference: 0.0014 /
     * 0.0014 / 0.0079 / 0.0082 / 0.060; the old streaming merge: 0.0017 / 0.0017 / 0.0054 /
     * 0.035 / 0.060, with 6% of the pixels off by > 0.1 at 3 nodes, and functions
     * rising by up to epsilon = 0.02). Bounds: the aim 0.02 at 3 nodes, about 1.5-2 times
     * the measurement elsewhere. */
    const uint32_t budget[] = {16, 8, 4, 3, 2};
    const double bound[] = {0.006, 0.006, 0.018, 0.02, 0.09};
    check_budgets(r, "nested shells, point light inside", budget, bound, 5);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_budget_thick_shell_oblique_light(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = radial_volume(ctx, shell_value, 0.06);
    umbra_transfer_function tf = shell_tf(ctx);
    const float dir[3] = {-0.5f, 0.4f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, sqrtf(3.0f) * N_VOX, 30.0f);
    umbra_light light = test_directional_light(0.8f, -0.5f, -0.35f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_GREY;
    umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &light, &o);
    /* Measured on PoCL: RMSE 0.0054, 0.0054, 0.0072, 0.0102, 0.059 (2026-12-01; before, with
     * the span error's trapezoid across sign changes: 0.0055, 0.0055, 0.0096, 0.0161, 0.060;
     * the old streaming merge: 0.0053 / 0.0053 / 0.0070 / 0.0135 / 0.090, functions rising by
     * up to 0.02). */
    const uint32_t budget[] = {16, 8, 4, 3, 2};
    const double bound[] = {0.008, 0.008, 0.013, 0.02, 0.08};
    check_budgets(r, "thick shell, oblique light", budget, bound, 5);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

/* ---- thin boards (issue 10, failure 7) -------------------------------------------------------
 * The deep map's lookup takes the nearest texel (as the paper's does), so at the edge of thin
 * material the map aliases at its texel size: a one-voxel board lit obliquely, its shadow on the
 * ground plane and on itself. The largest pixel error against the reference must stay within a
 * stated bound and shrink as the map grows (docs/techniques.md, "Deep shadow map"). */
static float board_value(int i, int j, int k)
{
    const double c = 0.5 * N_VOX - 0.5, x = i - c, y = j - c, z = k - c;
    if (fabs(y) >= 15.0 || fabs(z) >= 18.0)
        return 0.0f;
    return (float)fmax(0.0, 1.0 - fabs(x + 0.3 * z) / sqrt(1.09));
}

static void test_thin_board_edge_aliasing_shrinks_with_map_size(void **state)
{
    umbra_context ctx = *state;
    float *data = malloc((size_t)N_VOX * N_VOX * N_VOX * sizeof *data);
    assert_non_null(data);
    for (int k = 0; k < N_VOX; ++k)
        for (int j = 0; j < N_VOX; ++j)
            for (int i = 0; i < N_VOX; ++i)
                data[((size_t)k * N_VOX + j) * N_VOX + i] = board_value(i, j, k);
    umbra_volume vol = test_volume_bricks(ctx, N_VOX, N_VOX, N_VOX, data, 8);
    free(data);
    const float rgba[8] = {0.8f, 0.8f, 0.8f, 0.0f, 0.8f, 0.8f, 0.8f, 0.9f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    const float dir[3] = {0.5f, 0.6f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, sqrtf(3.0f) * N_VOX, 30.0f);
    umbra_light light = test_directional_light(0.7f, -1.0f, 0.25f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.ground_plane = 1;
    umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &light, &o);
    float *ref = malloc(W * H * 4 * sizeof *ref), *img = malloc(W * H * 4 * sizeof *img);
    assert_true(ref && img);
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_REFERENCE;
    render(r, &d, ref);
    /* Measured on PoCL: largest pixel error 0.203, 0.146, 0.111 at 128^2, 256^2, 512^2 (RMSE
     * 0.016, 0.014, 0.013: the aliasing lives on a few edge pixels). Bounds: 1.3 times that. */
    const uint32_t sizes[] = {128, 256, 512};
    const double bound[] = {0.26, 0.19, 0.15};
    double worst[3];
    for (int c = 0; c < 3; ++c) {
        d = deep_budget(0);
        d.map.size = sizes[c];
        render(r, &d, img);
        double frac, e = image_rmse(img, ref, &frac);
        worst[c] = 0.0;
        for (int i = 0; i < W * H * 4; ++i)
            if (i % 4 != 3)
                worst[c] = fmax(worst[c], fabs((double)img[i] - ref[i]));
        print_message("thin board, %4u^2 map: RMSE %.4f, largest pixel error %.3f (bound %.2f), "
                      "%.1f%% of pixels off by > 0.1\n",
                      sizes[c], e, worst[c], bound[c], 100.0 * frac);
        assert_true(worst[c] <= bound[c]);
        if (c > 0)
            assert_true(worst[c] < worst[c - 1]);
    }
    free(ref);
    free(img);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_budget_nested_shells_point_light_inside),
        cmocka_unit_test(test_budget_thick_shell_oblique_light),
        cmocka_unit_test(test_thin_board_edge_aliasing_shrinks_with_map_size),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
