// SPDX-License-Identifier: Apache-2.0
/* host/volume_update.c: umbra_volume_update, a volume's voxels changed in place (a sub-box, or a
 * whole new time step).
 *
 * The voxels are written where the volume keeps them (its buffer or slabs, its 3D images, each
 * channel's part of a multi-channel buffer), in the stored form they were made in (the value
 * range stays). Then the empty-space-skipping ranges of every brick and sub-cell whose footprint
 * the box touches are computed again, from the stored voxels read back around the box, one layer
 * of bricks at a time, by the same pass and the same mapping as at creation
 * (umbra__block_ranges, umbra__map_ranges), so that they equal what a fresh volume of the same
 * voxels and value range would hold. What renderers keep is keyed on the volume's versions
 * (host/tables.c, host/registry.c): `version` counts updates and rebuilds the light structures;
 * `ranges_version` counts the updates that changed some range and remakes the visibility tables;
 * nothing else (transfer-function tables, resampled transfer functions, programs) depends on the
 * voxels. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "common/umbra_shared.h"

void umbra_volume_update_desc_init(umbra_volume_update_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
}

/* Copies the box [o, o + n) of channel c's stored voxels (x fastest, tightly packed at host)
 * between host and device (write nonzero: to the device), slab by slab: a layer two slabs share
 * goes to (or comes from) both. Blocks. */
static umbra_status box_transfer(umbra_volume v, uint32_t c, const uint32_t o[3],
                                 const uint32_t n[3], void *host, int write)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    const size_t nx = v->dims[0], ny = v->dims[1];
    const size_t per = nx * ny * v->dims[2] + 1; /* a channel and its pad element */
    const int image = umbra__volume_images(v);
    for (uint32_t s = 0; s < v->slab_count; ++s) {
        uint32_t z0, z1;
        umbra__slab_layers(v, s, &z0, &z1);
        const uint32_t za = o[2] > z0 ? o[2] : z0, zl = o[2] + n[2] - 1;
        const uint32_t zb = zl < z1 ? zl : z1;
        if (za > zb)
            continue;
        char *h = (char *)host + (size_t)(za - o[2]) * n[0] * n[1] * esize;
        const size_t depth = (size_t)zb - za + 1;
        if (image) {
            const size_t origin[3] = {o[0], o[1], za - z0}, region[3] = {n[0], n[1], depth};
            if (write)
                UMBRA_CL(clEnqueueWriteImage(ctx->queue, v->slabs[s], CL_TRUE, origin, region,
                                             n[0] * esize, n[0] * n[1] * esize, h, 0, NULL,
                                             NULL));
            else
                UMBRA_CL(clEnqueueReadImage(ctx->queue, v->slabs[s], CL_TRUE, origin, region,
                                            n[0] * esize, n[0] * n[1] * esize, h, 0, NULL, NULL));
        } else {
            const size_t buf[3] = {(c * per + o[0]) * esize, o[1], za - z0};
            const size_t at[3] = {0, 0, 0}, region[3] = {n[0] * esize, n[1], depth};
            if (write)
                UMBRA_CL(clEnqueueWriteBufferRect(ctx->queue, v->slabs[s], CL_TRUE, buf, at,
                                                  region, nx * esize, nx * ny * esize,
                                                  n[0] * esize, n[0] * n[1] * esize, h, 0, NULL,
                                                  NULL));
            else
                UMBRA_CL(clEnqueueReadBufferRect(ctx->queue, v->slabs[s], CL_TRUE, buf, at,
                                                 region, nx * esize, nx * ny * esize,
                                                 n[0] * esize, n[0] * n[1] * esize, h, 0, NULL,
                                                 NULL));
        }
    }
fail:
    return st;
}

/* Checks the update: the box, the data, finite floats, and (for a volume stored as UNORM
 * images, which filter before they could clamp) values inside the range. Fills o and n. */
