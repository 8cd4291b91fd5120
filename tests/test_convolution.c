// SPDX-License-Identifier: Apache-2.0
/* tests/test_convolution.c: the convolution shadows (ICS, pre-integrated ICS, SCS, pre-integrated
 * SCS) and the pre-integration tables they share with the ray caster, pinned down.
 *
 *  - a homogeneous slab lit along the view axis with a delta kernel (cone angle 0): the light after
 *    k slices is (1 - a)^(k dz) for every variant (1e-4 relative), and an oblique light through a
 *    laterally unbounded slab gives (1 - a)^(k dz / cos theta) away from the upwind border;
 *  - the convolution keeps a constant light field constant away from the image borders (its
 *    kernel, cone-widened and displaced, sums to 1);
 *  - a pre-integration table's diagonal s_f = s_b is the step-corrected transfer function
 *    (colour premultiplied; light: the shading model's transmission), and a step transfer
 *    function gives finite entries in [0,1] everywhere;
 *  - sub-sample light weights lie in [0,1], rise with j, and are exactly 0 and 1 at the slices;
 *  - with no light attenuation the slices composite exactly like the ray caster (shading, ground
 *    plane, background), and the ground under a slab gets the analytic shadow;
 *  - on the coloured spheres with shading and ground, every variant at 0.5 voxel stays within
 *    0.006 mean absolute difference of the exact reference;
 *  - on a sharp transfer function (the spheres' bands), more sub-samples or pre-integration at the
 *    same slice distance never increase the error against the finest setting; the pre-integrated
 *    ray caster is closer to a fine ray caster than the plain one at the same step;
 *  - lights behind the slices give the documented status and message (bad parameters: the
 *    conformance suite, tests/test_conformance.c).
 *
 * Usage: test_convolution [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"
#include "techniques/convolution.h"
#include "test_util.h"

/* ---- helpers --------------------------------------------------------------------------------- */

/* Pre-integration on or off, the renderer's other options kept. */
static void set_preintegrated(umbra_renderer r, int on)
{
    umbra_render_desc o = r->opts;
    o.preintegrated = on;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
}

/* An orthographic camera above the origin looking straight down (-y), image x along +x. */
static umbra_camera camera_down(float height, float ortho_height)
{
    umbra_camera c;
    memset(&c, 0, sizeof c);
    c.projection = UMBRA_ORTHOGRAPHIC;
    c.eye[1] = height;
    c.up[2] = -1.0f;
    c.ortho_height = ortho_height;
    c.fovy_degrees = 30.0f;
    return c;
}

static void set_convolution(umbra_renderer r, float dz, uint32_t n, int pi, float cone)
{
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_CONVOLUTION;
    s.convolution.slice_distance = dz;
    s.convolution.subsamples = n;
    s.convolution.cone_angle_degrees = cone;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    set_preintegrated(r, pi);
}

static double mean_abs_diff(const float *a, const float *b, size_t pixels)
{
    double sum = 0.0;
    for (size_t i = 0; i < 4 * pixels; ++i)
        sum += fabs((double)a[i] - b[i]);
    return sum / (4.0 * pixels);
}

static const char *const variant_names[4] = {"ICS", "pre-integrated ICS", "SCS (2 sub-samples)",
                                             "pre-integrated SCS (2 sub-samples)"};

/* ---- the light through a homogeneous slab ------------------------------------------------------ */

enum { SLAB_N = 32, SLAB_H = 8, SLAB_IMG = 32 };

/* A 32 x 8 x 32 slab of constant grey material (alpha 0.03 per voxel), seen from above by an
 * orthographic camera whose view (16 voxels wide) lies inside the slab's extent. */
