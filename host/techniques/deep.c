// SPDX-License-Identifier: Apache-2.0
/* host/techniques/deep.c: the deep shadow map (Hadwiger et al. 2006, after Lokovic and Veach 2000),
 * host side. kernels/techniques/deep.cl has the algorithm; this module owns its device memory:
 *
 *   - the pre-compressed segment table (256 x 256 entries of 4 nodes), cached by what it depends
 *     on -- the light transfer function, the light step, the number of light channels and the
 *     transmission mode -- so a light move or a camera move never rebuilds it; two are kept
 *     where they differ only in the step (the draft's and the full map's, which interaction
 *     auto alternates between), so neither a draft nor the full map after it rebuilds one;
 *   - the blocked map: a pool of blocks (K node layers of one tile each), a head index per tile,
 *     a next index per block and a node count per texel. The pool is sized from the last build
 *     (or two blocks per tile the first time); a build that asks for more blocks than the pool
 *     holds is counted on the device, and the pool is re-allocated to exactly the count and the
 *     build repeated, so no node is dropped (or, with growth disabled, the build fails with a
 *     message giving both numbers);
 *   - or, with a fixed node budget N (max_nodes > 0), a flat array of N nodes per texel.
 * Memory reported: used blocks x block bytes + the layout (heads, used blocks' next indices,
 * counts) + the table; for a fixed budget map_size^2 x N x node bytes + the table.
 *
 * The build kernels live in kernels/techniques/deep.cl next to the lookup (the segment table's in
 * kernels/techniques/deep_lut.cl, the fixed-budget one in kernels/techniques/deep_budget.cl) but
 * are compiled only into the build program (DEEP_BUILD_KERNELS), not into every ray caster
 * program. The map on parts (its pieces exported and merged) is host/techniques/deep_part.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lightspace.h"
#include "techniques/deep_state.h"

_Static_assert(sizeof(UmbraDeep) == 16, "UmbraDeep layout");

/* Samples a texel's march takes, at most: the cost of a build launch (progress bands). */
static double march_cost(umbra_renderer r)
{
    return umbra__ray_samples(r, umbra__map_light_step(&r->shadow)) * r->shadow.deep.prefilter;
}

static deep_state *state_get(umbra_renderer r)
{
    if (!r->tech_state) {
        deep_state *s = calloc(1, sizeof *s);
        if (!s)
            return NULL;
        s->allow_growth = 1;
        r->tech_state = s;
    }
    return r->tech_state;
}

static void release_mem(cl_mem *m)
{
    if (*m)
        clReleaseMemObject(*m);
    *m = NULL;
}

static void release_kernel(cl_kernel *k)
{
    if (*k)
        clReleaseKernel(*k);
    *k = NULL;
}

/* A device buffer, failing with a message that names what it is for. */
static umbra_status create_buffer(umbra_context ctx, size_t bytes, const char *what, cl_mem *out)
{
    cl_ulong max_alloc = 0;
    clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc, &max_alloc, NULL);
    if (max_alloc && bytes > max_alloc)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_renderer_render: deep shadow map %s needs %zu bytes; the "
                           "device allows %llu per buffer (use a smaller map_size, a larger "
                           "epsilon or a node budget)", what, bytes, (unsigned long long)max_alloc);
    cl_int err;
    *out = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, bytes ? bytes : 16, NULL, &err);
    if (err != CL_SUCCESS) {
        *out = NULL;
        return umbra__fail(ctx,
                           err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE
                               ? UMBRA_ERROR_OUT_OF_MEMORY
                               : UMBRA_ERROR_OPENCL,
                           "umbra_renderer_render: deep shadow map %s (%zu bytes): clCreateBuffer "
                           "failed with %s (%d)", what, bytes, umbra__cl_error_name(err), (int)err);
    }
    return UMBRA_SUCCESS;
}

/* The build program (kernels/techniques/deep.cl with its build kernels switched on, then
 * deep_lut.cl and deep_budget.cl; without the ray caster, so it does not depend on how the
 * renderer assembles that one; the pre-filter's ray count compiled in, DEEP_SUB_RAYS), its three
 * kernels, and the tile edge the build's work-group size allows. */
