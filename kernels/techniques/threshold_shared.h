// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/threshold_shared.h: the opacity-threshold map's kernel constants, shared by
 * host/techniques/threshold.c (which fills them and checks the size) and threshold.cl, compiled
 * after kernels/common/umbra_shared.h on both sides. */
#ifndef UMBRA_THRESHOLD_SHARED_H
#define UMBRA_THRESHOLD_SHARED_H

typedef struct UmbraThreshold {
    float threshold;  /* accumulated opacity at which the build stores a texel's depth */
    float depth_bias; /* normalised depth a sample must lie beyond a stored depth to be shadowed */
    uint32_t taps;    /* texels per lookup */
    uint32_t pad;
} UmbraThreshold;

#endif
