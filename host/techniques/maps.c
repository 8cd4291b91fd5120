// SPDX-License-Identifier: Apache-2.0
/* host/techniques/maps.c: the two single-layer light-space shadow maps, which share everything but
 * their kernels: the opacity-threshold map ("threshold", kernels/techniques/threshold.cl) and the
 * colored stochastic shadow map ("cssm", kernels/techniques/cssm.cl, Weidner & Linsen).
 *
 * Both store a fixed number of floats per texel of a map_size^2 map fitted to the volume's box
 * (host/lightspace.c): the threshold map one depth, the CSSM one depth per simulated light channel
 * (three, or one when the light is grey: r->channels). The map buffer lives as long as the
 * technique and is re-allocated only when its size changes; the renderer calls build only when
 * the light, volume, light transfer function or shadow description changed, so a camera move
 * re-uses the map. */
#include <math.h>
#include <stdlib.h>

#include "lightspace.h"
#include "renderer_internal.h"

typedef struct map_state {
    cl_mem map;
    size_t map_bytes;
    cl_program program; /* owned by the context's cache; the program build_kernel came from */
    cl_kernel build_kernel;
} map_state;

typedef struct map_kind {
    const char *build_name;
    int per_channel; /* CSSM: one value per light channel; threshold: one value */
} map_kind;

static const map_kind threshold_kind = {"threshold_build", 0};
static const map_kind cssm_kind = {"cssm_build", 1};

/* The CSSM block whose photons share a light ray (kernels/techniques/cssm.cl), B x B texels: by
 * default B is the map's whole texels per voxel, at most UMBRA_CSSM_MAX_RAY_BLOCK, so that a
 * block never spans more than a voxel of the box as the light sees it. */
static uint32_t cssm_ray_block(double texels_per_voxel)
{
    if (!(texels_per_voxel >= 1.0)) /* NaN too */
        return 1u;
    return texels_per_voxel >= UMBRA_CSSM_MAX_RAY_BLOCK ? UMBRA_CSSM_MAX_RAY_BLOCK
                                                        : (uint32_t)texels_per_voxel;
}

static float map_light_step(const umbra_shadow_desc *d)
{
    return umbra__map_step(d, UMBRA__MAP_STEP_SURFACE);
}

static umbra_status map_validate(umbra_renderer r, const umbra_shadow_desc *d, const char *name)
{
    const char *fn = "umbra_renderer_set_shadow";
    umbra_status st = umbra__lightspace_validate(r, d, name);
    if (st != UMBRA_SUCCESS)
        return st;
    if (d->taps != 1 && d->taps != 7 && d->taps != 13 && d->taps != 21)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: %s taps %u must be 1, 7, 13 or 21", fn, name, d->taps);
    return UMBRA_SUCCESS;
}

static umbra_status threshold_validate(umbra_renderer r, const umbra_shadow_desc *d)
{
    if (!(d->threshold > 0.0f && d->threshold < 1.0f))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_set_shadow: threshold %g must lie in (0, 1)",
                           d->threshold);
    return map_validate(r, d, "threshold");
}

static umbra_status cssm_validate(umbra_renderer r, const umbra_shadow_desc *d)
{
    if (d->ray_block > UMBRA_CSSM_MAX_RAY_BLOCK)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_set_shadow: cssm ray_block %u must be 0 (the map's "
                           "own) or lie in [1, %d]",
                           d->ray_block, UMBRA_CSSM_MAX_RAY_BLOCK);
    return map_validate(r, d, "cssm");
}

static uint32_t map_values(umbra_renderer r, const map_kind *kind)
{
    return kind->per_channel ? r->channels : 1u;
}

