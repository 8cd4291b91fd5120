// SPDX-License-Identifier: Apache-2.0
/* tests/test_fidelity.c: the exact reference held to an independent integral (issue 10).
 *
 * The integral (tests/fidelity_integral.c) is a float64 plain-C integral of the shading model's
 * transmittance that shares no code with the kernels or the C twin.
 *
 * The tests query the reference (umbra_renderer_query_shadow, technique reference, its default
 * step 0.25 unless said) and assert, per case, the largest absolute error of a channel:
 *  - coloured homogeneous slab, every channel, steps 0.05 .. 2: 1e-4, and step-invariant to 1e-4;
 *  - a one-voxel opaque sheet (step TF at alpha 0.999, oblique light), points inside the band, at
 *    its lit face and behind it: FID_SHEET_BOUND;
 *  - a near-singular opacity ramp (alpha = 0.999 v over a ramp of the value): FID_RAMP_BOUND;
 *  - an alpha = 1e-6 cloud over 512 voxels at steps 0.25, 0.05 and 0.01: 3e-7 (0.06% of the
 *    attenuation 5.1e-4);
 *  - random points in a small generated volume with structure (blobs and a shell, anisotropic
 *    spacing, coloured, directional and point light): FID_RANDOM_BOUND, and the mean error;
 *  - and, rendered: an alpha = 1 sphere's lit face equals the unshadowed image to 0.02, with and
 *    without jitter (no speckles); a homogeneous dense box renders with jitter as without it
 *    (RMSE 0.01, issue #29.12).
 * Each bound is also stated in docs/hard-cases.md and docs/techniques.md ("Hard cases"). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fidelity_integral.h"

/* Measured at step 0.25 (PoCL): sheet 2.9e-6, ramp 2.8e-7, structured volume 2.9e-5 (mean
 * 3.5e-7). With steps refined at one kink (before 2026-12-01): 2.0e-6, 3.7e-4, 1.8e-4 (mean
 * 9e-6). Before issue 10 (midpoint rule, product of per-step factors): 0.56, 1.8e-2, 4.3e-2. */
#define FID_SHEET_BOUND 3e-5
#define FID_RAMP_BOUND 1e-5
#define FID_RANDOM_BOUND 5e-5
#define FID_RANDOM_MEAN_BOUND 1e-6

static uint32_t fid_rng = 0x2545f491u;
static double fid_uniform(void)
{
    fid_rng ^= fid_rng << 13;
    fid_rng ^= fid_rng >> 17;
    fid_rng ^= fid_rng << 5;
    return (fid_rng >> 8) * (1.0 / 16777216.0);
}

/* ---- the cases --------------------------------------------------------------------------------- */

/* Issue 10's example: a = 0.5 per voxel, t = (0.8, 0.45, 0.3), paths up to ~14 voxels; the old
 * per-step model gave 0.4305 at step 1 for the limit 0.3299 in red over 8 voxels. */
static void test_fidelity_coloured_slab_every_step(void **state)
{
    umbra_context ctx = *state;
    const double sp[3] = {1.0, 1.0, 1.0};
    fid_scene S = fid_alloc(12, 12, 12, sp);
    for (size_t i = 0; i < 12 * 12 * 12; ++i)
        S.voxels[i] = 0.5f;
    const float pts_tf[2][5] = {{0.0f, 0.8f, 0.45f, 0.3f, 0.5f}, {1.0f, 0.8f, 0.45f, 0.3f, 0.5f}};
    fid_tf_points(&S, pts_tf, 2);
    S.colored = 1;
    enum { N = 64 };
    float pts[3 * N];
    for (int i = 0; i < 3 * N; ++i)
        pts[i] = (float)(fid_uniform() * 11.6 - 5.8);
    const umbra_light lights[2] = {test_directional_light(0.3f, -0.8f, 0.5f),
                                   test_point_light(9.0f, 14.0f, -7.0f)};
    static const float steps[] = {0.05f, 0.1f, 0.25f, 0.5f, 1.0f, 1.5f, 2.0f};
    for (int li = 0; li < 2; ++li) {
        float first[3 * N], rgb[3 * N];
        double spread = 0.0;
        for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
            fid_stats st = fid_compare(ctx, &S, &lights[li], steps[k], pts, N, rgb);
            fid_report(li ? "coloured slab, point light" : "coloured slab, directional", steps[k],
                       &st, pts, 1e-4);
            if (k == 0)
                memcpy(first, rgb, sizeof rgb);
            for (int i = 0; i < 3 * N; ++i)
                spread = fmax(spread, fabs(rgb[i] - first[i]));
        }
        print_message("  largest change of a factor between steps: %.2e (bound 1e-4)\n", spread);
        assert_true(spread <= 1e-4);
    }
    fid_free(&S);
}

