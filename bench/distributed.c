// SPDX-License-Identifier: Apache-2.0
/* bench/distributed.c: `umbra-bench distributed --mpi BUILD`: umbra-render-mpi (built in BUILD
 * with -DUMBRA_WITH_MPI=ON) on P = 1, 2, 4, 8 ranks (grids 1x1x1, 2x1x1, 2x2x1, 2x2x2) of a
 * generated N^3 float32 volume, each run under mpirun --oversubscribe with Open MPI's pml
 * monitoring on, so the bytes each rank sends are the MPI library's count (every point-to-point
 * message, the collectives' included), beside the payload umbra_mpi hands in. Per rank: the
 * volume bytes it holds, the stage times umbra-render-mpi prints and the bytes. On one machine the
 * ranks share its cores: the times say what work each stage does, not how it speeds up.
 * The bench itself links no MPI: it runs the tool. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"

#define MAX_RANKS 8

typedef struct rank_row {
    double load, light, build, render, composite;
    unsigned long long payload, volume, sent; /* sent: pml monitoring's bytes */
} rank_row;

/* The bytes rank r sent (pml monitoring's "E" lines of prefix.r.prof: "E <src> <dst> <bytes>
 * bytes <n> msgs sent"); 0 if the file is missing. */
static unsigned long long monitored_bytes(const char *prefix, int r)
{
    char path[1200], line[512];
    unsigned long long sum = 0;
    snprintf(path, sizeof path, "%s.%d.prof", prefix, r);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f)) {
        int src, dst;
        unsigned long long b;
        if (line[0] == 'E' && sscanf(line + 1, "%d %d %llu", &src, &dst, &b) == 3)
            sum += b;
    }
    fclose(f);
    return sum;
}

/* Runs P ranks; fills rows[0..P). Returns 0 on success. */
static int run_ranks(const char *mpi_dir, const char *dir, int p, uint32_t size,
                     const char *technique, rank_row *rows)
{
    static const char *const grids[] = {"1x1x1", "2x1x1", NULL, "2x2x1", NULL, NULL, NULL,
                                        "2x2x2"};
    char cmd[4096], log[1100], mon[1100], line[512];
    snprintf(log, sizeof log, "%s/run_%d.log", dir, p);
    snprintf(mon, sizeof mon, "%s/mon_%d", dir, p);
    snprintf(cmd, sizeof cmd,
             "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe "
             "-np %d --mca pml_monitoring_enable 1 --mca pml_monitoring_enable_output 3 "
             "--mca pml_monitoring_filename '%s' '%s/umbra-render-mpi' --grid %s --volume "
             "'%s/vol.nhdr' --technique %s --map-size 256 --size %ux%u --termination 1 "
             "--no-ground --no-progress --light-dir 0.3,-1,0.4 -o '%s/out_%d.exr' 2>'%s' "
             ">/dev/null",
             p, mon, mpi_dir, grids[p - 1], dir, technique, size, size, dir, p, log);
    if (system(cmd) != 0) {
        fprintf(stderr, "umbra-bench distributed: P = %d failed; see %s\n", p, log);
        return 1;
    }
    FILE *f = fopen(log, "r");
    int got = 0;
    while (f && fgets(line, sizeof line, f)) {
        int r;
        char where[64], dims[64];
        rank_row x;
        if (sscanf(line, "%d %63s %63s %lf %lf %lf %lf %lf %llu %llu", &r, where, dims, &x.load,
                   &x.light, &x.build, &x.render, &x.composite, &x.payload, &x.volume) == 10 &&
            r >= 0 && r < p) {
            x.sent = monitored_bytes(mon, r);
            rows[r] = x;
            ++got;
        }
    }
    if (f)
        fclose(f);
    if (got != p) {
        fprintf(stderr, "umbra-bench distributed: P = %d: %d rank lines in %s\n", p, got, log);
        return 1;
    }
    return 0;
}

static int write_volume(const char *dir, uint32_t n)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/vol.raw", dir);
    FILE *f = fopen(path, "wb");
    if (!f)
        return 1;
    float *row = malloc(n * sizeof *row);
    for (uint32_t z = 0; z < n && row; ++z)
        for (uint32_t y = 0; y < n; ++y) {
            for (uint32_t x = 0; x < n; ++x) {
                float dx = (x - 0.45f * n) / (0.25f * n), dy = (y - 0.5f * n) / (0.2f * n);
                float dz = (z - 0.55f * n) / (0.3f * n);
                float s = expf(-(dx * dx + dy * dy + dz * dz)) +
                          0.1f * sinf(0.2f * x) * cosf(0.15f * y + 0.1f * z);
                row[x] = s < 0 ? 0 : s;
            }
            fwrite(row, sizeof *row, n, f);
        }
    free(row);
    fclose(f);
    snprintf(path, sizeof path, "%s/vol.nhdr", dir);
    f = fopen(path, "w");
    if (!f)
        return 1;
    fprintf(f, "NRRD0004\ntype: float\ndimension: 3\nsizes: %u %u %u\nencoding: raw\n"
               "endian: little\ndata file: vol.raw\n", n, n, n);
    fclose(f);
    return 0;
}

