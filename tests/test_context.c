/* tests/test_context.c: the OpenCL contract between umbra and the application that embeds it
 * (include/umbra/context.h, "The OpenCL contract"), one test per point:
 *
 *  - an out-of-order application queue gives the same pixels as an in-order one, for every
 *    technique, through every entry point (host buffer, application buffer, asynchronous,
 *    per-point queries);
 *  - a cl_mem that is not a writable buffer of the context, or too small, is refused with a
 *    message naming it;
 *  - the asynchronous render waits for the application's events, hands back a completion event,
 *    keeps what it needs alive after everything is released, and equals the blocking render;
 *  - the statistics say whether their times are device or wall-clock times;
 *  - the process-wide state umbra touches (POCL_CACHE_DIR, UMBRA_DEVICE) can be left alone, and a
 *    context description of the previous, shorter layout is still accepted.
 *
 * Usage: test_context [filter] (a cmocka test-name glob). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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
    umbra_renderer r = test_renderer(ctx, sc->volume, sc->tf, &sc->camera, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = tc->technique;
    s.preintegrated = tc->preintegrated;
    s.subsamples = tc->subsamples;
    s.map_size = 128;
    s.reference_step = 0.5f;
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

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_out_of_order_queue_matches_in_order),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
