// SPDX-License-Identifier: Apache-2.0
/* bench/interactive.c: `umbra-bench interactive`, what a shadow costs per frame in an interactive
 * session.
 *
 * For each scene (bench/scenes/walnut.scene and bonsai.scene by default), shading on and off, and
 * each light-space technique (threshold, CSSM, deep; map size auto unless --map-size says), four
 * sequences of frames:
 *   camera  the camera orbits the target 3 degrees a frame; light and transfer function stay, so
 *           the shadow map is built once and re-used;
 *   light   the light orbits the box's centre about the vertical 3 degrees a frame: every frame
 *           rebuilds the map;
 *   opacity the transfer function's opacity is scaled by a factor that changes every frame (a
 *           new transfer function each frame, set on the renderer): the light pass uses it, so
 *           every frame rebuilds the map, and the view tables are rebuilt as well;
 *   light-auto the light orbits as in light on a renderer with progressive shadows
 *           (umbra_render_desc.interaction UMBRA_INTERACTION_AUTO): every frame builds the
 *           technique's draft (umbra_technique_info.draft; the threshold map has none and builds
 *           its full map). After the timed frames one more frame with nothing changed builds the
 *           full map: its time is reported (stop ms) and its image is compared, bit for bit, with
 *           a fresh renderer's full render of the same view (stop identical).
 * A frame's time is the host wall clock of umbra_renderer_render (build, render and read-back of
 * the image: what an application waits for). The unshadowed frame of the same view is rendered by
 * a second renderer (technique none) on the same volume in turn with the shadowed one, frame by
 * frame, so a ratio compares frames taken under the same load. The shadow build's part of each
 * shadowed frame (umbra_render_stats.shadow_build_ms) is reported beside it: on PoCL a frame's
 * time is the build plus the ray caster to within a millisecond or two (no host step of a
 * rebuild costs more). Warm-up frames (kernel builds,
 * tables, the first map) are not timed. Results: CSV on stdout, commentary on stderr; --results
 * DIR also writes DIR/interactive.csv and DIR/interactive.md. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "scene_file.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

#define MAX_ROWS 64
#define STEP_DEGREES 3.0f
#define QUICK_MAX_SIDE 192u

typedef struct options {
    char scenes[256], techniques[128], sequences[128], scene_dir[1024];
    int frames, warmup, quick;
    uint32_t width, height;   /* 0: the scene's size (capped at QUICK_MAX_SIDE with --quick) */
    uint32_t map_size;        /* UMBRA_MAP_SIZE_AUTO by default */
    const char *results, *device;
} options;

typedef enum sequence { SEQ_CAMERA, SEQ_LIGHT, SEQ_OPACITY, SEQ_LIGHT_AUTO, SEQ_COUNT } sequence;
static const char *const sequence_names[SEQ_COUNT] = {"camera", "light", "opacity", "light-auto"};

typedef struct row {
    char scene[SCENE_NAME_MAX];
    int shading;
    umbra_shadow_technique technique;
    sequence seq;
    uint32_t map_lo, map_hi, width, height; /* map sizes seen over the timed frames */
    bench_timing shadowed, none;
    bench_timing build; /* the shadow build's share of the shadowed frames (stats.shadow_build_ms) */
    int drafts;         /* timed frames that used the technique's draft (stats.draft) */
    double stop_ms;     /* light-auto: the frame after the light stopped (the full map), else 0 */
    int stop_identical; /* light-auto: that frame equals a fresh renderer's bit for bit (1), or
                           not (0); -1 for the other sequences */
} row;

/* Everything one scene's sequences share: the volume, the scene's transfer function (its table
 * is scaled for the opacity sequence), and the two renderers. */
