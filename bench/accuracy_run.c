// SPDX-License-Identifier: Apache-2.0
/* bench/accuracy_run.c: `umbra-bench accuracy`, rendering and measuring one scene's settings
 * (bench/accuracy.c says what the subcommand measures), and the machine the numbers come from.
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
 * project; any other error is reported, the run is skipped, and the exit status is 1. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "accuracy.h"

/* ---- progress -------------------------------------------------------------------------------- */

static void progress(bench_run *B, const char *scene, const config *c)
{
    ++B->run_index;
    double elapsed = bench_now_ms() - B->t_start;
    char e[32], rem[32] = "?";
    accuracy_format_duration(elapsed, e, sizeof e);
    if (B->run_index > 1) {
        /* Runs differ a lot in cost; the average so far is a rough guide, labelled as such. */
        double per = elapsed / (double)(B->run_index - 1);
        accuracy_format_duration(per * (double)(B->run_total - B->run_index + 1), rem, sizeof rem);
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

void accuracy_describe_machine(bench_run *B)
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

void accuracy_write_machine(bench_run *B, FILE *f)
{
    double load_end[3];
    read_loadavg(load_end);
    if (B->o.report)
        fprintf(f, "- Written by `--report` from rows measured in earlier runs (`--merge %s`): "
                   "the machine below wrote the outputs and measured nothing\n", B->o.merge);
    fprintf(f, "- Started: %s; umbra commit %s\n", B->started, B->commit);
    fprintf(f, "- CPU: %s\n", B->machine);
    fprintf(f, "- OpenCL device: %s\n", B->device);
    fprintf(f, "- OpenCL platform: %s\n", B->platform);
    fprintf(f, "- Load average (1, 5, 15 min) at start %.2f %.2f %.2f, at the end %.2f %.2f %.2f\n",
            B->load_start[0], B->load_start[1], B->load_start[2], load_end[0], load_end[1],
            load_end[2]);
    if (B->o.report) {
        fprintf(f, "- Mode: %s; timed runs per setting as each row's runs column says\n",
                B->o.quick ? "--quick" : "full sweep");
        return;
    }
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
        accuracy_add_note(B, "%s: %s %s skipped (%s): %s", scene,
                          umbra_shadow_technique_name(c->desc.technique), c->label,
                          umbra_status_to_string(st), msg);
        return SKIPPED;
    }
    accuracy_add_note(B, "%s: %s %s FAILED in %s (%s): %s", scene,
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

/* The scene's options with the setting's pre-integration, then the setting's shadow, set after
 * technique none so that the technique's state starts afresh: the memory a setting reports is
 * then its own, not also what an earlier setting left cached (the deep map keeps the segment
 * table of another light step, a draft's, for interaction auto). */
static umbra_status set_config(scene_ctx *S, const config *c)
{
    umbra_render_desc o = S->scene.options;
    o.preintegrated = c->preintegrated;
    umbra_status st = umbra_renderer_set_options(S->r, &o);
    umbra_shadow_desc none;
    umbra_shadow_desc_init(&none);
    none.technique = UMBRA_SHADOW_NONE;
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_shadow(S->r, &none);
    return st == UMBRA_SUCCESS ? umbra_renderer_set_shadow(S->r, &c->desc) : st;
}

/* Renders the error image into rgba (scene light), then the timed frames into scratch. */
static outcome measure(bench_run *B, scene_ctx *S, const char *scene, const config *c,
                       float *rgba, float *scratch, measurement *m)
{
    umbra_renderer r = S->r;
    uint32_t w = S->width, h = S->height;
    umbra_status st = set_config(S, c);
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
 * directory) after one. The cached render time is the one measured when the image was cached. */
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
    key = scene_hash_bytes(key, &c->desc.reference.step, sizeof c->desc.reference.step);
    const char *dev = umbra_context_device_name(B->ctx);
    key = scene_hash_bytes(key, dev, strlen(dev));
    char exr[4096], meta[4096];
    snprintf(exr, sizeof exr, "%s/%s-%016llx.exr", B->o.cache_dir, spec->name,
             (unsigned long long)key);
    snprintf(meta, sizeof meta, "%s/%s-%016llx.txt", B->o.cache_dir, spec->name,
             (unsigned long long)key);
    *cached = 0;
    if (B->o.cache && accuracy_file_exists(exr) && accuracy_file_exists(meta)) {
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
    umbra_status st = set_config(S, c);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_light(S->r, &S->light);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render(S->r, S->width, S->height, rgba);
    if (st != UMBRA_SUCCESS)
        return classify(B, st, spec->name, c, "the exact reference");
    umbra_render_stats s;
    umbra_renderer_get_stats(S->r, &s);
    *ms = s.render_ms;
    /* Written with --no-cache too: that option refreshes the cache (its help says so). Reading
     * it alone once left a stale cache behind, and the next cached sweep took reference times
     * measured on older code. */
    if (accuracy_mkdirs(B->o.cache_dir) == 0) {
        if (umbra_image_write(B->ctx, exr, S->width, S->height, rgba) == UMBRA_SUCCESS) {
            FILE *f = fopen(meta, "w");
            if (f) {
                fprintf(f, "render_ms %.6f\ndevice %s\ndate %s\nscene %s\nsize %ux%u\n"
                           "reference_step %g\n", s.render_ms, dev, B->started, spec->path,
                        S->width, S->height, c->desc.reference.step);
                fclose(f);
            }
        } else {
            accuracy_add_note(B, "%s: could not cache the reference: %s", spec->name,
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
    if (accuracy_mkdirs(dir) != 0)
        return;
    if (strcmp(c->params, "-") == 0)
        snprintf(name, sizeof name, "%s", umbra_shadow_technique_name(c->desc.technique));
    else
        snprintf(name, sizeof name, "%s-%s", umbra_shadow_technique_name(c->desc.technique),
                 c->params);
    accuracy_sanitize(name, 1);
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    if (umbra_image_write(B->ctx, path, w, h, rgba) != UMBRA_SUCCESS) {
        accuracy_add_note(B, "%s: could not write %s: %s", scene, path,
                          umbra_context_last_message(B->ctx));
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
        accuracy_add_note(B, "%s: the scene cannot be set up (%s): %s", spec->name,
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

void accuracy_run_scene(bench_run *B, int si)
{
    const scene_spec *spec = &B->scenes[si];
    config_list L;
    accuracy_scene_configs(&B->o, spec, &L);
    scene_ctx S;
    if (open_scene(B, si, &S) != 0) {
        B->run_index += L.count;
        return;
    }
    size_t px = (size_t)S.width * S.height;
    float *ref = malloc(px * 4 * sizeof *ref), *img = malloc(px * 4 * sizeof *img);
    float *scratch = malloc(px * 4 * sizeof *scratch);
    if (!ref || !img || !scratch) {
        accuracy_add_note(B, "%s: out of host memory for %ux%u images", spec->name, S.width,
                          S.height);
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
        accuracy_add_note(B, "%s: no exact reference, so no errors: scene skipped", spec->name);
        B->run_index += L.count - 1;
        goto done;
    }
    if (want_image(&B->o, &L.items[0]))
        save_image(B, spec->name, &L.items[0], S.width, S.height, ref);
    int first_row = B->result_count;
    result *exact = accuracy_new_result(B);
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
        half.desc.reference.step *= 0.5f;
        double half_ms = 0.0;
        int half_cached = 0;
        if (reference_image(B, &S, si, &half, scratch, &half_ms, &half_cached) == MEASURED &&
            metrics_compare(scratch, ref, S.width, S.height, &unc) == 0)
            fprintf(stderr, "accuracy: %s: reference at step %g vs %g: RMSE %.5f, max %.4f\n",
                    spec->name, L.items[0].desc.reference.step, half.desc.reference.step,
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
        result *row = accuracy_new_result(B);
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
        if (c->desc.map.size == UMBRA_MAP_SIZE_AUTO && row->map_size) /* "auto size (192²)" */
            snprintf(row->cfg.label + strlen(row->cfg.label),
                     sizeof row->cfg.label - strlen(row->cfg.label), " (%u²)", row->map_size);
        row->width = S.width;
        row->height = S.height;
        row->reference_ms = ref_ms;
        row->reference_cached = cached;
        if (metrics_compare(img, ref, S.width, S.height, &row->err) != 0) {
            accuracy_add_note(B, "%s: out of host memory while comparing images", spec->name);
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
        accuracy_add_note(B, "%s: no unshadowed frame, so no overhead ratios", spec->name);
done:
    free(ref);
    free(img);
    free(scratch);
    scene_ctx_release(&S);
}

