// SPDX-License-Identifier: Apache-2.0
/* tests/test_world.c: volumes in the application's world, transfer functions in data units.
 *
 * - A volume with an index-to-world transform (translated, turned by 90-degree rotations, with and
 *   without a mirror, anisotropic spacing) renders what the same voxels, permuted into the default
 *   centred frame, render from the correspondingly translated camera and light: 90-degree turns
 *   resample exactly, so the two images may differ only by float rounding. The ground plane stays
 *   horizontal in the world, which in the rotated volume's own frame is no longer y = const.
 * - query_shadow at world points inside a rotated (by an arbitrary angle), translated, anisotropic
 *   homogeneous box matches exp(-sigma d), d the path to the light computed in double.
 * - Transforms the library cannot honour (sheared axes) or that make no sense are refused with a
 *   message; the volume info reports origin, directions and world centre.
 * - A transfer function over a data range renders, in every technique, like the equivalent table
 *   over the volume's normalised range, including data values beyond the function's range. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "internal.h"
#include "test_util.h"

/* A float32 volume from data with the given spacing, value range [lo, hi] and, with origin and
 * dirs, that index-to-world transform. */
static umbra_volume make_volume(umbra_context ctx, const uint32_t dims[3], const float spacing[3],
                                const float *data, float lo, float hi, const float *origin,
                                const float *dirs)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    memcpy(d.dims, dims, sizeof d.dims);
    memcpy(d.spacing, spacing, sizeof d.spacing);
    d.value_range_given = 1;
    d.value_min = lo;
    d.value_max = hi;
    d.brick_size = 8;
    if (origin) {
        d.transform_given = 1;
        memcpy(d.origin, origin, sizeof d.origin);
        memcpy(d.directions, dirs, sizeof d.directions);
    }
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    return v;
}

static double max_abs_diff(const float *a, const float *b, size_t n, double *mean)
{
    double worst = 0.0, sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double e = fabs((double)a[i] - (double)b[i]);
        worst = fmax(worst, e);
        sum += e;
    }
    if (mean)
        *mean = sum / (double)n;
    return worst;
}

static void set_technique(umbra_renderer r, umbra_shadow_technique t)
{
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = t;
    s.map.size = 128;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
}

enum { W = 40, H = 40 };

/* ---- a turned volume renders as its permuted copy --------------------------------------------- */

/* Index axis a of the turned volume runs along world axis perm[a] with sign sign[a]. */
typedef struct turn {
    int perm[3], sign[3];
    const char *name;
} turn;

