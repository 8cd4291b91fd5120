// SPDX-License-Identifier: Apache-2.0
/* kernels/raycast.cl: the view-space ray caster.
 *
 * Front-to-back emission-absorption compositing (Max 1995) with early ray termination,
 * empty-space skipping over bricks the view transfer function leaves empty, a seeded jittered
 * start, optional Blinn-Phong shading, and an optional opaque ground plane. Every sample with
 * non-zero opacity, and every ground-plane hit, takes its RGB shadow factor from the shadow
 * technique compiled into this program (see kernels/techniques/none.cl for the interface). The
 * host's
 * plain-C twin, tests/reference/cpu_reference.c, follows this file step for step (it takes each
 * sample's light at once, where the kernel takes it one sample late: the same arithmetic in the
 * same order per pixel, see the sample loop). */

/* Light arriving at a sample of colour c (alpha ignored) with shadow factor s. l_ray and hv_ray
 * are the direction to a directional light and the half vector, the same for every sample of a
 * ray, so the ray computes them once (shade_ray_light); a point light's are taken at p. The
 * normal is the gradient times one reciprocal length, as in the C twin. */
UMBRA_INLINE float3 shade_sample(__global const UmbraFrame *F, float3 c, float3 s, float3 p,
                                 float3 view, float3 grad, float3 l_ray, float3 hv_ray)
{
    float3 light = F3(F->light_color) * s;
    float3 amb = F3(F->ambient);
    if (!(F->flags & UMBRA_FLAG_SHADING))
        return c * (amb + light);
    float gl = umbra_length(grad);
    if (!(gl > 1e-6f))
        return c * (amb + light);
    float3 n = grad * (-1.0f / gl);
    float3 l = l_ray, hv = hv_ray;
    if (F->flags & UMBRA_FLAG_POINT_LIGHT) {
        l = to_light(F, p).xyz;
        hv = umbra_normalize(l + view);
    }
    float diff = fabs(dot(n, l));
    float spec = shading_power(fabs(dot(n, hv)), F->shininess);
    return c * (amb + light * F->kd * diff) + light * F->ks * spec;
}

/* The shading gradient at p: from the gradient volume gv where the host built one (gv_on,
 * kernels/common/sampling.cl: the same bits as view_gradient), else view_gradient. */
UMBRA_INLINE float3 ray_gradient(__global const UmbraFrame *F, VOLUME_PARAM, VolGeom g,
                                 __global const float4 *view_tf, __global const short4 *gv,
                                 uint gv_on, float3 p)
{
#if defined(UMBRA_GRADIENT_VOLUME) && !UMBRA_LABELS && UMBRA_CHANNELS == 1
    if (gv_on)
        return gradient_volume_sample(gv, g, p);
#else
    (void)gv;
    (void)gv_on;
#endif
    return view_gradient(F, vol, g, view_tf, p);
}

/* A directional light's direction and half vector for a ray of direction d (shade_sample). */
inline void shade_ray_light(__global const UmbraFrame *F, float3 d, float3 *l, float3 *hv)
{
    *l = -F3(F->light);
    *hv = normalize(*l - d);
}

/* The mean depth of the emission along a segment of opacity a, in units of its length, from its
 * front: the emission density is sigma exp(-sigma s) at depth s, whose mean is
 * 1/tau - (1 - a)/a, tau = -ln(1 - a): one half for a thin segment, 0 for an opaque one.
 * It only places where a sample's light is looked up within its step, so it is evaluated
 * approximately, without branches or calls (the exact form's log1p, two divisions and series
 * branch for small a are taken at every visible sample, issue #12): u = -log2(1 - a)
 * from 1 - a's exponent and a quadratic in its mantissa, then a rational function of u fitted to
 * the mean over u in [0, 24], which holds every float a < 1. Within 4.7e-4 of the exact mean for
 * every float a in [0, 1] (with or without fused multiply-adds); 1/2 at a = 0, 0 at a = 1.
 * tests/reference/cpu_reference.c (cpu_emission_depth) evaluates the same expression and
 * tests/test_emission_depth.c bounds it. */
