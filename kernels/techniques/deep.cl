// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/deep.cl: deep shadow maps for volume ray casting (Hadwiger, Kratz, Sigg and
 * Buehler 2006, after Lokovic and Veach 2000). One file past 800 lines, because the compression,
 * the texel's march (with its empty-space skip and a part's state) and the build kernel that
 * drives them are one algorithm; the segment table and the fixed budget, which only use it, are
 * in files of their own.
 * Three build stages, compiled (DEEP_BUILD_KERNELS=1) into the build program of
 * host/techniques/deep.c:
 *
 *   deep_lut          the pre-compressed segment table (kernels/techniques/deep_lut.cl): for
 *                     every pair of successive quantised light-ray samples (s_f, s_b) the
 *                     visibility of the segment between them,
 *                     integrated from the light transfer function at DEEP_LUT_SUBSTEPS sub-steps
 *                     (the scalar taken to vary linearly from s_f to s_b) and compressed to at
 *                     most DEEP_LUT_INTERIOR interior nodes plus the exact end value;
 *   deep_build        the map in blocks: one work-group per tile of deep_tile^2 texels; per
 *                     texel, light rays (1, or 5 pre-filtered sub-texel rays) march along a depth
 *                     grid, their visibility is compressed greedily within epsilon, and the nodes
 *                     are written into blocks of block_size node layers that the tile takes from a
 *                     pool with an atomic counter;
 *   deep_build_fixed  the same march with a fixed budget of max_nodes nodes per texel in a flat
 *                     array (for comparisons at equal memory, as in the CSSM paper), in
 *                     kernels/techniques/deep_budget.cl;
 * and the lookup (SHADOW_FACTOR) the ray caster calls for every sample, which is all the ray
 * caster's program compiles of this file.
 *
 * A node is (normalised depth, visibility per light channel): float2 with one light channel,
 * float4 (depth, r, g, b) with three. All channels share the node depths, as in Lokovic and
 * Veach's coloured deep shadow maps and in the CSSM paper's count of "four values per node". The
 * visibility before the first node is 1, between nodes linear, after the last node constant.
 *
 * Depth grid. Every light ray is cut into segments [t_k, t_k + h] (h = S->step) whose ends lie at
 * normalised depths k * h / (far - near): the same depth planes for every texel and sub-ray, so
 * the pre-filtered sub-rays can be combined segment by segment and no texel gets its own sampling
 * phase. A segment fully inside the box is integrated with the lookup table from the scalars at its
 * two ends, or (lookup_table = 0) with one sample at its midpoint, its optical depth that of the
 * shading model's extinction over the segment (kernels/common/common.cl), so a homogeneous medium
 * gives
 * exp(-sigma d) at every node with or without the table. The partial segments where a ray enters
 * or leaves the box always use the midpoint rule over their length. */

#ifndef DEEP_BUILD_KERNELS
#define DEEP_BUILD_KERNELS 0 /* the host's build program sets 1; the ray caster needs the lookup */
#endif
/* Sub-texel rays per texel (desc->prefilter, 1 or 5), a build option of the build program, not a
 * kernel argument: with the count known the compiler sizes the per-ray arrays to it and can
 * unroll the loops over the rays. The arithmetic and its order are unchanged, so the maps are
 * the same bit for bit; the gain is small, the march itself is the cost
 * (docs/performance-log.md, "Behind the kernels' comments"; issue #12). */
#ifndef DEEP_SUB_RAYS
#define DEEP_SUB_RAYS 1
#endif
#if DEEP_SUB_RAYS != 1 && DEEP_SUB_RAYS != 5
#error "DEEP_SUB_RAYS must be 1 or 5 (host/techniques/deep.c)"
#endif

/* Must match host/techniques/deep.h. */
#define DEEP_LUT_RES 256          /* quantised scalar values per table axis */
#define DEEP_LUT_INTERIOR 3       /* interior nodes per table entry, at most */
#define DEEP_LUT_NODES (DEEP_LUT_INTERIOR + 1) /* stored per entry: interior nodes + the end */
#define DEEP_LUT_SUBSTEPS 64      /* integration sub-steps per segment when building the table */
#define DEEP_LUT_TOL 1e-3f        /* an entry's tolerance when its node budget allows */
#define DEEP_MAX_SUB 5            /* sub-texel rays per texel, at most (the pre-filter's taps) */
#define DEEP_MAX_POINTS (DEEP_SUB_RAYS * DEEP_LUT_NODES) /* distinct positions in one segment */
#define DEEP_MAX_EMIT (DEEP_MAX_POINTS + 6) /* nodes one march step can emit (see deep_step) */

#if UMBRA_LIGHT_CHANNELS == 1
typedef float2 deep_node;
#define DEEP_DEPTH(n) ((n).x)
#define DEEP_VIS(n) ((n).y)
#define DEEP_NODE(z, v) ((float2)((z), (v)))
inline int deep_all_one(float v) { return v >= 1.0f; }
inline float deep_max_abs(float v) { return fabs(v); }
#else
typedef float4 deep_node;
#define DEEP_DEPTH(n) ((n).x)
#define DEEP_VIS(n) ((n).yzw)
#define DEEP_NODE(z, v) ((float4)((z), (v)))
inline int deep_all_one(float3 v) { return all(v >= (float3)(1.0f)); }
inline float deep_max_abs(float3 v) { return fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z))); }
#endif

#if DEEP_BUILD_KERNELS
/* ---- greedy compression (Lokovic and Veach's cone of slopes) ---------------------------------
 * A segment starts at the last emitted node (z0, v0). Every point fed afterwards narrows, per
 * channel, the interval [lo, hi] of slopes whose line from the origin passes within tol of it.
 * When a point would leave some channel's interval empty, the segment ends at the previous
 * point: its node gets, per channel, the slope nearest to the exact one through that point
 * (clamped into the interval), so every point of the segment stays within tol, and the next
 * segment starts there. Points are held back by one, so that the last point of a ray is fed with
 * tolerance 0: the visibility behind the volume (the ground plane's shadow) is exact.
 * Until the visibility first drops below 1 the origin slides along with the points, so empty
 * space in front of the first attenuation costs no node (the paper's "implicit" skipping). */
