// SPDX-License-Identifier: Apache-2.0
/* bench/accuracy.h: what the parts of `umbra-bench accuracy` share.
 *
 * The subcommand is one results table (bench_run.results) filled by one part and read by another:
 *   bench/accuracy.c         the settings swept, the options, the scene list and the entry point
 *                            bench_accuracy, with the small helpers the other parts use
 *   bench/accuracy_run.c     rendering and measuring each setting of a scene, and the machine
 *   bench/accuracy_report.c  the outputs: accuracy.csv, the Pareto fronts, the gnuplot plots,
 *                            summary.md, headline.md and papers.md
 * What the subcommand measures and how is said at the top of bench/accuracy.c and in
 * bench/README.md. All of it runs on one thread. */
#ifndef UMBRA_BENCH_ACCURACY_H
#define UMBRA_BENCH_ACCURACY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "bench.h"
#include "metrics.h"
#include "scene_file.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
/* ---- bench/accuracy_texel.c ------------------------------------------------------------------ */

/* <out>/texel.md: per scene the Pareto front over bytes per map texel (after accuracy_pareto)
 * and its plot, and the moment map against CSSM and the deep map at equal memory. */
void accuracy_write_texel(bench_run *B);

/* ---- bench/accuracy_merge.c ------------------------------------------------------------------ */

/* Reads the --merge file into memory (before the run can overwrite it); 0, or -1. */
int accuracy_merge_read(const char *path);

/* The scene names of the merge file's rows, comma-separated into names; -1 if unread. */
int accuracy_merge_scene_names(char *names, size_t size);

/* Adds the rows of B->o.merge that this run did not measure (same scene, technique and params)
 * to B->results, and puts all rows in the sweep's order; a file that cannot be read is a
 * failure. */
void accuracy_merge_rows(bench_run *B);

#endif

#define MAX_CONFIGS 96
#define MAX_SCENES 32
#define QUICK_MAX_SIDE 256u
/* Adaptive run counts: a setting whose first frame (build + render) takes longer than these gets
 * fewer timed runs (2, then 1), so that the 4096^2 maps do not dominate the sweep. There is always
 * at least one timed frame after the first: the first can carry one-time work (a deep map's block
 * pool growing to fit, a table built on first use) that a rebuild does not repeat. */
#define SLOW_MS 3000.0
#define VERY_SLOW_MS 12000.0

/* ---- the settings swept ---------------------------------------------------------------------- */

/* Rows of the headline table: none, the exact reference, then one representative setting (or
 * two) per technique, numbered in the sweep's order from H_FIRST_TECHNIQUE (the settings flagged
 * headline in the registry). */
enum { H_NONE = 1, H_EXACT, H_FIRST_TECHNIQUE };

typedef struct config {
    umbra_shadow_desc desc;
    int preintegrated; /* umbra_render_desc.preintegrated for this setting */
    char label[96];   /* for people: "1024² 13 taps" */
    char params[160]; /* for the CSV: "map_size=1024;taps=13" */
    int headline;     /* its row of the headline table (1.., H_NONE, H_EXACT, ...) or 0 */
    int exact;        /* the exact reference itself */
} config;

typedef struct config_list {
    config items[MAX_CONFIGS];
    int count;
    int headline_count; /* the largest headline row */
} config_list;

/* ---- results --------------------------------------------------------------------------------- */

typedef struct result {
    int scene;               /* index into the scene list */
    config cfg;
    int runs;                /* timed runs behind the medians (0: the first frame's times) */
    double build_ms, render_ms, total_ms;
    double build_min, build_max, render_min, render_max;
    double none_ms;          /* the scene's unshadowed render, same run */
    double reference_ms;     /* the scene's exact reference render */
    int reference_cached;    /* reference_ms comes from the cache */
    size_t memory;
    uint32_t channels, slices;
    uint32_t map_size;       /* light-space maps: the size built (what auto chose), else 0 */
    uint64_t samples;
    metrics_error err;
    uint32_t width, height;
    int pareto_time, pareto_memory, pareto_texel; /* on the front of time, memory, bytes per
                                                     map texel */
    /* The yardstick's own error: the scene's reference at its step against the reference at half
     * that step (display values, as err); rmse < 0 when it could not be measured. */
    metrics_error ref_unc;
    int order; /* --merge: the row's place in the sweep (bench/accuracy_merge.c) */
} result;

typedef struct note_list {
    char **items;
    int count, cap;
} note_list;

/* The command line (accuracy.c parse_options). */
typedef struct options {
    int quick, runs, warmup, plots, list;
    int report; /* --report: nothing measured, the outputs from the --merge rows */
    int cache; /* read cached references (0: --no-cache); they are written either way */
    const char *images;      /* none | headline | all */
    char out[2048], cache_dir[2100], scene_dir[2048], main_scene[SCENE_NAME_MAX];
    char scenes[1024];       /* comma-separated names, "" for all */
    char techniques[256];    /* comma-separated technique names, "" for all */
    char merge[2048];        /* --merge: an earlier accuracy.csv whose other rows are kept */
    const char *device;
    uint32_t max_map;
} options;

