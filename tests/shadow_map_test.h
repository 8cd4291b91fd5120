// SPDX-License-Identifier: Apache-2.0
/* tests/shadow_map_test.h: checks that the single-layer light-space maps (test_threshold.c,
 * test_cssm.c) share, written once and run per technique:
 *  - a homogeneous slab scene (the whole box filled with one value) and points placed at texel
 *    centres of the map, for analytic comparisons;
 *  - a camera move re-uses the map, a light change rebuilds it, and the reported memory is the
 *    map's size;
 *  - empty-space skipping of the light rays (the walk over the light's cell masks) changes no
 *    pixel, for the scene's directional light and a point light;
 *  - the image on the spheres scene stays within a stated mean error of the exact reference;
 *  - a filtered lookup is the mean of one-tap lookups at its taps' texels, over every texel of a
 *    small map and a rim around it, so that the lookups' two paths (all taps inside the map,
 *    and taps checked one by one near and beyond its edge) read the texels they should. */
#ifndef UMBRA_TESTS_SHADOW_MAP_TEST_H
#define UMBRA_TESTS_SHADOW_MAP_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "test_util.h"

/* The slab: the whole box of MT_NX x MT_NY x MT_NZ voxels (spacing 1) holds one value. */
#define MT_NX 48u
#define MT_NY 32u
#define MT_NZ 48u

/* A constant transfer function of colour (r, g, b) and per-voxel alpha a. */
static inline umbra_transfer_function mt_tf(umbra_context ctx, float r, float g, float b, float a)
{
    float rgba[8] = {r, g, b, a, r, g, b, a};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    return tf;
}

static inline umbra_shadow_desc mt_shadow(umbra_shadow_technique t, uint32_t map_size,
                                          uint32_t taps)
{
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = t;
    s.map.size = map_size;
    s.threshold.taps = taps;
    s.cssm.taps = taps;
    return s;
}

/* World point at the centre of texel (i, j) of an orthographic map, at distance `along` along the
 * light direction (the map's w axis) from the origin. The map must have been built. */
static inline void mt_texel_point(umbra_renderer r, uint32_t i, uint32_t j, float along, float p[3])
{
    const UmbraShadow *S = &r->shadow_params;
    assert_int_equal(S->ls_mode, UMBRA_LS_ORTHO);
    float n = (float)S->map_size;
    float a = S->ls_window[0] + ((float)i + 0.5f) / (n * S->ls_window[2]);
    float b = S->ls_window[1] + ((float)j + 0.5f) / (n * S->ls_window[3]);
    for (int k = 0; k < 3; ++k)
        p[k] = a * S->ls_u[k] + b * S->ls_v[k] + along * S->ls_w[k];
}

/* The tap offsets of kernels/common/lightspace.cl (ls_taps), the first `taps` of them for each set.
 * */
static const int mt_taps[21][2] = {{0, 0},   {4, 0},   {-4, 0}, {0, 4},  {0, -4},  {3, 3},  {-3, -3},
                                   {3, -3},  {-3, 3},  {7, 0},  {-7, 0}, {0, 7},   {0, -7}, {5, 5},
                                   {-5, -5}, {5, -5},  {-5, 5}, {10, 0}, {-10, 0}, {0, 10}, {0, -10}};

/* A filtered lookup at a texel's centre equals the mean of one-tap lookups at the centres of the
 * texels its taps read (outside the map: lit), for 13 and 21 taps, on a 64^2 map of a lumpy
 * volume under an oblique light, at every texel of the map and of a rim of 12 texels around it,
 * at three depths. */