static umbra_status check_update(umbra_volume v, const umbra_volume_update_desc *d,
                                 uint32_t o[3], uint32_t n[3])
{
    const char *fn = "umbra_volume_update";
    umbra_context ctx = v->ctx;
    if (d->struct_size != sizeof *d)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size %zu != %zu: call umbra_volume_update_desc_init",
                           fn, d->struct_size, sizeof *d);
    if (!d->data)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc->data is NULL", fn);
    const int whole = d->size[0] == 0 && d->size[1] == 0 && d->size[2] == 0;
    for (int a = 0; a < 3; ++a) {
        o[a] = whole ? 0 : d->origin[a];
        n[a] = whole ? v->dims[a] : d->size[a];
    }
    if (whole && (d->origin[0] || d->origin[1] || d->origin[2]))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: size 0 x 0 x 0 updates the whole volume; origin (%u, %u, %u) must "
                           "then be 0", fn, d->origin[0], d->origin[1], d->origin[2]);
    for (int a = 0; a < 3; ++a)
        if (n[a] == 0 || (uint64_t)o[a] + n[a] > v->dims[a])
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: the box at (%u, %u, %u) of %u x %u x %u voxels must have every "
                               "size > 0 and lie inside the volume's %u x %u x %u", fn,
                               d->origin[0], d->origin[1], d->origin[2], d->size[0], d->size[1],
                               d->size[2], v->dims[0], v->dims[1], v->dims[2]);
    const size_t count = (size_t)n[0] * n[1] * n[2] * v->channels;
    /* The type is the volume's input type: what the tables hold raw (float for float32). */
    const umbra_scalar_type type = v->input_type;
    if (type == UMBRA_FLOAT32) {
        const size_t i = umbra__first_nonfinite(d->data, count);
        if (i < count) {
            const size_t voxel = i / v->channels;
            char ch[32] = "";
            if (v->channels > 1)
                snprintf(ch, sizeof ch, ", channel %zu", i % v->channels);
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: voxel %zu of the box (x %zu, y %zu, z %zu of the volume%s) is "
                               "%g; float volumes must be finite", fn, voxel,
                               o[0] + voxel % n[0], o[1] + voxel / n[0] % n[1],
                               o[2] + voxel / ((size_t)n[0] * n[1]), ch,
                               (double)((const float *)d->data)[i]);
        }
    }
    if (umbra__volume_images(v) && v->stored_form != UMBRA__STORED_NORMALISED) {
        const double lo = v->range_d[0][0], hi = v->range_d[0][1];
        for (size_t i = 0; i < count; ++i) {
            double x = type == UMBRA_UINT8    ? ((const uint8_t *)d->data)[i]
                       : type == UMBRA_UINT16 ? ((const uint16_t *)d->data)[i]
                                              : ((const int16_t *)d->data)[i];
            if (x < lo || x > hi)
                return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                                   "%s: voxel %zu of the box is %g, outside the volume's value "
                                   "range [%g, %g]: a volume in UNORM 3D images (the image "
                                   "sampler) cannot clamp it; make the volume with a value range "
                                   "that covers the series", fn, i, x, lo, hi);
        }
    }
    return UMBRA_SUCCESS;
}

/* Writes the box's voxels, channel by channel, in stored form, a bounded number of layers at a
 * time. */
static umbra_status write_box(umbra_volume v, const void *data, const uint32_t o[3],
                              const uint32_t n[3])
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t in_size = umbra_scalar_type_size(v->input_type);
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    const size_t layer = (size_t)n[0] * n[1];
    const int direct = v->channels == 1 && v->stored_form == UMBRA__STORED_RAW;
    uint32_t layers = direct ? n[2] : (uint32_t)(((size_t)1 << 22) / layer);
    layers = layers < 1 ? 1 : (layers > n[2] ? n[2] : layers);
    unsigned char *raw = NULL, *conv = NULL;
    if (!direct) {
        raw = malloc(layer * layers * in_size);
        conv = malloc(layer * layers * esize);
        if (!raw || !conv) {
            st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_volume_update: out of host memory for a staging buffer of "
                             "%zu bytes", layer * layers * (in_size + esize));
            goto fail;
        }
    }
    for (uint32_t c = 0; c < v->channels; ++c)
        for (uint32_t z = 0; z < n[2]; z += layers) {
            const uint32_t nz = n[2] - z < layers ? n[2] - z : layers;
            const uint32_t bo[3] = {o[0], o[1], o[2] + z}, bn[3] = {n[0], n[1], nz};
            const size_t first = (size_t)z * layer, count = (size_t)nz * layer;
            void *src = (char *)(uintptr_t)data + first * in_size;
            if (!direct) {
                umbra__channel_copy(data, in_size, v->channels, c, first, count, raw);
                src = raw;
                if (v->stored_form != UMBRA__STORED_RAW) {
                    umbra__convert_voxels(raw, v->input_type, 0, count, v->stored_form,
                                          v->range_d[c][0],
                                          1.0 / (v->range_d[c][1] - v->range_d[c][0]), conv);
                    src = conv;
                }
            }
            if ((st = box_transfer(v, c, bo, bn, src, 1)) != UMBRA_SUCCESS)
                goto fail;
        }
