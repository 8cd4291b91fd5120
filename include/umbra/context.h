// SPDX-License-Identifier: Apache-2.0
/* umbra/context.h: the OpenCL device umbra runs on, and the contract with the application.
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
 * released) by one thread at a time (a call on a renderer in the middle of a render on another
 * thread is refused, UMBRA_ERROR_INVALID_ARGUMENT). The error state is then shared: umbra_context_take_error
 * and umbra_context_last_message return whichever thread's error came first or last, and their
 * message pointers may be overwritten by the next error on any thread; for per-call errors across
 * threads, use the callback, which runs on the thread whose call failed.
 *
 * The OpenCL contract (what umbra does with an application's OpenCL objects; each point is
 * pinned by a test in tests/test_context.c):
 *
 * 1. Ownership. The cl_context, device and queue given to umbra_context_create_from_cl are
 *    retained until the context is destroyed, then released; umbra never destroys them or changes
 *    their settings. A cl_mem given to a renderer is used only during the call (the asynchronous
 *    call: until its event completes, as OpenCL keeps objects alive for enqueued commands).
 *
 * 2. Buffers. A cl_mem the application passes must be a buffer (CL_MEM_OBJECT_BUFFER; a
 *    sub-buffer is one) of the context's cl_context, writable by kernels (not CL_MEM_READ_ONLY)
 *    and large enough. An image, a pipe, a read-only buffer, a buffer of another cl_context, a
 *    buffer too small or an invalid handle is refused with UMBRA_ERROR_INVALID_ARGUMENT and a
 *    message naming the value; nothing is enqueued then. umbra writes only the bytes it renders.
 *
 * 3. Queues and ordering. umbra's commands depend on each other in the order it enqueues them.
 *    - An in-order queue is used as is: umbra's commands run after everything the application
 *      enqueued on it before the call and before what it enqueues after.
 *    - An out-of-order queue (CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE) is accepted: umbra then
 *      creates an in-order queue of its own on the same cl_context and device (with profiling)
 *      and enqueues there; umbra_context_cl_queue returns that queue. Its commands are not
 *      ordered after the application's: make sure the application's commands that touch a buffer
 *      given to umbra have completed (clFinish, clWaitForEvents), or pass their events to
 *      umbra_renderer_render_to_cl_buffer_async; this is what an out-of-order queue asks between
 *      any two commands anyway. Every technique gives the same pixels as on an in-order queue.
 *    The blocking calls (umbra_renderer_render, _render_to_cl_buffer, _query_shadow) return after
 *    umbra's commands completed. umbra_renderer_render_to_cl_buffer_async (renderer.h) returns
 *    once they are enqueued, with an event that completes with them.
 *
 * 4. Timing. umbra_render_stats says where its times come from (umbra_timing): device times
 *    from the events' profiling counters when the queue umbra uses has CL_QUEUE_PROFILING_ENABLE
 *    (umbra's own queues always have it), else the host's wall clock from enqueue to completion,
 *    which includes any work queued ahead of umbra's.
 *
 * 5. Process-wide state. umbra's only mutable globals are mutexes and one process id: a mutex
 *    serialises device discovery (OpenCL start-up is process-wide, and PoCL's is not
 *    thread-safe), umbra_io holds one each around Teem, nifticlib and cJSON, which keep
 *    process-wide state of their own, and umbra records which process first started OpenCL.
 *    OpenCL does not survive fork() (PoCL's device threads do not exist in the child, whose
 *    commands wait forever): in a child forked after that, every call that would use OpenCL
 *    (context, volume and transfer-function creation, renders, queries) returns
 *    UMBRA_ERROR_UNSUPPORTED at once with a message saying what to do, and releasing inherited
 *    objects frees nothing (they are the parent's). Create contexts in the process that uses
 *    them, after any fork() (Python: multiprocessing's "spawn" or "forkserver" start method).
 *    umbra installs no signal or exit handlers and starts no threads (the OpenCL implementation
 *    may). It touches the environment only in
 *    umbra_context_create, and the application can turn each off in the description:
 *    - set_pocl_cache_dir (default 1): if POCL_CACHE_DIR is unset, umbra creates cache_dir (or
 *      $TMPDIR/umbra-pocl-cache-<uid>, else under /tmp; mode 0700) and sets POCL_CACHE_DIR to it
 *      with setenv(3), before OpenCL starts, because PoCL cannot build kernels without a writable
 *      cache. setenv is not safe while another thread reads the environment. With 0 umbra neither
 *      reads nor writes POCL_CACHE_DIR or TMPDIR.
 *    - use_environment (default 1): UMBRA_DEVICE is read (getenv) when no device is chosen in
 *      the description. With 0 it is not read.
 *    umbra_context_create_from_cl reads and writes no environment variable. */