typedef struct session {
    umbra_context ctx;
    umbra_scene scene;
    umbra_transfer_function light_tf; /* the scene's separate light tf, or NULL */
    umbra_renderer shadowed, none;
    float center[3];
    uint32_t width, height;
    float *image;
} session;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench interactive [options]\n"
            "  per scene, shading on and off, and technique: frames in which the camera orbits\n"
            "  (map cached), the light orbits (map rebuilt), the opacity changes (map and\n"
            "  tables rebuilt) and the light orbits with progressive shadows (interaction auto:\n"
            "  draft maps, then the full map once the light stops); median and max ms per\n"
            "  frame, each over the unshadowed frame\n"
            "  --quick          3 frames, 1 warm-up, images capped at 192 pixels\n"
            "  --frames N       timed frames per sequence (default 24)\n"
            "  --warmup N       untimed frames before them (default 2)\n"
            "  --size WxH       image size (default: the scene's)\n"
            "  --scenes A,B     scene files' stems (default walnut,bonsai)\n"
            "  --techniques A,B (default: every light-space map)\n"
            "  --sequences A,B  (default camera,light,opacity,light-auto)\n"
            "  --map-size auto|N  map size of the light-space techniques (default auto)\n"
            "  --scene-dir DIR  scene files (default <source>/bench/scenes)\n"
            "  --results DIR    also write DIR/interactive.csv and DIR/interactive.md\n"
            "  --device SPEC    OpenCL device (P:D or a name substring)\n");
}

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 24;
    o->warmup = 2;
    snprintf(o->scenes, sizeof o->scenes, "walnut,bonsai");
    /* Every light-space map of the registry (threshold, cssm, deep). */
    o->techniques[0] = '\0';
    for (uint32_t t = 0; t < umbra_technique_count(); ++t)
        if (umbra_technique_get(t)->flags & UMBRA_TECHNIQUE_MAP) {
            size_t n = strlen(o->techniques);
            snprintf(o->techniques + n, sizeof o->techniques - n, "%s%s", n ? "," : "",
                     umbra_technique_get(t)->name);
        }
    snprintf(o->sequences, sizeof o->sequences, "camera,light,opacity,light-auto");
    snprintf(o->scene_dir, sizeof o->scene_dir, "%s/bench/scenes", UMBRA_SOURCE_DIR);
    int frames_given = 0, warmup_given = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 1;
        } else if (strcmp(a, "--quick") == 0) {
            o->quick = 1;
            continue;
        } else if (strcmp(a, "--frames") == 0 && v && !bench_parse_int(v, 1, 10000, &l)) {
            o->frames = (int)l;
            frames_given = 1;
        } else if (strcmp(a, "--warmup") == 0 && v && !bench_parse_int(v, 1, 100, &l)) {
            o->warmup = (int)l;
            warmup_given = 1;
        } else if (strcmp(a, "--size") == 0 && v && !bench_parse_size(v, &o->width, &o->height)) {
        } else if (strcmp(a, "--scenes") == 0 && v) {
            snprintf(o->scenes, sizeof o->scenes, "%s", v);
        } else if (strcmp(a, "--techniques") == 0 && v) {
            snprintf(o->techniques, sizeof o->techniques, "%s", v);
        } else if (strcmp(a, "--sequences") == 0 && v) {
            snprintf(o->sequences, sizeof o->sequences, "%s", v);
        } else if (strcmp(a, "--map-size") == 0 && v &&
                   (strcmp(v, "auto") == 0 || !bench_parse_int(v, 16, 8192, &l))) {
            o->map_size = strcmp(v, "auto") == 0 ? UMBRA_MAP_SIZE_AUTO : (uint32_t)l;
        } else if (strcmp(a, "--scene-dir") == 0 && v) {
            snprintf(o->scene_dir, sizeof o->scene_dir, "%s", v);
        } else if (strcmp(a, "--results") == 0 && v) {
            o->results = v;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
        } else {
            fprintf(stderr, "umbra-bench interactive: bad option '%s'%s%s\n", a, v ? " " : "",
                    v ? v : "");
            usage(stderr);
            return -1;
        }
        ++i; /* every option but the flags takes a value */
    }
    if (o->quick) {
        if (!frames_given)
            o->frames = 3;
        if (!warmup_given)
            o->warmup = 1;
    }
    return 0;
}

/* Rotates p about the vertical axis through c by deg degrees. */
static void rotate_y(float p[3], const float c[3], float deg)
{
    float a = deg * 3.14159265f / 180.0f, s = sinf(a), k = cosf(a);
    float x = p[0] - c[0], z = p[2] - c[2];
    p[0] = c[0] + k * x + s * z;
    p[2] = c[2] - s * x + k * z;
}

