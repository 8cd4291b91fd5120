// SPDX-License-Identifier: Apache-2.0
/* tests/test_clip.c: the clip region (umbra_renderer_set_clip) pinned down against the same
 * volume with the clipped region zeroed. The scene: an occluder block, an empty gap, and a
 * receiver block, lit along the line from the occluder to the receiver; the clip region (a plane
 * in the gap, or a crop box ending there) keeps the receiver's side only.
 *  - the view: with technique none the clipped image equals the zeroed volume's to 1e-6, from
 *    views through the clipped part and from the side, with jitter and a rotated volume too, and
 *    differs from the unclipped one by more than 0.1 (the occluder is seen there);
 *  - the shadow, in every technique of the registry with a per-point lookup (the light-space
 *    maps and the reference, whatever is registered): in the gap every factor is 1 with the clip
 *    (the clipped occluder casts no shadow) while it is below 0.2 unclipped; in and behind the
 *    receiver the factors equal the zeroed volume's (mean difference <= 0.01, max <= 0.1; for
 *    a stochastic map, CSSM, whose photons stop in other segments when they start at the
 *    region's face instead of the box's, mean <= 0.06, max <= 0.5: measured 0, 0 for the
 *    reference, threshold and deep maps, 0.028 and 0.31 for CSSM);
 *  - every technique's image, convolution included (lit from the viewer's side, the occluder's
 *    shadow on the ground plane): the clipped image is the zeroed one's (mean difference <=
 *    0.004) and not the unclipped one's (max difference > 0.2);
 *  - a change of the region rebuilds the shadow structure, a camera move does not, and with
 *    nothing clipped the image is the one without any clip set, bit for bit;
 *  - bad planes and boxes are refused by name and change nothing.
 * Usage: test_clip [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"
#include "umbra/registry.h"

/* The group's context (test_group_setup), also used by the helpers below. */
static umbra_context ctx;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    return rc;
}

#define NX 40
#define NY 24
#define NZ 24
/* The clip plane keeps x >= PLANE_X (world; voxel 19 of the gap [12, 26)). */
#define PLANE_X (-0.5f)

/* The scene's voxels; zeroed: the occluder (the part the clip region removes) left out. */
static float *scene_voxels(int zeroed)
{
    float *v = calloc((size_t)NX * NY * NZ, sizeof *v);
    assert_non_null(v);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x) {
                float s = 0.0f;
                if (x >= 4 && x < 12 && y >= 6 && y < 18 && z >= 6 && z < 18 && !zeroed)
                    s = 1.0f;
                if (x >= 26 && x < 34 && y >= 4 && y < 20 && z >= 4 && z < 20)
                    s = 0.6f;
                v[((size_t)z * NY + y) * NX + x] = s;
            }
    return v;
}

static umbra_volume scene_volume(int zeroed, int rotated)
{
    float *v = scene_voxels(zeroed);
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = v;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    d.brick_size = 8;
    if (rotated) {
        /* Index x along world z, y along world x, z along world -y; centred as before. */
        const float dirs[9] = {0, 0, 1, 1, 0, 0, 0, -1, 0};
        d.transform_given = 1;
        memcpy(d.directions, dirs, sizeof dirs);
        d.origin[2] = -0.5f * NX + 0.5f;
        d.origin[0] = -0.5f * NY + 0.5f;
        d.origin[1] = 0.5f * NZ - 0.5f;
    }
    umbra_volume vol = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &vol), UMBRA_SUCCESS);
    free(v);
    return vol;
}

static umbra_transfer_function scene_tf(void)
{
    const float rgba[12] = {1.0f, 1.0f, 1.0f, 0.0f, 0.9f, 0.8f, 0.6f, 0.3f, 0.7f, 0.8f, 1.0f, 0.5f};
    /* value 0: clear; 0.6 (the receiver) about 0.34 per voxel; 1 (the occluder) 0.5. */
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 3, &tf), UMBRA_SUCCESS);
    return tf;
}

/* The clip that keeps the receiver's side: the plane x >= PLANE_X (world, or along the
 * rotated volume's index x), or a crop box from voxel 19 on. */
static umbra_clip_desc scene_clip(int crop, int rotated)
{
    umbra_clip_desc c;
    umbra_clip_desc_init(&c);
    if (crop) {
        c.crop = 1;
        const float lo[3] = {19.0f, -0.5f, -0.5f}, hi[3] = {NX - 0.5f, NY - 0.5f, NZ - 0.5f};
        memcpy(c.crop_min, lo, sizeof lo);
        memcpy(c.crop_max, hi, sizeof hi);
    } else {
        c.plane_count = 1;
        /* a scaled normal: the library normalises it */
        c.planes[0][rotated ? 2 : 0] = 2.0f;
        c.planes[0][3] = -2.0f * PLANE_X;
    }
    return c;
}



