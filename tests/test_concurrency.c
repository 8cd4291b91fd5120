// SPDX-License-Identifier: Apache-2.0
/* tests/test_concurrency.c: umbra on several threads (issue 11, rows 1 and 14).
 *
 *  - several threads creating contexts as the process's first OpenCL use (PoCL's lazy device
 *    set-up crashed in 28 of 40 runs before device discovery was serialised): the test runs
 *    itself as fresh child processes, each a first use, and every thread renders the same image;
 *  - two renderers on one context, on two threads, building their programs into the shared cache
 *    and recording errors at once, render what they render alone (ThreadSanitizer checks this
 *    test in CI: .ci/sanitize.sh).
 *
 * This file must not create a context before its threads do: it is its own executable. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.h"

enum { THREADS = 4, CHILDREN = 8, W = 24, H = 24, ROUNDS = 3 };

/* A small scene every thread renders the same way: a sphere-ish blob with reference shadows. */
static umbra_status render_scene(umbra_context ctx, umbra_shadow_technique technique, float *rgba)
{
    enum { N = 12 };
    float data[N * N * N];
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x) {
                float dx = x - 5.5f, dy = y - 5.5f, dz = z - 5.5f;
                data[(z * N + y) * N + x] = (dx * dx + dy * dy + dz * dz) < 20.0f ? 1.0f : 0.1f;
            }
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = N;
    umbra_volume v = NULL;
    umbra_transfer_function tf = NULL;
    umbra_renderer r = NULL;
    const float table[8] = {0.9f, 0.6f, 0.3f, 0.0f, 0.9f, 0.6f, 0.3f, 0.4f};
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = technique;
    s.map.size = 64;
    umbra_status st = umbra_volume_create(ctx, &d, &v);
    if (!st)
        st = umbra_transfer_function_create(ctx, table, 2, &tf);
    if (!st)
        st = umbra_renderer_create(ctx, &r);
    if (!st)
        st = umbra_renderer_set_volume(r, v);
    if (!st)
        st = umbra_renderer_set_transfer_function(r, tf);
    if (!st)
        st = umbra_renderer_set_shadow(r, &s);
    /* A refused argument on the way: the error state is shared by the context's threads. */
    if (!st && umbra_renderer_set_shadow(r, NULL) != UMBRA_ERROR_INVALID_ARGUMENT)
        st = UMBRA_ERROR_INVALID_ARGUMENT;
    if (!st)
        st = umbra_renderer_render(r, W, H, rgba);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
    return st;
}

static umbra_context create_context(void)
{
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    if (!getenv("UMBRA_DEVICE"))
        d.device_name = "pthread"; /* PoCL's CPU device, as test_context */
    umbra_context ctx = NULL;
    return umbra_context_create(&d, &ctx) == UMBRA_SUCCESS ? ctx : NULL;
}

/* ---- start-up ------------------------------------------------------------------------------ */

typedef struct startup_job {
    pthread_barrier_t *go;
    umbra_status st;
    float rgba[4 * W * H];
} startup_job;

static void *startup_thread(void *arg)
{
    startup_job *job = arg;
    pthread_barrier_wait(job->go);
    umbra_context ctx = create_context();
    job->st = ctx ? render_scene(ctx, UMBRA_SHADOW_REFERENCE, job->rgba) : UMBRA_ERROR_NO_DEVICE;
    umbra_context_release(ctx);
    return NULL;
}

/* THREADS threads create their contexts at once and render; 0 if all succeeded with the same
 * image. Run as a child process, this is the process's first OpenCL use. */
static int startup_race(void)
{
    static startup_job jobs[THREADS];
    pthread_t threads[THREADS];
    pthread_barrier_t go;
    pthread_barrier_init(&go, NULL, THREADS);
    for (int i = 0; i < THREADS; ++i) {
        jobs[i].go = &go;
        pthread_create(&threads[i], NULL, startup_thread, &jobs[i]);
    }
    for (int i = 0; i < THREADS; ++i)
        pthread_join(threads[i], NULL);
    pthread_barrier_destroy(&go);
    int bad = 0;
    for (int i = 0; i < THREADS; ++i) {
        if (jobs[i].st != UMBRA_SUCCESS) {
            fprintf(stderr, "thread %d: %s\n", i, umbra_status_to_string(jobs[i].st));
            bad = 1;
        } else if (memcmp(jobs[i].rgba, jobs[0].rgba, sizeof jobs[0].rgba) != 0) {
            fprintf(stderr, "thread %d rendered a different image\n", i);
            bad = 1;
        }
    }
    return bad;
}

