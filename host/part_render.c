// SPDX-License-Identifier: Apache-2.0
/* host/part_render.c: the renderer's side of a part (umbra/part.h): its screen rectangle, its
 * view segment rendered into a partial image (the light data that crosses parts is
 * host/part_light.c).
 *
 * A part's frame is the global volume's (host/frame.c fills the box, dims and camera from the
 * global grid, grid_dims); umbra__part_frame adds where the carried voxels lie and which samples
 * the part owns, and the ray caster, built with UMBRA_PART 1, takes only those
 * (kernels/raycast.cl, part_owns) and addresses the carried voxels (kernels/common/sampling.cl,
 * PART_INDEX). */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lightspace.h"
#include "part_light.h"
#include "renderer_internal.h"

static const char *const AXIS = "xyz";

static int part_empty(const umbra_part_desc *p)
{
    return p->size[0] == 0 || p->size[1] == 0 || p->size[2] == 0;
}

void umbra__part_frame(umbra_renderer r, int view)
{
    UmbraFrame *F = &r->frame;
    umbra_volume v = r->volume;
    memset(F->part_shift, 0, sizeof F->part_shift);
    memset(F->part_dims, 0, sizeof F->part_dims);
    memset(F->part_lo, 0, sizeof F->part_lo);
    memset(F->part_hi, 0, sizeof F->part_hi);
    if (!v || !v->is_part)
        return;
    const umbra_part_desc *p = &v->part;
    for (int a = 0; a < 3; ++a) {
        F->part_shift[a] = (int32_t)p->offset[a] - (int32_t)p->ghost_lo[a];
        F->part_dims[a] = (int32_t)v->dims[a];
        const uint32_t end = p->offset[a] + p->size[a];
        F->part_lo[a] = p->offset[a] == 0 ? -INFINITY : (float)p->offset[a];
        F->part_hi[a] = end >= p->global_dims[a] ? INFINITY : (float)end;
        if (part_empty(p)) {
            F->part_lo[a] = INFINITY;
            F->part_hi[a] = -INFINITY;
        }
    }
    F->flags &= ~UMBRA_FLAG_SKIP_EMPTY;
    if (view)
        memset(F->background, 0, sizeof F->background);
    if (view && r->part_front)
        F->flags |= UMBRA_FLAG_PART_FRONT;
}

/* The rectangle of the width x height image the core box's corners project to, grown by a pixel
 * (r->frame's camera must be up to date); the whole image when a corner lies behind the eye. */
static void part_rect(umbra_renderer r, uint32_t width, uint32_t height, umbra_part_rect *out)
{
    const umbra_part_desc *p = &r->volume->part;
    memset(out, 0, sizeof *out);
    if (part_empty(p))
        return;
    const UmbraFrame *F = &r->frame;
    const int ortho = (F->flags & UMBRA_FLAG_ORTHO) != 0;
    double rr = 0.0, uu = 0.0;
    for (int k = 0; k < 3; ++k) {
        rr += (double)F->right[k] * F->right[k];
        uu += (double)F->up[k] * F->up[k];
    }
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    int whole = !(rr > 0.0 && uu > 0.0);
    for (int c = 0; c < 8 && !whole; ++c) {
        double v[3], z = 0.0, sx = 0.0, sy = 0.0;
        for (int a = 0; a < 3; ++a) {
            const uint32_t i = (c >> a) & 1 ? p->offset[a] + p->size[a] : p->offset[a];
            const double spacing = 1.0 / (double)F->inv_spacing[a];
            v[a] = (double)F->box_min[a] + (double)i * spacing - F->eye[a];
        }
        for (int k = 0; k < 3; ++k) {
            z += v[k] * F->forward[k];
            sx += v[k] * F->right[k];
            sy += v[k] * F->up[k];
        }
        sx /= rr;
        sy /= uu;
        if (!ortho) {
            if (!(z > 1e-9)) {
                whole = 1;
                break;
            }
            sx /= z;
            sy /= z;
        }
        /* camera_ray: sx = (px + 0.5) / w * 2 - 1, sy = 1 - (py + 0.5) / h * 2. */
        const double px = (sx + 1.0) * 0.5 * width - 0.5, py = (1.0 - sy) * 0.5 * height - 0.5;
        x0 = fmin(x0, px);
        x1 = fmax(x1, px);
        y0 = fmin(y0, py);
        y1 = fmax(y1, py);
    }
    if (whole) {
        out->width = width;
        out->height = height;
        return;
    }
    x0 = fmax(floor(x0) - 1.0, 0.0);
    y0 = fmax(floor(y0) - 1.0, 0.0);
    x1 = fmin(ceil(x1) + 1.0, (double)width - 1.0);
    y1 = fmin(ceil(y1) + 1.0, (double)height - 1.0);
    if (!(x1 >= x0 && y1 >= y0))
        return;
    out->x = (uint32_t)x0;
    out->y = (uint32_t)y0;
    out->width = (uint32_t)(x1 - x0) + 1;
    out->height = (uint32_t)(y1 - y0) + 1;
}

