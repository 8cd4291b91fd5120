// SPDX-License-Identifier: Apache-2.0
/* tests/test_registry.c: the technique registry as umbra/registry.h shows it.
 *  - every technique of umbra/techniques/list.h is registered once under its enum value and
 *    name; names, ids and keys are unique; umbra_shadow_technique_name/parse agree with it;
 *  - every parameter is described (name, key, doc), its default lies in its range and is what
 *    umbra_shadow_desc_init sets, its storage lies in the technique's own member (or the shared
 *    map's, for a map technique's), and no technique has more than the rebuild key holds;
 *  - set_param/get_param by name, key and alias round-trip every type; technique NULL sets every
 *    technique that has the key and names the desc's own technique first when it refuses;
 *    unknown techniques and parameters are refused with the known ones listed, messages are
 *    truncated to the caller's buffer, and NULL arguments are refused;
 *  - umbra 0.4's flat umbra_shadow_desc and umbra_render_desc are accepted by struct_size and
 *    render bit for bit what the 0.5 layout gives (0.4's preintegrated reaching the render
 *    options), other sizes are refused.
 * Usage: test_registry [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "test_util.h"

static void test_registry_lists_every_technique_once(void **state)
{
    (void)state;
    const uint32_t n = umbra_technique_count();
    uint32_t rows = 0;
#define COUNT_ROW(name, NAME, id, member) ++rows;
    UMBRA_TECHNIQUE_LIST(COUNT_ROW)
#undef COUNT_ROW
    assert_int_equal(n, rows);
    assert_null(umbra_technique_get(n));
    for (uint32_t i = 0; i < n; ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        assert_non_null(t);
        assert_ptr_equal(umbra_technique_find(t->name), t);
        assert_ptr_equal(umbra_technique_find_id(t->id), t);
        assert_string_equal(umbra_shadow_technique_name(t->id), t->name);
        umbra_shadow_technique parsed;
        assert_int_equal(umbra_shadow_technique_parse(t->name, &parsed), UMBRA_SUCCESS);
        assert_int_equal(parsed, t->id);
        assert_true(t->title && t->title[0] && t->doc && strlen(t->doc) > 20);
        for (uint32_t j = 0; j < i; ++j) {
            assert_int_not_equal(umbra_technique_get(j)->id, t->id);
            assert_string_not_equal(umbra_technique_get(j)->name, t->name);
        }
        /* A map technique says what its map parameters' 0 means. */
        if (t->flags & UMBRA_TECHNIQUE_MAP)
            assert_true(t->map_texels_per_voxel > 0.0f && t->map_step > 0.0f);
    }
    /* The enum is the list's. */
