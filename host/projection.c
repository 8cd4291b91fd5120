// SPDX-License-Identifier: Apache-2.0
/* host/projection.c: the projection render modes (umbra_render_desc.mode: MIP, MinIP, average
 * intensity projection; kernels/projection.cl). A frame in these modes runs the projection
 * kernel where the composite mode runs the ray caster (host/renderer.c), over the same frame
 * constants and launch (bands, progress, asynchronous frames); its table is each channel's view
 * transfer function as given (a projection's pixel takes the entry's opacity uncorrected). */
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"

void umbra__projection_release(umbra_renderer r)
{
    if (r->projection_kernel)
        clReleaseKernel(r->projection_kernel);
    r->projection_kernel = NULL;
    r->projection_program = NULL; /* owned by the context's cache */
    umbra__release_mem(&r->projection_tf);
    memset(r->projection_key, 0, sizeof r->projection_key);
}

/* The channels' view tables in effect, one after the other, kept while they stay the same;
 * channel c's part at at[c], n[c] entries. */
static umbra_status projection_table(umbra_renderer r, cl_uint at[UMBRA_MAX_CHANNELS],
                                     cl_uint n[UMBRA_MAX_CHANNELS])
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    umbra_transfer_function tfs[UMBRA_MAX_CHANNELS];
    uint64_t want[UMBRA_MAX_CHANNELS] = {0};
    size_t total = 0;
    umbra__channel_tfs(r, 0, tfs);
    for (uint32_t c = 0; c < UMBRA_MAX_CHANNELS; ++c) {
        at[c] = (cl_uint)total;
        n[c] = c < r->volume->channels ? tfs[c]->count : 2u; /* unused channels: any 2 entries */
        if (c < r->volume->channels) {
            want[c] = tfs[c]->id;
            total += tfs[c]->count;
        }
    }
    if (r->projection_tf && memcmp(want, r->projection_key, sizeof want) == 0)
        return UMBRA_SUCCESS;
    umbra__release_mem(&r->projection_tf);
    memset(r->projection_key, 0, sizeof r->projection_key);
    float *t = malloc(total * 4 * sizeof *t);
    if (!t)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_renderer_render: out of memory for the projection's tables");
    for (uint32_t c = 0; c < r->volume->channels; ++c)
        memcpy(t + 4 * (size_t)at[c], tfs[c]->rgba, (size_t)tfs[c]->count * 4 * sizeof *t);
    cl_int err;
    r->projection_tf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                      total * 4 * sizeof *t, t, &err);
    free(t);
    UMBRA_CL_CHECK(err, "clCreateBuffer(projection tables)");
    memcpy(r->projection_key, want, sizeof want);
    r->rebuilds.tables++;
fail:
    return st;
}

umbra_status umbra__projection_kernel(umbra_renderer r, cl_mem out, cl_kernel *k, size_t local[2])
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    static const char *const files[] = {"common/common.cl", "common/sampling.cl",
                                        "common/channels.cl", "projection.cl"};
    char options[256];
    cl_program program;
    umbra__build_options(r, options, sizeof options);
    if ((st = umbra__program_get(ctx, files, 4, options, &program)) != UMBRA_SUCCESS)
        return st;
    if (program != r->projection_program || !r->projection_kernel) {
        if (r->projection_kernel)
            clReleaseKernel(r->projection_kernel);
        r->projection_kernel = NULL;
        r->projection_program = NULL;
        if ((st = umbra__kernel_create(ctx, program, "projection_render", &r->projection_kernel)))
            return st;
        r->projection_program = program;
    }
    cl_uint at[UMBRA_MAX_CHANNELS], n[UMBRA_MAX_CHANNELS];
    if ((st = projection_table(r, at, n)) != UMBRA_SUCCESS)
        return st;
    cl_kernel kk = r->projection_kernel;
    cl_uint next = 0;
    if ((st = umbra__bind_common(r, kk, &next)) != UMBRA_SUCCESS)
        return st;
    const cl_uint4 at4 = {{at[0], at[1], at[2], at[3]}}, n4 = {{n[0], n[1], n[2], n[3]}};
    const cl_uint mode = (cl_uint)r->opts.mode;
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof(cl_mem), &out));
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof(cl_mem), &r->samples_buf));
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof(cl_mem), &r->projection_tf));
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof at4, &at4));
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof n4, &n4));
    UMBRA_CL(clSetKernelArg(kk, next++, sizeof mode, &mode));
    umbra__choose_local(r, kk, local);
    *k = kk;
fail:
    return st;
}