static umbra_status ensure_program(umbra_renderer r, deep_state *s)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    static const char *const common[] = {"common/common.cl", "common/sampling.cl",
                                         "common/channels.cl",
                                         "common/lightspace.cl"};
    static const char *const after[] = {"techniques/deep_lut.cl", "techniques/deep_budget.cl",
                                        NULL};
    const char *files[16];
    const size_t nfiles = umbra__program_files(r->tech, common, 4, after, files, 16);
    char options[300];
    cl_program program;
    umbra__build_options(r, options, sizeof options - 48);
    const size_t used = strlen(options);
    snprintf(options + used, sizeof options - used, " -DDEEP_BUILD_KERNELS=1 -DDEEP_SUB_RAYS=%u",
             r->shadow.deep.prefilter);
    if ((st = umbra__program_get(ctx, files, nfiles, options, &program)) != UMBRA_SUCCESS)
        return st;
    if (program == s->program && s->k_build)
        return UMBRA_SUCCESS;
    release_kernel(&s->k_lut);
    release_kernel(&s->k_build);
    release_kernel(&s->k_fixed);
    s->program = NULL;
    if ((st = umbra__kernel_create(ctx, program, "deep_lut", &s->k_lut)) ||
        (st = umbra__kernel_create(ctx, program, "deep_build", &s->k_build)) ||
        (st = umbra__kernel_create(ctx, program, "deep_build_fixed", &s->k_fixed)))
        goto fail;
    /* One work-group per tile: 16 x 16 as in the paper where the kernel and device allow 256
     * work-items (PoCL's CPU device does), else 8 x 8. */
    size_t kernel_wg = 0, device_wg = 0, item_sizes[3] = {0, 0, 0};
    UMBRA_CL(clGetKernelWorkGroupInfo(s->k_build, ctx->device, CL_KERNEL_WORK_GROUP_SIZE,
                                      sizeof kernel_wg, &kernel_wg, NULL));
    UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof device_wg,
                             &device_wg, NULL));
    UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_WORK_ITEM_SIZES, sizeof item_sizes,
                             item_sizes, NULL));
    size_t limit = kernel_wg < device_wg ? kernel_wg : device_wg;
    size_t items = item_sizes[0] < item_sizes[1] ? item_sizes[0] : item_sizes[1];
    if (limit >= 256 && items >= 16)
        s->tile = 16;
    else if (limit >= 64 && items >= 8)
        s->tile = 8;
    else {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "umbra_renderer_render: the deep map build needs work-groups of 8 x 8 "
                         "work-items; this device allows %zu (kernel) / %zu (device)",
                         kernel_wg, device_wg);
        goto fail;
    }
    s->program = program;
    return UMBRA_SUCCESS;
fail:
    release_kernel(&s->k_lut);
    release_kernel(&s->k_build);
    release_kernel(&s->k_fixed);
    return st;
}

static umbra_status run_kernel(umbra_renderer r, cl_kernel k, const size_t global[2],
                               const size_t *local, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    cl_event ev = NULL;
    double t0 = umbra__now_ms();
    if ((st = umbra__enqueue(ctx, k, 2, global, local, &ev)) != UMBRA_SUCCESS)
        goto fail;
    UMBRA_CL(clWaitForEvents(1, &ev));
    double t = umbra__event_ms(ev);
    *ms += t >= 0.0 ? t : umbra__now_ms() - t0;
fail:
    if (ev)
        clReleaseEvent(ev);
    return st;
}

/* The segment table for the current light table, rebuilt only when its key changed. Two slots:
 * a new key replaces the slot not in use, and a table in the other slot whose key differs in more
 * than the step (another transfer function, channel count or transmission) is released. */
