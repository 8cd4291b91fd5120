// SPDX-License-Identifier: Apache-2.0
/* tests/test_labels.c: label maps (umbra_volume_desc.labels, kernels/common/channels.cl) pinned
 * down:
 *  - nearest sampling and exact label colours: an orthographic view down the columns of a
 *    uint8 label map whose labels are opaque shows, in every pixel and bit for bit, the colour of
 *    the first labelled voxel of the column nearest the pixel (no blend of two labels' colours
 *    where they meet, as interpolating labels would make), with and without empty-space
 *    skipping; labels at or past the table's end are transparent; a uint16 map with labels up to
 *    999 likewise;
 *  - shading: an opaque label's face seen along the light shades as a surface facing it (the
 *    gradient of the interpolated label opacity): colour kd c + ks;
 *  - shadows from label opacities: behind an occluder label of opacity 0.4 per voxel, 4 voxels
 *    thick, the reference gives 0.6^(4 (1 - t)) per colour channel (coloured transmission); the
 *    deep map and CSSM agree with it, the threshold map is dark there and lit in front;
 *  - refusals by name: float or int16 labels, a label map of several channels.
 * Usage: test_labels [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

/* The group's context (test_group_setup), also used by the helpers below. */
static umbra_context ctx;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    return rc;
}

#define NX 12
#define NY 10
#define NZ 8

/* Labels: 1 in x 2..5, 2 in x 6..9 (z up to 5), 5 a cube in front of both, 200 (past the
 * table) in front of part of label 1, 0 elsewhere. */
static unsigned label_at(int x, int y, int z)
{
    if (x >= 3 && x <= 4 && y >= 3 && y <= 4 && z >= 6)
        return 200;
    if (x >= 7 && x <= 8 && y >= 6 && y <= 8 && z >= 6)
        return 5;
    if (y >= 1 && y <= 8 && z <= 5) {
        if (x >= 2 && x <= 5)
            return 1;
        if (x >= 6 && x <= 9)
            return 2;
    }
    return 0;
}

static const float label_rgba[6 * 4] = {0, 0, 0, 0,   1, 0, 0, 1,   0, 1, 0, 1,
                                        1, 1, 1, 1,   1, 1, 1, 1,   0, 0, 1, 1};

static umbra_volume label_volume(umbra_scalar_type type, unsigned scale)
{
    const size_t n = (size_t)NX * NY * NZ;
    uint16_t *v16 = malloc(n * sizeof *v16);
    uint8_t *v8 = malloc(n);
    assert_non_null(v16);
    assert_non_null(v8);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x) {
                const unsigned l = label_at(x, y, z);
                const size_t i = ((size_t)z * NY + y) * NX + x;
                v8[i] = (uint8_t)l;
                v16[i] = (uint16_t)(l == 200 ? 65000 : l * scale);
            }
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = type == UMBRA_UINT8 ? (const void *)v8 : (const void *)v16;
    d.type = type;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.labels = 1;
    d.brick_size = 4;
    umbra_volume vol = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &vol), UMBRA_SUCCESS);
    free(v8);
    free(v16);
    return vol;
}

/* Looking down -z onto the label map, two pixels a voxel; ambient 0, white light, no shading:
 * an opaque sample's pixel is its colour exactly. */
static umbra_renderer view_renderer(umbra_volume vol, umbra_transfer_function tf, int skip,
                                    int shading)
{
    umbra_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.projection = UMBRA_ORTHOGRAPHIC;
    cam.eye[2] = 50.0f;
    cam.up[1] = 1.0f;
    cam.ortho_height = (float)NY;
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.ambient[0] = o.ambient[1] = o.ambient[2] = 0.0f;
    o.step = 0.3f;
    o.empty_space_skipping = skip;
    o.shading = shading;
    o.background[0] = o.background[1] = o.background[2] = 0.25f;
    o.background[3] = 1.0f;
    umbra_light light = test_directional_light(0.0f, 0.0f, -1.0f);
    return test_renderer(ctx, vol, tf, &cam, &light, &o);
}