fail:
    free(raw);
    free(conv);
    return st;
}

/* Recomputes the ranges of the bricks [b0, b1] per axis (those whose sub-cells' footprints the
 * box touches) one layer of bricks at a time; *changed is set if any brick or sub-cell range
 * changed. */
static umbra_status update_ranges(umbra_volume v, const uint32_t b0[3], const uint32_t b1[3],
                                  int *changed)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const uint32_t K = UMBRA_BRICK_CELLS, B = v->brick_size, C = (B + K - 1) / K;
    const size_t per_brick = (size_t)K * K * K;
    const size_t nbricks = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const size_t ncells = nbricks * per_brick;
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    uint32_t bo[3], bn[3], nb[3] = {b1[0] - b0[0] + 1, b1[1] - b0[1] + 1, 1};
    /* The block of voxels holding every footprint of a layer of those bricks. */
    for (int a = 0; a < 3; ++a) {
        const uint32_t lo = b0[a] * B, hi = b1[a] * B + K * C;
        bo[a] = lo;
        bn[a] = (hi < v->dims[a] - 1 ? hi : v->dims[a] - 1) - lo + 1;
    }
    const uint32_t depth_max = K * C + 1 > v->dims[2] ? v->dims[2] : K * C + 1;
    const size_t cells_n = (size_t)nb[0] * nb[1] * per_brick, bricks_n = (size_t)nb[0] * nb[1];
    void *block = malloc((size_t)bn[0] * bn[1] * depth_max * esize);
    float *cells = malloc(2 * cells_n * sizeof *cells), *bricks = malloc(2 * bricks_n * sizeof *bricks);
    if (!block || !cells || !bricks) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "umbra_volume_update: out of host memory for the ranges of %u x %u "
                         "bricks", nb[0], nb[1]);
        goto fail;
    }
    for (uint32_t c = 0; c < v->channels; ++c)
        for (uint32_t bz = b0[2]; bz <= b1[2]; ++bz) {
            const uint32_t lo = bz * B, hi = bz * B + K * C;
            bo[2] = lo;
            bn[2] = (hi < v->dims[2] - 1 ? hi : v->dims[2] - 1) - lo + 1;
            const uint32_t first[3] = {b0[0], b0[1], bz};
            if ((st = box_transfer(v, c, bo, bn, block, 0)) != UMBRA_SUCCESS)
                goto fail;
            if (!umbra__block_ranges(v, block, v->stored_type, bo, bn, first, nb, cells, bricks)) {
                st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                 "umbra_volume_update: out of host memory for the ranges");
                goto fail;
            }
            /* Stored values to the input's (a biased int16 image holds v + 32768), the clamp
             * flags against the range, then the mapping creation made (normalised floats are
             * already what it made of them: the mapping is monotonic). */
            const int normalised = v->stored_form == UMBRA__STORED_NORMALISED;
            const float bias = v->stored_form == UMBRA__STORED_BIASED_U16 ? 32768.0f : 0.0f;
            for (size_t i = 0; i < 2 * cells_n; ++i)
                cells[i] -= bias;
            for (size_t i = 0; i < 2 * bricks_n; ++i)
                bricks[i] -= bias;
            for (size_t b = 0; b < bricks_n; ++b) {
                const size_t gb = ((size_t)bz * v->brick_counts[1] + b0[1] + b / nb[0]) *
                                      v->brick_counts[0] + b0[0] + b % nb[0];
                for (size_t k = 0; k < per_brick; ++k) {
                    const float *mm = cells + 2 * (b * per_brick + k);
                    const size_t gc = ncells * c + gb * per_brick + k;
                    const int clamp = !normalised && !v->labels &&
                                      (mm[0] < v->range_d[c][0] || mm[1] > v->range_d[c][1]);
                    v->clamp_cells += (size_t)clamp - v->cell_clamps[gc];
                    v->cell_clamps[gc] = (unsigned char)clamp;
                }
                float *gcell = v->cell_minmax + 2 * (ncells * c + gb * per_brick);
                float *gbrick = v->brick_minmax + 2 * (nbricks * c + gb);
                float *mc = cells + 2 * b * per_brick, *mb = bricks + 2 * b;
                if (!normalised && !v->labels) {
                    umbra__map_ranges(v, c, mc, 2 * per_brick);
                    umbra__map_ranges(v, c, mb, 2);
                }
                if (memcmp(gcell, mc, 2 * per_brick * sizeof *mc) != 0 ||
                    memcmp(gbrick, mb, 2 * sizeof *mb) != 0)
                    *changed = 1;
                memcpy(gcell, mc, 2 * per_brick * sizeof *mc);
                memcpy(gbrick, mb, 2 * sizeof *mb);
            }
        }
