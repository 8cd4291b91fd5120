// SPDX-License-Identifier: Apache-2.0
/* tests/moments_twin.h: a plain-C twin, in double, of the moment shadow map's reconstruction
 * (kernels/techniques/moments.cl), found by other means, for tests/test_moments.c.
 *
 * The kernel finds the support of the canonical representation through x0 as the roots of the
 * kernel polynomial (closed forms, Newton for the quartic) and each point's weight from the
 * Christoffel function. The twin finds the roots by bisection over a fine grid of [-1, 1] and the
 * weights by solving the Vandermonde system of the moments, both in double; where fewer than n
 * roots lie in [-1, 1] it takes the representation with both ends (x0, the n - 1 roots in [-1, 1]
 * of (1 - x^2) mu's kernel polynomial, -1 and 1). Sharing no code with the kernel, it checks
 * the kernel's arithmetic, and its bounds, computed in double from the moments the map holds,
 * are the bounds the tests hold the reference's optical depth to. */
#ifndef UMBRA_TESTS_MOMENTS_TWIN_H
#define UMBRA_TESTS_MOMENTS_TWIN_H

#include <math.h>
#include <string.h>

#define TWIN_MAX 10 /* the largest system: n + 2 <= 6 points, a Hankel order <= 5 */

/* Solves A x = b (order k, A and b overwritten, x into b) by Gaussian elimination with partial
 * pivoting; 0 when A is singular. */
static inline int twin_solve(int k, double A[TWIN_MAX][TWIN_MAX], double *b)
{
    for (int c = 0; c < k; ++c) {
        int p = c;
        for (int i = c + 1; i < k; ++i)
            if (fabs(A[i][c]) > fabs(A[p][c]))
                p = i;
        if (!(fabs(A[p][c]) > 0.0))
            return 0;
        for (int j = 0; j < k; ++j) {
            const double t = A[c][j];
            A[c][j] = A[p][j];
            A[p][j] = t;
        }
        const double t = b[c];
        b[c] = b[p];
        b[p] = t;
        for (int i = c + 1; i < k; ++i) {
            const double f = A[i][c] / A[c][c];
            for (int j = c; j < k; ++j)
                A[i][j] -= f * A[c][j];
            b[i] -= f * b[c];
        }
    }
    for (int i = k - 1; i >= 0; --i) {
        for (int j = i + 1; j < k; ++j)
            b[i] -= A[i][j] * b[j];
        b[i] /= A[i][i];
    }
    return 1;
}

static inline double twin_poly(const double *c, int deg, double x)
{
    double v = 0.0;
    for (int i = deg; i >= 0; --i)
        v = v * x + c[i];
    return v;
}

/* The roots in [-1, 1] of the kernel polynomial K(x, x0) of the measure with moments m[0..2n]
 * (the solution c of H c = (1, x0, .., x0^n), H the Hankel matrix): sign changes over 20000
 * steps, each refined by bisection. Returns how many were found (at most TWIN_MAX), -1 for a
 * singular H. */
static inline int twin_kernel_roots(const double *m, int n, double x0, double *roots)
{
    double H[TWIN_MAX][TWIN_MAX], c[TWIN_MAX];
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j)
            H[i][j] = m[i + j];
        c[i] = pow(x0, i);
    }
    if (!twin_solve(n + 1, H, c))
        return -1;
    enum { STEPS = 20000 };
    int found = 0;
    double a = -1.0, fa = twin_poly(c, n, a);
    for (int s = 1; s <= STEPS && found < TWIN_MAX; ++s) {
        double b = -1.0 + 2.0 * s / STEPS, fb = twin_poly(c, n, b);
        if (fa == 0.0) {
            roots[found++] = a;
        } else if (fa * fb < 0.0) {
            double lo = a, hi = b, flo = fa;
            for (int it = 0; it < 100; ++it) {
                const double mid = 0.5 * (lo + hi), fm = twin_poly(c, n, mid);
                if ((fm < 0.0) == (flo < 0.0))
                    lo = mid, flo = fm;
                else
                    hi = mid;
            }
            roots[found++] = 0.5 * (lo + hi);
        }
        a = b;
        fa = fb;
    }
    return found;
}