#define CHECK_ROW(name, NAME, id, member)                                                      \
    assert_int_equal(UMBRA_SHADOW_##NAME, id);                                                 \
    assert_string_equal(umbra_shadow_technique_name(UMBRA_SHADOW_##NAME), #name);
    UMBRA_TECHNIQUE_LIST(CHECK_ROW)
#undef CHECK_ROW
    assert_null(umbra_technique_find("nonesuch"));
    assert_null(umbra_technique_find(NULL));
    assert_null(umbra_technique_find_id((umbra_shadow_technique)99));
    assert_null(umbra_shadow_technique_name((umbra_shadow_technique)99));
}

static void test_registry_parameters_described_and_defaulted(void **state)
{
    (void)state;
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    assert_int_equal(d.struct_size, sizeof d);
    assert_int_equal(d.technique, UMBRA_SHADOW_NONE);
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        const umbra__technique *desc = umbra__technique_by_id(t->id);
        assert_true(t->param_count <= UMBRA__MAX_PARAMS);
        assert_null(umbra_technique_param_get(t, t->param_count));
        int map_params = 0;
        for (uint32_t k = 0; k < t->param_count; ++k) {
            const umbra_param_info *p = umbra_technique_param_get(t, k);
            assert_true(p->name && p->key && p->doc && p->doc[0]);
            assert_ptr_equal(umbra_technique_param_find(t, p->key), p);
            assert_ptr_equal(umbra_technique_param_find(t, p->name), p);
            if (p->alias)
                assert_ptr_equal(umbra_technique_param_find(t, p->alias), p);
            for (uint32_t j = 0; j < k; ++j)
                assert_string_not_equal(umbra_technique_param_get(t, j)->key, p->key);
            assert_true(p->min <= p->max);
            assert_true(!(p->flags & UMBRA_PARAM_ZERO) || (p->zero_doc && p->zero_doc[0]));
            /* The default is what init set, and set_param accepts it. */
            double v;
            char msg[256];
            assert_int_equal(umbra_shadow_desc_get_param(&d, t->name, p->key, &v), UMBRA_SUCCESS);
            const double want =
                p->type == UMBRA_PARAM_FLOAT ? (double)(float)p->default_value : p->default_value;
            if (v != want)
                fail_msg("%s %s: init set %g, the registry says %g", t->name, p->key, v,
                         p->default_value);
            umbra_shadow_desc e = d;
            assert_int_equal(umbra_shadow_desc_set_param(&e, t->name, p->key, p->default_value,
                                                         msg, sizeof msg),
                             UMBRA_SUCCESS);
            assert_string_equal(msg, "");
            assert_memory_equal(&e, &d, sizeof d);
            /* The value lives in the technique's own member, or in the shared map's. */
            const size_t off = desc->params[k].offset;
            if (p->flags & UMBRA_PARAM_MAP) {
                ++map_params;
                assert_true(off >= offsetof(umbra_shadow_desc, map) &&
                            off < offsetof(umbra_shadow_desc, map) + sizeof(umbra_map_desc));
            } else {
                for (uint32_t u = 0; u < umbra_technique_count(); ++u) {
                    const umbra__technique *o = umbra__technique_by_id(umbra_technique_get(u)->id);
                    for (uint32_t j = 0; o != desc && j < o->info.param_count; ++j)
                        assert_int_not_equal(o->params[j].offset, off);
                }
            }
        }
        assert_int_equal(map_params, (t->flags & UMBRA_TECHNIQUE_MAP) ? 3 : 0);
    }
}

static void test_registry_set_and_get_by_name(void **state)
{
    (void)state;
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    char msg[1024];
    double v;
    /* Every type, by key, name and alias. */
    assert_int_equal(umbra_shadow_desc_set_param(&d, "deep", "epsilon", 0.05, msg, sizeof msg),
                     UMBRA_SUCCESS);
    assert_true(d.deep.epsilon == 0.05f);
    assert_int_equal(umbra_shadow_desc_set_param(&d, "deep", "nodes", 6, msg, sizeof msg),
                     UMBRA_SUCCESS);
    assert_int_equal(d.deep.max_nodes, 6);
    assert_int_equal(umbra_shadow_desc_set_param(&d, "deep", "lookup_table", 0, msg, sizeof msg),
                     UMBRA_SUCCESS);
    assert_int_equal(d.deep.lookup_table, 0);
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "size", 256, msg, sizeof msg),
                     UMBRA_SUCCESS);
    assert_int_equal(d.map.size, 256);
    assert_int_equal(umbra_shadow_desc_get_param(&d, "threshold", "map_size", &v), UMBRA_SUCCESS);
    assert_true(v == 256.0); /* the map's parameters are shared */
    assert_int_equal(umbra_shadow_desc_get_param(&d, "reference", "reference_step", &v),
                     UMBRA_SUCCESS);
    assert_true(v == 0.25);
    /* technique NULL: every technique with the key, the desc's own technique first. */
    d.technique = UMBRA_SHADOW_CSSM;
    assert_int_equal(umbra_shadow_desc_set_param(&d, NULL, "taps", 7, msg, sizeof msg),
                     UMBRA_SUCCESS);
    assert_int_equal(d.threshold.taps, 7);
    assert_int_equal(d.cssm.taps, 7);
    d.threshold.taps = 21;
    assert_int_equal(umbra_shadow_desc_get_param(&d, NULL, "taps", &v), UMBRA_SUCCESS);
    assert_true(v == 7.0); /* the desc's technique's */
    assert_int_equal(umbra_shadow_desc_set_param(&d, NULL, "taps", 5, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_string_equal(msg, "umbra_shadow_desc_set_param: cssm taps 5 must be 1, 7, 13 or 21");
    assert_int_equal(d.cssm.taps, 7); /* nothing changed */
    assert_int_equal(d.threshold.taps, 21);
    /* Refusals name what is known. */
    assert_int_equal(umbra_shadow_desc_set_param(&d, "shiny", "taps", 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "technique 'shiny' is unknown (none, reference,"));
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "tap", 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "cssm has no parameter 'tap' (map_size,"));
    assert_int_equal(umbra_shadow_desc_set_param(&d, "none", "taps", 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "it has none"));
    assert_int_equal(umbra_shadow_desc_set_param(&d, NULL, "shininess", 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "no technique has a parameter 'shininess'"));
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "ray_block", 4, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_string_equal(msg, "umbra_shadow_desc_set_param: cssm ray_block 4 must be 0 (the "
                             "map's own) or lie in [1, 3]");
    assert_int_equal(umbra_shadow_desc_set_param(&d, "deep", "lookup_table", 2, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "deep lookup_table 2 must be 0 or 1"));
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "seed", 4294967296.0, msg,
                                                 sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(msg, "cssm seed 4294967296 must be a whole number"));
    /* Truncated to the buffer; no buffer at all. */
    char small[16];
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "taps", 5, small, sizeof small),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(strlen(small), sizeof small - 1);
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", "taps", 5, NULL, 0),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_shadow_desc_set_param(NULL, "cssm", "taps", 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_shadow_desc_set_param(&d, "cssm", NULL, 7, msg, sizeof msg),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_shadow_desc_get_param(&d, "cssm", "taps", NULL),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_shadow_desc_get_param(&d, "cssm", "nonesuch", &v),
                     UMBRA_ERROR_INVALID_ARGUMENT);
}

