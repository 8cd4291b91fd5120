// SPDX-License-Identifier: Apache-2.0
/* host/techniques/maps.c: the single-layer light-space map machinery (maps.h) that the threshold
 * map (threshold.c) and CSSM (cssm.c) share: one buffer of a fixed number of floats per texel of
 * a map_size^2 map fitted to the volume's box (host/lightspace.c), built by one kernel of the
 * technique's own files and read by its lookup. */
#include <stdlib.h>
#include <string.h>

#include "lightspace.h"
#include "techniques/maps.h"

typedef struct map_state {
    cl_mem map;
    size_t map_bytes;
    cl_program program; /* owned by the context's cache; the program build_kernel came from */
    cl_kernel build_kernel, filter_kernel;
    unsigned char constants[64]; /* the technique's kernel constants (kind->constants_size) */
    int built;
    cl_mem constants_buf;
} map_state;

static map_state *state_get(umbra_renderer r)
{
    if (!r->tech_state)
        r->tech_state = calloc(1, sizeof(map_state));
    return r->tech_state;
}

const double umbra__map_taps[4] = {1, 7, 13, 21};

/* The map kind's filter passes over the built map (maps.h): each reads the map and writes a new
 * buffer, which becomes the map; the buffer read is released after the pass. */
static umbra_status run_filter(umbra_renderer r, map_state *s, uint32_t passes, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const cl_uint n = r->shadow_params.map_size;
    cl_mem out = NULL;
    for (cl_uint pass = 0; pass < passes; ++pass) {
        cl_int err;
        out = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, s->map_bytes, NULL, &err);
        if (err != CL_SUCCESS) {
            int oom = err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE;
            return umbra__fail(ctx, oom ? UMBRA_ERROR_OUT_OF_MEMORY : UMBRA_ERROR_OPENCL,
                               "umbra_renderer_render: %s map filter pass of %u x %u texels "
                               "(%zu bytes): clCreateBuffer failed with %s (%d)",
                               r->tech->info.name, n, n, s->map_bytes,
                               umbra__cl_error_name(err), (int)err);
        }
        UMBRA_CL(clSetKernelArg(s->filter_kernel, 0, sizeof(cl_mem), &r->shadow_buf));
        UMBRA_CL(clSetKernelArg(s->filter_kernel, 1, sizeof(cl_mem), &s->constants_buf));
        UMBRA_CL(clSetKernelArg(s->filter_kernel, 2, sizeof pass, &pass));
        UMBRA_CL(clSetKernelArg(s->filter_kernel, 3, sizeof(cl_mem), &s->map));
        UMBRA_CL(clSetKernelArg(s->filter_kernel, 4, sizeof(cl_mem), &out));
        const size_t global[2] = {n, n};
        /* cost: a pass reads a few texels per work-item, nothing like a light ray */
        if ((st = umbra__run_2d(r, s->filter_kernel, global, NULL, 16.0, ms,
                                "umbra_renderer_render")) != UMBRA_SUCCESS)
            goto fail;
        clReleaseMemObject(s->map);
        s->map = out;
        out = NULL;
    }
fail:
    if (out)
        clReleaseMemObject(out);
    return st;
}

