// SPDX-License-Identifier: Apache-2.0
/* bench/accuracy.c: `umbra-bench accuracy`, what accuracy costs in time.
 *
 * For every scene of bench/scenes/ (scene_file.h) and every shadow technique this build has, over
 * each technique's parameters, the bench measures the shadow build time and the render time
 * (device times from OpenCL profiling events, umbra_render_stats; medians of N runs after a
 * warm-up), the unshadowed render time of the same view (technique none, so that overheads are
 * ratios from the same run), the shadow structure's memory and light channels, and the image
 * error against the exact reference of the same scene and view (bench/metrics.h: RMSE, PSNR, max
 * and mean absolute error, SSIM on luma). It writes accuracy.csv (one row per run), summary.md,
 * headline.md (the README's headline table), papers.md (the seed papers' timing tables
 * re-measured, side by side with the papers' figures) and PNG plots through gnuplot
 * (bench/plot_accuracy.gp): error against time and error against memory, per scene, with the
 * Pareto front. bench/README.md documents the options and the method.
 *
 * How a build is timed again: the renderer rebuilds a shadow structure only when its light key
 * (light, volume, light transfer function, shadow description, transmission, skipping; compared
 * with memcmp in host/renderer.c prepare_shadow) changes. Each timed run therefore alternates the
 * light between the scene's light and a copy whose red intensity is one float ulp lower: the key
 * changes, so every timed frame rebuilds, while the work is the same (no technique's cost depends
 * on the light's colour). The error image is always rendered with the scene's own light.
 *
 * A technique that umbra_renderer_set_shadow or the first render rejects with
 * UMBRA_ERROR_UNSUPPORTED (not in this build, or a light convolution shadows cannot propagate) or
 * that runs out of memory is skipped with a note, so the bench runs at every stage of the
 * project; any other error is reported, the run is skipped, and the exit status is 1.
 *
 * Why one file past 800 lines: it is one subcommand whose parts (settings, runs, metrics, CSV,
 * summaries, plots) share one results table; splitting it is planned with the next bench change. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "metrics.h"
#include "scene_file.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
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

/* Rows of the headline table: one representative setting per technique. */
enum {
    H_NONE = 1,
    H_EXACT,
    H_REF_COARSE,
    H_THRESHOLD,
    H_CSSM,
    H_DEEP,
    H_DEEP3,
    H_CONV,
    H_COUNT
};


typedef struct config {
    umbra_shadow_desc desc;
    char label[96];   /* for people: "1024² 13 taps" */
    char params[160]; /* for the CSV: "map_size=1024;taps=13" */
    int headline;     /* H_* or 0 */
    int exact;        /* the exact reference itself */
} config;

typedef struct config_list {
    config items[MAX_CONFIGS];
    int count;
    uint32_t headline_map; /* the map size of the headline settings: 1024, or 512 with --quick */
} config_list;

static config *add_config(config_list *L, umbra_shadow_technique t)
{
    if (L->count >= MAX_CONFIGS)
        return NULL;
    config *c = &L->items[L->count++];
    memset(c, 0, sizeof *c);
    umbra_shadow_desc_init(&c->desc);
    c->desc.technique = t;
    return c;
}

static void add_none(config_list *L)
{
    config *c = add_config(L, UMBRA_SHADOW_NONE);
    if (!c)
        return;
    snprintf(c->label, sizeof c->label, "no shadows");
    snprintf(c->params, sizeof c->params, "-");
    c->headline = H_NONE;
}

static void add_reference(config_list *L, float step, int exact)
{
    config *c = add_config(L, UMBRA_SHADOW_REFERENCE);
    if (!c)
        return;
    c->desc.reference_step = step;
    c->exact = exact;
    snprintf(c->label, sizeof c->label, "step %g%s", step, exact ? " (exact)" : "");
    snprintf(c->params, sizeof c->params, "reference_step=%g", step);
    if (exact)
        c->headline = H_EXACT;
    else if (step == 1.0f)
        c->headline = H_REF_COARSE;
}

/* "1024" or "auto" (UMBRA_MAP_SIZE_AUTO: the renderer chooses; the run's label and the CSV's
 * map_size column give the size chosen, from umbra_render_stats.map_size). */
static const char *map_name(uint32_t map, char buf[16])
{
    if (map == UMBRA_MAP_SIZE_AUTO)
        return "auto";
    snprintf(buf, 16, "%u", map);
    return buf;
}

static const char *map_label(uint32_t map, char buf[16])
{
    if (map == UMBRA_MAP_SIZE_AUTO)
        return "auto size";
    snprintf(buf, 16, "%u²", map);
    return buf;
}

static void add_threshold(config_list *L, uint32_t map, uint32_t taps, float threshold)
{
    config *c = add_config(L, UMBRA_SHADOW_THRESHOLD);
    if (!c)
        return;
    c->desc.map_size = map;
    c->desc.taps = taps;
    c->desc.threshold = threshold;
    char a[16], b[16];
    snprintf(c->label, sizeof c->label, "%s, opacity %g%s", map_label(map, a), threshold,
             taps > 1 ? (taps == 7 ? ", 7 taps" : taps == 13 ? ", 13 taps" : ", 21 taps") : "");
    snprintf(c->params, sizeof c->params, "map_size=%s;taps=%u;threshold=%g", map_name(map, b),
             taps, threshold);
    if (map == L->headline_map && taps == 1 && threshold == 0.5f)
        c->headline = H_THRESHOLD;
}

static void add_cssm(config_list *L, uint32_t map, uint32_t taps)
{
    config *c = add_config(L, UMBRA_SHADOW_CSSM);
    if (!c)
        return;
    c->desc.map_size = map;
    c->desc.taps = taps;
    char a[16], b[16];
    snprintf(c->label, sizeof c->label, "%s, %u taps", map_label(map, a), taps);
    snprintf(c->params, sizeof c->params, "map_size=%s;taps=%u;seed=%u", map_name(map, b), taps,
             c->desc.seed);
    if (map == L->headline_map && taps == 13)
        c->headline = H_CSSM;
}

static void add_deep(config_list *L, uint32_t map, float eps, uint32_t nodes, uint32_t prefilter)
{
    config *c = add_config(L, UMBRA_SHADOW_DEEP);
    if (!c)
        return;
    c->desc.map_size = map;
    c->desc.epsilon = eps;
    c->desc.max_nodes = nodes;
    c->desc.prefilter = prefilter;
    char budget[32] = "";
    if (nodes)
        snprintf(budget, sizeof budget, ", %u nodes", nodes);
    char a[16], b[16];
    snprintf(c->label, sizeof c->label, "%s, ε %g%s%s", map_label(map, a), eps, budget,
             prefilter == 5 ? ", 5-tap prefilter" : "");
    snprintf(c->params, sizeof c->params, "map_size=%s;epsilon=%g;max_nodes=%u;prefilter=%u",
             map_name(map, b), eps, nodes, prefilter);
    if (map == L->headline_map && eps == 0.02f && prefilter == 1)
        c->headline = nodes == 0 ? H_DEEP : nodes == 3 ? H_DEEP3 : 0;
}

static void add_convolution(config_list *L, float slice, uint32_t sub, int pre)
{
    config *c = add_config(L, UMBRA_SHADOW_CONVOLUTION);
    if (!c)
        return;
    c->desc.slice_distance = slice;
    c->desc.subsamples = sub;
    c->desc.preintegrated = pre;
    const char *kind = pre ? (sub ? "pre-int. SCS" : "pre-int. ICS") : (sub ? "SCS" : "ICS");
    snprintf(c->label, sizeof c->label, "%s slice %g%s", kind,
             slice, sub ? (sub == 1 ? ", 1 sub-sample" : sub == 2 ? ", 2 sub-samples"
                                                                  : ", 3 sub-samples")
                        : "");
    snprintf(c->params, sizeof c->params,
             "slice_distance=%g;subsamples=%u;preintegrated=%d;cone_angle=%g", slice, sub, pre,
             c->desc.cone_angle_degrees);
    if (slice == 1.0f && sub == 0 && !pre)
        c->headline = H_CONV;
}

/* The sweep. The exact reference comes first (its image is every other row's yardstick), then
 * none (the unshadowed frame every overhead is measured against). Maps are 512^2 and 1024^2 (the
 * headline size); a scene marked `papers cssm` adds 2048^2 and 4096^2 for the CSSM paper's
 * Tables 3-4 (threshold, deep with 3 nodes per channel, CSSM with 13 taps; unbounded deep maps up
 * to 2048^2), one marked `papers deep` the deep-map paper's Table 1 (128^2-512^2 at epsilon 0.02
 * and 0.06 with the 5-tap pre-filter). On a 2-core CPU one 4096^2 build takes one to three
 * minutes, so the large maps are measured where the papers' tables need them. */
