// SPDX-License-Identifier: Apache-2.0
/* tests/test_interaction.c: progressive shadows (umbra_render_desc.interaction, umbra/renderer.h).
 *  - under UMBRA_INTERACTION_AUTO a frame after a light or transfer-function change uses the
 *    technique's draft (umbra_technique_info.draft): stats.draft set, the image bit for bit a
 *    fresh renderer's with the draft's parameters set by hand; the next frame with nothing
 *    changed builds the full structure, bit for bit a fresh full render; a camera move keeps it;
 *  - the first frame, queries, techniques without a draft and UMBRA_INTERACTION_OFF use the full
 *    structure; a view transfer-function change under a separate light one is no change;
 *  - the draft's parameters: the map's texels per voxel (auto sizes; the deep map's light step
 *    and epsilon too), a fixed size scaled and bounded, a coarser application setting kept;
 *    every registered draft applies, and the accuracy sweep's draft row of each technique
 *    (label "..., draft") is that draft;
 *  - set_options refuses an unknown interaction and accepts umbra 0.5.0's layout. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conformance.h"
#include "renderer_internal.h"
#include "setting.h"
#include "test_util.h"

enum { NX = CONF_TWO_BALLS_NX, NY = CONF_TWO_BALLS_NY, NZ = CONF_TWO_BALLS_NZ };
enum { W = 48, H = 40, PIXELS = W * H * 4 };

static umbra_context ctx;
static umbra_volume vol;
static umbra_transfer_function tf_a, tf_b;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    const float a[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.08f, 0.3f, 0.8f, 0.4f, 0.2f,
                         0.7f, 0.7f, 0.9f, 0.5f};
    const float b[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.15f, 0.3f, 0.8f, 0.4f, 0.4f,
                         0.7f, 0.7f, 0.9f, 0.8f};
    if (rc == 0 && (conf_volume(ctx, NX, NY, NZ, conf_two_balls, &vol) != UMBRA_SUCCESS ||
                    umbra_transfer_function_create(ctx, a, 4, &tf_a) != UMBRA_SUCCESS ||
                    umbra_transfer_function_create(ctx, b, 4, &tf_b) != UMBRA_SUCCESS))
        rc = -1;
    return rc;
}

static int teardown(void **state)
{
    umbra_transfer_function_release(tf_a);
    umbra_transfer_function_release(tf_b);
    umbra_volume_release(vol);
    return test_group_teardown(state);
}

static const umbra_light light_1 = {UMBRA_LIGHT_POINT, {-40.0f, 70.0f, 30.0f}, {0, -1, 0},
                                    {1, 1, 1}};
static const umbra_light light_2 = {UMBRA_LIGHT_POINT, {-20.0f, 75.0f, 45.0f}, {0, -1, 0},
                                    {1, 1, 1}};

static umbra_camera camera_at(float angle)
{
    const float dir[3] = {sinf(angle), 0.4f, cosf(angle)};
    return umbra_camera_orbit(dir, 62.0f, 30.0f);
}

/* A renderer on the scene: technique t at its defaults (or sd), coloured light, ground plane. */
static umbra_renderer make(const umbra_shadow_desc *sd, umbra_interaction interaction,
                           const umbra_light *light, umbra_transfer_function tf)
{
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    o.ground_plane = 1;
    o.interaction = interaction;
    const umbra_camera cam = camera_at(0.0f);
    umbra_renderer r = test_renderer(ctx, vol, tf, &cam, light, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, sd), UMBRA_SUCCESS);
    return r;
}

static umbra_shadow_desc shadow_of(umbra_shadow_technique t)
{
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = t;
    return sd;
}

static umbra_render_stats render(umbra_renderer r, float *img)
{
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    return st;
}

static void expect_same(const float *got, const float *want, const char *what, const char *name)
{
    for (long i = 0; i < PIXELS; ++i)
        if (memcmp(&got[i], &want[i], sizeof got[i]) != 0)
            fail_msg("%s: %s: pixel (%ld, %ld) channel %ld is %.9g, a fresh renderer's %.9g", name,
                     what, i / 4 % W, i / 4 / W, i % 4, got[i], want[i]);
}

static int differs(const float *a, const float *b)
{
    return memcmp(a, b, PIXELS * sizeof *a) != 0;
}