static void check_turn(umbra_context ctx, const turn *T)
{
    const uint32_t da[3] = {14, 10, 8};
    const float sa[3] = {1.0f, 0.5f, 1.5f};
    const float origin[3] = {40.0f, -7.0f, 13.0f};
    const size_t n = (size_t)da[0] * da[1] * da[2];
    float *va = malloc(n * sizeof *va), *vb = malloc(n * sizeof *vb);
    assert_non_null(va);
    assert_non_null(vb);
    uint32_t db[3];
    float sb[3], dirs[9] = {0};
    for (int a = 0; a < 3; ++a) {
        db[T->perm[a]] = da[a];
        sb[T->perm[a]] = sa[a];
        dirs[3 * a + T->perm[a]] = (float)T->sign[a];
    }
    /* Two blobs off every symmetry plane, so that a wrong axis or sign shows. */
    for (uint32_t k = 0; k < da[2]; ++k)
        for (uint32_t j = 0; j < da[1]; ++j)
            for (uint32_t i = 0; i < da[0]; ++i) {
                const double x = i * sa[0], y = j * sa[1], z = k * sa[2];
                double v = exp(-((x - 4.0) * (x - 4.0) + (y - 2.5) * (y - 2.5) + (z - 4.0) * (z - 4.0)) / 6.0) +
                           0.8 * exp(-((x - 10.0) * (x - 10.0) + (y - 3.0) * (y - 3.0) + (z - 8.0) * (z - 8.0)) / 3.0);
                const uint32_t idx[3] = {i, j, k};
                uint32_t jb[3];
                for (int a = 0; a < 3; ++a)
                    jb[T->perm[a]] = T->sign[a] > 0 ? idx[a] : da[a] - 1 - idx[a];
                va[((size_t)k * da[1] + j) * da[0] + i] = (float)v;
                vb[((size_t)jb[2] * db[1] + jb[1]) * db[0] + jb[0]] = (float)v;
            }
    umbra_volume A = make_volume(ctx, da, sa, va, 0.0f, 1.0f, origin, dirs);
    umbra_volume B = make_volume(ctx, db, sb, vb, 0.0f, 1.0f, NULL, NULL);
    /* World of A's voxel 0 minus world of B's voxel it became: B's world is A's moved by -t. */
    double t[3];
    for (int k = 0; k < 3; ++k)
        t[k] = origin[k];
    for (int a = 0; a < 3; ++a) {
        int k = T->perm[a];
        double jb0 = T->sign[a] > 0 ? 0.0 : (double)da[a] - 1.0;
        t[k] -= (jb0 + 0.5 - 0.5 * db[k]) * sb[k];
    }
    const float tf_rgba[12] = {0.2f, 0.3f, 0.9f, 0.0f, 0.9f, 0.6f, 0.3f, 0.15f,
                               1.0f, 1.0f, 0.8f, 0.6f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, tf_rgba, 3, &tf), UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    o.ground_plane = 1;
    o.background[3] = 1.0f;
    float *ia = malloc(4 * W * H * sizeof *ia), *ib = malloc(4 * W * H * sizeof *ib);
    assert_non_null(ia);
    assert_non_null(ib);

    /* 1. The default camera (framing the box's world centre) and a light from the viewer's side,
     * so that the convolution technique applies too. */
    umbra_light light = test_directional_light(-0.5f, -0.6f, -1.0f);
    umbra_renderer ra = test_renderer(ctx, A, tf, NULL, &light, &o);
    umbra_renderer rb = test_renderer(ctx, B, tf, NULL, &light, &o);
    /* Under 90-degree turns the threshold and deep maps' texels land on the same world points
     * in both frames, so these agree up to rounding too. */
    static const umbra_shadow_technique exact[] = {UMBRA_SHADOW_NONE, UMBRA_SHADOW_REFERENCE,
                                                   UMBRA_SHADOW_CONVOLUTION, UMBRA_SHADOW_THRESHOLD,
                                                   UMBRA_SHADOW_DEEP};
    for (size_t e = 0; e < sizeof exact / sizeof exact[0]; ++e) {
        set_technique(ra, exact[e]);
        set_technique(rb, exact[e]);
        assert_int_equal(umbra_renderer_render(ra, W, H, ia), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
        double mean, worst = max_abs_diff(ia, ib, 4 * W * H, &mean);
        print_message("  %s, default camera, %s: max |diff| %.2e, mean %.2e\n", T->name,
                      umbra_shadow_technique_name(exact[e]), worst, mean);
        if (worst > 2e-3)
            fail_msg("%s, %s: turned volume and permuted copy differ by %g", T->name,
                     umbra_shadow_technique_name(exact[e]), worst);
    }
    /* CSSM's random sample pattern is laid out in its map, whose axes are picked in each
     * volume's own frame: the two maps see different (equally valid) noise. */
    static const umbra_shadow_technique maps[] = {UMBRA_SHADOW_CSSM};
    for (size_t e = 0; e < sizeof maps / sizeof maps[0]; ++e) {
        set_technique(ra, maps[e]);
        set_technique(rb, maps[e]);
        assert_int_equal(umbra_renderer_render(ra, W, H, ia), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
        double mean, worst = max_abs_diff(ia, ib, 4 * W * H, &mean);
        print_message("  %s, default camera, %s: max |diff| %.2e, mean %.2e\n", T->name,
                      umbra_shadow_technique_name(maps[e]), worst, mean);
        if (mean > 1e-2)
            fail_msg("%s, %s: turned volume and permuted copy differ by %g on average", T->name,
                     umbra_shadow_technique_name(maps[e]), mean);
    }
    umbra_renderer_release(ra);
    umbra_renderer_release(rb);

    /* 2. An explicit camera and a point light, both given in A's world and moved by -t for B. */
    umbra_camera ca;
    memset(&ca, 0, sizeof ca);
    ca.projection = UMBRA_PERSPECTIVE;
    ca.fovy_degrees = 35.0f;
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(A, &info), UMBRA_SUCCESS);
    const float off[3] = {-6.0f, 40.0f, 25.0f};
    for (int k = 0; k < 3; ++k) {
        ca.target[k] = info.center[k];
        ca.eye[k] = info.center[k] + off[k];
    }
    ca.up[1] = 1.0f;
    umbra_camera cb = ca;
    umbra_light la = test_point_light(20.0f, 25.0f, 30.0f), lb = la;
    for (int k = 0; k < 3; ++k) {
        cb.eye[k] = (float)(ca.eye[k] - t[k]);
        cb.target[k] = (float)(ca.target[k] - t[k]);
        lb.position[k] = (float)(la.position[k] - t[k]);
    }
    ra = test_renderer(ctx, A, tf, &ca, &la, &o);
    rb = test_renderer(ctx, B, tf, &cb, &lb, &o);
    set_technique(ra, UMBRA_SHADOW_REFERENCE);
    set_technique(rb, UMBRA_SHADOW_REFERENCE);
    assert_int_equal(umbra_renderer_render(ra, W, H, ia), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
    double mean, worst = max_abs_diff(ia, ib, 4 * W * H, &mean);
    print_message("  %s, point light, reference: max |diff| %.2e, mean %.2e\n", T->name, worst,
                  mean);
    if (worst > 2e-3)
        fail_msg("%s, point light: turned volume and permuted copy differ by %g", T->name, worst);
    /* The picture is not empty: the volume and the lit ground both show. */
    double lum = 0.0;
    for (size_t i = 0; i < W * H; ++i)
        lum += ia[4 * i];
    assert_true(lum / (W * H) > 0.05);

    umbra_renderer_release(ra);
    umbra_renderer_release(rb);
    umbra_transfer_function_release(tf);
    umbra_volume_release(A);
    umbra_volume_release(B);
    free(ia);
    free(ib);
    free(va);
    free(vb);
}

static void test_turned_volume_renders_as_permuted_copy(void **state)
{
    umbra_context ctx = *state;
    /* axis 0 -> -y, 1 -> +z, 2 -> -x: a rotation (d0 x d1 = d2); the ground's normal is -x in
     * the volume's own frame. The second is the same with axis 2 mirrored (-x -> +x). */
    static const turn turns[] = {{{1, 2, 0}, {-1, 1, -1}, "rotation"},
                                 {{1, 2, 0}, {-1, 1, 1}, "mirrored rotation"},
                                 {{2, 0, 1}, {1, -1, -1}, "rotation 2"}};
    for (size_t i = 0; i < sizeof turns / sizeof turns[0]; ++i)
        check_turn(ctx, &turns[i]);
}

/* ---- query_shadow in a rotated, translated box ------------------------------------------------- */

static double next_uniform(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return (double)(x >> 8) / 16777216.0;
}

enum { QUERY_POINTS = 64 };

static void test_query_shadow_in_rotated_box_matches_exp(void **state)
{
    umbra_context ctx = *state;
    const uint32_t dims[3] = {12, 16, 10};
    const float spacing[3] = {1.0f, 0.75f, 1.25f};
    const double voxel = 0.75, a = 0.05;
    const float origin[3] = {100.0f, -50.0f, 20.0f};
    /* Rotation by 40 degrees about (1, 2, 3) (Rodrigues), columns = the index axes' directions. */
    double axis[3] = {1.0, 2.0, 3.0}, al = sqrt(14.0), th = 40.0 * 3.14159265358979323846 / 180.0;
    for (int k = 0; k < 3; ++k)
        axis[k] /= al;
    double R[3][3]; /* R[a] = world direction of index axis a */
    for (int a2 = 0; a2 < 3; ++a2) {
        double e[3] = {a2 == 0, a2 == 1, a2 == 2};
        double c = cos(th), s = sin(th), kd = axis[0] * e[0] + axis[1] * e[1] + axis[2] * e[2];
        double kx[3] = {axis[1] * e[2] - axis[2] * e[1], axis[2] * e[0] - axis[0] * e[2],
                        axis[0] * e[1] - axis[1] * e[0]};
        for (int k = 0; k < 3; ++k)
            R[a2][k] = e[k] * c + kx[k] * s + axis[k] * kd * (1.0 - c);
    }
    float dirs[9];
    for (int a2 = 0; a2 < 3; ++a2)
        for (int k = 0; k < 3; ++k)
            dirs[3 * a2 + k] = (float)R[a2][k];
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *data = malloc(n * sizeof *data);
    assert_non_null(data);
    for (size_t i = 0; i < n; ++i)
        data[i] = 1.0f;
    umbra_volume vol = make_volume(ctx, dims, spacing, data, 0.0f, 1.0f, origin, dirs);
    umbra_transfer_function tf = test_constant_tf(ctx, 0.7f, (float)a);
    /* The box centre in the world, for lights placed around it. */
    double centre[3], half[3];
    for (int k = 0; k < 3; ++k)
        centre[k] = origin[k];
    for (int a2 = 0; a2 < 3; ++a2) {
        half[a2] = 0.5 * dims[a2] * spacing[a2];
        for (int k = 0; k < 3; ++k)
            centre[k] += R[a2][k] * 0.5 * (dims[a2] - 1.0) * spacing[a2];
    }
    const umbra_light lights[] = {
        test_directional_light(0.3f, -0.8f, 0.5f),
        test_directional_light(-1.0f, 0.2f, 0.1f),
        test_point_light((float)(centre[0] + 20.0), (float)(centre[1] + 15.0),
                         (float)(centre[2] - 9.0)),
    };
    umbra_renderer r = test_renderer(ctx, vol, tf, NULL, &lights[0], NULL);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_REFERENCE;
    sd.reference.step = 0.25f;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    float pts[3 * QUERY_POINTS], rgb[3 * QUERY_POINTS];
    double local[QUERY_POINTS][3];
    uint32_t rng = 0x2545f491u;
    for (int i = 0; i < QUERY_POINTS; ++i) {
        /* Inside the box, off its faces: box-frame coordinates q, then the world. */
        double w[3] = {centre[0], centre[1], centre[2]};
        for (int a2 = 0; a2 < 3; ++a2) {
            local[i][a2] = (next_uniform(&rng) * 1.96 - 0.98) * half[a2];
            for (int k = 0; k < 3; ++k)
                w[k] += R[a2][k] * local[i][a2];
        }
        for (int k = 0; k < 3; ++k)
            pts[3 * i + k] = (float)w[k];
    }
    double worst = 0.0;
    for (size_t l = 0; l < sizeof lights / sizeof lights[0]; ++l) {
        assert_int_equal(umbra_renderer_set_light(r, &lights[l]), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_query_shadow(r, pts, QUERY_POINTS, rgb), UMBRA_SUCCESS);
        for (int i = 0; i < QUERY_POINTS; ++i) {
            /* Direction to the light and its distance, in the world, then in the box frame. */
            double dw[3], dist = INFINITY, dl[3];
            if (lights[l].type == UMBRA_LIGHT_POINT) {
                for (int k = 0; k < 3; ++k)
                    dw[k] = (double)lights[l].position[k] - pts[3 * i + k];
            } else {
                for (int k = 0; k < 3; ++k)
                    dw[k] = -(double)lights[l].direction[k];
            }
            double len = sqrt(dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2]);
            if (lights[l].type == UMBRA_LIGHT_POINT)
                dist = len;
            for (int a2 = 0; a2 < 3; ++a2)
                dl[a2] = (R[a2][0] * dw[0] + R[a2][1] * dw[1] + R[a2][2] * dw[2]) / len;
            double d = test_path_in_box(local[i], dl, half, dist);
            double want = exp(log(1.0 - a) * d / voxel);
            for (int c = 0; c < 3; ++c) {
                double err = fabs(rgb[3 * i + c] - want);
                worst = fmax(worst, err);
                if (err > 1e-4)
                    fail_msg("light %zu, point %d (box frame %g, %g, %g): path %g, got %.7f, want "
                             "%.7f", l, i, local[i][0], local[i][1], local[i][2], d,
                             rgb[3 * i + c], want);
            }
        }
    }
    print_message("  rotated, translated box: max |error| %.2e over %d points x %zu lights\n",
                  worst, QUERY_POINTS, sizeof lights / sizeof lights[0]);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
    free(data);
}

/* ---- refused transforms and the reported one --------------------------------------------------- */

static umbra_status create_with(umbra_context ctx, const float origin[3], const float dirs[9],
                                umbra_volume *out)
{
    static const float voxels[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = voxels;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = 2;
    d.spacing[0] = 0.5f;
    d.spacing[1] = 2.0f;
    d.spacing[2] = 3.0f;
    d.transform_given = 1;
    memcpy(d.origin, origin, sizeof d.origin);
    memcpy(d.directions, dirs, sizeof d.directions);
    return umbra_volume_create(ctx, &d, out);
}

static void assert_refused(umbra_context ctx, umbra_status got, umbra_status want,
                           const char *needle)
{
    assert_int_equal(got, want);
    if (!test_message_contains(ctx, needle))
        fail_msg("message lacks \"%s\"", needle);
    assert_int_equal(umbra_context_take_error(ctx, NULL), want);
    umbra_volume v = test_constant_volume(ctx, 2, 2, 2, 0.5f); /* the context still works */
    umbra_volume_release(v);
}

static void test_bad_transforms_refused(void **state)
{
    umbra_context ctx = *state;
    const float zero[3] = {0, 0, 0};
    const double c80 = cos(80.0 * 3.14159265358979323846 / 180.0),
                 s80 = sin(80.0 * 3.14159265358979323846 / 180.0);
    const float sheared[9] = {1, 0, 0, (float)c80, (float)s80, 0, 0, 0, 1};
    umbra_volume v = NULL;
    assert_refused(ctx, create_with(ctx, zero, sheared, &v), UMBRA_ERROR_UNSUPPORTED,
                   "index axes 0 and 1 meet at 80.000 degrees");
    assert_null(v);
    const float flat[9] = {1, 0, 0, 0, 1, 0, 0, 0, 0};
    assert_refused(ctx, create_with(ctx, zero, flat, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                   "index axis 2");
    const float nan_dir[9] = {1, 0, 0, 0, NAN, 0, 0, 0, 1};
    assert_refused(ctx, create_with(ctx, zero, nan_dir, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                   "index axis 1");
    const float ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, bad_origin[3] = {0, INFINITY, 0};
    assert_refused(ctx, create_with(ctx, bad_origin, ident, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                   "origin");
    assert_null(v);
}

static void test_volume_info_reports_world(void **state)
{
    umbra_context ctx = *state;
    umbra_volume_info info;
    /* Default: the centred box. */
    umbra_volume v = test_constant_volume(ctx, 4, 6, 8, 0.5f);
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 0);
    const float want_origin[3] = {-1.5f, -2.5f, -3.5f};
    for (int a = 0; a < 3; ++a) {
        assert_float_equal(info.origin[a], want_origin[a], 1e-6);
        assert_float_equal(info.center[a], 0.0, 1e-6);
        for (int k = 0; k < 3; ++k)
            assert_float_equal(info.directions[3 * a + k], a == k ? 1.0 : 0.0, 0.0);
    }
    umbra_volume_release(v);

    /* Mirrored axes a few hundredths of a degree off square and of length 2: accepted, made unit
     * and exactly orthogonal, handedness kept; the centre is origin + sum d_a s_a (n_a - 1)/2. */
    const float origin[3] = {10.0f, 20.0f, 30.0f};
    const float dirs[9] = {0, 2, 0, 2, 0.0006f, 0, 0, 0, 2}; /* y, x, z: a mirror */
    assert_int_equal(create_with(ctx, origin, dirs, &v), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 1);
    const float *d = info.directions;
    for (int a = 0; a < 3; ++a) {
        assert_float_equal(info.origin[a], origin[a], 0.0);
        for (int b = 0; b < 3; ++b) {
            double dot = d[3 * a] * d[3 * b] + d[3 * a + 1] * d[3 * b + 1] + d[3 * a + 2] * d[3 * b + 2];
            assert_float_equal(dot, a == b ? 1.0 : 0.0, 1e-6);
        }
    }
    double det = d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) +
                 d[2] * (d[3] * d[7] - d[4] * d[6]);
    assert_float_equal(det, -1.0, 1e-6);
    assert_float_equal(d[1], 1.0, 0.0); /* axis 0 is kept as given */
    /* spacing 0.5, 2, 3, dims 2: half a voxel along each axis */
    assert_float_equal(info.center[0], 10.0 + 1.0, 1e-3);
    assert_float_equal(info.center[1], 20.0 + 0.25, 1e-3);
    assert_float_equal(info.center[2], 30.0 + 1.5, 1e-3);
    umbra_volume_release(v);
}

/* ---- transfer functions over a data range ------------------------------------------------------ */

static void test_tf_range_resamples_onto_volume_range(void **state)
{
    umbra_context ctx = *state;
    const float ramp[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    umbra_transfer_function tf = NULL, eff = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, ramp, 2, &tf), UMBRA_SUCCESS);
    /* Without a range the table is used as it is. */
    assert_int_equal(umbra__tf_for_volume(tf, 0.0f, 400.0f, &eff), UMBRA_SUCCESS);
    assert_ptr_equal(eff, tf);
    umbra_transfer_function_release(eff);
    assert_int_equal(umbra_transfer_function_get_range(tf, NULL), 0);

    /* Over data 100..200; a volume spanning 0..400 sees 0 below 100, 1 above 200 and the ramp
     * between (linear, so the resampling is exact). */
    uint64_t id = tf->id;
    assert_int_equal(umbra_transfer_function_set_range(tf, 100.0f, 200.0f), UMBRA_SUCCESS);
    assert_true(tf->id != id);
    float range[2];
    assert_int_equal(umbra_transfer_function_get_range(tf, range), 1);
    assert_float_equal(range[0], 100.0, 0.0);
    assert_float_equal(range[1], 200.0, 0.0);
    const float spans[2][2] = {{0.0f, 400.0f}, {120.0f, 180.0f}};
    for (int s = 0; s < 2; ++s) {
        assert_int_equal(umbra__tf_for_volume(tf, spans[s][0], spans[s][1], &eff), UMBRA_SUCCESS);
        assert_true(eff != tf);
        assert_true(eff->count >= 2);
        for (uint32_t e = 0; e < eff->count; ++e) {
            double x = spans[s][0] + (spans[s][1] - spans[s][0]) * e / (eff->count - 1.0);
            double want = fmin(1.0, fmax(0.0, (x - 100.0) / 100.0));
            for (int c = 0; c < 4; ++c)
                assert_float_equal(eff->rgba[4 * e + c], want, 1e-6);
        }
        umbra_transfer_function_release(eff);
    }
    /* A step between two entries of a 256-entry table over 4095 units, on an 8000-unit volume
     * range: the resampled table keeps it within 1/64 of the jump. */
    float *step = calloc(4 * 256, sizeof *step);
    assert_non_null(step);
    for (int e = 128; e < 256; ++e)
        step[4 * e + 3] = 1.0f;
    umbra_transfer_function st = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, step, 256, &st), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_set_range(st, -1024.0f, 3071.0f), UMBRA_SUCCESS);
    assert_int_equal(umbra__tf_for_volume(st, -2000.0f, 6000.0f, &eff), UMBRA_SUCCESS);
    double worst = 0.0;
    const double w = 4095.0 / 255.0; /* data units per source entry */
    for (int i = 0; i <= 8000 * 8; ++i) {
        double x = -2000.0 + i / 8.0, u = (x + 2000.0) / 8000.0 * (eff->count - 1.0);
        uint32_t k = (uint32_t)fmin(u, eff->count - 2.0);
        double f = u - k, got = (1 - f) * eff->rgba[4 * k + 3] + f * eff->rgba[4 * k + 7];
        double want = fmin(1.0, fmax(0.0, (x - (-1024.0 + 127 * w)) / w));
        worst = fmax(worst, fabs(got - want));
    }
    print_message("  step resampled onto 8000 units (%u entries): max |alpha error| %.4f\n",
                  eff->count, worst);
    assert_true(worst <= 1.0 / 64.0 + 1e-6);
    umbra_transfer_function_release(eff);
    umbra_transfer_function_release(st);
    free(step);

    /* Bad ranges name the values and change nothing. */
    assert_int_equal(umbra_transfer_function_set_range(tf, 5.0f, 5.0f), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "[5, 5]"));
    assert_int_equal(umbra_transfer_function_set_range(tf, NAN, 5.0f), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_transfer_function_set_range(tf, 0.0f, INFINITY),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_transfer_function_get_range(tf, range), 1);
    assert_float_equal(range[0], 100.0, 0.0);
    umbra_transfer_function_release(tf);
}