/* A one-voxel sheet (value 1 in the plane y = 8, 0 elsewhere) under a step transfer function:
 * alpha 0 below 0.5, 0.999 above. The interpolant crosses 0.5 half a voxel either side of the
 * plane, so the opaque band is one voxel thick. Points inside it, within 0.3 voxel of its lit
 * face (the midpoint rule saw none of the material in front of such a point), and behind it. */
static void test_fidelity_sheet_step_tf(void **state)
{
    umbra_context ctx = *state;
    fid_scene S = fid_alloc(16, 17, 16, NULL);
    for (int z = 0; z < 16; ++z)
        for (int x = 0; x < 16; ++x)
            S.voxels[((size_t)z * 17 + 8) * 16 + x] = 1.0f;
    const float pts_tf[4][5] = {{0.0f, 1, 1, 1, 0.0f}, {0.5f, 1, 1, 1, 0.0f},
                                {0.5f, 1, 1, 1, 0.999f}, {1.0f, 1, 1, 1, 0.999f}};
    fid_tf_points(&S, pts_tf, 4);
    /* world y of voxel row 8's centre: -8.5 + 8.5 = 0; the band is |y| < 0.5, lit face y = 0.5 */
    enum { N = 96 };
    float pts[3 * N];
    for (int i = 0; i < N; ++i) {
        double y;
        if (i < 32)
            y = -0.49 + 0.98 * fid_uniform();          /* inside */
        else if (i < 64)
            y = 0.5 - 0.3 * fid_uniform();             /* just inside the lit face */
        else
            y = -0.5 - 4.0 * fid_uniform();            /* behind */
        pts[3 * i] = (float)(fid_uniform() * 6.0 - 3.0);
        pts[3 * i + 1] = (float)y;
        pts[3 * i + 2] = (float)(fid_uniform() * 6.0 - 3.0);
    }
    const umbra_light l = test_directional_light(0.45f, -1.0f, 0.3f);
    fid_stats st = fid_compare(ctx, &S, &l, 0.25f, pts, N, NULL);
    fid_report("one-voxel sheet, step TF 0.999, oblique light", 0.25f, &st, pts, FID_SHEET_BOUND);
    fid_free(&S);
}

/* alpha = 0.999 v over a value ramp 0 -> 1 across 2 voxels (rows 6 to 8): the extinction
 * -ln(1 - 0.999 v) climbs to 6.9 per voxel at the top, nearly singular. */
static void test_fidelity_near_singular_ramp(void **state)
{
    umbra_context ctx = *state;
    fid_scene S = fid_alloc(12, 16, 12, NULL);
    for (int z = 0; z < 12; ++z)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 12; ++x) {
                double v = (y - 6.0) / 2.0;
                S.voxels[((size_t)z * 16 + y) * 12 + x] = (float)(v < 0 ? 0 : (v > 1 ? 1 : v));
            }
    const float pts_tf[2][5] = {{0.0f, 1, 1, 1, 0.0f}, {1.0f, 1, 1, 1, 0.999f}};
    fid_tf_points(&S, pts_tf, 2);
    enum { N = 64 };
    float pts[3 * N];
    for (int i = 0; i < N; ++i) {
        pts[3 * i] = (float)(fid_uniform() * 8.0 - 4.0);
        pts[3 * i + 1] = (float)(fid_uniform() * 4.0 - 2.5); /* rows 5 .. 9 */
        pts[3 * i + 2] = (float)(fid_uniform() * 8.0 - 4.0);
    }
    /* the light comes from below (low values), and at a grazing angle along the ramp */
    const umbra_light lights[2] = {test_directional_light(0.3f, 1.0f, -0.2f),
                                   test_directional_light(1.0f, 0.35f, 0.1f)};
    for (int li = 0; li < 2; ++li) {
        fid_stats st = fid_compare(ctx, &S, &lights[li], 0.25f, pts, N, NULL);
        fid_report(li ? "ramp 0.999 v, grazing light" : "ramp 0.999 v, light from below",
                   0.25f, &st, pts, FID_RAMP_BOUND);
    }
    fid_free(&S);
}

