// SPDX-License-Identifier: Apache-2.0
/* host/internal.h: what the host modules share and the public API does not show.
 *
 * Error recording (one helper, one OpenCL check macro), the context's program cache, and the
 * internals of volumes and transfer functions. Internal names start with "umbra__". */
#ifndef UMBRA_HOST_INTERNAL_H
#define UMBRA_HOST_INTERNAL_H

#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "umbra/umbra.h"

#if defined(__GNUC__)
#define UMBRA_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define UMBRA_PRINTF(f, a)
#endif

#define UMBRA_MESSAGE_MAX 8192

/* ---- errors ------------------------------------------------------------------------------- */

/* Records status and a formatted message on ctx (which may be NULL: the message is then dropped)
 * and returns status, so a failing path reads `return umbra__fail(ctx, CODE, "%s: ...", __func__)`.
 * The message should start with the public function's name. */
umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt, ...)
    UMBRA_PRINTF(3, 4);

/* Records an OpenCL failure: "<func>: <call> failed with <CL_NAME> (<code>) at file:line". */
umbra_status umbra__fail_cl(umbra_context ctx, const char *func, const char *call, cl_int err,
                            const char *file, int line);

const char *umbra__cl_error_name(cl_int err);

/* Checks an OpenCL call; on failure records it, sets `st` and jumps to `fail`. Needs `ctx`,
 * `st` (umbra_status) and a `fail:` label in scope. */