static void slab_light(umbra_context ctx, const umbra_light *light, int variant, float dz,
                       const uint32_t *ks, size_t nk, const double *want, int first_col,
                       const char *what)
{
    float *data = malloc((size_t)SLAB_N * SLAB_H * SLAB_N * sizeof *data);
    assert_non_null(data);
    for (size_t i = 0; i < (size_t)SLAB_N * SLAB_H * SLAB_N; ++i)
        data[i] = 1.0f;
    umbra_volume v = test_volume(ctx, SLAB_N, SLAB_H, SLAB_N, data);
    free(data);
    umbra_transfer_function tf = test_constant_tf(ctx, 0.7f, 0.03f);
    umbra_camera cam = camera_down(20.0f, 16.0f);
    umbra_renderer r = test_renderer(ctx, v, tf, &cam, light, NULL);
    set_convolution(r, dz, (variant & 2) ? 2 : 0, variant & 1, 0.0f);
    float *rgb = malloc((size_t)SLAB_IMG * SLAB_IMG * 3 * sizeof *rgb);
    assert_non_null(rgb);
    for (size_t i = 0; i < nk; ++i) {
        assert_int_equal(umbra__convolution_light(r, SLAB_IMG, SLAB_IMG, ks[i], rgb),
                         UMBRA_SUCCESS);
        for (int y = 0; y < SLAB_IMG; ++y)
            for (int x = first_col; x < SLAB_IMG; ++x)
                for (int c = 0; c < 3; ++c) {
                    double got = rgb[3 * (y * SLAB_IMG + x) + c];
                    if (!(fabs(got - want[i]) <= 1e-4 * want[i]))
                        fail_msg("%s, %s: light after %u slices at pixel (%d, %d) channel %d is "
                                 "%.7f, want %.7f", what, variant_names[variant], ks[i], x, y, c,
                                 got, want[i]);
                }
    }
    free(rgb);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_slab_light_matches_transmittance(void **state)
{
    umbra_context ctx = *state;
    /* Light along the view axis: no displacement, so the delta kernel reads each texel's own
     * value. Slices every 0.5 voxel; the slab is 8 voxels (16 slices) thick. */
    const umbra_light down = test_directional_light(0.0f, -1.0f, 0.0f);
    const uint32_t ks[] = {0, 1, 5, 12, 15};
    double want[5];
    for (int i = 0; i < 5; ++i)
        want[i] = pow(0.97, ks[i] * 0.5);
    for (int variant = 0; variant < 4; ++variant)
        slab_light(ctx, &down, variant, 0.5f, ks, 5, want, 0, "light along the view axis");

    /* An oblique light (30 degrees from the view axis): each slab is crossed over dz / cos 30,
     * so the light after k slices is (1 - a)^(k dz / cos 30). The kernel reads 0.29 voxel
     * (0.58 pixel) upwind per slice; after 15 slices the 9 pixels nearest the upwind border
     * see light from outside the view (1), and bilinear resampling spreads it a few pixels
     * further: the 14 nearest are left out. */
    const double th = 30.0 * 3.14159265358979 / 180.0;
    const umbra_light oblique = test_directional_light((float)sin(th), (float)-cos(th), 0.0f);
    const uint32_t ko[] = {4, 15};
    double want_o[2];
    for (int i = 0; i < 2; ++i)
        want_o[i] = pow(0.97, ko[i] * 0.5 / cos(th));
    for (int variant = 0; variant < 4; ++variant)
        slab_light(ctx, &oblique, variant, 0.5f, ko, 2, want_o, 14, "light 30 degrees oblique");

    /* A point light far above on the view axis: per-pixel light directions within 1e-4 rad of
     * the axis, so the transmittance is that of the directional case. */
    umbra_light point = down;
    point.type = UMBRA_LIGHT_POINT;
    point.position[1] = 1e5f;
    slab_light(ctx, &point, 0, 0.5f, ks, 5, want, 0, "point light far above");
}

/* ---- the kernel preserves a constant light field ------------------------------------------------- */

static void test_convolution_preserves_constant_light(void **state)
{
    umbra_context ctx = *state;
    enum { N = 64, NY = 24, IMG = 64 };
    /* An occluding layer covering the whole view (the top 6 voxel rows) over empty space: below
     * it the light is laterally constant, and must stay so through the empty slices while the
     * wide (20 degree), displaced kernel keeps convolving it. */
    float *data = malloc((size_t)N * NY * N * sizeof *data);
    assert_non_null(data);
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < N; ++x)
                data[((size_t)z * NY + y) * N + x] = y >= NY - 6 ? 1.0f : 0.0f;
    umbra_volume v = test_volume(ctx, N, NY, N, data);
    free(data);
    float t[8] = {0.8f, 0.8f, 0.8f, 0.0f, 0.8f, 0.8f, 0.8f, 0.05f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, t, 2, &tf), UMBRA_SUCCESS);
    umbra_camera cam = camera_down(40.0f, 40.0f); /* 0.625 voxel per pixel */
    umbra_light light = test_directional_light(0.15f, -1.0f, 0.1f);
    umbra_renderer r = test_renderer(ctx, v, tf, &cam, &light, NULL);
    set_convolution(r, 1.0f, 0, 0, 20.0f);
    float *after = malloc((size_t)IMG * IMG * 3 * sizeof *after);
    float *later = malloc((size_t)IMG * IMG * 3 * sizeof *later);
    assert_non_null(after);
    assert_non_null(later);
    /* Slice 9 lies 9 voxels down, past the layer (6 voxels and its 1-voxel ramp); slice 23 has
     * had 14 more convolutions. Light from outside the view (1) creeps in from the upwind
     * border by 0.18 voxel per slice plus the kernel's spread: 20 voxels away, the centre
     * stays clear of it. */
    assert_int_equal(umbra__convolution_light(r, IMG, IMG, 9, after), UMBRA_SUCCESS);
    assert_int_equal(umbra__convolution_light(r, IMG, IMG, 23, later), UMBRA_SUCCESS);
    const int c0 = IMG / 2 - 8, c1 = IMG / 2 + 8; /* the central 16 x 16 pixels (10 voxels) */
    double ref = after[3 * ((IMG / 2) * IMG + IMG / 2)];
    assert_true(ref < 0.8 && ref > 0.5); /* the layer did attenuate */
    for (int y = c0; y < c1; ++y)
        for (int x = c0; x < c1; ++x)
            for (int c = 0; c < 3; ++c) {
                size_t i = 3 * ((size_t)y * IMG + x) + c;
                if (!(fabs(after[i] - ref) < 1e-5 && fabs(later[i] - ref) < 1e-5))
                    fail_msg("pixel (%d, %d): light %.7f after the layer and %.7f 14 slices "
                             "later; the constant is %.7f", x, y, after[i], later[i], ref);
            }
    free(after);
    free(later);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* ---- pre-integration tables ---------------------------------------------------------------------- */

