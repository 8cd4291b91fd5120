// SPDX-License-Identifier: Apache-2.0
/* umbra/transfer_function.h: 1D RGBA transfer functions.
 *
 * A transfer function is a table of RGBA entries spread evenly over the volume's normalised value
 * range [0,1] (entry i at value i/(count-1)), linearly interpolated. Given a data range
 * (umbra_transfer_function_set_range, or "range LO HI" in a file) the entries span data values
 * LO..HI instead, in the volume's own units (e.g. Hounsfield units), whatever the volume's value
 * range: the renderer resamples the table onto each volume's range, and data values outside
 * LO..HI take the end entries. Alpha is the opacity of one voxel length (the smallest spacing).
 * The light pass interpolates first, then converts the alpha to the extinction -ln(1 - a) per
 * voxel (a at most 1 - 2^-24), so a step of D voxels has opacity 1 - (1 - a)^D of the
 * interpolated a: the order that converges to one continuous model as the step shrinks
 * (correcting the entries first gives a step-dependent one). The view pass corrects the entries
 * for its step, a' = 1 - (1 - a)^step, then interpolates. RGB is the emitted colour for the view,
 * and for a light transfer function in UMBRA_TRANSMISSION_COLORED mode the transmission colour t
 * of the shading model (see renderer.h). */
#ifndef UMBRA_TRANSFER_FUNCTION_H
#define UMBRA_TRANSFER_FUNCTION_H

#include <stdint.h>

#include "umbra/context.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_transfer_function_t *umbra_transfer_function;

/* Copies count RGBA entries (4*count floats, each finite and in [0,1]), count >= 2. */
UMBRA_API umbra_status umbra_transfer_function_create(umbra_context ctx, const float *rgba,
                                                      uint32_t count, umbra_transfer_function *out);

/* A control point: value in [0,1] of the normalised range, colour and opacity in [0,1]. */
typedef struct umbra_tf_point {
    float value;
    float rgba[4];
} umbra_tf_point;

/* The most control points a transfer function is built from, and the most table entries. */
#define UMBRA_TF_MAX_POINTS 65536u

/* Builds a table of resolution entries (2..UMBRA_TF_MAX_POINTS) by linear interpolation between
 * points (sorted by value, 1..UMBRA_TF_MAX_POINTS of them; more is UMBRA_ERROR_INVALID_ARGUMENT).
 * Values outside the first and last point take those points' colours. Copies points. */
UMBRA_API umbra_status umbra_transfer_function_create_from_points(umbra_context ctx,
                                                                  const umbra_tf_point *points,
                                                                  uint32_t count,
                                                                  uint32_t resolution,
                                                                  umbra_transfer_function *out);

/* Makes tf's entries span data values lo..hi (finite, lo < hi; the volume's units, before its
 * normalisation) instead of the volume's normalised range; renderers pick the change up at their
 * next render. The table itself is unchanged. UMBRA_ERROR_INVALID_ARGUMENT names a bad range. */
UMBRA_API umbra_status umbra_transfer_function_set_range(umbra_transfer_function tf, float lo,
                                                         float hi);
/* Nonzero if tf has a data range; then writes it to range[0..1] (range may be NULL). */
UMBRA_API int umbra_transfer_function_get_range(umbra_transfer_function tf, float range[2]);

UMBRA_API uint32_t umbra_transfer_function_size(umbra_transfer_function tf);
/* The table, 4*size floats, owned by tf. */
UMBRA_API const float *umbra_transfer_function_data(umbra_transfer_function tf);

/* Nonzero when every entry with alpha > 0 has r == g == b: such a function, used as the light
 * transfer function, attenuates all colours alike and needs one light channel, not three. */
UMBRA_API int umbra_transfer_function_is_grey(umbra_transfer_function tf);

UMBRA_API void umbra_transfer_function_retain(umbra_transfer_function tf);
UMBRA_API void umbra_transfer_function_release(umbra_transfer_function tf); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
