// SPDX-License-Identifier: Apache-2.0
/* host/volume.c: uploading a scalar volume and its empty-space-skipping brick table.
 *
 * Voxels stay in their own type on the device (1, 2 or 4 bytes each), in a buffer (buffer
 * sampler) or a CL_R 3D image (image sampler), and the kernels map them to [0,1] through the
 * value range as they read them (kernels/common/sampling.cl); the few cases that cannot be stored
 * as
 * given (see volume_create) are normalised to float32 on the way, a few MiB at a time. Each brick
 * and each of its sub-cells keeps the min and max normalised value over the voxels its trilinear
 * footprint reads (its own and the next layer), so a brick or cell whose whole range maps to zero
 * opacity can be skipped without changing a pixel. Those ranges and the data's are found in one
 * parallel pass over the caller's voxels, with no converted copy of the volume. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "common/umbra_shared.h"

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
    desc->channels = 1;
}

/* Checks desc and copies it into *d, a layout from before channels taking their defaults. */
static umbra_status validate(umbra_context ctx, const umbra_volume_desc *desc,
                             umbra_volume_desc *d)
{
    const char *fn = "umbra_volume_create";
    const size_t size_0_5 = offsetof(umbra_volume_desc, channels);
    if (desc->struct_size != sizeof *d && desc->struct_size != size_0_5)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size %zu is neither %zu nor umbra 0.5's %zu: call "
                           "umbra_volume_desc_init", fn, desc->struct_size, sizeof *d, size_0_5);
    umbra_volume_desc_init(d);
    memcpy(d, desc, desc->struct_size);
    d->struct_size = sizeof *d;
    if (d->channels < 1 || d->channels > UMBRA_MAX_CHANNELS)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: channels %u must lie in [1, %d] (UMBRA_MAX_CHANNELS)", fn,
                           d->channels, UMBRA_MAX_CHANNELS);
    if (d->labels && (d->channels != 1 || (d->type != UMBRA_UINT8 && d->type != UMBRA_UINT16)))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: a label map has one channel of uint8 or uint16 labels (labels "
                           "below UMBRA_MAX_LABELS, %u), not %u channel%s of scalar type %d",
                           fn, UMBRA_MAX_LABELS, d->channels, d->channels == 1 ? "" : "s",
                           (int)d->type);
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
     * device holds (the device's own memory is checked before anything is uploaded). */
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

/* ---- the conversion for what cannot be stored as given ------------------------------------ */

void umbra__convert_voxels(const void *src, umbra_scalar_type type, size_t first, size_t n,
                           int form, double lo, double scale, void *dst)
{
    if (form == UMBRA__STORED_BIASED_U16) {
        const int16_t *s = (const int16_t *)src + first;
        uint16_t *d = dst;
        for (size_t i = 0; i < n; ++i)
            d[i] = (uint16_t)((int32_t)s[i] + 32768);
        return;
    }
    float *d = dst;
    for (size_t i = 0; i < n; ++i) {
        size_t k = first + i;
        double v = type == UMBRA_UINT8    ? ((const uint8_t *)src)[k]
                   : type == UMBRA_UINT16 ? ((const uint16_t *)src)[k]
                   : type == UMBRA_INT16  ? ((const int16_t *)src)[k]
                                          : ((const float *)src)[k];
        double x = (v - lo) * scale;
        d[i] = x < 0.0 ? 0.0f : (x > 1.0 ? 1.0f : (float)x);
    }
}

/* Creates v's slabs (one buffer or image unless the volume exceeds the device's largest,
 * host/volume_slabs.c) from data (one channel of type): straight from it where the device
 * stores the input as it is, else through a bounded staging buffer (a few MiB), never a
 * converted copy of the whole volume. Blocks until the data is on the device. */
static umbra_status upload(umbra_volume v, const void *data, umbra_scalar_type type,
                           cl_mem filled, int form, double lo, double scale)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t nx = v->dims[0], ny = v->dims[1];
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    void *stage = NULL;
    if (filled && form == UMBRA__STORED_RAW) {
        /* data is filled's mapping: the buffer already holds the voxels as stored (and
         * umbra_volume_create_filled maps one only for a volume that fits one buffer). */
        clRetainMemObject(filled);
        v->slabs[0] = filled;
        v->slab_count = 1;
        v->slab_step = v->dims[2];
        /* The buffer has one pad element (host/volume_slabs.c). */
        v->device_bytes = ((size_t)v->dims[0] * v->dims[1] * v->dims[2] + 1) * esize;
        return UMBRA_SUCCESS;
    }
    const cl_image_format fmt = {CL_R, v->stored_type == UMBRA_UINT8    ? CL_UNORM_INT8
                                       : v->stored_type == UMBRA_UINT16 ? CL_UNORM_INT16
                                                                        : CL_FLOAT};
    const int image = umbra__volume_images(v);
    st = umbra__slabs_create(ctx, v, esize, image ? &fmt : NULL,
                             form == UMBRA__STORED_RAW ? data : NULL);
    if (st != UMBRA_SUCCESS || form == UMBRA__STORED_RAW)
        return st;
    /* Whole rows of one slice per write (an image region is a box). */
    const size_t rows = nx >= ((size_t)1 << 20) ? 1 : ((size_t)1 << 20) / nx;
    stage = malloc((rows < ny ? rows : ny) * nx * esize);
    if (!stage) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "umbra_volume_create: out of host memory for a staging buffer of %zu "
                         "bytes", (rows < ny ? rows : ny) * nx * esize);
        goto fail;
    }
    /* Slab by slab: the layer two slabs share is converted for each. */
    for (uint32_t s = 0; s < v->slab_count; ++s) {
        uint32_t z0, z1;
        umbra__slab_layers(v, s, &z0, &z1);
        for (size_t z = z0; z <= z1; ++z)
            for (size_t y = 0; y < ny; y += rows) {
                size_t r = ny - y < rows ? ny - y : rows, first = (z * ny + y) * nx;
                umbra__convert_voxels(data, type, first, r * nx, form, lo, scale, stage);
                if (image) {
                    size_t origin[3] = {0, y, z - z0}, region[3] = {nx, r, 1};
                    UMBRA_CL(clEnqueueWriteImage(ctx->queue, v->slabs[s], CL_TRUE, origin, region,
                                                 0, 0, stage, 0, NULL, NULL));
                } else {
                    UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, v->slabs[s], CL_TRUE,
                                                  ((z - z0) * ny + y) * nx * esize, r * nx * esize,
                                                  stage, 0, NULL, NULL));
                }
            }
    }
