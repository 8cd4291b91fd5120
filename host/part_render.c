// SPDX-License-Identifier: Apache-2.0
/* host/part_render.c: the renderer's side of a part (umbra/part.h): its screen rectangle, its
 * view segment rendered into a partial image, and the light data that crosses parts.
 *
 * A part's frame is the global volume's (host/frame.c fills the box, dims and camera from the
 * global grid, grid_dims); umbra__part_frame adds where the carried voxels lie and which samples
 * the part owns, and the ray caster, built with UMBRA_PART 1, takes only those
 * (kernels/raycast.cl, part_owns) and addresses the carried voxels (kernels/common/sampling.cl,
 * PART_INDEX). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lightspace.h"
#include "renderer_internal.h"
#include "techniques/deep.h"
#include "techniques/deep_shared.h"
#include "techniques/maps.h"

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

/* The deep map on a part: one light ray per texel (the pre-filter's sub-rays would cross a
 * face at different depths, and a segment's nodes combine all of them), the unbounded map (a
 * budget chooses its nodes once the whole ray is known) and a light step of at most a voxel (a
 * segment's two ends then lie within the one ghost layer of the owned midpoint). */
static umbra_status check_part_deep(umbra_renderer r, const char *fn)
{
    const umbra_deep_desc *d = &r->shadow_set.deep;
    if (d->prefilter != 1)
        return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique deep with prefilter %u is refused on a part: the "
                           "sub-texel rays cross the parts' faces at different depths "
                           "(prefilter 1 splits)", fn, d->prefilter);
    if (d->max_nodes != 0)
        return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique deep with max_nodes %u is refused on a part: the "
                           "budget chooses a texel's nodes once its whole ray is known (the "
                           "unbounded map, max_nodes 0, splits)", fn, d->max_nodes);
    const float step = umbra__map_light_step(&r->shadow_set);
    if (!(step <= 1.0f))
        return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique deep with a light step of %g voxels is refused on a "
                           "part: a segment's ends must lie within the ghost layer of its "
                           "midpoint (map_step <= 1)", fn, (double)step);
    return UMBRA_SUCCESS;
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
        const umbra_status st = check_part_deep(r, fn);
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

/* A technique whose parts march the light (threshold, CSSM, deep): the state one part hands the
 * next on a texel's light ray, and what the parts share once all have marched.
 *  - state: per texel a run of fields, each one float or one per light channel (r->channels,
 *    set by umbra__frame_update_light); per field its value for a part first on the ray, the
 *    range an import must lie in, whether it counts (an integer) and its name;
 *  - shares: a depth per texel or per channel, which the parts reduce with umbra_part_minimum,
 *    or the pieces of the deep map, merged per texel (umbra_renderer_part_export_deep). */
typedef enum { SHARES_DEPTH, SHARES_DEPTH_PER_CHANNEL, SHARES_PIECES } PartShares;

typedef struct PartField {
    const char *name;
    int per_channel, integral;
    float start, lo, hi;
} PartField;

typedef struct PartLight {
    umbra_shadow_technique technique;
    const PartField *fields;
    uint32_t field_count;
    PartShares shares;
} PartLight;

/* kernels/techniques/threshold.cl: the product P of whole segments' 1 - alpha and the optical
 * depth tau. */
static const PartField THRESHOLD_STATE[] = {
    {"transmittance product", 0, 0, 1.0f, 0.0f, 1.0f},
    {"optical depth", 0, 0, 0.0f, 0.0f, INFINITY},
};
/* kernels/techniques/cssm.cl: the optical depth of each channel's photon. */
static const PartField CSSM_STATE[] = {{"optical depth", 1, 0, 0.0f, 0.0f, INFINITY}};
/* kernels/techniques/deep.cl (deep_state_load): the march's visibility and its fit's state, in
 * the order of kernels/techniques/deep_shared.h (DEEP_PART_STATE_FLOATS), starting as
 * deep_texel_init and deep_fit_init start a ray. */
