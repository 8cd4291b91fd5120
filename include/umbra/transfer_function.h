/* umbra/transfer_function.h: 1D RGBA transfer functions.
 *
 * A transfer function is a table of RGBA entries spread evenly over the volume's normalised value
 * range [0,1] (entry i at value i/(count-1)), linearly interpolated. Alpha is the opacity of one
 * sample taken every voxel (the reference step); renderers correct it for their own step with
 * a' = 1 - (1 - a)^(step / reference_step). RGB is the emitted colour for the view, and for a light
 * transfer function in UMBRA_TRANSMISSION_COLORED mode the transmission colour t of the shading
 * model (see renderer.h). */
#ifndef UMBRA_TRANSFER_FUNCTION_H
#define UMBRA_TRANSFER_FUNCTION_H

#include <stdint.h>

#include "umbra/context.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_transfer_function_t *umbra_transfer_function;

/* Copies count RGBA entries (4*count floats, each finite and in [0,1]), count >= 2. */
umbra_status umbra_transfer_function_create(umbra_context ctx, const float *rgba, uint32_t count,
                                            umbra_transfer_function *out);

/* A control point: value in [0,1] of the normalised range, colour and opacity in [0,1]. */
typedef struct umbra_tf_point {
    float value;
    float rgba[4];
} umbra_tf_point;

/* Builds a table of resolution entries (2..65536) by linear interpolation between points (sorted
 * by value, 1..65536 of them; more is UMBRA_ERROR_INVALID_ARGUMENT). Values outside the first and
 * last point take those points' colours. Copies points. */
umbra_status umbra_transfer_function_create_from_points(umbra_context ctx,
                                                        const umbra_tf_point *points,
                                                        uint32_t count, uint32_t resolution,
                                                        umbra_transfer_function *out);

/* Reads the text format documented in the README (and host/tf_file.c): '#' comments, an optional
 * line "resolution N" (2..65536, default 256) before the first point, then one control point
 * "value r g b a" per line (at most 65536), values ascending (equal values make a step). The file
 * must be a regular file; errors are UMBRA_ERROR_IO or UMBRA_ERROR_FORMAT naming path:line. */
umbra_status umbra_transfer_function_load(umbra_context ctx, const char *path,
                                          umbra_transfer_function *out);

uint32_t umbra_transfer_function_size(umbra_transfer_function tf);
/* The table, 4*size floats, owned by tf. */
const float *umbra_transfer_function_data(umbra_transfer_function tf);

/* Nonzero when every entry with alpha > 0 has r == g == b: such a function, used as the light
 * transfer function, attenuates all colours alike and needs one light channel, not three. */
int umbra_transfer_function_is_grey(umbra_transfer_function tf);

void umbra_transfer_function_retain(umbra_transfer_function tf);
void umbra_transfer_function_release(umbra_transfer_function tf); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
