// SPDX-License-Identifier: Apache-2.0
/* host/part.c: volumes that are parts of a global grid (umbra/part.h), and the host helpers that
 * compose what parts render: the visibility order of parts, the over operator on partial images,
 * the product and minimum of light-space arrays. The renderer's side of a part is
 * host/part_render.c (its view segment) and host/part_light.c (its light exchange). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"

void umbra_part_desc_init(umbra_part_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
}

uint32_t umbra_part_ghost_needed(const umbra_render_desc *o)
{
    if (!o)
        return 0;
    uint32_t n = 1;
    if (o->shading)
        n += 1;
    if (o->jitter && isfinite(o->step) && o->step > 0.0f)
        n += (uint32_t)ceilf(o->step);
    return n;
}

static const char *const AXIS = "xyz";

/* Checks part against the carried voxels' desc (struct_size already checked). */
static umbra_status check_part(umbra_context ctx, const umbra_volume_desc *d,
                               const umbra_part_desc *p, int *empty)
{
    const char *fn = "umbra_volume_create_part";
    const uint32_t bs = d->brick_size ? d->brick_size : 16u;
    *empty = p->size[0] == 0 && p->size[1] == 0 && p->size[2] == 0;
    if (!d->value_range_given)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->value_range_given is 0: every part must normalise with the "
                           "global value range, given", fn);
    if (d->channels > 1 || d->labels)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: %s: a part is a plain scalar volume (channels %u, labels %d)", fn,
                           d->labels ? "a label map" : "several channels", d->channels, d->labels);
    for (int a = 0; a < 3; ++a) {
        const uint64_t g = p->global_dims[a], o = p->offset[a], s = p->size[a];
        const uint64_t lo = p->ghost_lo[a], hi = p->ghost_hi[a];
        if (g == 0)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: global_dims[%d] (%c) is 0", fn, a, AXIS[a]);
        if ((double)g * d->spacing[a] > UMBRA_MAX_EXTENT)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: global extent %g along %c exceeds UMBRA_MAX_EXTENT %g", fn,
                               (double)g * d->spacing[a], AXIS[a], (double)UMBRA_MAX_EXTENT);
        if (*empty)
            continue;
        if (s == 0)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: size[%d] (%c) is 0 while another axis is not: an empty part "
                               "has size 0 on all three", fn, a, AXIS[a]);
        if (o % bs)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: offset[%d] (%c) %u is not a multiple of the brick size %u", fn,
                               a, AXIS[a], p->offset[a], bs);
        if (o + s > g)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: offset[%d] + size[%d] (%c) = %llu overflows global_dims %u", fn,
                               a, a, AXIS[a], (unsigned long long)(o + s), p->global_dims[a]);
        if (lo > o || lo > UMBRA_PART_MAX_GHOST)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ghost_lo[%d] (%c) %u exceeds the offset %u or "
                               "UMBRA_PART_MAX_GHOST %u", fn, a, AXIS[a], p->ghost_lo[a],
                               p->offset[a], UMBRA_PART_MAX_GHOST);
        if (hi > g - o - s || hi > UMBRA_PART_MAX_GHOST)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ghost_hi[%d] (%c) %u exceeds the %llu layers above the core or "
                               "UMBRA_PART_MAX_GHOST %u", fn, a, AXIS[a], p->ghost_hi[a],
                               (unsigned long long)(g - o - s), UMBRA_PART_MAX_GHOST);
        if (d->dims[a] != lo + s + hi)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: desc->dims[%d] (%c) %u is not ghost_lo + size + ghost_hi = "
                               "%llu", fn, a, AXIS[a], d->dims[a],
                               (unsigned long long)(lo + s + hi));
    }
    if (*empty && (d->dims[0] != 1 || d->dims[1] != 1 || d->dims[2] != 1))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: an empty part carries one voxel, not %u x %u x %u", fn, d->dims[0],
                           d->dims[1], d->dims[2]);
    return UMBRA_SUCCESS;
}

