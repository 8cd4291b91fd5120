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

/* ---- the settings swept ---------------------------------------------------------------------- */

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
    c->desc.reference.step = step;
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
    c->desc.map.size = map;
    c->desc.threshold.taps = taps;
    c->desc.threshold.threshold = threshold;
    char a[16], b[16];
    snprintf(c->label, sizeof c->label, "%s, opacity %g%s", map_label(map, a), threshold,
             taps > 1 ? (taps == 7 ? ", 7 taps" : taps == 13 ? ", 13 taps" : ", 21 taps") : "");
    snprintf(c->params, sizeof c->params, "map_size=%s;taps=%u;threshold=%g", map_name(map, b),
             taps, threshold);
    if (map == L->headline_map && taps == 1 && threshold == 0.5f)
        c->headline = H_THRESHOLD;
}

/* ray_block 0 is the default block of texels per light ray; 1, a ray per texel (the paper's),
 * is labelled and named as such. */
static config *add_cssm(config_list *L, uint32_t map, uint32_t taps, uint32_t ray_block)
{
    config *c = add_config(L, UMBRA_SHADOW_CSSM);
    if (!c)
        return NULL;
    c->desc.map.size = map;
    c->desc.cssm.taps = taps;
    c->desc.cssm.ray_block = ray_block;
    char a[16], b[16];
    snprintf(c->label, sizeof c->label, "%s, %u taps%s", map_label(map, a), taps,
             ray_block == 1 ? ", a ray per texel" : "");
    snprintf(c->params, sizeof c->params, "map_size=%s;taps=%u;seed=%u%s", map_name(map, b), taps,
             c->desc.cssm.seed, ray_block == 1 ? ";ray_block=1" : "");
    if (map == L->headline_map && taps == 13 && ray_block == 0)
        c->headline = H_CSSM;
    return c;
}

static config *add_deep(config_list *L, uint32_t map, float eps, uint32_t nodes,
                        uint32_t prefilter)
{
    config *c = add_config(L, UMBRA_SHADOW_DEEP);
    if (!c)
        return NULL;
    c->desc.map.size = map;
    c->desc.deep.epsilon = eps;
    c->desc.deep.max_nodes = nodes;
    c->desc.deep.prefilter = prefilter;
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
    return c;
}

/* An auto-size row made a draft: one texel per voxel (map_texels_per_voxel 1, what an application
 * asks for while the user drags the light), the threshold map's size, instead of the
 * technique's own. */
static void make_draft(config *c)
{
    if (!c)
        return;
    c->desc.map.texels_per_voxel = 1.0f;
    size_t n = strlen(c->label), m = strlen(c->params);
    snprintf(c->label + n, sizeof c->label - n, ", draft");
    snprintf(c->params + m, sizeof c->params - m, ";map_texels_per_voxel=1");
}

static void add_convolution(config_list *L, float slice, uint32_t sub, int pre)
{
    config *c = add_config(L, UMBRA_SHADOW_CONVOLUTION);
    if (!c)
        return;
    c->desc.convolution.slice_distance = slice;
    c->desc.convolution.subsamples = sub;
    c->preintegrated = pre;
    const char *kind = pre ? (sub ? "pre-int. SCS" : "pre-int. ICS") : (sub ? "SCS" : "ICS");
    snprintf(c->label, sizeof c->label, "%s slice %g%s", kind,
             slice, sub ? (sub == 1 ? ", 1 sub-sample" : sub == 2 ? ", 2 sub-samples"
                                                                  : ", 3 sub-samples")
                        : "");
    snprintf(c->params, sizeof c->params,
             "slice_distance=%g;subsamples=%u;preintegrated=%d;cone_angle=%g", slice, sub, pre,
             c->desc.convolution.cone_angle_degrees);
    if (slice == 1.0f && sub == 0 && !pre)
        c->headline = H_CONV;
}

/* The sweep. The exact reference comes first (its image is every other row's yardstick), then
 * none (the unshadowed frame every overhead is measured against). Maps are 512^2 and 1024^2 (the
 * headline size); a scene marked `papers cssm` adds 2048^2 and 4096^2 for the CSSM paper's
 * Tables 3-4 (threshold, deep with 3 nodes per channel, CSSM with 13 taps; unbounded deep maps up
 * to 2048^2), one marked `papers deep` the deep-map paper's Table 1 (128^2-512^2 at epsilon 0.02
 * and 0.06 with the 5-tap pre-filter). On a 2-core CPU one 4096^2 build takes one to three
 * minutes, so the large maps are measured where the papers' tables need them. CSSM and the deep
 * map also run at auto size as a draft (make_draft): what a dragged light costs in accuracy. */
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
        /* 13 taps is the library's default (umbra_shadow_desc_init): auto with 13 taps is the
         * threshold map an application gets unless it asks for another. */
        add_threshold(L, UMBRA_MAP_SIZE_AUTO, 13, 0.5f);
        add_threshold(L, 1024, 13, 0.5f);
        add_threshold(L, 1024, 1, 0.25f);
        add_threshold(L, 1024, 1, 0.75f);
    }
    for (size_t i = 0; i < nmaps; ++i)
        if (maps[i] <= max_map)
            add_cssm(L, maps[i], 13, 0);
    make_draft(add_cssm(L, UMBRA_MAP_SIZE_AUTO, 13, 0));
    add_cssm(L, L->headline_map, 7, 0);
    if (!quick) {
        add_cssm(L, 1024, 21, 0);
        add_cssm(L, UMBRA_MAP_SIZE_AUTO, 13, 1); /* what sharing rays costs in accuracy */
        add_cssm(L, 1024, 13, 1);
    }
    /* Unbounded deep maps stop at 2048^2: at 4096^2 one build takes about 3 minutes here. */
    for (size_t i = 0; i < nmaps && i < 4; ++i)
        if (maps[i] <= max_map)
            add_deep(L, maps[i], 0.02f, 0, 1);
    make_draft(add_deep(L, UMBRA_MAP_SIZE_AUTO, 0.02f, 0, 1));
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

float accuracy_exact_step(const scene_spec *s)
{
    return s->reference_step > 0.0f ? s->reference_step : 0.25f;
}

static int in_list(const char *list, const char *name);

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
            in_list(o->techniques, umbra_shadow_technique_name(c->desc.technique)))
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
                printf("  %-12s %-40s %s\n", umbra_shadow_technique_name(L.items[i].desc.technique),
                       L.items[i].label, L.items[i].params);
        }
        if (B.present[si])
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
        if (!B.present[si]) {
            accuracy_add_note(&B, "%s skipped: volume %s is not present", B.scenes[si].name,
                              B.scenes[si].volume);
            continue;
        }
        accuracy_run_scene(&B, si);
        /* After every scene, so that an interrupted sweep leaves what it measured. */
        accuracy_write_csv(&B);
    }
    accuracy_pareto(&B);
    accuracy_write_csv(&B);
    accuracy_write_headline(&B);
    accuracy_write_papers(&B);
    if (B.o.plots)
        accuracy_write_plots(&B);
    accuracy_write_summary(&B);
    char e[32];
    accuracy_format_duration(bench_now_ms() - B.t_start, e, sizeof e);
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
