// SPDX-License-Identifier: Apache-2.0
/* bench/features.c: `umbra-bench features`, the costs of the volume-rendering features of #31
 * (docs/features.md quotes them):
 *   clip_*      a frame (render_ms, the view pass) and a shadow build (shadow_build_ms) of the
 *               threshold map with nothing clipped (the renderer never told), with clipping set
 *               and cleared again, with 1 and 6 planes that keep everything (the cost of the
 *               tests alone), and with a plane and a crop box that each keep half the volume;
 *   mode_*      the composite frame (technique none) beside MIP, MinIP and average projection;
 *   channels_*  a frame (technique none) and a threshold-map build of 1, 2 and 4 channels,
 *               and a label map, of the same grid;
 *   update_*    the wall time of a new time step (umbra_volume_update of the whole volume, then
 *               a render: the shadow map rebuilds) and of a 16^3 sub-box update, against a fresh
 *               volume and renderer made and rendered from the same voxels (what an application
 *               without umbra_volume_update does for a time series); and the update call alone
 *               against umbra_volume_create alone.
 * The volume is procedural (gaussian blobs whose centres move with the time step, uint8, N^3,
 * default 128), so no data file is needed. Each round takes one sample of every row in turn, so
 * load on the machine falls on all rows alike; a build row's light alternates between two
 * directions 1 degree apart, so every render rebuilds. Medians over --frames rounds after
 * --warmup rounds (the first launch of each kernel compiles it). CSV on stdout, commentary on
 * stderr; --results DIR also writes DIR/features.csv and DIR/features.md. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"


#define MAX_FRAMES 200

typedef struct options {
    uint32_t n, width, height;
    int frames, warmup;
    const char *results, *device;
} options;

static void usage(FILE *f)
{
    fprintf(f, "usage: umbra-bench features [options]\n"
               "  the cost of clipping, projection modes, channels, label maps and volume updates\n"
               "  --frames N      timed rounds (default 9)\n"
               "  --warmup N      untimed rounds before them (default 2)\n"
               "  --volume N      a procedural N^3 uint8 volume (default 128; 32..512)\n"
               "  --size WxH      image size (default 256x256)\n"
               "  --results DIR   also write DIR/features.csv and DIR/features.md\n"
               "  --device SPEC   OpenCL device (P:D or a name substring)\n");
}

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->n = 128;
    o->width = o->height = 256;
    o->frames = 9;
    o->warmup = 2;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 1;
        } else if (strcmp(a, "--frames") == 0 && v && !bench_parse_int(v, 1, MAX_FRAMES, &l)) {
            o->frames = (int)l;
        } else if (strcmp(a, "--warmup") == 0 && v && !bench_parse_int(v, 0, 100, &l)) {
            o->warmup = (int)l;
        } else if (strcmp(a, "--volume") == 0 && v && !bench_parse_int(v, 32, 512, &l)) {
            o->n = (uint32_t)l;
        } else if (strcmp(a, "--size") == 0 && v && !bench_parse_size(v, &o->width, &o->height)) {
        } else if (strcmp(a, "--results") == 0 && v) {
            o->results = v;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
        } else {
            fprintf(stderr, "umbra-bench features: bad option '%s'%s%s\n", a, v ? " " : "",
                    v ? v : "");
            usage(stderr);
            return -1;
        }
        ++i; /* every option takes a value */
    }
    return 0;
}

/* Time step t of the procedural volume: channel c of `channels`, interleaved as umbra takes them
 * (channel fastest); each channel has its own blobs. With labels, the blob index (1..) where a
 * blob is above half its peak, else 0. */
