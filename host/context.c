// SPDX-License-Identifier: Apache-2.0
/* host/context.c: choosing an OpenCL device, owning (or retaining) its context and queue, and
 * the per-context cache of built programs.
 *
 * Device choice, in order: desc's platform/device indices or name substring; else, with
 * use_environment, $UMBRA_DEVICE ("P:D" indices or a name substring); else the first GPU, else
 * the first device of any type. PoCL needs a writable kernel cache: with set_pocl_cache_dir and
 * unless $POCL_CACHE_DIR is set, it is pointed at desc->cache_dir or a directory under $TMPDIR
 * (or /tmp) before OpenCL starts, so a user whose HOME is read-only still gets a working context.
 *
 * umbra's host code relies on its commands running in the order it enqueues them (a kernel reads
 * what the previous one wrote; a blocking read follows the kernel it reads). On an application's
 * out-of-order queue that order does not hold, so umbra makes its own in-order queue on the
 * application's context and device and enqueues there (include/umbra/context.h, "The OpenCL
 * contract").
 *
 * Threads: OpenCL start-up is process-wide and PoCL's lazy device set-up is not thread-safe (two
 * threads creating the first contexts crashed in clGetDeviceInfo), and setenv races with every
 * getenv: umbra_context_create does device discovery and creation under one process-wide mutex,
 * the only mutable global in umbra, which exists because the state it guards is process-wide. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "internal.h"

static pthread_mutex_t discovery_lock = PTHREAD_MUTEX_INITIALIZER;

/* The process in which umbra first started OpenCL (0: none yet). OpenCL's state is process-wide
 * and does not survive fork(), so this describes the process, not a context: a forked child
 * sees its parent's pid here, and umbra_context_create refuses instead of hanging. */
static atomic_long opencl_pid;

static const char *const fork_advice =
    "OpenCL does not work in a child made by fork() after it was started: create umbra contexts "
    "only in the process that uses them, after any fork() (in Python, use multiprocessing's "
    "'spawn' or 'forkserver' start method)";

umbra_status umbra__check_process(umbra_context ctx, const char *fn)
{
    if (!ctx || ctx->pid == (long)getpid())
        return UMBRA_SUCCESS;
    return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                       "%s: this process (pid %ld) was forked from the one that created the "
                       "context (pid %ld); %s", fn, (long)getpid(), ctx->pid, fork_advice);
}

int umbra__forked(umbra_context ctx) { return ctx && ctx->pid != (long)getpid(); }

static void report(const umbra_context_desc *desc, umbra_status st, const char *fmt, ...)
    UMBRA_PRINTF(3, 4);

/* Records that OpenCL is in use in this process, or refuses (reporting through desc) when it
 * was started in a parent before fork(). */
static umbra_status claim_process(const umbra_context_desc *desc, const char *fn)
{
    long none = 0, self = (long)getpid();
    if (atomic_compare_exchange_strong(&opencl_pid, &none, self) || none == self)
        return UMBRA_SUCCESS;
    report(desc, UMBRA_ERROR_UNSUPPORTED,
           "%s: this process (pid %ld) was forked from one (pid %ld) that had started OpenCL; %s",
           fn, self, none, fork_advice);
    return UMBRA_ERROR_UNSUPPORTED;
}

struct umbra__program {
    umbra__program *next;
    char *key;          /* file names and options: what makes two programs the same */
    cl_program program;
};

void umbra_context_desc_init(umbra_context_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
    desc->platform_index = -1;
    desc->device_index = -1;
    desc->use_environment = 1;
    desc->sampler = UMBRA_SAMPLER_AUTO;
    desc->set_pocl_cache_dir = 1;
}

static void report(const umbra_context_desc *desc, umbra_status st, const char *fmt, ...)
{
    if (!desc || !desc->error_callback)
        return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    desc->error_callback(desc->error_user, st, msg);
}

/* PoCL reads POCL_CACHE_DIR when the platform initialises; set it only if the user has not, and
 * only if the application lets umbra touch its environment. */
