// SPDX-License-Identifier: Apache-2.0
/* host/volume.c: uploading a scalar volume and its empty-space-skipping brick table.
 *
 * Voxels are normalised to [0,1] through the value range and stored as float32, in a buffer (for
 * the buffer sampler) or a CL_R/CL_FLOAT 3D image (image sampler). Each brick keeps the min and
 * max normalised value over the voxels its trilinear footprint reads (its own and the next layer),
 * so a brick whose whole range maps to zero opacity can be skipped without changing a pixel. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "umbra_shared.h"

size_t umbra_scalar_type_size(umbra_scalar_type type)
{
    switch (type) {
    case UMBRA_UINT8: return 1;
    case UMBRA_UINT16: return 2;
    case UMBRA_INT16: return 2;
    case UMBRA_FLOAT32: return 4;
    }
    return 0;
}

void umbra_volume_desc_init(umbra_volume_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
    desc->type = UMBRA_UINT8;
    desc->spacing[0] = desc->spacing[1] = desc->spacing[2] = 1.0f;
    desc->brick_size = 16;
}

static float voxel_at(const void *data, umbra_scalar_type type, size_t i)
{
    switch (type) {
    case UMBRA_UINT8: return (float)((const uint8_t *)data)[i];
    case UMBRA_UINT16: return (float)((const uint16_t *)data)[i];
    case UMBRA_INT16: return (float)((const int16_t *)data)[i];
    case UMBRA_FLOAT32: return ((const float *)data)[i];
    }
    return 0.0f;
}

static umbra_status validate(umbra_context ctx, const umbra_volume_desc *d)
{
    const char *fn = "umbra_volume_create";
    if (d->struct_size != sizeof *d)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size %zu != %zu: call umbra_volume_desc_init", fn,
                           d->struct_size, sizeof *d);
    if (!d->data)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc->data is NULL", fn);
    if (umbra_scalar_type_size(d->type) == 0)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: scalar type %d is unknown", fn,
                           (int)d->type);
    if (d->dims[0] == 0 || d->dims[1] == 0 || d->dims[2] == 0)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: dims %u x %u x %u: every size must be > 0", fn, d->dims[0],
                           d->dims[1], d->dims[2]);
    /* A bound on what a caller can make large: 2^36 float voxels are 256 GiB, more than any
     * device holds (the device's own memory is checked when the voxels are uploaded). */
    if ((uint64_t)d->dims[0] * d->dims[1] * d->dims[2] > ((uint64_t)1 << 36))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: dims %u x %u x %u: more than 2^36 voxels", fn, d->dims[0],
                           d->dims[1], d->dims[2]);
    for (int a = 0; a < 3; ++a)
        if (!(d->spacing[a] > 0.0f) || !isfinite(d->spacing[a]))
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: spacing %g x %g x %g: every spacing must be finite and > 0", fn,
                               d->spacing[0], d->spacing[1], d->spacing[2]);
    for (int a = 0; a < 3; ++a) {
        double extent = (double)d->dims[a] * d->spacing[a];
        if (!(extent <= UMBRA_MAX_EXTENT))
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: extent %g along axis %d (%u voxels x spacing %g) exceeds the "
                               "limit %g world units (UMBRA_MAX_EXTENT)", fn, extent, a,
                               d->dims[a], d->spacing[a], (double)UMBRA_MAX_EXTENT);
    }
    if (d->value_range_given &&
        (!isfinite(d->value_min) || !isfinite(d->value_max) || !(d->value_max > d->value_min)))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: value range [%g, %g] must be finite with max > min", fn,
                           d->value_min, d->value_max);
    if (d->brick_size < 2 || d->brick_size > 256)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: brick_size %u must lie in [2, 256]", fn, d->brick_size);
    return UMBRA_SUCCESS;
}

/* Min/max over each brick's footprint: voxels [b*B, (b+1)*B] per axis, clamped to the grid. */
static void compute_bricks(umbra_volume v, const float *vox)
{
    const uint32_t B = v->brick_size;
    const uint32_t *n = v->dims, *nb = v->brick_counts;
    for (uint32_t bz = 0; bz < nb[2]; ++bz)
        for (uint32_t by = 0; by < nb[1]; ++by)
            for (uint32_t bx = 0; bx < nb[0]; ++bx) {
                float lo = FLT_MAX, hi = -FLT_MAX;
                uint32_t z1 = bz * B + B < n[2] - 1 ? bz * B + B : n[2] - 1;
                uint32_t y1 = by * B + B < n[1] - 1 ? by * B + B : n[1] - 1;
                uint32_t x1 = bx * B + B < n[0] - 1 ? bx * B + B : n[0] - 1;
                for (uint32_t z = bz * B; z <= z1; ++z)
                    for (uint32_t y = by * B; y <= y1; ++y) {
                        const float *row = vox + ((size_t)z * n[1] + y) * n[0];
                        for (uint32_t x = bx * B; x <= x1; ++x) {
                            lo = row[x] < lo ? row[x] : lo;
                            hi = row[x] > hi ? row[x] : hi;
                        }
                    }
                size_t i = ((size_t)bz * nb[1] + by) * nb[0] + bx;
                v->brick_minmax[2 * i] = lo;
                v->brick_minmax[2 * i + 1] = hi;
            }
}