/* The scene's transfer function with every alpha times scale (at most 1), over the same range. */
static umbra_status scaled_tf(umbra_context ctx, umbra_transfer_function tf, float scale,
                              umbra_transfer_function *out)
{
    uint32_t n = umbra_transfer_function_size(tf);
    float *rgba = malloc((size_t)n * 4 * sizeof *rgba), range[2];
    if (!rgba)
        return UMBRA_ERROR_OUT_OF_MEMORY;
    memcpy(rgba, umbra_transfer_function_data(tf), (size_t)n * 4 * sizeof *rgba);
    for (uint32_t i = 0; i < n; ++i)
        rgba[4 * i + 3] = fminf(1.0f, rgba[4 * i + 3] * scale);
    umbra_status st = umbra_transfer_function_create(ctx, rgba, n, out);
    free(rgba);
    if (st == UMBRA_SUCCESS && umbra_transfer_function_get_range(tf, range))
        st = umbra_transfer_function_set_range(*out, range[0], range[1]);
    return st;
}

/* Frame i of a sequence on both renderers (shadowed first, then none), each timed. */
static umbra_status frame(session *S, sequence seq, int i, double *ms_shadowed, double *ms_none)
{
    umbra_status st = UMBRA_SUCCESS;
    umbra_camera cam = S->scene.camera;
    umbra_light light = S->scene.light;
    umbra_transfer_function tf = NULL;
    if (seq == SEQ_CAMERA) {
        rotate_y(cam.eye, cam.target, STEP_DEGREES * (float)i);
    } else if (seq == SEQ_LIGHT || seq == SEQ_LIGHT_AUTO) {
        float zero[3] = {0.0f, 0.0f, 0.0f};
        if (light.type == UMBRA_LIGHT_DIRECTIONAL)
            rotate_y(light.direction, zero, STEP_DEGREES * (float)(i + 1));
        else
            rotate_y(light.position, S->center, STEP_DEGREES * (float)(i + 1));
    } else {
        /* Opacity between 0.8x and 1.2x, never the same twice in a row. */
        float scale = 1.0f + 0.2f * sinf(0.9f * (float)(i + 1));
        if ((st = scaled_tf(S->ctx, S->scene.tf, scale, &tf)) != UMBRA_SUCCESS)
            return st;
    }
    umbra_renderer rs[2] = {S->shadowed, S->none};
    double *ms[2] = {ms_shadowed, ms_none};
    for (int k = 0; k < 2 && st == UMBRA_SUCCESS; ++k) {
        double t0 = bench_now_ms();
        st = umbra_renderer_set_camera(rs[k], &cam);
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_set_light(rs[k], &light);
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_set_transfer_function(rs[k], tf ? tf : S->scene.tf);
        if (st == UMBRA_SUCCESS)
            st = umbra_renderer_render(rs[k], S->width, S->height, S->image);
        *ms[k] = bench_now_ms() - t0;
    }
    umbra_transfer_function_release(tf);
    return st;
}

/* The shadow of a sequence: the technique at map_size, its other parameters the defaults. */
static umbra_shadow_desc shadow_for(umbra_shadow_technique t, uint32_t map_size)
{
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = t;
    sd.map.size = map_size;
    return sd;
}

static umbra_status renderer_for(session *S, umbra_shadow_technique t, uint32_t map_size,
                                 umbra_renderer *out)
{
    const umbra_shadow_desc sd = shadow_for(t, map_size);
    umbra_status st = umbra_renderer_create(S->ctx, out);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_volume(*out, S->scene.volume);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_transfer_function(*out, S->scene.tf);
    if (st == UMBRA_SUCCESS && S->light_tf)
        st = umbra_renderer_set_light_transfer_function(*out, S->light_tf);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_options(*out, &S->scene.options);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_shadow(*out, &sd);
    return st;
}

/* light-auto: the frame after the light stopped at frame `last`'s position (nothing changed, so
 * the full map), timed, and a fresh renderer's full render of the same view; r gets the time
 * and whether the two images are the same bit for bit. */
