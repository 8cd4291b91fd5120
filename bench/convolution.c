// SPDX-License-Identifier: Apache-2.0
/* bench/convolution.c: `umbra-bench convolution`, the shape of Table 1 of the convolution-shadow
 * paper: slice distance 0.2-0.8 voxel x 0-3 sub-samples, with and without pre-integration; for
 * each setting the time per frame (median of the timed runs after warm-up: device time of the
 * whole frame, stats.render_ms) and the mean absolute pixel difference against
 *   finest     ICS at the smallest slice distance without sub-samples (the paper's reference,
 *              the bottom-left image of its Figure 4 and the 0.0 cell of Table 1), and
 *   reference  umbra's exact technique (a shadow ray per sample, reference step 0.25 voxel) on
 *              the same view, ray cast with a view step of the smallest slice distance.
 * Also timed, as the paper's baselines: the ray caster without shadows with Blinn-Phong shading.
 *
 * The scene (the paper's Figure 1): the carp CT, carp_half.nhdr (128 x 128 x 256) from
 * $UMBRA_DATA_DIR or ../shared/data/volumes, averaged down 2 x 2 x 2 to 64 x 64 x 128 so the whole
 * grid runs in a few minutes on a 2-core CPU device, with the transfer function of
 * bench/scenes/carp.tf (translucent flesh, opaque bone), seen from its side by a perspective
 * camera and lit from the viewer's side, 36 degrees off the view axis; cone angle 5 degrees, no
 * gradient shading (the shadows shade), no ground plane. Without the carp, the built-in "spheres"
 * scene at 64^3 stands in. Pixel differences are taken on the final linear RGB (over an opaque
 * dark background), averaged over all pixels and over the pixels the volume covers ("fg").
 *
 * Writes CSV to stdout and, with --results DIR (default bench/results in the source tree),
 * DIR/convolution.csv, DIR/convolution.md and a few PNGs (conv_*.png). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bench.h"
#include "internal.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

/* The control points of bench/scenes/carp.tf (kept in step with that file). */
static const umbra_tf_point carp_tf[] = {
    {0.00f, {0.00f, 0.00f, 0.00f, 0.000f}}, {0.28f, {0.85f, 0.55f, 0.40f, 0.000f}},
    {0.33f, {0.85f, 0.55f, 0.40f, 0.012f}}, {0.42f, {0.85f, 0.55f, 0.40f, 0.012f}},
    {0.47f, {0.95f, 0.93f, 0.85f, 0.350f}}, {1.00f, {0.95f, 0.93f, 0.85f, 0.600f}},
};

static const float distances[] = {0.2f, 0.4f, 0.6f, 0.8f};
enum { ND = 4, NS = 4 };

typedef struct options {
    int runs, warmup, downsample, images;
    uint32_t width, height;
    float cone;
    const char *volume, *results, *device;
    int spheres;
} options;

typedef struct row {
    char name[64];
    float dz;
    int n, pi;
    uint32_t slices;
    bench_timing t;
    double mae_finest, mae_ref, fg_finest, fg_ref;
} row;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench convolution [options]\n"
            "  --runs N         timed runs per setting (default 3), after\n"
            "  --warmup N       untimed warm-up runs (default 1)\n"
            "  --size WxH       image size (default 160x80; 128x128 for spheres)\n"
            "  --volume FILE    the carp (or another volume) instead of the default search\n"
            "  --downsample K   average K^3 voxel blocks first (default 2; 1 keeps the volume)\n"
            "  --spheres        the built-in spheres scene (64^3) instead of the carp\n"
            "  --cone DEG       convolution cone angle (default 5)\n"
            "  --results DIR    write DIR/convolution.{csv,md} and PNGs (default "
            "<source>/bench/results; '-' for none)\n"
            "  --no-images      no PNGs\n"
            "  --device SPEC    OpenCL device (P:D or a name substring)\n");
}

