// SPDX-License-Identifier: Apache-2.0
/* tests/fidelity_integral.c: see fidelity_integral.h. A float64 plain-C integral of the shading
 * model's transmittance exp(-integral of sigma(a(v(s))) (1 - t(v(s))) ds) along the shadow ray,
 * through the trilinearly interpolated volume and the documented transfer function
 * (include/umbra/transfer_function.h: the table linearly interpolated, alpha at most 1 - 2^-24
 * converted to the extinction -ln(1 - a) per voxel of the smallest spacing). It shares no code
 * with the kernels or the C twin: the path is cut where the ray crosses a plane of voxel centres
 * (there the trilinear interpolant has its kinks), and each piece is integrated by adaptive
 * Simpson in double, started on 8 sub-pieces and refined to 1e-12 per piece, so a
 * transfer-function edge as sharp as one table entry is resolved (a feature narrower than 1/8 of a
 * voxel crossing that a piece's first samples step over entirely could be missed: the scenes of
 * the tests have none). */
#include "fidelity_integral.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The trilinear interpolant at world point p (box centred on the origin, voxel centres at
 * (i + 1/2) spacing from the box corner, clamped to the border voxels). */
static double fid_value(const fid_scene *S, const double p[3])
{
    int i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        double x = (p[a] + 0.5 * S->dims[a] * S->spacing[a]) / S->spacing[a] - 0.5;
        x = x < 0.0 ? 0.0 : (x > S->dims[a] - 1 ? S->dims[a] - 1 : x);
        int i = (int)floor(x);
        if (i > S->dims[a] - 2)
            i = S->dims[a] - 2 < 0 ? 0 : S->dims[a] - 2;
        i0[a] = i;
        i1[a] = i + 1 < S->dims[a] ? i + 1 : i;
        f[a] = x - i;
    }
    double v = 0.0;
    for (int c = 0; c < 8; ++c) {
        int ix = c & 1 ? i1[0] : i0[0], iy = c & 2 ? i1[1] : i0[1], iz = c & 4 ? i1[2] : i0[2];
        double w = (c & 1 ? f[0] : 1 - f[0]) * (c & 2 ? f[1] : 1 - f[1]) * (c & 4 ? f[2] : 1 - f[2]);
        v += w * S->voxels[((size_t)iz * S->dims[1] + iy) * S->dims[0] + ix];
    }
    return v;
}

/* Extinction per voxel length of value v, per channel: the documented lookup. */
static void fid_rate(const fid_scene *S, double v, double out[3])
{
    v = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
    double x = v * (S->n_tf - 1);
    int i = (int)x;
    if (i > S->n_tf - 2)
        i = S->n_tf - 2;
    double f = x - i, c[4];
    for (int k = 0; k < 4; ++k)
        c[k] = S->tf[4 * i + k] + f * (S->tf[4 * i + 4 + k] - S->tf[4 * i + k]);
    double a = c[3] < 0.99999994039535522 ? c[3] : 0.99999994039535522;
    double sigma = -log1p(-a);
    for (int k = 0; k < 3; ++k)
        out[k] = sigma * (S->colored ? 1.0 - c[k] : 1.0);
}

typedef struct fid_ray {
    const fid_scene *S;
    double o[3], d[3];
} fid_ray;

static void fid_f(const fid_ray *R, double s, double out[3])
{
    double p[3] = {R->o[0] + s * R->d[0], R->o[1] + s * R->d[1], R->o[2] + s * R->d[2]};
    fid_rate(R->S, fid_value(R->S, p), out);
}