/* Min/max over each brick's sub-cells: cell j of brick b along an axis covers the sample
 * positions [b*B + j*C, b*B + (j+1)*C) with C = ceil(B / UMBRA_BRICK_CELLS), whose trilinear footprint
 * is voxels [b*B + j*C, b*B + (j+1)*C], clamped to the grid (a cell that starts beyond the last
 * voxel takes the last voxel: the clamped sampler repeats it there). */
static void compute_cells(umbra_volume v, const float *vox)
{
    const uint32_t B = v->brick_size, C = (B + UMBRA_BRICK_CELLS - 1) / UMBRA_BRICK_CELLS;
    const uint32_t *n = v->dims, *nb = v->brick_counts;
    size_t i = 0;
    for (uint32_t bz = 0; bz < nb[2]; ++bz)
        for (uint32_t by = 0; by < nb[1]; ++by)
            for (uint32_t bx = 0; bx < nb[0]; ++bx)
                for (uint32_t c = 0; c < UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS; ++c, ++i) {
                    const uint32_t cell[3] = {c % UMBRA_BRICK_CELLS, (c / UMBRA_BRICK_CELLS) % UMBRA_BRICK_CELLS,
                                              c / (UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS)};
                    const uint32_t brick[3] = {bx, by, bz};
                    uint32_t lo3[3], hi3[3];
                    for (int a = 0; a < 3; ++a) {
                        uint32_t s0 = brick[a] * B + cell[a] * C, s1 = s0 + C;
                        lo3[a] = s0 < n[a] - 1 ? s0 : n[a] - 1;
                        hi3[a] = s1 < n[a] - 1 ? s1 : n[a] - 1;
                    }
                    float lo = FLT_MAX, hi = -FLT_MAX;
                    for (uint32_t z = lo3[2]; z <= hi3[2]; ++z)
                        for (uint32_t y = lo3[1]; y <= hi3[1]; ++y) {
                            const float *row = vox + ((size_t)z * n[1] + y) * n[0];
                            for (uint32_t x = lo3[0]; x <= hi3[0]; ++x) {
                                lo = row[x] < lo ? row[x] : lo;
                                hi = row[x] > hi ? row[x] : hi;
                            }
                        }
                    v->cell_minmax[2 * i] = lo;
                    v->cell_minmax[2 * i + 1] = hi;
                }
}