static umbra_status stop_frame(session *S, const options *o, umbra_shadow_technique t,
                               int last, row *r)
{
    const size_t bytes = (size_t)S->width * S->height * 4 * sizeof(float);
    float *fresh_img = malloc(bytes);
    umbra_renderer fresh = NULL;
    umbra_status st = fresh_img ? UMBRA_SUCCESS : UMBRA_ERROR_OUT_OF_MEMORY;
    umbra_light light = S->scene.light;
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    if (light.type == UMBRA_LIGHT_DIRECTIONAL)
        rotate_y(light.direction, zero, STEP_DEGREES * (float)(last + 1));
    else
        rotate_y(light.position, S->center, STEP_DEGREES * (float)(last + 1));
    double t0 = bench_now_ms();
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render(S->shadowed, S->width, S->height, S->image);
    r->stop_ms = bench_now_ms() - t0;
    umbra_render_stats stats;
    if (st == UMBRA_SUCCESS && (st = umbra_renderer_get_stats(S->shadowed, &stats)) ==
                                   UMBRA_SUCCESS && stats.draft)
        st = UMBRA_ERROR_INVALID_ARGUMENT; /* the frame after the light stopped must be full */
    if (st == UMBRA_SUCCESS)
        st = renderer_for(S, t, o->map_size, &fresh);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_camera(fresh, &S->scene.camera);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_light(fresh, &light);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render(fresh, S->width, S->height, fresh_img);
    if (st == UMBRA_SUCCESS)
        r->stop_identical = memcmp(S->image, fresh_img, bytes) == 0;
    umbra_renderer_release(fresh);
    free(fresh_img);
    return st;
}

/* One sequence of one technique: warm-up frames, then the timed ones, into r. */
static umbra_status run_sequence(session *S, const options *o, sequence seq, row *r)
{
    int n = o->warmup + o->frames;
    double *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b);
    double *c = malloc((size_t)n * sizeof *c);
    umbra_status st = a && b && c ? UMBRA_SUCCESS : UMBRA_ERROR_OUT_OF_MEMORY;
    r->map_lo = UINT32_MAX;
    for (int i = 0; i < n && st == UMBRA_SUCCESS; ++i) {
        umbra_render_stats stats;
        st = frame(S, seq, i, &a[i], &b[i]);
        if (st == UMBRA_SUCCESS &&
            (st = umbra_renderer_get_stats(S->shadowed, &stats)) == UMBRA_SUCCESS)
            c[i] = stats.shadow_build_ms;
        if (st == UMBRA_SUCCESS && i >= o->warmup) {
            r->map_lo = stats.map_size < r->map_lo ? stats.map_size : r->map_lo;
            r->map_hi = stats.map_size > r->map_hi ? stats.map_size : r->map_hi;
            r->drafts += stats.draft != 0;
        }
    }
    r->stop_identical = -1;
    if (st == UMBRA_SUCCESS) {
        r->shadowed = bench_timing_of(a + o->warmup, o->frames);
        r->none = bench_timing_of(b + o->warmup, o->frames);
        r->build = bench_timing_of(c + o->warmup, o->frames);
    }
    free(a);
    free(b);
    free(c);
    return st;
}

