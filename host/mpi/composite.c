// SPDX-License-Identifier: Apache-2.0
/* host/mpi/composite.c: umbra_mpi's image composites (include/umbra/mpi.h), the view side of
 * host/mpi/mpi.c. The ranks are first put in view order (umbra__mpi_view_ordered). Then either
 * each rank renders its part's rectangle and umbra_mpi_composite combines them:
 * MPI_Reduce_scatter_block with a non-commutative MPI_Op (the operands of a non-commutative
 * reduction are combined in rank order, so front over back in the view-ordered communicator)
 * and MPI_Gather to the root, or MPI_Gatherv of the rectangles to the root, which composites
 * them in order; or, for UMBRA_MPI_COMPOSITE_CHAIN, the frame passes from rank to rank in view
 * order (MPI_Send, MPI_Recv), each adding its part's samples (render_chain). As everywhere in
 * umbra_mpi, every failure is agreed before the next exchange. */
#define _POSIX_C_SOURCE 200809L

#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_internal.h"

/* The MPI_Op: inout = in over inout. MPI combines the operands of a non-commutative operator in
 * rank order, in (the lower ranks' partial result) and inout (the higher ones'), so with the
 * ranks in view order the reduction is front over back. */
static void over_op(void *in, void *inout, int *len, MPI_Datatype *type)
{
    (void)type;
    umbra_part_over(in, inout, inout, (size_t)*len);
}

umbra_status umbra_mpi_composite(MPI_Comm ordered, umbra_context ctx, const float *part,
                                 const umbra_part_rect *rect, uint32_t width, uint32_t height,
                                 const float background[4], umbra_mpi_composite_mode mode,
                                 int root, float *image, umbra_mpi_stats *stats)
{
    const double t0 = now_ms();
    const size_t pixels = (size_t)width * height;
    int me = 0, size = 1;
    float *frame = NULL, *piece = NULL, *all = NULL;
    umbra_part_rect *rects = NULL;
    int *counts = NULL, *displs = NULL;
    umbra_status st = UMBRA_SUCCESS;
    MPI_Comm_rank(ordered, &me);
    MPI_Comm_size(ordered, &size);
    const size_t block = (pixels + (size_t)size - 1) / (size_t)size;

    if (mode == UMBRA_MPI_COMPOSITE_CHAIN)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_composite: mode chain renders while it composites: use "
                             "umbra_mpi_render");
    else if (mode != UMBRA_MPI_COMPOSITE_REDUCE_SCATTER && mode != UMBRA_MPI_COMPOSITE_SEQUENTIAL)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_composite: mode %d is unknown", (int)mode);
    else if (!rect || (rect->width && rect->height && !part) || (me == root && !image) ||
             width == 0 || height == 0 || root < 0 || root >= size)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_composite: image %u x %u, root %d of %d ranks, "
                             "or a NULL rect, part or image at the root",
                             width, height, root, size);
    else if ((uint64_t)rect->x + rect->width > width || (uint64_t)rect->y + rect->height > height)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_composite: rect %u,%u %u x %u outside the "
                             "%u x %u image",
                             rect->x, rect->y, rect->width, rect->height, width, height);
    else if (block * (size_t)size * 4 > INT_MAX)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "umbra_mpi_composite: an image of %zu pixels over %d ranks "
                             "passes MPI's int counts",
                             pixels, size);
    st = agree(ordered, ctx, st);
    if (st != UMBRA_SUCCESS)
        return st;

    if (mode == UMBRA_MPI_COMPOSITE_REDUCE_SCATTER) {
        MPI_Datatype pixel;
        MPI_Op over;
        frame = calloc(block * (size_t)size * 4, sizeof *frame);
        piece = malloc(block * 4 * sizeof *piece);
        if (!frame || !piece)
            st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                 "umbra_mpi_composite: cannot allocate a %u x %u frame",
                                 width, height);
        st = agree(ordered, ctx, st);
        if (st != UMBRA_SUCCESS)
            goto fail;
        for (uint32_t y = 0; y < rect->height; ++y)
            memcpy(frame + ((size_t)(rect->y + y) * width + rect->x) * 4,
                   part + (size_t)y * rect->width * 4, (size_t)rect->width * 4 * sizeof *frame);
        MPI_Type_contiguous(4, MPI_FLOAT, &pixel);
        MPI_Type_commit(&pixel);
        MPI_Op_create(over_op, 0, &over);
        MPI_Reduce_scatter_block(frame, piece, (int)block, pixel, over, ordered);
        MPI_Gather(piece, (int)block, pixel, frame, (int)block, pixel, root, ordered);
        MPI_Op_free(&over);
        MPI_Type_free(&pixel);
        if (stats)
            stats->bytes_sent += (block * (size_t)size + (me == root ? 0 : block)) * 16;
        if (me == root)
            memcpy(image, frame, pixels * 4 * sizeof *image);
    } else {
        size_t total = 0;
        int mine = (int)((size_t)rect->width * rect->height * 4);
        if (me == root) {
            rects = malloc((size_t)size * sizeof *rects);
            counts = malloc((size_t)size * sizeof *counts);
            displs = malloc((size_t)size * sizeof *displs);
        }
        if (me == root && (!rects || !counts || !displs))
            st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                 "umbra_mpi_composite: out of memory");
        st = agree(ordered, ctx, st);
        if (st != UMBRA_SUCCESS)
            goto fail;
        MPI_Gather(rect, (int)sizeof *rect, MPI_BYTE, rects, (int)sizeof *rect, MPI_BYTE, root,
                   ordered);
        if (me == root) {
            for (int i = 0; i < size; ++i) {
                counts[i] = (int)((size_t)rects[i].width * rects[i].height * 4);
                displs[i] = (int)total;
                total += (size_t)counts[i];
            }
            if (total > INT_MAX)
                st = umbra__mpi_fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                                     "umbra_mpi_composite: the partial images hold %zu "
                                     "floats, past MPI's int counts",
                                     total);
            else if (!(all = malloc((total ? total : 1) * sizeof *all)))
                st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                     "umbra_mpi_composite: out of memory");
        }
        st = agree(ordered, ctx, st);
        if (st != UMBRA_SUCCESS)
            goto fail;
        MPI_Gatherv(part, mine, MPI_FLOAT, all, counts, displs, MPI_FLOAT, root, ordered);
        if (stats && me != root)
            stats->bytes_sent += (uint64_t)mine * sizeof(float);
        if (me == root) {
            memset(image, 0, pixels * 4 * sizeof *image);
            for (int i = 0; i < size; ++i)
                if (counts[i])
                    umbra_part_composite(image, width, height, all + displs[i], &rects[i]);
        }
    }
    if (me == root && background)
        umbra_part_background(image, pixels, background);
