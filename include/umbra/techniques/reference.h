// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/reference.h: the parameters of the exact reference (technique "reference",
 * UMBRA_SHADOW_REFERENCE): a shadow ray marched toward the light from every sample
 * (kernels/techniques/reference.cl). Slow, and the yardstick of every other technique. */
#ifndef UMBRA_TECHNIQUES_REFERENCE_H
#define UMBRA_TECHNIQUES_REFERENCE_H

typedef struct umbra_reference_desc {
    float step; /* shadow-ray step in voxels, [0.01, 64] (default 0.25); key reference_step */
} umbra_reference_desc;

#endif
