// SPDX-License-Identifier: Apache-2.0
/* io/image_unavailable.c: the image functions of a umbra_io configured with UMBRA_IO_IMAGES=OFF,
 * in place of io/image.cpp.
 *
 * Such a umbra_io links no OpenImageIO (whose Debian package loads about 200 shared libraries):
 * for an application that reads volumes and transfer functions but shows or stores its frames
 * itself, and for a machine without Debian's packages (bench/device/pack.sh carries umbra-bench
 * to a GPU host that way). Every call is refused with UMBRA_ERROR_UNSUPPORTED naming the file, so
 * a caller learns why at the first image rather than at link time. */
#include "umbra/umbra.h"

#include "io_internal.h"

#define UMBRA_NO_IMAGES "umbra_io was built without OpenImageIO (UMBRA_IO_IMAGES=OFF)"

umbra_status umbra_image_write(umbra_context ctx, const char *path, uint32_t width,
                               uint32_t height, const float *rgba)
{
    (void)width;
    (void)height;
    (void)rgba;
    return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "umbra_image_write: \"%s\": " UMBRA_NO_IMAGES,
                       path ? path : "(null)");
}

umbra_status umbra_image_read(umbra_context ctx, const char *path, uint32_t *width,
                              uint32_t *height, float **rgba)
{
    if (width)
        *width = 0;
    if (height)
        *height = 0;
    if (rgba)
        *rgba = NULL;
    return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "umbra_image_read: \"%s\": " UMBRA_NO_IMAGES,
                       path ? path : "(null)");
}
