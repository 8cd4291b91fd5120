// SPDX-License-Identifier: Apache-2.0
/* tests/mpi/test_mpi.c: umbra_mpi on P ranks (mpirun --oversubscribe -np P test_mpi, P = 1, 2, 4,
 * 8: the grid 1x1x1, 2x1x1, 2x2x1, 2x2x2) against one device rendering the whole volume (rank 0,
 * on its own context):
 *  - an analytic volume, each rank making only its part (core and ghosts); techniques none,
 *    threshold, CSSM and deep (at epsilon 0, and once at 0.02),
 *    directional light along a grid axis and oblique, a point light
 *    inside and outside the box, grey and coloured light; the composited image (reduce-scatter and
 *    sequential) within NONE_BOUND (none) or SHADOW_BOUND (the light-space maps) of the single
 *    device's, and the chain composite (each rank going on from the ranks in front) equal to it
 *    bit for bit;
 *  - a volume whose content lies in the first brick column only, so ranks own empty parts;
 *  - the file route: rank 0 writes the volume as a NRRD, every rank reads its box
 *    (umbra_mpi_load), the value range agreed; the image against the whole file on one device,
 *    each rank's voxel bytes within a brick layer of 1/P of the whole;
 *  - bad input refused on every rank with the same status and message, no rank left waiting (the
 *    ctest TIMEOUT catches a hang): a grid that does not tile the ranks, more parts than bricks, a
 *    rank without a device, a file missing on one rank.
 * Without cmocka: a failed check is counted, printed with its rank, and the program carries on to
 * the next collective, so a failure never strands the other ranks. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "umbra/mpi.h"

enum { NX = 48, NY = 40, NZ = 36, BS = 8, W = 40, H = 36 };

/* Bounds: none is the over operator's float rounding against one ray's running sum (umbra/part.h:
 * 3.6e-7 measured); the light-space maps add the product of exit transmittances against one
 * march. */
#define NONE_BOUND 1e-6f
#define SHADOW_BOUND 1e-5f

static int rank, ranks, failures;
static float worst_none, worst_shadow, worst_deep_eps;
static size_t chain_differing; /* over all scenes: the chain composite is bit for bit */

#define CHECK(cond, ...)                                                                          \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            ++failures;                                                                           \
            fprintf(stderr, "rank %d: %s:%d: ", rank, __FILE__, __LINE__);                        \
            fprintf(stderr, __VA_ARGS__);                                                         \
            fputc('\n', stderr);                                                                  \
        }                                                                                         \
    } while (0)

static float voxel(int empty, uint32_t x, uint32_t y, uint32_t z)
{
    if (empty && x >= BS)
        return 0.0f;
    float dx = (x - 21.0f) / 11.0f, dy = (y - 18.0f) / 9.0f, dz = (z - 17.0f) / 10.0f;
    float ex = (x - 33.0f) / 7.0f, ey = (y - 11.0f) / 7.0f, ez = (z - 26.0f) / 8.0f;
    float b = expf(-(dx * dx + dy * dy + dz * dz)) + 0.8f * expf(-(ex * ex + ey * ey + ez * ez));
    float s = b + 0.15f * sinf(0.7f * x + 0.45f * z) * cosf(0.5f * y - 0.3f * z);
    if (empty)
        s = 0.3f + 0.6f * fabsf(sinf(0.3f * x + 0.2f * y + 0.1f * z));
    return s < 0.0f ? 0.0f : (s > 1.0f ? 1.0f : s);
}

/* The voxels of box [lo, lo + n). */
static float *box_voxels(int empty, const uint32_t lo[3], const uint32_t n[3])
{
    float *v = malloc((size_t)n[0] * n[1] * n[2] * sizeof *v);
    if (!v)
        abort();
    for (uint32_t z = 0; z < n[2]; ++z)
        for (uint32_t y = 0; y < n[1]; ++y)
            for (uint32_t x = 0; x < n[0]; ++x)
                v[((size_t)z * n[1] + y) * n[0] + x] = voxel(empty, lo[0] + x, lo[1] + y, lo[2] + z);
    return v;
}

