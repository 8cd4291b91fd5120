// SPDX-License-Identifier: Apache-2.0
/* tests/test_rebuild.c: a shadow structure rebuilt after a light or transfer-function change is
 * the one a fresh renderer builds. An interactive session changes the light or the opacity every
 * frame and each light-space technique rebuilds its map into the buffers, kernels and tables it
 * kept (a map buffer re-used or re-sized when the auto size changes, the deep map's block pool
 * grown or re-used, its segment table rebuilt or kept, the light tables re-made); none of that
 * may leave a trace in the image. For threshold, CSSM, deep (blocked, with and without its
 * segment table) and deep with a node budget:
 *  - a renderer that rendered under light L1 then renders under L2, whose auto map size differs,
 *    and the image equals, bit for bit, that of a fresh renderer under L2;
 *  - then a new transfer function (more opaque), and the image equals a fresh renderer's with it;
 *  - then back to L1 and the first transfer function, equal to the first image.
 * Usage: test_rebuild [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

enum { NX = 40, NY = 32, NZ = 36, W = 48, H = 40 };

static umbra_context ctx;
static umbra_volume volume;
static umbra_transfer_function tf_a, tf_b;

/* Two soft balls of different density and a thin slab under them: partial shadows in colour. */
static float scene_value(float x, float y, float z)
{
    float d1 = sqrtf((x - 14.0f) * (x - 14.0f) + (y - 20.0f) * (y - 20.0f) +
                     (z - 15.0f) * (z - 15.0f)) - 7.0f;
    float d2 = sqrtf((x - 27.0f) * (x - 27.0f) + (y - 17.0f) * (y - 17.0f) +
                     (z - 22.0f) * (z - 22.0f)) - 5.0f;
    float v = fmaxf(0.6f * fminf(1.0f, fmaxf(0.0f, 0.5f - d1)),
                    0.9f * fminf(1.0f, fmaxf(0.0f, 0.5f - d2)));
    if (y > 5.0f && y < 7.0f)
        v = fmaxf(v, 0.35f);
    return v;
}

static int setup(void **state)
{
    (void)state;
    ctx = test_context();
    if (!ctx)
        return -1;
    float *data = malloc((size_t)NX * NY * NZ * sizeof *data);
    if (!data)
        return -1;
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x)
                data[((size_t)z * NY + y) * NX + x] = scene_value(x + 0.5f, y + 0.5f, z + 0.5f);
    volume = test_volume(ctx, NX, NY, NZ, data);
    free(data);
    const float a[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.08f, 0.3f, 0.8f, 0.4f, 0.2f,
                         0.7f, 0.7f, 0.9f, 0.5f};
    const float b[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.15f, 0.3f, 0.8f, 0.4f, 0.4f,
                         0.7f, 0.7f, 0.9f, 0.8f};
    if (umbra_transfer_function_create(ctx, a, 4, &tf_a) != UMBRA_SUCCESS ||
        umbra_transfer_function_create(ctx, b, 4, &tf_b) != UMBRA_SUCCESS)
        return -1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    umbra_transfer_function_release(tf_a);
    umbra_transfer_function_release(tf_b);
    umbra_volume_release(volume);
    umbra_context_release(ctx);
    return 0;
}

/* A renderer on the scene with the given shadow, light and transfer function. */
static umbra_renderer make(const umbra_shadow_desc *sd, const umbra_light *light,
                           umbra_transfer_function tf)
{
    const float dir[3] = {0.5f, 0.4f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 62.0f, 30.0f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    o.ground_plane = 1;
    umbra_renderer r = test_renderer(ctx, volume, tf, &cam, light, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, sd), UMBRA_SUCCESS);
    return r;
}

static void render(umbra_renderer r, float *img, uint32_t *map_size)
{
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_true(st.shadow_rebuilt);
    if (map_size)
        *map_size = st.map_size;
}

/* The first pixel (and channel) where a and b differ, or -1. */
static long first_difference(const float *a, const float *b)
{
    for (long i = 0; i < (long)W * H * 4; ++i)
        if (memcmp(&a[i], &b[i], sizeof a[i]) != 0)
            return i;
    return -1;
}

static void expect_same(const float *got, const float *want, const char *what, const char *tech)
{
    long i = first_difference(got, want);
    if (i >= 0)
        fail_msg("%s: %s: pixel (%ld, %ld) channel %ld is %.9g after the rebuild, %.9g from a "
                 "fresh renderer", tech, what, i / 4 % W, i / 4 / W, i % 4, got[i], want[i]);
}

/* The session (L1, then L2, then a new tf, then back) against fresh renderers. */
static void check_technique(const umbra_shadow_desc *sd, const char *tech)
{
    static float img[4][W * H * 4], fresh[W * H * 4];
    /* A point light outside the box (a perspective map), then one inside it in empty space (an
     * octahedral map over all directions): the auto map size and the projection change. */
    const umbra_light l1 = test_point_light(-40.0f, 70.0f, 30.0f);
    const umbra_light l2 = test_point_light(8.0f, 12.0f, -12.0f);
    uint32_t size1 = 0, size2 = 0, size_fresh = 0;
    umbra_renderer r = make(sd, &l1, tf_a);
    render(r, img[0], &size1);
    assert_int_equal(umbra_renderer_set_light(r, &l2), UMBRA_SUCCESS);
    render(r, img[1], &size2);
    if (sd->map.size == UMBRA_MAP_SIZE_AUTO && size1 == size2)
        fail_msg("%s: the auto map size did not change with the light (%u)", tech, size1);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf_b), UMBRA_SUCCESS);
    render(r, img[2], NULL);
    assert_int_equal(umbra_renderer_set_light(r, &l1), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf_a), UMBRA_SUCCESS);
    render(r, img[3], NULL);
    umbra_renderer_release(r);

    umbra_renderer f = make(sd, &l2, tf_a);
    render(f, fresh, &size_fresh);
    assert_int_equal(size_fresh, size2);
    expect_same(img[1], fresh, "light L1 -> L2", tech);
    umbra_renderer_release(f);
    f = make(sd, &l2, tf_b);
    render(f, fresh, NULL);
    expect_same(img[2], fresh, "then a new transfer function", tech);
    umbra_renderer_release(f);
    expect_same(img[3], img[0], "back to L1 and the first transfer function", tech);
    /* The light move changed the image: the comparisons above compare shadows. */
    assert_true(first_difference(img[0], img[1]) >= 0);
}

static void test_rebuild_threshold_equals_fresh(void **state)
{
    (void)state;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_THRESHOLD;
    sd.threshold.taps = 7;
    check_technique(&sd, "threshold");
}

static void test_rebuild_cssm_equals_fresh(void **state)
{
    (void)state;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_CSSM;
    check_technique(&sd, "cssm");
}

static void test_rebuild_deep_equals_fresh(void **state)
{
    (void)state;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_DEEP;
    check_technique(&sd, "deep");
    sd.deep.lookup_table = 0;
    sd.deep.prefilter = 5;
    check_technique(&sd, "deep, no segment table, 5 sub-rays");
}

static void test_rebuild_deep_budget_equals_fresh(void **state)
{
    (void)state;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_DEEP;
    sd.deep.max_nodes = 4;
    check_technique(&sd, "deep, 4 nodes");
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rebuild_threshold_equals_fresh),
        cmocka_unit_test(test_rebuild_cssm_equals_fresh),
        cmocka_unit_test(test_rebuild_deep_equals_fresh),
        cmocka_unit_test(test_rebuild_deep_budget_equals_fresh),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, teardown);
}