/* What a part cannot render, each refused naming the reason; then the ghost layers. */
static umbra_status check_part_render(umbra_renderer r, const char *fn)
{
    umbra_context ctx = r->ctx;
    if (!r->volume || !r->tf)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: set a volume and a transfer function first (volume %p, tf %p)", fn,
                           (void *)r->volume, (void *)r->tf);
    umbra_volume v = r->volume;
    if (!v->is_part)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: the volume is not a part: make it with umbra_volume_create_part",
                           fn);
    const char *tech = umbra_shadow_technique_name(r->shadow_set.technique);
    switch (r->shadow_set.technique) {
    case UMBRA_SHADOW_NONE:
        break;
    case UMBRA_SHADOW_REFERENCE:
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique %s does not split into parts: its shadow rays from "
                           "every sample would cross the other parts", fn, tech);
    case UMBRA_SHADOW_CONVOLUTION:
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique %s does not split into parts: its slices carry the light "
                           "over the whole view depth", fn, tech);
    case UMBRA_SHADOW_THRESHOLD: /* after its exchange: render_part checks */
    case UMBRA_SHADOW_CSSM:
        break;
    case UMBRA_SHADOW_DEEP: {
        const umbra_status st = umbra__part_check_deep(r, fn);
        if (st != UMBRA_SUCCESS)
            return st;
        break;
    }
    default:
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique %s is refused on a part: its light structure has no "
                           "exchange between parts", fn, tech ? tech : "?");
    }
    const umbra_render_desc *o = &r->opts;
    if (o->mode != UMBRA_RENDER_COMPOSITE)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: render mode %d (a projection mode) is refused on a part: only "
                           "compositing splits", fn, (int)o->mode);
    if (o->preintegrated)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: preintegrated is refused on a part: a segment reaches into the "
                           "next part", fn);
    if (o->ground_plane)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: ground_plane is refused on a part: the plane lies outside every "
                           "part's box", fn);
    if (o->interaction != UMBRA_INTERACTION_OFF)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: interaction AUTO is refused on a part: a draft changes the map "
                           "each part builds", fn);
    if (v->slab_count > 1 || umbra__volume_images(v))
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: a part is sampled from one buffer: this one is %s", fn,
                           v->slab_count > 1 ? "split into slabs" : "a 3D image (image sampler)");
    const umbra_part_desc *p = &v->part;
    if (part_empty(p))
        return UMBRA_SUCCESS;
    const uint32_t need = umbra_part_ghost_needed(o);
    for (int a = 0; a < 3; ++a) {
        if (p->offset[a] > 0 && p->ghost_lo[a] < need)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ghost_lo[%d] (%c) is %u: the lower %c face is shared and these "
                               "options need %u ghost layers (umbra_part_ghost_needed)", fn, a,
                               AXIS[a], p->ghost_lo[a], AXIS[a], need);
        if (p->offset[a] + p->size[a] < p->global_dims[a] && p->ghost_hi[a] < need)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ghost_hi[%d] (%c) is %u: the upper %c face is shared and these "
                               "options need %u ghost layers (umbra_part_ghost_needed)", fn, a,
                               AXIS[a], p->ghost_hi[a], AXIS[a], need);
    }
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_part_rect(umbra_renderer r, uint32_t width, uint32_t height,
                                      umbra_part_rect *out)
{
    CHECK_R();
    const char *fn = __func__;
    if (!out)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    memset(out, 0, sizeof *out);
    umbra_status st = umbra__check_size(r, width, height, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    if (!r->volume || !r->volume->is_part || !r->tf)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: set a part volume (umbra_volume_create_part) and a transfer "
                           "function first", fn);
    if ((st = umbra__effective_tfs(r)) != UMBRA_SUCCESS)
        return st;
    umbra__frame_update_light(r);
    umbra__frame_update_view(r, width, height);
    part_rect(r, width, height, out);
    return UMBRA_SUCCESS;
}

/* The front state of the frame's rectangle refused naming the first bad pixel: an opacity
 * outside [0, 1] or a NaN. */
