// SPDX-License-Identifier: Apache-2.0
/* tests/test_alignment.c: the exact reference wherever the trilinear interpolant's kinks fall
 * relative to its shadow-ray steps (issue #29.11).
 *
 * Along a ray the trilinear interpolant is smooth inside each cell of voxel centres and has a
 * kink where the ray crosses a plane of voxel centres; inside a cell it is a cubic in the ray
 * parameter, which can rise and fall again between two samples. The reference must integrate
 * through both wherever they lie: a kink on a step's boundary or in its middle, a peak whose two
 * flanks give its step's ends one value. Axis-aligned lights and lights on lattice points make
 * such alignments exact, so the cases place them there on purpose, at every step from 1/16 to 1
 * voxel, and assert the largest error of a channel against the independent float64 integral
 * (tests/fidelity_integral.c):
 *  - a value profile along y with five kinks (a peak among them), light along the axis, points
 *    placed so that each kink lies on a step boundary or a step's middle, exactly, 1e-5 and
 *    5e-4 voxel off: ALIGN_BOUND;
 *  - the same profile under a point light at a lattice point, points on rays whose kinks meet
 *    the steps' boundaries and middles: ALIGN_BOUND;
 *  - random voxels (kinks on all three axes, saddles inside the cells), a point light at a
 *    lattice point and points at lattice points along rays of whole-number directions, which
 *    meet planes of all three axes at once: ALIGN_BOUND.
 * A reference that samples the steps' ends and refines a step only where the extinction at them
 * differs (before 2026-12-01) misses a peak on a step's middle whole. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fidelity_integral.h"

/* Measured (PoCL): 3.4e-7, 3.3e-7, 4.6e-7 at worst over the steps. Before 2026-12-01 (the
 * reference refined a step at the one kink nearest its middle, and only where the extinction at
 * its two ends differed): 2.1e-2, 5.3e-3, 2.8e-3 at step 1, and 1.7e-3, 1.5e-3, 2.7e-4 at step
 * 1/16. */
#define ALIGN_BOUND 1e-5

static const float align_steps[] = {0.0625f, 0.1f, 0.2f, 0.25f, 0.5f, 1.0f};
#define N_STEPS (sizeof align_steps / sizeof align_steps[0])

static uint32_t align_rng = 0x9e3779b9u;
static double align_uniform(void)
{
    align_rng ^= align_rng << 13;
    align_rng ^= align_rng >> 17;
    align_rng ^= align_rng << 5;
    return (align_rng >> 8) * (1.0 / 16777216.0);
}

/* Rows 7 .. 13 of a 10 x 24 x 10 volume (unit spacing): 0, 0.3, 0.7, 1, 0.7, 0.2, 0; a kink at
 * every one of those rows, the peak at row 10 with flanks of one slope for a voxel either side
 * (a step centred on it has one value at both ends). alpha = 0.999 v. */
enum { PX = 10, PY = 24, PZ = 10 };
static const double profile_rows[7] = {0.0, 0.3, 0.7, 1.0, 0.7, 0.2, 0.0};
static fid_scene profile_scene(void)
{
    fid_scene S = fid_alloc(PX, PY, PZ, NULL);
    for (int z = 0; z < PZ; ++z)
        for (int y = 0; y < PY; ++y)
            for (int x = 0; x < PX; ++x)
                S.voxels[((size_t)z * PY + y) * PX + x] =
                    (float)(y >= 7 && y <= 13 ? profile_rows[y - 7] : 0.0);
    const float pts_tf[2][5] = {{0.0f, 1, 1, 1, 0.0f}, {1.0f, 1, 1, 1, 0.999f}};
    fid_tf_points(&S, pts_tf, 2);
    return S;
}

/* World coordinate of voxel coordinate x along an axis of n unit voxels centred on 0. */
static double world_of(double x, int n) { return x + 0.5 - 0.5 * n; }

/* The offsets of a kink from the step's boundary (0) or middle (0.5), in steps, and the shifts
 * off it in voxels. */
static const double align_offsets[2] = {0.0, 0.5};
static const double align_shifts[5] = {0.0, 1e-5, -1e-5, 5e-4, -5e-4};

static void test_alignment_axis_light_kinks_on_boundaries_and_middles(void **state)
{
    umbra_context ctx = *state;
    fid_scene S = profile_scene();
    const umbra_light l = test_directional_light(0.0f, -1.0f, 0.0f); /* the shadow ray goes +y */
    enum { MAX_PTS = 7 * 2 * 5 };
    float pts[3 * MAX_PTS];
    for (size_t si = 0; si < N_STEPS; ++si) {
        const double h = align_steps[si];
        int n = 0;
        /* a kink at row 7 + r lies (k + offset) steps plus a shift above the point */
        for (int r = 0; r < 7; ++r)
            for (int o = 0; o < 2; ++o)
                for (int s = 0; s < 5; ++s) {
                    const int k = 1 + (r + o + s) % 3;
                    const double y = 7 + r - (k + align_offsets[o]) * h + align_shifts[s];
                    pts[3 * n] = (float)world_of(1.0 + 7.0 * align_uniform(), PX);
                    pts[3 * n + 1] = (float)world_of(y, PY);
                    pts[3 * n + 2] = (float)world_of(1.0 + 7.0 * align_uniform(), PZ);
                    ++n;
                }
        fid_stats st = fid_compare(ctx, &S, &l, (float)h, pts, n, NULL);
        fid_report("kinks on steps' boundaries and middles, light along y", (float)h, &st, pts,
                   ALIGN_BOUND);
    }
    fid_free(&S);
}

