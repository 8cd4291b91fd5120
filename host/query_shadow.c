// SPDX-License-Identifier: Apache-2.0
/* host/query_shadow.c: umbra_renderer_query_shadow, the shadow factor at points the application
 * gives, through the ray caster's program (kernels/raycast.cl, raycast_query_shadow) after the
 * frame's shadow structure is prepared as for a render (host/renderer.c). */
#include <stdlib.h>

#include "renderer_internal.h"

static umbra_status query_shadow(umbra_renderer r, const float *points, size_t count, float *rgb)
{
    const char *fn = "umbra_renderer_query_shadow";
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_mem in = NULL, outb = NULL;
    float *moved = NULL;
    if (!points || !rgb || count == 0 || count > (1u << 28))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: points %p, rgb %p, count %zu: need both buffers and 1..2^28 points",
                           fn, (const void *)points, (void *)rgb, count);
    if ((st = umbra__check_ready(r, fn)) != UMBRA_SUCCESS ||
        (st = umbra__effective_tfs(r)) != UMBRA_SUCCESS)
        return st;
    if (!r->tech->kernel_files)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique '%s' has no per-point shadow lookup", fn,
                           r->tech->info.name);
    umbra__progress_begin(r);
    if ((st = umbra__prepare_shadow(r, 0.5, 0)) != UMBRA_SUCCESS)
        return st;
    umbra__progress_phase(r, r->progress_last, 1.0);
    if ((st = umbra__raycast_kernels(r)) != UMBRA_SUCCESS)
        return st;
    /* The points are in the volume's world; the kernel takes them in its local frame. */
    const float *local = points;
    if (r->volume->transformed) {
        if (!(moved = malloc(count * 3 * sizeof *moved)))
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: out of host memory for %zu points", fn, count);
        for (size_t i = 0; i < count; ++i)
            umbra__volume_point_to_local(r->volume, points + 3 * i, moved + 3 * i);
        local = moved;
    }
    cl_int err;
    in = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, count * 12,
                        (void *)local, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(points)");
    outb = clCreateBuffer(ctx->cl_ctx, CL_MEM_WRITE_ONLY, count * 12, NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(rgb)");
    if ((st = umbra__upload_params(r)) != UMBRA_SUCCESS)
        goto fail;
    cl_uint next = 0, n = (cl_uint)count;
    if ((st = umbra__bind_common(r, r->query_kernel, &next)) != UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clSetKernelArg(r->query_kernel, next++, sizeof(cl_mem), &in));
    UMBRA_CL(clSetKernelArg(r->query_kernel, next++, sizeof(cl_mem), &outb));
    UMBRA_CL(clSetKernelArg(r->query_kernel, next++, sizeof(cl_uint), &n));
    if (r->tech->bind && (st = r->tech->bind(r, r->query_kernel, next)) != UMBRA_SUCCESS)
        goto fail;
    /* In bands like a render: a shadow query of the reference marches a shadow ray per point. */
    const size_t global[2] = {count, 1};
    size_t group[2] = {64, 1};
    const double cost = umbra__march_cost(r, 0);
    double ms = 0.0;
    umbra__band_local(r, cost, group);
    if ((st = umbra__run_2d(r, r->query_kernel, global, group, cost, &ms, fn)) != UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, outb, CL_TRUE, 0, count * 12, rgb, 0, NULL, NULL));
    umbra__progress_end(r);
fail:
    free(moved);
    umbra__release_mem(&in);
    umbra__release_mem(&outb);
    return st;
}

umbra_status umbra_renderer_query_shadow(umbra_renderer r, const float *points, size_t count,
                                         float *rgb)
{
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = query_shadow(r, points, count, rgb);
        umbra__call_end(r);
    }
    return st;
}

