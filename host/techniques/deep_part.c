// SPDX-License-Identifier: Apache-2.0
/* host/techniques/deep_part.c: the deep shadow map on parts (include/umbra/part.h,
 * docs/distributed.md; host/part_light.c calls it). A part's map holds, per texel, the pieces
 * of the texel's visibility function its core owns: the nodes of the segments of the light ray
 * inside its core (kernels/techniques/deep.cl under UMBRA_PART). The export reads them back in
 * texel order; the import merges the pieces of all parts per texel in depth order, which is one
 * device's function (the march state, its fit included, passes from part to part), and lays
 * the merged map out in blocks as a build lays it out (a tile's chain as long as its longest
 * texel's list needs), so the lookup is unchanged. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "techniques/deep_state.h"

static umbra_status check_pieces(umbra_renderer r, const char *fn, deep_state **out)
{
    deep_state *s = r->tech_state;
    if (r->tech != &umbra__technique_deep || !s || s->builds == 0 || s->fixed_mode || !s->pool)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: no unbounded deep shadow map has been built", fn);
    *out = s;
    return UMBRA_SUCCESS;
}

umbra_status umbra__deep_part_export(umbra_renderer r, uint32_t *counts, float *nodes,
                                     size_t *node_count)
{
    const char *fn = "umbra_renderer_part_export_deep";
    deep_state *s = NULL;
    umbra_status st = check_pieces(r, fn, &s);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_context ctx = r->ctx;
    cl_command_queue q = ctx->queue;
    const size_t n = s->map_size, T = s->tile, T2 = T * T, K = s->block_size;
    const size_t nf = 1 + s->channels;
    int32_t *head = NULL, *next = NULL;
    float *pool = NULL;
    UMBRA_CL(clEnqueueReadBuffer(q, s->counts, CL_TRUE, 0, n * n * sizeof(cl_uint), counts, 0,
                                 NULL, NULL));
    size_t total = 0;
    for (size_t t = 0; t < n * n; ++t)
        total += counts[t];
    if (!nodes) {
        *node_count = total;
        return UMBRA_SUCCESS;
    }
    if (*node_count < total)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: nodes holds %zu nodes, the piece has %zu", fn, *node_count, total);
    *node_count = total;
    if (total == 0)
        return UMBRA_SUCCESS;
    head = malloc(s->head_count);
    next = malloc(s->used_blocks * sizeof *next);
    pool = malloc(s->used_blocks * s->block_bytes);
    if (!head || !next || !pool) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
        goto fail;
    }
    UMBRA_CL(clEnqueueReadBuffer(q, s->head, CL_TRUE, 0, s->head_count, head, 0, NULL, NULL));
    UMBRA_CL(clEnqueueReadBuffer(q, s->next, CL_TRUE, 0, s->used_blocks * sizeof *next, next, 0,
                                 NULL, NULL));
    UMBRA_CL(clEnqueueReadBuffer(q, s->pool, CL_TRUE, 0, s->used_blocks * s->block_bytes, pool,
                                 0, NULL, NULL));
    float *dst = nodes;
    for (size_t y = 0; y < n; ++y)
        for (size_t x = 0; x < n; ++x) {
            const size_t tile = (y / T) * s->tiles_per_row + x / T, lane = (y % T) * T + x % T;
            int32_t b = head[tile];
            for (size_t j = 0; j < counts[y * n + x]; ++j) {
                if (j > 0 && j % K == 0)
                    b = next[b];
                memcpy(dst, pool + (((size_t)b * K + j % K) * T2 + lane) * nf, nf * sizeof *dst);
                dst += nf;
            }
        }
fail:
    free(head);
    free(next);
    free(pool);
    return st;
}

typedef struct deep_piece {
    float depth;  /* of its first node */
    size_t first; /* its first node's index in the nodes array */
    uint32_t count;
} deep_piece;

