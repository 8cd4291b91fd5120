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

#endif