fail:
    free(stage);
    return st;
}

void umbra__channel_copy(const void *src, size_t esize, uint32_t channels, uint32_t c,
                         size_t first, size_t n, void *dst)
{
    const unsigned char *s = (const unsigned char *)src + (first * channels + c) * esize;
    unsigned char *d = dst;
    const size_t stride = channels * esize;
    if (channels == 1) {
        memcpy(d, s, n * esize);
        return;
    }
    for (size_t i = 0; i < n; ++i)
        memcpy(d + i * esize, s + i * stride, esize);
}

/* A multi-channel volume's one buffer (slabs[0]): each channel's voxels after the previous
 * channel's, each followed by its pad element, converted from the interleaved data through a
 * bounded staging buffer. Blocks until the data is on the device. */
static umbra_status upload_channels(umbra_volume v, const void *data, umbra_scalar_type type,
                                    int form, const double *lo, const double *scale)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t count = (size_t)v->dims[0] * v->dims[1] * v->dims[2], per = count + 1;
    const size_t in_size = umbra_scalar_type_size(type);
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    const size_t chunk = count < ((size_t)1 << 20) ? count : ((size_t)1 << 20);
    unsigned char *raw = malloc(chunk * in_size), *conv = NULL;
    if (raw && form != UMBRA__STORED_RAW)
        conv = malloc(chunk * esize);
    if (!raw || (form != UMBRA__STORED_RAW && !conv)) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "umbra_volume_create: out of host memory for a staging buffer of %zu "
                         "bytes", chunk * (in_size + esize));
        goto fail;
    }
    cl_int err;
    v->slabs[0] = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY, v->channels * per * esize, NULL,
                                 &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(volume channels)");
    v->slab_count = 1;
    v->slab_step = v->dims[2];
    v->device_bytes = v->channels * per * esize;
    for (uint32_t c = 0; c < v->channels; ++c) {
        for (size_t first = 0; first < count; first += chunk) {
            const size_t n = count - first < chunk ? count - first : chunk;
            umbra__channel_copy(data, in_size, v->channels, c, first, n, raw);
            const void *src = raw;
            if (form != UMBRA__STORED_RAW) {
                umbra__convert_voxels(raw, type, 0, n, form, lo[c], scale[c], conv);
                src = conv;
            }
            UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, v->slabs[0], CL_TRUE,
                                          (c * per + first) * esize, n * esize, src, 0, NULL,
                                          NULL));
        }
        const float zero = 0.0f; /* the pad element, as host/volume_slabs.c writes it */
        UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, v->slabs[0], CL_TRUE, (c * per + count) * esize,
                                      esize, &zero, 0, NULL, NULL));
    }
