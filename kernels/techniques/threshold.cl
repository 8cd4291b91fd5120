// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/threshold.cl: the opacity-threshold shadow map ("traditional shadow mapping,
 * where a thresholding at opacity 0.5 is applied", as the CSSM paper compares against).
 *
 * threshold_build marches each texel's light ray (through the texel centre) and stores the
 * normalised depth where the accumulated opacity first exceeds P->threshold, or LS_DEPTH_NEVER.
 * Only the light transfer function's opacity counts: the map holds one depth, so it cannot carry
 * colour and ignores the transmission colour. The lookup tests a sample against that depth:
 * shadowed (0) beyond it, lit (1) before; with P->taps > 1 it averages the tests at the CSSM tap
 * offsets (PCF), so that its softness compares fairly with CSSM's.
 *
 * The march: whole steps of S->step plus one partial step, each sampled at its midpoint, its
 * opacity that of the extinction of kernels/common/common.cl over the segment's length, empty cells
 * skipped. Within the
 * segment where the threshold is crossed the medium is taken as homogeneous and the crossing
 * solved for exactly, 1 - (1 - A)(1 - a)^(x / L) = threshold, so a homogeneous slab gives the
 * analytic depth -ln(1 - threshold) / sigma rather than one rounded to a step. The march keeps
 * the transmittance 1 - A of the whole segments as a product, not A (the same test and crossing
 * up to rounding, without a logarithm or an exponential per segment: see the kernel). */

#define SHADOW_KERNEL_PARAMS , __global const UmbraThreshold *P, __global const float *shadow_map

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

__kernel void threshold_build(__global const UmbraFrame *F, VOLUME_PARAM,
                              __global const float4 *view_tf, __global const float4 *light_tf,
                              __global const uchar *view_bricks,
                              __global const ulong *light_cells, __global const UmbraShadow *S,
                              __global const UmbraThreshold *P, __global float *map
#if UMBRA_PART
                              , __global float *part_state
#endif
                              )
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
    float depth = LS_DEPTH_NEVER;
    if (tb.y > tb.x) {
        const float h = S->step, thr = P->threshold, h_vox = light_step_voxels(F, S);
        const uint n_tf = F->light_tf_size;
        const int skip = (F->flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
        const float len = tb.y - tb.x;
        const int n_full = (int)floor(len / h);
        const float last = len - (float)n_full * h;
        /* The accumulated opacity 1 - exp(-tau) passes the threshold where the optical depth
         * tau passes -ln(1 - threshold). A whole segment's depth is h_vox (-ln(1 - a)), so
         * over whole segments tau = -h_vox ln P with P the product of their 1 - a: the march
         * keeps P, a multiplication per segment (no logarithm, no exponential), and tests
         * P (1 - a) < p_thr = exp(-tau_thr / h_vox). tau itself is taken only at the crossing
         * and at the partial last segment. The product and the sum of logarithms differ by
         * rounding (about 3e-8 of depth per segment); where the threshold needs p_thr below
         * 1e-30 (a tiny step and a threshold near 1) the float product would underflow, and
         * the march sums the logarithms instead. */
        const float tau_thr = -log1p(-thr), p_thr = exp(-tau_thr / h_vox);
        const int product = p_thr > 1e-30f;
        float tau = 0.0f, P = 1.0f;
#if UMBRA_PART
        /* A part goes on with the march state the parts before it on this ray left
         * (host/part_render.c): the same product and sum as one device's march, bit for bit. */
        P = part_state[2 * (y * n + x)];
        tau = part_state[2 * (y * n + x) + 1];
        int owned = 0;
#endif
        CellWalk w = walk_begin(g, o, d, tb.x);
        float t_cell = -UMBRA_INF;
        /* Segment k covers [tb.x + k h, tb.x + (k + 1) h]; k == n_full is the partial one. Whole
         * segments whose midpoint lies in an invisible cell are skipped (walk_next_sample). */
        for (int k = 0; k <= n_full;) {
            if (skip && k < n_full && tb.x + ((float)k + 0.5f) * h >= t_cell)
                k = walk_next_sample(&w, g, light_cells, tb.x, h, 0.5f, k, n_full, tb.y, &t_cell);
            const float seg = k < n_full ? h : last;
            if (!(seg > 0.0f))
                break;
            const float t_start = tb.x + (float)k * h;
            const float t_mid = t_start + 0.5f * seg;
            const float3 q = o + t_mid * d;
#if UMBRA_PART
            /* Only the segments whose midpoint the part owns; the first after them ends it. */
            if (!part_owns(F, world_to_voxel(g, q))) {
                if (owned)
                    break;
                ++k;
                continue;
            }
            owned = 1;
#endif
            const float4 c = light_sample(F, vol, g, light_tf, n_tf, q);
            if (c.w > 0.0f) {
                if (product) {
                    const float p = P * (1.0f - fmin(c.w, UMBRA_ALPHA_MAX));
                    if (k < n_full && !(p < p_thr)) {
                        P = p;
                        ++k;
                        continue;
                    }
                    tau = -h_vox * log(P);
                }
                /* The segment's optical depth (kernels/common/common.cl: extinction of the
                 * interpolated
                 * alpha over seg / h steps of h_vox voxels). */
                const float od = tf_extinction(c.w) * h_vox * (seg / h);
                if (tau + od > tau_thr) {
                    const float frac = (tau_thr - tau) / od;
                    depth = ls_depth(S, o, t_start + clamp(frac, 0.0f, 1.0f) * seg);
                    break;
                }
                tau += od;
                if (product) /* rounding put the two tests apart: go on from tau */
                    P = exp(-tau / h_vox);
            }
            ++k;
        }
#if UMBRA_PART
        part_state[2 * (y * n + x)] = P;
        part_state[2 * (y * n + x) + 1] = tau;
#endif
    }
    map[y * n + x] = depth;
}

/* Fraction of the taps around p's texel whose stored depth p does not lie beyond. */
UMBRA_INLINE float threshold_lookup(__global const UmbraShadow *S,
                                    __global const UmbraThreshold *P, __global const float *map,
                                    float3 p)
{
    const float3 m = ls_world_to_map(S, p);
    int2 base;
    if (!ls_base_texel(S, m.xy, &base))
        return 1.0f;
    const uint taps = P->taps;
    const float s = m.z - P->depth_bias;
    const int n = (int)S->map_size;
    float lit = 0.0f;
    if (ls_taps_inside(n, base)) {
        __global const float *c = map + (base.y * n + base.x);
        for (uint j = 0; j < taps; ++j)
            lit += !(s > c[ls_tap_offset(n, j)]) ? 1.0f : 0.0f;
        return lit / (float)taps;
    }
    for (uint j = 0; j < taps; ++j) {
        const int i = ls_texel_index(S, base + ls_taps[j]);
        lit += (i < 0 || !(s > map[i])) ? 1.0f : 0.0f;
    }
    return lit / (float)taps;
}

#define SHADOW_FACTOR(sr, p) ((float3)(threshold_lookup(S, P, shadow_map, (p))))
