// SPDX-License-Identifier: Apache-2.0
/* bench/builds.c: `umbra-bench builds`, the light-space map builds side by side at equal map size
 * (issue #12's "build at equal map size over the threshold build").
 *
 * For each scene (bench/scenes/walnut.scene and bonsai.scene by default) and map size (512 and
 * 1024 by default), a build of the same light for each variant the registry gives (the settings
 * of the light-space maps flagged for it, host/techniques/; today six):
 *   threshold       the opacity-threshold map at its default threshold, 0.5: the baseline;
 *   threshold-0.99  a threshold march as long as the deep map's: stopped where the deep map's
 *                   march stops (visibility below epsilon / 2 = 0.01, opacity 0.99), at the deep
 *                   map's light step of half a voxel (the threshold map's own is one voxel,
 *                   host/lightspace.h);
 *   cssm-grey, cssm-colored   CSSM with grey and with coloured transmission (13 taps do not
 *                   enter a build);
 *   deep-grey, deep-colored   the deep map with a fixed budget of 3 nodes and epsilon 0.02.
 * The threshold map ignores colour, so it is the same build for either transmission. A coloured
 * CSSM photon is tracked until every channel is absorbed, the least absorbed channel last; the
 * deep map marches until all visibility is below 0.01: their rays run further than the 0.5
 * threshold's, and threshold-0.99 says how much of a ratio that alone explains (the rest is the
 * cost per step).
 *
 * Each round builds every variant once, in turn, so load on the machine falls on all of them
 * alike; the light alternates between the scene's and the same turned 1 degree about the vertical
 * axis through the box's centre, so every render rebuilds. The time is the build's own
 * (umbra_render_stats.shadow_build_ms; the image is 32 x 32 pixels). Medians over --builds rounds
 * after --warmup rounds. CSV on stdout, commentary on stderr; --results DIR also writes
 * DIR/builds.csv and DIR/builds.md. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "renderer_internal.h"
#include "scene_file.h"
#include "setting.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

#define MAX_SIZES 8
#define MAX_ROWS 96
#define IMAGE_SIDE 32u
#define TURN_DEGREES 1.0f

/* A build the bench times: a setting of a light-space map from the registry (host/techniques/,
 * the sweep rows flagged UMBRA__SWEEP_BUILDS) with one transmission. */
typedef struct variant {
    char name[64];
    umbra_shadow_technique technique;
    const char *params;
    umbra_transmission transmission;
} variant;

/* Ratios are taken over the first variant (the threshold map at 0.5) and the second (its march
 * as long as the deep map's). */
enum { BASELINE = 0, MATCHED = 1, MAX_VARIANTS = 32 };
static variant variants[MAX_VARIANTS];
static int variant_count;

/* The variants from the registry, in its order: each build setting of each light-space map,
 * grey, and coloured too for a technique that carries colour; of them only those named in only
 * (NULL: all) beside the first two, the ratios' bases. */
static void make_variants(const char *only)
{
    variant_count = 0;
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra__technique *tech = umbra__technique_by_id(umbra_technique_get(t)->id);
        if (!(tech->info.flags & UMBRA_TECHNIQUE_MAP))
            continue;
        const int grey_only = (tech->info.flags & UMBRA_TECHNIQUE_GREY) != 0;
        for (uint32_t i = 0; i < tech->sweep_count; ++i) {
            if (!(tech->sweep[i].flags & UMBRA__SWEEP_BUILDS))
                continue;
            for (int colored = 0; colored <= !grey_only && variant_count < MAX_VARIANTS;
                 ++colored) {
                variant *v = &variants[variant_count++];
                snprintf(v->name, sizeof v->name, "%s%s", tech->sweep[i].label,
                         grey_only ? "" : colored ? "-colored" : "-grey");
                v->technique = tech->info.id;
                v->params = tech->sweep[i].params;
                v->transmission = colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
                if (variant_count > MATCHED + 1 && only && !bench_in_list(only, v->name))
                    --variant_count;
            }
        }
    }
}

typedef struct options {
    char scenes[256], scene_dir[1024];
    uint32_t sizes[MAX_SIZES];
    int nsizes, builds, warmup;
    const char *results, *device, *variants;
} options;