static umbra_status ensure_lut(umbra_renderer r, deep_state *s, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    float step = umbra__map_light_step(&r->shadow);
    uint32_t step_bits;
    memcpy(&step_bits, &step, sizeof step_bits);
    uint64_t key[4] = {umbra__light_tf(r)->id, step_bits, r->channels,
                       r->opts.transmission == UMBRA_TRANSMISSION_COLORED};
    for (int i = 0; i < 2; ++i)
        if (s->lut[i] && s->lut_valid[i] && memcmp(key, s->lut_key[i], sizeof key) == 0) {
            s->lut_cur = i;
            return UMBRA_SUCCESS;
        }
    const int slot = s->lut[s->lut_cur] && s->lut_valid[s->lut_cur] ? 1 - s->lut_cur : s->lut_cur;
    const int other = 1 - slot;
    if (s->lut[other] && (!s->lut_valid[other] || s->lut_key[other][0] != key[0] ||
                          s->lut_key[other][2] != key[2] || s->lut_key[other][3] != key[3])) {
        release_mem(&s->lut[other]);
        s->lut_valid[other] = 0;
    }
    s->lut_cur = slot;
    s->lut_valid[slot] = 0;
    release_mem(&s->lut[slot]);
    size_t bytes = (size_t)UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_NODES *
                   s->node_bytes;
    if ((st = create_buffer(ctx, bytes, "segment table", &s->lut[slot])) != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(s->k_lut, 0, sizeof(cl_mem), &r->frame_buf));
    UMBRA_CL(clSetKernelArg(s->k_lut, 1, sizeof(cl_mem), &r->light_tf_buf));
    UMBRA_CL(clSetKernelArg(s->k_lut, 2, sizeof(cl_mem), &s->lut[slot]));
    UMBRA_CL(clSetKernelArg(s->k_lut, 3, sizeof step, &step)); /* the segment, in voxels */
    size_t global[2] = {UMBRA__DEEP_LUT_RES, UMBRA__DEEP_LUT_RES};
    if ((st = run_kernel(r, s->k_lut, global, NULL, ms)) != UMBRA_SUCCESS)
        goto fail;
    memcpy(s->lut_key[slot], key, sizeof key);
    s->lut_valid[slot] = 1;
    s->lut_builds++;
fail:
    return st;
}

/* Arguments shared by deep_build and deep_build_fixed after the common ones; returns the next
 * index through *next. */
static umbra_status bind_march(umbra_renderer r, deep_state *s, cl_kernel k, cl_uint *next)
{
    umbra_context ctx = r->ctx;
    umbra_status st = umbra__bind_common(r, k, next);
    if (st != UMBRA_SUCCESS)
        return st;
    cl_uint use_lut = s->lut_used ? 1u : 0u;
    float eps = r->shadow.deep.epsilon;
    cl_mem lut = s->lut_used ? s->lut[s->lut_cur] : s->dummy;
    UMBRA_CL(clSetKernelArg(k, (*next)++, sizeof(cl_mem), &s->constants_buf));
    UMBRA_CL(clSetKernelArg(k, (*next)++, sizeof(cl_mem), &lut));
    UMBRA_CL(clSetKernelArg(k, (*next)++, sizeof use_lut, &use_lut));
    UMBRA_CL(clSetKernelArg(k, (*next)++, sizeof eps, &eps));
fail:
    return st;
}

static umbra_status ensure_size(umbra_context ctx, cl_mem *buf, size_t *have, size_t want,
                                const char *what)
{
    if (*buf && *have == want)
        return UMBRA_SUCCESS;
    release_mem(buf);
    *have = 0;
    umbra_status st = create_buffer(ctx, want, what, buf);
    if (st == UMBRA_SUCCESS)
        *have = want;
    return st;
}

umbra_status umbra__deep_alloc_pool(umbra_context ctx, deep_state *s, size_t blocks)
{
    release_mem(&s->pool);
    release_mem(&s->next);
    s->pool_blocks = 0;
    umbra_status st = create_buffer(ctx, blocks * s->block_bytes, "block pool", &s->pool);
    if (st == UMBRA_SUCCESS)
        st = create_buffer(ctx, blocks * sizeof(cl_int), "block links", &s->next);
    if (st == UMBRA_SUCCESS)
        s->pool_blocks = blocks;
    return st;
}

