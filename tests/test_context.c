// SPDX-License-Identifier: Apache-2.0
/* tests/test_context.c: the OpenCL contract between umbra and the application that embeds it
 * (include/umbra/context.h, "The OpenCL contract"), one test per point:
 *
 *  - an out-of-order application queue gives the same pixels as an in-order one, for every
 *    technique, through every entry point (host buffer, application buffer, asynchronous,
 *    per-point queries);
 *  - a cl_mem that is not a writable buffer of the context, or too small, is refused with a
 *    message naming it;
 *  - the asynchronous render waits for the application's events, hands back a completion event
 *    (its last kernel, timed; the stats time the frame once it has run), keeps what it needs
 *    alive after everything is released, and equals the blocking render;
 *  - the statistics say whether their times are device or wall-clock times;
 *  - the process-wide state umbra touches (POCL_CACHE_DIR, UMBRA_DEVICE) can be left alone, and a
 *    context description of the previous, shorter layout is still accepted.
 *
 * Usage: test_context [filter] (a cmocka test-name glob).
 *
 * Why one file past 800 lines: one test per contract point, each independent; a table of cases. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "test_util.h"

enum { W = 40, H = 40 };

/* ---- helpers --------------------------------------------------------------------------------- */

/* The application's side: its own cl_context on the device the test context uses, and a queue. */
typedef struct app_cl {
    cl_context ctx;
    cl_device_id device;
    cl_command_queue queue;
} app_cl;

/* Makes an application context and a queue with props; 0 if the device cannot make such a
 * queue (the caller skips). */
static int app_open(umbra_context own, cl_command_queue_properties props, app_cl *app)
{
    cl_int err;
    memset(app, 0, sizeof *app);
    app->device = umbra_context_cl_device(own);
    app->ctx = clCreateContext(NULL, 1, &app->device, NULL, NULL, &err);
    assert_int_equal(err, CL_SUCCESS);
    cl_command_queue_properties supported = 0;
    assert_int_equal(clGetDeviceInfo(app->device, CL_DEVICE_QUEUE_PROPERTIES, sizeof supported,
                                     &supported, NULL),
                     CL_SUCCESS);
    if ((props & supported) != props) {
        clReleaseContext(app->ctx);
        return 0;
    }
    app->queue = clCreateCommandQueue(app->ctx, app->device, props, &err);
    assert_int_equal(err, CL_SUCCESS);
    return 1;
}

static void app_close(app_cl *app)
{
    assert_int_equal(clFinish(app->queue), CL_SUCCESS);
    clReleaseCommandQueue(app->queue);
    clReleaseContext(app->ctx);
}

static umbra_context app_context(const app_cl *app)
{
    umbra_context ctx = NULL;
    assert_int_equal(umbra_context_create_from_cl(app->ctx, app->device, app->queue, NULL, &ctx),
                     UMBRA_SUCCESS);
    return ctx;
}

static cl_mem app_buffer(const app_cl *app, cl_mem_flags flags, size_t bytes)
{
    cl_int err;
    cl_mem m = clCreateBuffer(app->ctx, flags, bytes, NULL, &err);
    assert_int_equal(err, CL_SUCCESS);
    return m;
}

/* Reads an application buffer through a fresh in-order queue (whatever the app's queue is). */
static void app_read(const app_cl *app, cl_mem buf, float *out, size_t bytes)
{
    cl_int err;
    cl_command_queue q = clCreateCommandQueue(app->ctx, app->device, 0, &err);
    assert_int_equal(err, CL_SUCCESS);
    assert_int_equal(clEnqueueReadBuffer(q, buf, CL_TRUE, 0, bytes, out, 0, NULL, NULL),
                     CL_SUCCESS);
    clReleaseCommandQueue(q);
}

static double max_abs_diff(const float *a, const float *b, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d = fabs((double)a[i] - b[i]);
        m = d > m || isnan(d) ? (isnan(d) ? INFINITY : d) : m;
    }
    return m;
}

/* A technique and its settings, small enough to keep every test fast. */
typedef struct tech_case {
    const char *label;
    umbra_shadow_technique technique;
    int preintegrated;
    uint32_t subsamples;
} tech_case;

static const tech_case cases[] = {
    {"none", UMBRA_SHADOW_NONE, 0, 0},
    {"reference", UMBRA_SHADOW_REFERENCE, 0, 0},
    {"reference, pre-integrated", UMBRA_SHADOW_REFERENCE, 1, 0},
    {"threshold", UMBRA_SHADOW_THRESHOLD, 0, 0},
    {"deep", UMBRA_SHADOW_DEEP, 0, 0},
    {"cssm", UMBRA_SHADOW_CSSM, 0, 0},
    {"convolution", UMBRA_SHADOW_CONVOLUTION, 0, 0},
    {"convolution, pre-integrated SCS", UMBRA_SHADOW_CONVOLUTION, 1, 2},
};
enum { NCASES = sizeof cases / sizeof cases[0] };

