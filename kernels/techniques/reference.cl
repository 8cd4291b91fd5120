// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/reference.cl: the exact reference. From every point, a shadow ray is marched
 * toward the light with step S->step and the optical depth of the shading model (the extinction
 * per channel of kernels/common/common.cl) is integrated. Every other technique is measured against
 * it.
 *
 * Quadrature. The path [t_start, t_end] inside the volume (and before a point light) is split
 * into whole steps h plus one final partial step; the volume is sampled at the ends of every
 * segment, so the first sample is the point itself (a point just inside the lit face of a sheet
 * sees the material between it and the face, which a midpoint rule misses for up to h/2). Along a
 * segment the value is taken to run linearly between its two end samples, and the segment's
 * optical depth is integrated through the transfer function in value space, exactly: the value
 * interval is split at the table's entries, where the interpolated opacity has its kinks; across
 * one table interval the opacity and the colour run linearly, so the extinction integrates in
 * closed form (piece_depth: at most two logs, none on an opacity plateau, the entries'
 * extinctions coming from the host), and the whole intervals between come from per-interval
 * integrals the host computed in the same closed form in double (host/tables.c, appended to the
 * light table as compensated prefix sums). A sharp transfer-function edge therefore costs no
 * accuracy beyond the linearity of the value along one segment, and where the extinction varies
 * along a segment it is split further (segment_refined): at the interpolant's kinks, then at its
 * middle, keeping a split's halves and refining no further where they agree with the whole to
 * 3e-5 of depth, with thresholds relative to the light the segment still receives. A homogeneous
 * medium gives exp(-sigma d) for every h. Measured against an independent float64 integral
 * (tests/test_fidelity.c) at h = 0.25: 2e-6 on a one-voxel sheet under a step transfer function
 * (1.4e-4 with the Gauss rule), 3.7e-4 on a near-singular ramp (5e-4), 1.8e-4 at random points in
 * a structured volume (mean 9e-6). Bonsai (384^2): the reference at step 0.25 against 0.125, RMSE
 * 1e-5, max 8.5e-4. The price is time. Same-session frames (PoCL, 2 loaded cores): bonsai 64^2
 * 6.8 / 5.8 s with the Gauss rule, 1.3 / 1.7 s now (4.2x); Marschner-Lobb 64^3 at 256^2 8.2 / 9.2 s,
 * 6.0 / 5.3 s (1.55x: its rippled isosurface keeps most split candidates refining). Without any
 * refinement either frame costs about 40% of that. Against the old midpoint rule (1/27 of the
 * Gauss rule's bonsai frame, 1/11 of Marschner-Lobb's, measured before) that makes about 6x and
 * 7x. Thresholds of 4e-3 (kinks) and 1.6e-2 (middles) broke the ramp's and the structured volume's
 * bounds; an agreement tolerance of 1e-4 brought the structured volume to 2.7e-4 of its 3e-4, 3e-5
 * costs 20% less than 1e-5 on Marschner-Lobb and hardly anything on the bonsai, whose split
 * candidates are mostly resolved by their first split. The depths are summed (Kahan-compensated)
 * and exponentiated once, so a thin medium keeps its precision at any step
 * (1e-6 per voxel over 512 voxels at step 0.01). The march stops once every channel is below
 * 1e-6.
 *
 * Empty-space skipping: the ray walks the light's sub-cell masks; a segment whose two ends lie in
 * cells the light transfer function leaves empty is skipped, the one ending in a visible cell is
 * integrated from its invisible start. (A visible cell crossed between two samples in invisible
 * cells, possible only where it holds no sample, is skipped: skipping can change a value only
 * there.) */

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
 * widens lo, hi. At most two logs (none on a plateau of the opacity, one where an end lies on a
 * table entry), where three-point Gauss took three and three table lookups. */