static void test_clipped_view_equals_zeroed_volume(void **state)
{
    (void)state;
    umbra_transfer_function tf = scene_tf();
    const float dirs[3][3] = {{-1.0f, 0.3f, 0.2f}, {0.2f, 0.4f, 1.0f}, {1.0f, -0.2f, 0.5f}};
    for (int rotated = 0; rotated < 2; ++rotated)
        for (int crop = 0; crop < 2; ++crop)
            for (int v = 0; v < 3; ++v) {
                umbra_volume full = scene_volume(0, rotated), zero = scene_volume(1, rotated);
                umbra_render_desc o;
                umbra_render_desc_init(&o);
                o.jitter = v == 1;
                o.seed = 7;
                o.step = 0.6f;
                umbra_camera cam = umbra_camera_orbit(dirs[v], 55.0f, 30.0f);
                umbra_light light = test_directional_light(1.0f, 0.1f, 0.05f);
                umbra_renderer a = test_renderer(ctx, full, tf, &cam, &light, &o);
                umbra_renderer b = test_renderer(ctx, zero, tf, &cam, &light, &o);
                float *unclipped = test_render_image(a, 48, 40);
                umbra_clip_desc c = scene_clip(crop, rotated);
                assert_int_equal(umbra_renderer_set_clip(a, &c), UMBRA_SUCCESS);
                float *clipped = test_render_image(a, 48, 40);
                float *zeroed = test_render_image(b, 48, 40);
                const size_t n = (size_t)48 * 40 * 4;
                const float d = test_max_diff(clipped, zeroed, n, NULL);
                const float u = test_max_diff(clipped, unclipped, n, NULL);
                print_message("rotated %d crop %d view %d: clipped vs zeroed %.3g, vs unclipped "
                              "%.3g\n", rotated, crop, v, d, u);
                assert_true(d <= 1e-6f);
                assert_true(u > 0.1f);
                free(unclipped);
                free(clipped);
                free(zeroed);
                umbra_renderer_release(a);
                umbra_renderer_release(b);
                umbra_volume_release(full);
                umbra_volume_release(zero);
            }
    umbra_transfer_function_release(tf);
}

/* Query points: in the gap (lit once the occluder is clipped) and in and behind the receiver. */
#define GAP_POINTS 27
#define RECEIVER_POINTS 36
static void scene_points(float *gap, float *rec, int rotated)
{
    int g = 0, q = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                const float p[3] = {-3.0f + 3.0f * (float)i, -2.0f + 2.0f * (float)j,
                                    -2.0f + 2.0f * (float)k};
                memcpy(gap + 3 * g++, p, sizeof p);
            }
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                const float p[3] = {7.0f + 3.5f * (float)i, -2.0f + 2.0f * (float)j,
                                    -2.0f + 2.0f * (float)k};
                memcpy(rec + 3 * q++, p, sizeof p);
            }
    if (rotated) /* the same points of the volume in the rotated world: (x, y, z) -> (y, -z, x) */
        for (int n = 0; n < GAP_POINTS + RECEIVER_POINTS; ++n) {
            float *p = n < GAP_POINTS ? gap + 3 * n : rec + 3 * (n - GAP_POINTS);
            const float x = p[0], y = p[1], z = p[2];
            p[0] = y;
            p[1] = -z;
            p[2] = x;
        }
}