/* The coloured spheres (32^3) with shading, ground plane, jitter and a light from above and in
 * front (the convolution technique needs it on the viewer's side), lit by technique tc. The
 * scene is returned for release. */
static umbra_renderer case_renderer(umbra_context ctx, const tech_case *tc, umbra_scene *sc)
{
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, sc), UMBRA_SUCCESS);
    umbra_light light = test_directional_light(-0.3f, -1.0f, -0.6f);
    umbra_render_desc o = sc->options;
    o.shading = 1;
    o.jitter = 1;
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    o.preintegrated = tc->preintegrated;
    umbra_renderer r = test_renderer(ctx, sc->volume, sc->tf, &sc->camera, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = tc->technique;
    s.convolution.subsamples = tc->subsamples;
    s.map.size = 128;
    s.reference.step = 0.5f;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    return r;
}

/* ---- out-of-order queues --------------------------------------------------------------------- */

/* Every technique on an application's out-of-order queue equals the same technique on an
 * in-order queue of the same cl_context, rendered into host memory and into the application's
 * buffer, twice (a race shows as a difference between runs). */
static void test_out_of_order_queue_matches_in_order(void **state)
{
    umbra_context own = *state;
    app_cl ooo, ino;
    if (!app_open(own, CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &ooo))
        skip();
    assert_true(app_open(own, 0, &ino));
    clReleaseCommandQueue(ino.queue); /* an in-order queue on the out-of-order one's context */
    clReleaseContext(ino.ctx);
    ino.ctx = ooo.ctx;
    clRetainContext(ino.ctx);
    cl_int err;
    ino.queue = clCreateCommandQueue(ino.ctx, ino.device, 0, &err);
    assert_int_equal(err, CL_SUCCESS);

    umbra_context a = app_context(&ooo), b = app_context(&ino);
    const size_t n = (size_t)W * H * 4;
    float *want = malloc(n * sizeof *want), *got = malloc(n * sizeof *got);
    assert_non_null(want);
    assert_non_null(got);
    cl_mem buf = app_buffer(&ooo, CL_MEM_READ_WRITE, n * sizeof(float));
    double worst = 0.0;
    for (int c = 0; c < NCASES; ++c) {
        umbra_scene sa, sb;
        umbra_renderer ra = case_renderer(a, &cases[c], &sa), rb = case_renderer(b, &cases[c], &sb);
        assert_int_equal(umbra_renderer_render(rb, W, H, want), UMBRA_SUCCESS);
        if (cases[c].technique != UMBRA_SHADOW_CONVOLUTION) { /* it has no per-point lookup */
            float pts[3 * 64], qa[3 * 64], qb[3 * 64];
            for (int i = 0; i < 3 * 64; ++i)
                pts[i] = 0.4f * sinf(1.7f * (float)i);
            assert_int_equal(umbra_renderer_query_shadow(ra, pts, 64, qa), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_query_shadow(rb, pts, 64, qb), UMBRA_SUCCESS);
            worst = fmax(worst, max_abs_diff(qa, qb, 3 * 64));
        }
        for (int run = 0; run < 2; ++run) {
            assert_int_equal(umbra_renderer_render(ra, W, H, got), UMBRA_SUCCESS);
            double e = max_abs_diff(got, want, n);
            assert_int_equal(umbra_renderer_render_to_cl_buffer(ra, W, H, buf), UMBRA_SUCCESS);
            app_read(&ooo, buf, got, n * sizeof(float));
            double e_buf = max_abs_diff(got, want, n);
            print_message("  %-32s run %d: out-of-order vs in-order max |diff| %.3g (host), "
                          "%.3g (application buffer)\n", cases[c].label, run, e, e_buf);
            worst = fmax(worst, fmax(e, e_buf));
        }
        umbra_renderer_release(ra);
        umbra_renderer_release(rb);
        umbra_scene_release(&sa);
        umbra_scene_release(&sb);
    }
    assert_true(worst == 0.0);
    clReleaseMemObject(buf);
    umbra_context_release(a);
    umbra_context_release(b);
    free(want);
    free(got);
    app_close(&ooo);
    app_close(&ino);
}

