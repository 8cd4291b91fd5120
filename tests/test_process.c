// SPDX-License-Identifier: Apache-2.0
/* tests/test_process.c: what the library does where a process meets OpenCL's limits (#29 items 2
 * and 3). Each case runs in a child process and the test asserts how the child ended, so that a
 * regression (an abort inside the OpenCL implementation, a hang) fails the test instead of
 * killing or stalling the suite:
 *
 *  - after fork(), every entry point that would touch OpenCL returns UMBRA_ERROR_UNSUPPORTED
 *    with a message saying what to do, promptly (the child would otherwise wait forever: PoCL's
 *    device threads do not exist in it), releasing inherited objects returns, and the parent's
 *    context is unharmed;
 *  - an asynchronous frame whose wait list holds a user event the application then sets to a
 *    negative status fails: its *done ends with an error and its buffer is left as it was,
 *    frames queued behind it end too, an event that has already failed is refused at the call,
 *    and the context renders on; on PoCL 3.1 the first of these aborted the process
 *    (pocl_update_event_failed). That case runs in a freshly executed child (this program with
 *    --child), because a child forked after OpenCL started cannot use it. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.h"

extern char **environ;

enum { W = 40, H = 32 };

/* The coloured spheres (32^3) lit from above and in front (the convolution technique needs the
 * light on the viewer's side), shaded, with technique t. */
static umbra_renderer spheres(umbra_context ctx, umbra_shadow_technique t, umbra_scene *sc)
{
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, sc), UMBRA_SUCCESS);
    umbra_light light = test_directional_light(-0.3f, -1.0f, -0.6f);
    umbra_render_desc o = sc->options;
    o.shading = 1;
    umbra_renderer r = test_renderer(ctx, sc->volume, sc->tf, &sc->camera, &light, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = t;
    s.map.size = 64;
    s.reference.step = 1.0f;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    return r;
}

/* How a child ended, for the assertion message; 0 if it exited with status 0. */
static int child_result(pid_t pid, const char *what)
{
    int ws = 0;
    assert_int_equal(waitpid(pid, &ws, 0), pid);
    if (WIFSIGNALED(ws)) {
        print_message("%s: the child died of signal %d (%s)\n", what, WTERMSIG(ws),
                      WTERMSIG(ws) == SIGABRT   ? "SIGABRT: aborted"
                      : WTERMSIG(ws) == SIGALRM ? "SIGALRM: it hung"
                                                : "?");
        return 1000 + WTERMSIG(ws);
    }
    if (WEXITSTATUS(ws) != 0)
        print_message("%s: the child exited with status %d\n", what, WEXITSTATUS(ws));
    return WEXITSTATUS(ws);
}

/* ---- fork ----------------------------------------------------------------------------------- */

/* In a forked child cmocka's assertions would jump into the parent's copy of the test: checks
 * there exit with the failing line instead. */
#define CHILD_CHECK(cond)                                                                      \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "test_process child: line %d: %s\n", __LINE__, #cond);             \
            _exit(__LINE__ % 250 + 1);                                                         \
        }                                                                                      \
    } while (0)

static char forked_message[2048];

static void keep_message(void *user, umbra_status st, const char *message)
{
    (void)user;
    (void)st;
    snprintf(forked_message, sizeof forked_message, "%s", message);
}

/* status is UMBRA_ERROR_UNSUPPORTED and the last message names fn, the fork and the remedy. */
static int refused(umbra_context ctx, umbra_status status, const char *fn)
{
    const char *m = ctx ? umbra_context_last_message(ctx) : forked_message;
    if (status != UMBRA_ERROR_UNSUPPORTED || strncmp(m, fn, strlen(fn)) != 0 ||
        !strstr(m, "forked") || !strstr(m, "spawn")) {
        fprintf(stderr, "test_process child: %s gave %s: \"%s\"\n", fn,
                umbra_status_to_string(status), m);
        return 0;
    }
    return 1;
}