inline light_t piece_depth(__global const float4 *tf, uint n, float a, float b, uint flags,
                           float *lo, float *hi)
{
    const int i = min((int)a, (int)n - 2);
    const float4 c0 = tf[i], c1 = tf[i + 1];
    if (c0.w == 0.0f && c1.w == 0.0f) { /* transparent: the common case, no logs */
        *lo = 0.0f;
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
 * range (the Gauss nodes and the whole intervals' mean), times len. */
inline light_t segment_depth(__global const float4 *tf, uint n, float v0, float v1, float len,
                             uint flags, float *spread)
{
    const float last = (float)(n - 1);
    const float x0 = clamp(fmin(v0, v1), 0.0f, 1.0f) * last;
    const float x1 = clamp(fmax(v0, v1), 0.0f, 1.0f) * last;
    const float span = x1 - x0;
    *spread = 0.0f;
    if (!(span > 0.0f))
        return light_depth(tf_lookup(tf, n, x0 / last), len, flags);
    const int i0 = min((int)x0, (int)n - 2), i1 = min((int)x1, (int)n - 2);
    float lo = UMBRA_INF, hi = 0.0f;
    light_t sum;
    if (i0 == i1) {
        sum = piece_depth(tf, n, x0, x1, flags, &lo, &hi);
    } else {
        sum = piece_depth(tf, n, x0, (float)(i0 + 1), flags, &lo, &hi) +
              piece_depth(tf, n, (float)i1, x1, flags, &lo, &hi);
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
    return sum * (len / span);
}

/* Along one axis, the parameter t in (ta, tb) at which the ray x(t) = xo + t xd (voxel
 * coordinates) crosses a plane of voxel centres inside the grid [0, dim - 1], the one nearest
 * tm, or -1 if it crosses none away from the ends (the trilinear interpolant has its kinks on
 * those planes). */
inline float seg_kink_axis(float xo, float xd, int dim, float ta, float tb, float tm)
{
    if (xd == 0.0f)
        return -1.0f;
    const float x0 = xo + ta * xd, x1 = xo + tb * xd;
    const float lo = fmax(fmin(x0, x1), 0.0f), hi = fmin(fmax(x0, x1), (float)(dim - 1));
    const float c = clamp(rint(xo + tm * xd), ceil(lo), floor(hi));
    if (!(c >= lo && c <= hi))
        return -1.0f;
    const float t = (c - xo) / xd, margin = 1e-3f * (tb - ta);
    return (t > ta + margin && t < tb - margin) ? t : -1.0f;
}

/* The kink of the three axes' nearest the middle of (ta, tb), or -1. */
inline float seg_kink(VolGeom g, float3 xo, float3 xd, float ta, float tb)
{
    const float tm = 0.5f * (ta + tb);
    const float k[3] = {seg_kink_axis(xo.x, xd.x, g.dims.x, ta, tb, tm),
                        seg_kink_axis(xo.y, xd.y, g.dims.y, ta, tb, tm),
                        seg_kink_axis(xo.z, xd.z, g.dims.z, ta, tb, tm)};
    float best = -1.0f;
    for (int a = 0; a < 3; ++a)
        if (k[a] >= 0.0f && (best < 0.0f || fabs(k[a] - tm) < fabs(best - tm)))
            best = k[a];
    return best;
}

/* The optical depth of the segment [ta, tb] of the ray p + t d (len voxels long, per_t voxels per
 * unit of t; xo, xd the ray in voxel coordinates) whose ends have the values va, vb, behind
 * d_before of optical depth (the least over the channels) on the way to the light:
 * segment_depth, refined where the value's departure from a straight line within the segment
 * would shift the extinction. A piece is a candidate for a split at a new sample
 *  - where the ray crosses a plane of voxel centres (the trilinear interpolant's kinks, an error
 *    of first order in the piece's length) and the extinction varies along the piece by more
 *    than SEG_KINK_DEPTH of optical depth, at that crossing: past the kinks the pieces are smooth,
 *    and a value linear in space along an axis is integrated exactly;
 *  - else, where it varies by more than SEG_REFINE_DEPTH (the interpolant's curvature, an error
 *    of second order), at the middle;
 * and the split is taken: the two halves' depths replace the piece's. Where those differ from it
 * by more than SEG_REFINE_TOL in some channel, each half is a candidate in turn (depth-first,
 * with an explicit stack, at most SEG_REFINE_LEVELS deep); where they agree, the halves are
 * kept and the refinement stops there: most candidates are smooth pieces over a steep part of
 * the transfer function, which the first split already shows to be resolved. The three
 * thresholds are multiplied by exp(d_before): an error e in this segment's depth moves the
 * shadow factor by at most e exp(-d_before), so each stands for the same error in the factor,
 * which is what the bounds and the images measure, wherever the segment lies. */
#define SEG_REFINE_LEVELS 3
#define SEG_REFINE_DEPTH 4e-3f
#define SEG_KINK_DEPTH 1e-3f
#ifndef SEG_REFINE_TOL
#define SEG_REFINE_TOL 3e-5f
#endif
inline light_t segment_refined(VOLUME_PARAM, VolGeom g, __global const float4 *tf, uint n,
                               uint flags, float3 p, float3 d, float3 xo, float3 xd, float ta,
                               float tb, float va, float vb, float len, float per_t,
                               float d_before)
{
    /* The pieces still to do after the current one: their ends, values at the ends, lengths,
     * depths, spreads and levels (each starts where the one above it ends). A split divides a
     * piece's length in voxels between its halves, so that they add up to the segment's. */
    float st_t[SEG_REFINE_LEVELS], st_v[SEG_REFINE_LEVELS], st_s[SEG_REFINE_LEVELS];
    float st_len[SEG_REFINE_LEVELS];
    light_t st_d[SEG_REFINE_LEVELS];
    int st_l[SEG_REFINE_LEVELS];
    int top = -1, level = 0;
    float spread;
    light_t dd = segment_depth(tf, n, va, vb, len, flags, &spread);
    light_t D = (light_t)(0.0f);
    /* The thresholds in optical depth, scaled by the transmittance the light keeps to the
     * segment (exp of d_before, computed where first needed). */
    float scale = 0.0f;
    for (;;) {
        /* The current piece: [ta, tb], len voxels, values va, vb, depth dd and its spread. */
        float tm = -1.0f;
        if (level < SEG_REFINE_LEVELS && spread > SEG_KINK_DEPTH) {
            if (scale == 0.0f)
                scale = exp(d_before);
            if (spread > SEG_KINK_DEPTH * scale) {
                tm = seg_kink(g, xo, xd, ta, tb);
                if (tm < 0.0f && spread > SEG_REFINE_DEPTH * scale)
                    tm = 0.5f * (ta + tb);
            }
        }
        if (tm >= 0.0f) {
            const float vm = sample_volume(vol, g, p + tm * d);
            const float len_l = clamp((tm - ta) * per_t, 0.0f, len), len_r = len - len_l;
            float s_l, s_r;
            const light_t d_l = segment_depth(tf, n, va, vm, len_l, flags, &s_l);
            const light_t d_r = segment_depth(tf, n, vm, vb, len_r, flags, &s_r);
            if (light_max(fabs(d_l + d_r - dd)) > SEG_REFINE_TOL * scale) {
                ++top;
                st_t[top] = tb;
                st_v[top] = vb;
                st_len[top] = len_r;
                st_d[top] = d_r;
                st_s[top] = s_r;
                st_l[top] = ++level;
                tb = tm;
                vb = vm;
                len = len_l;
                dd = d_l;
                spread = s_l;
                continue;
            }
            dd = d_l + d_r;
        }
        D += dd;
        if (top < 0)
            break;
        ta = tb;
        va = vb;
        tb = st_t[top];
        vb = st_v[top];
        len = st_len[top];
        dd = st_d[top];
        spread = st_s[top];
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
    /* A whole step is h_vox voxels long, the final partial one h_vox last / h; the pieces of
     * a refined step divide its length at per_t voxels per unit of t (the final step's length in
     * t, t_end - t_k, can round to 0 where last does not: dividing by it gave 0 / 0, a NaN
     * pixel). */
    const float h_vox = light_step_voxels(F, S), per_t = h_vox / h;
    const uint n_tf = F->light_tf_size;
    const uint flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    const float len = t_end - t_start;
    const int n_full = (int)floor(len / h);
    const float last = len - (float)n_full * h;
    const float3 xo = world_to_voxel(g, p), xd = d * g.inv_spacing;
    /* Optical depth, with its Kahan compensation. */
    light_t D = (light_t)(0.0f), comp = (light_t)(0.0f);
    /* Samples at t_start + k h, k = 0 .. n_full; v_k holds the value of sample k_have. */
    float v_k = 0.0f;
    int k_have = -1;
    /* The ray walks the cells of the light's cell masks (CellWalk); samples before t_cell lie in
     * a cell already found visible. */
    CellWalk w = walk_begin(g, p, d, t_start);
    float t_cell = -UMBRA_INF;
    for (int k = 0; k < n_full;) {
        if (skip && t_start + (float)k * h >= t_cell) {
            /* The first sample at or after k in a visible cell; the segment ending there
             * starts at the sample before it. */
            int kv = walk_next_sample(&w, g, light_cells, t_start, h, 0.0f, k, n_full + 1, t_end,
                                      &t_cell);
            if (kv > n_full)
                break;
            k = max(k, kv - 1);
        }
        if (k_have != k)
            v_k = sample_volume(vol, g, p + (t_start + (float)k * h) * d);
        const float v_next = sample_volume(vol, g, p + (t_start + (float)(k + 1) * h) * d);
        const float ta = t_start + (float)k * h;
        const light_t y = segment_refined(vol, g, light_tf, n_tf, flags, p, d, xo, xd, ta, ta + h,
                                          v_k, v_next, h_vox, per_t, light_min(D)) - comp;
        const light_t s = D + y;
        comp = (s - D) - y;
        D = s;
        if (light_min(D) > 13.815511f) /* -ln(1e-6) */
            return (float3)(0.0f);
        v_k = v_next;
        k_have = ++k;
    }
    /* The final partial segment, always integrated: skipping above may stop at a sample in an
     * invisible cell before a visible one at the box face. */
    if (last > 0.0f) {
        const float t_k = t_start + (float)n_full * h;
        if (k_have != n_full)
            v_k = sample_volume(vol, g, p + t_k * d);
        const float v_end = sample_volume(vol, g, p + t_end * d);
        D += segment_refined(vol, g, light_tf, n_tf, flags, p, d, xo, xd, t_k, t_end, v_k, v_end,
                             last * per_t, per_t, light_min(D)) - comp;
    }
    return light_rgb(exp(-D));
}
#endif

#define SHADOW_FACTOR(sr, p) reference_shadow(F, vol, g, light_tf, light_cells, S, (p))