static void prepare_pocl_cache(const umbra_context_desc *desc)
{
    if (!desc->set_pocl_cache_dir || getenv("POCL_CACHE_DIR"))
        return;
    char dir[1024];
    if (desc && desc->cache_dir) {
        snprintf(dir, sizeof dir, "%s", desc->cache_dir);
    } else {
        const char *tmp = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/umbra-pocl-cache-%ld", tmp && *tmp ? tmp : "/tmp",
                 (long)getuid());
    }
    if (mkdir(dir, 0700) == 0 || errno == EEXIST)
        setenv("POCL_CACHE_DIR", dir, 0);
}

static int contains_ci(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; ++hay) {
        size_t i = 0;
        while (i < n && hay[i] && tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            ++i;
        if (i == n)
            return 1;
    }
    return n == 0;
}

typedef struct selection {
    int platform, device;
    const char *name;
} selection;

static selection selection_from(const umbra_context_desc *d)
{
    selection s = {d->platform_index, d->device_index, d->device_name};
    if (s.platform < 0 && s.device < 0 && !s.name && d->use_environment) {
        const char *env = getenv("UMBRA_DEVICE");
        int p, q;
        char tail;
        if (env && *env) {
            if (sscanf(env, "%d:%d%c", &p, &q, &tail) == 2) {
                s.platform = p;
                s.device = q;
            } else {
                s.name = env;
            }
        }
    }
    return s;
}

static umbra_status pick_device(const umbra_context_desc *desc, cl_platform_id *out_platform,
                                cl_device_id *out_device)
{
    cl_platform_id platforms[16];
    cl_uint np = 0;
    selection sel = selection_from(desc);
    cl_int err = clGetPlatformIDs(16, platforms, &np);
    if (err != CL_SUCCESS || np == 0) {
        report(desc, UMBRA_ERROR_NO_DEVICE,
               "umbra_context_create: no OpenCL platform found (clGetPlatformIDs: %s); install an "
               "ICD such as pocl-opencl-icd", umbra__cl_error_name(err));
        return UMBRA_ERROR_NO_DEVICE;
    }
    /* Two passes without an explicit choice: GPUs first, then anything. */
    for (int pass = 0; pass < 2; ++pass) {
        cl_device_type want = (pass == 0 && sel.platform < 0 && sel.device < 0 && !sel.name)
                                  ? CL_DEVICE_TYPE_GPU
                                  : CL_DEVICE_TYPE_ALL;
        for (cl_uint p = 0; p < np; ++p) {
            if (sel.platform >= 0 && (cl_uint)sel.platform != p)
                continue;
            cl_device_id devices[64];
            cl_uint nd = 0;
            if (clGetDeviceIDs(platforms[p], want, 64, devices, &nd) != CL_SUCCESS)
                continue;
            char pname[256] = "";
            clGetPlatformInfo(platforms[p], CL_PLATFORM_NAME, sizeof pname, pname, NULL);
            for (cl_uint i = 0; i < nd; ++i) {
                if (sel.device >= 0 && (cl_uint)sel.device != i)
                    continue;
                char dname[256] = "";
                clGetDeviceInfo(devices[i], CL_DEVICE_NAME, sizeof dname, dname, NULL);
                if (sel.name && !contains_ci(dname, sel.name) && !contains_ci(pname, sel.name))
                    continue;
                *out_platform = platforms[p];
                *out_device = devices[i];
                return UMBRA_SUCCESS;
            }
        }
    }
    report(desc, UMBRA_ERROR_NO_DEVICE,
           "umbra_context_create: no OpenCL device matches platform %d, device %d, name '%s' "
           "(%u platforms found)", sel.platform, sel.device, sel.name ? sel.name : "",
           (unsigned)np);
    return UMBRA_ERROR_NO_DEVICE;
}

