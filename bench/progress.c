// SPDX-License-Identifier: Apache-2.0
/* bench/progress.c: `umbra-bench progress`, how often a long render reports and how soon a
 * cancel takes effect (issue #28 item 5), on the reference technique: every view sample marches
 * a shadow ray, the costliest work-item umbra has.
 *
 * The scene is the built-in spheres (128^3, the CLI's default), lit and framed as umbra-render
 * draws it. For each reference step (--steps, default 0.25 and 0.05):
 *   overhead  a --overhead-size frame (default 128^2) rendered without a progress callback and
 *             with one that never cancels, alternately, --runs times each: the medians, their
 *             ratio (what the bands cost), the number of reports and the longest time between
 *             two reports;
 *   cancel    a --size frame (default 512^2) whose callback cancels once a timer thread, started
 *             with the render, has asked for it after T seconds (--cancel-at, default 5,15,30; the
 *             first rows of the image are background, so the earliest ask rarely finds a costly
 *             band): the time from that request to the render's return, and the longest time
 *             between two reports until then.
 * A warm-up render of each kind first compiles what the timed ones use. CSV on stdout, commentary
 * on stderr. */
#define _POSIX_C_SOURCE 200809L

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"

#define MAX_LIST 8

typedef struct options {
    float steps[MAX_LIST];
    int nsteps;
    float cancel_at[MAX_LIST];
    int ncancel;
    uint32_t size, overhead_size;
    int runs;
    const char *device;
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench progress [options]\n"
            "  --steps S,S,...      reference shadow steps in voxels (default 0.25,0.05)\n"
            "  --size N             image side of the cancel runs (default 512)\n"
            "  --cancel-at T,T,...  seconds after the start at which a cancel is asked for\n"
            "                       (default 5,15,30)\n"
            "  --overhead-size N    image side of the runs with and without a callback (128)\n"
            "  --runs N             runs of each for the overhead medians (default 3)\n"
            "  --device SPEC        OpenCL device: P:D indices or a name substring\n");
}

static int parse_list(const char *s, float lo, float hi, float *out, int *n)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    *n = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        if (*n == MAX_LIST || bench_parse_float(tok, lo, hi, &out[*n]) != 0)
            return -1;
        ++*n;
    }
    return *n ? 0 : -1;
}

static int parse(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->steps[0] = 0.25f;
    o->steps[1] = 0.05f;
    o->nsteps = 2;
    o->cancel_at[0] = 5.0f;
    o->cancel_at[1] = 15.0f;
    o->cancel_at[2] = 30.0f;
    o->ncancel = 3;
    o->size = 512;
    o->overhead_size = 128;
    o->runs = 3;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long n;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        } else if (strcmp(a, "--steps") == 0 && v) {
            if (parse_list(v, 0.01f, 64.0f, o->steps, &o->nsteps))
                return -1;
        } else if (strcmp(a, "--cancel-at") == 0 && v) {
            if (parse_list(v, 0.0f, 3600.0f, o->cancel_at, &o->ncancel))
                return -1;
        } else if ((strcmp(a, "--size") == 0 || strcmp(a, "--overhead-size") == 0) && v) {
            if (bench_parse_int(v, 1, 16384, &n))
                return -1;
            *(a[2] == 's' ? &o->size : &o->overhead_size) = (uint32_t)n;
        } else if (strcmp(a, "--runs") == 0 && v) {
            if (bench_parse_int(v, 1, 1000, &n))
                return -1;
            o->runs = (int)n;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
        } else {
            fprintf(stderr, "umbra-bench progress: unknown or incomplete option %s\n", a);
            return -1;
        }
        ++i;
    }
    return 0;
}

/* What the callback sees: reports, the longest time between two (from the start), and the
 * cancel request a timer thread sets. */
typedef struct watch {
    double start, last, longest, asked;
    int reports;
    atomic_int cancel;
} watch;

static int on_progress(void *user, float fraction)
{
    (void)fraction;
    watch *w = user;
    double t = bench_now_ms();
    if (t - w->last > w->longest)
        w->longest = t - w->last;
    w->last = t;
    w->reports++;
    return atomic_load(&w->cancel);
}

typedef struct timer {
    watch *w;
    double after_ms;
} timer;

