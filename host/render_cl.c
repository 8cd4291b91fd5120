// SPDX-License-Identifier: Apache-2.0
/* host/render_cl.c: rendering into the application's cl_mem, blocking or asynchronous (the
 * checks of include/umbra/context.h's contract points 2 and 3 live here). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"
#include "renderer_internal.h"

static const char *mem_type_name(cl_mem_object_type t)
{
    switch (t) {
    case CL_MEM_OBJECT_BUFFER: return "buffer";
    case CL_MEM_OBJECT_IMAGE2D: return "2D image";
    case CL_MEM_OBJECT_IMAGE3D: return "3D image";
    case CL_MEM_OBJECT_IMAGE2D_ARRAY: return "2D image array";
    case CL_MEM_OBJECT_IMAGE1D: return "1D image";
    case CL_MEM_OBJECT_IMAGE1D_ARRAY: return "1D image array";
    case CL_MEM_OBJECT_IMAGE1D_BUFFER: return "1D image buffer";
    default: return "memory object of unknown type";
    }
}

/* The application's output buffer (context.h contract point 2): a buffer of this cl_context that
 * kernels may write, of at least 16*w*h bytes. */
static umbra_status check_app_buffer(umbra_renderer r, cl_mem rgba, uint32_t width,
                                     uint32_t height, const char *fn)
{
    umbra_context ctx = r->ctx;
    if (!rgba)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: rgba is NULL", fn);
    size_t have = 0;
    cl_context owner = NULL;
    cl_mem_object_type type = 0;
    cl_mem_flags flags = 0;
    cl_int err = clGetMemObjectInfo(rgba, CL_MEM_TYPE, sizeof type, &type, NULL);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(rgba, CL_MEM_CONTEXT, sizeof owner, &owner, NULL);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(rgba, CL_MEM_SIZE, sizeof have, &have, NULL);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(rgba, CL_MEM_FLAGS, sizeof flags, &flags, NULL);
    if (err != CL_SUCCESS)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: rgba %p is not a valid cl_mem (clGetMemObjectInfo: %s, %d)", fn,
                           (void *)rgba, umbra__cl_error_name(err), (int)err);
    if (owner != ctx->cl_ctx)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: rgba %p belongs to another cl_context (%p; the renderer's is %p)",
                           fn, (void *)rgba, (void *)owner, (void *)ctx->cl_ctx);
    if (type != CL_MEM_OBJECT_BUFFER)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: rgba %p is a %s (CL_MEM_TYPE 0x%x); a buffer is required", fn,
                           (void *)rgba, mem_type_name(type), (unsigned)type);
    if (flags & CL_MEM_READ_ONLY)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: rgba %p was created CL_MEM_READ_ONLY; kernels must write it", fn,
                           (void *)rgba);
    if (have < (size_t)width * height * 16)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: rgba %p holds %zu bytes; %u x %u RGBA floats need %zu", fn,
                           (void *)rgba, have, width, height, (size_t)width * height * 16);
    return UMBRA_SUCCESS;
}

static umbra_status render_app_buffer(umbra_renderer r, uint32_t width, uint32_t height,
                                      cl_mem rgba)
{
    const char *fn = "umbra_renderer_render_to_cl_buffer";
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    if ((st = umbra__check_size(r, width, height, fn)) != UMBRA_SUCCESS ||
        (st = check_app_buffer(r, rgba, width, height, fn)) != UMBRA_SUCCESS)
        return st;
    clRetainMemObject(rgba);
    st = umbra__render_into(r, width, height, rgba);
    if (st == UMBRA_SUCCESS)
        UMBRA_CL(clFinish(ctx->queue));
fail:
    clReleaseMemObject(rgba);
    if (st == UMBRA_SUCCESS)
        umbra__progress_end(r);
    return st;
}

umbra_status umbra_renderer_render_to_cl_buffer(umbra_renderer r, uint32_t width, uint32_t height,
                                                cl_mem rgba)
{
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = render_app_buffer(r, width, height, rgba);
        umbra__call_end(r);
    }
    return st;
}

static umbra_status render_async(umbra_renderer r, uint32_t width, uint32_t height, cl_mem rgba,
                                 cl_uint num_wait, const cl_event *wait_list, cl_event *done)
{
    const char *fn = "umbra_renderer_render_to_cl_buffer_async";
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    if (!done)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: done is NULL", fn);
    *done = NULL;
    if ((st = umbra__check_size(r, width, height, fn)) != UMBRA_SUCCESS ||
        (st = check_app_buffer(r, rgba, width, height, fn)) != UMBRA_SUCCESS)
        return st;
    if ((num_wait > 0) != (wait_list != NULL))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: num_wait %u with wait_list %p: a list needs a count and a count "
                           "a list", fn, num_wait, (const void *)wait_list);
    for (cl_uint i = 0; i < num_wait; ++i) {
        cl_context owner = NULL;
        if (!wait_list[i] || clGetEventInfo(wait_list[i], CL_EVENT_CONTEXT, sizeof owner, &owner,
                                            NULL) != CL_SUCCESS)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: wait_list[%u] %p is not a valid event", fn, i,
                               (void *)wait_list[i]);
        if (owner != ctx->cl_ctx)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: wait_list[%u] %p belongs to another cl_context (%p; the "
                               "renderer's is %p)", fn, i, (void *)wait_list[i], (void *)owner,
                               (void *)ctx->cl_ctx);
        /* Commands behind an event that has already failed never run on PoCL (they wait
         * forever): such a frame is refused before anything is enqueued. */
        cl_int status = CL_COMPLETE;
        if (clGetEventInfo(wait_list[i], CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status,
                           &status, NULL) == CL_SUCCESS && status < 0)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: wait_list[%u] %p has ended in an error (execution status "
                               "%d, %s): the frame would never run", fn, i, (void *)wait_list[i],
                               (int)status, umbra__cl_error_name(status));
    }
    umbra__async async = {num_wait, wait_list, 0, NULL, NULL};
    r->async = &async;
    st = umbra__render_into(r, width, height, rgba);
    r->async = NULL;
    if (st != UMBRA_SUCCESS)
        goto fail;
    if (!async.gated || !async.last) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: technique '%s' enqueued its frame without the wait list's barrier "
                         "or without a kernel", fn, r->tech->info.name);
        goto fail;
    }
    UMBRA_CL(clFlush(ctx->queue));
    /* *done is the frame's last kernel: on the in-order queue it completes after every command
     * of the frame, and its profiling counters time that kernel (umbra_renderer_get_stats has
     * the whole frame's). */
    UMBRA_CL(clRetainEvent(async.last));
    *done = async.last;
    r->async_first = async.first;
    r->async_last = async.last;
    return UMBRA_SUCCESS;
fail:
    if (async.first)
        clReleaseEvent(async.first);
    if (async.last)
        clReleaseEvent(async.last);
    return st;
}

umbra_status umbra_renderer_render_to_cl_buffer_async(umbra_renderer r, uint32_t width,
                                                      uint32_t height, cl_mem rgba,
                                                      cl_uint num_wait, const cl_event *wait_list,
                                                      cl_event *done)
{
    if (done)
        *done = NULL;
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = render_async(r, width, height, rgba, num_wait, wait_list, done);
        umbra__call_end(r);
    }
    return st;
}
