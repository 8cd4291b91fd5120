// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/present.h: puts umbra's frames on the screen and the screen into files.
 *
 * The frame travels by texture upload: umbra renders premultiplied linear RGBA floats into host
 * memory, they are encoded to 8-bit sRGB exactly as umbra_image_write encodes a PNG (colour
 * un-premultiplied, clamped, the piecewise sRGB curve, rounded), and glTexSubImage2D puts them
 * into a GL_RGBA8 texture drawn 1:1 with nearest filtering, so the window shows the bytes the
 * PNG would hold. The encoding is exact and fast: per channel a table lookup and a short search
 * among the 255 thresholds where the 8-bit code changes.
 *
 * CL-GL sharing (rendering with umbra_renderer_render_to_cl_buffer into a buffer shared with a
 * GL pixel buffer) is not here: the devices this is tested on (PoCL on the CPU) have no
 * cl_khr_gl_sharing, so it could not be tested. */
#ifndef UMBRA_VIEW_PRESENT_H
#define UMBRA_VIEW_PRESENT_H

#include <stdint.h>

#include "umbra/io.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct present {
    unsigned texture;          /* GL texture name, 0 before the first upload */
    uint32_t width, height;    /* its size */
    uint8_t *rgba8;            /* the last frame, 8-bit sRGB RGBA, row 0 at the top */
    float threshold[257];      /* threshold[k]: the least linear value whose code is >= k */
    uint8_t start[1024];       /* the code at the bottom of each of 1024 slices of [0, 1] */
} present;

/* Builds the encoding tables. No GL call. */
void present_init(present *p);
/* Releases the texture and the buffer (the GL context must be current if a texture exists). */
void present_release(present *p);

/* The 8-bit sRGB code of a linear value in umbra_image_write's PNG encoding (NaN and below 0
 * give 0, 1 and above 255). */
uint8_t present_encode(const present *p, float linear);
/* Encodes a w x h premultiplied float frame (borrowed) and uploads it into the texture,
 * (re)creating it when the size changed. The GL context must be current. Returns 0, or -1 when
 * out of memory (the previous frame stays). */
int present_upload(present *p, const float *rgba, uint32_t w, uint32_t h);

/* Reads the w x h pixels of the current GL context's back buffer (the window as drawn, before
 * the swap) and writes them through umbra_image_write: the PNG holds the window's bytes. Errors
 * (out of memory too) are recorded on ctx. */
umbra_status present_write_window(const present *p, umbra_context ctx, const char *path,
                                  uint32_t w, uint32_t h);

#ifdef __cplusplus
}
#endif
#endif