fail:
    free(raw);
    free(conv);
    return st;
}

int umbra__volume_images(umbra_volume v)
{
    return v->ctx->sampler == UMBRA_SAMPLER_IMAGE && v->channels == 1 && !v->labels;
}

/* A volume that cannot fit the device is refused before the pass over its voxels. The device
 * stores at least the input type's bytes per voxel (or float32 in its place); the upload plans
 * again with the stored type. A multi-channel volume or a label map is one buffer. */
static umbra_status check_fits(umbra_context ctx, const umbra_volume_desc *desc)
{
    umbra__device_limits lim;
    uint32_t nslabs, step;
    uint64_t bytes;
    const size_t esize = umbra_scalar_type_size(desc->type);
    const int plain = desc->channels == 1 && !desc->labels;
    const int image = plain && ctx->sampler == UMBRA_SAMPLER_IMAGE;
    umbra_status st = umbra__device_limits_get(ctx, image, &lim);
    if (st != UMBRA_SUCCESS)
        return st;
    if (plain)
        return umbra__slabs_plan(ctx, desc->dims, esize, image, &lim, &nslabs, &step, &bytes);
    bytes = (uint64_t)desc->channels *
            ((uint64_t)desc->dims[0] * desc->dims[1] * desc->dims[2] + 1) * esize;
    if (bytes > lim.max_alloc || bytes > lim.global_mem)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_volume_create: %s of %u x %u x %u voxels need one buffer of "
                           "%llu bytes; the device's largest allocation is %llu bytes (a "
                           "multi-channel volume or a label map is not split into slabs)",
                           desc->labels ? "a label map" : "the channels", desc->dims[0],
                           desc->dims[1], desc->dims[2], (unsigned long long)bytes,
                           (unsigned long long)lim.max_alloc);
    return UMBRA_SUCCESS;
}

