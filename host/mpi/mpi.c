// SPDX-License-Identifier: Apache-2.0
/* host/mpi/mpi.c: umbra_mpi (include/umbra/mpi.h), the communication around libumbra's parts:
 * the agreement, the split, the load, the orders and the light; the image composites are in
 * host/mpi/composite.c.
 *
 * Everything is collective and every failure is agreed (umbra_mpi_agree) before the next
 * exchange, so a rank that fails never leaves the others waiting in a collective it will not
 * enter. Only MPI's own collectives move data here: MPI_Allreduce (the value range, depths),
 * MPI_Allgather(v) (the parts, the deep map's pieces) and MPI_Comm_split (the ranks renumbered
 * in light or view order). One chain passes data from rank to rank in light order instead
 * (MPI_Send, MPI_Recv), where each step needs the one before: the threshold and CSSM march
 * state (umbra_mpi_light). */
#define _POSIX_C_SOURCE 200809L

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_internal.h"

static umbra_status note(char *buf, umbra_status st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static umbra_status note(char *buf, umbra_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, MSG, fmt, ap);
    va_end(ap);
    return st;
}

umbra_status umbra_mpi_agree(MPI_Comm comm, umbra_context ctx, umbra_status local,
                             const char *local_message, char *message, size_t size)
{
    struct {
        int status;
        char text[MSG];
    } agreed;
    int me = 0, mine, first = INT_MAX;
    if (message && size)
        message[0] = '\0';
    if (MPI_Comm_rank(comm, &me) != MPI_SUCCESS)
        return UMBRA_ERROR_IO;
    mine = local == UMBRA_SUCCESS ? INT_MAX : me;
    if (MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm) != MPI_SUCCESS)
        return UMBRA_ERROR_IO;
    if (first == INT_MAX)
        return UMBRA_SUCCESS;
    memset(&agreed, 0, sizeof agreed);
    if (me == first) {
        const char *text = local_message;
        if (!text && ctx)
            text = umbra_context_last_message(ctx);
        if (!text || !*text)
            text = umbra_status_to_string(local);
        agreed.status = (int)local;
        snprintf(agreed.text, sizeof agreed.text, "rank %d: %s", me, text);
    }
    if (MPI_Bcast(&agreed, (int)sizeof agreed, MPI_BYTE, first, comm) != MPI_SUCCESS)
        return UMBRA_ERROR_IO;
    agreed.text[MSG - 1] = '\0';
    if (message && size)
        snprintf(message, size, "%s", agreed.text);
    if (ctx)
        umbra_context_record_error(ctx, (umbra_status)agreed.status, agreed.text);
    return (umbra_status)agreed.status;
}

umbra_status umbra__mpi_fail(umbra_context ctx, umbra_status status, const char *fmt, ...)
{
    char text[MSG];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    return umbra_context_record_error(ctx, status, text);
}

void umbra_mpi_split_desc_init(umbra_mpi_split_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
    desc->brick_size = 16;
    desc->ghost = 1;
}