/* ---- older layouts --------------------------------------------------------------------------- */

/* umbra 0.4's public umbra_shadow_desc, as an application built against 0.4 fills it. */
typedef struct shadow_desc_0_4 {
    size_t struct_size;
    umbra_shadow_technique technique;
    float reference_step;
    uint32_t map_size;
    float map_texels_per_voxel, map_step, threshold;
    uint32_t taps;
    float epsilon;
    uint32_t max_nodes, block_size, prefilter;
    int lookup_table;
    uint32_t seed, ray_block;
    float slice_distance;
    uint32_t subsamples;
    int preintegrated;
    float cone_angle_degrees;
} shadow_desc_0_4;

static shadow_desc_0_4 old_defaults(umbra_shadow_technique t)
{
    shadow_desc_0_4 o = {sizeof(shadow_desc_0_4), t, 0.25f, 0, 0.0f, 0.0f, 0.5f, 13, 0.02f, 0,
                         8, 1, 1, 1, 0, 0.5f, 0, 0, 5.0f};
    return o;
}

/* An old desc where the new API takes a new one: what a 0.4 binary passes. */
static const umbra_shadow_desc *as_0_5(const shadow_desc_0_4 *old)
{
    return (const umbra_shadow_desc *)(const void *)old;
}

static void render_with(umbra_renderer r, const void *shadow, const void *options, float *img)
{
    assert_int_equal(umbra_renderer_set_options(r, options), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_shadow(r, shadow), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 32, 24, img), UMBRA_SUCCESS);
}

static void test_registry_layout_0_4_accepted(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 24, &sc), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &sc.light, &sc.options);
    static float a[32 * 24 * 4], b[32 * 24 * 4];
    umbra_render_desc o = sc.options;
    /* 0.4's render options end before preintegrated. */
    umbra_render_desc o_0_4 = o;
    o_0_4.struct_size = offsetof(umbra_render_desc, preintegrated);

    /* CSSM with 7 taps, seed 3, 128^2, the 0.4 way and the 0.5 way. */
    shadow_desc_0_4 old = old_defaults(UMBRA_SHADOW_CSSM);
    old.taps = 7;
    old.seed = 3;
    old.map_size = 128;
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_CSSM;
    d.cssm.taps = 7;
    d.cssm.seed = 3;
    d.map.size = 128;
    render_with(r, &old, &o_0_4, a);
    render_with(r, &d, &o, b);
    assert_memory_equal(a, b, sizeof a);
    /* Convolution, pre-integrated through the 0.4 shadow desc, in either order of the calls. */
    old = old_defaults(UMBRA_SHADOW_CONVOLUTION);
    old.slice_distance = 1.0f;
    old.preintegrated = 1;
    const umbra_light front = test_directional_light(-0.3f, -1.0f, -0.6f);
    assert_int_equal(umbra_renderer_set_light(r, &front), UMBRA_SUCCESS);
    render_with(r, &old, &o_0_4, a);
    assert_int_equal(r->opts.preintegrated, 1);
    assert_int_equal(umbra_renderer_set_shadow(r, as_0_5(&old)), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_options(r, &o_0_4), UMBRA_SUCCESS);
    assert_int_equal(r->opts.preintegrated, 1); /* 0.4's options leave it */
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_CONVOLUTION;
    d.convolution.slice_distance = 1.0f;
    o.preintegrated = 1;
    render_with(r, &d, &o, b);
    assert_memory_equal(a, b, sizeof a);
    o.preintegrated = 0;
    render_with(r, &d, &o, b);
    assert_true(memcmp(a, b, sizeof a) != 0); /* the comparison above saw pre-integration */
    /* A 0.4 value out of range is refused by its new name. */
    old = old_defaults(UMBRA_SHADOW_DEEP);
    old.prefilter = 3;
    test_assert_failed(ctx, umbra_renderer_set_shadow(r, as_0_5(&old)),
                       UMBRA_ERROR_INVALID_ARGUMENT, "deep prefilter 3", NULL);
    /* Other sizes are refused. */
    umbra_shadow_desc_init(&d);
    d.struct_size = sizeof d - 4;
    test_assert_failed(ctx, umbra_renderer_set_shadow(r, &d), UMBRA_ERROR_INVALID_ARGUMENT,
                       "struct_size", "0.4");
    o.struct_size = sizeof o + 4;
    test_assert_failed(ctx, umbra_renderer_set_options(r, &o), UMBRA_ERROR_INVALID_ARGUMENT,
                       "struct_size", NULL);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry_lists_every_technique_once),
        cmocka_unit_test(test_registry_parameters_described_and_defaulted),
        cmocka_unit_test(test_registry_set_and_get_by_name),
        cmocka_unit_test(test_registry_layout_0_4_accepted),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