static const PartField DEEP_STATE[] = {
    {"visibility", 1, 0, 1.0f, 0.0f, 1.0f},
    {"fit origin depth", 0, 0, 0.0f, -INFINITY, INFINITY},
    {"fit origin visibility", 1, 0, 1.0f, 0.0f, 1.0f},
    {"last point's depth", 0, 0, 0.0f, -INFINITY, INFINITY},
    {"last point's visibility", 1, 0, 1.0f, 0.0f, 1.0f},
    {"held point's depth", 0, 0, 0.0f, -INFINITY, INFINITY},
    {"held point's visibility", 1, 0, 1.0f, 0.0f, 1.0f},
    {"lowest slope", 1, 0, 0.0f, -INFINITY, INFINITY},
    {"highest slope", 1, 0, 0.0f, -INFINITY, INFINITY},
    {"points since the origin", 0, 1, 0.0f, 0.0f, 16777216.0f},
    {"origin emitted", 0, 1, 0.0f, 0.0f, 1.0f},
    {"point held", 0, 1, 0.0f, 0.0f, 1.0f},
    {"last pushed depth", 0, 0, -INFINITY, -INFINITY, INFINITY},
};

#define FIELDS(a) a, sizeof a / sizeof a[0]
static const PartLight PART_LIGHTS[] = {
    {UMBRA_SHADOW_THRESHOLD, FIELDS(THRESHOLD_STATE), SHARES_DEPTH},
    {UMBRA_SHADOW_CSSM, FIELDS(CSSM_STATE), SHARES_DEPTH_PER_CHANNEL},
    {UMBRA_SHADOW_DEEP, FIELDS(DEEP_STATE), SHARES_PIECES},
};
#undef FIELDS

static const PartLight *part_light(umbra_shadow_technique t)
{
    for (size_t i = 0; i < sizeof PART_LIGHTS / sizeof PART_LIGHTS[0]; ++i)
        if (PART_LIGHTS[i].technique == t)
            return &PART_LIGHTS[i];
    return NULL;
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
    const PartLight *light = part_light(r->shadow_set.technique);
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

/* ---- the light exchange -------------------------------------------------------------------- */

static uint32_t state_floats(umbra_renderer r, const PartLight *light)
{
    uint32_t n = 0;
    for (uint32_t f = 0; f < light->field_count; ++f)
        n += light->fields[f].per_channel ? r->channels : 1u;
    return n;
}

static uint32_t depth_floats(umbra_renderer r, const PartLight *light)
{
    return light->shares == SHARES_DEPTH ? 1u
           : light->shares == SHARES_DEPTH_PER_CHANNEL ? r->channels
                                                       : 0u;
}

/* The field of a texel's state float i (0 <= i < state_floats). */
static const PartField *state_field(umbra_renderer r, const PartLight *light, uint32_t i)
{
    for (uint32_t f = 0;; ++f) {
        const uint32_t w = light->fields[f].per_channel ? r->channels : 1u;
        if (i < w || f + 1 == light->field_count)
            return &light->fields[f];
        i -= w;
    }
}

/* An imported state's first bad value, refused naming its texel, field and value. */
static umbra_status state_check(umbra_renderer r, const PartLight *light, const char *fn,
                                const float *s, uint32_t n)
{
    const uint32_t per = state_floats(r, light);
    for (size_t i = 0; i < (size_t)n * n * per; ++i) {
        const PartField *f = state_field(r, light, (uint32_t)(i % per));
        if (!(s[i] >= f->lo && s[i] <= f->hi) || (f->integral && s[i] != floorf(s[i])))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: texel %zu (%zu, %zu): %s %g (state float %zu) must %s "
                               "[%g, %g] (technique %s's march state)", fn, i / per,
                               i / per % n, i / per / n, f->name, (double)s[i], i % per,
                               f->integral ? "be an integer in" : "lie in", (double)f->lo,
                               (double)f->hi, umbra_shadow_technique_name(light->technique));
    }
    return UMBRA_SUCCESS;
}

static int is_deep(umbra_renderer r)
{
    return r->shadow_set.technique == UMBRA_SHADOW_DEEP;
}

/* The deep march state's fields (DEEP_STATE) that must agree with each other, beyond each lying
 * in its own range: exactly what every march leaves (kernels/techniques/deep.cl, deep_fit_feed),
 * so no state a part exported is refused. Until the fit's origin node is emitted no point has
 * been fed and the origin's visibility is 1; once points are fed, the window of slopes that
 * keeps them within tolerance is not empty (lowest <= highest: the windows are intersected only
 * while they overlap, and a point's own window always holds its exact slope). A state that
 * breaks either is none a march could leave, and the part would go on from a fit that no single
 * device's march ever holds. Run after state_check, so every value is a number. */
