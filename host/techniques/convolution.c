// SPDX-License-Identifier: Apache-2.0
/* host/techniques/convolution.c: the "convolution" technique: Instant Convolution Shadows with the
 * seed paper's pre-integration and supersampling (ICS, pre-integrated ICS, SCS, pre-integrated
 * SCS, chosen by desc->subsamples and desc->preintegrated). It renders the frame itself with
 * view-aligned slices (kernels/techniques/convolution.cl explains the algorithm); this file places
 * the
 * slices, checks the light, keeps the buffers and enqueues one kernel per slice.
 *
 * Supported lights: light must cross the slices in the order they are composited (front to
 * back), so it has to come from the viewer's side. A directional light is supported when its
 * travel direction makes at most UMBRA__CONV_MAX_LIGHT_DEGREES with the view direction; a point
 * light when the direction from it to every corner of the volume's box does (then it lies in front
 * of every slice and every slice point has a well-defined light direction, used per pixel). Others
 * get UMBRA_ERROR_UNSUPPORTED naming the direction and the angle. Beyond 80 degrees one slice step
 * would carry the light more than 5.7 slice distances sideways through a single sample's opacity.
 *
 * Everything stays on the device during a frame: two ping-pong buffers for the attenuated light,
 * two for the light arriving at the last two slices (the sub-samples interpolate between them),
 * the eye buffer and the pending slab colours. All slice kernels are enqueued back to back; the
 * frame waits once, at the end. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"
#include "techniques/convolution.h"

#define CONV_MAX_SLICES 65536u

typedef struct conv_state {
    cl_program program;           /* owned by the context's cache */
    cl_kernel slice, resolve;
    cl_mem a[2], l[2], eye, pend;
    uint32_t width, height, channels;
    size_t bytes;
    umbra__preint *pi_view, *pi_light;
} conv_state;

/* Where the slices lie for the current frame. */
typedef struct conv_geom {
    float z0, dz, cone_tan, min_cos;
    uint32_t slices, subsamples, pi_size;
    int32_t rect[4];              /* pixels the slices cover: [x0, x1) x [y0, y1) */
} conv_geom;

static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Pixels of margin around the projected box in the slices' rectangle. */
#define CONV_RECT_MARGIN 4

/* Pixel coordinates of world point p (the kernels' conv_fetch mapping); 0 if it lies at or behind
 * a perspective eye, where it has none. */
static int to_pixel(const UmbraFrame *F, const float p[3], float near, float *fx, float *fy)
{
    float v[3] = {p[0] - F->eye[0], p[1] - F->eye[1], p[2] - F->eye[2]};
    float hw = sqrtf(dot3(F->right, F->right)), hh = sqrtf(dot3(F->up, F->up));
    float sc = 1.0f;
    if (!(F->flags & UMBRA_FLAG_ORTHO)) {
        float depth = dot3(v, F->forward);
        if (!(depth > near))
            return 0;
        sc = 1.0f / depth;
    }
    *fx = (dot3(v, F->right) / hw * sc / hw + 1.0f) * 0.5f * (float)F->width - 0.5f;
    *fy = (1.0f - dot3(v, F->up) / hh * sc / hh) * 0.5f * (float)F->height - 0.5f;
    return 1;
}

/* Grows rect to hold point p's pixel; a point without one makes it the whole image. */
static void rect_add(const UmbraFrame *F, const float p[3], float near, float lo[2], float hi[2],
                     int *whole)
{
    float fx, fy;
    if (!to_pixel(F, p, near, &fx, &fy)) {
        *whole = 1;
        return;
    }
    lo[0] = fminf(lo[0], fx);
    lo[1] = fminf(lo[1], fy);
    hi[0] = fmaxf(hi[0], fx);
    hi[1] = fmaxf(hi[1], fy);
}

static float conv_light_step(const umbra_shadow_desc *d)
{
    return d->convolution.slice_distance / (float)(d->convolution.subsamples + 1u);
}

