// SPDX-License-Identifier: Apache-2.0
/* host/frame.c: the constants a frame's kernels read (umbra__frame: light, view, box, options),
 * brought up to date from the renderer's state and uploaded; the orbit cameras; the build
 * options and the kernel arguments every technique's kernels share. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"
#include "renderer_internal.h"

static void set4(float dst[4], float x, float y, float z, float w)
{
    dst[0] = x;
    dst[1] = y;
    dst[2] = z;
    dst[3] = w;
}

void umbra__frame_update_light(umbra_renderer r)
{
    UmbraFrame *F = &r->frame;
    umbra_volume v = r->volume;
    float ext[3];
    for (int a = 0; a < 3; ++a)
        ext[a] = (float)v->grid_dims[a] * v->spacing[a];
    set4(F->box_min, -0.5f * ext[0], -0.5f * ext[1], -0.5f * ext[2], 0.0f);
    set4(F->box_max, 0.5f * ext[0], 0.5f * ext[1], 0.5f * ext[2], 0.0f);
    set4(F->inv_spacing, 1.0f / v->spacing[0], 1.0f / v->spacing[1], 1.0f / v->spacing[2], 0.0f);
    for (int a = 0; a < 3; ++a) {
        F->dims[a] = (int32_t)v->grid_dims[a];
        F->bricks[a] = (int32_t)v->brick_counts[a];
    }
    F->dims[3] = 0;
    F->bricks[3] = (int32_t)v->brick_size;
    set4(F->value_map, v->value_map[0], v->value_map[1], v->value_map[2], 0.0f);
    F->ch.count = v->channels;
    F->ch.labels = v->labels ? 1u : 0u;
    for (uint32_t c = 0; c < UMBRA_MAX_CHANNELS; ++c)
        for (int k = 0; k < 3; ++k)
            F->ch.value_map[c][k] = c < v->channels ? v->channel_map[c][k] : 0.0f;
    umbra__clip_update(r);
    /* The light is given in the volume's world; the kernels work in its local frame. */
    const umbra_light *l = &r->light;
    float lp[3];
    if (l->type == UMBRA_LIGHT_POINT) {
        umbra__volume_point_to_local(v, l->position, lp);
        set4(F->light, lp[0], lp[1], lp[2], 1.0f);
    } else {
        umbra__volume_dir_to_local(v, l->direction, lp);
        set4(F->light, lp[0], lp[1], lp[2], 0.0f);
    }
    set4(F->light_color, l->color[0], l->color[1], l->color[2], 0.0f);
    F->flags &= ~(UMBRA_FLAG_POINT_LIGHT | UMBRA_FLAG_COLORED | UMBRA_FLAG_SKIP_EMPTY);
    if (l->type == UMBRA_LIGHT_POINT)
        F->flags |= UMBRA_FLAG_POINT_LIGHT;
    if (r->opts.transmission == UMBRA_TRANSMISSION_COLORED)
        F->flags |= UMBRA_FLAG_COLORED;
    if (r->opts.empty_space_skipping)
        F->flags |= UMBRA_FLAG_SKIP_EMPTY;
    F->step_ref = umbra__voxel_world(r);
    F->light_tf_size = umbra__light_tf(r)->count;
    r->channels = (r->opts.transmission == UMBRA_TRANSMISSION_GREY || umbra__light_tfs_grey(r))
                      ? 1u
                      : 3u;
    umbra__part_frame(r, 0);
}

/* Length in double: the squares of floats above 1.8e19 overflow a float (a direction of
 * (0, -1e20, 0) would get length inf and normalise to zero), never a double. */
umbra_camera umbra_camera_orbit(const float dir[3], float box_diagonal, float fovy_degrees)
{
    const float origin[3] = {0.0f, 0.0f, 0.0f};
    return umbra_camera_orbit_at(origin, dir, box_diagonal, fovy_degrees);
}

umbra_camera umbra_camera_orbit_at(const float center[3], const float dir[3], float box_diagonal,
                                   float fovy_degrees)
{
    umbra_camera c;
    memset(&c, 0, sizeof c);
    float d[3] = {dir[0], dir[1], dir[2]};
    umbra__normalize3(d);
    if (!(fovy_degrees > 0.0f && fovy_degrees < 180.0f))
        fovy_degrees = 30.0f;
    float dist = 0.5f * box_diagonal / sinf(0.5f * fovy_degrees * 3.14159265f / 180.0f) * 1.05f;
    c.projection = UMBRA_PERSPECTIVE;
    for (int i = 0; i < 3; ++i) {
        c.eye[i] = center[i] + d[i] * dist;
        c.target[i] = center[i];
    }
    c.up[1] = 1.0f;
    if (fabsf(d[1]) > 0.99f) { /* looking straight down or up: y cannot be "up" */
        c.up[1] = 0.0f;
        c.up[2] = -1.0f;
    }
    c.fovy_degrees = fovy_degrees;
    c.ortho_height = box_diagonal;
    return c;
}