static cl_command_queue_properties queue_properties(cl_command_queue q)
{
    cl_command_queue_properties p = 0;
    assert_int_equal(clGetCommandQueueInfo(q, CL_QUEUE_PROPERTIES, sizeof p, &p, NULL),
                     CL_SUCCESS);
    return p;
}

static cl_uint context_refs(cl_context c)
{
    cl_uint n = 0;
    assert_int_equal(clGetContextInfo(c, CL_CONTEXT_REFERENCE_COUNT, sizeof n, &n, NULL),
                     CL_SUCCESS);
    return n;
}

/* On an out-of-order queue umbra works on an in-order queue of its own, with profiling, on the
 * application's context and device, and gives back every reference when it is gone; an in-order
 * queue is used as it is. */
static void test_out_of_order_queue_gets_own_in_order_queue(void **state)
{
    umbra_context own = *state;
    app_cl ooo, ino;
    if (!app_open(own, CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &ooo))
        skip();
    assert_true(app_open(own, 0, &ino));
    const cl_uint refs = context_refs(ooo.ctx);
    umbra_context a = app_context(&ooo), b = app_context(&ino);
    cl_command_queue q = umbra_context_cl_queue(a);
    assert_true(q != ooo.queue);
    assert_int_equal(queue_properties(q) & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, 0);
    assert_true(queue_properties(q) & CL_QUEUE_PROFILING_ENABLE);
    cl_context qctx = NULL;
    assert_int_equal(clGetCommandQueueInfo(q, CL_QUEUE_CONTEXT, sizeof qctx, &qctx, NULL),
                     CL_SUCCESS);
    assert_ptr_equal(qctx, ooo.ctx);
    assert_ptr_equal(umbra_context_cl_queue(b), ino.queue);
    umbra_context_release(a);
    umbra_context_release(b);
    assert_int_equal(context_refs(ooo.ctx), refs);
    app_close(&ooo);
    app_close(&ino);
}

/* ---- the application's cl_mem ------------------------------------------------------------------ */

/* Both output calls refuse mem for a w x h frame with INVALID_ARGUMENT and a message containing
 * needle, leave a sentinel in good untouched, and the context keeps working. */
static void expect_refused(umbra_context ctx, const app_cl *app, cl_mem mem, uint32_t w,
                           uint32_t h, const char *needle)
{
    umbra_scene sc;
    umbra_renderer r = case_renderer(ctx, &cases[0], &sc);
    assert_int_equal(umbra_renderer_render_to_cl_buffer(r, w, h, mem),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, needle));
    assert_true(test_message_contains(ctx, "umbra_renderer_render_to_cl_buffer: rgba 0x"));
    cl_event done = (cl_event)&done;
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, w, h, mem, 0, NULL, &done),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_null(done);
    assert_true(test_message_contains(ctx, needle));
    assert_true(test_message_contains(ctx, "umbra_renderer_render_to_cl_buffer_async: rgba"));
    /* The context still renders into a proper buffer. */
    cl_mem good = app_buffer(app, CL_MEM_READ_WRITE, (size_t)W * H * 16);
    assert_int_equal(umbra_renderer_render_to_cl_buffer(r, W, H, good), UMBRA_SUCCESS);
    clReleaseMemObject(good);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

static void test_cl_image_refused_as_output(void **state)
{
    app_cl app;
    assert_true(app_open(*state, 0, &app));
    umbra_context ctx = app_context(&app);
    cl_bool images = CL_FALSE;
    clGetDeviceInfo(app.device, CL_DEVICE_IMAGE_SUPPORT, sizeof images, &images, NULL);
    if (images) {
        cl_image_format fmt = {CL_RGBA, CL_FLOAT};
        cl_int err;
        cl_image_desc idesc;
        memset(&idesc, 0, sizeof idesc);
        idesc.image_type = CL_MEM_OBJECT_IMAGE2D;
        idesc.image_width = W;
        idesc.image_height = H;
        cl_mem img = clCreateImage(app.ctx, CL_MEM_READ_WRITE, &fmt, &idesc, NULL, &err);
        assert_int_equal(err, CL_SUCCESS);
        expect_refused(ctx, &app, img, W, H, "is a 2D image");
        clReleaseMemObject(img);
    }
    umbra_context_release(ctx);
    app_close(&app);
    if (!images)
        skip();
}

static void test_read_only_buffer_refused_as_output(void **state)
{
    app_cl app;
    assert_true(app_open(*state, 0, &app));
    umbra_context ctx = app_context(&app);
    cl_mem m = app_buffer(&app, CL_MEM_READ_ONLY, (size_t)W * H * 16);
    expect_refused(ctx, &app, m, W, H, "CL_MEM_READ_ONLY");
    clReleaseMemObject(m);
    umbra_context_release(ctx);
    app_close(&app);
}

