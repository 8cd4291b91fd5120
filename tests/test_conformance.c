// SPDX-License-Identifier: Apache-2.0
/* tests/test_conformance.c: the conformance suite, run for every technique of the registry.
 *  - every technique has rows in the bounds table (tests/conformance.h), and every row names a
 *    registered technique;
 *  - the analytic slab (grey and coloured) and the hard cases (axis-aligned, grazing, point
 *    lights on a face, a corner, inside empty space and inside material, near-opaque,
 *    near-transparent over long paths, a sharp transfer function) stay within each row's bounds
 *    against the analytic factor or the exact reference, or are refused where the row says so;
 *    images are finite and non-negative, factors in [0, 1], and points with nothing between them
 *    and the light are lit exactly;
 *  - a shadow structure rebuilt after light and transfer-function changes equals, bit for bit,
 *    a fresh renderer's (for the light-space maps also across a change of the auto map size);
 *  - every parameter outside its range (below, above, NaN, outside its set, not a whole number)
 *    is refused by umbra_renderer_set_shadow and umbra_shadow_desc_set_param with a message
 *    naming the technique, the parameter and the value, while another technique's parameters are
 *    neither checked nor compared;
 *  - changing another technique's parameter does not rebuild; the technique's own parameters
 *    flagged UMBRA_PARAM_REBUILDS do, the others do not;
 *  - a program's file list (umbra__program_files) counts every technique's files in full and
 *    writes only up to its array; a count past what a program holds is refused by
 *    umbra__program_get, naming it, and the context goes on.
 * Usage: test_conformance [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conformance.h"
#include "renderer_internal.h"
#include "test_util.h"

/* The group's context (test_group_setup), for the helpers below. */
static umbra_context ctx;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    return rc;
}

static const char *row_name(const conf_row *row, char *buf, size_t size)
{
    snprintf(buf, size, "%s%s%s", row->technique, row->params[0] ? " " : "", row->params);
    return buf;
}

/* ---- the table ------------------------------------------------------------------------------- */

static void test_conformance_every_technique_has_rows(void **state)
{
    (void)state;
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        int rows = 0;
        for (size_t i = 0; i < CONF_ROWS; ++i)
            rows += strcmp(conf_rows[i].technique, umbra_technique_get(t)->name) == 0;
        if (!rows)
            fail_msg("technique '%s' has no row in tests/conformance.h",
                     umbra_technique_get(t)->name);
    }
    for (size_t i = 0; i < CONF_ROWS; ++i)
        if (!umbra_technique_find(conf_rows[i].technique))
            fail_msg("conformance row %zu names '%s', not in the registry", i,
                     conf_rows[i].technique);
}

/* ---- the cases ------------------------------------------------------------------------------- */

static int check(int ok, int *failures, const char *row, const char *c, const char *what,
                 double got, double bound)
{
    if (!ok) {
        print_message("FAIL %s on %s: %s %.6g (bound %.6g)\n", row, c, what, got, bound);
        ++*failures;
    }
    return ok;
}

