// SPDX-License-Identifier: Apache-2.0
/* bench/device/time_techniques.c: absolute frame and build times of every shadow technique on a
 * built-in scene, on whatever OpenCL device UMBRA_DEVICE (or the default choice) gives.
 *
 * It needs libumbra alone (no umbra_io, no data files), so it builds on a machine that has only a
 * compiler, CMake and an OpenCL loader: bench/device/run.sh builds the core there and runs it.
 * Per technique: one warm-up frame (kernels compile on first launch), then `frames` frames with the
 * camera orbiting (the shadow structure is reused) and `frames` with the light orbiting (rebuilt
 * every frame); medians of the wall time per frame and of the stats' build and render times.
 * Usage: time_techniques [scene] [resolution] [width] [height] [frames] */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "umbra/umbra.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The scene's light turned by angle (radians) about the vertical axis. */
static umbra_light turned(umbra_light l, float angle)
{
    float c = cosf(angle), s = sinf(angle);
    float *v = l.type == UMBRA_LIGHT_POINT ? l.position : l.direction;
    float x = v[0], z = v[2];
    v[0] = c * x + s * z;
    v[2] = -s * x + c * z;
    return l;
}

int main(int argc, char **argv)
{
    const char *scene_name = argc > 1 ? argv[1] : "spheres";
    uint32_t res = argc > 2 ? (uint32_t)strtoul(argv[2], NULL, 10) : 128;
    uint32_t w = argc > 3 ? (uint32_t)strtoul(argv[3], NULL, 10) : 512;
    uint32_t h = argc > 4 ? (uint32_t)strtoul(argv[4], NULL, 10) : 512;
    int frames = argc > 5 ? atoi(argv[5]) : 5;
    if (res < 8 || res > 1024 || w < 8 || w > 8192 || h < 8 || h > 8192 || frames < 1 ||
        frames > 100) {
        fprintf(stderr, "time_techniques: bad arguments\n");
        return 1;
    }
    umbra_context ctx = NULL;
    umbra_scene scene = {0};
    umbra_renderer r = NULL;
    float *rgba = malloc((size_t)w * h * 4 * sizeof *rgba);
    double *wall = malloc(sizeof(double) * 4 * (size_t)frames);
    umbra_status st = rgba && wall ? umbra_context_create(NULL, &ctx) : UMBRA_ERROR_OUT_OF_MEMORY;
    if (!st) st = umbra_scene_create(ctx, scene_name, res, &scene);
    if (!st) st = umbra_renderer_create(ctx, &r);
    if (!st) st = umbra_renderer_set_volume(r, scene.volume);
    if (!st) st = umbra_renderer_set_transfer_function(r, scene.tf);
    if (!st) st = umbra_renderer_set_options(r, &scene.options);
    if (st) {
        fprintf(stderr, "time_techniques: %s: %s\n", umbra_status_to_string(st),
                ctx ? umbra_context_last_message(ctx) : "");
        return 2;
    }
    printf("device: %s\numbra %s, scene %s %u^3, %ux%u, medians of %d frames after a warm-up\n\n",
           umbra_context_device_name(ctx), umbra_version(), scene_name, res, w, h, frames);
    printf("| technique | camera orbit: frame ms | light orbit: frame ms | build ms (stats) | "
           "render ms (stats) | shadow memory MiB |\n|---|---|---|---|---|---|\n");
    /* Every technique of the registry, in its order. */
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = ti->id;
        umbra_render_stats stats;
        double *cam = wall, *lit = wall + frames, *build = wall + 2 * frames,
               *render = wall + 3 * frames;
        umbra_camera c0 = scene.camera;
        umbra_light l0 = scene.light;
        if (ti->flags & UMBRA_TECHNIQUE_FRAME) {
            /* Slices carry light front to back: a directional light from behind the viewer,
             * tilted 30 degrees downwards, within the technique's 80 degrees. */
            float d[3], up = 0.577f, n = 0.0f;
            for (int k = 0; k < 3; ++k) {
                d[k] = c0.target[k] - c0.eye[k];
                n += d[k] * d[k];
            }
            n = sqrtf(n);
            l0.type = UMBRA_LIGHT_DIRECTIONAL;
            for (int k = 0; k < 3; ++k)
                l0.direction[k] = d[k] / n - (k == 1 ? up : 0.0f);
        }
        st = umbra_renderer_set_shadow(r, &sd);
        if (!st) st = umbra_renderer_set_camera(r, &c0);
        if (!st) st = umbra_renderer_set_light(r, &l0);
        if (!st) st = umbra_renderer_render(r, w, h, rgba); /* warm-up: compiles the kernels */
        for (int i = 0; !st && i < frames; ++i) {
            /* Small camera steps about the vertical axis: the light (and map) stay. */
            umbra_camera c = c0;
            float a = 0.02f * (float)(i + 1), x = c.eye[0], z = c.eye[2];
            c.eye[0] = cosf(a) * x + sinf(a) * z;
            c.eye[2] = -sinf(a) * x + cosf(a) * z;
            double t0 = now_ms();
            st = umbra_renderer_set_camera(r, &c);
            if (!st) st = umbra_renderer_render(r, w, h, rgba);
            cam[i] = now_ms() - t0;
        }
        if (!st) st = umbra_renderer_set_camera(r, &c0);
        for (int i = 0; !st && i < frames; ++i) {
            umbra_light l = turned(l0, 0.02f * (float)(i + 1));
            double t0 = now_ms();
            st = umbra_renderer_set_light(r, &l);
            if (!st) st = umbra_renderer_render(r, w, h, rgba);
            lit[i] = now_ms() - t0;
            if (!st) st = umbra_renderer_get_stats(r, &stats);
            build[i] = stats.shadow_build_ms;
            render[i] = stats.render_ms;
        }
        if (st) {
            printf("| %s | failed: %s: %s | | | | |\n", ti->name,
                   umbra_status_to_string(st), umbra_context_last_message(ctx));
            umbra_context_take_error(ctx, NULL);
            continue;
        }
        printf("| %s | %.2f | %.2f | %.2f | %.2f | %.1f |\n", ti->name,
               median(cam, frames), median(lit, frames), median(build, frames),
               median(render, frames), stats.shadow_memory_bytes / 1048576.0);
        fflush(stdout);
    }
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    umbra_context_release(ctx);
    free(rgba);
    free(wall);
    return 0;
}
