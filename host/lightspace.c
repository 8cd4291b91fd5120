// SPDX-License-Identifier: Apache-2.0
/* host/lightspace.c: fitting a light-space map to the volume's box. See lightspace.h. */
#include <math.h>
#include <string.h>

#include "lightspace.h"

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void basis_from(const float w_in[3], float u[3], float v[3], float w[3])
{
    float l = sqrtf(dot3(w_in, w_in));
    for (int i = 0; i < 3; ++i)
        w[i] = w_in[i] / l;
    /* Any vector not parallel to w gives a basis; pick the axis w is least aligned with. */
    float a[3] = {0, 0, 0};
    int k = fabsf(w[0]) < fabsf(w[1]) ? (fabsf(w[0]) < fabsf(w[2]) ? 0 : 2) : (fabsf(w[1]) < fabsf(w[2]) ? 1 : 2);
    a[k] = 1.0f;
    u[0] = a[1] * w[2] - a[2] * w[1];
    u[1] = a[2] * w[0] - a[0] * w[2];
    u[2] = a[0] * w[1] - a[1] * w[0];
    l = sqrtf(dot3(u, u));
    for (int i = 0; i < 3; ++i)
        u[i] /= l;
    v[0] = w[1] * u[2] - w[2] * u[1];
    v[1] = w[2] * u[0] - w[0] * u[2];
    v[2] = w[0] * u[1] - w[1] * u[0];
}

float umbra__map_light_step(const umbra_shadow_desc *d)
{
    return d->map.step > 0.0f ? d->map.step : umbra_technique_find_id(d->technique)->map_step;
}

/* Texels per voxel UMBRA_MAP_SIZE_AUTO gives the technique: the application's (a draft while the
 * light moves), else the technique's own (its descriptor says why it chose it). */
static double texels_per_voxel(umbra_renderer r)
{
    if (r->shadow.map.texels_per_voxel > 0.0f)
        return r->shadow.map.texels_per_voxel;
    return r->tech->info.map_texels_per_voxel;
}

/* Voxels across the map: how many voxels of the box the map's window spans as the light sees it,
 * so that texels_per_voxel(r) times it is UMBRA_MAP_SIZE_AUTO's size (before rounding). extent is
 * the wider side of the map's window in its own units (world units for an orthographic map,
 * tangents for a perspective one), scale the world length one window unit stands for at the box
 * (1 for orthographic, the distance to the box's centre for a perspective frustum); an
 * octahedral map covers the sphere of directions, 4 pi steradians over its n^2 texels, and a
 * voxel at distance R subtends (voxel / R)^2 of it, so n = sqrt(4 pi) R / voxel with R the
 * distance to the farthest corner (every voxel at most that far gets its share). In double: a
 * world of 1e18 units must not overflow. */
static double voxels_across(umbra_renderer r, int mode, double extent, double scale, double far)
{
    double voxel = umbra__voxel_world(r);
    return mode == UMBRA_LS_OCTAHEDRAL ? sqrt(4.0 * 3.14159265358979) * far / voxel
                                       : extent * scale / voxel;
}

/* UMBRA_MAP_SIZE_AUTO: texels_per_voxel(r) per voxel across, rounded up to a multiple of
 * UMBRA_MAP_SIZE_AUTO_ROUND (the deep map's tiles are 8 or 16 texels, so whole tiles and full
 * 8 x 8 work-groups) and bounded to [MIN, MAX]. */
static uint32_t auto_map_size(umbra_renderer r, double across)
{
    double n = texels_per_voxel(r) * across;
    if (!(n >= UMBRA_MAP_SIZE_AUTO_MIN)) /* NaN too */
        return UMBRA_MAP_SIZE_AUTO_MIN;
    if (n >= UMBRA_MAP_SIZE_AUTO_MAX)
        return UMBRA_MAP_SIZE_AUTO_MAX;
    const uint32_t q = UMBRA_MAP_SIZE_AUTO_ROUND;
    return ((uint32_t)ceil(n) + q - 1) / q * q;
}

static void set4(float d[4], const float s[3], float w)
{
    d[0] = s[0];
    d[1] = s[1];
    d[2] = s[2];
    d[3] = w;
}