/* All sequences of one scene file, shading on and off, appended to rows. */
static int run_scene(umbra_context ctx, const options *o, const char *name, row *rows, int *nrows)
{
    char path[1400], data[1024], err[512];
    scene_spec spec;
    session S;
    memset(&S, 0, sizeof S);
    S.ctx = ctx;
    snprintf(path, sizeof path, "%s/%s.scene", o->scene_dir, name);
    scene_data_dir(UMBRA_SOURCE_DIR, data, sizeof data);
    if (scene_parse_file(path, data, &spec, err, sizeof err) != 0) {
        fprintf(stderr, "umbra-bench interactive: %s\n", err);
        return 1;
    }
    if (!scene_volume_present(&spec)) {
        fprintf(stderr, "umbra-bench interactive: %s: volume %s is missing; skipped\n", name,
                spec.volume);
        return 0;
    }
    umbra_status st = scene_create(ctx, &spec, &S.scene, &S.light_tf);
    umbra_volume_info info;
    if (st == UMBRA_SUCCESS && (st = umbra_volume_get_info(S.scene.volume, &info)) == UMBRA_SUCCESS)
        memcpy(S.center, info.center, sizeof S.center);
    S.width = o->width ? o->width : spec.width ? spec.width : 512;
    S.height = o->width ? o->height : spec.height ? spec.height : 512;
    if (o->quick && !o->width) {
        uint32_t side = S.width > S.height ? S.width : S.height;
        if (side > QUICK_MAX_SIDE) {
            S.width = S.width * QUICK_MAX_SIDE / side;
            S.height = S.height * QUICK_MAX_SIDE / side;
        }
    }
    S.image = malloc((size_t)S.width * S.height * 4 * sizeof(float));
    if (!S.image)
        st = UMBRA_ERROR_OUT_OF_MEMORY;
    /* The light-space maps of the registry, in its order. */
    umbra_shadow_technique techs[32];
    int ntechs = 0;
    for (uint32_t t = 0; t < umbra_technique_count() && ntechs < 32; ++t)
        if (umbra_technique_get(t)->flags & UMBRA_TECHNIQUE_MAP)
            techs[ntechs++] = umbra_technique_get(t)->id;
    for (int shading = 1; shading >= 0 && st == UMBRA_SUCCESS; --shading) {
        S.scene.options.shading = shading;
        for (int t = 0; t < ntechs && st == UMBRA_SUCCESS; ++t) {
            if (!bench_in_list(o->techniques, umbra_shadow_technique_name(techs[t])))
                continue;
            if ((st = renderer_for(&S, techs[t], o->map_size, &S.shadowed)) == UMBRA_SUCCESS)
                st = renderer_for(&S, UMBRA_SHADOW_NONE, 0, &S.none);
            for (int q = 0; q < SEQ_COUNT && st == UMBRA_SUCCESS && *nrows < MAX_ROWS; ++q) {
                if (!bench_in_list(o->sequences, sequence_names[q]))
                    continue;
                if (q == SEQ_LIGHT_AUTO) {
                    /* The last sequence: progressive shadows on for it. */
                    umbra_render_desc auto_opts = S.scene.options;
                    auto_opts.interaction = UMBRA_INTERACTION_AUTO;
                    if ((st = umbra_renderer_set_options(S.shadowed, &auto_opts)) !=
                        UMBRA_SUCCESS)
                        break;
                }
                row *r = &rows[*nrows];
                memset(r, 0, sizeof *r);
                snprintf(r->scene, sizeof r->scene, "%s", name);
                r->shading = shading;
                r->technique = techs[t];
                r->seq = (sequence)q;
                r->width = S.width;
                r->height = S.height;
                fprintf(stderr, "interactive: %s, shading %s, %s, %s ...\n", name,
                        shading ? "on" : "off", umbra_shadow_technique_name(techs[t]),
                        sequence_names[q]);
                st = run_sequence(&S, o, (sequence)q, r);
                if (st == UMBRA_SUCCESS && q == SEQ_LIGHT_AUTO)
                    st = stop_frame(&S, o, techs[t], o->warmup + o->frames - 1, r);
                if (st == UMBRA_SUCCESS)
                    ++*nrows;
            }
            umbra_renderer_release(S.shadowed);
            umbra_renderer_release(S.none);
            S.shadowed = S.none = NULL;
        }
    }
    if (st != UMBRA_SUCCESS)
        fprintf(stderr, "umbra-bench interactive: %s: %s: %s\n", name, umbra_status_to_string(st),
                umbra_context_last_message(ctx));
    free(S.image);
    umbra_transfer_function_release(S.light_tf);
    umbra_scene_release(&S.scene);
    return st == UMBRA_SUCCESS ? 0 : 1;
}

/* ---- the report -------------------------------------------------------------------------------- */

#define CSV_HEADER                                                                                 \
    "scene,shading,technique,sequence,map_min,map_max,width,height,frames,ms_median,ms_max,"             \
    "none_ms_median,none_ms_max,over_none_median,over_none_max,build_ms_median,build_ms_max,"        \
    "drafts,stop_ms,stop_identical"