static void test_conformance_cases_within_bounds(void **state)
{
    (void)state;
    int failures = 0;
    for (int c = 0; c < CONF_CASES; ++c) {
        conf_scene s;
        conf_yardstick y[2];
        char msg[1024];
        assert_int_equal(conf_scene_make(ctx, c, &s), UMBRA_SUCCESS);
        for (int unlit = 0; unlit < 2; ++unlit)
            if (!s.analytic && conf_yardstick_make(ctx, &s, unlit, &y[unlit], msg, sizeof msg))
                fail_msg("%s: the yardstick failed: %s", conf_case_names[c], msg);
        for (size_t i = 0; i < CONF_ROWS; ++i) {
            const conf_row *row = &conf_rows[i];
            const umbra_technique_info *t = umbra_technique_find(row->technique);
            const int unlit = (t->flags & UMBRA_TECHNIQUE_NO_LIGHT) != 0;
            char name[256];
            row_name(row, name, sizeof name);
            conf_result res;
            conf_run(ctx, &s, &y[unlit], row, &res);
            if (row->image[c] == CONF_UNSUPPORTED) {
                print_message("%-22s %-18s refused: %s\n", name, conf_case_names[c],
                              res.status == UMBRA_ERROR_UNSUPPORTED ? "yes" : "NO");
                check(res.status == UMBRA_ERROR_UNSUPPORTED, &failures, name,
                      conf_case_names[c], "status (UMBRA_ERROR_UNSUPPORTED expected)",
                      (double)res.status, UMBRA_ERROR_UNSUPPORTED);
                continue;
            }
            if (!check(res.status == UMBRA_SUCCESS, &failures, name, conf_case_names[c],
                       res.message, (double)res.status, 0))
                continue;
            print_message("%-22s %-18s %s %.2e (bound %.1e)  %s %.2e (bound %.1e)\n", name,
                          conf_case_names[c], s.analytic ? "mean" : "image", res.image,
                          row->image[c], s.analytic ? "max" : "points", res.point,
                          row->point[c]);
            check(res.image <= row->image[c], &failures, name, conf_case_names[c],
                  s.analytic ? "slab mean error" : "image error", res.image, row->image[c]);
            if (row->point[c] != CONF_NA)
                check(res.point <= row->point[c], &failures, name, conf_case_names[c],
                      s.analytic ? "slab max error" : "point error", res.point, row->point[c]);
            check(res.out_of_range == 0, &failures, name, conf_case_names[c],
                  "values out of range", (double)res.out_of_range, 0);
            check(res.lit_wrong == 0, &failures, name, conf_case_names[c],
                  "lit points not lit exactly", (double)res.lit_wrong, 0);
        }
        if (!s.analytic)
            for (int unlit = 0; unlit < 2; ++unlit)
                conf_yardstick_release(&y[unlit]);
        conf_scene_release(&s);
    }
    if (failures)
        fail_msg("%d conformance check(s) failed (listed above)", failures);
}

/* ---- rebuild equals fresh -------------------------------------------------------------------- */

enum { RB_NX = CONF_TWO_BALLS_NX, RB_NY = CONF_TWO_BALLS_NY, RB_NZ = CONF_TWO_BALLS_NZ };
enum { RB_W = 48, RB_H = 40 };