static void test_clipped_occluder_casts_no_shadow(void **state)
{
    (void)state;
    umbra_transfer_function tf = scene_tf();
    int checked = 0;
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        if ((ti->flags & (UMBRA_TECHNIQUE_FRAME | UMBRA_TECHNIQUE_NO_LIGHT)))
            continue; /* no per-point lookup, or no light pass */
        for (int rotated = 0; rotated < 2; ++rotated)
            for (int crop = 0; crop < 2; ++crop) {
                umbra_volume full = scene_volume(0, rotated), zero = scene_volume(1, rotated);
                umbra_light light = rotated ? test_directional_light(0.1f, -0.05f, 1.0f)
                                            : test_directional_light(1.0f, 0.1f, 0.05f);
                umbra_renderer a = test_renderer(ctx, full, tf, NULL, &light, NULL);
                umbra_renderer b = test_renderer(ctx, zero, tf, NULL, &light, NULL);
                umbra_shadow_desc sd;
                umbra_shadow_desc_init(&sd);
                sd.technique = ti->id;
                assert_int_equal(umbra_renderer_set_shadow(a, &sd), UMBRA_SUCCESS);
                assert_int_equal(umbra_renderer_set_shadow(b, &sd), UMBRA_SUCCESS);
                float gap[3 * GAP_POINTS], rec[3 * RECEIVER_POINTS];
                float g_full[3 * GAP_POINTS], g_clip[3 * GAP_POINTS];
                float r_clip[3 * RECEIVER_POINTS], r_zero[3 * RECEIVER_POINTS];
                scene_points(gap, rec, rotated);
                assert_int_equal(umbra_renderer_query_shadow(a, gap, GAP_POINTS, g_full),
                                 UMBRA_SUCCESS);
                umbra_clip_desc c = scene_clip(crop, rotated);
                assert_int_equal(umbra_renderer_set_clip(a, &c), UMBRA_SUCCESS);
                assert_int_equal(umbra_renderer_query_shadow(a, gap, GAP_POINTS, g_clip),
                                 UMBRA_SUCCESS);
                assert_int_equal(umbra_renderer_query_shadow(a, rec, RECEIVER_POINTS, r_clip),
                                 UMBRA_SUCCESS);
                assert_int_equal(umbra_renderer_query_shadow(b, rec, RECEIVER_POINTS, r_zero),
                                 UMBRA_SUCCESS);
                float lit = 1.0f, dark = 0.0f;
                for (int i = 0; i < 3 * GAP_POINTS; ++i) {
                    lit = g_clip[i] < lit ? g_clip[i] : lit;
                    dark = g_full[i] > dark ? g_full[i] : dark;
                }
                double mean;
                const float d = test_max_diff(r_clip, r_zero, 3 * RECEIVER_POINTS, &mean);
                print_message("%s rotated %d crop %d: gap lit >= %.4f clipped, <= %.3f "
                              "unclipped; receiver vs zeroed max %.3g mean %.3g\n", ti->name,
                              rotated, crop, lit, dark, d, mean);
                /* A moment map's estimate lies between bounds on the depth in front (its
                 * overestimation leaks a little shadow from the receiver behind the gap:
                 * measured 0.985, docs/moments.md); the others light the gap exactly. */
                const int moments = umbra_technique_param_find(ti, "moment_overestimation") != NULL;
                assert_true(lit >= (moments ? 0.98f : 0.999f));
                assert_true(dark <= 0.2f);
                /* A stochastic map (one with a seed: CSSM) stops its photons in other segments
                 * when they start at another face: noise of its own size. */
                const int stochastic = umbra_technique_param_find(ti, "seed") != NULL;
                assert_true(mean <= (stochastic ? 0.06 : 0.01));
                assert_true(d <= (stochastic ? 0.5f : 0.1f));
                umbra_renderer_release(a);
                umbra_renderer_release(b);
                umbra_volume_release(full);
                umbra_volume_release(zero);
                ++checked;
            }
    }
    assert_true(checked >= 4 * 4); /* reference, threshold, CSSM, deep (and any added since) */
    umbra_transfer_function_release(tf);
}

static void test_every_technique_image_clips_light_and_view(void **state)
{
    (void)state;
    umbra_transfer_function tf = scene_tf();
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        umbra_volume full = scene_volume(0, 0), zero = scene_volume(1, 0);
        umbra_render_desc o;
        umbra_render_desc_init(&o);
        o.ground_plane = 1;
        o.step = 0.5f;
        /* From the light's side (the convolution technique's condition), above. */
        umbra_camera cam;
        memset(&cam, 0, sizeof cam);
        cam.projection = UMBRA_PERSPECTIVE;
        const float eye[3] = {-62.0f, 30.0f, 20.0f}, target[3] = {4.0f, -8.0f, 0.0f};
        memcpy(cam.eye, eye, sizeof eye);
        memcpy(cam.target, target, sizeof target);
        cam.up[1] = 1.0f;
        cam.fovy_degrees = 40.0f;
        umbra_light light = test_directional_light(1.0f, -0.45f, 0.15f);
        umbra_renderer a = test_renderer(ctx, full, tf, &cam, &light, &o);
        umbra_renderer b = test_renderer(ctx, zero, tf, &cam, &light, &o);
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = ti->id;
        assert_int_equal(umbra_renderer_set_shadow(a, &sd), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_set_shadow(b, &sd), UMBRA_SUCCESS);
        float *unclipped = test_render_image(a, 64, 48);
        umbra_clip_desc c = scene_clip(0, 0);
        assert_int_equal(umbra_renderer_set_clip(a, &c), UMBRA_SUCCESS);
        float *clipped = test_render_image(a, 64, 48), *zeroed = test_render_image(b, 64, 48);
        double mean;
        const size_t n = (size_t)64 * 48 * 4;
        const float d = test_max_diff(clipped, zeroed, n, &mean);
        const float u = test_max_diff(clipped, unclipped, n, NULL);
        print_message("%s: clipped vs zeroed max %.3g mean %.3g; vs unclipped max %.3g\n",
                      ti->name, d, mean, u);
        assert_true(mean <= 0.004);
        assert_true(u > 0.2f);
        free(unclipped);
        free(clipped);
        free(zeroed);
        umbra_renderer_release(a);
        umbra_renderer_release(b);
        umbra_volume_release(full);
        umbra_volume_release(zero);
    }
    umbra_transfer_function_release(tf);
}