umbra_status umbra_volume_create_part(umbra_context ctx, const umbra_volume_desc *desc,
                                      const umbra_part_desc *part, umbra_volume *out)
{
    const char *fn = "umbra_volume_create_part";
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    *out = NULL;
    if (!ctx || !desc || !part)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: ctx %p, desc %p, part %p: none may be NULL", fn, (void *)ctx,
                           (void *)desc, (void *)part);
    if (part->struct_size != sizeof *part)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: part->struct_size %zu is not %zu: call umbra_part_desc_init", fn,
                           part->struct_size, sizeof *part);
    /* The fields check_part reads, from a layout umbra_volume_create accepts (it checks
     * struct_size itself). */
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    if (desc->struct_size == sizeof d || desc->struct_size == offsetof(umbra_volume_desc, channels))
        memcpy(&d, desc, desc->struct_size);
    else
        return umbra_volume_create(ctx, desc, out); /* refuses the size by name */
    d.struct_size = sizeof d;
    int empty = 0;
    umbra_status st = check_part(ctx, &d, part, &empty);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_volume v = NULL;
    if ((st = umbra_volume_create(ctx, &d, &v)) != UMBRA_SUCCESS)
        return st;
    /* Placed as the global volume: the world box, centre and origin of the global grid. */
    umbra_volume_desc g = d;
    memcpy(g.dims, part->global_dims, sizeof g.dims);
    if ((st = umbra__volume_set_transform(ctx, &g, v)) != UMBRA_SUCCESS) {
        umbra_volume_release(v);
        return st;
    }
    memcpy(v->grid_dims, part->global_dims, sizeof v->grid_dims);
    v->is_part = 1;
    v->part = *part;
    *out = v;
    return UMBRA_SUCCESS;
}

umbra_status umbra_volume_get_part(umbra_volume v, umbra_part_desc *out)
{
    if (!v || !out)
        return umbra__fail(v ? v->ctx : NULL, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_volume_get_part: volume %p, out %p: neither may be NULL",
                           (void *)v, (void *)out);
    if (v->is_part) {
        *out = v->part;
        return UMBRA_SUCCESS;
    }
    umbra_part_desc_init(out);
    memcpy(out->global_dims, v->dims, sizeof out->global_dims);
    memcpy(out->size, v->dims, sizeof out->size);
    return UMBRA_SUCCESS;
}

/* ---- visibility order ---------------------------------------------------------------------- */

/* Whether part a must come before part b as seen along dir (local voxel axes) or from point p
 * (global voxel coordinates, voxel i's cell [i, i + 1)): they are separated by a plane normal to
 * some axis, and the viewer is on a's side of it. Returns 1 (a first), -1 (b first) or 0. */
static int before(const umbra_part_desc *a, const umbra_part_desc *b, const double w[3],
                  int is_point)
{
    for (int k = 0; k < 3; ++k) {
        const double a_lo = a->offset[k], a_hi = a_lo + a->size[k];
        const double b_lo = b->offset[k], b_hi = b_lo + b->size[k];
        double s;
        int a_low; /* a lies below the plane */
        if (a_hi <= b_lo) {
            s = a_hi;
            a_low = 1;
        } else if (b_hi <= a_lo) {
            s = a_lo;
            a_low = 0;
        } else
            continue;
        if (is_point) {
            if (w[k] == s)
                continue;
            return (w[k] < s) == a_low ? 1 : -1;
        }
        if (w[k] == 0.0)
            continue;
        return (w[k] > 0.0) == a_low ? 1 : -1;
    }
    return 0;
}

