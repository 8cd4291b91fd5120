// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/moments.cl: the moment shadow map (after Peters & Klein 2015, "Moment
 * Shadow Mapping", and Muenstermann et al. 2018, "Moment-Based Order-Independent Transparency",
 * which stores moments of absorbance rather than of surface depth, as this map does).
 *
 * What a texel holds. Along the texel's light ray (through its centre, the light-space frame of
 * kernels/common/lightspace.cl) the light's optical depth tau grows with depth; its density over
 * the warped depth x = 2 z - 1 in [-1, 1] (z the map's normalised depth, 0 and 1 at the box's
 * nearest and farthest points along the light) is a non-negative measure on [-1, 1]. Per light
 * channel the texel stores that measure's total b0 (the ray's whole optical depth) and its
 * normalised power moments m_k = (1 / b0) integral of x^k, k = 1..count (count 4, 6 or 8). The
 * optical depth in front of a sample at x0 is b0 F(x0), F the measure's normalised cumulative;
 * the shadow factor is exp(-b0 F(x0)).
 *
 * Build (moments_build): one additive pass over the ray in any order. The march is the other
 * maps' (whole steps of S->step plus a partial one, empty cells skipped); a segment's optical
 * depth is that of its midpoint sample over its length (kernels/common/common.cl, light_depth),
 * taken as spread evenly over the segment's depth interval, whose exact mean of x^k (the
 * binomial sum below, without the cancellation of a difference of powers) it adds. The whole
 * segments share one half-width, so the march adds only od mid^j per segment and channel (mid
 * the segment's midpoint depth, x affine in the ray parameter) and applies the binomial sum once
 * at the end (mom_mix). A homogeneous medium therefore gives exactly the moments of the uniform spread over the depths
 * it covers. A channel's march stops once its optical depth reaches P->depth_cap (the segment
 * that passes it is cut where it does): the moments are then those of the measure in front of
 * that point, whose cumulative is the true one up to there, and a sample behind it gets
 * transmittance at most exp(-depth_cap). Then the moments are normalised and stored, as floats
 * or as 16-bit fixed point (P->bits).
 *
 * Pre-filter (moments_blur, optional): moments are linear in the measure, so the map can be
 * filtered before the lookup like any image: a separable binomial blur of radius P->blur texels
 * over b0 and b0 m_k (one pass per axis, host/techniques/maps.c), texels outside the map counting
 * as empty (the octahedral map's border folds as the taps' does).
 *
 * Lookup: the four texels around the sample's map position are mixed bilinearly (again in b0 and
 * b0 m_k: the moments of the mixed measure). The moments are biased, m' = (1 - alpha) m + alpha
 * u, u those of the uniform measure on [-1, 1] (alpha = P->bias; Peters & Klein's moment bias,
 * which keeps the Hankel matrix positive definite under rounding and quantisation). For the
 * biased moments the Chebyshev-Markov-Stieltjes inequalities of the Hausdorff moment problem
 * (support in [-1, 1]) give the sharp bounds
 *     lower(x0) <= F'(x0-) <= F'(x0) <= upper(x0) = lower(x0) + w0(x0):
 * the weights below x0 of the canonical representation through x0 (the atomic measure with the
 * same moments that puts the most weight w0 on x0), which is either n + 1 interior points (x0
 * and the roots of the kernel polynomial K(x, x0) of the Hankel matrix; the Hamburger
 * representation, n = count / 2), or, when a root falls outside [-1, 1], x0, n - 1 interior
 * points and both ends -1 and 1 (found as the Hamburger representation of (1 - x^2) times the
 * measure). Each interior point s weighs 1 / K(s, s) (the Christoffel function). With the bias
 * taken back out exactly (the uniform measure's cumulative is known), the optical depth in front
 * of x0 lies between b0 F_lo and b0 F_hi, F_lo = (lower - alpha (x0 + 1) / 2) / (1 - alpha) and
 * F_hi the same of upper, both clamped to [0, 1], so the shadow factor between lit =
 * exp(-b0 F_lo) and dark = exp(-b0 F_hi). The estimate is the factor lit + beta (dark - lit)
 * (beta = P->overestimation): at the default 0.5 the midpoint of the factor's bounds, the
 * estimate whose worst error in the factor is least. This departs from Muenstermann et al., whose
 * overestimation places the estimate between the bounds of the optical depth (as this map did
 * before 2026-12-03): the two agree where the bounds are narrow; where they are wide (an opaque
 * surface behind thin material, whose lit side's optical depth spans the whole capped depth) the
 * factor's midpoint leans to the lit side. In the seven-scene sweep it lowered the RMSE on six
 * scenes, the bonsai's by 55 %, and raised the walnut's by 2 % (docs/moments.md).
 *
 * Error. Against the stored measure the estimated factor is off by at most
 * max(beta, 1 - beta) (lit - dark) (too dark by at most beta (lit - dark), too light by at most
 * (1 - beta) (lit - dark)), and its optical depth lies between b0 F_lo and b0 F_hi. w0, the
 * largest weight any measure with these moments can put on x0, is small where the moments pin
 * the measure down (away from material: where the sample has material on one side only, or a
 * single thin layer) and largest inside thick, varied material. Before the box (x0 <= -1) nothing
 * is in front (factor 1 exactly), beyond it (x0 >= 1) all of b0 (exp(-b0), exact), and where a
 * measure has no weight in front of x0, the lower bound of the biased moments is at most
 * alpha (x0 + 1) / 2, so with beta = 0 the factor is 1 up to float rounding (1e-6). Beside it:
 * the midpoint sampling of the segments (the other maps'), the cap, the bilinear mix (optical
 * depth interpolated between texel rays), and rounding, which the bias covers.
 * tests/test_moments.c checks the bound on slabs and against the reference. */

#define SHADOW_KERNEL_PARAMS , __global const UmbraMoments *P, __global const uint *shadow_map

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

/* Channel c of a light_t. */
#if UMBRA_LIGHT_CHANNELS == 1
#define MOM_CH(v, c) (v)
#else
#define MOM_CH(v, c) ((c) == 0 ? (v).x : (c) == 1 ? (v).y : (v).z)
#endif

#define MOM_N_MAX (UMBRA_MOMENTS_MAX / 2) /* the largest Hankel order */

/* ---- storage ------------------------------------------------------------------------------- */

/* A channel's record at word `at` of the map: b0, then m_1..m_count (floats, or two 16-bit
 * fixed-point values to a word, m_{2j+1} in the low half). */
UMBRA_INLINE void mom_store(__global uint *map, size_t at, uint bits, int count, float b0,
                            const float *m)
{
    map[at] = as_uint(b0);
    if (bits == 32u) {
        for (int k = 1; k <= count; ++k)
            map[at + (size_t)k] = as_uint(m[k]);
        return;
    }
    for (int j = 0; 2 * j < count; ++j) {
        const int lo = convert_int_sat_rte(clamp(m[2 * j + 1], -1.0f, 1.0f) * 32767.0f);
        const int hi = convert_int_sat_rte(clamp(m[2 * j + 2], -1.0f, 1.0f) * 32767.0f);
        map[at + 1 + (size_t)j] = ((uint)lo & 0xffffu) | ((uint)hi << 16);
    }
}

/* b0 of the record at `at`, and its moments times w b0 added to acc[1..count]; returns b0. */
UMBRA_INLINE float mom_load_add(__global const uint *map, size_t at, uint bits, int count,
                                float w, float *acc)
{
    const float b0 = as_float(map[at]);
    const float wb = w * b0;
    if (bits == 32u) {
        for (int k = 1; k <= count; ++k)
            acc[k] += wb * as_float(map[at + (size_t)k]);
        return b0;
    }
    const float q = wb * (1.0f / 32767.0f);
    for (int j = 0; 2 * j < count; ++j) {
        const uint v = map[at + 1 + (size_t)j];
        acc[2 * j + 1] += q * (float)(short)(v & 0xffffu);
        acc[2 * j + 2] += q * (float)(short)(v >> 16);
    }
    return b0;
}

/* ---- build ----------------------------------------------------------------------------------- */

/* C(k, 2i): the binomial coefficients of the segment sums below, k <= 8. */
__constant float mom_binomial_even[UMBRA_MOMENTS_MAX + 1][5] = {
    {1, 0, 0, 0, 0},   {1, 0, 0, 0, 0},    {1, 1, 0, 0, 0},    {1, 3, 0, 0, 0},
    {1, 6, 1, 0, 0},   {1, 10, 5, 0, 0},   {1, 15, 15, 1, 0},  {1, 21, 35, 7, 0},
    {1, 28, 70, 28, 1}};

/* e[k], k = 1..count: the mean of x^k over x uniform on [mid - rad, mid + rad], which is
 * sum over i of C(k, 2i) mid^(k - 2i) rad^(2i) / (2i + 1). */
UMBRA_INLINE void mom_segment(float mid, float rad, int count, float *e)
{
    float mp[UMBRA_MOMENTS_MAX + 1], hq[5];
    mp[0] = 1.0f;
    for (int k = 1; k <= count; ++k)
        mp[k] = mp[k - 1] * mid;
    const float h2 = rad * rad;
    float hp = 1.0f;
    for (int i = 0; i < 5; ++i, hp *= h2)
        hq[i] = hp / (float)(2 * i + 1);
    for (int k = 1; k <= count; ++k) {
        float s = 0.0f;
        for (int i = 0; 2 * i <= k; ++i)
            s += mom_binomial_even[k][i] * mp[k - 2 * i] * hq[i];
        e[k] = s;
    }
}

/* The march adds, per channel, the sums of od mid^j (j = 0..count, od a segment's optical depth,
 * mid its depth's midpoint) over the whole segments, whose half-width rad is the same for all of
 * them: the segments' sum of od e[k] is then sum over i of C(k, 2i) rad^(2i) / (2i + 1) times
 * the sum of od mid^(k - 2i), mixed once at the end (mom_mix), so a segment costs count
 * multiply-adds per channel rather than mom_segment's binomial sums. The partial last segment
 * and the one the cap cuts add their mom_segment means directly. */
UMBRA_INLINE void mom_mix(float rad, int count, const float *pw, float *sum)
{
    float hq[5];
    const float h2 = rad * rad;
    float hp = 1.0f;
    for (int i = 0; i < 5; ++i, hp *= h2)
        hq[i] = hp / (float)(2 * i + 1);
    for (int k = 1; k <= count; ++k) {
        float s = 0.0f;
        for (int i = 0; 2 * i <= k; ++i)
            s += mom_binomial_even[k][i] * pw[k - 2 * i] * hq[i];
        sum[k] += s;
    }
}

/* The march of one texel's light ray (o, d over tb), into tau, pw and sum (zeroed by the
 * caller). count is a constant at each call (moments_build's switch), so that the loops over the
 * moments and channels unroll and the sums stay in registers: with count read at run time they
 * live in memory, loaded and stored per segment and channel. */
UMBRA_INLINE void mom_march(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                            __global const float4 *light_tf, __global const ulong *light_cells,
                            __global const UmbraShadow *S, const float cap, float3 o, float3 d,
                            float2 tb, float x_of0, float x_per_t, const int count,
                            float tau[UMBRA_LIGHT_CHANNELS],
                            float pw[UMBRA_LIGHT_CHANNELS][UMBRA_MOMENTS_MAX + 1],
                            float sum[UMBRA_LIGHT_CHANNELS][UMBRA_MOMENTS_MAX + 1])
{
    const float h = S->step;
    const float h_vox = light_step_voxels(F, S);
    const uint n_tf = F->light_tf_size, flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    const float len = tb.y - tb.x;
    const int n_full = (int)floor(len / h);
    const float last = len - (float)n_full * h;
    CellWalk w = walk_begin(g, o, d, tb.x);
    float t_cell = -UMBRA_INF;
    for (int k = 0; k <= n_full;) {
        if (skip && k < n_full && tb.x + ((float)k + 0.5f) * h >= t_cell)
            k = walk_next_sample(&w, g, light_cells, tb.x, h, 0.5f, k, n_full, tb.y, &t_cell);
        const float seg = k < n_full ? h : last;
        if (!(seg > 0.0f))
            break;
        const float t_start = tb.x + (float)k * h;
        const float t_mid = t_start + 0.5f * seg;
        const float4 col = light_sample(F, vol, g, light_tf, n_tf, o + t_mid * d);
        if (col.w > 0.0f) {
            const light_t od = light_depth(col, h_vox * (seg / h), flags);
            const float mid = x_of0 + t_mid * x_per_t, rad = 0.5f * seg * x_per_t;
            float mp[UMBRA_MOMENTS_MAX + 1];
            mp[0] = 1.0f;
            for (int i = 1; i <= count; ++i)
                mp[i] = mp[i - 1] * mid;
            int going = 0;
            for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
                const float odc = MOM_CH(od, c);
                if (tau[c] >= cap)
                    continue;
                if (tau[c] + odc < cap) {
                    tau[c] += odc;
                    if (k < n_full) {
                        for (int i = 0; i <= count; ++i)
                            pw[c][i] += odc * mp[i];
                    } else { /* the partial last segment */
                        float e[UMBRA_MOMENTS_MAX + 1];
                        mom_segment(mid, rad, count, e);
                        for (int i = 1; i <= count; ++i)
                            sum[c][i] += odc * e[i];
                    }
                    ++going;
                    continue;
                }
                /* The cap is passed in this segment: only its part in front of that point, at
                 * the segment's density. */
                const float part = cap - tau[c], f = part / odc;
                float ec[UMBRA_MOMENTS_MAX + 1];
                mom_segment(mid - rad + f * rad, f * rad, count, ec);
                for (int i = 1; i <= count; ++i)
                    sum[c][i] += part * ec[i];
                tau[c] = cap;
            }
            if (!going)
                break;
        }
        ++k;
    }
}

__kernel void moments_build(__global const UmbraFrame *F, VOLUME_PARAM,
                            __global const float4 *view_tf, __global const float4 *light_tf,
                            __global const uchar *view_bricks, __global const ulong *light_cells,
                            __global const UmbraShadow *S, __global const UmbraMoments *P,
                            __global uint *map)
{
    const int x = get_global_id(0), y = get_global_id(1);
    const int n = (int)S->map_size;
    if (x >= n || y >= n)
        return;
    (void)view_tf;
    (void)view_bricks;
    const int count = (int)P->count;
    /* tau: the optical depth so far; pw: the whole segments' sums of od mid^j; sum: the
     * partial segments' sums of od e[k] */
    float tau[UMBRA_LIGHT_CHANNELS], pw[UMBRA_LIGHT_CHANNELS][UMBRA_MOMENTS_MAX + 1],
        sum[UMBRA_LIGHT_CHANNELS][UMBRA_MOMENTS_MAX + 1];
    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
        tau[c] = 0.0f;
        for (int k = 0; k <= UMBRA_MOMENTS_MAX; ++k)
            pw[c][k] = sum[c][k] = 0.0f;
    }
    const VolGeom g = vol_geom(F);
    float3 o, d;
    const float2 tb = ls_texel_ray(S, g, (float2)((float)x + 0.5f, (float)y + 0.5f), &o, &d);
    /* the warped depth is affine in the ray parameter: x(t) = x_of0 + t x_per_t */
    const float x_of0 = 2.0f * ls_depth(S, o, 0.0f) - 1.0f;
    const float x_per_t = 2.0f * S->near_far[2];
    const float rad_full = 0.5f * S->step * x_per_t;
    if (tb.y > tb.x) {
        const float cap = P->depth_cap;
        if (count == 4)
            mom_march(F, vol, g, light_tf, light_cells, S, cap, o, d, tb, x_of0, x_per_t, 4, tau,
                      pw, sum);
        else if (count == 6)
            mom_march(F, vol, g, light_tf, light_cells, S, cap, o, d, tb, x_of0, x_per_t, 6, tau,
                      pw, sum);
        else
            mom_march(F, vol, g, light_tf, light_cells, S, cap, o, d, tb, x_of0, x_per_t, 8, tau,
                      pw, sum);
    }
    const size_t texel = ((size_t)y * (size_t)n + (size_t)x) * UMBRA_LIGHT_CHANNELS;
    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
        float m[UMBRA_MOMENTS_MAX + 1];
        mom_mix(rad_full, count, pw[c], sum[c]);
        const float inv = tau[c] > 0.0f ? 1.0f / tau[c] : 0.0f;
        for (int k = 1; k <= count; ++k)
            m[k] = clamp(sum[c][k] * inv, -1.0f, 1.0f);
        mom_store(map, (texel + (size_t)c) * P->words, P->bits, count, tau[c], m);
    }
}

