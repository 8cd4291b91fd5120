/* host/internal.h: what the host modules share and the public API does not show.
 *
 * Error recording (one helper, one OpenCL check macro), the context's program cache, and the
 * internals of volumes and transfer functions. Internal names start with "umbra__". */
#ifndef UMBRA_HOST_INTERNAL_H
#define UMBRA_HOST_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

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

struct umbra_context_t {
    int refs;
    cl_platform_id platform;
    cl_context cl_ctx;
    cl_device_id device;
    cl_command_queue queue;
    int is_cpu;
    int has_float_r_image3d;
    umbra_sampler_kind sampler;
    char device_name[600];              /* "platform / device": two 256-byte names */
    umbra__program *programs;           /* cache: one entry per (sources, options) */
    umbra_status first_error;           /* sticky until umbra_context_take_error */
    char first_message[UMBRA_MESSAGE_MAX];
    char last_message[UMBRA_MESSAGE_MAX];
    umbra_error_callback callback;
    void *callback_user;
    uint64_t next_id;                   /* source of volume / transfer-function ids */
};

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

/* Milliseconds between an event's start and end (profiling is enabled on umbra's own queues;
 * on an application queue without profiling, wall-clock time around clFinish is used). */
double umbra__event_ms(cl_event ev);
double umbra__now_ms(void);

/* ---- volume ---------------------------------------------------------------------------------- */

struct umbra_volume_t {
    int refs;
    umbra_context ctx;
    uint32_t dims[3];
    float spacing[3];
    float value_min, value_max;
    uint32_t brick_size;
    uint32_t brick_counts[3];
    float *brick_minmax;     /* host: 2 floats (normalised min, max) per brick */
    float *cell_minmax;      /* host: the same per sub-cell, UMBRA_BRICK_CELLS^3 per brick,
                                brick-major, x fastest (kernels/umbra_shared.h) */
    cl_mem data;             /* normalised float32 voxels (buffer sampler) */
    cl_mem image;            /* CL_R / CL_FLOAT 3D image (image sampler), or NULL */
    uint64_t id;             /* unique per volume, for cache invalidation */
    size_t device_bytes;
};

/* ---- transfer function ---------------------------------------------------------------------- */

struct umbra_transfer_function_t {
    int refs;
    umbra_context ctx;
    uint32_t count;
    float *rgba;             /* host copy, 4*count */
    cl_mem buffer;           /* device copy, float4 per entry */
    uint64_t id;             /* unique per table */
};

/* The most control points a transfer function may be built from (the most table entries too). */
#define UMBRA__TF_MAX_POINTS 65536u

/* A process-wide counter would be a mutable global; ids come from the context instead. */
uint64_t umbra__next_id(umbra_context ctx);

/* ---- helpers shared by the I/O modules -------------------------------------------------------- */

/* Reads a whole file into a malloc'ed buffer, followed by one NUL byte not counted in *size (the
 * text parsers rely on it). Regular files only (see umbra__file_open). */
umbra_status umbra__read_file(umbra_context ctx, const char *func, const char *path, void **data,
                              size_t *size);

/* Opens path for reading if it is a regular file, without ever blocking (a FIFO or device is
 * refused, not waited on), and gives its size. The FILE is the caller's to fclose. Every reader of
 * umbra opens its files through this. func names the public function in messages. */
umbra_status umbra__file_open(umbra_context ctx, const char *func, const char *path, FILE **out,
                              size_t *size);

/* Reads exactly size bytes of f (which is path) into dst, or fails naming how many came. */
umbra_status umbra__file_read(umbra_context ctx, const char *func, const char *path, FILE *f,
                              void *dst, size_t size);

/* strerror_r into buf; thread-safe. */
const char *umbra__errno_text(int err, char *buf, size_t n);

/* The one integer parser of the file readers: the n characters at s must be decimal digits only
 * (no sign, blank or other trailing text) and the value at most max. Returns 1 and sets *out, else
 * 0 (also on overflow). */
int umbra__parse_uint(const char *s, size_t n, uint64_t max, uint64_t *out);

int umbra__host_is_big_endian(void);
void umbra__swap_bytes(void *data, size_t count, size_t width);

/* Hands voxels in host memory (copied) to umbra_volume_create. */
umbra_status umbra__volume_from_host(umbra_context ctx, const void *data, umbra_scalar_type type,
                                     const uint32_t dims[3], const float spacing[3],
                                     umbra_volume *out);

#endif