umbra_status umbra_volume_create(umbra_context ctx, const umbra_volume_desc *desc,
                                 umbra_volume *out)
{
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_volume_create: out is NULL");
    *out = NULL;
    if (!ctx || !desc)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_volume_create: ctx %p, desc %p: neither may be NULL",
                           (void *)ctx, (void *)desc);
    umbra_status st = validate(ctx, desc);
    if (st != UMBRA_SUCCESS)
        return st;

    float *vox = NULL;
    umbra_volume v = calloc(1, sizeof *v);
    const size_t count = (size_t)desc->dims[0] * desc->dims[1] * desc->dims[2];
    if (!v)
        goto oom;
    atomic_init(&v->refs, 1);
    v->ctx = ctx;
    umbra_context_retain(ctx);
    memcpy(v->dims, desc->dims, sizeof v->dims);
    memcpy(v->spacing, desc->spacing, sizeof v->spacing);
    if ((st = umbra__volume_set_transform(ctx, desc, v)) != UMBRA_SUCCESS)
        goto fail;
    v->brick_size = desc->brick_size;
    for (int a = 0; a < 3; ++a)
        v->brick_counts[a] = (v->dims[a] + v->brick_size - 1) / v->brick_size;
    v->id = umbra__next_id(ctx);

    /* The range and the mapping in double: max - min of finite floats can overflow a float
     * (+-3e38), and lo + 1 rounds back to lo for |lo| > 2^24. Float data is scanned for NaN and
     * infinity even with a given range: the mapping would clamp infinity to an end of the table
     * and NaN to 0, a picture of values that are not there. Integer types are always finite. */
    double lo = desc->value_min, hi = desc->value_max;
    if (!desc->value_range_given || desc->type == UMBRA_FLOAT32) {
        double dlo = INFINITY, dhi = -INFINITY;
        for (size_t i = 0; i < count; ++i) {
            float x = voxel_at(desc->data, desc->type, i);
            if (!isfinite(x)) {
                const size_t nx = desc->dims[0], ny = desc->dims[1];
                st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "umbra_volume_create: voxel %zu is %g (x %zu, y %zu, z %zu); "
                                 "float volumes must be finite",
                                 i, x, i % nx, i / nx % ny, i / (nx * ny));
                goto fail;
            }
            dlo = x < dlo ? x : dlo;
            dhi = x > dhi ? x : dhi;
        }
        if (!desc->value_range_given) {
            lo = dlo;
            hi = dhi;
        }
    }
    if (!desc->value_range_given) {
        /* A constant volume maps to 0 (at FLT_MAX, to 1): any range around its value will do;
         * the gap is wide enough to survive the rounding of the reported float range. */
        if (!(hi > lo)) {
            double gap = fmax(1.0, fabs(lo) * 0x1p-20);
            if (lo + gap <= FLT_MAX)
                hi = lo + gap;
            else
                lo -= gap;
        }
    }
    v->value_min = (float)lo;
    v->value_max = (float)hi;

    /* Refused before the host copy is made when it cannot fit the device (the upload plans
     * again: the query is cheap). */
    {
        umbra__device_limits lim;
        uint32_t nslabs, step;
        uint64_t bytes;
        if ((st = umbra__device_limits_get(ctx, ctx->sampler == UMBRA_SAMPLER_IMAGE, &lim)) !=
                UMBRA_SUCCESS ||
            (st = umbra__slabs_plan(ctx, v->dims, sizeof *vox, ctx->sampler == UMBRA_SAMPLER_IMAGE,
                                    &lim, &nslabs, &step, &bytes)) != UMBRA_SUCCESS)
            goto fail;
    }
    vox = malloc(count * sizeof *vox);
    size_t nbricks = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    v->brick_minmax = malloc(2 * nbricks * sizeof *v->brick_minmax);
    v->cell_minmax = malloc(2 * nbricks * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS *
                            sizeof *v->cell_minmax);
    if (!vox || !v->brick_minmax || !v->cell_minmax)
        goto oom;
    const double scale = 1.0 / (hi - lo);
    for (size_t i = 0; i < count; ++i) {
        double x = ((double)voxel_at(desc->data, desc->type, i) - lo) * scale;
        vox[i] = x < 0.0 ? 0.0f : (x > 1.0 ? 1.0f : (x == x ? (float)x : 0.0f));
    }
    compute_bricks(v, vox);
    compute_cells(v, vox);

    const cl_image_format fmt = {CL_R, CL_FLOAT};
    if ((st = umbra__slabs_upload(ctx, v, vox, sizeof *vox,
                                  ctx->sampler == UMBRA_SAMPLER_IMAGE ? &fmt : NULL)) !=
        UMBRA_SUCCESS)
        goto fail;
    free(vox);
    *out = v;
    return UMBRA_SUCCESS;
oom:
    st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                     "umbra_volume_create: out of host memory for %u x %u x %u voxels",
                     desc->dims[0], desc->dims[1], desc->dims[2]);
fail:
    free(vox);
    umbra_volume_release(v);
    return st;
}

umbra_status umbra_volume_get_info(umbra_volume v, umbra_volume_info *out)
{
    if (!v || !out)
        return umbra__fail(v ? v->ctx : NULL, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_volume_get_info: volume %p, out %p: neither may be NULL",
                           (void *)v, (void *)out);
    for (int a = 0; a < 3; ++a) {
        out->dims[a] = v->dims[a];
        out->spacing[a] = v->spacing[a];
        out->extent[a] = (float)v->dims[a] * v->spacing[a];
        out->brick_counts[a] = v->brick_counts[a];
    }
    out->value_min = v->value_min;
    out->value_max = v->value_max;
    out->brick_size = v->brick_size;
    out->device_bytes = v->device_bytes;
    out->transform_given = v->transformed;
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    double centre[3];
    umbra__volume_point_to_world(v, zero, centre);
    for (int a = 0; a < 3; ++a) {
        out->origin[a] = (float)v->origin[a];
        out->center[a] = (float)centre[a];
        for (int k = 0; k < 3; ++k)
            out->directions[3 * a + k] = (float)v->axes[3 * a + k];
    }
    return UMBRA_SUCCESS;
}

void umbra_volume_retain(umbra_volume v)
{
    if (v)
        atomic_fetch_add(&v->refs, 1);
}

void umbra_volume_release(umbra_volume v)
{
    if (!v || atomic_fetch_sub(&v->refs, 1) > 1)
        return;
    for (int s = 0; s < UMBRA__MAX_SLABS; ++s)
        if (v->slabs[s])
            clReleaseMemObject(v->slabs[s]);
    free(v->brick_minmax);
    free(v->cell_minmax);
    umbra_context_release(v->ctx);
    free(v);
}