static void build_configs(int quick, int papers, uint32_t max_map, float exact_step,
                          config_list *L)
{
    /* auto (UMBRA_MAP_SIZE_AUTO) beside the fixed sizes, so every scene shows what it costs and
     * loses against them; the quick sweep has 1024^2 too, the size auto is measured against. */
    static const uint32_t maps_full[] = {UMBRA_MAP_SIZE_AUTO, 512, 1024, 2048, 4096};
    static const uint32_t maps_quick[] = {UMBRA_MAP_SIZE_AUTO, 512, 1024};
    const uint32_t *maps = quick ? maps_quick : maps_full;
    size_t nmaps = quick ? 3 : (papers & SCENE_PAPERS_CSSM) ? 5 : 3;
    L->count = 0;
    L->headline_map = quick ? 512 : 1024;
    add_reference(L, exact_step, 1);
    add_none(L);
    if (quick) {
        add_reference(L, 1.0f, 0);
    } else {
        add_reference(L, 0.5f, 0);
        add_reference(L, 1.0f, 0);
        add_reference(L, 2.0f, 0);
    }
    for (size_t i = 0; i < nmaps; ++i)
        if (maps[i] <= max_map)
            add_threshold(L, maps[i], 1, 0.5f);
    if (!quick) {
        add_threshold(L, 1024, 13, 0.5f);
        add_threshold(L, 1024, 1, 0.25f);
        add_threshold(L, 1024, 1, 0.75f);
    }
    for (size_t i = 0; i < nmaps; ++i)
        if (maps[i] <= max_map)
            add_cssm(L, maps[i], 13);
    add_cssm(L, L->headline_map, 7);
    if (!quick)
        add_cssm(L, 1024, 21);
    /* Unbounded deep maps stop at 2048^2: at 4096^2 one build takes about 3 minutes here. */
    for (size_t i = 0; i < nmaps && i < 4; ++i)
        if (maps[i] <= max_map)
            add_deep(L, maps[i], 0.02f, 0, 1);
    add_deep(L, L->headline_map, 0.02f, 3, 1);
    if (!quick) {
        for (size_t i = 3; i < nmaps; ++i)
            if (maps[i] <= max_map)
                add_deep(L, maps[i], 0.02f, 3, 1);
        add_deep(L, 1024, 0.02f, 2, 1);
        add_deep(L, 1024, 0.02f, 6, 1);
        add_deep(L, 1024, 0.01f, 0, 1);
        add_deep(L, 1024, 0.06f, 0, 1);
        add_deep(L, 1024, 0.1f, 0, 1);
    }
    if (!quick && (papers & SCENE_PAPERS_DEEP)) {
        add_deep(L, 1024, 0.02f, 0, 5);
        static const uint32_t small[] = {128, 256, 512};
        for (size_t i = 0; i < 3; ++i) {
            add_deep(L, small[i], 0.02f, 0, 5);
            add_deep(L, small[i], 0.06f, 0, 5);
        }
    }
    /* Convolution renders every frame slice by slice: a frame costs seconds to a minute on the
     * CPU, so the sweep samples its parameter plane rather than covering it (the convolution
     * bench covers the paper's Table 1 grid on a small image). */
    if (quick) {
        add_convolution(L, 1.0f, 0, 0);
        add_convolution(L, 2.0f, 0, 0);
        add_convolution(L, 2.0f, 1, 0);
    } else {
        add_convolution(L, 0.5f, 0, 0);
        add_convolution(L, 1.0f, 0, 0);
        add_convolution(L, 2.0f, 0, 0);
        add_convolution(L, 2.0f, 1, 0);
        add_convolution(L, 2.0f, 3, 0);
        add_convolution(L, 1.0f, 0, 1);
        add_convolution(L, 2.0f, 0, 1);
        add_convolution(L, 2.0f, 3, 1);
    }
}

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
    int pareto_time, pareto_memory;
    /* The yardstick's own error: the scene's reference at its step against the reference at half
     * that step (display values, as err); rmse < 0 when it could not be measured. */
    metrics_error ref_unc;
} result;

typedef struct note_list {
    char **items;
    int count, cap;
} note_list;

typedef struct options {
    int quick, runs, warmup, plots, cache, list;
    const char *images;      /* none | headline | all */
    char out[2048], cache_dir[2100], scene_dir[2048], main_scene[SCENE_NAME_MAX];
    char scenes[1024];       /* comma-separated names, "" for all */
    char techniques[256];    /* comma-separated technique names, "" for all */
    const char *device;
    uint32_t max_map;
} options;

typedef struct bench_run {
    options o;
    umbra_context ctx;
    scene_spec scenes[MAX_SCENES];
    int present[MAX_SCENES];
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

static void add_note(bench_run *B, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    fprintf(stderr, "accuracy: %s\n", buf);
    /* The summary keeps the first line (a build log follows on the next ones, on stderr). */
    buf[strcspn(buf, "\n")] = '\0';
    note_list *n = &B->notes;
    if (n->count == n->cap) {
        int cap = n->cap ? 2 * n->cap : 32;
        char **grown = realloc(n->items, (size_t)cap * sizeof *grown);
        if (!grown)
            return;
        n->items = grown;
        n->cap = cap;
    }
    n->items[n->count] = malloc(strlen(buf) + 1);
    if (n->items[n->count])
        strcpy(n->items[n->count++], buf);
}

static result *new_result(bench_run *B)
{
    if (B->result_count == B->result_cap) {
        int cap = B->result_cap ? 2 * B->result_cap : 128;
        result *grown = realloc(B->results, (size_t)cap * sizeof *grown);
        if (!grown)
            return NULL;
        B->results = grown;
        B->result_cap = cap;
    }
    result *r = &B->results[B->result_count++];
    memset(r, 0, sizeof *r);
    return r;
}

/* ---- small helpers --------------------------------------------------------------------------- */

static int mkdirs(const char *path)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; ++p)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    return mkdir(buf, 0777) != 0 && errno != EEXIST ? -1 : 0;
}

