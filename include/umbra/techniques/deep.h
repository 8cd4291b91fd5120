// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/deep.h: the parameters of the deep shadow map (technique "deep",
 * UMBRA_SHADOW_DEEP, Hadwiger et al. 2006), a light-space map (umbra_shadow_desc.map) storing per
 * texel the visibility along its light ray as a compressed piecewise-linear function. */
#ifndef UMBRA_TECHNIQUES_DEEP_H
#define UMBRA_TECHNIQUES_DEEP_H

#include <stdint.h>

typedef struct umbra_deep_desc {
    float epsilon;        /* compression error bound in [0, 1] (default 0.02) */
    uint32_t max_nodes;   /* fixed budget of nodes per texel, 0 (unbounded, the default) or
                             2..64; a node holds a depth and every channel's visibility (4 floats
                             for coloured light: 3 nodes = 12 values). The nodes kept are chosen
                             once the whole ray is known, for the least error; the stored
                             function never rises and its end value is the unbounded map's */
    uint32_t block_size;  /* node layers per block of the unbounded map, 1..256 (default 8) */
    uint32_t prefilter;   /* sub-pixel rays per texel, 1 or 5 (default 1) */
    int lookup_table;     /* nonzero (default): use the pre-compressed segment table */
} umbra_deep_desc;

#endif