static umbra_status deep_state_check(umbra_renderer r, const char *fn, const float *s, uint32_t n)
{
    const uint32_t C = r->channels, per = DEEP_PART_STATE_FLOATS(C);
    const uint32_t v0 = C + 1, lo = 4 * C + 3, hi = 5 * C + 3, npts = 6 * C + 3;
    const uint32_t started = npts + 1;
    for (size_t t = 0; t < (size_t)n * n; ++t) {
        const float *x = s + t * per;
        /* The point count and the origin's flag are the texel's, not a channel's. */
        const char *why = x[started] == 0.0f && x[npts] != 0.0f
                              ? "points since the origin must be 0 while the origin is not emitted"
                              : NULL;
        int channel = -1; /* the channel refused, if a channel's field is */
        for (uint32_t c = 0; !why && c < C; ++c) {
            if (x[started] == 0.0f && x[v0 + c] != 1.0f)
                why = "fit origin visibility must be 1 while the origin is not emitted";
            else if (x[npts] > 0.0f && !(x[lo + c] <= x[hi + c]))
                why = "lowest slope must not exceed the highest once points are fed";
            channel = why ? (int)c : -1;
        }
        if (why) {
            char named[32] = "";
            if (channel >= 0)
                snprintf(named, sizeof named, ", channel %d", channel);
            const uint32_t c = channel >= 0 ? (uint32_t)channel : 0;
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: texel %zu (%zu, %zu)%s: %s (points %g, origin emitted %g, "
                               "origin visibility %g, slopes [%g, %g]; technique deep's march "
                               "state)", fn, t, t % n, t / n, named, why, (double)x[npts],
                               (double)x[started], (double)x[v0 + c], (double)x[lo + c],
                               (double)x[hi + c]);
        }
    }
    return UMBRA_SUCCESS;
}

static umbra_status light_unsupported(umbra_renderer r, const char *fn)
{
    const char *tech = umbra_shadow_technique_name(r->shadow_set.technique);
    return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                       "%s: technique %s has no light exchange between parts (none, "
                       "threshold, cssm and deep have)", fn, tech ? tech : "?");
}

/* The light inputs brought up to date and the map size chosen, for a part whose technique
 * exchanges light (PART_LIGHTS). */
static umbra_status light_ready(umbra_renderer r, const char *fn, uint32_t *map_size)
{
    if (!r->volume || !r->volume->is_part || !r->tf)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: set a part volume (umbra_volume_create_part) and a transfer "
                           "function first", fn);
    const PartLight *light = part_light(r->shadow_set.technique);
    if (!light)
        return light_unsupported(r, fn);
    umbra_status st = is_deep(r) ? check_part_deep(r, fn) : UMBRA_SUCCESS;
    if (st == UMBRA_SUCCESS)
        st = umbra__effective_tfs(r);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra__frame_update_light(r);
    r->shadow = r->shadow_set; /* what the build will use: parts refuse drafts */
    umbra__lightspace_setup(r, r->shadow.map.size);
    *map_size = r->shadow_params.map_size;
    return UMBRA_SUCCESS;
}

umbra_status umbra__part_bind_build(umbra_renderer r, cl_kernel k, cl_uint index, uint32_t n)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const PartLight *light = part_light(r->shadow_set.technique);
    const uint32_t per = state_floats(r, light);
    const size_t floats = (size_t)n * n * per, bytes = floats * sizeof(float);
    if (r->part_state_in && r->part_state_floats != floats)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_render_part: the imported transmittance holds %zu "
                           "floats, the %u x %u map %zu: import it again", r->part_state_floats, n,
                           n, floats);
    float *init = NULL;
    const float *src = r->part_state_in;
    if (!src) {
        if (!(init = malloc(bytes)))
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory",
                               "umbra_renderer_render_part");
        for (size_t i = 0; i < floats; ++i)
            init[i] = state_field(r, light, (uint32_t)(i % per))->start;
        src = init;
    }
    size_t have = 0;
    if (r->part_state_buf)
        UMBRA_CL(clGetMemObjectInfo(r->part_state_buf, CL_MEM_SIZE, sizeof have, &have, NULL));
    if (have != bytes)
        umbra__release_mem(&r->part_state_buf);
    if ((st = umbra__ensure_buffer(r, &r->part_state_buf, bytes, CL_MEM_READ_WRITE)) !=
        UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, r->part_state_buf, CL_TRUE, 0, bytes, src, 0, NULL,
                                  NULL));
    UMBRA_CL(clSetKernelArg(k, index, sizeof(cl_mem), &r->part_state_buf));