static void test_small_buffer_refused_as_output(void **state)
{
    app_cl app;
    assert_true(app_open(*state, 0, &app));
    umbra_context ctx = app_context(&app);
    cl_mem m = app_buffer(&app, CL_MEM_READ_WRITE, (size_t)W * H * 16 - 4);
    char want[128];
    snprintf(want, sizeof want, "holds %zu bytes; %u x %u RGBA floats need %zu",
             (size_t)W * H * 16 - 4, (unsigned)W, (unsigned)H, (size_t)W * H * 16);
    expect_refused(ctx, &app, m, W, H, want);
    clReleaseMemObject(m);
    umbra_context_release(ctx);
    app_close(&app);
}

static void test_buffer_of_other_context_refused_as_output(void **state)
{
    app_cl app, other;
    assert_true(app_open(*state, 0, &app));
    assert_true(app_open(*state, 0, &other));
    umbra_context ctx = app_context(&app);
    cl_mem m = app_buffer(&other, CL_MEM_READ_WRITE, (size_t)W * H * 16);
    expect_refused(ctx, &app, m, W, H, "belongs to another cl_context");
    clReleaseMemObject(m);
    umbra_context_release(ctx);
    app_close(&app);
    app_close(&other);
}

/* ---- the asynchronous render ------------------------------------------------------------------ */

static cl_int event_status(cl_event e)
{
    cl_int s = 0;
    assert_int_equal(clGetEventInfo(e, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof s, &s, NULL),
                     CL_SUCCESS);
    return s;
}

static void fill_sentinel(const app_cl *app, cl_mem buf, size_t n)
{
    const float sentinel = -7.0f;
    cl_int err;
    cl_command_queue q = clCreateCommandQueue(app->ctx, app->device, 0, &err);
    assert_int_equal(err, CL_SUCCESS);
    assert_int_equal(clEnqueueFillBuffer(q, buf, &sentinel, sizeof sentinel, 0, n * sizeof(float),
                                         0, NULL, NULL),
                     CL_SUCCESS);
    assert_int_equal(clFinish(q), CL_SUCCESS);
    clReleaseCommandQueue(q);
}

static int all_sentinel(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (v[i] != -7.0f)
            return 0;
    return 1;
}

/* For every technique, on an in-order and an out-of-order queue: the asynchronous frame (on a
 * fresh renderer, so its builds happen in the call) waits for the application's user event (its
 * event stays pending and the buffer untouched until the event is set), then equals the
 * blocking render exactly; its stats say the render was not timed. */
static void test_async_render_waits_for_user_event_and_equals_blocking(void **state)
{
    umbra_context own = *state;
    const size_t n = (size_t)W * H * 4;
    float *want = malloc(n * sizeof *want), *got = malloc(n * sizeof *got);
    assert_non_null(want);
    assert_non_null(got);
    alarm(120); /* a call that blocked on the user event would hang: fail instead */
    for (int kind = 0; kind < 2; ++kind) {
        app_cl app;
        if (!app_open(own, kind ? CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE : 0, &app))
            continue;
        umbra_context ctx = app_context(&app);
        cl_mem buf = app_buffer(&app, CL_MEM_READ_WRITE, n * sizeof(float));
        for (int c = 0; c < NCASES; ++c) {
            umbra_scene sc;
            umbra_renderer r = case_renderer(ctx, &cases[c], &sc);
            fill_sentinel(&app, buf, n);
            cl_int err;
            cl_event user = clCreateUserEvent(app.ctx, &err), done = NULL;
            assert_int_equal(err, CL_SUCCESS);
            assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &user,
                                                                      &done),
                             UMBRA_SUCCESS);
            assert_non_null(done);
            umbra_render_stats st;
            assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
            assert_int_equal(st.render_timing, UMBRA_TIMING_NONE);
            assert_true(st.render_ms == 0.0);
            /* Time for the device to run anything that did not wait. */
            nanosleep(&(struct timespec){0, 20000000}, NULL);
            assert_true(event_status(done) > CL_COMPLETE);
            app_read(&app, buf, got, n * sizeof(float));
            assert_true(all_sentinel(got, n));
            assert_int_equal(clSetUserEventStatus(user, CL_COMPLETE), CL_SUCCESS);
            assert_int_equal(clWaitForEvents(1, &done), CL_SUCCESS);
            app_read(&app, buf, got, n * sizeof(float));
            assert_int_equal(umbra_renderer_render(r, W, H, want), UMBRA_SUCCESS);
            double e = max_abs_diff(got, want, n);
            print_message("  %-13s %-32s asynchronous vs blocking max |diff| %.3g\n",
                          kind ? "out-of-order" : "in-order", cases[c].label, e);
            assert_true(e == 0.0);
            clReleaseEvent(done);
            clReleaseEvent(user);
            umbra_renderer_release(r);
            umbra_scene_release(&sc);
        }
        clReleaseMemObject(buf);
        umbra_context_release(ctx);
        app_close(&app);
    }
    alarm(0);
    free(want);
    free(got);
}

