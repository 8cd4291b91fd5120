// SPDX-License-Identifier: Apache-2.0
/* kernels/common/common.cl: math shared by every umbra program: ray-box intersection, the clip
 * region, transfer-function lookup, the counter-based random numbers, and the brick walk used
 * for empty-space skipping.
 * It follows common/umbra_shared.h and precedes common/sampling.cl in every program. */

#define UMBRA_INF INFINITY

/* The counter of samples a frame takes (umbra_render_stats.samples): 64-bit where the device has
 * the atomics. */
#if defined(cl_khr_int64_base_atomics)
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#define UMBRA_COUNT_T ulong
#define UMBRA_COUNT_ADD(p, v) atom_add(umbra_count_lane(p), (ulong)(v))
#else
#define UMBRA_COUNT_T uint
#define UMBRA_COUNT_ADD(p, v) atomic_add(umbra_count_lane(p), (uint)(v))
#endif

/* The counter's lane of this work-group (UMBRA_COUNT_LANES, kernels/common/umbra_shared.h). */
inline __global UMBRA_COUNT_T *umbra_count_lane(__global UMBRA_COUNT_T *p)
{
    const size_t group = get_group_id(1) * get_num_groups(0) + get_group_id(0);
    return p + (group % UMBRA_COUNT_LANES) * (UMBRA_COUNT_LANE_BYTES / sizeof(UMBRA_COUNT_T));
}

/* For functions of the ray loops that the compiler would otherwise call out of line (PoCL did,
 * copying VolGeom on every call). */
#define UMBRA_INLINE inline __attribute__((always_inline))

/* Geometry of the volume in private memory, so inner loops do not re-read the frame struct. */
typedef struct VolGeom {
    float3 box_min;
    float3 box_max;
    float3 spacing;
    float3 inv_spacing;
    int3 dims;
    int3 bricks;
    int brick_size;
    int cell_size; /* voxels along a brick's sub-cell: ceil(brick_size / UMBRA_BRICK_CELLS) */
    float value_lo, value_scale, image_scale; /* UmbraFrame.value_map (kernels/common/sampling.cl)
    */
#if UMBRA_PART
    int3 part_shift, part_dims; /* UmbraFrame.part_shift, part_dims (sampling.cl, PART_INDEX) */
#endif
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
    g.cell_size = (g.brick_size + UMBRA_BRICK_CELLS - 1) / UMBRA_BRICK_CELLS;
    g.value_lo = F->value_map[0];
    g.value_scale = F->value_map[1];
    g.image_scale = F->value_map[2];
#if UMBRA_PART
    g.part_shift = (int3)(F->part_shift[0], F->part_shift[1], F->part_shift[2]);
    g.part_dims = (int3)(F->part_dims[0], F->part_dims[1], F->part_dims[2]);
#endif
    return g;
}

#if UMBRA_PART
/* Whether the part owns the sample at voxel coordinates x (UmbraFrame.part_lo, part_hi): the
 * half-open core box, so a sample on a face two parts share is taken by one of them (view
 * samples, kernels/raycast.cl, and light-ray segments by their midpoint). */
inline int part_owns(__global const UmbraFrame *F, float3 x)
{
    const float3 c = x + 0.5f;
    return all(c >= F3(F->part_lo)) && all(c < F3(F->part_hi));
}
#endif

/* Slab test: the parametric interval [t0, t1] where o + t d lies in [bmin, bmax] (faces
 * included); t1 < t0 when the ray misses. Division by a zero component gives +-inf, which the
 * min/max handle where o lies off that axis' planes. On a plane it gives 0 * inf = NaN for that
 * plane's bound and the other bound infinite, which fmin/fmax kept: a ray along a face, from a
 * point on it, missed the box (a point on a side face of a box lit along an axis read fully
 * lit, issue #29.14). A ray parallel to an axis lies in its slab for every t or for none. */
inline float2 ray_box(float3 o, float3 d, float3 bmin, float3 bmax)
{
    float3 inv = 1.0f / d;
    float3 ta = (bmin - o) * inv;
    float3 tb = (bmax - o) * inv;
    float3 tmin = fmin(ta, tb);
    float3 tmax = fmax(ta, tb);
    const int3 parallel = d == (float3)(0.0f);
    const int3 inside = (o >= bmin) & (o <= bmax);
    tmin = select(tmin, select((float3)(UMBRA_INF), (float3)(-UMBRA_INF), inside), parallel);
    tmax = select(tmax, select((float3)(-UMBRA_INF), (float3)(UMBRA_INF), inside), parallel);
    float t0 = fmax(fmax(tmin.x, tmin.y), tmin.z);
    float t1 = fmin(fmin(tmax.x, tmax.y), tmax.z);
    return (float2)(t0, t1);
}

