// SPDX-License-Identifier: Apache-2.0
/* kernels/common/channels.cl: what a sample of the volume is, for every technique: the view
 * sample (colour and step-corrected opacity), the light sample (the light transfer function's
 * entry) and the shading gradient at a point. For a plain scalar volume each is the one lookup
 * it always was (tf_lookup of sample_volume; volume_gradient), so those programs compile to the
 * same code; this file adds the two other kinds of volume.h, chosen by build options from the
 * volume (host/frame.c):
 *
 *   UMBRA_CHANNELS = 2..4, a multi-channel volume: channel c's voxels follow channel c - 1's in
 *   the one buffer (each dims voxels and a pad element), each normalised through its own value
 *   map and looked up in its own part of the tables (UmbraChannels). The channels mix as
 *   emission-absorption media do (Max 1995's model is linear in the densities; Cai and Sakas
 *   1999, "Data intermixing and multi-volume rendering", call it illumination-model
 *   intermixing): at a point the extinctions sigma_c = -ln(1 - a_c) add, so the opacity of a
 *   length is 1 - prod (1 - a_c), and the emitted colour is the extinction-weighted mean
 *   sum sigma_c rgb_c / sum sigma_c. The light's transmission colour mixes the same way:
 *   t = sum sigma_c t_c / sum sigma_c makes sigma (1 - t), the extinction per colour channel
 *   that light_absorbed and light_depth take (kernels/common/common.cl), equal to the sum of
 *   the channels' sigma_c (1 - t_c), exactly, so every technique's light pass absorbs the light
 *   by the summed extinction, each channel's through its own transmission colour. Where one
 *   channel alone is visible its entry is taken as it is (no logarithm: the common case of
 *   channels that do not overlap).
 *
 *   UMBRA_LABELS = 1, a label map: the voxel nearest the point (no interpolation) holds a label
 *   l, whose colour and opacity are entry l of the table, transparent at l >= n; the shading
 *   gradient is that of the label opacities interpolated between voxels (the surfaces of the
 *   labelled regions shade as iso-surfaces of their opacity).
 *
 * Both are one buffer (host/volume.c), never images or slabs. It follows common/sampling.cl. */

#ifndef UMBRA_CHANNELS
#define UMBRA_CHANNELS 1
#endif
#ifndef UMBRA_LABELS
#define UMBRA_LABELS 0
#endif
#define UMBRA_MIXED (UMBRA_CHANNELS > 1 || UMBRA_LABELS)
#if UMBRA_MIXED && (UMBRA_SAMPLER_IMAGE || UMBRA_VOLUME_SLABS > 1)
#error "a multi-channel volume or a label map is one buffer (host/volume.c)"
#endif
#if UMBRA_CHANNELS < 1 || UMBRA_CHANNELS > UMBRA_MAX_CHANNELS || (UMBRA_LABELS && UMBRA_CHANNELS != 1)
#error "UMBRA_CHANNELS must lie in [1, UMBRA_MAX_CHANNELS], 1 for a label map"
#endif

#if UMBRA_CHANNELS > 1
/* Channel c's normalised value at p: the one sampler over the channel's part of the buffer,
 * through its value map. */
UMBRA_INLINE float sample_channel(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                  float3 p, int c)
{
    VolGeom gc = g;
    gc.value_lo = F->ch.value_map[c][0];
    gc.value_scale = F->ch.value_map[c][1];
    gc.image_scale = F->ch.value_map[c][2];
    const size_t stride = (size_t)g.dims.x * (size_t)g.dims.y * (size_t)g.dims.z + 1;
    return sample_volume(vol + (size_t)c * stride, gc, p);
}

/* The channels' entries at p in their parts of tf (channel c at at[c], n[c] entries), mixed
 * (see the top of the file): the colour (or transmission colour) weighted by extinction, the
 * opacity 1 - prod (1 - a_c). */
UMBRA_INLINE float4 mix_channels(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                 __global const float4 *tf, __global const uint *at,
                                 __global const uint *n, float3 p)
{
    float4 e[UMBRA_CHANNELS];
    int visible = 0, last = 0;
    float keep = 1.0f;
    for (int c = 0; c < UMBRA_CHANNELS; ++c) {
        e[c] = tf_lookup(tf + at[c], n[c], sample_channel(F, vol, g, p, c));
        if (e[c].w > 0.0f) {
            ++visible;
            last = c;
            keep *= 1.0f - e[c].w;
        }
    }
    if (visible <= 1)
        return e[last];
    float3 rgb = (float3)(0.0f);
    float ext = 0.0f;
    for (int c = 0; c < UMBRA_CHANNELS; ++c)
        if (e[c].w > 0.0f) {
            const float x = tf_extinction(e[c].w);
            rgb += x * e[c].xyz;
            ext += x;
        }
    return (float4)(rgb / ext, 1.0f - keep);
}
#endif

#if UMBRA_LABELS
/* The voxel nearest p, as x, y, z (the border voxels repeat outside the grid). */
UMBRA_INLINE int3 label_voxel(VolGeom g, float3 p)
{
    const float3 x = clamp(world_to_voxel(g, p), (float3)(0.0f), convert_float3(g.dims - 1));
    return min(convert_int3(x + 0.5f), g.dims - 1); /* x >= 0: truncation rounds x */
}