/* For every technique with a draft: frame 1 full, a light move drafts (equal to a fresh renderer
 * given the draft's parameters), the next unchanged frame is the full map (equal to a fresh full
 * render), a camera move keeps it; a new transfer function drafts again and refines again. */
static void test_interaction_draft_then_full_equals_fresh(void **state)
{
    (void)state;
    static float img[PIXELS], want[PIXELS], draft_img[PIXELS];
    int drafted = 0;
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        if (!t->draft)
            continue;
        const umbra_shadow_desc full = shadow_of(t->id);
        umbra_renderer r = make(&full, UMBRA_INTERACTION_AUTO, &light_1, tf_a);
        umbra_render_stats st = render(r, img);
        assert_int_equal(st.draft, 0); /* the first frame: nothing moved */
        assert_true(st.shadow_rebuilt);

        assert_int_equal(umbra_renderer_set_light(r, &light_2), UMBRA_SUCCESS);
        st = render(r, draft_img);
        if (!st.draft)
            fail_msg("%s: the frame after a light move is not a draft", t->name);
        assert_true(st.shadow_rebuilt);
        const uint32_t draft_size = st.map_size;
        umbra_shadow_desc by_hand;
        assert_int_equal(umbra__draft_desc(umbra__technique_by_id(t->id), &full, &by_hand), 1);
        umbra_renderer f = make(&by_hand, UMBRA_INTERACTION_OFF, &light_2, tf_a);
        umbra_render_stats fs = render(f, want);
        assert_int_equal(fs.draft, 0);
        assert_int_equal(fs.map_size, draft_size);
        expect_same(draft_img, want, "the draft frame", t->name);
        umbra_renderer_release(f);

        st = render(r, img); /* nothing changed: the full map */
        assert_int_equal(st.draft, 0);
        assert_true(st.shadow_rebuilt);
        f = make(&full, UMBRA_INTERACTION_OFF, &light_2, tf_a);
        fs = render(f, want);
        expect_same(img, want, "the frame after the light stopped", t->name);
        assert_int_equal(st.map_size, fs.map_size);
        if ((t->flags & UMBRA_TECHNIQUE_MAP) && !(draft_size < st.map_size))
            fail_msg("%s: draft map %u^2 is not smaller than the full %u^2", t->name,
                     draft_size, st.map_size);
        assert_true(differs(draft_img, img)); /* the draft is another structure */
        umbra_renderer_release(f);

        /* A camera move: the full map is kept, no draft. */
        const umbra_camera cam = camera_at(0.3f);
        assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
        st = render(r, img);
        assert_int_equal(st.draft, 0);
        assert_false(st.shadow_rebuilt);

        /* A new transfer function (the light pass reads it): a draft, then the full map. */
        assert_int_equal(umbra_renderer_set_transfer_function(r, tf_b), UMBRA_SUCCESS);
        st = render(r, img);
        assert_int_equal(st.draft, 1);
        st = render(r, img);
        assert_int_equal(st.draft, 0);
        assert_true(st.shadow_rebuilt);
        f = make(&full, UMBRA_INTERACTION_OFF, &light_2, tf_b);
        assert_int_equal(umbra_renderer_set_camera(f, &cam), UMBRA_SUCCESS);
        render(f, want);
        expect_same(img, want, "after the transfer function stopped changing", t->name);
        umbra_renderer_release(f);
        umbra_renderer_release(r);
        print_message("%-10s draft %u^2, full %u^2\n", t->name, draft_size, st.map_size);
        ++drafted;
    }
    assert_true(drafted >= 2); /* CSSM and the deep map have drafts */
}

/* Without interaction (the default), or for a technique without a draft, every frame is full;
 * a change of the view transfer function under a separate light one changes no map input. */
