// SPDX-License-Identifier: Apache-2.0
/* host/techniques/deep.h: the deep shadow map technique (host/techniques/deep.c,
 * kernels/techniques/deep.cl), its pieces on parts (host/techniques/deep_part.c) and the
 * internals its tests look at: the block layout, the pool and the lookup-table cache. */
#ifndef UMBRA_SHADOW_DEEP_H
#define UMBRA_SHADOW_DEEP_H

#include "renderer_internal.h"

/* Must match kernels/techniques/deep.cl. */
#define UMBRA__DEEP_LUT_RES 256u     /* quantised scalars per table axis */
#define UMBRA__DEEP_LUT_NODES 4u     /* nodes per table entry: 3 interior + the end */

extern const umbra__technique umbra__technique_deep;

typedef struct umbra__deep_info {
    uint32_t tile;            /* tile edge in texels (the build's work-group is tile x tile) */
    uint32_t tiles_per_row;   /* tiles per map row (and per column) */
    uint32_t block_size;      /* K: node layers per block */
    uint32_t channels;        /* light channels per node (1 or 3) */
    uint32_t max_nodes;       /* fixed budget per texel, 0 for the blocked layout */
    size_t node_bytes;        /* 4 * (1 + channels): depth + one visibility per channel */
    size_t block_bytes;       /* K * tile^2 * node_bytes */
    size_t pool_blocks;       /* capacity of the block pool */
    size_t used_blocks;       /* blocks the last build took */
    size_t asked_blocks;      /* blocks the last build pass asked for (it stops once past the
                                 limit: umbra__deep_set_limit) */
    size_t map_bytes;         /* blocked: used blocks' bytes; fixed: map_size^2 * N * node_bytes */
    size_t layout_bytes;      /* head per tile + next per used block + node count per texel */
    size_t lut_bytes;         /* the segment table, 0 when lookup_table = 0 */
    uint64_t builds;          /* map builds (each counts once, however many pool attempts) */
    uint64_t build_passes;    /* kernel runs, including those repeated after the pool grew */
    uint64_t lut_builds;      /* segment-table builds */
    uint64_t pool_growths;    /* times a full pool was re-allocated */
} umbra__deep_info;

/* State of the current deep map; UMBRA_ERROR_INVALID_ARGUMENT unless the technique is deep. */
umbra_status umbra__deep_get_info(umbra_renderer r, umbra__deep_info *out);

/* Test knob: the pool holds exactly `blocks` blocks at the next build (0: sized automatically)
 * and, with allow_growth = 0, a build that needs more fails with UMBRA_ERROR_OUT_OF_MEMORY
 * instead of growing the pool. Forces a rebuild at the next render. The technique must be deep. */
umbra_status umbra__deep_set_pool(umbra_renderer r, size_t blocks, int allow_growth);

/* Test knob: the most blocks a build may ask for before it stops and fails with
 * UMBRA_ERROR_OUT_OF_MEMORY (0: what the device's largest allocation holds). Forces a rebuild. */
umbra_status umbra__deep_set_limit(umbra_renderer r, size_t blocks);

/* Reads the last build back (each pointer may be NULL): head (tiles_per_row^2 ints, -1 for a tile
 * without blocks), next (used_blocks ints, -1 ending a chain), counts (map_size^2 node counts)
 * and nodes (blocked: used_blocks * block_bytes; fixed: map_size^2 * max_nodes * node_bytes).
 * Blocked layout: node j of texel (x, y) lies in the (j / K)-th block of its tile's chain, at
 * float offset ((block * K + j % K) * tile^2 + lane) * (1 + channels), lane = (y % tile) * tile +
 * x % tile. */
umbra_status umbra__deep_read(umbra_renderer r, int32_t *head, int32_t *next, uint32_t *counts,
                              float *nodes);

/* A part's pieces of the unbounded map (host/techniques/deep_part.c, for host/part_light.c):
 * the export writes the built map's node count per texel (map_size^2) and, unless nodes is
 * NULL, its nodes in texel order (1 + channels floats each; *node_count their capacity in, their
 * number out); the import merges the pieces of `parts` parts (counts: parts x map_size^2,
 * part-major; nodes: their arrays one after another, node_count in all) per texel in depth
 * order into the map, in blocks. */
umbra_status umbra__deep_part_export(umbra_renderer r, uint32_t *counts, float *nodes,
                                     size_t *node_count);
umbra_status umbra__deep_part_import(umbra_renderer r, uint32_t parts, const uint32_t *counts,
                                     const float *nodes, size_t node_count);

#endif