static int file_exists_here(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void format_duration(double ms, char *buf, size_t size)
{
    long s = (long)(ms / 1000.0 + 0.5);
    if (s >= 3600)
        snprintf(buf, size, "%ldh%02ldm", s / 3600, (s / 60) % 60);
    else if (s >= 60)
        snprintf(buf, size, "%ldm%02lds", s / 60, s % 60);
    else
        snprintf(buf, size, "%lds", s);
}

/* Replaces characters that would break a CSV field or a file name. */
static void sanitize(char *s, int for_file)
{
    for (; *s; ++s) {
        if (*s == ',' || *s == '"' || *s == '\n')
            *s = ';';
        if (for_file && !((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
                          (*s >= '0' && *s <= '9') || *s == '-' || *s == '.' || *s == '_'))
            *s = '_';
    }
}

static void progress(bench_run *B, const char *scene, const config *c)
{
    ++B->run_index;
    double elapsed = bench_now_ms() - B->t_start;
    char e[32], rem[32] = "?";
    format_duration(elapsed, e, sizeof e);
    if (B->run_index > 1) {
        /* Runs differ a lot in cost; the average so far is a rough guide, labelled as such. */
        double per = elapsed / (double)(B->run_index - 1);
        format_duration(per * (double)(B->run_total - B->run_index + 1), rem, sizeof rem);
    }
    fprintf(stderr, "accuracy: run %d of %d  %s  %s %s  elapsed %s, remaining ~%s\n",
            B->run_index, B->run_total, scene, umbra_shadow_technique_name(c->desc.technique),
            c->label, e, rem);
}

/* ---- the machine ----------------------------------------------------------------------------- */

static void read_loadavg(double out[3])
{
    out[0] = out[1] = out[2] = -1.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf %lf %lf", &out[0], &out[1], &out[2]) != 3)
            out[0] = out[1] = out[2] = -1.0;
        fclose(f);
    }
}

static void describe_machine(bench_run *B)
{
    bench_cpu_model(B->machine, sizeof B->machine);
    bench_device_description(B->ctx, B->device, sizeof B->device);
    cl_platform_id platform = NULL;
    char version[256] = "?", driver[128] = "?";
    cl_device_id dev = umbra_context_cl_device(B->ctx);
    clGetDeviceInfo(dev, CL_DEVICE_PLATFORM, sizeof platform, &platform, NULL);
    if (platform)
        clGetPlatformInfo(platform, CL_PLATFORM_VERSION, sizeof version, version, NULL);
    clGetDeviceInfo(dev, CL_DRIVER_VERSION, sizeof driver, driver, NULL);
    snprintf(B->platform, sizeof B->platform, "%s (driver %s)", version, driver);
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(B->started, sizeof B->started, "%Y-%m-%d %H:%M UTC", &tm);
    read_loadavg(B->load_start);
    snprintf(B->commit, sizeof B->commit, "unknown");
    FILE *p = popen("git -C '" UMBRA_SOURCE_DIR "' rev-parse --short HEAD 2>/dev/null", "r");
    if (p) {
        char line[64] = "";
        if (fgets(line, sizeof line, p)) {
            line[strcspn(line, "\n")] = '\0';
            if (line[0])
                snprintf(B->commit, sizeof B->commit, "%s", line);
        }
        pclose(p);
    }
    p = popen("git -C '" UMBRA_SOURCE_DIR "' status --porcelain --untracked-files=no 2>/dev/null",
              "r");
    if (p) {
        char line[256];
        int dirty = fgets(line, sizeof line, p) != NULL;
        pclose(p);
        if (dirty && strcmp(B->commit, "unknown") != 0) {
            size_t n = strlen(B->commit);
            snprintf(B->commit + n, sizeof B->commit - n, " + local changes");
        }
    }
}

static void write_machine(bench_run *B, FILE *f)
{
    double load_end[3];
    read_loadavg(load_end);
    fprintf(f, "- Started: %s; umbra commit %s\n", B->started, B->commit);
    fprintf(f, "- CPU: %s\n", B->machine);
    fprintf(f, "- OpenCL device: %s\n", B->device);
    fprintf(f, "- OpenCL platform: %s\n", B->platform);
    fprintf(f, "- Load average (1, 5, 15 min) at start %.2f %.2f %.2f, at the end %.2f %.2f %.2f\n",
            B->load_start[0], B->load_start[1], B->load_start[2], load_end[0], load_end[1],
            load_end[2]);
    fprintf(f, "- Mode: %s; %d timed run%s per setting after %d warm-up frame%s (fewer for slow "
               "settings, see the runs column)\n",
            B->o.quick ? "--quick" : "full sweep", B->o.runs, B->o.runs == 1 ? "" : "s",
            B->o.warmup, B->o.warmup == 1 ? "" : "s");
}

/* ---- rendering and measuring ----------------------------------------------------------------- */

typedef struct scene_ctx {
    umbra_scene scene;
    umbra_transfer_function light_tf;
    umbra_renderer r;
    uint32_t width, height;
    umbra_light light, light_alt;
} scene_ctx;

/* 0: measured; 1: skipped with a note; -1: failed. */
typedef enum outcome { MEASURED = 0, SKIPPED = 1, FAILED = -1 } outcome;

static outcome classify(bench_run *B, umbra_status st, const char *scene, const config *c,
                        const char *what)
{
    const char *msg = umbra_context_last_message(B->ctx);
    umbra_context_take_error(B->ctx, NULL);
    if (st == UMBRA_ERROR_UNSUPPORTED || st == UMBRA_ERROR_OUT_OF_MEMORY) {
        add_note(B, "%s: %s %s skipped (%s): %s", scene,
                 umbra_shadow_technique_name(c->desc.technique), c->label,
                 umbra_status_to_string(st), msg);
        return SKIPPED;
    }
    add_note(B, "%s: %s %s FAILED in %s (%s): %s", scene,
             umbra_shadow_technique_name(c->desc.technique), c->label, what,
             umbra_status_to_string(st), msg);
    ++B->failures;
    return FAILED;
}

typedef struct measurement {
    int runs;
    bench_timing build, render;
    umbra_render_stats stats;
} measurement;

/* Renders the error image into rgba (scene light), then the timed frames into scratch. */
static outcome measure(bench_run *B, scene_ctx *S, const char *scene, const config *c,
                       float *rgba, float *scratch, measurement *m)
{
    umbra_renderer r = S->r;
    uint32_t w = S->width, h = S->height;
    umbra_status st = umbra_renderer_set_shadow(r, &c->desc);
    if (st != UMBRA_SUCCESS)
        return classify(B, st, scene, c, "umbra_renderer_set_shadow");
    if ((st = umbra_renderer_set_light(r, &S->light)) != UMBRA_SUCCESS)
        return classify(B, st, scene, c, "umbra_renderer_set_light");
    /* The first frame: compiles what it needs, builds the structure, gives the error image. */
    if ((st = umbra_renderer_render(r, w, h, rgba)) != UMBRA_SUCCESS)
        return classify(B, st, scene, c, "umbra_renderer_render");
    umbra_render_stats first;
    umbra_renderer_get_stats(r, &first);
    memset(m, 0, sizeof *m);
    m->stats = first;
    double t0 = first.shadow_build_ms + first.render_ms;
    int runs = B->o.runs, warmup = B->o.warmup - 1;
    /* --quick is for a look, not for the record: it cuts the slow settings' runs sooner. */
    double slow = B->o.quick ? SLOW_MS / 2.0 : SLOW_MS;
    double very_slow = B->o.quick ? VERY_SLOW_MS / 2.0 : VERY_SLOW_MS;
    if (t0 > very_slow) {
        runs = 1;
        warmup = 0;
    } else if (t0 > slow) {
        runs = runs < 2 ? runs : 2;
        warmup = 0;
    }
    double build[64], render[64];
    if (runs > 64)
        runs = 64;
    int flip = 0;
    for (int i = 0; i < warmup + runs; ++i) {
        flip ^= 1;
        st = umbra_renderer_set_light(r, flip ? &S->light_alt : &S->light);
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_render(r, w, h, scratch);
        if (st != UMBRA_SUCCESS)
            return classify(B, st, scene, c, "a timed umbra_renderer_render");
        umbra_render_stats s;
        umbra_renderer_get_stats(r, &s);
        if (i >= warmup) {
            build[i - warmup] = s.shadow_build_ms;
            render[i - warmup] = s.render_ms;
            m->stats = s;
        }
    }
    /* The error image above came from the scene's own light; leave the renderer with it. */
    umbra_renderer_set_light(r, &S->light);
    if (runs == 0) {
        build[0] = first.shadow_build_ms;
        render[0] = first.render_ms;
    }
    m->runs = runs;
    m->build = bench_timing_of(build, runs ? runs : 1);
    m->render = bench_timing_of(render, runs ? runs : 1);
    return MEASURED;
}

/* The reference image and its render time: from the cache when the key matches, else rendered
 * (and cached). The key hashes the scene file and its transfer functions (scene_spec.hash), the
 * image size, the shadow-ray step and the device: change any and the reference is rendered again.
 * A change to the renderer itself is not in the key: pass --no-cache (or delete the cache
 * directory) after one. */
static outcome reference_image(bench_run *B, scene_ctx *S, int si, const config *c, float *rgba,
                               double *ms, int *cached)
{
    const scene_spec *spec = &B->scenes[si];
    uint64_t key = spec->hash;
    /* v2: the extinction model and segment quadrature of issue 10 */
    const char *tag = "umbra-bench accuracy reference v2";
    key = scene_hash_bytes(key, tag, strlen(tag));
    key = scene_hash_bytes(key, &S->width, sizeof S->width);
    key = scene_hash_bytes(key, &S->height, sizeof S->height);
    key = scene_hash_bytes(key, &c->desc.reference_step, sizeof c->desc.reference_step);
    const char *dev = umbra_context_device_name(B->ctx);
    key = scene_hash_bytes(key, dev, strlen(dev));
    char exr[4096], meta[4096];
    snprintf(exr, sizeof exr, "%s/%s-%016llx.exr", B->o.cache_dir, spec->name,
             (unsigned long long)key);
    snprintf(meta, sizeof meta, "%s/%s-%016llx.txt", B->o.cache_dir, spec->name,
             (unsigned long long)key);
    *cached = 0;
    if (B->o.cache && file_exists_here(exr) && file_exists_here(meta)) {
        FILE *f = fopen(meta, "r");
        double t = -1.0;
        if (f) {
            if (fscanf(f, "render_ms %lf", &t) != 1)
                t = -1.0;
            fclose(f);
        }
        uint32_t w = 0, h = 0;
        float *img = NULL;
        if (t > 0.0 && umbra_image_read(B->ctx, exr, &w, &h, &img) == UMBRA_SUCCESS &&
            w == S->width && h == S->height) {
            memcpy(rgba, img, (size_t)w * h * 4 * sizeof *rgba);
            free(img);
            *ms = t;
            *cached = 1;
            fprintf(stderr, "accuracy: %s: exact reference from the cache %s\n", spec->name, exr);
            return MEASURED;
        }
        free(img);
        umbra_context_take_error(B->ctx, NULL);
    }
    /* One frame: it takes seconds to minutes, and its device time is the same on every run. */
    umbra_status st = umbra_renderer_set_shadow(S->r, &c->desc);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_light(S->r, &S->light);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render(S->r, S->width, S->height, rgba);
    if (st != UMBRA_SUCCESS)
        return classify(B, st, spec->name, c, "the exact reference");
    umbra_render_stats s;
    umbra_renderer_get_stats(S->r, &s);
    *ms = s.render_ms;
    if (B->o.cache && mkdirs(B->o.cache_dir) == 0) {
        if (umbra_image_write(B->ctx, exr, S->width, S->height, rgba) == UMBRA_SUCCESS) {
            FILE *f = fopen(meta, "w");
            if (f) {
                fprintf(f, "render_ms %.6f\ndevice %s\ndate %s\nscene %s\nsize %ux%u\n"
                           "reference_step %g\n", s.render_ms, dev, B->started, spec->path,
                        S->width, S->height, c->desc.reference_step);
                fclose(f);
            }
        } else {
            add_note(B, "%s: could not cache the reference: %s", spec->name,
                     umbra_context_last_message(B->ctx));
            umbra_context_take_error(B->ctx, NULL);
        }
    }
    return MEASURED;
}

static int want_image(const options *o, const config *c)
{
    if (strcmp(o->images, "all") == 0)
        return 1;
    if (strcmp(o->images, "headline") == 0)
        return c->headline != 0;
    return 0;
}

static void save_image(bench_run *B, const char *scene, const config *c, uint32_t w, uint32_t h,
                       const float *rgba)
{
    char dir[4096], name[256], path[4600];
    snprintf(dir, sizeof dir, "%s/images/%s", B->o.out, scene);
    if (mkdirs(dir) != 0)
        return;
    if (strcmp(c->params, "-") == 0)
        snprintf(name, sizeof name, "%s", umbra_shadow_technique_name(c->desc.technique));
    else
        snprintf(name, sizeof name, "%s-%s", umbra_shadow_technique_name(c->desc.technique),
                 c->params);
    sanitize(name, 1);
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    if (umbra_image_write(B->ctx, path, w, h, rgba) != UMBRA_SUCCESS) {
        add_note(B, "%s: could not write %s: %s", scene, path, umbra_context_last_message(B->ctx));
        umbra_context_take_error(B->ctx, NULL);
    }
}

static void scene_ctx_release(scene_ctx *S)
{
    umbra_renderer_release(S->r);
    umbra_transfer_function_release(S->light_tf);
    umbra_scene_release(&S->scene);
    memset(S, 0, sizeof *S);
}

static int open_scene(bench_run *B, int si, scene_ctx *S)
{
    const scene_spec *spec = &B->scenes[si];
    memset(S, 0, sizeof *S);
    umbra_status st = scene_create(B->ctx, spec, &S->scene, &S->light_tf);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_create(B->ctx, &S->r);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_volume(S->r, S->scene.volume);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_transfer_function(S->r, S->scene.tf);
    if (st == UMBRA_SUCCESS && S->light_tf)
        st = umbra_renderer_set_light_transfer_function(S->r, S->light_tf);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_camera(S->r, &S->scene.camera);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_options(S->r, &S->scene.options);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_light(S->r, &S->scene.light);
    if (st != UMBRA_SUCCESS) {
        add_note(B, "%s: the scene cannot be set up (%s): %s", spec->name,
                 umbra_status_to_string(st), umbra_context_last_message(B->ctx));
        umbra_context_take_error(B->ctx, NULL);
        ++B->failures;
        scene_ctx_release(S);
        return -1;
    }
    S->light = S->scene.light;
    S->light_alt = S->light;
    S->light_alt.color[0] = nextafterf(S->light.color[0], 0.0f);
    if (S->light_alt.color[0] == S->light.color[0]) /* a black red channel: go up instead */
        S->light_alt.color[0] = nextafterf(S->light.color[0], 1.0f);
    S->width = spec->width ? spec->width : 512;
    S->height = spec->height ? spec->height : 512;
    if (B->o.quick) {
        uint32_t side = S->width > S->height ? S->width : S->height;
        if (side > QUICK_MAX_SIDE) {
            S->width = (uint32_t)((uint64_t)S->width * QUICK_MAX_SIDE / side);
            S->height = (uint32_t)((uint64_t)S->height * QUICK_MAX_SIDE / side);
        }
    }
    return 0;
}

static float exact_step(const scene_spec *s)
{
    return s->reference_step > 0.0f ? s->reference_step : 0.25f;
}

static int in_list(const char *list, const char *name);

/* The sweep for one scene, less the techniques --techniques leaves out (the exact reference and
 * the unshadowed frame always stay: every other row is measured against them). */
static void scene_configs(const options *o, const scene_spec *s, config_list *L)
{
    build_configs(o->quick, s->papers, o->max_map, exact_step(s), L);
    if (!o->techniques[0])
        return;
    int n = 0;
    for (int i = 0; i < L->count; ++i) {
        const config *c = &L->items[i];
        if (c->exact || c->desc.technique == UMBRA_SHADOW_NONE ||
            in_list(o->techniques, umbra_shadow_technique_name(c->desc.technique)))
            L->items[n++] = *c;
    }
    L->count = n;
}

static void run_scene(bench_run *B, int si)
{
    const scene_spec *spec = &B->scenes[si];
    config_list L;
    scene_configs(&B->o, spec, &L);
    scene_ctx S;
    if (open_scene(B, si, &S) != 0) {
        B->run_index += L.count;
        return;
    }
    size_t px = (size_t)S.width * S.height;
    float *ref = malloc(px * 4 * sizeof *ref), *img = malloc(px * 4 * sizeof *img);
    float *scratch = malloc(px * 4 * sizeof *scratch);
    if (!ref || !img || !scratch) {
        add_note(B, "%s: out of host memory for %ux%u images", spec->name, S.width, S.height);
        ++B->failures;
        goto done;
    }
    fprintf(stderr, "accuracy: scene %s (%s), %ux%u\n", spec->name, spec->description, S.width,
            S.height);

    /* The exact reference: the yardstick, and the denominator of every speed-up. */
    double ref_ms = 0.0;
    int cached = 0;
    progress(B, spec->name, &L.items[0]);
    if (reference_image(B, &S, si, &L.items[0], ref, &ref_ms, &cached) != MEASURED) {
        add_note(B, "%s: no exact reference, so no errors: scene skipped", spec->name);
        B->run_index += L.count - 1;
        goto done;
    }
    if (want_image(&B->o, &L.items[0]))
        save_image(B, spec->name, &L.items[0], S.width, S.height, ref);
    int first_row = B->result_count;
    result *exact = new_result(B);
    if (!exact)
        goto done;
    exact->scene = si;
    exact->cfg = L.items[0];
    exact->runs = cached ? -1 : 0;
    exact->render_ms = exact->total_ms = exact->render_min = exact->render_max = ref_ms;
    exact->reference_ms = ref_ms;
    exact->reference_cached = cached;
    exact->ref_unc.rmse = -1.0;
    exact->channels = 0;
    exact->width = S.width;
    exact->height = S.height;
    metrics_compare(ref, ref, S.width, S.height, &exact->err);

    /* The reference's uncertainty: the same reference at half its step (cached alike). */
    metrics_error unc = {-1.0, 0.0, 0.0, 0.0, 0.0};
    {
        config half = L.items[0];
        half.desc.reference_step *= 0.5f;
        double half_ms = 0.0;
        int half_cached = 0;
        if (reference_image(B, &S, si, &half, scratch, &half_ms, &half_cached) == MEASURED &&
            metrics_compare(scratch, ref, S.width, S.height, &unc) == 0)
            fprintf(stderr, "accuracy: %s: reference at step %g vs %g: RMSE %.5f, max %.4f\n",
                    spec->name, L.items[0].desc.reference_step, half.desc.reference_step,
                    unc.rmse, unc.max_abs);
        else
            unc.rmse = -1.0;
    }

    double none_ms = 0.0;
    for (int i = 1; i < L.count; ++i) {
        const config *c = &L.items[i];
        progress(B, spec->name, c);
        measurement m;
        if (measure(B, &S, spec->name, c, img, scratch, &m) != MEASURED)
            continue;
        result *row = new_result(B);
        if (!row)
            break;
        row->scene = si;
        row->cfg = *c;
        row->runs = m.runs;
        row->build_ms = m.build.median;
        row->build_min = m.build.min;
        row->build_max = m.build.max;
        row->render_ms = m.render.median;
        row->render_min = m.render.min;
        row->render_max = m.render.max;
        row->total_ms = row->build_ms + row->render_ms;
        row->memory = m.stats.shadow_memory_bytes;
        row->channels = m.stats.light_channels;
        row->slices = m.stats.slices;
        row->samples = m.stats.samples;
        row->map_size = m.stats.map_size;
        if (c->desc.map_size == UMBRA_MAP_SIZE_AUTO && row->map_size) /* "auto size (192²)" */
            snprintf(row->cfg.label + strlen(row->cfg.label),
                     sizeof row->cfg.label - strlen(row->cfg.label), " (%u²)", row->map_size);
        row->width = S.width;
        row->height = S.height;
        row->reference_ms = ref_ms;
        row->reference_cached = cached;
        if (metrics_compare(img, ref, S.width, S.height, &row->err) != 0) {
            add_note(B, "%s: out of host memory while comparing images", spec->name);
            ++B->failures;
        }
        if (c->desc.technique == UMBRA_SHADOW_NONE)
            none_ms = row->render_ms;
        if (want_image(&B->o, c))
            save_image(B, spec->name, c, S.width, S.height, img);
    }
    /* B->results may have moved: fill the per-scene columns now. */
    for (int k = first_row; k < B->result_count; ++k) {
        B->results[k].none_ms = none_ms;
        B->results[k].ref_unc = unc;
        /* The exact reference simulates as many channels as the coarser ones measured. */
        if (B->results[k].cfg.desc.technique == UMBRA_SHADOW_REFERENCE)
            B->results[first_row].channels = B->results[k].channels;
    }
    if (none_ms <= 0.0)
        add_note(B, "%s: no unshadowed frame, so no overhead ratios", spec->name);
done:
    free(ref);
    free(img);
    free(scratch);
    scene_ctx_release(&S);
}

/* ---- Pareto fronts --------------------------------------------------------------------------- */

typedef struct front_point {
    double cost, rmse;
    int row;
} front_point;

static int cmp_front(const void *a, const void *b)
{
    const front_point *x = a, *y = b;
    if (x->cost != y->cost)
        return (x->cost > y->cost) - (x->cost < y->cost);
    return (x->rmse > y->rmse) - (x->rmse < y->rmse);
}

/* Marks, per scene, the runs no other run beats in both cost and error (strictly in one). The
 * exact reference (error 0 by definition) and, for memory, runs that hold no memory are left out:
 * the plots are logarithmic. Writes the fronts, sorted by cost, to <out>/plots/<scene>-pareto-
 * {time,memory}.dat for gnuplot. */
static void pareto(bench_run *B)
{
    front_point *pts = malloc((size_t)(B->result_count + 1) * sizeof *pts);
    if (!pts)
        return;
    for (int si = 0; si < B->scene_count; ++si)
        for (int mem = 0; mem < 2; ++mem) {
            int n = 0;
            for (int k = 0; k < B->result_count; ++k) {
                const result *r = &B->results[k];
                if (r->scene == si && !r->cfg.exact && r->err.rmse > 0.0 &&
                    (!mem || r->memory > 0)) {
                    pts[n].cost = mem ? (double)r->memory : r->total_ms;
                    pts[n].rmse = r->err.rmse;
                    pts[n].row = k;
                    ++n;
                }
            }
            if (n == 0)
                continue;
            qsort(pts, (size_t)n, sizeof *pts, cmp_front);
            char path[4200];
            snprintf(path, sizeof path, "%s/plots/%s-pareto-%s.dat", B->o.out,
                     B->scenes[si].name, mem ? "memory" : "time");
            FILE *f = fopen(path, "w");
            if (f)
                fprintf(f, "# %s,rmse,technique and setting\n", mem ? "memory_mib" : "total_ms");
            double best = INFINITY;
            for (int j = 0; j < n; ++j) {
                result *r = &B->results[pts[j].row];
                if (r->err.rmse < best) {
                    best = r->err.rmse;
                    if (mem)
                        r->pareto_memory = 1;
                    else
                        r->pareto_time = 1;
                    char label[160];
                    snprintf(label, sizeof label, "%s %s",
                             umbra_shadow_technique_name(r->cfg.desc.technique), r->cfg.label);
                    sanitize(label, 0);
                    if (f)
                        fprintf(f, "%.6g,%.6g,%s\n",
                                mem ? (double)r->memory / 1048576.0 : r->total_ms, r->err.rmse,
                                label);
                }
            }
            if (f)
                fclose(f);
        }
    free(pts);
}

/* ---- output: CSV ----------------------------------------------------------------------------- */

/* Columns of accuracy.csv, in order; plot_accuracy.gp gets the indices it needs from here. */
static const char *const csv_columns[] = {
    "scene", "technique", "label", "params", "width", "height", "runs", "build_ms", "render_ms",
    "total_ms", "build_ms_min", "build_ms_max", "render_ms_min", "render_ms_max", "none_render_ms",
    "render_overhead", "build_over_frame", "reference_ms", "speedup_vs_reference", "memory_bytes",
    "light_channels", "slices", "samples", "rmse", "psnr_db", "max_abs", "mean_abs", "ssim",
    "pareto_time", "pareto_memory", "reference_half_step_rmse", "reference_half_step_max_abs",
    "map_size",
};

static int csv_column(const char *name)
{
    for (size_t i = 0; i < sizeof csv_columns / sizeof csv_columns[0]; ++i)
        if (strcmp(csv_columns[i], name) == 0)
            return (int)i + 1;
    return 0;
}

static void write_csv(bench_run *B)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/accuracy.csv", B->o.out);
    FILE *f = fopen(path, "w");
    if (!f) {
        add_note(B, "cannot write %s: %s", path, strerror(errno));
        ++B->failures;
        return;
    }
    for (size_t i = 0; i < sizeof csv_columns / sizeof csv_columns[0]; ++i)
        fprintf(f, "%s%s", i ? "," : "", csv_columns[i]);
    fputc('\n', f);
    for (int k = 0; k < B->result_count; ++k) {
        const result *r = &B->results[k];
        char label[128], params[192];
        snprintf(label, sizeof label, "%s", r->cfg.label);
        snprintf(params, sizeof params, "%s", r->cfg.params);
        sanitize(label, 0);
        sanitize(params, 0);
        double total = r->total_ms;
        fprintf(f, "%s,%s,%s,%s,%u,%u,%d,", B->scenes[r->scene].name,
                umbra_shadow_technique_name(r->cfg.desc.technique), label, params, r->width,
                r->height, r->runs);
        fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,", r->build_ms, r->render_ms, total,
                r->build_min, r->build_max, r->render_min, r->render_max, r->none_ms);
        if (r->none_ms > 0.0)
            fprintf(f, "%.4f,%.4f,", r->render_ms / r->none_ms, r->build_ms / r->none_ms);
        else
            fprintf(f, ",,");
        fprintf(f, "%.4f,%.4f,%zu,%u,%u,%llu,", r->reference_ms,
                total > 0.0 ? r->reference_ms / total : 0.0, r->memory, r->channels, r->slices,
                (unsigned long long)r->samples);
        fprintf(f, "%.6g,", r->err.rmse);
        if (isinf(r->err.psnr_db))
            fprintf(f, "inf,");
        else
            fprintf(f, "%.3f,", r->err.psnr_db);
        fprintf(f, "%.6g,%.6g,%.6f,%d,%d,", r->err.max_abs, r->err.mean_abs, r->err.ssim,
                r->pareto_time, r->pareto_memory);
        if (r->ref_unc.rmse >= 0.0)
            fprintf(f, "%.6g,%.6g,", r->ref_unc.rmse, r->ref_unc.max_abs);
        else
            fprintf(f, ",,");
        fprintf(f, "%u\n", r->map_size);
    }
    fclose(f);
}

