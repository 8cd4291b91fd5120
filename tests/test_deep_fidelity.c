// SPDX-License-Identifier: Apache-2.0
/* tests/test_deep_fidelity.c: the deep shadow map where issue #29 found it off the reference.
 *
 *  - Small budgets with a point light inside (#29.13). A generated head-like phantom (scalp, a
 *    skull of two dense tables round a lighter diploe, brain), a coloured point light inside it,
 *    grey transmission: the 3-node map's image against the exact reference within RMSE 0.02, at
 *    most 1% of the pixels off by more than 0.1. Through the skull every light ray has a gentle
 *    stretch (brain), two cliffs (the tables) and another gentle stretch (scalp), more than three
 *    nodes follow, so which three the fixed-budget build keeps decides what the camera sees: the
 *    outer table, lit through everything inside it. And the built-in spheres with the light
 *    among them: unbounded, 8, 4 and 3 nodes against the reference.
 *  - A box lit exactly along an axis (#29.14): points on the four faces that run along the light,
 *    on its edges and inside, against the float64 integral (tests/fidelity_integral.c), for both
 *    directions of each axis and for a 1 x 1 x 16 volume: the map within its compression
 *    tolerance epsilon, the reference to 1e-5. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fidelity_integral.h"

/* ---- the head phantom ----------------------------------------------------------------------- */

enum { HEAD_N = 64, HEAD_W = 128 };

static double unit_clamp(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* An ellipsoidal head, level r = 1 at the skin (radii 28, 24, 30 voxels, about 27 voxels per unit
 * of r): scalp and brain 0.3, the skull between r = in and r = out (both varying with direction,
 * so its thickness does) as two tables of `table` voxels at 0.9 round a diploe of 0.55, CT-like
 * noise, 1-voxel transitions. */
static float head_value(int i, int j, int k, double table)
{
    const double c = 0.5 * HEAD_N - 0.5, R = 27.0;
    const double x = i - c, y = j - c, z = k - c;
    const double ex = x / 28.0, ey = y / 24.0, ez = z / 30.0;
    const double r = sqrt(ex * ex + ey * ey + ez * ez);
    const double ang = atan2(y, x), el = atan2(z, sqrt(x * x + y * y));
    const double in = 0.80 + 0.03 * sin(3.0 * ang) * cos(2.0 * el);
    const double out = 0.91 + 0.025 * cos(2.0 * ang + el), th = table / R;
    const double skin = unit_clamp((1.0 - r) * R + 0.5);
    const double t_in = unit_clamp((r - in) * R + 0.5) - unit_clamp((r - in - th) * R + 0.5);
    const double t_out = unit_clamp((r - out + th) * R + 0.5) - unit_clamp((r - out) * R + 0.5);
    const double dip = unit_clamp((r - in - th) * R + 0.5) - unit_clamp((r - out + th) * R + 0.5);
    double v = 0.3 * skin + 0.6 * fmax(t_in, t_out) + 0.25 * dip;
    if (v > 0.0)
        v += 0.03 * test_voxel_noise(i, j, k);
    return (float)unit_clamp(v);
}

static void render_with(umbra_context ctx, umbra_renderer r, umbra_shadow_technique t,
                        uint32_t max_nodes, float *img)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = t;
    d.deep.max_nodes = max_nodes;
    assert_int_equal(umbra_renderer_set_shadow(r, &d), UMBRA_SUCCESS);
    if (umbra_renderer_render(r, HEAD_W, HEAD_W, img) != UMBRA_SUCCESS)
        fail_msg("render: %s", umbra_context_last_message(ctx));
}

/* RMSE over the RGB of every pixel, the fraction of pixels off by more than 0.1 and the largest
 * channel error (max_err may be NULL). */
