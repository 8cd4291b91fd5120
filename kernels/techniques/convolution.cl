// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/convolution.cl: slice-based convolution shadows: Instant Convolution Shadows
 * (ICS,
 * Patel et al. 2009) with the pre-integration and supersampling of "Pre-integration and
 * supersampling for convolution shadows" (the seed paper). It follows common/common.cl,
 * common/sampling.cl and
 * common/preintegration.cl. The host side is host/techniques/convolution.c.
 *
 * The volume is cut by planes perpendicular to the view direction ("slices"), slice i at depth
 * z_i = z0 + i dz (depth = distance along the unit view direction from the eye, or from the view
 * plane of an orthographic camera). Every slice is a 2D buffer over the image plane, one texel per
 * pixel: texel x of slice i stands for the point where pixel x's view ray crosses plane i. For a
 * perspective camera the planes are cut by diverging rays, so a texel covers z / (focal length)
 * world units and the sample spacing along a ray is dz / cos(ray, view axis); view opacities are
 * corrected per pixel for that longer path.
 *
 * One kernel launch per slice, front to back (convolution_slice), then convolution_resolve:
 *   1. light L_i arriving at slice i = the previous slice's attenuated light A_{i-1} convolved with
 *      k(x): displaced by the light direction's lateral part times the distance dz / cos(light,
 *      view axis) it travels between the planes, and widened by the cone angle: the cone's
 *      cross-section there, a disk of radius R = dl tan(cone) around the light ray, projected along
 *      the light onto the plane (an ellipse for an oblique light, as in multidirectional
 *      occlusion shading). The disk is represented by 3 taps of weight 1/3 on a circle of radius
 *      R / sqrt 2 (an equilateral triangle, turned 60 degrees every other slice so that no
 *      direction is favoured): they have the uniform disk's mean and covariance, the kernel sums
 *      to 1, and with cone angle 0 it is a delta. Each tap is a bilinear read; texels outside
 *      the image read 1: light from outside the view arrives unoccluded. (ICS optimises its
 *      kernel for few taps too; 3 taps cost a third of a 7-tap disk on a CPU device.)
 *   2. slab i = depths [z_i, z_i + dz) is sampled at z_i + j dz/(n+1), j = 0..n (n = sub-samples;
 *      n = 0 is ICS); every sample is a shadow receiver lit by the light interpolated between L_i
 *      and L_{i+1} with weight j/(n+1) (the paper's Figure 2) and an occluder: the light leaving
 *      the slab, A_i = L_i * product of the samples' light transmissions (the shading model's
 *      (1 - a)^(D (1 - t)) over the light's path D = dz/(n+1)/cos(light, view axis)).
 *   3. with pre-integration each sample is a segment [z, z + dz/(n+1)] from the 2D tables: colour
 *      and opacity from the view table, the light attenuated by the light table's transmittance
 *      (tissue pre-integration; the light is taken at the segment's front, the paper's S1).
 * L_{i+1} is only known after every texel of A_i is, i.e. in the next launch, so a slab's colour
 * is kept as E + B0 L_i + B1 L_{i+1} (the shading model is linear in the light) in `pend` and
 * added to the eye buffer by the next launch; its opacity is added at once. Light therefore never
 * lags: A sample at depth z is lit by light attenuated by exactly the slabs in front of its slab.
 * The ground plane is a receiver like any sample: its hit lies in some slab and takes the light
 * interpolated by depth; before the first and after the last slice it is unshadowed (the host
 * extends the slices behind the box far enough to cover the box's shadow on the plane).
 *
 * The slices cover only the rectangle `rect` of the image that holds the box's projection (and,
 * with the ground plane, the projection of the box's shadow on it), plus a margin: a light path
 * that meets the box projects to a line through the box's (convex) silhouette, and once it has
 * left it never comes back, so outside the rectangle the light that matters is unoccluded. Texels
 * outside read 1, as outside the image; only the kernel's spread beyond the margin is cut off.
 *
 * Buffers, per pixel: a_prev/a_next (A, ping-pong), l_prev/l_cur (L of the last two slices),
 * eye (premultiplied colour, opacity), pend (3 float4: E + cached s, B0 + cache flag, B1).
 * geo = (z0, dz, tan(cone angle), cos of the largest supported light angle); ctl = (slice,
 * sub-samples n, pre-integration table size or 0, number of slices). */

#if UMBRA_LIGHT_CHANNELS == 1
#define CONV_LOAD(buf, i) ((buf)[(i)])
#define CONV_STORE(v, buf, i) ((buf)[(i)] = (v))
inline light_t conv_light_pow(float4 t, float r) { return pow(t.x, r); }
#else
#define CONV_LOAD(buf, i) vload3((i), (buf))
#define CONV_STORE(v, buf, i) vstore3((v), (i), (buf))
inline light_t conv_light_pow(float4 t, float r) { return pow(t.xyz, (float3)(r)); }
#endif

/* The kernel's ring: an equilateral triangle, and the same turned by 60 degrees. */
__constant float2 conv_ring[2][3] = {
    {(float2)(1.0f, 0.0f), (float2)(-0.5f, 0.8660254f), (float2)(-0.5f, -0.8660254f)},
    {(float2)(-1.0f, 0.0f), (float2)(0.5f, -0.8660254f), (float2)(0.5f, 0.8660254f)}};

/* Light weight of sub-sample j of n between two slices: 0 at the front slice, 1 at the next. */
inline float conv_subsample_weight(uint j, uint n) { return (float)j / (float)(n + 1u); }

typedef struct ConvCam {
    float3 eye, fwd, rhat, uhat;
    float half_w, half_h; /* half the view at depth 1 (perspective) or in world units (ortho) */
    int ortho, width, height;
    int4 rect;            /* the pixels the slices cover: [x0, x1) x [y0, y1) */
} ConvCam;

inline ConvCam conv_cam(__global const UmbraFrame *F, int4 rect)
{
    ConvCam c;
    c.eye = F3(F->eye);
    c.fwd = F3(F->forward);
    c.half_w = length(F3(F->right));
    c.half_h = length(F3(F->up));
    c.rhat = F3(F->right) / c.half_w;
    c.uhat = F3(F->up) / c.half_h;
    c.ortho = (F->flags & UMBRA_FLAG_ORTHO) != 0;
    c.width = (int)F->width;
    c.height = (int)F->height;
    c.rect = rect;
    return c;
}

/* A pixel's view ray (the mapping of raycast.cl's camera_ray) and the depths where it samples. */
typedef struct ConvPixel {
    float3 o, d;     /* the point at depth z is o + d z / cosv */
    float cosv;      /* cos(ray, view axis) */
    float z_in, z_out;/* depth interval inside the box, in front of the eye and of the ground */
    float z_ground;  /* depth of the ground hit, or infinity */
} ConvPixel;

inline ConvPixel conv_pixel(__global const UmbraFrame *F, ConvCam c, VolGeom g, int px, int py)
{
    ConvPixel P;
    float sx = ((float)px + 0.5f) / (float)F->width * 2.0f - 1.0f;
    float sy = 1.0f - ((float)py + 0.5f) / (float)F->height * 2.0f;
    if (c.ortho) {
        P.o = c.eye + sx * F3(F->right) + sy * F3(F->up);
        P.d = c.fwd;
        P.cosv = 1.0f;
    } else {
        P.o = c.eye;
        P.d = normalize(c.fwd + sx * F3(F->right) + sy * F3(F->up));
        P.cosv = dot(P.d, c.fwd);
    }
    float t_ground = UMBRA_INF;
    if (F->flags & UMBRA_FLAG_GROUND) {
        float3 n = F3(F->ground);
        float dn = dot(n, P.d);
        float tg = -(dot(n, P.o) + F->ground[3]) / dn;
        if (dn < 0.0f && tg > 0.0f)
            t_ground = tg;
    }
    float2 tb = ray_box(P.o, P.d, g.box_min, g.box_max);
    P.z_in = fmax(tb.x, 0.0f) * P.cosv;
    P.z_out = fmin(tb.y, t_ground) * P.cosv;
    P.z_ground = t_ground * P.cosv;
    return P;
}

inline light_t conv_texel(__global const float *a, ConvCam c, int x, int y)
{
    if (x < c.rect.x || y < c.rect.y || x >= c.rect.z || y >= c.rect.w)
        return (light_t)(1.0f);
    return CONV_LOAD(a, y * c.width + x);
}

/* Bilinear read of a light buffer at pixel coordinates (fx, fy) (texel centres at integers). */
inline light_t conv_fetch(__global const float *a, ConvCam c, float fx, float fy)
{
    /* Far outside, every texel reads 1; clamping first keeps the int conversion defined. */
    fx = clamp(fx, (float)c.rect.x - 2.0f, (float)c.rect.z + 1.0f);
    fy = clamp(fy, (float)c.rect.y - 2.0f, (float)c.rect.w + 1.0f);
    const int2 i0 = floor_int2((float2)(fx, fy));
    const int ix = i0.x, iy = i0.y;
    const float tx = fx - (float)ix, ty = fy - (float)iy;
    light_t t00, t10, t01, t11;
    if (ix >= c.rect.x && iy >= c.rect.y && ix + 1 < c.rect.z && iy + 1 < c.rect.w) {
        int i = iy * c.width + ix;
        t00 = CONV_LOAD(a, i);
        t10 = CONV_LOAD(a, i + 1);
        t01 = CONV_LOAD(a, i + c.width);
        t11 = CONV_LOAD(a, i + c.width + 1);
    } else {
        t00 = conv_texel(a, c, ix, iy);
        t10 = conv_texel(a, c, ix + 1, iy);
        t01 = conv_texel(a, c, ix, iy + 1);
        t11 = conv_texel(a, c, ix + 1, iy + 1);
    }
    return mix(mix(t00, t10, tx), mix(t01, t11, tx), ty);
}

/* The light arriving at point p of slice `slice`: the attenuated light of the slice dz in front,
 * convolved with the displaced, cone-widened kernel (see the file comment). The kernel's centre
 * is projected to the previous slice's pixel grid; its taps, lying in that plane, map to pixel
 * offsets by the plane's (constant) world-to-pixel scale. */
inline light_t conv_gather(__global const UmbraFrame *F, __global const float *a, ConvCam c,
                           float3 p, uint slice, float dz, float cone_tan, float min_cos)
{
    float3 L = -to_light(F, p).xyz; /* travel direction */
    float cosl = fmax(dot(L, c.fwd), min_cos);
    float dl = dz / cosl;
    float3 v = p - dl * L - c.eye;
    float depth = dot(v, c.fwd);
    float kx = 0.5f * (float)c.width / (c.half_w * (c.ortho ? 1.0f : depth));
    float ky = 0.5f * (float)c.height / (c.half_h * (c.ortho ? 1.0f : depth));
    float fx = dot(v, c.rhat) * kx + 0.5f * (float)c.width - 0.5f;
    float fy = 0.5f * (float)c.height - dot(v, c.uhat) * ky - 0.5f;
    float radius = dl * cone_tan * 0.70710678f; /* the cone's radius / sqrt 2 */
    if (!(radius > 0.0f))
        return conv_fetch(a, c, fx, fy);
    float3 e1 = normalize(cross(L, fabs(L.x) < 0.9f ? (float3)(1.0f, 0.0f, 0.0f)
                                                     : (float3)(0.0f, 1.0f, 0.0f)));
    float3 e2 = cross(L, e1);
    light_t sum = (light_t)(0.0f);
    for (int k = 0; k < 3; ++k) {
        float2 r = conv_ring[slice & 1u][k];
        float3 w = radius * (r.x * e1 + r.y * e2);
        w -= L * (dot(w, c.fwd) / cosl); /* along the light onto the plane */
        sum += conv_fetch(a, c, fx + dot(w, c.rhat) * kx, fy - dot(w, c.uhat) * ky);
    }
    return sum * (1.0f / 3.0f);
}

/* The shading model (renderer.h) split as lit = amb + coef * S, S the light reaching the sample,
 * so S can be applied once the next slice's light is known. Mirrors raycast.cl's shade_sample. */
inline void conv_shade(__global const UmbraFrame *F, float3 c, float3 p, float3 view, float3 grad,
                       float3 *amb, float3 *coef)
{
    *amb = c * F3(F->ambient);
    float3 lc = F3(F->light_color);
    float gl = umbra_length(grad);
    if (!(F->flags & UMBRA_FLAG_SHADING) || !(gl > 1e-6f)) {
        *coef = c * lc;
        return;
    }
    float3 n = -grad / gl;
    float3 l = to_light(F, p).xyz;
    float3 hv = umbra_normalize(l + view);
    float diff = fabs(dot(n, l));
    float spec = shading_power(fabs(dot(n, hv)), F->shininess);
    *coef = lc * (c * F->kd * diff + F->ks * spec);
}

__kernel void convolution_slice(__global const UmbraFrame *F, VOLUME_PARAM,
                                __global const float4 *view_tf, __global const float4 *light_tf,
                                __global const uchar *view_bricks,
                                __global const ulong *light_cells,
                                __global const UmbraShadow *S, __global const float4 *pi_view,
                                __global const float4 *pi_light, __global const float *a_prev,
                                __global float *a_next, __global const float *l_prev,
                                __global float *l_cur, __global float4 *eye,
                                __global float4 *pend, float4 geo, uint4 ctl, int4 rect)
{
    const int px = get_global_id(0), py = get_global_id(1);
    if (px >= rect.z || py >= rect.w)
        return;
    const float h_light = light_step_voxels(F, S); /* the light sub-step along the view axis */
    const int idx = py * (int)F->width + px;
    const VolGeom g = vol_geom(F);
    const ConvCam cam = conv_cam(F, rect);
    const ConvPixel P = conv_pixel(F, cam, g, px, py);
    const uint flags = F->flags;
    const uint slice = ctl.x, nsub = ctl.y, pi_size = ctl.z;
    const float dz = geo.y, hsub = dz / (float)(nsub + 1u);
    const float zi = geo.x + (float)slice * dz;
    const float3 p_slice = P.o + P.d * (zi / P.cosv);

    light_t L = slice == 0 ? (light_t)(1.0f)
                           : conv_gather(F, a_prev, cam, p_slice, slice, dz, geo.z, geo.w);
    CONV_STORE(L, l_cur, idx);

    /* Finish the previous slab: its colour is linear in the light at its two ends. */
    float4 acc = (float4)(0.0f);
    float cached_s = 0.0f;
    int cached = 0;
    if (slice > 0) {
        float4 e = pend[3 * idx], b0 = pend[3 * idx + 1], b1 = pend[3 * idx + 2];
        acc = eye[idx];
        acc.xyz += e.xyz + b0.xyz * light_rgb(CONV_LOAD(l_prev, idx)) + b1.xyz * light_rgb(L);
        cached_s = e.w;
        cached = b0.w != 0.0f;
    }

    float3 E = (float3)(0.0f), B0 = (float3)(0.0f), B1 = (float3)(0.0f);
    float alpha = acc.w;
    light_t T = (light_t)(1.0f);
    float next_s = 0.0f;
    int next_cached = 0;
    /* Tolerance so the sample on the box's front face counts as inside despite rounding. */
    const float z_lo = P.z_in - 1e-4f * hsub;
    if (zi + dz > z_lo && zi < P.z_out) {
        const float r_light = 1.0f / fmax(-dot(to_light(F, p_slice).xyz, cam.fwd), geo.w);
        /* The view table is corrected for the ray caster's step, the pre-integration tables for
         * the sub-step along the view axis, and the light's extinction is taken over h_light
         * voxels there; a perspective ray crosses the slab obliquely, the light at its angle. */
        const float r_view = pi_size ? 1.0f / P.cosv : hsub / (P.cosv * F->step);
        const int skip = !pi_size && (flags & UMBRA_FLAG_SKIP_EMPTY);
        const float step_t = hsub / P.cosv;
        float s_front = 0.0f;
        int have_front = 0;
        for (uint j = 0; j <= nsub; ++j) {
            const float z = zi + (float)j * hsub;
            if (z < z_lo || z >= P.z_out) {
                have_front = 0;
                continue;
            }
            const float3 p = P.o + P.d * (z / P.cosv);
            /* A sample the clip region leaves out is neither seen nor attenuates the light. */
            if (!clip_keeps(&S->clip, p)) {
                have_front = 0;
                continue;
            }
            if (skip) {
                int b = brick_index(g, p);
                if (!view_bricks[b] && !light_cells[b])
                    continue;
            }
            float4 c;
            light_t pass;
            if (pi_size) {
                float sf = have_front ? s_front
                                      : (j == 0 && cached ? cached_s : sample_volume(vol, g, p));
                float sb = sample_volume(vol, g, p + step_t * P.d);
                s_front = sb;
                have_front = 1;
                float4 e = preint_view_for_fraction(preint_lookup(pi_view, pi_size, sf, sb), r_view);
                c = (float4)(preint_color(e), e.w);
                pass = conv_light_pow(preint_lookup(pi_light, pi_size, sf, sb), r_light);
                if (j == nsub) {
                    next_s = sb;
                    next_cached = 1;
                }
            } else {
#if UMBRA_MIXED
                c = alpha_for_fraction(view_sample(F, vol, g, view_tf, F->tf_size, p), r_view);
                pass = light_pass(light_sample(F, vol, g, light_tf, F->light_tf_size, p),
                                  r_light * h_light, flags);
#else
                float s = sample_volume(vol, g, p);
                c = alpha_for_fraction(tf_lookup(view_tf, F->tf_size, s), r_view);
                pass = light_pass(tf_lookup(light_tf, F->light_tf_size, s), r_light * h_light,
                                  flags);
#endif
            }
            T *= pass;
            if (c.w > 0.0f && !(alpha > F->termination)) {
                float3 grad = (flags & UMBRA_FLAG_SHADING) ? view_gradient(F, vol, g, view_tf, p)
                                                           : (float3)(0.0f);
                float3 amb, coef;
                conv_shade(F, c.xyz, p, -P.d, grad, &amb, &coef);
                float w = (1.0f - alpha) * c.w, f = conv_subsample_weight(j, nsub);
                E += w * amb;
                B0 += (w * (1.0f - f)) * coef;
                B1 += (w * f) * coef;
                alpha += w;
            }
        }
    }

    /* The ground, where this pixel's ray meets it inside this slab. */
    if (P.z_ground >= zi && P.z_ground < zi + dz && !(alpha > F->termination)) {
        float3 pg = P.o + P.d * (P.z_ground / P.cosv);
        float ndl = fmax(dot(F3(F->ground), to_light(F, pg).xyz), 0.0f);
        float f = (P.z_ground - zi) / dz, w = 1.0f - alpha;
        float3 coef = F3(F->ground_color) * F3(F->light_color) * ndl;
        E += w * F3(F->ground_color) * F3(F->ambient);
        B0 += (w * (1.0f - f)) * coef;
        B1 += (w * f) * coef;
        alpha = 1.0f;
    }

    eye[idx] = (float4)(acc.xyz, alpha);
    pend[3 * idx] = (float4)(E, next_s);
    pend[3 * idx + 1] = (float4)(B0, next_cached ? 1.0f : 0.0f);
    pend[3 * idx + 2] = (float4)(B1, 0.0f);
    CONV_STORE(L * T, a_next, idx);
}

/* After the last slice: finishes its slab, adds the ground outside the sliced depths (unshadowed),
 * blends the background and writes the premultiplied image. */
__kernel void convolution_resolve(__global const UmbraFrame *F, __global const float *a_prev,
                                  __global const float *l_prev, __global const float4 *eye,
                                  __global const float4 *pend, __global float4 *out, float4 geo,
                                  uint4 ctl, int4 rect)
{
    const int px = get_global_id(0), py = get_global_id(1);
    if (px >= (int)F->width || py >= (int)F->height)
        return;
    const int idx = py * (int)F->width + px;
    const VolGeom g = vol_geom(F);
    const ConvCam cam = conv_cam(F, rect);
    const ConvPixel P = conv_pixel(F, cam, g, px, py);
    const int inside = px >= rect.x && py >= rect.y && px < rect.z && py < rect.w;
    const uint slices = inside ? ctl.w : 0u;
    const float z_end = geo.x + (float)ctl.w * geo.y;
    float4 acc = (float4)(0.0f);
    if (slices > 0) {
        float3 p = P.o + P.d * (z_end / P.cosv);
        light_t L = conv_gather(F, a_prev, cam, p, ctl.w, geo.y, geo.z, geo.w);
        acc = eye[idx];
        acc.xyz += pend[3 * idx].xyz + pend[3 * idx + 1].xyz * light_rgb(CONV_LOAD(l_prev, idx)) +
                   pend[3 * idx + 2].xyz * light_rgb(L);
    }
    const int sliced = slices > 0 && P.z_ground >= geo.x && P.z_ground < z_end;
    if (P.z_ground < UMBRA_INF && !sliced && !(acc.w > F->termination)) {
        float3 pg = P.o + P.d * (P.z_ground / P.cosv);
        float ndl = fmax(dot(F3(F->ground), to_light(F, pg).xyz), 0.0f);
        float3 lit = F3(F->ground_color) * (F3(F->ambient) + F3(F->light_color) * ndl);
        acc.xyz += (1.0f - acc.w) * lit;
        acc.w = 1.0f;
    }
    float4 bg = vload4(0, F->background);
    out[idx] = acc + (1.0f - acc.w) * bg;
}

/* The sub-sample light weights conv_subsample_weight gives for j = 0..n+1, for tests. */
__kernel void convolution_subsample_weights(__global float *out, uint n)
{
    const uint j = get_global_id(0);
    if (j <= n + 1u)
        out[j] = conv_subsample_weight(j, n);
}
