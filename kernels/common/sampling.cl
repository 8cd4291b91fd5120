// SPDX-License-Identifier: Apache-2.0
/* kernels/common/sampling.cl: the one volume-sampling function, with two back ends chosen per
 * device at
 * build time (UMBRA_SAMPLER_IMAGE): a buffer with hand-written trilinear interpolation (fastest on
 * PoCL's CPU device) or a 3D image with the sampler's linear filtering (texture hardware on GPUs).
 * Both clamp to the border voxels and put voxel centres at integer voxel coordinates, so they
 * agree to the filtering hardware's precision.
 *
 * Voxels stay in the volume's own type on the device (UMBRA_VOXEL_T: uchar, ushort, short or
 * float, a build option from the volume), 1, 2 or 4 bytes each, and are normalised to [0,1]
 * through the value range when read: n = clamp((s * image_scale - lo) * scale, 0, 1)
 * (voxel_normalise, constants in VolGeom from UmbraFrame.value_map). The mapping is linear
 * until it clamps, so where no voxel lies outside the value range (UMBRA_VOXEL_CLAMPS 0, a build
 * option from the volume) the sampler blends the stored values and maps the result once, which
 * keeps the buffer path as fast as the float volume was (per-corner mapping cost much of a
 * frame); where a given range clamps voxels, the buffer path maps each of the eight corners
 * before blending, so values outside the range clamp before they blend, as the float volume
 * did. The image path's filter always blends first: the host stores a normalised float image
 * instead wherever that would differ (host/volume.c).
 *
 * A volume larger than one device allocation (or, for images, deeper than the device's largest
 * 3D image) lives in UMBRA_VOLUME_SLABS z-slabs (host/volume_slabs.c): slab s holds the voxel
 * layers [s * UMBRA_SLAB_STEP, (s + 1) * UMBRA_SLAB_STEP], the last one clipped to the grid, so
 * neighbouring slabs share one layer (the apron). A trilinear sample reads the layers floor(z) and
 * floor(z) + 1, which always lie in the slab floor(z) / UMBRA_SLAB_STEP; the gradient is built
 * from such samples, so neither ever straddles two slabs and a split volume samples exactly as an
 * unsplit one. OpenCL C 1.2 has no arrays of buffers or images: the slabs are separate kernel
 * parameters (VOLUME_PARAM), and the macro `vol` names all of them, so every kernel passes its
 * volume on as `vol` however many slabs there are. One slab (the default) compiles to exactly
 * the single-buffer code. */

#ifndef UMBRA_SAMPLER_IMAGE
#define UMBRA_SAMPLER_IMAGE 0
#endif
#ifndef UMBRA_VOXEL_T
#define UMBRA_VOXEL_T float
#endif
#ifndef UMBRA_VOXEL_KIND
#define UMBRA_VOXEL_KIND -1 /* umbra_scalar_type of UMBRA_VOXEL_T; -1: not given, generic loads */
#endif
#ifndef UMBRA_VOXEL_CLAMPS
#define UMBRA_VOXEL_CLAMPS 1
#endif
#ifndef UMBRA_VOLUME_SLABS
#define UMBRA_VOLUME_SLABS 1
#endif
#if UMBRA_VOLUME_SLABS < 1 || UMBRA_VOLUME_SLABS > 8
#error "UMBRA_VOLUME_SLABS must lie in [1, 8] (UMBRA__MAX_SLABS in host/internal.h)"
#endif
#if UMBRA_VOLUME_SLABS > 1 && !defined(UMBRA_SLAB_STEP)
#error "a volume in several slabs needs UMBRA_SLAB_STEP (voxel layers from one slab to the next)"
#endif

/* A stored value (a raw voxel, or a UNORM image's value in [0,1]) mapped to [0,1]. */
UMBRA_INLINE float voxel_normalise(VolGeom g, float s)
{
    return clamp((s * g.image_scale - g.value_lo) * g.value_scale, 0.0f, 1.0f);
}