/* ---- pre-filter ------------------------------------------------------------------------------ */

/* One pass of the separable binomial blur, along x (pass 0) or y (pass 1): weights
 * C(2r, j) / 4^r at offsets j - r. */
__kernel void moments_blur(__global const UmbraShadow *S, __global const UmbraMoments *P,
                           uint pass, __global const uint *src, __global uint *dst)
{
    const int x = get_global_id(0), y = get_global_id(1);
    const int n = (int)S->map_size;
    if (x >= n || y >= n)
        return;
    const int r = min((int)P->blur, UMBRA_MOMENTS_MAX_BLUR), count = (int)P->count;
    const uint bits = P->bits, words = P->words;
    float b0[UMBRA_LIGHT_CHANNELS], acc[UMBRA_LIGHT_CHANNELS][UMBRA_MOMENTS_MAX + 1];
    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
        b0[c] = 0.0f;
        for (int k = 0; k <= UMBRA_MOMENTS_MAX; ++k)
            acc[c][k] = 0.0f;
    }
    float wj = 1.0f; /* C(2r, j), built up term by term */
    const float norm = 1.0f / (float)(1 << (2 * r));
    for (int j = 0; j <= 2 * r; ++j) {
        const int2 t = pass == 0u ? (int2)(x + j - r, y) : (int2)(x, y + j - r);
        const int i = ls_texel_index(S, t);
        if (i >= 0)
            for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c)
                b0[c] += wj * norm *
                         mom_load_add(src, ((size_t)i * UMBRA_LIGHT_CHANNELS + (size_t)c) * words,
                                      bits, count, wj * norm, acc[c]);
        wj = wj * (float)(2 * r - j) / (float)(j + 1);
    }
    const size_t texel = ((size_t)y * (size_t)n + (size_t)x) * UMBRA_LIGHT_CHANNELS;
    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
        const float inv = b0[c] > 0.0f ? 1.0f / b0[c] : 0.0f;
        for (int k = 1; k <= count; ++k)
            acc[c][k] = clamp(acc[c][k] * inv, -1.0f, 1.0f);
        mom_store(dst, (texel + (size_t)c) * words, bits, count, b0[c], acc[c]);
    }
}

