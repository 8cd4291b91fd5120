// SPDX-License-Identifier: Apache-2.0
/* bench/bench.h: what umbra-bench's subcommands share.
 *
 * umbra-bench is one executable with subcommands (`umbra-bench raycast ...`). Each subcommand
 * lives in its own file, bench/<name>.c, as `int bench_<name>(int argc, char **argv)` (argv[0] is
 * the subcommand's name; returns the process exit status), and has one row in the table in
 * bench/main.c. The helpers here (bench/bench_util.c) give every subcommand the same timing
 * (median of N runs after warm-up), the same CSV layout, the same test volume and the same
 * description of the machine, so their results read alike. Timing belongs here, never in tests. */
#ifndef UMBRA_BENCH_H
#define UMBRA_BENCH_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "umbra/io.h"

/* ---- subcommands ------------------------------------------------------------------------------ */

typedef int (*bench_fn)(int argc, char **argv);

typedef struct bench_command {
    const char *name;  /* the subcommand, as typed */
    bench_fn run;
    const char *help;  /* one line for `umbra-bench --help` */
} bench_command;

int bench_raycast(int argc, char **argv); /* bench/raycast.c */
int bench_convolution(int argc, char **argv); /* bench/convolution.c */
int bench_accuracy(int argc, char **argv); /* bench/accuracy.c */
int bench_readme(int argc, char **argv);   /* bench/readme.c */
int bench_scale(int argc, char **argv);    /* bench/scale.c */
int bench_distributed(int argc, char **argv); /* bench/distributed.c */
int bench_interactive(int argc, char **argv); /* bench/interactive.c */
int bench_builds(int argc, char **argv);   /* bench/builds.c */
int bench_conformance(int argc, char **argv); /* bench/conformance.c */
int bench_progress(int argc, char **argv); /* bench/progress.c */
int bench_features(int argc, char **argv); /* bench/features.c */

/* ---- timing -------------------------------------------------------------------------------------- */

/* Wall-clock milliseconds from a monotonic clock. */
double bench_now_ms(void);

typedef struct bench_timing {
    double median, min, max; /* milliseconds */
    int runs;
} bench_timing;

/* Median (mean of the middle two for an even count), min and max of n >= 1 timings. */
bench_timing bench_timing_of(const double *ms, int n);

/* ---- CSV ----------------------------------------------------------------------------------------- */

/* The header every timing CSV starts with. */
#define BENCH_CSV_HEADER "case,ms_median,samples_per_s,samples,ms_min,ms_max"

/* One row: samples_per_s = samples / median; samples == 0 leaves both fields empty (a peer that
 * does not report what it sampled). */
void bench_csv_row(FILE *f, const char *name, bench_timing t, uint64_t samples);

/* ---- the test volume ------------------------------------------------------------------------------ */

typedef struct bench_volume {
    umbra_volume volume;  /* on the benchmark's context */
    float *voxels;        /* the normalised values umbra samples, x fastest (malloc'ed) */
    uint32_t dims[3];
    float spacing[3];
    float value_min, value_max; /* the value range mapped to [0, 1] */
    char path[1024];      /* an NRRD header holding the same data (for peers such as VTK) */
    char description[1200];
    char tmpdir[256];     /* scratch directory of a written procedural volume, or "" */
} bench_volume;

/* The bonsai CT: `path` if given, else $UMBRA_DATA_DIR/bonsai.nhdr or
 * $UMBRA_DATA_DIR/volumes/bonsai.nhdr, else UMBRA_SOURCE_DIR/../shared/data/volumes/bonsai.nhdr;
 * when none exists (or procedural is nonzero), a procedural 256^3 uint8 stand-in of similar
 * structure (see bench_util.c), which is also written to a scratch NRRD so peers read the same
 * data. Prints what it loaded to stderr. Returns 0 on success. */
int bench_volume_load_bonsai(umbra_context ctx, const char *path, int procedural,
                             bench_volume *out);
void bench_volume_free(bench_volume *v);

/* ---- the machine ------------------------------------------------------------------------------------ */

/* "model name" of /proc/cpuinfo and the number of online CPUs, e.g. "Intel(R) Xeon(R) ... x 2". */
void bench_cpu_model(char *buf, size_t size);

/* The OpenCL device umbra runs on, with its compute units and sampler back end. */
void bench_device_description(umbra_context ctx, char *buf, size_t size);

/* ---- results files ------------------------------------------------------------------------------ */

/* Opens DIR/<subcommand>.<ext> ("csv", "md") for writing, creating DIR if it is missing; NULL,
 * with "umbra-bench <subcommand>: cannot write PATH" on stderr, where it cannot. */
FILE *bench_results_open(const char *dir, const char *subcommand, const char *ext);

/* The head of a results .md: "# umbra-bench <subcommand>", then the date (UTC), the command line
 * (argv[0] the subcommand), the OpenCL device (bench_device_description) and the CPU. */
void bench_results_header(FILE *f, const char *subcommand, int argc, char **argv,
                          const char *device);

/* ---- command-line helpers ---------------------------------------------------------------------------- */

/* Whether name is one of the names of a comma-separated list. */
int bench_in_list(const char *list, const char *name);

/* Strict parsers: the whole string must be a number in range; return 0 on success. */
int bench_parse_int(const char *s, long lo, long hi, long *out);
int bench_parse_float(const char *s, float lo, float hi, float *out);
int bench_parse_size(const char *s, uint32_t *w, uint32_t *h); /* "WxH", each in [1, 16384] */

/* A context on `device` (NULL: the default choice, $UMBRA_DEVICE honoured); prints the reason to
 * stderr and returns NULL on failure. */
umbra_context bench_context(const char *device);

/* Table formatting shared by the subcommands: "0", "812.0 KiB", "3.1 MiB", "1.25 GiB"; and
 * milliseconds with three significant digits ("1234", "56.7", "8.91"). */
void bench_format_bytes(size_t bytes, char *buf, size_t size);

/* Splits a CSV line without quoting (accuracy.csv has none) in place at its commas, the line end
 * cut off; returns the field count (at most max). */
int bench_split_csv(char *line, char **fields, int max);
void bench_format_ms(double ms, char *buf, size_t size);

#endif
