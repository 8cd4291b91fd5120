// SPDX-License-Identifier: Apache-2.0
/* kernels/common/lightspace.cl: the light-space map projection shared by the shadow-map techniques.
 * host/lightspace.c fits it to the volume's box; see UMBRA_LS_* in common/umbra_shared.h.
 *
 * Map coordinates: x, y in texels (texel i covers [i, i+1)), depth in [0,1] between the box's
 * nearest and farthest points along the light. Orthographic depth is the distance along the light
 * direction; perspective and octahedral depth is the distance from the light. */

inline float2 ls_oct_encode(float3 d)
{
    d /= (fabs(d.x) + fabs(d.y) + fabs(d.z));
    float2 e = d.xy;
    if (d.z < 0.0f) {
        float2 s = (float2)(e.x >= 0.0f ? 1.0f : -1.0f, e.y >= 0.0f ? 1.0f : -1.0f);
        e = (1.0f - fabs(e.yx)) * s;
    }
    return e;
}

inline float3 ls_oct_decode(float2 e)
{
    float3 d = (float3)(e, 1.0f - fabs(e.x) - fabs(e.y));
    if (d.z < 0.0f) {
        float2 s = (float2)(d.x >= 0.0f ? 1.0f : -1.0f, d.y >= 0.0f ? 1.0f : -1.0f);
        d.xy = (1.0f - fabs(d.yx)) * s;
    }
    return normalize(d);
}

/* World point -> (x texel, y texel, depth01). */
UMBRA_INLINE float3 ls_world_to_map(__global const UmbraShadow *S, float3 p)
{
    float3 u = F3(S->ls_u), v = F3(S->ls_v), w = F3(S->ls_w);
    float n = (float)S->map_size;
    float2 a;
    float depth;
    if (S->ls_mode == UMBRA_LS_ORTHO) {
        a = (float2)(dot(p, u), dot(p, v));
        depth = dot(p, w);
    } else {
        float3 q = p - F3(S->ls_origin);
        float3 l = (float3)(dot(q, u), dot(q, v), dot(q, w));
        depth = umbra_length(q);
        if (S->ls_mode == UMBRA_LS_PERSPECTIVE)
            a = l.z > 0.0f ? l.xy / l.z : (float2)(-UMBRA_INF, -UMBRA_INF);
        else
            a = depth > 0.0f ? ls_oct_encode(l / depth) : (float2)(0.0f);
    }
    float2 xy = (a - (float2)(S->ls_window[0], S->ls_window[1])) *
                (float2)(S->ls_window[2], S->ls_window[3]) * n;
    return (float3)(xy, (depth - S->near_far[0]) * S->near_far[2]);
}

/* The light ray through map position (x, y) in texels: origin o, unit direction d, and the
 * parameter interval [t.x, t.y] where it crosses the volume's box and the clip region (empty if
 * t.y <= t.x). Depth at
 * parameter t is ls_depth(S, o, t). */
inline float2 ls_texel_ray(__global const UmbraShadow *S, VolGeom g, float2 xy, float3 *o, float3 *d)
{
    float3 u = F3(S->ls_u), v = F3(S->ls_v), w = F3(S->ls_w);
    float2 a = xy / (float)S->map_size / (float2)(S->ls_window[2], S->ls_window[3]) +
               (float2)(S->ls_window[0], S->ls_window[1]);
    if (S->ls_mode == UMBRA_LS_ORTHO) {
        *o = a.x * u + a.y * v + (S->near_far[0] - 1.0f) * w;
        *d = w;
    } else {
        *o = F3(S->ls_origin);
        if (S->ls_mode == UMBRA_LS_PERSPECTIVE) {
            *d = normalize(a.x * u + a.y * v + w);
        } else {
            float3 l = ls_oct_decode(a);
            *d = l.x * u + l.y * v + l.z * w;
        }
    }
    /* The clip region's part: a clipped region casts no shadow in any map. */
    float2 t = clip_interval(&S->clip, *o, *d, ray_box(*o, *d, g.box_min, g.box_max));
    t.x = fmax(t.x, 0.0f);
    return t;
}

/* Normalised depth of the point at parameter t on a ray from ls_texel_ray. */
inline float ls_depth(__global const UmbraShadow *S, float3 o, float t)
{
    float along = S->ls_mode == UMBRA_LS_ORTHO ? dot(o, F3(S->ls_w)) + t : t;
    return (along - S->near_far[0]) * S->near_far[2];
}

