// SPDX-License-Identifier: Apache-2.0
/* umbra/error.h: status codes and error reporting.
 *
 * Every function that can fail returns an umbra_status. The context keeps the first error since it
 * was last read (sticky, as in Embree) and the most recent message; an optional callback receives
 * every error as it happens. The library never prints and never exits. */
#ifndef UMBRA_ERROR_H
#define UMBRA_ERROR_H

#include "umbra/config.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum umbra_status {
    UMBRA_SUCCESS = 0,
    UMBRA_ERROR_INVALID_ARGUMENT = 1, /* a NULL pointer, a zero size, a NaN, a value out of range */
    UMBRA_ERROR_OUT_OF_MEMORY = 2,    /* host or device allocation failed */
    UMBRA_ERROR_OPENCL = 3,           /* an OpenCL call failed; the message names call and cl_int */
    UMBRA_ERROR_BUILD = 4,            /* a kernel program failed to build; the message has the
                                         log */
    UMBRA_ERROR_IO = 5,               /* a file could not be opened, read or written */
    UMBRA_ERROR_FORMAT = 6,           /* a file was read but its contents are malformed */
    UMBRA_ERROR_UNSUPPORTED = 7,      /* valid request this device or technique cannot do */
    UMBRA_ERROR_NO_DEVICE = 8,        /* no OpenCL platform or device matched the request */
    UMBRA_ERROR_CANCELLED = 9         /* the progress callback asked to stop; nothing is broken */
} umbra_status;

/* Static English name of a status ("UMBRA_ERROR_IO"); never NULL. */
UMBRA_API const char *umbra_status_to_string(umbra_status status);

/* The library's version at run time, "MAJOR.MINOR.PATCH" (static storage); compare with
 * UMBRA_VERSION_STRING, the version the application was compiled against. */
UMBRA_API const char *umbra_version(void);

/* The same as MAJOR * 10000 + MINOR * 100 + PATCH (see UMBRA_VERSION). */
UMBRA_API unsigned umbra_version_number(void);

/* Called for every error as it is recorded, on the calling thread. message is valid only during
 * the call. */
typedef void (*umbra_error_callback)(void *user, umbra_status status, const char *message);

#ifdef __cplusplus
}
#endif
#endif
