// SPDX-License-Identifier: Apache-2.0
/* host/preintegration.c: the cached pre-integration tables. See preintegration.h. */
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"

struct umbra__preint {
    cl_mem buffer;
    cl_kernel units, build;
    cl_program program;       /* the context's cached program the kernel came from */
    uint64_t tf_id;
    float length_voxels;
    umbra__preint_kind kind;
    int colored;
};

size_t umbra__preint_bytes(const umbra__preint *t)
{
    return t && t->buffer ? (size_t)UMBRA__PREINT_SIZE * UMBRA__PREINT_SIZE * 16 : 0;
}

void umbra__preint_release(umbra__preint *t)
{
    if (!t)
        return;
    if (t->buffer)
        clReleaseMemObject(t->buffer);
    if (t->units)
        clReleaseKernel(t->units);
    if (t->build)
        clReleaseKernel(t->build);
    free(t);
}

umbra_status umbra__preint_ensure(umbra_context ctx, const char *func, umbra__preint **table,
                                  umbra_transfer_function tf, float length_voxels,
                                  umbra__preint_kind kind, int colored, cl_mem *buf, double *ms)
{
    umbra_status st = UMBRA_SUCCESS;
    cl_event ev0 = NULL, ev = NULL;
    cl_mem units = NULL;
    umbra__preint *t = *table;
    if (kind == UMBRA__PREINT_VIEW)
        colored = 0; /* the view table does not depend on it: do not rebuild for it */
    colored = colored != 0;
    if (!t) {
        t = calloc(1, sizeof *t);
        if (!t)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory", func);
        *table = t;
    }
    if (t->buffer && t->tf_id == tf->id && t->length_voxels == length_voxels && t->kind == kind &&
        t->colored == colored) {
        *buf = t->buffer;
        return UMBRA_SUCCESS;
    }
    const char *files[] = {"common/common.cl", "common/preintegration.cl"};
    cl_program program;
    if ((st = umbra__program_get(ctx, files, 2, "", &program)) != UMBRA_SUCCESS)
        return st;
    if (program != t->program) {
        if (t->units)
            clReleaseKernel(t->units);
        if (t->build)
            clReleaseKernel(t->build);
        t->units = t->build = NULL;
        t->program = NULL;
        if ((st = umbra__kernel_create(ctx, program, "preintegration_units", &t->units)) ||
            (st = umbra__kernel_create(ctx, program, "preintegration_build", &t->build)))
            return st;
        t->program = program;
    }
    cl_int err;
    const size_t n = UMBRA__PREINT_SIZE - 1, bytes = (size_t)UMBRA__PREINT_SIZE * UMBRA__PREINT_SIZE * 16;
    if (!t->buffer) {
        t->buffer = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, bytes, NULL, &err);
        UMBRA_CL_CHECK(err, "clCreateBuffer(pre-integration table)");
    }
    /* The per-(span, unit) sub-steps live only during the build. */
    units = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, n * n * 16, NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(pre-integration sub-steps)");
    t->tf_id = 0; /* invalid until the rebuild below succeeds */
    cl_uint tf_size = tf->count, size = UMBRA__PREINT_SIZE, k = (cl_uint)kind, c = (cl_uint)colored;
    UMBRA_CL(clSetKernelArg(t->units, 0, sizeof(cl_mem), &tf->buffer));
    UMBRA_CL(clSetKernelArg(t->units, 1, sizeof tf_size, &tf_size));
    UMBRA_CL(clSetKernelArg(t->units, 2, sizeof(cl_mem), &units));
    UMBRA_CL(clSetKernelArg(t->units, 3, sizeof size, &size));
    UMBRA_CL(clSetKernelArg(t->units, 4, sizeof length_voxels, &length_voxels));
    UMBRA_CL(clSetKernelArg(t->units, 5, sizeof k, &k));
    UMBRA_CL(clSetKernelArg(t->units, 6, sizeof c, &c));
    UMBRA_CL(clSetKernelArg(t->build, 0, sizeof(cl_mem), &tf->buffer));
    UMBRA_CL(clSetKernelArg(t->build, 1, sizeof tf_size, &tf_size));
    UMBRA_CL(clSetKernelArg(t->build, 2, sizeof(cl_mem), &units));
    UMBRA_CL(clSetKernelArg(t->build, 3, sizeof(cl_mem), &t->buffer));
    UMBRA_CL(clSetKernelArg(t->build, 4, sizeof size, &size));
    UMBRA_CL(clSetKernelArg(t->build, 5, sizeof length_voxels, &length_voxels));
    UMBRA_CL(clSetKernelArg(t->build, 6, sizeof k, &k));
    UMBRA_CL(clSetKernelArg(t->build, 7, sizeof c, &c));
    size_t gu[2] = {n, n}, gb[2] = {UMBRA__PREINT_SIZE, UMBRA__PREINT_SIZE};
    double t0 = umbra__now_ms();
    if ((st = umbra__enqueue(ctx, t->units, 2, gu, NULL, &ev0)) != UMBRA_SUCCESS ||
        (st = umbra__enqueue(ctx, t->build, 2, gb, NULL, &ev)) != UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clWaitForEvents(1, &ev));
    if (ms) {
        cl_ulong a = 0, b = 0;
        if (clGetEventProfilingInfo(ev0, CL_PROFILING_COMMAND_START, sizeof a, &a, NULL) ==
                CL_SUCCESS &&
            clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof b, &b, NULL) ==
                CL_SUCCESS && b >= a)
            *ms += (double)(b - a) * 1e-6;
        else
            *ms += umbra__now_ms() - t0;
    }
    t->tf_id = tf->id;
    t->length_voxels = length_voxels;
    t->kind = kind;
    t->colored = colored;
    *buf = t->buffer;
fail:
    if (ev0)
        clReleaseEvent(ev0);
    if (ev)
        clReleaseEvent(ev);
    if (units)
        clReleaseMemObject(units);
    return st;
}