/* ---- output: plots --------------------------------------------------------------------------- */

static const umbra_shadow_technique plot_order[] = {
    UMBRA_SHADOW_NONE, UMBRA_SHADOW_REFERENCE, UMBRA_SHADOW_THRESHOLD,
    UMBRA_SHADOW_CSSM, UMBRA_SHADOW_DEEP, UMBRA_SHADOW_CONVOLUTION,
};

/* gnuplot single-quoted string: a quote is doubled. */
static void gp_string(FILE *f, const char *name, const char *value)
{
    fprintf(f, "%s = '", name);
    for (const char *p = value; *p; ++p) {
        if (*p == '\'')
            fputc('\'', f);
        fputc(*p, f);
    }
    fprintf(f, "'\n");
}

static void write_plots(bench_run *B)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/bench/plot_accuracy.gp", UMBRA_SOURCE_DIR);
    if (!file_exists_here(script)) {
        add_note(B, "plots skipped: %s not found", script);
        return;
    }
    for (int si = 0; si < B->scene_count; ++si) {
        /* Techniques present in this scene, with a fixed style index each across all plots;
         * for the memory plot only those that hold memory (the axis is logarithmic). */
        char techs[256] = "", styles[64] = "", techs_mem[256] = "", styles_mem[64] = "";
        int any = 0, any_mem = 0;
        for (size_t t = 0; t < sizeof plot_order / sizeof plot_order[0]; ++t) {
            int has = 0, has_mem = 0;
            for (int k = 0; k < B->result_count; ++k) {
                const result *r = &B->results[k];
                if (r->scene == si && r->cfg.desc.technique == plot_order[t] && !r->cfg.exact &&
                    r->err.rmse > 0.0) {
                    has = 1;
                    has_mem |= r->memory > 0;
                }
            }
            const char *name = umbra_shadow_technique_name(plot_order[t]);
            if (has) {
                size_t n = strlen(techs), m = strlen(styles);
                snprintf(techs + n, sizeof techs - n, "%s%s", any ? " " : "", name);
                snprintf(styles + m, sizeof styles - m, "%s%zu", any ? " " : "", t + 1);
                any = 1;
            }
            if (has_mem) {
                size_t n = strlen(techs_mem), m = strlen(styles_mem);
                snprintf(techs_mem + n, sizeof techs_mem - n, "%s%s", any_mem ? " " : "", name);
                snprintf(styles_mem + m, sizeof styles_mem - m, "%s%zu", any_mem ? " " : "", t + 1);
                any_mem = 1;
            }
        }
        if (!any)
            continue;
        const scene_spec *spec = &B->scenes[si];
        char buf[4200];
        FILE *gp = popen("gnuplot 2>&1", "w");
        if (!gp) {
            add_note(B, "plots skipped: cannot run gnuplot");
            return;
        }
        snprintf(buf, sizeof buf, "%s/accuracy.csv", B->o.out);
        gp_string(gp, "csv", buf);
        gp_string(gp, "scene", spec->name);
        gp_string(gp, "scene_title", spec->description[0] ? spec->description : spec->name);
        gp_string(gp, "techniques", techs);
        gp_string(gp, "styles", styles);
        gp_string(gp, "techniques_memory", techs_mem);
        gp_string(gp, "styles_memory", styles_mem);
        snprintf(buf, sizeof buf, "%s/plots/%s-pareto-time.dat", B->o.out, spec->name);
        gp_string(gp, "pareto_time", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-pareto-memory.dat", B->o.out, spec->name);
        gp_string(gp, "pareto_memory", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-error-vs-time.png", B->o.out, spec->name);
        gp_string(gp, "out_time", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-error-vs-memory.png", B->o.out, spec->name);
        gp_string(gp, "out_memory", any_mem ? buf : "");
        fprintf(gp, "c_scene = %d\nc_tech = %d\nc_total = %d\nc_rmse = %d\nc_mem = %d\n"
                    "c_exact_ref = %d\nc_width = %d\nc_height = %d\n",
                csv_column("scene"), csv_column("technique"), csv_column("total_ms"),
                csv_column("rmse"), csv_column("memory_bytes"), csv_column("reference_ms"),
                csv_column("width"), csv_column("height"));
        gp_string(gp, "script", script);
        fprintf(gp, "load script\n");
        int rc = pclose(gp);
        if (rc != 0) {
            add_note(B, "plots for %s: gnuplot exited with status %d (is gnuplot installed? "
                        "Debian: apt-get install gnuplot-nox)", spec->name, rc);
            return;
        }
    }
}

/* ---- output: Markdown ------------------------------------------------------------------------ */

static const result *find_headline(const bench_run *B, int si, int h)
{
    for (int k = 0; k < B->result_count; ++k)
        if (B->results[k].scene == si && B->results[k].cfg.headline == h)
            return &B->results[k];
    return NULL;
}

static int main_scene(const bench_run *B)
{
    int first = -1;
    for (int si = 0; si < B->scene_count; ++si) {
        int has = 0;
        for (int k = 0; k < B->result_count && !has; ++k)
            has = B->results[k].scene == si;
        if (!has)
            continue;
        if (strcmp(B->scenes[si].name, B->o.main_scene) == 0)
            return si;
        if (first < 0)
            first = si;
    }
    return first;
}

static void fmt_ratio(double x, char *buf, size_t size)
{
    if (!(x > 0.0) || !isfinite(x))
        snprintf(buf, size, "–");
    else if (x >= 100.0)
        snprintf(buf, size, "%.0f×", x);
    else if (x >= 10.0)
        snprintf(buf, size, "%.1f×", x);
    else
        snprintf(buf, size, "%.2f×", x);
}

/* The headline table for one scene (si >= 0), or geometric means over all scenes (si < 0). */
static void headline_table(const bench_run *B, FILE *f, int si)
{
    fprintf(f, "| technique | render overhead over unshadowed | map build / unshadowed frame | "
               "RMSE | reference's own RMSE | SSIM | memory | speed-up over exact reference |%s\n"
               "|---|---|---|---|---|---|---|---|%s\n", si < 0 ? " scenes |" : "",
            si < 0 ? "---|" : "");
    for (int h = H_NONE; h < H_COUNT; ++h) {
        double lo = 0, lb = 0, rm = 0, ss = 0, lmem = 0, lsp = 0, ru = 0;
        int n = 0, nb = 0, nmem = 0, nu = 0;
        const result *any = NULL;
        for (int s = 0; s < B->scene_count; ++s) {
            if (si >= 0 && s != si)
                continue;
            const result *r = find_headline(B, s, h);
            if (!r || !(r->none_ms > 0.0))
                continue;
            lo += log(r->render_ms / r->none_ms);
            if (r->build_ms > 0.0) {
                lb += log(r->build_ms / r->none_ms);
                ++nb;
            }
            rm += r->err.rmse;
            if (r->ref_unc.rmse >= 0.0) {
                ru += r->ref_unc.rmse;
                ++nu;
            }
            ss += r->err.ssim;
            if (r->memory > 0) {
                lmem += log((double)r->memory);
                ++nmem;
            }
            lsp += log(r->reference_ms / r->total_ms);
            any = r;
            ++n;
        }
        if (n == 0)
            continue;
        char o[32], b[32], m[32], sp[32];
        fmt_ratio(exp(lo / n), o, sizeof o);
        if (nb)
            fmt_ratio(exp(lb / nb), b, sizeof b);
        else
            snprintf(b, sizeof b, "–");
        if (nmem)
            bench_format_bytes((size_t)exp(lmem / nmem), m, sizeof m);
        else
            snprintf(m, sizeof m, "0");
        fmt_ratio(exp(lsp / n), sp, sizeof sp);
        char name[160];
        if (h == H_NONE)
            snprintf(name, sizeof name, "none (unshadowed)");
        else
            snprintf(name, sizeof name, "%s, %s",
                     umbra_shadow_technique_name(any->cfg.desc.technique), any->cfg.label);
        char u[32] = "–";
        if (nu)
            snprintf(u, sizeof u, "%.1e", ru / nu);
        fprintf(f, "| %s | %s | %s | %.4f | %s | %.4f | %s | %s |", name, o, b, rm / n, u, ss / n, m,
                sp);
        if (si < 0)
            fprintf(f, " %d |", n);
        fprintf(f, "\n");
    }
}

static void write_headline(bench_run *B)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/headline.md", B->o.out);
    FILE *f = fopen(path, "w");
    if (!f)
        return;
    int ms = main_scene(B);
    int nscenes = 0;
    char names[1024] = "";
    for (int si = 0; si < B->scene_count; ++si) {
        int has = 0;
        for (int k = 0; k < B->result_count && !has; ++k)
            has = B->results[k].scene == si;
        if (!has)
            continue;
        size_t n = strlen(names);
        snprintf(names + n, sizeof names - n, "%s%s", nscenes ? ", " : "", B->scenes[si].name);
        ++nscenes;
    }
    fprintf(f, "<!-- generated by `umbra-bench accuracy%s` from accuracy.csv; do not edit -->\n",
            B->o.quick ? " --quick" : "");
    if (ms >= 0) {
        const result *none = find_headline(B, ms, H_NONE);
        char t[32] = "?";
        if (none)
            bench_format_ms(none->render_ms, t, sizeof t);
        fprintf(f, "**%s** (%ux%u, unshadowed frame %s ms):\n\n", B->scenes[ms].name,
                none ? none->width : 0, none ? none->height : 0, t);
        headline_table(B, f, ms);
    }
    fprintf(f, "\n**All %d scenes** (%s): ratios, memory and speed-ups are geometric means, RMSE "
               "and SSIM arithmetic means over the scenes where the setting ran:\n\n",
            nscenes, names);
    headline_table(B, f, -1);
    fprintf(f, "\nRender overhead: render time with shadows over the unshadowed render of the same "
               "view; build: the shadow structure's construction over one unshadowed frame (paid "
               "when the light or the transfer function changes); RMSE and SSIM against the "
               "exact reference (display values, `bench/metrics.h`); the reference's own RMSE: "
               "the exact reference at its step against the exact reference at half that step, "
               "the yardstick's uncertainty (an RMSE near it is not a measured error); speed-up: "
               "the exact "
               "reference's render time over build + render. Device: %s. %s.\n",
            B->device, B->started);
    fclose(f);
}

static void write_summary(bench_run *B)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/summary.md", B->o.out);
    FILE *f = fopen(path, "w");
    if (!f) {
        add_note(B, "cannot write %s: %s", path, strerror(errno));
        ++B->failures;
        return;
    }
    fprintf(f, "# umbra-bench accuracy%s\n\nWhat accuracy costs in time: every shadow technique "
               "against the exact reference, per scene. Generated by `umbra-bench accuracy%s`; "
               "the raw numbers are in `accuracy.csv`, the method in `bench/README.md`.\n\n",
            B->o.quick ? " --quick" : "", B->o.quick ? " --quick" : "");
    write_machine(B, f);
    fprintf(f, "\n## Headline\n\n");
    FILE *h = NULL;
    snprintf(path, sizeof path, "%s/headline.md", B->o.out);
    h = fopen(path, "r");
    if (h) {
        char line[2048];
        while (fgets(line, sizeof line, h))
            if (strncmp(line, "<!--", 4) != 0)
                fputs(line, f);
        fclose(h);
    }
    for (int si = 0; si < B->scene_count; ++si) {
        const scene_spec *spec = &B->scenes[si];
        int rows = 0;
        for (int k = 0; k < B->result_count; ++k)
            rows += B->results[k].scene == si;
        fprintf(f, "\n## %s\n\n%s. Scene file `bench/scenes/%s.scene`.\n\n", spec->name,
                spec->description[0] ? spec->description : spec->name, spec->name);
        if (!B->present[si]) {
            fprintf(f, "Skipped: volume `%s` is not present.\n", spec->volume);
            continue;
        }
        if (rows == 0) {
            fprintf(f, "No results (see the notes).\n");
            continue;
        }
        fprintf(f, "![error vs time](plots/%s-error-vs-time.png) "
                   "![error vs memory](plots/%s-error-vs-memory.png)\n\n", spec->name,
                spec->name);
        for (int k = 0; k < B->result_count; ++k)
            if (B->results[k].scene == si) {
                const result *r = &B->results[k];
                if (r->ref_unc.rmse >= 0.0)
                    fprintf(f, "The reference's own uncertainty (its step %g against half of it): "
                               "RMSE %.1e, max %.1e; column \"ref ±\" below.\n\n",
                            r->cfg.desc.technique == UMBRA_SHADOW_REFERENCE
                                ? r->cfg.desc.reference_step
                                : exact_step(spec),
                            r->ref_unc.rmse, r->ref_unc.max_abs);
                else
                    fprintf(f, "The reference's own uncertainty could not be measured.\n\n");
                break;
            }
        fprintf(f, "| technique | setting | build ms | render ms | overhead | build/frame | "
                   "memory | ch | RMSE | ref ± | PSNR dB | max | SSIM | speed-up | runs | front |\n"
                   "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int k = 0; k < B->result_count; ++k) {
            const result *r = &B->results[k];
            if (r->scene != si)
                continue;
            char b[32], rd[32], ov[32], bf[32], mem[32], sp[32], psnr[32], runs[32];
            bench_format_ms(r->build_ms, b, sizeof b);
            bench_format_ms(r->render_ms, rd, sizeof rd);
            fmt_ratio(r->none_ms > 0 ? r->render_ms / r->none_ms : 0, ov, sizeof ov);
            fmt_ratio(r->none_ms > 0 ? r->build_ms / r->none_ms : 0, bf, sizeof bf);
            bench_format_bytes(r->memory, mem, sizeof mem);
            fmt_ratio(r->reference_ms / r->total_ms, sp, sizeof sp);
            if (isinf(r->err.psnr_db))
                snprintf(psnr, sizeof psnr, "∞");
            else
                snprintf(psnr, sizeof psnr, "%.1f", r->err.psnr_db);
            if (r->runs < 0)
                snprintf(runs, sizeof runs, "cached");
            else
                snprintf(runs, sizeof runs, "%d", r->runs ? r->runs : 1);
            char unc_s[32] = "–";
            if (r->ref_unc.rmse >= 0.0)
                snprintf(unc_s, sizeof unc_s, "%.1e", r->ref_unc.rmse);
            fprintf(f, "| %s | %s | %s | %s | %s | %s | %s | %u | %.4f | %s | %s | %.3f | %.4f | "
                       "%s | %s | %s |\n",
                    umbra_shadow_technique_name(r->cfg.desc.technique), r->cfg.label, b, rd, ov,
                    bf, mem, r->channels, r->err.rmse, unc_s, psnr, r->err.max_abs, r->err.ssim,
                    sp, runs,
                    r->pareto_time ? (r->pareto_memory ? "time, memory" : "time")
                                   : (r->pareto_memory ? "memory" : ""));
        }
    }
    fprintf(f, "\n## Notes\n\n");
    if (B->notes.count == 0)
        fprintf(f, "None: every setting ran.\n");
    for (int i = 0; i < B->notes.count; ++i)
        fprintf(f, "- %s\n", B->notes.items[i]);
    fclose(f);
}

