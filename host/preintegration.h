// SPDX-License-Identifier: Apache-2.0
/* host/preintegration.h: pre-integration tables on the device (kernels/common/preintegration.cl),
 * shared
 * by the convolution shadows (host/techniques/convolution.c) and the ray caster's pre-integrated
 * mode
 * (host/renderer.c). A table is a cache: it is recomputed only when the transfer function, the
 * segment length, the kind or the transmission mode it was made for change. */
#ifndef UMBRA_PREINTEGRATION_H
#define UMBRA_PREINTEGRATION_H

#include "internal.h"

/* Entries per side of every table: size x size float4, s_f along rows, s_b down columns. */
#define UMBRA__PREINT_SIZE 256u

typedef enum umbra__preint_kind {
    UMBRA__PREINT_VIEW = 0,  /* premultiplied colour and opacity of the segment */
    UMBRA__PREINT_LIGHT = 1  /* per-channel transmittance of the shading model through it */
} umbra__preint_kind;

typedef struct umbra__preint umbra__preint;

/* Makes *table (created on first use, owned by the caller) hold tf's table for segments of
 * length_voxels, recomputing it on the device only when an input changed. colored selects the
 * transmission colour of PREINT_LIGHT (ignored for PREINT_VIEW). Returns the table's buffer
 * (borrowed, valid until the next call or release) through *buf and adds the device time of a
 * rebuild to *ms (may be NULL). func names the public function for error messages. */
umbra_status umbra__preint_ensure(umbra_context ctx, const char *func, umbra__preint **table,
                                  umbra_transfer_function tf, float length_voxels,
                                  umbra__preint_kind kind, int colored, cl_mem *buf, double *ms);

/* Device bytes the table holds (0 for NULL). */
size_t umbra__preint_bytes(const umbra__preint *table);

/* Frees the table; NULL is a no-op. */
void umbra__preint_release(umbra__preint *table);

#endif
