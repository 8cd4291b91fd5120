// SPDX-License-Identifier: Apache-2.0
/* host/techniques/deep_state.h: the deep shadow map's device state, shared by the build
 * (host/techniques/deep.c) and the part exchange (host/techniques/deep_part.c). */
#ifndef UMBRA_SHADOW_DEEP_STATE_H
#define UMBRA_SHADOW_DEEP_STATE_H

#include "techniques/deep.h"
#include "techniques/deep_shared.h"

typedef struct deep_state {
    cl_program program;             /* owned by the context's cache */
    cl_kernel k_lut, k_build, k_fixed;
    uint32_t tile;                  /* chosen for k_build's work-group limit */

    cl_mem lut[2];                  /* the tables held; lut_cur is the one the build uses */
    uint64_t lut_key[2][4];         /* (light tf id, light step bits, channels, colored) */
    int lut_valid[2], lut_cur;

    UmbraDeep constants;            /* the kernels' UmbraDeep, for the last build */
    cl_mem constants_buf;
    cl_mem pool, next, head, counts, counter, fixed, dummy;
    size_t pool_blocks, head_count, counts_count, fixed_bytes;
    size_t block_bytes, node_bytes;
    size_t used_blocks, asked_blocks;
    uint32_t tiles_per_row, block_size, channels, max_nodes, map_size;
    int fixed_mode, lut_used;

    size_t pool_override;           /* test knob: exact pool capacity, 0 = automatic */
    size_t limit_override;          /* test knob: the block limit, 0 = the device's */
    int allow_growth;

    uint64_t builds, build_passes, lut_builds, pool_growths;
} deep_state;

/* Re-allocates the block pool and its links to hold `blocks` blocks (the old contents are
 * dropped). */
umbra_status umbra__deep_alloc_pool(umbra_context ctx, deep_state *s, size_t blocks);

#endif