/* ---- output: the papers' tables -------------------------------------------------------------- */

static const result *find_run(const bench_run *B, int si, umbra_shadow_technique t,
                              uint32_t map, uint32_t taps, float eps, uint32_t nodes,
                              uint32_t prefilter)
{
    for (int k = 0; k < B->result_count; ++k) {
        const result *r = &B->results[k];
        const umbra_shadow_desc *d = &r->cfg.desc;
        if (r->scene != si || d->technique != t || d->map_size != map)
            continue;
        if (t == UMBRA_SHADOW_THRESHOLD && (d->taps != taps || d->threshold != 0.5f))
            continue;
        if (t == UMBRA_SHADOW_CSSM && d->taps != taps)
            continue;
        if (t == UMBRA_SHADOW_DEEP &&
            (d->epsilon != eps || d->max_nodes != nodes || d->prefilter != prefilter))
            continue;
        return r;
    }
    return NULL;
}

static int scene_index(const bench_run *B, const char *name)
{
    for (int si = 0; si < B->scene_count; ++si)
        if (strcmp(B->scenes[si].name, name) == 0)
            return si;
    return -1;
}

/* Mean over the scenes (only scene `only` if >= 0) that have all three techniques at all three
 * sizes: build times, or render times with render set. */
static int cssm_tables_mean(const bench_run *B, int only, int render, double out[3][3],
                            int *nscenes)
{
    static const uint32_t maps[3] = {1024, 2048, 4096};
    memset(out, 0, 9 * sizeof(double));
    int n = 0;
    for (int si = 0; si < B->scene_count; ++si) {
        double v[3][3];
        int ok = only < 0 || si == only;
        for (int m = 0; m < 3 && ok; ++m) {
            const result *rr[3] = {
                find_run(B, si, UMBRA_SHADOW_THRESHOLD, maps[m], 1, 0, 0, 0),
                find_run(B, si, UMBRA_SHADOW_DEEP, maps[m], 0, 0.02f, 3, 1),
                find_run(B, si, UMBRA_SHADOW_CSSM, maps[m], 13, 0, 0, 0),
            };
            for (int t = 0; t < 3; ++t) {
                if (!rr[t]) {
                    ok = 0;
                    break;
                }
                v[m][t] = render ? rr[t]->render_ms : rr[t]->build_ms;
            }
        }
        if (!ok)
            continue;
        for (int m = 0; m < 3; ++m)
            for (int t = 0; t < 3; ++t)
                out[m][t] += v[m][t];
        ++n;
    }
    for (int m = 0; m < 3 && n; ++m)
        for (int t = 0; t < 3; ++t)
            out[m][t] /= n;
    *nscenes = n;
    return n > 0;
}