umbra_status umbra__map_build(umbra_renderer r, double *ms)
{
    const umbra__map_kind *kind = r->tech->data;
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    map_state *s = state_get(r);
    if (!s)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_renderer_render: out of memory");
    const umbra_shadow_desc *d = &r->shadow;
    UmbraShadow *S = &r->shadow_params;
    const double texels_per_voxel = umbra__lightspace_setup(r, d->map.size);
    const uint32_t n = S->map_size; /* the size chosen, when d->map.size is auto */
    const uint32_t block = kind->build_constants(r, texels_per_voxel, s->constants);
    s->built = 1;
    if ((st = umbra__upload_params(r)) != UMBRA_SUCCESS ||
        (st = umbra__upload_constants(r, s->constants, kind->constants_size, &s->constants_buf)))
        return st;

    /* The technique's files without the ray caster: the build kernel needs only the volume
     * access and the projection. Built once per context and options (the context caches it). */
    static const char *const common[] = {"common/common.cl", "common/sampling.cl",
                                         "common/channels.cl",
                                         "common/lightspace.cl"};
    const char *files[16];
    size_t nfiles = umbra__program_files(r->tech, common, 4, NULL, files, 16);
    char options[256];
    cl_program program;
    umbra__build_options(r, options, sizeof options);
    if ((st = umbra__program_get(ctx, files, nfiles, options, &program)) != UMBRA_SUCCESS)
        return st;
    if (program != s->program || !s->build_kernel) {
        if (s->build_kernel)
            clReleaseKernel(s->build_kernel);
        if (s->filter_kernel)
            clReleaseKernel(s->filter_kernel);
        s->build_kernel = s->filter_kernel = NULL;
        s->program = NULL;
        if ((st = umbra__kernel_create(ctx, program, kind->build_kernel, &s->build_kernel)) ||
            (kind->filter_kernel &&
             (st = umbra__kernel_create(ctx, program, kind->filter_kernel, &s->filter_kernel))))
            return st;
        s->program = program;
    }

    size_t bytes = (size_t)n * n * kind->values(r) * sizeof(float);
    if (s->map && s->map_bytes != bytes) {
        clReleaseMemObject(s->map);
        s->map = NULL;
        s->map_bytes = 0;
    }
    if (!s->map) {
        cl_int err;
        s->map = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, bytes, NULL, &err);
        if (err != CL_SUCCESS) {
            int oom = err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE;
            return umbra__fail(ctx, oom ? UMBRA_ERROR_OUT_OF_MEMORY : UMBRA_ERROR_OPENCL,
                               "umbra_renderer_render: %s map of %u x %u texels (%zu bytes): "
                               "clCreateBuffer failed with %s (%d)",
                               r->tech->info.name, n, n, bytes, umbra__cl_error_name(err),
                               (int)err);
        }
        s->map_bytes = bytes;
    }

    cl_uint next = 0;
    if ((st = umbra__bind_common(r, s->build_kernel, &next)) != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(s->build_kernel, next++, sizeof(cl_mem), &s->constants_buf));
    UMBRA_CL(clSetKernelArg(s->build_kernel, next, sizeof(cl_mem), &s->map));
    /* A part's march goes on from the state the parts before it left (host/part_light.c). */
    if (r->volume->is_part && (st = umbra__part_bind_build(r, s->build_kernel, next + 1, n)))
        return st;
    const size_t blocks = (n + block - 1) / block;
    size_t global[2] = {blocks, blocks};
    st = umbra__run_2d(r, s->build_kernel, global, NULL,
                       umbra__ray_samples(r, r->tech->light_step(d)), ms, "umbra_renderer_render");
    const uint32_t passes =
        kind->filter_kernel && kind->filter_passes ? kind->filter_passes(r) : 0u;
    if (st == UMBRA_SUCCESS && passes)
        st = run_filter(r, s, passes, ms);
fail:
    return st;
}

umbra_status umbra__map_bind(umbra_renderer r, cl_kernel k, cl_uint first)
{
    const umbra__map_kind *kind = r->tech->data;
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    map_state *s = r->tech_state;
    if (!s || !s->map || !s->built)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_render: the %s map has not been built",
                           r->tech->info.name);
    if (kind->lookup_constants)
        kind->lookup_constants(r, s->constants);
    if ((st = umbra__upload_constants(r, s->constants, kind->constants_size, &s->constants_buf)))
        return st;
    UMBRA_CL(clSetKernelArg(k, first, sizeof(cl_mem), &s->constants_buf));
    UMBRA_CL(clSetKernelArg(k, first + 1, sizeof(cl_mem), &s->map));
fail:
    return st;
}

size_t umbra__map_memory(umbra_renderer r)
{
    const map_state *s = r->tech_state;
    return s ? s->map_bytes : 0;
}

void umbra__map_destroy(umbra_renderer r)
{
    map_state *s = r->tech_state;
    if (!s)
        return;
    if (s->build_kernel)
        clReleaseKernel(s->build_kernel);
    if (s->filter_kernel)
        clReleaseKernel(s->filter_kernel);
    if (s->map)
        clReleaseMemObject(s->map);
    if (s->constants_buf)
        clReleaseMemObject(s->constants_buf);
    free(s);
    r->tech_state = NULL;
}

const void *umbra__map_constants(umbra_renderer r)
{
    const map_state *s = r->tech_state;
    return s && s->built ? s->constants : NULL;
}

umbra_status umbra__map_write(umbra_renderer r, const void *data, size_t bytes)
{
    const map_state *s = r->tech->build == umbra__map_build ? r->tech_state : NULL;
    umbra_status st = UMBRA_SUCCESS;
    umbra_context ctx = r->ctx;
    if (!s || !s->map || !s->built || bytes != s->map_bytes)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra__map_write: %zu bytes for a map of %zu (built: %d)", bytes,
                           s ? s->map_bytes : (size_t)0, s ? s->built : 0);
    UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, s->map, CL_TRUE, 0, bytes, data, 0, NULL, NULL));
fail:
    return st;
}

umbra_status umbra__map_read(umbra_renderer r, void *out, size_t bytes)
{
    const map_state *s = r->tech->build == umbra__map_build ? r->tech_state : NULL;
    umbra_status st = UMBRA_SUCCESS;
    umbra_context ctx = r->ctx;
    if (!s || !s->map || !s->built || bytes < s->map_bytes)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra__map_read: %zu bytes for a map of %zu (built: %d)", bytes,
                           s ? s->map_bytes : (size_t)0, s ? s->built : 0);
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, s->map, CL_TRUE, 0, s->map_bytes, out, 0, NULL,
                                 NULL));
fail:
    return st;
}
