// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/moments.h: the parameters of the moment shadow map (technique "moments",
 * UMBRA_SHADOW_MOMENTS; after Peters & Klein 2015 and Muenstermann et al. 2018), a light-space
 * map (umbra_shadow_desc.map) holding per texel and simulated light channel the optical depth of
 * its light ray and a few power moments of how that depth is spread over the ray, from which the
 * lookup bounds the optical depth in front of a sample (the Hausdorff bounds) and takes a point
 * between the bounds. Fixed memory: map_size^2 x channels x (1 + moments) x 4 bytes at 32 bits,
 * (1 + moments / 2) x 4 at 16 (docs/moments.md). */
#ifndef UMBRA_TECHNIQUES_MOMENTS_H
#define UMBRA_TECHNIQUES_MOMENTS_H

#include <stdint.h>

typedef struct umbra_moments_desc {
    uint32_t count;       /* power moments per channel beside the optical depth: 4, 6 or 8
                             (default 6) */
    uint32_t bits;        /* storage of each normalised moment: 32 (float, the default) or 16
                             (fixed point); the optical depth is always a float */
    float bias;           /* moment bias alpha in [0, 0.1]: the moments read are mixed with this
                             weight with those of a uniform spread, which keeps the
                             reconstruction well posed under rounding; 0 (the default): the
                             technique's own for the count and bits. Read by the lookup only */
    float overestimation; /* in [0, 1] (default 0.5): where the estimated shadow factor lies
                             between its bounds' lit end (0: the lower bound of the optical
                             depth in front of a sample) and dark end (1: the upper bound).
                             Read by the lookup only */
    uint32_t blur;        /* radius in texels, 0..4 (default 0: none), of a separable binomial
                             pre-filter over the built map (moments filter linearly) */
} umbra_moments_desc;

#endif