static void volume_desc(umbra_volume_desc *d, const float *data, const uint32_t dims[3])
{
    umbra_volume_desc_init(d);
    d->data = data;
    d->type = UMBRA_FLOAT32;
    memcpy(d->dims, dims, sizeof d->dims);
    d->value_range_given = 1;
    d->value_min = 0.0f;
    d->value_max = 1.0f;
    d->brick_size = BS;
}

typedef struct scene {
    const char *name;
    umbra_shadow_technique technique;
    int light;   /* 0 axis, 1 oblique, 2 point inside, 3 point outside */
    int colored;
    int deep_eps;  /* the deep map: 0 at epsilon 0, 1 at 0.02 (both within SHADOW_BOUND) */
} scene;

static umbra_transfer_function make_tf(umbra_context ctx)
{
    const umbra_tf_point pts[] = {{0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
                                  {0.25f, {0.9f, 0.5f, 0.2f, 0.0f}},
                                  {0.5f, {0.3f, 0.8f, 0.4f, 0.08f}},
                                  {1.0f, {1.0f, 1.0f, 0.9f, 0.3f}}};
    umbra_transfer_function tf = NULL;
    umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf);
    return tf;
}

/* A renderer for volume v as scene s sets it; camera and light into *cam, *light. */
static umbra_status make_renderer(umbra_context ctx, umbra_volume v, umbra_transfer_function tf,
                                  const scene *s, umbra_camera *cam, umbra_light *light,
                                  umbra_render_desc *opts, umbra_renderer *out)
{
    const float diag = sqrtf((float)(NX * NX + NY * NY + NZ * NZ));
    const float dir[3] = {0.6f, 0.45f, 1.0f};
    umbra_shadow_desc sd;
    umbra_renderer r = NULL;
    umbra_status st;
    *cam = umbra_camera_orbit(dir, diag, 30.0f);
    memset(light, 0, sizeof *light);
    light->type = s->light >= 2 ? UMBRA_LIGHT_POINT : UMBRA_LIGHT_DIRECTIONAL;
    const float axis[3] = {0.0f, -1.0f, 0.0f}, oblique[3] = {0.3f, -1.0f, 0.4f};
    const float inside[3] = {3.0f, 5.0f, -2.0f}, outside[3] = {80.0f, 60.0f, 90.0f};
    memcpy(light->direction, s->light == 0 ? axis : oblique, sizeof light->direction);
    memcpy(light->position, s->light == 2 ? inside : outside, sizeof light->position);
    light->color[0] = 1.0f;
    light->color[1] = s->colored ? 0.7f : 1.0f;
    light->color[2] = s->colored ? 0.4f : 1.0f;
    umbra_render_desc_init(opts);
    opts->step = 0.7f;
    opts->termination = 1.0f;
    opts->shading = 1;
    opts->transmission = s->colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    opts->background[0] = 0.1f;
    opts->background[1] = 0.2f;
    opts->background[2] = 0.3f;
    opts->background[3] = 1.0f;
    umbra_shadow_desc_init(&sd);
    sd.technique = s->technique;
    sd.map.size = 96;
    sd.deep.epsilon = s->deep_eps ? 0.02f : 0.0f;
    if ((st = umbra_renderer_create(ctx, &r)) != UMBRA_SUCCESS)
        return st;
    if ((st = umbra_renderer_set_volume(r, v)) || (st = umbra_renderer_set_transfer_function(r, tf)) ||
        (st = umbra_renderer_set_camera(r, cam)) || (st = umbra_renderer_set_light(r, light)) ||
        (st = umbra_renderer_set_options(r, opts)) || (st = umbra_renderer_set_shadow(r, &sd))) {
        umbra_renderer_release(r);
        return st;
    }
    *out = r;
    return UMBRA_SUCCESS;
}