static uint8_t *make_voxels(uint32_t n, uint32_t channels, int labels, int t)
{
    uint8_t *v = malloc((size_t)n * n * n * channels);
    if (!v)
        return NULL;
    enum { BLOBS = 6 };
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x)
                for (uint32_t c = 0; c < channels; ++c) {
                    float best = 0.0f, sum = 0.0f;
                    int which = 0;
                    for (int b = 0; b < BLOBS; ++b) {
                        float ph = 1.7f * (float)b + 0.9f * (float)c + 0.15f * (float)t;
                        float cx = 0.5f + 0.28f * sinf(ph), cy = 0.5f + 0.28f * cosf(1.3f * ph),
                              cz = 0.5f + 0.28f * sinf(0.7f * ph + 1.0f);
                        float dx = (float)x / (float)n - cx, dy = (float)y / (float)n - cy,
                              dz = (float)z / (float)n - cz;
                        float g = expf(-(dx * dx + dy * dy + dz * dz) / (2.0f * 0.012f));
                        sum += g;
                        if (g > best)
                            best = g, which = b + 1;
                    }
                    size_t i = (((size_t)z * n + y) * n + x) * channels + c;
                    v[i] = labels ? (uint8_t)(best > 0.5f ? which : 0)
                                  : (uint8_t)fminf(255.0f, 255.0f * sum);
                }
    return v;
}

static umbra_volume make_volume(umbra_context ctx, uint32_t n, uint32_t channels, int labels,
                                const uint8_t *voxels)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = voxels;
    d.type = UMBRA_UINT8;
    d.dims[0] = d.dims[1] = d.dims[2] = n;
    d.value_range_given = !labels;
    d.value_min = 0.0f;
    d.value_max = 255.0f;
    d.channels = channels;
    d.labels = labels;
    umbra_volume v = NULL;
    return umbra_volume_create(ctx, &d, &v) == UMBRA_SUCCESS ? v : NULL;
}

/* A renderer of volume with tf on every channel, the technique and mode given, clip (or NULL). */
static umbra_renderer make_renderer(umbra_context ctx, umbra_volume vol,
                                    umbra_transfer_function tf, umbra_shadow_technique technique,
                                    umbra_render_mode mode, const umbra_clip_desc *clip)
{
    umbra_renderer r = NULL;
    if (umbra_renderer_create(ctx, &r) != UMBRA_SUCCESS)
        return NULL;
    umbra_volume_info info;
    umbra_volume_get_info(vol, &info);
    float diag = sqrtf(3.0f) * info.extent[0];
    const float dir[3] = {0.35f, 0.25f, 1.0f};
    umbra_camera cam = umbra_camera_orbit_at(info.center, dir, 1.5f * diag, 30.0f);
    umbra_light light;
    memset(&light, 0, sizeof light);
    light.type = UMBRA_LIGHT_DIRECTIONAL;
    light.direction[0] = 0.3f, light.direction[1] = -1.0f, light.direction[2] = 0.2f;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;
    umbra_render_desc rd;
    umbra_render_desc_init(&rd);
    rd.mode = mode;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = technique;
    umbra_status st = umbra_renderer_set_volume(r, vol);
    for (uint32_t c = 0; c < info.channels && !st; ++c)
        st = umbra_renderer_set_channel_transfer_function(r, c, tf, NULL);
    if (!st)
        st = umbra_renderer_set_camera(r, &cam);
    if (!st)
        st = umbra_renderer_set_light(r, &light);
    if (!st)
        st = umbra_renderer_set_options(r, &rd);
    if (!st)
        st = umbra_renderer_set_shadow(r, &sd);
    if (!st && clip)
        st = umbra_renderer_set_clip(r, clip);
    if (st) {
        umbra_renderer_release(r);
        return NULL;
    }
    return r;
}

/* A row: a renderer drawn each round, timed by its render_ms or shadow_build_ms; or an update. */
typedef enum kind {
    FRAME,
    BUILD,
    UPDATE_STEP,  /* a new time step and the frame that shows it */
    UPDATE_BOX,   /* a 16^3 sub-box and the frame */
    FRESH,        /* a new volume and renderer and their first frame */
    UPDATE_ALONE, /* a new time step of a volume no renderer draws: the call alone */
    CREATE_ALONE  /* umbra_volume_create of the same voxels alone */
} kind;
typedef struct row {
    const char *name;
    kind kind;
    umbra_renderer r;
    int base; /* the row its `over` ratio divides by */
    double ms[MAX_FRAMES];
    bench_timing t;
} row;

enum { MAX_ROWS = 32 };