static umbra_renderer rebuild_renderer(umbra_volume v, umbra_transfer_function tf,
                                       const umbra_light *light, const conf_row *row)
{
    const float dir[3] = {0.5f, 0.4f, 1.0f};
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    assert_int_equal(umbra_shadow_technique_parse(row->technique, &sd.technique), UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    char msg[1024];
    if (setting_apply(&sd, &o.preintegrated, row->params, msg, sizeof msg) != 0)
        fail_msg("%s", msg);
    umbra_camera cam = umbra_camera_orbit(dir, 62.0f, 30.0f);
    o.transmission = UMBRA_TRANSMISSION_COLORED;
    o.ground_plane = 1;
    umbra_renderer r = test_renderer(ctx, v, tf, &cam, light, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    return r;
}

/* Renders; the structure was rebuilt (or, for a technique that has none to rebuild, the
 * renderer's first frame built what it needs). */
static void rebuild_render(umbra_renderer r, float *img, uint32_t *map_size)
{
    assert_int_equal(umbra_renderer_render(r, RB_W, RB_H, img), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    if (r->tech->info.rebuilt_by)
        assert_true(st.shadow_rebuilt);
    if (map_size)
        *map_size = st.map_size;
}

static long first_difference(const float *a, const float *b)
{
    for (long i = 0; i < (long)RB_W * RB_H * 4; ++i)
        if (memcmp(&a[i], &b[i], sizeof a[i]) != 0)
            return i;
    return -1;
}

static void expect_same(const float *got, const float *want, const char *what, const char *row)
{
    long i = first_difference(got, want);
    if (i >= 0)
        fail_msg("%s: %s: pixel (%ld, %ld) channel %ld is %.9g after the rebuild, %.9g from a "
                 "fresh renderer", row, what, i / 4 % RB_W, i / 4 / RB_W, i % 4, got[i], want[i]);
}

/* A renderer that rendered under light L1 renders under L2 (for a light-space map a point light
 * outside the box, then one inside it in empty space: the auto map size and the projection
 * change; for a technique that renders the frame itself two lights on the viewer's side), then
 * with a more opaque transfer function, then back to L1 and the first one: each image equals,
 * bit for bit, a fresh renderer's. */
static void test_conformance_rebuild_equals_fresh(void **state)
{
    (void)state;
    umbra_volume vol;
    umbra_transfer_function tf_a, tf_b;
    assert_int_equal(conf_volume(ctx, RB_NX, RB_NY, RB_NZ, conf_two_balls, &vol), UMBRA_SUCCESS);
    const float a[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.08f, 0.3f, 0.8f, 0.4f, 0.2f,
                         0.7f, 0.7f, 0.9f, 0.5f};
    const float b[16] = {0, 0, 0, 0, 0.9f, 0.5f, 0.2f, 0.15f, 0.3f, 0.8f, 0.4f, 0.4f,
                         0.7f, 0.7f, 0.9f, 0.8f};
    assert_int_equal(umbra_transfer_function_create(ctx, a, 4, &tf_a), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_create(ctx, b, 4, &tf_b), UMBRA_SUCCESS);
    static float img[4][RB_W * RB_H * 4], fresh[RB_W * RB_H * 4];
    for (size_t i = 0; i < CONF_ROWS; ++i) {
        const conf_row *row = &conf_rows[i];
        const umbra_technique_info *t = umbra_technique_find(row->technique);
        char name[256];
        row_name(row, name, sizeof name);
        const int frame = (t->flags & UMBRA_TECHNIQUE_FRAME) != 0;
        const umbra_light l1 = frame ? conf_directional(-0.3f, -1.0f, -0.6f)
                                     : conf_point(-40.0f, 70.0f, 30.0f);
        const umbra_light l2 = frame ? conf_directional(-0.6f, -0.3f, -0.8f)
                                     : conf_point(8.0f, 12.0f, -12.0f);
        uint32_t size1 = 0, size2 = 0, size_fresh = 0;
        umbra_renderer r = rebuild_renderer(vol, tf_a, &l1, row);
        rebuild_render(r, img[0], &size1);
        assert_int_equal(umbra_renderer_set_light(r, &l2), UMBRA_SUCCESS);
        rebuild_render(r, img[1], &size2);
        if ((t->flags & UMBRA_TECHNIQUE_MAP) && r->shadow.map.size == UMBRA_MAP_SIZE_AUTO &&
            size1 == size2)
            fail_msg("%s: the auto map size did not change with the light (%u)", name, size1);
        assert_int_equal(umbra_renderer_set_transfer_function(r, tf_b), UMBRA_SUCCESS);
        rebuild_render(r, img[2], NULL);
        assert_int_equal(umbra_renderer_set_light(r, &l1), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_set_transfer_function(r, tf_a), UMBRA_SUCCESS);
        rebuild_render(r, img[3], NULL);
        umbra_renderer_release(r);

        umbra_renderer f = rebuild_renderer(vol, tf_a, &l2, row);
        rebuild_render(f, fresh, &size_fresh);
        assert_int_equal(size_fresh, size2);
        expect_same(img[1], fresh, "light L1 -> L2", name);
        umbra_renderer_release(f);
        f = rebuild_renderer(vol, tf_b, &l2, row);
        rebuild_render(f, fresh, NULL);
        expect_same(img[2], fresh, "then a new transfer function", name);
        umbra_renderer_release(f);
        expect_same(img[3], img[0], "back to L1 and the first transfer function", name);
        /* The light move changed the image (of a technique with a light pass): the comparisons
         * above compare shadows. */
        if (!(t->flags & UMBRA_TECHNIQUE_NO_LIGHT))
            assert_true(first_difference(img[0], img[1]) >= 0);
        print_message("%-22s rebuilds equal fresh renderers (map %u -> %u)\n", name, size1, size2);
    }
    umbra_transfer_function_release(tf_a);
    umbra_transfer_function_release(tf_b);
    umbra_volume_release(vol);
}

/* ---- bad parameters -------------------------------------------------------------------------- */

/* Values param p refuses: below and above its range, NaN (floats), a value between two of its
 * set; the count. */
static int bad_values(const umbra_param_info *p, double out[6])
{
    int n = 0;
    if (p->type == UMBRA_PARAM_BOOL)
        return 0;
    const double step = p->type == UMBRA_PARAM_FLOAT ? 1e-3 * (p->max - p->min) : 1.0;
    const double below = (p->flags & UMBRA_PARAM_MIN_EXCLUSIVE) ? p->min : p->min - step;
    if (below >= 0.0 || p->type == UMBRA_PARAM_FLOAT)
        if (!((p->flags & UMBRA_PARAM_ZERO) && below == 0.0))
            out[n++] = below;
    const double above = (p->flags & UMBRA_PARAM_MAX_EXCLUSIVE) ? p->max : p->max + step;
    if (above <= 4294967295.0)
        out[n++] = above;
    if (p->type == UMBRA_PARAM_FLOAT)
        out[n++] = NAN;
    for (uint32_t k = 0; p->allowed && k + 1 < p->allowed_count && n < 6; ++k)
        if (p->allowed[k + 1] - p->allowed[k] > 1.0) {
            out[n++] = p->allowed[k] + 1.0;
            break;
        }
    return n;
}

/* The value as the refusal prints it (host/registry.c). */
static void value_text(double v, char *buf, size_t size)
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, size, "%.0f", v);
    else
        snprintf(buf, size, "%g", v);
}

static void test_conformance_bad_parameters_refused_by_name(void **state)
{
    (void)state;
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    int refused = 0;
    for (uint32_t ti = 0; ti < umbra_technique_count(); ++ti) {
        const umbra__technique *t = umbra__technique_by_id(umbra_technique_get(ti)->id);
        for (uint32_t k = 0; k < t->info.param_count; ++k) {
            const umbra__param *p = &t->params[k];
            double bad[6];
            const int n = bad_values(&p->info, bad);
            for (int b = 0; b < n; ++b) {
                char value[40], needle[256], msg[1024];
                umbra_shadow_desc d;
                umbra_shadow_desc_init(&d);
                d.technique = t->info.id;
                /* The field as a caller may fill it: a float, or a whole number of 32 bits. */
                char *field = (char *)&d + p->offset;
                const float fv = (float)bad[b];
                const uint32_t uv = (uint32_t)bad[b];
                if (p->info.type == UMBRA_PARAM_FLOAT)
                    memcpy(field, &fv, sizeof fv);
                else
                    memcpy(field, &uv, sizeof uv);
                value_text(p->info.type == UMBRA_PARAM_FLOAT ? (double)fv : (double)uv, value,
                           sizeof value);
                snprintf(needle, sizeof needle, "%s %s %s", t->info.name, p->info.key, value);
                test_assert_failed(ctx, umbra_renderer_set_shadow(r, &d),
                                   UMBRA_ERROR_INVALID_ARGUMENT, "umbra_renderer_set_shadow",
                                   needle);
                /* set_param refuses the value too, naming it the same way, and changes nothing. */
                umbra_shadow_desc_init(&d);
                const umbra_shadow_desc before = d;
                assert_int_equal(umbra_shadow_desc_set_param(&d, t->info.name, p->info.key,
                                                             bad[b], msg, sizeof msg),
                                 UMBRA_ERROR_INVALID_ARGUMENT);
                value_text(bad[b], value, sizeof value);
                snprintf(needle, sizeof needle, "%s %s %s", t->info.name, p->info.key, value);
                if (!strstr(msg, needle) || !strstr(msg, "umbra_shadow_desc_set_param"))
                    fail_msg("set_param refused with '%s', which lacks '%s'", msg, needle);
                assert_memory_equal(&d, &before, sizeof d);
                ++refused;
            }
            if (p->info.type == UMBRA_PARAM_UINT) {
                char msg[1024];
                umbra_shadow_desc d;
                umbra_shadow_desc_init(&d);
                assert_int_equal(umbra_shadow_desc_set_param(&d, t->info.name, p->info.key,
                                                             p->info.min + 0.5, msg, sizeof msg),
                                 UMBRA_ERROR_INVALID_ARGUMENT);
                assert_non_null(strstr(msg, "whole number"));
            }
            /* Another technique's bad value is neither checked nor compared: a technique with
             * parameters of its own (not the shared map's) accepts this one's garbage. */
            if (!(p->info.flags & UMBRA_PARAM_MAP) && n > 0) {
                umbra_shadow_desc d;
                umbra_shadow_desc_init(&d);
                d.technique = t->info.id == UMBRA_SHADOW_NONE ? UMBRA_SHADOW_REFERENCE
                                                              : UMBRA_SHADOW_NONE;
                const float fv = (float)bad[0];
                const uint32_t uv = (uint32_t)bad[0];
                memcpy((char *)&d + p->offset, p->info.type == UMBRA_PARAM_FLOAT
                                                   ? (const void *)&fv
                                                   : (const void *)&uv, 4);
                assert_int_equal(umbra_renderer_set_shadow(r, &d), UMBRA_SUCCESS);
            }
        }
    }
    print_message("%d bad values refused by name\n", refused);
    assert_true(refused > 20);
    umbra_context_take_error(ctx, NULL);
    umbra_renderer_release(r);
}

/* ---- what rebuilds --------------------------------------------------------------------------- */

/* Another valid value of p (the next of its set, or a step inside its range). */
static double other_value(const umbra_param_info *p, double v)
{
    if (p->type == UMBRA_PARAM_BOOL)
        return v != 0.0 ? 0.0 : 1.0;
    if (p->allowed) {
        for (uint32_t k = 0; k < p->allowed_count; ++k)
            if (p->allowed[k] != v)
                return p->allowed[k];
    }
    if (v == 0.0 && (p->flags & UMBRA_PARAM_ZERO))
        return p->type == UMBRA_PARAM_UINT ? ceil(p->min) : p->min + 0.25 * (p->max - p->min);
    const double mid = 0.5 * (p->min + p->max);
    const double w = p->type == UMBRA_PARAM_UINT ? floor(mid) : mid;
    return w != v ? w : (p->type == UMBRA_PARAM_UINT ? w + 1.0 : 0.5 * (w + p->max));
}

static int rebuilt(umbra_renderer r, const umbra_shadow_desc *d)
{
    float img[16 * 16 * 4];
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_set_shadow(r, d), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 16, 16, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    return st.shadow_rebuilt;
}

/* Per technique: a change of any parameter of another technique (that is not also its own, the
 * shared map's) leaves the structure as it is; of its own, a parameter flagged
 * UMBRA_PARAM_REBUILDS rebuilds it and one without the flag does not. Parameter values that make
 * a frame long (a 8192^2 map, a 0.01-voxel step) are kept out: the map's size and the steps keep
 * small values. */
static void test_conformance_only_own_parameters_rebuild(void **state)
{
    (void)state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 16, &sc), UMBRA_SUCCESS);
    const umbra_light light = conf_directional(-0.3f, -1.0f, -0.6f); /* the viewer's side */
    int checked = 0;
    for (uint32_t ti = 0; ti < umbra_technique_count(); ++ti) {
        const umbra__technique *t = umbra__technique_by_id(umbra_technique_get(ti)->id);
        umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &light, &sc.options);
        umbra_shadow_desc d;
        umbra_shadow_desc_init(&d);
        d.technique = t->info.id;
        assert_true(rebuilt(r, &d));
        for (uint32_t ui = 0; ui < umbra_technique_count(); ++ui) {
            const umbra__technique *u = umbra__technique_by_id(umbra_technique_get(ui)->id);
            for (uint32_t k = 0; k < u->info.param_count; ++k) {
                const umbra__param *p = &u->params[k];
                int own = 0, flagged = 0;
                for (uint32_t j = 0; j < t->info.param_count; ++j)
                    if (t->params[j].offset == p->offset) {
                        own = 1;
                        flagged = (t->params[j].info.flags & UMBRA_PARAM_REBUILDS) != 0;
                    }
                if (own && u != t)
                    continue; /* the shared map's, checked as t's own */
                double v;
                assert_int_equal(umbra_shadow_desc_get_param(&d, u->info.name, p->info.key, &v),
                                 UMBRA_SUCCESS);
                double w = other_value(&p->info, v);
                if (strcmp(p->info.name, "size") == 0 && (p->info.flags & UMBRA_PARAM_MAP))
                    w = v == 64 ? 96 : 64;
                if (p->info.unit && strcmp(p->info.unit, "voxels") == 0)
                    w = v == 1.0 ? 0.75 : 1.0;
                char msg[1024];
                if (umbra_shadow_desc_set_param(&d, u->info.name, p->info.key, w, msg,
                                                sizeof msg) != UMBRA_SUCCESS)
                    fail_msg("%s", msg);
                const int want = own && flagged;
                const int got = rebuilt(r, &d);
                if (got != want)
                    fail_msg("technique %s: changing %s's %s from %g to %g %s", t->info.name,
                             u->info.name, p->info.key, v, w,
                             got ? "rebuilt the structure" : "did not rebuild it");
                ++checked;
            }
        }
        umbra_renderer_release(r);
    }
    print_message("%d parameter changes checked\n", checked);
    umbra_scene_release(&sc);
}