static void fid_simpson(const fid_ray *R, double a, double b, const double fa[3],
                        const double fm[3], const double fb[3], const double whole[3], int depth,
                        double out[3])
{
    double m = 0.5 * (a + b), l[3], r[3], fl[3], fr[3], err = 0.0;
    fid_f(R, 0.5 * (a + m), fl);
    fid_f(R, 0.5 * (m + b), fr);
    for (int k = 0; k < 3; ++k) {
        l[k] = (m - a) / 6.0 * (fa[k] + 4.0 * fl[k] + fm[k]);
        r[k] = (b - m) / 6.0 * (fm[k] + 4.0 * fr[k] + fb[k]);
        err = fmax(err, fabs(l[k] + r[k] - whole[k]));
    }
    if (depth <= 0 || err < 1e-12) {
        for (int k = 0; k < 3; ++k)
            out[k] += l[k] + r[k] + (l[k] + r[k] - whole[k]) / 15.0;
        return;
    }
    fid_simpson(R, a, m, fa, fl, fm, l, depth - 1, out);
    fid_simpson(R, m, b, fm, fr, fb, r, depth - 1, out);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void fid_transmittance(const fid_scene *S, const umbra_light *l, const double p[3], double T[3])
{
    fid_ray R = {S, {p[0], p[1], p[2]}, {0, 0, 0}};
    double dist = INFINITY;
    if (l->type == UMBRA_LIGHT_POINT) {
        double v[3] = {l->position[0] - p[0], l->position[1] - p[1], l->position[2] - p[2]};
        dist = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int a = 0; a < 3; ++a)
            R.d[a] = v[a] / dist;
    } else {
        double v[3] = {l->direction[0], l->direction[1], l->direction[2]};
        double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int a = 0; a < 3; ++a)
            R.d[a] = -v[a] / n;
    }
    double t0 = 0.0, t1 = dist;
    for (int a = 0; a < 3; ++a) {
        double h = 0.5 * S->dims[a] * S->spacing[a];
        if (R.d[a] == 0.0) {
            if (fabs(p[a]) > h)
                t1 = -1.0;
            continue;
        }
        double ta = (-h - p[a]) / R.d[a], tb = (h - p[a]) / R.d[a];
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }
    T[0] = T[1] = T[2] = 1.0;
    if (!(t1 > t0))
        return;
    /* Cuts where the ray crosses a plane of voxel centres. */
    int cap = 2 + 2 * (S->dims[0] + S->dims[1] + S->dims[2]);
    double *cuts = malloc((size_t)cap * sizeof *cuts);
    assert_non_null(cuts);
    int nc = 0;
    cuts[nc++] = t0;
    cuts[nc++] = t1;
    for (int a = 0; a < 3; ++a) {
        if (R.d[a] == 0.0)
            continue;
        double h = 0.5 * S->dims[a] * S->spacing[a];
        for (int i = 0; i < S->dims[a]; ++i) {
            double t = (-h + (i + 0.5) * S->spacing[a] - p[a]) / R.d[a];
            if (t > t0 && t < t1)
                cuts[nc++] = t;
        }
    }
    qsort(cuts, (size_t)nc, sizeof *cuts, cmp_double);
    double D[3] = {0, 0, 0};
    for (int c = 0; c + 1 < nc; ++c)
        for (int j = 0; j < 8; ++j) {
            double a = cuts[c] + (cuts[c + 1] - cuts[c]) * j / 8.0;
            double b = cuts[c] + (cuts[c + 1] - cuts[c]) * (j + 1) / 8.0;
            if (!(b > a))
                continue;
            double fa[3], fm[3], fb[3], w[3];
            fid_f(&R, a, fa);
            fid_f(&R, 0.5 * (a + b), fm);
            fid_f(&R, b, fb);
            for (int k = 0; k < 3; ++k)
                w[k] = (b - a) / 6.0 * (fa[k] + 4.0 * fm[k] + fb[k]);
            fid_simpson(&R, a, b, fa, fm, fb, w, 40, D);
        }
    free(cuts);
    double voxel = fmin(S->spacing[0], fmin(S->spacing[1], S->spacing[2]));
    for (int k = 0; k < 3; ++k)
        T[k] = exp(-D[k] / voxel);
}


fid_scene fid_alloc(int nx, int ny, int nz, const double spacing[3])
{
    fid_scene S;
    memset(&S, 0, sizeof S);
    S.dims[0] = nx;
    S.dims[1] = ny;
    S.dims[2] = nz;
    for (int a = 0; a < 3; ++a)
        S.spacing[a] = spacing ? spacing[a] : 1.0;
    S.voxels = calloc((size_t)nx * ny * nz, sizeof *S.voxels);
    assert_non_null(S.voxels);
    return S;
}