static void cssm_table(FILE *f, const char *title, const double paper[3][3], double ours[3][3],
                       const char *whose)
{
    static const char *const tech[3] = {"threshold map", "deep map (3 nodes)", "CSSM (13 taps)"};
    static const char *const sizes[3] = {"1024²", "2048²", "4096²"};
    fprintf(f, "%s — %s\n\n| map | technique | paper ms | ours ms | paper: ÷ threshold | ours: "
               "÷ threshold | paper: ÷ 1024² | ours: ÷ 1024² |\n"
               "|---|---|---|---|---|---|---|---|\n", title, whose);
    for (int m = 0; m < 3; ++m)
        for (int t = 0; t < 3; ++t) {
            char o[32], pr[32], orr[32], ps[32], os[32];
            bench_format_ms(ours[m][t], o, sizeof o);
            fmt_ratio(paper[m][t] / paper[m][0], pr, sizeof pr);
            fmt_ratio(ours[m][0] > 0 ? ours[m][t] / ours[m][0] : 0, orr, sizeof orr);
            fmt_ratio(paper[m][t] / paper[0][t], ps, sizeof ps);
            fmt_ratio(ours[0][t] > 0 ? ours[m][t] / ours[0][t] : 0, os, sizeof os);
            fprintf(f, "| %s | %s | %.1f | %s | %s | %s | %s | %s |\n", sizes[m], tech[t],
                    paper[m][t], o, pr, orr, ps, os);
        }
    fprintf(f, "\n");
}