typedef struct DeepFit {
    float z0, zl, zh;          /* origin depth, last fed point's depth, held point's depth */
    light_t v0, vl, vh, lo, hi;
    int npts;                  /* points fed since the origin */
    int started;               /* the origin node has been emitted */
    int held;                  /* a point is held back */
} DeepFit;

inline void deep_fit_init(DeepFit *f)
{
    f->z0 = f->zl = f->zh = 0.0f;
    f->v0 = f->vl = f->vh = (light_t)(1.0f);
    f->lo = f->hi = (light_t)(0.0f);
    f->npts = 0;
    f->started = 0;
    f->held = 0;
}

/* The node that ends the current segment at the last fed point: per channel the slope nearest to
 * the exact one through that point among those that keep every point of the segment within tol
 * and put the node at or above the point (deep_fit_feed ends a segment before that becomes
 * impossible). A node never lies below the visibility it stands for, so the next segment's origin
 * is at or above every later point, each later window admits a slope <= 0, and the function never
 * rises -- not even at the last point, which is fed with tolerance 0 (with nodes allowed below
 * the curve, an exact end behind a flat stretch rose by up to tol). The fmin only absorbs
 * rounding. */
inline deep_node deep_fit_close(const DeepFit *f)
{
    float dz = f->zl - f->z0;
    light_t exact = (f->vl - f->v0) / dz;
    light_t s = fmin(clamp(fmax(exact, f->lo), f->lo, f->hi), (light_t)(0.0f));
    light_t v = clamp(f->v0 + s * dz, (light_t)(0.0f), (light_t)(1.0f));
    return DEEP_NODE(f->zl, v);
}

/* The slopes from the origin whose line passes within tol of (z0 + dz, v) and stays inside
 * [0, 1] there. The second condition keeps every node in [0, 1] without clamping a node after
 * the fact (which would move the line by more than tol at the points before it); a point's own
 * window always meets [0, 1], since v does. */
inline void deep_fit_window(const DeepFit *f, float dz, light_t v, float tol, light_t *lo,
                            light_t *hi)
{
    *lo = fmax(v - tol, (light_t)(0.0f));
    *hi = fmin(v + tol, (light_t)(1.0f));
    *lo = (*lo - f->v0) / dz;
    *hi = (*hi - f->v0) / dz;
}

/* Feeds one point with tolerance tol; appends emitted nodes to e[*n] (at most 2). Forced inline
 * with three light channels (PoCL kept it a call): the coloured 3-node build 12%-15% cheaper.
 * With one channel the call stays: inlined there, it measured 2% better on the walnut and 6%
 * worse on the bonsai (docs/performance-log.md, 2026-12-04). The same maps either way. */
#if UMBRA_LIGHT_CHANNELS == 3
#define DEEP_FIT_INLINE UMBRA_INLINE
#else
#define DEEP_FIT_INLINE inline
#endif
DEEP_FIT_INLINE void deep_fit_feed(DeepFit *f, float z, light_t v, float tol, deep_node *e, int *n)
{
    if (!f->started) {
        if (deep_all_one(v)) {
            f->z0 = z;
            return;
        }
        f->started = 1;
        f->v0 = (light_t)(1.0f);
        f->npts = 0;
        e[(*n)++] = DEEP_NODE(f->z0, f->v0);
    }
    /* Depths increase strictly by construction; a rounding tie would divide by zero. */
    z = fmax(z, f->z0 + 1e-7f * (1.0f + fabs(f->z0)));
    float dz = z - f->z0;
    light_t lo, hi;
    deep_fit_window(f, dz, v, tol, &lo, &hi);
    if (f->npts > 0) {
        /* The segment ends at the previous point when no slope keeps every point within tol, or
         * when none of those reaches up to this point (its node would lie below it). */
        light_t nlo = fmax(lo, f->lo), nhi = fmin(hi, f->hi);
        if (light_any_gt(nlo, nhi) || light_any_gt((v - f->v0) / dz, nhi)) {
            deep_node c = deep_fit_close(f);
            e[(*n)++] = c;
            f->z0 = DEEP_DEPTH(c);
            f->v0 = DEEP_VIS(c);
            f->npts = 0;
            z = fmax(z, f->z0 + 1e-7f * (1.0f + fabs(f->z0)));
            dz = z - f->z0;
            deep_fit_window(f, dz, v, tol, &lo, &hi);
        } else {
            lo = nlo;
            hi = nhi;
        }
    }
    f->lo = lo;
    f->hi = hi;
    f->zl = z;
    f->vl = v;
    f->npts++;
}

/* Adds a point (the previously held one is fed now with tolerance eps). */
inline void deep_fit_push(DeepFit *f, float z, light_t v, float eps, deep_node *e, int *n)
{
    if (f->held)
        deep_fit_feed(f, f->zh, f->vh, eps, e, n);
    f->zh = z;
    f->vh = v;
    f->held = 1;
}

/* Ends the function: the held point exactly, then the node closing the last segment (at most 3
 * nodes). A ray whose visibility never dropped emits nothing. */
inline void deep_fit_finish(DeepFit *f, deep_node *e, int *n)
{
    if (f->held)
        deep_fit_feed(f, f->zh, f->vh, 0.0f, e, n);
    f->held = 0;
    if (f->started && f->npts > 0)
        e[(*n)++] = deep_fit_close(f);
    f->npts = 0;
}