static void test_interaction_off_and_no_draft_stay_full(void **state)
{
    (void)state;
    static float img[PIXELS], want[PIXELS];
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    assert_int_equal(o.interaction, UMBRA_INTERACTION_OFF);
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        if (t->flags & UMBRA_TECHNIQUE_FRAME)
            continue; /* renders the frame itself: covered by the no-draft branch below too */
        const umbra_shadow_desc sd = shadow_of(t->id);
        umbra_renderer r = make(&sd, t->draft ? UMBRA_INTERACTION_OFF : UMBRA_INTERACTION_AUTO,
                                &light_1, tf_a);
        render(r, img);
        assert_int_equal(umbra_renderer_set_light(r, &light_2), UMBRA_SUCCESS);
        umbra_render_stats st = render(r, img);
        assert_int_equal(st.draft, 0);
        umbra_renderer f = make(&sd, UMBRA_INTERACTION_OFF, &light_2, tf_a);
        render(f, want);
        expect_same(img, want, t->draft ? "interaction off" : "no draft", t->name);
        umbra_renderer_release(f);
        umbra_renderer_release(r);
    }
    /* A separate light transfer function: the view one's change rebuilds nothing. */
    const umbra_shadow_desc deep = shadow_of(UMBRA_SHADOW_DEEP);
    umbra_renderer r = make(&deep, UMBRA_INTERACTION_AUTO, &light_1, tf_a);
    assert_int_equal(umbra_renderer_set_light_transfer_function(r, tf_a), UMBRA_SUCCESS);
    render(r, img);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf_b), UMBRA_SUCCESS);
    umbra_render_stats st = render(r, img);
    assert_int_equal(st.draft, 0);
    assert_false(st.shadow_rebuilt);
    umbra_renderer_release(r);
}

/* A query after a draft frame answers from the full structure, as a fresh renderer does; the
 * frame after it (nothing changed) keeps that structure. */
static void test_interaction_query_uses_full(void **state)
{
    (void)state;
    static float img[PIXELS];
    const float points[9] = {0.0f, -6.0f, 0.0f, 5.0f, -12.0f, 3.0f, -8.0f, -13.0f, -6.0f};
    float got[9], want[9];
    const umbra_shadow_desc deep = shadow_of(UMBRA_SHADOW_DEEP);
    umbra_renderer r = make(&deep, UMBRA_INTERACTION_AUTO, &light_1, tf_a);
    render(r, img);
    assert_int_equal(umbra_renderer_set_light(r, &light_2), UMBRA_SUCCESS);
    assert_int_equal(render(r, img).draft, 1);
    assert_int_equal(umbra_renderer_query_shadow(r, points, 3, got), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.draft, 0);
    assert_true(st.shadow_rebuilt);
    umbra_renderer f = make(&deep, UMBRA_INTERACTION_OFF, &light_2, tf_a);
    assert_int_equal(umbra_renderer_query_shadow(f, points, 3, want), UMBRA_SUCCESS);
    assert_memory_equal(got, want, sizeof got);
    int shadowed = 0;
    for (int i = 0; i < 9; ++i)
        shadowed += want[i] < 0.99f;
    assert_true(shadowed >= 3); /* a point lies in shadow: the check compares shadows */
    st = render(r, img);
    assert_int_equal(st.draft, 0);
    assert_false(st.shadow_rebuilt);
    umbra_renderer_release(f);
    umbra_renderer_release(r);
}

/* The draft's parameters from the registry's strings. */
static void test_interaction_draft_parameters(void **state)
{
    (void)state;
    const umbra__technique *deep = umbra__technique_by_id(UMBRA_SHADOW_DEEP);
    const umbra__technique *cssm = umbra__technique_by_id(UMBRA_SHADOW_CSSM);
    umbra_shadow_desc d = shadow_of(UMBRA_SHADOW_DEEP), out;
    assert_int_equal(umbra__draft_desc(deep, &d, &out), 1);
    assert_true(out.map.texels_per_voxel == 0.5f);
    assert_true(out.map.step == 1.0f); /* the technique's own, 0.5, coarsened */
    assert_true(out.deep.epsilon == 0.06f);
    assert_int_equal(out.map.size, UMBRA_MAP_SIZE_AUTO);
    /* An application's coarser setting is kept. */
    d.map.texels_per_voxel = 0.25f;
    d.map.step = 2.0f;
    d.deep.epsilon = 0.1f;
    assert_int_equal(umbra__draft_desc(deep, &d, &out), 0);
    assert_memory_equal(&out, &d, sizeof d);
    /* A fixed size: scaled by the draft's texels per voxel over the technique's own, rounded
     * up to whole tiles, at least UMBRA_MAP_SIZE_AUTO_MIN, at most the full size. */
    d = shadow_of(UMBRA_SHADOW_DEEP);
    d.map.size = 1024;
    assert_int_equal(umbra__draft_desc(deep, &d, &out), 1);
    assert_int_equal(out.map.size, 256);
    assert_true(out.map.texels_per_voxel == 0.0f);
    d = shadow_of(UMBRA_SHADOW_CSSM);
    d.map.size = 1024;
    assert_int_equal(umbra__draft_desc(cssm, &d, &out), 1);
    assert_int_equal(out.map.size, 352); /* 1024 / 3 = 341.3 */
    d.map.size = 100;
    assert_int_equal(umbra__draft_desc(cssm, &d, &out), 1);
    assert_int_equal(out.map.size, 64);
    d.map.size = 40;
    assert_int_equal(umbra__draft_desc(cssm, &d, &out), 0); /* nothing smaller to draft */
    assert_int_equal(out.map.size, 40);
    /* Every technique's draft applies to its defaults and stays within every range. */
    umbra_renderer r;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra__technique *t = umbra__technique_by_id(umbra_technique_get(i)->id);
        d = shadow_of(t->info.id);
        const int has = umbra__draft_desc(t, &d, &out);
        assert_int_equal(has, t->info.draft != NULL);
        if (has)
            assert_int_equal(umbra_renderer_set_shadow(r, &out), UMBRA_SUCCESS);
    }
    umbra_renderer_release(r);
}