/* ---- reconstruction -------------------------------------------------------------------------- */

/* The LDL^T factors of the Hankel matrix H[i][j] = m[i + j], i, j = 0..n: unit lower L (below
 * the diagonal), D. Returns the largest order <= n whose matrix is positive definite (the
 * moments beyond it are not used), or -1 when m[0] is not positive. */
UMBRA_INLINE int mom_ldl(const float *m, int n, float L[MOM_N_MAX + 1][MOM_N_MAX + 1],
                         float *D)
{
    for (int j = 0; j <= n; ++j) {
        float dj = m[2 * j];
        for (int k = 0; k < j; ++k)
            dj -= L[j][k] * L[j][k] * D[k];
        if (!(dj > 1e-30f))
            return j - 1;
        D[j] = dj;
        for (int i = j + 1; i <= n; ++i) {
            float s = m[i + j];
            for (int k = 0; k < j; ++k)
                s -= L[i][k] * L[j][k] * D[k];
            L[i][j] = s / dj;
        }
    }
    return n;
}

/* u = L^-1 (1, x, .., x^n); returns K(x, x) = sum of u_i^2 / D_i, the kernel polynomial's
 * diagonal (1 / K(x, x) is the Christoffel function: the most weight a measure with these
 * moments can put on x). */
UMBRA_INLINE float mom_kernel_diag(float L[MOM_N_MAX + 1][MOM_N_MAX + 1], const float *D, int n,
                                   float x, float *u)
{
    float p = 1.0f, k = 0.0f;
    for (int i = 0; i <= n; ++i, p *= x) {
        float s = p;
        for (int j = 0; j < i; ++j)
            s -= L[i][j] * u[j];
        u[i] = s;
        k += s * s / D[i];
    }
    return k;
}

