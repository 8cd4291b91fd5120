// SPDX-License-Identifier: Apache-2.0
/* tests/test_paraview.c: ParaView presets beyond the basics of tests/test_formats.c: the HSV
 * colour space against vtkMath's hexcone worked by hand, categorical (IndexedColors /
 * Annotations) presets as step tables, the default opacity, finding presets by name in the
 * search path (and its order), the presets umbra installs, ParaView 5.11's own 195 when
 * $UMBRA_PARAVIEW_PRESETS names that file (skipped otherwise), and the bound on what parsing a
 * large file costs, counted in cJSON's allocations (never in seconds). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>
#include <cmocka.h>

#include "test_util.h"

#define PATH_MAX_LEN 1024

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

/* Loads the JSON text as a preset (name may be NULL) with the given resolution. */
static umbra_status load_text(umbra_context ctx, const char *json, const char *name,
                              uint32_t resolution, umbra_transfer_function *tf, double range[2])
{
    char path[PATH_MAX_LEN];
    umbra_paraview_options o;
    tmp_path(path, "preset.json");
    test_write_text(path, json);
    umbra_paraview_options_init(&o);
    o.preset = name;
    o.resolution = resolution;
    return umbra_transfer_function_load_paraview(ctx, path, &o, tf, range);
}

static void assert_rgba(const float *t, uint32_t e, double r, double g, double b, double a,
                        double tol)
{
    assert_float_equal(t[4 * e + 0], r, tol);
    assert_float_equal(t[4 * e + 1], g, tol);
    assert_float_equal(t[4 * e + 2], b, tol);
    assert_float_equal(t[4 * e + 3], a, tol);
}

/* Blue (hue 2/3) to red (hue 0) without wrap goes the long way: cyan at a quarter (hue 1/2),
 * green halfway (1/3), yellow at three quarters (1/6); with HSVWrap the short way: magenta
 * halfway (5/6). Saturation and value blend linearly: white (s 0) to red gives pink. */