/* Slice placement and the light check, from r->frame (camera part filled for this frame). */
static umbra_status conv_geometry(umbra_renderer r, const char *fn, conv_geom *G)
{
    const UmbraFrame *F = &r->frame;
    const float deg = 3.14159265358979f / 180.0f;
    const float *fwd = F->forward, *eye = F->eye;
    float corners[8][3], zmin = INFINITY, zmax = -INFINITY, diag = 0.0f;
    memset(G, 0, sizeof *G);
    for (int c = 0; c < 8; ++c) {
        float v[3];
        for (int a = 0; a < 3; ++a) {
            corners[c][a] = (c >> a) & 1 ? F->box_max[a] : F->box_min[a];
            v[a] = corners[c][a] - eye[a];
        }
        zmin = fminf(zmin, dot3(v, fwd));
        zmax = fmaxf(zmax, dot3(v, fwd));
    }
    for (int a = 0; a < 3; ++a)
        diag += (F->box_max[a] - F->box_min[a]) * (F->box_max[a] - F->box_min[a]);
    diag = sqrtf(diag);
    G->min_cos = cosf(UMBRA__CONV_MAX_LIGHT_DEGREES * deg);
    const int point = (F->flags & UMBRA_FLAG_POINT_LIGHT) != 0;
    if (!point) {
        float c = dot3(F->light, fwd);
        if (c < G->min_cos)
            return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: convolution shadows propagate light through view-aligned "
                               "slices front to back, so the light must shine from the viewer's "
                               "side: directional light direction (%.3g, %.3g, %.3g) makes %.1f "
                               "degrees with the view direction (%.3g, %.3g, %.3g); at most %.0f "
                               "are supported", fn, F->light[0], F->light[1], F->light[2],
                               acosf(fmaxf(-1.0f, fminf(1.0f, c))) / deg, fwd[0], fwd[1], fwd[2],
                               UMBRA__CONV_MAX_LIGHT_DEGREES);
    } else {
        float worst = 1.0f;
        for (int c = 0; c < 8; ++c) {
            float v[3] = {corners[c][0] - F->light[0], corners[c][1] - F->light[1],
                          corners[c][2] - F->light[2]};
            float len = sqrtf(dot3(v, v));
            worst = fminf(worst, len > 0.0f ? dot3(v, fwd) / len : -1.0f);
        }
        if (worst < G->min_cos)
            return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: convolution shadows propagate light through view-aligned "
                               "slices front to back, so a point light must lie on the viewer's "
                               "side of the volume: from (%.3g, %.3g, %.3g) some corner of the box "
                               "lies %.1f degrees off the view direction (%.3g, %.3g, %.3g); at "
                               "most %.0f are supported", fn, F->light[0], F->light[1],
                               F->light[2], acosf(fmaxf(-1.0f, fminf(1.0f, worst))) / deg, fwd[0],
                               fwd[1], fwd[2], UMBRA__CONV_MAX_LIGHT_DEGREES);
    }
    /* Orthographic rays start on the view plane; perspective slices must stay clear of the eye,
     * where a texel shrinks to nothing. */
    const float near = (F->flags & UMBRA_FLAG_ORTHO) ? 0.0f : 1e-3f * diag;
    G->z0 = fmaxf(zmin, near);
    G->dz = r->shadow.convolution.slice_distance * umbra__voxel_world(r);
    G->cone_tan = tanf(r->shadow.convolution.cone_angle_degrees * deg);
    G->subsamples = r->shadow.convolution.subsamples;
    G->pi_size = r->opts.preintegrated ? UMBRA__PREINT_SIZE : 0u;
    G->slices = 0;
    if (!(zmax > G->z0))
        return UMBRA_SUCCESS;
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    int whole = 0;
    for (int c = 0; c < 8; ++c)
        rect_add(F, corners[c], near, lo, hi, &whole);
    /* Behind the box the slices only carry light on, down to where the box's shadow falls on
     * the ground plane (found by casting the box's corners onto it), at most 2 diagonals on. */
    float z_end = zmax;
    if (F->flags & UMBRA_FLAG_GROUND) {
        /* The plane n.p + w = 0 (local frame; n = (0, 1, 0) unless the volume is rotated). */
        for (int c = 0; c < 8; ++c) {
            float o[3], d[3];
            for (int a = 0; a < 3; ++a) {
                o[a] = point ? F->light[a] : corners[c][a];
                d[a] = point ? corners[c][a] - F->light[a] : F->light[a];
            }
            const float dn = dot3(F->ground, d), height = dot3(F->ground, o) + F->ground[3];
            if (!(dn < 0.0f) || !(height > 0.0f))
                continue;
            float t = -height / dn, g[3], v[3];
            for (int a = 0; a < 3; ++a) {
                g[a] = o[a] + t * d[a];
                v[a] = g[a] - eye[a];
            }
            z_end = fmaxf(z_end, dot3(v, fwd) + 2.0f * G->dz);
            rect_add(F, g, near, lo, hi, &whole);
        }
        z_end = fminf(z_end, zmax + 2.0f * diag);
    }
    double n = ceil(((double)z_end - G->z0) / G->dz);
    if (n > CONV_MAX_SLICES)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: slice_distance %g voxels needs %.0f slices over a depth of %g "
                           "voxels; at most %u are allowed", fn,
                           r->shadow.convolution.slice_distance, n,
                           (z_end - G->z0) / umbra__voxel_world(r), CONV_MAX_SLICES);
    G->slices = (uint32_t)n;
    G->rect[0] = 0;
    G->rect[1] = 0;
    G->rect[2] = (int32_t)F->width;
    G->rect[3] = (int32_t)F->height;
    if (!whole) {
        G->rect[0] = (int32_t)fmaxf(0.0f, floorf(lo[0]) - CONV_RECT_MARGIN);
        G->rect[1] = (int32_t)fmaxf(0.0f, floorf(lo[1]) - CONV_RECT_MARGIN);
        G->rect[2] = (int32_t)fminf((float)F->width, ceilf(hi[0]) + 1 + CONV_RECT_MARGIN);
        G->rect[3] = (int32_t)fminf((float)F->height, ceilf(hi[1]) + 1 + CONV_RECT_MARGIN);
        if (G->rect[2] <= G->rect[0] || G->rect[3] <= G->rect[1])
            G->slices = 0; /* the box lies outside the view */
    }
    return UMBRA_SUCCESS;
}