static umbra_status build_blocked(umbra_renderer r, deep_state *s, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const uint32_t n = s->map_size, T = s->tile;
    const size_t tiles = (size_t)s->tiles_per_row * s->tiles_per_row;
    size_t have_counter = s->counter ? sizeof(cl_uint) : 0;
    if ((st = ensure_size(ctx, &s->head, &s->head_count, tiles * sizeof(cl_int), "tile heads")) ||
        (st = ensure_size(ctx, &s->counts, &s->counts_count, (size_t)n * n * sizeof(cl_uint),
                          "node counts")) ||
        (st = ensure_size(ctx, &s->counter, &have_counter, sizeof(cl_uint), "block counter")))
        return st;
    /* Pool: the knob's size, else room for the last build plus an eighth, else two blocks a tile;
     * it only grows, so a light moving back and forth does not re-allocate. */
    size_t want = s->pool_override ? s->pool_override
                  : s->used_blocks ? s->used_blocks + s->used_blocks / 8 + 1
                                   : 2 * tiles;
    if (!s->pool || (s->pool_override ? s->pool_blocks != want : s->pool_blocks < want))
        if ((st = umbra__deep_alloc_pool(ctx, s, want)) != UMBRA_SUCCESS)
            return st;
    /* The most blocks the pool (one buffer) could ever hold on this device: a build that asks
     * for more stops as soon as it does, and fails here, instead of finishing a pass of a map
     * that can never be stored (a 4096^2 map at epsilon 0 took a minute to find out). Below
     * 2^31 so that the block counter cannot wrap. */
    cl_ulong max_alloc = 0;
    UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc,
                             &max_alloc, NULL));
    cl_ulong limit64 = max_alloc / s->block_bytes;
    limit64 = limit64 < ((cl_ulong)1 << 31) ? limit64 : ((cl_ulong)1 << 31);
    if (s->limit_override)
        limit64 = s->limit_override;
    const cl_uint limit = (cl_uint)limit64;
    for (int attempt = 0;; ++attempt) {
        const cl_uint zero = 0, capacity = (cl_uint)s->pool_blocks;
        cl_uint next = 0, used = 0;
        UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, s->counter, CL_TRUE, 0, sizeof zero, &zero, 0,
                                      NULL, NULL));
        if ((st = bind_march(r, s, s->k_build, &next)) != UMBRA_SUCCESS)
            return st;
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof(cl_mem), &s->pool));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof(cl_mem), &s->head));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof(cl_mem), &s->next));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof(cl_mem), &s->counts));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof(cl_mem), &s->counter));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof capacity, &capacity));
        UMBRA_CL(clSetKernelArg(s->k_build, next++, sizeof limit, &limit));
        /* A part marches on from the visibility imported (host/part_light.c), written again
         * before each pass: the kernel leaves the exit visibility in its place. */
        if (r->volume->is_part && (st = umbra__part_bind_build(r, s->k_build, next++, n)) !=
                                      UMBRA_SUCCESS)
            return st;
        size_t global[2] = {(size_t)s->tiles_per_row * T, (size_t)s->tiles_per_row * T};
        size_t local[2] = {T, T};
        if ((st = umbra__run_2d(r, s->k_build, global, local, march_cost(r), ms,
                                "umbra_renderer_render")) != UMBRA_SUCCESS)
            return st;
        s->build_passes++;
        UMBRA_CL(clEnqueueReadBuffer(ctx->queue, s->counter, CL_TRUE, 0, sizeof used, &used, 0,
                                     NULL, NULL));
        s->asked_blocks = used;
        if (used >= limit)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "umbra_renderer_render: the deep shadow map of %u x %u texels at "
                               "epsilon %g needs more than %u blocks of %zu bytes, more than "
                               "the device's largest allocation (%llu bytes) holds; raise "
                               "epsilon or map_step, set max_nodes, or lower map_size", n, n,
                               (double)r->shadow.deep.epsilon, limit, s->block_bytes,
                               (unsigned long long)max_alloc);
        if (used <= capacity) {
            s->used_blocks = used;
            break;
        }
        /* The count is deterministic (each tile's chain length depends only on its texels), so
         * one re-allocation to exactly the count always suffices. */
        if (!s->allow_growth || attempt >= 2)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "umbra_renderer_render: the deep shadow map needs %u blocks of "
                               "%zu bytes but the pool holds %u and may not grow", used,
                               s->block_bytes, capacity);
        if ((st = umbra__deep_alloc_pool(ctx, s, used)) != UMBRA_SUCCESS)
            return st;
        s->pool_growths++;
    }
