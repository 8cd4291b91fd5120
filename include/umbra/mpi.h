// SPDX-License-Identifier: Apache-2.0
/* umbra/mpi.h: umbra_mpi, one volume rendered by the ranks of an MPI communicator, each holding
 * one part of it on its own device (docs/distributed.md).
 *
 * A library of its own (libumbra_mpi, CMake target umbra::mpi, built with -DUMBRA_WITH_MPI=ON)
 * over libumbra's part-aware core (umbra/part.h) and umbra_io, linking the MPI library the
 * application uses (Open MPI from Debian: libopenmpi-dev). What it adds is the communication:
 *   - the split of the global grid into px x py x pz parts on the brick grid, one per rank;
 *   - each rank reading only its part of the file (umbra_volume_read_box), with ghost layers,
 *     and the value range agreed over all ranks;
 *   - the light data in light order, over the ranks renumbered in light order (MPI_Comm_split):
 *     the march state (the threshold map's, the deep map's visibility) passed down that order,
 *     part to part; then for the threshold map a minimum of depths (MPI_Allreduce, MPI_MIN),
 *     for the deep map every rank's pieces of the map gathered on every rank (MPI_Allgather,
 *     MPI_Allgatherv) and merged;
 *   - the view composited in visibility order: MPI_Reduce_scatter_block with a non-commutative
 *     "over" MPI_Op on a communicator whose ranks are ordered front to back, then a gather; or,
 *     sequentially, every partial image gathered and composited front to back in one place.
 *
 * Every function here is collective over comm: all ranks call it with the same arguments where
 * marked, and all return the same status. A failure on any rank (a bad argument, a file, no
 * device) is agreed by a collective before anything else is exchanged, so no rank waits for one
 * that gave up: every rank returns the status of the lowest failing rank, and its message
 * ("rank R: ...") is recorded on each rank's context (when not NULL) and copied into the
 * caller's buffer. The library prints nothing and never calls MPI_Abort. */
#ifndef UMBRA_MPI_H
#define UMBRA_MPI_H

#include <stddef.h>
#include <stdint.h>

#include <mpi.h>

#include "umbra/io.h"
#include "umbra/part.h"
#include "umbra/umbra.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bytes of an agreed message (umbra_mpi_agree), NUL included. */
#define UMBRA_MPI_MESSAGE_MAX 1024

/* Collective: every rank passes its own status (UMBRA_SUCCESS when it is fine) and message
 * (NULL: its context's last message, or the status's name). All ranks return the status of the
 * lowest-numbered failing rank (UMBRA_SUCCESS when none failed); that rank's message, prefixed
 * "rank R: ", goes into message (size bytes, may be NULL) and is recorded on ctx (may be NULL).
 * An MPI error is UMBRA_ERROR_IO naming the call. */
UMBRA_API umbra_status umbra_mpi_agree(MPI_Comm comm, umbra_context ctx, umbra_status local,
                                       const char *local_message, char *message, size_t size);

/* How a volume is split over a communicator. */
typedef struct umbra_mpi_split_desc {
    size_t struct_size;      /* sizeof(umbra_mpi_split_desc); set by umbra_mpi_split_desc_init */
    uint32_t grid[3];        /* parts per axis px, py, pz, each >= 1; their product must be the
                                communicator's size (default 0: refused) */
    uint32_t brick_size;     /* the volume's brick edge, faces lie on multiples of it (default
                                16, umbra_volume_desc.brick_size) */
    uint32_t ghost;          /* ghost layers beyond each shared face, at most
                                UMBRA_PART_MAX_GHOST (default 1; umbra_part_ghost_needed gives
                                what the render options need) */
} umbra_mpi_split_desc;