/* ---- the light-ray march --------------------------------------------------------------------
 * Pre-filter (desc->prefilter = 5): the paper casts several sub-pixel rays per texel and
 * combines their samples, but gives neither positions nor weights. We use the quincunx kernel:
 * the texel centre with weight 1/2 and its four corners with weight 1/8 each, a 5-tap
 * approximation of a tent filter one texel in radius (each corner ray is shared in weight with
 * the three neighbours that touch it). The combined visibility is the weighted sum of the
 * sub-rays' piecewise linear visibilities, evaluated exactly at the union of their node positions
 * within each segment. */
__constant float4 deep_taps[DEEP_MAX_SUB] = {
    (float4)(0.0f, 0.0f, 0.5f, 0.0f),    (float4)(-0.5f, -0.5f, 0.125f, 0.0f),
    (float4)(0.5f, -0.5f, 0.125f, 0.0f), (float4)(-0.5f, 0.5f, 0.125f, 0.0f),
    (float4)(0.5f, 0.5f, 0.125f, 0.0f)};

typedef struct DeepSub {
    float3 o, d;
    float ta, tb;   /* where the ray is inside the box */
    float w;        /* filter weight */
    float s_prev;   /* scalar at the current segment's front end, if has_prev */
    int has_prev;
    float3 xo, xd;  /* the ray in voxel coordinates (deep_point_class) */
    float t_class;  /* the last segment's back end, its class and its cell */
    int class_b;
    int3 cell_b;
    float t_cell_exit; /* where the ray leaves cell_b */
    float s_next;   /* scalar at the back end of segment k_next, sampled ahead */
    int k_next;     /* -1: none */
    light_t v;      /* visibility at the current segment's front end */
} DeepSub;

typedef struct DeepTexel {
    DeepSub sub[DEEP_SUB_RAYS];
    int k, k_end;     /* current segment, one past the last */
    float base;       /* ray parameter of depth 0 */
    float zstep;      /* normalised depth per segment */
    float z_pushed;   /* depth of the last point given to the fit */
    float eps, v_stop;
    int done;
    int owned;        /* a part (UMBRA_PART): it has marched a segment it owns */
    DeepFit fit;
} DeepTexel;

inline void deep_texel_init(DeepTexel *T, __global const UmbraShadow *S, VolGeom g, int2 texel,
                            float eps)
{
    const float h = S->step;
    float ta_min = UMBRA_INF, tb_max = -UMBRA_INF;
    T->base = 0.0f;
    for (int i = 0; i < DEEP_SUB_RAYS; ++i) {
        float4 tap = DEEP_SUB_RAYS == 1 ? (float4)(0.0f, 0.0f, 1.0f, 0.0f) : deep_taps[i];
        float2 xy = convert_float2(texel) + 0.5f + tap.xy;
        float3 o, d;
        float2 t = ls_texel_ray(S, g, xy, &o, &d);
        if (i == 0)
            T->base = S->near_far[0] - (S->ls_mode == UMBRA_LS_ORTHO ? dot(o, F3(S->ls_w)) : 0.0f);
        DeepSub *s = &T->sub[i];
        s->o = o;
        s->d = d;
        s->w = tap.z;
        s->v = (light_t)(1.0f);
        s->has_prev = 0;
        s->s_prev = 0.0f;
        s->s_next = 0.0f;
        s->k_next = -1;
        s->xo = world_to_voxel(g, o);
        s->xd = d * g.inv_spacing;
        s->t_class = -UMBRA_INF;
        s->class_b = 0;
        s->cell_b = (int3)(0);
        s->t_cell_exit = -UMBRA_INF;
        /* A ray that misses (or grazes) the box keeps an empty interval and its weight: lit. */
        s->ta = t.x;
        s->tb = (t.y > t.x && isfinite(t.x) && isfinite(t.y)) ? t.y : t.x;
        if (s->tb > s->ta) {
            ta_min = fmin(ta_min, s->ta);
            tb_max = fmax(tb_max, s->tb);
        }
    }
    /* Ray parameter base + (k + x) h lies at ls_depth (k + x) * zstep on every sub-ray: the
     * orthographic rays share their start plane, the perspective / octahedral ones the light. */
    T->zstep = h * S->near_far[2];
    T->eps = eps;
    T->v_stop = fmax(0.5f * eps, 1e-4f);
    T->z_pushed = -UMBRA_INF;
    T->owned = 0;
    deep_fit_init(&T->fit);
    T->done = !(tb_max > ta_min);
    T->k = T->k_end = 0;
    if (!T->done) {
        T->k = (int)floor((ta_min - T->base) / h);
        T->k_end = (int)ceil((tb_max - T->base) / h);
        T->k = max(T->k, 0);
        T->done = T->k >= T->k_end;
    }
}

/* A sub-ray's visibility within the current segment: (x, v) points after the implicit (0, v0),
 * constant after the last. */
typedef struct DeepPoints {
    float x[DEEP_LUT_NODES];
    light_t v[DEEP_LUT_NODES];
    int n;
} DeepPoints;

inline light_t deep_points_eval(const DeepPoints *p, light_t v0, float x)
{
    float xp = 0.0f;
    light_t vp = v0;
    for (int j = 0; j < p->n; ++j) {
        if (x <= p->x[j]) {
            float w = p->x[j] > xp ? (x - xp) / (p->x[j] - xp) : 1.0f;
            return mix(vp, p->v[j], clamp(w, 0.0f, 1.0f));
        }
        xp = p->x[j];
        vp = p->v[j];
    }
    return vp;
}