fail:
    return st;
}

static umbra_status build_fixed(umbra_renderer r, deep_state *s, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const uint32_t n = s->map_size;
    size_t bytes = (size_t)n * n * r->shadow.deep.max_nodes * s->node_bytes;
    if ((st = ensure_size(ctx, &s->fixed, &s->fixed_bytes, bytes, "node array")) != UMBRA_SUCCESS)
        return st;
    cl_uint next = 0;
    if ((st = bind_march(r, s, s->k_fixed, &next)) != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(s->k_fixed, next++, sizeof(cl_mem), &s->fixed));
    size_t global[2] = {n, n};
    st = umbra__run_2d(r, s->k_fixed, global, NULL, march_cost(r), ms, "umbra_renderer_render");
    if (st == UMBRA_SUCCESS)
        s->build_passes++;
fail:
    return st;
}

static umbra_status deep_build(umbra_renderer r, double *ms)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    deep_state *s = state_get(r);
    if (!s)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_renderer_render: out of memory");
    const umbra_deep_desc *d = &r->shadow.deep;
    if ((st = ensure_program(r, s)) != UMBRA_SUCCESS)
        return st;
    const UmbraShadow *S = &r->shadow_params;
    umbra__lightspace_setup(r, r->shadow.map.size);
    s->constants.tile = s->tile;
    s->constants.tiles_per_row = (S->map_size + s->tile - 1) / s->tile; /* the size chosen */
    s->constants.block_size = d->block_size;
    s->constants.max_nodes = d->max_nodes;
    if ((st = umbra__upload_params(r)) != UMBRA_SUCCESS ||
        (st = umbra__upload_constants(r, &s->constants, sizeof s->constants,
                                      &s->constants_buf)) != UMBRA_SUCCESS)
        return st;
    s->tiles_per_row = s->constants.tiles_per_row;
    s->block_size = d->block_size;
    s->channels = r->channels;
    s->max_nodes = d->max_nodes;
    s->map_size = S->map_size;
    s->node_bytes = sizeof(float) * (1u + r->channels);
    s->block_bytes = (size_t)d->block_size * s->tile * s->tile * s->node_bytes;
    if (!s->dummy && (st = create_buffer(ctx, 16, "placeholder", &s->dummy)) != UMBRA_SUCCESS)
        return st;
    /* The segment table integrates one transfer function over pairs of values: a multi-channel
     * volume or a label map marches the midpoint rule, as lookup_table 0 does. */
    s->lut_used = d->lookup_table != 0 && r->volume->channels == 1 && !r->volume->labels;
    if (s->lut_used) {
        if ((st = ensure_lut(r, s, ms)) != UMBRA_SUCCESS)
            return st;
    }
    /* Without the table a cached one is kept (turning the option back on must not rebuild it)
     * but not counted: memory() reports what the map uses. */
    s->fixed_mode = d->max_nodes > 0;
    if (s->fixed_mode) {
        release_mem(&s->pool);
        release_mem(&s->next);
        s->pool_blocks = s->used_blocks = 0;
        st = build_fixed(r, s, ms);
    } else {
        release_mem(&s->fixed);
        s->fixed_bytes = 0;
        st = build_blocked(r, s, ms);
    }
    if (st == UMBRA_SUCCESS)
        s->builds++;
    return st;
}