#if UMBRA_SAMPLER_IMAGE
#define UMBRA_SLAB_PARAM(i) __read_only image3d_t vol_##i
#else
#define UMBRA_SLAB_PARAM(i) __global const UMBRA_VOXEL_T *restrict vol_##i
#endif
#define UMBRA_SLAB_NAME(i) vol_##i
#define UMBRA_SLABS_1(M) M(0)
#define UMBRA_SLABS_2(M) UMBRA_SLABS_1(M), M(1)
#define UMBRA_SLABS_3(M) UMBRA_SLABS_2(M), M(2)
#define UMBRA_SLABS_4(M) UMBRA_SLABS_3(M), M(3)
#define UMBRA_SLABS_5(M) UMBRA_SLABS_4(M), M(4)
#define UMBRA_SLABS_6(M) UMBRA_SLABS_5(M), M(5)
#define UMBRA_SLABS_7(M) UMBRA_SLABS_6(M), M(6)
#define UMBRA_SLABS_8(M) UMBRA_SLABS_7(M), M(7)
#define UMBRA_SLABS_(n, M) UMBRA_SLABS_##n(M)
#define UMBRA_SLABS(n, M) UMBRA_SLABS_(n, M)

#if UMBRA_VOLUME_SLABS == 1
#if UMBRA_SAMPLER_IMAGE
#define VOLUME_PARAM __read_only image3d_t vol
#else
#define VOLUME_PARAM __global const UMBRA_VOXEL_T *restrict vol
#endif
#else
#define VOLUME_PARAM UMBRA_SLABS(UMBRA_VOLUME_SLABS, UMBRA_SLAB_PARAM)
#define vol UMBRA_SLABS(UMBRA_VOLUME_SLABS, UMBRA_SLAB_NAME)
#endif

#if UMBRA_SAMPLER_IMAGE
#if UMBRA_VOLUME_SLABS == 1
__constant sampler_t umbra_linear =
    CLK_NORMALIZED_COORDS_TRUE | CLK_ADDRESS_CLAMP_TO_EDGE | CLK_FILTER_LINEAR;

/* The filtered stored value at voxel coordinates x (world_to_voxel), before voxel_normalise. */
inline float sample_stored(VOLUME_PARAM, VolGeom g, float3 x)
{
    float3 u = (x + 0.5f) / convert_float3(g.dims);
    return read_imagef(vol, umbra_linear, (float4)(u, 0.0f)).x;
}

inline float sample_volume(VOLUME_PARAM, VolGeom g, float3 p)
{
    float3 u = (p - g.box_min) / (g.box_max - g.box_min);
    return voxel_normalise(g, read_imagef(vol, umbra_linear, (float4)(u, 0.0f)).x);
}
#else
/* Unnormalised coordinates: voxel i's centre is at i + 0.5 in its slab's image. */
__constant sampler_t umbra_linear =
    CLK_NORMALIZED_COORDS_FALSE | CLK_ADDRESS_CLAMP_TO_EDGE | CLK_FILTER_LINEAR;