static int parse(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->runs = 3;
    o->warmup = 1;
    o->downsample = 2;
    o->images = 1;
    o->cone = 5.0f;
    o->results = UMBRA_SOURCE_DIR "/bench/results";
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        } else if (strcmp(a, "--runs") == 0 && v && !bench_parse_int(v, 1, 1000, &l)) {
            o->runs = (int)l;
            ++i;
        } else if (strcmp(a, "--warmup") == 0 && v && !bench_parse_int(v, 0, 1000, &l)) {
            o->warmup = (int)l;
            ++i;
        } else if (strcmp(a, "--downsample") == 0 && v && !bench_parse_int(v, 1, 8, &l)) {
            o->downsample = (int)l;
            ++i;
        } else if (strcmp(a, "--size") == 0 && v && !bench_parse_size(v, &o->width, &o->height)) {
            ++i;
        } else if (strcmp(a, "--cone") == 0 && v && !bench_parse_float(v, 0.0f, 60.0f, &o->cone)) {
            ++i;
        } else if (strcmp(a, "--volume") == 0 && v) {
            o->volume = argv[++i];
        } else if (strcmp(a, "--results") == 0 && v) {
            o->results = strcmp(v, "-") == 0 ? NULL : v;
            ++i;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = argv[++i];
        } else if (strcmp(a, "--spheres") == 0) {
            o->spheres = 1;
        } else if (strcmp(a, "--no-images") == 0) {
            o->images = 0;
        } else {
            fprintf(stderr, "umbra-bench convolution: bad option '%s'%s\n", a,
                    v ? "" : " (or missing value)");
            usage(stderr);
            return -1;
        }
    }
    return 0;
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* The carp averaged down k x k x k (normalised voxels read back from the device). */
static umbra_volume load_carp(umbra_context ctx, const char *path, int k, char *desc, size_t dn)
{
    umbra_volume full = NULL, out = NULL;
    float *v = NULL, *d = NULL;
    if (umbra_volume_load(ctx, path, &full) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench: %s\n", umbra_context_last_message(ctx));
        return NULL;
    }
    const uint32_t *n = full->dims;
    size_t count = (size_t)n[0] * n[1] * n[2];
    uint32_t m[3] = {n[0] / k, n[1] / k, n[2] / k};
    v = malloc(count * sizeof *v);
    d = malloc((size_t)m[0] * m[1] * m[2] * sizeof *d);
    if (!v || !d || umbra__volume_read_normalised(full, v) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench: reading %s back failed\n", path);
        goto done;
    }
    for (uint32_t z = 0; z < m[2]; ++z)
        for (uint32_t y = 0; y < m[1]; ++y)
            for (uint32_t x = 0; x < m[0]; ++x) {
                double s = 0.0;
                for (int c = 0; c < k * k * k; ++c) {
                    size_t xx = (size_t)x * k + c % k, yy = (size_t)y * k + (c / k) % k,
                           zz = (size_t)z * k + c / (k * k);
                    s += v[(zz * n[1] + yy) * n[0] + xx];
                }
                d[((size_t)z * m[1] + y) * m[0] + x] = (float)(s / (k * k * k));
            }
    umbra_volume_desc vd;
    umbra_volume_desc_init(&vd);
    vd.data = d;
    vd.type = UMBRA_FLOAT32;
    memcpy(vd.dims, m, sizeof m);
    for (int a = 0; a < 3; ++a)
        vd.spacing[a] = full->spacing[a] * (float)k;
    vd.value_range_given = 1;
    vd.value_min = 0.0f;
    vd.value_max = 1.0f;
    if (umbra_volume_create(ctx, &vd, &out) != UMBRA_SUCCESS)
        fprintf(stderr, "umbra-bench: %s\n", umbra_context_last_message(ctx));
    snprintf(desc, dn, "carp CT (%s) averaged %dx%dx%d to %u x %u x %u, spacing %g x %g x %g",
             path, k, k, k, m[0], m[1], m[2], vd.spacing[0], vd.spacing[1], vd.spacing[2]);
done:
    free(v);
    free(d);
    umbra_volume_release(full);
    return out;
}