/* Roots of sum c[i] x^i, i = 0..deg (1 <= deg <= 4, all roots real: a kernel polynomial's),
 * into r; returns 0 when the leading coefficient vanishes (no root is then trusted), else deg.
 * deg is the Hankel order, read at run time (count / 2). */
UMBRA_INLINE int mom_roots(const float *c_in, const int deg, float *r)
{
    float c[MOM_N_MAX + 1];
    if (!(fabs(c_in[deg]) > 0.0f))
        return 0;
    const float lead = 1.0f / c_in[deg];
    for (int i = 0; i <= deg; ++i)
        c[i] = c_in[i] * lead;
    if (deg == 1) {
        r[0] = -c[0];
        return 1;
    }
    if (deg == 2) {
        const float b = c[1], disc = fmax(b * b - 4.0f * c[0], 0.0f);
        const float q = -0.5f * (b + copysign(sqrt(disc), b));
        r[0] = q;
        r[1] = q != 0.0f ? c[0] / q : 0.0f;
        return 2;
    }
    if (deg == 4) {
        /* Newton from above every root (Cauchy's bound) goes down to the largest one, steadily,
         * for a polynomial whose roots are real; then divide it out. */
        float x = 1.0f;
        for (int i = 0; i < 4; ++i)
            x = fmax(x, 1.0f + fabs(c[i]));
        for (int it = 0; it < 60; ++it) {
            const float p = (((x + c[3]) * x + c[2]) * x + c[1]) * x + c[0];
            const float dp = ((4.0f * x + 3.0f * c[3]) * x + 2.0f * c[2]) * x + c[1];
            const float step = dp != 0.0f ? p / dp : 0.0f;
            x -= step;
            if (!(fabs(step) > 1e-7f * fmax(1.0f, fabs(x))))
                break;
        }
        r[3] = x;
    }
    float a3 = c[2], b3 = c[1], e3 = c[0];
    if (deg == 4) { /* c / (x - r[3]) by synthetic division: the monic cubic left */
        const float x = r[3];
        a3 = c[3] + x;
        b3 = c[2] + x * a3;
        e3 = c[1] + x * b3;
    }
    /* Monic cubic x^3 + a x^2 + b x + e with three real roots: Viete's trigonometric form. */
    const float Q = (a3 * a3 - 3.0f * b3) / 9.0f;
    const float R = (2.0f * a3 * a3 * a3 - 9.0f * a3 * b3 + 27.0f * e3) / 54.0f;
    const float sq = sqrt(fmax(Q, 0.0f));
    const float cosarg = Q > 0.0f ? clamp(R / (Q * sq), -1.0f, 1.0f) : 0.0f;
    const float th = acos(cosarg) / 3.0f, sc = -2.0f * sq, shift = a3 / 3.0f;
    float cth;
    const float sth = sincos(th, &cth);
    /* cos(th -+ 2 pi / 3) = -cos(th) / 2 +- sin(th) sqrt(3) / 2: one sincos for three cosines */
    const float mid = -0.5f * cth, side = 0.8660254f * sth;
    r[0] = sc * cth - shift;
    r[1] = sc * (mid - side) - shift;
    r[2] = sc * (mid + side) - shift;
    return deg;
}

