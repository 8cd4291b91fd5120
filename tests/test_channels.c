// SPDX-License-Identifier: Apache-2.0
/* tests/test_channels.c: multi-channel volumes (umbra_volume_desc.channels,
 * umbra_renderer_set_channel_transfer_function, kernels/common/channels.cl) pinned down against
 * single-channel renders of each channel's mixture:
 *  - a channel whose transfer function is clear leaves the other channel's render as it is, in
 *    every technique that renders several channels (the same image as the single-channel volume
 *    of that channel, to 1e-6; the reference, which takes the midpoint rule for a mixture, and
 *    the deep map, which marches it without its segment table, to their own tolerance);
 *  - two channels of the same data under transfer functions A and B render as one channel under
 *    their mixture M (opacity 1 - (1 - a_A)(1 - a_B), colour and transmission colour weighted
 *    by extinction, all three tabulated finely), coloured transmission on, in every such
 *    technique: within 1e-4 (3.4e-5 measured; the reference 0.02, CSSM 0.01, see the test);
 *  - coloured shadows through each: behind a red-passing occluder of channel 0 and a
 *    green-passing one of channel 1 the shadow factor is the product of the single channels'
 *    (the extinctions add), red behind the first alone, green behind the second;
 *  - each channel keeps its own value range (its data's, or the given one) and the volume info
 *    says so; the image sampler renders the same image (the channels are one buffer there too);
 *  - refusals by name: a channel without a transfer function, pre-integration, a bad channel
 *    count or index, a label map of several channels.
 * Usage: test_channels [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
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

#define NX 32
#define NY 28
#define NZ 24
#define COUNT ((size_t)NX * NY * NZ)

/* A smooth blob (0), a block (1), or both (2), values in [0, 1]. */
static float field(int x, int y, int z, int which)
{
    if (which == 2)
        return fmaxf(field(x, y, z, 0), field(x, y, z, 1));
    if (which == 0) {
        const float dx = (float)x - 12.0f, dy = (float)y - 14.0f, dz = (float)z - 12.0f;
        const float r2 = (dx * dx + dy * dy + dz * dz) / 64.0f;
        return r2 < 1.0f ? 1.0f - r2 : 0.0f;
    }
    return (x >= 18 && x < 28 && y >= 6 && y < 22 && z >= 4 && z < 20) ? 0.8f : 0.0f;
}

/* A volume of `channels` channels whose channel c holds planes[c] (COUNT floats each). */
static umbra_volume channel_volume(umbra_context c, const float *const *planes, uint32_t channels,
                                   int range_given)
{
    float *inter = malloc(COUNT * channels * sizeof *inter);
    assert_non_null(inter);
    for (size_t i = 0; i < COUNT; ++i)
        for (uint32_t k = 0; k < channels; ++k)
            inter[i * channels + k] = planes[k][i];
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = inter;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.channels = channels;
    d.value_range_given = range_given;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    d.brick_size = 8;
    umbra_volume v = NULL;
    umbra_status st = umbra_volume_create(c, &d, &v);
    if (st != UMBRA_SUCCESS)
        fail_msg("%s", umbra_context_last_message(c));
    free(inter);
    return v;
}

static float *plane_of(int which)
{
    float *p = malloc(COUNT * sizeof *p);
    assert_non_null(p);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x)
                p[((size_t)z * NY + y) * NX + x] = field(x, y, z, which);
    return p;
}

static umbra_transfer_function make_tf(const float *rgba, uint32_t n)
{
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, n, &tf), UMBRA_SUCCESS);
    return tf;
}

/* Transfer functions A (warm, denser at high values) and B (cool, a bump in the middle). */
static const float tf_a[4 * 4] = {1.0f, 0.9f, 0.8f, 0.0f, 1.0f, 0.5f, 0.2f, 0.05f,
                                  0.9f, 0.3f, 0.1f, 0.3f, 0.8f, 0.2f, 0.1f, 0.6f};
static const float tf_b[4 * 4] = {0.2f, 0.6f, 1.0f, 0.0f, 0.3f, 0.8f, 0.9f, 0.25f,
                                  0.1f, 0.9f, 0.6f, 0.1f, 0.1f, 0.5f, 1.0f, 0.02f};
static const float tf_clear[2 * 4] = {1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f};