fail:
    free(init);
    return st;
}

static umbra_status light_info(umbra_renderer r, const char *fn, umbra_part_light_info *out)
{
    if (r->shadow_set.technique == UMBRA_SHADOW_NONE) {
        out->kind = UMBRA_PART_LIGHT_NOTHING;
        return UMBRA_SUCCESS;
    }
    uint32_t n = 0;
    umbra_status st = light_ready(r, fn, &n);
    if (st != UMBRA_SUCCESS)
        return st;
    const PartLight *light = part_light(r->shadow_set.technique);
    out->kind = light->shares == SHARES_PIECES ? UMBRA_PART_LIGHT_TAU : UMBRA_PART_LIGHT_TAU_DEPTH;
    out->map_size = n;
    out->channels = state_floats(r, light);
    out->depth_channels = depth_floats(r, light);
    out->tau_floats = (size_t)n * n * out->channels;
    out->depth_floats = (size_t)n * n * out->depth_channels;
    out->node_floats = light->shares == SHARES_PIECES ? 1 + r->channels : 0;
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_part_light_info(umbra_renderer r, umbra_part_light_info *out)
{
    CHECK_R();
    /* The struct before node_floats (2026-12-03) is the smallest one taken. */
    const size_t old_size = offsetof(umbra_part_light_info, node_floats);
    if (!out || (out->struct_size != sizeof *out && out->struct_size != old_size))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: out %p must be non-NULL with struct_size %zu (or %zu)", __func__,
                           (void *)out, sizeof *out, old_size);
    umbra_part_light_info info;
    memset(&info, 0, sizeof info);
    info.struct_size = out->struct_size;
    umbra_status st = light_info(r, __func__, &info);
    if (st == UMBRA_SUCCESS)
        memcpy(out, &info, info.struct_size);
    return st;
}

/* Builds the light structure if its inputs changed (the import of tau_in is one). */
static umbra_status build(umbra_renderer r, const char *fn, uint32_t *n)
{
    umbra_status st = light_ready(r, fn, n);
    if (st == UMBRA_SUCCESS)
        st = umbra__prepare_shadow(r, 1.0, 0);
    if (st == UMBRA_SUCCESS && r->shadow_params.map_size != *n)
        st = umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: the map built has %u texels a side, not %u", fn,
                         r->shadow_params.map_size, *n);
    return st;
}

/* The exports: builds if needed, then reads the march state (depths 0) or the depth map. */
static umbra_status export_light(umbra_renderer r, const char *fn, float *out, int depths)
{
    if (!out)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: the array is NULL", fn);
    uint32_t n = 0;
    umbra_status st = umbra__call_begin(r, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_context ctx = r->ctx;
    if ((st = build(r, fn, &n)) != UMBRA_SUCCESS)
        goto fail;
    const PartLight *light = part_light(r->shadow_set.technique);
    if (depths && light->shares == SHARES_PIECES) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: technique deep exchanges pieces of its map, not depths "
                         "(umbra_renderer_part_export_deep)", fn);
    } else if (depths) {
        st = umbra__map_read(r, out, (size_t)n * n * depth_floats(r, light) * sizeof(float));
    } else if (!r->part_state_buf) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: no march state was built", fn);
    } else {
        UMBRA_CL(clEnqueueReadBuffer(ctx->queue, r->part_state_buf, CL_TRUE, 0,
                                     (size_t)n * n * state_floats(r, light) * sizeof(float), out,
                                     0, NULL, NULL));
    }
fail:
    umbra__call_end(r);
    return st;
}

umbra_status umbra_renderer_part_export_transmittance(umbra_renderer r, float *tau_exit)
{
    CHECK_R();
    return export_light(r, __func__, tau_exit, 0);
}