static umbra_status split_local(MPI_Comm comm, const uint32_t dims[3],
                                const umbra_mpi_split_desc *d, umbra_part_desc *part,
                                uint32_t cell[3], char *msg)
{
    static const char axis[3] = {'x', 'y', 'z'};
    int me = 0, size = 1;
    uint64_t product = 1;
    MPI_Comm_rank(comm, &me);
    MPI_Comm_size(comm, &size);
    if (!dims || !d || !part)
        return note(msg, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_mpi_split: %s is NULL",
                    !dims ? "dims" : !d ? "desc" : "part");
    if (d->struct_size != sizeof *d)
        return note(msg, UMBRA_ERROR_INVALID_ARGUMENT,
                    "umbra_mpi_split: desc->struct_size is %zu, expected %zu (call "
                    "umbra_mpi_split_desc_init)",
                    d->struct_size, sizeof *d);
    if (d->brick_size == 0 || d->ghost > UMBRA_PART_MAX_GHOST)
        return note(msg, UMBRA_ERROR_INVALID_ARGUMENT,
                    "umbra_mpi_split: brick size %u (must be > 0), ghost %u (at most %u)",
                    d->brick_size, d->ghost, UMBRA_PART_MAX_GHOST);
    for (int a = 0; a < 3; ++a)
        product *= d->grid[a];
    if (product != (uint64_t)size)
        return note(msg, UMBRA_ERROR_INVALID_ARGUMENT,
                    "umbra_mpi_split: the grid %u x %u x %u makes %llu parts, but the "
                    "communicator has %d ranks: the parts must tile it, one per rank",
                    d->grid[0], d->grid[1], d->grid[2], (unsigned long long)product, size);
    umbra_part_desc_init(part);
    uint32_t c[3] = {(uint32_t)me % d->grid[0], ((uint32_t)me / d->grid[0]) % d->grid[1],
                     (uint32_t)me / (d->grid[0] * d->grid[1])};
    for (int a = 0; a < 3; ++a) {
        uint64_t bricks = dims[a] == 0 ? 0 : (dims[a] + (uint64_t)d->brick_size - 1) / d->brick_size;
        if (dims[a] == 0)
            return note(msg, UMBRA_ERROR_INVALID_ARGUMENT,
                        "umbra_mpi_split: dims %u x %u x %u: every size must be > 0", dims[0],
                        dims[1], dims[2]);
        if (d->grid[a] > bricks)
            return note(msg, UMBRA_ERROR_INVALID_ARGUMENT,
                        "umbra_mpi_split: %u parts along %c, but the volume has %llu bricks "
                        "there (%u voxels, brick size %u): at most one part per brick",
                        d->grid[a], axis[a], (unsigned long long)bricks, dims[a], d->brick_size);
        uint64_t lo = c[a] * bricks / d->grid[a] * d->brick_size;
        uint64_t hi = (c[a] + 1) * bricks / d->grid[a] * d->brick_size;
        if (hi > dims[a])
            hi = dims[a];
        part->global_dims[a] = dims[a];
        part->offset[a] = (uint32_t)lo;
        part->size[a] = (uint32_t)(hi - lo);
        part->ghost_lo[a] = lo < d->ghost ? (uint32_t)lo : d->ghost;
        part->ghost_hi[a] = dims[a] - hi < d->ghost ? (uint32_t)(dims[a] - hi) : d->ghost;
        if (cell)
            cell[a] = c[a];
    }
    return UMBRA_SUCCESS;
}

umbra_status umbra_mpi_split(MPI_Comm comm, umbra_context ctx, const uint32_t dims[3],
                             const umbra_mpi_split_desc *desc, umbra_part_desc *part,
                             uint32_t cell[3])
{
    char msg[MSG] = "";
    umbra_status st = split_local(comm, dims, desc, part, cell, msg);
    return umbra_mpi_agree(comm, ctx, st, st == UMBRA_SUCCESS ? NULL : msg, NULL, 0);
}

/* ---- loading ------------------------------------------------------------------------------ */

/* Min and max of the part's core (the carried box minus the ghosts) of voxels. */
static void core_range(const void *voxels, umbra_scalar_type type, const umbra_part_desc *p,
                       double *lo, double *hi)
{
    const uint32_t nx = p->size[0] + p->ghost_lo[0] + p->ghost_hi[0];
    const uint32_t ny = p->size[1] + p->ghost_lo[1] + p->ghost_hi[1];
    double mn = INFINITY, mx = -INFINITY;
    for (uint32_t z = 0; z < p->size[2]; ++z) {
        for (uint32_t y = 0; y < p->size[1]; ++y) {
            size_t at = ((size_t)(z + p->ghost_lo[2]) * ny + y + p->ghost_lo[1]) * nx +
                        p->ghost_lo[0];
            for (uint32_t x = 0; x < p->size[0]; ++x, ++at) {
                double v;
                switch (type) {
                case UMBRA_UINT8: v = ((const uint8_t *)voxels)[at]; break;
                case UMBRA_UINT16: v = ((const uint16_t *)voxels)[at]; break;
                case UMBRA_INT16: v = ((const int16_t *)voxels)[at]; break;
                default: v = ((const float *)voxels)[at]; break;
                }
                mn = v < mn ? v : mn;
                mx = v > mx ? v : mx;
            }
        }
    }
    *lo = mn;
    *hi = mx;
}

