/* kernels/shadow_reference.cl: the exact reference. From every point, a shadow ray is marched
 * toward the light with step S->step and the per-channel transmittance of the shading model is
 * accumulated. Every other technique is measured against it.
 *
 * Exactness: the path [t_start, t_end] inside the volume (and before a point light) is split into
 * whole steps h plus one final partial step, each sampled at its midpoint, so the segment lengths
 * add up to the path length exactly; the light table is corrected for h on the host and the final
 * step re-corrected for its fraction. A homogeneous slab therefore gives exp(-sigma d) for every h,
 * to float precision. Cells the light transfer function leaves empty are skipped on the same
 * sample grid, so skipping changes no value; the march stops once every channel is below 1e-6. */

#define SHADOW_KERNEL_PARAMS

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

inline float3 reference_shadow(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                               __global const float4 *light_tf,
                               __global const ulong *light_cells,
                               __global const UmbraShadow *S, float3 p)
{
    float4 l = to_light(F, p);
    float3 d = l.xyz;
    float2 tb = ray_box(p, d, g.box_min, g.box_max);
    float t_start = fmax(tb.x, 0.0f);
    float t_end = fmin(tb.y, l.w);
    if (!(t_end > t_start))
        return (float3)(1.0f);
    const float h = S->step;
    const uint n_tf = F->light_tf_size;
    const uint flags = F->flags;
    const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
    float len = t_end - t_start;
    int n_full = (int)floor(len / h);
    float last = len - (float)n_full * h;
    light_t T = (light_t)(1.0f);
    /* The ray walks the cells of the light's cell masks (CellWalk) and samples only visible ones;
     * samples before t_cell lie in a cell already found visible. */
    CellWalk w = walk_begin(g, p, d, t_start);
    float t_cell = -UMBRA_INF;
    for (int k = 0; k < n_full;) {
        float t = t_start + ((float)k + 0.5f) * h;
        if (skip && t >= t_cell) {
            k = walk_next_sample(&w, g, light_cells, t_start, h, 0.5f, k, n_full, t_end, &t_cell);
            if (k >= n_full)
                break;
            t = t_start + ((float)k + 0.5f) * h;
        }
        float3 q = p + t * d;
        float4 c = tf_lookup(light_tf, n_tf, sample_volume(vol, g, q));
        T *= light_pass(c, flags);
        if (light_max(T) < 1e-6f)
            return (float3)(0.0f);
        ++k;
    }
    if (last > 0.0f) {
        float3 q = p + (t_start + (float)n_full * h + 0.5f * last) * d;
        float4 c = tf_lookup(light_tf, n_tf, sample_volume(vol, g, q));
        T *= light_pass(alpha_for_fraction(c, last / h), flags);
    }
    return light_rgb(T);
}

#define SHADOW_FACTOR(sr, p) reference_shadow(F, vol, g, light_tf, light_cells, S, (p))