/* Where voxel position x lies for the empty-space test: 0 in a brick the light transfer function
 * leaves empty, 1 in an invisible sub-cell of a non-empty brick, 2 in a visible sub-cell; *cell
 * is the sub-cell's index on the whole grid of sub-cells (brick b's cell j: b CELLS + j). Cell j
 * of brick b covers the positions [b B + j C, b B + (j + 1) C) along each axis, C = ceil(B /
 * UMBRA_BRICK_CELLS), the border cells on to infinity (host/volume.c, compute_cells). Located
 * with the reciprocals of B and C (inv_B, inv_C) instead of divisions, last = (B - 1) / C
 * given, and from the sub-ray in voxel coordinates: a point within rounding of a face may be
 * counted to either side, as the threshold map's and CSSM's walks count theirs. Truncation stands
 * for floor: they differ only below 0, which the clamp takes to 0 either way (and x lies in the
 * box, far from the int range). In its earlier form (a division and floor() per axis, and both
 * ends located afresh every step) the test was a large part of a deep build in a profile;
 * this one and the cache in deep_step made builds cheaper (docs/performance.md; issue #12). */
inline int deep_point_class(VolGeom g, __global const ulong *cells, float3 x, float inv_B,
                            float inv_C, int last, int3 *cell)
{
    const int B = g.brick_size;
    const int3 b = clamp(convert_int3(x * inv_B), (int3)(0), g.bricks - 1);
    const int3 c =
        clamp(convert_int3((x - convert_float3(b * B)) * inv_C), (int3)(0), (int3)(last));
    *cell = b * UMBRA_BRICK_CELLS + c;
    const ulong m = cells[(b.z * g.bricks.y + b.y) * g.bricks.x + b.x];
    if (!m)
        return 0;
    const int bit = (c.z * UMBRA_BRICK_CELLS + c.y) * UMBRA_BRICK_CELLS + c.x;
    return 1 + (int)((m >> bit) & 1UL);
}

/* The ray parameter at which xo + t xd (a sub-ray in voxel coordinates) leaves sub-cell `cell`
 * (deep_point_class's index of it), or with whole set the brick that holds it. From the index
 * the empty-space test found, not the position located afresh: located anew (with a division
 * and a floor, in world coordinates), a point within rounding of a face could be put in the
 * cell beyond it, and the march jumped to that cell's exit over a cell it had not tested (one
 * device's map then differed from the march without the skip by 1.5e-4 in the image of a
 * 512^3 volume, docs/distributed.md). The border cells and bricks extend to infinity. */
inline float deep_exit(VolGeom g, float3 xo, float3 xd, int3 cell, int whole)
{
    const int B = g.brick_size, C = g.cell_size, last = (B - 1) / C;
    const int3 b = cell / UMBRA_BRICK_CELLS, c = cell - b * UMBRA_BRICK_CELLS;
    const int3 lo_c = whole ? (int3)(0) : c, hi_c = whole ? (int3)(last) : c;
    float3 lo = convert_float3(b * B + lo_c * C);
    float3 hi = convert_float3(b * B + min((hi_c + 1) * C, (int3)(B)));
    lo = select(lo, (float3)(-UMBRA_INF), (b == (int3)(0)) & (lo_c == (int3)(0)));
    hi = select(hi, (float3)(UMBRA_INF), (b == g.bricks - 1) & (hi_c == (int3)(last)));
    float3 t = select((lo - xo) / xd, (hi - xo) / xd, xd > 0.0f);
    t = select(t, (float3)(UMBRA_INF), xd == 0.0f);
    return fmin(fmin(t.x, t.y), t.z);
}

inline int deep_quant(float s)
{
    return (int)(clamp(s, 0.0f, 1.0f) * (float)(DEEP_LUT_RES - 1) + 0.5f);
}

/* Marches one segment (or jumps over empty bricks or sub-cells) and feeds the fit; writes the emitted nodes
 * to e and returns their number (at most DEEP_MAX_EMIT: one per distinct position, one for the
 * gap point, one for the fit's first node, three when the ray ends). Sets T->done at the end.
 * Always inlined: called, it kept the texel's state in memory, and the build was slower on PoCL
 * (docs/performance-log.md, "Behind the kernels' comments"). */