static inline void mt_check_taps_read_their_texels(umbra_context ctx,
                                                   umbra_shadow_technique technique)
{
    enum { N = 24, MAP = 64, RIM = 12, SIDE = MAP + 2 * RIM, DEPTHS = 3 };
    float *data = malloc((size_t)N * N * N * sizeof *data);
    assert_non_null(data);
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x)
                data[(z * N + y) * N + x] =
                    0.5f + 0.5f * sinf(0.9f * (float)x) * cosf(0.7f * (float)y + 0.5f * (float)z);
    umbra_volume vol = test_volume(ctx, N, N, N, data);
    free(data);
    const float rgba[8] = {0, 0, 0, 0, 0.8f, 0.6f, 0.4f, 0.5f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, test_directional_light(0.3f, -1, 0.2f),
                                                  UMBRA_TRANSMISSION_GREY);
    const size_t count = (size_t)SIDE * SIDE * DEPTHS;
    float *p = malloc(count * 3 * sizeof *p), *f = malloc(count * 3 * sizeof *f);
    float *one = malloc(count * 3 * sizeof *one);
    assert_non_null(p);
    assert_non_null(f);
    assert_non_null(one);
    for (uint32_t taps = 13; taps <= 21; taps += 8) {
        umbra_shadow_desc s = mt_shadow(technique, MAP, taps);
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        const float probe[3] = {0, 0, 0}; /* builds the map, so that its window is known */
        float pf[3];
        assert_int_equal(umbra_renderer_query_shadow(r, probe, 1, pf), UMBRA_SUCCESS);
        const UmbraShadow *S = &r->shadow_params;
        assert_int_equal(S->ls_mode, UMBRA_LS_ORTHO);
        assert_int_equal(S->map_size, MAP);
        /* Texel (i, j)'s centre at `along` (mt_texel_point, here for texels off the map too). */
#define MT_POINT(dst, i, j, along)                                                                 \
    do {                                                                                           \
        float a_ = S->ls_window[0] + ((float)(i) + 0.5f) / ((float)MAP * S->ls_window[2]);         \
        float b_ = S->ls_window[1] + ((float)(j) + 0.5f) / ((float)MAP * S->ls_window[3]);         \
        for (int k_ = 0; k_ < 3; ++k_)                                                             \
            (dst)[k_] = a_ * S->ls_u[k_] + b_ * S->ls_v[k_] + (along) * S->ls_w[k_];               \
    } while (0)
        const float along[DEPTHS] = {-6.0f, 0.0f, 5.0f};
        size_t q = 0;
        for (int d = 0; d < DEPTHS; ++d)
            for (int j = -RIM; j < MAP + RIM; ++j)
                for (int i = -RIM; i < MAP + RIM; ++i, ++q)
                    MT_POINT(p + 3 * q, i, j, along[d]);
        assert_int_equal(umbra_renderer_query_shadow(r, p, count, f), UMBRA_SUCCESS);
        double *sum = calloc(count * 3, sizeof *sum);
        assert_non_null(sum);
        s.threshold.taps = s.cssm.taps = 1;
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        for (uint32_t t = 0; t < taps; ++t) {
            q = 0;
            for (int d = 0; d < DEPTHS; ++d)
                for (int j = -RIM; j < MAP + RIM; ++j)
                    for (int i = -RIM; i < MAP + RIM; ++i, ++q)
                        MT_POINT(p + 3 * q, i + mt_taps[t][0], j + mt_taps[t][1], along[d]);
            assert_int_equal(umbra_renderer_query_shadow(r, p, count, one), UMBRA_SUCCESS);
            for (size_t k = 0; k < count * 3; ++k)
                sum[k] += one[k];
        }
#undef MT_POINT
        size_t differ = 0, partial = 0;
        for (size_t k = 0; k < count * 3; ++k) {
            const double expect = sum[k] / taps;
            differ += !(fabs((double)f[k] - expect) <= 1e-6);
            partial += expect > 0.0 && expect < 1.0;
        }
        printf("%u taps: %zu of %zu factors differ from the mean of their taps, %zu partly lit\n",
               taps, differ, count * 3, partial);
        assert_true(partial > count / 10); /* the check sees the taps disagree */
        assert_int_equal(differ, 0);
        free(sum);
    }
    free(one);
    free(f);
    free(p);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static inline int mt_finite_unit(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i]) || v[i] < 0.0f || v[i] > 1.0f)
            return 0;
    return 1;
}

/* Mean over pixels of the mean absolute RGB difference. */
static inline double mt_mean_abs_error(const float *a, const float *b, size_t pixels)
{
    double sum = 0.0;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c)
            sum += fabs((double)a[4 * i + c] - (double)b[4 * i + c]) / 3.0;
    return sum / (double)pixels;
}

/* ---- empty-space skipping -------------------------------------------------------------------- */

/* The spheres at 64x64 with skipping off and on, for the scene's light and a point light above
 * a corner: the light rays sample the same grid either way, and what skipping leaves out has
 * opacity 0, so the pictures agree (to 1e-6, for a sample on a cell face that rounding may count
 * to either cell). */
