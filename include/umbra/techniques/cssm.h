// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/cssm.h: the parameters of the colored stochastic shadow map (technique "cssm",
 * UMBRA_SHADOW_CSSM, Weidner & Linsen), a light-space map (umbra_shadow_desc.map) holding one
 * depth per simulated light channel (3, or 1 for a grey light): map_size^2 * 12 or 4 bytes. */
#ifndef UMBRA_TECHNIQUES_CSSM_H
#define UMBRA_TECHNIQUES_CSSM_H

#include <stdint.h>

typedef struct umbra_cssm_desc {
    uint32_t taps;      /* texels averaged per lookup, 1, 7, 13 (the paper's set) or 21 (default
                           13); fixed in texels (kernels/common/lightspace.cl): more taps reach
                           farther (radius 4, 7, 10), trading noise for a wider blur of shadow
                           edges. Read by the lookup only: a change does not rebuild the map */
    uint32_t seed;      /* seed of the counter-based random numbers (default 1): the same seed
                           gives the same map and image, bit for bit, on the same device */
    uint32_t ray_block; /* texels per side of the square blocks whose photons share one light ray
                           (through the block's centre; each photon keeps its own random
                           number): 0 (the default: the map's whole texels per voxel, at most 3,
                           so that a block spans no more than a voxel), 1 (a ray per texel, as in
                           the paper), 2 or 3; docs/techniques.md, CSSM */
} umbra_cssm_desc;

#endif