typedef struct row {
    char scene[SCENE_NAME_MAX];
    uint32_t map_size;
    int variant;
    bench_timing build;
} row;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench builds [options]\n"
            "  the light-space map builds at equal map size: threshold (0.5, and 0.99 where the\n"
            "  deep map's march stops), CSSM and the deep map (3 nodes), grey and coloured;\n"
            "  median build ms and each over the threshold map's\n"
            "  --builds N       timed builds per variant (default 5)\n"
            "  --warmup N       untimed builds before them (default 1)\n"
            "  --sizes A,B      map sizes (default 512,1024; each 16..8192)\n"
            "  --scenes A,B     scene files' stems (default walnut,bonsai)\n"
            "  --scene-dir DIR  scene files (default <source>/bench/scenes)\n"
            "  --variants A,B   only these variants (names as in the table) beside threshold\n"
            "                   and threshold-0.99, the ratios' bases (default: all)\n"
            "  --results DIR    also write DIR/builds.csv and DIR/builds.md\n"
            "  --device SPEC    OpenCL device (P:D or a name substring)\n");
}

static int parse_sizes(const char *s, options *o)
{
    char list[128], *save = NULL;
    snprintf(list, sizeof list, "%s", s);
    o->nsizes = 0;
    for (char *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        long l;
        if (o->nsizes == MAX_SIZES || bench_parse_int(t, 16, 8192, &l))
            return -1;
        o->sizes[o->nsizes++] = (uint32_t)l;
    }
    return o->nsizes ? 0 : -1;
}

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->builds = 5;
    o->warmup = 1;
    o->sizes[0] = 512;
    o->sizes[1] = 1024;
    o->nsizes = 2;
    snprintf(o->scenes, sizeof o->scenes, "walnut,bonsai");
    snprintf(o->scene_dir, sizeof o->scene_dir, "%s/bench/scenes", UMBRA_SOURCE_DIR);
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 1;
        } else if (strcmp(a, "--builds") == 0 && v && !bench_parse_int(v, 1, 1000, &l)) {
            o->builds = (int)l;
        } else if (strcmp(a, "--warmup") == 0 && v && !bench_parse_int(v, 0, 100, &l)) {
            o->warmup = (int)l;
        } else if (strcmp(a, "--sizes") == 0 && v && !parse_sizes(v, o)) {
        } else if (strcmp(a, "--scenes") == 0 && v) {
            snprintf(o->scenes, sizeof o->scenes, "%s", v);
        } else if (strcmp(a, "--scene-dir") == 0 && v) {
            snprintf(o->scene_dir, sizeof o->scene_dir, "%s", v);
        } else if (strcmp(a, "--variants") == 0 && v) {
            o->variants = v;
        } else if (strcmp(a, "--results") == 0 && v) {
            o->results = v;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
        } else {
            fprintf(stderr, "umbra-bench builds: bad option '%s'%s%s\n", a, v ? " " : "",
                    v ? v : "");
            usage(stderr);
            return -1;
        }
        ++i; /* every option takes a value */
    }
    return 0;
}

/* The scene's light, turned by deg degrees about the vertical axis through c. */
static umbra_light turned_light(umbra_light light, const float c[3], float deg)
{
    float a = deg * 3.14159265f / 180.0f, s = sinf(a), k = cosf(a);
    float *p = light.type == UMBRA_LIGHT_DIRECTIONAL ? light.direction : light.position;
    const float o[3] = {0.0f, 0.0f, 0.0f};
    const float *q = light.type == UMBRA_LIGHT_DIRECTIONAL ? o : c;
    float x = p[0] - q[0], z = p[2] - q[2];
    p[0] = q[0] + k * x + s * z;
    p[2] = q[2] - s * x + k * z;
    return light;
}