/* ---- program file lists ---------------------------------------------------------------------- */

static void test_conformance_program_files_counted_or_refused(void **state)
{
    (void)state;
    /* A list of the test's own around each technique's files: counted in full whatever the
     * array, written only up to its end. (That every real list fits is shown by every render:
     * umbra__program_get refuses one that does not.) */
    static const char *const common[] = {"common/common.cl", "common/sampling.cl"};
    static const char *const after[] = {"raycast.cl", NULL};
    for (uint32_t ti = 0; ti < umbra_technique_count(); ++ti) {
        const umbra__technique *t = umbra__technique_by_id(umbra_technique_get(ti)->id);
        size_t own = 0;
        while (t->kernel_files && t->kernel_files[own])
            ++own;
        const char *files[16] = {NULL};
        const size_t n = umbra__program_files(t, common, 2, after, files, 16);
        assert_int_equal(n, 2 + own + 1);
        assert_string_equal(files[1], "common/sampling.cl");
        assert_string_equal(files[n - 1], "raycast.cl");
        const char *few[16] = {NULL};
        assert_int_equal(umbra__program_files(t, common, 2, after, few, n - 1), n);
        assert_non_null(few[n - 2]);
        assert_null(few[n - 1]);
    }
    /* A count past the 15 a program holds is refused before a file is read, naming it. */
    const char *many[17];
    for (size_t i = 0; i < 17; ++i)
        many[i] = "common/common.cl";
    cl_program program = NULL;
    assert_int_equal(umbra__program_get(ctx, many, 17, "", &program),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(umbra_context_last_message(ctx), "17 kernel files"));
    assert_null(program);
    assert_int_equal(umbra__program_get(ctx, many, 0, "", &program),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    /* The context is still usable. */
    assert_int_equal(umbra__program_get(ctx, many, 1, "", &program), UMBRA_SUCCESS);
    assert_non_null(program);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conformance_every_technique_has_rows),
        cmocka_unit_test(test_conformance_cases_within_bounds),
        cmocka_unit_test(test_conformance_rebuild_equals_fresh),
        cmocka_unit_test(test_conformance_bad_parameters_refused_by_name),
        cmocka_unit_test(test_conformance_only_own_parameters_rebuild),
        cmocka_unit_test(test_conformance_program_files_counted_or_refused),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