UMBRA_INLINE int deep_step(DeepTexel *T, __global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                           __global const float4 *light_tf, __global const ulong *light_cells,
                           __global const UmbraShadow *S, __global const deep_node *lut,
                           uint use_lut, deep_node *e)
{
    int ne = 0;
    if (T->done)
        return 0;
#if UMBRA_MIXED
    use_lut = 0u; /* the segment table is over one transfer function (host/techniques/deep.c) */
#endif
    const float h = S->step;
    const uint n_tf = F->light_tf_size, flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    /* t1 as the next segment's t0, not t0 + h: the two ends meet exactly (the class cache). */
    const float t0 = T->base + (float)T->k * h, t1 = T->base + (float)(T->k + 1) * h;
    const float inv_B = 1.0f / (float)g.brick_size, inv_C = 1.0f / (float)g.cell_size;
    const int last_cell = (g.brick_size - 1) / g.cell_size;

#if UMBRA_PART
    /* A part (host/part_render.c; one sub-ray, prefilter 1) marches the segments whose midpoint
     * its core owns, going on from the whole march state the part before it on the ray left
     * (deep_state_load: the visibility and the fit, held point and open segment included): the
     * same segments, samples, points and fit as one device's march, so the parts' pieces join
     * into one device's function node for node. The segments it owns are consecutive (the core
     * is convex): the first segment in the box after them hands the ray on unfinished; where
     * the ray ends (past its last segment, or its light below v_stop) the fit is finished here,
     * as on one device. */
    {
        const DeepSub *s0 = &T->sub[0];
        const float a = fmax(t0, s0->ta), b = fmin(t1, s0->tb);
        const int inside = b > a;
        if (inside ? !part_owns(F, world_to_voxel(g, s0->o + (0.5f * (a + b)) * s0->d))
                   : !T->owned) {
            if (T->owned) {
                T->done = 1; /* handed on: the next part on the ray goes on from the state */
                return 0;
            }
            T->k++;
            T->done = T->k >= T->k_end;
            return 0;
        }
        T->owned = 1;
    }
#endif
    DeepPoints pts[DEEP_SUB_RAYS];
    light_t v_front[DEEP_SUB_RAYS]; /* each sub-ray's visibility at the segment's front end */
    light_t v_start = (light_t)(0.0f), v_end = (light_t)(0.0f);
    /* flat: every point of every sub-ray leaves its visibility as it was at the front end. */
    int any_points = 0, flat = 1, all_empty = 1, all_cells_empty = 1;
    for (int i = 0; i < DEEP_SUB_RAYS; ++i) {
        DeepSub *s = &T->sub[i];
        DeepPoints *p = &pts[i];
        p->n = 0;
        v_front[i] = s->v;
        v_start += s->w * s->v;
        float a = fmax(t0, s->ta), b = fmin(t1, s->tb);
        if (!(b > a)) {
            s->has_prev = 0;
            v_end += s->w * s->v;
            continue;
        }
        const float3 pa = s->o + a * s->d, pb = s->o + b * s->d;
        if (skip) {
            /* The front end's class is the previous segment's back end's when the two are the
             * same point (t1 is computed as the next t0 is, so they are, segment after segment). */
            const int chained = a == s->t_class;
            int3 ca = s->cell_b, cb = s->cell_b;
            const int ka = chained ? s->class_b
                                   : deep_point_class(g, light_cells, s->xo + a * s->xd, inv_B,
                                                      inv_C, last_cell, &ca);
            /* The back end is still in the front end's sub-cell while it lies before that
             * cell's exit along the ray: its class is then the front end's, and only a back end
             * that left the cell is located and tested (its cell's exit taken with it). A cell
             * is cell_size voxels across (4 at the default bricks), so most segments locate
             * nothing: builds 2%-8% cheaper, the maps the same bit for bit
             * (docs/performance-log.md, 2026-12-04). As with the located point, a back end
             * within rounding of the exit counts to either side. */
            int kb = s->class_b;
            if (!chained || !(b < s->t_cell_exit)) {
                kb = deep_point_class(g, light_cells, s->xo + b * s->xd, inv_B, inv_C, last_cell,
                                      &cb);
                s->t_cell_exit = deep_exit(g, s->xo, s->xd, cb, 0);
            }
            s->t_class = b;
            s->class_b = kb;
            s->cell_b = cb;
            /* The segment lies in its ends' sub-cells only if they are one cell or share a face
             * (two face neighbours make a box); one that cuts across an edge or a corner passes
             * through a third, which may be visible, and is marched. With that the skip is
             * exact: the march that does not skip gives such a segment the same visibility, and
             * a part (which does not skip) the same map. */
            const uint3 dc = abs_diff(ca, cb);
            const int within = dc.x + dc.y + dc.z <= 1u;
            if (within && ka == 0 && kb == 0) {
                /* Both ends in bricks the light transfer function leaves empty: transparent,
                 * and (if every sub-ray is) the march may jump to the bricks' exits below. */
                s->has_prev = 0;
                v_end += s->w * s->v;
                continue;
            }
            if (within && ka < 2 && kb < 2) {
                /* Both ends in sub-cells it leaves empty (kernels/common/umbra_shared.h):
                 * transparent too, as the threshold map's and CSSM's walks take them. Half the
                 * walnut's segments in non-empty bricks are, and each saved a sample, a table
                 * entry and a step of the fit. If every sub-ray is, the march jumps to the
                 * cells' exits. */
                all_empty = 0;
                s->has_prev = 0;
                v_end += s->w * s->v;
                continue;
            }
        }
        all_empty = 0;
        all_cells_empty = 0;
        const int full = a <= t0 && b >= t1;
        if (full && use_lut) {
            float sf = s->has_prev ? s->s_prev : sample_volume(vol, g, pa);
            float sb = s->k_next == T->k ? s->s_next : sample_volume(vol, g, pb);
            /* The next segment's back end, sampled before this segment's table entry and fit so
             * that its loads overlap them; at the position the next step computes (its t1), so
             * the value is the one it would sample. */
            const float t1_next = T->base + (float)(T->k + 2) * h;
            s->k_next = -1;
            if (t1_next <= s->tb) {
                s->s_next = sample_volume(vol, g, s->o + t1_next * s->d);
                s->k_next = T->k + 1;
            }
            s->s_prev = sb;
            s->has_prev = 1;
            size_t pair = (size_t)deep_quant(sf) * DEEP_LUT_RES + (size_t)deep_quant(sb);
            __global const deep_node *entry = lut + pair * DEEP_LUT_NODES;
            for (int j = 0; j < DEEP_LUT_NODES; ++j) {
                deep_node nd = entry[j];
                if (j < DEEP_LUT_NODES - 1 && DEEP_DEPTH(nd) >= 1.0f)
                    continue; /* an unused interior slot */
                p->x[p->n] = DEEP_DEPTH(nd);
                p->v[p->n] = s->v * DEEP_VIS(nd);
                p->n++;
            }
        } else {
            s->has_prev = 0;
            float3 mid = s->o + 0.5f * (a + b) * s->d;
            const float4 c = light_sample(F, vol, g, light_tf, n_tf, mid);
            float xa = (a - t0) / h, xb = (b - t0) / h;
            if (xa > 0.0f) {
                p->x[p->n] = xa;
                p->v[p->n] = s->v;
                p->n++;
            }
            p->x[p->n] = fmin(xb, 1.0f);
            p->v[p->n] = s->v * light_pass(c, light_step_voxels(F, S) * ((b - a) / h), flags);
            p->n++;
        }
        any_points = 1;
        for (int j = 0; j < p->n; ++j)
            flat &= light_equal(p->v[j], v_front[i]);
        s->v = p->v[p->n - 1];
        v_end += s->w * s->v;
    }

    /* A flat segment gives the fit nothing, as a segment the empty-space skip jumps over gives
     * it nothing: the next segment that is not flat starts with a point at its front end
     * (below), and the fit's piece across the flat stretch is within epsilon of both its ends,
     * so of the constant visibility between. A march that skips (one device) and one that does
     * not (parts, UMBRA_FLAG_SKIP_EMPTY off) so feed the fit the same points, and their maps
     * agree node for node at any epsilon (tests/test_deep.c, test_skipping_changes_nothing;
     * tests/test_part_maps.c). */
    if (any_points && !flat) {
        /* A segment that follows empty or flat ones starts with a point at its front end, so
         * the fit sees the flat stretch before it as flat. */
        float z_front = (float)T->k * T->zstep;
        if (z_front > T->z_pushed) {
            deep_fit_push(&T->fit, z_front, v_start, T->eps, e, &ne);
            T->z_pushed = z_front;
        }
#if DEEP_SUB_RAYS == 1
        /* One ray: its points are in order (a table entry's interior nodes, then its end; or
         * the partial segment's entry and end), and the visibility at each is the point's own,
         * taken as it is rather than interpolated to it from the point before (a division and
         * a search per point, docs/performance-log.md, 2026-12-04). */
        float last = -1.0f;
        for (int q = 0; q < pts[0].n; ++q) {
            const float x = pts[0].x[q];
            if (!(x > last + 1e-6f) || !(x > 0.0f))
                continue;
            last = x;
            const float z = ((float)T->k + x) * T->zstep;
            deep_fit_push(&T->fit, z, pts[0].v[q], T->eps, e, &ne);
            T->z_pushed = z;
        }
#else
        /* The union of the sub-rays' positions, sorted, without repeats, and at each the
         * filter-weighted sum of the sub-rays' visibilities there. */
        float xs[DEEP_MAX_POINTS];
        int nx = 0;
        for (int i = 0; i < DEEP_SUB_RAYS; ++i)
            for (int j = 0; j < pts[i].n; ++j) {
                float x = pts[i].x[j];
                int q = nx;
                while (q > 0 && xs[q - 1] > x) {
                    xs[q] = xs[q - 1];
                    --q;
                }
                xs[q] = x;
                ++nx;
            }
        float last = -1.0f;
        for (int q = 0; q < nx; ++q) {
            float x = xs[q];
            if (!(x > last + 1e-6f) || !(x > 0.0f))
                continue;
            last = x;
            light_t v = (light_t)(0.0f);
            for (int i = 0; i < DEEP_SUB_RAYS; ++i)
                v += T->sub[i].w * deep_points_eval(&pts[i], v_front[i], x);
            float z = ((float)T->k + x) * T->zstep;
            deep_fit_push(&T->fit, z, v, T->eps, e, &ne);
            T->z_pushed = z;
        }
#endif
    }

    /* Next segment, or a jump over bricks (or sub-cells) that are empty for every sub-ray. The
     * segments jumped over lie in those bricks (cells), so the march would have skipped them one
     * by one. */
    int k_next = T->k + 1;
    if (skip && !all_empty && all_cells_empty) {
        float jump = (float)T->k_end;
        for (int i = 0; i < DEEP_SUB_RAYS; ++i) {
            const DeepSub *s = &T->sub[i];
            if (!(s->tb > s->ta) || s->tb <= t1)
                continue;
            float tj;
            if (s->ta > t1)
                tj = s->ta;
            else if (s->t_class != t1)
                tj = t1; /* t1 untested (the ray's entry): no jump */
            else
                tj = fmin(s->t_cell_exit, s->tb); /* the exit of cell_b (above) */
            /* A thousandth of a step short of the exit: a rounded exit past a segment's end must
             * not jump over a segment whose back end already lies in the next cell. */
            jump = fmin(jump, floor((tj - T->base) / h - 1e-3f));
        }
        if (jump > (float)k_next)
            k_next = (int)jump;
    }
    if (skip && all_empty) {
        float jump = (float)T->k_end;
        for (int i = 0; i < DEEP_SUB_RAYS; ++i) {
            const DeepSub *s = &T->sub[i];
            if (!(s->tb > s->ta) || s->tb <= t1)
                continue;
            float tj;
            if (s->ta > t1)
                tj = s->ta; /* not entered yet: its entry */
            else if (s->t_class != t1)
                tj = t1;
            else
                tj = fmin(deep_exit(g, s->xo, s->xd, s->cell_b, 1), s->tb);
            /* A thousandth of a step short, as for the cells above. */
            jump = fmin(jump, floor((tj - T->base) / h - 1e-3f));
        }
        if (jump > (float)k_next)
            k_next = (int)jump;
    }
    T->k = k_next;
    if (T->k >= T->k_end || light_max(v_end) < T->v_stop) {
        deep_fit_finish(&T->fit, e, &ne);
        T->done = 1;
    }
    return ne;
}