/* Fills the device facts and picks the sampler back end. */
static void describe_device(umbra_context ctx, const umbra_context_desc *desc)
{
    char pname[256] = "", dname[256] = "";
    cl_bool images = CL_FALSE;
    clGetPlatformInfo(ctx->platform, CL_PLATFORM_NAME, sizeof pname, pname, NULL);
    clGetDeviceInfo(ctx->device, CL_DEVICE_NAME, sizeof dname, dname, NULL);
    clGetDeviceInfo(ctx->device, CL_DEVICE_IMAGE_SUPPORT, sizeof images, &images, NULL);
    snprintf(ctx->device_name, sizeof ctx->device_name, "%s / %s", pname, dname);

    ctx->has_float_r_image3d = ctx->has_unorm8_r_image3d = ctx->has_unorm16_r_image3d = 0;
    if (images) {
        cl_image_format formats[256];
        cl_uint nf = 0;
        if (clGetSupportedImageFormats(ctx->cl_ctx, CL_MEM_READ_ONLY, CL_MEM_OBJECT_IMAGE3D, 256,
                                       formats, &nf) == CL_SUCCESS) {
            for (cl_uint i = 0; i < nf && i < 256; ++i) {
                if (formats[i].image_channel_order != CL_R)
                    continue;
                cl_channel_type t = formats[i].image_channel_data_type;
                ctx->has_float_r_image3d |= t == CL_FLOAT;
                ctx->has_unorm8_r_image3d |= t == CL_UNORM_INT8;
                ctx->has_unorm16_r_image3d |= t == CL_UNORM_INT16;
            }
        }
    }
    /* AUTO is the buffer on every device (context.h says why: exact trilinear weights). */
    umbra_sampler_kind want = desc ? desc->sampler : UMBRA_SAMPLER_AUTO;
    if (want == UMBRA_SAMPLER_AUTO)
        want = UMBRA_SAMPLER_BUFFER;
    if (want == UMBRA_SAMPLER_IMAGE && !ctx->has_float_r_image3d)
        want = UMBRA_SAMPLER_BUFFER;
    ctx->sampler = want;
}

