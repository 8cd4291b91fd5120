// SPDX-License-Identifier: Apache-2.0
/* host/part_light.c: the light data that crosses parts (umbra/part.h) for the light-space maps
 * whose parts march the light (threshold, CSSM, deep): the march state a part hands the next on
 * each light ray (its export, its import checked field by field), the depths the parts reduce,
 * and the deep map's pieces, merged per texel (host/techniques/deep_part.c). A part's view is
 * host/part_render.c. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lightspace.h"
#include "part_light.h"
#include "renderer_internal.h"
#include "techniques/deep.h"
#include "techniques/deep_shared.h"
#include "techniques/maps.h"

/* The deep map on a part: one light ray per texel (the pre-filter's sub-rays would cross a
 * face at different depths, and a segment's nodes combine all of them), the unbounded map (a
 * budget chooses its nodes once the whole ray is known) and a light step of at most a voxel (a
 * segment's two ends then lie within the one ghost layer of the owned midpoint). */
umbra_status umbra__part_check_deep(umbra_renderer r, const char *fn)
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

const PartLight *umbra__part_light(umbra_shadow_technique t)
{
    for (size_t i = 0; i < sizeof PART_LIGHTS / sizeof PART_LIGHTS[0]; ++i)
        if (PART_LIGHTS[i].technique == t)
            return &PART_LIGHTS[i];
    return NULL;
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
    if (!light)
        return light_unsupported(r, fn);
    umbra_status st = is_deep(r) ? umbra__part_check_deep(r, fn) : UMBRA_SUCCESS;
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
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
    const PartLight *light = umbra__part_light(r->shadow_set.technique);
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
