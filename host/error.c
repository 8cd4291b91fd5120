// SPDX-License-Identifier: Apache-2.0
/* host/error.c: status names and the one place errors are recorded.
 *
 * The first error since the last umbra_context_take_error sticks; the latest message is kept for
 * umbra_context_last_message; the callback sees each one. Nothing is printed. */
#include <stdio.h>
#include <string.h>

#include "internal.h"

const char *umbra_version(void)
{
    return UMBRA_VERSION_STRING;
}

unsigned umbra_version_number(void)
{
    return UMBRA_VERSION;
}

const char *umbra_status_to_string(umbra_status status)
{
    switch (status) {
    case UMBRA_SUCCESS: return "UMBRA_SUCCESS";
    case UMBRA_ERROR_INVALID_ARGUMENT: return "UMBRA_ERROR_INVALID_ARGUMENT";
    case UMBRA_ERROR_OUT_OF_MEMORY: return "UMBRA_ERROR_OUT_OF_MEMORY";
    case UMBRA_ERROR_OPENCL: return "UMBRA_ERROR_OPENCL";
    case UMBRA_ERROR_BUILD: return "UMBRA_ERROR_BUILD";
    case UMBRA_ERROR_IO: return "UMBRA_ERROR_IO";
    case UMBRA_ERROR_FORMAT: return "UMBRA_ERROR_FORMAT";
    case UMBRA_ERROR_UNSUPPORTED: return "UMBRA_ERROR_UNSUPPORTED";
    case UMBRA_ERROR_NO_DEVICE: return "UMBRA_ERROR_NO_DEVICE";
    case UMBRA_ERROR_CANCELLED: return "UMBRA_ERROR_CANCELLED";
    }
    return "UMBRA_ERROR_UNKNOWN";
}

/* Under the context's error lock (objects of one context may be used on several threads); the
 * callback runs outside it, so that it may call back into umbra. */
static void record(umbra_context ctx, umbra_status status, const char *message)
{
    if (!ctx)
        return;
    pthread_mutex_lock(&ctx->error_lock);
    snprintf(ctx->last_message, sizeof ctx->last_message, "%s", message);
    if (ctx->first_error == UMBRA_SUCCESS) {
        ctx->first_error = status;
        snprintf(ctx->first_message, sizeof ctx->first_message, "%s", message);
    }
    umbra_error_callback cb = ctx->callback;
    void *user = ctx->callback_user;
    pthread_mutex_unlock(&ctx->error_lock);
    if (cb)
        cb(user, status, message);
}

umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt, ...)
{
    char message[UMBRA_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    record(ctx, status, message);
    return status;
}

umbra_status umbra_context_record_error(umbra_context ctx, umbra_status status,
                                        const char *message)
{
    record(ctx, status, message ? message : "");
    return status;
}

umbra_status umbra__fail_cl(umbra_context ctx, const char *func, const char *call, cl_int err,
                            const char *file, int line)
{
    umbra_status st = (err == CL_OUT_OF_HOST_MEMORY || err == CL_OUT_OF_RESOURCES ||
                       err == CL_MEM_OBJECT_ALLOCATION_FAILURE)
                          ? UMBRA_ERROR_OUT_OF_MEMORY
                          : UMBRA_ERROR_OPENCL;
    const char *base = strrchr(file, '/');
    return umbra__fail(ctx, st, "%s: %s failed with %s (%d) at %s:%d", func, call,
                       umbra__cl_error_name(err), (int)err, base ? base + 1 : file, line);
}

const char *umbra__cl_error_name(cl_int err)
{
    switch (err) {
#define N(x) case x: return #x;
        N(CL_SUCCESS) N(CL_DEVICE_NOT_FOUND) N(CL_DEVICE_NOT_AVAILABLE)
        N(CL_COMPILER_NOT_AVAILABLE) N(CL_MEM_OBJECT_ALLOCATION_FAILURE) N(CL_OUT_OF_RESOURCES)
        N(CL_OUT_OF_HOST_MEMORY) N(CL_PROFILING_INFO_NOT_AVAILABLE) N(CL_MEM_COPY_OVERLAP)
        N(CL_IMAGE_FORMAT_MISMATCH) N(CL_IMAGE_FORMAT_NOT_SUPPORTED) N(CL_BUILD_PROGRAM_FAILURE)
        N(CL_MAP_FAILURE) N(CL_INVALID_VALUE) N(CL_INVALID_DEVICE_TYPE) N(CL_INVALID_PLATFORM)
        N(CL_INVALID_DEVICE) N(CL_INVALID_CONTEXT) N(CL_INVALID_QUEUE_PROPERTIES)
        N(CL_INVALID_COMMAND_QUEUE) N(CL_INVALID_HOST_PTR) N(CL_INVALID_MEM_OBJECT)
        N(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR) N(CL_INVALID_IMAGE_SIZE) N(CL_INVALID_SAMPLER)
        N(CL_INVALID_BINARY) N(CL_INVALID_BUILD_OPTIONS) N(CL_INVALID_PROGRAM)
        N(CL_INVALID_PROGRAM_EXECUTABLE) N(CL_INVALID_KERNEL_NAME) N(CL_INVALID_KERNEL_DEFINITION)
        N(CL_INVALID_KERNEL) N(CL_INVALID_ARG_INDEX) N(CL_INVALID_ARG_VALUE) N(CL_INVALID_ARG_SIZE)
        N(CL_INVALID_KERNEL_ARGS) N(CL_INVALID_WORK_DIMENSION) N(CL_INVALID_WORK_GROUP_SIZE)
        N(CL_INVALID_WORK_ITEM_SIZE) N(CL_INVALID_GLOBAL_OFFSET) N(CL_INVALID_EVENT_WAIT_LIST)
        N(CL_INVALID_EVENT) N(CL_INVALID_OPERATION) N(CL_INVALID_BUFFER_SIZE)
        N(CL_INVALID_GLOBAL_WORK_SIZE) N(CL_INVALID_PROPERTY)
#undef N
    default: return "CL_UNKNOWN_ERROR";
    }
}

umbra_status umbra_context_take_error(umbra_context ctx, const char **message)
{
    static const char none[] = "";
    if (!ctx) {
        if (message)
            *message = "umbra_context_take_error: ctx is NULL";
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    pthread_mutex_lock(&ctx->error_lock);
    umbra_status st = ctx->first_error;
    /* first_message is only rewritten when the next error is recorded, so it outlives the reset. */
    if (message)
        *message = st == UMBRA_SUCCESS ? none : ctx->first_message;
    ctx->first_error = UMBRA_SUCCESS;
    pthread_mutex_unlock(&ctx->error_lock);
    return st;
}

const char *umbra_context_last_message(umbra_context ctx)
{
    return ctx ? ctx->last_message : "umbra_context_last_message: ctx is NULL";
}

void umbra_context_set_error_callback(umbra_context ctx, umbra_error_callback cb, void *user)
{
    if (!ctx)
        return;
    pthread_mutex_lock(&ctx->error_lock);
    ctx->callback = cb;
    ctx->callback_user = user;
    pthread_mutex_unlock(&ctx->error_lock);
}