/* filled: NULL, or a buffer sampler's buffer (of desc->type) whose mapping desc->data is. */
static umbra_status volume_create(umbra_context ctx, const umbra_volume_desc *given,
                                  cl_mem filled, umbra_volume *out)
{
    umbra_volume_desc copy;
    const umbra_volume_desc *desc = &copy;
    umbra_status st = validate(ctx, given, &copy);
    if (st == UMBRA_SUCCESS)
        st = check_fits(ctx, desc);
    if (st != UMBRA_SUCCESS)
        return st;
    void *stage = NULL;
    umbra_volume v = calloc(1, sizeof *v);
    const size_t count = (size_t)desc->dims[0] * desc->dims[1] * desc->dims[2];
    const uint32_t channels = desc->channels;
    if (!v)
        goto oom;
    atomic_init(&v->refs, 1);
    v->ctx = ctx;
    umbra_context_retain(ctx);
    memcpy(v->dims, desc->dims, sizeof v->dims);
    memcpy(v->grid_dims, desc->dims, sizeof v->grid_dims);
    memcpy(v->spacing, desc->spacing, sizeof v->spacing);
    v->channels = channels;
    v->labels = desc->labels != 0;
    v->input_type = desc->type;
    if ((st = umbra__volume_set_transform(ctx, desc, v)) != UMBRA_SUCCESS)
        goto fail;
    v->brick_size = desc->brick_size;
    for (int a = 0; a < 3; ++a)
        v->brick_counts[a] = (v->dims[a] + v->brick_size - 1) / v->brick_size;
    v->id = umbra__next_id(ctx);

    const size_t nbricks = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const size_t ncells = nbricks * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    const size_t in_size = umbra_scalar_type_size(desc->type);
    v->brick_minmax = malloc(2 * nbricks * channels * sizeof *v->brick_minmax);
    v->cell_minmax = malloc(2 * ncells * channels * sizeof *v->cell_minmax);
    v->cell_clamps = calloc(ncells * channels, 1);
    if (channels > 1)
        stage = malloc(count * in_size);
    if (!v->brick_minmax || !v->cell_minmax || !v->cell_clamps || (channels > 1 && !stage))
        goto oom;

    /* Per channel: raw min and max per sub-cell and per brick (umbra__block_ranges), in one
     * parallel pass over the caller's voxels (a channel of several deinterleaved first). Float
     * data is scanned for NaN and infinity even with a given range: the mapping would clamp
     * infinity to an end of the table and NaN to 0, a picture of values that are not there.
     * Integer types are always finite. */
    double dlo[UMBRA_MAX_CHANNELS], dhi[UMBRA_MAX_CHANNELS];
    const uint32_t zero[3] = {0, 0, 0};
    for (uint32_t c = 0; c < channels; ++c) {
        const void *data = desc->data;
        if (channels > 1) {
            umbra__channel_copy(desc->data, in_size, channels, c, 0, count, stage);
            data = stage;
        }
        if (desc->type == UMBRA_FLOAT32) {
            const size_t i = umbra__first_nonfinite(data, count);
            if (i < count) {
                const size_t nx = desc->dims[0], ny = desc->dims[1];
                char ch[32] = "";
                if (channels > 1)
                    snprintf(ch, sizeof ch, ", channel %u", c);
                st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "umbra_volume_create: voxel %zu is %g (x %zu, y %zu, z %zu%s); "
                                 "float volumes must be finite",
                                 i, (double)((const float *)data)[i], i % nx, i / nx % ny,
                                 i / (nx * ny), ch);
                goto fail;
            }
        }
        float *cells = v->cell_minmax + 2 * ncells * c, *bricks = v->brick_minmax + 2 * nbricks * c;
        if (!umbra__block_ranges(v, data, desc->type, zero, v->dims, zero, v->brick_counts, cells,
                                 bricks))
            goto oom;
        /* The bricks cover every voxel: their extremes are the data's. */
        dlo[c] = INFINITY;
        dhi[c] = -INFINITY;
        for (size_t b = 0; b < nbricks; ++b) {
            dlo[c] = bricks[2 * b] < dlo[c] ? bricks[2 * b] : dlo[c];
            dhi[c] = bricks[2 * b + 1] > dhi[c] ? bricks[2 * b + 1] : dhi[c];
        }
    }
    free(stage);
    stage = NULL;

    /* Each channel's range and mapping, in double: max - min of finite floats can overflow a
     * float (+-3e38), and lo + 1 rounds back to lo for |lo| > 2^24. A sub-cell whose footprint
     * holds a value outside a given range is flagged (cell_clamps: the kernels then normalise
     * each voxel before they blend). */
    double lo[UMBRA_MAX_CHANNELS], scale[UMBRA_MAX_CHANNELS];
    int float_ok = 1;
    for (uint32_t c = 0; c < channels; ++c) {
        double l = desc->value_min, h = desc->value_max;
        if (!desc->value_range_given || v->labels) {
            l = dlo[c];
            h = dhi[c];
            /* A constant volume maps to 0 (at FLT_MAX, to 1): any range around its value will
             * do; the gap is wide enough to survive the rounding of the reported float range. */
            if (!(h > l)) {
                double gap = fmax(1.0, fabs(l) * 0x1p-20);
                if (l + gap <= FLT_MAX)
                    h = l + gap;
                else
                    l -= gap;
            }
        }
        lo[c] = l;
        scale[c] = 1.0 / (h - l);
        v->range_d[c][0] = l;
        v->range_d[c][1] = h;
        v->channel_range[c][0] = (float)l;
        v->channel_range[c][1] = (float)h;
        float_ok = float_ok && h - l >= 1e-30 && h - l <= 1e30 && fabs(l) <= 1e30;
        const float *cells = v->cell_minmax + 2 * ncells * c;
        if (desc->value_range_given && !v->labels)
            for (size_t k = 0; k < ncells; ++k)
                if (cells[2 * k] < l || cells[2 * k + 1] > h) {
                    v->cell_clamps[ncells * c + k] = 1;
                    ++v->clamp_cells;
                }
    }
    const int clamps = v->clamp_cells > 0;
    v->value_min = v->channel_range[0][0];
    v->value_max = v->channel_range[0][1];

    /* How the device stores the voxels. The kernels normalise the buffer's raw values per voxel
     * in float, (s - lo) * scale: safe for integers and for floats whose range is neither huge
     * nor tiny (+-3e38 is not); otherwise normalised floats, as before. An image's filter blends
     * before it normalises, which differs from blending normalised values where a given range
     * clamps the data, and CL_SNORM_INT16 would merge -32768 with -32767: images of integers
     * are stored as UNORM (int16 biased) only where neither happens and the device has the
     * format. A label map keeps its labels as they are. */
    int form = UMBRA__STORED_RAW;
    v->stored_type = desc->type;
    double s_lo = lo[0], s_scale = 1.0;
    if (v->labels) {
        form = UMBRA__STORED_RAW;
    } else if (umbra__volume_images(v)) {
        if (desc->type == UMBRA_UINT8 && ctx->has_unorm8_r_image3d && !clamps)
            s_scale = 255.0;
        else if (desc->type == UMBRA_UINT16 && ctx->has_unorm16_r_image3d && !clamps)
            s_scale = 65535.0;
        else if (desc->type == UMBRA_INT16 && ctx->has_unorm16_r_image3d && !clamps) {
            form = UMBRA__STORED_BIASED_U16;
            v->stored_type = UMBRA_UINT16;
            s_scale = 65535.0;
            s_lo = lo[0] + 32768.0;
        } else
            form = UMBRA__STORED_NORMALISED;
    } else if (desc->type == UMBRA_FLOAT32 && !float_ok)
        form = UMBRA__STORED_NORMALISED;
    v->stored_form = form;
    v->clamps = form != UMBRA__STORED_NORMALISED && !v->labels && clamps;
    if (form == UMBRA__STORED_NORMALISED)
        v->stored_type = UMBRA_FLOAT32;
    for (uint32_t c = 0; c < channels; ++c) {
        float *m = v->channel_map[c];
        if (form == UMBRA__STORED_NORMALISED || v->labels) {
            m[0] = 0.0f;
            m[1] = 1.0f;
            m[2] = 1.0f;
        } else {
            m[0] = (float)(c == 0 ? s_lo : lo[c]);
            m[1] = (float)scale[c];
            m[2] = (float)(c == 0 ? s_scale : 1.0);
        }
    }
    memcpy(v->value_map, v->channel_map[0], sizeof v->value_map);

    /* The tables in normalised values, mapped as the kernels map a voxel (the mapping is
     * monotonic, so the extremes map to the extremes); a label map's hold labels. */
    for (uint32_t c = 0; c < channels && !v->labels; ++c)
        umbra__map_ranges(v, c, v->cell_minmax + 2 * ncells * c, 2 * ncells);
    for (uint32_t c = 0; c < channels && !v->labels; ++c)
        umbra__map_ranges(v, c, v->brick_minmax + 2 * nbricks * c, 2 * nbricks);

    if (channels == 1)
        st = upload(v, desc->data, desc->type, filled, form, lo[0], scale[0]);
    else
        st = upload_channels(v, desc->data, desc->type, form, lo, scale);
    if (st != UMBRA_SUCCESS)
        goto fail;
    *out = v;
    return UMBRA_SUCCESS;