umbra_status umbra_mpi_load(MPI_Comm comm, umbra_context ctx, const char *path,
                            const umbra_volume_box_desc *file, const umbra_mpi_split_desc *split,
                            const float *range, umbra_mpi_volume *out, umbra_mpi_stats *stats)
{
    const double t0 = now_ms();
    umbra_volume_box_desc box;
    void *voxels = NULL;
    umbra_status st;
    double lo = 0, hi = 0, g[2];
    size_t voxel_count = 1;

    if (!out)
        return umbra_mpi_agree(comm, ctx, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_mpi_load: out is NULL",
                               NULL, 0);
    memset(out, 0, sizeof *out);
    umbra_volume_box_desc_init(&box);
    if (file) {
        box.raw = file->raw;
        box.options = file->options;
    }
    /* 1. The header, on every rank (a few hundred bytes). */
    st = umbra_volume_read_box(ctx, path, &box, &out->file, &voxels);
    if (st == UMBRA_SUCCESS && out->file.channels != 1)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "umbra_mpi_load: a volume of several channels is not "
                             "split (a part holds one channel)");
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS)
        goto fail;
    /* 2. The split of its grid. */
    st = umbra_mpi_split(comm, ctx, out->file.dims, split, &out->part, out->cell);
    if (st != UMBRA_SUCCESS)
        goto fail;
    /* 3. This rank's box, ghosts included, and nothing else of the file. */
    for (int a = 0; a < 3; ++a) {
        box.origin[a] = out->part.offset[a] - out->part.ghost_lo[a];
        box.size[a] = out->part.size[a] + out->part.ghost_lo[a] + out->part.ghost_hi[a];
        voxel_count *= box.size[a];
    }
    st = agree(comm, ctx, umbra_volume_read_box(ctx, path, &box, &out->file, &voxels));
    if (st != UMBRA_SUCCESS)
        goto fail;
    if (stats) {
        stats->volume_bytes = voxel_count * umbra_scalar_type_size(out->file.type);
        stats->file_bytes_read = stats->volume_bytes;
    }
    /* 4. The value range: the global minimum and maximum, as one device computes them. */
    if (range) {
        g[0] = range[0];
        g[1] = range[1];
    } else {
        double mine[2];
        core_range(voxels, out->file.type, &out->part, &lo, &hi);
        mine[0] = lo;
        mine[1] = -hi;
        if (MPI_Allreduce(mine, g, 2, MPI_DOUBLE, MPI_MIN, comm) != MPI_SUCCESS) {
            st = umbra_mpi_agree(comm, ctx, UMBRA_ERROR_IO, "umbra_mpi_load: MPI_Allreduce failed",
                                 NULL, 0);
            goto fail;
        }
        g[1] = -g[1];
        if (!(g[1] > g[0]))
            g[1] = g[0] + 1.0; /* a constant volume maps to 0, as on one device */
    }
    out->value_min = (float)g[0];
    out->value_max = (float)g[1];
    /* 5. The part volume. */
    {
        umbra_volume_desc vd;
        umbra_volume_desc_init(&vd);
        vd.data = voxels;
        vd.type = out->file.type;
        memcpy(vd.dims, box.size, sizeof vd.dims);
        memcpy(vd.spacing, out->file.spacing, sizeof vd.spacing);
        vd.value_range_given = 1;
        vd.value_min = out->value_min;
        vd.value_max = out->value_max;
        vd.brick_size = split ? split->brick_size : 16;
        if (out->file.transform_given) {
            vd.transform_given = 1;
            memcpy(vd.origin, out->file.origin, sizeof vd.origin);
            memcpy(vd.directions, out->file.directions, sizeof vd.directions);
        }
        st = umbra_volume_create_part(ctx, &vd, &out->part, &out->volume);
    }
    st = agree(comm, ctx, st);
fail:
    free(voxels);
    if (st != UMBRA_SUCCESS) {
        umbra_volume_release(out->volume);
        memset(out, 0, sizeof *out);
    }
    if (stats)
        stats->load_ms += now_ms() - t0;
    return st;
}

/* ---- order -------------------------------------------------------------------------------- */