/* ---- the clip region (UmbraClip, kernels/common/umbra_shared.h) --------------------------------
 * One mechanism for every ray: the region is convex, so a ray crosses it in one interval, which
 * the view rays, the light-space maps' light rays (ls_texel_ray) and the reference's shadow rays
 * take in place of their interval in the volume's box; the convolution technique's slices test
 * each sample (clip_keeps). Nothing is read past `active` when nothing is clipped. */

/* The part of the interval tb (a ray's part in the volume's box, from ray_box) of the ray o + t d
 * that the clip region keeps: empty (.y < .x, or .y = -inf) where the ray misses it. */
inline float2 clip_interval(__global const UmbraClip *C, float3 o, float3 d, float2 tb)
{
    if (!C->active)
        return tb;
    const float2 tc = ray_box(o, d, F3(C->box_min), F3(C->box_max));
    float2 t = (float2)(fmax(tb.x, tc.x), fmin(tb.y, tc.y));
    for (uint i = 0; i < C->plane_count; ++i) {
        const float3 n = F3(C->planes[i]);
        const float dn = dot(n, d), s = dot(n, o) + C->planes[i][3];
        /* Kept where s + t dn >= 0: from -s / dn on when dn > 0, up to it when dn < 0, and
         * everywhere or nowhere on a ray parallel to the plane. */
        if (dn > 0.0f)
            t.x = fmax(t.x, -s / dn);
        else if (dn < 0.0f)
            t.y = fmin(t.y, -s / dn);
        else if (s < 0.0f)
            t.y = -UMBRA_INF;
    }
    return t;
}

/* Whether the clip region keeps point p. */
inline int clip_keeps(__global const UmbraClip *C, float3 p)
{
    if (!C->active)
        return 1;
    if (any(p < F3(C->box_min)) || any(p > F3(C->box_max)))
        return 0;
    for (uint i = 0; i < C->plane_count; ++i)
        if (dot(F3(C->planes[i]), p) + C->planes[i][3] < 0.0f)
            return 0;
    return 1;
}

/* The first sample index k >= 0 of a ray sampled at t0 + (k + offset) h that lies at or after
 * t_from: the clipped interval's first sample, on the same grid as the unclipped ray's, so that
 * clipping drops samples and moves none (a clip plane moving through the volume does not shift
 * the sampling of what it keeps). 0 where t_from <= t0. */