double umbra__lightspace_setup(umbra_renderer r, uint32_t map_size)
{
    UmbraShadow *S = &r->shadow_params;
    const UmbraFrame *F = &r->frame;
    float corners[8][3];
    for (int c = 0; c < 8; ++c)
        for (int a = 0; a < 3; ++a)
            corners[c][a] = (c >> a) & 1 ? F->box_max[a] : F->box_min[a];
    float u[3], v[3], w[3];
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float dist_centre = 0.0f;
    memset(S->ls_origin, 0, sizeof S->ls_origin);

    /* F->light is the light in the volume's local frame (the box is centred there). */
    if (!(F->flags & UMBRA_FLAG_POINT_LIGHT)) {
        basis_from(F->light, u, v, w);
        for (int c = 0; c < 8; ++c) {
            float p[3] = {dot3(corners[c], u), dot3(corners[c], v), dot3(corners[c], w)};
            for (int a = 0; a < 3; ++a) {
                lo[a] = fminf(lo[a], p[a]);
                hi[a] = fmaxf(hi[a], p[a]);
            }
        }
        S->ls_mode = UMBRA_LS_ORTHO;
    } else {
        const float *P = F->light;
        float centre[3] = {-P[0], -P[1], -P[2]}; /* the box is centred on the origin */
        dist_centre = sqrtf(dot3(centre, centre));
        /* Nearest box point: distance 0 inside; farthest: the farthest corner. */
        float near2 = 0.0f;
        for (int a = 0; a < 3; ++a) {
            float d = P[a] < F->box_min[a] ? F->box_min[a] - P[a] : (P[a] > F->box_max[a] ? P[a] - F->box_max[a] : 0.0f);
            near2 += d * d;
        }
        lo[2] = sqrtf(near2);
        hi[2] = 0.0f;
        for (int c = 0; c < 8; ++c) {
            float q[3] = {corners[c][0] - P[0], corners[c][1] - P[1], corners[c][2] - P[2]};
            hi[2] = fmaxf(hi[2], sqrtf(dot3(q, q)));
        }
        S->ls_mode = UMBRA_LS_OCTAHEDRAL;
        set4(S->ls_origin, P, 0.0f);
        if (dist_centre > 0.0f) {
            basis_from(centre, u, v, w);
            float tmax = 0.0f;
            int in_front = 1;
            for (int c = 0; c < 8; ++c) {
                float q[3] = {corners[c][0] - P[0], corners[c][1] - P[1], corners[c][2] - P[2]};
                float z = dot3(q, w);
                if (!(z > 0.0f)) {
                    in_front = 0;
                    break;
                }
                float x = dot3(q, u) / z, y = dot3(q, v) / z;
                lo[0] = fminf(lo[0], x);
                hi[0] = fmaxf(hi[0], x);
                lo[1] = fminf(lo[1], y);
                hi[1] = fmaxf(hi[1], y);
                tmax = fmaxf(tmax, fmaxf(fabsf(x), fabsf(y)));
            }
            /* tan(70 deg) = 2.75: beyond that a frustum wastes most texels at its rim. */
            if (in_front && tmax < 2.75f)
                S->ls_mode = UMBRA_LS_PERSPECTIVE;
        } else {
            const float up[3] = {0.0f, 1.0f, 0.0f};
            basis_from(up, u, v, w);
        }
        if (S->ls_mode == UMBRA_LS_OCTAHEDRAL) {
            lo[0] = lo[1] = -1.0f;
            hi[0] = hi[1] = 1.0f;
        }
    }
    const double across =
        voxels_across(r, (int)S->ls_mode, fmax((double)hi[0] - lo[0], (double)hi[1] - lo[1]),
                      S->ls_mode == UMBRA_LS_PERSPECTIVE ? dist_centre : 1.0, hi[2]);
    if (map_size == UMBRA_MAP_SIZE_AUTO)
        map_size = auto_map_size(r, across);
    S->map_size = map_size;
    r->stats.map_size = map_size;
    /* Half a texel of margin so that bilinear taps at the rim still see the box. */
    for (int a = 0; a < 2; ++a) {
        float pad = S->ls_mode == UMBRA_LS_OCTAHEDRAL ? 0.0f : (hi[a] - lo[a]) / (float)map_size;
        lo[a] -= pad;
        hi[a] += pad;
        if (!(hi[a] > lo[a]))
            hi[a] = lo[a] + 1e-6f;
    }
    if (!(hi[2] > lo[2]))
        hi[2] = lo[2] + 1e-6f;
    set4(S->ls_u, u, 0.0f);
    set4(S->ls_v, v, 0.0f);
    set4(S->ls_w, w, 0.0f);
    S->ls_window[0] = lo[0];
    S->ls_window[1] = lo[1];
    S->ls_window[2] = 1.0f / (hi[0] - lo[0]);
    S->ls_window[3] = 1.0f / (hi[1] - lo[1]);
    S->near_far[0] = lo[2];
    S->near_far[1] = hi[2];
    S->near_far[2] = 1.0f / (hi[2] - lo[2]);
    S->near_far[3] = 0.0f;
    return across > 0.0 ? (double)map_size / across : INFINITY; /* across 0 or NaN: no extent */
}