static double head_rmse_max(const float *a, const float *b, double *frac_off, double *max_err)
{
    double s = 0.0, worst = 0.0;
    int off = 0;
    for (int i = 0; i < HEAD_W * HEAD_W; ++i) {
        double m = 0.0;
        for (int k = 0; k < 3; ++k) {
            const double e = (double)a[4 * i + k] - b[4 * i + k];
            s += e * e;
            m = fmax(m, fabs(e));
        }
        off += m > 0.1;
        worst = fmax(worst, m);
    }
    *frac_off = (double)off / (HEAD_W * HEAD_W);
    if (max_err)
        *max_err = worst;
    return sqrt(s / (3.0 * HEAD_W * HEAD_W));
}

static double head_rmse(const float *a, const float *b, double *frac_off)
{
    return head_rmse_max(a, b, frac_off, NULL);
}

static void test_deep_three_nodes_light_inside_head_phantom(void **state)
{
    umbra_context ctx = *state;
    /* soft tissue faint (0.01 .. 0.02 per voxel), diploe and tables dense */
    static const struct {
        double table;
        float soft, diploe, bone;
        double bound;
    } cases[] = {{2.0, 0.02f, 0.2f, 0.6f, 0.02}, {1.5, 0.01f, 0.1f, 0.5f, 0.02}};
    float *data = malloc((size_t)HEAD_N * HEAD_N * HEAD_N * sizeof *data);
    float *ref = malloc(HEAD_W * HEAD_W * 4 * sizeof *ref);
    float *img = malloc(HEAD_W * HEAD_W * 4 * sizeof *img);
    assert_true(data && ref && img);
    for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ++ci) {
        for (int k = 0; k < HEAD_N; ++k)
            for (int j = 0; j < HEAD_N; ++j)
                for (int i = 0; i < HEAD_N; ++i)
                    data[((size_t)k * HEAD_N + j) * HEAD_N + i] =
                        head_value(i, j, k, cases[ci].table);
        umbra_volume vol = test_volume_bricks(ctx, HEAD_N, HEAD_N, HEAD_N, data, 8);
        const float s = cases[ci].soft, d = cases[ci].diploe, b = cases[ci].bone;
        const umbra_tf_point p[] = {
            {0.00f, {0.0f, 0.0f, 0.0f, 0.0f}},    {0.15f, {0.0f, 0.0f, 0.0f, 0.0f}},
            {0.25f, {0.85f, 0.45f, 0.35f, s}},    {0.35f, {0.9f, 0.55f, 0.45f, s}},
            {0.55f, {0.95f, 0.75f, 0.6f, d}},     {0.85f, {1.0f, 0.95f, 0.9f, b}},
            {1.00f, {1.0f, 0.95f, 0.9f, b}}};
        umbra_transfer_function tf = NULL;
        assert_int_equal(umbra_transfer_function_create_from_points(
                             ctx, p, sizeof p / sizeof p[0], 256, &tf),
                         UMBRA_SUCCESS);
        const float dir[3] = {0.7f, 0.35f, 1.0f};
        umbra_camera cam = umbra_camera_orbit(dir, 1.6f * HEAD_N, 30.0f);
        umbra_light light = test_point_light(6.0f, 4.0f, -5.0f);
        light.color[1] = 0.85f;
        light.color[2] = 0.7f;
        umbra_render_desc o;
        umbra_render_desc_init(&o);
        o.transmission = UMBRA_TRANSMISSION_GREY;
        o.ground_plane = 0;
        umbra_renderer r = test_renderer(ctx, vol, tf, &cam, &light, &o);
        render_with(ctx, r, UMBRA_SHADOW_REFERENCE, 0, ref);
        double frac, frac3;
        render_with(ctx, r, UMBRA_SHADOW_DEEP, 0, img);
        const double e_all = head_rmse(img, ref, &frac);
        render_with(ctx, r, UMBRA_SHADOW_DEEP, 3, img);
        const double e3 = head_rmse(img, ref, &frac3);
        print_message("  head phantom, tables %.1f voxels: unbounded map RMSE %.4f; 3 nodes RMSE "
                      "%.4f (bound %.2f), %.1f%% of pixels off by > 0.1 (bound 1%%)\n",
                      cases[ci].table, e_all, e3, cases[ci].bound, 100.0 * frac3);
        /* Measured on PoCL (2026-12-02): unbounded 0.0038 / 0.0042, 3 nodes 0.0113 / 0.0108
         * with no pixel off by > 0.1; before the fixed-budget changes of 2026-12-01/02 (span
         * error by trapezoid, sqrt(v) weight, the fit within epsilon, the flat tail kept):
         * 0.0283 with 4.7% of the pixels off by > 0.1 (the first skull). */
        assert_true(e_all <= 0.006);
        assert_true(e3 <= cases[ci].bound);
        assert_true(frac3 <= 0.01);
        umbra_renderer_release(r);
        umbra_transfer_function_release(tf);
        umbra_volume_release(vol);
    }
    free(data);
    free(ref);
    free(img);
}

