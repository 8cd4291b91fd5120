// SPDX-License-Identifier: Apache-2.0
/* tests/fidelity_integral.h: an independent float64 integral of the shading model's shadow factor
 * (fidelity_integral.c), the scenes it integrates over, and the comparison of a technique's
 * umbra_renderer_query_shadow against it. Shared by the tests that hold a technique to the
 * integral (tests/test_fidelity.c, tests/test_alignment.c, tests/test_deep_budget.c). */
#ifndef UMBRA_FIDELITY_INTEGRAL_H
#define UMBRA_FIDELITY_INTEGRAL_H

#include "test_util.h"

typedef struct fid_scene {
    float *voxels; /* normalised values, x fastest */
    int dims[3];
    double spacing[3];
    float *tf;     /* RGBA table, alpha per voxel */
    int n_tf;
    int colored;
} fid_scene;

/* Transmittance per channel from world point p toward light l, in double. */
void fid_transmittance(const fid_scene *S, const umbra_light *l, const double p[3], double T[3]);

/* A scene of nx x ny x nz zero voxels (unit spacing where spacing is NULL), no table yet. */
fid_scene fid_alloc(int nx, int ny, int nz, const double spacing[3]);

/* A 256-entry table from control points (value, r, g, b, a), as the README's text format. */
void fid_tf_points(fid_scene *S, const float (*pts)[5], int n);

void fid_free(fid_scene *S);

/* A renderer on S lit by l with shadow technique sd (the scene's volume and table are created
 * into *vol_out, *tf_out, which the caller releases). */
umbra_renderer fid_renderer_shadow(umbra_context ctx, const fid_scene *S, const umbra_light *l,
                                   const umbra_shadow_desc *sd, umbra_volume *vol_out,
                                   umbra_transfer_function *tf_out);

typedef struct fid_stats {
    double worst, sum;
    int count, worst_point;
    float got;
    double want;
} fid_stats;

/* Queries n points with technique sd and compares every channel with the integral; returns the
 * error statistics and leaves the technique's factors in rgb_out (3 n floats) if given. */
fid_stats fid_compare_shadow(umbra_context ctx, const fid_scene *S, const umbra_light *l,
                             const umbra_shadow_desc *sd, const float *pts, int n,
                             float *rgb_out);

/* fid_compare_shadow with the exact reference at a shadow-ray step of step voxels. */
fid_stats fid_compare(umbra_context ctx, const fid_scene *S, const umbra_light *l, float step,
                      const float *pts, int n, float *rgb_out);

/* Prints the statistics and fails the test if the largest error exceeds bound. */
void fid_report(const char *what, float step, const fid_stats *st, const float *pts,
                double bound);

#endif