static inline void mt_check_skipping_changes_nothing(umbra_context ctx, umbra_shadow_desc shadow)
{
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &scene), UMBRA_SUCCESS);
    const umbra_light lights[2] = {scene.light, test_point_light(30.0f, 45.0f, -25.0f)};
    enum { W = 64, H = 64 };
    static float img[2][W * H * 4];
    for (int l = 0; l < 2; ++l) {
        for (int skip = 0; skip < 2; ++skip) {
            umbra_render_desc o = scene.options;
            o.empty_space_skipping = skip;
            umbra_renderer r =
                test_renderer(ctx, scene.volume, scene.tf, &scene.camera, &lights[l], &o);
            assert_int_equal(umbra_renderer_set_shadow(r, &shadow), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render(r, W, H, img[skip]), UMBRA_SUCCESS);
            umbra_renderer_release(r);
        }
        double worst = 0.0;
        for (size_t i = 0; i < W * H * 4; ++i)
            worst = fmax(worst, fabs((double)img[0][i] - img[1][i]));
        printf("%s, light %d: skipping on/off max |diff| %.2e\n",
               umbra_shadow_technique_name(shadow.technique), l, worst);
        assert_true(worst <= 1e-6);
    }
    umbra_scene_release(&scene);
}

/* ---- caching and memory --------------------------------------------------------------------- */

/* Camera moves re-use the map; a light change and a light transfer function change rebuild it;
 * the memory is map_size^2 * values * 4 bytes with values per texel as given (for the spheres'
 * coloured light in coloured mode, and for grey mode). */
static inline void mt_check_reuse_and_memory(umbra_context ctx, umbra_shadow_desc shadow,
                                             uint32_t values_colored, uint32_t values_grey)
{
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &scene), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(ctx, scene.volume, scene.tf, scene.light,
                                                  UMBRA_TRANSMISSION_COLORED);
    enum { W = 32, H = 32 };
    float img[W * H * 4];
    umbra_render_stats st;
    const size_t texels = (size_t)shadow.map.size * shadow.map.size;
    assert_int_equal(umbra_renderer_set_shadow(r, &shadow), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_true(st.shadow_build_ms > 0.0);
    assert_int_equal(st.shadow_memory_bytes, texels * values_colored * 4);
    assert_int_equal(st.light_channels, values_colored); /* one value per simulated channel */

    umbra_camera cam = scene.camera;
    cam.eye[0] += 10.0f;
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 0);
    assert_true(st.shadow_build_ms == 0.0);
    assert_int_equal(st.shadow_memory_bytes, texels * values_colored * 4);

    umbra_light l = scene.light;
    l.direction[0] += 0.1f;
    assert_int_equal(umbra_renderer_set_light(r, &l), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);

    umbra_transfer_function grey = mt_tf(ctx, 0.5f, 0.5f, 0.5f, 0.05f);
    assert_int_equal(umbra_renderer_set_light_transfer_function(r, grey), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_int_equal(st.light_channels, 1);
    assert_int_equal(st.shadow_memory_bytes, texels * values_grey * 4);
    assert_int_equal(umbra_renderer_set_light_transfer_function(r, NULL), UMBRA_SUCCESS);

    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_GREY;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_int_equal(st.light_channels, 1);
    assert_int_equal(st.shadow_memory_bytes, texels * values_grey * 4);
    umbra_renderer_release(r);
    umbra_transfer_function_release(grey);
    umbra_scene_release(&scene);
}

/* ---- against the reference ------------------------------------------------------------------ */

/* Renders the spheres scene (48^3, its light, camera and coloured options, with the ground
 * plane) at 96x96 with shadow and with the exact reference; returns the mean absolute error. */
static inline double mt_error_vs_reference(umbra_context ctx, umbra_shadow_desc shadow)
{
    enum { W = 96, H = 96 };
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &scene), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(ctx, scene.volume, scene.tf, scene.light,
                                   scene.options.transmission);
    assert_int_equal(umbra_renderer_set_options(r, &scene.options), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_camera(r, &scene.camera), UMBRA_SUCCESS);
    float *a = malloc(W * H * 4 * sizeof *a), *b = malloc(W * H * 4 * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    umbra_shadow_desc ref;
    umbra_shadow_desc_init(&ref);
    ref.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &ref), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, a), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_shadow(r, &shadow), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, b), UMBRA_SUCCESS);
    double e = mt_mean_abs_error(a, b, (size_t)W * H);
    free(a);
    free(b);
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    return e;
}

#endif