int bench_distributed(int argc, char **argv)
{
    const char *mpi_dir = NULL, *results = NULL, *technique = "threshold";
    uint32_t n = 128, image = 256;
    for (int i = 1; i < argc; ++i) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--mpi") == 0 && v) {
            mpi_dir = v;
            ++i;
        } else if (strcmp(argv[i], "--results") == 0 && v) {
            results = v;
            ++i;
        } else if (strcmp(argv[i], "--technique") == 0 && v) {
            technique = v;
            ++i;
        } else if (strcmp(argv[i], "--n") == 0 && v) {
            n = (uint32_t)atoi(v);
            ++i;
        } else {
            printf("usage: umbra-bench distributed --mpi BUILD [--results DIR] [--technique T] "
                   "[--n N]\n"
                   "  --mpi BUILD    a build directory made with -DUMBRA_WITH_MPI=ON (its "
                   "umbra-render-mpi)\n"
                   "  --results DIR  also write DIR/distributed.csv, .md and .png\n"
                   "  --technique T  a technique umbra-render-mpi splits (default threshold)\n"
                   "  --n N          the volume's edge in voxels (default 128, float32)\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    if (!mpi_dir || n < 32 || n > 2048) {
        fprintf(stderr, "umbra-bench distributed: --mpi BUILD is required; --n in [32, 2048]\n");
        return 2;
    }
    char dir[] = "/tmp/umbra-bench-distributed-XXXXXX";
    if (!mkdtemp(dir) || write_volume(dir, n) != 0) {
        fprintf(stderr, "umbra-bench distributed: cannot write the volume\n");
        return 1;
    }
    static const int ps[] = {1, 2, 4, 8};
    rank_row rows[4][MAX_RANKS];
    memset(rows, 0, sizeof rows);
    int rc = 0;
    for (int k = 0; k < 4 && rc == 0; ++k) {
        fprintf(stderr, "P = %d ...\n", ps[k]);
        rc = run_ranks(mpi_dir, dir, ps[k], image, technique, rows[k]);
    }
    char csv[1200], md[1200];
    FILE *c = stdout, *m = NULL;
    if (results) {
        snprintf(csv, sizeof csv, "%s/distributed.csv", results);
        snprintf(md, sizeof md, "%s/distributed.md", results);
        c = fopen(csv, "w");
        m = fopen(md, "w");
        if (!c || !m) {
            fprintf(stderr, "umbra-bench distributed: cannot write into %s\n", results);
            return 1;
        }
    }
    fprintf(c, "ranks,rank,technique,volume_edge,image_edge,volume_bytes,load_ms,light_exchange_ms,"
               "build_ms,render_ms,composite_ms,payload_bytes,mpi_bytes_sent\n");
    for (int k = 0; k < 4 && rc == 0; ++k)
        for (int r = 0; r < ps[k]; ++r) {
            const rank_row *x = &rows[k][r];
            fprintf(c, "%d,%d,%s,%u,%u,%llu,%.2f,%.2f,%.2f,%.2f,%.2f,%llu,%llu\n", ps[k], r,
                    technique, n, image, x->volume, x->load, x->light, x->build, x->render,
                    x->composite, x->payload, x->sent);
        }
    if (m && rc == 0) {
        const double vol = (double)n * n * n * 4, img = (double)image * image * 16;
        fprintf(m, "# umbra-bench distributed\n\n"
                   "`umbra-bench distributed --mpi build-mpi --results bench/results --technique %s`: "
                   "umbra-render-mpi, technique %s, a %u^3 float32 volume (%.2f MiB), map "
                   "256^2, image %u^2 (%.2f MiB of float RGBA), P ranks oversubscribed on this "
                   "machine's cores (times: the work of each stage with the ranks sharing the "
                   "cores, not speed-ups). Bytes sent: Open MPI's pml monitoring (every message, "
                   "collectives included), mean over the ranks; payload: what umbra_mpi hands to "
                   "MPI. Times: the largest over the ranks.\n\n"
                   "| P | volume MiB per rank (max) | x P / whole | sent per rank, MiB | payload "
                   "per rank, MiB | load ms | light exchange ms | build ms | render ms | "
                   "composite ms |\n|---|---|---|---|---|---|---|---|---|---|\n",
                technique, technique, n, vol / 1048576.0, image, img / 1048576.0);
        for (int k = 0; k < 4; ++k) {
            double vmax = 0, sent = 0, pay = 0, t[5] = {0, 0, 0, 0, 0};
            for (int r = 0; r < ps[k]; ++r) {
                const rank_row *x = &rows[k][r];
                vmax = fmax(vmax, (double)x->volume);
                sent += (double)x->sent / ps[k];
                pay += (double)x->payload / ps[k];
                t[0] = fmax(t[0], x->load);
                t[1] = fmax(t[1], x->light);
                t[2] = fmax(t[2], x->build);
                t[3] = fmax(t[3], x->render);
                t[4] = fmax(t[4], x->composite);
            }
            fprintf(m, "| %d | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f | %.0f |\n",
                    ps[k], vmax / 1048576.0, vmax * ps[k] / vol, sent / 1048576.0,
                    pay / 1048576.0, t[0], t[1], t[2], t[3], t[4]);
        }
        fclose(m);
        fclose(c);
        /* The log-log plot: bench/plot_distributed.gp. */
        char gp[3000];
        snprintf(gp, sizeof gp,
                 "gnuplot -e \"csv='%s'; out='%s/distributed.png'\" '%s/bench/plot_distributed.gp' "
                 ">/dev/null 2>&1",
                 csv, results, UMBRA_SOURCE_DIR);
        if (system(gp) != 0)
            fprintf(stderr, "umbra-bench distributed: plot skipped (gnuplot failed or is "
                            "missing)\n");
        fprintf(stderr, "wrote %s, %s\n", csv, md);
    }
    char rm[200];
    snprintf(rm, sizeof rm, "rm -rf '%s'", dir);
    if (system(rm) != 0)
        rc = 1;
    return rc;
}
