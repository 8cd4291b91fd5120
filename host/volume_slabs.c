// SPDX-License-Identifier: Apache-2.0
/* host/volume_slabs.c: a volume's voxels on the device, in one buffer (or 3D image) or, when the
 * volume is larger than the device's largest allocation or deeper than its largest 3D image, in
 * several z-slabs.
 *
 * Slab s holds the voxel layers [s * step, (s + 1) * step] clipped to the grid: neighbours share
 * one layer (the apron), so every trilinear sample, and every central-difference gradient built
 * from such samples, reads one slab only (kernels/common/sampling.cl picks it by the sample's z).
 * The
 * plan is made, and checked against the device's global memory, before anything is allocated, so
 * a volume that cannot fit is refused with its sizes instead of failing half-way through.
 *
 * Every buffer has one pad element after its last voxel: the buffer sampler reads voxels in x
 * pairs (vload2), and the pair of a slab's last voxel reads one beyond it, with weight 0. */
#include <string.h>

#include "internal.h"

void umbra__context_limit_alloc(umbra_context ctx, uint64_t bytes)
{
    if (ctx)
        ctx->alloc_limit = bytes;
}

umbra_status umbra__device_limits_get(umbra_context ctx, int image, umbra__device_limits *out)
{
    umbra_status st = UMBRA_SUCCESS;
    cl_ulong max_alloc = 0, global_mem = 0;
    memset(out, 0, sizeof *out);
    UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc,
                             &max_alloc, NULL));
    UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof global_mem,
                             &global_mem, NULL));
    if (image) {
        UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_IMAGE3D_MAX_WIDTH, sizeof(size_t),
                                 &out->image_max[0], NULL));
        UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_IMAGE3D_MAX_HEIGHT, sizeof(size_t),
                                 &out->image_max[1], NULL));
        UMBRA_CL(clGetDeviceInfo(ctx->device, CL_DEVICE_IMAGE3D_MAX_DEPTH, sizeof(size_t),
                                 &out->image_max[2], NULL));
    }
    out->max_alloc = max_alloc;
    out->global_mem = global_mem;
    if (ctx->alloc_limit && ctx->alloc_limit < out->max_alloc)
        out->max_alloc = ctx->alloc_limit;
fail:
    return st;
}

umbra_status umbra__slabs_plan(umbra_context ctx, const uint32_t dims[3], size_t voxel_bytes,
                               int image, const umbra__device_limits *lim, uint32_t *count,
                               uint32_t *step, uint64_t *bytes)
{
    const char *fn = "umbra_volume_create";
    const char *what = image ? "3D image" : "buffer";
    const uint64_t layer = (uint64_t)dims[0] * dims[1] * voxel_bytes;
    const uint64_t total = layer * dims[2];
    const uint64_t pad = image ? 0 : voxel_bytes;
    if (image && (dims[0] > lim->image_max[0] || dims[1] > lim->image_max[1]))
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: dims %u x %u x %u: the device's largest 3D image is %zu x %zu "
                           "(x %zu); only the depth can be split (the buffer sampler has no "
                           "such limit)", fn, dims[0], dims[1], dims[2], lim->image_max[0],
                           lim->image_max[1], lim->image_max[2]);
    /* The most layers one slab may hold. */
    uint64_t fit = lim->max_alloc > pad ? (lim->max_alloc - pad) / layer : 0;
    if (image && fit > lim->image_max[2])
        fit = lim->image_max[2];
    uint32_t n = 1, s = dims[2];
    if (fit < dims[2]) {
        /* Slabs of up to `fit` layers advance by fit - 1 (the shared layer), covering the
         * dims[2] - 1 cells between layers; the step is then evened out over the slabs. */
        if (fit < 2)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: dims %u x %u x %u: two z-layers (%llu bytes) exceed the "
                               "device's largest %s (%llu bytes)", fn, dims[0], dims[1],
                               dims[2], (unsigned long long)(2 * layer + pad), what,
                               (unsigned long long)lim->max_alloc);
        const uint64_t cells = dims[2] - 1u;
        uint64_t want = (cells + fit - 2) / (fit - 1);
        if (want > UMBRA__MAX_SLABS)
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: dims %u x %u x %u (%llu bytes) need %llu slabs of at most "
                               "%llu layers (the device's largest %s is %llu bytes); at most %d "
                               "are supported", fn, dims[0], dims[1], dims[2],
                               (unsigned long long)total, (unsigned long long)want,
                               (unsigned long long)fit, what, (unsigned long long)lim->max_alloc,
                               UMBRA__MAX_SLABS);
        s = (uint32_t)((cells + want - 1) / want);
        n = (uint32_t)((cells + s - 1) / s); /* so that the last slab is not empty */
    }
    const uint64_t need = total + (uint64_t)(n - 1) * layer + n * pad;
    if (need > lim->global_mem)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "%s: dims %u x %u x %u need %llu bytes of device memory (%u slab%s "
                           "of %zu-byte voxels); the device has %llu bytes of global memory", fn,
                           dims[0], dims[1], dims[2], (unsigned long long)need, n,
                           n == 1 ? "" : "s", voxel_bytes, (unsigned long long)lim->global_mem);
    *count = n;
    *step = s;
    *bytes = need;
    return UMBRA_SUCCESS;
}