/* An application that pipelines: two asynchronous frames with different cameras are queued
 * behind two user events before either is set; the second call returns without waiting, and
 * each frame keeps its own camera (its constants were copied at its call). */
static void test_async_frames_pipeline_without_waiting(void **state)
{
    const size_t n = (size_t)W * H * 4;
    float *want = malloc(n * sizeof *want), *got = malloc(n * sizeof *got);
    assert_non_null(want);
    assert_non_null(got);
    app_cl app;
    assert_true(app_open(*state, 0, &app));
    umbra_context ctx = app_context(&app);
    cl_mem buf[2] = {app_buffer(&app, CL_MEM_READ_WRITE, n * sizeof(float)),
                     app_buffer(&app, CL_MEM_READ_WRITE, n * sizeof(float))};
    const tech_case *tcs[2] = {&cases[3], &cases[6]}; /* threshold (ray caster), convolution */
    alarm(120); /* the second call blocking on the first frame's user event would hang */
    for (int t = 0; t < 2; ++t) {
        umbra_scene sc;
        umbra_renderer r = case_renderer(ctx, tcs[t], &sc);
        umbra_camera cam[2] = {sc.camera, sc.camera};
        cam[1].eye[0] += 0.3f * cam[1].eye[2];
        assert_int_equal(umbra_renderer_render(r, W, H, want), UMBRA_SUCCESS); /* builds */
        cl_int err;
        cl_event user[2], done[2];
        for (int f = 0; f < 2; ++f) {
            user[f] = clCreateUserEvent(app.ctx, &err);
            assert_int_equal(err, CL_SUCCESS);
            assert_int_equal(umbra_renderer_set_camera(r, &cam[f]), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf[f], 1,
                                                                      &user[f], &done[f]),
                             UMBRA_SUCCESS);
        }
        assert_true(event_status(done[0]) > CL_COMPLETE);
        assert_int_equal(clSetUserEventStatus(user[1], CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clSetUserEventStatus(user[0], CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clWaitForEvents(2, done), CL_SUCCESS);
        for (int f = 0; f < 2; ++f) {
            assert_int_equal(umbra_renderer_set_camera(r, &cam[f]), UMBRA_SUCCESS);
            assert_int_equal(umbra_renderer_render(r, W, H, want), UMBRA_SUCCESS);
            app_read(&app, buf[f], got, n * sizeof(float));
            double e = max_abs_diff(got, want, n);
            print_message("  %s frame %d: asynchronous vs blocking max |diff| %.3g\n",
                          tcs[t]->label, f, e);
            assert_true(e == 0.0);
            clReleaseEvent(done[f]);
            clReleaseEvent(user[f]);
        }
        umbra_renderer_release(r);
        umbra_scene_release(&sc);
    }
    alarm(0);
    clReleaseMemObject(buf[0]);
    clReleaseMemObject(buf[1]);
    umbra_context_release(ctx);
    app_close(&app);
    free(want);
    free(got);
}

/* The application may release the renderer, scene and umbra context as soon as the
 * asynchronous call returns: the frame still completes, right. */
static void test_async_frame_survives_release_of_everything(void **state)
{
    umbra_context own = *state;
    const size_t n = (size_t)W * H * 4;
    float *want = malloc(n * sizeof *want), *got = malloc(n * sizeof *got);
    assert_non_null(want);
    assert_non_null(got);
    alarm(120);
    for (int kind = 0; kind < 2; ++kind) {
        app_cl app;
        if (!app_open(own, kind ? CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE : 0, &app))
            continue;
        cl_mem buf = app_buffer(&app, CL_MEM_READ_WRITE, n * sizeof(float));
        umbra_context ctx = app_context(&app);
        umbra_scene sc;
        umbra_renderer r = case_renderer(ctx, &cases[6], &sc); /* convolution: many commands */
        assert_int_equal(umbra_renderer_render(r, W, H, want), UMBRA_SUCCESS);
        cl_int err;
        cl_event user = clCreateUserEvent(app.ctx, &err), done = NULL;
        assert_int_equal(err, CL_SUCCESS);
        assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &user, &done),
                         UMBRA_SUCCESS);
        umbra_renderer_release(r);
        umbra_scene_release(&sc);
        umbra_context_release(ctx);
        assert_int_equal(clSetUserEventStatus(user, CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clWaitForEvents(1, &done), CL_SUCCESS);
        app_read(&app, buf, got, n * sizeof(float));
        double e = max_abs_diff(got, want, n);
        print_message("  %s: frame after release vs blocking max |diff| %.3g\n",
                      kind ? "out-of-order" : "in-order", e);
        assert_true(e == 0.0);
        clReleaseEvent(done);
        clReleaseEvent(user);
        clReleaseMemObject(buf);
        app_close(&app);
    }
    alarm(0);
    free(want);
    free(got);
}