static float *read_table(umbra_context ctx, cl_mem buf)
{
    size_t n = (size_t)UMBRA__PREINT_SIZE * UMBRA__PREINT_SIZE * 4;
    float *t = malloc(n * sizeof *t);
    assert_non_null(t);
    assert_int_equal(clEnqueueReadBuffer(umbra_context_cl_queue(ctx), buf, CL_TRUE, 0,
                                         n * sizeof *t, t, 0, NULL, NULL),
                     CL_SUCCESS);
    return t;
}

static void test_preintegration_diagonal_is_corrected_tf(void **state)
{
    umbra_context ctx = *state;
    /* 256 entries, so table entry (i, i) sits exactly on transfer-function entry i. */
    enum { N = UMBRA__PREINT_SIZE };
    float *rgba = malloc(4 * N * sizeof *rgba);
    assert_non_null(rgba);
    for (int i = 0; i < N; ++i) {
        float s = (float)i / (N - 1);
        rgba[4 * i] = 0.5f + 0.5f * sinf(9.0f * s);
        rgba[4 * i + 1] = s;
        rgba[4 * i + 2] = 1.0f - s * s;
        rgba[4 * i + 3] = (i / 16) % 2 ? 0.9f * s : 0.02f; /* bands: a sharp function */
    }
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, N, &tf), UMBRA_SUCCESS);
    const float lengths[] = {0.25f, 0.7f, 2.5f};
    umbra__preint *view = NULL, *light = NULL;
    for (int li = 0; li < 3; ++li)
        for (int colored = 0; colored < 2; ++colored) {
            const double len = lengths[li];
            cl_mem vb, lb;
            double ms = 0.0;
            assert_int_equal(umbra__preint_ensure(ctx, "test", &view, tf, lengths[li],
                                                  UMBRA__PREINT_VIEW, 0, &vb, &ms), UMBRA_SUCCESS);
            assert_int_equal(umbra__preint_ensure(ctx, "test", &light, tf, lengths[li],
                                                  UMBRA__PREINT_LIGHT, colored, &lb, &ms),
                             UMBRA_SUCCESS);
            float *tv = read_table(ctx, vb), *tl = read_table(ctx, lb);
            for (int i = 0; i < N; ++i) {
                const float *e = tv + 4 * ((size_t)i * N + i), *f = tl + 4 * ((size_t)i * N + i);
                double a = 1.0 - pow(1.0 - rgba[4 * i + 3], len);
                assert_float_equal(e[3], a, 2e-6);
                for (int c = 0; c < 3; ++c) {
                    assert_float_equal(e[c], rgba[4 * i + c] * a, 2e-6);
                    double tr = pow(1.0 - rgba[4 * i + 3],
                                    len * (colored ? 1.0 - rgba[4 * i + c] : 1.0));
                    assert_float_equal(f[c], tr, 2e-6);
                }
            }
            free(tv);
            free(tl);
        }
    /* Asking again for the same table rebuilds nothing. */
    cl_mem again;
    double ms = 0.0;
    assert_int_equal(umbra__preint_ensure(ctx, "test", &view, tf, 2.5f, UMBRA__PREINT_VIEW, 0,
                                          &again, &ms), UMBRA_SUCCESS);
    assert_true(ms == 0.0);

    /* A step function: transparent, then fully opaque from entry 128 on. */
    umbra_transfer_function step = NULL;
    for (int i = 0; i < N; ++i)
        rgba[4 * i + 3] = i >= N / 2 ? 1.0f : 0.0f;
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, N, &step), UMBRA_SUCCESS);
    cl_mem vb, lb;
    assert_int_equal(umbra__preint_ensure(ctx, "test", &view, step, 1.0f, UMBRA__PREINT_VIEW, 0,
                                          &vb, NULL), UMBRA_SUCCESS);
    assert_int_equal(umbra__preint_ensure(ctx, "test", &light, step, 1.0f, UMBRA__PREINT_LIGHT, 1,
                                          &lb, NULL), UMBRA_SUCCESS);
    float *tv = read_table(ctx, vb), *tl = read_table(ctx, lb);
    for (size_t i = 0; i < (size_t)N * N * 4; ++i) {
        if (!(isfinite(tv[i]) && isfinite(tl[i]) && tv[i] >= 0.0f && tv[i] <= 1.0f + 1e-6f &&
              tl[i] >= 0.0f && tl[i] <= 1.0f + 1e-6f))
            fail_msg("step function: entry %zu channel %zu is %g (view) / %g (light)", i / 4,
                     i % 4, tv[i], tl[i]);
    }
    /* Every segment that reaches the opaque half is opaque; one that never does is clear. */
    assert_float_equal(tv[4 * ((size_t)(N - 1) * N + 0) + 3], 1.0f, 1e-6);
    assert_float_equal(tv[4 * ((size_t)0 * N + (N - 1)) + 3], 1.0f, 1e-6);
    assert_float_equal(tv[4 * ((size_t)(N / 2 - 2) * N + 3) + 3], 0.0f, 1e-6);
    free(tv);
    free(tl);
    umbra__preint_release(view);
    umbra__preint_release(light);
    umbra_transfer_function_release(step);
    umbra_transfer_function_release(tf);
    free(rgba);
}