static void test_clip_rebuilds_and_costs_nothing_unset(void **state)
{
    (void)state;
    umbra_transfer_function tf = scene_tf();
    umbra_volume full = scene_volume(0, 0);
    umbra_light light = test_directional_light(1.0f, 0.1f, 0.05f);
    umbra_renderer r = test_renderer(ctx, full, tf, NULL, &light, NULL);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_THRESHOLD;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    umbra_render_stats st;
    float *before = test_render_image(r, 32, 32);
    /* An empty region is nothing clipped: the same image, bit for bit, no rebuild. */
    umbra_clip_desc c;
    umbra_clip_desc_init(&c);
    assert_int_equal(umbra_renderer_set_clip(r, &c), UMBRA_SUCCESS);
    float *same = test_render_image(r, 32, 32);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 0);
    assert_memory_equal(before, same, (size_t)32 * 32 * 4 * sizeof(float));
    /* A crop box covering the whole volume keeps every sample: the same image. */
    c.crop = 1;
    const float lo[3] = {-0.5f, -0.5f, -0.5f}, hi[3] = {NX - 0.5f, NY - 0.5f, NZ - 0.5f};
    memcpy(c.crop_min, lo, sizeof lo);
    memcpy(c.crop_max, hi, sizeof hi);
    assert_int_equal(umbra_renderer_set_clip(r, &c), UMBRA_SUCCESS);
    float *whole = test_render_image(r, 32, 32);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_true(test_max_diff(before, whole, (size_t)32 * 32 * 4, NULL) <= 1e-6f);
    /* The plane rebuilds the map; a camera move then reuses it. */
    c = scene_clip(0, 0);
    assert_int_equal(umbra_renderer_set_clip(r, &c), UMBRA_SUCCESS);
    free(test_render_image(r, 32, 32));
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    const float dir[3] = {0.3f, 1.0f, 0.2f};
    umbra_camera cam = umbra_camera_orbit(dir, 55.0f, 30.0f);
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    free(test_render_image(r, 32, 32));
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 0);
    /* NULL clears it: the first image again. */
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_clip(r, NULL), UMBRA_SUCCESS);
    free(before);
    free(same);
    free(whole);
    umbra_renderer_release(r);
    umbra_volume_release(full);
    umbra_transfer_function_release(tf);
}

static void test_bad_clip_refused(void **state)
{
    (void)state;
    umbra_transfer_function tf = scene_tf();
    umbra_volume vol = test_constant_volume(ctx, 4, 4, 4, 0.5f);
    umbra_light light = test_directional_light(1.0f, 0.0f, 0.0f);
    umbra_renderer r = test_renderer(ctx, vol, tf, NULL, &light, NULL);
    umbra_clip_desc c;
    umbra_clip_desc_init(&c);
    c.plane_count = 7;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "plane_count 7", "UMBRA_MAX_CLIP_PLANES");
    c.plane_count = 2;
    c.planes[0][0] = 1.0f;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "plane 1 (0, 0, 0, 0)", "non-zero normal");
    c.planes[1][1] = NAN;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "plane 1 (0, nan, 0, 0)", NULL);
    c.planes[1][1] = 1.0f;
    c.planes[1][3] = 1e30f;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "plane 1", "UMBRA_MAX_COORDINATE");
    c.planes[1][3] = 0.0f;
    c.crop = 1;
    c.crop_min[1] = 3.0f;
    c.crop_max[1] = 2.0f;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "crop box along y [3, 2]", "min <= max");
    c.crop_max[1] = INFINITY;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "crop box along y [3, inf]", NULL);
    c.crop_max[1] = 3.5f;
    c.struct_size = 8;
    test_assert_failed(ctx, umbra_renderer_set_clip(r, &c), UMBRA_ERROR_INVALID_ARGUMENT,
                       "struct_size 8", "umbra_clip_desc_init");
    c.struct_size = sizeof c;
    assert_int_equal(umbra_renderer_set_clip(r, &c), UMBRA_SUCCESS);
    float img[4 * 8 * 8];
    assert_int_equal(umbra_renderer_render(r, 8, 8, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_clip(NULL, &c), UMBRA_ERROR_INVALID_ARGUMENT);
    umbra_renderer_release(r);
    umbra_volume_release(vol);
    umbra_transfer_function_release(tf);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clipped_view_equals_zeroed_volume),
        cmocka_unit_test(test_clipped_occluder_casts_no_shadow),
        cmocka_unit_test(test_every_technique_image_clips_light_and_view),
        cmocka_unit_test(test_clip_rebuilds_and_costs_nothing_unset),
        cmocka_unit_test(test_bad_clip_refused),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
