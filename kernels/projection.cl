// SPDX-License-Identifier: Apache-2.0
/* kernels/projection.cl: the projection render modes (umbra_render_mode in
 * include/umbra/renderer.h): maximum, minimum and average intensity projection. Each pixel's view
 * ray takes the samples the ray caster's would (kernels/raycast.cl: the same camera ray, the box
 * and the clip region, the same jittered grid of steps) and reduces the normalised value to its
 * largest, its smallest or its mean, without empty-space skipping (a projection reads every
 * sample) or early termination; the pixel is the uncorrected view table's entry at that value,
 * premultiplied, over the background. A multi-channel volume projects each channel through its
 * own part of the table and adds the premultiplied colours (alpha 1 - prod (1 - a_c)). No light:
 * the host refuses a shadow technique (host/channels.c). Follows common/channels.cl. host/
 * projection.c builds and launches it; tests/test_projection.c checks it against a brute-force
 * projection in plain C. */

#define UMBRA_PROJECT_MIP 1u     /* UMBRA_RENDER_MIP */
#define UMBRA_PROJECT_MINIP 2u   /* UMBRA_RENDER_MINIP */
#define UMBRA_PROJECT_AVERAGE 3u /* UMBRA_RENDER_AVERAGE */

/* tf: each channel's table, uncorrected, channel c's entries [at[c], at[c] + n[c]). */
__kernel void projection_render(__global const UmbraFrame *F, VOLUME_PARAM,
                                __global const float4 *view_tf, __global const float4 *light_tf,
                                __global const uchar *view_bricks,
                                __global const ulong *light_cells, __global const UmbraShadow *S,
                                __global float4 *out, __global UMBRA_COUNT_T *samples,
                                __global const float4 *tf, uint4 at, uint4 n, uint mode)
{
    const int px = get_global_id(0), py = get_global_id(1);
    if (px >= (int)F->width || py >= (int)F->height)
        return;
    (void)view_tf;
    (void)light_tf;
    (void)view_bricks;
    (void)light_cells;
    const VolGeom g = vol_geom(F);
    float3 o, d;
    camera_ray(F, px, py, &o, &d);
    const float2 tb = ray_box(o, d, g.box_min, g.box_max);
    const float t0 = fmax(tb.x, 0.0f);
    const float2 tc = clip_interval(&S->clip, o, d, tb);
    const float h = F->step;
    const float jitter = (F->flags & UMBRA_FLAG_JITTER) ? umbra_random(F->seed, px, py, 0u) : 0.0f;
    int k0 = 0, k1 = 0;
    if (tc.y > t0) {
        k0 = clip_first_sample(t0, h, jitter, tc.x);
        k1 = (int)ceil((tc.y - t0) / h - jitter);
    }
    float m[UMBRA_CHANNELS];
    for (int c = 0; c < UMBRA_CHANNELS; ++c)
        m[c] = mode == UMBRA_PROJECT_MINIP ? 1.0f : 0.0f;
    for (int k = k0; k < k1; ++k) {
        const float3 p = o + (t0 + ((float)k + jitter) * h) * d;
        for (int c = 0; c < UMBRA_CHANNELS; ++c) {
#if UMBRA_CHANNELS > 1
            const float v = sample_channel(F, vol, g, p, c);
#else
            const float v = sample_volume(vol, g, p);
#endif
            m[c] = mode == UMBRA_PROJECT_MIP     ? fmax(m[c], v)
                   : mode == UMBRA_PROJECT_MINIP ? fmin(m[c], v)
                                                 : m[c] + v;
        }
    }
    const int taken = k1 > k0 ? k1 - k0 : 0;
    const float4 bg = vload4(0, F->background);
    if (!taken) {
        out[py * (int)F->width + px] = bg;
        return;
    }
    float3 rgb = (float3)(0.0f);
    float keep = 1.0f;
    for (int c = 0; c < UMBRA_CHANNELS; ++c) {
        const float v = mode == UMBRA_PROJECT_AVERAGE ? m[c] / (float)taken : m[c];
        const uint at_c = c == 0 ? at.x : c == 1 ? at.y : c == 2 ? at.z : at.w;
        const uint n_c = c == 0 ? n.x : c == 1 ? n.y : c == 2 ? n.z : n.w;
        const float4 e = tf_lookup(tf + at_c, n_c, v);
        rgb += e.xyz * e.w;
        keep *= 1.0f - e.w;
    }
    out[py * (int)F->width + px] = (float4)(rgb, 1.0f - keep) + keep * bg;
    UMBRA_COUNT_ADD(samples, taken);
}