static void csv_rows(FILE *f, const row *rows, int n)
{
    fprintf(f, "%s\n", CSV_HEADER);
    for (int i = 0; i < n; ++i) {
        const row *r = &rows[i];
        fprintf(f, "%s,%s,%s,%s,%u,%u,%u,%u,%d,%.2f,%.2f,%.2f,%.2f,%.3f,%.3f,%.2f,%.2f,%d,", r->scene,
                r->shading ? "on" : "off", umbra_shadow_technique_name(r->technique),
                sequence_names[r->seq], r->map_lo, r->map_hi, r->width, r->height, r->shadowed.runs,
                r->shadowed.median, r->shadowed.max, r->none.median, r->none.max,
                r->shadowed.median / r->none.median, r->shadowed.max / r->none.max,
                r->build.median, r->build.max, r->drafts);
        if (r->stop_identical >= 0)
            fprintf(f, "%.2f,%s\n", r->stop_ms, r->stop_identical ? "yes" : "no");
        else
            fprintf(f, ",\n");
    }
}

static int write_results(const options *o, int argc, char **argv, umbra_context ctx,
                         const row *rows, int n)
{
    char device[600];
    bench_device_description(ctx, device, sizeof device);
    FILE *f = bench_results_open(o->results, "interactive", "csv");
    if (!f)
        return -1;
    csv_rows(f, rows, n);
    fclose(f);
    if (!(f = bench_results_open(o->results, "interactive", "md")))
        return -1;
    bench_results_header(f, "interactive", argc, argv, device);
    fprintf(f, "- per sequence %d timed frames after %d warm-up frames; a frame is the wall time "
               "of umbra_renderer_render (build, render, read-back); the unshadowed frame of the "
               "same view is rendered in turn with it (bench/interactive.c)\n\n",
            o->frames, o->warmup);
    fprintf(f, "ms per frame, median / max, and over the unshadowed frame (median over median, "
               "max over max). camera: the camera orbits, the map is cached; light: the light "
               "orbits, every frame rebuilds; opacity: the transfer function changes every "
               "frame; light-auto: the light orbits on a renderer with interaction auto, so "
               "every frame builds the technique's draft (umbra_technique_info.draft; the "
               "threshold map has none), and drafts counts the timed frames that did. build: the "
               "shadow build's part of the shadowed frame "
               "(umbra_render_stats.shadow_build_ms, device time; 0 where the map is re-used): "
               "the rest of a frame is the ray caster and the read-back. stop: light-auto's "
               "frame after the light stopped (the full map) and whether its image equals a "
               "fresh renderer's full render bit for bit.\n\n");
    fprintf(f, "| scene | shading | technique | map | sequence | ms median | ms max | none "
               "median | none max | × median | × max | build median | drafts | stop ms | stop "
               "identical |\n"
               "|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    for (int i = 0; i < n; ++i) {
        const row *r = &rows[i];
        char map[32];
        if (r->map_lo == r->map_hi)
            snprintf(map, sizeof map, "%u²", r->map_lo);
        else
            snprintf(map, sizeof map, "%u²–%u²", r->map_lo, r->map_hi);
        char stop[64] = "| – | –";
        if (r->stop_identical >= 0)
            snprintf(stop, sizeof stop, "| %.1f | %s", r->stop_ms,
                     r->stop_identical ? "yes" : "**no**");
        fprintf(f, "| %s | %s | %s | %s | %s | %.1f | %.1f | %.1f | %.1f | %.2f× | %.2f× | %.1f "
                   "| %d %s |\n",
                r->scene, r->shading ? "on" : "off", umbra_shadow_technique_name(r->technique),
                map, sequence_names[r->seq], r->shadowed.median, r->shadowed.max,
                r->none.median, r->none.max, r->shadowed.median / r->none.median,
                r->shadowed.max / r->none.max, r->build.median, r->drafts, stop);
    }
    fclose(f);
    fprintf(stderr, "wrote %s/interactive.csv and %s/interactive.md\n", o->results, o->results);
    return 0;
}

int bench_interactive(int argc, char **argv)
{
    options o;
    int rc = parse_options(argc, argv, &o);
    if (rc != 0)
        return rc > 0 ? 0 : 2;
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
