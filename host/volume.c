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
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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
}

/* Threads for the passes over the voxels: the online processors, at most UMBRA__MAX_THREADS. */
#define UMBRA__MAX_THREADS 32

static uint32_t umbra__thread_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > UMBRA__MAX_THREADS ? UMBRA__MAX_THREADS : (uint32_t)n);
}

typedef struct thread_arg {
    void (*fn)(void *job, uint32_t t, uint32_t threads);
    void *job;
    uint32_t t, threads;
} thread_arg;

static void *thread_main(void *p)
{
    thread_arg *a = p;
    a->fn(a->job, a->t, a->threads);
    return NULL;
}

/* Runs fn(job, t, threads) for t = 0 .. threads - 1, on threads of their own where they can be
 * started and in the calling thread otherwise, and returns when all are done. */
static void umbra__parallel(uint32_t threads, void (*fn)(void *, uint32_t, uint32_t), void *job)
{
    pthread_t tid[UMBRA__MAX_THREADS];
    thread_arg args[UMBRA__MAX_THREADS];
    int started[UMBRA__MAX_THREADS] = {0};
    threads = threads < 1 ? 1 : (threads > UMBRA__MAX_THREADS ? UMBRA__MAX_THREADS : threads);
    for (uint32_t t = 1; t < threads; ++t) {
        args[t] = (thread_arg){fn, job, t, threads};
        started[t] = pthread_create(&tid[t], NULL, thread_main, &args[t]) == 0;
    }
    fn(job, 0, threads);
    for (uint32_t t = 1; t < threads; ++t) {
        if (started[t])
            pthread_join(tid[t], NULL);
        else
            fn(job, t, threads);
    }
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

/* ---- min and max over boxes of voxels, in parallel ------------------------------------------ */

/* One table of boxes (the sub-cells, or the bricks): along axis a, box k spans voxels
 * lo[a][k] .. hi[a][k], inclusive. Each thread takes every threads-th layer of boxes along z, so
 * no two write the same entry. A box's rows are folded element by element in the input's own
 * type (vectorised by the compiler), and the folded row reduced per box along x: no converted
 * copy of the volume is made, and each voxel is read about (1 + 1/C)^2 times. */
typedef struct box_job {
    const void *data;
    umbra_scalar_type type;
    uint32_t dims[3];
    uint32_t count[3];      /* boxes per axis */
    uint32_t *lo[3], *hi[3];
    int cells;              /* 1: cell-table order (brick-major, UMBRA_BRICK_CELLS^3 per brick) */
    uint32_t bricks[3];
    float *out;             /* raw min, max per box */
    atomic_int failed;      /* a thread found no memory for its two rows */
} box_job;

static size_t box_index(const box_job *J, uint32_t kx, uint32_t ky, uint32_t kz)
{
    if (!J->cells)
        return ((size_t)kz * J->count[1] + ky) * J->count[0] + kx;
    const uint32_t K = UMBRA_BRICK_CELLS;
    size_t b = ((size_t)(kz / K) * J->bricks[1] + ky / K) * J->bricks[0] + kx / K;
    return b * K * K * K + kx % K + K * (ky % K + K * (kz % K));
}

#define UMBRA_BOX_LAYER(T, NAME)                                                                  \
    static void NAME(box_job *J, uint32_t kz, void *mn_row, void *mx_row)                         \
    {                                                                                             \
        const T *d = J->data;                                                                     \
        T *mn = mn_row, *mx = mx_row;                                                             \
        const size_t nx = J->dims[0], ny = J->dims[1];                                            \
        for (uint32_t ky = 0; ky < J->count[1]; ++ky) {                                           \
            int first = 1;                                                                        \
            for (uint32_t z = J->lo[2][kz]; z <= J->hi[2][kz]; ++z)                               \
                for (uint32_t y = J->lo[1][ky]; y <= J->hi[1][ky]; ++y) {                         \
                    const T *row = d + ((size_t)z * ny + y) * nx;                                 \
                    if (first) {                                                                  \
                        memcpy(mn, row, nx * sizeof(T));                                          \
                        memcpy(mx, row, nx * sizeof(T));                                          \
                        first = 0;                                                                \
                        continue;                                                                 \
                    }                                                                             \
                    for (size_t x = 0; x < nx; ++x) {                                             \
                        mn[x] = row[x] < mn[x] ? row[x] : mn[x];                                  \
                        mx[x] = row[x] > mx[x] ? row[x] : mx[x];                                  \
                    }                                                                             \
                }                                                                                 \
            for (uint32_t kx = 0; kx < J->count[0]; ++kx) {                                       \
                T lo = mn[J->lo[0][kx]], hi = mx[J->lo[0][kx]];                                   \
                for (uint32_t x = J->lo[0][kx] + 1; x <= J->hi[0][kx]; ++x) {                     \
                    lo = mn[x] < lo ? mn[x] : lo;                                                 \
                    hi = mx[x] > hi ? mx[x] : hi;                                                 \
                }                                                                                 \
                size_t i = box_index(J, kx, ky, kz);                                              \
                J->out[2 * i] = (float)lo;                                                        \
                J->out[2 * i + 1] = (float)hi;                                                    \
            }                                                                                     \
        }                                                                                         \
    }
UMBRA_BOX_LAYER(uint8_t, box_layer_u8)
UMBRA_BOX_LAYER(uint16_t, box_layer_u16)
UMBRA_BOX_LAYER(int16_t, box_layer_i16)
UMBRA_BOX_LAYER(float, box_layer_f32)
#undef UMBRA_BOX_LAYER

static void box_worker(void *job, uint32_t t, uint32_t threads)
{
    box_job *J = job;
    const size_t size = umbra_scalar_type_size(J->type);
    unsigned char *rows = malloc(2 * (size_t)J->dims[0] * size);
    if (!rows) {
        atomic_store(&J->failed, 1);
        return;
    }
    void *mn = rows, *mx = rows + (size_t)J->dims[0] * size;
    for (uint32_t kz = t; kz < J->count[2]; kz += threads) {
        switch (J->type) {
        case UMBRA_UINT8: box_layer_u8(J, kz, mn, mx); break;
        case UMBRA_UINT16: box_layer_u16(J, kz, mn, mx); break;
        case UMBRA_INT16: box_layer_i16(J, kz, mn, mx); break;
        case UMBRA_FLOAT32: box_layer_f32(J, kz, mn, mx); break;
        }
    }
    free(rows);
}

/* Float voxels: the first that is NaN or infinite, per thread over its share. */
typedef struct finite_job {
    const float *data;
    size_t count;
    size_t first_bad[UMBRA__MAX_THREADS]; /* count where none */
} finite_job;

static void finite_worker(void *job, uint32_t t, uint32_t threads)
{
    finite_job *J = job;
    size_t a = J->count / threads * t, b = t + 1 == threads ? J->count : J->count / threads * (t + 1);
    J->first_bad[t] = J->count;
    for (size_t i = a; i < b; ++i)
        if (!isfinite(J->data[i])) {
            J->first_bad[t] = i;
            return;
        }
}

/* ---- the conversion for what cannot be stored as given ------------------------------------ */

typedef enum stored_form {
    STORED_RAW,        /* the input's bytes as they are */
    STORED_BIASED_U16, /* int16 + 32768 as uint16 (a CL_UNORM_INT16 image) */
    STORED_NORMALISED  /* normalised float32, computed in double as the range's mapping is */
} stored_form;

static void convert_voxels(const void *src, umbra_scalar_type type, size_t first, size_t n,
                           stored_form form, double lo, double scale, void *dst)
{
    if (form == STORED_BIASED_U16) {
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
 * host/volume_slabs.c) from the caller's voxels: straight from them where the device stores the
 * input as it is, else through a bounded staging buffer (a few MiB), never a converted copy of
 * the whole volume. Blocks until the data is on the device. */
static umbra_status upload(umbra_volume v, const umbra_volume_desc *desc, cl_mem filled,
                           stored_form form, double lo, double scale)
{
    umbra_context ctx = v->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t nx = v->dims[0], ny = v->dims[1];
    const size_t esize = umbra_scalar_type_size(v->stored_type);
    void *stage = NULL;
    if (filled && form == STORED_RAW) {
        /* desc->data is filled's mapping: the buffer already holds the voxels as stored (and
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
    const int image = ctx->sampler == UMBRA_SAMPLER_IMAGE;
    st = umbra__slabs_create(ctx, v, esize, image ? &fmt : NULL,
                             form == STORED_RAW ? desc->data : NULL);
    if (st != UMBRA_SUCCESS || form == STORED_RAW)
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
                convert_voxels(desc->data, desc->type, first, r * nx, form, lo, scale, stage);
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

/* filled: NULL, or a buffer sampler's buffer (of desc->type) whose mapping desc->data is. */
static umbra_status volume_create(umbra_context ctx, const umbra_volume_desc *desc, cl_mem filled,
                                  umbra_volume *out)
{
    umbra_status st = validate(ctx, desc);
    if (st != UMBRA_SUCCESS)
        return st;
    /* A volume that cannot fit the device is refused before the pass over its voxels. The
     * device stores at least the input type's bytes per voxel (or float32 in its place); the
     * upload plans again with the stored type. */
    {
        umbra__device_limits lim;
        uint32_t nslabs, step;
        uint64_t bytes;
        const int image = ctx->sampler == UMBRA_SAMPLER_IMAGE;
        if ((st = umbra__device_limits_get(ctx, image, &lim)) != UMBRA_SUCCESS ||
            (st = umbra__slabs_plan(ctx, desc->dims, umbra_scalar_type_size(desc->type), image,
                                    &lim, &nslabs, &step, &bytes)) != UMBRA_SUCCESS)
            return st;
    }

    box_job cells = {0}, bricks = {0};
    uint32_t *intervals = NULL;
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
    const uint32_t threads = umbra__thread_count();

    /* Float data is scanned for NaN and infinity even with a given range: the mapping would clamp
     * infinity to an end of the table and NaN to 0, a picture of values that are not there.
     * Integer types are always finite. */
    if (desc->type == UMBRA_FLOAT32) {
        finite_job fj = {.data = desc->data, .count = count};
        umbra__parallel(threads, finite_worker, &fj);
        for (uint32_t t = 0; t < threads; ++t)
            if (fj.first_bad[t] < count) {
                const size_t i = fj.first_bad[t], nx = desc->dims[0], ny = desc->dims[1];
                st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "umbra_volume_create: voxel %zu is %g (x %zu, y %zu, z %zu); "
                                 "float volumes must be finite",
                                 i, (double)((const float *)desc->data)[i], i % nx, i / nx % ny,
                                 i / (nx * ny));
                goto fail;
            }
    }

    /* Raw min and max per sub-cell and per brick. Cell j of brick b along an axis covers the
     * sample positions [b*B + j*C, b*B + (j+1)*C) with C = ceil(B / UMBRA_BRICK_CELLS), whose
     * trilinear footprint is voxels [b*B + j*C, b*B + (j+1)*C], clamped to the grid (a cell that
     * starts beyond the last voxel takes the last voxel: the clamped sampler repeats it there).
     * A brick's footprint is voxels [b*B, (b+1)*B], clamped: the union of its cells' when
     * C * UMBRA_BRICK_CELLS == B, so then the bricks come from the cells. */
    const uint32_t B = v->brick_size, C = (B + UMBRA_BRICK_CELLS - 1) / UMBRA_BRICK_CELLS;
    const size_t nbricks = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const size_t ncells = nbricks * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    size_t nint = 0;
    for (int a = 0; a < 3; ++a)
        nint += 2 * (size_t)v->brick_counts[a] * (UMBRA_BRICK_CELLS + 1);
    intervals = malloc(nint * sizeof *intervals);
    v->brick_minmax = malloc(2 * nbricks * sizeof *v->brick_minmax);
    v->cell_minmax = malloc(2 * ncells * sizeof *v->cell_minmax);
    if (!intervals || !v->brick_minmax || !v->cell_minmax)
        goto oom;
    box_job *jobs[2] = {&cells, &bricks};
    uint32_t *next = intervals;
    for (int j = 0; j < 2; ++j) {
        box_job *J = jobs[j];
        J->data = desc->data;
        J->type = desc->type;
        J->cells = j == 0;
        J->out = j == 0 ? v->cell_minmax : v->brick_minmax;
        atomic_init(&J->failed, 0);
        for (int a = 0; a < 3; ++a) {
            const uint32_t n = v->dims[a], per = j == 0 ? UMBRA_BRICK_CELLS : 1;
            J->dims[a] = n;
            J->bricks[a] = v->brick_counts[a];
            J->count[a] = v->brick_counts[a] * per;
            J->lo[a] = next;
            J->hi[a] = next + J->count[a];
            next += 2 * (size_t)J->count[a];
            for (uint32_t k = 0; k < J->count[a]; ++k) {
                uint32_t s0 = j == 0 ? k / per * B + k % per * C : k * B;
                uint32_t s1 = s0 + (j == 0 ? C : B);
                J->lo[a][k] = s0 < n - 1 ? s0 : n - 1;
                J->hi[a][k] = s1 < n - 1 ? s1 : n - 1;
            }
        }
    }
    const int bricks_from_cells = C * UMBRA_BRICK_CELLS == B;
    umbra__parallel(threads < cells.count[2] ? threads : cells.count[2], box_worker, &cells);
    if (!bricks_from_cells)
        umbra__parallel(threads < bricks.count[2] ? threads : bricks.count[2], box_worker, &bricks);
    if (atomic_load(&cells.failed) || atomic_load(&bricks.failed))
        goto oom;
    const size_t per_brick = ncells / nbricks;
    if (bricks_from_cells)
        for (size_t b = 0; b < nbricks; ++b) {
            const float *c = v->cell_minmax + 2 * b * per_brick;
            float lo = c[0], hi = c[1];
            for (size_t k = 1; k < per_brick; ++k) {
                lo = c[2 * k] < lo ? c[2 * k] : lo;
                hi = c[2 * k + 1] > hi ? c[2 * k + 1] : hi;
            }
            v->brick_minmax[2 * b] = lo;
            v->brick_minmax[2 * b + 1] = hi;
        }
    /* The bricks cover every voxel: their extremes are the data's. */
    double dlo = INFINITY, dhi = -INFINITY;
    for (size_t b = 0; b < nbricks; ++b) {
        dlo = v->brick_minmax[2 * b] < dlo ? v->brick_minmax[2 * b] : dlo;
        dhi = v->brick_minmax[2 * b + 1] > dhi ? v->brick_minmax[2 * b + 1] : dhi;
    }

    /* The range and the mapping in double: max - min of finite floats can overflow a float
     * (+-3e38), and lo + 1 rounds back to lo for |lo| > 2^24. */
    double lo = desc->value_min, hi = desc->value_max;
    if (!desc->value_range_given) {
        lo = dlo;
        hi = dhi;
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
    const double scale = 1.0 / (hi - lo);

    /* How the device stores the voxels. The kernels normalise the buffer's raw values per voxel
     * in float, (s - lo) * scale: safe for integers and for floats whose range is neither huge
     * nor tiny (+-3e38 is not); otherwise normalised floats, as before. An image's filter blends
     * before it normalises, which differs from blending normalised values where a given range
     * clamps the data, and CL_SNORM_INT16 would merge -32768 with -32767: images of integers
     * are stored as UNORM (int16 biased) only where neither happens and the device has the
     * format. */
    const int clamps = desc->value_range_given && (dlo < lo || dhi > hi);
    const int float_ok = hi - lo >= 1e-30 && hi - lo <= 1e30 && fabs(lo) <= 1e30;
    stored_form form = STORED_RAW;
    v->stored_type = desc->type;
    double s_lo = lo, s_scale = 1.0;
    if (ctx->sampler == UMBRA_SAMPLER_IMAGE) {
        if (desc->type == UMBRA_UINT8 && ctx->has_unorm8_r_image3d && !clamps)
            s_scale = 255.0;
        else if (desc->type == UMBRA_UINT16 && ctx->has_unorm16_r_image3d && !clamps)
            s_scale = 65535.0;
        else if (desc->type == UMBRA_INT16 && ctx->has_unorm16_r_image3d && !clamps) {
            form = STORED_BIASED_U16;
            v->stored_type = UMBRA_UINT16;
            s_scale = 65535.0;
            s_lo = lo + 32768.0;
        } else
            form = STORED_NORMALISED;
    } else if (desc->type == UMBRA_FLOAT32 && !float_ok)
        form = STORED_NORMALISED;
    v->clamps = form != STORED_NORMALISED && clamps;
    if (form == STORED_NORMALISED) {
        v->stored_type = UMBRA_FLOAT32;
        v->value_map[0] = 0.0f;
        v->value_map[1] = 1.0f;
        v->value_map[2] = 1.0f;
    } else {
        v->value_map[0] = (float)s_lo;
        v->value_map[1] = (float)scale;
        v->value_map[2] = (float)s_scale;
    }

    /* The tables in normalised values, mapped as the kernels map a voxel (the mapping is
     * monotonic, so the extremes map to the extremes). */
    const float flo = (float)lo, fscale = (float)scale;
    float *tables[2] = {v->cell_minmax, v->brick_minmax};
    const size_t lengths[2] = {2 * ncells, 2 * nbricks};
    for (int t = 0; t < 2; ++t)
        for (size_t i = 0; i < lengths[t]; ++i) {
            float x;
            if (form == STORED_NORMALISED)
                convert_voxels(tables[t], UMBRA_FLOAT32, i, 1, form, lo, scale, &x);
            else {
                x = (tables[t][i] - flo) * fscale;
                x = x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
            }
            tables[t][i] = x;
        }

    if ((st = upload(v, desc, filled, form, lo, scale)) != UMBRA_SUCCESS)
        goto fail;
    free(intervals);
    *out = v;
    return UMBRA_SUCCESS;
oom:
    st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                     "umbra_volume_create: out of host memory for %u x %u x %u voxels",
                     desc->dims[0], desc->dims[1], desc->dims[2]);
fail:
    free(intervals);
    umbra_volume_release(v);
    return st;
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
    if (desc->struct_size == sizeof *desc && desc->data)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->data must be NULL: fill writes the voxels", fn);
    /* validate() wants data: a stand-in until the real pointer is known. */
    umbra_volume_desc d = *desc;
    d.data = &d;
    umbra_status st = umbra__check_process(ctx, fn);
    if (st == UMBRA_SUCCESS)
        st = validate(ctx, &d);
    if (st != UMBRA_SUCCESS)
        return st;
    const size_t bytes = (size_t)d.dims[0] * d.dims[1] * d.dims[2] * umbra_scalar_type_size(d.type);
    cl_mem buf = NULL;
    void *host = NULL, *mapped = NULL;
    cl_int err;
    /* One mapped buffer only for a volume that fits one (host/volume_slabs.c); the slabs of a
     * larger one are filled from host memory, as an image is. */
    umbra__device_limits lim;
    uint32_t nslabs = 1, step;
    uint64_t need;
    if ((st = umbra__device_limits_get(ctx, ctx->sampler == UMBRA_SAMPLER_IMAGE, &lim)) !=
            UMBRA_SUCCESS ||
        (st = umbra__slabs_plan(ctx, d.dims, umbra_scalar_type_size(d.type),
                                ctx->sampler == UMBRA_SAMPLER_IMAGE, &lim, &nslabs, &step,
                                &need)) != UMBRA_SUCCESS)
        return st;
    if (ctx->sampler == UMBRA_SAMPLER_BUFFER && nslabs == 1) {
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
    if (!v || atomic_fetch_sub(&v->refs, 1) > 1 || umbra__forked(v->ctx))
        return;
    for (int s = 0; s < UMBRA__MAX_SLABS; ++s)
        if (v->slabs[s])
            clReleaseMemObject(v->slabs[s]);
    free(v->brick_minmax);
    free(v->cell_minmax);
    umbra_context_release(v->ctx);
    free(v);
}
