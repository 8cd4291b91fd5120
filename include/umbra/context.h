/* umbra/context.h: the OpenCL device umbra runs on.
 *
 * A context owns the OpenCL context, device and queue (or retains the application's), the cache of
 * built programs, and the error state. Every other umbra object belongs to one context and keeps
 * it alive.
 *
 * Threads. Contexts may be created, used and released on any threads at once (device discovery
 * is serialised inside umbra_context_create, as OpenCL start-up is process-wide); two contexts
 * never interfere. Objects of one context may also be used on different threads at once (two
 * renderers rendering on two threads share the program cache, the queue and the error state
 * safely; reference counts are atomic), but each object (a renderer, a volume being created or
 * released) by one thread at a time. The error state is then shared: umbra_context_take_error
 * and umbra_context_last_message return whichever thread's error came first or last, and their
 * message pointers may be overwritten by the next error on any thread; for per-call errors across
 * threads, use the callback, which runs on the thread whose call failed. */
#ifndef UMBRA_CONTEXT_H
#define UMBRA_CONTEXT_H

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>
#include <stddef.h>

#include "umbra/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_context_t *umbra_context;

/* How volumes are sampled on the device: a plain buffer with hand-written trilinear
 * interpolation, or a 3D image with the sampler's linear filtering. AUTO picks per device: the
 * buffer on CPU devices (on PoCL it measured about 3x faster), the image on GPUs that support
 * single-channel float images. */
typedef enum umbra_sampler_kind {
    UMBRA_SAMPLER_AUTO = 0,
    UMBRA_SAMPLER_BUFFER = 1,
    UMBRA_SAMPLER_IMAGE = 2
} umbra_sampler_kind;

typedef struct umbra_context_desc {
    size_t struct_size;            /* sizeof(umbra_context_desc); set by umbra_context_desc_init */
    int platform_index;            /* -1: any platform */
    int device_index;              /* -1: the first device that matches */
    const char *device_name;       /* substring of platform or device name, or NULL; copied */
    int use_environment;           /* nonzero (default): UMBRA_DEVICE="P:D" or a name substring
                                      is used when the fields above are left at their defaults */
    umbra_sampler_kind sampler;    /* default AUTO */
    const char *cache_dir;         /* PoCL kernel cache; NULL: $POCL_CACHE_DIR if set, else a
                                      directory under the system temporary directory */
    umbra_error_callback error_callback; /* optional; also called for errors during creation */
    void *error_user;              /* passed to error_callback */
} umbra_context_desc;

/* Fills desc with the defaults. */
void umbra_context_desc_init(umbra_context_desc *desc);

/* Creates a context on the device desc selects (desc may be NULL for defaults). On failure *out is
 * NULL and the reason went to desc->error_callback, if any. Blocks while OpenCL initialises. */
umbra_status umbra_context_create(const umbra_context_desc *desc, umbra_context *out);

/* Creates a context on the application's OpenCL objects, which are retained (never released
 * beyond that retain, never destroyed). queue must belong to cl_ctx and device. */
umbra_status umbra_context_create_from_cl(cl_context cl_ctx, cl_device_id device,
                                          cl_command_queue queue,
                                          const umbra_context_desc *desc, umbra_context *out);

void umbra_context_retain(umbra_context ctx);
/* Drops one reference; the context is destroyed when the last umbra object using it is gone.
 * NULL is a no-op. */
void umbra_context_release(umbra_context ctx);

/* Returns the first error recorded since the last call (UMBRA_SUCCESS if none) and clears it. If
 * message is not NULL it receives that error's message, owned by the context and valid until the
 * next call on this context. */
umbra_status umbra_context_take_error(umbra_context ctx, const char **message);

/* The message of the most recent error, or "" if none; owned by the context, valid until the next
 * failing call. */
const char *umbra_context_last_message(umbra_context ctx);

/* Installs (or with NULL removes) the error callback. */
void umbra_context_set_error_callback(umbra_context ctx, umbra_error_callback cb, void *user);

/* "platform / device" names, owned by the context. */
const char *umbra_context_device_name(umbra_context ctx);

/* The sampler back end actually in use (never AUTO). */
umbra_sampler_kind umbra_context_sampler(umbra_context ctx);

/* The OpenCL objects in use (borrowed: retain them to keep them). */
cl_context umbra_context_cl_context(umbra_context ctx);
cl_device_id umbra_context_cl_device(umbra_context ctx);
cl_command_queue umbra_context_cl_queue(umbra_context ctx);

#ifdef __cplusplus
}
#endif
#endif