static umbra_status deep_bind(umbra_renderer r, cl_kernel k, cl_uint first)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    deep_state *s = r->tech_state;
    if (!s || !s->dummy || (s->fixed_mode ? !s->fixed : !s->pool))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_render: the deep shadow map has not been built");
    cl_mem args[5] = {s->constants_buf, s->fixed_mode ? s->fixed : s->pool,
                      s->fixed_mode ? s->dummy : s->head, s->fixed_mode ? s->dummy : s->next,
                      s->fixed_mode ? s->dummy : s->counts};
    for (cl_uint i = 0; i < 5; ++i)
        UMBRA_CL(clSetKernelArg(k, first + i, sizeof(cl_mem), &args[i]));
fail:
    return st;
}

/* The tables held (one, or the draft's and the full map's). */
static size_t lut_bytes(const deep_state *s)
{
    if (!s->lut_used)
        return 0;
    const size_t one =
        (size_t)UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_NODES * s->node_bytes;
    return one * (size_t)((s->lut[0] != NULL) + (s->lut[1] != NULL));
}

static size_t map_bytes(const deep_state *s)
{
    return s->fixed_mode ? s->fixed_bytes : s->used_blocks * s->block_bytes;
}

static size_t layout_bytes(const deep_state *s)
{
    if (s->fixed_mode)
        return 0;
    return (size_t)s->tiles_per_row * s->tiles_per_row * sizeof(cl_int) +
           s->used_blocks * sizeof(cl_int) + (size_t)s->map_size * s->map_size * sizeof(cl_uint);
}

static size_t deep_memory(umbra_renderer r)
{
    const deep_state *s = r->tech_state;
    if (!s || s->builds == 0)
        return 0;
    return map_bytes(s) + layout_bytes(s) + lut_bytes(s);
}

static void deep_destroy(umbra_renderer r)
{
    deep_state *s = r->tech_state;
    if (!s)
        return;
    release_kernel(&s->k_lut);
    release_kernel(&s->k_build);
    release_kernel(&s->k_fixed);
    cl_mem *mems[] = {&s->lut[0], &s->lut[1], &s->pool,  &s->next,  &s->head,
                      &s->counts, &s->counter, &s->fixed, &s->dummy, &s->constants_buf};
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; ++i)
        release_mem(mems[i]);
    free(s);
    r->tech_state = NULL;
}

static const double prefilter_set[] = {1, 5};

static const umbra__param params[] = {
    UMBRA__MAP_PARAMS,
    UMBRA__PARAM(deep, epsilon,
                 .doc = "compression error bound: every visibility the march gave lies within "
                        "epsilon of the stored function",
                 .flags = UMBRA_PARAM_REBUILDS, .default_value = 0.02, .min = 0, .max = 1),
    UMBRA__PARAM(deep, max_nodes, .alias = "nodes",
                 .doc = "fixed budget of nodes per texel: the nodes kept are chosen once the "
                        "whole ray is known, for the least error",
                 .flags = UMBRA_PARAM_ZERO | UMBRA_PARAM_REBUILDS, .default_value = 0, .min = 2,
                 .max = 64, .zero_doc = "unbounded"),
    UMBRA__PARAM(deep, block_size,
                 .doc = "node layers per block of the unbounded map's pool",
                 .flags = UMBRA_PARAM_REBUILDS, .default_value = 8, .min = 1, .max = 256),
    UMBRA__PARAM(deep, prefilter,
                 .doc = "sub-pixel rays per texel (the paper's pre-filter)",
                 .flags = UMBRA_PARAM_REBUILDS, .default_value = 1, .min = 1, .max = 5,
                 .allowed = prefilter_set, .allowed_count = 2),
    UMBRA__PARAM(deep, lookup_table,
                 .doc = "compress through the pre-compressed segment table",
                 .flags = UMBRA_PARAM_REBUILDS, .default_value = 1, .min = 0, .max = 1),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting). */