/* The canonical representation through x0 of the measure whose moments are mm[0..2n] (Hankel
 * factors L, D of order n): its other support points, the roots of K(x, x0), into s (count
 * returned), their weights 1 / K(s, s) into ws, and x0's, 1 / K(x0, x0), into *w0. */
UMBRA_INLINE int mom_canonical(float L[MOM_N_MAX + 1][MOM_N_MAX + 1], const float *D, int n,
                               float x0, float *s, float *ws, float *w0)
{
    float u[MOM_N_MAX + 1], cf[MOM_N_MAX + 1];
    *w0 = 1.0f / mom_kernel_diag(L, D, n, x0, u);
    /* K(x, x0)'s coefficients: H^-1 (1, x0, ..) = L^-T D^-1 u */
    for (int i = n; i >= 0; --i) {
        float v = u[i] / D[i];
        for (int j = i + 1; j <= n; ++j)
            v -= L[j][i] * cf[j];
        cf[i] = v;
    }
    const int k = mom_roots(cf, n, s);
    for (int i = 0; i < k; ++i)
        ws[i] = 1.0f / mom_kernel_diag(L, D, n, s[i], u);
    return k;
}

/* The lower Hausdorff bound on the normalised cumulative in front of x0 in (-1, 1) of the
 * measure with moments m[0..2n] (m[0] = 1, biased), into *lower, and the weight the canonical
 * representation through x0 puts on x0, into *w0 (upper = lower + w0). Returns 0, leaving both
 * unset, where the Hankel matrix of order n (or, with both ends in the support, that of
 * (1 - x^2) mu of order n - 1) is not positive definite. */