/* The built-in spheres (64^3, coloured transmission, ground plane) with a white point light
 * inside the box, among the spheres (#29.13), against the reference: the unbounded map and the
 * budgets 8, 4, 3; printed are RMSE, the largest channel error and the pixels off by > 0.1. */
static void test_deep_budgets_spheres_light_inside(void **state)
{
    umbra_context ctx = *state;
    static const float pos[][3] = {{0.0f, 0.0f, 0.0f}, {6.0f, -4.0f, 5.0f}};
    static const uint32_t budget[] = {0, 8, 4, 3};
    enum { NB = sizeof budget / sizeof budget[0] };
    double rmse[NB] = {0}, worst[NB] = {0}, off[NB] = {0};
    float *ref = malloc(HEAD_W * HEAD_W * 4 * sizeof *ref);
    float *img = malloc(HEAD_W * HEAD_W * 4 * sizeof *img);
    assert_true(ref && img);
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 64, &sc), UMBRA_SUCCESS);
    for (size_t li = 0; li < sizeof pos / sizeof pos[0]; ++li) {
        umbra_light light = test_point_light(pos[li][0], pos[li][1], pos[li][2]);
        umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &light, &sc.options);
        render_with(ctx, r, UMBRA_SHADOW_REFERENCE, 0, ref);
        for (int bi = 0; bi < NB; ++bi) {
            double frac, mx;
            render_with(ctx, r, UMBRA_SHADOW_DEEP, budget[bi], img);
            const double e = head_rmse_max(img, ref, &frac, &mx);
            print_message("  spheres, light at (%g, %g, %g), %s%u nodes: RMSE %.4f, max %.3f, "
                          "%.2f%% of pixels off by > 0.1\n", pos[li][0], pos[li][1], pos[li][2],
                          budget[bi] ? "" : "unbounded, ", budget[bi], e, mx, 100.0 * frac);
            rmse[bi] = fmax(rmse[bi], e);
            worst[bi] = fmax(worst[bi], mx);
            off[bi] = fmax(off[bi], frac);
        }
        umbra_renderer_release(r);
    }
    /* Measured on PoCL (2026-12-02), worst of the two lights, unbounded / 8 / 4 / 3 nodes: RMSE
     * 0.0021 / 0.0016 / 0.0090 / 0.0096, largest error 0.055 / 0.055 / 0.138 / 0.153, pixels
     * off by > 0.1 0 / 0 / 0.89% / 0.97% (3 nodes before the fixed-budget changes of
     * 2026-12-01/02: RMSE 0.0102, largest 0.141). 8 nodes are as close as the unbounded map;
     * the largest error at 3 and 4 nodes is the budget's, on the lit faces of the dense white
     * sphere seen through a coloured one (docs/hard-cases.md). */
    assert_true(rmse[0] <= 0.004 && worst[0] <= 0.07);
    assert_true(rmse[1] <= 0.003 && worst[1] <= 0.07);
    assert_true(rmse[3] <= 0.012 && off[3] <= 0.015);
    assert_true(worst[3] <= 0.2);
    umbra_scene_release(&sc);
    free(ref);
    free(img);
}

/* ---- a box lit along an axis ---------------------------------------------------------------- */

/* Points of the box nx x ny x nz (unit spacing, centred) for a light along axis `ax`: on each of
 * the four faces that run along it (a grid of positions, edges and corners included), and
 * inside. Returns the count. */