/* Weights w of the points p[0..k-1] reproducing the moments m[0..k-1]: sum w_i p_i^j = m_j. */
static inline int twin_weights(const double *p, int k, const double *m, double *w)
{
    double V[TWIN_MAX][TWIN_MAX];
    for (int j = 0; j < k; ++j) {
        for (int i = 0; i < k; ++i)
            V[j][i] = pow(p[i], j);
        w[j] = m[j];
    }
    return twin_solve(k, V, w);
}

/* The Hausdorff bounds at x0 in (-1, 1) of the measure with moments m[0..2n], m[0] = 1: lower
 * (the weight strictly below x0) and upper (lower plus x0's weight) of the canonical
 * representation through x0. Returns 0 where the moments admit none (a singular system). */
static inline int twin_bounds(const double *m, int n, double x0, double *lower, double *upper)
{
    double r[TWIN_MAX], p[TWIN_MAX], w[TWIN_MAX];
    int k = twin_kernel_roots(m, n, x0, r);
    int np;
    if (k == n) {
        p[0] = x0;
        memcpy(p + 1, r, (size_t)n * sizeof *r);
        np = n + 1;
    } else {
        double nu[2 * TWIN_MAX];
        for (int i = 0; i <= 2 * n - 2; ++i)
            nu[i] = m[i] - m[i + 2];
        k = n > 1 ? twin_kernel_roots(nu, n - 1, x0, r) : 0;
        if (k != n - 1)
            return 0;
        p[0] = x0;
        p[1] = -1.0;
        p[2] = 1.0;
        memcpy(p + 3, r, (size_t)(n - 1) * sizeof *r);
        np = n + 2;
    }
    if (!twin_weights(p, np, m, w))
        return 0;
    double lo = 0.0;
    for (int i = 1; i < np; ++i)
        lo += p[i] < x0 ? w[i] : 0.0;
    *lower = lo;
    *upper = lo + w[0];
    return 1;
}

/* The kernel's estimate of the optical depth in front of x0 (-1 < x0 < 1) from a record: b0
 * and the normalised moments mom[1..count], with the bias alpha and the overestimation beta
 * (moments.cl's mom_factor: the factor beta of the way from the bounds' lit end exp(-lo) to their
 * dark end exp(-hi), as an optical depth). Also the bounds lo and hi it lies between, for the
 * unbiased moments' measure: b0 (lower - alpha F*) / (1 - alpha) and b0 (upper - alpha F*) /
 * (1 - alpha), clamped to [0, b0]. Returns 0 where twin_bounds does. */
static inline int twin_depth(double b0, const double *mom, int count, double x0, double alpha,
                             double beta, double *estimate, double *lo, double *hi)
{
    double m[TWIN_MAX + 1];
    m[0] = 1.0;
    for (int k = 1; k <= count; ++k)
        m[k] = (1.0 - alpha) * mom[k] + ((k & 1) ? 0.0 : alpha / (k + 1));
    double lower, upper;
    if (!twin_bounds(m, count / 2, x0, &lower, &upper))
        return 0;
    const double fstar = 0.5 * (x0 + 1.0);
#define TWIN_CLAMP01(v) fmin(fmax((v), 0.0), 1.0)
    *lo = b0 * TWIN_CLAMP01((lower - alpha * fstar) / (1.0 - alpha));
    *hi = b0 * TWIN_CLAMP01((upper - alpha * fstar) / (1.0 - alpha));
    *estimate = -log(exp(-*lo) + beta * (exp(-*hi) - exp(-*lo)));
#undef TWIN_CLAMP01
    return 1;
}

#endif