/* ---- sub-sample weights -------------------------------------------------------------------------- */

static void test_subsample_weights(void **state)
{
    umbra_context ctx = *state;
    const uint32_t ns[] = {0, 1, 2, 3, 7, 64};
    float w[66];
    for (size_t t = 0; t < sizeof ns / sizeof ns[0]; ++t) {
        uint32_t n = ns[t];
        assert_int_equal(umbra__convolution_subsample_weights(ctx, n, w), UMBRA_SUCCESS);
        assert_true(w[0] == 0.0f);     /* exactly the front slice's light */
        assert_true(w[n + 1] == 1.0f); /* exactly the next slice's light */
        for (uint32_t j = 0; j <= n + 1; ++j) {
            assert_true(w[j] >= 0.0f && w[j] <= 1.0f);
            assert_float_equal(w[j], (double)j / (n + 1), 1e-7);
            if (j > 0)
                assert_true(w[j] > w[j - 1]);
        }
    }
}

/* ---- compositing like the ray caster --------------------------------------------------------------- */

/* With a light transfer function that attenuates nothing, every technique's shadow factor is 1,
 * so the slices must reproduce the ray caster's image: on an axis-aligned orthographic view with
 * slice distance = view step, the samples fall on the same points. */
static void test_compositing_matches_raycaster(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &sc), UMBRA_SUCCESS);
    float clear[8] = {1, 1, 1, 0, 1, 1, 1, 0};
    umbra_transfer_function none = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, clear, 2, &none), UMBRA_SUCCESS);
    umbra_camera cam = camera_down(40.0f, 70.0f); /* the ground shows around the box */
    umbra_light light = test_directional_light(0.2f, -1.0f, 0.1f);
    enum { W = 64, H = 48 };
    float *a = malloc(W * H * 4 * sizeof *a), *b = malloc(W * H * 4 * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    for (int shading = 0; shading < 2; ++shading) {
        umbra_render_desc o = sc.options;
        o.shading = shading;
        o.step = 0.5f;
        o.background[0] = 0.1f;
        o.background[1] = 0.2f;
        o.background[2] = 0.3f;
        o.background[3] = 1.0f;
        o.termination = shading ? 0.95f : 1.0f;
        umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &cam, &light, &o);
        assert_int_equal(umbra_renderer_set_light_transfer_function(r, none), UMBRA_SUCCESS);
        umbra_shadow_desc s;
        umbra_shadow_desc_init(&s);
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, H, a), UMBRA_SUCCESS);
        set_convolution(r, 0.5f, 0, 0, 5.0f);
        assert_int_equal(umbra_renderer_render(r, W, H, b), UMBRA_SUCCESS);
        umbra_render_stats st;
        assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
        assert_true(st.slices >= 64); /* 32 voxels deep at 0.5 */
        for (int i = 0; i < W * H * 4; ++i)
            if (!(fabsf(a[i] - b[i]) <= 2e-4f))
                fail_msg("shading %d: pixel %d channel %d: ray caster %.6f, slices %.6f", shading,
                         i / 4, i % 4, a[i], b[i]);
        umbra_renderer_release(r);
    }
    free(a);
    free(b);
    umbra_transfer_function_release(none);
    umbra_scene_release(&sc);
}