static void test_paraview_hsv_matches_hexcone(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    const float *t;
    const double a = UMBRA_PARAVIEW_DEFAULT_OPACITY;
    assert_int_equal(load_text(ctx,
                               "[{\"Name\": \"Blue to Red Rainbow\", \"ColorSpace\": \"HSV\", "
                               "\"RGBPoints\": [0, 0, 0, 1, 1, 1, 0, 0]}]",
                               NULL, 5, &tf, NULL),
                     UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_rgba(t, 0, 0, 0, 1, 0, 1e-6);
    assert_rgba(t, 1, 0, 1, 1, 0.25 * a, 1e-6);
    assert_rgba(t, 2, 0, 1, 0, 0.5 * a, 1e-6);
    assert_rgba(t, 3, 1, 1, 0, 0.75 * a, 1e-6);
    assert_rgba(t, 4, 1, 0, 0, a, 1e-6);
    umbra_transfer_function_release(tf);

    assert_int_equal(load_text(ctx,
                               "{\"ColorSpace\": \"HSV\", \"HSVWrap\": true, "
                               "\"RGBPoints\": [0, 0, 0, 1, 1, 1, 0, 0]}",
                               NULL, 3, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_rgba(umbra_transfer_function_data(tf), 1, 1, 0, 1, 0.5 * a, 1e-6);
    umbra_transfer_function_release(tf);

    /* (1,1,1) is hue 0, s 0, v 1; halfway to red: s 0.5, v 1 -> (1, 0.5, 0.5). */
    assert_int_equal(load_text(ctx,
                               "{\"ColorSpace\": \"HSV\", \"RGBPoints\": [0, 1, 1, 1, 1, 1, 0, 0]}",
                               NULL, 3, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_rgba(umbra_transfer_function_data(tf), 1, 1, 0.5, 0.5, 0.5 * a, 1e-6);
    umbra_transfer_function_release(tf);

    test_assert_failed(ctx,
                       load_text(ctx,
                                 "{\"ColorSpace\": \"HSV\", \"HSVWrap\": \"yes\", "
                                 "\"RGBPoints\": [0, 0, 0, 1, 1, 1, 0, 0]}",
                                 NULL, 3, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "HSVWrap is not a boolean", NULL);
    test_assert_failed(ctx,
                       load_text(ctx,
                                 "{\"ColorSpace\": \"Lab/CIEDE2000\", "
                                 "\"RGBPoints\": [0, 0, 0, 1, 1, 1, 0, 0]}",
                                 NULL, 3, &tf, NULL),
                       UMBRA_ERROR_UNSUPPORTED, "\"Lab/CIEDE2000\" is not supported",
                       "shortest path");
}

/* Categories: values 1, 2 and 5 (a number, a string, a number) take colours 0, 1, 0 (two
 * colours cycle); the table spans [0.5, 5.5] and every entry within 0.5 of a value takes its
 * colour at the default opacity, the rest (3.5 .. 4.5) is transparent black. Without
 * Annotations the values are 0 .. n-1. */
static void test_paraview_categorical_is_a_step_table(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    const double a = UMBRA_PARAVIEW_DEFAULT_OPACITY;
    const float *t;
    double range[2];
    float fr[2];
    assert_int_equal(load_text(ctx,
                               "[{\"Name\": \"labels\", \"IndexedColors\": [1, 0, 0, 0, 0, 1], "
                               "\"Annotations\": [5, \"five\", \"2\", \"two\", 1, \"one\"]}]",
                               NULL, 21, &tf, range),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 21);
    assert_float_equal(range[0], 0.5, 0.0);
    assert_float_equal(range[1], 5.5, 0.0);
    assert_true(umbra_transfer_function_get_range(tf, fr));
    assert_float_equal(fr[0], 0.5, 0.0);
    t = umbra_transfer_function_data(tf);
    /* Entry e lies at 0.5 + e / 4; the k-th annotation takes colour k % 2: 5 and 1 red, 2
     * blue. */
    assert_rgba(t, 0, 1, 0, 0, a, 0.0);  /* 0.5: value 1 */
    assert_rgba(t, 2, 1, 0, 0, a, 0.0);  /* 1.0 */
    assert_rgba(t, 6, 0, 0, 1, a, 0.0);  /* 2.0 */
    assert_rgba(t, 8, 0, 0, 1, a, 0.0);  /* 2.5: 0.5 from 2 */
    assert_rgba(t, 9, 0, 0, 0, 0, 0.0);  /* 2.75: 0.75 from 2, no category */
    assert_rgba(t, 13, 0, 0, 0, 0, 0.0); /* 3.75: no category */
    assert_rgba(t, 18, 1, 0, 0, a, 0.0); /* 5.0 */
    umbra_transfer_function_release(tf);

    /* No Annotations: 0, 1, 2; a resolution too coarse for the categories is raised. */
    assert_int_equal(load_text(ctx, "{\"IndexedColors\": [0, 1, 0, 1, 1, 0, 0, 1, 1]}", NULL, 2,
                               &tf, range),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 13);
    assert_float_equal(range[0], -0.5, 0.0);
    assert_float_equal(range[1], 2.5, 0.0);
    t = umbra_transfer_function_data(tf);
    assert_rgba(t, 2, 0, 1, 0, a, 0.0);
    assert_rgba(t, 6, 1, 1, 0, a, 0.0);
    assert_rgba(t, 10, 0, 1, 1, a, 0.0);
    umbra_transfer_function_release(tf);

    test_assert_failed(ctx,
                       load_text(ctx,
                                 "{\"IndexedColors\": [1, 0, 0], \"Annotations\": [1, \"a\", 1, "
                                 "\"b\"]}",
                                 NULL, 16, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "name the value 1 twice", NULL);
    test_assert_failed(ctx,
                       load_text(ctx,
                                 "{\"IndexedColors\": [1, 0, 0], \"Annotations\": [\"x\", \"a\"]}",
                                 NULL, 16, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "Annotations[0] (the value of category 0)", NULL);
    test_assert_failed(ctx,
                       load_text(ctx, "{\"IndexedColors\": [1, 0, 0], \"Annotations\": [1]}",
                                 NULL, 16, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "Annotations has 1 items", NULL);
    test_assert_failed(ctx,
                       load_text(ctx, "{\"IndexedColors\": [1, 0, 2]}", NULL, 16, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "IndexedColors[2] is not a number in [0,1]", NULL);
    test_assert_failed(ctx,
                       load_text(ctx,
                                 "{\"IndexedColors\": [1, 0, 0], \"Annotations\": [0, \"a\", "
                                 "100000, \"b\"]}",
                                 NULL, 16, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "needs 400005 table entries", "more than 65536");
}

/* options.default_opacity sets the ramp's top (and a category's opacity); Points still win. */
static void test_paraview_default_opacity_option(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    umbra_paraview_options o;
    char path[PATH_MAX_LEN];
    tmp_path(path, "ramp.json");
    test_write_text(path, "{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1]}");
    umbra_paraview_options_init(&o);
    assert_float_equal(o.default_opacity, UMBRA_PARAVIEW_DEFAULT_OPACITY, 0.0);
    o.resolution = 3;
    o.default_opacity = 0.6;
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_float_equal(umbra_transfer_function_data(tf)[4 + 3], 0.3, 1e-6);
    assert_float_equal(umbra_transfer_function_data(tf)[8 + 3], 0.6, 1e-6);
    umbra_transfer_function_release(tf);
    o.default_opacity = NAN;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "default_opacity nan is not in [0,1]", NULL);
    test_write_text(path, "{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1], "
                          "\"Points\": [0, 0.7, 0.5, 0, 1, 0.7, 0.5, 0]}");
    o.default_opacity = 0.2;
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_float_equal(umbra_transfer_function_data(tf)[4 + 3], 0.7, 1e-6);
    umbra_transfer_function_release(tf);
    /* A caller built against 0.4's header (no default_opacity) gets the default. */
    test_write_text(path, "{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1]}");
    o.default_opacity = 0.6;
    o.struct_size = offsetof(umbra_paraview_options, default_opacity);
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_float_equal(umbra_transfer_function_data(tf)[8 + 3], UMBRA_PARAVIEW_DEFAULT_OPACITY,
                       1e-6);
    umbra_transfer_function_release(tf);
    o.struct_size = sizeof o - 1;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "struct_size", NULL);
}

/* Name lookup: $UMBRA_PRESET_PATH first (its "Cool to Warm" shadows the installed one), then
 * the installed presets (the build tree's share/umbra/presets), then the current directory; a
 * bare name through umbra_transfer_function_load; a name found nowhere names the places. */
static void test_paraview_found_by_name_in_search_order(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    umbra_paraview_options o;
    char dir[PATH_MAX_LEN], path[2 * PATH_MAX_LEN], cwd[PATH_MAX_LEN], env[2 * PATH_MAX_LEN];
    const float *t;

    tmp_path(dir, "search");
    assert_int_equal(mkdir(dir, 0700), 0);
    snprintf(path, sizeof path, "%s/b.json", dir);
    test_write_text(path, "[{\"Name\": \"Cool to Warm\", \"RGBPoints\": [0, 0, 1, 0, 1, 0, 1, 0]},"
                          " {\"Name\": \"Mine\", \"RGBPoints\": [0, 1, 0, 1, 1, 1, 0, 1]}]");
    snprintf(path, sizeof path, "%s/a.json", dir);
    test_write_text(path, "{ not json");
    snprintf(env, sizeof env, "/nonexistent:%s", dir);
    assert_int_equal(setenv("UMBRA_PRESET_PATH", env, 1), 0);

    umbra_paraview_options_init(&o);
    o.preset = "Mine";
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, NULL, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_rgba(umbra_transfer_function_data(tf), 0, 1, 0, 1, 0, 0.0);
    umbra_transfer_function_release(tf);
    o.preset = "Cool to Warm";
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, NULL, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    assert_rgba(umbra_transfer_function_data(tf), 0, 0, 1, 0, 0, 0.0); /* the env's, green */
    umbra_transfer_function_release(tf);

    /* Without the variable: the installed Cool to Warm (ParaView's blue end). */
    assert_int_equal(unsetenv("UMBRA_PRESET_PATH"), 0);
    assert_int_equal(umbra_transfer_function_load(ctx, "Cool to Warm", &tf), UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[0], 0.23137254902, 1e-4);
    assert_float_equal(t[2], 0.752941176471, 1e-4);
    umbra_transfer_function_release(tf);

    /* The current directory comes last. */
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(dir), 0);
    o.preset = "Mine";
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, NULL, &o, &tf, NULL),
                     UMBRA_SUCCESS);
    umbra_transfer_function_release(tf);
    assert_int_equal(chdir(cwd), 0);

    o.preset = "No Such Preset";
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, NULL, &o, &tf, NULL),
                       UMBRA_ERROR_IO, "no preset named \"No Such Preset\"",
                       "share/umbra/presets");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, "No Such Preset", &tf),
                       UMBRA_ERROR_IO, "is neither a file nor the name of a preset", NULL);
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, NULL, NULL, &tf, NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "path is NULL", "names no preset");
}

/* Loads every preset of the file at path by name; returns how many there are. Each must load
 * (a table in [0,1] spanning a non-empty range). */
static size_t load_every_preset(umbra_context ctx, const char *path)
{
    size_t size = 0, count = 0;
    char *text = test_read_bytes(path, &size);
    cJSON *root = cJSON_ParseWithLength(text, size), *item;
    assert_true(cJSON_IsArray(root));
    cJSON_ArrayForEach(item, root)
    {
        umbra_transfer_function tf = NULL;
        umbra_paraview_options o;
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(item, "Name"));
        double range[2];
        uint32_t n, i;
        assert_non_null(name);
        umbra_paraview_options_init(&o);
        o.preset = name;
        if (umbra_transfer_function_load_paraview(ctx, path, &o, &tf, range) != UMBRA_SUCCESS) {
            fail_msg("preset \"%s\": %s", name, umbra_context_last_message(ctx));
        }
        assert_true(range[1] > range[0]);
        n = umbra_transfer_function_size(tf);
        for (i = 0; i < 4 * n; ++i) {
            assert_true(umbra_transfer_function_data(tf)[i] >= 0.0f &&
                        umbra_transfer_function_data(tf)[i] <= 1.0f);
        }
        umbra_transfer_function_release(tf);
        ++count;
    }
    cJSON_Delete(root);
    free(text);
    return count;
}

