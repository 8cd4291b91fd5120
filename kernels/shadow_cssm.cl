// SPDX-License-Identifier: Apache-2.0
/* kernels/shadow_cssm.cl: colored stochastic shadow maps for direct volume rendering (Weidner &
 * Linsen, after McGuire & Enderton's CSSM for surfaces).
 *
 * Generation, the paper's Table 1 (cssm_build): one photon per texel, on the light ray through
 * the texel centre, discretised into segments i. Per segment one random number r_i, shared by the
 * channels, and per channel the probability that the photon is not transmitted. The paper has
 * rho_i = alpha_i (1 - t_i) (t the light transfer function's RGB in coloured mode, 0 in grey
 * mode); umbra takes rho_i = 1 - (1 - alpha_i)^(1 - t_i), 1 - light_pass of the shading model's
 * extinction (kernels/common.cl), of which the paper's is the first-order form: the two agree in
 * grey mode and for thin segments, and only umbra's is independent of the step in a homogeneous
 * medium. Where rho_i > r_i the channel's depth is set
 * to min(c, z_i) (z grows along the ray, so that is the first such segment); the march stops once
 * every channel is set. Unset channels keep LS_DEPTH_NEVER. With UMBRA_LIGHT_CHANNELS == 1 (a grey
 * light) one channel is simulated and stored, not three.
 *
 * Segments: whole steps of S->step plus one partial step, sampled at their midpoints, each with
 * the optical depth of its length, so the product of the (1 - rho_i) along a whole ray is the
 * midpoint-rule transmittance. z_i is the depth of segment
 * i's midpoint, its sample point: a sample at depth s is then shadowed by exactly the segments
 * whose sample lies in front of it, so P(lit) = prod over those of (1 - rho_i), within half a step
 * of the continuous exp(-sigma d) on either side, and no bias is needed (the paper has none).
 *
 * r_i = umbra_random(seed, x, y, i) with i the segment's index along the ray: counter-based, so
 * the map depends on the seed alone (same seed, same map and image, bit for bit), and skipped
 * empty segments (rho = 0, never > r) change nothing.
 *
 * Lookup, the paper's Table 2: the m taps around the sample's texel (ls_taps); channel c is lit by
 * each tap whose stored depth lies beyond the sample's (c_lambda > s_z); the factor is j/m. */

#define SHADOW_KERNEL_PARAMS , __global const float *shadow_map

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

#if UMBRA_LIGHT_CHANNELS == 1
#define CSSM_STORE(v, i, map) ((map)[i] = (v))
#define CSSM_LOAD(i, map) ((map)[i])
#define CSSM_ALL_SET(c) ((c) < LS_DEPTH_NEVER)
#define CSSM_HIT(rho, r) ((rho) > (r))
#else
#define CSSM_STORE(v, i, map) vstore3((v), (i), (map))
#define CSSM_LOAD(i, map) vload3((i), (map))
#define CSSM_ALL_SET(c) all((c) < (float3)(LS_DEPTH_NEVER))
#define CSSM_HIT(rho, r) ((rho) > (float3)(r))
#endif

__kernel void cssm_build(__global const UmbraFrame *F, VOLUME_PARAM,
                         __global const float4 *view_tf, __global const float4 *light_tf,
                         __global const uchar *view_bricks, __global const ulong *light_cells,
                         __global const UmbraShadow *S, __global float *map)
{
    const int x = get_global_id(0), y = get_global_id(1);
    const int n = (int)S->map_size;
    if (x >= n || y >= n)
        return;
    (void)view_tf;
    (void)view_bricks;
    const VolGeom g = vol_geom(F);
    float3 o, d;
    const float2 tb = ls_texel_ray(S, g, (float2)((float)x + 0.5f, (float)y + 0.5f), &o, &d);
    light_t c = (light_t)(LS_DEPTH_NEVER);
    if (tb.y > tb.x) {
        const float h = S->step, h_vox = light_step_voxels(F, S);
        const uint n_tf = F->light_tf_size, flags = F->flags, seed = S->seed;
        const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
        const float len = tb.y - tb.x;
        const int n_full = (int)floor(len / h);
        const float last = len - (float)n_full * h;
        CellWalk w = walk_begin(g, o, d, tb.x);
        float t_cell = -UMBRA_INF;
        /* Segment k covers [tb.x + k h, tb.x + k h + seg]; k == n_full is the partial one. Whole
         * segments whose midpoint lies in an invisible cell are skipped (walk_next_sample). */
        for (int k = 0; k <= n_full;) {
            if (skip && k < n_full && tb.x + ((float)k + 0.5f) * h >= t_cell)
                k = walk_next_sample(&w, g, light_cells, tb.x, h, 0.5f, k, n_full, tb.y, &t_cell);
            const float seg = k < n_full ? h : last;
            if (!(seg > 0.0f))
                break;
            const float t_mid = tb.x + (float)k * h + 0.5f * seg;
            const float3 q = o + t_mid * d;
            const float4 col = tf_lookup(light_tf, n_tf, sample_volume(vol, g, q));
            /* A transparent sample (alpha 0, common in visible cells) stops no photon: rho = 0
             * is never > r, so its logarithms and random number are skipped. */
            const float r = col.w > 0.0f ? umbra_random(seed, (uint)x, (uint)y, (uint)k) : 1.0f;
            /* Most segments of a translucent medium stop no photon, and that is decided without
             * a logarithm: od = -ln(1 - a) len m (m the largest absorbed fraction) is at most
             * a / (1 - a) len m, and -ln(1 - r) at least r, so a bound below r (by a margin of
             * 1e-4 relative, far beyond the float rounding of either side) means od < -ln(1 - r)
             * in every channel: the same miss the exact test below finds. */
            const float a_max = fmin(col.w, UMBRA_ALPHA_MAX);
            const float len_vox = h_vox * (seg / h);
            if (col.w > 0.0f &&
                !(a_max / (1.0f - a_max) * len_vox * light_max(light_absorbed(col, flags)) *
                      1.0001f < r)) {
                const light_t od = light_depth(col, len_vox, flags);
                /* rho > r, i.e. 1 - exp(-od) > r, compared as od > -ln(1 - r): one logarithm
                 * per segment instead of an exponential per channel (the two sides differ only
                 * where rounding puts r within an ulp of rho, a measure-zero change). */
                const float r_od = -log1p(-r);
                c = select(c, fmin(c, (light_t)(ls_depth(S, o, t_mid))), CSSM_HIT(od, r_od));
                if (CSSM_ALL_SET(c))
                    break;
            }
            ++k;
        }
    }
    CSSM_STORE(c, y * n + x, map);
}

/* Table 2: per channel, the fraction of the taps whose stored depth lies beyond p's. */
UMBRA_INLINE float3 cssm_lookup(__global const UmbraShadow *S, __global const float *map, float3 p)
{
    const float3 m = ls_world_to_map(S, p);
    int2 base;
    if (!ls_base_texel(S, m.xy, &base))
        return (float3)(1.0f);
    const uint taps = S->taps;
    const float s = m.z - S->depth_bias;
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

#define SHADOW_FACTOR(sr, p) cssm_lookup(S, shadow_map, (p))