/* The ground under a slab lit straight down: shadowed by exactly the slab's transmittance. */
static void test_ground_shadow_under_slab(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "slab", 32, &sc), UMBRA_SUCCESS); /* 32 x 8 x 32 */
    umbra_camera cam = camera_down(30.0f, 48.0f);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_render_desc o = sc.options;
    o.transmission = UMBRA_TRANSMISSION_GREY;
    umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &cam, &light, &o);
    enum { W = 48, H = 48 };
    float *img = malloc(W * H * 4 * sizeof *img);
    assert_non_null(img);
    for (int variant = 0; variant < 4; ++variant) {
        set_convolution(r, 0.5f, (variant & 2) ? 2 : 0, variant & 1, 0.0f);
        assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
        /* Pixel (2, 24) sees the ground beside the slab: unshadowed. */
        const float *g = img + 4 * (24 * W + 2);
        const double gc = o.ground_color[0], amb = o.ambient[0];
        double lit = gc * (amb + 1.0);
        for (int c = 0; c < 3; ++c)
            assert_float_equal(g[c], lit, 1e-4);
        /* The centre sees the slab (8 voxels, colour 0.7, alpha 0.03, lit from above through
         * the part in front of each sample) over the ground in its shadow 0.97^8. */
        const float *p = img + 4 * (24 * W + 24);
        double T = 1.0, col = 0.0;
        /* m samples per slab (1, or 3 with 2 sub-samples), each a 1/(2m)-voxel step (for the
         * pre-integrated variants a constant segment: the same); sample j of slab i is lit by
         * the light at the slab's two ends, L_i = 0.97^(i/2), weighted by j/m. */
        const int m = (variant & 2) ? 3 : 1;
        const double a = 1.0 - pow(0.97, 0.5 / m);
        for (int k = 0; k < 16 * m; ++k) {
            int slab = k / m;
            double f = (double)(k % m) / m;
            double S = (1.0 - f) * pow(0.97, slab * 0.5) + f * pow(0.97, (slab + 1) * 0.5);
            col += T * a * 0.7 * (amb + S);
            T *= 1.0 - a;
        }
        col += T * gc * (amb + pow(0.97, 8.0));
        for (int c = 0; c < 3; ++c)
            if (!(fabs(p[c] - col) < 1e-4))
                fail_msg("%s: centre pixel channel %d is %.6f, want %.6f", variant_names[variant],
                         c, p[c], col);
    }
    free(img);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

/* Against the exact reference on the coloured spheres, with gradient shading and the ground plane
 * (whose shadows the slices carry down to it), ICS stays close: the remaining difference is the
 * method's (light resampled every slice, the cone's blur, one slice of light lag). */