static void write_papers(bench_run *B)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/papers.md", B->o.out);
    FILE *f = fopen(path, "w");
    if (!f)
        return;
    fprintf(f, "# The seed papers' timing tables, re-measured\n\n"
               "Generated by `umbra-bench accuracy%s` from the same runs as `accuracy.csv`. The "
               "papers timed GPUs of their day; umbra here runs on a CPU through PoCL, so absolute "
               "times do not compare. What does compare is the shape: each technique's cost "
               "relative to another measured on the same machine, and how cost grows with the map "
               "size. Those ratios stand next to the papers'.\n\n", B->o.quick ? " --quick" : "");
    write_machine(B, f);

    /* CSSM paper (Weidner & Linsen), Tables 3 and 4: ms, rows 1024/2048/4096, columns threshold
     * shadow map, deep shadow map (3 nodes per channel), CSSM (13 offsets). */
    static const double paper_gen[3][3] = {{1.0, 1.1, 1.2}, {2.9, 3.3, 3.6}, {8.5, 10.5, 11.1}};
    static const double paper_ren[3][3] = {{3.2, 3.3, 4.9}, {3.2, 3.1, 4.7}, {3.3, 3.4, 4.9}};
    fprintf(f, "\n## CSSM paper, Tables 3 and 4 (Weidner & Linsen)\n\n"
               "Generation (shadow-map build) and rendering times at 1024², 2048² and 4096² for "
               "the opacity-threshold map (opacity 0.5), the deep shadow map with 3 nodes per "
               "colour channel and CSSM with 13 taps. The paper's numbers are averages over "
               "several data sets on its GPU; ours are medians on the scenes marked `papers "
               "cssm` (the walnut: the paper's Figure 3 data set), averaged if several. "
               "Ratios: each technique over the threshold map at the same size, and each size "
               "over 1024² for the same technique.\n\n");
    int n = 0;
    double ours[3][3];
    if (cssm_tables_mean(B, -1, 0, ours, &n)) {
        char names[256] = "";
        /* Room for the longest names plus the prefix: a possible truncation is a -Werror at -O0
         * (the Debug build), where GCC cannot see the names are short. */
        char whose[sizeof names + 32];
        for (int si = 0, k = 0; si < B->scene_count; ++si) {
            double dummy[3][3];
            int one = 0;
            if (cssm_tables_mean(B, si, 0, dummy, &one)) {
                size_t len = strlen(names);
                snprintf(names + len, sizeof names - len, "%s%s", k++ ? ", " : "",
                         B->scenes[si].name);
            }
        }
        if (n == 1)
            snprintf(whose, sizeof whose, "ours: %s", names);
        else
            snprintf(whose, sizeof whose, "ours: mean over %s", names);
        cssm_table(f, "**Table 3, generation**", paper_gen, ours, whose);
        cssm_tables_mean(B, -1, 1, ours, &n);
        cssm_table(f, "**Table 4, rendering**", paper_ren, ours, whose);
        int w = scene_index(B, "walnut"), nw = 0;
        if (n > 1 && w >= 0 && cssm_tables_mean(B, w, 0, ours, &nw)) {
            cssm_table(f, "**Table 3, generation**", paper_gen, ours, "ours: walnut");
            cssm_tables_mean(B, w, 1, ours, &nw);
            cssm_table(f, "**Table 4, rendering**", paper_ren, ours, "ours: walnut");
        }
    } else {
        fprintf(f, "Not measured in this run: it needs threshold, deep (3 nodes) and CSSM at "
                   "1024², 2048² and 4096² (the full sweep on a scene marked `papers cssm`; "
                   "`--quick` and `--max-map` below 4096 leave them out).\n\n");
    }

    /* Deep-map paper (Hadwiger et al.), Table 1: construction speed in fps for 128^2..512^2 maps
     * at epsilon 0.02 and 0.06, 5-tap pre-filter, CT hand 256x128x256, ATI X1800. */
    static const char *const paper_fps[3][2] = {{"2–3", "5–6"}, {"1–2", "2–3"},
                                                {"0.3–0.5", "1–1.5"}};
    static const double paper_mid[3][2] = {{2.5, 5.5}, {1.5, 2.5}, {0.4, 1.25}};
    fprintf(f, "\n## Deep-shadow-map paper, Table 1 (Hadwiger et al.)\n\n"
               "Construction speed of the deep shadow map (frames per second of map building "
               "alone) at 128², 256² and 512² with error bounds ε = 0.02 and 0.06 and a 5-tap "
               "pre-filter. The paper's hand CT (256×128×256) is not available; the foot CT "
               "(256³) stands in for it where present, else the first scene measured. The "
               "paper's fps include its multi-pass rendering and copies into a 3D texture, "
               "which a single OpenCL kernel does not need; compare the ratios: ε = 0.06 over "
               "ε = 0.02 (the paper: larger ε builds faster because fewer nodes are written) and "
               "each size over 128².\n\n");
    int fs = scene_index(B, "foot");
    if (fs < 0 || !find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5))
        for (int si = 0; si < B->scene_count; ++si)
            if (find_run(B, si, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5)) {
                fs = si;
                break;
            }
    if (fs >= 0 && find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5)) {
        static const uint32_t sizes[3] = {128, 256, 512};
        fprintf(f, "Scene: %s.\n\n| map | ε | paper fps | ours ms | ours fps | memory | paper: "
                   "fps(0.06) ÷ fps(0.02) | ours | paper: time ÷ 128² | ours |\n"
                   "|---|---|---|---|---|---|---|---|---|---|\n", B->scenes[fs].name);
        const result *base[2] = {find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5),
                                 find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.06f, 0, 5)};
        for (int s = 0; s < 3; ++s) {
            const result *r[2] = {find_run(B, fs, UMBRA_SHADOW_DEEP, sizes[s], 0, 0.02f, 0, 5),
                                  find_run(B, fs, UMBRA_SHADOW_DEEP, sizes[s], 0, 0.06f, 0, 5)};
            for (int e = 0; e < 2; ++e) {
                if (!r[e])
                    continue;
                char ms[32], mem[32], pe[32] = "", oe[32] = "", ps[32], os[32];
                bench_format_ms(r[e]->build_ms, ms, sizeof ms);
                bench_format_bytes(r[e]->memory, mem, sizeof mem);
                if (e == 1 && r[0]) {
                    fmt_ratio(paper_mid[s][1] / paper_mid[s][0], pe, sizeof pe);
                    fmt_ratio(r[0]->build_ms / r[1]->build_ms, oe, sizeof oe);
                }
                fmt_ratio(paper_mid[0][e] / paper_mid[s][e], ps, sizeof ps);
                fmt_ratio(base[e] ? r[e]->build_ms / base[e]->build_ms : 0, os, sizeof os);
                fprintf(f, "| %u² | %.2f | %s | %s | %.1f | %s | %s | %s | %s | %s |\n", sizes[s],
                        e ? 0.06 : 0.02, paper_fps[s][e], ms, 1000.0 / r[e]->build_ms, mem, pe,
                        oe, ps, os);
            }
        }
        fprintf(f, "\nPaper ratios use the midpoints of its fps ranges.\n");
    } else {
        fprintf(f, "Not measured in this run (the full sweep measures it; `--quick` does not).\n");
    }

    fprintf(f, "\n## Convolution-shadow paper, Table 1\n\n"
               "Re-measured by `umbra-bench convolution` (slice distance 0.2–0.8 voxel × 0–3 "
               "sub-samples, time per frame and mean absolute pixel difference): see "
               "`bench/results/convolution.md`. This sweep's convolution rows (`accuracy.csv`, "
               "technique `convolution`) add the error against the exact reference.\n");
    fclose(f);
}

/* ---- options and the main loop --------------------------------------------------------------- */

