// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/cssm.cl: colored stochastic shadow maps for direct volume rendering (Weidner &
 * Linsen, after McGuire & Enderton's CSSM for surfaces).
 *
 * Generation, the paper's Table 1 (cssm_build): one photon per texel on a light ray discretised
 * into segments i, per channel the probability rho_i that the photon is not transmitted by
 * segment i, and the depth of the first segment that stops it stored per channel. The paper has
 * rho_i = alpha_i (1 - t_i) (t the light transfer function's RGB in coloured mode, 0 in grey
 * mode); umbra takes rho_i = 1 - exp(-od_i), od_i = -ln(1 - alpha_i) (1 - t_i) the segment's
 * optical depth in the shading model's extinction (kernels/common/common.cl, light_depth), of which
 * the
 * paper's is the first-order form: the two agree in grey mode and for thin segments, and only
 * umbra's is independent of the step in a homogeneous medium. With UMBRA_LIGHT_CHANNELS == 1 (a
 * grey light) one channel is simulated and stored, not three. Two deviations, both keeping each
 * texel's stored depth distributed as the paper's:
 *
 * 1. One random number per photon, not one per segment. The paper draws r_i per segment (shared
 *    by the channels) and stops the photon where rho_i > r_i. umbra draws u per photon (shared by
 *    the channels) and stops it in the first segment where the optical depth from the light,
 *    sum od_i, passes E = -ln(1 - u): inverse-transform sampling of the same event. Both stop a
 *    photon in segment i with probability prod_{k<i} (1 - rho_k) rho_i, and in both a channel
 *    that absorbs more is stopped no later. One number a photon costs a logarithm once, where the
 *    per-segment test needed a random number per segment; and it lets photons share a ray:
 *
 * 2. The photons of a block of B x B texels share one light ray, through the block's centre
 *    (P->ray_block; B = 1 is the paper's ray per texel). Each keeps its own u, so the block's
 *    photons are independent draws on that ray: the march sorts their E and stops each photon
 *    where the optical depth passes its E, until the last one (in every channel) is stopped. The
 *    host's default B is the map's whole texels per voxel, at most 3, so that the rays a block
 *    stands for would cross the same voxels: at auto sizes (3 texels per voxel) that is a ninth
 *    of the rays, each marched until the deepest of nine photons stops; the error and build
 *    time against a ray per texel (ray_block 1) are in docs/techniques.md (CSSM) and
 *    docs/performance.md. The taps of a lookup (radius >= 4 texels) fall in other blocks, so
 *    the average still draws on 13 rays.
 *
 * Segments: whole steps of S->step plus one partial step, sampled at their midpoints, each with
 * the optical depth of its length, so the product of the (1 - rho_i) along a whole ray is the
 * midpoint-rule transmittance. z_i is the depth of segment i's midpoint, its sample point: a
 * sample at depth s is then shadowed by exactly the segments whose sample lies in front of it, so
 * P(lit) = prod over those of (1 - rho_i), within half a step of the continuous exp(-sigma d) on
 * either side, and no bias is needed (the paper has none). Unstopped channels keep
 * LS_DEPTH_NEVER.
 *
 * u = umbra_random(seed, x, y, 0) for texel (x, y): counter-based, so the map depends on the seed
 * alone (same seed, same map and image, bit for bit), and skipped empty segments (od = 0) change
 * nothing.
 *
 * Lookup, the paper's Table 2: the m taps around the sample's texel (ls_taps); channel c is lit by
 * each tap whose stored depth lies beyond the sample's (c_lambda > s_z); the factor is j/m. */

#define SHADOW_KERNEL_PARAMS , __global const UmbraCssm *P, __global const float *shadow_map

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

/* A texel's depths (one per light channel) in the map, and per channel c of a light_t (c a
 * constant in the unrolled loops below) the value, and a light_t of an array's values. */
#if UMBRA_LIGHT_CHANNELS == 1
#define CSSM_STORE(v, i, map) ((map)[i] = (v))
#define CSSM_LOAD(i, map) ((map)[i])
#define LIGHT_CH(v, c) (v)
#define LIGHT_FROM(a) ((a)[0])
#else
#define CSSM_STORE(v, i, map) vstore3((v), (i), (map))
#define CSSM_LOAD(i, map) vload3((i), (map))
#define LIGHT_CH(v, c) ((c) == 0 ? (v).x : (c) == 1 ? (v).y : (v).z)
#define LIGHT_FROM(a) ((float3)((a)[0], (a)[1], (a)[2]))
#endif

/* light_depth (kernels/common/common.cl) without its library call: the march needs a segment's
 * optical
 * depth at every segment of material, and PoCL's log1p, a call per segment, was a large part of
 * a build (docs/performance-log.md, "Behind the kernels' comments"). For alpha up to 0.5,
 * -ln(1 - a) = 2 atanh(s) with s = a / (2 - a) <= 1/3, summed to s^13: within 1.8 float epsilons
 * of the exact value at every float a in (0, 0.5] (checked against a double log1p), where
 * log1p is within 0.7; above 0.5, 1 - a is exact and a plain logarithm serves (rare: such a
 * segment stops most photons). */
inline light_t cssm_depth(float4 c, float len, uint flags)
{
    const float a = fmin(c.w, UMBRA_ALPHA_MAX);
    float ext;
    if (a > 0.5f) {
        ext = -log(1.0f - a);
    } else {
        const float s = a / (2.0f - a), s2 = s * s;
        ext = 2.0f * s *
              (1.0f + s2 * (1.0f / 3.0f +
                            s2 * (1.0f / 5.0f +
                                  s2 * (1.0f / 7.0f +
                                        s2 * (1.0f / 9.0f + s2 * (1.0f / 11.0f + s2 / 13.0f))))));
    }
    return (ext * len) * light_absorbed(c, flags);
}

/* A block's photons: one per texel of the block, at most UMBRA_CSSM_MAX_RAY_BLOCK^2. */
#define CSSM_MAX_PHOTONS (UMBRA_CSSM_MAX_RAY_BLOCK * UMBRA_CSSM_MAX_RAY_BLOCK)

__kernel void cssm_build(__global const UmbraFrame *F, VOLUME_PARAM,
                         __global const float4 *view_tf, __global const float4 *light_tf,
                         __global const uchar *view_bricks, __global const ulong *light_cells,
                         __global const UmbraShadow *S, __global const UmbraCssm *P,
                         __global float *map
#if UMBRA_PART
                         , __global float *part_state
#endif
                         )
{
    const int n = (int)S->map_size, B = clamp((int)P->ray_block, 1, UMBRA_CSSM_MAX_RAY_BLOCK);
    const int x0 = (int)get_global_id(0) * B, y0 = (int)get_global_id(1) * B;
    if (x0 >= n || y0 >= n)
        return;
    (void)view_tf;
    (void)view_bricks;
    const uint seed = P->seed;
    const int bw = min(B, n - x0), bh = min(B, n - y0); /* the block's texels inside the map */
    /* The photons' optical-depth thresholds E = -ln(1 - u), sorted ascending, with their
     * texels (index j = row * B + column in the block). */
    float e[CSSM_MAX_PHOTONS];
    int id[CSSM_MAX_PHOTONS];
    int np = 0;
    for (int j = 0; j < B * B; ++j) {
        const int x = x0 + j % B, y = y0 + j / B;
        if (x >= n || y >= n)
            continue;
        const float v = -log1p(-umbra_random(seed, (uint)x, (uint)y, 0u));
        int i = np++;
        for (; i > 0 && e[i - 1] > v; --i) {
            e[i] = e[i - 1];
            id[i] = id[i - 1];
        }
        e[i] = v;
        id[i] = j;
    }
    /* z[i * CH + c]: the depth at which sorted photon i is stopped in channel c. */
    float z[CSSM_MAX_PHOTONS * UMBRA_LIGHT_CHANNELS];
    for (int i = 0; i < np * UMBRA_LIGHT_CHANNELS; ++i)
        z[i] = LS_DEPTH_NEVER;
    const VolGeom g = vol_geom(F);
    float3 o, d;
    const float2 tb = ls_texel_ray(
        S, g, (float2)((float)x0 + 0.5f * (float)bw, (float)y0 + 0.5f * (float)bh), &o, &d);
    if (tb.y > tb.x) {
        const float h = S->step, h_vox = light_step_voxels(F, S);
        const uint n_tf = F->light_tf_size, flags = F->flags;
        const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
        const float len = tb.y - tb.x;
        const int n_full = (int)floor(len / h);
        const float last = len - (float)n_full * h;
        CellWalk w = walk_begin(g, o, d, tb.x);
        float t_cell = -UMBRA_INF;
        light_t tau = (light_t)(0.0f);
        int next[UMBRA_LIGHT_CHANNELS]; /* per channel, the first sorted photon still going */
        for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c)
            next[c] = 0;
        int going = np * UMBRA_LIGHT_CHANNELS;
        light_t e_next = (light_t)(e[0]); /* per channel, that photon's threshold */
#if UMBRA_PART
        /* A part goes on with the optical depth per channel the parts before it on this ray left
         * (host/part_render.c; the block's first texel holds it): the same sum as one device's
         * march, bit for bit. A photon whose threshold that depth has passed was stopped by an
         * earlier part, which stored its depth; here it keeps LS_DEPTH_NEVER, and the minimum
         * over the parts' maps is one device's map. */
        const int s0 = (y0 * n + x0) * UMBRA_LIGHT_CHANNELS;
        {
            float en[UMBRA_LIGHT_CHANNELS];
            for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
                const float tc = part_state[s0 + c];
                int i = 0;
                while (i < np && tc > e[i])
                    ++i;
                next[c] = i;
                going -= i;
                en[c] = i < np ? e[i] : UMBRA_INF;
            }
            tau = LIGHT_FROM(part_state + s0);
            e_next = LIGHT_FROM(en);
        }
        int owned = 0;
#endif
        for (int k = 0; k <= n_full && going > 0;) {
            if (skip && k < n_full && tb.x + ((float)k + 0.5f) * h >= t_cell)
                k = walk_next_sample(&w, g, light_cells, tb.x, h, 0.5f, k, n_full, tb.y, &t_cell);
            const float seg = k < n_full ? h : last;
            if (!(seg > 0.0f))
                break;
            const float t_mid = tb.x + (float)k * h + 0.5f * seg;
#if UMBRA_PART
            /* Only the segments whose midpoint the part owns; the first after them ends it. */
            if (!part_owns(F, world_to_voxel(g, o + t_mid * d))) {
                if (owned)
                    break;
                ++k;
                continue;
            }
            owned = 1;
#endif
            const float4 col = light_sample(F, vol, g, light_tf, n_tf, o + t_mid * d);
            if (col.w > 0.0f) {
                tau += cssm_depth(col, h_vox * (seg / h), flags);
                if (light_any_gt(tau, e_next)) {
                    const float zk = ls_depth(S, o, t_mid);
                    float en[UMBRA_LIGHT_CHANNELS];
                    for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c) {
                        const float tc = LIGHT_CH(tau, c);
                        int i = next[c];
                        for (; i < np && tc > e[i]; ++i)
                            z[i * UMBRA_LIGHT_CHANNELS + c] = zk;
                        going -= i - next[c];
                        next[c] = i;
                        en[c] = i < np ? e[i] : UMBRA_INF;
                    }
                    if (going == 0)
                        break;
                    e_next = LIGHT_FROM(en);
                }
            }
            ++k;
        }