static void check_label_view(umbra_volume vol, umbra_transfer_function tf, unsigned scale)
{
    const uint32_t w = 2 * NX, h = 2 * NY;
    for (int skip = 0; skip < 2; ++skip) {
        umbra_renderer r = view_renderer(vol, tf, skip, 0);
        float img[4 * 2 * NX * 2 * NY];
        assert_int_equal(umbra_renderer_render(r, w, h, img), UMBRA_SUCCESS);
        for (uint32_t py = 0; py < h; ++py)
            for (uint32_t px = 0; px < w; ++px) {
                /* The pixel's centre in voxel coordinates; its nearest column. */
                const int x = (int)lroundf(((float)px + 0.5f) * 0.5f - 0.5f);
                const int y = (int)lroundf((float)NY - ((float)py + 0.5f) * 0.5f - 0.5f);
                float want[4] = {0.25f, 0.25f, 0.25f, 1.0f};
                for (int z = NZ - 1; z >= 0; --z) {
                    const unsigned l = label_at(x, y, z) * (label_at(x, y, z) == 200 ? 1 : scale);
                    if (l / scale < 6 && l % scale == 0 && label_rgba[4 * (l / scale) + 3] > 0.0f) {
                        memcpy(want, label_rgba + 4 * (l / scale), sizeof want);
                        break;
                    }
                }
                const float *got = img + 4 * ((size_t)py * w + px);
                if (memcmp(got, want, sizeof want) != 0)
                    fail_msg("skip %d pixel (%u, %u), column (%d, %d): (%g, %g, %g, %g), want "
                             "(%g, %g, %g, %g)", skip, px, py, x, y, got[0], got[1], got[2],
                             got[3], want[0], want[1], want[2], want[3]);
            }
        umbra_renderer_release(r);
    }
}

static void test_nearest_labels_show_exact_colours(void **state)
{
    (void)state;
    umbra_volume vol = label_volume(UMBRA_UINT8, 1);
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, label_rgba, 6, &tf), UMBRA_SUCCESS);
    check_label_view(vol, tf, 1);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_true(info.labels);
    assert_float_equal(info.value_max, 200.0f, 0.0f);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);

    /* uint16 labels 0, 200, 400, 1000 (and 65000 past the table): the table has 1001 entries. */
    vol = label_volume(UMBRA_UINT16, 200);
    float *big = calloc(1001 * 4, sizeof *big);
    assert_non_null(big);
    for (int l = 0; l < 6; ++l)
        memcpy(big + 4 * 200 * l, label_rgba + 4 * l, 4 * sizeof *big);
    for (int l = 1; l < 1001; ++l)
        if (l % 200) /* labels no voxel has: opaque, so that any blend would show */
            big[4 * l + 3] = 1.0f;
    assert_int_equal(umbra_transfer_function_create(ctx, big, 1001, &tf), UMBRA_SUCCESS);
    check_label_view(vol, tf, 200);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
    free(big);
}

