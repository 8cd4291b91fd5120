// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/deep_shared.h: the deep shadow map's kernel constants, shared by
 * host/techniques/deep.c (which fills them and checks the size) and deep.cl / deep_budget.cl,
 * compiled after kernels/common/umbra_shared.h on both sides. */
#ifndef UMBRA_DEEP_SHARED_H
#define UMBRA_DEEP_SHARED_H

typedef struct UmbraDeep {
    uint32_t tile;          /* tile edge in texels (16, or 8 on small work-groups) */
    uint32_t tiles_per_row; /* tiles per map row */
    uint32_t block_size;    /* node layers per block */
    uint32_t max_nodes;     /* node budget per texel (0: unbounded, the blocked layout) */
} UmbraDeep;

/* A part's march state per texel of the map (umbra/part.h, the deep map's transmittance
 * arrays), with C light channels: everything one device's march carries from a segment to the
 * next, so the part after this one on the ray marches on as one device does (deep.cl,
 * deep_state_load; host/part_render.c names each field for an import's check). In order:
 *   C  visibility at the next segment's front end
 *   1  fit origin depth z0         C  fit origin visibility v0
 *   1  last fed point's depth zl   C  its visibility vl
 *   1  held point's depth zh       C  its visibility vh
 *   C  lowest slope lo             C  highest slope hi
 *   1  points fed since the origin 1  origin emitted (0 or 1)   1  a point held (0 or 1)
 *   1  depth of the last point given to the fit (-infinity before the first) */
#define DEEP_PART_STATE_FLOATS(C) (6 * (C) + 7)

#endif
