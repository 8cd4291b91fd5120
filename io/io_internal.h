/* io/io_internal.h: what the readers and writers of umbra_io share.
 *
 * umbra_io is built on libumbra's public API alone (it never sees host/internal.h), so that the
 * core can keep every internal symbol hidden. Errors are recorded on the context through the
 * public umbra_context_record_error; umbra__fail below is io's own formatting wrapper over it,
 * static inline so that each library keeps its own and a program linking both statically sees no
 * clash. */
#ifndef UMBRA_IO_INTERNAL_H
#define UMBRA_IO_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "umbra/io.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define UMBRA_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define UMBRA_PRINTF(f, a)
#endif

#define UMBRA_MESSAGE_MAX 8192

/* Records status and a formatted message on ctx (which may be NULL: the message is then dropped)
 * and returns status, as the core's umbra__fail does. */
static inline umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt,
                                       ...) UMBRA_PRINTF(3, 4);
static inline umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt,
                                       ...)
{
    char message[UMBRA_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    return umbra_context_record_error(ctx, status, message);
}

/* Reads a whole regular file into a malloc'ed buffer, followed by one NUL byte not counted in
 * *size (the text parsers rely on it). func names the public function in messages. */
umbra_status umbra__read_file(umbra_context ctx, const char *func, const char *path, void **data,
                              size_t *size);

#ifdef __cplusplus
}
#endif
#endif