/* ---- building the map ------------------------------------------------------------------------
 * deep_build: one work-group per tile of deep_tile x deep_tile texels (local size = tile). The
 * tile's texels march in passes, as the paper's multi-pass fragment programs do: before each pass
 * every texel marches until it has a node to write or its ray ends, and the work-group checks
 * (local flag, barrier) whether any of its texels has a node;
 * if so, one work-item takes the next block from the pool (atomic_inc on counter[0]) and links it
 * into the tile's chain (head[tile], then next[block]; -1 ends a chain), and every texel writes
 * up to block_size nodes into its own lane of the block's layers. A tile whose rays have all
 * finished stops taking blocks. A block index at or beyond capacity is counted but not written:
 * the host reads the counter back, grows the pool to what was asked for and builds again, so no
 * node is ever dropped silently. A tile that is handed a block index at or beyond limit (the
 * most blocks the device could ever hold) stops at once: the host then reports the map as too
 * large without the rest of the build's work. Every work-item reaches every barrier (texels
 * outside the map take part with nothing to march). */
#if UMBRA_PART
/* A part's march state per texel: DEEP_PART_FLOATS floats in the order of
 * kernels/techniques/deep_shared.h (host/part_render.c checks an import against it). */
#define DEEP_PART_FLOATS DEEP_PART_STATE_FLOATS(UMBRA_LIGHT_CHANNELS)
#if UMBRA_LIGHT_CHANNELS == 1
#define DEEP_LOAD_V(s) ((s)[0])
#define DEEP_STORE_V(s, v) ((s)[0] = (v))
#else
#define DEEP_LOAD_V(s) vload3(0, (s))
#define DEEP_STORE_V(s, v) vstore3((v), 0, (s))
#endif

