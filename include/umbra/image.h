/* umbra/image.h: writing and reading images through OpenImageIO.
 *
 * The format follows the extension: .png is written as 8-bit sRGB-encoded RGBA (colour
 * un-premultiplied, clamped), .exr as linear float RGBA as rendered. */
#ifndef UMBRA_IMAGE_H
#define UMBRA_IMAGE_H

#include <stdint.h>

#include "umbra/context.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Writes width x height premultiplied RGBA floats (borrowed), row 0 at the top. Errors are
 * recorded on ctx. */
umbra_status umbra_image_write(umbra_context ctx, const char *path, uint32_t width,
                               uint32_t height, const float *rgba);

/* Reads an image as linear premultiplied RGBA floats into a malloc'ed buffer the caller frees
 * with free(). PNG values are decoded from sRGB; missing channels are filled (alpha 1). */
umbra_status umbra_image_read(umbra_context ctx, const char *path, uint32_t *width,
                              uint32_t *height, float **rgba);

#ifdef __cplusplus
}
#endif
#endif