umbra_status umbra_renderer_part_import_transmittance(umbra_renderer r, const float *tau_in)
{
    CHECK_R();
    const char *fn = __func__;
    uint32_t n = 0;
    umbra_status st = light_ready(r, fn, &n);
    if (st != UMBRA_SUCCESS)
        return st;
    const PartLight *light = part_light(r->shadow_set.technique);
    const size_t floats = (size_t)n * n * state_floats(r, light);
    float *copy = NULL;
    if (tau_in) {
        if ((st = state_check(r, light, fn, tau_in, n)) != UMBRA_SUCCESS ||
            (is_deep(r) && (st = deep_state_check(r, fn, tau_in, n)) != UMBRA_SUCCESS))
            return st;
        if (!(copy = malloc(floats * sizeof *copy)))
            return umbra__fail(r->ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
        memcpy(copy, tau_in, floats * sizeof *copy);
    }
    free(r->part_state_in);
    r->part_state_in = copy;
    r->part_state_floats = copy ? floats : 0;
    r->built_valid = 0; /* the next build marches from the new state */
    r->part_depths_valid = 0;
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_part_export_depths(umbra_renderer r, float *depths)
{
    CHECK_R();
    return export_light(r, __func__, depths, 1);
}

umbra_status umbra_renderer_part_import_depths(umbra_renderer r, const float *depths)
{
    CHECK_R();
    const char *fn = __func__;
    if (!depths)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: depths is NULL", fn);
    uint32_t n = 0;
    umbra_status st = umbra__call_begin(r, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    if ((st = build(r, fn, &n)) != UMBRA_SUCCESS)
        goto done;
    const PartLight *light = part_light(r->shadow_set.technique);
    if (light->shares == SHARES_PIECES) {
        st = umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: technique deep imports pieces of its map, not depths "
                         "(umbra_renderer_part_import_deep)", fn);
        goto done;
    }
    const size_t ch = depth_floats(r, light);
    for (size_t i = 0; i < (size_t)n * n * ch; ++i)
        if (isnan(depths[i])) {
            st = umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "%s: texel %zu (%zu, %zu): the depth is NaN", fn, i / ch,
                             i / ch % n, i / ch / n);
            goto done;
        }
    if ((st = umbra__map_write(r, depths, (size_t)n * n * ch * sizeof(float))) == UMBRA_SUCCESS) {
        r->part_depths_at = r->rebuilds.shadow;
        r->part_depths_valid = 1;
    }
done:
    umbra__call_end(r);
    return st;
}

/* ---- the deep map's pieces ----------------------------------------------------------------- */

static umbra_status deep_ready(umbra_renderer r, const char *fn, uint32_t *n)
{
    if (!is_deep(r))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: the technique is %s, not deep", fn,
                           umbra_shadow_technique_name(r->shadow_set.technique));
    return build(r, fn, n);
}

umbra_status umbra_renderer_part_export_deep(umbra_renderer r, uint32_t *counts, float *nodes,
                                             size_t *node_count)
{
    CHECK_R();
    const char *fn = __func__;
    if (!counts || !node_count)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: counts (%p) and node_count (%p) must not be NULL", fn,
                           (void *)counts, (void *)node_count);
    umbra_status st = umbra__call_begin(r, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    uint32_t n = 0;
    if ((st = deep_ready(r, fn, &n)) == UMBRA_SUCCESS)
        st = umbra__deep_part_export(r, counts, nodes, node_count);
    umbra__call_end(r);
    return st;
}

umbra_status umbra_renderer_part_import_deep(umbra_renderer r, uint32_t parts,
                                             const uint32_t *counts, const float *nodes,
                                             size_t node_count)
{
    CHECK_R();
    const char *fn = __func__;
    if (parts == 0 || !counts || (node_count && !nodes))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: parts %u must be > 0, counts (%p) non-NULL and nodes (%p) "
                           "non-NULL for %zu nodes", fn, parts, (void *)counts, (void *)nodes,
                           node_count);
    umbra_status st = umbra__call_begin(r, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    uint32_t n = 0;
    if ((st = deep_ready(r, fn, &n)) == UMBRA_SUCCESS &&
        (st = umbra__deep_part_import(r, parts, counts, nodes, node_count)) == UMBRA_SUCCESS) {
        r->part_depths_at = r->rebuilds.shadow;
        r->part_depths_valid = 1;
    }
    umbra__call_end(r);
    return st;
}