/* What *done carries: it is the frame's last kernel (the ray caster's, or the convolution
 * technique's resolve), so its profiling counters time that kernel, not a marker's instant; the
 * stats, untimed while the frame is queued, give the frame's device time once it has completed:
 * for a one-kernel frame exactly done's, for the convolution's slices and resolve more. */
static void test_async_done_is_the_last_kernel_and_stats_time_the_frame(void **state)
{
    umbra_context ctx = *state;
    const size_t n = (size_t)W * H * 4;
    cl_int err;
    cl_mem buf = clCreateBuffer(umbra_context_cl_context(ctx), CL_MEM_READ_WRITE,
                                n * sizeof(float), NULL, &err);
    assert_int_equal(err, CL_SUCCESS);
    const tech_case *tcs[2] = {&cases[1], &cases[6]}; /* reference (ray caster), convolution */
    alarm(120);
    for (int t = 0; t < 2; ++t) {
        umbra_scene sc;
        umbra_renderer r = case_renderer(ctx, tcs[t], &sc);
        cl_event user = clCreateUserEvent(umbra_context_cl_context(ctx), &err), done = NULL;
        assert_int_equal(err, CL_SUCCESS);
        assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &user, &done),
                         UMBRA_SUCCESS);
        cl_command_type type = 0;
        assert_int_equal(clGetEventInfo(done, CL_EVENT_COMMAND_TYPE, sizeof type, &type, NULL),
                         CL_SUCCESS);
        assert_int_equal(type, CL_COMMAND_NDRANGE_KERNEL);
        umbra_render_stats st;
        assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
        assert_int_equal(st.render_timing, UMBRA_TIMING_NONE); /* queued: not timed yet */
        assert_true(st.render_ms == 0.0);
        assert_int_equal(clSetUserEventStatus(user, CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clWaitForEvents(1, &done), CL_SUCCESS);
        cl_ulong a = 0, b = 0;
        assert_int_equal(clGetEventProfilingInfo(done, CL_PROFILING_COMMAND_START, sizeof a, &a,
                                                 NULL),
                         CL_SUCCESS);
        assert_int_equal(clGetEventProfilingInfo(done, CL_PROFILING_COMMAND_END, sizeof b, &b,
                                                 NULL),
                         CL_SUCCESS);
        const double kernel_ms = (double)(b - a) * 1e-6;
        assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
        print_message("  %s: done times %.3f ms, the stats %.3f ms\n", tcs[t]->label, kernel_ms,
                      st.render_ms);
        assert_int_equal(st.render_timing, UMBRA_TIMING_DEVICE);
        assert_true(kernel_ms > 0.0);
        if (t == 0)
            assert_true(st.render_ms == kernel_ms);
        else
            assert_true(st.render_ms > kernel_ms);
        clReleaseEvent(done);
        clReleaseEvent(user);
        umbra_renderer_release(r);
        umbra_scene_release(&sc);
    }
    alarm(0);
    clReleaseMemObject(buf);
}

static void test_async_bad_arguments_refused(void **state)
{
    app_cl app, other;
    assert_true(app_open(*state, 0, &app));
    assert_true(app_open(*state, 0, &other));
    umbra_context ctx = app_context(&app);
    umbra_scene sc;
    umbra_renderer r = case_renderer(ctx, &cases[0], &sc);
    cl_mem buf = app_buffer(&app, CL_MEM_READ_WRITE, (size_t)W * H * 16);
    cl_int err;
    cl_event foreign = clCreateUserEvent(other.ctx, &err), done = NULL, none = NULL;
    assert_int_equal(err, CL_SUCCESS);
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 0, NULL, NULL),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "done is NULL"));
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 2, NULL, &done),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "num_wait 2 with wait_list (nil)"));
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &none, &done),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "wait_list[0] (nil) is not a valid event"));
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &foreign, &done),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "wait_list[0] 0x"));
    assert_true(test_message_contains(ctx, "belongs to another cl_context"));
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, 0, H, buf, 0, NULL, &done),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "size 0 x 40"));
    assert_null(done);
    /* Without a wait list the frame just runs; the context is fine after the refusals. */
    assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 0, NULL, &done),
                     UMBRA_SUCCESS);
    assert_int_equal(clWaitForEvents(1, &done), CL_SUCCESS);
    clReleaseEvent(done);
    clSetUserEventStatus(foreign, CL_COMPLETE);
    clReleaseEvent(foreign);
    clReleaseMemObject(buf);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
    umbra_context_release(ctx);
    app_close(&app);
    app_close(&other);
}