static const umbra__setting sweep[] = {
    {"max_nodes=3", "deep", UMBRA__SWEEP_BUILDS}, /* epsilon stays at its default, 0.02 */
    {"map_size=auto;epsilon=0.02;max_nodes=0;prefilter=1", "auto size, ε 0.02",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"map_size=512;epsilon=0.02;max_nodes=0;prefilter=1", "512², ε 0.02",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE_QUICK},
    {"map_size=1024;epsilon=0.02;max_nodes=0;prefilter=1", "1024², ε 0.02",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE},
    {"map_size=2048;epsilon=0.02;max_nodes=0;prefilter=1", "2048², ε 0.02",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=auto;epsilon=0.06;max_nodes=0;prefilter=1;map_texels_per_voxel=0.5;map_step=1",
     "auto size, ε 0.06, step 1, draft",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"map_size=512;epsilon=0.02;max_nodes=3;prefilter=1", "512², ε 0.02, 3 nodes",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_HEADLINE_QUICK},
    {"map_size=1024;epsilon=0.02;max_nodes=3;prefilter=1", "1024², ε 0.02, 3 nodes",
     UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE},
    {"map_size=2048;epsilon=0.02;max_nodes=3;prefilter=1", "2048², ε 0.02, 3 nodes",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=4096;epsilon=0.02;max_nodes=3;prefilter=1", "4096², ε 0.02, 3 nodes",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=1024;epsilon=0.02;max_nodes=2;prefilter=1", "1024², ε 0.02, 2 nodes",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;epsilon=0.02;max_nodes=6;prefilter=1", "1024², ε 0.02, 6 nodes",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;epsilon=0.01;max_nodes=0;prefilter=1", "1024², ε 0.01",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;epsilon=0.06;max_nodes=0;prefilter=1", "1024², ε 0.06",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;epsilon=0.1;max_nodes=0;prefilter=1", "1024², ε 0.1",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;epsilon=0.02;max_nodes=0;prefilter=5", "1024², ε 0.02, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=128;epsilon=0.02;max_nodes=0;prefilter=5", "128², ε 0.02, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=128;epsilon=0.06;max_nodes=0;prefilter=5", "128², ε 0.06, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=256;epsilon=0.02;max_nodes=0;prefilter=5", "256², ε 0.02, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=256;epsilon=0.06;max_nodes=0;prefilter=5", "256², ε 0.06, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=512;epsilon=0.02;max_nodes=0;prefilter=5", "512², ε 0.02, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
    {"map_size=512;epsilon=0.06;max_nodes=0;prefilter=5", "512², ε 0.06, 5-tap prefilter",
     UMBRA__SWEEP_PAPERS_DEEP},
};

static const char *const kernel_files[] = {"techniques/deep_shared.h", "techniques/deep.cl",
                                           NULL};

const umbra__technique umbra__technique_deep = {
    .info = {
        .id = UMBRA_SHADOW_DEEP,
        .name = "deep",
        .title = "deep shadow map (Hadwiger et al. 2006)",
        .doc = "Per texel of a light-space map, the visibility along the light ray as a "
               "piecewise-linear function compressed within epsilon, per light channel: close "
               "to the reference on translucent and coloured material; memory grows with the "
               "function's nodes (or is fixed by a node budget).",
        .flags = UMBRA_TECHNIQUE_MAP | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
        /* A nearest-texel lookup: its error keeps falling with the size; two texels per voxel
         * halve the error of one (walnut: 0.0018 to 0.0010) for under half the rays of three. */
        .map_texels_per_voxel = 2.0f,
        .map_step = 0.5f, /* lightspace.h: its nodes follow the sampled visibility */
        /* While the light moves (interaction auto): half a texel per voxel (a sixteenth of the
         * full map's texels), a step of one voxel and epsilon 0.06 (the deep-shadow paper's
         * "lower resolution and higher error bound during interaction"); the build is then a
         * small part of the frame, whose cost is the lookups (docs/performance-log.md,
         * 2026-12-02). */
        .draft = "map_texels_per_voxel<=0.5;map_step>=1;epsilon>=0.06",
    },
    .params = params,
    .sweep = sweep,
    .sweep_count = sizeof sweep / sizeof sweep[0],
    .kernel_files = kernel_files,
    .light_step = umbra__map_light_step,
    .build = deep_build,
    .bind = deep_bind,
    .memory = deep_memory,
    .destroy = deep_destroy,
};

/* ---- internals for the tests ----------------------------------------------------------------- */

static umbra_status check_deep(umbra_renderer r, const char *fn)
{
    if (!r)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    if (r->tech != &umbra__technique_deep)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: the renderer's technique is '%s', not 'deep'", fn,
                           r->tech->info.name);
    return UMBRA_SUCCESS;
}