static umbra_status check_front(umbra_renderer r, const char *fn, const float *frame,
                                uint32_t width, const umbra_part_rect *rect)
{
    for (uint32_t y = rect->y; y < rect->y + rect->height; ++y)
        for (uint32_t x = rect->x; x < rect->x + rect->width; ++x) {
            const float *p = frame + ((size_t)y * width + x) * 4;
            if (!(p[3] >= 0.0f && p[3] <= 1.0f) || isnan(p[0]) || isnan(p[1]) || isnan(p[2]))
                return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                   "%s: frame pixel (%u, %u): (%g, %g, %g, %g) must have an "
                                   "opacity in [0, 1] and no NaN (premultiplied RGBA of the "
                                   "parts in front)", fn, x, y, p[0], p[1], p[2], p[3]);
        }
    return UMBRA_SUCCESS;
}

/* out receives the rectangle's partial image (into 0), or the width x height frame out's
 * rectangle goes on from the accumulation in it and is written back (into 1). */
static umbra_status render_part(umbra_renderer r, const char *fn, uint32_t width, uint32_t height,
                                umbra_part_rect *rect_out, float *out, int into)
{
    float *rgba = into ? NULL : out, *frame = into ? out : NULL;
    umbra_context ctx = r->ctx;
    umbra_status st = umbra__check_size(r, width, height, fn);
    if (st == UMBRA_SUCCESS)
        st = check_part_render(r, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: %s is NULL", fn,
                           into ? "frame" : "rgba");
    if ((st = umbra__effective_tfs(r)) != UMBRA_SUCCESS)
        return st;
    /* A light build now (if its inputs changed) would overwrite the imported depths (or the
     * deep map's merged pieces). */
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
    if (light) {
        if ((st = umbra__prepare_shadow(r, 0.5, 1)) != UMBRA_SUCCESS)
            return st;
        const int pieces = light->shares == SHARES_PIECES;
        if (!r->part_depths_valid || r->part_depths_at != r->rebuilds.shadow)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: technique %s: import the %s of all parts (%s) after the last "
                               "light build", fn, umbra_shadow_technique_name(light->technique),
                               pieces ? "pieces" : "depths",
                               pieces ? "umbra_renderer_part_import_deep"
                                      : "umbra_renderer_part_import_depths");
    }
    umbra__frame_update_light(r);
    umbra__frame_update_view(r, width, height);
    umbra_part_rect rect;
    part_rect(r, width, height, &rect);
    if (rect_out)
        *rect_out = rect;
    if (!rect.width || !rect.height)
        return UMBRA_SUCCESS;
    /* The whole frame is cast (rays that miss the part's box end at once), and the rectangle is
     * read back. */
    const size_t bytes = (size_t)width * height * 4 * sizeof(float);
    if (r->out_bytes != bytes)
        umbra__release_mem(&r->out_buf);
    if ((st = umbra__ensure_buffer(r, &r->out_buf, bytes, CL_MEM_READ_WRITE)) != UMBRA_SUCCESS)
        return st;
    r->out_bytes = bytes;
    const size_t px = 4 * sizeof(float);
    const size_t origin[3] = {rect.x * px, rect.y, 0};
    const size_t region[3] = {rect.width * px, rect.height, 1};
    if (frame) {
        /* The rays of the rectangle go on from the front state (kernels/raycast.cl). */
        if ((st = check_front(r, fn, frame, width, &rect)) != UMBRA_SUCCESS)
            return st;
        UMBRA_CL(clEnqueueWriteBufferRect(ctx->queue, r->out_buf, CL_TRUE, origin, origin,
                                          region, width * px, 0, width * px, 0, frame, 0, NULL,
                                          NULL));
    }
    r->part_call = 1;
    r->part_front = frame != NULL;
    st = umbra__render_into(r, width, height, r->out_buf);
    r->part_call = 0;
    r->part_front = 0;
    if (st != UMBRA_SUCCESS)
        return st;
    if (frame)
        UMBRA_CL(clEnqueueReadBufferRect(ctx->queue, r->out_buf, CL_TRUE, origin, origin, region,
                                         width * px, 0, width * px, 0, frame, 0, NULL, NULL));
    else
        UMBRA_CL(clEnqueueReadBufferRect(ctx->queue, r->out_buf, CL_TRUE, origin,
                                         (size_t[3]){0, 0, 0}, region, width * px, 0,
                                         rect.width * px, 0, rgba, 0, NULL, NULL));
    umbra__progress_end(r);
fail:
    return st;
}

umbra_status umbra_renderer_render_part(umbra_renderer r, uint32_t width, uint32_t height,
                                        umbra_part_rect *rect, float *rgba)
{
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = render_part(r, __func__, width, height, rect, rgba, 0);
        umbra__call_end(r);
    }
    return st;
}

umbra_status umbra_renderer_render_part_into(umbra_renderer r, uint32_t width, uint32_t height,
                                             umbra_part_rect *rect, float *frame)
{
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = render_part(r, __func__, width, height, rect, frame, 1);
        umbra__call_end(r);
    }
    return st;
}