void umbra__frame_update_view(umbra_renderer r, uint32_t width, uint32_t height)
{
    UmbraFrame *F = &r->frame;
    const umbra_render_desc *o = &r->opts;
    float ext[3], diag = 0.0f;
    for (int a = 0; a < 3; ++a) {
        ext[a] = (float)r->volume->grid_dims[a] * r->volume->spacing[a];
        diag += ext[a] * ext[a];
    }
    diag = sqrtf(diag);
    umbra_volume v = r->volume;
    umbra_camera c = r->camera;
    if (!r->camera_set) {
        const float dir[3] = {0.6f, 0.45f, 1.0f}, zero[3] = {0.0f, 0.0f, 0.0f};
        double centre[3];
        umbra__volume_point_to_world(v, zero, centre);
        const float at[3] = {(float)centre[0], (float)centre[1], (float)centre[2]};
        c = umbra_camera_orbit_at(at, dir, diag, 30.0f);
    }
    /* The camera's frame is built in the world (so a mirrored volume does not mirror the
     * image) and then taken into the volume's local frame, vector by vector. */
    float fw[3] = {c.target[0] - c.eye[0], c.target[1] - c.eye[1], c.target[2] - c.eye[2]};
    umbra__normalize3(fw);
    float rw[3], uw[3], f[3], right[3], up[3], eye[3];
    umbra__cross3(fw, c.up, rw);
    umbra__normalize3(rw);
    umbra__cross3(rw, fw, uw);
    umbra__volume_dir_to_local(v, fw, f);
    umbra__volume_dir_to_local(v, rw, right);
    umbra__volume_dir_to_local(v, uw, up);
    umbra__volume_point_to_local(v, c.eye, eye);
    float aspect = (float)width / (float)height;
    float half_h = c.projection == UMBRA_ORTHOGRAPHIC
                       ? 0.5f * c.ortho_height
                       : tanf(0.5f * c.fovy_degrees * 3.14159265358979f / 180.0f);
    float half_w = half_h * aspect;
    set4(F->eye, eye[0], eye[1], eye[2], 0.0f);
    set4(F->right, right[0] * half_w, right[1] * half_w, right[2] * half_w, 0.0f);
    set4(F->up, up[0] * half_h, up[1] * half_h, up[2] * half_h, 0.0f);
    set4(F->forward, f[0], f[1], f[2], 0.0f);
    set4(F->ambient, o->ambient[0], o->ambient[1], o->ambient[2], 0.0f);
    set4(F->background, o->background[0], o->background[1], o->background[2], o->background[3]);
    set4(F->ground_color, o->ground_color[0], o->ground_color[1], o->ground_color[2], 0.0f);
    umbra__ground_plane(v, ext, o->ground_offset * diag, F->ground);
    F->width = width;
    F->height = height;
    F->seed = o->seed;
    F->step = o->step * umbra__voxel_world(r);
    F->termination = o->termination;
    F->kd = o->kd;
    F->ks = o->ks;
    F->shininess = o->shininess;
    F->tf_size = umbra__view_tf(r)->count;
    uint32_t keep = F->flags & (UMBRA_FLAG_POINT_LIGHT | UMBRA_FLAG_COLORED | UMBRA_FLAG_SKIP_EMPTY);
    F->flags = keep | (o->jitter ? UMBRA_FLAG_JITTER : 0u) | (o->shading ? UMBRA_FLAG_SHADING : 0u) |
               (o->ground_plane ? UMBRA_FLAG_GROUND : 0u) |
               (c.projection == UMBRA_ORTHOGRAPHIC ? UMBRA_FLAG_ORTHO : 0u);
    umbra__part_frame(r, 1);
}

umbra_status umbra__ensure_buffer(umbra_renderer r, cl_mem *buf, size_t bytes, cl_mem_flags flags)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    if (*buf)
        return UMBRA_SUCCESS;
    cl_int err;
    *buf = clCreateBuffer(ctx->cl_ctx, flags, bytes, NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer");
fail:
    return st;
}

umbra_status umbra__upload_params(umbra_renderer r)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_int err;
    /* New buffers rather than writes into the old ones: a write from r->frame would have to wait
     * (or r->frame stay unchanged) until it ran, and a frame still queued behind the application's
     * wait list must keep its own constants. OpenCL frees the old buffers once the commands that
     * use them have completed. */
    umbra__release_mem(&r->frame_buf);
    umbra__release_mem(&r->shadow_buf);
    r->frame_buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                  sizeof r->frame, &r->frame, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(frame constants)");
    r->shadow_buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                   sizeof r->shadow_params, &r->shadow_params, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(shadow constants)");
fail:
    return st;
}

umbra_status umbra__upload_constants(umbra_renderer r, const void *data, size_t bytes,
                                     cl_mem *buf)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_int err;
    /* A new buffer for the same reason as umbra__upload_params. */
    umbra__release_mem(buf);
    *buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes,
                          (void *)data, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(technique constants)");