/* Images cannot be held in variables or chosen with ?: in OpenCL C 1.2: one read per case. */
#define UMBRA_SLAB_READ(i)                                                                     \
    case i:                                                                                    \
        return read_imagef(vol_##i, umbra_linear, c).x;

/* The filtered stored value at voxel coordinates x (world_to_voxel), before voxel_normalise. */
inline float sample_stored(VOLUME_PARAM, VolGeom g, float3 x)
{
    x = clamp(x, (float3)(0.0f), convert_float3(g.dims - 1));
    int s = min((int)x.z / UMBRA_SLAB_STEP, UMBRA_VOLUME_SLABS - 1);
    float4 c = (float4)(x.x + 0.5f, x.y + 0.5f, x.z - (float)(s * UMBRA_SLAB_STEP) + 0.5f, 0.0f);
    switch (s) {
        UMBRA_SLAB_READ(0)
        UMBRA_SLAB_READ(1)
#if UMBRA_VOLUME_SLABS > 2
        UMBRA_SLAB_READ(2)
#endif
#if UMBRA_VOLUME_SLABS > 3
        UMBRA_SLAB_READ(3)
#endif
#if UMBRA_VOLUME_SLABS > 4
        UMBRA_SLAB_READ(4)
#endif
#if UMBRA_VOLUME_SLABS > 5
        UMBRA_SLAB_READ(5)
#endif
#if UMBRA_VOLUME_SLABS > 6
        UMBRA_SLAB_READ(6)
#endif
#if UMBRA_VOLUME_SLABS > 7
        UMBRA_SLAB_READ(7)
#endif
    }
    return 0.0f;
}

inline float sample_volume(VOLUME_PARAM, VolGeom g, float3 p)
{
    return voxel_normalise(g, sample_stored(vol, g, world_to_voxel(g, p)));
}
#endif
#else
/* Voxel i (x fastest) of one buffer (the volume or a slab), ready to blend: normalised where
 * the range clamps, else as stored (voxel_blended maps the blend). The one place the buffer is
 * read. */
UMBRA_INLINE float voxel_load(__global const UMBRA_VOXEL_T *restrict v, VolGeom g, size_t i)
{
#if UMBRA_VOXEL_CLAMPS
    return voxel_normalise(g, convert_float(v[i]));
#else
    return convert_float(v[i]);
#endif
}

/* Voxels i and i + 1 (every buffer has a pad element after its last voxel, host/
 * volume_slabs.c). */
UMBRA_INLINE float2 voxel_load2(__global const UMBRA_VOXEL_T *restrict v, VolGeom g, size_t i)
{
#if UMBRA_VOXEL_CLAMPS
    float2 s = convert_float2(vload2(0, v + i));
    return (float2)(voxel_normalise(g, s.x), voxel_normalise(g, s.y));
#else
    return convert_float2(vload2(0, v + i));
#endif
}

/* The eight corners of a trilinear cell as voxel_load values: the voxel pairs (i, i + 1) at
 * b, b + oy, b + oz and b + oz + oy, their first voxels in lo and their second in hi. An integer
 * voxel type (UMBRA_VOXEL_KIND 0-2: uchar, ushort, short) loads each pair as one word and
 * splits the four words with vector shifts: PoCL's code for four separate pairs extracted and
 * converted every voxel on its own, a quarter of the instructions of a sample
 * (docs/performance.md). The same values either way: the conversions are exact. A word holds
 * its first voxel in its low bits on a little-endian device only; others load the pairs. */
UMBRA_INLINE void voxel_load_corners(__global const UMBRA_VOXEL_T *restrict v, VolGeom g, size_t b,
                                     size_t oy, size_t oz, float4 *lo, float4 *hi)
{
#if (UMBRA_VOXEL_KIND == 0 || UMBRA_VOXEL_KIND == 1 || UMBRA_VOXEL_KIND == 2) &&                 \
    defined(__ENDIAN_LITTLE__)
#if UMBRA_VOXEL_KIND == 0
#define UMBRA_PAIR(i) (uint)as_ushort(vload2(0, v + (i)))
#else
#define UMBRA_PAIR(i) as_uint(vload2(0, v + (i)))
#endif
    const uint4 w = (uint4)(UMBRA_PAIR(b), UMBRA_PAIR(b + oy), UMBRA_PAIR(b + oz),
                            UMBRA_PAIR(b + oz + oy));
#undef UMBRA_PAIR
#if UMBRA_VOXEL_KIND == 0
    *lo = convert_float4(w & 0xffu);
    *hi = convert_float4(w >> 8);
#elif UMBRA_VOXEL_KIND == 1
    *lo = convert_float4(w & 0xffffu);
    *hi = convert_float4(w >> 16);
#else
    *lo = convert_float4(as_int4(w << 16) >> 16);
    *hi = convert_float4(as_int4(w) >> 16);
#endif
#if UMBRA_VOXEL_CLAMPS
    *lo = clamp((*lo * g.image_scale - g.value_lo) * g.value_scale, 0.0f, 1.0f);
    *hi = clamp((*hi * g.image_scale - g.value_lo) * g.value_scale, 0.0f, 1.0f);
#endif
#else
    const float2 c0 = voxel_load2(v, g, b), c1 = voxel_load2(v, g, b + oy);
    const float2 c2 = voxel_load2(v, g, b + oz), c3 = voxel_load2(v, g, b + oz + oy);
    *lo = (float4)(c0.x, c1.x, c2.x, c3.x);
    *hi = (float4)(c0.y, c1.y, c2.y, c3.y);
#endif
}

/* A blend of voxel_load values, normalised. */
UMBRA_INLINE float voxel_blended(VolGeom g, float b)
{
#if UMBRA_VOXEL_CLAMPS
    return b;
#else
    return voxel_normalise(g, b);
#endif
}

/* A part of a global grid (UMBRA_PART, umbra/part.h): positions and clamping are those of the
 * global grid (g.dims), and the carried voxels are addressed from global indices less
 * g.part_shift, clamped to what the part carries (g.part_dims). A whole volume: the identity. */
#if UMBRA_PART
#define PART_INDEX(i) clamp((i) - g.part_shift, (int3)(0), g.part_dims - 1)
#define PART_DIMS g.part_dims
#else
#define PART_INDEX(i) (i)
#define PART_DIMS g.dims
#endif

#if UMBRA_VOLUME_SLABS > 1
/* The buffer of slab s. */
UMBRA_INLINE __global const UMBRA_VOXEL_T *volume_slab(VOLUME_PARAM, int s)
{
    __global const UMBRA_VOXEL_T *v = vol_0;
    v = s == 1 ? vol_1 : v;
#if UMBRA_VOLUME_SLABS > 2
    v = s == 2 ? vol_2 : v;
#endif
#if UMBRA_VOLUME_SLABS > 3
    v = s == 3 ? vol_3 : v;
#endif
#if UMBRA_VOLUME_SLABS > 4
    v = s == 4 ? vol_4 : v;
#endif
#if UMBRA_VOLUME_SLABS > 5
    v = s == 5 ? vol_5 : v;
#endif
#if UMBRA_VOLUME_SLABS > 6
    v = s == 6 ? vol_6 : v;
#endif
#if UMBRA_VOLUME_SLABS > 7
    v = s == 7 ? vol_7 : v;
#endif
    return v;
}
#endif

/* The trilinear blend at voxel coordinates x (world_to_voxel) of voxel_load values: normalised
 * where the range clamps voxels, else stored values (voxel_blended maps them). */
UMBRA_INLINE float sample_stored(VOLUME_PARAM, VolGeom g, float3 x)
{
    /* clamp(x, 0, dims - 1) as two compares and selects: clamp's NaN rules cost PoCL four
     * instructions more, and a NaN comes out 0 either way. */
    const float3 top = convert_float3(g.dims - 1);
    x = select((float3)(0.0f), x, x > 0.0f);
    x = select(top, x, x < top);
    /* x >= 0, so truncation is floor, exactly: PoCL's floor() is a dozen instructions (it handles
     * negative and huge values), a conversion one. Converted as four lanes: PoCL split a float3's
     * conversions into a scalar one and a vector one and shuffled them together. */
    const float4 x4 = (float4)(x, 0.0f);
    const int4 j0 = convert_int4(x4);
    const float3 f = (x4 - convert_float4(j0)).xyz;
    int3 i0 = j0.xyz;
    int3 i1 = min(i0 + 1, g.dims - 1);
#if UMBRA_PART
    i0 = PART_INDEX(i0);
    i1 = PART_INDEX(i1);
#endif
#if UMBRA_VOLUME_SLABS == 1
    __global const UMBRA_VOXEL_T *restrict v = vol;
#else
    /* The slab holding layers i0.z and i1.z (see the top of the file), and the layers in it. */
    const int s = min(i0.z / UMBRA_SLAB_STEP, UMBRA_VOLUME_SLABS - 1);
    __global const UMBRA_VOXEL_T *v = volume_slab(vol, s);
    i0.z -= s * UMBRA_SLAB_STEP;
    i1.z -= s * UMBRA_SLAB_STEP;
#endif
    /* The first corner's index and the steps to the others (0 where the cell repeats the
     * border voxel): one index product instead of four. */
    const size_t sy = (size_t)PART_DIMS.x, sz = (size_t)PART_DIMS.x * (size_t)PART_DIMS.y;
    const size_t b = (size_t)i0.z * sz + (size_t)i0.y * sy + (size_t)i0.x;
    const size_t oy = (size_t)(i1.y - i0.y) * sy, oz = (size_t)(i1.z - i0.z) * sz;
    float4 lo, hi;
    voxel_load_corners(v, g, b, oy, oz, &lo, &hi);
    /* The four x blends (c00, c10, c01, c11), then the two y blends, then z, each a + t (b - a)
     * as one fused multiply-add: mix's multiply and add are two dependent steps on the chain
     * from the loads to the view table's entry, and the fused form is 5% of the walnut's
     * unshaded frame (docs/performance.md); fma is correctly rounded on every device, and the
     * C twin (tests/reference/cpu_reference.c, lerp_fma) blends the same way. */
    const float4 bx = fma(f.x, hi - lo, lo);
    const float2 by = fma(f.y, bx.s13 - bx.s02, bx.s02);
    return fma(f.z, by.y - by.x, by.x);
}

inline float sample_volume(VOLUME_PARAM, VolGeom g, float3 p)
{
    return voxel_blended(g, sample_stored(vol, g, world_to_voxel(g, p)));
}
#endif

/* The eight voxels of the cell of voxel centres whose lowest corner is voxel i0 (i0 in
 * [0, dims - 2], 0 on an axis of one voxel, where the cell repeats it), as sample_volume reads
 * and normalises them, x fastest: c[x + 2 y + 4 z]. The trilinear interpolant inside the cell is
 * then a blend of these (kernels/techniques/reference.cl integrates along a ray cell by cell). */
#if UMBRA_SAMPLER_IMAGE
/* Filtered reads at the voxel centres, where the filter's weights are 1 and 0: the texels. */
UMBRA_INLINE void volume_cell(VOLUME_PARAM, VolGeom g, int3 i0, float *c)
{
    const int3 i1 = min(i0 + 1, g.dims - 1);
    for (int k = 0; k < 8; ++k) {
        const int3 i = (int3)((k & 1) ? i1.x : i0.x, (k & 2) ? i1.y : i0.y, (k & 4) ? i1.z : i0.z);
        c[k] = sample_volume(vol, g, g.box_min + (convert_float3(i) + 0.5f) * g.spacing);
    }
}
#else
UMBRA_INLINE void volume_cell(VOLUME_PARAM, VolGeom g, int3 i0, float *c)
{
    int3 i1 = min(i0 + 1, g.dims - 1);
#if UMBRA_PART
    i0 = PART_INDEX(i0);
    i1 = PART_INDEX(i1);
#endif
#if UMBRA_VOLUME_SLABS == 1
    __global const UMBRA_VOXEL_T *restrict v = vol;
#else
    const int s = min(i0.z / UMBRA_SLAB_STEP, UMBRA_VOLUME_SLABS - 1);
    __global const UMBRA_VOXEL_T *v = volume_slab(vol, s);
    i0.z -= s * UMBRA_SLAB_STEP;
    i1.z -= s * UMBRA_SLAB_STEP;
#endif
    const size_t sy = (size_t)g.dims.x, sz = (size_t)g.dims.x * (size_t)g.dims.y;
    const size_t z0 = (size_t)i0.z * sz, z1 = (size_t)i1.z * sz;
    const size_t y0 = (size_t)i0.y * sy, y1 = (size_t)i1.y * sy;
    float2 r[4] = {voxel_load2(v, g, z0 + y0 + i0.x), voxel_load2(v, g, z0 + y1 + i0.x),
                   voxel_load2(v, g, z1 + y0 + i0.x), voxel_load2(v, g, z1 + y1 + i0.x)};
    for (int k = 0; k < 4; ++k) {
        /* one voxel along x: the second load is the next row's (or the pad), not this cell's */
        const float x1 = i1.x == i0.x ? r[k].x : r[k].y;
        c[2 * k] = voxel_blended(g, r[k].x);
        c[2 * k + 1] = voxel_blended(g, x1);
    }
}
#endif

/* The view ray's classification in one step (issue #28): sample_stored's value s maps to a
 * transfer function table's coordinate by one multiply-add, s * a + b (TfMap), clamped once to
 * the table, instead of voxel_normalise's map and clamp followed by tf_lookup's clamp and scale.
 * The view table carries one entry past its last, a copy of it (host/tables.c, corrected_table),
 * so that the interval's first entry is the coordinate's integer part, with no clamp to n - 2:
 * at the top, x = n - 1, the blend is the last entry with weight 0 on the copy. The same line as
 * tf_lookup(sample_volume(..)) where nothing clamps, up to float rounding. */
typedef struct TfMap {
    float a, b, top; /* table coordinate s * a + b, clamped to [0, top = n - 1] */
} TfMap;

inline TfMap tf_map(VolGeom g, uint n)
{
    TfMap m;
    m.top = (float)(n - 1);
#if !UMBRA_SAMPLER_IMAGE && UMBRA_VOXEL_CLAMPS
    m.a = m.top; /* sample_stored is normalised already */
    m.b = 0.0f;
#else
    m.a = g.image_scale * g.value_scale * m.top;
    m.b = -g.value_lo * g.value_scale * m.top;
#endif
    return m;
}

/* tf's entry at sample_stored value s, linearly interpolated; tf holds n + 1 entries, the last
 * two equal (TfMap). */
UMBRA_INLINE float4 tf_classify(__global const float4 *tf, TfMap m, float s)
{
    float x = clamp(fma(s, m.a, m.b), 0.0f, m.top);
    int i = (int)x;
    float f = x - (float)i;
    const float4 a = tf[i];
    return fma(f, tf[i + 1] - a, a); /* fused, as sample_stored's blends */
}

#if UMBRA_SAMPLER_IMAGE || UMBRA_VOLUME_SLABS > 1
/* Central-difference gradient, one voxel each way, in value per world unit: six samples (on the
 * image back end six filtered reads, the texture hardware interpolates). A volume in several
 * slabs takes this form on the buffer back end too: each sample lies in one slab, while the
 * 32-voxel stencil below spans four layers, which can straddle a slab's one-layer apron. */
inline float3 volume_gradient(VOLUME_PARAM, VolGeom g, float3 p)
{
    float3 s = g.spacing;
    float gx = sample_volume(vol, g, p + (float3)(s.x, 0, 0)) - sample_volume(vol, g, p - (float3)(s.x, 0, 0));
    float gy = sample_volume(vol, g, p + (float3)(0, s.y, 0)) - sample_volume(vol, g, p - (float3)(0, s.y, 0));
    float gz = sample_volume(vol, g, p + (float3)(0, 0, s.z)) - sample_volume(vol, g, p - (float3)(0, 0, s.z));
    return (float3)(gx, gy, gz) * 0.5f * g.inv_spacing;
}
#else
/* The same gradient as the image back end's, (s(p + e) - s(p - e)) / 2 per axis with the clamped
 * trilinear sampler s, one voxel e each way, in value per world unit, computed in one pass over
 * the 32 voxels those six samples read (a 4 x 2 x 2 block through p's cell along each axis):
 * as all six share p's fractions, each axis' component is the trilinear interpolation, over p's
 * cell, of the voxels' central differences v[i+1] - v[i-1]. Six separate samples cost 48 loads
 * and six index computations, which made PoCL's shaded frames markedly costlier than this
 * (measured: docs/performance-log.md, "Behind the kernels' comments"). Indices come from the
 * unclamped position and are
 * clamped one by one, which repeats the border voxels exactly as clamping each sample's
 * position does (a position clamped to the border interpolates between two copies of the
 * border voxel). It differs from
 * the six samples only by float rounding, and less of it: the differences are taken before the
 * interpolation, not between two interpolated values (tests/test_raycast.c bounds the image
 * change against the six-sample form). */
#define VX(i) voxel_load(vol, g, i) /* voxel i, through the one buffer read */
UMBRA_INLINE float3 volume_gradient(VOLUME_PARAM, VolGeom g, float3 p)
{
    /* Clamped to one voxel past the border, where every difference is 0 either way, so the
     * integer conversion below stays defined for any p. */
    float3 x = clamp(world_to_voxel(g, p), (float3)(-1.0f), convert_float3(g.dims));
    int3 i = floor_int3(x);
    float3 f = x - convert_float3(i);
    int3 top = g.dims - 1;
    int3 a = clamp(i - 1, (int3)(0), top), b = clamp(i, (int3)(0), top);
    int3 c = clamp(i + 1, (int3)(0), top), d = clamp(i + 2, (int3)(0), top);
#if UMBRA_PART
    a = PART_INDEX(a);
    b = PART_INDEX(b);
    c = PART_INDEX(c);
    d = PART_INDEX(d);
#endif
    size_t sy = (size_t)PART_DIMS.x, sz = (size_t)PART_DIMS.x * (size_t)PART_DIMS.y;
    size_t xa = (size_t)a.x, xb = (size_t)b.x, xc = (size_t)c.x, xd = (size_t)d.x;
    size_t ya = (size_t)a.y * sy, yb = (size_t)b.y * sy;
    size_t yc = (size_t)c.y * sy, yd = (size_t)d.y * sy;
    size_t za = (size_t)a.z * sz, zb = (size_t)b.z * sz;
    size_t zc = (size_t)c.z * sz, zd = (size_t)d.z * sz;
    /* p's cell: the corners (b or c per axis) */
    float v_bbb = VX(zb + yb + xb), v_cbb = VX(zb + yb + xc);
    float v_bcb = VX(zb + yc + xb), v_ccb = VX(zb + yc + xc);
    float v_bbc = VX(zc + yb + xb), v_cbc = VX(zc + yb + xc);
    float v_bcc = VX(zc + yc + xb), v_ccc = VX(zc + yc + xc);
    /* along x: the differences at x = b (v[c] - v[a]) and x = c (v[d] - v[b]), mixed by f.x */
    float dx_bb = mix(v_cbb - VX(zb + yb + xa), VX(zb + yb + xd) - v_bbb, f.x);
    float dx_cb = mix(v_ccb - VX(zb + yc + xa), VX(zb + yc + xd) - v_bcb, f.x);
    float dx_bc = mix(v_cbc - VX(zc + yb + xa), VX(zc + yb + xd) - v_bbc, f.x);
    float dx_cc = mix(v_ccc - VX(zc + yc + xa), VX(zc + yc + xd) - v_bcc, f.x);
    float gx = mix(mix(dx_bb, dx_cb, f.y), mix(dx_bc, dx_cc, f.y), f.z);
    float dy_bb = mix(v_bcb - VX(zb + ya + xb), VX(zb + yd + xb) - v_bbb, f.y);
    float dy_cb = mix(v_ccb - VX(zb + ya + xc), VX(zb + yd + xc) - v_cbb, f.y);
    float dy_bc = mix(v_bcc - VX(zc + ya + xb), VX(zc + yd + xb) - v_bbc, f.y);
    float dy_cc = mix(v_ccc - VX(zc + ya + xc), VX(zc + yd + xc) - v_cbc, f.y);
    float gy = mix(mix(dy_bb, dy_cb, f.x), mix(dy_bc, dy_cc, f.x), f.z);
    float dz_bb = mix(v_bbc - VX(za + yb + xb), VX(zd + yb + xb) - v_bbb, f.z);
    float dz_cb = mix(v_cbc - VX(za + yb + xc), VX(zd + yb + xc) - v_cbb, f.z);
    float dz_bc = mix(v_bcc - VX(za + yc + xb), VX(zd + yc + xb) - v_bcb, f.z);
    float dz_cc = mix(v_ccc - VX(za + yc + xc), VX(zd + yc + xc) - v_ccb, f.z);
    float gz = mix(mix(dz_bb, dz_cb, f.x), mix(dz_bc, dz_cc, f.x), f.y);
    /* Where voxel_load gives stored values (no voxel clamps), the differences are of stored
     * values: the normalisation is linear there, so its slope scales them once. */
#if UMBRA_VOXEL_CLAMPS
    const float slope = 1.0f;
#else
    const float slope = g.image_scale * g.value_scale;
#endif
    return (float3)(gx, gy, gz) * (0.5f * slope) * g.inv_spacing;
}

/* The gradient volume (issue #28): the per-voxel central differences volume_gradient above
 * interpolates, computed once per volume instead of at every shaded sample (32 voxel loads and
 * their index arithmetic become 8 loads of 8 bytes at one index). Entry q, q in [-1, dims + 1]
 * per axis (a grid of dims + 3 per axis, q + 1 x fastest), holds per axis a the difference
 * v[clamp(q + e_a)] - v[clamp(q - e_a)] of voxel_load values, every index clamped to the grid:
 * exactly the corner differences of volume_gradient's stencil at the cell whose lowest corner is
 * q, 0 past the border. They are held as int16, which is exact where the voxels are integers
 * loaded as stored (uchar, ushort or short without UMBRA_VOXEL_CLAMPS) spanning at most 32767
 * (the host builds the volume only there), so gradient_volume_sample blends the same floats in
 * the same order: the same gradient bit for bit. 8 bytes a voxel, built only for shaded frames
 * and again when the volume changes (host/gradient_volume.c). Whole volumes in one
 * buffer only (UMBRA_GRADIENT_VOLUME). */
#if !UMBRA_PART && !UMBRA_VOXEL_CLAMPS
#define UMBRA_GRADIENT_VOLUME 1
inline short4 gradient_volume_entry(VOLUME_PARAM, VolGeom g, int3 q)
{
    const int3 top = g.dims - 1;
    const int3 lo = clamp(q - 1, (int3)(0), top), mid = clamp(q, (int3)(0), top);
    const int3 hi = clamp(q + 1, (int3)(0), top);
    const size_t sy = (size_t)g.dims.x, sz = (size_t)g.dims.x * (size_t)g.dims.y;
    const size_t y = (size_t)mid.y * sy, z = (size_t)mid.z * sz;
    const float dx = VX(z + y + (size_t)hi.x) - VX(z + y + (size_t)lo.x);
    const float dy = VX(z + (size_t)hi.y * sy + (size_t)mid.x) - VX(z + (size_t)lo.y * sy + (size_t)mid.x);
    const float dz = VX((size_t)hi.z * sz + y + (size_t)mid.x) - VX((size_t)lo.z * sz + y + (size_t)mid.x);
    return convert_short4((float4)(dx, dy, dz, 0.0f));
}

/* volume_gradient(vol, g, p) from the gradient volume gv. */
UMBRA_INLINE float3 gradient_volume_sample(__global const short4 *restrict gv, VolGeom g, float3 p)
{
    float3 x = clamp(world_to_voxel(g, p), (float3)(-1.0f), convert_float3(g.dims));
    int3 i = floor_int3(x);
    float3 f = x - convert_float3(i);
    const size_t nx = (size_t)g.dims.x + 3, nxy = nx * ((size_t)g.dims.y + 3);
    const size_t b = (size_t)(i.z + 1) * nxy + (size_t)(i.y + 1) * nx + (size_t)(i.x + 1);
    /* the cell's corners, named as volume_gradient's: x, y, z each b (i) or c (i + 1) */
#define GV(i) convert_float4(gv[i])
    const float4 g_bbb = GV(b), g_cbb = GV(b + 1), g_bcb = GV(b + nx), g_ccb = GV(b + nx + 1);
    const float4 g_bbc = GV(b + nxy), g_cbc = GV(b + nxy + 1);
    const float4 g_bcc = GV(b + nxy + nx), g_ccc = GV(b + nxy + nx + 1);
#undef GV
    float dx_bb = mix(g_bbb.x, g_cbb.x, f.x), dx_cb = mix(g_bcb.x, g_ccb.x, f.x);
    float dx_bc = mix(g_bbc.x, g_cbc.x, f.x), dx_cc = mix(g_bcc.x, g_ccc.x, f.x);
    float gx = mix(mix(dx_bb, dx_cb, f.y), mix(dx_bc, dx_cc, f.y), f.z);
    float dy_bb = mix(g_bbb.y, g_bcb.y, f.y), dy_cb = mix(g_cbb.y, g_ccb.y, f.y);
    float dy_bc = mix(g_bbc.y, g_bcc.y, f.y), dy_cc = mix(g_cbc.y, g_ccc.y, f.y);
    float gy = mix(mix(dy_bb, dy_cb, f.x), mix(dy_bc, dy_cc, f.x), f.z);
    float dz_bb = mix(g_bbb.z, g_bbc.z, f.z), dz_cb = mix(g_cbb.z, g_cbc.z, f.z);
    float dz_bc = mix(g_bcb.z, g_bcc.z, f.z), dz_cc = mix(g_ccb.z, g_ccc.z, f.z);
    float gz = mix(mix(dz_bb, dz_cb, f.x), mix(dz_bc, dz_cc, f.x), f.y);
    const float slope = g.image_scale * g.value_scale; /* no voxel clamps: stored values */
    return (float3)(gx, gy, gz) * (0.5f * slope) * g.inv_spacing;
}
#endif
#undef VX
#endif
