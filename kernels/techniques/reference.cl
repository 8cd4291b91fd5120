// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/reference.cl: the exact reference. From every point, a shadow ray toward
 * the light, along which the optical depth of the shading model (the extinction per channel of
 * kernels/common/common.cl) is integrated. Every other technique is measured against it.
 *
 * Quadrature. The path [t_start, t_end] inside the volume (and before a point light) is walked
 * cell by cell of voxel centres. Inside a cell the trilinear interpolant is one blend of the
 * cell's eight voxels, a cubic along the ray (RayCell, read with one load of the eight); its
 * kinks lie on the cell's faces, where the walk cuts the path, so a kink on a step's boundary or
 * in its middle is integrated like any other. Each cell's part is cut further at the steps of
 * h = S->step from the point (the first piece starts at the point itself: a point just inside a
 * sheet's lit face sees the material between it and the face) and at the cubic's extrema, so
 * that along every piece the value runs smoothly and monotonically from va to vb. A piece's
 * optical depth is first integrated through the transfer function in value space as if the
 * value ran linearly, exactly: the value interval is split at the table's entries, where the
 * interpolated opacity has its kinks; across one table interval the opacity and the colour run
 * linearly, so the extinction integrates in closed form (piece_depth: at most two logs, none on
 * an opacity plateau, the entries' extinctions coming from the host), and the whole intervals
 * between come from per-interval integrals the host computed in the same closed form in double
 * (host/tables.c, appended to the light table as compensated prefix sums). The value's curve
 * departs from that line (inside a cell crossed obliquely) by v - chord, known in closed form
 * from the cubic: its integral times the extinction's secant slope over the piece's values is
 * added, which is exact where the extinction runs linearly over them (piece_depth_curved); where
 * what that can leave (a transfer-function edge inside the piece's values) exceeds 1e-4 of depth,
 * the piece is halved, and halved again where the halves differ from the whole by more than
 * 3e-5 (piece_refined), thresholds relative to the light the piece still receives. A homogeneous
 * medium gives exp(-sigma d) for every h, and a value linear along each piece (light along an
 * axis) is integrated exactly. The depths are summed (Kahan-compensated) and exponentiated once,
 * so a thin medium keeps its precision at any step (1e-6 per voxel over 512 voxels at step 0.01).
 * The march stops once every channel is below 1e-6.
 *
 * Held to an independent float64 integral within the bounds of tests/test_fidelity.c and
 * tests/test_alignment.c (kinks on steps' boundaries and middles, lights on lattice points); what
 * it measured, what the walk costs and what it replaced (until 2026-12-01): docs/hard-cases.md.
 *
 * Empty-space skipping: the ray walks the light's sub-cell masks too and integrates only inside
 * visible sub-cells: in an invisible one the light transfer function leaves every value the
 * interpolant takes transparent, so skipping changes no depth. */

#define SHADOW_KERNEL_PARAMS

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

/* The moments over tau in [0, 1] of -ln(1 - r tau), the extinction's excess over its value at a
 * piece's more transparent end where the opacity rises linearly to the other (r = the rise over
 * that end's 1 - a, 1 - r = the other's 1 - a over this one's, om_r; lr = -ln(1 - r)):
 * .x = int -ln(1 - r tau) = 1 - (1 - r) lr / r, .y = int tau (-ln(1 - r tau)) =
 * (lr (1 - 1 / r^2) + 1 / r + 1 / 2) / 2. Both cancel for small r, where their series
 * sum_k r^k / (k (k + 1)) and sum_k r^k / (k (k + 2)) take over (r < 1/2, 18 terms: truncation
 * below 4e-8 of the result). */
inline float2 log_moments(float r, float om_r, float lr)
{
    if (r < 0.5f) {
        /* Horner over the coefficients 1 / (k (k + 1)) and 1 / (k (k + 2)), k = 18 .. 1 */
        const float c_phi[18] = {
            2.92397661e-03f, 3.26797386e-03f, 3.67647059e-03f, 4.16666667e-03f, 4.76190476e-03f,
            5.49450549e-03f, 6.41025641e-03f, 7.57575758e-03f, 9.09090909e-03f, 1.11111111e-02f,
            1.38888889e-02f, 1.78571429e-02f, 2.38095238e-02f, 3.33333333e-02f, 5.00000000e-02f,
            8.33333333e-02f, 1.66666667e-01f, 5.00000000e-01f};
        const float c_psi[18] = {
            2.77777778e-03f, 3.09597523e-03f, 3.47222222e-03f, 3.92156863e-03f, 4.46428571e-03f,
            5.12820513e-03f, 5.95238095e-03f, 6.99300699e-03f, 8.33333333e-03f, 1.01010101e-02f,
            1.25000000e-02f, 1.58730159e-02f, 2.08333333e-02f, 2.85714286e-02f, 4.16666667e-02f,
            6.66666667e-02f, 1.25000000e-01f, 3.33333333e-01f};
        float phi = 0.0f, psi = 0.0f;
        for (int k = 0; k < 18; ++k) {
            phi = fma(phi, r, c_phi[k]);
            psi = fma(psi, r, c_psi[k]);
        }
        return (float2)(phi * r, psi * r);
    }
    const float ir = 1.0f / r;
    return (float2)(1.0f - om_r * lr * ir, 0.5f * (lr * (1.0f - ir * ir) + ir + 0.5f));
}

/* The optical depth per light channel of [a, b] (table units, within one table interval), in
 * table units, exact: across an interval the opacity a and the colour t run linearly, so the
 * extinction -ln(1 - a) (1 - t_c) integrates in closed form, from the more transparent end e
 * (a rise r = (a_o - a_e) / (1 - a_e) to the other end o): (b - a) (f_e m0 + (f_o - f_e) m1),
 * f = 1 - t_c, m0 = s_e + phi(r), m1 = s_e / 2 + psi(r) (log_moments), s = -ln(1 - a). The ends'
 * opacities are clamped to UMBRA_ALPHA_MAX before, not after, the interpolation between them,
 * which differs from tf_extinction only where the table reaches opacity 1, over 2^-24 of an
 * interval. The range of the extinction over the piece (its two ends: it is monotonic in a)
 * widens lo, hi; *ext_a, *ext_b get the extinctions at a and b. At most two logs (none on a
 * plateau of the opacity, one where an end lies on a table entry), where three-point Gauss took
 * three and three table lookups. */
inline light_t piece_depth(__global const float4 *tf, uint n, float a, float b, uint flags,
                           float *lo, float *hi, light_t *ext_a, light_t *ext_b)
{
    const int i = min((int)a, (int)n - 2);
    const float4 c0 = tf[i], c1 = tf[i + 1];
    if (c0.w == 0.0f && c1.w == 0.0f) { /* transparent: the common case, no logs */
        *lo = 0.0f;
        *ext_a = *ext_b = (light_t)(0.0f);
        return (light_t)(0.0f);
    }
    /* The ends, and their extinctions: an end on a table entry (or a plateau of the opacity)
     * takes the entry's from the host (after the prefix sums), the others a log. */
    const float fa = a - (float)i, fb = b - (float)i;
    float4 ca = fa == 0.0f ? c0 : mix(c0, c1, fa), cb = fb == 1.0f ? c1 : mix(c0, c1, fb);
    ca.w = fmin(ca.w, UMBRA_ALPHA_MAX);
    cb.w = fmin(cb.w, UMBRA_ALPHA_MAX);
    const int plateau = c0.w == c1.w;
    const float sa = (fa == 0.0f || plateau) ? tf[3 * n + i].x : -log1p(-ca.w);
    const float sb = fb == 1.0f ? tf[3 * n + i + 1].x : plateau ? sa : -log1p(-cb.w);
    const int up = cb.w >= ca.w;
    const float4 ce = up ? ca : cb, co = up ? cb : ca;
    const float se = up ? sa : sb, so = up ? sb : sa;
    const light_t fe = light_absorbed(ce, flags), fo = light_absorbed(co, flags);
    const light_t de = se * fe, dob = so * fo;
    *ext_a = up ? de : dob;
    *ext_b = up ? dob : de;
    *lo = fmin(*lo, fmin(light_min(de), light_min(dob)));
    *hi = fmax(*hi, fmax(light_max(de), light_max(dob)));
    if (co.w == ce.w) /* a constant opacity: the colour's mean */
        return (0.5f * (b - a)) * (de + dob);
    const float qe = 1.0f - ce.w;
    const float2 m = log_moments((co.w - ce.w) / qe, (1.0f - co.w) / qe, so - se);
    return (b - a) * (fe * (se + m.x) + (fo - fe) * (0.5f * se + m.y));
}

/* The sum of the interval depths of the table's entries [0, k) (host/renderer.c, after the n
 * entries: hi at n + 2k, lo at n + 2k + 1), per light channel. */
inline float4 interval_sum(__global const float4 *tf, uint n, int k, int j)
{
    const float4 hi = tf[n + 2 * j] - tf[n + 2 * k], lo = tf[n + 2 * j + 1] - tf[n + 2 * k + 1];
    return hi + lo;
}

/* The optical depth per light channel of a segment of len voxels along which the value runs
 * linearly from v0 to v1: len times the mean extinction over [v0, v1] of the light table
 * (n entries): the partial table intervals at the ends by three-point Gauss, the whole ones
 * between from the host's exact interval sums. *spread: how much the extinction varies over the
 * range (the ends' extinctions and the whole intervals' mean), times len; *ext0, *ext1: the
 * extinctions per voxel at v0 and v1. */
inline light_t segment_depth(__global const float4 *tf, uint n, float v0, float v1, float len,
                             uint flags, float *spread, light_t *ext0, light_t *ext1)
{
    const float last = (float)(n - 1);
    const float x0 = clamp(fmin(v0, v1), 0.0f, 1.0f) * last;
    const float x1 = clamp(fmax(v0, v1), 0.0f, 1.0f) * last;
    const float span = x1 - x0;
    *spread = 0.0f;
    if (!(span > 0.0f)) {
        *ext0 = *ext1 = light_depth(tf_lookup(tf, n, x0 / last), 1.0f, flags);
        return *ext0 * len;
    }
    const int i0 = min((int)x0, (int)n - 2), i1 = min((int)x1, (int)n - 2);
    float lo = UMBRA_INF, hi = 0.0f;
    light_t sum, e_lo, e_hi, e_mid;
    if (i0 == i1) {
        sum = piece_depth(tf, n, x0, x1, flags, &lo, &hi, &e_lo, &e_hi);
    } else {
        sum = piece_depth(tf, n, x0, (float)(i0 + 1), flags, &lo, &hi, &e_lo, &e_mid) +
              piece_depth(tf, n, (float)i1, x1, flags, &lo, &hi, &e_mid, &e_hi);
        if (i1 > i0 + 1) {
            const float4 w = interval_sum(tf, n, i0 + 1, i1);
#if UMBRA_LIGHT_CHANNELS == 1
            const light_t whole = (flags & UMBRA_FLAG_COLORED) ? w.x : w.w;
#else
            const light_t whole = (flags & UMBRA_FLAG_COLORED) ? w.xyz : (float3)(w.w);
#endif
            sum += whole;
            const light_t mean = whole / (float)(i1 - i0 - 1);
            lo = fmin(lo, light_min(mean));
            hi = fmax(hi, light_max(mean));
        }
    }
    *spread = (hi - lo) * len;
    *ext0 = v0 <= v1 ? e_lo : e_hi;
    *ext1 = v0 <= v1 ? e_hi : e_lo;
    return sum * (len / span);
}

/* ---- the ray inside one cell of voxel centres ----------------------------------------------
 * Between two planes of voxel centres on every axis the trilinear interpolant is one blend of the
 * cell's eight voxels, so along the ray it is a cubic in t: v(t0 + s) = v(t0) + k1 s + k2 s^2 +
 * k3 s^3. Its kinks lie on the cell's faces, its extrema (at most two) where 3 k3 s^2 + 2 k2 s +
 * k1 = 0. An axis on which the ray lies outside the grid (the half voxel at the box's faces,
 * where the sampler clamps) or which has one voxel leaves the interpolant constant along it. */
typedef struct RayCell {
    float c[8];        /* the voxels, x fastest (volume_cell) */
    float3 p, q;       /* the local coordinates u = clamp(p + q (t - t0), 0, 1) in the cell */
    float t0;
    float k1, k2, k3;  /* the cubic in s = t - t0 */
} RayCell;

/* The cell j of the ray xo + t xd (voxel coordinates): per axis between the planes of voxel
 * centres j and j + 1, j in [-1, dims - 1] (-1 before the first plane, dims - 1 past the last). */
inline void ray_cell_load(VOLUME_PARAM, VolGeom g, int3 j, float3 xo, float3 xd, float t0,
                          RayCell *C)
{
    const int3 i0 = clamp(j, (int3)(0), max(g.dims - 2, (int3)(0)));
    volume_cell(vol, g, i0, C->c);
    const int3 inside = (j >= (int3)(0)) & (j <= g.dims - 2);
    const float3 outside_u = select((float3)(0.0f), (float3)(1.0f), j >= (int3)(0));
    const float3 p = select(outside_u, xo + t0 * xd - convert_float3(i0), inside);
    const float3 q = select((float3)(0.0f), xd, inside);
    C->p = p;
    C->q = q;
    C->t0 = t0;
    const float *c = C->c;
    const float bx = c[1] - c[0], by = c[2] - c[0], bz = c[4] - c[0];
    const float cxy = c[3] - c[2] - c[1] + c[0], cxz = c[5] - c[4] - c[1] + c[0];
    const float cyz = c[6] - c[4] - c[2] + c[0];
    const float d = c[7] - c[6] - c[5] - c[3] + c[4] + c[2] + c[1] - c[0];
    C->k1 = bx * q.x + by * q.y + bz * q.z + cxy * (p.x * q.y + q.x * p.y) +
            cxz * (p.x * q.z + q.x * p.z) + cyz * (p.y * q.z + q.y * p.z) +
            d * (q.x * p.y * p.z + p.x * q.y * p.z + p.x * p.y * q.z);
    C->k2 = cxy * q.x * q.y + cxz * q.x * q.z + cyz * q.y * q.z +
            d * (q.x * q.y * p.z + q.x * p.y * q.z + p.x * q.y * q.z);
    C->k3 = d * q.x * q.y * q.z;
}

/* The interpolant at t in the cell: sample_volume's blend of the cell's voxels. */
inline float ray_cell_value(const RayCell *C, float t)
{
    const float3 u = clamp(C->p + C->q * (t - C->t0), 0.0f, 1.0f);
    const float c00 = mix(C->c[0], C->c[1], u.x), c10 = mix(C->c[2], C->c[3], u.x);
    const float c01 = mix(C->c[4], C->c[5], u.x), c11 = mix(C->c[6], C->c[7], u.x);
    return mix(mix(c00, c10, u.y), mix(c01, c11, u.y), u.z);
}

/* The interpolant's extrema along the ray in the cell, as t (UMBRA_INF where there is none),
 * the smaller first. */
inline float2 ray_cell_extrema(const RayCell *C)
{
    const float a = 3.0f * C->k3, b = 2.0f * C->k2, c = C->k1;
    float r0 = UMBRA_INF, r1 = UMBRA_INF;
    if (a == 0.0f) {
        if (b != 0.0f)
            r0 = -c / b;
    } else {
        const float disc = b * b - 4.0f * a * c;
        if (disc >= 0.0f) {
            const float qq = -0.5f * (b + copysign(sqrt(disc), b));
            r0 = qq / a;
            r1 = qq != 0.0f ? c / qq : UMBRA_INF;
        }
    }
    const float lo = fmin(r0, r1), hi = fmax(r0, r1);
    return (float2)(C->t0 + lo, hi < UMBRA_INF ? C->t0 + hi : UMBRA_INF);
}

/* How far the interpolant departs from the straight line between its values at ta and tb
 * (within one cell), at most: v(t) - chord(t) = (t - ta) (t - tb) (k2 + k3 (sa + sb + s)). */
inline float ray_cell_bend(const RayCell *C, float ta, float tb)
{
    const float sa = ta - C->t0, sb = tb - C->t0, l = tb - ta;
    return 0.25f * l * l *
           fmax(fabs(C->k2 + C->k3 * (2.0f * sa + sb)), fabs(C->k2 + C->k3 * (sa + 2.0f * sb)));
}

/* The integral of v(t) - chord(t) over [ta, tb]: -(l^3 / 6) (k2 + 3/2 k3 (sa + sb)). */
inline float ray_cell_bend_integral(const RayCell *C, float ta, float tb)
{
    const float sa = ta - C->t0, sb = tb - C->t0, l = tb - ta;
    return (-1.0f / 6.0f) * l * l * l * (C->k2 + 1.5f * C->k3 * (sa + sb));
}

/* The optical depth of the piece [ta, tb] of the ray inside cell C, between two of its kinks,
 * extrema or step boundaries, so that its value runs monotonically from va to vb (per_t voxels
 * per unit of t). segment_depth takes the value to run linearly; the value's curve departs from
 * that line by v - chord (ray_cell_bend at most), which moves the depth by about the extinction's
 * slope in value times the integral of v - chord: that is added, with the slope taken as the
 * secant between the ends' extinctions (exact where the extinction runs linearly over the
 * piece's values, second order in its curvature); where it could not move the depth by
 * SEG_CORRECT_TOL it is left out. *err: what the correction leaves at most where the extinction
 * is not linear there (a transfer-function edge inside the range): its spread over the piece
 * times the fraction of the piece by which the curve departs from the line. */
#define SEG_CORRECT_TOL 1e-7f
inline light_t piece_depth_curved(const RayCell *C, __global const float4 *tf, uint n, uint flags,
                                  float ta, float tb, float va, float vb, float per_t,
                                  float *err)
{
    float spread;
    light_t ext_a, ext_b;
    light_t dd = segment_depth(tf, n, va, vb, (tb - ta) * per_t, flags, &spread, &ext_a, &ext_b);
    const float dv = vb - va, bent = spread * ray_cell_bend(C, ta, tb);
    *err = 0.0f;
    if (bent > SEG_CORRECT_TOL * fabs(dv)) {
        *err = bent / fabs(dv);
        dd += (ext_b - ext_a) * (ray_cell_bend_integral(C, ta, tb) * per_t / dv);
    }
    return dd;
}

/* The optical depth of a piece (piece_depth_curved), behind d_before of optical depth (the least
 * over the channels) on the way to the light, refined where the estimate of its error exceeds
 * SEG_REFINE_CAND: the piece is halved at its middle (its value from the cell's voxels, no load)
 * and the halves' depths replace it; where they differ from it by more than SEG_REFINE_TOL,
 * each half is a candidate in turn (depth-first, an explicit stack, at most SEG_REFINE_LEVELS
 * deep); where they agree, the refinement stops there (most candidates lie over a part of the
 * transfer function where the correction is already good). Both thresholds are multiplied by
 * exp(d_before): an error e in this piece's depth moves the shadow factor by at most
 * e exp(-d_before), so each stands for the same error in the factor wherever the piece lies. */
#define SEG_REFINE_LEVELS 3
#define SEG_REFINE_CAND 1e-4f
#ifndef SEG_REFINE_TOL
#define SEG_REFINE_TOL 3e-5f
#endif
inline light_t piece_refined(const RayCell *C, __global const float4 *tf, uint n, uint flags,
                             float ta, float tb, float va, float vb, float per_t,
                             float d_before)
{
    /* The pieces still to do after the current one: their ends, values at the ends, depths,
     * error estimates and levels (each starts where the one above it ends). */
    float st_t[SEG_REFINE_LEVELS], st_v[SEG_REFINE_LEVELS], st_e[SEG_REFINE_LEVELS];
    light_t st_d[SEG_REFINE_LEVELS];
    int st_l[SEG_REFINE_LEVELS];
    int top = -1, level = 0;
    float err;
    light_t dd = piece_depth_curved(C, tf, n, flags, ta, tb, va, vb, per_t, &err);
    light_t D = (light_t)(0.0f);
    float scale = 0.0f; /* exp(d_before), computed where first needed */
    for (;;) {
        if (level < SEG_REFINE_LEVELS && err > SEG_REFINE_CAND) {
            if (scale == 0.0f)
                scale = exp(d_before);
            if (err > SEG_REFINE_CAND * scale) {
                const float tm = 0.5f * (ta + tb), vm = ray_cell_value(C, tm);
                float e_l, e_r;
                const light_t d_l =
                    piece_depth_curved(C, tf, n, flags, ta, tm, va, vm, per_t, &e_l);
                const light_t d_r =
                    piece_depth_curved(C, tf, n, flags, tm, tb, vm, vb, per_t, &e_r);
                if (light_max(fabs(d_l + d_r - dd)) > SEG_REFINE_TOL * scale) {
                    ++top;
                    st_t[top] = tb;
                    st_v[top] = vb;
                    st_d[top] = d_r;
                    st_e[top] = e_r;
                    st_l[top] = ++level;
                    tb = tm;
                    vb = vm;
                    dd = d_l;
                    err = e_l;
                    continue;
                }
                dd = d_l + d_r;
            }
        }
        D += dd;
        if (top < 0)
            break;
        ta = tb;
        va = vb;
        tb = st_t[top];
        vb = st_v[top];
        dd = st_d[top];
        err = st_e[top];
        level = st_l[top];
        --top;
    }
    return D;
}

#if UMBRA_MIXED
/* A multi-channel volume or a label map (kernels/common/channels.cl): the integration below runs
 * through one transfer function along a value that runs linearly between samples, and a
 * mixture's extinction is neither, so its shadow ray takes the midpoint rule at step h instead:
 * whole steps and a final partial one, each sampled at its middle (light_sample) with the optical
 * depth of its length, segments in invisible cells skipped as the light-space maps skip theirs,
 * the depths summed (Kahan-compensated) and exponentiated once. Exact in a homogeneous medium;
 * elsewhere within the midpoint rule's error of the exact integral (second order in h for a
 * smooth extinction, first order across a label boundary). */
inline float3 reference_shadow(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                               __global const float4 *light_tf,
                               __global const ulong *light_cells,
                               __global const UmbraShadow *S, float3 p)
{
    const float4 l = to_light(F, p);
    const float3 d = l.xyz;
    const float2 tb = clip_interval(&S->clip, p, d, ray_box(p, d, g.box_min, g.box_max));
    const float t_start = fmax(tb.x, 0.0f), t_end = fmin(tb.y, l.w);
    if (!(t_end > t_start))
        return (float3)(1.0f);
    const float h = S->step, h_vox = light_step_voxels(F, S);
    const uint n_tf = F->light_tf_size, flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    const float len = t_end - t_start;
    const int n_full = (int)floor(len / h);
    const float last = len - (float)n_full * h;
    light_t D = (light_t)(0.0f), comp = (light_t)(0.0f);
    CellWalk w = walk_begin(g, p, d, t_start);
    float t_cell = -UMBRA_INF;
    for (int k = 0; k <= n_full;) {
        if (skip && k < n_full && t_start + ((float)k + 0.5f) * h >= t_cell)
            k = walk_next_sample(&w, g, light_cells, t_start, h, 0.5f, k, n_full, t_end, &t_cell);
        const float seg = k < n_full ? h : last;
        if (!(seg > 0.0f))
            break;
        const float4 c =
            light_sample(F, vol, g, light_tf, n_tf, p + (t_start + (float)k * h + 0.5f * seg) * d);
        if (c.w > 0.0f) {
            const light_t y = light_depth(c, h_vox * (seg / h), flags) - comp;
            const light_t s = D + y;
            comp = (s - D) - y;
            D = s;
            if (light_min(D) > 13.815511f) /* -ln(1e-6) */
                return (float3)(0.0f);
        }
        ++k;
    }
    return light_rgb(exp(-D));
}
#else
/* The exact reference's shadow ray from p: the path [t_start, t_end] inside the box (and before
 * a point light) walked cell by cell of voxel centres, each cell's part cut at the steps of h
 * from p and at the interpolant's extrema, every piece integrated by piece_refined. With
 * skipping, the ray walks the light's sub-cell masks (CellWalk) too and integrates only inside
 * visible sub-cells: elsewhere the light transfer function leaves every value the interpolant
 * takes transparent, so nothing is lost. */
inline float3 reference_shadow(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                               __global const float4 *light_tf,
                               __global const ulong *light_cells,
                               __global const UmbraShadow *S, float3 p)
{
    float4 l = to_light(F, p);
    float3 d = l.xyz;
    /* The clip region's part of the ray: a clipped region casts no shadow. */
    float2 tb = clip_interval(&S->clip, p, d, ray_box(p, d, g.box_min, g.box_max));
    float t_start = fmax(tb.x, 0.0f);
    float t_end = fmin(tb.y, l.w);
    if (!(t_end > t_start))
        return (float3)(1.0f);
    const float h = S->step;
    const float per_t = light_step_voxels(F, S) / h; /* voxels per unit of t */
    const uint n_tf = F->light_tf_size;
    const uint flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    const float3 xo = world_to_voxel(g, p), xd = d * g.inv_spacing, inv_xd = 1.0f / xd;
    const int3 dir = select(select((int3)(0), (int3)(-1), xd < 0.0f), (int3)(1), xd > 0.0f);
    /* Optical depth, with its Kahan compensation. */
    light_t D = (light_t)(0.0f), comp = (light_t)(0.0f);
    CellWalk w = walk_begin(g, p, d, t_start);
    float t = t_start;
    int k = 1;            /* the next step boundary: t_start + k h */
    int3 j = (int3)(0);   /* the cell of voxel centres at t, */
    int have_j = 0;       /* once found (again after a skip) */
    while (t < t_end) {
        /* The end of the stretch to integrate: the visible sub-cell's exit, or the ray's. */
        float t_vis = t_end;
        if (skip) {
            const float t_in = walk_to_visible(&w, g, light_cells, t, t_end);
            if (!(t_in < t_end))
                break;
            if (t_in > t) {
                t = t_in;
                have_j = 0;
            }
            t_vis = fmin(walk_exit(&w), t_end);
        }
        if (!have_j) {
            j = clamp(floor_int3(xo + t * xd), (int3)(-1), g.dims - 1);
            k = max(k, (int)floor((t - t_start) / h) + 1);
            have_j = 1;
        }
        while (t < t_vis) {
            /* Where the ray leaves cell j: the next plane of voxel centres per axis. */
            const int3 plane = select(j, j + 1, dir > 0);
            const int3 has = (dir != 0) & (plane >= (int3)(0)) & (plane <= g.dims - 1);
            const float3 te = select((float3)(UMBRA_INF), (convert_float3(plane) - xo) * inv_xd,
                                     has);
            const float t_face = fmin(fmin(te.x, te.y), te.z);
            const float t_out = fmin(t_face, t_vis);
            RayCell C;
            ray_cell_load(vol, g, j, xo, xd, t, &C);
            const float2 ext = ray_cell_extrema(&C);
            float ta = t, va = ray_cell_value(&C, t);
            while (ta < t_out) {
                float tk = t_start + (float)k * h;
                while (!(tk > ta)) /* rounding, or a cell shorter than a step */
                    tk = t_start + (float)(++k) * h;
                float tn = fmin(t_out, tk);
                if (ext.x > ta && ext.x < tn)
                    tn = ext.x;
                else if (ext.y > ta && ext.y < tn)
                    tn = ext.y;
                const float vn = ray_cell_value(&C, tn);
                const light_t y = piece_refined(&C, light_tf, n_tf, flags, ta, tn, va, vn, per_t,
                                                light_min(D)) - comp;
                const light_t s = D + y;
                comp = (s - D) - y;
                D = s;
                if (light_min(D) > 13.815511f) /* -ln(1e-6) */
                    return (float3)(0.0f);
                ta = tn;
                va = vn;
            }
            t = fmax(t, t_out);
            if (!(t_face <= t_vis))
                break; /* the stretch ends inside this cell */
            /* into the next cell, across every face the ray leaves through at t_face */
            j += select((int3)(0), dir, te <= t_face);
        }
        if (!skip)
            break;
    }
    return light_rgb(exp(-D));
}
#endif

#define SHADOW_FACTOR(sr, p) reference_shadow(F, vol, g, light_tf, light_cells, S, (p))