/* A renderer of the scene building variant v at map size n. */
static umbra_status renderer_for(umbra_context ctx, const umbra_scene *scene,
                                 umbra_transfer_function light_tf, const variant *v, uint32_t n,
                                 umbra_renderer *out)
{
    umbra_render_desc opts = scene->options;
    opts.transmission = v->transmission;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = v->technique;
    char msg[1024];
    if (setting_apply(&sd, &opts.preintegrated, v->params, msg, sizeof msg) != 0) {
        fprintf(stderr, "umbra-bench builds: %s\n", msg);
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    sd.map.size = n;
    umbra_status st = umbra_renderer_create(ctx, out);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_volume(*out, scene->volume);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_transfer_function(*out, scene->tf);
    if (st == UMBRA_SUCCESS && light_tf)
        st = umbra_renderer_set_light_transfer_function(*out, light_tf);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_camera(*out, &scene->camera);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_options(*out, &opts);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_shadow(*out, &sd);
    return st;
}

/* Every variant at map size n, in rounds; one row per variant. */
static umbra_status run_size(umbra_context ctx, const options *o, const char *name,
                             const umbra_scene *scene, umbra_transfer_function light_tf,
                             const float center[3], uint32_t n, row *rows)
{
    umbra_renderer r[MAX_VARIANTS] = {NULL};
    const int rounds = o->warmup + o->builds;
    double *ms = malloc((size_t)variant_count * (size_t)rounds * sizeof *ms);
    float *image = malloc((size_t)IMAGE_SIDE * IMAGE_SIDE * 4 * sizeof *image);
    umbra_status st = ms && image ? UMBRA_SUCCESS : UMBRA_ERROR_OUT_OF_MEMORY;
    for (int v = 0; v < variant_count && st == UMBRA_SUCCESS; ++v)
        st = renderer_for(ctx, scene, light_tf, &variants[v], n, &r[v]);
    for (int i = 0; i < rounds && st == UMBRA_SUCCESS; ++i) {
        const umbra_light light = turned_light(scene->light, center, (i % 2) * TURN_DEGREES);
        for (int v = 0; v < variant_count && st == UMBRA_SUCCESS; ++v) {
            umbra_render_stats stats;
            st = umbra_renderer_set_light(r[v], &light);
            if (st == UMBRA_SUCCESS)
                st = umbra_renderer_render(r[v], IMAGE_SIDE, IMAGE_SIDE, image);
            if (st == UMBRA_SUCCESS)
                st = umbra_renderer_get_stats(r[v], &stats);
            if (st == UMBRA_SUCCESS)
                ms[v * rounds + i] = stats.shadow_build_ms;
        }
    }
    for (int v = 0; v < variant_count && st == UMBRA_SUCCESS; ++v) {
        snprintf(rows[v].scene, sizeof rows[v].scene, "%s", name);
        rows[v].map_size = n;
        rows[v].variant = v;
        rows[v].build = bench_timing_of(ms + v * rounds + o->warmup, o->builds);
    }
    for (int v = 0; v < variant_count; ++v)
        umbra_renderer_release(r[v]);
    free(ms);
    free(image);
    return st;
}

/* Every map size of one scene file, appended to rows. */
static int run_scene(umbra_context ctx, const options *o, const char *name, row *rows, int *nrows)
{
    char path[1400], data[1024], err[512];
    scene_spec spec;
    snprintf(path, sizeof path, "%s/%s.scene", o->scene_dir, name);
    scene_data_dir(UMBRA_SOURCE_DIR, data, sizeof data);
    if (scene_parse_file(path, data, &spec, err, sizeof err) != 0) {
        fprintf(stderr, "umbra-bench builds: %s\n", err);
        return 1;
    }
    if (!scene_volume_present(&spec)) {
        fprintf(stderr, "umbra-bench builds: %s: volume %s is missing; skipped\n", name,
                spec.volume);
        return 0;
    }
    umbra_scene scene;
    umbra_transfer_function light_tf = NULL;
    umbra_volume_info info;
    memset(&scene, 0, sizeof scene);
    umbra_status st = scene_create(ctx, &spec, &scene, &light_tf);
    const int created = st == UMBRA_SUCCESS;
    if (st == UMBRA_SUCCESS)
        st = umbra_volume_get_info(scene.volume, &info);
    for (int s = 0; s < o->nsizes && st == UMBRA_SUCCESS; ++s) {
        if (*nrows + variant_count > MAX_ROWS)
            break;
        fprintf(stderr, "builds: %s, %u^2 ...\n", name, o->sizes[s]);
        st = run_size(ctx, o, name, &scene, light_tf, info.center, o->sizes[s], rows + *nrows);
        if (st == UMBRA_SUCCESS)
            *nrows += variant_count;
    }
    if (st != UMBRA_SUCCESS)
        fprintf(stderr, "umbra-bench builds: %s: %s: %s\n", name, umbra_status_to_string(st),
                umbra_context_last_message(ctx));
    if (created) {
        umbra_transfer_function_release(light_tf);
        umbra_scene_release(&scene);
    }
    return st == UMBRA_SUCCESS ? 0 : 1;
}

/* ---- the report ------------------------------------------------------------------------------ */

/* Row i's median over the baseline's (or the matched threshold's) of the same scene and size:
 * rows come in groups of variant_count, in the order of variants[]. */
static double over(const row *rows, int i, int base)
{
    return rows[i].build.median / rows[i - rows[i].variant + base].build.median;
}

static void csv_rows(FILE *f, const row *rows, int n)
{
    fprintf(f, "scene,map_size,variant,builds,build_ms_median,build_ms_min,build_ms_max,"
               "over_threshold,over_threshold_0.99\n");
    for (int i = 0; i < n; ++i)
        fprintf(f, "%s,%u,%s,%d,%.2f,%.2f,%.2f,%.3f,%.3f\n", rows[i].scene, rows[i].map_size,
                variants[rows[i].variant].name, rows[i].build.runs, rows[i].build.median,
                rows[i].build.min, rows[i].build.max, over(rows, i, BASELINE),
                over(rows, i, MATCHED));
}

static int write_results(const options *o, int argc, char **argv, umbra_context ctx,
                         const row *rows, int n)
{
    char device[600];
    bench_device_description(ctx, device, sizeof device);
    FILE *f = bench_results_open(o->results, "builds", "csv");
    if (!f)
        return -1;
    csv_rows(f, rows, n);
    fclose(f);
    if (!(f = bench_results_open(o->results, "builds", "md")))
        return -1;
    bench_results_header(f, "builds", argc, argv, device);
    fprintf(f, "- median of %d builds per variant after %d warm-up builds, the variants in turn "
               "each round; the build's own time (umbra_render_stats.shadow_build_ms) "
               "(bench/builds.c)\n\n",
            o->builds, o->warmup);
    fprintf(f, "Build ms at equal map size and over the threshold map's (its light step is one "
               "voxel, CSSM's too). threshold-0.99 stops where the deep map's march stops "
               "(visibility 0.01), at the deep map's step of half a voxel: the last column says "
               "how much more a build costs than a threshold march of that length. The deep map "
               "has 3 nodes and epsilon 0.02.\n\n"
               "| scene | map | variant | build ms | over threshold | over threshold-0.99 |\n"
               "|---|---:|---|---:|---:|---:|\n");
    for (int i = 0; i < n; ++i)
        fprintf(f, "| %s | %u² | %s | %.1f | %.2f× | %.2f× |\n", rows[i].scene, rows[i].map_size,
                variants[rows[i].variant].name, rows[i].build.median, over(rows, i, BASELINE),
                over(rows, i, MATCHED));
    fclose(f);
    fprintf(stderr, "wrote %s/builds.csv and %s/builds.md\n", o->results, o->results);
    return 0;
}

int bench_builds(int argc, char **argv)
{
    options o;
    int rc = parse_options(argc, argv, &o);
    if (rc != 0)
        return rc > 0 ? 0 : 2;
    make_variants(o.variants);
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    row *rows = calloc(MAX_ROWS, sizeof *rows);
    int n = 0, failures = 0;
    if (!rows) {
        umbra_context_release(ctx);
        return 1;
    }
    char list[256];
    snprintf(list, sizeof list, "%s", o.scenes);
    for (char *save = NULL, *name = strtok_r(list, ",", &save); name;
         name = strtok_r(NULL, ",", &save))
        failures += run_scene(ctx, &o, name, rows, &n);
    csv_rows(stdout, rows, n);
    if (o.results && write_results(&o, argc, argv, ctx, rows, n) != 0)
        ++failures; /* a results file that cannot be written (the message is on stderr) */
    free(rows);
    umbra_context_release(ctx);
    return failures ? 1 : 0;
}