/* Fills desc with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_mpi_split_desc_init(umbra_mpi_split_desc *desc);

/* Collective (the same dims and desc on every rank): this rank's part of a global grid of dims
 * voxels. Rank r is cell (r mod px, (r / px) mod py, r / (px py)); along an axis of B bricks
 * split in n, cell c holds bricks [floor(c B / n), floor((c + 1) B / n)), so every part holds at
 * least one brick and the parts tile the grid. Refused on every rank with
 * UMBRA_ERROR_INVALID_ARGUMENT naming the values: a grid whose product is not the
 * communicator's size, more parts along an axis than bricks, a zero size, brick size or too many
 * ghosts. cell (may be NULL) receives the rank's cell. */
UMBRA_API umbra_status umbra_mpi_split(MPI_Comm comm, umbra_context ctx, const uint32_t dims[3],
                                       const umbra_mpi_split_desc *desc, umbra_part_desc *part,
                                       uint32_t cell[3]);

/* What a rank did and sent: per-stage wall times in milliseconds (each rank's own, measured
 * around its calls, waits included) and bytes. */
typedef struct umbra_mpi_stats {
    double load_ms;          /* header, own box of the file, value range, part volume */
    double light_exchange_ms;/* the light data crossing ranks (state, minima, pieces) */
    double build_ms;         /* the part's light passes (exports of transmittance and depths) */
    double render_ms;        /* the part's partial image */
    double composite_ms;     /* reduce-scatter and gather, or the sequential composite */
    uint64_t bytes_sent;     /* payload this rank handed to MPI (each collective's send buffer,
                                once per call; what the MPI library's algorithm moves for it is
                                in docs/distributed.md) */
    uint64_t volume_bytes;   /* host bytes of this rank's voxels (core and ghosts) as read */
    uint64_t file_bytes_read;/* bytes of the file this rank read (the box's rows) */
} umbra_mpi_stats;

/* A part volume loaded by umbra_mpi_load. */
typedef struct umbra_mpi_volume {
    umbra_volume volume;          /* the part (umbra_volume_create_part); release it */
    umbra_part_desc part;         /* where it lies */
    uint32_t cell[3];             /* its cell of the split grid */
    umbra_volume_file_info file;  /* what the file's header declares (global dims, placement) */
    float value_min, value_max;   /* the global value range the part normalises with */
} umbra_mpi_volume;

/* Collective (the same path, file, split and range on every rank): every rank reads the header
 * of path, splits its grid (umbra_mpi_split), reads only its part's box (core and ghosts) of the
 * file (umbra_volume_read_box: NRRD, NIfTI, MetaImage, Voreen .dat, raw with file->raw), agrees the
 * value range (range NULL: the minimum and maximum over all ranks' cores, as one device computes
 * it of the whole volume; else range[0], range[1]) and makes its part volume on ctx. file (may
 * be NULL: the defaults) gives file->raw and file->options; its box is not used. stats (may be
 * NULL) gets load_ms, volume_bytes and file_bytes_read. out is zeroed on failure. */
UMBRA_API umbra_status umbra_mpi_load(MPI_Comm comm, umbra_context ctx, const char *path,
                                      const umbra_volume_box_desc *file,
                                      const umbra_mpi_split_desc *split, const float *range,
                                      umbra_mpi_volume *out, umbra_mpi_stats *stats);

/* Collective: a communicator of comm's ranks in visibility order of their parts (part, this
 * rank's; all ranks' are gathered) from a point (is_point nonzero: an eye or a point light) or
 * along a direction, in the world of placement (umbra_volume_get_info of the part volume): rank
 * 0 of *ordered is the part met first. Free it with MPI_Comm_free. */
UMBRA_API umbra_status umbra_mpi_order(MPI_Comm comm, umbra_context ctx,
                                       const umbra_part_desc *part,
                                       const umbra_volume_info *placement, const float where[3],
                                       int is_point, MPI_Comm *ordered);

