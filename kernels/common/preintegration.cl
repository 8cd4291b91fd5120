// SPDX-License-Identifier: Apache-2.0
/* kernels/common/preintegration.cl: pre-integration tables (Engel, Kraus & Ertl 2001) and their
 * lookup,
 * shared by the convolution shadows (kernels/techniques/convolution.cl) and the ray caster's
 * pre-integrated
 * mode (kernels/raycast.cl).
 *
 * An entry (i, j) describes one segment of length L voxels along which the scalar runs linearly
 * from s_f = i / (size - 1) at the front to s_b = j / (size - 1) at the back:
 *   PREINT_VIEW   (C, A): the segment's premultiplied colour and opacity, composited front to back
 *                 (emission-absorption, alpha per voxel as everywhere in umbra);
 *   PREINT_LIGHT  (T, 0): the per-channel transmittance of the shading model through the segment,
 *                 the product of (1 - a)^(len (1 - t_c)) over its sub-steps (t = 0 unless
 *                 colored; kernels/common/common.cl): the light attenuation with pre-integrated
 *                 opacity
 *                 that the convolution paper proposes.
 * The integral is evaluated numerically at the table's own resolution: the value interval between
 * two grid values is one "unit", and a segment spanning d = |j - i| units is d sub-steps of length
 * L / d, each sampled at its unit's midpoint. Since a sub-step depends only on (d, unit), the
 * units are evaluated once per d (preintegration_units: one pow each) and every entry composites
 * its d units in traversal order (preintegration_build: multiply-adds only), which keeps a
 * 256 x 256 table to a few tens of milliseconds on a CPU device. No formula divides by s_b - s_f,
 * so s_f = s_b (d = 0) needs no special case beyond taking one sample at s_f whose alpha is
 * corrected for the whole length: exactly the step-corrected transfer function. A constant
 * stretch of the transfer function gives the exact 1 - (1 - a)^L for any d. It follows
 * common/common.cl
 * (tf_lookup). Rows are indexed by s_b, columns by s_f: table[j * size + i]. */

#define PREINT_VIEW 0u
#define PREINT_LIGHT 1u

/* One sub-step of a segment: view (colour, opacity) or light (transmission per channel, 0). */
inline float4 preint_substep(__global const float4 *tf, uint tf_size, float s, float len,
                             uint kind, uint colored)
{
    float4 c = tf_lookup(tf, tf_size, s);
    if (kind == PREINT_VIEW)
        return (float4)(c.xyz, alpha_for_length(c.w, len));
    /* light_pass of kernels/common/common.cl, with the transmission mode as an argument */
    return (float4)(exp(-(tf_extinction(c.w) * len) * (colored ? 1.0f - c.xyz : (float3)(1.0f))),
                    0.0f);
}

/* units[(d - 1) * (size - 1) + k]: the sub-step over unit k (values k/(size-1) .. (k+1)/(size-1))
 * in a segment of d units; global size (size - 1) x (size - 1). */
__kernel void preintegration_units(__global const float4 *tf, uint tf_size,
                                   __global float4 *units, uint size, float length_voxels,
                                   uint kind, uint colored)
{
    const int k = get_global_id(0), d = get_global_id(1) + 1;
    const int n = (int)size - 1;
    if (k >= n || d > n)
        return;
    float s = ((float)k + 0.5f) / (float)n;
    units[(d - 1) * n + k] =
        preint_substep(tf, tf_size, s, length_voxels / (float)d, kind, colored);
}

__kernel void preintegration_build(__global const float4 *tf, uint tf_size,
                                   __global const float4 *units, __global float4 *table,
                                   uint size, float length_voxels, uint kind, uint colored)
{
    const int i = get_global_id(0), j = get_global_id(1);
    const int n = (int)size - 1;
    if (i > n || j > n)
        return;
    const int d = abs(j - i);
    float4 out;
    if (d == 0) {
        out = preint_substep(tf, tf_size, (float)i / (float)n, length_voxels, kind, colored);
        if (kind == PREINT_VIEW)
            out.xyz *= out.w;
    } else {
        /* Front to back: units i, i+1, ..., j-1 upwards; i-1, i-2, ..., j downwards. */
        const int dir = j > i ? 1 : -1;
        __global const float4 *u = units + (d - 1) * n;
        float3 color = (float3)(0.0f), trans = (float3)(1.0f);
        float alpha = 0.0f;
        for (int m = 0, k = j > i ? i : i - 1; m < d; ++m, k += dir) {
            float4 e = u[k];
            color += (1.0f - alpha) * e.w * e.xyz;
            alpha += (1.0f - alpha) * e.w;
            trans *= e.xyz;
        }
        out = kind == PREINT_VIEW ? (float4)(color, alpha) : (float4)(trans, 0.0f);
    }
    table[j * (int)size + i] = out;
}

/* Bilinear lookup of the segment (s_f, s_b); values are clamped to [0,1]. */
inline float4 preint_lookup(__global const float4 *table, uint size, float sf, float sb)
{
    float x = clamp(sf, 0.0f, 1.0f) * (float)(size - 1);
    float y = clamp(sb, 0.0f, 1.0f) * (float)(size - 1);
    int i = min((int)x, (int)size - 2), j = min((int)y, (int)size - 2);
    float fx = x - (float)i, fy = y - (float)j;
    int r0 = j * (int)size + i, r1 = r0 + (int)size;
    return mix(mix(table[r0], table[r0 + 1], fx), mix(table[r1], table[r1 + 1], fx), fy);
}

/* A view entry for a segment r times as long as the table's: opacity 1 - (1 - A)^r, colour scaled
 * with the opacity so the segment keeps its mean colour (exact for a constant segment). */
inline float4 preint_view_for_fraction(float4 e, float r)
{
    if (r == 1.0f)
        return e;
    float a = alpha_for_length(e.w, r);
    return (float4)(e.xyz * (e.w > 0.0f ? a / e.w : r), a);
}

/* The non-premultiplied colour of a view entry (what the shading model multiplies by the light). */
inline float3 preint_color(float4 e) { return e.w > 0.0f ? e.xyz / e.w : (float3)(0.0f); }