/* Rank 0: the whole volume on one device. */
static float *render_whole(umbra_context ctx, umbra_volume whole, umbra_transfer_function tf,
                           const scene *s)
{
    umbra_camera cam;
    umbra_light light;
    umbra_render_desc opts;
    umbra_renderer r = NULL;
    float *img = malloc((size_t)W * H * 4 * sizeof *img);
    if (!img || make_renderer(ctx, whole, tf, s, &cam, &light, &opts, &r) != UMBRA_SUCCESS ||
        umbra_renderer_render(r, W, H, img) != UMBRA_SUCCESS) {
        CHECK(0, "%s: the single-device render failed: %s", s->name,
              umbra_context_last_message(ctx));
        free(img);
        img = NULL;
    }
    umbra_renderer_release(r);
    return img;
}

static float max_diff(const float *a, const float *b, size_t n)
{
    float m = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        float d = fabsf(a[i] - b[i]);
        m = d > m || d != d ? d : m;
    }
    return m;
}

/* One scene on all ranks, both composites, against want (rank 0). */
static void run_scene(MPI_Comm comm, umbra_context ctx, umbra_volume part,
                      umbra_transfer_function tf, const scene *s, const float *want)
{
    umbra_camera cam;
    umbra_light light;
    umbra_render_desc opts;
    umbra_renderer r = NULL;
    float *img[3] = {NULL, NULL, NULL};
    umbra_mpi_stats stats;
    memset(&stats, 0, sizeof stats);
    umbra_status st = make_renderer(ctx, part, tf, s, &cam, &light, &opts, &r);
    st = umbra_mpi_agree(comm, ctx, st, NULL, NULL, 0);
    if (st == UMBRA_SUCCESS)
        st = umbra_mpi_light(comm, ctx, r, part, &light, &stats);
    /* A light-space technique the part-aware core does not exchange yet says so by name
     * (umbra/part.h); shown, not counted, so the rest still runs. */
    if (st == UMBRA_ERROR_UNSUPPORTED && s->technique == UMBRA_SHADOW_DEEP) {
        if (rank == 0)
            printf("%-34s SKIP: %s\n", s->name, umbra_context_last_message(ctx));
        umbra_renderer_release(r);
        return;
    }
    for (int m = 0; m < 3 && st == UMBRA_SUCCESS; ++m) {
        if (rank == 0)
            img[m] = malloc((size_t)W * H * 4 * sizeof(float));
        st = umbra_mpi_render(comm, ctx, r, part, &cam, W, H, opts.background,
                              (umbra_mpi_composite_mode)m, 0, img[m], &stats);
    }
    CHECK(st == UMBRA_SUCCESS, "%s: %s", s->name, umbra_context_last_message(ctx));
    if (st == UMBRA_SUCCESS && rank == 0 && want) {
        const float bound = s->technique == UMBRA_SHADOW_NONE ? NONE_BOUND : SHADOW_BOUND;
        float d0 = max_diff(img[0], want, (size_t)W * H * 4);
        float d1 = max_diff(img[1], want, (size_t)W * H * 4);
        float *worst = s->technique == UMBRA_SHADOW_NONE ? &worst_none
                       : s->deep_eps                     ? &worst_deep_eps
                                                         : &worst_shadow;
        size_t bits = 0; /* the chain's floats that differ from one device's in any bit */
        for (size_t i = 0; i < (size_t)W * H * 4; ++i)
            bits += memcmp(&img[2][i], &want[i], sizeof want[i]) != 0;
        /* none has no map; the threshold and CSSM maps equal one device's depth for depth. */
        const int exact = s->technique == UMBRA_SHADOW_NONE ||
                          s->technique == UMBRA_SHADOW_THRESHOLD ||
                          s->technique == UMBRA_SHADOW_CSSM;
        *worst = fmaxf(*worst, fmaxf(d0, d1));
        chain_differing += exact ? bits : 0;
        printf("%-34s reduce-scatter %.3g  sequential %.3g  (bound %.0e)  chain: %zu floats "
               "differ\n", s->name, (double)d0, (double)d1, (double)bound, bits);
        CHECK(d0 <= bound && d1 <= bound, "%s: %.3g / %.3g past %.3g", s->name, (double)d0,
              (double)d1, (double)bound);
        CHECK(!exact || bits == 0, "%s: the chain composite differs from one device in %zu floats",
              s->name, bits);
    }
    free(img[0]);
    free(img[1]);
    free(img[2]);
    umbra_renderer_release(r);
}