static void test_labels_shade_as_surfaces(void **state)
{
    (void)state;
    umbra_volume vol = label_volume(UMBRA_UINT8, 1);
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, label_rgba, 6, &tf), UMBRA_SUCCESS);
    umbra_renderer r = view_renderer(vol, tf, 1, 1);
    float img[4 * 2 * NX * 2 * NY];
    assert_int_equal(umbra_renderer_render(r, 2 * NX, 2 * NY, img), UMBRA_SUCCESS);
    /* Inside label 1's top face (column (3.75, 6.25): z 5 under empty voxels) and label 2's
     * (7.75, 3.25), at least a voxel from every side face, so that the gradient's stencil sees
     * the top face alone. */
    const int pixels[2][2] = {{8, 6}, {16, 12}};
    const float kd = 0.8f, ks = 0.3f;
    for (int k = 0; k < 2; ++k) {
        const float *got = img + 4 * ((size_t)pixels[k][1] * 2 * NX + pixels[k][0]);
        const float *c = label_rgba + 4 * (k + 1);
        for (int i = 0; i < 3; ++i)
            assert_float_equal(got[i], kd * c[i] + ks, 1e-5f);
        assert_float_equal(got[3], 1.0f, 0.0f);
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_label_opacities_cast_shadows(void **state)
{
    (void)state;
    /* Label 3 fills x 2..5 (4 voxels), 1 a receiver at x 9..10; lit along +x. */
    enum { SX = 16, SY = 12, SZ = 12 };
    uint8_t *v = calloc((size_t)SX * SY * SZ, 1);
    assert_non_null(v);
    for (int z = 2; z < SZ - 2; ++z)
        for (int y = 2; y < SY - 2; ++y) {
            for (int x = 2; x <= 5; ++x)
                v[((size_t)z * SY + y) * SX + x] = 3;
            for (int x = 9; x <= 10; ++x)
                v[((size_t)z * SY + y) * SX + x] = 1;
        }
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = v;
    d.dims[0] = SX;
    d.dims[1] = SY;
    d.dims[2] = SZ;
    d.labels = 1;
    d.brick_size = 4;
    umbra_volume vol = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &vol), UMBRA_SUCCESS);
    const float table[4 * 4] = {0, 0, 0, 0, 0.5f, 0.5f, 0.5f, 0.3f, 0, 0, 0, 0,
                                1.0f, 0.5f, 0.0f, 0.4f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, table, 4, &tf), UMBRA_SUCCESS);
    /* Points at voxel centres x = 7 (between) and 1 (in front), y, z inside the occluder's
     * extent: voxel (i, j, k)'s centre is at (i + 0.5 - dims / 2). */
    float pts[2 * 9 * 3];
    for (int k = 0; k < 9; ++k) {
        const float y = (float)(3 + 2 * (k % 3)) + 0.5f - SY / 2.0f;
        const float z = (float)(3 + 2 * (k / 3)) + 0.5f - SZ / 2.0f;
        const float behind[3] = {7.5f - SX / 2.0f, y, z}, front[3] = {1.5f - SX / 2.0f, y, z};
        memcpy(pts + 3 * k, behind, sizeof behind);
        memcpy(pts + 27 + 3 * k, front, sizeof front);
    }
    const double want[3] = {pow(0.6, 0.0), pow(0.6, 4.0 * 0.5), pow(0.6, 4.0)};
    const umbra_shadow_technique techs[4] = {UMBRA_SHADOW_REFERENCE, UMBRA_SHADOW_DEEP,
                                             UMBRA_SHADOW_CSSM, UMBRA_SHADOW_THRESHOLD};
    /* CSSM: per point a fraction of 13 binary taps, whose mean over the 9 points is held to
     * the bound (one point's spread is about 0.13). */
    const float tol[3] = {1e-4f, 0.03f, 0.06f};
    for (int t = 0; t < 4; ++t) {
        umbra_render_desc o;
        umbra_render_desc_init(&o);
        o.transmission = UMBRA_TRANSMISSION_COLORED;
        umbra_light light = test_directional_light(1.0f, 0.0f, 0.0f);
        umbra_renderer r = test_renderer(ctx, vol, tf, NULL, &light, &o);
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = techs[t];
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        float f[54];
        assert_int_equal(umbra_renderer_query_shadow(r, pts, 18, f), UMBRA_SUCCESS);
        print_message("%s: behind (%.4f %.4f %.4f), in front (%.3f %.3f %.3f)\n",
                      umbra_shadow_technique_name(techs[t]), f[12], f[13], f[14], f[39], f[40],
                      f[41]);
        for (int c = 0; c < 3; ++c) {
            double mean = 0.0;
            for (int k = 0; k < 9; ++k) {
                const float behind = f[3 * k + c], front = f[27 + 3 * k + c];
                if (techs[t] == UMBRA_SHADOW_THRESHOLD) /* grey and binary: dark behind */
                    assert_float_equal(behind, 0.0f, 0.0f);
                else if (techs[t] != UMBRA_SHADOW_CSSM)
                    assert_float_equal(behind, (float)want[c], tol[t]);
                mean += behind / 9.0;
                assert_float_equal(front, 1.0f, 1e-6f);
            }
            if (techs[t] == UMBRA_SHADOW_CSSM)
                assert_float_equal((float)mean, (float)want[c], tol[2]);
        }
        umbra_renderer_release(r);
    }
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
    free(v);
}

static void test_label_refusals(void **state)
{
    (void)state;
    const float f[8] = {0, 1, 2, 3, 0, 1, 2, 3};
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = f;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = 2;
    d.labels = 1;
    umbra_volume v = NULL;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "a label map has one channel of uint8 or uint16 labels", "scalar type 3");
    d.type = UMBRA_INT16;
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "uint8 or uint16", "scalar type 2");
    assert_null(v);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nearest_labels_show_exact_colours),
        cmocka_unit_test(test_labels_shade_as_surfaces),
        cmocka_unit_test(test_label_opacities_cast_shadows),
        cmocka_unit_test(test_label_refusals),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