static int face_points(int nx, int ny, int nz, int ax, float *pts, int cap)
{
    const float h[3] = {0.5f * nx, 0.5f * ny, 0.5f * nz};
    const int u = (ax + 1) % 3, v = (ax + 2) % 3;
    int n = 0;
    for (int side = 0; side < 4; ++side)
        for (int i = 0; i <= 4; ++i)
            for (int j = 0; j <= 6; ++j) {
                if (n >= cap)
                    return n;
                float p[3];
                const float s = (float)i / 4.0f * 2.0f - 1.0f; /* across the face, edges at +-1 */
                const float t = (float)j / 6.0f * 2.0f - 1.0f; /* along the light */
                const int across = side < 2 ? v : u, normal = side < 2 ? u : v;
                p[ax] = t * h[ax];
                p[normal] = side % 2 ? -h[normal] : h[normal];
                p[across] = s * h[across];
                memcpy(pts + 3 * n++, p, sizeof p);
            }
    for (int i = 0; i < 8 && n < cap; ++i) {
        float p[3] = {0.3f * h[0] * (i & 1 ? 1 : -1), 0.2f * h[1] * (i & 2 ? 1 : -1),
                      (0.8f - 0.2f * i) * h[2]};
        memcpy(pts + 3 * n++, p, sizeof p);
    }
    return n;
}

static void check_axis_box(umbra_context ctx, int nx, int ny, int nz, const char *what)
{
    const double sp[3] = {1.0, 1.0, 1.0};
    fid_scene S = fid_alloc(nx, ny, nz, sp);
    for (size_t i = 0; i < (size_t)nx * ny * nz; ++i)
        S.voxels[i] = 0.5f;
    const float tf_pts[2][5] = {{0.0f, 1, 1, 1, 0.06f}, {1.0f, 1, 1, 1, 0.06f}};
    fid_tf_points(&S, tf_pts, 2);
    enum { CAP = 160 };
    float pts[3 * CAP];
    double worst_deep = 0.0, worst_ref = 0.0;
    for (int ax = 0; ax < 3; ++ax)
        for (int sign = -1; sign <= 1; sign += 2) {
            float dir[3] = {0.0f, 0.0f, 0.0f};
            dir[ax] = (float)sign;
            const umbra_light l = test_directional_light(dir[0], dir[1], dir[2]);
            const int n = face_points(nx, ny, nz, ax, pts, CAP);
            umbra_shadow_desc sd;
            umbra_shadow_desc_init(&sd);
            sd.technique = UMBRA_SHADOW_DEEP;
            sd.deep.epsilon = 0.005f;
            const fid_stats deep = fid_compare_shadow(ctx, &S, &l, &sd, pts, n, NULL);
            const fid_stats ref = fid_compare(ctx, &S, &l, 0.25f, pts, n, NULL);
            const float *w = pts + 3 * deep.worst_point;
            print_message("  %s, light along %c%c: deep map off the integral by %.2e at most "
                          "(%.4f for %.4f at (%g, %g, %g)), reference %.2e\n",
                          what, sign < 0 ? '-' : '+', "xyz"[ax], deep.worst, deep.got, deep.want,
                          w[0], w[1], w[2], ref.worst);
            worst_deep = fmax(worst_deep, deep.worst);
            worst_ref = fmax(worst_ref, ref.worst);
        }
    /* epsilon, and a little for the light step's quadrature between the map's nodes */
    assert_true(worst_deep <= 0.005 + 1e-3);
    assert_true(worst_ref <= 1e-5);
    fid_free(&S);
}

static void test_deep_box_faces_along_an_axis_light(void **state)
{
    umbra_context ctx = *state;
    check_axis_box(ctx, 12, 10, 16, "box 12 x 10 x 16");
    check_axis_box(ctx, 1, 1, 16, "box 1 x 1 x 16");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deep_three_nodes_light_inside_head_phantom),
        cmocka_unit_test(test_deep_budgets_spheres_light_inside),
        cmocka_unit_test(test_deep_box_faces_along_an_axis_light),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