/* ---- filtered map lookups (threshold and CSSM) -------------------------------------------------
 * A lookup reads m texels around the sample's texel at these offsets and averages the m binary
 * tests (the CSSM paper's Table 2; the threshold map uses the same sets, so softness compares
 * fairly). The first m entries form the set for m = 1, 7, 13, 21:
 *   13: the paper's {(0,0), (+-3,+-3), (+-4,0), (0,+-4), (+-7,0), (0,+-7)};
 *    7: its seven smallest: (0,0), the four axis taps at radius 4 and, of the four diagonals at
 *       radius 4.24, the point-symmetric pair (3,3), (-3,-3), so the set stays centred on the
 *       sample (no shift of the shadow): which pair is a free choice, the paper does not say;
 *   21: the 13 plus eight larger: (+-5,+-5) (radius 7.07) completing the ring at radius 7 and
 *       (+-10,0), (0,+-10), a ring at radius 10. */
#define LS_MAX_TAPS 21
/* The stored depth of a texel whose ray is never stopped. Not 1: points beyond the box's far
 * extent (the ground plane) have depths above 1 and must still count as lit there. */
#define LS_DEPTH_NEVER FLT_MAX
__constant int2 ls_taps[LS_MAX_TAPS] = {
    (int2)(0, 0),   (int2)(4, 0),   (int2)(-4, 0),  (int2)(0, 4),   (int2)(0, -4),
    (int2)(3, 3),   (int2)(-3, -3), (int2)(3, -3),  (int2)(-3, 3),  (int2)(7, 0),
    (int2)(-7, 0),  (int2)(0, 7),   (int2)(0, -7),  (int2)(5, 5),   (int2)(-5, -5),
    (int2)(5, -5),  (int2)(-5, 5),  (int2)(10, 0),  (int2)(-10, 0), (int2)(0, 10),
    (int2)(0, -10)};

/* The sample's texel, or false where the map position is not finite or far outside the map
 * (behind a perspective light, for instance): such a point is not covered and counts as lit. */
inline bool ls_base_texel(__global const UmbraShadow *S, float2 xy, int2 *texel)
{
    const float lim = 2.0f * (float)S->map_size + 64.0f;
    if (!(fabs(xy.x) < lim && fabs(xy.y) < lim))
        return false;
    *texel = floor_int2(xy);
    return true;
}

/* How far the taps reach from the sample's texel along x or y (the largest |offset| above). */
#define LS_TAP_REACH 10

/* Whether every tap around texel t lies inside the map, so that tap j is simply at
 * t's index + ls_tap_offset(n, j), with no folding or bounds check: the lookups take this path
 * for all but the samples within LS_TAP_REACH texels of the map's edge, and it reads the same
 * texels as ls_texel_index would (the per-tap checks were most of a lookup's work, issue #12). */
inline bool ls_taps_inside(int n, int2 t)
{
    return t.x >= LS_TAP_REACH && t.y >= LS_TAP_REACH && t.x < n - LS_TAP_REACH &&
           t.y < n - LS_TAP_REACH;
}

inline int ls_tap_offset(int n, uint j) { return ls_taps[j].y * n + ls_taps[j].x; }

/* Texel t folded into the map, and whether it lies in it. An octahedral map covers every
 * direction and its border folds onto itself (the octahedron's lower faces meet there), so a tap
 * that crosses the border continues mirrored on the other side of the edge's midpoint; elsewhere
 * a texel outside the map is not in it. */
inline bool ls_fold_texel(__global const UmbraShadow *S, int2 *texel)
{
    const int n = (int)S->map_size;
    int2 t = *texel;
    if (S->ls_mode == UMBRA_LS_OCTAHEDRAL) {
        if (t.x < 0 || t.x >= n) {
            t.x = t.x < 0 ? -1 - t.x : 2 * n - 1 - t.x;
            t.y = n - 1 - t.y;
        }
        if (t.y < 0 || t.y >= n) {
            t.y = t.y < 0 ? -1 - t.y : 2 * n - 1 - t.y;
            t.x = n - 1 - t.x;
        }
    }
    *texel = t;
    return t.x >= 0 && t.y >= 0 && t.x < n && t.y < n;
}

/* Index of texel t in the map (folded as above), or -1 outside it. */
inline int ls_texel_index(__global const UmbraShadow *S, int2 t)
{
    return ls_fold_texel(S, &t) ? t.y * (int)S->map_size + t.x : -1;
}