UMBRA_INLINE int mom_bounds_of_order(const float *m, const int n, float x0, float *lower,
                                     float *w0)
{
    float L[MOM_N_MAX + 1][MOM_N_MAX + 1], D[MOM_N_MAX + 1], s[MOM_N_MAX], ws[MOM_N_MAX];
    if (mom_ldl(m, n, L, D) < n)
        return 0;
    const int k = mom_canonical(L, D, n, x0, s, ws, w0);
    int inside = k == n;
    for (int i = 0; i < n; ++i)
        inside &= s[i] >= -1.0f && s[i] <= 1.0f;
    if (inside) { /* the Hamburger representation lies in [-1, 1] */
        float lo = 0.0f, all = *w0;
        for (int i = 0; i < n; ++i) {
            all += ws[i];
            lo += s[i] < x0 ? ws[i] : 0.0f;
        }
        *lower = lo / all;
        *w0 /= all;
        return 1;
    }
    /* Both ends in the support: the interior points are the Hamburger representation through
     * x0 of nu = (1 - x^2) mu, whose moments are m_k - m_{k+2}; mu's weight at an interior
     * point is nu's over 1 - x^2, and the ends' weights follow from m_0 and m_1. */
    float nu[UMBRA_MOMENTS_MAX + 1], wx;
    for (int i = 0; i <= 2 * n - 2; ++i)
        nu[i] = m[i] - m[i + 2];
    if (mom_ldl(nu, n - 1, L, D) < n - 1)
        return 0;
    int kn = 0;
    if (n > 1) {
        kn = mom_canonical(L, D, n - 1, x0, s, ws, &wx);
        if (kn < n - 1)
            return 0;
    } else {
        wx = nu[0]; /* order 0: K = 1 / nu_0 */
    }
    wx = fmax(wx, 0.0f) / fmax(1.0f - x0 * x0, 1e-12f);
    float mass = wx, first = x0 * wx, lo = 0.0f;
    for (int i = 0; i < n - 1; ++i) {
        const float si = clamp(s[i], -1.0f, 1.0f);
        const float wi = fmax(ws[i], 0.0f) / fmax(1.0f - si * si, 1e-12f);
        mass += wi;
        first += si * wi;
        lo += si < x0 ? wi : 0.0f;
    }
    const float w_left = fmax(0.5f * (m[0] - mass - (m[1] - first)), 0.0f);
    const float w_right = fmax(0.5f * (m[0] - mass + (m[1] - first)), 0.0f);
    const float all = mass + w_left + w_right;
    *lower = (lo + w_left) / all;
    *w0 = wx / all;
    return 1;
}

