/* kernels/common.cl: math shared by every umbra program: ray-box intersection, transfer-function
 * lookup, the counter-based random numbers, and the brick walk used for empty-space skipping.
 * It follows umbra_shared.h and precedes sampling.cl in every program. */

#define UMBRA_INF INFINITY

/* Geometry of the volume in private memory, so inner loops do not re-read the frame struct. */
typedef struct VolGeom {
    float3 box_min;
    float3 box_max;
    float3 spacing;
    float3 inv_spacing;
    int3 dims;
    int3 bricks;
    int brick_size;
} VolGeom;

inline VolGeom vol_geom(__global const UmbraFrame *F)
{
    VolGeom g;
    g.box_min = F3(F->box_min);
    g.box_max = F3(F->box_max);
    g.inv_spacing = F3(F->inv_spacing);
    g.spacing = 1.0f / g.inv_spacing;
    g.dims = (int3)(F->dims[0], F->dims[1], F->dims[2]);
    g.bricks = (int3)(F->bricks[0], F->bricks[1], F->bricks[2]);
    g.brick_size = F->bricks[3];
    return g;
}

/* Slab test: the parametric interval [t0, t1] where o + t d lies in [bmin, bmax]; t1 < t0 when
 * the ray misses. Division by a zero component gives +-inf, which the min/max handle, so axis-
 * aligned rays need no special case. */
inline float2 ray_box(float3 o, float3 d, float3 bmin, float3 bmax)
{
    float3 inv = 1.0f / d;
    float3 ta = (bmin - o) * inv;
    float3 tb = (bmax - o) * inv;
    /* A component of d that is exactly zero gives 0 * inf = NaN when o lies on the slab plane;
     * fmin/fmax drop NaN operands, which treats that axis as unbounded, as it should be. */
    float3 tmin = fmin(ta, tb);
    float3 tmax = fmax(ta, tb);
    float t0 = fmax(fmax(tmin.x, tmin.y), tmin.z);
    float t1 = fmin(fmin(tmax.x, tmax.y), tmax.z);
    return (float2)(t0, t1);
}

/* Linear interpolation in an RGBA table spread over [0,1]. */
inline float4 tf_lookup(__global const float4 *tf, uint n, float v)
{
    float x = clamp(v, 0.0f, 1.0f) * (float)(n - 1);
    int i = min((int)x, (int)n - 2);
    float f = x - (float)i;
    return mix(tf[i], tf[i + 1], f);
}

/* Integer hash (lowbias32, Chris Wellons): a counter-based generator, so a value depends only on
 * (seed, counters) and the same seed gives the same image bit for bit. */
inline uint umbra_hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