inline void deep_state_load(DeepTexel *T, __global const float *state, int texel)
{
    const int C = UMBRA_LIGHT_CHANNELS;
    __global const float *s = state + (size_t)texel * DEEP_PART_FLOATS;
    DeepFit *f = &T->fit;
    T->sub[0].v = DEEP_LOAD_V(s);
    f->z0 = s[C];
    f->v0 = DEEP_LOAD_V(s + C + 1);
    f->zl = s[2 * C + 1];
    f->vl = DEEP_LOAD_V(s + 2 * C + 2);
    f->zh = s[3 * C + 2];
    f->vh = DEEP_LOAD_V(s + 3 * C + 3);
    f->lo = DEEP_LOAD_V(s + 4 * C + 3);
    f->hi = DEEP_LOAD_V(s + 5 * C + 3);
    f->npts = (int)s[6 * C + 3];
    f->started = (int)s[6 * C + 4];
    f->held = (int)s[6 * C + 5];
    T->z_pushed = s[6 * C + 6];
}

inline void deep_state_store(__global float *state, int texel, const DeepTexel *T)
{
    const int C = UMBRA_LIGHT_CHANNELS;
    __global float *s = state + (size_t)texel * DEEP_PART_FLOATS;
    const DeepFit *f = &T->fit;
    DEEP_STORE_V(s, T->sub[0].v);
    s[C] = f->z0;
    DEEP_STORE_V(s + C + 1, f->v0);
    s[2 * C + 1] = f->zl;
    DEEP_STORE_V(s + 2 * C + 2, f->vl);
    s[3 * C + 2] = f->zh;
    DEEP_STORE_V(s + 3 * C + 3, f->vh);
    DEEP_STORE_V(s + 4 * C + 3, f->lo);
    DEEP_STORE_V(s + 5 * C + 3, f->hi);
    s[6 * C + 3] = (float)f->npts;
    s[6 * C + 4] = (float)f->started;
    s[6 * C + 5] = (float)f->held;
    s[6 * C + 6] = T->z_pushed;
}
#endif

__kernel void deep_build(__global const UmbraFrame *F, VOLUME_PARAM,
                         __global const float4 *view_tf, __global const float4 *light_tf,
                         __global const uchar *view_bricks, __global const ulong *light_cells,
                         __global const UmbraShadow *S, __global const UmbraDeep *D,
                         __global const deep_node *lut, uint use_lut, float eps,
                         __global deep_node *nodes,
                         __global int *head, __global int *next, __global uint *counts,
                         volatile __global uint *counter, uint capacity, uint limit
#if UMBRA_PART
                         , __global float *part_state
#endif
                         )
{
    (void)view_tf;
    (void)view_bricks;
    const int T = (int)D->tile;
    const int lane = (int)get_local_id(1) * T + (int)get_local_id(0);
    const int n = (int)S->map_size;
    const int gx = (int)get_global_id(0), gy = (int)get_global_id(1);
    /* From the global id, not the group id: the host may launch the map in bands of rows with a
     * global offset (host/renderer.c, umbra__run_2d). */
    const int tile = (gy / T) * (int)D->tiles_per_row + gx / T;
    const uint K = D->block_size;
    const size_t T2 = (size_t)(T * T);
    const VolGeom g = vol_geom(F);
    __local int l_block;
    __local int l_more;

    DeepTexel st;
    st.done = 1;
    if (gx < n && gy < n) {
        deep_texel_init(&st, S, g, (int2)(gx, gy), eps);
#if UMBRA_PART
        /* The march state reaching the part on this ray (host/part_render.c); a ray whose light
         * fell below the march's stop before it is done (and finished), as one device's march
         * stopped. */
        deep_state_load(&st, part_state, gy * n + gx);
        if (light_max(st.sub[0].v) < st.v_stop)
            st.done = 1;
#endif
    }
    deep_node pend[DEEP_MAX_EMIT];
    int npend = 0, ppos = 0;
    uint written = 0, layer_end = 0;
    int prev_block = -1;
    if (lane == 0)
        head[tile] = -1;
    for (;;) {
        /* March until a node is ready or the ray is done: a ray that still runs may emit
         * nothing more (transparent to its end), and must not make the tile take a block. */
        while (ppos == npend && !st.done) {
            npend = deep_step(&st, F, vol, g, light_tf, light_cells, S, lut, use_lut, pend);
            ppos = 0;
        }
        if (lane == 0)
            l_more = 0;
        barrier(CLK_LOCAL_MEM_FENCE);
        if (ppos < npend)
            l_more = 1;
        barrier(CLK_LOCAL_MEM_FENCE);
        if (!l_more)
            break; /* the same value for the whole work-group */
        if (lane == 0) {
            uint b = atomic_inc(counter);
            l_block = b < limit ? (int)b : -1;
            if (b < capacity) {
                if (prev_block < 0)
                    head[tile] = (int)b;
                else if ((uint)prev_block < capacity)
                    next[prev_block] = (int)b;
                next[b] = -1;
            }
            prev_block = (int)b;
        }
        barrier(CLK_LOCAL_MEM_FENCE);
        const int block = l_block;
        if (block < 0)
            break; /* beyond the limit: the host fails the build (the same for the work-group) */
        layer_end += K;
        while (written < layer_end) {
            if (ppos == npend) {
                if (st.done)
                    break;
                npend = deep_step(&st, F, vol, g, light_tf, light_cells, S, lut, use_lut, pend);
                ppos = 0;
                continue;
            }
            if ((uint)block < capacity)
                nodes[((size_t)block * K + (written + K - layer_end)) * T2 + (size_t)lane] =
                    pend[ppos];
            ++ppos;
            ++written;
        }
    }
    if (gx < n && gy < n) {
        counts[gy * n + gx] = written;
#if UMBRA_PART
        deep_state_store(part_state, gy * n + gx, &st);
#endif
    }
}