/* mom_bounds_of_order at order n, else at the highest lower order that is well
 * posed (rare: the bias keeps order n so), else a single point at the mean. */
UMBRA_INLINE void mom_bounds(const float *m, const int n, float x0, float *lower, float *w0)
{
    if (mom_bounds_of_order(m, n, x0, lower, w0))
        return;
    for (int k = n - 1; k >= 1; --k)
        if (mom_bounds_of_order(m, k, x0, lower, w0))
            return;
    *lower = m[1] < x0 ? 1.0f : 0.0f;
    *w0 = 0.0f;
}

/* The estimated shadow factor of a channel whose mixed record is b0 and the moment sums
 * acc[1..count] (b0 times the moments), in front of x0. */
UMBRA_INLINE float mom_factor(__global const UmbraMoments *P, const int count, float b0,
                              const float *acc, float x0)
{
    if (!(b0 > 0.0f))
        return 1.0f;
    if (x0 >= 1.0f)
        return exp(-b0); /* behind the box: everything is in front */
    const float alpha = P->bias, inv = 1.0f / b0;
    float m[UMBRA_MOMENTS_MAX + 1];
    m[0] = 1.0f;
    for (int k = 1; k <= count; ++k) /* the uniform measure's moments: 1 / (k + 1), k even */
        m[k] = (1.0f - alpha) * clamp(acc[k] * inv, -1.0f, 1.0f) +
               ((k & 1) ? 0.0f : alpha / (float)(k + 1));
    float lower, w0;
    mom_bounds(m, count / 2, x0, &lower, &w0);
    const float unbias = alpha * 0.5f * (x0 + 1.0f), scale = b0 / (1.0f - alpha);
    const float lit = exp(-scale * clamp(lower - unbias, 0.0f, 1.0f - alpha));
    const float dark = exp(-scale * clamp(lower + w0 - unbias, 0.0f, 1.0f - alpha));
    return lit + P->overestimation * (dark - lit);
}