static void lerp_entry(const float *tf, uint32_t n, double v, double out[4])
{
    const double x = v * (n - 1);
    const uint32_t i = (uint32_t)x < n - 2 ? (uint32_t)x : n - 2;
    const double f = x - i;
    for (int c = 0; c < 4; ++c)
        out[c] = tf[4 * i + c] + (tf[4 * i + 4 + c] - tf[4 * i + c]) * f;
}

/* tf (4 entries) tabulated at n values: the view pass corrects a table's entries for its step
 * before it interpolates them (transfer_function.h), so a mixture is compared with its channels
 * at one fine resolution, where that order no longer matters. */
static float *fine_table(const float *tf, uint32_t n)
{
    float *m = malloc((size_t)n * 4 * sizeof *m);
    assert_non_null(m);
    for (uint32_t i = 0; i < n; ++i) {
        double e[4];
        lerp_entry(tf, 4, (double)i / (n - 1), e);
        for (int c = 0; c < 4; ++c)
            m[4 * i + c] = (float)e[c];
    }
    return m;
}

/* The mixture of A and B tabulated at n values (the standard rule, in double). */
static float *mixture_table(uint32_t n)
{
    float *m = malloc((size_t)n * 4 * sizeof *m);
    assert_non_null(m);
    for (uint32_t i = 0; i < n; ++i) {
        double a[4], b[4];
        lerp_entry(tf_a, 4, (double)i / (n - 1), a);
        lerp_entry(tf_b, 4, (double)i / (n - 1), b);
        const double sa = a[3] > 0 ? -log1p(-a[3]) : 0, sb = b[3] > 0 ? -log1p(-b[3]) : 0;
        for (int c = 0; c < 3; ++c)
            m[4 * i + c] = sa + sb > 0 ? (float)((sa * a[c] + sb * b[c]) / (sa + sb)) : 0.0f;
        m[4 * i + 3] = (float)(1.0 - (1.0 - a[3]) * (1.0 - b[3]));
    }
    return m;
}

static umbra_renderer channel_renderer(umbra_volume vol, umbra_transfer_function tf0,
                                       umbra_transfer_function tf1, umbra_shadow_technique t,
                                       int colored)
{
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    o.shading = 1;
    o.ground_plane = 1;
    o.step = 0.5f;
    const float dir[3] = {-0.7f, 0.5f, -1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 50.0f, 30.0f);
    /* From the viewer's side, for the convolution technique. */
    umbra_light light = test_directional_light(0.6f, -0.5f, 1.0f);
    umbra_renderer r = test_renderer(ctx, vol, tf0, &cam, &light, &o);
    if (tf1)
        assert_int_equal(umbra_renderer_set_channel_transfer_function(r, 1, tf1, NULL),
                         UMBRA_SUCCESS);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = t;
    sd.deep.lookup_table = 0; /* a mixture marches the midpoint rule: compare like with like */
    sd.reference.step = 0.25f;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    return r;
}



#define W 48
#define H 40

static void test_clear_channel_changes_nothing(void **state)
{
    (void)state;
    float *p0 = plane_of(0), *p1 = plane_of(1);
    const float *planes[2] = {p0, p1};
    umbra_volume two = channel_volume(ctx, planes, 2, 1), one = channel_volume(ctx, planes, 1, 1);
    umbra_transfer_function a = make_tf(tf_a, 4), clear = make_tf(tf_clear, 2);
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        assert_true(ti->flags & UMBRA_TECHNIQUE_CHANNELS);
        for (int colored = 0; colored < 2; ++colored) {
            umbra_renderer r2 = channel_renderer(two, a, clear, ti->id, colored);
            umbra_renderer r1 = channel_renderer(one, a, NULL, ti->id, colored);
            float *i2 = test_render_image(r2, W, H), *i1 = test_render_image(r1, W, H);
            double mean;
            const float d = test_max_diff(i1, i2, (size_t)W * H * 4, &mean);
            print_message("%s colored %d: max %.3g mean %.3g\n", ti->name, colored, d, mean);
            /* The reference integrates one channel exactly and a mixture by the midpoint rule. */
            if (ti->id == UMBRA_SHADOW_REFERENCE)
                assert_true(d <= 0.02f && mean <= 1e-3);
            else
                assert_true(d <= 1e-6f);
            free(i1);
            free(i2);
            umbra_renderer_release(r1);
            umbra_renderer_release(r2);
        }
    }
    umbra_transfer_function_release(a);
    umbra_transfer_function_release(clear);
    umbra_volume_release(one);
    umbra_volume_release(two);
    free(p0);
    free(p1);
}