inline float emission_depth(float a)
{
    const uint b = as_uint(1.0f - a);
    const float f = as_float((b & 0x007fffffu) | 0x3f800000u) - 1.0f; /* mantissa - 1 */
    const float u = (float)(127 - (int)(b >> 23)) - f * (1.35457563f - 0.35457563f * f);
    const float m = (0.5f + u * (0.0153764998f + u * 0.00439499835f)) /
                    (1.0f + u * (0.147417943f + u * (0.0241450484f + u * 0.00272645837f)));
    return select(0.0f, m, a < 1.0f); /* a = 1: u = 127, and the mean is 0 */
}

/* Where a plain sample at p (opacity a, step h along d) takes its light. A thin sample stands for
 * the segment [t - h/2, t + h/2] around it; an opaque one is the first to see a surface that lies
 * in (t - h, t], so it stands for that segment. Between the two the segment is blended by a, and
 * the light is taken at the segment's mean emission depth: p + h (m - (1 + a)/2) along d, which
 * is p for a thin sample and p - h for an opaque one. Taking it at p whatever the opacity made
 * it depend on how deep behind a surface the sample happened to fall: across an opaque surface
 * the light falls by exp(-sigma depth) within one view step, so a lit opaque face showed the view
 * step's phase against the voxel grid as voxel-scale moire, and as noise with jitter. (A
 * pre-integrated sample stands for [t, t + h]: its light at p + m h.) */
inline float3 shadow_point(float3 p, float3 d, float h, float a)
{
    return p + (h * (emission_depth(a) - 0.5f * (1.0f + a))) * d;
}