/* Collective: the light passes of renderer r (its part volume, transfer functions, technique and
 * light set; volume and light the ones set on r) and the exchange between them, as
 * umbra_renderer_part_light_info says, on comm's ranks in light order: each part imports the
 * march state the part before it exported and exports its own for the next (MPI_Recv, MPI_Send:
 * P - 1 steps one after the other); then for UMBRA_PART_LIGHT_TAU_DEPTH the depths' minimum over
 * all ranks (MPI_Allreduce, MPI_MIN), imported; for UMBRA_PART_LIGHT_TAU (the deep map) every
 * rank's pieces of the map (MPI_Allgather of the counts, MPI_Allgatherv of the nodes), merged
 * into each rank's map. Whole maps cross: a lookup near a part's rim reads texels whose rays pass
 * through other parts, so no rank's share is cut to its own column of parts. After it r renders its part (umbra_mpi_render). Nothing to do for
 * UMBRA_SHADOW_NONE. stats (may be NULL) gets build_ms, light_exchange_ms and bytes_sent added. */
UMBRA_API umbra_status umbra_mpi_light(MPI_Comm comm, umbra_context ctx, umbra_renderer r,
                                       umbra_volume volume, const umbra_light *light,
                                       umbra_mpi_stats *stats);

/* How umbra_mpi_render composites. */
typedef enum umbra_mpi_composite_mode {
    /* MPI_Reduce_scatter_block of the full-frame partial images with the non-commutative over
     * operator on the ranks in view order (every rank composites 1/P of the image), then
     * MPI_Gather of the pieces at root. */
    UMBRA_MPI_COMPOSITE_REDUCE_SCATTER = 0,
    /* Every partial image (its rectangle only) gathered at root (MPI_Gatherv) and composited
     * there front to back, one after the other: the order of the floating-point operations does
     * not depend on the number of ranks or the MPI library's reduction tree. */
    UMBRA_MPI_COMPOSITE_SEQUENTIAL = 1,
    /* One frame passed down the ranks in view order (MPI_Send, MPI_Recv), each rank adding its
     * part's samples to the accumulation of the parts in front (umbra_renderer_render_part_into)
     * and the last handing it to root: one device's image bit for bit, where the two modes above
     * round the over operator differently (within 1e-6). The renders run one after the other, so
     * the render stage takes the sum of the ranks' times, not the largest, and each rank sends a
     * whole frame (docs/distributed.md). umbra_mpi_render only (umbra_mpi_composite refuses it:
     * it has no renderer). */
    UMBRA_MPI_COMPOSITE_CHAIN = 2
} umbra_mpi_composite_mode;

/* Collective: renders r's part (umbra_renderer_render_part of a width x height image; volume and
 * camera the ones set on r) and composites all ranks' partial images in view order, over background
 * (4 floats, premultiplied; NULL: transparent), into image at rank root of comm (width * height
 * premultiplied RGBA floats, row 0 at the top; NULL on other ranks). stats (may be NULL) gets
 * render_ms, composite_ms and bytes_sent added. */
UMBRA_API umbra_status umbra_mpi_render(MPI_Comm comm, umbra_context ctx, umbra_renderer r,
                                        umbra_volume volume, const umbra_camera *camera,
                                        uint32_t width,
                                        uint32_t height, const float background[4],
                                        umbra_mpi_composite_mode mode, int root, float *image,
                                        umbra_mpi_stats *stats);

/* Collective: the composite step alone, for partial images made elsewhere. Each rank gives its
 * premultiplied partial image part (rect->width x rect->height RGBA floats; an empty rect gives
 * nothing) of a width x height frame; ordered is comm's ranks in view order (umbra_mpi_order),
 * root a rank of ordered. The result is written to image at root as umbra_mpi_render writes it
 * (over background). */
UMBRA_API umbra_status umbra_mpi_composite(MPI_Comm ordered, umbra_context ctx, const float *part,
                                           const umbra_part_rect *rect, uint32_t width,
                                           uint32_t height, const float background[4],
                                           umbra_mpi_composite_mode mode, int root, float *image,
                                           umbra_mpi_stats *stats);

#ifdef __cplusplus
}
#endif
#endif