static void test_same_data_renders_as_the_mixture(void **state)
{
    (void)state;
    float *p = plane_of(2); /* both fields: every part of the tables is seen */
    const float *planes[2] = {p, p};
    umbra_volume two = channel_volume(ctx, planes, 2, 1), one = channel_volume(ctx, planes, 1, 1);
    float *mix = mixture_table(4096), *fa = fine_table(tf_a, 4096), *fb = fine_table(tf_b, 4096);
    umbra_transfer_function a = make_tf(fa, 4096), b = make_tf(fb, 4096), m = make_tf(mix, 4096);
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        umbra_renderer r2 = channel_renderer(two, a, b, ti->id, 1);
        umbra_renderer r1 = channel_renderer(one, m, NULL, ti->id, 1);
        float *i2 = test_render_image(r2, W, H), *i1 = test_render_image(r1, W, H);
        double mean;
        const float d = test_max_diff(i1, i2, (size_t)W * H * 4, &mean);
        print_message("%s: two channels vs their mixture: max %.3g mean %.3g\n", ti->name, d,
                      mean);
        /* The reference integrates one channel exactly and a mixture by the midpoint rule; a
         * CSSM photon stops where the depth passes its threshold, which a last-bit difference
         * of depth can move by a segment. Measured: 2.6e-4, 1.6e-3, the rest 3.4e-5 at most. */
        const float bound = ti->id == UMBRA_SHADOW_REFERENCE ? 0.02f
                            : umbra_technique_param_find(ti, "seed") ? 0.01f
                                                                     : 1e-4f;
        assert_true(d <= bound);
        assert_true(mean <= 2e-5);
        free(i1);
        free(i2);
        umbra_renderer_release(r1);
        umbra_renderer_release(r2);
    }
    umbra_transfer_function_release(a);
    umbra_transfer_function_release(b);
    umbra_transfer_function_release(m);
    umbra_volume_release(one);
    umbra_volume_release(two);
    free(mix);
    free(fa);
    free(fb);
    free(p);
}

/* An occluder block per channel across the light's path, x in [x0, x0 + 4), the rest clear. */
static float *occluder_plane(int x0)
{
    float *p = calloc(COUNT, sizeof *p);
    assert_non_null(p);
    for (int z = 4; z < NZ - 4; ++z)
        for (int y = 4; y < NY - 4; ++y)
            for (int x = x0; x < x0 + 4; ++x)
                p[((size_t)z * NY + y) * NX + x] = 1.0f;
    return p;
}

/* The factors at n points of a renderer of volume vol with technique t, channel 0 under tf0 and
 * channel 1 (if tf1) under tf1, lit along +x, coloured transmission. */
static void factors(umbra_volume vol, umbra_transfer_function tf0, umbra_transfer_function tf1,
                    umbra_shadow_technique t, const float *points, size_t n, float *rgb)
{
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    umbra_light light = test_directional_light(1.0f, 0.05f, 0.03f);
    umbra_renderer r = test_renderer(ctx, vol, tf0, NULL, &light, &o);
    if (tf1)
        assert_int_equal(umbra_renderer_set_channel_transfer_function(r, 1, tf1, NULL),
                         UMBRA_SUCCESS);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = t;
    sd.deep.lookup_table = 0;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    if (umbra_renderer_query_shadow(r, points, n, rgb) != UMBRA_SUCCESS)
        fail_msg("query: %s", umbra_context_last_message(ctx));
    umbra_renderer_release(r);
}