#if UMBRA_PART
        /* The state at the part's exit, for the part after it: every texel of the block. */
        for (int j = 0; j < bw * bh; ++j) {
            const int si = ((y0 + j / bw) * n + x0 + j % bw) * UMBRA_LIGHT_CHANNELS;
            for (int c = 0; c < UMBRA_LIGHT_CHANNELS; ++c)
                part_state[si + c] = LIGHT_CH(tau, c);
        }
#endif
    }
    for (int i = 0; i < np; ++i)
        CSSM_STORE(LIGHT_FROM(z + i * UMBRA_LIGHT_CHANNELS), (y0 + id[i] / B) * n + x0 + id[i] % B,
                   map);
}

/* Table 2: per channel, the fraction of the taps whose stored depth lies beyond p's. */
UMBRA_INLINE float3 cssm_lookup(__global const UmbraShadow *S, __global const UmbraCssm *P,
                                __global const float *map, float3 p)
{
    const float3 m = ls_world_to_map(S, p);
    int2 base;
    if (!ls_base_texel(S, m.xy, &base))
        return (float3)(1.0f);
    const uint taps = P->taps;
    const float s = m.z; /* no bias: the depths are segment midpoints (see above) */
    const int n = (int)S->map_size;
    light_t lit = (light_t)(0.0f);
    if (ls_taps_inside(n, base)) {
        const int i0 = base.y * n + base.x;
        for (uint j = 0; j < taps; ++j)
            lit += select((light_t)(0.0f), (light_t)(1.0f),
                          CSSM_LOAD(i0 + ls_tap_offset(n, j), map) > (light_t)(s));
        return light_rgb(lit / (float)taps);
    }
    for (uint j = 0; j < taps; ++j) {
        const int i = ls_texel_index(S, base + ls_taps[j]);
        if (i < 0)
            lit += 1.0f;
        else
            lit += select((light_t)(0.0f), (light_t)(1.0f), CSSM_LOAD(i, map) > (light_t)(s));
    }
    return light_rgb(lit / (float)taps);
}

#define SHADOW_FACTOR(sr, p) cssm_lookup(S, P, shadow_map, (p))