static void *ask_cancel(void *user)
{
    timer *t = user;
    const long ms = (long)t->after_ms;
    struct timespec ts = {(time_t)(ms / 1000), (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
    t->w->asked = bench_now_ms();
    atomic_store(&t->w->cancel, 1);
    return NULL;
}

/* One render of side n, with the callback when w is not NULL; *ms: its wall time. */
static umbra_status render(umbra_renderer r, uint32_t n, float *px, watch *w, double *ms)
{
    umbra_renderer_set_progress(r, w ? on_progress : NULL, w);
    double t0 = bench_now_ms();
    if (w)
        w->start = w->last = t0;
    umbra_status st = umbra_renderer_render(r, n, n, px);
    *ms = bench_now_ms() - t0;
    return st;
}

int bench_progress(int argc, char **argv)
{
    options o;
    if (parse(argc, argv, &o) != 0) {
        usage(stderr);
        return 2;
    }
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    char device[1024];
    bench_device_description(ctx, device, sizeof device);
    fprintf(stderr, "umbra-bench progress: %s\n", device);
    umbra_scene sc;
    umbra_renderer r = NULL;
    int rc = 1;
    uint32_t biggest = o.size > o.overhead_size ? o.size : o.overhead_size;
    float *px = malloc((size_t)biggest * biggest * 4 * sizeof *px);
    if (!px || umbra_scene_create(ctx, "spheres", 0, &sc) != UMBRA_SUCCESS)
        goto out;
    if (umbra_renderer_create(ctx, &r) != UMBRA_SUCCESS ||
        umbra_renderer_set_volume(r, sc.volume) != UMBRA_SUCCESS ||
        umbra_renderer_set_transfer_function(r, sc.tf) != UMBRA_SUCCESS ||
        umbra_renderer_set_camera(r, &sc.camera) != UMBRA_SUCCESS ||
        umbra_renderer_set_light(r, &sc.light) != UMBRA_SUCCESS ||
        umbra_renderer_set_options(r, &sc.options) != UMBRA_SUCCESS)
        goto fail;
    printf("step,what,size,value_ms_or_count,detail\n");
    for (int s = 0; s < o.nsteps; ++s) {
        umbra_shadow_desc d;
        umbra_shadow_desc_init(&d);
        d.technique = UMBRA_SHADOW_REFERENCE;
        d.reference.step = o.steps[s];
        if (umbra_renderer_set_shadow(r, &d) != UMBRA_SUCCESS)
            goto fail;
        watch w;
        double ms;
        memset(&w, 0, sizeof w);
        /* Warm-up: the kernel at the work-group the bands use, and at the unbanded one. */
        if (render(r, 16, px, &w, &ms) != UMBRA_SUCCESS || render(r, 16, px, NULL, &ms))
            goto fail;
        double plain[64], banded[64];
        int reports = 0;
        double longest = 0.0;
        const int runs = o.runs < 64 ? o.runs : 64;
        for (int k = 0; k < runs; ++k) {
            if (render(r, o.overhead_size, px, NULL, &plain[k]) != UMBRA_SUCCESS)
                goto fail;
            memset(&w, 0, sizeof w);
            if (render(r, o.overhead_size, px, &w, &banded[k]) != UMBRA_SUCCESS)
                goto fail;
            reports = w.reports;
            longest = w.longest > longest ? w.longest : longest;
        }
        bench_timing tp = bench_timing_of(plain, runs), tb = bench_timing_of(banded, runs);
        fprintf(stderr, "step %g, %u^2: %.0f ms without a callback, %.0f ms with (%.3fx), %d "
                "reports, at most %.0f ms apart\n", o.steps[s], o.overhead_size, tp.median,
                tb.median, tb.median / tp.median, reports, longest);
        printf("%g,plain,%u,%.1f,median of %d\n", o.steps[s], o.overhead_size, tp.median, runs);
        printf("%g,banded,%u,%.1f,median of %d (%.3fx)\n", o.steps[s], o.overhead_size, tb.median,
               runs, tb.median / tp.median);
        printf("%g,reports,%u,%d,\n", o.steps[s], o.overhead_size, reports);
        printf("%g,longest_gap,%u,%.1f,\n", o.steps[s], o.overhead_size, longest);
        for (int c = 0; c < o.ncancel; ++c) {
            memset(&w, 0, sizeof w);
            timer t = {&w, 1000.0 * o.cancel_at[c]};
            pthread_t th;
            if (pthread_create(&th, NULL, ask_cancel, &t) != 0)
                goto fail;
            umbra_status st = render(r, o.size, px, &w, &ms);
            pthread_join(th, NULL);
            double end = w.start + ms;
            if (st == UMBRA_ERROR_CANCELLED) {
                fprintf(stderr, "step %g, %u^2: cancel asked at %.1f s took effect %.0f ms "
                        "later (%d reports, at most %.0f ms apart)\n", o.steps[s], o.size,
                        o.cancel_at[c], end - w.asked, w.reports, w.longest);
                printf("%g,cancel_latency,%u,%.1f,asked at %.1f s\n", o.steps[s], o.size,
                       end - w.asked, o.cancel_at[c]);
                printf("%g,longest_gap_to_cancel,%u,%.1f,\n", o.steps[s], o.size, w.longest);
            } else if (st == UMBRA_SUCCESS) {
                fprintf(stderr, "step %g, %u^2: the frame (%.0f ms) ended before the cancel at "
                        "%.1f s\n", o.steps[s], o.size, ms, o.cancel_at[c]);
            } else {
                goto fail;
            }
            umbra_context_take_error(ctx, NULL);
        }
    }
    rc = 0;
fail:
    if (rc)
        fprintf(stderr, "umbra-bench progress: %s\n", umbra_context_last_message(ctx));
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
out:
    free(px);
    umbra_context_release(ctx);
    return rc;
}