#ifndef UMBRA_CONTEXT_H
#define UMBRA_CONTEXT_H

/* umbra uses OpenCL 1.2 calls only, and any target the application chooses with
 * CL_TARGET_OPENCL_VERSION compiles against these declarations. An application that chose none
 * gets the OpenCL headers' own default, 3.0 (300), as CL/cl_version.h would set it, only without
 * the note cl_version.h prints into every file that includes this header. */
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 300
#endif
#include <CL/cl.h>
#include <stddef.h>

#include "umbra/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_context_t *umbra_context;

/* How volumes are sampled on the device: a plain buffer with hand-written trilinear
 * interpolation in float, or a 3D image with the sampler's linear filtering. AUTO is the buffer
 * on every device: faster on PoCL, and exact where a GPU's texture filter interpolates with
 * fixed-point weights (9 bits in CUDA's documentation), which shading and sharp transfer
 * functions magnify (measured: docs/architecture.md, "Samplers"; docs/performance.md).
 * IMAGE, where the device has single-channel float 3D images, is for comparison. */
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
    /* Fields below were added after the first layout; a desc whose struct_size is that layout's
     * size (offsetof(umbra_context_desc, set_pocl_cache_dir)) is accepted with their defaults. */
    int set_pocl_cache_dir;        /* nonzero (default): umbra_context_create may set
                                      POCL_CACHE_DIR (contract point 5); 0: never */
} umbra_context_desc;

/* Fills desc with the defaults (struct_size included). */
UMBRA_API void umbra_context_desc_init(umbra_context_desc *desc);

/* Creates a context on the device desc selects (desc may be NULL for defaults). On failure *out is
 * NULL and the reason went to desc->error_callback, if any. Blocks while OpenCL initialises. */
UMBRA_API umbra_status umbra_context_create(const umbra_context_desc *desc, umbra_context *out);

/* Creates a context on the application's OpenCL objects, which are retained (never released
 * beyond that retain, never destroyed). queue must belong to cl_ctx and device; it may be in-order
 * or out-of-order (contract point 3). desc may be NULL; its device fields and set_pocl_cache_dir
 * are not used. UMBRA_ERROR_INVALID_ARGUMENT for a NULL handle or a queue of another context or
 * device. Touches no process-wide state. */
UMBRA_API umbra_status umbra_context_create_from_cl(cl_context cl_ctx, cl_device_id device,
                                                    cl_command_queue queue,
                                                    const umbra_context_desc *desc,
                                                    umbra_context *out);

/* Adds one reference (for an application that keeps the context beyond its objects). NULL is a
 * no-op. */
UMBRA_API void umbra_context_retain(umbra_context ctx);
/* Drops one reference; the context is destroyed when the last umbra object using it is gone.
 * NULL is a no-op. */
UMBRA_API void umbra_context_release(umbra_context ctx);

/* Returns the first error recorded since the last call (UMBRA_SUCCESS if none) and clears it. If
 * message is not NULL it receives that error's message, owned by the context and valid until the
 * next call on this context. */
UMBRA_API umbra_status umbra_context_take_error(umbra_context ctx, const char **message);

/* The message of the most recent error, or "" if none; owned by the context, valid until the next
 * failing call. */
UMBRA_API const char *umbra_context_last_message(umbra_context ctx);

/* Records an error on ctx exactly as umbra's own functions do (sticky first error, last message,
 * callback) and returns status. For layers built on the public API, such as umbra_io; message is
 * copied (truncated to 8191 bytes). ctx NULL: nothing is recorded. */
UMBRA_API umbra_status umbra_context_record_error(umbra_context ctx, umbra_status status,
                                                  const char *message);

/* Installs (or with NULL removes) the error callback. */
UMBRA_API void umbra_context_set_error_callback(umbra_context ctx, umbra_error_callback cb,
                                                void *user);

/* "platform / device" names, owned by the context. */
UMBRA_API const char *umbra_context_device_name(umbra_context ctx);

/* The sampler back end actually in use (never AUTO). */
UMBRA_API umbra_sampler_kind umbra_context_sampler(umbra_context ctx);

/* The OpenCL objects in use (borrowed: retain them to keep them). The queue is the one umbra
 * enqueues on: the application's in-order queue, or umbra's own in-order queue when the
 * application gave an out-of-order one (contract point 3). */
UMBRA_API cl_context umbra_context_cl_context(umbra_context ctx);
UMBRA_API cl_device_id umbra_context_cl_device(umbra_context ctx);
UMBRA_API cl_command_queue umbra_context_cl_queue(umbra_context ctx);

#ifdef __cplusplus
}
#endif
#endif