static umbra_status map_build(umbra_renderer r, double *ms, const map_kind *kind)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    map_state *s = r->tech_state;
    if (!s) {
        s = calloc(1, sizeof *s);
        if (!s)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "umbra_renderer_render: out of memory");
        r->tech_state = s;
    }
    const umbra_shadow_desc *d = &r->shadow;
    UmbraShadow *S = &r->shadow_params;
    const double texels_per_voxel = umbra__lightspace_setup(r, d->map_size);
    const uint32_t n = S->map_size; /* the size chosen, when d->map_size is auto */
    S->ray_block = !kind->per_channel ? 1u
                   : d->ray_block   ? d->ray_block
                                    : cssm_ray_block(texels_per_voxel);
    S->threshold = d->threshold;
    S->taps = d->taps;
    S->seed = d->seed;
    /* The threshold map stores an exact crossing depth from the texel centre's ray; a sample
     * half a texel beside that ray on a surface oblique to the light sees a slightly different
     * crossing, and would shadow itself (acne) without a margin. Half a light step (in normalised
     * depth) covers slopes up to step / texel and stays inside the +-1 step the crossing is
     * promised to. CSSM depths are segment midpoints, unbiased on average (see its kernel):
     * no bias, as in the paper. */
    S->depth_bias = kind->per_channel ? 0.0f : 0.5f * S->step * S->near_far[2];
    if ((st = umbra__upload_params(r)) != UMBRA_SUCCESS)
        return st;

    /* The technique's file without the ray caster: the build kernel needs only the volume
     * access and the projection. Built once per context and options (the context caches it). */
    const char *files[] = {"common/common.cl", "common/sampling.cl", "common/lightspace.cl",
                           r->tech->kernel_file};
    char options[256];
    cl_program program;
    umbra__build_options(r, options, sizeof options);
    if ((st = umbra__program_get(ctx, files, 4, options, &program)) != UMBRA_SUCCESS)
        return st;
    if (program != s->program || !s->build_kernel) {
        if (s->build_kernel)
            clReleaseKernel(s->build_kernel);
        s->build_kernel = NULL;
        s->program = NULL;
        if ((st = umbra__kernel_create(ctx, program, kind->build_name, &s->build_kernel)))
            return st;
        s->program = program;
    }

    size_t bytes = (size_t)n * n * map_values(r, kind) * sizeof(float);
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
                               umbra_shadow_technique_name(r->tech->id), n, n, bytes,
                               umbra__cl_error_name(err), (int)err);
        }
        s->map_bytes = bytes;
    }

    cl_uint next = 0;
    if ((st = umbra__bind_common(r, s->build_kernel, &next)) != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(s->build_kernel, next, sizeof(cl_mem), &s->map));
    const size_t blocks = (n + S->ray_block - 1) / S->ray_block;
    size_t global[2] = {blocks, blocks};
    st = umbra__run_2d(r, s->build_kernel, global, NULL, umbra__ray_samples(r, map_light_step(d)),
                       ms, "umbra_renderer_render");
fail:
    return st;
}

static umbra_status threshold_build(umbra_renderer r, double *ms)
{
    return map_build(r, ms, &threshold_kind);
}

static umbra_status cssm_build(umbra_renderer r, double *ms)
{
    return map_build(r, ms, &cssm_kind);
}

static umbra_status map_bind(umbra_renderer r, cl_kernel k, cl_uint first)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    map_state *s = r->tech_state;
    if (!s || !s->map)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_render: the %s map has not been built",
                           umbra_shadow_technique_name(r->tech->id));
    UMBRA_CL(clSetKernelArg(k, first, sizeof(cl_mem), &s->map));
fail:
    return st;
}

static size_t map_memory(umbra_renderer r)
{
    const map_state *s = r->tech_state;
    return s ? s->map_bytes : 0;
}

static void map_destroy(umbra_renderer r)
{
    map_state *s = r->tech_state;
    if (!s)
        return;
    if (s->build_kernel)
        clReleaseKernel(s->build_kernel);
    if (s->map)
        clReleaseMemObject(s->map);
    free(s);
    r->tech_state = NULL;
}

const umbra__technique umbra__technique_threshold = {
    .id = UMBRA_SHADOW_THRESHOLD,
    .kernel_file = "techniques/threshold.cl",
    .light_step = map_light_step,
    .validate = threshold_validate,
    .build = threshold_build,
    .bind = map_bind,
    .channels = 1, /* one depth, a binary test: grey light only */
    .memory = map_memory,
    .destroy = map_destroy,
};

const umbra__technique umbra__technique_cssm = {
    .id = UMBRA_SHADOW_CSSM,
    .kernel_file = "techniques/cssm.cl",
    .light_step = map_light_step,
    .validate = cssm_validate,
    .build = cssm_build,
    .bind = map_bind,
    .memory = map_memory,
    .destroy = map_destroy,
};