static void test_coloured_shadows_through_each_channel(void **state)
{
    (void)state;
    float *red = occluder_plane(6), *green = occluder_plane(16);
    float *empty = calloc(COUNT, sizeof *empty);
    assert_non_null(empty);
    const float *both[2] = {red, green}, *only_red[2] = {red, empty}, *only_green[2] = {empty, green};
    umbra_volume v_both = channel_volume(ctx, both, 2, 1);
    umbra_volume v_red = channel_volume(ctx, only_red, 1, 1);
    umbra_volume v_green = channel_volume(ctx, &only_green[1], 1, 1);
    /* Channel 0 passes red, channel 1 green (transmission colours), each 0.4 a voxel. */
    const float t_red[8] = {0, 0, 0, 0, 1.0f, 0.2f, 0.1f, 0.4f};
    const float t_green[8] = {0, 0, 0, 0, 0.1f, 1.0f, 0.3f, 0.4f};
    umbra_transfer_function tr = make_tf(t_red, 2), tg = make_tf(t_green, 2);
    /* Points between the occluders (behind the red one) and behind both. */
    float pts[2 * 9 * 3];
    for (int k = 0; k < 9; ++k) {
        const float y = -3.0f + 3.0f * (float)(k % 3), z = -3.0f + 3.0f * (float)(k / 3);
        const float between[3] = {-2.0f, y, z}, behind[3] = {8.0f, y, z};
        memcpy(pts + 3 * k, between, sizeof between);
        memcpy(pts + 27 + 3 * k, behind, sizeof behind);
    }
    const umbra_shadow_technique techs[3] = {UMBRA_SHADOW_REFERENCE, UMBRA_SHADOW_DEEP,
                                             UMBRA_SHADOW_CSSM};
    const float tol[3] = {0.01f, 0.05f, 0.12f};
    for (int t = 0; t < 3; ++t) {
        float f_both[54], f_red[54], f_green[54];
        factors(v_both, tr, tg, techs[t], pts, 18, f_both);
        factors(v_red, tr, NULL, techs[t], pts, 18, f_red);
        factors(v_green, tg, NULL, techs[t], pts, 18, f_green);
        float worst = 0.0f;
        for (int k = 0; k < 18; ++k)
            for (int c = 0; c < 3; ++c) {
                const float want = f_red[3 * k + c] * f_green[3 * k + c];
                worst = fmaxf(worst, fabsf(f_both[3 * k + c] - want));
            }
        print_message("%s: two occluders vs the product of each alone: worst %.3g; between "
                      "(%.3f %.3f %.3f), behind (%.3f %.3f %.3f)\n",
                      umbra_shadow_technique_name(techs[t]), worst, f_both[12], f_both[13],
                      f_both[14], f_both[39], f_both[40], f_both[41]);
        assert_true(worst <= tol[t]);
        /* Behind the red-passing occluder the light is red; behind both it has lost most red
         * and green but keeps more of each than the blue neither passes. */
        assert_true(f_both[12] > 0.5f && f_both[13] < 0.35f && f_both[14] < 0.3f);
        assert_true(f_both[39] > f_both[41] && f_both[40] > f_both[41]);
        assert_true(f_both[39] < f_both[12] && f_both[40] > f_both[13] * 0.1f);
    }
    umbra_transfer_function_release(tr);
    umbra_transfer_function_release(tg);
    umbra_volume_release(v_both);
    umbra_volume_release(v_red);
    umbra_volume_release(v_green);
    free(red);
    free(green);
    free(empty);
}

static void test_channel_ranges_and_image_sampler(void **state)
{
    (void)state;
    /* Channel 1 in [100, 300]: its own range without a given one. */
    float *p0 = plane_of(0), *p1 = plane_of(1);
    float *p1s = malloc(COUNT * sizeof *p1s);
    assert_non_null(p1s);
    for (size_t i = 0; i < COUNT; ++i)
        p1s[i] = 100.0f + 250.0f * p1[i];
    const float *planes[2] = {p0, p1s};
    umbra_volume v = channel_volume(ctx, planes, 2, 0);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.channels, 2);
    assert_int_equal(info.labels, 0);
    assert_float_equal(info.channel_min[0], 0.0f, 0.0f);
    assert_float_equal(info.channel_max[0], 1.0f, 1e-6f);
    assert_float_equal(info.channel_min[1], 100.0f, 0.0f);
    assert_float_equal(info.channel_max[1], 300.0f, 0.0f);
    assert_float_equal(info.value_min, info.channel_min[0], 0.0f);
    /* The same render on a context of the image sampler (the channels stay one buffer). */
    umbra_transfer_function a = make_tf(tf_a, 4), b = make_tf(tf_b, 4);
    umbra_renderer r = channel_renderer(v, a, b, UMBRA_SHADOW_THRESHOLD, 0);
    float *img = test_render_image(r, W, H);
    umbra_context_desc cd;
    umbra_context_desc_init(&cd);
    cd.sampler = UMBRA_SAMPLER_IMAGE;
    umbra_context ictx = NULL;
    assert_int_equal(umbra_context_create(&cd, &ictx), UMBRA_SUCCESS);
    umbra_volume iv = channel_volume(ictx, planes, 2, 0);
    umbra_transfer_function ia = NULL, ib = NULL;
    assert_int_equal(umbra_transfer_function_create(ictx, tf_a, 4, &ia), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_create(ictx, tf_b, 4, &ib), UMBRA_SUCCESS);
    umbra_renderer ir = NULL;
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    o.ground_plane = 1;
    const float dir[3] = {-0.7f, 0.5f, -1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 50.0f, 30.0f);
    umbra_light light = test_directional_light(0.6f, -0.5f, 1.0f);
    assert_int_equal(umbra_renderer_create(ictx, &ir), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_volume(ir, iv), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_transfer_function(ir, ia), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_channel_transfer_function(ir, 1, ib, NULL),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_camera(ir, &cam), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_light(ir, &light), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_options(ir, &o), UMBRA_SUCCESS);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_THRESHOLD;
    assert_int_equal(umbra_renderer_set_shadow(ir, &sd), UMBRA_SUCCESS);
    float *iimg = malloc((size_t)W * H * 4 * sizeof *iimg);
    assert_non_null(iimg);
    assert_int_equal(umbra_renderer_render(ir, W, H, iimg), UMBRA_SUCCESS);
    assert_true(test_max_diff(img, iimg, (size_t)W * H * 4, NULL) <= 1e-6f);
    free(img);
    free(iimg);
    umbra_renderer_release(ir);
    umbra_renderer_release(r);
    umbra_transfer_function_release(ia);
    umbra_transfer_function_release(ib);
    umbra_transfer_function_release(a);
    umbra_transfer_function_release(b);
    umbra_volume_release(iv);
    umbra_volume_release(v);
    umbra_context_release(ictx);
    free(p0);
    free(p1);
    free(p1s);
}