static double mae(const float *a, const float *b, size_t pixels, const unsigned char *mask,
                  size_t *count)
{
    double s = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < pixels; ++i) {
        if (mask && !mask[i])
            continue;
        for (int c = 0; c < 3; ++c)
            s += fabs((double)a[4 * i + c] - b[4 * i + c]);
        ++n;
    }
    if (count)
        *count = n;
    return n ? s / (3.0 * n) : 0.0;
}

/* Renders `warmup + runs` frames, keeps the last image and the median device time. */
static int measure(umbra_renderer r, const options *o, float *img, bench_timing *t,
                   uint32_t *slices)
{
    double ms[1000];
    for (int k = 0; k < o->warmup + o->runs; ++k) {
        if (umbra_renderer_render(r, o->width, o->height, img) != UMBRA_SUCCESS)
            return -1;
        umbra_render_stats st;
        umbra_renderer_get_stats(r, &st);
        if (k >= o->warmup)
            ms[k - o->warmup] = st.render_ms;
        *slices = st.slices;
    }
    *t = bench_timing_of(ms, o->runs);
    return 0;
}

static void save(umbra_context ctx, const options *o, const char *name, const float *img)
{
    if (!o->results || !o->images)
        return;
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", o->results, name);
    if (umbra_image_write(ctx, path, o->width, o->height, img) != UMBRA_SUCCESS)
        fprintf(stderr, "umbra-bench: %s\n", umbra_context_last_message(ctx));
}

/* |a - b| * 10 over black, as the paper's Figure 4 (d). */
static void save_diff(umbra_context ctx, const options *o, const char *name, const float *a,
                      const float *b, float *tmp)
{
    size_t n = (size_t)o->width * o->height;
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c)
            tmp[4 * i + c] = fminf(1.0f, 10.0f * fabsf(a[4 * i + c] - b[4 * i + c]));
        tmp[4 * i + 3] = 1.0f;
    }
    save(ctx, o, name, tmp);
}

