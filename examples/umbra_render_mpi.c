// SPDX-License-Identifier: Apache-2.0
/* umbra-render-mpi: umbra-render over MPI ranks (mpirun -np P umbra-render-mpi --grid PXxPYxPZ
 * --volume FILE ...). Every umbra-render option is read by umbra-render's own parser
 * (examples/umbra_render_args.c) and sets up the same renderer (session_setup,
 * examples/umbra_render.c); each rank then holds only its part of the volume (umbra_mpi_load:
 * its box of the file, ghost layers included), the light data cross ranks in light order
 * (umbra_mpi_light) and the partial images are composited in view order at rank 0
 * (umbra_mpi_render), which writes the one image and prints each rank's stage times and bytes.
 * A failure on any rank is agreed by all (umbra_mpi_agree) and printed once, by rank 0; every
 * rank exits with umbra-render's status for it (1 bad input, 2 device or memory). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "umbra/mpi.h"
#include "umbra_render.h"

typedef struct mpi_options {
    uint32_t grid[3];
    int have_grid;
    umbra_mpi_composite_mode mode;
} mpi_options;

enum { OPT_GRID, OPT_COMPOSITE };

static const program_option mpi_option_list[] = {
    [OPT_GRID] = {"grid", "PXxPYxPZ", "parts per axis, one per rank: their product is the "
                                      "number of ranks (required)"},
    [OPT_COMPOSITE] = {"composite", "reduce-scatter|sequential|chain",
                       "how the partial images compose: MPI_Reduce_scatter_block with the over "
                       "operator (default), all gathered at rank 0 and composited front to back "
                       "there, or one frame passed down the ranks in view order, each going on "
                       "from the ones in front (one device's image bit for bit; the renders run "
                       "one after the other)"},
};

static int mpi_take(void *user, size_t index, const char *v)
{
    mpi_options *o = user;
    if (index == OPT_GRID) {
        unsigned a, b, c;
        char tail;
        if (sscanf(v, "%ux%ux%u%c", &a, &b, &c, &tail) != 3 || a < 1 || b < 1 || c < 1 ||
            a > 4096 || b > 4096 || c > 4096) {
            fprintf(stderr, "umbra-render-mpi: --grid '%s' is not PXxPYxPZ with each in "
                            "[1, 4096]\n", v);
            return 1;
        }
        o->grid[0] = a;
        o->grid[1] = b;
        o->grid[2] = c;
        o->have_grid = 1;
        return 0;
    }
    if (strcmp(v, "reduce-scatter") != 0 && strcmp(v, "sequential") != 0 &&
        strcmp(v, "chain") != 0) {
        fprintf(stderr, "umbra-render-mpi: --composite '%s' is not reduce-scatter, sequential "
                        "or chain\n", v);
        return 1;
    }
    o->mode = strcmp(v, "sequential") == 0 ? UMBRA_MPI_COMPOSITE_SEQUENTIAL
              : strcmp(v, "chain") == 0    ? UMBRA_MPI_COMPOSITE_CHAIN
                                           : UMBRA_MPI_COMPOSITE_REDUCE_SCATTER;
    return 0;
}

/* What stops a command line before any rank loads anything: the techniques that do not split
 * and what is not a volume file. NULL when it can go on. */
static const char *refusal(const options *o, const mpi_options *m)
{
    if (!m->have_grid)
        return "--grid PXxPYxPZ is required (the parts per axis, one per rank)";
    if (o->shadow.technique == UMBRA_SHADOW_REFERENCE)
        return "--technique reference does not split over ranks: its shadow rays from every "
               "sample would cross the other ranks' parts";
    if (o->shadow.technique == UMBRA_SHADOW_CONVOLUTION)
        return "--technique convolution does not split over ranks: its view-aligned slices "
               "carry the light through the whole view depth";
    if (!o->volume && !o->raw)
        return "a volume file is required (--volume or --raw): each rank reads its part of it; "
               "the built-in scenes are made whole in memory";
    return NULL;
}