#define UMBRA_CL(call)                                                                         \
    do {                                                                                       \
        cl_int umbra_cl_err_ = (call);                                                         \
        if (umbra_cl_err_ != CL_SUCCESS) {                                                     \
            st = umbra__fail_cl(ctx, __func__, #call, umbra_cl_err_, __FILE__, __LINE__);      \
            goto fail;                                                                         \
        }                                                                                      \
    } while (0)

/* Same for calls that return the error through their last argument: `x = clCreate...(..., &e)`. */
#define UMBRA_CL_CHECK(err, what)                                                              \
    do {                                                                                       \
        if ((err) != CL_SUCCESS) {                                                             \
            st = umbra__fail_cl(ctx, __func__, (what), (err), __FILE__, __LINE__);             \
            goto fail;                                                                         \
        }                                                                                      \
    } while (0)

/* ---- context -------------------------------------------------------------------------------- */

typedef struct umbra__program umbra__program;

/* The object structs use C11 atomics, which C++17 lacks: a C++ file including this header would
 * see only the functions (none does today; umbra_io's image.cpp uses the public API). */
#ifndef __cplusplus
/* Threads: a context may be shared by objects used on different threads (include/umbra/
 * context.h), so its reference count and ids are atomic and mutexes guard what they share: the
 * program cache and the error state (one mutex each: a failing build records its error while
 * holding the cache). Objects' reference counts are atomic too; the rest of an object is used by
 * one thread at a time. */
struct umbra_context_t {
    atomic_int refs;
    pthread_mutex_t program_lock;       /* guards programs */
    pthread_mutex_t error_lock;         /* guards first_error, the messages and the callback */
    cl_platform_id platform;
    cl_context cl_ctx;
    cl_device_id device;
    cl_command_queue queue;             /* where umbra enqueues: in-order, always */
    cl_command_queue app_queue;         /* the application's out-of-order queue, retained, when
                                           umbra runs on its own in-order queue; else NULL */
    int profiling;                      /* queue has CL_QUEUE_PROFILING_ENABLE: device times */
    int has_float_r_image3d;
    int has_unorm8_r_image3d, has_unorm16_r_image3d; /* CL_R 3D images of CL_UNORM_INT8 / 16 */
    umbra_sampler_kind sampler;
    char device_name[600];              /* "platform / device": two 256-byte names */
    umbra__program *programs;           /* cache: one entry per (sources, options) */
    umbra_status first_error;           /* sticky until umbra_context_take_error */
    char first_message[UMBRA_MESSAGE_MAX];
    char last_message[UMBRA_MESSAGE_MAX];
    umbra_error_callback callback;
    void *callback_user;
    atomic_uint_least64_t next_id;      /* source of volume / transfer-function ids */
    uint64_t alloc_limit;               /* tests only (umbra__context_limit_alloc): a largest
                                           allocation below the device's, 0 for none */
    long pid;                           /* the process that created the context (getpid) */
};
#endif

/* Returns (building on first use, then from the context's cache) the program made of the named
 * embedded kernel files, concatenated in order after the shared struct header, built with the
 * given options. The program stays owned by the context. A failed build records its log. */
umbra_status umbra__program_get(umbra_context ctx, const char *const *files, size_t nfiles,
                                const char *options, cl_program *out);

/* Creates a kernel from a cached program; the caller releases it. */
umbra_status umbra__kernel_create(umbra_context ctx, cl_program program, const char *name,
                                  cl_kernel *out);

/* The embedded source of kernels/<name>, or NULL. Defined in the generated kernel table. */
const char *umbra__kernel_source(const char *name);

/* Enqueues a 1D or 2D range with the global size rounded up to the local size (PoCL rejects
 * non-uniform work-groups; kernels bounds-check). local may be NULL for the default (8x8 / 64). */
umbra_status umbra__enqueue(umbra_context ctx, cl_kernel k, cl_uint dim, const size_t *global,
                            const size_t *local, cl_event *event);

/* Milliseconds between an event's start and end, or -1 without profiling (ctx->profiling is 0
 * on an application's in-order queue without CL_QUEUE_PROFILING_ENABLE: callers then time the
 * wall clock, and the stats say so). */
double umbra__event_ms(cl_event ev);
double umbra__now_ms(void);

/* ---- volume ---------------------------------------------------------------------------------- */

/* The most z-slabs a volume may be split into: each is a kernel parameter
 * (kernels/common/sampling.cl
 * spells out this many). */
#define UMBRA__MAX_SLABS 8

#ifndef __cplusplus
struct umbra_volume_t {
    atomic_int refs;
    umbra_context ctx;
    uint32_t dims[3];
    float spacing[3];
    float value_min, value_max;
    uint32_t brick_size;
    uint32_t brick_counts[3];
    float *brick_minmax;     /* host: 2 floats (normalised min, max) per brick */
    float *cell_minmax;      /* host: the same per sub-cell, UMBRA_BRICK_CELLS^3 per brick,
                                brick-major, x fastest (kernels/common/umbra_shared.h) */
    /* The voxels on the device, in slab_count z-slabs (slab s holds the layers
     * [s * slab_step, (s + 1) * slab_step] clipped to the grid, host/volume_slabs.c): buffers of
     * the input type's raw values, or normalised float32 (stored_type FLOAT32 with value_map
     * 0, 1, 1), for the buffer sampler; 3D images for the image sampler: CL_R of CL_UNORM_INT8 /
     * CL_UNORM_INT16 (int16 biased by 32768) or normalised CL_FLOAT. */
    cl_mem slabs[UMBRA__MAX_SLABS];
    uint32_t slab_count;
    uint32_t slab_step;
    umbra_scalar_type stored_type; /* element type on the device (kernels' UMBRA_VOXEL_T) */
    float value_map[3];      /* UmbraFrame.value_map: stored value s -> clamp((s [2] - [0]) [1]) */
    int clamps;              /* some stored value maps outside [0,1] (kernels' UMBRA_VOXEL_CLAMPS) */
    uint64_t id;             /* unique per volume, for cache invalidation */
    size_t device_bytes;
    /* Index-to-world transform. The kernels work in the local frame (the centred, axis-aligned
     * box); the host maps world inputs into it. Without a transform (transformed 0) world and
     * local coincide and the maps copy their input, so default scenes stay bit for bit. */
    int transformed;
    double origin[3];        /* world position of voxel (0, 0, 0)'s centre */
    double axes[9];          /* orthonormal world direction of index axis a in axes[3a..3a+2] */
    double centre0[3];       /* local position of voxel (0, 0, 0)'s centre, (0.5 - dims/2) spacing */
    /* Channels and labels (volume.h). With channels > 1 the tables above hold channel 0's
     * ranges followed by each further channel's (brick_minmax: 2 nbricks floats a channel,
     * cell_minmax: 2 ncells), every channel's voxels lie in slabs[0] one after the other
     * (dims[0] dims[1] dims[2] + 1 elements each: the pad), and channel c's value map and range
     * are channel_map[c], channel_range[c] (channel 0's also in value_map, value_min/max). A
     * label map keeps the raw labels in its tables and one buffer. */
    uint32_t channels;
    int labels;
    float channel_map[UMBRA_MAX_CHANNELS][3];
    float channel_range[UMBRA_MAX_CHANNELS][2];
    double range_d[UMBRA_MAX_CHANNELS][2]; /* each channel's value range in double, as its
                                mapping was made */
    int stored_form;         /* UMBRA__STORED_* */
    umbra_scalar_type input_type; /* the type the voxels were given in (and updates give) */
    /* Updates (umbra_volume_update, host/volume_update.c): version counts them; ranges_version
     * counts those that changed some brick or sub-cell range (renderers remake their
     * visibility tables then); cell_clamps flags the sub-cells (per channel) whose footprint
     * holds a voxel outside the value range, clamp_cells counts them (clamps = clamp_cells > 0
     * for the forms that normalise in the kernels). */
    uint64_t version, ranges_version;
    unsigned char *cell_clamps;
    size_t clamp_cells;
    /* A part of a global grid (umbra/part.h, host/part.c): grid_dims is the grid the world box,
     * the frame and the rays are made of (dims for a whole volume, the global dims for a part);
     * part says where the carried voxels (dims) lie in it. */
    uint32_t grid_dims[3];
    int is_part;
    umbra_part_desc part;
};
#endif

/* What bounds a volume on a device: its largest allocation (lowered by the test knob below), its
 * global memory and, for the image sampler, its largest 3D image (width, height, depth). */
typedef struct umbra__device_limits {
    uint64_t max_alloc;
    uint64_t global_mem;
    size_t image_max[3];
} umbra__device_limits;

/* Queries ctx's device; image_max is queried only when image is nonzero (else zeros).
 * host/volume_slabs.c. */
umbra_status umbra__device_limits_get(umbra_context ctx, int image, umbra__device_limits *out);

/* Tests only: pretend ctx's device allocates at most bytes at once (0: the device's own limit),
 * so that a small volume is split into slabs. Volumes created afterwards see it. */
void umbra__context_limit_alloc(umbra_context ctx, uint64_t bytes);

/* Splits dims (voxel_bytes per voxel) into the fewest z-slabs that each fit lim (one slab when
 * the whole volume fits): *count slabs, slab s starting at layer s * *step (the step is dims[2]
 * for one slab), *bytes on the device in all, aprons and buffers' pad elements
 * included. UMBRA_ERROR_OUT_OF_MEMORY with a
 * message naming the sizes when the slabs would exceed the device's global memory, two layers
 * exceed one allocation, or more than UMBRA__MAX_SLABS slabs would be needed;
 * UMBRA_ERROR_UNSUPPORTED when a layer is wider or taller than the device's largest 3D image. */
umbra_status umbra__slabs_plan(umbra_context ctx, const uint32_t dims[3], size_t voxel_bytes,
                               int image, const umbra__device_limits *lim, uint32_t *count,
                               uint32_t *step, uint64_t *bytes);

/* Creates v's slabs (sets v->slab_count, slab_step, device_bytes) for voxels of voxel_bytes
 * each: buffers, or 3D images of format fmt when fmt is not NULL; filled from voxels (dims[0] *
 * dims[1] * dims[2] values, x fastest, copied) unless it is NULL (the caller then writes each
 * slab's layers, umbra__slab_layers). On failure the slabs made so far stay in v->slabs for
 * umbra_volume_release. */
umbra_status umbra__slabs_create(umbra_context ctx, umbra_volume v, size_t voxel_bytes,
                                 const cl_image_format *fmt, const void *voxels);

/* The voxel layers [*z0, *z1] (inclusive) that slab s of v holds. */
void umbra__slab_layers(umbra_volume v, uint32_t s, uint32_t *z0, uint32_t *z1);

/* Reads v's voxels back from its slabs into out (dims[0] * dims[1] * dims[2] values of
 * voxel_bytes each, as the device holds them, x fastest). Blocks. */
umbra_status umbra__slabs_read(umbra_volume v, void *out, size_t voxel_bytes);

/* v's voxels read back and normalised to [0,1] as the kernels normalise them (voxel_normalise in
 * kernels/common/sampling.cl): dims[0] * dims[1] * dims[2] floats into out, x fastest. Blocks. */
umbra_status umbra__volume_read_normalised(umbra_volume v, float *out);

/* The first of count float voxels that is NaN or infinite, or count when all are finite; in
 * parallel (host/volume_ranges.c). */
size_t umbra__first_nonfinite(const float *data, size_t count);

/* The raw min and max (in type's values, as floats) over the footprint of every sub-cell and
 * brick of the bricks [b0, b0 + nb) per axis of v's brick grid, from block, the voxels
 * [origin, origin + bdims) of one channel (x fastest, of type), which must hold those
 * footprints: 2 floats per sub-cell into cells (brick-major over the nb bricks,
 * UMBRA_BRICK_CELLS^3 a brick, x fastest) and per brick into bricks. In parallel; 0 when out of
 * memory (host/volume_ranges.c). */
int umbra__block_ranges(umbra_volume v, const void *block, umbra_scalar_type type,
                        const uint32_t origin[3], const uint32_t bdims[3], const uint32_t b0[3],
                        const uint32_t nb[3], float *cells, float *bricks);

/* How a volume's voxels are stored on the device (umbra_volume_t.stored_form). */
enum {
    UMBRA__STORED_RAW,        /* the input's values as they are */
    UMBRA__STORED_BIASED_U16, /* int16 + 32768 as uint16 (a CL_UNORM_INT16 image) */
    UMBRA__STORED_NORMALISED  /* normalised float32, computed in double as the range's mapping
                                 is */
};

/* Voxels first .. first + n - 1 of src (of type) in stored form `form` (not RAW) into dst:
 * biased, or normalised by (v - lo) scale and clamped to [0, 1] (host/volume.c). */
void umbra__convert_voxels(const void *src, umbra_scalar_type type, size_t first, size_t n,
                           int form, double lo, double scale, void *dst);

/* Values first .. first + n - 1 of channel c of src (channels values of esize bytes per voxel,
 * interleaved) into dst, one after the other (host/volume.c). */
void umbra__channel_copy(const void *src, size_t esize, uint32_t channels, uint32_t c,
                         size_t first, size_t n, void *dst);

/* Raw ranges (n floats of channel c, in the input's values) mapped in place to the normalised
 * values the kernels see, clamped to [0, 1], as the volume was made (host/volume.c). */
void umbra__map_ranges(umbra_volume v, uint32_t c, float *values, size_t n);

/* Nonzero when v keeps its voxels in 3D images: the image sampler's plain scalar volumes (a
 * multi-channel volume or a label map is one buffer on every sampler). */
int umbra__volume_images(umbra_volume v);

/* Validates desc's index-to-world transform and sets v's (the identity map without one);
 * UMBRA_ERROR_UNSUPPORTED for sheared axes. host/world.c. */
umbra_status umbra__volume_set_transform(umbra_context ctx, const umbra_volume_desc *desc,
                                         umbra_volume v);
/* World -> local: l_a = axes_a . (w - origin) + centre0_a (points), axes_a . w (directions). */
void umbra__volume_point_to_local(umbra_volume v, const float w[3], float out[3]);
void umbra__volume_dir_to_local(umbra_volume v, const float w[3], float out[3]);
/* Local -> world: origin + sum_a axes_a (l_a - centre0_a). */
void umbra__volume_point_to_world(umbra_volume v, const float l[3], double out[3]);

/* ---- transfer function ---------------------------------------------------------------------- */

#ifndef __cplusplus
struct umbra_transfer_function_t {
    atomic_int refs;
    umbra_context ctx;
    uint32_t count;
    float *rgba;             /* host copy, 4*count */
    cl_mem buffer;           /* device copy, float4 per entry */
    uint64_t id;             /* unique per table (and per range: set_range gives a new id) */
    int range_given;         /* nonzero: the table spans data values range_lo..range_hi */
    float range_lo, range_hi;
};
#endif

/* The table tf means for a volume whose normalised range [0,1] stands for data values
 * value_min..value_max: tf itself (retained) when it has no data range, else a new table over
 * [0,1] resampled from tf's range (values outside it take the end entries), with 16 entries per
 * entry of tf (up to 65536), so a jump of J between two of tf's entries is kept to within J/64. */
umbra_status umbra__tf_for_volume(umbra_transfer_function tf, float value_min, float value_max,
                                  umbra_transfer_function *out);

/* ---- processes ---------------------------------------------------------------------------- */

/* OpenCL does not survive fork(): the implementation's threads (PoCL's device workers) are gone
 * in the child, whose commands then wait forever. Every entry point that would enqueue or
 * create OpenCL objects calls this first: UMBRA_ERROR_UNSUPPORTED, with a message naming fn and
 * saying what to do, when the calling process is not the one that created ctx. */
umbra_status umbra__check_process(umbra_context ctx, const char *fn);

/* Nonzero in a process forked from the one that created ctx: the *_release functions then leave
 * the object alone (its OpenCL objects belong to the parent; freeing them could touch the
 * parent's device state), which frees nothing in the child. */
int umbra__forked(umbra_context ctx);

/* A process-wide counter would be a mutable global; ids come from the context instead. */
uint64_t umbra__next_id(umbra_context ctx);

#endif