static umbra_status context_alloc(const umbra_context_desc *desc, umbra_context *out)
{
    umbra_context ctx = calloc(1, sizeof *ctx);
    if (!ctx) {
        report(desc, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_context_create: out of host memory");
        return UMBRA_ERROR_OUT_OF_MEMORY;
    }
    if (pthread_mutex_init(&ctx->program_lock, NULL) != 0) {
        free(ctx);
        report(desc, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_context_create: pthread_mutex_init failed");
        return UMBRA_ERROR_OUT_OF_MEMORY;
    }
    if (pthread_mutex_init(&ctx->error_lock, NULL) != 0) {
        pthread_mutex_destroy(&ctx->program_lock);
        free(ctx);
        report(desc, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_context_create: pthread_mutex_init failed");
        return UMBRA_ERROR_OUT_OF_MEMORY;
    }
    atomic_init(&ctx->refs, 1);
    atomic_init(&ctx->next_id, 0);
    ctx->pid = (long)getpid();
    if (desc) {
        ctx->callback = desc->error_callback;
        ctx->callback_user = desc->error_user;
    }
    *out = ctx;
    return UMBRA_SUCCESS;
}

/* The size of umbra_context_desc before set_pocl_cache_dir was added: callers built against that
 * layout are still accepted and get the new fields' defaults. */
#define DESC_SIZE_V1 offsetof(umbra_context_desc, set_pocl_cache_dir)

/* Checks desc and copies it, completed with defaults for fields an older layout lacks, into
 * *full (the defaults when desc is NULL). */
static int desc_ok(const umbra_context_desc *desc, umbra_context_desc *full)
{
    umbra_context_desc_init(full);
    if (!desc)
        return 1;
    if (desc->struct_size != sizeof *desc && desc->struct_size != DESC_SIZE_V1) {
        report(desc, UMBRA_ERROR_INVALID_ARGUMENT,
               "umbra_context_create: desc->struct_size %zu is neither %zu nor the older %zu: "
               "call umbra_context_desc_init", desc->struct_size, sizeof *desc,
               (size_t)DESC_SIZE_V1);
        return 0;
    }
    memcpy(full, desc, desc->struct_size);
    full->struct_size = sizeof *full;
    if (full->sampler < UMBRA_SAMPLER_AUTO || full->sampler > UMBRA_SAMPLER_IMAGE) {
        report(desc, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_context_create: sampler %d is unknown",
               (int)full->sampler);
        return 0;
    }
    return 1;
}

umbra_status umbra_context_create(const umbra_context_desc *desc, umbra_context *out)
{
    if (!out) {
        report(desc, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_context_create: out is NULL");
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    *out = NULL;
    umbra_context_desc full;
    if (!desc_ok(desc, &full))
        return UMBRA_ERROR_INVALID_ARGUMENT;
    desc = &full;

    umbra_status st = claim_process(desc, "umbra_context_create");
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_context ctx = NULL;
    if ((st = context_alloc(desc, &ctx)) != UMBRA_SUCCESS)
        return st;
    pthread_mutex_lock(&discovery_lock);
    prepare_pocl_cache(desc);
    st = pick_device(desc, &ctx->platform, &ctx->device);
    if (st != UMBRA_SUCCESS)
        goto fail;
    cl_int err;
    ctx->cl_ctx = clCreateContext(NULL, 1, &ctx->device, NULL, NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateContext");
    ctx->queue = clCreateCommandQueue(ctx->cl_ctx, ctx->device, CL_QUEUE_PROFILING_ENABLE, &err);
    UMBRA_CL_CHECK(err, "clCreateCommandQueue");
    ctx->profiling = 1;
    describe_device(ctx, desc);
    pthread_mutex_unlock(&discovery_lock);
    *out = ctx;
    return UMBRA_SUCCESS;
fail:
    pthread_mutex_unlock(&discovery_lock);
    umbra_context_release(ctx);
    return st;
}

umbra_status umbra_context_create_from_cl(cl_context cl_ctx, cl_device_id device,
                                          cl_command_queue queue,
                                          const umbra_context_desc *desc, umbra_context *out)
{
    if (!out || !cl_ctx || !device || !queue) {
        report(desc, UMBRA_ERROR_INVALID_ARGUMENT,
               "umbra_context_create_from_cl: cl_ctx %p, device %p, queue %p, out %p: none may "
               "be NULL", (void *)cl_ctx, (void *)device, (void *)queue, (void *)out);
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    *out = NULL;
    umbra_context_desc full;
    if (!desc_ok(desc, &full))
        return UMBRA_ERROR_INVALID_ARGUMENT;
    desc = &full;
    if (claim_process(desc, "umbra_context_create_from_cl") != UMBRA_SUCCESS)
        return UMBRA_ERROR_UNSUPPORTED;
    cl_context qctx = NULL;
    cl_device_id qdev = NULL;
    cl_command_queue_properties props = 0;
    if (clGetCommandQueueInfo(queue, CL_QUEUE_CONTEXT, sizeof qctx, &qctx, NULL) != CL_SUCCESS ||
        clGetCommandQueueInfo(queue, CL_QUEUE_DEVICE, sizeof qdev, &qdev, NULL) != CL_SUCCESS ||
        clGetCommandQueueInfo(queue, CL_QUEUE_PROPERTIES, sizeof props, &props, NULL) !=
            CL_SUCCESS ||
        qctx != cl_ctx || qdev != device) {
        report(desc, UMBRA_ERROR_INVALID_ARGUMENT,
               "umbra_context_create_from_cl: queue %p does not belong to context %p and device %p",
               (void *)queue, (void *)cl_ctx, (void *)device);
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    umbra_context ctx = NULL;
    umbra_status st = context_alloc(desc, &ctx);
    if (st != UMBRA_SUCCESS)
        return st;
    clRetainContext(cl_ctx);
    ctx->cl_ctx = cl_ctx;
    ctx->device = device;
    if (props & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE) {
        /* umbra's commands depend on each other in enqueue order: they go to an in-order queue
         * of umbra's own (with profiling, so the stats get device times). */
        cl_int err;
        ctx->queue = clCreateCommandQueue(cl_ctx, device, CL_QUEUE_PROFILING_ENABLE, &err);
        if (err != CL_SUCCESS) {
            ctx->queue = NULL;
            st = umbra__fail_cl(ctx, __func__,
                                "clCreateCommandQueue (an in-order queue beside the application's "
                                "out-of-order queue)", err, __FILE__, __LINE__);
            goto fail; /* the error callback (from desc) has seen it */
        }
        clRetainCommandQueue(queue);
        ctx->app_queue = queue;
        ctx->profiling = 1;
    } else {
        clRetainCommandQueue(queue);
        ctx->queue = queue;
        ctx->profiling = (props & CL_QUEUE_PROFILING_ENABLE) != 0;
    }
    clGetDeviceInfo(device, CL_DEVICE_PLATFORM, sizeof ctx->platform, &ctx->platform, NULL);
    describe_device(ctx, desc);
    *out = ctx;
    return UMBRA_SUCCESS;
fail:
    umbra_context_release(ctx);
    return st;
}

void umbra_context_retain(umbra_context ctx)
{
    if (ctx)
        atomic_fetch_add(&ctx->refs, 1);
}

void umbra_context_release(umbra_context ctx)
{
    if (!ctx || atomic_fetch_sub(&ctx->refs, 1) > 1 || umbra__forked(ctx))
        return;
    for (umbra__program *p = ctx->programs; p;) {
        umbra__program *next = p->next;
        clReleaseProgram(p->program);
        free(p->key);
        free(p);
        p = next;
    }
    if (ctx->queue)
        clReleaseCommandQueue(ctx->queue);
    if (ctx->app_queue)
        clReleaseCommandQueue(ctx->app_queue);
    if (ctx->cl_ctx)
        clReleaseContext(ctx->cl_ctx);
    pthread_mutex_destroy(&ctx->program_lock);
    pthread_mutex_destroy(&ctx->error_lock);
    free(ctx);
}

const char *umbra_context_device_name(umbra_context ctx) { return ctx ? ctx->device_name : ""; }
umbra_sampler_kind umbra_context_sampler(umbra_context ctx)
{
    return ctx ? ctx->sampler : UMBRA_SAMPLER_BUFFER;
}
cl_context umbra_context_cl_context(umbra_context ctx) { return ctx ? ctx->cl_ctx : NULL; }
cl_device_id umbra_context_cl_device(umbra_context ctx) { return ctx ? ctx->device : NULL; }
cl_command_queue umbra_context_cl_queue(umbra_context ctx) { return ctx ? ctx->queue : NULL; }

uint64_t umbra__next_id(umbra_context ctx) { return atomic_fetch_add(&ctx->next_id, 1) + 1; }

/* ---- programs ------------------------------------------------------------------------------- */

static char *program_key(const char *const *files, size_t nfiles, const char *options)
{
    size_t len = strlen(options) + 2;
    for (size_t i = 0; i < nfiles; ++i)
        len += strlen(files[i]) + 1;
    char *key = malloc(len);
    if (!key)
        return NULL;
    key[0] = 0;
    for (size_t i = 0; i < nfiles; ++i) {
        strcat(key, files[i]);
        strcat(key, "+");
    }
    strcat(key, "|");
    strcat(key, options);
    return key;
}

/* Two renderers on one context may ask for the same program at once: the lookup, the build and
 * the insertion happen under the cache's lock, so each program is built once. */
static umbra_status program_get_locked(umbra_context ctx, const char *const *files, size_t nfiles,
                                       const char *options, cl_program *out);

umbra_status umbra__program_get(umbra_context ctx, const char *const *files, size_t nfiles,
                                const char *options, cl_program *out)
{
    pthread_mutex_lock(&ctx->program_lock);
    umbra_status st = program_get_locked(ctx, files, nfiles, options, out);
    pthread_mutex_unlock(&ctx->program_lock);
    return st;
}

static umbra_status program_get_locked(umbra_context ctx, const char *const *files, size_t nfiles,
                                       const char *options, cl_program *out)
{
    umbra_status st = UMBRA_SUCCESS;
    const char *sources[16];
    /* Refused before anything reads files[]: a count from umbra__program_files above its
     * caller's array means the list did not fit. */
    if (nfiles == 0 || nfiles + 1 > sizeof sources / sizeof sources[0])
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra__program_get: %zu kernel files (1 to %zu)", nfiles,
                           sizeof sources / sizeof sources[0] - 1);
    char *key = program_key(files, nfiles, options);
    char *log = NULL;
    cl_program program = NULL;
    umbra__program *entry = NULL;
    if (!key)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra__program_get: out of memory");
    for (umbra__program *p = ctx->programs; p; p = p->next) {
        if (strcmp(p->key, key) == 0) {
            free(key);
            *out = p->program;
            return UMBRA_SUCCESS;
        }
    }
    sources[0] = umbra__kernel_source("common/umbra_shared.h");
    for (size_t i = 0; i < nfiles; ++i) {
        sources[i + 1] = umbra__kernel_source(files[i]);
        if (!sources[i + 1] || !sources[0]) {
            st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra__program_get: kernel file '%s' is not embedded", files[i]);
            goto fail;
        }
    }
    cl_int err;
    program = clCreateProgramWithSource(ctx->cl_ctx, (cl_uint)(nfiles + 1), sources, NULL, &err);
    UMBRA_CL_CHECK(err, "clCreateProgramWithSource");
    err = clBuildProgram(program, 1, &ctx->device, options, NULL, NULL);
    if (err != CL_SUCCESS) {
        size_t log_size = 0;
        clGetProgramBuildInfo(program, ctx->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &log_size);
        log = calloc(1, log_size + 1);
        if (log)
            clGetProgramBuildInfo(program, ctx->device, CL_PROGRAM_BUILD_LOG, log_size, log, NULL);
        st = umbra__fail(ctx, UMBRA_ERROR_BUILD,
                         "umbra__program_get: building %s with options '%s' failed with %s (%d); "
                         "build log:\n%s", key, options, umbra__cl_error_name(err), (int)err,
                         log ? log : "(unavailable)");
        goto fail;
    }
    entry = calloc(1, sizeof *entry);
    if (!entry) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra__program_get: out of memory");
        goto fail;
    }
    entry->key = key;
    entry->program = program;
    entry->next = ctx->programs;
    ctx->programs = entry;
    *out = program;
    return UMBRA_SUCCESS;
fail:
    free(log);
    free(key);
    if (program)
        clReleaseProgram(program);
    return st;
}

umbra_status umbra__kernel_create(umbra_context ctx, cl_program program, const char *name,
                                  cl_kernel *out)
{
    cl_int err;
    *out = clCreateKernel(program, name, &err);
    if (err != CL_SUCCESS) {
        *out = NULL;
        return umbra__fail_cl(ctx, __func__, name, err, __FILE__, __LINE__);
    }
    return UMBRA_SUCCESS;
}

umbra_status umbra__enqueue(umbra_context ctx, cl_kernel k, cl_uint dim, const size_t *global,
                            const size_t *local, cl_event *event)
{
    umbra_status st = UMBRA_SUCCESS;
    size_t def_local[3] = {64, 1, 1};
    if (dim == 2) {
        def_local[0] = 8;
        def_local[1] = 8;
    } else if (dim == 3) {
        def_local[0] = 4;
        def_local[1] = 4;
        def_local[2] = 4;
    }
    const size_t *l = local ? local : def_local;
    size_t rounded[3];
    for (cl_uint i = 0; i < dim; ++i)
        rounded[i] = (global[i] + l[i] - 1) / l[i] * l[i];
    UMBRA_CL(clEnqueueNDRangeKernel(ctx->queue, k, dim, NULL, rounded, l, 0, NULL, event));
fail:
    return st;
}

double umbra__event_ms(cl_event ev)
{
    cl_ulong a = 0, b = 0;
    if (!ev || clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_START, sizeof a, &a, NULL) != CL_SUCCESS ||
        clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof b, &b, NULL) != CL_SUCCESS)
        return -1.0;
    return (double)(b - a) * 1e-6;
}

double umbra__now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