inline int clip_first_sample(float t0, float h, float offset, float t_from)
{
    if (!(t_from > t0))
        return 0;
    return (int)fmin(ceil((t_from - t0) / h - offset), 2147483000.0f);
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

/* floor(x) as integers, for |x| < 2^31: a conversion (truncation toward zero) and one less where
 * that rounded up (x negative, not whole). PoCL's floor() is a dozen instructions, since it also
 * handles huge and infinite values; in the sample and lookup loops that was a noticeable part
 * of the unshadowed frame (docs/performance.md; issue #12). */
inline int2 floor_int2(float2 x)
{
    const int2 i = convert_int2(x);
    return i + (convert_float2(i) > x); /* a true vector comparison is -1 */
}

inline int3 floor_int3(float3 x)
{
    const int3 i = convert_int3(x);
    return i + (convert_float3(i) > x);
}

/* |v| and v / |v| where they run per sample. PoCL's length() and normalize() guard against
 * overflow and underflow by scaling, which costs several times the square root; the vectors here
 * (gradients, offsets within the scene) are far from either, and the results were the same bit
 * for bit on every image checked. What it gained: docs/performance-log.md, "Behind the kernels'
 * comments" (issue #12). */
inline float umbra_length(float3 v) { return sqrt(dot(v, v)); }

inline float3 umbra_normalize(float3 v) { return v * (1.0f / sqrt(dot(v, v))); }

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

/* The first sample index k (samples at t0 + (k + offset) h) that lies past t_exit, at least k+1. */
inline int next_sample_after(float t0, float h, float offset, float t_exit, int k)
{
    float kk = ceil((t_exit - t0) / h - offset);
    return (kk > (float)(k + 1)) ? (int)fmin(kk, 2147483000.0f) : k + 1;
}

/* ---- a ray's walk over the bricks' sub-cells ----------------------------------------------------
 * A 3D DDA (Amanatides & Woo 1987) in voxel coordinates over the cells of
 * kernels/common/umbra_shared.h:
 * along each axis, brick b's cell j covers the positions [b B + j C, b B + min((j + 1) C, B)),
 * C = ceil(B / UMBRA_BRICK_CELLS), and the border cells reach on to infinity, as the clamped
 * sampler repeats the border voxels there. Each step crosses one face, found by comparing three
 * parameters, each computed afresh from its integer face position (nothing accumulates rounding),
 * with no division: on CPUs this costs a fraction of locating every cell from its position. */
typedef struct CellWalk {
    float3 xo;     /* the ray in voxel coordinates: xo + t xd */
    float3 xd;     /* (the direction, per voxel) */
    float3 inv_xd; /* 1 / xd (+-inf on an axis the ray is parallel to) */
    int3 dir;      /* the ray's direction per axis: +1, -1 or 0 */
    int3 brick;    /* the current cell: its brick, */
    int3 cell;     /* its index in the brick, */
    float3 t_face; /* the parameter at which the ray leaves it through each axis' face, */
    float t_in;    /* and the one at which the ray entered it */
} CellWalk;

/* The parameter at which a ray (origin x, 1 / direction inv, sign dir) along one axis leaves
 * cell c of brick b (B voxels a brick, C a cell, nb bricks). */
UMBRA_INLINE float walk_face(float x, float inv, int dir, int b, int c, int B, int C, int nb)
{
    if (dir > 0) {
        int hi = min((c + 1) * C, B);
        return (b == nb - 1 && hi == B) ? UMBRA_INF : ((float)(b * B + hi) - x) * inv;
    }
    if (dir < 0)
        return (b == 0 && c == 0) ? UMBRA_INF : ((float)(b * B + c * C) - x) * inv;
    return UMBRA_INF;
}

/* The current cell's three exit parameters. */
UMBRA_INLINE void walk_set_faces(CellWalk *w, VolGeom g)
{
    const int B = g.brick_size, C = g.cell_size;
    w->t_face = (float3)(walk_face(w->xo.x, w->inv_xd.x, w->dir.x, w->brick.x, w->cell.x, B, C, g.bricks.x),
                         walk_face(w->xo.y, w->inv_xd.y, w->dir.y, w->brick.y, w->cell.y, B, C, g.bricks.y),
                         walk_face(w->xo.z, w->inv_xd.z, w->dir.z, w->brick.z, w->cell.z, B, C, g.bricks.z));
}

/* The cell of brick b holding voxel position x, clamped into the brick. */
UMBRA_INLINE int3 walk_cell_at(VolGeom g, int3 b, float3 x)
{
    const int B = g.brick_size, C = g.cell_size;
    return clamp(convert_int3(floor((x - convert_float3(b * B)) / (float)C)), (int3)(0),
                 (int3)((B - 1) / C));
}

/* The walk of the ray o + t d from its point at t. */
UMBRA_INLINE CellWalk walk_begin(VolGeom g, float3 o, float3 d, float t)
{
    CellWalk w;
    const float3 xd = d * g.inv_spacing;
    w.xo = world_to_voxel(g, o);
    w.xd = xd;
    w.inv_xd = 1.0f / xd;
    w.dir = select(select((int3)(0), (int3)(-1), xd < 0.0f), (int3)(1), xd > 0.0f);
    w.brick = brick_coords(g, o + t * d);
    w.cell = walk_cell_at(g, w.brick, w.xo + t * xd);
    walk_set_faces(&w, g);
    w.t_in = t;
    return w;
}

/* The parameter at which the ray leaves the current cell. */
UMBRA_INLINE float walk_exit(const CellWalk *w)
{
    return fmin(fmin(w->t_face.x, w->t_face.y), w->t_face.z);
}

/* One step along an axis in direction dir from cell c of brick b: the next (brick, cell). */
UMBRA_INLINE int2 walk_step_axis(int dir, int b, int c, int B, int C)
{
    if (dir > 0)
        return min((c + 1) * C, B) == B ? (int2)(b + 1, 0) : (int2)(b, c + 1);
    return c == 0 ? (int2)(b - 1, (B - 1) / C) : (int2)(b, c - 1);
}

/* Moves the walk into the next cell, through its nearest face (the caller checks that the ray
 * leaves the current one: walk_exit < infinity). */
UMBRA_INLINE void walk_advance(CellWalk *w, VolGeom g)
{
    const int B = g.brick_size, C = g.cell_size;
    const float3 tf = w->t_face;
    w->t_in = walk_exit(w);
    if (tf.x <= tf.y && tf.x <= tf.z) {
        const int2 s = walk_step_axis(w->dir.x, w->brick.x, w->cell.x, B, C);
        w->brick.x = s.x;
        w->cell.x = s.y;
        w->t_face.x = walk_face(w->xo.x, w->inv_xd.x, w->dir.x, w->brick.x, w->cell.x, B, C, g.bricks.x);
    } else if (tf.y <= tf.z) {
        const int2 s = walk_step_axis(w->dir.y, w->brick.y, w->cell.y, B, C);
        w->brick.y = s.x;
        w->cell.y = s.y;
        w->t_face.y = walk_face(w->xo.y, w->inv_xd.y, w->dir.y, w->brick.y, w->cell.y, B, C, g.bricks.y);
    } else {
        const int2 s = walk_step_axis(w->dir.z, w->brick.z, w->cell.z, B, C);
        w->brick.z = s.x;
        w->cell.z = s.y;
        w->t_face.z = walk_face(w->xo.z, w->inv_xd.z, w->dir.z, w->brick.z, w->cell.z, B, C, g.bricks.z);
    }
}

/* The parameter at which a ray along one axis leaves brick b (the walk_face of a whole brick). */
UMBRA_INLINE float walk_brick_face(float x, float inv, int dir, int b, int B, int nb)
{
    if (dir > 0)
        return b == nb - 1 ? UMBRA_INF : ((float)((b + 1) * B) - x) * inv;
    if (dir < 0)
        return b == 0 ? UMBRA_INF : ((float)(b * B) - x) * inv;
    return UMBRA_INF;
}

/* Moves the walk out of the current brick, whose cells are all invisible, into the cell of the
 * next brick where the ray enters it: one step instead of one per cell crossed (a ray crosses
 * about six of a brick's 4^3 cells). Along the exit axis the cell is the first one on the entry
 * side; along the others it is found from the entry point, clamped into the brick, so rounding
 * can only misplace it by the rounding error of that point. A ray that leaves the grid ends the
 * walk (t_in = UMBRA_INF). */
UMBRA_INLINE void walk_skip_brick(CellWalk *w, VolGeom g)
{
    const int B = g.brick_size, C = g.cell_size;
    const int last = (B - 1) / C;
    const float3 tb = (float3)(walk_brick_face(w->xo.x, w->inv_xd.x, w->dir.x, w->brick.x, B, g.bricks.x),
                               walk_brick_face(w->xo.y, w->inv_xd.y, w->dir.y, w->brick.y, B, g.bricks.y),
                               walk_brick_face(w->xo.z, w->inv_xd.z, w->dir.z, w->brick.z, B, g.bricks.z));
    const float t = fmin(fmin(tb.x, tb.y), tb.z);
    if (!(t < UMBRA_INF)) {
        w->t_in = UMBRA_INF;
        return;
    }
    const float3 x = w->xo + t * w->xd;
    w->cell = walk_cell_at(g, w->brick, x);
    if (tb.x <= tb.y && tb.x <= tb.z) {
        w->brick.x += w->dir.x;
        w->cell.x = w->dir.x > 0 ? 0 : last;
    } else if (tb.y <= tb.z) {
        w->brick.y += w->dir.y;
        w->cell.y = w->dir.y > 0 ? 0 : last;
    } else {
        w->brick.z += w->dir.z;
        w->cell.z = w->dir.z > 0 ? 0 : last;
    }
    walk_set_faces(w, g);
    w->t_in = t;
}

/* Whether the walk's current cell is visible in the per-brick cell masks. */
UMBRA_INLINE int walk_cell_visible(const CellWalk *w, VolGeom g, __global const ulong *cells)
{
    const ulong mask = cells[(w->brick.z * g.bricks.y + w->brick.y) * g.bricks.x + w->brick.x];
    const int bit = (w->cell.z * UMBRA_BRICK_CELLS + w->cell.y) * UMBRA_BRICK_CELLS + w->cell.x;
    return (int)((mask >> bit) & 1UL);
}

/* Walks on to the first cell that the ray leaves after t and that is visible in the per-brick
 * cell masks (a brick the transfer function leaves empty has none), and returns where the ray
 * entered it: at most t if t lies in it, UMBRA_INF if no such cell begins before t_end. */
UMBRA_INLINE float walk_to_visible(CellWalk *w, VolGeom g, __global const ulong *cells, float t,
                             float t_end)
{
    for (;;) {
        if (!(w->t_in < t_end))
            return UMBRA_INF;
        const ulong mask = cells[(w->brick.z * g.bricks.y + w->brick.y) * g.bricks.x + w->brick.x];
        if (!mask) {
            walk_skip_brick(w, g);
            continue;
        }
        const float t_out = walk_exit(w);
        if (t_out > t) {
            int bit = (w->cell.z * UMBRA_BRICK_CELLS + w->cell.y) * UMBRA_BRICK_CELLS + w->cell.x;
            if ((mask >> bit) & 1UL)
                return w->t_in;
        }
        if (!(t_out < UMBRA_INF))
            return UMBRA_INF;
        walk_advance(w, g);
    }
}

/* Empty-space skipping on a ray sampled at t0 + (k + offset) h, k < n: the first sample index at
 * or after k that lies in a visible cell of the cell masks (walking w on to that cell and setting
 * *t_cell to its exit, before which later samples need no test), or n if there is none before
 * t_end. The cell of a sample is the walk's: a sample on a face may be counted to either side
 * (the rounding of t), which changes no value, as both cells' footprints hold the face's voxels. */
UMBRA_INLINE int walk_next_sample(CellWalk *w, VolGeom g, __global const ulong *cells, float t0,
                                  float h, float offset, int k, int n, float t_end, float *t_cell)
{
    for (;;) {
        float t = t0 + ((float)k + offset) * h;
        const float t_in = walk_to_visible(w, g, cells, t, t_end);
        if (t_in > t) {
            if (!(t_in < t_end))
                return n;
            k = next_sample_after(t0, h, offset, t_in, k);
            if (k >= n)
                return n;
            t = t0 + ((float)k + offset) * h;
            if (!(t < walk_exit(w)))
                continue; /* the visible cell holds no sample: walk on from t */
        }
        /* A run of visible cells is taken as one: the walk moves on while the next cell is
         * visible too, so that the samples of the run need no test (the same samples: each lies
         * in a visible cell of the run, and t_cell, the run's end, is the exit of its last
         * cell, the same float). It stops in the first invisible cell after the run (where the
         * next test begins, as it would have begun in that cell), or in the last visible cell
         * if the ray ends in it. */
        for (;;) {
            const float t_out = walk_exit(w);
            if (!(t_out < t_end)) {
                *t_cell = t_out;
                return k;
            }
            walk_advance(w, g);
            if (!walk_cell_visible(w, g, cells)) {
                *t_cell = w->t_in;
                return k;
            }
        }
    }
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

/* The view ray through pixel (px, py): origin and unit direction. */
inline void camera_ray(__global const UmbraFrame *F, int px, int py, float3 *o, float3 *d)
{
    float sx = ((float)px + 0.5f) / (float)F->width * 2.0f - 1.0f;
    float sy = 1.0f - ((float)py + 0.5f) / (float)F->height * 2.0f;
    if (F->flags & UMBRA_FLAG_ORTHO) {
        *o = F3(F->eye) + sx * F3(F->right) + sy * F3(F->up);
        *d = F3(F->forward);
    } else {
        *o = F3(F->eye);
        *d = normalize(F3(F->forward) + sx * F3(F->right) + sy * F3(F->up));
    }
}

/* Direction towards the light and the distance to it (infinite for a directional light). */
inline float4 to_light(__global const UmbraFrame *F, float3 p)
{
    if (F->flags & UMBRA_FLAG_POINT_LIGHT) {
        float3 v = F3(F->light) - p;
        float dist = umbra_length(v);
        return dist > 0.0f ? (float4)(v / dist, dist) : (float4)(0.0f, 1.0f, 0.0f, 0.0f);
    }
    return (float4)(-F3(F->light), UMBRA_INF);
}

/* x^n for x in [0, 1] and n > 0: Blinn-Phong's specular |N.H|^shininess. pow() was the costliest
 * call of a shaded sample on PoCL (docs/performance-log.md, "Behind the kernels' comments"): it
 * handles every sign, range and exponent and rounds nearly exactly. A whole
 * exponent up to UMBRA_POWER_BY_SQUARING, as shininess almost always is, is taken by binary
 * powering instead: at most 2 log2(n) multiplications, each adding half an ulp, whose errors
 * the squarings double, so the result is within (n - 1) 2^-24 relative of the exact power (6e-6
 * at n = 100). Other exponents keep pow(). The C twin (tests/reference/cpu_reference.c) does
 * the same. */
#define UMBRA_POWER_BY_SQUARING 256.0f
UMBRA_INLINE float shading_power(float x, float n)
{
    /* n > 0 (the host checks it), so below the bound truncation tells a whole n */
    if (!(n <= UMBRA_POWER_BY_SQUARING && n == (float)(int)n))
        return pow(x, n);
    uint e = (uint)n;
    float r = 1.0f;
    for (;;) {
        if (e & 1u)
            r *= x;
        e >>= 1;
        if (!e)
            return r;
        x *= x;
    }
}

/* ---- the shading model's light transport ------------------------------------------------------
 * Light is absorbed per channel with extinction sigma_c = sigma (1 - t_c), where sigma =
 * -ln(1 - a) per voxel length is the extinction of the light transfer function's opacity a (the
 * table's alpha, linearly interpolated first, then converted: include/umbra/transfer_function.h)
 * and t = 0 unless UMBRA_FLAG_COLORED, where t is the light transfer function's RGB. A length of
 * D voxels at one value therefore passes (1 - a)^(D (1 - t_c)) of channel c: exact for every D in a
 * homogeneous medium, so every technique's result is independent of its step there. (The CSSM
 * paper's rho = a (1 - t) is the one-sample form of this, first order in the step.) Opacity 1 is
 * taken as the largest float below 1 (UMBRA_ALPHA_MAX, an extinction of 16.6 per voxel): a float
 * table cannot tell them apart, and a finite extinction keeps the light of a point on an opaque
 * surface, whose shadow ray crosses the material only for a rounding error's length, at 1 rather
 * than at 0 or at 1 by the chance of that rounding (black speckles on lit opaque faces).
 * UMBRA_LIGHT_CHANNELS = 1 is chosen by the host when t is the same in all channels wherever a > 0
 * (grey mode, or a grey light transfer function): then one channel carries the light, and its
 * value stands for all three. The light table on the device holds the uncorrected alphas. */
#ifndef UMBRA_LIGHT_CHANNELS
#define UMBRA_LIGHT_CHANNELS 3
#endif

#define UMBRA_ALPHA_MAX 0.99999994f /* 1 - 2^-24 */

/* Extinction per voxel length of (interpolated) table opacity a: -ln(1 - a), at most 16.64. */
inline float tf_extinction(float a) { return -log1p(-fmin(a, UMBRA_ALPHA_MAX)); }

#if UMBRA_LIGHT_CHANNELS == 1
typedef float light_t;
/* The fraction 1 - t of the extinction that light transfer-function colour c applies. */
inline light_t light_absorbed(float4 c, uint flags)
{
    return (flags & UMBRA_FLAG_COLORED) ? 1.0f - c.x : 1.0f;
}
inline float3 light_rgb(light_t v) { return (float3)(v); }
inline float light_max(light_t v) { return v; }
inline float light_min(light_t v) { return v; }
inline int light_any_gt(light_t a, light_t b) { return a > b; } /* in any channel */
inline int light_equal(light_t a, light_t b) { return a == b; }    /* in every channel */
#else
typedef float3 light_t;
inline light_t light_absorbed(float4 c, uint flags)
{
    return (flags & UMBRA_FLAG_COLORED) ? 1.0f - c.xyz : (float3)(1.0f);
}
inline float3 light_rgb(light_t v) { return v; }
inline float light_max(light_t v) { return fmax(v.x, fmax(v.y, v.z)); }
inline float light_min(light_t v) { return fmin(v.x, fmin(v.y, v.z)); }
inline int light_any_gt(light_t a, light_t b) { return any(a > b); }
inline int light_equal(light_t a, light_t b) { return all(a == b); }
#endif

/* Optical depth of len voxels of light transfer-function colour c, per light channel. */
inline light_t light_depth(float4 c, float len, uint flags)
{
    return (tf_extinction(c.w) * len) * light_absorbed(c, flags);
}

/* The fraction of light passing len voxels of light transfer-function colour c, per channel. */
inline light_t light_pass(float4 c, float len, uint flags) { return exp(-light_depth(c, len, flags)); }

/* The light step of a shadow structure in voxels (the length unit of the table's alpha). */
inline float light_step_voxels(__global const UmbraFrame *F, __global const UmbraShadow *S)
{
    return S->step / F->step_ref;
}

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