oom:
    st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                     "umbra_volume_create: out of host memory for %u x %u x %u voxels",
                     desc->dims[0], desc->dims[1], desc->dims[2]);
fail:
    free(stage);
    umbra_volume_release(v);
    return st;
}

void umbra__map_ranges(umbra_volume v, uint32_t c, float *values, size_t n)
{
    const double lo = v->range_d[c][0], scale = 1.0 / (v->range_d[c][1] - v->range_d[c][0]);
    const float flo = (float)lo, fscale = (float)scale;
    for (size_t i = 0; i < n; ++i) {
        float x;
        if (v->stored_form == UMBRA__STORED_NORMALISED)
            umbra__convert_voxels(values, UMBRA_FLOAT32, i, 1, v->stored_form, lo, scale, &x);
        else {
            x = (values[i] - flo) * fscale;
            x = x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
        }
        values[i] = x;
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
    umbra_status st = umbra__check_process(ctx, "umbra_volume_create");
    if (st != UMBRA_SUCCESS)
        return st;
    return volume_create(ctx, desc, NULL, out);
}

umbra_status umbra_volume_create_filled(umbra_context ctx, const umbra_volume_desc *desc,
                                        umbra_volume_fill_fn fill, void *user, umbra_volume *out)
{
    const char *fn = "umbra_volume_create_filled";
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    *out = NULL;
    if (!ctx || !desc || !fill)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: ctx %p, desc %p, fill %p: none may be NULL", fn, (void *)ctx,
                           (void *)desc, (void *)(uintptr_t)fill);
    /* validate() wants data: a stand-in until the real pointer is known. A layout it accepts
     * is copied as long as it is; another it refuses by its size. */
    umbra_volume_desc given, d;
    umbra_volume_desc_init(&given);
    if (desc->struct_size == sizeof given ||
        desc->struct_size == offsetof(umbra_volume_desc, channels))
        memcpy(&given, desc, desc->struct_size);
    else
        given.struct_size = desc->struct_size;
    if (given.data)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->data must be NULL: fill writes the voxels", fn);
    given.data = &given;
    umbra_status st = umbra__check_process(ctx, fn);
    if (st == UMBRA_SUCCESS)
        st = validate(ctx, &given, &d);
    if (st != UMBRA_SUCCESS)
        return st;
    const size_t bytes = (size_t)d.dims[0] * d.dims[1] * d.dims[2] * d.channels *
                         umbra_scalar_type_size(d.type);
    cl_mem buf = NULL;
    void *host = NULL, *mapped = NULL;
    cl_int err;
    /* One mapped buffer only for a plain or label volume that fits one (host/volume_slabs.c);
     * the slabs of a larger one are filled from host memory, as an image is, and so are the
     * interleaved channels of a multi-channel volume. */
    umbra__device_limits lim;
    uint32_t nslabs = 1, step;
    uint64_t need;
    const int image = ctx->sampler == UMBRA_SAMPLER_IMAGE && d.channels == 1 && !d.labels;
    if ((st = umbra__device_limits_get(ctx, image, &lim)) != UMBRA_SUCCESS ||
        (st = umbra__slabs_plan(ctx, d.dims, umbra_scalar_type_size(d.type) * d.channels, image,
                                &lim, &nslabs, &step, &need)) != UMBRA_SUCCESS)
        return st;
    if (!image && d.channels == 1 && nslabs == 1) {
        /* The device's own buffer, mapped: on a CPU device the mapping is the buffer itself,
         * so the voxels are written once, where the kernels read them. */
        buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_ALLOC_HOST_PTR,
                             bytes + umbra_scalar_type_size(d.type), NULL, &err);
        if (err == CL_SUCCESS)
            mapped = clEnqueueMapBuffer(ctx->queue, buf, CL_TRUE, CL_MAP_WRITE_INVALIDATE_REGION,
                                        0, bytes + umbra_scalar_type_size(d.type), 0, NULL, NULL,
                                        &err);
        if (err == CL_SUCCESS) /* the sampler's pad element (see upload) */
            memset((unsigned char *)mapped + bytes, 0, umbra_scalar_type_size(d.type));
        if (err != CL_SUCCESS) {
            int oom = err == CL_OUT_OF_RESOURCES || err == CL_MEM_OBJECT_ALLOCATION_FAILURE ||
                      err == CL_OUT_OF_HOST_MEMORY;
            st = umbra__fail(ctx, oom ? UMBRA_ERROR_OUT_OF_MEMORY : UMBRA_ERROR_OPENCL,
                             "%s: a mapped buffer of %zu bytes for %u x %u x %u voxels: %s (%d)",
                             fn, bytes, d.dims[0], d.dims[1], d.dims[2], umbra__cl_error_name(err),
                             (int)err);
            goto fail;
        }
        d.data = mapped;
    } else {
        /* An image (or slabs) is made from host memory: the voxels go there first. */
        host = malloc(bytes);
        if (!host) {
            st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "%s: out of host memory for %zu bytes of voxels", fn, bytes);
            goto fail;
        }
        d.data = host;
    }
    if ((st = fill(user, (void *)d.data, bytes)) != UMBRA_SUCCESS)
        goto fail;
    st = volume_create(ctx, &d, buf, out);