/* alpha = 1e-6 per voxel over 512 voxels: attenuation 5.1e-4, which a product of per-sample
 * factors loses at fine steps (19% of it at step 0.01 before issue 10). */
static void test_fidelity_thin_cloud_fine_steps(void **state)
{
    umbra_context ctx = *state;
    fid_scene S = fid_alloc(512, 4, 4, NULL);
    for (size_t i = 0; i < 512 * 16; ++i)
        S.voxels[i] = 0.5f;
    const float pts_tf[2][5] = {{0.0f, 1, 1, 1, 1e-6f}, {1.0f, 1, 1, 1, 1e-6f}};
    fid_tf_points(&S, pts_tf, 2);
    enum { N = 8 };
    float pts[3 * N];
    for (int i = 0; i < N; ++i) {
        pts[3 * i] = (float)(-255.5 + 40.0 * fid_uniform()); /* 472 .. 512 voxels from the face */
        pts[3 * i + 1] = (float)(fid_uniform() * 3.0 - 1.5);
        pts[3 * i + 2] = (float)(fid_uniform() * 3.0 - 1.5);
    }
    const umbra_light l = test_directional_light(-1.0f, 0.0f, 0.0f);
    static const float steps[] = {0.25f, 0.05f, 0.01f};
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
        fid_stats st = fid_compare(ctx, &S, &l, steps[k], pts, N, NULL);
        fid_report("alpha 1e-6 cloud, 512 voxels", steps[k], &st, pts, 3e-7);
    }
    fid_free(&S);
}

/* A small volume with structure: two Gaussian blobs, a thin spherical shell and a gentle
 * gradient, anisotropic spacing; a coloured transfer function with a soft and a sharp feature;
 * random points, a directional and a point light. */
static void test_fidelity_random_points_structured_volume(void **state)
{
    umbra_context ctx = *state;
    const double sp[3] = {1.0, 0.75, 1.25};
    enum { NX = 24, NY = 28, NZ = 18 };
    fid_scene S = fid_alloc(NX, NY, NZ, sp);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x) {
                double px = (x + 0.5) * sp[0] - 0.5 * NX * sp[0];
                double py = (y + 0.5) * sp[1] - 0.5 * NY * sp[1];
                double pz = (z + 0.5) * sp[2] - 0.5 * NZ * sp[2];
                double b1 = exp(-((px - 3) * (px - 3) + py * py + (pz + 2) * (pz + 2)) / 10.0);
                double b2 = 0.8 * exp(-((px + 5) * (px + 5) + (py - 4) * (py - 4) + pz * pz) / 6.0);
                double rr = sqrt(px * px + (py + 3) * (py + 3) + (pz - 3) * (pz - 3));
                double shell = exp(-(rr - 5.0) * (rr - 5.0) / 1.5);
                double v = 0.6 * b1 + 0.55 * b2 + 0.5 * shell + 0.05 * (py / (NY * sp[1]) + 0.5);
                S.voxels[((size_t)z * NY + y) * NX + x] = (float)(v > 1 ? 1 : v);
            }
    const float pts_tf[6][5] = {{0.0f, 1.0f, 1.0f, 1.0f, 0.0f},   {0.1f, 0.9f, 0.7f, 0.5f, 0.02f},
                                {0.3f, 0.8f, 0.3f, 0.2f, 0.15f},  {0.45f, 0.3f, 0.6f, 0.9f, 0.35f},
                                {0.47f, 0.9f, 0.9f, 0.8f, 0.7f}, {1.0f, 0.6f, 0.2f, 0.1f, 0.8f}};
    fid_tf_points(&S, pts_tf, 6);
    S.colored = 1;
    enum { N = 400 };
    float *pts = malloc(3 * N * sizeof *pts);
    assert_non_null(pts);
    for (int i = 0; i < N; ++i)
        for (int a = 0; a < 3; ++a)
            pts[3 * i + a] = (float)((fid_uniform() - 0.5) * S.dims[a] * sp[a] * 0.98);
    const umbra_light lights[2] = {test_directional_light(-0.4f, -0.7f, 0.55f),
                                   test_point_light(14.0f, 12.0f, -10.0f)};
    for (int li = 0; li < 2; ++li) {
        fid_stats st = fid_compare(ctx, &S, &lights[li], 0.25f, pts, N, NULL);
        fid_report(li ? "structured volume, point light" : "structured volume, directional",
                   0.25f, &st, pts, FID_RANDOM_BOUND);
        assert_true(st.sum / st.count <= FID_RANDOM_MEAN_BOUND);
    }
    free(pts);
    fid_free(&S);
}


