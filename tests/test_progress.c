// SPDX-License-Identifier: Apache-2.0
/* tests/test_progress.c: progress reports and cancellation (issue 11, row 16).
 *
 *  - with a progress callback, every technique reports fractions in [0, 1] that never decrease
 *    and end at exactly 1, in several steps (launches split into bands; the test shrinks the
 *    bands with the renderer's band_samples knob), and renders the image it renders without one,
 *    bit for bit;
 *  - a callback that asks to stop makes the render return UMBRA_ERROR_CANCELLED promptly (no
 *    further report), in the shadow build or in the frame; the next render succeeds with the
 *    same image as an uninterrupted one;
 *  - a deep map needing more blocks than the device could hold fails with out-of-memory (it
 *    stops its pass when it asks for them);
 *  - the pieces follow the samples marched: a reference render, whose every view sample marches
 *    a shadow ray, and a reference shadow query come in at least as many bands as their
 *    estimated samples over a band's budget (the view samples alone made one band), the image
 *    is the same with and without them, and a cancel at the first report returns after at most
 *    one more band;
 *  - a progress callback that calls its own renderer, or another thread calling a renderer in
 *    the middle of a render, is refused with a message naming both calls, and the render goes
 *    on; a callback may release the renderer. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "techniques/deep.h"
#include "test_util.h"

enum { W = 48, H = 40, MAXCALLS = 100000 };

typedef struct recorder {
    int calls;
    int cancel_at;        /* 0: never; else the call number that returns nonzero */
    float fractions[MAXCALLS];
} recorder;

static int record(void *user, float fraction)
{
    recorder *rec = user;
    if (rec->calls < MAXCALLS)
        rec->fractions[rec->calls] = fraction;
    rec->calls++;
    return rec->cancel_at && rec->calls >= rec->cancel_at;
}