umbra_status umbra__deep_get_info(umbra_renderer r, umbra__deep_info *out)
{
    umbra_status st = check_deep(r, "umbra__deep_get_info");
    if (st != UMBRA_SUCCESS)
        return st;
    memset(out, 0, sizeof *out);
    const deep_state *s = r->tech_state;
    if (!s)
        return UMBRA_SUCCESS;
    out->tile = s->tile;
    out->tiles_per_row = s->tiles_per_row;
    out->block_size = s->block_size;
    out->channels = s->channels;
    out->max_nodes = s->fixed_mode ? s->max_nodes : 0;
    out->node_bytes = s->node_bytes;
    out->block_bytes = s->block_bytes;
    out->pool_blocks = s->pool_blocks;
    out->used_blocks = s->used_blocks;
    out->asked_blocks = s->asked_blocks;
    out->map_bytes = map_bytes(s);
    out->layout_bytes = layout_bytes(s);
    out->lut_bytes = lut_bytes(s);
    out->builds = s->builds;
    out->build_passes = s->build_passes;
    out->lut_builds = s->lut_builds;
    out->pool_growths = s->pool_growths;
    return UMBRA_SUCCESS;
}

umbra_status umbra__deep_set_limit(umbra_renderer r, size_t blocks)
{
    umbra_status st = check_deep(r, "umbra__deep_set_limit");
    if (st != UMBRA_SUCCESS)
        return st;
    deep_state *s = state_get(r);
    if (!s)
        return umbra__fail(r->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra__deep_set_limit: out of memory");
    s->limit_override = blocks;
    r->built_valid = 0;
    return UMBRA_SUCCESS;
}

umbra_status umbra__deep_set_pool(umbra_renderer r, size_t blocks, int allow_growth)
{
    umbra_status st = check_deep(r, "umbra__deep_set_pool");
    if (st != UMBRA_SUCCESS)
        return st;
    deep_state *s = state_get(r);
    if (!s)
        return umbra__fail(r->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra__deep_set_pool: out of memory");
    s->pool_override = blocks;
    s->allow_growth = allow_growth;
    r->built_valid = 0;
    return UMBRA_SUCCESS;
}

umbra_status umbra__deep_read(umbra_renderer r, int32_t *head, int32_t *next, uint32_t *counts,
                              float *nodes)
{
    umbra_status st = check_deep(r, "umbra__deep_read");
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_context ctx = r->ctx;
    const deep_state *s = r->tech_state;
    if (!s || s->builds == 0)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra__deep_read: the deep shadow map has not been built");
    cl_command_queue q = ctx->queue;
    if (s->fixed_mode) {
        if (head || next || counts)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "umbra__deep_read: a fixed-budget map has no block layout");
        if (nodes)
            UMBRA_CL(clEnqueueReadBuffer(q, s->fixed, CL_TRUE, 0, s->fixed_bytes, nodes, 0, NULL,
                                         NULL));
        return UMBRA_SUCCESS;
    }
    if (head)
        UMBRA_CL(clEnqueueReadBuffer(q, s->head, CL_TRUE, 0, s->head_count, head, 0, NULL, NULL));
    if (next && s->used_blocks)
        UMBRA_CL(clEnqueueReadBuffer(q, s->next, CL_TRUE, 0, s->used_blocks * sizeof(cl_int), next,
                                     0, NULL, NULL));
    if (counts)
        UMBRA_CL(clEnqueueReadBuffer(q, s->counts, CL_TRUE, 0, s->counts_count, counts, 0, NULL,
                                     NULL));
    if (nodes && s->used_blocks)
        UMBRA_CL(clEnqueueReadBuffer(q, s->pool, CL_TRUE, 0, s->used_blocks * s->block_bytes,
                                     nodes, 0, NULL, NULL));
fail:
    return st;
}