static void release_buffers(conv_state *s)
{
    cl_mem *m[] = {&s->a[0], &s->a[1], &s->l[0], &s->l[1], &s->eye, &s->pend};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; ++i) {
        if (*m[i])
            clReleaseMemObject(*m[i]);
        *m[i] = NULL;
    }
    s->bytes = 0;
    s->width = s->height = 0;
}

static void conv_destroy(umbra_renderer r)
{
    conv_state *s = r->tech_state;
    if (!s)
        return;
    release_buffers(s);
    if (s->slice)
        clReleaseKernel(s->slice);
    if (s->resolve)
        clReleaseKernel(s->resolve);
    umbra__preint_release(s->pi_view);
    umbra__preint_release(s->pi_light);
    free(s);
    r->tech_state = NULL;
}

static size_t conv_memory(umbra_renderer r)
{
    conv_state *s = r->tech_state;
    return s ? s->bytes + umbra__preint_bytes(s->pi_view) + umbra__preint_bytes(s->pi_light) : 0;
}

static umbra_status ensure_state(umbra_renderer r, uint32_t w, uint32_t h)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    conv_state *s = r->tech_state;
    if (!s) {
        s = calloc(1, sizeof *s);
        if (!s)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_renderer_render: out of memory");
        r->tech_state = s;
    }
    char options[256];
    umbra__build_options(r, options, sizeof options);
    const char *files[] = {"common/common.cl", "common/sampling.cl", "common/channels.cl",
                           "common/preintegration.cl",
                           "techniques/convolution.cl"};
    cl_program program;
    if ((st = umbra__program_get(ctx, files, 5, options, &program)) != UMBRA_SUCCESS)
        return st;
    if (program != s->program) {
        if (s->slice)
            clReleaseKernel(s->slice);
        if (s->resolve)
            clReleaseKernel(s->resolve);
        s->slice = s->resolve = NULL;
        s->program = NULL;
        if ((st = umbra__kernel_create(ctx, program, "convolution_slice", &s->slice)) ||
            (st = umbra__kernel_create(ctx, program, "convolution_resolve", &s->resolve)))
            return st;
        s->program = program;
    }
    if (s->width == w && s->height == h && s->channels == r->channels && s->eye)
        return UMBRA_SUCCESS;
    release_buffers(s);
    const size_t px = (size_t)w * h, light = px * r->channels * sizeof(float);
    const size_t sizes[6] = {light, light, light, light, px * 16, px * 48};
    cl_mem *m[6] = {&s->a[0], &s->a[1], &s->l[0], &s->l[1], &s->eye, &s->pend};
    cl_int err;
    for (int i = 0; i < 6; ++i) {
        *m[i] = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, sizes[i], NULL, &err);
        UMBRA_CL_CHECK(err, "clCreateBuffer(convolution buffers)");
        s->bytes += sizes[i];
    }
    s->width = w;
    s->height = h;
    s->channels = r->channels;