fail:
    free(block);
    free(cells);
    free(bricks);
    return st;
}

/* After a failure the ranges of bricks [b0, b1] may not match the voxels: they are widened to
 * everything (visible under any transfer function that shows anything), so that empty-space
 * skipping stays conservative until the next update of the box. */
static void widen_ranges(umbra_volume v, const uint32_t b0[3], const uint32_t b1[3])
{
    const size_t per_brick = (size_t)UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    const size_t nbricks = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const float lo = 0.0f, hi = v->labels ? (float)(UMBRA_MAX_LABELS - 1) : 1.0f;
    for (uint32_t c = 0; c < v->channels; ++c)
        for (uint32_t z = b0[2]; z <= b1[2]; ++z)
            for (uint32_t y = b0[1]; y <= b1[1]; ++y)
                for (uint32_t x = b0[0]; x <= b1[0]; ++x) {
                    const size_t b = ((size_t)z * v->brick_counts[1] + y) * v->brick_counts[0] + x;
                    float *br = v->brick_minmax + 2 * (nbricks * c + b);
                    float *ce = v->cell_minmax + 2 * (nbricks * per_brick * c + b * per_brick);
                    br[0] = lo;
                    br[1] = hi;
                    for (size_t k = 0; k < per_brick; ++k) {
                        ce[2 * k] = lo;
                        ce[2 * k + 1] = hi;
                    }
                }
}

umbra_status umbra_volume_update(umbra_volume v, const umbra_volume_update_desc *desc)
{
    const char *fn = "umbra_volume_update";
    if (!v)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    umbra_context ctx = v->ctx;
    if (!desc)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc is NULL", fn);
    uint32_t o[3], n[3];
    umbra_status st = umbra__check_process(ctx, fn);
    if (st == UMBRA_SUCCESS)
        st = check_update(v, desc, o, n);
    if (st != UMBRA_SUCCESS)
        return st; /* nothing written */
    /* The bricks whose sub-cells' footprints hold a voxel of the box: brick b's reach voxels
     * [b B, b B + UMBRA_BRICK_CELLS C] (host/volume_ranges.c), clamped to the grid. */
    uint32_t b0[3], b1[3];
    const uint32_t B = v->brick_size;
    const uint32_t reach = UMBRA_BRICK_CELLS * ((B + UMBRA_BRICK_CELLS - 1) / UMBRA_BRICK_CELLS);
    for (int a = 0; a < 3; ++a) {
        b0[a] = o[a] > reach ? (o[a] - reach + B - 1) / B : 0;
        b1[a] = (o[a] + n[a] - 1) / B;
        b1[a] = b1[a] < v->brick_counts[a] - 1 ? b1[a] : v->brick_counts[a] - 1;
    }
    /* From here on the voxels may have changed: every renderer sees a new version. */
    v->version++;
    int changed = 0;
    st = write_box(v, desc->data, o, n);
    if (st == UMBRA_SUCCESS)
        st = update_ranges(v, b0, b1, &changed);
    if (st != UMBRA_SUCCESS)
        widen_ranges(v, b0, b1);
    if (changed || st != UMBRA_SUCCESS)
        v->ranges_version++;
    /* Normalising each voxel before it blends is right whatever the voxels (after a failure
     * their flags are not known). */
    v->clamps = v->stored_form != UMBRA__STORED_NORMALISED && !v->labels &&
                (v->clamp_cells > 0 || st != UMBRA_SUCCESS);
    return st;
}
