// SPDX-License-Identifier: Apache-2.0
/* host/techniques/convolution.h: internals of the convolution shadows that the tests look at. The
 * technique itself is umbra__technique_convolution (renderer_internal.h). */
#ifndef UMBRA_SHADOW_CONVOLUTION_H
#define UMBRA_SHADOW_CONVOLUTION_H

#include "renderer_internal.h"

/* Largest angle, in degrees, between a directional light's travel direction (or, for a point
 * light, the direction to any corner of the box) and the view direction. */
#define UMBRA__CONV_MAX_LIGHT_DEGREES 80.0f

/* Renders a width x height frame with r (which must use the convolution technique), then runs
 * slices 0..k again and reads the light arriving at slice k (L_k: before slice k attenuates it)
 * into rgb, 3 floats per pixel, row 0 at the top. k must be below the frame's slice count. */
umbra_status umbra__convolution_light(umbra_renderer r, uint32_t width, uint32_t height,
                                      uint32_t k, float *rgb);

/* Evaluates the kernels' sub-sample light weight for j = 0..n+1 into out (n + 2 floats). */
umbra_status umbra__convolution_subsample_weights(umbra_context ctx, uint32_t n, float *out);

#endif