/* Issue 10, failure 5: opaque material lit from the front renders lit, without speckles. A
 * sphere (radius 7 voxels, the value falling through 0.5 over 1.5 voxels at its surface) under a
 * step transfer function of alpha 1, seen along -z with an ortho camera, lit from the camera's
 * side; shading off, so a lit sample shows its colour times (ambient + light) exactly as
 * unshadowed. On the pixels whose sphere point faces the light (N.L > 0.5, away from the
 * silhouette) the reference image must match the unshadowed one to 0.02 per channel, with and
 * without jitter: nothing lies between such a surface and the light. Before, the shadow was taken
 * at the view sample, up to one view step behind the surface, and alpha 1 made any depth behind
 * it black: the largest difference was 1.0, on about 700 of the 929 pixels. */
static void test_fidelity_opaque_lit_surface_no_speckles(void **state)
{
    umbra_context ctx = *state;
    enum { N = 24, W = 64 };
    float *vox = malloc(N * N * N * sizeof *vox);
    assert_non_null(vox);
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x) {
                double r = sqrt((x - 11.5) * (x - 11.5) + (y - 11.5) * (y - 11.5) +
                                (z - 11.5) * (z - 11.5));
                double v = 0.5 + (7.0 - r) / 1.5;
                vox[((size_t)z * N + y) * N + x] = (float)(v < 0 ? 0 : (v > 1 ? 1 : v));
            }
    umbra_volume vol = test_volume(ctx, N, N, N, vox);
    free(vox);
    const umbra_light l = test_directional_light(-0.35f, -0.45f, -0.82f); /* toward +z camera */
    const double ll = sqrt(0.35 * 0.35 + 0.45 * 0.45 + 0.82 * 0.82);
    const double tl[3] = {0.35 / ll, 0.45 / ll, 0.82 / ll};
    umbra_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.projection = UMBRA_ORTHOGRAPHIC;
    cam.eye[2] = 40.0f;
    cam.up[1] = 1.0f;
    cam.ortho_height = 20.0f;
    const umbra_tf_point pts[4] = {{0.0f, {1, 1, 1, 0}},
                                   {0.5f, {1, 1, 1, 0}},
                                   {0.5f, {1, 1, 1, 1}},
                                   {1.0f, {1, 1, 1, 1}}};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf),
                     UMBRA_SUCCESS);
    float *none = malloc(W * W * 4 * sizeof *none), *ref = malloc(W * W * 4 * sizeof *ref);
    assert_non_null(none);
    assert_non_null(ref);
    for (int jitter = 0; jitter < 2; ++jitter) {
        umbra_render_desc o;
        umbra_render_desc_init(&o);
        o.jitter = jitter;
        umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &l, &o);
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = UMBRA_SHADOW_NONE;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, W, none), UMBRA_SUCCESS);
        sd.technique = UMBRA_SHADOW_REFERENCE;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, W, ref), UMBRA_SUCCESS);
        double worst = 0.0;
        int checked = 0, bad = 0;
        for (int py = 0; py < W; ++py)
            for (int px = 0; px < W; ++px) {
                /* the pixel's ray, and where it meets the sphere's value 0.5 (radius 7) */
                double x = ((px + 0.5) / W * 2.0 - 1.0) * 10.0;
                double y = (1.0 - (py + 0.5) / W * 2.0) * 10.0;
                double rr = 49.0 - x * x - y * y;
                if (rr < 4.0)
                    continue;
                double ndl = (x * tl[0] + y * tl[1] + sqrt(rr) * tl[2]) / 7.0;
                if (ndl < 0.5)
                    continue;
                ++checked;
                for (int c = 0; c < 3; ++c) {
                    double e = fabs(ref[4 * (py * W + px) + c] - none[4 * (py * W + px) + c]);
                    worst = fmax(worst, e);
                    bad += e > 0.02;
                }
            }
        print_message("  alpha 1, jitter %d: %d lit surface pixels, largest |reference - "
                      "unshadowed| %.4f (bound 0.02), %d channels over it\n",
                      jitter, checked, worst, bad);
        assert_true(checked > 200);
        assert_true(worst <= 0.02);
        umbra_renderer_release(r);
    }
    umbra_transfer_function_release(tf);
    free(none);
    free(ref);
    umbra_volume_release(vol);
}

