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
 *    stops its pass when it asks for them). */
#include <math.h>
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

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_progress_fractions_are_monotone_and_end_at_1),
        cmocka_unit_test(test_cancel_from_callback_stops_render_and_next_render_succeeds),
        cmocka_unit_test(test_query_shadow_reports_and_cancels_its_build),
        cmocka_unit_test(test_deep_map_beyond_device_memory_fails_with_out_of_memory),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