static void test_close_to_exact_reference(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &sc), UMBRA_SUCCESS);
    enum { W = 48, H = 48 };
    umbra_light light = test_directional_light(-0.3f, -1.0f, -0.6f);
    umbra_render_desc o = sc.options;
    o.shading = 1;
    umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &light, &o);
    float *ref = malloc(W * H * 4 * sizeof *ref), *img = malloc(W * H * 4 * sizeof *img);
    assert_non_null(ref);
    assert_non_null(img);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, ref), UMBRA_SUCCESS);
    for (int variant = 0; variant < 4; ++variant) {
        set_convolution(r, 0.5f, (variant & 2) ? 2 : 0, variant & 1, 5.0f);
        assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
        double e = mean_abs_diff(img, ref, W * H);
        print_message("%s at 0.5 voxel vs exact: mean abs difference %.5f\n",
                      variant_names[variant], e);
        assert_true(e < 0.006);
    }
    free(ref);
    free(img);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

/* ---- accuracy on a sharp transfer function --------------------------------------------------------- */

static void test_subsamples_and_preintegration_reduce_error(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    /* Spheres with thin shells of transfer-function bands: a sharp transfer function over
     * smooth data, the case pre-integration is for. */
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &sc), UMBRA_SUCCESS);
    enum { W = 48, H = 48 };
    const float dir[3] = {0.3f, 0.8f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, sqrtf(3.0f) * 32.0f, 30.0f);
    umbra_light light = test_directional_light(-0.2f, -0.9f, -0.6f);
    umbra_render_desc o = sc.options;
    o.ground_plane = 0;
    o.shading = 0; /* gradient shading at a slice's sample is not what the variants change */
    umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &cam, &light, &o);
    float *fine = malloc(W * H * 4 * sizeof *fine), *img = malloc(W * H * 4 * sizeof *img);
    assert_non_null(fine);
    assert_non_null(img);
    /* The finest setting: ICS at 0.1 voxel. */
    set_convolution(r, 0.1f, 0, 0, 5.0f);
    assert_int_equal(umbra_renderer_render(r, W, H, fine), UMBRA_SUCCESS);
    const float dz = 1.5f;
    double err[2][4];
    for (int pi = 0; pi < 2; ++pi)
        for (uint32_t n = 0; n < 4; ++n) {
            set_convolution(r, dz, n, pi, 5.0f);
            assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
            err[pi][n] = mean_abs_diff(img, fine, W * H);
            print_message("slice distance %.1f, %u sub-samples%s: mean abs error %.5f\n", dz, n,
                          pi ? ", pre-integrated" : "", err[pi][n]);
        }
    for (int pi = 0; pi < 2; ++pi)
        for (int n = 1; n < 4; ++n)
            if (err[pi][n] > err[pi][n - 1])
                fail_msg("%s: %d sub-samples give error %.5f, more than %d give (%.5f)",
                         pi ? "pre-integrated" : "plain", n, err[pi][n], n - 1, err[pi][n - 1]);
    for (int n = 0; n < 4; ++n)
        if (err[1][n] > err[0][n])
            fail_msg("%d sub-samples: pre-integration gives error %.5f, more than without (%.5f)",
                     n, err[1][n], err[0][n]);
    /* Reaching the finest setting's sampling this way must actually help. */
    assert_true(err[0][3] < 0.7 * err[0][0]);
    assert_true(err[1][0] < 0.7 * err[0][0]);
    free(fine);
    free(img);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