static void print_stats(const umbra_mpi_stats *all, int ranks, const umbra_part_desc *parts)
{
    fprintf(stderr, "rank  part (offset, size)                 load_ms  light_ms  build_ms  "
                    "render_ms  composite_ms  bytes_sent  volume_bytes\n");
    for (int i = 0; i < ranks; ++i) {
        const umbra_mpi_stats *s = all + i;
        const umbra_part_desc *p = parts + i;
        char where[64];
        snprintf(where, sizeof where, "%u,%u,%u %ux%ux%u", p->offset[0], p->offset[1],
                 p->offset[2], p->size[0], p->size[1], p->size[2]);
        fprintf(stderr, "%4d  %-34s %8.1f  %8.1f  %8.1f  %9.1f  %12.1f  %10llu  %12llu\n", i,
                where, s->load_ms, s->light_exchange_ms, s->build_ms, s->render_ms,
                s->composite_ms, (unsigned long long)s->bytes_sent,
                (unsigned long long)s->volume_bytes);
    }
}

static int run(MPI_Comm comm, const options *o, const mpi_options *m, session *s, int rank,
               int ranks)
{
    char message[UMBRA_MPI_MESSAGE_MAX] = "";
    umbra_mpi_stats stats, *all = NULL;
    umbra_mpi_volume part;
    umbra_part_desc *parts = NULL;
    umbra_status st;
    int rc;
    memset(&stats, 0, sizeof stats);
    memset(&part, 0, sizeof part);

    /* Every rank parsed the same command line, so all refuse alike; agreed all the same. */
    const char *why = refusal(o, m);
    st = umbra_mpi_agree(comm, NULL, why ? UMBRA_ERROR_UNSUPPORTED : UMBRA_SUCCESS, why, message,
                         sizeof message);
    if (st == UMBRA_SUCCESS) {
        /* A rank without a device has no context: its status and message go in by hand. */
        st = session_open(o, s, 1);
        char none[UMBRA_MPI_MESSAGE_MAX];
        snprintf(none, sizeof none, "no OpenCL device: %s (%s)", umbra_status_to_string(st),
                 o->device ? o->device : "the default device");
        st = umbra_mpi_agree(comm, s->ctx, st, s->ctx ? NULL : none, message, sizeof message);
    }
    if (st == UMBRA_SUCCESS) {
        umbra_volume_load_options lo;
        umbra_volume_box_desc file;
        umbra_mpi_split_desc split;
        umbra_render_desc rd;
        umbra_volume_load_options_init(&lo);
        lo.data_roots = o->data_roots;
        lo.data_root_count = o->data_root_count;
        umbra_volume_box_desc_init(&file);
        file.options = &lo;
        file.raw = o->raw ? &o->raw_desc : NULL;
        /* The ghost layers the render options need (umbra/part.h), from the options that
         * session_setup will set. */
        umbra_render_desc_init(&rd);
        if (o->shading >= 0)
            rd.shading = o->shading;
        rd.jitter = o->jitter;
        if (o->have_step)
            rd.step = o->step;
        umbra_mpi_split_desc_init(&split);
        memcpy(split.grid, m->grid, sizeof split.grid);
        split.ghost = umbra_part_ghost_needed(&rd);
        st = umbra_mpi_load(comm, s->ctx, o->volume ? o->volume : o->raw, &file, &split, NULL,
                            &part, &stats);
    }
    if (st == UMBRA_SUCCESS) {
        s->volume = part.volume;
        part.volume = NULL;
        rc = session_setup(o, s);
        st = rc == 0 ? UMBRA_SUCCESS : rc == 1 ? UMBRA_ERROR_INVALID_ARGUMENT : UMBRA_ERROR_OPENCL;
        st = umbra_mpi_agree(comm, s->ctx, st, NULL, message, sizeof message);
    }
    if (st == UMBRA_SUCCESS)
        st = umbra_mpi_light(comm, s->ctx, s->renderer, s->view_volume, &s->light, &stats);
    if (st == UMBRA_SUCCESS && rank == 0) {
        s->pixels = malloc((size_t)s->width * s->height * 4 * sizeof(float));
        st = s->pixels ? UMBRA_SUCCESS
                       : umbra_context_record_error(s->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                                    "out of memory for the image");
    }
    if (st == UMBRA_SUCCESS)
        st = umbra_mpi_agree(comm, s->ctx, st, NULL, message, sizeof message);
    if (st == UMBRA_SUCCESS)
        st = umbra_mpi_render(comm, s->ctx, s->renderer, s->view_volume, &s->camera, s->width,
                              s->height, s->options.background, m->mode, 0, s->pixels, &stats);
    if (st != UMBRA_SUCCESS) {
        if (rank == 0)
            fprintf(stderr, "umbra-render-mpi: %s: %s\n", umbra_status_to_string(st),
                    s->ctx ? umbra_context_last_message(s->ctx) : message);
        return exit_status(st);
    }

    /* Every rank's stages and bytes, printed by rank 0. */
    umbra_part_desc mine;
    umbra_volume_get_part(s->view_volume, &mine);
    if (rank == 0) {
        all = calloc((size_t)ranks, sizeof *all);
        parts = calloc((size_t)ranks, sizeof *parts);
    }
    MPI_Gather(&stats, (int)sizeof stats, MPI_BYTE, all, (int)sizeof stats, MPI_BYTE, 0, comm);
    MPI_Gather(&mine, (int)sizeof mine, MPI_BYTE, parts, (int)sizeof mine, MPI_BYTE, 0, comm);
    rc = 0;
    if (rank == 0) {
        umbra_volume_info info;
        umbra_volume_get_info(s->view_volume, &info);
        fprintf(stderr, "technique: %s, %d ranks, grid %ux%ux%u, volume %ux%ux%u\n",
                umbra_shadow_technique_name(o->shadow.technique), ranks, m->grid[0], m->grid[1],
                m->grid[2], mine.global_dims[0], mine.global_dims[1], mine.global_dims[2]);
        if (all && parts)
            print_stats(all, ranks, parts);
        if (umbra_image_write(s->ctx, o->out, s->width, s->height, s->pixels) != UMBRA_SUCCESS) {
            fprintf(stderr, "umbra-render-mpi: %s\n", umbra_context_last_message(s->ctx));
            rc = 2;
        } else {
            fprintf(stderr, "wrote %s\n", o->out);
        }
    }
    free(all);
    free(parts);
    MPI_Bcast(&rc, 1, MPI_INT, 0, comm);
    return rc;
}