/* ---- timing --------------------------------------------------------------------------------- */

/* Renders the threshold case twice (build, then re-use) on ctx; checks the stats' timing kinds. */
static void expect_timing(umbra_context ctx, umbra_timing want, const char *what)
{
    umbra_scene sc;
    umbra_renderer r = case_renderer(ctx, &cases[3], &sc);
    float *img = malloc((size_t)W * H * 16);
    assert_non_null(img);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.render_timing, UMBRA_TIMING_NONE);
    assert_int_equal(st.shadow_build_timing, UMBRA_TIMING_NONE);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    print_message("  %s: render %.3f ms (timing %d), build %.3f ms (timing %d)\n", what,
                  st.render_ms, (int)st.render_timing, st.shadow_build_ms,
                  (int)st.shadow_build_timing);
    assert_int_equal(st.render_timing, want);
    assert_int_equal(st.shadow_build_timing, want);
    assert_true(st.render_ms > 0.0 && st.shadow_build_ms > 0.0);
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.render_timing, want);
    assert_int_equal(st.shadow_build_timing, UMBRA_TIMING_NONE); /* re-used: nothing built */
    assert_true(st.shadow_build_ms == 0.0);
    free(img);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

static void test_stats_say_device_or_wall_time(void **state)
{
    umbra_context own = *state;
    expect_timing(own, UMBRA_TIMING_DEVICE, "umbra's own queue");
    app_cl app;
    assert_true(app_open(own, 0, &app));
    umbra_context ctx = app_context(&app);
    expect_timing(ctx, UMBRA_TIMING_WALL, "application's in-order queue without profiling");
    umbra_context_release(ctx);
    app_close(&app);
    assert_true(app_open(own, CL_QUEUE_PROFILING_ENABLE, &app));
    ctx = app_context(&app);
    expect_timing(ctx, UMBRA_TIMING_DEVICE, "application's in-order queue with profiling");
    umbra_context_release(ctx);
    app_close(&app);
    if (app_open(own, CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE, &app)) {
        ctx = app_context(&app);
        expect_timing(ctx, UMBRA_TIMING_DEVICE, "application's out-of-order queue (umbra's own)");
        umbra_context_release(ctx);
        app_close(&app);
    }
}

/* ---- process-wide state and the description's layout ------------------------------------------ */

typedef struct captured {
    umbra_status status;
    char message[1024];
} captured;

static void capture(void *user, umbra_status status, const char *message)
{
    captured *c = user;
    c->status = status;
    snprintf(c->message, sizeof c->message, "%s", message);
}

/* Creates a context with d (on PoCL's CPU device unless d says otherwise) and returns the status;
 * the context is released. */
static umbra_status try_create(umbra_context_desc *d, captured *cap)
{
    memset(cap, 0, sizeof *cap);
    d->error_callback = capture;
    d->error_user = cap;
    umbra_context ctx = NULL;
    umbra_status st = umbra_context_create(d, &ctx);
    umbra_context_release(ctx);
    return st;
}

/* A saved environment variable, restored by env_restore. */
typedef struct saved_env {
    const char *name;
    char value[1024];
    int was_set;
} saved_env;

static saved_env env_save(const char *name)
{
    saved_env e = {name, "", 0};
    const char *v = getenv(name);
    if (v) {
        e.was_set = 1;
        snprintf(e.value, sizeof e.value, "%s", v);
    }
    return e;
}

static void env_restore(const saved_env *e)
{
    if (e->was_set)
        setenv(e->name, e->value, 1);
    else
        unsetenv(e->name);
}