/* One run of the subcommand: what every part reads and the results table they fill. */
typedef struct bench_run {
    options o;
    umbra_context ctx;
    scene_spec scenes[MAX_SCENES];
    int present[MAX_SCENES];
    int merged_only[MAX_SCENES]; /* scenes whose rows all come from --merge: not run */
    int scene_count;
    result *results;
    int result_count, result_cap;
    note_list notes;
    int failures;
    int run_index, run_total;
    double t_start;
    char machine[1024], device[1024], platform[512], started[64], commit[128];
    double load_start[3];
} bench_run;

/* ---- bench/accuracy.c ------------------------------------------------------------------------ */

/* The scene's exact-reference shadow-ray step: its reference_step, else 0.25 voxel. */
float accuracy_exact_step(const scene_spec *s);

/* Fills L with the sweep for one scene, less the techniques o->techniques leaves out. */
void accuracy_scene_configs(const options *o, const scene_spec *s, config_list *L);

/* Prints the note to stderr and keeps its first line for summary.md (dropped if out of memory). */
void accuracy_add_note(bench_run *B, const char *fmt, ...);

/* Appends a zeroed row to B->results (which may move); NULL when out of memory. */
result *accuracy_new_result(bench_run *B);

/* mkdir -p: 0, or -1 with errno set. */
int accuracy_mkdirs(const char *path);

/* Whether stat() finds path. */
int accuracy_file_exists(const char *path);

/* ms as "42s", "3m07s" or "1h02m" into buf. */
void accuracy_format_duration(double ms, char *buf, size_t size);

/* Replaces, in place, characters that would break a CSV field (for_file: or a file name). */
void accuracy_sanitize(char *s, int for_file);

/* The index of the scene called name in B->scenes, or -1. */
int accuracy_scene_index(const bench_run *B, const char *name);

/* ---- bench/accuracy_run.c -------------------------------------------------------------------- */

/* Fills B's machine, device, platform, start time, load average and commit; needs B->ctx. */
void accuracy_describe_machine(bench_run *B);

/* The machine and the run's mode as a Markdown list into f (summary.md, papers.md). */
void accuracy_write_machine(bench_run *B, FILE *f);

/* Measures every setting of scene si against its exact reference and appends the rows to
 * B->results; what fails or is skipped becomes a note (failures also count in B->failures). */
void accuracy_run_scene(bench_run *B, int si);

/* ---- bench/accuracy_report.c ----------------------------------------------------------------- */

/* Marks the per-scene Pareto fronts in B->results and writes them under <out>/plots. */
void accuracy_pareto(bench_run *B);
/* A light-space map's shadow memory over its texels (map_size^2): bytes per texel; 0 for a run
 * without a map. */
static inline double accuracy_bytes_per_texel(const result *r)
{
    return r->map_size ? (double)r->memory / ((double)r->map_size * (double)r->map_size) : 0.0;
}

/* <out>/accuracy.csv, one row per result; a file that cannot be written is a failure. */
void accuracy_write_csv(bench_run *B);

/* <out>/plots/<scene>-error-vs-{time,memory}.png through gnuplot; a note when it cannot. */
void accuracy_write_plots(bench_run *B);

/* <out>/headline.md, the README's headline table. */
void accuracy_write_headline(bench_run *B);

/* <out>/summary.md: the machine, headline.md (so after accuracy_write_headline), every scene's
 * table and the notes. */
void accuracy_write_summary(bench_run *B);

/* <out>/papers.md: the seed papers' timing tables beside ours. */
void accuracy_write_papers(bench_run *B);

/* ---- bench/accuracy_texel.c ------------------------------------------------------------------ */

/* <out>/texel.md: per scene the Pareto front over bytes per map texel (after accuracy_pareto)
 * and its plot, and the moment map against CSSM and the deep map at equal memory. */
void accuracy_write_texel(bench_run *B);

/* ---- bench/accuracy_merge.c ------------------------------------------------------------------ */

/* Reads the --merge file into memory (before the run can overwrite it); 0, or -1. */
int accuracy_merge_read(const char *path);

/* The scene names of the merge file's rows, comma-separated into names; -1 if unread. */
int accuracy_merge_scene_names(char *names, size_t size);

/* Adds the rows of B->o.merge that this run did not measure (same scene, technique and params)
 * to B->results, and puts all rows in the sweep's order; a file that cannot be read is a
 * failure. */
void accuracy_merge_rows(bench_run *B);

#endif