/* All ranks' parts, in rank order (malloc'ed). */
static umbra_status gather_parts(MPI_Comm comm, umbra_context ctx, const umbra_part_desc *part,
                                 umbra_part_desc **all, int *count)
{
    int size = 1;
    umbra_status st = UMBRA_SUCCESS;
    MPI_Comm_size(comm, &size);
    *count = size;
    *all = calloc((size_t)size, sizeof **all);
    if (!*all)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi: cannot allocate the parts of the ranks");
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS) {
        free(*all);
        *all = NULL;
        return st;
    }
    MPI_Allgather(part, (int)sizeof *part, MPI_BYTE, *all, (int)sizeof *part, MPI_BYTE, comm);
    return UMBRA_SUCCESS;
}

/* comm's ranks renumbered by their position in order (order[i]: the rank met i-th). */
static umbra_status split_in_order(MPI_Comm comm, umbra_context ctx, const uint32_t *order,
                                   int count, MPI_Comm *ordered)
{
    int me = 0, pos = 0;
    MPI_Comm_rank(comm, &me);
    for (int i = 0; i < count; ++i)
        if (order[i] == (uint32_t)me)
            pos = i;
    if (MPI_Comm_split(comm, 0, pos, ordered) != MPI_SUCCESS)
        return umbra_mpi_agree(comm, ctx, UMBRA_ERROR_IO, "umbra_mpi: MPI_Comm_split failed", NULL,
                               0);
    return UMBRA_SUCCESS;
}

umbra_status umbra_mpi_order(MPI_Comm comm, umbra_context ctx, const umbra_part_desc *part,
                             const umbra_volume_info *placement, const float where[3],
                             int is_point, MPI_Comm *ordered)
{
    umbra_part_desc *all = NULL;
    uint32_t *order = NULL;
    int count = 0;
    umbra_status st;
    if (!part || !placement || !where || !ordered)
        return umbra_mpi_agree(comm, ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "umbra_mpi_order: an argument is NULL", NULL, 0);
    *ordered = MPI_COMM_NULL;
    st = gather_parts(comm, ctx, part, &all, &count);
    if (st != UMBRA_SUCCESS)
        return st;
    order = malloc((size_t)count * sizeof *order);
    st = order ? umbra_part_visibility_order(all, (uint32_t)count, placement, where, is_point,
                                             order)
               : UMBRA_ERROR_OUT_OF_MEMORY;
    st = agree(comm, ctx, st);
    if (st == UMBRA_SUCCESS)
        st = split_in_order(comm, ctx, order, count, ordered);
    free(order);
    free(all);
    return st;
}

umbra_status umbra__mpi_view_ordered(MPI_Comm comm, umbra_context ctx,
                                     const umbra_part_desc *part,
                                     const umbra_volume_info *placement,
                                     const umbra_camera *camera, int root, MPI_Comm *ordered,
                                     int *ordered_root)
{
    umbra_part_desc *all = NULL;
    uint32_t *order = NULL;
    int count = 0;
    umbra_status st = gather_parts(comm, ctx, part, &all, &count);
    if (st != UMBRA_SUCCESS)
        return st;
    order = malloc((size_t)count * sizeof *order);
    st = order ? umbra_part_view_order(all, (uint32_t)count, placement, camera, order)
               : UMBRA_ERROR_OUT_OF_MEMORY;
    st = agree(comm, ctx, st);
    if (st == UMBRA_SUCCESS)
        st = split_in_order(comm, ctx, order, count, ordered);
    *ordered_root = -1;
    for (int i = 0; st == UMBRA_SUCCESS && i < count; ++i)
        if (order[i] == (uint32_t)root)
            *ordered_root = i;
    free(order);
    free(all);
    return st;
}

/* ---- light -------------------------------------------------------------------------------- */

/* The deep map's pieces: each rank's node counts per texel and its nodes (after the chain of
 * the visibility in light order built them), gathered on every rank (MPI_Allgather of the counts
 * and the node totals, MPI_Allgatherv of the nodes) and merged there into its map. Together
 * they are about one device's map (the nodes of every texel once, plus a node where a ray
 * crosses into another part), which is what each rank then holds; docs/distributed.md. */