static void test_forked_child_is_refused_at_every_entry_point(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    umbra_renderer r = spheres(ctx, UMBRA_SHADOW_REFERENCE, &sc);
    static float before[4 * W * H], after[4 * W * H];
    assert_int_equal(umbra_renderer_render(r, W, H, before), UMBRA_SUCCESS);
    cl_int err;
    cl_mem buf = clCreateBuffer(umbra_context_cl_context(ctx), CL_MEM_READ_WRITE,
                                sizeof before, NULL, &err);
    assert_int_equal(err, CL_SUCCESS);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        alarm(30); /* a call that waited for PoCL's threads would hang: end the child instead */
        static float px[4 * W * H];
        const float point[3] = {0.0f, 0.0f, 0.0f};
        float rgb[3];
        CHILD_CHECK(refused(ctx, umbra_renderer_render(r, W, H, px), "umbra_renderer_render"));
        CHILD_CHECK(refused(ctx, umbra_renderer_render_to_cl_buffer(r, W, H, buf),
                            "umbra_renderer_render_to_cl_buffer"));
        cl_event done = (cl_event)1;
        CHILD_CHECK(refused(ctx,
                            umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 0, NULL, &done),
                            "umbra_renderer_render_to_cl_buffer_async"));
        CHILD_CHECK(done == NULL);
        CHILD_CHECK(refused(ctx, umbra_renderer_query_shadow(r, point, 1, rgb),
                            "umbra_renderer_query_shadow"));
        umbra_volume v = NULL;
        const uint8_t voxels[8] = {0};
        umbra_volume_desc vd;
        umbra_volume_desc_init(&vd);
        vd.data = voxels;
        vd.type = UMBRA_UINT8;
        vd.dims[0] = vd.dims[1] = vd.dims[2] = 2;
        CHILD_CHECK(refused(ctx, umbra_volume_create(ctx, &vd, &v), "umbra_volume_create"));
        CHILD_CHECK(v == NULL);
        umbra_transfer_function tf = NULL;
        const float table[8] = {0, 0, 0, 0, 1, 1, 1, 1};
        CHILD_CHECK(refused(ctx, umbra_transfer_function_create(ctx, table, 2, &tf),
                            "umbra_transfer_function_create"));
        umbra_scene sc2;
        CHILD_CHECK(umbra_scene_create(ctx, "spheres", 8, &sc2) == UMBRA_ERROR_UNSUPPORTED);
        /* A new context: OpenCL was started in the parent. */
        umbra_context_desc d;
        umbra_context_desc_init(&d);
        d.error_callback = keep_message;
        umbra_context c2 = (umbra_context)1;
        CHILD_CHECK(refused(NULL, umbra_context_create(&d, &c2), "umbra_context_create"));
        CHILD_CHECK(c2 == NULL);
        CHILD_CHECK(refused(NULL,
                            umbra_context_create_from_cl(umbra_context_cl_context(ctx),
                                                         umbra_context_cl_device(ctx),
                                                         umbra_context_cl_queue(ctx), &d, &c2),
                            "umbra_context_create_from_cl"));
        /* Releasing what the parent made returns (and leaves the parent's objects alone). */
        clReleaseMemObject(buf);
        umbra_renderer_release(r);
        umbra_scene_release(&sc);
        umbra_context_release(ctx);
        _exit(0);
    }
    assert_int_equal(child_result(pid, "fork"), 0);
    /* The parent goes on as before. */
    assert_int_equal(umbra_renderer_render(r, W, H, after), UMBRA_SUCCESS);
    assert_memory_equal(before, after, sizeof before);
    clReleaseMemObject(buf);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_SUCCESS);
}

/* ---- a failed wait-list event (in a freshly executed child) ---------------------------------- */

static const umbra_shadow_technique techniques[] = {
    UMBRA_SHADOW_NONE, UMBRA_SHADOW_REFERENCE, UMBRA_SHADOW_THRESHOLD,
    UMBRA_SHADOW_DEEP, UMBRA_SHADOW_CSSM,      UMBRA_SHADOW_CONVOLUTION};

static cl_int event_status(cl_event e)
{
    cl_int s = 1;
    assert_int_equal(clGetEventInfo(e, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof s, &s, NULL),
                     CL_SUCCESS);
    return s;
}

static void fill(umbra_context ctx, cl_mem buf, float value)
{
    cl_command_queue q = umbra_context_cl_queue(ctx);
    assert_int_equal(clEnqueueFillBuffer(q, buf, &value, sizeof value, 0, 4 * W * H * sizeof value,
                                         0, NULL, NULL),
                     CL_SUCCESS);
    assert_int_equal(clFinish(q), CL_SUCCESS);
}

static void read_back(umbra_context ctx, cl_mem buf, float *out)
{
    assert_int_equal(clEnqueueReadBuffer(umbra_context_cl_queue(ctx), buf, CL_TRUE, 0,
                                         4 * W * H * sizeof *out, out, 0, NULL, NULL),
                     CL_SUCCESS);
}

static int all_equal(const float *v, float x)
{
    for (size_t i = 0; i < 4 * W * H; ++i)
        if (v[i] != x)
            return 0;
    return 1;
}

/* Runs in the child. For every technique, on a fresh renderer (its builds happen in the call):
 * the frame behind a user event set to -5 ends with an error and leaves the buffer as it was;
 * two frames behind two events, the first of which fails, both end; an event that has already
 * failed is refused; the context then renders the same image as a fresh renderer, blocking and
 * asynchronously. */