fail:
    free(all);
    free(displs);
    free(counts);
    free(rects);
    free(piece);
    free(frame);
    if (stats)
        stats->composite_ms += now_ms() - t0;
    return st;
}

/* UMBRA_MPI_COMPOSITE_CHAIN: the frame goes down the ranks in view order, each adding its
 * part's samples to the accumulation of the parts in front (umbra_renderer_render_part_into),
 * then to root, which puts the background under it: one device's image bit for bit. The renders
 * run one after the other (a rank waits for the ones in front of it), as the light chain of
 * umbra_mpi_light does; a rank that fails passes its status on with the frame, and the agreement
 * at the end reports the first failure. */
static umbra_status render_chain(MPI_Comm comm, umbra_context ctx, umbra_renderer r,
                                 umbra_volume volume, const umbra_camera *camera, uint32_t width,
                                 uint32_t height, const float background[4], int root,
                                 float *image, umbra_mpi_stats *stats)
{
    umbra_part_desc part;
    umbra_volume_info placement;
    float *frame = NULL, flag = 0.0f;
    MPI_Comm ordered = MPI_COMM_NULL;
    int me = 0, pos = 0, size = 1, oroot = -1;
    const size_t floats = (size_t)width * height * 4;
    umbra_status st;

    MPI_Comm_rank(comm, &me);
    MPI_Comm_size(comm, &size);
    umbra_part_desc_init(&part);
    st = camera ? umbra_volume_get_part(volume, &part)
                : umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                  "umbra_mpi_render: camera is NULL");
    if (st == UMBRA_SUCCESS && (root < 0 || root >= size))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_render: root %d of %d ranks", root, size);
    if (st == UMBRA_SUCCESS)
        st = umbra_volume_get_info(volume, &placement);
    if (st == UMBRA_SUCCESS && (width == 0 || height == 0 || floats > INT_MAX))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_render: chain composite of a %u x %u image: it must "
                             "be non-empty and within MPI's int counts (%zu floats)", width,
                             height, floats);
    if (st == UMBRA_SUCCESS && me == root && !image)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "umbra_mpi_render: image is NULL at root");
    if (st == UMBRA_SUCCESS && !(frame = malloc(floats * sizeof *frame)))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi_render: cannot allocate a %u x %u frame", width, height);
    st = agree(comm, ctx, st);
    if (st == UMBRA_SUCCESS)
        st = umbra__mpi_view_ordered(comm, ctx, &part, &placement, camera, root, &ordered,
                                     &oroot);
    if (st != UMBRA_SUCCESS)
        goto fail;
    MPI_Comm_rank(ordered, &pos);
    MPI_Comm_size(ordered, &size);

    double t = now_ms();
    if (pos == 0) {
        memset(frame, 0, floats * sizeof *frame);
    } else {
        MPI_Recv(frame, (int)floats, MPI_FLOAT, pos - 1, 0, ordered, MPI_STATUS_IGNORE);
        MPI_Recv(&flag, 1, MPI_FLOAT, pos - 1, 1, ordered, MPI_STATUS_IGNORE);
        if (flag != 0.0f)
            st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "umbra_mpi_render: a rank before this one in view order failed");
    }
    if (stats)
        stats->composite_ms += now_ms() - t;
    t = now_ms();
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render_part_into(r, width, height, NULL, frame);
    if (stats)
        stats->render_ms += now_ms() - t;
    t = now_ms();
    flag = st == UMBRA_SUCCESS ? 0.0f : 1.0f;
    const int next = pos + 1 < size ? pos + 1 : oroot; /* the last rank hands it to root */
    if (next != pos) {
        MPI_Send(frame, (int)floats, MPI_FLOAT, next, 0, ordered);
        MPI_Send(&flag, 1, MPI_FLOAT, next, 1, ordered);
        if (stats)
            stats->bytes_sent += floats * sizeof *frame + sizeof flag;
    }
    if (pos == oroot && pos != size - 1) {
        MPI_Recv(frame, (int)floats, MPI_FLOAT, size - 1, 0, ordered, MPI_STATUS_IGNORE);
        MPI_Recv(&flag, 1, MPI_FLOAT, size - 1, 1, ordered, MPI_STATUS_IGNORE);
    }
    if (pos == oroot && st == UMBRA_SUCCESS && flag == 0.0f) {
        umbra_part_background(frame, (size_t)width * height, background ? background
                                                                        : (const float[4]){0});
        memcpy(image, frame, floats * sizeof *image);
    }
    if (stats)
        stats->composite_ms += now_ms() - t;
    st = agree(comm, ctx, st);