void umbra__slab_layers(umbra_volume v, uint32_t s, uint32_t *z0, uint32_t *z1)
{
    *z0 = s * v->slab_step;
    *z1 = v->slab_count == 1 || *z0 + v->slab_step > v->dims[2] - 1 ? v->dims[2] - 1
                                                                     : *z0 + v->slab_step;
}

umbra_status umbra__slabs_create(umbra_context ctx, umbra_volume v, size_t voxel_bytes,
                                 const cl_image_format *fmt, const void *voxels)
{
    umbra_status st;
    umbra__device_limits lim;
    uint64_t bytes;
    if ((st = umbra__device_limits_get(ctx, fmt != NULL, &lim)) != UMBRA_SUCCESS ||
        (st = umbra__slabs_plan(ctx, v->dims, voxel_bytes, fmt != NULL, &lim, &v->slab_count,
                                &v->slab_step, &bytes)) != UMBRA_SUCCESS)
        return st;
    const size_t layer = (size_t)v->dims[0] * v->dims[1] * voxel_bytes;
    for (uint32_t s = 0; s < v->slab_count; ++s) {
        uint32_t z0, z1;
        umbra__slab_layers(v, s, &z0, &z1);
        const size_t depth = (size_t)z1 - z0 + 1;
        /* The host pointer is only read (CL_MEM_COPY_HOST_PTR copies it at the call). */
        void *src = voxels ? (char *)(uintptr_t)voxels + (size_t)z0 * layer : NULL;
        cl_int err;
        if (fmt) {
            cl_image_desc idesc;
            memset(&idesc, 0, sizeof idesc);
            idesc.image_type = CL_MEM_OBJECT_IMAGE3D;
            idesc.image_width = v->dims[0];
            idesc.image_height = v->dims[1];
            idesc.image_depth = depth;
            v->slabs[s] = clCreateImage(ctx->cl_ctx,
                                        CL_MEM_READ_ONLY | (src ? CL_MEM_COPY_HOST_PTR : 0), fmt,
                                        &idesc, src, &err);
            UMBRA_CL_CHECK(err, "clCreateImage(volume slab)");
        } else {
            v->slabs[s] = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY,
                                         (depth * layer) + voxel_bytes, NULL, &err);
            UMBRA_CL_CHECK(err, "clCreateBuffer(volume slab)");
            const float zero = 0.0f; /* a finite pad: weight 0 times anything else could be NaN */
            UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, v->slabs[s], CL_TRUE, depth * layer,
                                          voxel_bytes, &zero, 0, NULL, NULL));
            if (src)
                UMBRA_CL(clEnqueueWriteBuffer(ctx->queue, v->slabs[s], CL_TRUE, 0, depth * layer,
                                              src, 0, NULL, NULL));
        }
    }
    v->device_bytes = (size_t)bytes;
fail:
    return st;
}

umbra_status umbra__slabs_read(umbra_volume v, void *out, size_t voxel_bytes)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t layer = (size_t)v->dims[0] * v->dims[1] * voxel_bytes;
    for (uint32_t s = 0; s < v->slab_count; ++s) {
        /* Each slab without its last layer (the next slab's first), the last slab whole. */
        uint32_t z0, z1;
        umbra__slab_layers(v, s, &z0, &z1);
        z1 += s + 1 == v->slab_count;
        char *dst = (char *)out + (size_t)z0 * layer;
        cl_mem_object_type type = 0;
        UMBRA_CL(clGetMemObjectInfo(v->slabs[s], CL_MEM_TYPE, sizeof type, &type, NULL));
        if (type == CL_MEM_OBJECT_BUFFER) {
            UMBRA_CL(clEnqueueReadBuffer(ctx->queue, v->slabs[s], CL_TRUE, 0,
                                         (size_t)(z1 - z0) * layer, dst, 0, NULL, NULL));
        } else {
            size_t origin[3] = {0, 0, 0}, region[3] = {v->dims[0], v->dims[1], z1 - z0};
            UMBRA_CL(clEnqueueReadImage(ctx->queue, v->slabs[s], CL_TRUE, origin, region, 0, 0,
                                        dst, 0, NULL, NULL));
        }
    }
fail:
    return st;
}

umbra_status umbra__volume_read_normalised(umbra_volume v, float *out)
{
    const size_t count = (size_t)v->dims[0] * v->dims[1] * v->dims[2];
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    /* Float voxels are read in place; narrower ones into the front of out's own bytes would be
     * overwritten while converting forwards, so they are read into its back end and converted
     * from the front (element i's source lies at or after where value i is written). */
    unsigned char *raw = (unsigned char *)out + count * (sizeof *out - esize);
    umbra_status st = umbra__slabs_read(v, raw, esize);
    if (st != UMBRA_SUCCESS)
        return st;
    for (size_t i = 0; i < count; ++i) {
        float s;
        switch (v->stored_type) {
        case UMBRA_UINT8: s = (float)raw[i]; break;
        case UMBRA_UINT16: {
            uint16_t x;
            memcpy(&x, raw + 2 * i, 2);
            s = (float)x;
            break;
        }
        case UMBRA_INT16: {
            int16_t x;
            memcpy(&x, raw + 2 * i, 2);
            s = (float)x;
            break;
        }
        default: memcpy(&s, raw + 4 * i, 4); break;
        }
        /* As voxel_normalise in kernels/common/sampling.cl, with an image's UNORM texels read as
         * the
         * integers they encode (value_map[0] is in those units). */
        float x = (s - v->value_map[0]) * v->value_map[1];
        out[i] = x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
    }
    return UMBRA_SUCCESS;
}