static void write_results(const options *o, const char *scene, const char *machine,
                          const char *device, const row *rows, int nrows, const row *base,
                          int nbase, size_t fg)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/convolution.csv", o->results);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "umbra-bench: cannot write %s\n", path);
        return;
    }
    fprintf(f, "case,slice_distance,subsamples,preintegrated,volume_step,slices,ms_median,ms_min,"
               "ms_max,mae_vs_finest,mae_vs_reference,mae_fg_vs_finest,mae_fg_vs_reference\n");
    for (int i = 0; i < nbase + nrows; ++i) {
        const row *q = i < nbase ? &base[i] : &rows[i - nbase];
        fprintf(f, "%s,%g,%d,%d,%g,%u,%.2f,%.2f,%.2f,%.5f,%.5f,%.5f,%.5f\n", q->name, q->dz, q->n,
                q->pi, q->n >= 0 ? q->dz / (q->n + 1) : q->dz, q->slices, q->t.median, q->t.min,
                q->t.max, q->mae_finest, q->mae_ref, q->fg_finest, q->fg_ref);
    }
    fclose(f);
    snprintf(path, sizeof path, "%s/convolution.md", o->results);
    f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "umbra-bench: cannot write %s\n", path);
        return;
    }
    fprintf(f, "# umbra-bench convolution\n\n"
               "The shape of Table 1 of the convolution-shadow paper (its Figure 4 scene was the "
               "carp too).\n\n"
               "- scene: %s\n- image: %u x %u, perspective, 30 degree field of view; light from the "
               "viewer's side, 36 degrees off the view axis; cone angle %g degrees; no gradient "
               "shading, no ground plane; %zu pixels covered by the volume (\"fg\")\n"
               "- machine: %s; device: %s\n"
               "- time: median device time of the whole frame over %d runs after %d warm-up\n"
               "- error: mean absolute difference of linear RGB in [0,1] over all pixels (fg: over "
               "the covered pixels); finest = ICS at 0.2 voxel, 0 sub-samples; reference = the exact "
               "technique (shadow rays, step 0.25) ray cast at 0.2 voxel\n\n",
            scene, o->width, o->height, o->cone, fg, machine, device, o->runs, o->warmup);
    for (int pi = 0; pi < 2; ++pi) {
        const char *title[3] = {"time per frame, ms: median (min)", "error vs finest (fg in brackets)",
                                "error vs reference (fg in brackets)"};
        for (int tab = 0; tab < 3; ++tab) {
            fprintf(f, "### %s ICS / SCS: %s\n\n| slice distance | 0 | 1 | 2 | 3 sub-samples |\n"
                       "|---|---|---|---|---|\n", pi ? "Pre-integrated" : "Plain", title[tab]);
            for (int di = 0; di < ND; ++di) {
                fprintf(f, "| %.1f |", distances[di]);
                for (int n = 0; n < NS; ++n) {
                    const row *q = &rows[(pi * ND + di) * NS + n];
                    if (tab == 0)
                        fprintf(f, " %.0f (%.0f) |", q->t.median, q->t.min);
                    else if (tab == 1)
                        fprintf(f, " %.4f (%.4f) |", q->mae_finest, q->fg_finest);
                    else
                        fprintf(f, " %.4f (%.4f) |", q->mae_ref, q->fg_ref);
                }
                fprintf(f, "\n");
            }
            fprintf(f, "\n");
        }
    }
    /* What each variant buys, from the numbers above: at the coarsest distance, and the cheapest
     * setting that is at least as close to the finest image as plain ICS at twice the finest
     * distance (the paper's way of reading Table 1: same quality, fewer convolutions). */
    const row *ics8 = &rows[(0 * ND + ND - 1) * NS], *scs8 = ics8 + NS - 1;
    const row *pics8 = &rows[(1 * ND + ND - 1) * NS], *pscs8 = pics8 + NS - 1;
    const row *ics4 = &rows[(0 * ND + 1) * NS], *best = ics4;
    for (int i = 0; i < nrows; ++i)
        if (rows[i].fg_finest <= ics4->fg_finest && rows[i].t.median < best->t.median)
            best = &rows[i];
    fprintf(f, "### What each variant buys (this run)\n\n"
               "- at %.1f voxel (%u slices): ICS %.0f ms, error vs finest %.4f (fg %.4f); SCS with "
               "3 sub-samples %.0f ms, %.4f (%.4f); pre-integrated ICS %.0f ms, %.4f (%.4f); "
               "pre-integrated SCS with 3 sub-samples %.0f ms, %.4f (%.4f). The finest setting "
               "takes %.0f ms.\n"
               "- the cheapest setting at least as close to the finest (fg) as ICS at %.1f voxel "
               "(%.0f ms, fg %.4f) is %s: %.0f ms, fg %.4f, %.2fx the speed of that ICS and %.2fx "
               "the speed of the finest.\n\n",
            distances[ND - 1], ics8->slices, ics8->t.median, ics8->mae_finest, ics8->fg_finest,
            scs8->t.median, scs8->mae_finest, scs8->fg_finest, pics8->t.median, pics8->mae_finest,
            pics8->fg_finest, pscs8->t.median, pscs8->mae_finest, pscs8->fg_finest,
            base[1].t.median, distances[1], ics4->t.median, ics4->fg_finest, best->name,
            best->t.median, best->fg_finest, ics4->t.median / best->t.median,
            base[1].t.median / best->t.median);
    fprintf(f, "### Baselines\n\n| case | ms | slices | error vs finest (fg) | error vs reference "
               "(fg) |\n|---|---|---|---|---|\n");
    for (int i = 0; i < nbase; ++i)
        fprintf(f, "| %s | %.0f | %u | %.4f (%.4f) | %.4f (%.4f) |\n", base[i].name,
                base[i].t.median, base[i].slices, base[i].mae_finest, base[i].fg_finest,
                base[i].mae_ref, base[i].fg_ref);
    fprintf(f, "\nPictures: conv_reference.png (exact), conv_finest.png (ICS 0.2), conv_ics_0.8.png, "
               "conv_scs_0.8_n3.png, conv_pi_ics_0.8.png, conv_pi_scs_0.8_n3.png, "
               "conv_phong.png (ray casting with Blinn-Phong, no shadows), and |difference| x 10 "
               "against the finest setting: conv_diff_ics_0.8.png, conv_diff_pi_scs_0.8_n3.png.\n");
    fclose(f);
    fprintf(stderr, "wrote %s/convolution.csv and %s/convolution.md\n", o->results, o->results);
}