fail:
    if (mapped) {
        /* The kernels that will read the buffer are queued after the unmap. */
        err = clEnqueueUnmapMemObject(ctx->queue, buf, mapped, 0, NULL, NULL);
        /* A buffer nobody will use is freed now, not whenever the queue next drains. */
        if (st != UMBRA_SUCCESS)
            clFinish(ctx->queue);
        if (err != CL_SUCCESS && st == UMBRA_SUCCESS) {
            umbra_volume_release(*out);
            *out = NULL;
            st = umbra__fail(ctx, UMBRA_ERROR_OPENCL, "%s: clEnqueueUnmapMemObject: %s (%d)", fn,
                             umbra__cl_error_name(err), (int)err);
        }
    }
    if (buf)
        clReleaseMemObject(buf);
    free(host);
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
        out->extent[a] = (float)v->grid_dims[a] * v->spacing[a]; /* a part: the global box */
        out->brick_counts[a] = v->brick_counts[a];
    }
    out->value_min = v->value_min;
    out->value_max = v->value_max;
    out->brick_size = v->brick_size;
    out->device_bytes = v->device_bytes;
    out->transform_given = v->transformed;
    out->channels = v->channels;
    out->labels = v->labels;
    out->version = v->version;
    out->type = v->input_type;
    for (uint32_t c = 0; c < UMBRA_MAX_CHANNELS; ++c) {
        out->channel_min[c] = c < v->channels ? v->channel_range[c][0] : 0.0f;
        out->channel_max[c] = c < v->channels ? v->channel_range[c][1] : 0.0f;
    }
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
    if (!v || atomic_fetch_sub(&v->refs, 1) > 1 || umbra__forked(v->ctx))
        return;
    for (int s = 0; s < UMBRA__MAX_SLABS; ++s)
        if (v->slabs[s])
            clReleaseMemObject(v->slabs[s]);
    free(v->brick_minmax);
    free(v->cell_minmax);
    free(v->cell_clamps);
    umbra_context_release(v->ctx);
    free(v);
}