static void test_set_pocl_cache_dir_off_leaves_environment(void **state)
{
    (void)state;
    saved_env saved = env_save("POCL_CACHE_DIR");
    char dir[512];
    snprintf(dir, sizeof dir, "%s/pocl-cache-by-umbra", test_tmpdir());
    captured cap;
    umbra_context_desc d;

    unsetenv("POCL_CACHE_DIR");
    umbra_context_desc_init(&d);
    assert_int_equal(d.set_pocl_cache_dir, 1);
    d.set_pocl_cache_dir = 0;
    d.cache_dir = dir;
    d.device_name = "pthread";
    umbra_status st = try_create(&d, &cap);
    const char *after_off = getenv("POCL_CACHE_DIR");
    print_message("  set_pocl_cache_dir 0: status %d, POCL_CACHE_DIR %s\n", (int)st,
                  after_off ? after_off : "(unset)");
    assert_null(after_off);
    assert_int_equal(access(dir, F_OK), -1); /* not even the directory was made */

    /* The default sets it, to cache_dir. */
    d.set_pocl_cache_dir = 1;
    assert_int_equal(try_create(&d, &cap), UMBRA_SUCCESS);
    const char *after_on = getenv("POCL_CACHE_DIR");
    assert_non_null(after_on);
    assert_string_equal(after_on, dir);
    assert_int_equal(access(dir, W_OK), 0);
    env_restore(&saved);
}

static void test_use_environment_off_ignores_umbra_device(void **state)
{
    (void)state;
    saved_env saved = env_save("UMBRA_DEVICE");
    setenv("UMBRA_DEVICE", "no-such-device-umbra-test", 1);
    captured cap;
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    assert_int_equal(try_create(&d, &cap), UMBRA_ERROR_NO_DEVICE);
    assert_non_null(strstr(cap.message, "no-such-device-umbra-test"));
    d.use_environment = 0;
    assert_int_equal(try_create(&d, &cap), UMBRA_SUCCESS);
    env_restore(&saved);
}

/* A caller built against the first layout of umbra_context_desc (without set_pocl_cache_dir) is
 * accepted and gets the new field's default; a size that is neither layout is refused, named. */
static void test_context_desc_of_older_layout_accepted(void **state)
{
    umbra_context own = *state;
    saved_env saved = env_save("POCL_CACHE_DIR");
    const size_t v1 = offsetof(umbra_context_desc, set_pocl_cache_dir);
    char dir[512];
    snprintf(dir, sizeof dir, "%s/pocl-cache-old-layout", test_tmpdir());
    captured cap;
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    d.struct_size = v1;
    d.set_pocl_cache_dir = 0; /* beyond the old layout: must not be read */
    d.cache_dir = dir;
    d.device_name = "pthread";
    unsetenv("POCL_CACHE_DIR");
    assert_int_equal(try_create(&d, &cap), UMBRA_SUCCESS);
    const char *env = getenv("POCL_CACHE_DIR");
    assert_non_null(env);
    assert_string_equal(env, dir); /* the default (1) was used */
    env_restore(&saved);

    app_cl app;
    assert_true(app_open(own, 0, &app));
    umbra_context ctx = NULL;
    assert_int_equal(umbra_context_create_from_cl(app.ctx, app.device, app.queue, &d, &ctx),
                     UMBRA_SUCCESS);
    umbra_context_release(ctx);

    d.struct_size = v1 - 4;
    assert_int_equal(try_create(&d, &cap), UMBRA_ERROR_INVALID_ARGUMENT);
    char want[128];
    snprintf(want, sizeof want, "desc->struct_size %zu", v1 - 4);
    assert_non_null(strstr(cap.message, want));
    memset(&cap, 0, sizeof cap);
    assert_int_equal(umbra_context_create_from_cl(app.ctx, app.device, app.queue, &d, &ctx),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_null(ctx);
    assert_non_null(strstr(cap.message, want));
    app_close(&app);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_out_of_order_queue_matches_in_order),
        cmocka_unit_test(test_out_of_order_queue_gets_own_in_order_queue),
        cmocka_unit_test(test_cl_image_refused_as_output),
        cmocka_unit_test(test_read_only_buffer_refused_as_output),
        cmocka_unit_test(test_small_buffer_refused_as_output),
        cmocka_unit_test(test_buffer_of_other_context_refused_as_output),
        cmocka_unit_test(test_async_render_waits_for_user_event_and_equals_blocking),
        cmocka_unit_test(test_async_frames_pipeline_without_waiting),
        cmocka_unit_test(test_async_frame_survives_release_of_everything),
        cmocka_unit_test(test_async_done_is_the_last_kernel_and_stats_time_the_frame),
        cmocka_unit_test(test_async_bad_arguments_refused),
        cmocka_unit_test(test_stats_say_device_or_wall_time),
        cmocka_unit_test(test_set_pocl_cache_dir_off_leaves_environment),
        cmocka_unit_test(test_use_environment_off_ignores_umbra_device),
        cmocka_unit_test(test_context_desc_of_older_layout_accepted),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