/* The accuracy sweep measures each technique's draft: its row labelled "..., draft" sets what
 * the draft of the technique's defaults sets, and only techniques with a draft have one. */
static void test_interaction_sweep_rows_are_the_drafts(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra__technique *t = umbra__technique_by_id(umbra_technique_get(i)->id);
        int rows = 0;
        for (uint32_t k = 0; k < t->sweep_count; ++k) {
            const char *label = t->sweep[k].label;
            const size_t n = strlen(label);
            if (n < 5 || strcmp(label + n - 5, "draft") != 0)
                continue;
            umbra_shadow_desc d = shadow_of(t->info.id), row = d, draft;
            char msg[2048];
            int preintegrated = 0;
            if (setting_apply(&row, &preintegrated, t->sweep[k].params, msg, sizeof msg) != 0)
                fail_msg("%s", msg);
            assert_int_equal(umbra__draft_desc(t, &d, &draft), 1);
            if (memcmp(&row, &draft, sizeof row) != 0)
                fail_msg("%s: the sweep's row '%s' is not the technique's draft '%s'",
                         t->info.name, t->sweep[k].params, t->info.draft);
            ++rows;
        }
        assert_int_equal(rows > 0, t->info.draft != NULL);
    }
}

/* set_options: an unknown interaction is refused by name; umbra 0.5.0's layout (ending with
 * preintegrated) is accepted and keeps the interaction set before. */
static void test_interaction_options_checked(void **state)
{
    (void)state;
    umbra_renderer r;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.interaction = (umbra_interaction)2;
    test_assert_failed(ctx, umbra_renderer_set_options(r, &o), UMBRA_ERROR_INVALID_ARGUMENT,
                       "umbra_renderer_set_options: interaction 2", NULL);
    o.interaction = UMBRA_INTERACTION_AUTO;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    assert_int_equal(r->opts.interaction, UMBRA_INTERACTION_AUTO);
    umbra_render_desc old = o;
    old.struct_size = (offsetof(umbra_render_desc, preintegrated) + sizeof(int) +
                       _Alignof(umbra_render_desc) - 1) /
                      _Alignof(umbra_render_desc) * _Alignof(umbra_render_desc);
    old.interaction = (umbra_interaction)7; /* beyond that layout: not read */
    old.shading = 1;
    assert_int_equal(umbra_renderer_set_options(r, &old), UMBRA_SUCCESS);
    assert_int_equal(r->opts.interaction, UMBRA_INTERACTION_AUTO);
    assert_int_equal(r->opts.shading, 1);
    umbra_renderer_release(r);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interaction_draft_then_full_equals_fresh),
        cmocka_unit_test(test_interaction_off_and_no_draft_stay_full),
        cmocka_unit_test(test_interaction_query_uses_full),
        cmocka_unit_test(test_interaction_draft_parameters),
        cmocka_unit_test(test_interaction_sweep_rows_are_the_drafts),
        cmocka_unit_test(test_interaction_options_checked),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