static void usage(FILE *f)
{
    fprintf(f,
        "usage: umbra-bench accuracy [options]\n"
        "  every shadow technique over its parameters, per scene of bench/scenes/, against the\n"
        "  exact reference: times (medians of N), memory, RMSE/PSNR/max/SSIM; writes\n"
        "  accuracy.csv, summary.md, headline.md, papers.md and plots/*.png into --out\n"
        "  --quick          small images (longer side %u), scenes marked 'quick yes', a reduced\n"
        "                   parameter set: a few minutes on 2 cores\n"
        "  --scenes A,B     only these scenes (file stems in the scene directory)\n"
        "  --techniques A,B only these techniques (the exact reference and none always run)\n"
        "  --out DIR        output directory (default: <source>/bench/results/accuracy, or\n"
        "                   accuracy-quick/ next to umbra-bench with --quick)\n"
        "  --runs N         timed runs per setting (default 3); fewer for settings\n"
        "                   whose first frame takes over %.0f s (2) or %.0f s (1);\n"
        "                   half those with --quick\n"
        "  --warmup N       warm-up frames per setting, the first one included (default 1)\n"
        "  --max-map N      leave out light-space maps larger than N^2 (default 4096)\n"
        "  --images MODE    PNGs under DIR/images: none, headline (default), all\n"
        "  --cache DIR      reference-image cache (default DIR/cache)\n"
        "  --no-cache       render the exact references again (and refresh the cache)\n"
        "  --no-plots       skip gnuplot\n"
        "  --scene-dir DIR  scene files (default <source>/bench/scenes)\n"
        "  --main NAME      the scene of the headline's first table (default walnut)\n"
        "  --list           print the scenes and settings, run nothing\n"
        "  --device SPEC    OpenCL device (P:D or a name substring)\n"
        "Volumes are looked up in $UMBRA_DATA_DIR, else <source>/../shared/data/volumes.\n",
        QUICK_MAX_SIDE, SLOW_MS / 1000.0, VERY_SLOW_MS / 1000.0);
}

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->runs = -1;
    o->warmup = 1;
    o->plots = 1;
    o->cache = 1;
    o->images = "headline";
    o->max_map = 4096;
    snprintf(o->scene_dir, sizeof o->scene_dir, "%s/bench/scenes", UMBRA_SOURCE_DIR);
    snprintf(o->main_scene, sizeof o->main_scene, "walnut");
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 1;
        } else if (strcmp(a, "--quick") == 0) {
            o->quick = 1;
        } else if (strcmp(a, "--list") == 0) {
            o->list = 1;
        } else if (strcmp(a, "--no-plots") == 0) {
            o->plots = 0;
        } else if (strcmp(a, "--no-cache") == 0) {
            o->cache = 0;
        } else if (strcmp(a, "--runs") == 0 && v && !bench_parse_int(v, 1, 64, &l)) {
            o->runs = (int)l;
            ++i;
        } else if (strcmp(a, "--warmup") == 0 && v && !bench_parse_int(v, 1, 100, &l)) {
            o->warmup = (int)l;
            ++i;
        } else if (strcmp(a, "--max-map") == 0 && v && !bench_parse_int(v, 64, 16384, &l)) {
            o->max_map = (uint32_t)l;
            ++i;
        } else if (strcmp(a, "--images") == 0 && v &&
                   (!strcmp(v, "none") || !strcmp(v, "headline") || !strcmp(v, "all"))) {
            o->images = v;
            ++i;
        } else if (strcmp(a, "--scenes") == 0 && v) {
            snprintf(o->scenes, sizeof o->scenes, "%s", v);
            ++i;
        } else if (strcmp(a, "--techniques") == 0 && v) {
            snprintf(o->techniques, sizeof o->techniques, "%s", v);
            for (char *t = o->techniques; *t;) {
                size_t len = strcspn(t, ",");
                char name[64];
                umbra_shadow_technique id;
                snprintf(name, sizeof name, "%.*s", (int)(len < 63 ? len : 63), t);
                if (umbra_shadow_technique_parse(name, &id) != UMBRA_SUCCESS) {
                    fprintf(stderr, "umbra-bench accuracy: --techniques: unknown technique '%s'\n",
                            name);
                    return -1;
                }
                t += len + (t[len] == ',');
            }
            ++i;
        } else if (strcmp(a, "--out") == 0 && v) {
            snprintf(o->out, sizeof o->out, "%s", v);
            ++i;
        } else if (strcmp(a, "--cache") == 0 && v) {
            snprintf(o->cache_dir, sizeof o->cache_dir, "%s", v);
            ++i;
        } else if (strcmp(a, "--scene-dir") == 0 && v) {
            snprintf(o->scene_dir, sizeof o->scene_dir, "%s", v);
            ++i;
        } else if (strcmp(a, "--main") == 0 && v) {
            snprintf(o->main_scene, sizeof o->main_scene, "%s", v);
            ++i;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
            ++i;
        } else {
            fprintf(stderr, "umbra-bench accuracy: bad option '%s'%s\n\n", a,
                    v ? "" : " (or its value is missing)");
            usage(stderr);
            return -1;
        }
    }
    if (o->runs < 0)
        o->runs = 3;
    if (!o->out[0]) {
        /* --quick results are for looking at, not for committing: next to the executable (the
         * build directory), else in the working directory. */
        char exe[1800];
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        char *slash = n > 0 ? (exe[n] = '\0', strrchr(exe, '/')) : NULL;
        if (slash)
            *slash = '\0';
        if (o->quick)
            snprintf(o->out, sizeof o->out, "%s/accuracy-quick", slash ? exe : ".");
        else
            snprintf(o->out, sizeof o->out, "%s/bench/results/accuracy", UMBRA_SOURCE_DIR);
    }
    if (!o->cache_dir[0])
        snprintf(o->cache_dir, sizeof o->cache_dir, "%s/cache", o->out);
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static int in_list(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0)
            return 1;
        if (!comma)
            break;
        p = comma + 1;
    }
    return 0;
}

/* Reads the scene files: all of the scene directory (sorted by name), or those --scenes names.
 * A malformed file stops the bench with its message. */
static int load_scenes(bench_run *B)
{
    DIR *dir = opendir(B->o.scene_dir);
    if (!dir) {
        fprintf(stderr, "umbra-bench accuracy: cannot open the scene directory %s: %s\n",
                B->o.scene_dir, strerror(errno));
        return -1;
    }
    char *names[MAX_SCENES];
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL && n < MAX_SCENES) {
        size_t len = strlen(e->d_name);
        if (len > 6 && strcmp(e->d_name + len - 6, ".scene") == 0) {
            names[n] = malloc(len + 1);
            if (names[n])
                strcpy(names[n++], e->d_name);
        }
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof names[0], cmp_str);
    char data_dir[SCENE_PATH_MAX];
    scene_data_dir(UMBRA_SOURCE_DIR, data_dir, sizeof data_dir);
    int rc = 0;
    for (int i = 0; i < n; ++i) {
        char path[SCENE_PATH_MAX + 512], err[1024], stem[SCENE_NAME_MAX];
        snprintf(stem, sizeof stem, "%.*s", (int)(strlen(names[i]) - 6), names[i]);
        if (B->o.scenes[0] && !in_list(B->o.scenes, stem))
            continue;
        snprintf(path, sizeof path, "%s/%s", B->o.scene_dir, names[i]);
        scene_spec *s = &B->scenes[B->scene_count];
        if (scene_parse_file(path, data_dir, s, err, sizeof err) != 0) {
            fprintf(stderr, "umbra-bench accuracy: %s\n", err);
            rc = -1;
            break;
        }
        if (B->o.quick && !s->quick && !B->o.scenes[0])
            continue;
        B->present[B->scene_count] = scene_volume_present(s);
        ++B->scene_count;
    }
    for (int i = 0; i < n; ++i)
        free(names[i]);
    if (rc == 0 && B->o.scenes[0]) {
        /* Every name asked for must exist. */
        char list[1024];
        snprintf(list, sizeof list, "%s", B->o.scenes);
        for (char *t = strtok(list, ","); t; t = strtok(NULL, ","))
            if (scene_index(B, t) < 0) {
                fprintf(stderr, "umbra-bench accuracy: no scene '%s' in %s\n", t, B->o.scene_dir);
                rc = -1;
            }
    }
    if (rc == 0 && B->scene_count == 0) {
        fprintf(stderr, "umbra-bench accuracy: no scenes in %s\n", B->o.scene_dir);
        rc = -1;
    }
    return rc;
}

int bench_accuracy(int argc, char **argv)
{
    static bench_run B; /* large (scene specs), and one per process: keep it off the stack */
    memset(&B, 0, sizeof B);
    int prc = parse_options(argc, argv, &B.o);
    if (prc != 0)
        return prc > 0 ? 0 : 2;
    if (load_scenes(&B) != 0)
        return 2;

    B.run_total = 0;
    for (int si = 0; si < B.scene_count; ++si) {
        config_list L;
        scene_configs(&B.o, &B.scenes[si], &L);
        if (B.o.list) {
            printf("%s%s: %s (%s)\n", B.scenes[si].name, B.present[si] ? "" : " [volume absent]",
                   B.scenes[si].description, B.scenes[si].volume);
            for (int i = 0; i < L.count; ++i)
                printf("  %-12s %-40s %s\n", umbra_shadow_technique_name(L.items[i].desc.technique),
                       L.items[i].label, L.items[i].params);
        }
        if (B.present[si])
            B.run_total += L.count;
    }
    if (B.o.list)
        return 0;

    if (mkdirs(B.o.out) != 0) {
        fprintf(stderr, "umbra-bench accuracy: cannot create %s: %s\n", B.o.out, strerror(errno));
        return 1;
    }
    char plots[4200];
    snprintf(plots, sizeof plots, "%s/plots", B.o.out);
    mkdirs(plots);
    B.ctx = bench_context(B.o.device);
    if (!B.ctx)
        return 1;
    describe_machine(&B);
    fprintf(stderr, "accuracy: %s on %s; %d settings over %d scene%s; results in %s\n",
            B.o.quick ? "--quick" : "full sweep", B.device, B.run_total, B.scene_count,
            B.scene_count == 1 ? "" : "s", B.o.out);
    B.t_start = bench_now_ms();
    for (int si = 0; si < B.scene_count; ++si) {
        if (!B.present[si]) {
            add_note(&B, "%s skipped: volume %s is not present", B.scenes[si].name,
                     B.scenes[si].volume);
            continue;
        }
        run_scene(&B, si);
        /* After every scene, so that an interrupted sweep leaves what it measured. */
        write_csv(&B);
    }
    pareto(&B);
    write_csv(&B);
    write_headline(&B);
    write_papers(&B);
    if (B.o.plots)
        write_plots(&B);
    write_summary(&B);
    char e[32];
    format_duration(bench_now_ms() - B.t_start, e, sizeof e);
    fprintf(stderr, "accuracy: %d runs in %s; wrote %s/{accuracy.csv,summary.md,headline.md,"
                    "papers.md,plots/}%s\n", B.result_count, e, B.o.out,
            B.failures ? "; SOME RUNS FAILED (see summary.md notes)" : "");
    for (int i = 0; i < B.notes.count; ++i)
        free(B.notes.items[i]);
    free(B.notes.items);
    free(B.results);
    umbra_context_release(B.ctx);
    return B.failures ? 1 : 0;
}
