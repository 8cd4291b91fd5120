// SPDX-License-Identifier: Apache-2.0
/* tests/reference/cpu_reference.c: see cpu_reference.h. Plain C99 with OpenMP; every formula is
 * restated here from the documented model rather than shared with the library, so a mistake in
 * one is not silently repeated in the other. Why one file past 800 lines: it is one renderer,
 * read side by side with kernels/raycast.cl and techniques/reference.cl, step for step. */
#include "cpu_reference.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct v3 {
    float x, y, z;
} v3;

static v3 mk(float x, float y, float z) { v3 r = {x, y, z}; return r; }
static v3 add(v3 a, v3 b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
static v3 sub(v3 a, v3 b) { return mk(a.x - b.x, a.y - b.y, a.z - b.z); }
static v3 mul(v3 a, float s) { return mk(a.x * s, a.y * s, a.z * s); }
static v3 vmul(v3 a, v3 b) { return mk(a.x * b.x, a.y * b.y, a.z * b.z); }
static float dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static v3 cross(v3 a, v3 b) { return mk(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static v3 norm(v3 a) { float l = sqrtf(dot(a, a)); return l > 0 ? mul(a, 1.0f / l) : a; }
static v3 from(const float *p) { return mk(p[0], p[1], p[2]); }
static float lerp(float a, float b, float t) { return a + (b - a) * t; }
/* The kernels' blend of the trilinear sample and the view table (kernels/common/sampling.cl):
 * one rounding fewer than lerp, the same on every device (fmaf is correctly rounded). */
static float lerp_fma(float a, float b, float t) { return fmaf(t, b - a, a); }
static float clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }

/* Everything derived once per render. */
typedef struct prep {
    const cpu_scene *s;
    v3 bmin, bmax, spacing, inv_spacing;
    float voxel;                  /* world length of one voxel step: the smallest spacing */
    float *view_tf, *light_tf;    /* alpha corrected for the view step / as given (light) */
    int view_n, light_n;
    unsigned char *light_bricks;  /* per brick, visible to the light transfer function */
    double *light_int;            /* per light table interval: the integral of the extinction
                                     times 1 - t (r, g, b) and times 1 (grey), table units */
    uint64_t *view_cells;         /* per brick, its visible sub-cells (CELLS^3 bits, x fastest) */
    int nb[3], B, C;              /* bricks per axis, brick edge, sub-cell edge (voxels) */
    float step, shadow_step;
    int colored, point;
    v3 light_vec;                 /* point position or unit travel direction */
} prep;

/* Voxel coordinates of world point p: voxel centres at whole numbers. */
static v3 to_voxel(const prep *P, v3 p)
{
    return mk((p.x - P->bmin.x) * P->inv_spacing.x - 0.5f,
              (p.y - P->bmin.y) * P->inv_spacing.y - 0.5f,
              (p.z - P->bmin.z) * P->inv_spacing.z - 0.5f);
}

/* The clamped trilinear sample at voxel coordinates xv. */
static float sample_voxel(const prep *P, v3 xv)
{
    const cpu_scene *s = P->s;
    float x[3] = {xv.x, xv.y, xv.z};
    int i0[3], i1[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        x[a] = clampf(x[a], 0.0f, (float)(s->dims[a] - 1));
        float fl = floorf(x[a]);
        f[a] = x[a] - fl;
        i0[a] = (int)fl;
        i1[a] = i0[a] + 1 < s->dims[a] ? i0[a] + 1 : s->dims[a] - 1;
    }
    size_t sy = (size_t)s->dims[0], sz = (size_t)s->dims[0] * s->dims[1];
#define V(X, Y, Z) s->voxels[(size_t)(Z) * sz + (size_t)(Y) * sy + (size_t)(X)]
    float c00 = lerp_fma(V(i0[0], i0[1], i0[2]), V(i1[0], i0[1], i0[2]), f[0]);
    float c10 = lerp_fma(V(i0[0], i1[1], i0[2]), V(i1[0], i1[1], i0[2]), f[0]);
    float c01 = lerp_fma(V(i0[0], i0[1], i1[2]), V(i1[0], i0[1], i1[2]), f[0]);
    float c11 = lerp_fma(V(i0[0], i1[1], i1[2]), V(i1[0], i1[1], i1[2]), f[0]);
#undef V
    return lerp_fma(lerp_fma(c00, c10, f[1]), lerp_fma(c01, c11, f[1]), f[2]);
}

static float sample(const prep *P, v3 p) { return sample_voxel(P, to_voxel(P, p)); }

static void lookup(const float *tf, int n, float v, float out[4])
{
    float x = clampf(v, 0.0f, 1.0f) * (float)(n - 1);
    int i = (int)x < n - 2 ? (int)x : n - 2;
    float f = x - (float)i;
    for (int c = 0; c < 4; ++c)
        out[c] = lerp(tf[4 * i + c], tf[4 * i + 4 + c], f);
}

/* lookup in a table of n + 1 entries whose last two are equal (corrected's view table; the
 * kernels' tf_classify): the interval's first entry is x's integer part, with no clamp. */
static void view_lookup(const float *tf, int n, float v, float out[4])
{
    float x = clampf(v, 0.0f, 1.0f) * (float)(n - 1);
    int i = (int)x;
    float f = x - (float)i;
    for (int c = 0; c < 4; ++c)
        out[c] = lerp_fma(tf[4 * i + c], tf[4 * i + 4 + c], f);
}

/* tf with alpha corrected for the step (as given for step 0), followed by a copy of its last
 * entry (view_lookup). */
static float *corrected(const float *tf, int n, float step_voxels)
{
    float *t = malloc((size_t)(n + 1) * 4 * sizeof *t);
    if (!t)
        return NULL;
    for (int i = 0; i < n; ++i) {
        memcpy(t + 4 * i, tf + 4 * i, 3 * sizeof *t);
        double a = tf[4 * i + 3];
        t[4 * i + 3] = step_voxels == 0.0f ? (float)a
                       : a < 1.0 ? (float)-expm1((double)step_voxels * log1p(-a))
                                 : 1.0f;
    }
    memcpy(t + 4 * n, t + 4 * (n - 1), 4 * sizeof *t);
    return t;
}

/* Whether some table entry that values in [lo, hi] interpolate has alpha > 0. */
static int range_visible(const float *tf, int n, float lo, float hi)
{
    int a = (int)floorf(lo * (n - 1)), b = (int)ceilf(hi * (n - 1));
    a = a < 0 ? 0 : a;
    b = b > n - 1 ? n - 1 : b;
    for (int i = a; i <= b; ++i)
        if (tf[4 * i + 3] > 0.0f)
            return 1;
    return 0;
}

/* 1 per brick if any voxel its trilinear footprint reads maps to alpha > 0. */
static unsigned char *bricks(const prep *P, const float *tf, int n)
{
    const cpu_scene *s = P->s;
    const int B = P->B;
    unsigned char *out = calloc((size_t)P->nb[0] * P->nb[1] * P->nb[2], 1);
    if (!out)
        return NULL;
    for (int bz = 0; bz < P->nb[2]; ++bz)
        for (int by = 0; by < P->nb[1]; ++by)
            for (int bx = 0; bx < P->nb[0]; ++bx) {
                float lo = FLT_MAX, hi = -FLT_MAX;
                for (int z = bz * B; z <= bz * B + B && z < s->dims[2]; ++z)
                    for (int y = by * B; y <= by * B + B && y < s->dims[1]; ++y)
                        for (int x = bx * B; x <= bx * B + B && x < s->dims[0]; ++x) {
                            float v = s->voxels[((size_t)z * s->dims[1] + y) * s->dims[0] + x];
                            lo = v < lo ? v : lo;
                            hi = v > hi ? v : hi;
                        }
                out[((size_t)bz * P->nb[1] + by) * P->nb[0] + bx] =
                    (unsigned char)range_visible(tf, n, lo, hi);
            }
    return out;
}

/* The kernels' UMBRA_BRICK_CELLS (kernels/common/umbra_shared.h): each brick split into CELLS^3
 * sub-cells of ceil(B / CELLS) voxels. Bit (x + CELLS (y + CELLS z)) of a brick's mask is set if
 * a voxel of the sub-cell's trilinear footprint (clamped to the grid; a cell beyond the last
 * voxel takes the last voxel) maps to alpha > 0. */
enum { CELLS = 4 };

static uint64_t *cells(const prep *P, const float *tf, int n)
{
    const cpu_scene *s = P->s;
    const int B = P->B, C = P->C;
    uint64_t *out = calloc((size_t)P->nb[0] * P->nb[1] * P->nb[2], sizeof *out);
    if (!out)
        return NULL;
    for (int bz = 0; bz < P->nb[2]; ++bz)
        for (int by = 0; by < P->nb[1]; ++by)
            for (int bx = 0; bx < P->nb[0]; ++bx)
                for (int c = 0; c < CELLS * CELLS * CELLS; ++c) {
                    int cell[3] = {c % CELLS, (c / CELLS) % CELLS, c / (CELLS * CELLS)};
                    int brick[3] = {bx, by, bz}, lo3[3], hi3[3];
                    for (int a = 0; a < 3; ++a) {
                        int s0 = brick[a] * B + cell[a] * C, last = s->dims[a] - 1;
                        lo3[a] = s0 < last ? s0 : last;
                        hi3[a] = s0 + C < last ? s0 + C : last;
                    }
                    float lo = FLT_MAX, hi = -FLT_MAX;
                    for (int z = lo3[2]; z <= hi3[2]; ++z)
                        for (int y = lo3[1]; y <= hi3[1]; ++y)
                            for (int x = lo3[0]; x <= hi3[0]; ++x) {
                                float v = s->voxels[((size_t)z * s->dims[1] + y) * s->dims[0] + x];
                                lo = v < lo ? v : lo;
                                hi = v > hi ? v : hi;
                            }
                    if (range_visible(tf, n, lo, hi))
                        out[((size_t)bz * P->nb[1] + by) * P->nb[0] + bx] |= (uint64_t)1 << c;
                }
    return out;
}

/* The view ray's walk over the bricks' sub-cells (the kernels' CellWalk, kernels/common/common.cl):
 * a
 * 3D DDA in voxel coordinates; along each axis brick b's cell j covers [b B + j C,
 * b B + min((j + 1) C, B)), the border cells reaching on to infinity. */
typedef struct walk {
    float xo[3], xd[3], inv[3]; /* the ray in voxel coordinates, 1 / its direction */
    int dir[3], b[3], c[3];  /* direction signs; the current cell's brick and index in it */
    float face[3];           /* parameter at which the ray leaves the cell through each axis */
    float t_in;              /* and at which it entered it */
} walk;

static float walk_face(const prep *P, const walk *w, int a)
{
    const int B = P->B, C = P->C;
    if (w->dir[a] > 0) {
        int hi = (w->c[a] + 1) * C < B ? (w->c[a] + 1) * C : B;
        return (w->b[a] == P->nb[a] - 1 && hi == B) ? INFINITY
                                                     : ((float)(w->b[a] * B + hi) - w->xo[a]) * w->inv[a];
    }
    if (w->dir[a] < 0)
        return (w->b[a] == 0 && w->c[a] == 0) ? INFINITY
                                               : ((float)(w->b[a] * B + w->c[a] * C) - w->xo[a]) * w->inv[a];
    return INFINITY;
}

/* The cell of the current brick holding voxel position x along axis a, clamped into the brick. */
static int walk_cell_at(const prep *P, const walk *w, int a, float x)
{
    const int B = P->B, C = P->C;
    int c = (int)floorf((x - (float)(w->b[a] * B)) / (float)C);
    return c < 0 ? 0 : (c > (B - 1) / C ? (B - 1) / C : c);
}

static int brick_of(const prep *P, v3 p, int b[3]);

static void walk_begin(const prep *P, walk *w, v3 o, v3 d, float t)
{
    float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    float bmin[3] = {P->bmin.x, P->bmin.y, P->bmin.z};
    float is[3] = {P->inv_spacing.x, P->inv_spacing.y, P->inv_spacing.z};
    for (int a = 0; a < 3; ++a) {
        float xd = dd[a] * is[a];
        w->xo[a] = (oo[a] - bmin[a]) * is[a] - 0.5f;
        w->xd[a] = xd;
        w->inv[a] = 1.0f / xd;
        w->dir[a] = xd > 0.0f ? 1 : (xd < 0.0f ? -1 : 0);
    }
    brick_of(P, add(o, mul(d, t)), w->b);
    for (int a = 0; a < 3; ++a)
        w->c[a] = walk_cell_at(P, w, a, w->xo[a] + t * w->xd[a]);
    for (int a = 0; a < 3; ++a)
        w->face[a] = walk_face(P, w, a);
    w->t_in = t;
}

static float walk_exit(const walk *w)
{
    return fminf(fminf(w->face[0], w->face[1]), w->face[2]);
}

static void walk_advance(const prep *P, walk *w)
{
    const int B = P->B, C = P->C;
    int a = w->face[0] <= w->face[1] && w->face[0] <= w->face[2] ? 0 : (w->face[1] <= w->face[2] ? 1 : 2);
    w->t_in = walk_exit(w);
    if (w->dir[a] > 0) {
        if (((w->c[a] + 1) * C < B ? (w->c[a] + 1) * C : B) == B) {
            ++w->b[a];
            w->c[a] = 0;
        } else {
            ++w->c[a];
        }
    } else if (w->c[a] == 0) {
        --w->b[a];
        w->c[a] = (B - 1) / C;
    } else {
        --w->c[a];
    }
    w->face[a] = walk_face(P, w, a);
}

/* Moves the walk out of the current brick, all of whose cells are invisible, into the cell of
 * the next brick where the ray enters it (the kernels' walk_skip_brick); t_in = infinity when
 * the ray leaves the grid. */
static void walk_skip_brick(const prep *P, walk *w)
{
    const int B = P->B, C = P->C, last = (B - 1) / C;
    float tb[3];
    for (int a = 0; a < 3; ++a) {
        tb[a] = INFINITY;
        if (w->dir[a] > 0 && w->b[a] < P->nb[a] - 1)
            tb[a] = ((float)((w->b[a] + 1) * B) - w->xo[a]) * w->inv[a];
        if (w->dir[a] < 0 && w->b[a] > 0)
            tb[a] = ((float)(w->b[a] * B) - w->xo[a]) * w->inv[a];
    }
    float t = fminf(fminf(tb[0], tb[1]), tb[2]);
    if (!(t < INFINITY)) {
        w->t_in = INFINITY;
        return;
    }
    for (int a = 0; a < 3; ++a)
        w->c[a] = walk_cell_at(P, w, a, w->xo[a] + t * w->xd[a]);
    int e = tb[0] <= tb[1] && tb[0] <= tb[2] ? 0 : (tb[1] <= tb[2] ? 1 : 2);
    w->b[e] += w->dir[e];
    w->c[e] = w->dir[e] > 0 ? 0 : last;
    for (int a = 0; a < 3; ++a)
        w->face[a] = walk_face(P, w, a);
    w->t_in = t;
}

/* Walks on to the first visible cell that the ray leaves after t; returns where the ray entered
 * it (at most t if t lies in it), or infinity if none begins before t_end. */
static float walk_to_visible(const prep *P, walk *w, float t, float t_end)
{
    for (;;) {
        if (!(w->t_in < t_end))
            return INFINITY;
        uint64_t mask = P->view_cells[(w->b[2] * P->nb[1] + w->b[1]) * P->nb[0] + w->b[0]];
        if (!mask) {
            walk_skip_brick(P, w);
            continue;
        }
        float t_out = walk_exit(w);
        if (t_out > t) {
            int bit = (w->c[2] * CELLS + w->c[1]) * CELLS + w->c[0];
            if ((mask >> bit) & 1u)
                return w->t_in;
        }
        if (!(t_out < INFINITY))
            return INFINITY;
        walk_advance(P, w);
    }
}

/* The end of the run of visible cells that begins with the walk's current (visible) cell: the
 * walk moves on while the next cell is visible too and stops in the first invisible one, or in
 * the last visible one where the ray ends before t_end (the kernels' walk_next_sample). */
static float walk_run_end(const prep *P, walk *w, float t_end)
{
    for (;;) {
        float t_out = walk_exit(w);
        if (!(t_out < t_end))
            return t_out;
        walk_advance(P, w);
        uint64_t mask = P->view_cells[(w->b[2] * P->nb[1] + w->b[1]) * P->nb[0] + w->b[0]];
        int bit = (w->c[2] * CELLS + w->c[1]) * CELLS + w->c[0];
        if (!((mask >> bit) & 1u))
            return w->t_in;
    }
}

/* The integral over a table interval (table units) between the entries e0 and e1 (RGBA) of the
 * extinction -ln(1 - a) times 1 - t_c (c = r, g, b) and times 1 (grey), a and t linear between
 * them, a at most 1 - 2^-24 (clamped at the entries): in double, from the substitution
 * q = 1 - a. Over tau in [0, 1] from the more transparent end e, with x = 1 - (1 - a_o) /
 * (1 - a_e) the relative fall of q: int -ln q = s_e + A(x), int tau (-ln q) = s_e / 2 + B(x),
 * A(x) = 1 + (1 - x) ln(1 - x) / x, B(x) = (-ln(1 - x) (1 - 1 / x^2) + 1 / x + 1 / 2) / 2, summed
 * as their Taylor series for x < 1/2 where those cancel. *s_e, *s_o: the ends' extinctions
 * -ln(1 - a) (if not NULL). */
static void linear_extinction(const float *e0, const float *e1, double out[4], double *s_e,
                              double *s_o)
{
    const double amax = 0.99999994039535522;
    double a0 = e0[3] < amax ? e0[3] : amax, a1 = e1[3] < amax ? e1[3] : amax;
    const float *ce = a1 >= a0 ? e0 : e1, *co = a1 >= a0 ? e1 : e0;
    double ae = a1 >= a0 ? a0 : a1, ao = a1 >= a0 ? a1 : a0;
    double se = -log1p(-ae), so = -log1p(-ao), x = (ao - ae) / (1.0 - ae), A = 0.0, B = 0.0;
    if (x < 0.5) {
        double xk = 1.0;
        for (int k = 1; k <= 60; ++k) {
            xk *= x;
            A += xk / ((double)k * (k + 1));
            B += xk / ((double)k * (k + 2));
        }
    } else {
        double L = so - se;
        A = 1.0 - (1.0 - ao) / (1.0 - ae) * L / x;
        B = 0.5 * (L * (1.0 - 1.0 / (x * x)) + 1.0 / x + 0.5);
    }
    for (int k = 0; k < 3; ++k)
        out[k] = (1.0 - ce[k]) * (se + A) + (ce[k] - co[k]) * (0.5 * se + B);
    out[3] = se + A;
    if (s_e)
        *s_e = se;
    if (s_o)
        *s_o = so;
}

static void prep_init(prep *P, const cpu_scene *s)
{
    memset(P, 0, sizeof *P);
    P->s = s;
    v3 ext = mk(s->dims[0] * s->spacing[0], s->dims[1] * s->spacing[1], s->dims[2] * s->spacing[2]);
    P->bmin = mul(ext, -0.5f);
    P->bmax = mul(ext, 0.5f);
    P->spacing = from(s->spacing);
    P->inv_spacing = mk(1.0f / s->spacing[0], 1.0f / s->spacing[1], 1.0f / s->spacing[2]);
    P->voxel = fminf(s->spacing[0], fminf(s->spacing[1], s->spacing[2]));
    P->step = s->opts.step * P->voxel;
    P->shadow_step = s->reference_step * P->voxel;
    P->B = s->brick_size;
    P->C = (P->B + CELLS - 1) / CELLS;
    for (int a = 0; a < 3; ++a)
        P->nb[a] = (s->dims[a] + P->B - 1) / P->B;
    const float *ltf = s->light_tf ? s->light_tf : s->tf;
    P->light_n = s->light_tf ? s->light_tf_count : s->tf_count;
    P->view_n = s->tf_count;
    P->view_tf = corrected(s->tf, s->tf_count, s->opts.step);
    P->light_tf = corrected(ltf, P->light_n, 0.0f);
    P->view_cells = cells(P, s->tf, s->tf_count);
    P->light_bricks = bricks(P, ltf, P->light_n);
    P->light_int = malloc((size_t)4 * (P->light_n - 1) * sizeof *P->light_int);
    if (P->light_int)
        for (int i = 0; i + 1 < P->light_n; ++i)
            linear_extinction(ltf + 4 * i, ltf + 4 * i + 4, P->light_int + 4 * i, NULL, NULL);
    P->colored = s->opts.transmission == UMBRA_TRANSMISSION_COLORED;
    P->point = s->light.type == UMBRA_LIGHT_POINT;
    P->light_vec = P->point ? from(s->light.position) : norm(from(s->light.direction));
}

static void prep_free(prep *P)
{
    free(P->view_tf);
    free(P->light_tf);
    free(P->view_cells);
    free(P->light_bricks);
    free(P->light_int);
}

/* The interval [*t0, *t1] of o + t d inside the box; *t1 < *t0 when the ray misses. */
static void ray_box(const prep *P, v3 o, v3 d, float *t0, float *t1)
{
    float lo = -INFINITY, hi = INFINITY;
    float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    float bmin[3] = {P->bmin.x, P->bmin.y, P->bmin.z}, bmax[3] = {P->bmax.x, P->bmax.y, P->bmax.z};
    /* Multiplying by the reciprocal, as the kernel does, so both round alike: a one-ulp
     * difference in the entry point can change the number of samples on a ray. A ray parallel
     * to an axis lies in its slab (faces included) for every t or for none. */
    for (int a = 0; a < 3; ++a) {
        if (dd[a] == 0.0f) {
            if (!(oo[a] >= bmin[a] && oo[a] <= bmax[a]))
                lo = INFINITY, hi = -INFINITY;
            continue;
        }
        float inv = 1.0f / dd[a];
        float ta = (bmin[a] - oo[a]) * inv, tb = (bmax[a] - oo[a]) * inv;
        lo = fmaxf(lo, fminf(ta, tb));
        hi = fminf(hi, fmaxf(ta, tb));
    }
    *t0 = lo;
    *t1 = hi;
}

static int brick_of(const prep *P, v3 p, int b[3])
{
    float x[3] = {((p.x - P->bmin.x) * P->inv_spacing.x - 0.5f) / P->B,
                  ((p.y - P->bmin.y) * P->inv_spacing.y - 0.5f) / P->B,
                  ((p.z - P->bmin.z) * P->inv_spacing.z - 0.5f) / P->B};
    for (int a = 0; a < 3; ++a) {
        int i = (int)floorf(x[a]);
        b[a] = i < 0 ? 0 : (i > P->nb[a] - 1 ? P->nb[a] - 1 : i);
    }
    return (b[2] * P->nb[1] + b[1]) * P->nb[0] + b[0];
}

static int next_after(float t0, float h, float off, float t_exit, int k)
{
    float kk = ceilf((t_exit - t0) / h - off);
    return kk > (float)(k + 1) ? (int)fminf(kk, 2147483000.0f) : k + 1;
}

/* Unit vector to the light and the distance to it. */
static v3 to_light(const prep *P, v3 p, float *dist)
{
    if (P->point) {
        v3 v = sub(P->light_vec, p);
        float l = sqrtf(dot(v, v));
        *dist = l;
        return l > 0.0f ? mul(v, 1.0f / l) : mk(0, 1, 0);
    }
    *dist = INFINITY;
    return mul(P->light_vec, -1.0f);
}

/* The shading model's light transport (renderer.h): extinction -ln(1 - a) per voxel of the
 * interpolated alpha, a at most 1 - 2^-24, times 1 - t_c per channel (t = 0 in grey mode). */
static void depth_rate(const prep *P, const float c[4], float out[3])
{
    float a = c[3] < 0.99999994f ? c[3] : 0.99999994f;
    float sigma = -log1pf(-a);
    for (int ch = 0; ch < 3; ++ch)
        out[ch] = sigma * (P->colored ? 1.0f - c[ch] : 1.0f);
}

/* The integral over [a, b] (table units, within one interval) of the extinction rate per
 * channel, added to out: linear_extinction between the interpolated ends, times b - a; lo, hi
 * take the range of the ends' rates (the rate is monotonic in a). A transparent interval adds 0
 * and sets lo to 0, as the kernel does. */
static void piece(const prep *P, float a, float b, double out[3], float *lo, float *hi)
{
    const int n = P->light_n;
    int i = (int)a < n - 2 ? (int)a : n - 2;
    const float *t = P->light_tf + 4 * i;
    if (t[3] == 0.0f && t[7] == 0.0f) {
        *lo = 0.0f;
        return;
    }
    float ca[4], cb[4];
    for (int k = 0; k < 4; ++k) {
        ca[k] = lerp(t[k], t[4 + k], a - (float)i);
        cb[k] = lerp(t[k], t[4 + k], b - (float)i);
    }
    double m[4], sa, sb;
    linear_extinction(ca, cb, m, &sa, &sb);
    if (cb[3] < ca[3]) { /* s_e belongs to b */
        double s = sa;
        sa = sb;
        sb = s;
    }
    for (int ch = 0; ch < 3; ++ch) {
        out[ch] += (double)(b - a) * (P->colored ? m[ch] : m[3]);
        float ra = (float)sa * (P->colored ? 1.0f - ca[ch] : 1.0f);
        float rb = (float)sb * (P->colored ? 1.0f - cb[ch] : 1.0f);
        *lo = fminf(*lo, fminf(ra, rb));
        *hi = fmaxf(*hi, fmaxf(ra, rb));
    }
}

/* Optical depth of a segment of len voxels whose value runs linearly from v0 to v1: len times
 * the mean extinction over [v0, v1]: the partial table intervals at the ends and the whole ones
 * between in closed form (piece, light_int), as kernels/techniques/reference.cl; *spread: the range
 * of the extinction over the pieces' ends and the whole intervals' mean, times len. */
static void segment(const prep *P, float v0, float v1, float len, float out[3], float *spread)
{
    const int n = P->light_n;
    const float last = (float)(n - 1);
    float x0 = clampf(v0 < v1 ? v0 : v1, 0.0f, 1.0f) * last;
    float x1 = clampf(v0 < v1 ? v1 : v0, 0.0f, 1.0f) * last;
    float span = x1 - x0, c[4], r[3];
    float lo = INFINITY, hi = 0.0f;
    double sum[3] = {0, 0, 0};
    *spread = 0.0f;
    if (!(span > 0.0f)) {
        lookup(P->light_tf, n, x0 / last, c);
        depth_rate(P, c, r);
        for (int ch = 0; ch < 3; ++ch)
            out[ch] = r[ch] * len;
        return;
    }
    int i0 = (int)x0 < n - 2 ? (int)x0 : n - 2, i1 = (int)x1 < n - 2 ? (int)x1 : n - 2;
    if (i0 == i1) {
        piece(P, x0, x1, sum, &lo, &hi);
    } else {
        piece(P, x0, (float)(i0 + 1), sum, &lo, &hi);
        piece(P, (float)i1, x1, sum, &lo, &hi);
        if (i1 > i0 + 1) {
            double whole[4] = {0, 0, 0, 0};
            for (int i = i0 + 1; i < i1; ++i)
                for (int k = 0; k < 4; ++k)
                    whole[k] += P->light_int[4 * i + k];
            for (int ch = 0; ch < 3; ++ch) {
                double w = P->colored ? whole[ch] : whole[3];
                sum[ch] += w;
                float mean = (float)(w / (i1 - i0 - 1));
                lo = fminf(lo, mean);
                hi = fmaxf(hi, mean);
            }
        }
    }
    for (int ch = 0; ch < 3; ++ch)
        out[ch] = (float)(sum[ch] * (len / span));
    *spread = (hi - lo) * len;
}

/* The interpolant along the ray over one cell's part [ta, ta + len] of it (t the ray parameter), a
 * cubic in s = t - ta: v = c[0] + c[1] s + c[2] s^2 + c[3] s^3, fitted in double through its
 * values at s = 0, len / 3, 2 len / 3, len (Newton's divided differences). The kernel expands the
 * cell's trilinear blend instead; this form shares no algebra with it. */
typedef struct cubic {
    double ta, c[4];
} cubic;

static cubic cell_cubic(const prep *P, v3 p, v3 d, float ta, float len)
{
    cubic q;
    double s[4], f[4];
    for (int i = 0; i < 4; ++i) {
        s[i] = len * (double)i / 3.0;
        f[i] = sample(P, add(p, mul(d, ta + (float)s[i])));
    }
    for (int j = 1; j < 4; ++j) /* divided differences, in place */
        for (int i = 3; i >= j; --i)
            f[i] = (f[i] - f[i - 1]) / (s[i] - s[i - j]);
    /* f[0] + f[1] s + f[2] s (s - s1) + f[3] s (s - s1) (s - s2) */
    q.ta = ta;
    q.c[0] = f[0];
    q.c[1] = f[1] - f[2] * s[1] + f[3] * s[1] * s[2];
    q.c[2] = f[2] - f[3] * (s[1] + s[2]);
    q.c[3] = f[3];
    return q;
}

/* The piece [ta, tb] of a cell's part: the most the cubic departs from its chord there, and the
 * integral of its departure: v - chord = (s - sa)(s - sb)(c2 + c3 (sa + sb + s)). */
static double cubic_bend(const cubic *q, float ta, float tb)
{
    double sa = ta - q->ta, sb = tb - q->ta, l = sb - sa;
    return 0.25 * l * l *
           fmax(fabs(q->c[2] + q->c[3] * (2 * sa + sb)), fabs(q->c[2] + q->c[3] * (sa + 2 * sb)));
}

static double cubic_bend_integral(const cubic *q, float ta, float tb)
{
    double sa = ta - q->ta, sb = tb - q->ta, l = sb - sa;
    return -l * l * l / 6.0 * (q->c[2] + 1.5 * q->c[3] * (sa + sb));
}

/* The depth of the piece [ta, tb] of the ray p + t d within one cell (va, vb its ends' values,
 * monotonic between), as kernels/techniques/reference.cl takes it: segment's depth, which takes
 * the value linear, plus the extinction's secant slope between the ends times the integral of
 * the cubic's departure from its chord (where the spread times the bend exceeds 1e-7 |vb - va|);
 * *err: the spread times the bend over |vb - va|, what that leaves at most. */
static void piece_curved(const prep *P, const cubic *q, float ta, float tb, float va, float vb,
                         float per_t, double out[3], double *err)
{
    float f[3], spread;
    segment(P, va, vb, (tb - ta) * per_t, f, &spread);
    const double dv = (double)vb - va, bent = spread * cubic_bend(q, ta, tb);
    *err = 0.0;
    for (int ch = 0; ch < 3; ++ch)
        out[ch] = f[ch];
    if (bent > 1e-7 * fabs(dv)) {
        float ca[4], cb[4], ra[3], rb[3];
        lookup(P->light_tf, P->light_n, va, ca);
        lookup(P->light_tf, P->light_n, vb, cb);
        depth_rate(P, ca, ra);
        depth_rate(P, cb, rb);
        for (int ch = 0; ch < 3; ++ch)
            out[ch] += (rb[ch] - ra[ch]) / dv * cubic_bend_integral(q, ta, tb) * per_t;
        *err = bent / fabs(dv);
    }
}

/* A piece's depth (piece_curved, whole: w, err), refined as the kernel does: where err exceeds
 * 1e-4 times scale (1 over the transmittance the light keeps to the piece) the piece is halved
 * at its middle, and where the halves differ from the whole by more than 3e-5 times scale, each
 * is refined in turn (at most 3 deep); else the halves are kept. Depths added to D. */
static void piece_refined(const prep *P, v3 p, v3 d, const cubic *q, float ta, float tb,
                          float va, float vb, float per_t, int level, float scale,
                          const double w[3], double err, double D[3])
{
    if (level < 3 && err > 1e-4 * scale) {
        float tm = 0.5f * (ta + tb), vm = sample(P, add(p, mul(d, tm)));
        double l[3], r[3], el, er, diff = 0.0;
        piece_curved(P, q, ta, tm, va, vm, per_t, l, &el);
        piece_curved(P, q, tm, tb, vm, vb, per_t, r, &er);
        for (int ch = 0; ch < 3; ++ch)
            diff = fmax(diff, fabs(l[ch] + r[ch] - w[ch]));
        if (diff > 3e-5 * scale) {
            piece_refined(P, p, d, q, ta, tm, va, vm, per_t, level + 1, scale, l, el, D);
            piece_refined(P, p, d, q, tm, tb, vm, vb, per_t, level + 1, scale, r, er, D);
            return;
        }
        for (int ch = 0; ch < 3; ++ch)
            D[ch] += l[ch] + r[ch];
        return;
    }
    for (int ch = 0; ch < 3; ++ch)
        D[ch] += w[ch];
}

/* The next parameter after t at which the ray xo + t xd (voxel coordinates, axis a) crosses a
 * plane of voxel centres of the grid before t_end, or t_end. */
static float next_plane(const prep *P, const float xo[3], const float xd[3], int a, float t,
                        float t_end)
{
    if (xd[a] == 0.0f)
        return t_end;
    const int last = P->s->dims[a] - 1;
    const float x = xo[a] + t * xd[a];
    int k = xd[a] > 0.0f ? (int)floorf(x) + 1 : (int)ceilf(x) - 1;
    for (;;) {
        if (xd[a] > 0.0f ? k > last : k < 0)
            return t_end;
        if (xd[a] > 0.0f && k < 0)
            k = 0;
        if (xd[a] < 0.0f && k > last)
            k = last;
        float tk = ((float)k - xo[a]) / xd[a];
        if (tk > t)
            return fminf(tk, t_end);
        k += xd[a] > 0.0f ? 1 : -1; /* rounding put the plane at or before t */
    }
}

/* The exact reference's shadow ray: the path inside the box (and before a point light) cut where
 * it crosses a plane of voxel centres (the interpolant's kinks); each cell's part cut further at
 * the steps of h from the point and at the interpolant's extrema (the roots of its cubic's
 * derivative), so that every piece's value is smooth and monotonic; each piece integrated by
 * piece_refined, depths summed in double and exponentiated once. It skips a cell's part whose
 * brick the light transfer function leaves empty, where the kernel walks the bricks' sub-cells
 * (kernels/techniques/reference.cl): both skip only parts of depth 0, so the simpler test stays
 * an independent check of the kernel's walk. */
static v3 shadow(const prep *P, v3 p)
{
    float dist;
    v3 d = to_light(P, p, &dist);
    float t0, t1;
    ray_box(P, p, d, &t0, &t1);
    const float t_start = fmaxf(t0, 0.0f), t_end = fminf(t1, dist);
    if (!(t_end > t_start))
        return mk(1, 1, 1);
    const float h = P->shadow_step, per_t = P->s->reference_step / h;
    const float xo[3] = {(p.x - P->bmin.x) * P->inv_spacing.x - 0.5f,
                         (p.y - P->bmin.y) * P->inv_spacing.y - 0.5f,
                         (p.z - P->bmin.z) * P->inv_spacing.z - 0.5f};
    const float xd[3] = {d.x * P->inv_spacing.x, d.y * P->inv_spacing.y, d.z * P->inv_spacing.z};
    const int skip = P->s->opts.empty_space_skipping;
    double D[3] = {0, 0, 0};
    int k = 1; /* the next step boundary, t_start + k h */
    for (float tc = t_start; tc < t_end;) {
        float tn = t_end;
        for (int a = 0; a < 3; ++a)
            tn = fminf(tn, next_plane(P, xo, xd, a, tc, t_end));
        const float tc0 = tc;
        tc = tn;
        if (skip) {
            int b[3];
            v3 mid = add(p, mul(d, 0.5f * (tc0 + tn)));
            if (!P->light_bricks[brick_of(P, mid, b)])
                continue;
        }
        cubic q = cell_cubic(P, p, d, tc0, tn - tc0);
        /* the extrema: roots of c1 + 2 c2 s + 3 c3 s^2 inside the part */
        double e[2] = {INFINITY, INFINITY}, A = 3 * q.c[3], Bq = 2 * q.c[2], Cq = q.c[1];
        if (A == 0.0) {
            if (Bq != 0.0)
                e[0] = -Cq / Bq;
        } else if (Bq * Bq - 4 * A * Cq >= 0.0) {
            double r = sqrt(Bq * Bq - 4 * A * Cq);
            e[0] = (-Bq - r) / (2 * A);
            e[1] = (-Bq + r) / (2 * A);
            if (e[1] < e[0]) {
                double x = e[0];
                e[0] = e[1];
                e[1] = x;
            }
        }
        float ta = tc0, va = sample(P, add(p, mul(d, ta)));
        while (ta < tn) {
            float tk = t_start + (float)k * h;
            while (!(tk > ta))
                tk = t_start + (float)(++k) * h;
            float tb = fminf(tn, tk);
            for (int i = 0; i < 2; ++i) {
                float te = (float)(q.ta + e[i]);
                if (e[i] < INFINITY && te > ta && te < tb)
                    tb = te;
            }
            float vb = sample(P, add(p, mul(d, tb)));
            float scale = expf((float)fmin(D[0], fmin(D[1], D[2])));
            double w[3], err;
            piece_curved(P, &q, ta, tb, va, vb, per_t, w, &err);
            piece_refined(P, p, d, &q, ta, tb, va, vb, per_t, 0, scale, w, err, D);
            if (fmin(D[0], fmin(D[1], D[2])) > 13.815511)
                return mk(0, 0, 0);
            ta = tb;
            va = vb;
        }
    }
    return mk((float)exp(-D[0]), (float)exp(-D[1]), (float)exp(-D[2]));
}

static v3 shadow_factor(const prep *P, v3 p)
{
    return P->s->shadow == UMBRA_SHADOW_REFERENCE ? shadow(P, p) : mk(1, 1, 1);
}

/* The gradient before issue #12: six trilinear samples one voxel each way. */
static v3 gradient_six_samples(const prep *P, v3 p)
{
    v3 s = P->spacing;
    float gx = sample(P, add(p, mk(s.x, 0, 0))) - sample(P, sub(p, mk(s.x, 0, 0)));
    float gy = sample(P, add(p, mk(0, s.y, 0))) - sample(P, sub(p, mk(0, s.y, 0)));
    float gz = sample(P, add(p, mk(0, 0, s.z))) - sample(P, sub(p, mk(0, 0, s.z)));
    return vmul(mul(mk(gx, gy, gz), 0.5f), P->inv_spacing);
}

/* x^n as the kernel takes the specular power (kernels/common/common.cl, shading_power): by binary
 * powering for a whole n up to 256, within (n - 1) 2^-24 relative of powf, else powf. */
static float shading_power(float x, float n)
{
    if (!(n == floorf(n) && n <= 256.0f))
        return powf(x, n);
    unsigned e = (unsigned)n;
    float r = 1.0f;
    for (;;) {
        if (e & 1u)
            r *= x;
        e >>= 1;
        if (!e)
            return r;
        x *= x;
    }
}

/* The central difference of the trilinear interpolant, (sample(p + e) - sample(p - e)) / 2 per
 * axis, one voxel e each way, computed as the kernel does (kernels/common/sampling.cl,
 * volume_gradient): the voxels' central differences interpolated over p's cell, from the 32
 * voxels the six samples read, indices clamped one by one. */
static v3 gradient(const prep *P, v3 p)
{
    const cpu_scene *s = P->s;
    const float x[3] = {(p.x - P->bmin.x) * P->inv_spacing.x - 0.5f,
                        (p.y - P->bmin.y) * P->inv_spacing.y - 0.5f,
                        (p.z - P->bmin.z) * P->inv_spacing.z - 0.5f};
    size_t idx[3][4]; /* per axis: the offsets of voxels i - 1, i, i + 1, i + 2, clamped */
    float f[3];
    const size_t stride[3] = {1, (size_t)s->dims[0], (size_t)s->dims[0] * (size_t)s->dims[1]};
    for (int a = 0; a < 3; ++a) {
        float xa = clampf(x[a], -1.0f, (float)s->dims[a]);
        float fl = floorf(xa);
        f[a] = xa - fl;
        for (int k = 0; k < 4; ++k) {
            int i = (int)fl - 1 + k;
            i = i < 0 ? 0 : i > s->dims[a] - 1 ? s->dims[a] - 1 : i;
            idx[a][k] = (size_t)i * stride[a];
        }
    }
    float g[3];
    for (int a = 0; a < 3; ++a) {
        /* the other two axes u, v (in increasing order): the cell's 2 x 2 corners across them */
        const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
        float dcell[2][2];
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) {
                size_t base = idx[u][1 + j] + idx[v][1 + k];
                const float *r = s->voxels + base;
                float d0 = r[idx[a][2]] - r[idx[a][0]], d1 = r[idx[a][3]] - r[idx[a][1]];
                dcell[j][k] = lerp(d0, d1, f[a]);
            }
        g[a] = lerp(lerp(dcell[0][0], dcell[1][0], f[u]), lerp(dcell[0][1], dcell[1][1], f[u]), f[v]);
    }
    return vmul(mul(mk(g[0], g[1], g[2]), 0.5f), P->inv_spacing);
}

/* The mean emission depth of a segment of opacity a as the kernel evaluates it
 * (kernels/raycast.cl, emission_depth): the same expression, operation for operation. */
float cpu_emission_depth(float a)
{
    const float x = 1.0f - a;
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    const uint32_t mb = (b & 0x007fffffu) | 0x3f800000u;
    float f;
    memcpy(&f, &mb, sizeof f);
    f -= 1.0f; /* mantissa - 1 */
    const float u = (float)(127 - (int32_t)(b >> 23)) - f * (1.35457563f - 0.35457563f * f);
    const float m = (0.5f + u * (0.0153764998f + u * 0.00439499835f)) /
                    (1.0f + u * (0.147417943f + u * (0.0241450484f + u * 0.00272645837f)));
    return a < 1.0f ? m : 0.0f;
}

static uint32_t hash(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

static float random01(uint32_t seed, uint32_t a, uint32_t b, uint32_t c)
{
    return (float)(hash(seed ^ hash(a ^ hash(b ^ hash(c)))) >> 8) * (1.0f / 16777216.0f);
}

typedef struct view {
    v3 eye, right, up, fwd;
    int ortho;
} view;

static view make_view(const cpu_scene *s, uint32_t w, uint32_t h)
{
    const umbra_camera *c = &s->camera;
    view v;
    v.fwd = norm(sub(from(c->target), from(c->eye)));
    v3 r = norm(cross(v.fwd, from(c->up)));
    v3 u = cross(r, v.fwd);
    float hh = c->projection == UMBRA_ORTHOGRAPHIC ? 0.5f * c->ortho_height
                                                   : tanf(0.5f * c->fovy_degrees * 3.14159265358979f / 180.0f);
    float hw = hh * (float)w / (float)h;
    v.right = mul(r, hw);
    v.up = mul(u, hh);
    v.eye = from(c->eye);
    v.ortho = c->projection == UMBRA_ORTHOGRAPHIC;
    return v;
}

/* The light a sample of colour c at p on a view ray of direction d sends back, its shadow taken
 * at light_at: only where there is a shadow to look up, as the kernel compiled without one
 * does. */
static v3 lit_sample(const prep *P, v3 p, v3 d, const float c[4], v3 light_at)
{
    const cpu_scene *s = P->s;
    const umbra_render_desc *o = &s->opts;
    v3 sf = s->shadow == UMBRA_SHADOW_REFERENCE ? shadow(P, light_at) : mk(1, 1, 1);
    v3 light = vmul(from(s->light.color), sf);
    v3 amb = from(o->ambient);
    const int six = s->six_sample_shading;
    v3 g = !o->shading ? mk(0, 0, 0) : six ? gradient_six_samples(P, p) : gradient(P, p);
    float gl = sqrtf(dot(g, g));
    if (!o->shading || !(gl > 1e-6f))
        return vmul(mk(c[0], c[1], c[2]), add(amb, light));
    v3 nrm = mul(g, -1.0f / gl);
    float dist;
    v3 l = to_light(P, p, &dist);
    v3 hv = norm(add(l, mul(d, -1.0f)));
    float diff = fabsf(dot(nrm, l));
    float spec = six ? powf(fabsf(dot(nrm, hv)), o->shininess)
                     : shading_power(fabsf(dot(nrm, hv)), o->shininess);
    return add(vmul(mk(c[0], c[1], c[2]), add(amb, mul(light, o->kd * diff))),
               mul(light, o->ks * spec));
}

static uint32_t pixel(const prep *P, const view *V, uint32_t w, uint32_t h, int px, int py,
                      float out[4])
{
    const cpu_scene *s = P->s;
    const umbra_render_desc *o = &s->opts;
    float sx = ((float)px + 0.5f) / (float)w * 2.0f - 1.0f;
    float sy = 1.0f - ((float)py + 0.5f) / (float)h * 2.0f;
    v3 org, d;
    if (V->ortho) {
        org = add(add(V->eye, mul(V->right, sx)), mul(V->up, sy));
        d = V->fwd;
    } else {
        org = V->eye;
        d = norm(add(add(V->fwd, mul(V->right, sx)), mul(V->up, sy)));
    }
    float ext_y = P->bmax.y - P->bmin.y;
    float diag = sqrtf(dot(sub(P->bmax, P->bmin), sub(P->bmax, P->bmin)));
    float y0 = -0.5f * ext_y - o->ground_offset * diag;
    float t_ground = INFINITY;
    if (o->ground_plane) {
        float tg = -(org.y - y0) / d.y;
        if (d.y < 0.0f && tg > 0.0f)
            t_ground = tg;
    }
    float col[3] = {0, 0, 0}, A = 0.0f, c[4];
    uint32_t taken = 0;
    float ta, tb;
    ray_box(P, org, d, &ta, &tb);
    {
        float t0 = fmaxf(ta, 0.0f), t1 = fminf(tb, t_ground);
        if (t1 > t0) {
            const float hstep = P->step;
            float jitter = o->jitter ? random01(o->seed, (uint32_t)px, (uint32_t)py, 0u) : 0.0f;
            int n = (int)ceilf((t1 - t0) / hstep - jitter);
            /* The view ray in voxel coordinates, where its samples are taken (the kernel's xo,
             * xd): x = xo + t xd. */
            const v3 xo = to_voxel(P, org), xd = vmul(d, P->inv_spacing);
            walk w;
            walk_begin(P, &w, org, d, t0);
            float t_cell = -INFINITY; /* samples before it lie in a visible cell */
            int k = 0;
            /* A jittered ray (kernels/raycast.cl): the unjittered first sample at t0, then the
             * unjittered second, at t0 + h, cut to the fraction jitter of a step (its light at
             * the fraction's mean emission depth from where that sample's segment begins), then
             * the jittered samples from k = 1. */
            if (jitter > 0.0f) {
                for (int pre = 0; pre < 2 && A <= o->termination; ++pre) {
                    float tp = t0 + (float)pre * hstep;
                    if (!(tp < t1))
                        break;
                    v3 p = add(org, mul(d, tp));
                    ++taken;
                    lookup(P->view_tf, P->view_n, sample(P, p), c);
                    float a = pre ? (c[3] < 1.0f ? -expm1f(jitter * log1pf(-c[3])) : 1.0f) : c[3];
                    if (!(a > 0.0f))
                        continue;
                    float m = cpu_emission_depth(a);
                    v3 at = pre ? add(p, mul(d, -0.5f * hstep * (1.0f + c[3]) + jitter * hstep * m))
                                : add(p, mul(d, (m - 0.5f * (1.0f + a)) * hstep));
                    v3 lit = lit_sample(P, p, d, c, at);
                    col[0] += (1.0f - A) * a * lit.x;
                    col[1] += (1.0f - A) * a * lit.y;
                    col[2] += (1.0f - A) * a * lit.z;
                    A += (1.0f - A) * a;
                }
                k = A > o->termination ? n : 1;
            }
            while (k < n) {
                float t = t0 + ((float)k + jitter) * hstep;
                if (o->empty_space_skipping && t >= t_cell) {
                    float t_in = walk_to_visible(P, &w, t, t1);
                    if (t_in > t) {
                        if (!(t_in < t1))
                            break;
                        k = next_after(t0, hstep, jitter, t_in, k);
                        if (k >= n)
                            break;
                        t = t0 + ((float)k + jitter) * hstep;
                        if (!(t < walk_exit(&w)))
                            continue;
                    }
                    t_cell = walk_run_end(P, &w, t1);
                }
                v3 p = add(org, mul(d, t));
                ++taken;
                view_lookup(P->view_tf, P->view_n, sample_voxel(P, add(xo, mul(xd, t))), c);
                if (c[3] > 0.0f) {
                    /* The light at p + h (m - (1 + a)/2) along d, m the mean emission depth of
                     * a segment of opacity a (kernels/raycast.cl, shadow_point). */
                    float a = c[3], m = cpu_emission_depth(a);
                    v3 at = add(p, mul(d, (m - 0.5f * (1.0f + a)) * hstep));
                    v3 lit = lit_sample(P, p, d, c, at);
                    col[0] += (1.0f - A) * c[3] * lit.x;
                    col[1] += (1.0f - A) * c[3] * lit.y;
                    col[2] += (1.0f - A) * c[3] * lit.z;
                    A += (1.0f - A) * c[3];
                    if (A > o->termination)
                        break;
                }
                ++k;
            }
        }
    }
    if (t_ground < INFINITY && A <= o->termination) {
        v3 p = add(org, mul(d, t_ground));
        v3 sf = shadow_factor(P, p);
        float dist;
        float ndl = fmaxf(to_light(P, p, &dist).y, 0.0f);
        v3 lit = vmul(from(o->ground_color), add(from(o->ambient), mul(vmul(from(s->light.color), sf), ndl)));
        col[0] += (1.0f - A) * lit.x;
        col[1] += (1.0f - A) * lit.y;
        col[2] += (1.0f - A) * lit.z;
        A = 1.0f;
    }
    for (int ch = 0; ch < 3; ++ch)
        out[ch] = col[ch] + (1.0f - A) * o->background[ch];
    out[3] = A + (1.0f - A) * o->background[3];
    return taken;
}

struct cpu_prepared {
    prep P;
};

cpu_prepared *cpu_prepare(const cpu_scene *s)
{
    cpu_prepared *p = malloc(sizeof *p);
    if (!p)
        return NULL;
    prep_init(&p->P, s);
    if (!p->P.view_tf || !p->P.light_tf || !p->P.light_bricks || !p->P.light_int ||
        !p->P.view_cells) {
        cpu_prepared_free(p);
        return NULL;
    }
    return p;
}

void cpu_prepared_free(cpu_prepared *p)
{
    if (!p)
        return;
    prep_free(&p->P);
    free(p);
}

uint64_t cpu_render_prepared(const cpu_prepared *p, uint32_t w, uint32_t h, float *rgba)
{
    const prep *P = &p->P;
    view V = make_view(P->s, w, h);
    uint64_t total = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : total)
    for (int py = 0; py < (int)h; ++py)
        for (int px = 0; px < (int)w; ++px)
            total += pixel(P, &V, w, h, px, py, rgba + 4 * ((size_t)py * w + px));
    return total;
}

uint64_t cpu_render(const cpu_scene *s, uint32_t w, uint32_t h, float *rgba)
{
    cpu_prepared *p = cpu_prepare(s);
    if (!p)
        return 0;
    uint64_t total = cpu_render_prepared(p, w, h, rgba);
    cpu_prepared_free(p);
    return total;
}

void cpu_shadow(const cpu_scene *s, const float p[3], float rgb[3])
{
    prep P;
    prep_init(&P, s);
    v3 r = shadow(&P, from(p));
    rgb[0] = r.x;
    rgb[1] = r.y;
    rgb[2] = r.z;
    prep_free(&P);
}