fail:
    if (st != UMBRA_SUCCESS)
        release_buffers(s);
    return st;
}

/* Sets up the frame and enqueues slices 0..last (all of them and the resolve into out when last
 * is UINT32_MAX). Waits for the device once, at the end; the frame's device time goes to *ms. */
static umbra_status conv_run(umbra_renderer r, uint32_t w, uint32_t h, cl_mem out, uint32_t last,
                             double *ms, conv_geom *geom_out)
{
    const char *fn = "umbra_renderer_render";
    umbra_context ctx = r->ctx;
    umbra_status st;
    cl_event first = NULL, end = NULL;
    conv_geom G = {0};
    if ((st = conv_geometry(r, fn, &G)) != UMBRA_SUCCESS)
        return st;
    if ((st = ensure_state(r, w, h)) != UMBRA_SUCCESS)
        return st;
    conv_state *s = r->tech_state;
    cl_mem pi_view = r->view_tf_buf, pi_light = r->view_tf_buf; /* placeholders when unused */
    if (G.pi_size) {
        /* Both tables integrate one sub-step along the view axis; the kernel corrects them for
         * oblique rays and the light's angle. */
        float len = conv_light_step(&r->shadow);
        int colored = r->opts.transmission == UMBRA_TRANSMISSION_COLORED;
        double before = r->stats.shadow_build_ms;
        if ((st = umbra__preint_ensure(ctx, fn, &s->pi_view, umbra__view_tf(r), len,
                                       UMBRA__PREINT_VIEW, 0, &pi_view,
                                       &r->stats.shadow_build_ms)) ||
            (st = umbra__preint_ensure(ctx, fn, &s->pi_light, umbra__light_tf(r), len,
                                       UMBRA__PREINT_LIGHT, colored, &pi_light,
                                       &r->stats.shadow_build_ms)))
            return st;
        if (r->stats.shadow_build_ms != before)
            r->stats.shadow_rebuilt = 1;
    }
    cl_uint next = 0;
    /* Declared before the first UMBRA_CL: the fail path releases them. */
    cl_event pending = NULL, mark = NULL, sliced = NULL;
    if ((st = umbra__bind_common(r, s->slice, &next)) != UMBRA_SUCCESS)
        return st;
    const cl_uint base = next;
    cl_float4 geo = {{G.z0, G.dz, G.cone_tan, G.min_cos}};
    cl_uint4 ctl = {{0, G.subsamples, G.pi_size, G.slices}};
    UMBRA_CL(clSetKernelArg(s->slice, base, sizeof(cl_mem), &pi_view));
    UMBRA_CL(clSetKernelArg(s->slice, base + 1, sizeof(cl_mem), &pi_light));
    UMBRA_CL(clSetKernelArg(s->slice, base + 6, sizeof(cl_mem), &s->eye));
    UMBRA_CL(clSetKernelArg(s->slice, base + 7, sizeof(cl_mem), &s->pend));
    cl_int4 rect = {{G.rect[0], G.rect[1], G.rect[2], G.rect[3]}};
    UMBRA_CL(clSetKernelArg(s->slice, base + 8, sizeof geo, &geo));
    UMBRA_CL(clSetKernelArg(s->slice, base + 10, sizeof rect, &rect));
    const size_t global[2] = {w, h}, local[2] = {8, 8};
    /* The slices run over the rectangle only: a global offset, the size rounded up to whole
     * work-groups (the kernel checks the far edges). */
    const size_t offset[2] = {(size_t)G.rect[0], (size_t)G.rect[1]};
    const size_t range[2] = {((size_t)(G.rect[2] - G.rect[0]) + 7) / 8 * 8,
                             ((size_t)(G.rect[3] - G.rect[1]) + 7) / 8 * 8};
    uint32_t n = last == UINT32_MAX ? G.slices : last + 1;
    if (n > G.slices)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra__convolution_light: slice %u requested; the frame has %u", last,
                           G.slices);
    /* An asynchronous frame waits for the application from here on: everything above may
     * block the host (the pre-integration tables), nothing below does. */
    if ((st = umbra__frame_gate(r)) != UMBRA_SUCCESS)
        return st;
    double t0 = umbra__now_ms();
    /* With a progress callback the slices go in groups of about UMBRA__BAND_SAMPLES samples:
     * after queueing a group the previous one is waited for and reported, so the device stays
     * busy and a cancel waits for at most two groups. An asynchronous frame waits for nothing. */
    const double per_slice = (double)range[0] * range[1] * (G.subsamples + 1u);
    uint32_t group = UINT32_MAX;
    if (r->progress && !r->async) {
        double budget = r->band_samples > 0.0 ? r->band_samples : UMBRA__BAND_SAMPLES;
        double g = budget / (per_slice > 1.0 ? per_slice : 1.0);
        group = g < 1.0 ? 1u : g > (double)n ? (n ? n : 1u) : (uint32_t)g;
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (group != UINT32_MAX && i > 0 && i % group == 0) {
            UMBRA_CL(clEnqueueMarkerWithWaitList(ctx->queue, 0, NULL, &mark));
            UMBRA_CL(clFlush(ctx->queue));
            if (pending) {
                UMBRA_CL(clWaitForEvents(1, &pending));
                clReleaseEvent(pending);
                pending = NULL;
                if ((st = umbra__progress(r, (double)(i - group) / n, fn)) != UMBRA_SUCCESS)
                    goto fail;
            }
            pending = mark;
            mark = NULL;
        }
        ctl.s[0] = i;
        UMBRA_CL(clSetKernelArg(s->slice, base + 2, sizeof(cl_mem), &s->a[(i + 1) % 2]));
        UMBRA_CL(clSetKernelArg(s->slice, base + 3, sizeof(cl_mem), &s->a[i % 2]));
        UMBRA_CL(clSetKernelArg(s->slice, base + 4, sizeof(cl_mem), &s->l[(i + 1) % 2]));
        UMBRA_CL(clSetKernelArg(s->slice, base + 5, sizeof(cl_mem), &s->l[i % 2]));
        UMBRA_CL(clSetKernelArg(s->slice, base + 9, sizeof ctl, &ctl));
        cl_event *slot = i == 0 ? &first : r->async ? &sliced : NULL;
        UMBRA_CL(clEnqueueNDRangeKernel(ctx->queue, s->slice, 2, offset, range, local, 0, NULL,
                                        slot));
        if (slot && (st = umbra__async_hold(r, *slot, 1)) != UMBRA_SUCCESS)
            goto fail;
        if (sliced)
            clReleaseEvent(sliced);
        sliced = NULL;
    }
    if (last == UINT32_MAX) {
        uint32_t k = G.slices ? (G.slices - 1) % 2 : 0;
        cl_uint a = 0;
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &r->frame_buf));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &s->a[k]));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &s->l[k]));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &s->eye));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &s->pend));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof(cl_mem), &out));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof geo, &geo));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof ctl, &ctl));
        UMBRA_CL(clSetKernelArg(s->resolve, a++, sizeof rect, &rect));
        if ((st = umbra__enqueue(ctx, s->resolve, 2, global, NULL, &end)) ||
            (st = umbra__async_hold(r, end, 1)))
            goto fail;
        if (r->async) { /* the caller hands out the resolve as the frame's end; nothing is timed */
            if (ms)
                *ms = 0.0;
            ms = NULL;
        } else {
            UMBRA_CL(clWaitForEvents(1, &end));
        }
    } else {
        UMBRA_CL(clFinish(ctx->queue));
    }
    if (ms) {
        cl_ulong a = 0, b = 0;
        if (first && end &&
            clGetEventProfilingInfo(first, CL_PROFILING_COMMAND_START, sizeof a, &a, NULL) ==
                CL_SUCCESS &&
            clGetEventProfilingInfo(end, CL_PROFILING_COMMAND_END, sizeof b, &b, NULL) ==
                CL_SUCCESS && b >= a)
            *ms = (double)(b - a) * 1e-6;
        else
            *ms = umbra__now_ms() - t0;
    }
    r->stats.slices = G.slices;
    if (geom_out)
        *geom_out = G;