static umbra_status exchange_pieces(MPI_Comm comm, MPI_Comm ordered, umbra_context ctx,
                                    umbra_renderer r, const umbra_part_light_info *info,
                                    umbra_mpi_stats *stats)
{
    const size_t texels = (size_t)info->map_size * info->map_size, nf = info->node_floats;
    int size = 1;
    MPI_Comm_size(ordered, &size);
    uint32_t *counts = malloc(texels * sizeof *counts);
    uint32_t *all_counts = malloc((size_t)size * texels * sizeof *all_counts);
    long long *totals = malloc((size_t)size * sizeof *totals);
    int *recv = malloc((size_t)size * sizeof *recv), *displs = malloc((size_t)size * sizeof *displs);
    float *nodes = NULL, *all_nodes = NULL;
    size_t mine = 0, total = 0;
    double t = now_ms();
    umbra_status st = UMBRA_SUCCESS;
    if (!counts || !all_counts || !totals || !recv || !displs || texels > INT_MAX)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi_light: cannot allocate the deep map's counts (%zu "
                             "texels, %d ranks)", texels, size);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_part_export_deep(r, counts, NULL, &mine);
    if (st == UMBRA_SUCCESS && !(nodes = malloc((mine ? mine : 1) * nf * sizeof *nodes)))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi_light: cannot allocate the piece's %zu nodes", mine);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_part_export_deep(r, counts, nodes, &mine);
    if (stats)
        stats->build_ms += now_ms() - t;
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS)
        goto fail;
    t = now_ms();
    const long long floats = (long long)(mine * nf);
    MPI_Allgather(&floats, 1, MPI_LONG_LONG, totals, 1, MPI_LONG_LONG, ordered);
    long long sum = 0;
    for (int i = 0; i < size; ++i) {
        displs[i] = (int)sum;
        recv[i] = (int)totals[i];
        sum += totals[i];
    }
    total = (size_t)sum / nf;
    if (sum > INT_MAX)
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "umbra_mpi_light: the deep map's pieces hold %lld floats, more "
                             "than one MPI_Allgatherv moves (2^31)", sum);
    else if (!(all_nodes = malloc((size_t)(sum ? sum : 1) * sizeof *all_nodes)))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi_light: cannot allocate the gathered pieces (%lld "
                             "floats)", sum);
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS)
        goto fail;
    MPI_Allgather(counts, (int)texels, MPI_UINT32_T, all_counts, (int)texels, MPI_UINT32_T,
                  ordered);
    MPI_Allgatherv(nodes, (int)floats, MPI_FLOAT, all_nodes, recv, displs, MPI_FLOAT, ordered);
    if (stats) {
        stats->light_exchange_ms += now_ms() - t;
        stats->bytes_sent += sizeof floats + texels * sizeof *counts + (size_t)floats * sizeof(float);
    }
    t = now_ms();
    st = agree(comm, ctx,
               umbra_renderer_part_import_deep(r, (uint32_t)size, all_counts, all_nodes, total));
    if (stats)
        stats->build_ms += now_ms() - t;
fail:
    free(counts);
    free(all_counts);
    free(totals);
    free(recv);
    free(displs);
    free(nodes);
    free(all_nodes);
    return st;
}