/* Issue #29.12: jitter must not change a converged image. A homogeneous box of dense material
 * (alpha 0.99999 and 0.8 per voxel everywhere), seen across a corner with three faces lit
 * obliquely, exact-reference shadows, view step 0.5: the jittered image must equal the
 * unjittered one to an RMSE of 0.01 over every pixel and channel (linear, premultiplied), and to
 * 0.03 in any value away from the silhouette. The unjittered first sample, at the box's face,
 * takes its light half a step and more in front of the face; a jittered first sample lies up to
 * a step inside, and before 2026-12-01 its light did too, in the shadow of the face itself: RMSE
 * 0.119 (max 0.72) at alpha 0.99999, 0.102 (0.37) at 0.8; now 0 and 0.0043 (0.011). */
static void test_fidelity_jitter_keeps_homogeneous_dense_image(void **state)
{
    umbra_context ctx = *state;
    enum { N = 24, W = 64 };
    umbra_volume vol = test_constant_volume(ctx, N, N, N, 0.5f);
    const umbra_light l = test_directional_light(-0.45f, -0.8f, -0.4f);
    umbra_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.projection = UMBRA_PERSPECTIVE;
    cam.eye[0] = 34.0f;
    cam.eye[1] = 28.0f;
    cam.eye[2] = 40.0f;
    cam.up[1] = 1.0f;
    cam.fovy_degrees = 40.0f;
    static const float alphas[] = {0.99999f, 0.8f};
    float *img[2];
    for (int j = 0; j < 2; ++j) {
        img[j] = malloc(W * W * 4 * sizeof *img[j]);
        assert_non_null(img[j]);
    }
    for (size_t ai = 0; ai < sizeof alphas / sizeof alphas[0]; ++ai) {
        const float rgba[8] = {0.9f, 0.7f, 0.5f, alphas[ai], 0.9f, 0.7f, 0.5f, alphas[ai]};
        umbra_transfer_function tf = NULL;
        assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
        for (int jitter = 0; jitter < 2; ++jitter) {
            umbra_render_desc o;
            umbra_render_desc_init(&o);
            o.jitter = jitter;
            o.seed = 3u;
            o.ground_plane = 0;
            o.step = 0.5f;
            umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &l, &o);
            umbra_shadow_desc sd;
            umbra_shadow_desc_init(&sd);
            sd.technique = UMBRA_SHADOW_REFERENCE;
            assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render(r, W, W, img[jitter]), UMBRA_SUCCESS);
            umbra_renderer_release(r);
        }
        /* the RMSE over every pixel; the largest difference away from the silhouette (a pixel
         * whose 3 x 3 neighbourhood the box covers), where a ray's short path through an edge
         * takes one sample more or less with jitter */
        double sum = 0.0, worst = 0.0;
        int covered = 0;
        for (int i = 0; i < W * W; ++i) {
            const int x = i % W, y = i / W;
            int inside = x > 0 && y > 0 && x < W - 1 && y < W - 1;
            for (int dy = -1; inside && dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    inside &= img[0][4 * ((y + dy) * W + x + dx) + 3] > 0.99f;
            covered += inside;
            for (int c = 0; c < 3; ++c) {
                const double e = fabs((double)img[1][4 * i + c] - img[0][4 * i + c]);
                sum += e * e;
                if (inside)
                    worst = fmax(worst, e);
            }
        }
        const double rmse = sqrt(sum / (3.0 * W * W));
        print_message("  alpha %g: %d box pixels away from the silhouette; jittered against "
                      "unjittered: RMSE %.4f (bound 0.01), max %.4f there (bound 0.03)\n",
                      (double)alphas[ai], covered, rmse, worst);
        assert_true(covered > W * W / 4);
        assert_true(rmse <= 0.01);
        assert_true(worst <= 0.03);
        umbra_transfer_function_release(tf);
    }
    for (int j = 0; j < 2; ++j)
        free(img[j]);
    umbra_volume_release(vol);
}