static void child_failed_wait_event_fails_the_frame(void **state)
{
    umbra_context ctx = *state;
    cl_context cl = umbra_context_cl_context(ctx);
    static float got[4 * W * H], want[4 * W * H];
    cl_int err;
    cl_mem buf = clCreateBuffer(cl, CL_MEM_READ_WRITE, sizeof got, NULL, &err);
    assert_int_equal(err, CL_SUCCESS);
    for (size_t t = 0; t < sizeof techniques / sizeof techniques[0]; ++t) {
        const char *name = umbra_shadow_technique_name(techniques[t]);
        umbra_scene sc;
        umbra_renderer r = spheres(ctx, techniques[t], &sc);
        fill(ctx, buf, -7.0f);
        cl_event user = clCreateUserEvent(cl, &err), done = NULL;
        assert_int_equal(err, CL_SUCCESS);
        assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &user, &done),
                         UMBRA_SUCCESS);
        assert_int_equal(clSetUserEventStatus(user, -5), CL_SUCCESS);
        assert_int_not_equal(clWaitForEvents(1, &done), CL_SUCCESS);
        const cl_int ended = event_status(done);
        print_message("  %-11s frame behind a failed event: done ends with %d\n", name, ended);
        assert_true(ended < 0);
        read_back(ctx, buf, got);
        assert_true(all_equal(got, -7.0f)); /* nothing of the frame ran */
        umbra_render_stats stats;
        assert_int_equal(umbra_renderer_get_stats(r, &stats), UMBRA_SUCCESS);
        assert_int_equal(stats.render_timing, UMBRA_TIMING_NONE);
        clReleaseEvent(done);
        clReleaseEvent(user);

        /* Two frames queued, the first one's event fails, the second's completes: on the
         * in-order queue the second frame follows the first, so it ends (with the first's
         * error) instead of waiting forever. */
        cl_event users[2], dones[2];
        for (int f = 0; f < 2; ++f) {
            users[f] = clCreateUserEvent(cl, &err);
            assert_int_equal(err, CL_SUCCESS);
            assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &users[f],
                                                                      &dones[f]),
                             UMBRA_SUCCESS);
        }
        assert_int_equal(clSetUserEventStatus(users[1], CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clSetUserEventStatus(users[0], -5), CL_SUCCESS);
        clWaitForEvents(2, dones);
        assert_true(event_status(dones[0]) < 0);
        assert_true(event_status(dones[1]) <= CL_COMPLETE);
        for (int f = 0; f < 2; ++f) {
            clReleaseEvent(dones[f]);
            clReleaseEvent(users[f]);
        }

        /* An event that has already failed: refused before anything is enqueued. */
        cl_event failed = clCreateUserEvent(cl, &err);
        assert_int_equal(err, CL_SUCCESS);
        assert_int_equal(clSetUserEventStatus(failed, -5), CL_SUCCESS);
        done = (cl_event)1;
        test_assert_failed(ctx,
                           umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &failed,
                                                                    &done),
                           UMBRA_ERROR_INVALID_ARGUMENT, "wait_list[0]", "has ended in an error");
        assert_null(done);
        clReleaseEvent(failed);

        /* The renderer goes on: blocking, then asynchronously, both as a fresh renderer draws. */
        umbra_scene sc2;
        umbra_renderer fresh = spheres(ctx, techniques[t], &sc2);
        assert_int_equal(umbra_renderer_render(fresh, W, H, want), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render(r, W, H, got), UMBRA_SUCCESS);
        assert_memory_equal(got, want, sizeof got);
        user = clCreateUserEvent(cl, &err);
        assert_int_equal(err, CL_SUCCESS);
        fill(ctx, buf, -7.0f);
        assert_int_equal(umbra_renderer_render_to_cl_buffer_async(r, W, H, buf, 1, &user, &done),
                         UMBRA_SUCCESS);
        assert_int_equal(clSetUserEventStatus(user, CL_COMPLETE), CL_SUCCESS);
        assert_int_equal(clWaitForEvents(1, &done), CL_SUCCESS);
        read_back(ctx, buf, got);
        assert_memory_equal(got, want, sizeof got);
        clReleaseEvent(done);
        clReleaseEvent(user);
        umbra_renderer_release(fresh);
        umbra_scene_release(&sc2);
        umbra_renderer_release(r);
        umbra_scene_release(&sc);
    }
    clReleaseMemObject(buf);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_SUCCESS);
}

static void test_failed_wait_event_fails_the_frame_without_aborting(void **state)
{
    (void)state;
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    assert_true(n > 0);
    self[n] = '\0';
    char *argv[] = {self, "--child", NULL};
    pid_t pid;
    fflush(NULL);
    assert_int_equal(posix_spawn(&pid, self, NULL, NULL, argv, environ), 0);
    assert_int_equal(child_result(pid, "failed wait-list event"), 0);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--child") == 0) {
        alarm(240); /* a frame that waited forever would hang the child: end it instead */
        const struct CMUnitTest child[] = {
            cmocka_unit_test(child_failed_wait_event_fails_the_frame),
        };
        return cmocka_run_group_tests(child, test_group_setup, test_group_teardown);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_forked_child_is_refused_at_every_entry_point),
        cmocka_unit_test(test_failed_wait_event_fails_the_frame_without_aborting),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