umbra_status umbra_mpi_light(MPI_Comm comm, umbra_context ctx, umbra_renderer r,
                             umbra_volume volume, const umbra_light *light,
                             umbra_mpi_stats *stats)
{
    umbra_part_light_info info;
    umbra_volume_info placement;
    umbra_part_desc part, *all = NULL;
    MPI_Comm ordered = MPI_COMM_NULL;
    float *tau = NULL, *tau_in = NULL, *depth = NULL;
    uint32_t *order = NULL;
    int count = 0, pos = 0;
    double t;
    umbra_status st;

    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    umbra_part_desc_init(&part);
    st = light ? umbra_renderer_part_light_info(r, &info)
               : umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                 "umbra_mpi_light: light is NULL");
    if (st == UMBRA_SUCCESS)
        st = umbra_volume_get_part(volume, &part);
    if (st == UMBRA_SUCCESS)
        st = umbra_volume_get_info(volume, &placement);
    if (st == UMBRA_SUCCESS && (info.tau_floats > INT_MAX || info.depth_floats > INT_MAX))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "umbra_mpi_light: a map of more than 2^31 floats");
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS || info.kind == UMBRA_PART_LIGHT_NOTHING)
        return st;

    /* The ranks in light order; for a light along a grid axis, split into the columns along it
     * (each light ray meets one column only). */
    st = gather_parts(comm, ctx, &part, &all, &count);
    if (st != UMBRA_SUCCESS)
        return st;
    order = malloc((size_t)count * sizeof *order);
    tau = info.tau_floats ? malloc(info.tau_floats * sizeof *tau) : NULL;
    tau_in = info.tau_floats ? malloc(info.tau_floats * sizeof *tau_in) : NULL;
    depth = info.depth_floats ? malloc(info.depth_floats * sizeof *depth) : NULL;
    if (!order || (info.tau_floats && (!tau || !tau_in)) || (info.depth_floats && !depth))
        st = umbra__mpi_fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_mpi_light: cannot allocate the maps (%zu floats)",
                             2 * info.tau_floats + info.depth_floats);
    else
        st = umbra_part_visibility_order(all, (uint32_t)count, &placement,
                                         light->type == UMBRA_LIGHT_POINT ? light->position
                                                                          : light->direction,
                                         light->type == UMBRA_LIGHT_POINT, order);
    st = agree(comm, ctx, st);
    if (st != UMBRA_SUCCESS)
        goto fail;
    st = split_in_order(comm, ctx, order, count, &ordered);
    if (st != UMBRA_SUCCESS)
        goto fail;
    MPI_Comm_rank(ordered, &pos);

    if (info.tau_floats) {
        /* The march state goes on from part to part in light order
         * (import what the part before left, march, export for the next), so the parts pass it
         * down the chain of the ordered ranks. A rank that fails passes its status on instead,
         * and the chain still ends; the agreement after it reports the first failure. */
        int size = 1;
        float flag = 0.0f;
        MPI_Comm_size(ordered, &size);
        st = UMBRA_SUCCESS;
        if (pos > 0) {
            double w = now_ms();
            MPI_Recv(tau_in, (int)info.tau_floats, MPI_FLOAT, pos - 1, 0, ordered,
                     MPI_STATUS_IGNORE);
            MPI_Recv(&flag, 1, MPI_FLOAT, pos - 1, 1, ordered, MPI_STATUS_IGNORE);
            if (stats)
                stats->light_exchange_ms += now_ms() - w;
            if (flag != 0.0f)
                st = umbra__mpi_fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                     "umbra_mpi_light: a rank before this one in light order "
                                     "failed");
        }
        t = now_ms();
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_part_import_transmittance(r, pos == 0 ? NULL : tau_in);
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_part_export_transmittance(r, tau);
        if (stats)
            stats->build_ms += now_ms() - t;
        if (pos + 1 < size) {
            double w = now_ms();
            flag = st == UMBRA_SUCCESS ? 0.0f : 1.0f;
            MPI_Send(tau, (int)info.tau_floats, MPI_FLOAT, pos + 1, 0, ordered);
            MPI_Send(&flag, 1, MPI_FLOAT, pos + 1, 1, ordered);
            if (stats) {
                stats->light_exchange_ms += now_ms() - w;
                stats->bytes_sent += info.tau_floats * sizeof *tau + sizeof flag;
            }
        }
        st = agree(comm, ctx, st);
        if (st != UMBRA_SUCCESS)
            goto fail;
    }
    /* The deep map: every part's pieces to every part (umbra_renderer_part_import_deep). */
    if (info.kind == UMBRA_PART_LIGHT_TAU)
        st = exchange_pieces(comm, ordered, ctx, r, &info, stats);
    /* Depths: build and export, minimum over the ranks, import. */
    if (info.depth_floats) {
        t = now_ms();
        st = agree(comm, ctx, umbra_renderer_part_export_depths(r, depth));
        if (stats)
            stats->build_ms += now_ms() - t;
        if (st != UMBRA_SUCCESS)
            goto fail;
        t = now_ms();
        MPI_Allreduce(MPI_IN_PLACE, depth, (int)info.depth_floats, MPI_FLOAT, MPI_MIN, ordered);
        if (stats) {
            stats->light_exchange_ms += now_ms() - t;
            stats->bytes_sent += info.depth_floats * sizeof *depth;
        }
        st = agree(comm, ctx, umbra_renderer_part_import_depths(r, depth));
    }
fail:
    if (ordered != MPI_COMM_NULL)
        MPI_Comm_free(&ordered);
    free(depth);
    free(tau_in);
    free(tau);
    free(order);
    free(all);
    return st;
}
