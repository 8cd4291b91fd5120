// SPDX-License-Identifier: Apache-2.0
/* host/part_light.h: what a part's view (host/part_render.c) needs of the light exchange between
 * parts (host/part_light.c). */
#ifndef UMBRA_PART_LIGHT_H
#define UMBRA_PART_LIGHT_H

#include "renderer_internal.h"

/* A technique whose parts march the light (threshold, CSSM, deep): the state one part hands the
 * next on a texel's light ray, and what the parts share once all have marched.
 *  - state: per texel a run of fields, each one float or one per light channel (r->channels,
 *    set by umbra__frame_update_light); per field its value for a part first on the ray, the
 *    range an import must lie in, whether it counts (an integer) and its name;
 *  - shares: a depth per texel or per channel, which the parts reduce with umbra_part_minimum,
 *    or the pieces of the deep map, merged per texel (umbra_renderer_part_export_deep). */
typedef enum { SHARES_DEPTH, SHARES_DEPTH_PER_CHANNEL, SHARES_PIECES } PartShares;

typedef struct PartField {
    const char *name;
    int per_channel, integral;
    float start, lo, hi;
} PartField;

typedef struct PartLight {
    umbra_shadow_technique technique;
    const PartField *fields;
    uint32_t field_count;
    PartShares shares;
} PartLight;

/* The exchange of technique t, or NULL if its parts march no light. */
const PartLight *umbra__part_light(umbra_shadow_technique t);

/* The deep map's settings a part refuses, each naming the reason (UMBRA_SUCCESS: none). */
umbra_status umbra__part_check_deep(umbra_renderer r, const char *fn);

#endif