int main(int argc, char **argv)
{
    mpi_options m;
    memset(&m, 0, sizeof m);
    const program prog = {
        "umbra-render-mpi",
        "umbra-render over MPI ranks (mpirun -np P umbra-render-mpi --grid PXxPYxPZ --volume "
        "FILE ...): each rank reads and renders one part of the volume, the light crosses the "
        "ranks in light order and rank 0 writes the composited image. Every umbra-render option "
        "applies; the techniques reference and convolution do not split; a part draws no ground "
        "plane (off unless --ground is given, which is refused).",
        mpi_option_list, sizeof mpi_option_list / sizeof mpi_option_list[0], mpi_take, &m};
    /* Only rank 0 speaks: the others' messages reach it through the agreement. */
    const char *env_rank = getenv("OMPI_COMM_WORLD_RANK");
    if (!env_rank)
        env_rank = getenv("PMI_RANK");
    if (env_rank && atoi(env_rank) != 0) {
        if (!freopen("/dev/null", "w", stderr) || !freopen("/dev/null", "w", stdout))
            return 2;
    }
    options o;
    if (parse_args_as(&prog, argc, argv, &o) != 0)
        return 1;
    if (o.ground < 0)
        o.ground = 0;
    o.progress = 0;
    if (MPI_Init(&argc, &argv) != MPI_SUCCESS)
        return 2;
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    session s;
    memset(&s, 0, sizeof s);
    int rc = run(MPI_COMM_WORLD, &o, &m, &s, rank, ranks);
    session_end(&s);
    MPI_Finalize();
    return rc;
}