/* The profile under a point light at the lattice point (4, 20, 5); each point lies on a ray
 * toward it placed so that the ray crosses the plane of one of the profile's kinks (k + offset)
 * steps from the point, plus a shift. */
static void test_alignment_lattice_light_kinks_on_boundaries_and_middles(void **state)
{
    umbra_context ctx = *state;
    fid_scene S = profile_scene();
    const double L[3] = {world_of(4, PX), world_of(20, PY), world_of(5, PZ)};
    const umbra_light l = test_point_light((float)L[0], (float)L[1], (float)L[2]);
    enum { MAX_PTS = 7 * 2 * 5 };
    float pts[3 * MAX_PTS];
    for (size_t si = 0; si < N_STEPS; ++si) {
        const double h = align_steps[si];
        int n = 0;
        for (int r = 0; r < 7; ++r)
            for (int o = 0; o < 2; ++o)
                for (int s = 0; s < 5; ++s) {
                    /* a direction toward the light, at most ~50 degrees off the y axis */
                    double u[3] = {align_uniform() - 0.5, 1.0, align_uniform() - 0.5};
                    const double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
                    for (int a = 0; a < 3; ++a)
                        u[a] /= un;
                    const int k = 1 + (r + o + s) % 3;
                    const double t = (k + align_offsets[o]) * h + align_shifts[s];
                    const double y_kink = world_of(7 + r, PY);
                    const double y = y_kink - t * u[1]; /* t from the point to the plane */
                    const double dist = (L[1] - y) / u[1];
                    for (int a = 0; a < 3; ++a)
                        pts[3 * n + a] = (float)(L[a] - dist * u[a]);
                    ++n;
                }
        fid_stats st = fid_compare(ctx, &S, &l, (float)h, pts, n, NULL);
        fid_report("kinks on steps' boundaries and middles, point light", (float)h, &st, pts,
                   ALIGN_BOUND);
    }
    fid_free(&S);
}

/* Random voxels in [0, 1] (a kink at every plane the ray crosses, saddles and peaks inside the
 * cells), alpha = 0.6 v; a point light at the lattice point (8, 8, 8) of a 16^3 volume, points
 * at lattice points m (a, b, c) away from it along whole-number directions of whole length (the
 * ray meets planes of several axes at once, at whole and half steps). */
static void test_alignment_lattice_points_random_voxels(void **state)
{
    umbra_context ctx = *state;
    enum { N = 16 };
    fid_scene S = fid_alloc(N, N, N, NULL);
    for (size_t i = 0; i < (size_t)N * N * N; ++i)
        S.voxels[i] = (float)align_uniform();
    const float pts_tf[2][5] = {{0.0f, 1, 1, 1, 0.0f}, {1.0f, 1, 1, 1, 0.6f}};
    fid_tf_points(&S, pts_tf, 2);
    const double L[3] = {world_of(8, N), world_of(8, N), world_of(8, N)};
    const umbra_light l = test_point_light((float)L[0], (float)L[1], (float)L[2]);
    static const int dirs[][3] = {{1, 2, 2},  {-2, 1, 2}, {2, -2, -1}, {0, 3, 4},  {4, 0, -3},
                                  {-3, -4, 0}, {2, 3, 6}, {-6, 2, 3},  {1, 1, 0},  {1, -1, 1},
                                  {0, 0, 1},  {-1, 0, 0}, {2, 6, -3},  {-2, -2, 1}};
    enum { N_DIRS = sizeof dirs / sizeof dirs[0] };
    float pts[3 * N_DIRS * 3];
    int n = 0;
    for (int di = 0; di < N_DIRS; ++di)
        for (int m = 1; m <= 3; ++m) {
            int ok = 1;
            for (int a = 0; a < 3; ++a) {
                const int x = 8 - m * dirs[di][a];
                ok &= x >= 0 && x <= N - 1;
            }
            if (!ok)
                continue;
            for (int a = 0; a < 3; ++a)
                pts[3 * n + a] = (float)world_of(8 - m * dirs[di][a], N);
            ++n;
        }
    assert_true(n >= 20);
    for (size_t si = 0; si < N_STEPS; ++si) {
        fid_stats st = fid_compare(ctx, &S, &l, align_steps[si], pts, n, NULL);
        fid_report("random voxels, lattice-point light and points", align_steps[si], &st, pts,
                   ALIGN_BOUND);
    }
    fid_free(&S);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alignment_axis_light_kinks_on_boundaries_and_middles),
        cmocka_unit_test(test_alignment_lattice_light_kinks_on_boundaries_and_middles),
        cmocka_unit_test(test_alignment_lattice_points_random_voxels),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