/* The shadow factor at p: the bilinear mix of the four texels around p's map position.
 * Specialising it per count and storage at compile time (a switch over six instances with
 * constant count and bits) measured no faster on PoCL and compiled six copies, so count and
 * bits are read at run time; the cost is the reconstruction's arithmetic, per channel and sample
 * (docs/moments.md has the measurements). */
UMBRA_INLINE float3 moments_lookup_as(__global const UmbraShadow *S,
                                      __global const UmbraMoments *P, __global const uint *map,
                                      float3 p, const int count, const uint bits)
{
    const float3 mp = ls_world_to_map(S, p);
    const float x0 = 2.0f * mp.z - 1.0f;
    int2 base;
    if (!(x0 > -1.0f) || !ls_base_texel(S, mp.xy - 0.5f, &base))
        return (float3)(1.0f); /* in front of the box, or off the map */
    const float2 f = mp.xy - 0.5f - convert_float2(base);
    const float wt[4] = {(1.0f - f.x) * (1.0f - f.y), f.x * (1.0f - f.y), (1.0f - f.x) * f.y,
                         f.x * f.y};
    const int n = (int)S->map_size;
    const uint words = 1u + (bits == 16u ? (uint)count / 2u : (uint)count);
    int idx[4];
    if (base.x >= 0 && base.y >= 0 && base.x < n - 1 && base.y < n - 1) {
        idx[0] = base.y * n + base.x;
        idx[1] = idx[0] + 1;
        idx[2] = idx[0] + n;
        idx[3] = idx[2] + 1;
    } else {
        for (int j = 0; j < 4; ++j)
            idx[j] = ls_texel_index(S, base + (int2)(j & 1, j >> 1));
    }
    float out[3];
    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
        float acc[UMBRA_MOMENTS_MAX + 1], b0 = 0.0f;
        for (int k = 1; k <= count; ++k)
            acc[k] = 0.0f;
        for (int j = 0; j < 4; ++j)
            if (idx[j] >= 0)
                b0 += wt[j] * mom_load_add(map,
                                           ((size_t)idx[j] * UMBRA_LIGHT_CHANNELS + (size_t)c) *
                                               words,
                                           bits, count, wt[j], acc);
        out[c] = mom_factor(P, count, b0, acc, x0);
    }
#if UMBRA_LIGHT_CHANNELS == 1
    return (float3)(out[0]);
#else
    return (float3)(out[0], out[1], out[2]);
#endif
}

UMBRA_INLINE float3 moments_lookup(__global const UmbraShadow *S, __global const UmbraMoments *P,
                                   __global const uint *map, float3 p)
{
    return moments_lookup_as(S, P, map, p, (int)P->count, P->bits);
}

#define SHADOW_FACTOR(sr, p) moments_lookup(S, P, shadow_map, (p))