umbra_status umbra__deep_part_import(umbra_renderer r, uint32_t parts, const uint32_t *counts,
                                     const float *nodes, size_t node_count)
{
    const char *fn = "umbra_renderer_part_import_deep";
    deep_state *s = NULL;
    umbra_status st = check_pieces(r, fn, &s);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_context ctx = r->ctx;
    cl_command_queue q = ctx->queue;
    const size_t n = s->map_size, T = s->tile, T2 = T * T, K = s->block_size;
    const size_t nf = 1 + s->channels, texels = n * n, tpr = s->tiles_per_row;
    const size_t tiles = tpr * tpr;
    size_t *start = malloc((size_t)parts * texels * sizeof *start);
    uint32_t *merged = calloc(texels, sizeof *merged);
    size_t *tile_blocks = calloc(tiles, sizeof *tile_blocks);
    int32_t *head = malloc(tiles * sizeof *head);
    deep_piece *pieces = malloc((size_t)parts * sizeof *pieces);
    int32_t *next = NULL;
    float *pool = NULL;
    if (!start || !merged || !tile_blocks || !head || !pieces) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
        goto fail;
    }
    /* Where each part's piece of each texel starts (the parts' arrays one after another). */
    size_t at = 0;
    for (size_t p = 0; p < parts; ++p)
        for (size_t t = 0; t < texels; ++t) {
            start[p * texels + t] = at;
            at += counts[p * texels + t];
            merged[t] += counts[p * texels + t];
        }
    if (at != node_count) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: the counts add up to %zu nodes, node_count is %zu", fn, at,
                         node_count);
        goto fail;
    }
    for (size_t i = 0; i < node_count; ++i)
        for (size_t c = 0; c < nf; ++c)
            if (!(c == 0 ? !isnan(nodes[i * nf]) : nodes[i * nf + c] >= 0.0f &&
                                                       nodes[i * nf + c] <= 1.0f)) {
                st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "%s: node %zu: %s %g (a depth must not be NaN, a visibility "
                                 "must lie in [0, 1])", fn, i, c == 0 ? "depth" : "visibility",
                                 (double)nodes[i * nf + c]);
                goto fail;
            }
    /* Blocks per tile: its longest list, in layers of K. */
    for (size_t y = 0; y < n; ++y)
        for (size_t x = 0; x < n; ++x) {
            const size_t tile = (y / T) * tpr + x / T, need = (merged[y * n + x] + K - 1) / K;
            if (need > tile_blocks[tile])
                tile_blocks[tile] = need;
        }
    size_t blocks = 0;
    for (size_t t = 0; t < tiles; ++t) {
        head[t] = tile_blocks[t] ? (int32_t)blocks : -1;
        blocks += tile_blocks[t];
    }
    if (blocks >= ((size_t)1 << 31)) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "%s: the merged map needs %zu blocks, more than a map holds", fn, blocks);
        goto fail;
    }
    next = malloc((blocks ? blocks : 1) * sizeof *next);
    pool = calloc(blocks ? blocks : 1, s->block_bytes);
    if (!next || !pool) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
        goto fail;
    }
    for (size_t t = 0; t < tiles; ++t)
        for (size_t j = 0; j < tile_blocks[t]; ++j)
            next[head[t] + (int32_t)j] = j + 1 < tile_blocks[t] ? head[t] + (int32_t)j + 1 : -1;
    for (size_t y = 0; y < n; ++y)
        for (size_t x = 0; x < n; ++x) {
            const size_t t = y * n + x, tile = (y / T) * tpr + x / T, lane = (y % T) * T + x % T;
            /* The pieces lie in disjoint depth ranges (each part owns a run of the ray's
             * segments): in the order of their first depths (insertion sort, stable). */
            size_t np = 0;
            for (size_t p = 0; p < parts; ++p) {
                const uint32_t c = counts[p * texels + t];
                if (!c)
                    continue;
                deep_piece pc = {nodes[start[p * texels + t] * nf], start[p * texels + t], c};
                size_t k = np++;
                while (k > 0 && pieces[k - 1].depth > pc.depth) {
                    pieces[k] = pieces[k - 1];
                    --k;
                }
                pieces[k] = pc;
            }
            size_t j = 0;
            for (size_t k = 0; k < np; ++k)
                for (uint32_t i = 0; i < pieces[k].count; ++i, ++j) {
                    const size_t b = (size_t)head[tile] + j / K;
                    memcpy(pool + ((b * K + j % K) * T2 + lane) * nf,
                           nodes + (pieces[k].first + i) * nf, nf * sizeof *pool);
                }
        }
    if (!s->pool || s->pool_blocks < blocks || s->pool_override)
        if ((st = umbra__deep_alloc_pool(ctx, s, blocks ? blocks : 1)) != UMBRA_SUCCESS)
            goto fail;
    if (blocks) {
        UMBRA_CL(clEnqueueWriteBuffer(q, s->pool, CL_TRUE, 0, blocks * s->block_bytes, pool, 0,
                                      NULL, NULL));
        UMBRA_CL(clEnqueueWriteBuffer(q, s->next, CL_TRUE, 0, blocks * sizeof *next, next, 0,
                                      NULL, NULL));
    }
    UMBRA_CL(clEnqueueWriteBuffer(q, s->head, CL_TRUE, 0, tiles * sizeof *head, head, 0, NULL,
                                  NULL));
    UMBRA_CL(clEnqueueWriteBuffer(q, s->counts, CL_TRUE, 0, texels * sizeof *merged, merged, 0,
                                  NULL, NULL));
    s->used_blocks = blocks;
fail:
    free(start);
    free(merged);
    free(tile_blocks);
    free(head);
    free(pieces);
    free(next);
    free(pool);
    return st;
}