/* The split of the tests: grid, their bricks, the ghosts shading needs. */
static void split_for(umbra_mpi_split_desc *split, const uint32_t grid[3])
{
    umbra_render_desc opts;
    umbra_render_desc_init(&opts);
    opts.shading = 1;
    umbra_mpi_split_desc_init(split);
    memcpy(split->grid, grid, 3 * sizeof *grid);
    split->brick_size = BS;
    split->ghost = umbra_part_ghost_needed(&opts);
}

/* This rank's part of the analytic volume, and rank 0's whole one. */
static umbra_status make_part(MPI_Comm comm, umbra_context ctx, int empty, const uint32_t grid[3],
                              umbra_volume *part, umbra_volume *whole)
{
    const uint32_t dims[3] = {NX, NY, NZ};
    umbra_mpi_split_desc split;
    umbra_part_desc p;
    umbra_volume_desc d;
    umbra_status st;
    split_for(&split, grid);
    st = umbra_mpi_split(comm, ctx, dims, &split, &p, NULL);
    if (st != UMBRA_SUCCESS)
        return st;
    uint32_t lo[3], n[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = p.offset[a] - p.ghost_lo[a];
        n[a] = p.size[a] + p.ghost_lo[a] + p.ghost_hi[a];
    }
    float *v = box_voxels(empty, lo, n);
    volume_desc(&d, v, n);
    st = umbra_volume_create_part(ctx, &d, &p, part);
    free(v);
    if (st == UMBRA_SUCCESS && rank == 0) {
        const uint32_t zero[3] = {0, 0, 0};
        v = box_voxels(empty, zero, dims);
        volume_desc(&d, v, dims);
        st = umbra_volume_create(ctx, &d, whole);
        free(v);
    }
    return umbra_mpi_agree(comm, ctx, st, NULL, NULL, 0);
}

static void test_scenes(MPI_Comm comm, umbra_context ctx, const uint32_t grid[3])
{
    static const scene scenes[] = {
        {"none, oblique", UMBRA_SHADOW_NONE, 1, 0, 0},
        {"none, point inside, coloured", UMBRA_SHADOW_NONE, 2, 1, 0},
        {"deep, axis", UMBRA_SHADOW_DEEP, 0, 0, 0},
        {"deep, oblique, coloured", UMBRA_SHADOW_DEEP, 1, 1, 0},
        {"deep, point inside", UMBRA_SHADOW_DEEP, 2, 0, 0},
        {"deep, point outside, coloured", UMBRA_SHADOW_DEEP, 3, 1, 0},
        {"threshold, axis, coloured", UMBRA_SHADOW_THRESHOLD, 0, 1, 0},
        {"threshold, oblique", UMBRA_SHADOW_THRESHOLD, 1, 0, 0},
        {"threshold, point outside", UMBRA_SHADOW_THRESHOLD, 3, 0, 0},
        {"cssm, axis", UMBRA_SHADOW_CSSM, 0, 0, 0},
        {"cssm, oblique, coloured", UMBRA_SHADOW_CSSM, 1, 1, 0},
        {"cssm, point inside", UMBRA_SHADOW_CSSM, 2, 0, 0},
        {"cssm, point outside, coloured", UMBRA_SHADOW_CSSM, 3, 1, 0},
        {"deep eps 0.02, oblique, coloured", UMBRA_SHADOW_DEEP, 1, 1, 1},
    };
    const char *only = getenv("UMBRA_MPI_TEST_ONLY"); /* a technique's name, while working */
    umbra_volume part = NULL, whole = NULL;
    umbra_transfer_function tf = make_tf(ctx);
    for (int empty = 0; empty < 2; ++empty) {
        if (make_part(comm, ctx, empty, grid, &part, &whole) != UMBRA_SUCCESS) {
            CHECK(0, "the part volume: %s", umbra_context_last_message(ctx));
            break;
        }
        for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; ++i) {
            scene s = scenes[i];
            char name[64];
            if (only && strcmp(only, umbra_shadow_technique_name(s.technique)) != 0)
                continue;
            if (empty && i % 3 != 0)
                continue; /* the empty parts: a third of the scenes */
            snprintf(name, sizeof name, "%s%s", s.name, empty ? ", empty parts" : "");
            s.name = name;
            float *want = rank == 0 ? render_whole(ctx, whole, tf, &s) : NULL;
            run_scene(comm, ctx, part, tf, &s, want);
            free(want);
        }
        umbra_volume_release(part);
        umbra_volume_release(whole);
        part = whole = NULL;
    }
    umbra_transfer_function_release(tf);
}