UMBRA_INLINE uint label_of(VOLUME_PARAM, VolGeom g, int3 i)
{
    return (uint)vol[((size_t)i.z * (size_t)g.dims.y + (size_t)i.y) * (size_t)g.dims.x +
                     (size_t)i.x];
}

/* Label l's entry of a table of n entries, transparent past its end. */
UMBRA_INLINE float4 label_entry(__global const float4 *tf, uint n, uint l)
{
    return l < n ? tf[l] : (float4)(0.0f);
}

/* The label opacity (entry alpha of tf, n entries) interpolated trilinearly between the voxels
 * around p. */
UMBRA_INLINE float label_opacity(VOLUME_PARAM, VolGeom g, __global const float4 *tf, uint n,
                                 float3 p)
{
    const float3 x = clamp(world_to_voxel(g, p), (float3)(0.0f), convert_float3(g.dims - 1));
    const int3 i0 = convert_int3(x), i1 = min(i0 + 1, g.dims - 1);
    const float3 f = x - convert_float3(i0);
#define LA(X, Y, Z) label_entry(tf, n, label_of(vol, g, (int3)((X).x, (Y).y, (Z).z))).w
    const float c00 = mix(LA(i0, i0, i0), LA(i1, i0, i0), f.x);
    const float c10 = mix(LA(i0, i1, i0), LA(i1, i1, i0), f.x);
    const float c01 = mix(LA(i0, i0, i1), LA(i1, i0, i1), f.x);
    const float c11 = mix(LA(i0, i1, i1), LA(i1, i1, i1), f.x);
#undef LA
    return mix(mix(c00, c10, f.y), mix(c01, c11, f.y), f.z);
}
#endif

/* The view sample at p: colour and opacity from the view table (n entries; with channels or
 * labels the parts UmbraChannels gives). */
UMBRA_INLINE float4 view_sample(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                __global const float4 *view_tf, uint n, float3 p)
{
#if UMBRA_LABELS
    (void)n;
    return label_entry(view_tf, F->ch.view_n[0], label_of(vol, g, label_voxel(g, p)));
#elif UMBRA_CHANNELS > 1
    (void)n;
    return mix_channels(F, vol, g, view_tf, F->ch.view_at, F->ch.view_n, p);
#else
    (void)F;
    return tf_lookup(view_tf, n, sample_volume(vol, g, p));
#endif
}

/* The light sample at p: the light table's entry (n entries), its colour the transmission
 * colour t and its alpha the opacity per voxel length; a mixture's equivalent entry (see the top
 * of the file). Every technique's light pass takes it. */
UMBRA_INLINE float4 light_sample(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                 __global const float4 *light_tf, uint n, float3 p)
{
#if UMBRA_LABELS
    (void)n;
    return label_entry(light_tf, F->ch.light_n[0], label_of(vol, g, label_voxel(g, p)));
#elif UMBRA_CHANNELS > 1
    (void)n;
    return mix_channels(F, vol, g, light_tf, F->ch.light_at, F->ch.light_n, p);
#else
    (void)F;
    return tf_lookup(light_tf, n, sample_volume(vol, g, p));
#endif
}

/* The shading gradient at p, in value per world unit: volume_gradient of a plain volume; of a
 * label map, the gradient of its interpolated label opacity (central differences one voxel each
 * way); of a multi-channel volume, the channels' value gradients weighted by their extinctions
 * at p (each channel's iso-surfaces shade where it is what is seen). */
UMBRA_INLINE float3 view_gradient(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                  __global const float4 *view_tf, float3 p)
{
#if UMBRA_LABELS
    const uint n = F->ch.view_n[0];
    const float3 s = g.spacing;
    const float gx = label_opacity(vol, g, view_tf, n, p + (float3)(s.x, 0, 0)) -
                     label_opacity(vol, g, view_tf, n, p - (float3)(s.x, 0, 0));
    const float gy = label_opacity(vol, g, view_tf, n, p + (float3)(0, s.y, 0)) -
                     label_opacity(vol, g, view_tf, n, p - (float3)(0, s.y, 0));
    const float gz = label_opacity(vol, g, view_tf, n, p + (float3)(0, 0, s.z)) -
                     label_opacity(vol, g, view_tf, n, p - (float3)(0, 0, s.z));
    return (float3)(gx, gy, gz) * 0.5f * g.inv_spacing;
#elif UMBRA_CHANNELS > 1
    const size_t stride = (size_t)g.dims.x * (size_t)g.dims.y * (size_t)g.dims.z + 1;
    float3 grad = (float3)(0.0f);
    float ext = 0.0f;
    for (int c = 0; c < UMBRA_CHANNELS; ++c) {
        const float a =
            tf_lookup(view_tf + F->ch.view_at[c], F->ch.view_n[c], sample_channel(F, vol, g, p, c)).w;
        if (!(a > 0.0f))
            continue;
        VolGeom gc = g;
        gc.value_lo = F->ch.value_map[c][0];
        gc.value_scale = F->ch.value_map[c][1];
        gc.image_scale = F->ch.value_map[c][2];
        const float x = tf_extinction(a);
        grad += x * volume_gradient(vol + (size_t)c * stride, gc, p);
        ext += x;
    }
    return ext > 0.0f ? grad / ext : grad;
#else
    (void)F;
    (void)view_tf;
    return volume_gradient(vol, g, p);
#endif
}