/* Uniform float in [0,1) from a seed and up to three counters. */
inline float umbra_random(uint seed, uint a, uint b, uint c)
{
    uint h = umbra_hash(seed ^ umbra_hash(a ^ umbra_hash(b ^ umbra_hash(c))));
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

/* Continuous voxel coordinates (voxel i's centre at i) of a world point. */
inline float3 world_to_voxel(VolGeom g, float3 p)
{
    return (p - g.box_min) * g.inv_spacing - 0.5f;
}

/* Grid coordinates of the brick whose trilinear footprint contains p (positions outside the grid
 * clamp to the border bricks, as the sampler clamps to the border voxels). */
inline int3 brick_coords(VolGeom g, float3 p)
{
    float3 x = world_to_voxel(g, p) / (float)g.brick_size;
    return clamp(convert_int3(floor(x)), (int3)(0), g.bricks - 1);
}

inline int brick_index(VolGeom g, float3 p)
{
    int3 b = brick_coords(g, p);
    return (b.z * g.bricks.y + b.y) * g.bricks.x + b.x;
}

/* The sub-cell (UMBRA_BRICK_CELLS per axis) of p within the brick whose first voxel is origin
 * (brick coordinates times brick_size); inv_cell is 1 / the cell size in voxels. */
inline int3 cell_coords(VolGeom g, float3 origin, float inv_cell, float3 p)
{
    return clamp(convert_int3(floor((world_to_voxel(g, p) - origin) * inv_cell)), (int3)(0),
                 (int3)(UMBRA_BRICK_CELLS - 1));
}

/* Whether sub-cell c is visible in a brick's cell mask. */
inline bool cell_visible(ulong mask, int3 c)
{
    int bit = (c.z * UMBRA_BRICK_CELLS + c.y) * UMBRA_BRICK_CELLS + c.x;
    return ((mask >> bit) & 1UL) != 0UL;
}

/* The ray parameter at which o + t d leaves sub-cell c of the brick whose first voxel is origin
 * (a point clamped into the cell may lie behind its exit: the caller steps at least one sample). */
inline float cell_exit(VolGeom g, float3 o, float3 d, float3 origin, float cell, int3 c)
{
    float3 lo = (origin + convert_float3(c) * cell + 0.5f) * g.spacing + g.box_min;
    float3 hi = lo + cell * g.spacing;
    float3 t = select((lo - o) / d, (hi - o) / d, d > 0.0f);
    t = select(t, (float3)(UMBRA_INF), d == 0.0f);
    return fmin(fmin(t.x, t.y), t.z);
}

/* The ray parameter at which o + t d leaves the brick containing o + t_now d. */
inline float brick_exit(VolGeom g, float3 o, float3 d, float t_now)
{
    float3 p = o + t_now * d;
    float3 x = world_to_voxel(g, p) / (float)g.brick_size;
    int3 b = clamp(convert_int3(floor(x)), (int3)(0), g.bricks - 1);
    float3 lo = (convert_float3(b * g.brick_size) + 0.5f) * g.spacing + g.box_min;
    float3 hi = (convert_float3((b + 1) * g.brick_size) + 0.5f) * g.spacing + g.box_min;
    /* Border bricks extend to infinity: the clamped sampler repeats the border voxels there. */
    lo = select(lo, (float3)(-UMBRA_INF), b == (int3)(0));
    hi = select(hi, (float3)(UMBRA_INF), b == g.bricks - 1);
    float3 t_hi = (hi - o) / d;
    float3 t_lo = (lo - o) / d;
    float3 t = select(t_lo, t_hi, d > 0.0f);
    t = select(t, (float3)(UMBRA_INF), d == 0.0f);
    return fmin(fmin(t.x, t.y), t.z);
}

/* The first sample index k (samples at t0 + (k + offset) h) that lies past t_exit, at least k+1. */
inline int next_sample_after(float t0, float h, float offset, float t_exit, int k)
{
    float kk = ceil((t_exit - t0) / h - offset);
    return (kk > (float)(k + 1)) ? (int)fmin(kk, 2147483000.0f) : k + 1;
}

/* Direction towards the light and the distance to it (infinite for a directional light). */
inline float4 to_light(__global const UmbraFrame *F, float3 p)
{
    if (F->flags & UMBRA_FLAG_POINT_LIGHT) {
        float3 v = F3(F->light) - p;
        float dist = length(v);
        return dist > 0.0f ? (float4)(v / dist, dist) : (float4)(0.0f, 1.0f, 0.0f, 0.0f);
    }
    return (float4)(-F3(F->light), UMBRA_INF);
}

/* ---- the shading model's light transport ------------------------------------------------------
 * A sample of step-corrected opacity a and transmission colour t passes the fraction
 * 1 - a (1 - t_c) of light channel c; t = 0 unless UMBRA_FLAG_COLORED, where t is the light
 * transfer function's RGB. UMBRA_LIGHT_CHANNELS = 1 is chosen by the host when t is the same in
 * all channels wherever a > 0 (grey mode, or a grey light transfer function): then one channel
 * carries the light, and its value stands for all three. */
#ifndef UMBRA_LIGHT_CHANNELS
#define UMBRA_LIGHT_CHANNELS 3
#endif

#if UMBRA_LIGHT_CHANNELS == 1
typedef float light_t;
inline light_t light_pass(float4 c, uint flags)
{
    return 1.0f - c.w * ((flags & UMBRA_FLAG_COLORED) ? (1.0f - c.x) : 1.0f);
}
inline float3 light_rgb(light_t v) { return (float3)(v); }
inline float light_max(light_t v) { return v; }
#else
typedef float3 light_t;
inline light_t light_pass(float4 c, uint flags)
{
    float3 t = (flags & UMBRA_FLAG_COLORED) ? c.xyz : (float3)(0.0f);
    return 1.0f - c.w * (1.0f - t);
}
inline float3 light_rgb(light_t v) { return v; }
inline float light_max(light_t v) { return fmax(v.x, fmax(v.y, v.z)); }
#endif

/* The opacity a of one length unit over r units: 1 - (1 - a)^r, written -expm1(r log1p(-a)) so
 * that a near-transparent a (1e-6) keeps its relative precision, where 1 - a would round it away;
 * an opaque a stays opaque over any r > 0, and no length is transparent. */
inline float alpha_for_length(float a, float r)
{
    if (!(r > 0.0f))
        return 0.0f;
    return a < 1.0f ? -expm1(r * log1p(-a)) : 1.0f;
}

/* Opacity of a sample whose table alpha was corrected for step h, re-corrected for a step of
 * fraction r of h. */
inline float4 alpha_for_fraction(float4 c, float r)
{
    c.w = alpha_for_length(c.w, r);
    return c;
}