static void add_row(row *rows, int *n, const char *name, kind k, umbra_renderer r, int base)
{
    row *w = &rows[(*n)++];
    w->name = name;
    w->kind = k;
    w->r = r;
    w->base = base;
}

int bench_features(int argc, char **argv)
{
    options o;
    int pr = parse_options(argc, argv, &o);
    if (pr)
        return pr > 0 ? 0 : 2;
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    int rc = 1;
    const uint32_t n = o.n;
    uint8_t *step[2] = {make_voxels(n, 1, 0, 0), make_voxels(n, 1, 0, 1)};
    uint8_t *ch2 = make_voxels(n, 2, 0, 0), *ch4 = make_voxels(n, 4, 0, 0);
    uint8_t *lab = make_voxels(n, 1, 1, 0);
    float *rgba = malloc((size_t)o.width * o.height * 4 * sizeof(float));
    uint8_t *box = malloc(16 * 16 * 16);
    umbra_volume vol = NULL, vol2 = NULL, vol4 = NULL, vlab = NULL, vupd = NULL, valone = NULL;
    umbra_transfer_function tf = NULL, ltf = NULL;
    row rows[MAX_ROWS];
    int nrows = 0;
    memset(rows, 0, sizeof rows);
    if (!step[0] || !step[1] || !ch2 || !ch4 || !lab || !rgba || !box) {
        fprintf(stderr, "umbra-bench features: out of memory\n");
        goto done;
    }
    const umbra_tf_point pts[] = {{0.0f, {1, 1, 1, 0}},
                                  {0.15f, {0.9f, 0.6f, 0.3f, 0}},
                                  {0.5f, {0.9f, 0.6f, 0.3f, 0.08f}},
                                  {1.0f, {1, 0.95f, 0.9f, 0.4f}}};
    /* Labels 1..6: a colour each, opacity 0.3 per voxel. */
    float ltable[8 * 4] = {0};
    for (int i = 1; i < 8; ++i) {
        ltable[4 * i + 0] = (float)(i & 1), ltable[4 * i + 1] = (float)((i >> 1) & 1);
        ltable[4 * i + 2] = (float)((i >> 2) & 1), ltable[4 * i + 3] = 0.3f;
    }
    vol = make_volume(ctx, n, 1, 0, step[0]);
    vol2 = make_volume(ctx, n, 2, 0, ch2);
    vol4 = make_volume(ctx, n, 4, 0, ch4);
    vlab = make_volume(ctx, n, 1, 1, lab);
    vupd = make_volume(ctx, n, 1, 0, step[0]);
    valone = make_volume(ctx, n, 1, 0, step[0]);
    if (!vol || !vol2 || !vol4 || !vlab || !vupd || !valone ||
        umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf) != UMBRA_SUCCESS ||
        umbra_transfer_function_create(ctx, ltable, 8, &ltf) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench features: %s\n", umbra_context_last_message(ctx));
        goto done;
    }

    /* Clip regions: nothing; 1 and 6 planes keeping the whole box (each > 0 everywhere in it);
     * a plane through the centre; a crop box of the lower half. */
    const float far = 4.0f * (float)n;
    umbra_clip_desc none, keep1, keep6, half_plane, half_crop;
    umbra_clip_desc_init(&none);
    umbra_clip_desc_init(&keep1);
    keep1.plane_count = 1;
    keep1.planes[0][1] = 1.0f, keep1.planes[0][3] = far;
    umbra_clip_desc_init(&keep6);
    keep6.plane_count = 6;
    for (int p = 0; p < 6; ++p) {
        keep6.planes[p][p / 2] = p % 2 ? -1.0f : 1.0f;
        keep6.planes[p][3] = far;
    }
    umbra_clip_desc_init(&half_plane);
    half_plane.plane_count = 1;
    half_plane.planes[0][0] = -1.0f, half_plane.planes[0][1] = -0.3f;
    umbra_clip_desc_init(&half_crop);
    half_crop.crop = 1;
    for (int a = 0; a < 3; ++a)
        half_crop.crop_min[a] = -0.5f, half_crop.crop_max[a] = (float)n - 0.5f;
    half_crop.crop_max[1] = 0.5f * (float)n - 0.5f;

    const struct {
        const char *frame, *build;
        const umbra_clip_desc *clip;
    } clips[] = {{"clip_unset_frame", "clip_unset_build", NULL},
                 {"clip_cleared_frame", "clip_cleared_build", &none},
                 {"clip_keep1_frame", "clip_keep1_build", &keep1},
                 {"clip_keep6_frame", "clip_keep6_build", &keep6},
                 {"clip_half_plane_frame", "clip_half_plane_build", &half_plane},
                 {"clip_half_crop_frame", "clip_half_crop_build", &half_crop}};
    for (size_t i = 0; i < sizeof clips / sizeof clips[0]; ++i) {
        add_row(rows, &nrows, clips[i].frame, FRAME,
                make_renderer(ctx, vol, tf, UMBRA_SHADOW_THRESHOLD, UMBRA_RENDER_COMPOSITE,
                              clips[i].clip),
                0);
        add_row(rows, &nrows, clips[i].build, BUILD,
                make_renderer(ctx, vol, tf, UMBRA_SHADOW_THRESHOLD, UMBRA_RENDER_COMPOSITE,
                              clips[i].clip),
                1);
    }
    /* "cleared": set and then cleared, as an application that turns clipping off. */
    umbra_renderer_set_clip(rows[2].r, &half_plane);
    umbra_renderer_set_clip(rows[2].r, NULL);
    umbra_renderer_set_clip(rows[3].r, &half_plane);
    umbra_renderer_set_clip(rows[3].r, NULL);
    const umbra_render_mode COMPOSITE = UMBRA_RENDER_COMPOSITE;
    const struct {
        const char *name;
        umbra_volume *v;
        umbra_shadow_technique t;
        umbra_render_mode m;
        int labels, base; /* base: the index in frames[] of the row it is compared with */
    } frames[] = {{"mode_composite", &vol, UMBRA_SHADOW_NONE, UMBRA_RENDER_COMPOSITE, 0, 0},
                  {"mode_mip", &vol, UMBRA_SHADOW_NONE, UMBRA_RENDER_MIP, 0, 0},
                  {"mode_minip", &vol, UMBRA_SHADOW_NONE, UMBRA_RENDER_MINIP, 0, 0},
                  {"mode_average", &vol, UMBRA_SHADOW_NONE, UMBRA_RENDER_AVERAGE, 0, 0},
                  {"channels_1_none", &vol, UMBRA_SHADOW_NONE, UMBRA_RENDER_COMPOSITE, 0, 4},
                  {"channels_2_none", &vol2, UMBRA_SHADOW_NONE, UMBRA_RENDER_COMPOSITE, 0, 4},
                  {"channels_4_none", &vol4, UMBRA_SHADOW_NONE, UMBRA_RENDER_COMPOSITE, 0, 4},
                  {"labels_none", &vlab, UMBRA_SHADOW_NONE, UMBRA_RENDER_COMPOSITE, 1, 4},
                  {"channels_1_threshold_build", &vol, UMBRA_SHADOW_THRESHOLD, COMPOSITE, 0, 8},
                  {"channels_2_threshold_build", &vol2, UMBRA_SHADOW_THRESHOLD, COMPOSITE, 0, 8},
                  {"channels_4_threshold_build", &vol4, UMBRA_SHADOW_THRESHOLD, COMPOSITE, 0, 8},
                  {"labels_threshold_build", &vlab, UMBRA_SHADOW_THRESHOLD, COMPOSITE, 1, 8}};
    const int first_frame = nrows;
    for (size_t i = 0; i < sizeof frames / sizeof frames[0]; ++i)
        add_row(rows, &nrows, frames[i].name,
                frames[i].t == UMBRA_SHADOW_THRESHOLD ? BUILD : FRAME,
                make_renderer(ctx, *frames[i].v, frames[i].labels ? ltf : tf, frames[i].t,
                              frames[i].m, NULL),
                first_frame + frames[i].base);
    /* The updates with their frame over a fresh volume and renderer with its first frame; the
     * update call alone over umbra_volume_create alone. */
    const int fresh = nrows + 2;
    add_row(rows, &nrows, "update_timestep", UPDATE_STEP,
            make_renderer(ctx, vupd, tf, UMBRA_SHADOW_THRESHOLD, COMPOSITE, NULL), fresh);
    add_row(rows, &nrows, "update_box16", UPDATE_BOX,
            make_renderer(ctx, vupd, tf, UMBRA_SHADOW_THRESHOLD, COMPOSITE, NULL), fresh);
    add_row(rows, &nrows, "fresh_volume_renderer", FRESH, NULL, fresh);
    add_row(rows, &nrows, "update_timestep_alone", UPDATE_ALONE, NULL, nrows + 1);
    add_row(rows, &nrows, "create_volume_alone", CREATE_ALONE, NULL, nrows);
    for (int i = 0; i < nrows; ++i)
        if (!rows[i].r && rows[i].kind < FRESH) {
            fprintf(stderr, "umbra-bench features: %s: %s\n", rows[i].name,
                    umbra_context_last_message(ctx));
            goto done;
        }

    char device[512];
    bench_device_description(ctx, device, sizeof device);
    fprintf(stderr, "umbra-bench features: %u^3 uint8 procedural volume, %ux%u image, %d rounds "
            "after %d warm-up, on %s\n", n, o.width, o.height, o.frames, o.warmup, device);
    umbra_light lights[2];
    memset(lights, 0, sizeof lights);
    for (int k = 0; k < 2; ++k) {
        float a = (float)k * 3.14159265f / 180.0f;
        lights[k].type = UMBRA_LIGHT_DIRECTIONAL;
        lights[k].direction[0] = 0.3f * cosf(a) + 0.2f * sinf(a);
        lights[k].direction[1] = -1.0f;
        lights[k].direction[2] = -0.3f * sinf(a) + 0.2f * cosf(a);
        lights[k].color[0] = lights[k].color[1] = lights[k].color[2] = 1.0f;
    }
    int t_step = 0; /* the time step vupd holds */
    for (int round = 0; round < o.warmup + o.frames; ++round) {
        const int timed = round - o.warmup;
        for (int i = 0; i < nrows; ++i) {
            row *w = &rows[i];
            umbra_status st = UMBRA_SUCCESS;
            umbra_render_stats s;
            double t0 = bench_now_ms(), ms = 0.0;
            if (w->kind == BUILD)
                st = umbra_renderer_set_light(w->r, &lights[round & 1]);
            if (w->kind == UPDATE_STEP) {
                /* The next time step: all voxels, then the frame that shows it. */
                t_step ^= 1;
                umbra_volume_update_desc u;
                umbra_volume_update_desc_init(&u);
                u.data = step[t_step];
                t0 = bench_now_ms();
                st = umbra_volume_update(vupd, &u);
            } else if (w->kind == UPDATE_BOX) {
                memset(box, (round & 1) ? 200 : 20, 16 * 16 * 16);
                umbra_volume_update_desc u;
                umbra_volume_update_desc_init(&u);
                u.data = box;
                for (int a = 0; a < 3; ++a)
                    u.origin[a] = n / 2 - 8, u.size[a] = 16;
                t0 = bench_now_ms();
                st = umbra_volume_update(vupd, &u);
            } else if (w->kind == FRESH) {
                /* What an application without updates does for the next time step. */
                t0 = bench_now_ms();
                umbra_volume v = make_volume(ctx, n, 1, 0, step[t_step]);
                umbra_renderer r =
                    v ? make_renderer(ctx, v, tf, UMBRA_SHADOW_THRESHOLD, COMPOSITE, NULL) : NULL;
                st = r ? umbra_renderer_render(r, o.width, o.height, rgba)
                       : UMBRA_ERROR_OUT_OF_MEMORY;
                ms = bench_now_ms() - t0;
                umbra_renderer_release(r);
                umbra_volume_release(v);
            } else if (w->kind == UPDATE_ALONE) {
                umbra_volume_update_desc u;
                umbra_volume_update_desc_init(&u);
                u.data = step[round & 1];
                t0 = bench_now_ms();
                st = umbra_volume_update(valone, &u);
                ms = bench_now_ms() - t0;
            } else if (w->kind == CREATE_ALONE) {
                t0 = bench_now_ms();
                umbra_volume v = make_volume(ctx, n, 1, 0, step[round & 1]);
                ms = bench_now_ms() - t0;
                st = v ? UMBRA_SUCCESS : UMBRA_ERROR_OUT_OF_MEMORY;
                umbra_volume_release(v);
            }
            if (!st && w->kind < FRESH)
                st = umbra_renderer_render(w->r, o.width, o.height, rgba);
            if (st) {
                fprintf(stderr, "umbra-bench features: %s: %s\n", w->name,
                        umbra_context_last_message(ctx));
                goto done;
            }
            umbra_renderer_get_stats(w->r ? w->r : rows[0].r, &s);
            if (w->kind == FRAME)
                ms = s.render_ms;
            else if (w->kind == BUILD)
                ms = s.shadow_build_ms;
            else if (w->kind < FRESH)
                ms = bench_now_ms() - t0;
            if (timed >= 0)
                w->ms[timed] = ms;
        }
    }
    for (int i = 0; i < nrows; ++i)
        rows[i].t = bench_timing_of(rows[i].ms, o.frames);

    FILE *csv = o.results ? bench_results_open(o.results, "features", "csv") : NULL;
    FILE *md = o.results ? bench_results_open(o.results, "features", "md") : NULL;
    printf("%s,over,over_min\n", BENCH_CSV_HEADER);
    if (csv)
        fprintf(csv, "%s,over,over_min\n", BENCH_CSV_HEADER);
    if (md) {
        bench_results_header(md, "features", argc, argv, device);
        fprintf(md, "- volume: %u^3 uint8, procedural (gaussian blobs); image %ux%u; medians of "
                "%d rounds after %d warm-up\n\n"
                "Frame rows: the view pass's device time (render_ms); build rows: the threshold "
                "map's build (shadow_build_ms); update and fresh rows: wall time of the update "
                "(or of making the volume and renderer) and the render that shows it. `over`: "
                "the row's median over its group's first row's; `over min`: the same of the minima "
                "(less disturbed by other load on the machine).\n\n"
                "| case | median ms | min | max | over | over min |\n"
                "|---|---:|---:|---:|---:|---:|\n",
                n, o.width, o.height, o.frames, o.warmup);
    }
    for (int i = 0; i < nrows; ++i) {
        const int base = rows[i].base;
        const bench_timing *t = &rows[i].t, *b = &rows[base].t;
        double over = t->median / (b->median > 0 ? b->median : 1);
        double over_min = t->min / (b->min > 0 ? b->min : 1);
        printf("%s,%.3f,,,%.3f,%.3f,%.3f,%.3f\n", rows[i].name, t->median, t->min, t->max, over,
               over_min);
        if (csv)
            fprintf(csv, "%s,%.3f,,,%.3f,%.3f,%.3f,%.3f\n", rows[i].name, t->median, t->min,
                    t->max, over, over_min);
        if (md)
            fprintf(md, "| %s | %.3f | %.3f | %.3f | %.3f | %.3f |\n", rows[i].name, t->median,
                    t->min, t->max, over, over_min);
    }
    if (csv)
        fclose(csv);
    if (md)
        fclose(md);
    rc = 0;
done:
    for (int i = 0; i < nrows; ++i)
        umbra_renderer_release(rows[i].r);
    umbra_volume_release(vol);
    umbra_volume_release(vol2);
    umbra_volume_release(vol4);
    umbra_volume_release(vlab);
    umbra_volume_release(vupd);
    umbra_volume_release(valone);
    umbra_transfer_function_release(tf);
    umbra_transfer_function_release(ltf);
    free(step[0]);
    free(step[1]);
    free(ch2);
    free(ch4);
    free(lab);
    free(rgba);
    free(box);
    umbra_context_release(ctx);
    return rc;
}