static void test_preintegrated_raycaster(void **state)
{
    umbra_context ctx = *state;
    enum { W = 48, H = 48 };
    float *fine = malloc(W * H * 4 * sizeof *fine), *a = malloc(W * H * 4 * sizeof *a),
          *b = malloc(W * H * 4 * sizeof *b);
    assert_non_null(fine);
    assert_non_null(a);
    assert_non_null(b);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_REFERENCE;

    /* A constant volume: pre-integration changes no colour or opacity. (Unshadowed: a plain
     * sample takes its light about its position, a pre-integrated one from the segment after it,
     * kernels/raycast.cl shadow_point, about half a view step apart.) */
    s.technique = UMBRA_SHADOW_NONE;
    umbra_volume cv = test_constant_volume(ctx, 16, 16, 16, 0.6f);
    umbra_transfer_function ctf = test_constant_tf(ctx, 0.6f, 0.08f);
    const float dir[3] = {0.4f, 0.7f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 28.0f, 30.0f);
    umbra_light light = test_directional_light(-0.4f, -1.0f, -0.2f);
    umbra_renderer r = test_renderer(ctx, cv, ctf, &cam, &light, NULL);
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, a), UMBRA_SUCCESS);
    set_preintegrated(r, 1);
    assert_int_equal(umbra_renderer_render(r, W, H, b), UMBRA_SUCCESS);
    for (int i = 0; i < W * H * 4; ++i)
        assert_float_equal(a[i], b[i], 1e-4);
    umbra_renderer_release(r);
    umbra_transfer_function_release(ctf);
    umbra_volume_release(cv);

    /* The spheres' banded transfer function: at a 1-voxel step the pre-integrated ray caster is
     * far closer to a 0.1-voxel ray caster than the plain one. */
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &sc), UMBRA_SUCCESS);
    umbra_render_desc o = sc.options;
    o.step = 0.1f;
    o.shading = 0; /* pre-integration fixes the opacity integral, not the shading position */
    s.technique = UMBRA_SHADOW_NONE;
    r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &sc.light, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, fine), UMBRA_SUCCESS);
    o.step = 1.0f;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, a), UMBRA_SUCCESS);
    set_preintegrated(r, 1);
    assert_int_equal(umbra_renderer_render(r, W, H, b), UMBRA_SUCCESS);
    double e_plain = mean_abs_diff(a, fine, W * H), e_pi = mean_abs_diff(b, fine, W * H);
    print_message("ray caster, step 1: mean abs error %.5f plain, %.5f pre-integrated\n", e_plain,
                  e_pi);
    assert_true(e_pi < 0.6 * e_plain);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
    free(fine);
    free(a);
    free(b);
}

/* ---- what is not supported ------------------------------------------------------------------------ */

static void test_unsupported_lights(void **state)
{
    umbra_context ctx = *state;
    umbra_volume v = test_constant_volume(ctx, 16, 16, 16, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 0.5f, 0.05f);
    umbra_camera cam = camera_down(30.0f, 20.0f);
    umbra_light up = test_directional_light(0.0f, 1.0f, 0.0f); /* towards the viewer */
    umbra_renderer r = test_renderer(ctx, v, tf, &cam, &up, NULL);
    set_convolution(r, 1.0f, 0, 0, 5.0f);
    float img[16 * 16 * 4];
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_ERROR_UNSUPPORTED);
    assert_true(test_message_contains(ctx, "180.0 degrees"));
    assert_true(test_message_contains(ctx, "(0, 1, 0)"));
    umbra_light grazing = test_directional_light(1.0f, -0.1f, 0.0f); /* 84 degrees off the view axis */
    assert_int_equal(umbra_renderer_set_light(r, &grazing), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_ERROR_UNSUPPORTED);
    assert_true(test_message_contains(ctx, "84.3 degrees"));
    /* A point light below the volume: the far side of the slices. */
    umbra_light below = up;
    below.type = UMBRA_LIGHT_POINT;
    below.position[1] = -30.0f;
    assert_int_equal(umbra_renderer_set_light(r, &below), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_ERROR_UNSUPPORTED);
    assert_true(test_message_contains(ctx, "point light"));
    /* A point light above it, on the viewer's side, works. */
    below.position[1] = 40.0f;
    assert_int_equal(umbra_renderer_set_light(r, &below), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.slices, 16);
    assert_true(st.shadow_memory_bytes > 0);

    /* The context keeps working. */
    umbra_context_take_error(ctx, NULL);
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_SUCCESS);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* ---- main ---------------------------------------------------------------------------------------- */

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab_light_matches_transmittance),
        cmocka_unit_test(test_convolution_preserves_constant_light),
        cmocka_unit_test(test_preintegration_diagonal_is_corrected_tf),
        cmocka_unit_test(test_subsample_weights),
        cmocka_unit_test(test_compositing_matches_raycaster),
        cmocka_unit_test(test_ground_shadow_under_slab),
        cmocka_unit_test(test_close_to_exact_reference),
        cmocka_unit_test(test_subsamples_and_preintegration_reduce_error),
        cmocka_unit_test(test_preintegrated_raycaster),
        cmocka_unit_test(test_unsupported_lights),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