static umbra_renderer scene(umbra_context ctx, umbra_shadow_technique technique,
                            umbra_volume *vol, umbra_transfer_function *tf)
{
    enum { N = 20 };
    static float data[N * N * N];
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x) {
                float dx = x - 9.5f, dy = y - 9.5f, dz = z - 9.5f;
                data[(z * N + y) * N + x] = sqrtf(dx * dx + dy * dy + dz * dz) / 16.0f;
            }
    *vol = test_volume(ctx, N, N, N, data);
    const float table[12] = {1, 0.8f, 0.5f, 0.3f, 0.5f, 0.8f, 1, 0.1f, 1, 1, 1, 0};
    assert_int_equal(umbra_transfer_function_create(ctx, table, 3, tf), UMBRA_SUCCESS);
    /* Along the default view, so that the convolution technique takes it too. */
    umbra_light light = test_directional_light(-0.6f, -0.45f, -1.0f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.ground_plane = 1;
    o.step = 0.25f;
    umbra_renderer r = test_renderer(ctx, *vol, *tf, NULL, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = technique;
    s.map.size = 64;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    return r;
}

static const umbra_shadow_technique all[] = {UMBRA_SHADOW_NONE,  UMBRA_SHADOW_REFERENCE,
                                             UMBRA_SHADOW_THRESHOLD, UMBRA_SHADOW_DEEP,
                                             UMBRA_SHADOW_CSSM, UMBRA_SHADOW_CONVOLUTION};
enum { TECHNIQUES = sizeof all / sizeof all[0] };

/* The image each technique renders with no callback. */
static void plain_image(umbra_context ctx, umbra_shadow_technique t, float *rgba)
{
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = scene(ctx, t, &v, &tf);
    assert_int_equal(umbra_renderer_render(r, W, H, rgba), UMBRA_SUCCESS);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_progress_fractions_are_monotone_and_end_at_1(void **state)
{
    umbra_context ctx = *state;
    static float expect[4 * W * H], got[4 * W * H];
    static recorder rec;
    for (int i = 0; i < TECHNIQUES; ++i) {
        plain_image(ctx, all[i], expect);
        umbra_volume v;
        umbra_transfer_function tf;
        umbra_renderer r = scene(ctx, all[i], &v, &tf);
        r->band_samples = 20000.0; /* many small bands */
        memset(&rec, 0, sizeof rec);
        assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
        print_message("%s: %d reports\n", umbra_shadow_technique_name(all[i]), rec.calls);
        assert_true(rec.calls >= 4);
        for (int k = 0; k < rec.calls; ++k) {
            assert_true(rec.fractions[k] >= 0.0f && rec.fractions[k] <= 1.0f);
            if (k)
                assert_true(rec.fractions[k] >= rec.fractions[k - 1]);
        }
        assert_true(rec.fractions[rec.calls - 1] == 1.0f);
        /* Bands change no pixel. */
        assert_memory_equal(got, expect, sizeof got);
        /* A second frame (the shadow structure re-used) reports from 0 to 1 again. */
        memset(&rec, 0, sizeof rec);
        assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
        assert_true(rec.calls >= 2 && rec.fractions[rec.calls - 1] == 1.0f);
        assert_memory_equal(got, expect, sizeof got);
        umbra_renderer_release(r);
        umbra_transfer_function_release(tf);
        umbra_volume_release(v);
    }
}

static void test_cancel_from_callback_stops_render_and_next_render_succeeds(void **state)
{
    umbra_context ctx = *state;
    static float expect[4 * W * H], got[4 * W * H];
    static recorder rec;
    for (int i = 0; i < TECHNIQUES; ++i) {
        plain_image(ctx, all[i], expect);
        /* Cancel at the first report (in the shadow build where there is one) and in the
         * middle of the work. */
        for (int at = 1; at <= 3; at += 2) {
            umbra_volume v;
            umbra_transfer_function tf;
            umbra_renderer r = scene(ctx, all[i], &v, &tf);
            r->band_samples = 20000.0;
            memset(&rec, 0, sizeof rec);
            rec.cancel_at = at;
            assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_ERROR_CANCELLED);
            assert_int_equal(rec.calls, at); /* nothing reported after the cancel */
            assert_true(rec.fractions[at - 1] < 1.0f);
            assert_true(test_message_contains(ctx, "cancelled by the progress callback"));
            /* The same renderer goes on: with the callback letting it run, then without. */
            memset(&rec, 0, sizeof rec);
            assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
            assert_true(rec.fractions[rec.calls - 1] == 1.0f);
            assert_memory_equal(got, expect, sizeof got);
            assert_int_equal(umbra_renderer_set_progress(r, NULL, NULL), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
            assert_memory_equal(got, expect, sizeof got);
            umbra_renderer_release(r);
            umbra_transfer_function_release(tf);
            umbra_volume_release(v);
        }
    }
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_CANCELLED);
    assert_string_equal(umbra_status_to_string(UMBRA_ERROR_CANCELLED), "UMBRA_ERROR_CANCELLED");
}

static void test_query_shadow_reports_and_cancels_its_build(void **state)
{
    umbra_context ctx = *state;
    static recorder rec;
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = scene(ctx, UMBRA_SHADOW_DEEP, &v, &tf);
    r->band_samples = 20000.0;
    const float p[6] = {0, 0, 0, 1, 2, 3};
    float rgb[6], expect[6];
    memset(&rec, 0, sizeof rec);
    rec.cancel_at = 2;
    assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_query_shadow(r, p, 2, rgb), UMBRA_ERROR_CANCELLED);
    rec.cancel_at = 0;
    rec.calls = 0;
    assert_int_equal(umbra_renderer_query_shadow(r, p, 2, rgb), UMBRA_SUCCESS);
    assert_true(rec.calls >= 2 && rec.fractions[rec.calls - 1] == 1.0f);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
    r = scene(ctx, UMBRA_SHADOW_DEEP, &v, &tf);
    assert_int_equal(umbra_renderer_query_shadow(r, p, 2, expect), UMBRA_SUCCESS);
    assert_memory_equal(rgb, expect, sizeof rgb);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* A deep map that needs more blocks than the device could hold stops as soon as it asks for
 * them and fails with a message, instead of finishing its pass first; the renderer goes on. */
static void test_deep_map_beyond_device_memory_fails_with_out_of_memory(void **state)
{
    umbra_context ctx = *state;
    static float got[4 * W * H];
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = scene(ctx, UMBRA_SHADOW_DEEP, &v, &tf);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_DEEP;
    s.map.size = 64;
    s.deep.epsilon = 0.0f;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
    umbra__deep_info info;
    assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_SUCCESS);
    print_message("the map takes %zu blocks\n", info.used_blocks);
    assert_true(info.used_blocks > 8);
    const size_t limit = info.used_blocks / 4;
    assert_int_equal(umbra__deep_set_limit(r, limit), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_ERROR_OUT_OF_MEMORY);
    assert_true(test_message_contains(ctx, "largest allocation"));
    assert_true(test_message_contains(ctx, "epsilon 0"));
    /* Each tile stopped at its first block past the limit. */
    assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_SUCCESS);
    print_message("limit %zu: the pass asked for %zu blocks (%u tiles)\n", limit,
                  info.asked_blocks, info.tiles_per_row * info.tiles_per_row);
    assert_true(info.asked_blocks <= limit + info.tiles_per_row * info.tiles_per_row);
    assert_int_equal(umbra__deep_set_limit(r, 0), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* ---- pieces that follow the samples marched -------------------------------------------------- */

/* The scene's reference renderer at shadow step `step`. */
static umbra_renderer reference_at(umbra_context ctx, float step, umbra_volume *v,
                                   umbra_transfer_function *tf)
{
    umbra_renderer r = scene(ctx, UMBRA_SHADOW_REFERENCE, v, tf);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_REFERENCE;
    s.reference.step = step;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    return r;
}

/* The samples a reference ray marches at most in the scene's 20^3 box (unit voxels): along the
 * diagonal at the view step 0.25, from each sample a shadow ray at shadow step `step`. */
static double reference_cost(float step, int view)
{
    const double diag = sqrt(3.0) * 20.0, shadow = diag / step;
    return view ? diag / 0.25 * (1.0 + shadow) : 1.0 + shadow;
}

static void test_reference_bands_follow_its_shadow_rays(void **state)
{
    umbra_context ctx = *state;
    static float plain[4 * W * H], got[4 * W * H];
    static recorder rec;
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = reference_at(ctx, 0.05f, &v, &tf);
    assert_int_equal(umbra_renderer_render(r, W, H, plain), UMBRA_SUCCESS);
    const double total = (double)W * H * reference_cost(0.05f, 1);
    /* With the knob (one compute unit, no minimum) and at the default budget. */
    const double budgets[2] = {1e6, UMBRA__BAND_SAMPLES};
    for (int k = 0; k < 2; ++k) {
        r->band_samples = k == 0 ? budgets[0] : 0.0;
        memset(&rec, 0, sizeof rec);
        assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
        const double least = ceil(total / budgets[k]);
        print_message("budget %.3g samples: %d bands for an estimate of %.3g samples (at least "
                      "%.0f)\n", budgets[k], rec.calls, total, least);
        assert_true(rec.calls >= least);
        /* Each band holds at least half a budget but for the last of each row of groups. */
        assert_true(rec.calls <= 2.0 * least + H);
        assert_true(rec.fractions[rec.calls - 1] == 1.0f);
        assert_memory_equal(got, plain, sizeof got); /* bands change no pixel */
    }
    /* A shadow query marches one shadow ray per point. */
    enum { N = 4096 };
    static float points[3 * N], rgb[3 * N], rgb_plain[3 * N];
    for (int i = 0; i < N; ++i) {
        points[3 * i] = (float)(i % 16) - 7.5f;
        points[3 * i + 1] = (float)(i / 16 % 16) - 7.5f;
        points[3 * i + 2] = (float)(i / 256) - 7.5f;
    }
    assert_int_equal(umbra_renderer_set_progress(r, NULL, NULL), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_query_shadow(r, points, N, rgb_plain), UMBRA_SUCCESS);
    r->band_samples = 1e5;
    memset(&rec, 0, sizeof rec);
    assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_query_shadow(r, points, N, rgb), UMBRA_SUCCESS);
    const double least = ceil(N * reference_cost(0.05f, 0) / 1e5);
    print_message("query: %d bands, at least %.0f\n", rec.calls, least);
    assert_true(rec.calls >= least && rec.calls <= 2.0 * least + 1.0);
    assert_memory_equal(rgb, rgb_plain, sizeof rgb);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* A cancel asked for at the first report (after the first band) returns once the band in flight
 * has ended: into a buffer of sentinels, the render writes at most two bands' pixels. */
static void test_cancel_at_first_report_returns_after_one_more_band(void **state)
{
    umbra_context ctx = *state;
    static recorder rec;
    static float px[4 * W * H];
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = reference_at(ctx, 0.05f, &v, &tf);
    r->band_samples = 2e6;
    cl_int err;
    cl_mem buf = clCreateBuffer(umbra_context_cl_context(ctx), CL_MEM_READ_WRITE, sizeof px, NULL,
                                &err);
    assert_int_equal(err, CL_SUCCESS);
    cl_command_queue q = umbra_context_cl_queue(ctx);
    const float sentinel = -7.0f;
    assert_int_equal(clEnqueueFillBuffer(q, buf, &sentinel, sizeof sentinel, 0, sizeof px, 0,
                                         NULL, NULL),
                     CL_SUCCESS);
    assert_int_equal(clFinish(q), CL_SUCCESS);
    memset(&rec, 0, sizeof rec);
    rec.cancel_at = 1;
    assert_int_equal(umbra_renderer_set_progress(r, record, &rec), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render_to_cl_buffer(r, W, H, buf), UMBRA_ERROR_CANCELLED);
    assert_int_equal(rec.calls, 1);
    assert_int_equal(clEnqueueReadBuffer(q, buf, CL_TRUE, 0, sizeof px, px, 0, NULL, NULL),
                     CL_SUCCESS);
    size_t written = 0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        written += px[4 * i + 3] != sentinel;
    /* The band the renderer launches, as it plans it. */
    size_t local[2] = {r->render_local[0], r->render_local[1]}, tile[2];
    const size_t global[2] = {W, H};
    const double cost = umbra__march_cost(r, 1);
    assert_true(fabs(cost - reference_cost(0.05f, 1)) < 1e-6 * cost);
    umbra__band_local(r, cost, local);
    umbra__band_plan(r, global, local, cost, tile);
    print_message("band of %zu x %zu work-items (groups of %zu x %zu): %zu pixels written\n",
                  tile[0], tile[1], local[0], local[1], written);
    assert_true((double)tile[0] * tile[1] * cost <= 2e6);
    assert_true(written >= 1 && written <= 2 * tile[0] * tile[1]);
    assert_true(written < (size_t)W * H);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_CANCELLED);
    clReleaseMemObject(buf);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* ---- a callback that calls its renderer ------------------------------------------------------ */

typedef struct reentry {
    umbra_renderer r;
    int calls;
    umbra_status render, shadow, stats, progress;
    char message[1024];
    int release; /* release r (the caller's only reference) at the first report */
} reentry;

static int reenter(void *user, float fraction)
{
    (void)fraction;
    reentry *e = user;
    if (e->calls++)
        return 0;
    if (e->release) {
        umbra_renderer_release(e->r);
        return 0;
    }
    float px[4 * 4 * 4];
    e->render = umbra_renderer_render(e->r, 4, 4, px);
    snprintf(e->message, sizeof e->message, "%s", umbra_context_last_message(e->r->ctx));
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    e->shadow = umbra_renderer_set_shadow(e->r, &s);
    umbra_render_stats st;
    e->stats = umbra_renderer_get_stats(e->r, &st);
    e->progress = umbra_renderer_set_progress(e->r, NULL, NULL);
    return 0;
}

static void test_callback_calling_its_renderer_is_refused(void **state)
{
    umbra_context ctx = *state;
    static float expect[4 * W * H], got[4 * W * H];
    plain_image(ctx, UMBRA_SHADOW_DEEP, expect);
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = scene(ctx, UMBRA_SHADOW_DEEP, &v, &tf);
    r->band_samples = 20000.0;
    reentry e = {r, 0, UMBRA_SUCCESS, UMBRA_SUCCESS, UMBRA_SUCCESS, UMBRA_SUCCESS, "", 0};
    assert_int_equal(umbra_renderer_set_progress(r, reenter, &e), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
    print_message("from the callback: \"%s\"\n", e.message);
    assert_int_equal(e.render, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "umbra_renderer_render: renderer"));
    assert_non_null(strstr(e.message, "in the middle of umbra_renderer_render on this thread"));
    assert_non_null(strstr(e.message, "must not call the renderer it reports on"));
    assert_int_equal(e.shadow, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(e.stats, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(e.progress, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(e.calls >= 2); /* the callback stayed installed */
    assert_memory_equal(got, expect, sizeof got);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
    /* Outside the call the renderer takes calls again. */
    assert_int_equal(umbra_renderer_set_progress(r, NULL, NULL), UMBRA_SUCCESS);
    /* A callback that drops the application's only reference: the call finishes first. */
    e.calls = 0;
    e.release = 1;
    assert_int_equal(umbra_renderer_set_progress(r, reenter, &e), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
    assert_memory_equal(got, expect, sizeof got);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* Another thread calling the renderer while its render runs (in the callback, the render waits
 * for that thread's attempt) is told so, not that it is the callback. */
typedef struct other_thread {
    umbra_renderer r;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    int stage; /* 1: the render is in its callback; 2: the other thread has tried */
    umbra_status got;
    char message[1024];
} other_thread;

static void *try_render(void *user)
{
    other_thread *o = user;
    pthread_mutex_lock(&o->lock);
    while (o->stage < 1)
        pthread_cond_wait(&o->cond, &o->lock);
    pthread_mutex_unlock(&o->lock);
    float px[4 * 4 * 4];
    o->got = umbra_renderer_render(o->r, 4, 4, px);
    snprintf(o->message, sizeof o->message, "%s", umbra_context_last_message(o->r->ctx));
    pthread_mutex_lock(&o->lock);
    o->stage = 2;
    pthread_cond_signal(&o->cond);
    pthread_mutex_unlock(&o->lock);
    return NULL;
}

static int wait_for_other(void *user, float fraction)
{
    (void)fraction;
    other_thread *o = user;
    pthread_mutex_lock(&o->lock);
    if (o->stage == 0) {
        o->stage = 1;
        pthread_cond_signal(&o->cond);
        while (o->stage < 2)
            pthread_cond_wait(&o->cond, &o->lock);
    }
    pthread_mutex_unlock(&o->lock);
    return 0;
}

static void test_other_thread_during_render_is_refused(void **state)
{
    umbra_context ctx = *state;
    static float got[4 * W * H];
    umbra_volume v;
    umbra_transfer_function tf;
    umbra_renderer r = scene(ctx, UMBRA_SHADOW_THRESHOLD, &v, &tf);
    r->band_samples = 20000.0;
    other_thread o = {.r = r, .stage = 0};
    pthread_mutex_init(&o.lock, NULL);
    pthread_cond_init(&o.cond, NULL);
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, try_render, &o), 0);
    assert_int_equal(umbra_renderer_set_progress(r, wait_for_other, &o), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
    pthread_join(th, NULL);
    print_message("the other thread: \"%s\"\n", o.message);
    assert_int_equal(o.got, UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(o.message, "in the middle of umbra_renderer_render on another thread"));
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
    pthread_cond_destroy(&o.cond);
    pthread_mutex_destroy(&o.lock);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_progress_fractions_are_monotone_and_end_at_1),
        cmocka_unit_test(test_cancel_from_callback_stops_render_and_next_render_succeeds),
        cmocka_unit_test(test_query_shadow_reports_and_cancels_its_build),
        cmocka_unit_test(test_deep_map_beyond_device_memory_fails_with_out_of_memory),
        cmocka_unit_test(test_reference_bands_follow_its_shadow_rays),
        cmocka_unit_test(test_cancel_at_first_report_returns_after_one_more_band),
        cmocka_unit_test(test_callback_calling_its_renderer_is_refused),
        cmocka_unit_test(test_other_thread_during_render_is_refused),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