fail:
    /* A cancelled frame returns with nothing of it left running on the device. */
    if (pending || mark)
        clFinish(ctx->queue);
    if (pending)
        clReleaseEvent(pending);
    if (mark)
        clReleaseEvent(mark);
    if (sliced)
        clReleaseEvent(sliced);
    if (first)
        clReleaseEvent(first);
    if (end)
        clReleaseEvent(end);
    return st;
}

static umbra_status conv_render(umbra_renderer r, uint32_t w, uint32_t h, cl_mem out, double *ms)
{
    return conv_run(r, w, h, out, UINT32_MAX, ms, NULL);
}

static const umbra__param params[] = {
    UMBRA__PARAM(convolution, slice_distance, .doc = "distance between slices", .unit = "voxels",
                 .default_value = 0.5, .min = 0.02, .max = 16),
    UMBRA__PARAM(convolution, subsamples,
                 .doc = "SCS: volume samples between two slices; the light is interpolated "
                        "between the two",
                 .default_value = 0, .min = 0, .max = 64),
    UMBRA__PARAM(convolution, cone_angle_degrees, .alias = "cone_angle",
                 .doc = "half-angle of the cone the kernel spreads the light over per slice "
                        "(0: no blur)",
                 .unit = "degrees", .default_value = 5, .min = 0, .max = 60),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting). */