void fid_tf_points(fid_scene *S, const float (*pts)[5], int n)
{
    enum { N = 256 };
    S->n_tf = N;
    S->tf = malloc(4 * N * sizeof *S->tf);
    assert_non_null(S->tf);
    for (int e = 0; e < N; ++e) {
        float x = (float)e / (N - 1);
        int j = 0;
        while (j < n && pts[j][0] < x)
            ++j;
        for (int c = 0; c < 4; ++c) {
            float v;
            if (j == 0)
                v = pts[0][1 + c];
            else if (j == n)
                v = pts[n - 1][1 + c];
            else {
                float w = pts[j][0] > pts[j - 1][0] ? (x - pts[j - 1][0]) / (pts[j][0] - pts[j - 1][0]) : 1.0f;
                v = pts[j - 1][1 + c] + w * (pts[j][1 + c] - pts[j - 1][1 + c]);
            }
            S->tf[4 * e + c] = v;
        }
    }
}

void fid_free(fid_scene *S)
{
    free(S->voxels);
    free(S->tf);
}

umbra_renderer fid_renderer_shadow(umbra_context ctx, const fid_scene *S, const umbra_light *l,
                                   const umbra_shadow_desc *sd, umbra_volume *vol_out,
                                   umbra_transfer_function *tf_out)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = S->voxels;
    d.type = UMBRA_FLOAT32;
    for (int a = 0; a < 3; ++a) {
        d.dims[a] = (uint32_t)S->dims[a];
        d.spacing[a] = (float)S->spacing[a];
    }
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    d.brick_size = 8;
    assert_int_equal(umbra_volume_create(ctx, &d, vol_out), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_create(ctx, S->tf, (uint32_t)S->n_tf, tf_out),
                     UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = S->colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    umbra_renderer r = test_renderer(ctx, *vol_out, *tf_out, NULL, l, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, sd), UMBRA_SUCCESS);
    return r;
}

fid_stats fid_compare_shadow(umbra_context ctx, const fid_scene *S, const umbra_light *l,
                             const umbra_shadow_desc *sd, const float *pts, int n,
                             float *rgb_out)
{
    umbra_volume vol = NULL;
    umbra_transfer_function tf = NULL;
    umbra_renderer r = fid_renderer_shadow(ctx, S, l, sd, &vol, &tf);
    float *rgb = malloc((size_t)n * 3 * sizeof *rgb);
    assert_non_null(rgb);
    assert_int_equal(umbra_renderer_query_shadow(r, pts, (size_t)n, rgb), UMBRA_SUCCESS);
    fid_stats st = {0, 0, 0, -1, 0, 0};
    for (int i = 0; i < n; ++i) {
        double p[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}, T[3];
        fid_transmittance(S, l, p, T);
        for (int c = 0; c < 3; ++c) {
            double e = fabs(rgb[3 * i + c] - T[c]);
            st.sum += e;
            st.count++;
            if (e > st.worst || st.worst_point < 0) {
                st.worst = e;
                st.worst_point = i;
                st.got = rgb[3 * i + c];
                st.want = T[c];
            }
        }
    }
    if (rgb_out)
        memcpy(rgb_out, rgb, (size_t)n * 3 * sizeof *rgb);
    free(rgb);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
    return st;
}

fid_stats fid_compare(umbra_context ctx, const fid_scene *S, const umbra_light *l, float step,
                      const float *pts, int n, float *rgb_out)
{
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_REFERENCE;
    sd.reference.step = step;
    return fid_compare_shadow(ctx, S, l, &sd, pts, n, rgb_out);
}

void fid_report(const char *what, float step, const fid_stats *st, const float *pts,
                double bound)
{
    const float *p = pts + 3 * st->worst_point;
    print_message("  %s, step %g: max |error| %.2e (bound %.0e), mean %.2e; worst at (%g, %g, %g): "
                  "%.6f for %.6f\n",
                  what, step, st->worst, bound, st->sum / st->count, p[0], p[1], p[2], st->got,
                  st->want);
    if (!(st->worst <= bound))
        fail_msg("%s, step %g: error %.3e exceeds its bound %.0e", what, step, st->worst, bound);
}