__kernel void raycast_render(__global const UmbraFrame *F, VOLUME_PARAM,
                             __global const float4 *view_tf, __global const float4 *light_tf,
                             __global const uchar *view_bricks, __global const ulong *light_cells,
                             __global const UmbraShadow *S, __global float4 *out,
                             __global UMBRA_COUNT_T *samples, __global const float4 *preint,
                             uint preint_size, __global const ulong *view_cells,
                             __global const short4 *grad_vol, uint grad_on SHADOW_KERNEL_PARAMS)
{
    const int px = get_global_id(0), py = get_global_id(1);
    if (px >= (int)F->width || py >= (int)F->height)
        return;
    const VolGeom g = vol_geom(F);
    const uint flags = F->flags;
    /* Frame constants the sample loop uses, read from the global frame once. */
    const TfMap tm = tf_map(g, F->tf_size);
    const float termination = F->termination;
    float3 o, d;
    camera_ray(F, px, py, &o, &d);
    /* The ray in voxel coordinates, where the volume is sampled: x = xo + t xd. */
    const float3 xo = world_to_voxel(g, o), xd = d * g.inv_spacing;

    /* The ground plane n.x + w = 0 ends the ray where it is hit from above. */
    float t_ground = UMBRA_INF;
    if (flags & UMBRA_FLAG_GROUND) {
        float3 n = F3(F->ground);
        float dn = dot(n, d);
        float tg = -(dot(n, o) + F->ground[3]) / dn;
        if (dn < 0.0f && tg > 0.0f)
            t_ground = tg;
    }

    float3 color = (float3)(0.0f);
    float alpha = 0.0f;
#if UMBRA_PART
    /* A part rendered after the parts in front of it (umbra_renderer_render_part_into) goes on
     * from the colour and opacity they accumulated: one device's running sum, bit for bit. */
    if (flags & UMBRA_FLAG_PART_FRONT) {
        const float4 front = out[py * (int)F->width + px];
        color = front.xyz;
        alpha = front.w;
    }
#endif
    uint taken = 0;
    ShadowRay sr;
    shadow_ray_init(&sr);
    float3 l_ray = (float3)(0.0f), hv_ray = (float3)(0.0f);
    if ((flags & UMBRA_FLAG_SHADING) && !(flags & UMBRA_FLAG_POINT_LIGHT))
        shade_ray_light(F, d, &l_ray, &hv_ray);
    float2 tb = ray_box(o, d, g.box_min, g.box_max);
    float t0 = fmax(tb.x, 0.0f);
    /* The clip region's part of the ray (tb unless something is clipped), sampled on the
     * unclipped ray's grid: from its first sample k0 on, up to t1. */
    const float2 tc = clip_interval(&S->clip, o, d, tb);
    float t1 = fmin(tc.y, t_ground);
    if (t1 > t0) {
        const float h = F->step;
        const float jitter = (flags & UMBRA_FLAG_JITTER) ? umbra_random(F->seed, px, py, 0u) : 0.0f;
        const int k0 = clip_first_sample(t0, h, jitter, tc.x);
        const int skip = (flags & UMBRA_FLAG_SKIP_EMPTY) != 0;
        /* At most UMBRA_MAX_RAY_SAMPLES + 1: the host refuses steps that would take more along
         * the box's diagonal (host/renderer.c, check_ray_samples), so this fits an int. */
        const int n = (int)ceil((t1 - t0) / h - jitter);
        /* Pre-integrated mode (preint_size != 0, kernels/common/preintegration.cl): sample k stands
         * for
         * the segment [t, t + h], its colour and opacity from the table at (s(t), s(t + h)), its
         * shading taken at the front (its shadow: shadow_point). The back value is kept for the
         * next segment. */
        int k_back = -1;
        float s_back = 0.0f;
        /* Empty-space skipping. The ray walks the sub-cells of the brick grid (CellWalk) and
         * takes the samples of the visible ones; a cell is tested once, when the first sample
         * past the previous visible cell's exit (t_cell) is reached, and invisible cells are
         * crossed without computing any sample. Pre-integrated segments reach into the next
         * sample's cell, so that mode tests whole bricks instead: a segment is skipped only if
         * both its ends lie in empty bricks, and a skip stops one sample short so that the
         * segment entering a visible brick is kept; samples before t_visible lie in a brick
         * already found visible. */
        const int walk_cells = skip && !preint_size;
        CellWalk w = walk_begin(g, o, d, fmax(t0, tc.x));
        float t_cell = -UMBRA_INF;
        float t_visible = -UMBRA_INF;
        /* A visible sample's light (its shadow lookup, gradient and shading) is taken one
         * sample late: after the next sample's colour, whose loads do not depend on it, so that
         * the processor overlaps them with the lookup's chain of dependent steps (the light
         * point depends on the sample's opacity, shadow_point, and the lookup's texels on the
         * light point). The opacity is composited at once, so termination and the samples taken
         * are unchanged, and each colour is added in the same order with the same weight: the
         * image is the same bit for bit. The light point (l_pend) is computed when the sample
         * is composited, where its opacity is at hand, not at the lookup: the same arithmetic,
         * placed where the processor can start it a sample earlier. What both gained:
         * docs/performance-log.md, "Behind the kernels' comments" (issue #12). */
        int pending = 0;
        float3 p_pend = (float3)(0.0f), l_pend = (float3)(0.0f);
        float4 c_pend = (float4)(0.0f);
        float w_pend = 0.0f;
        int k = k0;
        /* Jitter moves where the ray's segments are cut, not where they begin. Sample k stands
         * for the segment of one step that ends (1 - a) h / 2 past it (shadow_point), so the
         * unjittered ray's segments tile the ray from half a step and more before t0, the first
         * one's light taken in front of the box's face. Jittered samples at t0 + (k + jitter) h
         * drop that first whole segment and the fraction jitter of a step before the next: a
         * jittered first sample took its light up to a step deeper, in the shadow of the face
         * of dense material itself (a lit face speckled dark and grey, neghip at alpha 0.99999:
         * RMSE 0.10 against the unjittered image). So a jittered ray takes the unjittered first
         * sample, at t0, as is, then the fraction as the unjittered second sample, at t0 + h,
         * cut to it (its opacity for jitter h, its light at the fraction's mean emission depth
         * from where that sample's segment begins), then the jittered samples from k = 1: the
         * segments tile the ray from the same start as without jitter, the light of a dense
         * face is where it was, and at jitter 0 and 1 the samples are the unjittered ones. Both
         * are taken with their light at once, before the loop below. Only where nothing is clipped
         * in front of the box's face: a clipped ray starts at its first jittered sample past the
         * clip (k0). */
#if UMBRA_PART
        /* A part takes the two unjittered samples only if it owns the first; every part then
         * goes on from k = 1, and from the first sample its box may hold. */
        const int own0 = part_owns(F, world_to_voxel(g, o + t0 * d));
        if (jitter > 0.0f && !(tc.x > t0) && !own0)
            k = 1;
        if (jitter > 0.0f && !(tc.x > t0) && own0) {
#else
        if (jitter > 0.0f && !(tc.x > t0)) {
#endif
            for (int pre = 0; pre < 2 && alpha <= termination; ++pre) {
                const float tp = t0 + (float)pre * h;
                if (!(tp < t1))
                    break;
                const float3 p = o + tp * d;
                const float frac = pre ? jitter : 1.0f;
                float4 c;
                ++taken;
                if (preint_size) {
                    c = preint_lookup(preint, preint_size, sample_volume(vol, g, p),
                                      sample_volume(vol, g, p + (frac * h) * d));
                    c.xyz = preint_color(c);
                } else {
                    c = view_sample(F, vol, g, view_tf, F->tf_size, p);
                }
                const float a = pre ? alpha_for_length(c.w, jitter) : c.w;
                if (!(a > 0.0f))
                    continue;
                const float front = preint_size ? 0.0f : -0.5f * h * (1.0f + c.w);
                const float3 l_at = pre ? p + (front + jitter * h * emission_depth(a)) * d
                                    : preint_size ? p + (h * emission_depth(c.w)) * d
                                                  : shadow_point(p, d, h, c.w);
                const float3 s = SHADOW_FACTOR(sr, l_at);
                const float3 grad = (flags & UMBRA_FLAG_SHADING)
                                        ? ray_gradient(F, vol, g, view_tf, grad_vol, grad_on, p)
                                        : (float3)(0.0f);
                color += ((1.0f - alpha) * a) *
                         shade_sample(F, c.xyz, s, p, -d, grad, l_ray, hv_ray);
                alpha += (1.0f - alpha) * a;
            }
            k = alpha > termination ? n : 1;
        }
#if UMBRA_PART
        {
            /* The core box grown by a voxel (finite at the global faces): a ray that misses it
             * takes no sample of the part, and none before its entry. */
            const float3 dims = convert_float3(g.dims);
            const float3 lo = fmax(F3(F->part_lo), 0.0f) - 1.0f;
            const float3 hi = fmin(F3(F->part_hi), dims) + 1.0f;
            const float2 pb = ray_box(o, d, g.box_min + lo * g.spacing, g.box_min + hi * g.spacing);
            if (!(pb.y >= pb.x) || alpha > termination) /* missed, or ended in front */
                k = n;
            else if (pb.x > t0)
                k = max(k, (int)floor((pb.x - t0) / h - jitter) - 1);
        }
        int owned = 0;
#endif
        for (;;) {
            int more = k < n;
            float t = 0.0f;
            if (more) {
                t = t0 + ((float)k + jitter) * h;
                if (walk_cells && t >= t_cell) {
                    k = walk_next_sample(&w, g, view_cells, t0, h, jitter, k, n, t1, &t_cell);
                    more = k < n;
                    t = t0 + ((float)k + jitter) * h;
                }
            }
#if UMBRA_PART
            /* Samples before the part's are passed over; the first after them ends the ray. */
            if (more && !part_owns(F, xo + t * xd)) {
                if (!owned) {
                    ++k;
                    continue;
                }
                more = 0;
            }
            owned |= more;
#endif
            float3 p = o + t * d;
            float4 c = (float4)(0.0f);
            if (more) {
                if (skip && preint_size && t >= t_visible) {
                    float t_exit = brick_exit(g, o, d, t);
                    if (view_bricks[brick_index(g, p)]) {
                        t_visible = t_exit;
                    } else if (!view_bricks[brick_index(g, p + h * d)]) {
                        int next = next_sample_after(t0, h, jitter, t_exit, k);
                        k = max(next - 1, k + 1);
                        continue;
                    }
                }
                ++taken;
                if (preint_size) {
                    float sf = k == k_back ? s_back : sample_volume(vol, g, p);
                    s_back = sample_volume(vol, g, p + h * d);
                    k_back = k + 1;
                    c = preint_lookup(preint, preint_size, sf, s_back);
                    c.xyz = preint_color(c);
                } else {
#if UMBRA_LABELS || UMBRA_CHANNELS > 1
                    c = view_sample(F, vol, g, view_tf, F->tf_size, p);
#else
                    c = tf_classify(view_tf, tm, sample_stored(vol, g, xo + t * xd));
#endif
                }
            }
            if (pending) {
                float3 s = SHADOW_FACTOR(sr, l_pend);
                float3 grad = (flags & UMBRA_FLAG_SHADING)
                                  ? ray_gradient(F, vol, g, view_tf, grad_vol, grad_on, p_pend)
                                  : (float3)(0.0f);
                float3 lit = shade_sample(F, c_pend.xyz, s, p_pend, -d, grad, l_ray, hv_ray);
                color += w_pend * lit;
                pending = 0;
            }
            if (!more)
                break;
            if (c.w > 0.0f) {
                pending = 1;
                p_pend = p;
                c_pend = c;
                l_pend = preint_size ? p + (h * emission_depth(c.w)) * d
                                     : shadow_point(p, d, h, c.w);
                w_pend = (1.0f - alpha) * c.w;
                alpha += (1.0f - alpha) * c.w;
                if (alpha > termination)
                    k = n; /* the next round adds this sample's light and ends the ray */
            }
            ++k;
        }
    }

    if (t_ground < UMBRA_INF && alpha <= termination) {
        float3 p = o + t_ground * d;
        float3 s = SHADOW_FACTOR(sr, p);
        float ndl = fmax(dot(F3(F->ground), to_light(F, p).xyz), 0.0f);
        float3 lit = F3(F->ground_color) * (F3(F->ambient) + F3(F->light_color) * s * ndl);
        color += (1.0f - alpha) * lit;
        alpha = 1.0f;
    }
    float4 bg = vload4(0, F->background);
    /* An explicit fma, correctly rounded on every device (a compiler may or may not contract
     * the product and sum): umbra_part_background (host/part.c) does the same with fmaf, so a
     * frame rendered part after part over the background is one device's image bit for bit. */
    out[py * (int)F->width + px] = fma((float4)(1.0f - alpha), bg, (float4)(color, alpha));
    if (taken)
        UMBRA_COUNT_ADD(samples, taken);
}

/* Fills the gradient volume (kernels/common/sampling.cl, gradient_volume_entry): one work-item
 * per entry of the (dims + 3)^3 grid, entry (x, y, z) for q = (x, y, z) - 1. */
__kernel void raycast_gradient_volume(__global const UmbraFrame *F, VOLUME_PARAM,
                                      __global short4 *out)
{
    const VolGeom g = vol_geom(F);
    const int3 n = g.dims + 3;
    const int3 e = (int3)(get_global_id(0), get_global_id(1), get_global_id(2));
    if (e.x >= n.x || e.y >= n.y || e.z >= n.z)
        return;
#if defined(UMBRA_GRADIENT_VOLUME)
    const size_t at = ((size_t)e.z * (size_t)n.y + (size_t)e.y) * (size_t)n.x + (size_t)e.x;
    out[at] = gradient_volume_entry(vol, g, e - 1);
#else
    (void)out;
#endif
}

/* Evaluates the shadow factor at arbitrary world points: for tests, and for applications that
 * shade their own geometry with umbra's shadows. */
__kernel void raycast_query_shadow(__global const UmbraFrame *F, VOLUME_PARAM,
                                   __global const float4 *view_tf, __global const float4 *light_tf,
                                   __global const uchar *view_bricks,
                                   __global const ulong *light_cells,
                                   __global const UmbraShadow *S, __global const float *points,
                                   __global float *rgb, uint count SHADOW_KERNEL_PARAMS)
{
    const uint i = get_global_id(0);
    if (i >= count)
        return;
    (void)view_tf;
    (void)view_bricks;
    const VolGeom g = vol_geom(F);
    ShadowRay sr;
    shadow_ray_init(&sr);
    float3 p = vload3(i, points);
    vstore3(SHADOW_FACTOR(sr, p), i, rgb);
}
