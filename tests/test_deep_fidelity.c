// SPDX-License-Identifier: Apache-2.0
/* tests/test_deep_fidelity.c: the deep shadow map where issue #29 found it off the reference.
 *
 *  - A box lit exactly along an axis (#29.14): points on the four faces that run along the light,
 *    on its edges and inside, against the float64 integral (tests/fidelity_integral.c), for both
 *    directions of each axis and for a 1 x 1 x 16 volume: the map within its compression
 *    tolerance epsilon, the reference to 1e-5. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fidelity_integral.h"

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
            sd.epsilon = 0.005f;
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
        cmocka_unit_test(test_deep_box_faces_along_an_axis_light),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