/* The 21 installed presets all load by name, as do ParaView 5.11's 195 when the file is given. */
static void test_paraview_installed_and_paraview_presets_load(void **state)
{
    umbra_context ctx = *state;
    const char *data = UMBRA_TEST_DATA_DIR, *pv = getenv("UMBRA_PARAVIEW_PRESETS");
    char path[PATH_MAX_LEN];
    size_t n = strlen(data) - strlen("/tests/data");
    snprintf(path, sizeof path, "%.*s/share/umbra/presets/paraview.json", (int)n, data);
    assert_int_equal(load_every_preset(ctx, path), 21);
    if (pv && pv[0]) {
        assert_int_equal(load_every_preset(ctx, pv), 195);
    } else {
        print_message("(ParaView's presets not checked: set UMBRA_PARAVIEW_PRESETS to "
                      "ParaView 5.11's ColorMaps.json)\n");
    }
}

/* ---- the cost of a large file, counted in cJSON's allocations -------------------------------- */

static size_t cjson_allocs;

static void *counting_malloc(size_t n)
{
    ++cjson_allocs;
    return malloc(n);
}

/* The largest preset allowed (two arrays of 65536 points, 2.6 MB) loads, with cJSON making at
 * most two allocations per value; a 62 MiB file of 32.5 million values (under the 64 MiB
 * size cap) is refused by its value count before cJSON allocates anything. Before that count
 * existed it took 65 million allocations, 2.8 GB and 14 s. */
