// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/threshold.h: the parameters of the opacity-threshold shadow map (technique
 * "threshold", UMBRA_SHADOW_THRESHOLD), a light-space map (umbra_shadow_desc.map) of one depth per
 * texel, map_size^2 * 4 bytes: where the accumulated light opacity first passes the threshold.
 * Grey and binary: everything behind that depth is black in every channel, even where coloured
 * transmission lets light through, so in coloured scenes where light passes coloured material it
 * can be worse than no shadows (docs/techniques.md, "Opacity-threshold shadow map"). */
#ifndef UMBRA_TECHNIQUES_THRESHOLD_H
#define UMBRA_TECHNIQUES_THRESHOLD_H

#include <stdint.h>

typedef struct umbra_threshold_desc {
    float threshold; /* accumulated light opacity in (0, 1) at which a texel's depth is stored
                        (default 0.5) */
    uint32_t taps;   /* texels averaged per lookup (percentage-closer filtering), 1, 7, 13 or 21
                        (default 13); the offsets are CSSM's, fixed in texels
                        (kernels/common/lightspace.cl). Read by the lookup only: a change does
                        not rebuild the map */
} umbra_threshold_desc;

#endif