fail:
    if (ordered != MPI_COMM_NULL)
        MPI_Comm_free(&ordered);
    free(frame);
    return st;
}

umbra_status umbra_mpi_render(MPI_Comm comm, umbra_context ctx, umbra_renderer r,
                              umbra_volume volume, const umbra_camera *camera, uint32_t width,
                              uint32_t height, const float background[4],
                              umbra_mpi_composite_mode mode, int root, float *image,
                              umbra_mpi_stats *stats)
{
    if (mode == UMBRA_MPI_COMPOSITE_CHAIN)
        return render_chain(comm, ctx, r, volume, camera, width, height, background, root, image,
                            stats);
    umbra_part_rect rect = {0, 0, 0, 0};
    umbra_part_desc part;
    umbra_volume_info placement;
    float *pixels = NULL;
    MPI_Comm ordered = MPI_COMM_NULL;
    int me = 0, oroot = -1;
    double t = now_ms();
    umbra_status st;

    umbra_part_desc_init(&part);
    st = camera ? umbra_volume_get_part(volume, &part)
                : umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                  "umbra_mpi_render: camera is NULL");
    if (st == UMBRA_SUCCESS)
        st = umbra_volume_get_info(volume, &placement);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_part_rect(r, width, height, &rect);
    if (st == UMBRA_SUCCESS) {
        pixels = malloc(((size_t)rect.width * rect.height * 4 + 1) * sizeof *pixels);
        st = pixels ? umbra_renderer_render_part(r, width, height, &rect, pixels)
                    : umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                      "umbra_mpi_render: out of memory");
    }
    st = agree(comm, ctx, st);
    if (stats)
        stats->render_ms += now_ms() - t;
    if (st != UMBRA_SUCCESS)
        goto fail;
    /* root, a rank of comm, in the view-ordered communicator (-1: none, refused there). */
    st = umbra__mpi_view_ordered(comm, ctx, &part, &placement, camera, root, &ordered, &oroot);
    if (st != UMBRA_SUCCESS)
        goto fail;
    MPI_Comm_rank(comm, &me);
    st = umbra_mpi_composite(ordered, ctx, pixels, &rect, width, height, background, mode, oroot,
                             me == root ? image : NULL, stats);
fail:
    if (ordered != MPI_COMM_NULL)
        MPI_Comm_free(&ordered);
    free(pixels);
    return st;
}