static void test_contexts_created_on_threads_at_start_up_render_identical_images(void **state)
{
    (void)state;
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    assert_true(n > 0);
    self[n] = 0;
    /* Each child is a fresh process: its threads race through OpenCL's start-up. */
    for (int c = 0; c < CHILDREN; ++c) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            execl(self, self, "--startup-child", (char *)NULL);
            _exit(127);
        }
        int status = 0;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        if (WIFSIGNALED(status))
            fail_msg("child %d died of signal %d", c, WTERMSIG(status));
        assert_true(WIFEXITED(status));
        assert_int_equal(WEXITSTATUS(status), 0);
    }
    /* And this process, whose first OpenCL use this is too; then more rounds after start-up. */
    for (int round = 0; round < ROUNDS; ++round)
        assert_int_equal(startup_race(), 0);
}

/* ---- two renderers on one context ----------------------------------------------------------- */

typedef struct shared_job {
    umbra_context ctx;
    umbra_shadow_technique technique;
    pthread_barrier_t *go;
    umbra_status st;
    float rgba[ROUNDS][4 * W * H];
} shared_job;

static void *shared_thread(void *arg)
{
    shared_job *job = arg;
    pthread_barrier_wait(job->go);
    job->st = UMBRA_SUCCESS;
    for (int i = 0; i < ROUNDS && job->st == UMBRA_SUCCESS; ++i)
        job->st = render_scene(job->ctx, job->technique, job->rgba[i]);
    return NULL;
}

static void test_two_renderers_on_one_context_on_two_threads_render_as_alone(void **state)
{
    (void)state;
    static const umbra_shadow_technique techniques[] = {UMBRA_SHADOW_REFERENCE,
                                                        UMBRA_SHADOW_THRESHOLD, UMBRA_SHADOW_DEEP,
                                                        UMBRA_SHADOW_CSSM};
    enum { JOBS = sizeof techniques / sizeof techniques[0] };
    umbra_context ctx = create_context();
    assert_non_null(ctx);
    static shared_job jobs[JOBS];
    pthread_t threads[JOBS];
    pthread_barrier_t go;
    pthread_barrier_init(&go, NULL, JOBS);
    for (int i = 0; i < JOBS; ++i) {
        jobs[i].ctx = ctx;
        jobs[i].technique = techniques[i];
        jobs[i].go = &go;
        pthread_create(&threads[i], NULL, shared_thread, &jobs[i]);
    }
    for (int i = 0; i < JOBS; ++i)
        pthread_join(threads[i], NULL);
    pthread_barrier_destroy(&go);
    /* Each technique alone, on a fresh context, gives the same image bit for bit. */
    umbra_context alone = create_context();
    assert_non_null(alone);
    for (int i = 0; i < JOBS; ++i) {
        static float expect[4 * W * H];
        assert_int_equal(jobs[i].st, UMBRA_SUCCESS);
        assert_int_equal(render_scene(alone, techniques[i], expect), UMBRA_SUCCESS);
        for (int k = 0; k < ROUNDS; ++k)
            assert_memory_equal(jobs[i].rgba[k], expect, sizeof expect);
    }
    /* The first error the threads recorded is one of theirs, whole. */
    const char *message = NULL;
    assert_int_equal(umbra_context_take_error(ctx, &message), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(message, "umbra_renderer_set_shadow: desc is NULL"));
    umbra_context_release(alone);
    umbra_context_release(ctx);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--startup-child") == 0)
        return startup_race();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contexts_created_on_threads_at_start_up_render_identical_images),
        cmocka_unit_test(test_two_renderers_on_one_context_on_two_threads_render_as_alone),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