static const umbra__setting sweep[] = {
    {"slice_distance=0.5;subsamples=0;preintegrated=0;cone_angle=5", "ICS slice 0.5",
     UMBRA__SWEEP_FULL},
    {"slice_distance=1;subsamples=0;preintegrated=0;cone_angle=5", "ICS slice 1",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE | UMBRA__SWEEP_HEADLINE_QUICK},
    {"slice_distance=2;subsamples=0;preintegrated=0;cone_angle=5", "ICS slice 2",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"slice_distance=2;subsamples=1;preintegrated=0;cone_angle=5", "SCS slice 2, 1 sub-sample",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"slice_distance=2;subsamples=3;preintegrated=0;cone_angle=5", "SCS slice 2, 3 sub-samples",
     UMBRA__SWEEP_FULL},
    {"slice_distance=1;subsamples=0;preintegrated=1;cone_angle=5", "pre-int. ICS slice 1",
     UMBRA__SWEEP_FULL},
    {"slice_distance=2;subsamples=0;preintegrated=1;cone_angle=5", "pre-int. ICS slice 2",
     UMBRA__SWEEP_FULL},
    {"slice_distance=2;subsamples=3;preintegrated=1;cone_angle=5",
     "pre-int. SCS slice 2, 3 sub-samples",
     UMBRA__SWEEP_FULL},
};