static void test_channel_refusals(void **state)
{
    (void)state;
    float *p0 = plane_of(0);
    const float *planes[3] = {p0, p0, p0};
    umbra_volume v = channel_volume(ctx, planes, 3, 1);
    umbra_transfer_function a = make_tf(tf_a, 4);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_renderer r = test_renderer(ctx, v, a, NULL, &light, NULL);
    float img[4 * 8 * 8];
    assert_int_equal(umbra_renderer_set_channel_transfer_function(r, 1, a, NULL), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render(r, 8, 8, img), UMBRA_ERROR_INVALID_ARGUMENT,
                       "channel 2 has no transfer function", NULL);
    assert_int_equal(umbra_renderer_set_channel_transfer_function(r, 2, a, a), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 8, 8, img), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_set_channel_transfer_function(r, 4, a, NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "channel 4 must lie in [0, 4)", NULL);
    test_assert_failed(ctx, umbra_renderer_set_channel_transfer_function(r, 1, NULL, NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "tf of channel 1 is NULL", NULL);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.preintegrated = 1;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render(r, 8, 8, img), UMBRA_ERROR_INVALID_ARGUMENT,
                       "pre-integrated", "multi-channel volume");
    umbra_renderer_release(r);
    umbra_volume_release(v);
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = p0;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = 4;
    d.channels = 5;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "channels 5 must lie in [1, 4]", NULL);
    d.channels = 0;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "channels 0", NULL);
    d.channels = 2;
    d.labels = 1;
    d.type = UMBRA_UINT8;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "a label map has one channel", "2 channels");
    /* A NaN in channel 1 is named with its channel. */
    float nan_data[2 * 8];
    for (int i = 0; i < 16; ++i)
        nan_data[i] = 0.5f;
    nan_data[2 * 5 + 1] = NAN;
    d.labels = 0;
    d.type = UMBRA_FLOAT32;
    d.data = nan_data;
    d.dims[0] = d.dims[1] = d.dims[2] = 2;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "voxel 5 is nan", "channel 1");
    /* umbra 0.5's layout, without channels, still makes a plain volume. */
    d.struct_size = offsetof(umbra_volume_desc, channels);
    d.data = p0;
    d.dims[0] = d.dims[1] = d.dims[2] = 4;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.channels, 1);
    umbra_volume_release(v);
    umbra_transfer_function_release(a);
    free(p0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clear_channel_changes_nothing),
        cmocka_unit_test(test_same_data_renders_as_the_mixture),
        cmocka_unit_test(test_coloured_shadows_through_each_channel),
        cmocka_unit_test(test_channel_ranges_and_image_sampler),
        cmocka_unit_test(test_channel_refusals),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
