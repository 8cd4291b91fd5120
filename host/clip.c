// SPDX-License-Identifier: Apache-2.0
/* host/clip.c: the clip region (umbra_renderer_set_clip): the planes and crop box the
 * application gives, checked, and taken into the volume's local frame as the kernels' UmbraClip
 * (kernels/common/umbra_shared.h), which every view ray, light ray, shadow ray and convolution
 * slice reads (kernels/common/common.cl, clip_interval). The region is part of the light key: a
 * change rebuilds the shadow structure (UMBRA_REBUILD_CLIP), never the view tables. */
#include <math.h>
#include <string.h>

#include "renderer_internal.h"

_Static_assert(UMBRA_MAX_CLIP_PLANES == UMBRA_CLIP_PLANES, "clip planes");

void umbra_clip_desc_init(umbra_clip_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
}

umbra_status umbra_renderer_set_clip(umbra_renderer r, const umbra_clip_desc *desc)
{
    const char *fn = "umbra_renderer_set_clip";
    CHECK_R();
    umbra_clip_desc d;
    umbra_clip_desc_init(&d);
    if (!desc) {
        r->clip = d;
        return UMBRA_SUCCESS;
    }
    if (desc->struct_size != sizeof d)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size %zu != %zu: call umbra_clip_desc_init", fn,
                           desc->struct_size, sizeof d);
    if (desc->plane_count > UMBRA_MAX_CLIP_PLANES)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: plane_count %u exceeds UMBRA_MAX_CLIP_PLANES (%d)", fn,
                           desc->plane_count, UMBRA_MAX_CLIP_PLANES);
    for (uint32_t i = 0; i < desc->plane_count; ++i) {
        const float *p = desc->planes[i];
        const double n = umbra__len3d(p);
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) || !isfinite(p[3]) ||
            !(n > 0.0) || !isfinite(n) || !(fabs(p[3]) / n <= UMBRA_MAX_COORDINATE))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: plane %u (%g, %g, %g, %g) must be finite with a non-zero "
                               "normal (a, b, c) and lie within %g of the origin "
                               "(UMBRA_MAX_COORDINATE)", fn, i, p[0], p[1], p[2], p[3],
                               UMBRA_MAX_COORDINATE);
    }
    if (desc->crop) {
        static const char axis[3] = {'x', 'y', 'z'};
        for (int a = 0; a < 3; ++a)
            if (!isfinite(desc->crop_min[a]) || !isfinite(desc->crop_max[a]) ||
                !(desc->crop_min[a] <= desc->crop_max[a]) ||
                !(fabsf(desc->crop_min[a]) <= 1e9f) || !(fabsf(desc->crop_max[a]) <= 1e9f))
                return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                   "%s: crop box along %c [%g, %g] voxels must be finite, within "
                                   "+-1e9, with min <= max", fn, axis[a], desc->crop_min[a],
                                   desc->crop_max[a]);
    }
    d = *desc;
    for (uint32_t i = d.plane_count; i < UMBRA_MAX_CLIP_PLANES; ++i)
        memset(d.planes[i], 0, sizeof d.planes[i]);
    if (!d.crop) {
        memset(d.crop_min, 0, sizeof d.crop_min);
        memset(d.crop_max, 0, sizeof d.crop_max);
    }
    d.crop = d.crop != 0;
    r->clip = d;
    return UMBRA_SUCCESS;
}

void umbra__clip_update(umbra_renderer r)
{
    UmbraClip *C = &r->shadow_params.clip;
    const umbra_clip_desc *d = &r->clip;
    umbra_volume v = r->volume;
    memset(C, 0, sizeof *C); /* the light key compares it byte for byte */
    if (!d->crop && d->plane_count == 0)
        return;
    C->active = 1;
    C->plane_count = d->plane_count;
    /* Voxel i's centre lies at box_min + (i + 0.5) spacing in the local frame; without a crop
     * box the region's box is the volume's. */
    for (int a = 0; a < 3; ++a) {
        const float half = 0.5f * (float)v->grid_dims[a] * v->spacing[a];
        C->box_min[a] = d->crop ? -half + (d->crop_min[a] + 0.5f) * v->spacing[a] : -half;
        C->box_max[a] = d->crop ? -half + (d->crop_max[a] + 0.5f) * v->spacing[a] : half;
    }
    for (uint32_t i = 0; i < d->plane_count; ++i) {
        /* The unit normal and the plane's point nearest the world origin, both taken into the
         * local frame (the map is rigid): n.p + w = 0 there with w = -n.q. */
        const double len = umbra__len3d(d->planes[i]);
        float n[3], q[3], nl[3], ql[3];
        for (int k = 0; k < 3; ++k) {
            n[k] = (float)(d->planes[i][k] / len);
            q[k] = (float)(-(double)d->planes[i][3] / len * (double)n[k]);
        }
        umbra__volume_dir_to_local(v, n, nl);
        umbra__volume_point_to_local(v, q, ql);
        for (int k = 0; k < 3; ++k)
            C->planes[i][k] = nl[k];
        C->planes[i][3] = -(nl[0] * ql[0] + nl[1] * ql[1] + nl[2] * ql[2]);
    }
}
