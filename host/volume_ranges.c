// SPDX-License-Identifier: Apache-2.0
/* host/volume_ranges.c: the passes over a volume's voxels that umbra_volume_create and
 * umbra_volume_update share, on all processors: the min and max over every brick's and sub-cell's
 * footprint (the empty-space-skipping ranges), and the check that float voxels are finite. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "internal.h"
#include "common/umbra_shared.h"

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


size_t umbra__first_nonfinite(const float *data, size_t count)
{
    finite_job fj = {.data = data, .count = count};
    const uint32_t threads = umbra__thread_count();
    umbra__parallel(threads, finite_worker, &fj);
    size_t first = count;
    for (uint32_t t = 0; t < threads && t < UMBRA__MAX_THREADS; ++t)
        if (fj.first_bad[t] < first)
            first = fj.first_bad[t];
    return first;
}

int umbra__block_ranges(umbra_volume v, const void *block, umbra_scalar_type type,
                        const uint32_t origin[3], const uint32_t bdims[3], const uint32_t b0[3],
                        const uint32_t nb[3], float *cells_out, float *bricks_out)
{
    /* Cell j of brick b along an axis covers the sample positions [b*B + j*C, b*B + (j+1)*C)
     * with C = ceil(B / UMBRA_BRICK_CELLS), whose trilinear footprint is voxels
     * [b*B + j*C, b*B + (j+1)*C], clamped to the grid (a cell that starts beyond the last voxel
     * takes the last voxel: the clamped sampler repeats it there). A brick's footprint is voxels
     * [b*B, (b+1)*B], clamped: the union of its cells' when C * UMBRA_BRICK_CELLS == B, so then
     * the bricks come from the cells. */
    const uint32_t K = UMBRA_BRICK_CELLS, B = v->brick_size, C = (B + K - 1) / K;
    box_job cells = {0}, bricks = {0};
    size_t nint = 0;
    for (int a = 0; a < 3; ++a)
        nint += 2 * (size_t)nb[a] * (K + 1);
    uint32_t *intervals = malloc(nint * sizeof *intervals);
    if (!intervals)
        return 0;
    box_job *jobs[2] = {&cells, &bricks};
    uint32_t *next = intervals;
    for (int j = 0; j < 2; ++j) {
        box_job *J = jobs[j];
        J->data = block;
        J->type = type;
        J->cells = j == 0;
        J->out = j == 0 ? cells_out : bricks_out;
        atomic_init(&J->failed, 0);
        for (int a = 0; a < 3; ++a) {
            const uint32_t n = v->dims[a], per = j == 0 ? K : 1;
            J->dims[a] = bdims[a];
            J->bricks[a] = nb[a];
            J->count[a] = nb[a] * per;
            J->lo[a] = next;
            J->hi[a] = next + J->count[a];
            next += 2 * (size_t)J->count[a];
            for (uint32_t k = 0; k < J->count[a]; ++k) {
                const uint32_t b = b0[a] + k / per;
                const uint32_t s0 = j == 0 ? b * B + k % per * C : b * B;
                const uint32_t s1 = s0 + (j == 0 ? C : B);
                J->lo[a][k] = (s0 < n - 1 ? s0 : n - 1) - origin[a];
                J->hi[a][k] = (s1 < n - 1 ? s1 : n - 1) - origin[a];
            }
        }
    }
    const int bricks_from_cells = C * K == B;
    const uint32_t threads = umbra__thread_count();
    umbra__parallel(threads < cells.count[2] ? threads : cells.count[2], box_worker, &cells);
    if (!bricks_from_cells)
        umbra__parallel(threads < bricks.count[2] ? threads : bricks.count[2], box_worker, &bricks);
    free(intervals);
    if (atomic_load(&cells.failed) || atomic_load(&bricks.failed))
        return 0;
    if (bricks_from_cells) {
        const size_t nbricks = (size_t)nb[0] * nb[1] * nb[2], per_brick = (size_t)K * K * K;
        for (size_t b = 0; b < nbricks; ++b) {
            const float *c = cells_out + 2 * b * per_brick;
            float lo = c[0], hi = c[1];
            for (size_t k = 1; k < per_brick; ++k) {
                lo = c[2 * k] < lo ? c[2 * k] : lo;
                hi = c[2 * k + 1] > hi ? c[2 * k + 1] : hi;
            }
            bricks_out[2 * b] = lo;
            bricks_out[2 * b + 1] = hi;
        }
    }
    return 1;
}