/* deep_build_fixed, the build with a fixed node budget, is in kernels/techniques/deep_budget.cl
 * (appended after this file in the build program only). */

#endif /* DEEP_BUILD_KERNELS */

/* ---- lookup ----------------------------------------------------------------------------------
 * The paper's lookup: the sample's nearest texel (no bilinear filtering of four visibilities, as
 * in the paper: pre-filtering at build time does the anti-aliasing), its node list found through
 * the layout (head / next / counts), searched linearly for the sample's depth and interpolated
 * linearly. The search starts at the node the previous sample of the same view ray ended at
 * (ShadowRay), in the same texel or, since neighbouring texels have similar node depths, in a new
 * one; when that node lies deeper than the sample (the view ray moved toward the light) the search
 * restarts at the texel's first node. */
#define SHADOW_KERNEL_PARAMS                                                                   \
    , __global const UmbraDeep *D, __global const deep_node *deep_nodes,                      \
        __global const int *deep_head, __global const int *deep_next,                          \
        __global const uint *deep_counts

typedef struct ShadowRay {
    int texel; /* map texel of the last lookup, -1 before the first */
    int n;     /* index of the node the last lookup interpolated from */
    int block; /* the block holding node n (blocked layout) */
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr)
{
    sr->texel = -1;
    sr->n = 0;
    sr->block = -1;
}

inline deep_node deep_fetch(__global const deep_node *nodes, int fixed, size_t texel_base,
                            int block, int j, uint K, size_t T2, int lane)
{
    if (fixed)
        return nodes[texel_base + (size_t)j];
    return nodes[((size_t)block * K + (size_t)((uint)j % K)) * T2 + (size_t)lane];
}

inline float3 deep_shadow(__global const UmbraShadow *S, __global const UmbraDeep *D, VolGeom g,
                          __global const deep_node *nodes, __global const int *head,
                          __global const int *next, __global const uint *counts, ShadowRay *sr,
                          float3 p)
{
    float3 m = ls_world_to_map(S, p);
    int2 t;
    if (!isfinite(m.z) || !ls_base_texel(S, m.xy, &t))
        return (float3)(1.0f);
    t = ls_box_texel(S, g, p, t);
    if (!ls_fold_texel(S, &t))
        return (float3)(1.0f);
    const int n = (int)S->map_size;
    const int idx = t.y * n + t.x;
    const int fixed = D->max_nodes > 0u;
    const uint K = D->block_size;
    /* The tile is a power of two (host/techniques/deep.c): shifts and masks, not four divisions. */
    const int T = (int)D->tile, shift = 31 - (int)clz((uint)T);
    const size_t T2 = (size_t)(T * T);
    const int tile = (t.y >> shift) * (int)D->tiles_per_row + (t.x >> shift);
    const int lane = ((t.y & (T - 1)) << shift) + (t.x & (T - 1));
    const size_t base = (size_t)idx * D->max_nodes;
    const int count = fixed ? (int)D->max_nodes : (int)counts[idx];
    const float d = m.z;
    if (count <= 0)
        return (float3)(1.0f);
    if (sr->texel != idx) {
        sr->texel = idx;
        sr->n = min(sr->n, count - 1);
        if (!fixed) {
            int b = head[tile];
            for (int q = sr->n / (int)K; q > 0; --q)
                b = next[b];
            sr->block = b;
        }
    }
    deep_node a = deep_fetch(nodes, fixed, base, sr->block, sr->n, K, T2, lane);
    if (d < DEEP_DEPTH(a) && sr->n > 0) {
        sr->n = 0;
        sr->block = fixed ? 0 : head[tile];
        a = deep_fetch(nodes, fixed, base, sr->block, 0, K, T2, lane);
    }
    if (d <= DEEP_DEPTH(a))
        return sr->n == 0 ? (float3)(1.0f) : light_rgb(DEEP_VIS(a));
    for (;;) {
        const int j = sr->n + 1;
        if (j >= count)
            return light_rgb(DEEP_VIS(a));
        int b = sr->block;
        if (!fixed && (uint)j % K == 0u)
            b = next[b];
        deep_node c = deep_fetch(nodes, fixed, base, b, j, K, T2, lane);
        if (DEEP_DEPTH(c) >= d) {
            float span = DEEP_DEPTH(c) - DEEP_DEPTH(a);
            float w = span > 0.0f ? clamp((d - DEEP_DEPTH(a)) / span, 0.0f, 1.0f) : 1.0f;
            return light_rgb(mix(DEEP_VIS(a), DEEP_VIS(c), w));
        }
        a = c;
        sr->n = j;
        sr->block = b;
    }
}

#define SHADOW_FACTOR(sr, p)                                                                   \
    deep_shadow(S, D, g, deep_nodes, deep_head, deep_next, deep_counts, &(sr), (p))