/* The piecewise-linear function of a table over [lo, hi] at data value x (ends clamp). */
static void table_at(const float *rgba, uint32_t count, double lo, double hi, double x,
                     double out[4])
{
    double u = fmin(1.0, fmax(0.0, (x - lo) / (hi - lo))) * (count - 1.0);
    uint32_t k = (uint32_t)fmin(u, count - 2.0);
    double f = u - k;
    for (int c = 0; c < 4; ++c)
        out[c] = (1 - f) * rgba[4 * k + c] + f * rgba[4 * (k + 1) + c];
}

static void test_tf_range_renders_like_normalised_table(void **state)
{
    umbra_context ctx = *state;
    /* A "CT" ball: data from 3500 at the centre down to -1500 outside, on a volume whose value
     * range is -2000..6000, so ignoring the TF's range would move every feature. */
    const uint32_t n = 24, dims[3] = {n, n, n};
    const float spacing[3] = {1.0f, 1.0f, 1.0f};
    float *data = malloc((size_t)n * n * n * sizeof *data);
    assert_non_null(data);
    for (uint32_t k = 0; k < n; ++k)
        for (uint32_t j = 0; j < n; ++j)
            for (uint32_t i = 0; i < n; ++i) {
                double x = i - 11.5, y = j - 9.5, z = k - 12.5;
                double r = sqrt(x * x + y * y + z * z);
                data[((size_t)k * n + j) * n + i] = (float)(3500.0 - 5000.0 * fmin(1.0, r / 10.0));
            }
    umbra_volume vol = make_volume(ctx, dims, spacing, data, -2000.0f, 6000.0f, NULL, NULL);
    /* 64 entries over -1024..3071: transparent below ~0, a soft-tissue shell, a sharp bone step,
     * the top entry (taken by data above 3071) opaque-ish. */
    enum { COUNT = 64 };
    float tab[4 * COUNT];
    for (int e = 0; e < COUNT; ++e) {
        double x = -1024.0 + 4095.0 * e / (COUNT - 1.0);
        float *p = tab + 4 * e;
        p[0] = (float)(0.3 + 0.7 * e / (COUNT - 1.0));
        p[1] = 0.6f;
        p[2] = (float)(1.0 - 0.8 * e / (COUNT - 1.0));
        p[3] = x < 0.0 ? 0.0f : (x < 1200.0 ? 0.04f : 0.35f);
    }
    umbra_transfer_function data_tf = NULL, norm_tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, tab, COUNT, &data_tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_set_range(data_tf, -1024.0f, 3071.0f), UMBRA_SUCCESS);
    /* The same function over the volume's normalised range, sampled finely (0.125 units). */
    const uint32_t fine = 64001;
    float *ft = malloc(4 * (size_t)fine * sizeof *ft);
    assert_non_null(ft);
    for (uint32_t e = 0; e < fine; ++e) {
        double v[4];
        table_at(tab, COUNT, -1024.0, 3071.0, -2000.0 + 8000.0 * e / (fine - 1.0), v);
        for (int c = 0; c < 4; ++c)
            ft[4 * e + c] = (float)v[c];
    }
    assert_int_equal(umbra_transfer_function_create(ctx, ft, fine, &norm_tf), UMBRA_SUCCESS);
    /* Ignoring the range (the table as if over the normalised range) must look different. */
    umbra_transfer_function wrong_tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, tab, COUNT, &wrong_tf), UMBRA_SUCCESS);

    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    o.ground_plane = 1;
    o.background[3] = 1.0f;
    umbra_light light = test_directional_light(-0.5f, -0.6f, -1.0f);
    umbra_renderer ra = test_renderer(ctx, vol, data_tf, NULL, &light, &o);
    umbra_renderer rb = test_renderer(ctx, vol, norm_tf, NULL, &light, &o);
    float *ia = malloc(4 * W * H * sizeof *ia), *ib = malloc(4 * W * H * sizeof *ib);
    assert_non_null(ia);
    assert_non_null(ib);
    for (int t = UMBRA_SHADOW_NONE; t <= UMBRA_SHADOW_CONVOLUTION; ++t) {
        set_technique(ra, (umbra_shadow_technique)t);
        set_technique(rb, (umbra_shadow_technique)t);
        assert_int_equal(umbra_renderer_render(ra, W, H, ia), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
        double mean, worst = max_abs_diff(ia, ib, 4 * W * H, &mean);
        print_message("  data-range tf vs normalised table, %s: max |diff| %.2e, mean %.2e\n",
                      umbra_shadow_technique_name((umbra_shadow_technique)t), worst, mean);
        if (worst > 5e-3)
            fail_msg("%s: data-range transfer function differs by %g",
                     umbra_shadow_technique_name((umbra_shadow_technique)t), worst);
        if (t == UMBRA_SHADOW_REFERENCE) {
            /* The shadow queried at a point behind the ball agrees too. */
            const float p[3] = {-3.0f, -5.8f, -5.3f}; /* 8 voxels past the centre */
            float sa[3], sb[3];
            assert_int_equal(umbra_renderer_query_shadow(ra, p, 1, sa), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_query_shadow(rb, p, 1, sb), UMBRA_SUCCESS);
            assert_float_equal(sa[0], sb[0], 1e-3);
            assert_true(sa[0] < 0.9f); /* it is in shadow */
        }
    }
    /* The test can tell: without the range the image moves a lot. */
    assert_int_equal(umbra_renderer_set_transfer_function(rb, wrong_tf), UMBRA_SUCCESS);
    set_technique(ra, UMBRA_SHADOW_NONE);
    set_technique(rb, UMBRA_SHADOW_NONE);
    assert_int_equal(umbra_renderer_render(ra, W, H, ia), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
    double wrong = max_abs_diff(ia, ib, 4 * W * H, NULL);
    print_message("  the same table without its range: max |diff| %.2e\n", wrong);
    assert_true(wrong > 0.1);
    /* Setting a range on the tf in use is picked up at the next render. */
    assert_int_equal(umbra_transfer_function_set_range(wrong_tf, -1024.0f, 3071.0f), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(rb, W, H, ib), UMBRA_SUCCESS);
    assert_true(max_abs_diff(ia, ib, 4 * W * H, NULL) < 5e-3);

    umbra_renderer_release(ra);
    umbra_renderer_release(rb);
    umbra_transfer_function_release(data_tf);
    umbra_transfer_function_release(norm_tf);
    umbra_transfer_function_release(wrong_tf);
    umbra_volume_release(vol);
    free(ia);
    free(ib);
    free(ft);
    free(data);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_turned_volume_renders_as_permuted_copy),
        cmocka_unit_test(test_query_shadow_in_rotated_box_matches_exp),
        cmocka_unit_test(test_bad_transforms_refused),
        cmocka_unit_test(test_volume_info_reports_world),
        cmocka_unit_test(test_tf_range_resamples_onto_volume_range),
        cmocka_unit_test(test_tf_range_renders_like_normalised_table),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
