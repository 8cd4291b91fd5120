// SPDX-License-Identifier: Apache-2.0
/* host/gradient_volume.h: the ray caster's shading gradient volume (host/gradient_volume.c),
 * internal to the library. */
#ifndef UMBRA_GRADIENT_VOLUME_H
#define UMBRA_GRADIENT_VOLUME_H

#include "renderer_internal.h"

/* The shading gradient volume for this frame (kernels/common/sampling.cl, gradient_volume_entry):
 * *on is 1 and *buf the volume's gradients where the frame shades a plain whole volume of
 * integers in one buffer whose (dims + 3)^3 entries of 8 bytes fit one allocation, made again
 * when the volume, its version or the program changed; else *on is 0, *buf any buffer, and a
 * gradient volume held is released (only shaded frames pay its memory). The kernel reads it in
 * place of the 32-voxel stencil, the same gradient bit for bit. */
umbra_status umbra__gradient_volume(umbra_renderer r, cl_mem *buf, cl_uint *on);

#endif