umbra_status umbra_part_visibility_order(const umbra_part_desc *descs, uint32_t count,
                                         const umbra_volume_info *info, const float where[3],
                                         int is_point, uint32_t *order)
{
    if (!descs || !count || !info || !where || !order || count > 1u << 20)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    for (uint32_t i = 1; i < count; ++i)
        if (memcmp(descs[i].global_dims, descs[0].global_dims, sizeof descs[0].global_dims))
            return UMBRA_ERROR_INVALID_ARGUMENT;
    /* where in global voxel axes: a point in voxel coordinates + 0.5 (cell edges at integers),
     * a direction in index-axis components over the spacing. */
    double w[3];
    for (int a = 0; a < 3; ++a) {
        double dot = 0.0;
        for (int k = 0; k < 3; ++k)
            dot += ((double)where[k] - (is_point ? (double)info->origin[k] : 0.0)) *
                   (double)info->directions[3 * a + k];
        w[a] = dot / (double)info->spacing[a] + (is_point ? 0.5 : 0.0);
        if (!isfinite(w[a]))
            return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    if (!is_point && w[0] == 0.0 && w[1] == 0.0 && w[2] == 0.0)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    /* Repeatedly take the first remaining part that no remaining part must precede (a
     * topological sort; boxes of a k-d split or a grid have no cycle). */
    unsigned char *done = calloc(count, 1);
    if (!done)
        return UMBRA_ERROR_OUT_OF_MEMORY;
    for (uint32_t n = 0; n < count; ++n) {
        uint32_t pick = count;
        for (uint32_t i = 0; i < count && pick == count; ++i) {
            if (done[i])
                continue;
            int blocked = 0;
            for (uint32_t j = 0; j < count && !blocked; ++j)
                blocked = j != i && !done[j] && before(&descs[j], &descs[i], w, is_point) > 0;
            if (!blocked)
                pick = i;
        }
        if (pick == count) /* a cycle (overlapping or odd boxes): the first remaining */
            for (pick = 0; done[pick]; ++pick)
                ;
        done[pick] = 1;
        order[n] = pick;
    }
    free(done);
    return UMBRA_SUCCESS;
}

umbra_status umbra_part_view_order(const umbra_part_desc *descs, uint32_t count,
                                   const umbra_volume_info *info, const umbra_camera *camera,
                                   uint32_t *order)
{
    if (!camera)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    if (camera->projection == UMBRA_PERSPECTIVE)
        return umbra_part_visibility_order(descs, count, info, camera->eye, 1, order);
    float dir[3];
    for (int a = 0; a < 3; ++a)
        dir[a] = camera->target[a] - camera->eye[a];
    return umbra_part_visibility_order(descs, count, info, dir, 0, order);
}

/* ---- images and maps ------------------------------------------------------------------------ */

/* One pixel of front over back, as the ray caster composites: back's weight (1 - a_front). */
static void over_pixel(const float *f, const float *b, float *o)
{
    const float t = 1.0f - f[3];
    float r[4];
    for (int c = 0; c < 4; ++c)
        r[c] = f[c] + t * b[c];
    memcpy(o, r, sizeof r);
}

void umbra_part_over(const float *front, const float *back, float *out, size_t count)
{
    if (!front || !back || !out)
        return;
    for (size_t i = 0; i < count; ++i)
        over_pixel(front + 4 * i, back + 4 * i, out + 4 * i);
}

umbra_status umbra_part_composite(float *frame, uint32_t width, uint32_t height, const float *part,
                                  const umbra_part_rect *rect)
{
    if (!frame || !rect || (!part && rect->width && rect->height))
        return UMBRA_ERROR_INVALID_ARGUMENT;
    if ((uint64_t)rect->x + rect->width > width || (uint64_t)rect->y + rect->height > height)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    for (uint32_t y = 0; y < rect->height; ++y) {
        float *row = frame + 4 * ((size_t)(rect->y + y) * width + rect->x);
        umbra_part_over(row, part + 4 * (size_t)y * rect->width, row, rect->width);
    }
    return UMBRA_SUCCESS;
}

void umbra_part_background(float *rgba, size_t count, const float bg[4])
{
    if (!rgba || !bg)
        return;
    for (size_t i = 0; i < count; ++i) {
        float *p = rgba + 4 * i;
        const float t = 1.0f - p[3];
        for (int c = 0; c < 4; ++c)
            p[c] = fmaf(t, bg[c], p[c]); /* as kernels/raycast.cl: the same rounding */
    }
}

void umbra_part_multiply(float *acc, const float *t, size_t count)
{
    if (!acc || !t)
        return;
    for (size_t i = 0; i < count; ++i)
        acc[i] *= t[i];
}

void umbra_part_minimum(float *acc, const float *d, size_t count)
{
    if (!acc || !d)
        return;
    for (size_t i = 0; i < count; ++i)
        acc[i] = d[i] < acc[i] ? d[i] : acc[i];
}