int bench_convolution(int argc, char **argv)
{
    options o;
    if (parse(argc, argv, &o) != 0)
        return 2;
    int rc = 1;
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    umbra_scene sc;
    memset(&sc, 0, sizeof sc);
    umbra_volume vol = NULL;
    umbra_transfer_function tf = NULL;
    umbra_renderer r = NULL;
    float *finest = NULL, *ref = NULL, *img = NULL, *tmp = NULL;
    unsigned char *mask = NULL;
    char scene[1400], machine[512], device[512];
    umbra_camera cam;
    umbra_light light;
    memset(&light, 0, sizeof light);
    light.type = UMBRA_LIGHT_DIRECTIONAL;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;

    char path[1024] = "";
    const char *dd = getenv("UMBRA_DATA_DIR");
    if (o.volume) {
        snprintf(path, sizeof path, "%s", o.volume);
    } else {
        const char *where[3] = {"%s/carp_half.nhdr", "%s/volumes/carp_half.nhdr",
                                "%s/../shared/data/volumes/carp_half.nhdr"};
        for (int i = 0; i < 3; ++i) {
            const char *dir = i < 2 ? dd : UMBRA_SOURCE_DIR;
            if (!dir || !*dir)
                continue;
            snprintf(path, sizeof path, where[i], dir);
            if (exists(path))
                break;
        }
    }
    if (!o.spheres && !exists(path)) {
        if (o.volume) {
            fprintf(stderr, "umbra-bench: volume %s does not exist\n", o.volume);
            goto done;
        }
        fprintf(stderr, "umbra-bench: carp_half.nhdr not found; using the spheres scene\n");
        o.spheres = 1;
    }
    if (o.spheres) {
        if (umbra_scene_create(ctx, "spheres", 64, &sc) != UMBRA_SUCCESS)
            goto done;
        vol = sc.volume;
        tf = sc.tf;
        cam = sc.camera;
        light.direction[0] = -0.3f;
        light.direction[1] = -1.0f;
        light.direction[2] = -0.6f;
        snprintf(scene, sizeof scene, "built-in spheres, 64^3, with its banded transfer function");
        if (!o.width)
            o.width = o.height = 128;
    } else {
        if (!(vol = load_carp(ctx, path, o.downsample, scene, sizeof scene)))
            goto done;
        if (umbra_transfer_function_create_from_points(ctx, carp_tf, 6, 256, &tf) != UMBRA_SUCCESS)
            goto done;
        if (!o.width) {
            o.width = 160;
            o.height = 80;
        }
        /* From the fish's side (y), x up, far enough for its length (z) to fill 90% of the
         * width. */
        umbra_volume_info info;
        umbra_volume_get_info(vol, &info);
        const float dir[3] = {0.15f, 1.0f, 0.2f}, tan_half = tanf(15.0f * 3.14159265f / 180.0f);
        float len = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        float dist = 0.5f * info.extent[2] / 0.9f / (tan_half * (float)o.width / o.height) +
                     0.5f * info.extent[1];
        memset(&cam, 0, sizeof cam);
        cam.projection = UMBRA_PERSPECTIVE;
        for (int a = 0; a < 3; ++a) { /* around the box's world centre (0 unless transformed) */
            cam.eye[a] = info.center[a] + dir[a] / len * dist;
            cam.target[a] = info.center[a];
        }
        cam.up[0] = 1.0f;
        cam.fovy_degrees = 30.0f;
        light.direction[0] = -0.7f;
        light.direction[1] = -0.7f;
        light.direction[2] = -0.1f;
    }
    bench_cpu_model(machine, sizeof machine);
    bench_device_description(ctx, device, sizeof device);
    fprintf(stderr, "scene: %s\nimage %u x %u, device %s\n", scene, o.width, o.height, device);

    const size_t px = (size_t)o.width * o.height;
    finest = malloc(px * 16);
    ref = malloc(px * 16);
    img = malloc(px * 16);
    tmp = malloc(px * 16);
    mask = malloc(px);
    if (!finest || !ref || !img || !tmp || !mask) {
        fprintf(stderr, "umbra-bench: out of memory\n");
        goto done;
    }
    umbra_render_desc rd;
    umbra_render_desc_init(&rd);
    rd.step = distances[0];
    rd.ambient[0] = rd.ambient[1] = rd.ambient[2] = 0.25f;
    rd.background[0] = 0.08f;
    rd.background[1] = 0.08f;
    rd.background[2] = 0.1f;
    rd.background[3] = 1.0f;
    rd.transmission = o.spheres ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    if (umbra_renderer_create(ctx, &r) != UMBRA_SUCCESS || umbra_renderer_set_volume(r, vol) ||
        umbra_renderer_set_transfer_function(r, tf) || umbra_renderer_set_camera(r, &cam) ||
        umbra_renderer_set_light(r, &light) || umbra_renderer_set_options(r, &rd))
        goto done;
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    row base[3];
    memset(base, 0, sizeof base);
    uint32_t slices = 0;

    /* The exact reference and the finest setting first: everything is measured against them. */
    sd.technique = UMBRA_SHADOW_REFERENCE;
    sd.reference.step = 0.25f;
    if (umbra_renderer_set_shadow(r, &sd) || measure(r, &o, ref, &base[0].t, &slices))
        goto done;
    snprintf(base[0].name, sizeof base[0].name, "reference");
    base[0].dz = distances[0];
    base[0].n = -1;
    sd.technique = UMBRA_SHADOW_CONVOLUTION;
    sd.convolution.slice_distance = distances[0];
    sd.convolution.cone_angle_degrees = o.cone;
    if (umbra_renderer_set_shadow(r, &sd) || measure(r, &o, finest, &base[1].t, &base[1].slices))
        goto done;
    size_t fg = 0;
    for (size_t i = 0; i < px; ++i) {
        double d = 0.0;
        for (int c = 0; c < 3; ++c)
            d += fabs(finest[4 * i + c] - rd.background[c]) + fabs(ref[4 * i + c] - rd.background[c]);
        mask[i] = d > 1e-3;
    }
    base[0].mae_finest = mae(ref, finest, px, NULL, NULL);
    base[0].fg_finest = mae(ref, finest, px, mask, &fg);
    snprintf(base[1].name, sizeof base[1].name, "finest_ics_0.2");
    base[1].dz = distances[0];
    base[1].mae_ref = mae(finest, ref, px, NULL, NULL);
    base[1].fg_ref = mae(finest, ref, px, mask, NULL);
    save(ctx, &o, "conv_reference.png", ref);
    save(ctx, &o, "conv_finest.png", finest);

    /* Baseline: ray casting with Blinn-Phong, no shadows (the paper's Figure 1 (a)). */
    rd.shading = 1;
    rd.step = 0.5f;
    sd.technique = UMBRA_SHADOW_NONE;
    if (umbra_renderer_set_options(r, &rd) || umbra_renderer_set_shadow(r, &sd) ||
        measure(r, &o, img, &base[2].t, &slices))
        goto done;
    snprintf(base[2].name, sizeof base[2].name, "raycast_phong_0.5");
    base[2].dz = 0.5f;
    base[2].n = -1;
    base[2].mae_finest = mae(img, finest, px, NULL, NULL);
    base[2].fg_finest = mae(img, finest, px, mask, NULL);
    base[2].mae_ref = mae(img, ref, px, NULL, NULL);
    base[2].fg_ref = mae(img, ref, px, mask, NULL);
    save(ctx, &o, "conv_phong.png", img);
    rd.shading = 0;
    if (umbra_renderer_set_options(r, &rd))
        goto done;

    printf("case,slice_distance,subsamples,preintegrated,slices,ms_median,mae_vs_finest,"
           "mae_vs_reference\n");
    for (int i = 0; i < 3; ++i)
        printf("%s,%g,%d,0,%u,%.2f,%.5f,%.5f\n", base[i].name, base[i].dz, base[i].n,
               base[i].slices, base[i].t.median, base[i].mae_finest, base[i].mae_ref);
    row rows[2 * ND * NS];
    memset(rows, 0, sizeof rows);
    sd.technique = UMBRA_SHADOW_CONVOLUTION;
    for (int pi = 0; pi < 2; ++pi)
        for (int di = 0; di < ND; ++di)
            for (int n = 0; n < NS; ++n) {
                row *q = &rows[(pi * ND + di) * NS + n];
                q->dz = distances[di];
                q->n = n;
                q->pi = pi;
                snprintf(q->name, sizeof q->name, "%s%s_%.1f_n%d", pi ? "pi_" : "",
                         n ? "scs" : "ics", q->dz, n);
                sd.convolution.slice_distance = q->dz;
                sd.convolution.subsamples = (uint32_t)n;
                rd.preintegrated = pi;
                if (umbra_renderer_set_options(r, &rd) || umbra_renderer_set_shadow(r, &sd) ||
                    measure(r, &o, img, &q->t, &q->slices))
                    goto done;
                q->mae_finest = mae(img, finest, px, NULL, NULL);
                q->fg_finest = mae(img, finest, px, mask, NULL);
                q->mae_ref = mae(img, ref, px, NULL, NULL);
                q->fg_ref = mae(img, ref, px, mask, NULL);
                printf("%s,%g,%d,%d,%u,%.2f,%.5f,%.5f\n", q->name, q->dz, n, pi, q->slices,
                       q->t.median, q->mae_finest, q->mae_ref);
                fflush(stdout);
                if (di == ND - 1 && (n == 0 || n == 3)) {
                    char name[64];
                    snprintf(name, sizeof name, "conv_%s%s_0.8%s.png", pi ? "pi_" : "",
                             n ? "scs" : "ics", n ? "_n3" : "");
                    save(ctx, &o, name, img);
                    if ((pi == 0 && n == 0) || (pi == 1 && n == 3))
                        save_diff(ctx, &o, pi ? "conv_diff_pi_scs_0.8_n3.png" : "conv_diff_ics_0.8.png",
                                  img, finest, tmp);
                }
            }
    if (o.results)
        write_results(&o, scene, machine, device, rows, 2 * ND * NS, base, 3, fg);
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "umbra-bench convolution: %s\n", umbra_context_last_message(ctx));
    free(finest);
    free(ref);
    free(img);
    free(tmp);
    free(mask);
    umbra_renderer_release(r);
    if (o.spheres) {
        umbra_scene_release(&sc);
    } else {
        umbra_transfer_function_release(tf);
        umbra_volume_release(vol);
    }
    umbra_context_release(ctx);
    return rc;
}