/* Rank 0 writes the volume as uint16 NRRD; every rank reads its box of it. */
static void test_file(MPI_Comm comm, umbra_context ctx, const uint32_t grid[3], const char *dir)
{
    char hdr[1024], raw[1024];
    const uint32_t dims[3] = {NX, NY, NZ}, zero[3] = {0, 0, 0};
    const size_t count = (size_t)NX * NY * NZ;
    snprintf(hdr, sizeof hdr, "%s/vol.nhdr", dir);
    snprintf(raw, sizeof raw, "%s/vol.raw", dir);
    if (rank == 0) {
        float *v = box_voxels(0, zero, dims);
        uint16_t *u = malloc(count * sizeof *u);
        for (size_t i = 0; i < count; ++i)
            u[i] = (uint16_t)(100 + 3000 * v[i]);
        FILE *f = fopen(raw, "wb");
        fwrite(u, sizeof *u, count, f);
        fclose(f);
        f = fopen(hdr, "w");
        fprintf(f, "NRRD0004\ntype: uint16\ndimension: 3\nsizes: %d %d %d\nencoding: raw\n"
                   "endian: little\ndata file: vol.raw\n", NX, NY, NZ);
        fclose(f);
        free(u);
        free(v);
    }
    MPI_Barrier(comm);
    umbra_mpi_split_desc split;
    umbra_mpi_volume mv;
    umbra_mpi_stats stats;
    memset(&stats, 0, sizeof stats);
    split_for(&split, grid);
    umbra_status st = umbra_mpi_load(comm, ctx, hdr, NULL, &split, NULL, &mv, &stats);
    CHECK(st == UMBRA_SUCCESS, "umbra_mpi_load: %s", umbra_context_last_message(ctx));
    if (st != UMBRA_SUCCESS)
        return;
    /* Each rank's voxels: its part (whole bricks: 2 or 3 of the 5 along y) and its ghost layers,
     * never the whole; the cores add up to the whole. */
    const double share = (double)count * 2 / ranks;
    uint64_t core = (uint64_t)mv.part.size[0] * mv.part.size[1] * mv.part.size[2] * 2, cores = 0;
    MPI_Allreduce(&core, &cores, 1, MPI_UINT64_T, MPI_SUM, comm);
    CHECK(cores == count * 2, "the parts' cores hold %llu bytes, the volume %zu",
          (unsigned long long)cores, count * 2);
    uint64_t carried = 2;
    for (int a = 0; a < 3; ++a)
        carried *= mv.part.size[a] + mv.part.ghost_lo[a] + mv.part.ghost_hi[a];
    CHECK(stats.volume_bytes == carried && (ranks == 1 || carried < 2 * count),
          "rank %d holds %llu voxel bytes, its core and ghosts %llu (1/P of the whole: %.0f)",
          rank, (unsigned long long)stats.volume_bytes, (unsigned long long)carried, share);
    umbra_volume whole = NULL;
    umbra_transfer_function tf = make_tf(ctx);
    float *want = NULL;
    const scene s = {"file (NRRD by box), none, oblique", UMBRA_SHADOW_NONE, 1, 0, 0};
    if (rank == 0) {
        st = umbra_volume_load(ctx, hdr, &whole);
        umbra_volume_info info;
        umbra_volume_get_info(whole, &info);
        CHECK(info.value_min == mv.value_min && info.value_max == mv.value_max,
              "agreed range %g..%g, one device %g..%g", (double)mv.value_min,
              (double)mv.value_max, (double)info.value_min, (double)info.value_max);
        want = render_whole(ctx, whole, tf, &s);
    }
    run_scene(comm, ctx, mv.volume, tf, &s, want);
    free(want);
    umbra_volume_release(whole);
    umbra_volume_release(mv.volume);
    umbra_transfer_function_release(tf);
}