static void test_paraview_large_file_cost_is_bounded(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    cJSON_Hooks hooks = {counting_malloc, free};
    char path[PATH_MAX_LEN];
    size_t i, len = 0, values = 0, bytes;
    char *json = malloc(8u << 20);
    static const char head[] = "[{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1], \"Junk\": [";
    FILE *f;

    assert_non_null(json);
    len += (size_t)sprintf(json + len, "{\"RGBPoints\": [");
    for (i = 0; i < 65536; ++i, values += 4) {
        len += (size_t)sprintf(json + len, "%zu,0.5,0.25,1,", i);
    }
    len += (size_t)sprintf(json + len - 1, "], \"Points\": [") - 1;
    for (i = 0; i < 65536; ++i, values += 4) {
        len += (size_t)sprintf(json + len, "%zu,0.5,0.5,0,", i);
    }
    len += (size_t)sprintf(json + len - 1, "]}") - 1;
    tmp_path(path, "large.json");
    test_write_bytes(path, json, len);
    cJSON_InitHooks(&hooks);
    cjson_allocs = 0;
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, NULL),
                     UMBRA_SUCCESS);
    /* A node per value, and Debian's cJSON copies each number's text while it parses it. */
    assert_true(cjson_allocs > values && cjson_allocs <= 2 * values + 16);
    umbra_transfer_function_release(tf);
    free(json);

    /* 62 MiB of "0,": the value scan refuses it; cJSON is never called. */
    bytes = (size_t)62 << 20;
    json = malloc(bytes);
    assert_non_null(json);
    memcpy(json, head, strlen(head));
    for (i = strlen(head); i + 4 < bytes; i += 2) {
        json[i] = '0';
        json[i + 1] = ',';
    }
    memcpy(json + i - 1, "0]}]", 4);
    i += 3;
    tmp_path(path, "junk.json");
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(json, 1, i, f), i);
    assert_int_equal(fclose(f), 0);
    free(json);
    cjson_allocs = 0;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, NULL),
                       UMBRA_ERROR_FORMAT, "JSON values, more than a preset file may",
                       "(1048576)");
    assert_int_equal(cjson_allocs, 0);
    cJSON_InitHooks(NULL);
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paraview_hsv_matches_hexcone),
        cmocka_unit_test(test_paraview_categorical_is_a_step_table),
        cmocka_unit_test(test_paraview_default_opacity_option),
        cmocka_unit_test(test_paraview_found_by_name_in_search_order),
        cmocka_unit_test(test_paraview_installed_and_paraview_presets_load),
        cmocka_unit_test(test_paraview_large_file_cost_is_bounded),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
