/* kernels/lightspace.cl: the light-space map projection shared by the shadow-map techniques.
 * host/lightspace.c fits it to the volume's box; see UMBRA_LS_* in umbra_shared.h.
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
inline float3 ls_world_to_map(__global const UmbraShadow *S, float3 p)
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
        depth = length(q);
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
 * parameter interval [t.x, t.y] where it crosses the volume's box (empty if t.y <= t.x). Depth at
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
    float2 t = ray_box(*o, *d, g.box_min, g.box_max);
    t.x = fmax(t.x, 0.0f);
    return t;
}

/* Normalised depth of the point at parameter t on a ray from ls_texel_ray. */
inline float ls_depth(__global const UmbraShadow *S, float3 o, float t)
{
    float along = S->ls_mode == UMBRA_LS_ORTHO ? dot(o, F3(S->ls_w)) + t : t;
    return (along - S->near_far[0]) * S->near_far[2];
}
