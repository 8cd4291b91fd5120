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
 * headline.md (docs/accuracy.md's headline table), papers.md (the seed papers' timing tables
 * re-measured, side by side with the papers' figures) and PNG plots through gnuplot
 * (bench/plot_accuracy.gp): error against time and error against memory, per scene, with the
 * Pareto front. bench/README.md documents the options and the method.
 *
 * This file holds the settings swept, the options, the scene list, the entry point and the small
 * helpers the other parts share; bench/accuracy_run.c renders and measures, and
 * bench/accuracy_report.c writes the outputs (bench/accuracy.h lists what they share). */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "accuracy.h"
#include "renderer_internal.h"
#include "setting.h"

/* ---- the settings swept ---------------------------------------------------------------------- */

/* The sweep is the technique registry's: every technique's descriptor lists the settings it is
 * measured at (host/renderer_internal.h, umbra__setting: its parameters as "key=value;...", a
 * label, and whether it belongs to the quick sweep, the full one, a paper's table, the headline).
 * The exact reference comes first (its image is every other row's yardstick), then none (the
 * unshadowed frame every overhead is measured against), then each technique's settings in the
 * registry's order. A scene marked `papers cssm` adds 2048^2 and 4096^2 maps for the CSSM
 * paper's Tables 3-4, one marked `papers deep` the deep-map paper's Table 1 settings; on a 2-core
 * CPU one 4096^2 build takes one to three minutes, so the large maps are measured where the
 * papers' tables need them. */

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

/* The setting's parameters in c (tests/setting.h). A setting the registry refuses is a bug of
 * its table: reported, and left out. */
static int apply_params(config *c, const char *params)
{
    char msg[1024];
    if (setting_apply(&c->desc, &c->preintegrated, params, msg, sizeof msg) == 0)
        return 0;
    fprintf(stderr, "accuracy: %s\n", msg);
    return -1;
}

static void add_exact_reference(config_list *L, float step)
{
    config *c = add_config(L, UMBRA_SHADOW_REFERENCE);
    if (!c)
        return;
    c->desc.reference.step = step;
    c->exact = 1;
    c->headline = H_EXACT;
    snprintf(c->label, sizeof c->label, "step %g (exact)", step);
    snprintf(c->params, sizeof c->params, "reference_step=%g", step);
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

/* Whether a setting with these flags runs in this sweep, for a scene with these papers. */
static int in_sweep(uint32_t flags, int quick, int papers)
{
    if (quick)
        return (flags & UMBRA__SWEEP_QUICK) != 0;
    return (flags & UMBRA__SWEEP_FULL) ||
           ((flags & UMBRA__SWEEP_PAPERS_CSSM) && (papers & SCENE_PAPERS_CSSM)) ||
           ((flags & UMBRA__SWEEP_PAPERS_DEEP) && (papers & SCENE_PAPERS_DEEP));
}

/* The sweep of one scene. Headline rows are numbered in the order they come: none, the exact
 * reference, then each technique's. Light-space maps larger than max_map^2 are left out. */
static void build_configs(int quick, int papers, uint32_t max_map, float exact_step,
                          config_list *L)
{
    L->count = 0;
    L->headline_count = H_FIRST_TECHNIQUE - 1;
    add_exact_reference(L, exact_step);
    add_none(L);
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra__technique *tech = umbra__technique_by_id(umbra_technique_get(t)->id);
        for (uint32_t i = 0; i < tech->sweep_count; ++i) {
            const umbra__setting *s = &tech->sweep[i];
            if (!in_sweep(s->flags, quick, papers))
                continue;
            config *c = add_config(L, tech->info.id);
            if (!c)
                return;
            snprintf(c->label, sizeof c->label, "%s", s->label);
            snprintf(c->params, sizeof c->params, "%s", s->params);
            if (apply_params(c, s->params) != 0 ||
                ((tech->info.flags & UMBRA_TECHNIQUE_MAP) && c->desc.map.size > max_map)) {
                L->count--;
                continue;
            }
            if (s->flags & (quick ? UMBRA__SWEEP_HEADLINE_QUICK : UMBRA__SWEEP_HEADLINE))
                c->headline = ++L->headline_count;
        }
    }
}

float accuracy_exact_step(const scene_spec *s)
{
    return s->reference_step > 0.0f ? s->reference_step : 0.25f;
}


/* The sweep for one scene, less the techniques --techniques leaves out (the exact reference and
 * the unshadowed frame always stay: every other row is measured against them). */
void accuracy_scene_configs(const options *o, const scene_spec *s, config_list *L)
{
    build_configs(o->quick, s->papers, o->max_map, accuracy_exact_step(s), L);
    if (!o->techniques[0])
        return;
    int n = 0;
    for (int i = 0; i < L->count; ++i) {
        const config *c = &L->items[i];
        if (c->exact || c->desc.technique == UMBRA_SHADOW_NONE ||
            bench_in_list(o->techniques, umbra_shadow_technique_name(c->desc.technique)))
            L->items[n++] = *c;
    }
    L->count = n;
}

/* ---- notes and results ----------------------------------------------------------------------- */

void accuracy_add_note(bench_run *B, const char *fmt, ...)
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

result *accuracy_new_result(bench_run *B)
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

int accuracy_mkdirs(const char *path)
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

int accuracy_file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

void accuracy_format_duration(double ms, char *buf, size_t size)
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
void accuracy_sanitize(char *s, int for_file)
{
    for (; *s; ++s) {
        if (*s == ',' || *s == '"' || *s == '\n')
            *s = ';';
        if (for_file && !((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
                          (*s >= '0' && *s <= '9') || *s == '-' || *s == '.' || *s == '_'))
            *s = '_';
    }
}

int accuracy_scene_index(const bench_run *B, const char *name)
{
    for (int si = 0; si < B->scene_count; ++si)
        if (strcmp(B->scenes[si].name, name) == 0)
            return si;
    return -1;
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
        "  --merge CSV      keep the rows of an earlier accuracy.csv that this run does not\n"
        "                   measure (same scene, technique and params), and report them all\n"
        "  --report         measure nothing: write the outputs from the --merge rows alone\n"
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
        } else if (strcmp(a, "--report") == 0) {
            o->report = 1;
        } else if (strcmp(a, "--merge") == 0 && v) {
            snprintf(o->merge, sizeof o->merge, "%s", v);
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
    char merged[1024] = "";
    if (B->o.merge[0] && (accuracy_merge_read(B->o.merge) != 0 ||
                          accuracy_merge_scene_names(merged, sizeof merged) != 0)) {
        fprintf(stderr, "umbra-bench accuracy: --merge %s: cannot read it\n", B->o.merge);
        for (int i = 0; i < n; ++i)
            free(names[i]);
        return -1;
    }
    int rc = 0;
    for (int i = 0; i < n; ++i) {
        char path[SCENE_PATH_MAX + 512], err[1024], stem[SCENE_NAME_MAX];
        snprintf(stem, sizeof stem, "%.*s", (int)(strlen(names[i]) - 6), names[i]);
        const int from_merge = bench_in_list(merged, stem);
        if (B->o.scenes[0] && !bench_in_list(B->o.scenes, stem) && !from_merge)
            continue;
        snprintf(path, sizeof path, "%s/%s", B->o.scene_dir, names[i]);
        scene_spec *s = &B->scenes[B->scene_count];
        if (scene_parse_file(path, data_dir, s, err, sizeof err) != 0) {
            fprintf(stderr, "umbra-bench accuracy: %s\n", err);
            rc = -1;
            break;
        }
        const int selected = B->o.report      ? 0
                             : B->o.scenes[0] ? bench_in_list(B->o.scenes, stem)
                                              : !(B->o.quick && !s->quick);
        if (!selected && !from_merge)
            continue;
        B->merged_only[B->scene_count] = !selected;
        B->present[B->scene_count] = !selected || scene_volume_present(s);
        ++B->scene_count;
    }
    for (int i = 0; i < n; ++i)
        free(names[i]);
    if (rc == 0 && B->o.scenes[0]) {
        /* Every name asked for must exist. */
        char list[1024];
        snprintf(list, sizeof list, "%s", B->o.scenes);
        for (char *t = strtok(list, ","); t; t = strtok(NULL, ","))
            if (accuracy_scene_index(B, t) < 0) {
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
    if (B.o.report && !B.o.merge[0]) {
        fprintf(stderr, "umbra-bench accuracy: --report needs --merge CSV\n");
        return 2;
    }
    if (load_scenes(&B) != 0)
        return 2;

    B.run_total = 0;
    for (int si = 0; si < B.scene_count; ++si) {
        config_list L;
        accuracy_scene_configs(&B.o, &B.scenes[si], &L);
        if (B.o.list) {
            printf("%s%s: %s (%s)\n", B.scenes[si].name, B.present[si] ? "" : " [volume absent]",
                   B.scenes[si].description, B.scenes[si].volume);
            for (int i = 0; i < L.count; ++i)
                printf("  %-12s %-40s %s%s\n",
                       umbra_shadow_technique_name(L.items[i].desc.technique),
                       L.items[i].label, L.items[i].params,
                       L.items[i].headline ? " [headline]" : "");
        }
        if (B.present[si] && !B.merged_only[si])
            B.run_total += L.count;
    }
    if (B.o.list)
        return 0;

    if (accuracy_mkdirs(B.o.out) != 0) {
        fprintf(stderr, "umbra-bench accuracy: cannot create %s: %s\n", B.o.out, strerror(errno));
        return 1;
    }
    char plots[4200];
    snprintf(plots, sizeof plots, "%s/plots", B.o.out);
    accuracy_mkdirs(plots);
    B.ctx = bench_context(B.o.device);
    if (!B.ctx)
        return 1;
    accuracy_describe_machine(&B);
    fprintf(stderr, "accuracy: %s on %s; %d settings over %d scene%s; results in %s\n",
            B.o.quick ? "--quick" : "full sweep", B.device, B.run_total, B.scene_count,
            B.scene_count == 1 ? "" : "s", B.o.out);
    B.t_start = bench_now_ms();
    for (int si = 0; si < B.scene_count; ++si) {
        if (B.merged_only[si])
            continue;
        if (!B.present[si]) {
            accuracy_add_note(&B, "%s skipped: volume %s is not present", B.scenes[si].name,
                              B.scenes[si].volume);
            continue;
        }
        accuracy_run_scene(&B, si);
        /* After every scene, so that an interrupted sweep leaves what it measured. */
        accuracy_write_csv(&B);
    }
    if (B.o.merge[0])
        accuracy_merge_rows(&B);
    accuracy_pareto(&B);
    accuracy_write_csv(&B);
    accuracy_write_headline(&B);
    accuracy_write_papers(&B);
    if (B.o.plots)
        accuracy_write_plots(&B);
    accuracy_write_summary(&B);
    accuracy_write_texel(&B);
    char e[32];
    accuracy_format_duration(bench_now_ms() - B.t_start, e, sizeof e);
    fprintf(stderr, "accuracy: %d runs in %s; wrote %s/{accuracy.csv,summary.md,headline.md,"
                    "papers.md,texel.md,plots/}%s\n", B.result_count, e, B.o.out,
            B.failures ? "; SOME RUNS FAILED (see summary.md notes)" : "");
    for (int i = 0; i < B.notes.count; ++i)
        free(B.notes.items[i]);
    free(B.notes.items);
    free(B.results);
    umbra_context_release(B.ctx);
    return B.failures ? 1 : 0;
}