const umbra__technique umbra__technique_convolution = {
    .info = {
        .id = UMBRA_SHADOW_CONVOLUTION,
        .name = "convolution",
        .title = "slice-based convolution shadows (ICS / SCS)",
        .doc = "Renders the frame itself in view-aligned slices front to back, carrying the "
               "light from slice to slice through a blur kernel: soft shadows at the cost of a "
               "kernel launch per slice every frame, for lights on the viewer's side only.",
        .flags = UMBRA_TECHNIQUE_FRAME | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
    },
    .params = params,
    .sweep = sweep,
    .sweep_count = sizeof sweep / sizeof sweep[0],
    .light_step = conv_light_step,
    .render = conv_render,
    .memory = conv_memory,
    .destroy = conv_destroy,
};

/* ---- test hooks ------------------------------------------------------------------------------ */

umbra_status umbra__convolution_light(umbra_renderer r, uint32_t w, uint32_t h, uint32_t k,
                                      float *rgb)
{
    const char *fn = "umbra__convolution_light";
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    float *img = NULL, *light = NULL;
    if (r->tech != &umbra__technique_convolution)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: the renderer's technique is not convolution", fn);
    img = malloc((size_t)w * h * 4 * sizeof *img);
    light = malloc((size_t)w * h * 3 * sizeof *light);
    if (!img || !light) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
        goto fail;
    }
    /* A full frame first: it prepares the tables, the frame constants and the buffers. */
    if ((st = umbra_renderer_render(r, w, h, img)) != UMBRA_SUCCESS)
        goto fail;
    if ((st = conv_run(r, w, h, NULL, k, NULL, NULL)) != UMBRA_SUCCESS)
        goto fail;
    conv_state *s = r->tech_state;
    const uint32_t ch = s->channels;
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, s->l[k % 2], CL_TRUE, 0,
                                 (size_t)w * h * ch * sizeof(float), light, 0, NULL, NULL));
    for (size_t i = 0; i < (size_t)w * h; ++i)
        for (uint32_t c = 0; c < 3; ++c)
            rgb[3 * i + c] = light[ch * i + (ch == 1 ? 0 : c)];
fail:
    free(img);
    free(light);
    return st;
}

umbra_status umbra__convolution_subsample_weights(umbra_context ctx, uint32_t n, float *out)
{
    umbra_status st = UMBRA_SUCCESS;
    cl_kernel k = NULL;
    cl_mem buf = NULL;
    cl_program program;
    const char *files[] = {"common/common.cl", "common/sampling.cl", "common/channels.cl",
                           "common/preintegration.cl",
                           "techniques/convolution.cl"};
    if ((st = umbra__program_get(ctx, files, 5, "", &program)) != UMBRA_SUCCESS)
        return st;
    if ((st = umbra__kernel_create(ctx, program, "convolution_subsample_weights", &k)))
        return st;
    cl_int err;
    buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_WRITE_ONLY, (n + 2) * sizeof(float), NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(weights)");
    cl_uint nn = n;
    UMBRA_CL(clSetKernelArg(k, 0, sizeof(cl_mem), &buf));
    UMBRA_CL(clSetKernelArg(k, 1, sizeof nn, &nn));
    size_t global = n + 2;
    if ((st = umbra__enqueue(ctx, k, 1, &global, NULL, NULL)) != UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, buf, CL_TRUE, 0, (n + 2) * sizeof(float), out, 0,
                                 NULL, NULL));
fail:
    if (buf)
        clReleaseMemObject(buf);
    clReleaseKernel(k);
    return st;
}