fail:
    return st;
}

umbra_status umbra__frame_gate(umbra_renderer r)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_event barrier = NULL;
    if (!r->async || r->async->gated)
        return UMBRA_SUCCESS;
    if (r->async->num_wait) {
        UMBRA_CL(clEnqueueBarrierWithWaitList(ctx->queue, r->async->num_wait, r->async->wait_list,
                                              &barrier));
        if ((st = umbra__async_hold(r, barrier, 0)) != UMBRA_SUCCESS)
            goto fail;
    }
    r->async->gated = 1;
fail:
    if (barrier)
        clReleaseEvent(barrier);
    return st;
}

static void CL_CALLBACK release_held(cl_event e, cl_int status, void *user)
{
    (void)status;
    (void)user;
    clReleaseEvent(e);
}

umbra_status umbra__async_hold(umbra_renderer r, cl_event e, int kernel)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    if (!r->async || !e)
        return UMBRA_SUCCESS;
    /* Should the callback not be set, the reference stays: an event kept is harmless. */
    UMBRA_CL(clRetainEvent(e));
    UMBRA_CL(clSetEventCallback(e, CL_COMPLETE, release_held, NULL));
    if (kernel) {
        UMBRA_CL(clRetainEvent(e));
        if (r->async->last)
            clReleaseEvent(r->async->last);
        r->async->last = e;
        if (!r->async->first) {
            UMBRA_CL(clRetainEvent(e));
            r->async->first = e;
        }
    }
fail:
    return st;
}

void umbra__build_options(umbra_renderer r, char *buf, size_t size)
{
    /* The buffer's element type is the volume's: a volume of another type gets another program
     * (the context caches both). */
    static const char *const voxel_t[] = {"uchar", "ushort", "short", "float"};
    umbra_scalar_type t = r->volume ? r->volume->stored_type : UMBRA_FLOAT32;
    const int image = r->volume ? umbra__volume_images(r->volume)
                                : r->ctx->sampler == UMBRA_SAMPLER_IMAGE;
    const int kind = t <= UMBRA_FLOAT32 ? (int)t : (int)UMBRA_FLOAT32;
    int n = snprintf(buf, size,
                     "-DUMBRA_SAMPLER_IMAGE=%d -DUMBRA_LIGHT_CHANNELS=%u -DUMBRA_VOXEL_T=%s "
                     "-DUMBRA_VOXEL_KIND=%d -DUMBRA_VOXEL_CLAMPS=%d",
                     image, r->channels, voxel_t[kind], kind, r->volume ? r->volume->clamps : 1);
    /* A multi-channel volume or a label map (kernels/common/channels.cl); a plain volume adds
     * nothing, so its programs stay what they were. */
    if (r->volume && (r->volume->channels > 1 || r->volume->labels) && n > 0 && (size_t)n < size)
        n += snprintf(buf + n, size - (size_t)n, " -DUMBRA_CHANNELS=%u -DUMBRA_LABELS=%d",
                      r->volume->channels, r->volume->labels ? 1 : 0);
    /* A volume in several slabs: kernels/common/sampling.cl takes one parameter per slab. One slab
     * adds
     * nothing, so its programs stay those of the single-buffer code. */
    if (r->volume && r->volume->slab_count > 1 && n > 0 && (size_t)n < size)
        n += snprintf(buf + n, size - (size_t)n, " -DUMBRA_VOLUME_SLABS=%u -DUMBRA_SLAB_STEP=%u",
                      r->volume->slab_count, r->volume->slab_step);
    /* A part of a global grid (host/part_render.c); a whole volume adds nothing. */
    if (r->volume && r->volume->is_part && n > 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, " -DUMBRA_PART=1");
}

umbra_status umbra__bind_common(umbra_renderer r, cl_kernel k, cl_uint *next)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_mem view_tf = r->view_tf_buf ? r->view_tf_buf : r->light_tf_buf;
    /* A shadow build runs before the view tables exist and does not read them: any buffer will
     * do for the argument. */
    cl_mem view_bricks = r->view_bricks_buf ? r->view_bricks_buf : r->light_cells_buf;
    /* VOLUME_PARAM (kernels/common/sampling.cl) is one parameter per slab. */
    const cl_uint nslabs = r->volume->slab_count;
    cl_mem args[2 + UMBRA__MAX_SLABS + 5] = {r->frame_buf};
    memcpy(args + 1, r->volume->slabs, nslabs * sizeof(cl_mem));
    cl_mem rest[] = {view_tf, r->light_tf_buf, view_bricks, r->light_cells_buf, r->shadow_buf};
    memcpy(args + 1 + nslabs, rest, sizeof rest);
    const cl_uint nargs = 1 + nslabs + (cl_uint)(sizeof rest / sizeof rest[0]);
    for (cl_uint i = 0; i < nargs; ++i)
        UMBRA_CL(clSetKernelArg(k, i, sizeof(cl_mem), &args[i]));
    *next = nargs;
fail:
    return st;
}