/* A shadow ray whose length is a whole number of steps up to rounding: t_end = fl(n h) just
 * above n h, so the final partial step is positive (last = t_end - n h, exact under the fused
 * multiply-add the device may use) while its end t_start + n h rounds onto t_end. Its length in
 * voxels was taken as h_vox last / h over a t-length of 0: 0 / 0, a NaN shadow factor (two NaN
 * pixels in the 384^2 bonsai reference). Axis-aligned rays from points at x = 8 - fl(n h) in a
 * homogeneous 16^3 box, for every n and four steps whose products round up: every factor must
 * be (1 - a)^length. */
static void test_fidelity_whole_steps_up_to_rounding(void **state)
{
    umbra_context ctx = *state;
    enum { MAX_PTS = 512 };
    static const float steps[] = {0.3f, 0.7f, 0.1f, 0.45f};
    const float a = 0.3f;
    umbra_volume vol = test_constant_volume(ctx, 16, 16, 16, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, a);
    const umbra_light l = test_directional_light(-1.0f, 0.0f, 0.0f); /* toward +x */
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, l, UMBRA_TRANSMISSION_GREY);
    float pts[3 * MAX_PTS], rgb[3 * MAX_PTS], len[MAX_PTS];
    int rounded_up = 0;
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
        const float h = steps[k];
        int n_pts = 0;
        for (int n = 1; (double)n * h < 15.9 && n_pts < MAX_PTS; ++n) {
            const float t = (float)n * h, x = 8.0f - t;
            if (8.0f - x != t)
                continue; /* the box face would not lie t from the point */
            rounded_up += (double)t > (double)n * (double)h;
            pts[3 * n_pts] = x;
            pts[3 * n_pts + 1] = 0.3f;
            pts[3 * n_pts + 2] = -0.2f;
            len[n_pts++] = t;
        }
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = UMBRA_SHADOW_REFERENCE;
        sd.reference.step = h;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_query_shadow(r, pts, (size_t)n_pts, rgb), UMBRA_SUCCESS);
        for (int i = 0; i < n_pts; ++i) {
            const double want = pow(1.0 - a, len[i]);
            for (int c = 0; c < 3; ++c)
                if (!(fabs(rgb[3 * i + c] - want) <= 1e-5))
                    fail_msg("step %g, path %.9g voxels (x = %.9g): factor %g, want %.7f", h,
                             len[i], pts[3 * i], rgb[3 * i + c], want);
        }
    }
    print_message("  %d paths of fl(n h) > n h, every factor finite and exact to 1e-5\n",
                  rounded_up);
    assert_true(rounded_up >= 20);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fidelity_coloured_slab_every_step),
        cmocka_unit_test(test_fidelity_sheet_step_tf),
        cmocka_unit_test(test_fidelity_near_singular_ramp),
        cmocka_unit_test(test_fidelity_thin_cloud_fine_steps),
        cmocka_unit_test(test_fidelity_random_points_structured_volume),
        cmocka_unit_test(test_fidelity_opaque_lit_surface_no_speckles),
        cmocka_unit_test(test_fidelity_whole_steps_up_to_rounding),
        cmocka_unit_test(test_fidelity_jitter_keeps_homogeneous_dense_image),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