/* Every rank got status want and the same message, naming needle. */
static void check_agreed(MPI_Comm comm, umbra_status got, umbra_status want, const char *message,
                         const char *needle, const char *what)
{
    int mine[2] = {(int)got, -(int)got}, all[2];
    MPI_Allreduce(mine, all, 2, MPI_INT, MPI_MIN, comm);
    CHECK(all[0] == -all[1], "%s: the ranks returned different statuses", what);
    CHECK(got == want, "%s: status %s, expected %s", what, umbra_status_to_string(got),
          umbra_status_to_string(want));
    CHECK(strstr(message, needle) != NULL, "%s: message \"%s\" does not name \"%s\"", what,
          message, needle);
    char first[UMBRA_MPI_MESSAGE_MAX];
    snprintf(first, sizeof first, "%s", message);
    MPI_Bcast(first, (int)sizeof first, MPI_CHAR, 0, comm);
    CHECK(strcmp(first, message) == 0, "%s: rank %d's message \"%s\" is not rank 0's", what, rank,
          message);
}

static void test_bad_input(MPI_Comm comm, umbra_context ctx, const uint32_t grid[3],
                           const char *dir)
{
    char msg[UMBRA_MPI_MESSAGE_MAX];
    umbra_mpi_split_desc split;
    umbra_part_desc p;
    umbra_status st;
    const uint32_t dims[3] = {NX, NY, NZ};

    /* A grid that does not tile the ranks. */
    umbra_mpi_split_desc_init(&split);
    split.brick_size = BS;
    split.grid[0] = grid[0] + 1;
    split.grid[1] = grid[1];
    split.grid[2] = grid[2];
    st = umbra_mpi_split(comm, ctx, dims, &split, &p, NULL);
    snprintf(msg, sizeof msg, "%s", umbra_context_last_message(ctx));
    check_agreed(comm, st, UMBRA_ERROR_INVALID_ARGUMENT, msg, "must tile", "a grid of P+1 parts");

    /* More parts along x than bricks. */
    if (ranks > 1) {
        const uint32_t thin[3] = {BS, NY, NZ};
        split.grid[0] = (uint32_t)ranks;
        split.grid[1] = split.grid[2] = 1;
        st = umbra_mpi_split(comm, ctx, thin, &split, &p, NULL);
        snprintf(msg, sizeof msg, "%s", umbra_context_last_message(ctx));
        check_agreed(comm, st, UMBRA_ERROR_INVALID_ARGUMENT, msg, "bricks", "more parts than bricks");
    }

    /* The last rank has no device. */
    {
        umbra_context_desc cd;
        umbra_context c = NULL;
        umbra_context_desc_init(&cd);
        if (rank == ranks - 1)
            cd.device_name = "no device is called this";
        st = umbra_context_create(&cd, &c);
        char none[128];
        snprintf(none, sizeof none, "no OpenCL device (%s)", umbra_status_to_string(st));
        st = umbra_mpi_agree(comm, c, st, c ? NULL : none, msg, sizeof msg);
        char needle[32];
        snprintf(needle, sizeof needle, "rank %d: ", ranks - 1);
        check_agreed(comm, st, UMBRA_ERROR_NO_DEVICE, msg, needle, "a rank without a device");
        umbra_context_release(c);
    }

    /* A file missing on one rank only. */
    {
        umbra_mpi_volume mv;
        umbra_mpi_split_desc_init(&split);
        memcpy(split.grid, grid, sizeof split.grid);
        split.brick_size = BS;
        char good[1024], needle[32];
        snprintf(good, sizeof good, "%s/small.nrrd", dir);
        if (rank == 0) {
            FILE *f = fopen(good, "wb");
            unsigned char v[16 * 16 * 16] = {0};
            fprintf(f, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 16 16 16\nencoding: raw\n\n");
            fwrite(v, 1, sizeof v, f);
            fclose(f);
        }
        MPI_Barrier(comm);
        const char *path = rank == ranks - 1 ? "/nonexistent/missing.nhdr" : good;
        st = umbra_mpi_load(comm, ctx, path, NULL, &split, NULL, &mv, NULL);
        snprintf(msg, sizeof msg, "%s", umbra_context_last_message(ctx));
        snprintf(needle, sizeof needle, "rank %d: ", ranks - 1);
        check_agreed(comm, st, UMBRA_ERROR_IO, msg, needle, "a file missing on a rank");
        CHECK(strstr(msg, "missing.nhdr") != NULL, "the message \"%s\" names no file", msg);
        CHECK(mv.volume == NULL, "a failed load left a volume");
    }
    /* The context is still usable. */
    umbra_transfer_function tf = make_tf(ctx);
    CHECK(tf != NULL, "the context is unusable after the refusals");
    umbra_transfer_function_release(tf);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    uint32_t grid[3] = {1, 1, 1};
    for (int a = 0, left = ranks; left > 1; a = (a + 1) % 3, left /= 2)
        grid[a] *= 2;
    if (grid[0] * grid[1] * grid[2] != (uint32_t)ranks) {
        if (rank == 0)
            fprintf(stderr, "test_mpi: run on 1, 2, 4 or 8 ranks (got %d)\n", ranks);
        MPI_Finalize();
        return 1;
    }
    umbra_context ctx = NULL;
    umbra_status st = umbra_context_create(NULL, &ctx);
    if (umbra_mpi_agree(MPI_COMM_WORLD, ctx, st, ctx ? NULL : "no OpenCL device", NULL, 0) !=
        UMBRA_SUCCESS) {
        if (rank == 0)
            fprintf(stderr, "test_mpi: no context\n");
        MPI_Finalize();
        return 1;
    }
    char dir[] = "/tmp/umbra-mpi-XXXXXX";
    if (rank == 0 && !mkdtemp(dir))
        ++failures;
    MPI_Bcast(dir, (int)sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
    if (rank == 0)
        printf("%d ranks, grid %ux%ux%u, volume %ux%ux%u, image %ux%u\n", ranks, grid[0], grid[1],
               grid[2], NX, NY, NZ, W, H);
    const char *only = argc > 1 ? argv[1] : NULL; /* "scenes", "file" or "bad": one group */
    if (!only || strcmp(only, "bad") == 0)
        test_bad_input(MPI_COMM_WORLD, ctx, grid, dir);
    if (!only || strcmp(only, "scenes") == 0)
        test_scenes(MPI_COMM_WORLD, ctx, grid);
    if (!only || strcmp(only, "file") == 0)
        test_file(MPI_COMM_WORLD, ctx, grid, dir);
    if (rank == 0) {
        char cmd[1100];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            ++failures;
        printf("largest difference: none %.3g (bound %.0e), light-space maps %.3g (bound %.0e), "
               "deep at epsilon 0.02 %.3g (bound %.0e); chain composite: %zu floats differ\n",
               (double)worst_none, (double)NONE_BOUND, (double)worst_shadow, (double)SHADOW_BOUND,
               (double)worst_deep_eps, (double)SHADOW_BOUND, chain_differing);
    }
    int total = 0;
    MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (rank == 0)
        printf("%s: %d failed check%s\n", total ? "FAIL" : "PASS", total, total == 1 ? "" : "s");
    umbra_context_release(ctx);
    MPI_Finalize();
    return total ? 1 : 0;
}
