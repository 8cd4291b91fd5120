// SPDX-License-Identifier: Apache-2.0
/* tests/test_formats.c: ParaView transfer-function presets and NIfTI volumes (umbra_io).
 *
 * Presets are checked against values worked out independently: linear RGB presets against
 * umbra_transfer_function_create_from_points, the midpoint/sharpness curve at the points its
 * definition fixes, the Lab blend of black and white against CIE L* = 50, the diverging blend
 * against Moreland's published midpoint. NIfTI files are written by nifticlib's own writer (and
 * then broken byte by byte); loaded volumes are read back from the device. Every refusal is
 * checked for its status, a message naming the problem, and a usable context afterwards. The last
 * test runs umbra-render (./umbra-render in ctest's working directory, or $UMBRA_RENDER) on a
 * NIfTI file and a preset written here. One file past 800 lines because the two formats share
 * the helpers and the last test needs both; it is a table of cases more than code. */
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
#include <sys/types.h>
#include <unistd.h>

#include <cmocka.h>
#include <nifti2_io.h>

#include "../io/nifti.h"
#include "nifti_test.h"
#include "internal.h"
#include "test_util.h"

#define PATH_MAX_LEN 1024

/* ---- helpers ------------------------------------------------------------------------------- */

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

/* "<source tree>/<rel>" into buf: UMBRA_TEST_DATA_DIR is "<source tree>/tests/data", which need
 * not exist, so the tail is cut off rather than walked up with "..". */
static const char *source_path(char *buf, const char *rel)
{
    const char *data = UMBRA_TEST_DATA_DIR;
    size_t n = strlen(data), tail = strlen("/tests/data");
    int m;
    assert_true(n > tail && strcmp(data + n - tail, "/tests/data") == 0);
    m = snprintf(buf, PATH_MAX_LEN, "%.*s/%s", (int)(n - tail), data, rel);
    assert_true(m > 0 && m < PATH_MAX_LEN);
    return buf;
}

/* ---- ParaView presets ---------------------------------------------------------------------- */

/* Loads the JSON text as a preset with the given resolution (and range when lo < hi). */
static umbra_status load_preset(umbra_context ctx, const char *json, const char *name,
                                uint32_t resolution, double lo, double hi,
                                umbra_transfer_function *tf, double range[2])
{
    char path[PATH_MAX_LEN];
    umbra_paraview_options o;
    tmp_path(path, "preset.json");
    test_write_text(path, json);
    umbra_paraview_options_init(&o);
    o.preset = name;
    o.resolution = resolution;
    if (lo < hi) {
        o.range_given = 1;
        o.range_min = lo;
        o.range_max = hi;
    }
    return umbra_transfer_function_load_paraview(ctx, path, &o, tf, range);
}

static void test_paraview_defaults(void **state)
{
    umbra_paraview_options o;
    (void)state;
    memset(&o, 0xab, sizeof o);
    umbra_paraview_options_init(&o);
    assert_int_equal(o.struct_size, sizeof o);
    assert_null(o.preset);
    assert_int_equal(o.resolution, 1024);
    assert_int_equal(o.range_given, 0);
}

/* A linear RGB preset gives the table umbra builds from the same points (x normalised over the
 * preset's range), and reports that range. */
static void test_paraview_rgb_matches_points(void **state)
{
    umbra_context ctx = *state;
    static const char *json =
        "[{\"Name\": \"lin\", \"ColorSpace\": \"RGB\",\n"
        "  \"RGBPoints\": [-1000, 0, 0, 0,  0, 1, 0.5, 0,  3000, 0.2, 0.4, 1],\n"
        "  \"Points\": [-1000, 0, 0.5, 0,  1000, 0.8, 0.5, 0,  3000, 0.1, 0.5, 0]}]";
    /* Over [-1000, 3000] normalised, both functions break at 0, 0.25 (x = 0), 0.5 (x = 1000)
     * and 1: at 0.5 the colour is a third of the way from (1, 0.5, 0) to (0.2, 0.4, 1); at 0.25
     * the opacity is halfway from 0 to 0.8. */
    const umbra_tf_point pts[4] = {
        {0.0f, {0, 0, 0, 0}},
        {0.25f, {1, 0.5f, 0, 0.4f}},
        {0.5f, {(float)(2.0 / 3.0 + 0.2 / 3.0), (float)(1.0 / 3.0 + 0.4 / 3.0),
                (float)(1.0 / 3.0), 0.8f}},
        {1.0f, {0.2f, 0.4f, 1, 0.1f}}};
    umbra_transfer_function tf = NULL, ref = NULL;
    double range[2] = {0, 0};
    const float *a, *b;
    uint32_t i;
    assert_int_equal(load_preset(ctx, json, NULL, 257, 0, 0, &tf, range), UMBRA_SUCCESS);
    assert_float_equal(range[0], -1000.0, 0.0);
    assert_float_equal(range[1], 3000.0, 0.0);
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 4, 257, &ref),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 257);
    a = umbra_transfer_function_data(tf);
    b = umbra_transfer_function_data(ref);
    for (i = 0; i < 4 * 257; ++i) {
        if (fabsf(a[i] - b[i]) > 1e-5f) {
            print_message("entry %u channel %u: %g, expected %g\n", i / 4, i % 4, (double)a[i],
                          (double)b[i]);
        }
        assert_float_equal(a[i], b[i], 1e-5);
    }
    umbra_transfer_function_release(ref);
    umbra_transfer_function_release(tf);
}

/* An explicit range places the preset in data units: entries outside the preset's points take
 * its end values. */
static void test_paraview_explicit_range(void **state)
{
    umbra_context ctx = *state;
    static const char *json =
        "{\"RGBPoints\": [-1000, 0, 0, 0, 1000, 1, 1, 1],"
        " \"Points\": [-1000, 0, 0.5, 0, 1000, 1, 0.5, 0]}";
    umbra_transfer_function tf = NULL;
    double range[2];
    const float *t;
    /* 401 entries over [-1000, 3000]: entry 100 at HU 0, entry 200 at HU 1000. */
    assert_int_equal(load_preset(ctx, json, NULL, 401, -1000, 3000, &tf, range), UMBRA_SUCCESS);
    assert_float_equal(range[0], -1000.0, 0.0);
    assert_float_equal(range[1], 3000.0, 0.0);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[0], 0.0, 1e-6);
    assert_float_equal(t[4 * 100 + 0], 0.5, 1e-6);
    assert_float_equal(t[4 * 100 + 3], 0.5, 1e-6);
    assert_float_equal(t[4 * 200 + 1], 1.0, 1e-6);
    assert_float_equal(t[4 * 400 + 2], 1.0, 1e-6);
    assert_float_equal(t[4 * 400 + 3], 1.0, 1e-6);
    umbra_transfer_function_release(tf);
}

/* vtkPiecewiseFunction's definition: the curve passes the mean of its ends at the midpoint,
 * sharpness 0 is linear on each side of it, sharpness 1 is a step there. */
static void test_paraview_midpoint_and_sharpness(void **state)
{
    umbra_context ctx = *state;
    static const char *soft =
        "{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1], \"Points\": [0, 0, 0.25, 0, 1, 1, 0.5, 0]}";
    static const char *step =
        "{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1], \"Points\": [0, 0.2, 0.75, 1, 1, 0.6, 0.5, 0]}";
    static const char *curved =
        "{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1], \"Points\": [0, 0, 0.5, 0.5, 1, 1, 0.5, 0]}";
    umbra_transfer_function tf = NULL;
    const float *t;
    /* 101 entries: entry i at x = i / 100. */
    assert_int_equal(load_preset(ctx, soft, NULL, 101, 0, 0, &tf, NULL), UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[4 * 25 + 3], 0.5, 1e-6);   /* the mean at the midpoint 0.25 */
    assert_float_equal(t[4 * 10 + 3], 0.2, 1e-6);   /* linear below it: 0.5 * 0.10 / 0.25 */
    assert_float_equal(t[4 * 70 + 3], 0.8, 1e-6);   /* and above: 0.5 + 0.5 * 0.45 / 0.75 */
    umbra_transfer_function_release(tf);

    assert_int_equal(load_preset(ctx, step, NULL, 101, 0, 0, &tf, NULL), UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[4 * 74 + 3], 0.2, 1e-6);
    assert_float_equal(t[4 * 76 + 3], 0.6, 1e-6);
    umbra_transfer_function_release(tf);

    /* Sharpness 0.5: still the mean at the midpoint and monotone, but flatter near the ends
     * than the straight line. */
    assert_int_equal(load_preset(ctx, curved, NULL, 101, 0, 0, &tf, NULL), UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[4 * 50 + 3], 0.5, 1e-6);
    assert_true(t[4 * 20 + 3] < 0.2f);
    /* At x = 0.2 VTK's curve compresses s to 0.5 (2 s)^(1 + 10 sharpness) = 0.002048, then the
     * Hermite blend with tangents (1 - sharpness)(y2 - y1) gives 0.00103028. */
    assert_float_equal(t[4 * 20 + 3], 0.00103028, 1e-7);
    assert_true(t[4 * 80 + 3] > 0.8f);
    {
        int i;
        for (i = 1; i < 101; ++i) {
            assert_true(t[4 * i + 3] >= t[4 * (i - 1) + 3]);
        }
    }
    umbra_transfer_function_release(tf);
}

/* Without Points the opacity is umbra's default ramp over the preset's range: 0 to 0.1. */
static void test_paraview_default_opacity_ramp(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    const float *t;
    assert_int_equal(load_preset(ctx, "[{\"RGBPoints\": [10, 0, 0, 1, 20, 1, 0, 0]}]", NULL, 11,
                                 0, 0, &tf, NULL),
                     UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[3], 0.0, 1e-6);
    assert_float_equal(t[4 * 3 + 3], 0.03, 1e-6);
    assert_float_equal(t[4 * 10 + 3], UMBRA_PARAVIEW_DEFAULT_OPACITY, 1e-6);
    umbra_transfer_function_release(tf);
}

/* Lab: black to white passes L* = 50 halfway, which is sRGB 0.4663 (Y = 0.18419), not 0.5.
 * Diverging: Moreland's cool-to-warm ends meet at his published white, M = 88 (sRGB 0.8654).
 * Step: each colour holds to the next point. */
static void test_paraview_color_spaces(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    const float *t;
    int k;
    assert_int_equal(load_preset(ctx,
                                 "{\"ColorSpace\": \"Lab\", \"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1]}",
                                 NULL, 3, 0, 0, &tf, NULL),
                     UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    for (k = 0; k < 3; ++k) {
        assert_float_equal(t[4 + k], 0.4663, 1e-3);
        assert_float_equal(t[8 + k], 1.0, 1e-3);
    }
    umbra_transfer_function_release(tf);

    assert_int_equal(load_preset(ctx,
                                 "{\"ColorSpace\": \"Diverging\", \"RGBPoints\": "
                                 "[0, 0.229806, 0.298718, 0.753683, 1, 0.705673, 0.0155562, "
                                 "0.150233]}",
                                 NULL, 3, 0, 0, &tf, NULL),
                     UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    for (k = 0; k < 3; ++k) {
        assert_float_equal(t[4 + k], 0.8654, 2e-3);
    }
    /* The ends go through Lab and Msh and back (VTK's 4-digit sRGB matrices): within 1e-4. */
    assert_float_equal(t[0], 0.229806, 1e-4);
    assert_float_equal(t[8 + 1], 0.0155562, 1e-4);
    umbra_transfer_function_release(tf);

    assert_int_equal(load_preset(ctx,
                                 "{\"ColorSpace\": \"Step\", \"RGBPoints\": "
                                 "[0, 1, 0, 0, 0.5, 0, 1, 0, 1, 0, 0, 1]}",
                                 NULL, 5, 0, 0, &tf, NULL),
                     UMBRA_SUCCESS);
    t = umbra_transfer_function_data(tf);
    assert_float_equal(t[4 * 1 + 0], 1.0, 0.0); /* x = 0.25: still red */
    assert_float_equal(t[4 * 2 + 1], 1.0, 0.0); /* x = 0.5: green */
    assert_float_equal(t[4 * 3 + 1], 1.0, 0.0); /* x = 0.75: still green */
    assert_float_equal(t[4 * 4 + 2], 1.0, 0.0);
    umbra_transfer_function_release(tf);
}

static void test_paraview_picks_preset_by_name(void **state)
{
    umbra_context ctx = *state;
    static const char *json = "[{\"Name\": \"a\", \"RGBPoints\": [0, 1, 0, 0, 1, 1, 0, 0]},"
                              " {\"Name\": \"b\", \"RGBPoints\": [0, 0, 1, 0, 1, 0, 1, 0]}]";
    umbra_transfer_function tf = NULL;
    assert_int_equal(load_preset(ctx, json, NULL, 2, 0, 0, &tf, NULL), UMBRA_SUCCESS);
    assert_float_equal(umbra_transfer_function_data(tf)[0], 1.0, 0.0);
    umbra_transfer_function_release(tf);
    assert_int_equal(load_preset(ctx, json, "b", 2, 0, 0, &tf, NULL), UMBRA_SUCCESS);
    assert_float_equal(umbra_transfer_function_data(tf)[1], 1.0, 0.0);
    umbra_transfer_function_release(tf);
    test_assert_failed(ctx, load_preset(ctx, json, "c", 2, 0, 0, &tf, NULL), UMBRA_ERROR_FORMAT,
                  "no preset named \"c\"", "among 2");
    assert_null(tf);
}

/* umbra_transfer_function_load reads a .json as a preset; the shipped presets load. */
static void test_paraview_through_tf_load_and_shipped_presets(void **state)
{
    umbra_context ctx = *state;
    static const char *const shipped[3] = {"ct_bone.json", "walnut.json", "cool_to_warm.json"};
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    double range[2];
    int i;
    tmp_path(path, "ramp.json");
    test_write_text(path, "[{\"RGBPoints\": [5, 0, 0, 0, 6, 1, 1, 1]}]");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 1024);
    assert_float_equal(umbra_transfer_function_data(tf)[4 * 1023], 1.0, 0.0);
    umbra_transfer_function_release(tf);
    for (i = 0; i < 3; ++i) {
        char rel[64];
        snprintf(rel, sizeof rel, "examples/presets/%s", shipped[i]);
        source_path(path, rel);
        tf = NULL;
        assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, range),
                         UMBRA_SUCCESS);
        assert_true(range[1] > range[0]);
        umbra_transfer_function_release(tf);
    }
    /* The CT preset is in Hounsfield units. */
    source_path(path, "examples/presets/ct_bone.json");
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, range),
                     UMBRA_SUCCESS);
    assert_float_equal(range[0], -1024.0, 0.0);
    assert_float_equal(range[1], 3071.0, 0.0);
    umbra_transfer_function_release(tf);
}

typedef struct bad_preset {
    const char *json;
    umbra_status status;
    const char *needle, *needle2;
} bad_preset;

static void test_paraview_bad_presets_named(void **state)
{
    umbra_context ctx = *state;
    static const bad_preset cases[] = {
        {"[{\"RGBPoints\": [0, 1, 1, 1,\n 1, 1, 1 1]}]", UMBRA_ERROR_FORMAT, "malformed JSON",
         ":2:"},
        {"", UMBRA_ERROR_FORMAT, "malformed JSON", NULL},
        {"[{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1]}] trailing", UMBRA_ERROR_FORMAT,
         "malformed JSON", NULL},
        {"[{\"Name\": \"x\", \"Points\": [0, 0, 0.5, 0, 1, 1, 0.5, 0]}]", UMBRA_ERROR_FORMAT,
         "has neither RGBPoints nor IndexedColors", "\"x\""},
        {"[{\"Name\": \"cat\", \"IndexedColors\": [1, 0]}]", UMBRA_ERROR_FORMAT,
         "IndexedColors has 2 numbers", "multiple of 3"},
        {"[{\"RGBPoints\": [0, 0, 0, 0, 2, 1, 1, 1, 1, 0, 0, 0]}]", UMBRA_ERROR_FORMAT,
         "point 2 has x = 1 below point 1's 2", "ascend"},
        {"[{\"RGBPoints\": [0, 0, 0, 0, 1, 1, 1, 1], \"Points\": [1, 0, 0.5, 0, 0, 1, 0.5, 0]}]",
         UMBRA_ERROR_FORMAT, "Points point 1 has x = 0", "ascend"},
        {"[{\"RGBPoints\": []}]", UMBRA_ERROR_FORMAT, "RGBPoints has 0 numbers",
         "multiple of 4"},
        {"[{\"RGBPoints\": [0, 1, 1, 1], \"Points\": []}]", UMBRA_ERROR_FORMAT,
         "Points has 0 numbers", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1]}]", UMBRA_ERROR_FORMAT, "has 7 numbers",
         "x, r, g, b"},
        {"[]", UMBRA_ERROR_FORMAT, "list of presets is empty", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1, 1, \"1\", 1, 1]}]", UMBRA_ERROR_FORMAT,
         "RGBPoints[5] (red of point 1) is not a number", NULL},
        {"[{\"RGBPoints\": {\"x\": 0}}]", UMBRA_ERROR_FORMAT, "RGBPoints is not an array", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1], \"ColorSpace\": 3}]", UMBRA_ERROR_FORMAT,
         "ColorSpace is not a string", NULL},
        {"[{\"Name\": 7, \"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1]}]", UMBRA_ERROR_FORMAT,
         "Name is not a string", NULL},
        {"[7]", UMBRA_ERROR_FORMAT, "list item 0 is not a preset object", NULL},
        {"\"RGBPoints\"", UMBRA_ERROR_FORMAT, "expected a preset object", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1.5, 1, 1, 1, 1]}]", UMBRA_ERROR_FORMAT,
         "RGBPoints[3] = 1.5 (blue of point 0) is not in [0,1]", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1], \"Points\": [0, 0, 0.5, 2, 1, 1, 0.5, 0]}]",
         UMBRA_ERROR_FORMAT, "(sharpness of point 0) is not in [0,1]", NULL},
        {"[{\"RGBPoints\": [0, 1, 1, 1, 1e999, 1, 1, 1]}]", UMBRA_ERROR_FORMAT,
         "RGBPoints[4] (x of point 1) is not finite", NULL},
        {"[{\"RGBPoints\": [-1e308, 1, 1, 1, 1e308, 1, 1, 1]}]", UMBRA_ERROR_FORMAT,
         "finite distance apart", NULL},
        {"[{\"RGBPoints\": [3, 1, 1, 1]}]", UMBRA_ERROR_FORMAT, "span [3, 3]", NULL},
        {"[{\"ColorSpace\": \"HSL\", \"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1]}]",
         UMBRA_ERROR_UNSUPPORTED, "ColorSpace \"HSL\" is not supported", NULL},
        {"[{\"ColorSpace\": \"Lab/CIEDE2000\", \"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1]}]",
         UMBRA_ERROR_UNSUPPORTED, "\"Lab/CIEDE2000\"", NULL},
    };
    size_t i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        umbra_transfer_function tf = NULL;
        print_message("case %zu: %s\n", i, cases[i].json);
        test_assert_failed(ctx, load_preset(ctx, cases[i].json, NULL, 16, 0, 0, &tf, NULL),
                      cases[i].status, cases[i].needle, cases[i].needle2);
        assert_null(tf);
    }
}

/* Deep nesting stops at cJSON's limit, more points than the limit are refused by count, a file
 * past the size limit is refused before it is read, NUL bytes are refused. */
static void test_paraview_bounded(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    size_t n = 65537 * 4, i, len = 0;
    char *json = malloc(n * 4 + 64);
    FILE *f;
    assert_non_null(json);
    len += (size_t)sprintf(json + len, "{\"RGBPoints\": [");
    for (i = 0; i < n; ++i) {
        len += (size_t)sprintf(json + len, i % 4 == 0 ? "%zu," : "1,", i / 4);
    }
    json[len - 1] = ']';
    json[len++] = '}';
    json[len] = '\0';
    test_assert_failed(ctx, load_preset(ctx, json, NULL, 16, 0, 0, &tf, NULL), UMBRA_ERROR_FORMAT,
                  "RGBPoints has more than 65536 points", NULL);

    for (i = 0; i < 5000; ++i) {
        json[i] = '[';
    }
    json[i] = '\0';
    test_assert_failed(ctx, load_preset(ctx, json, NULL, 16, 0, 0, &tf, NULL), UMBRA_ERROR_FORMAT,
                  "malformed JSON", "nested deeper than 1000");
    free(json);

    {
        static const char nul[] = "[{\"RGBPoints\": [0, 1, 1, 1,\0 1, 1, 1, 1]}]";
        char where[32];
        snprintf(where, sizeof where, ":1:%zu:", strlen(nul) + 1);
        tmp_path(path, "nul.json");
        test_write_bytes(path, nul, sizeof nul - 1);
        test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, NULL),
                      UMBRA_ERROR_FORMAT, "NUL byte", where);
    }

    /* A sparse file of 65 MiB: refused from its size, without reading it. */
    tmp_path(path, "huge.json");
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(ftruncate(fileno(f), (off_t)65 << 20), 0);
    fclose(f);
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, NULL),
                  UMBRA_ERROR_FORMAT, "68157440 bytes", "67108864");
    remove(path);

    tmp_path(path, "dir.json");
    assert_int_equal(mkdir(path, 0700), 0);
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, NULL, &tf, NULL),
                  UMBRA_ERROR_IO, "not a regular file", NULL);
    rmdir(path);
    tmp_path(path, "missing.json");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_IO,
                  "missing.json", NULL);
}

static void test_paraview_bad_arguments(void **state)
{
    umbra_context ctx = *state;
    umbra_transfer_function tf = NULL;
    umbra_paraview_options o;
    char path[PATH_MAX_LEN];
    tmp_path(path, "ok.json");
    test_write_text(path, "{\"RGBPoints\": [0, 1, 1, 1, 1, 1, 1, 1]}");
    umbra_paraview_options_init(&o);
    o.resolution = 1;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                  UMBRA_ERROR_INVALID_ARGUMENT, "resolution 1 is not in 2..65536", NULL);
    umbra_paraview_options_init(&o);
    o.range_given = 1;
    o.range_min = 5;
    o.range_max = 5;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                  UMBRA_ERROR_INVALID_ARGUMENT, "range [5, 5]", NULL);
    umbra_paraview_options_init(&o);
    o.struct_size = 8;
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, path, &o, &tf, NULL),
                  UMBRA_ERROR_INVALID_ARGUMENT, "struct_size is 8", NULL);
    test_assert_failed(ctx, umbra_transfer_function_load_paraview(ctx, NULL, NULL, &tf, NULL),
                  UMBRA_ERROR_INVALID_ARGUMENT, "path is NULL", NULL);
    assert_int_equal(umbra_transfer_function_load_paraview(ctx, path, NULL, NULL, NULL),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
}

/* ---- NIfTI --------------------------------------------------------------------------------- */

/* A new image of nx x ny x nz (x nt) voxels of datatype, zero-filled, unit pixdim, no transform. */
static nifti_image *nim_new(int datatype, int64_t nx, int64_t ny, int64_t nz, int64_t nt)
{
    int64_t dims[8] = {nt > 1 ? 4 : 3, nx, ny, nz, nt, 1, 1, 1};
    nifti_image *nim = nifti_make_new_nim(dims, datatype, 1);
    assert_non_null(nim);
    return nim;
}

static void nim_write(nifti_image *nim, const char *path)
{
    test_nifti_write(nim, path); /* NIfTI-2 too (nifti_test.h says why it is not nifticlib's) */
}

/* uint8 NIfTI-1 .nii and uint16 NIfTI-2 .nii.gz through umbra_volume_load, spacing from
 * pixdim. */
static void test_nifti_loads_nii_and_gz(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {3, 4, 5};
    const float spacing[3] = {0.5f, 1.5f, 2.0f};
    char path[PATH_MAX_LEN];
    double want[60];
    umbra_volume vol = NULL;
    nifti_image *nim;
    int pass, i;
    for (pass = 0; pass < 2; ++pass) {
        nim = nim_new(pass ? DT_UINT16 : DT_UINT8, 3, 4, 5, 1);
        for (i = 0; i < 60; ++i) {
            want[i] = pass ? 1000.0 * i + 7 : (double)(i * 3 % 61);
            if (pass) {
                ((uint16_t *)nim->data)[i] = (uint16_t)want[i];
            } else {
                ((uint8_t *)nim->data)[i] = (uint8_t)want[i];
            }
        }
        nim->dx = nim->pixdim[1] = 0.5;
        nim->dy = nim->pixdim[2] = -1.5; /* the sign is the qform's business, not the spacing's */
        nim->dz = nim->pixdim[3] = 2.0;
        if (pass) {
            nim->nifti_type = NIFTI_FTYPE_NIFTI2_1;
        }
        nim_write(nim, tmp_path(path, pass ? "v2.nii.gz" : "v1.nii"));
        assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
        test_assert_volume(vol, dims, spacing, want, pass ? 7.0 : 0.0, pass ? 59007.0 : 60.0);
        umbra_volume_release(vol);
        vol = NULL;
    }
}

/* scl_slope / scl_inter give float32 voxels in real units; int8 widens to int16, float64
 * narrows to float32; a 4-D file with one time point is a volume. */
static void test_nifti_types_and_scaling(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {2, 2, 2};
    char path[PATH_MAX_LEN];
    double want[8];
    umbra_volume vol = NULL;
    nifti_image *nim;
    int i;

    nim = nim_new(DT_INT16, 2, 2, 2, 1);
    for (i = 0; i < 8; ++i) {
        ((int16_t *)nim->data)[i] = (int16_t)(i * 300);
        want[i] = 2.0 * i * 300 - 1024.0;
    }
    nim->scl_slope = 2.0;
    nim->scl_inter = -1024.0;
    nim_write(nim, tmp_path(path, "ct.nii.gz"));
    assert_int_equal(umbra_volume_load_nifti(ctx, path, &vol), UMBRA_SUCCESS);
    test_assert_volume(vol, dims, (const float[3]){1, 1, 1}, want, -1024.0, 3176.0);
    umbra_volume_release(vol);

    nim = nim_new(DT_INT8, 2, 2, 2, 1);
    for (i = 0; i < 8; ++i) {
        ((int8_t *)nim->data)[i] = (int8_t)(i * 20 - 70);
        want[i] = i * 20 - 70;
    }
    nim_write(nim, tmp_path(path, "s8.nii"));
    {
        umbra__nifti_volume nv;
        assert_int_equal(umbra__nifti_read(ctx, __func__, path, &nv), UMBRA_SUCCESS);
        assert_int_equal(nv.type, UMBRA_INT16);
        assert_int_equal(((int16_t *)nv.voxels)[0], -70);
        umbra__nifti_volume_free(&nv);
    }
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    test_assert_volume(vol, dims, (const float[3]){1, 1, 1}, want, -70.0, 70.0);
    umbra_volume_release(vol);

    nim = nim_new(DT_FLOAT64, 2, 2, 2, 1);
    for (i = 0; i < 8; ++i) {
        ((double *)nim->data)[i] = 0.1 * i;
        want[i] = (double)(float)(0.1 * i);
    }
    nim_write(nim, tmp_path(path, "f64.nii"));
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    test_assert_volume(vol, dims, (const float[3]){1, 1, 1}, want, 0.0, (double)(float)0.7);
    umbra_volume_release(vol);

    nim = nim_new(DT_INT32, 2, 2, 2, 1);
    for (i = 0; i < 8; ++i) {
        ((int32_t *)nim->data)[i] = 100000 * i - 5;
        want[i] = 100000.0 * i - 5;
    }
    {
        int64_t d4[8] = {4, 2, 2, 2, 1, 1, 1, 1};
        nifti_image *n4 = nifti_make_new_nim(d4, DT_INT32, 1);
        assert_non_null(n4);
        memcpy(n4->data, nim->data, 8 * sizeof(int32_t));
        nifti_image_free(nim);
        nim_write(n4, tmp_path(path, "i32t1.nii"));
    }
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    test_assert_volume(vol, dims, (const float[3]){1, 1, 1}, want, -5.0, 699995.0);
    umbra_volume_release(vol);
}

/* The sform wins over the qform, the qform over pixdim; spacing follows the chosen matrix. */
static void test_nifti_transforms(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra__nifti_volume nv;
    nifti_image *nim;
    int r, c;

    /* qform: 90 degrees about z (quaternion b = c = 0, d = sin 45), offsets, pixdim 2 3 4. */
    nim = nim_new(DT_UINT8, 2, 2, 2, 1);
    nim->dx = nim->pixdim[1] = 2.0;
    nim->dy = nim->pixdim[2] = 3.0;
    nim->dz = nim->pixdim[3] = 4.0;
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->quatern_b = 0.0;
    nim->quatern_c = 0.0;
    nim->quatern_d = sqrt(0.5);
    nim->qoffset_x = 10.0;
    nim->qoffset_y = -20.0;
    nim->qoffset_z = 30.0;
    nim->qfac = 1.0;
    nim_write(nim, tmp_path(path, "q.nii"));
    assert_int_equal(umbra__nifti_read(ctx, __func__, path, &nv), UMBRA_SUCCESS);
    {
        const double want[4][4] = {
            {0, -3, 0, 10}, {2, 0, 0, -20}, {0, 0, 4, 30}, {0, 0, 0, 1}};
        assert_int_equal(nv.transform, UMBRA__NIFTI_QFORM);
        for (r = 0; r < 4; ++r) {
            for (c = 0; c < 4; ++c) {
                assert_float_equal(nv.index_to_world[r][c], want[r][c], 1e-5);
            }
        }
        assert_float_equal(nv.spacing[0], 2.0, 1e-5);
        assert_float_equal(nv.spacing[1], 3.0, 1e-5);
        assert_float_equal(nv.spacing[2], 4.0, 1e-5);
    }
    umbra__nifti_volume_free(&nv);
    {
        /* The loaded volume carries that world: origin, unit directions per index axis. */
        const float origin[3] = {10, -20, 30}, dirs[9] = {0, 1, 0, -1, 0, 0, 0, 0, 1};
        umbra_volume vol = NULL;
        umbra_volume_info info;
        assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
        assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
        assert_int_equal(info.transform_given, 1);
        for (r = 0; r < 3; ++r) {
            assert_float_equal(info.origin[r], origin[r], 1e-5);
            assert_float_equal(info.spacing[r], 2.0 + r, 1e-5);
        }
        for (r = 0; r < 9; ++r) {
            assert_float_equal(info.directions[r], dirs[r], 1e-5);
        }
        umbra_volume_release(vol);
    }

    /* sform: a shear-free affine whose column lengths (0.6, 5, 7) differ from pixdim (1 1 1). */
    nim = nim_new(DT_UINT8, 2, 2, 2, 1);
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->sform_code = NIFTI_XFORM_MNI_152;
    memset(&nim->sto_xyz, 0, sizeof nim->sto_xyz);
    nim->sto_xyz.m[0][0] = 0.36;
    nim->sto_xyz.m[1][0] = 0.48; /* column 0: (0.36, 0.48, 0), length 0.6 */
    nim->sto_xyz.m[1][1] = 5.0;
    nim->sto_xyz.m[2][2] = -7.0;
    nim->sto_xyz.m[0][3] = 1.5;
    nim->sto_xyz.m[3][3] = 1.0;
    nim_write(nim, tmp_path(path, "s.nii"));
    assert_int_equal(umbra__nifti_read(ctx, __func__, path, &nv), UMBRA_SUCCESS);
    assert_int_equal(nv.transform, UMBRA__NIFTI_SFORM);
    assert_float_equal(nv.index_to_world[1][0], 0.48, 1e-6);
    assert_float_equal(nv.index_to_world[0][3], 1.5, 1e-6);
    assert_float_equal(nv.spacing[0], 0.6, 1e-6);
    assert_float_equal(nv.spacing[1], 5.0, 1e-6);
    assert_float_equal(nv.spacing[2], 7.0, 1e-6);
    umbra__nifti_volume_free(&nv);

    /* Neither: diag(pixdim), pixdim 0 read as 1. */
    nim = nim_new(DT_UINT8, 2, 2, 2, 1);
    nim->dx = nim->pixdim[1] = 0.25;
    nim->dz = nim->pixdim[3] = 0.0;
    nim_write(nim, tmp_path(path, "p.nii"));
    assert_int_equal(umbra__nifti_read(ctx, __func__, path, &nv), UMBRA_SUCCESS);
    assert_int_equal(nv.transform, UMBRA__NIFTI_PIXDIM);
    assert_float_equal(nv.spacing[0], 0.25, 1e-6);
    assert_float_equal(nv.spacing[2], 1.0, 1e-6);
    assert_float_equal(nv.index_to_world[0][3], 0.0, 0.0);
    umbra__nifti_volume_free(&nv);
}

/* Writes a valid 4x4x4 uint16 .nii and returns its bytes. */
static unsigned char *valid_nii(const char *path, size_t *size)
{
    nifti_image *nim = nim_new(DT_UINT16, 4, 4, 4, 1);
    int i;
    for (i = 0; i < 64; ++i) {
        ((uint16_t *)nim->data)[i] = (uint16_t)i;
    }
    nim_write(nim, path);
    return test_read_bytes(path, size);
}

/* NIfTI-1 header field offsets (nifti1.h): dim[8] shorts at 40, datatype at 70. */
static void put_i16(unsigned char *hdr, size_t off, int16_t v)
{
    memcpy(hdr + off, &v, sizeof v);
}

static void write_gz(const char *path, const void *data, size_t size)
{
    znzFile z = znzopen(path, "wb", 1);
    assert_false(znz_isnull(z));
    assert_int_equal(znzwrite(data, 1, size, z), size);
    Xznzclose(&z);
}

static void test_nifti_broken_files_refused(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], bad[PATH_MAX_LEN];
    umbra_volume vol = NULL;
    unsigned char *bytes;
    size_t size;

    bytes = valid_nii(tmp_path(path, "good.nii"), &size);
    assert_int_equal(size, 352 + 128);

    /* Truncated: the header's claim is checked against the file before reading. */
    test_write_bytes(tmp_path(bad, "short.nii"), bytes, size - 10);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT, "holds 470 bytes",
                  "352 + 128");
    assert_null(vol);

    /* A claim of 30000^3 voxels in a 480-byte file. */
    put_i16(bytes, 42, 30000);
    put_i16(bytes, 44, 30000);
    put_i16(bytes, 46, 30000);
    test_write_bytes(tmp_path(bad, "huge.nii"), bytes, size);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT, "holds 480 bytes",
                  "54000000000000");
    /* The same compressed: bounded by gzip's ratio. */
    write_gz(tmp_path(bad, "huge.nii.gz"), bytes, size);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT,
                  "compressed bytes, too few", "1032");

    /* A second time point. */
    put_i16(bytes, 40, 4);
    put_i16(bytes, 42, 2);
    put_i16(bytes, 44, 2);
    put_i16(bytes, 46, 4);
    put_i16(bytes, 48, 2);
    test_write_bytes(tmp_path(bad, "t2.nii"), bytes, size);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT, "dim 4 (of 4) is 2",
                  NULL);
    put_i16(bytes, 40, 3);
    put_i16(bytes, 42, 4);
    put_i16(bytes, 44, 4);
    put_i16(bytes, 46, 4);
    put_i16(bytes, 48, 1);

    /* Complex voxels (DT_COMPLEX64): the type is refused before any size is looked at. */
    put_i16(bytes, 46, 2);
    put_i16(bytes, 70, DT_COMPLEX64);
    put_i16(bytes, 72, 64);
    test_write_bytes(tmp_path(bad, "complex.nii"), bytes, size);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_UNSUPPORTED,
                  "datatype COMPLEX64", NULL);
    free(bytes);

    /* A float64 voxel beyond float32. */
    {
        nifti_image *nim = nim_new(DT_FLOAT64, 2, 1, 1, 1);
        ((double *)nim->data)[1] = 1e300;
        nim_write(nim, tmp_path(bad, "big.nii"));
        test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT,
                      "not a finite float32", "FLOAT64");
    }

    /* Truncated compressed voxels: the header reads, the data do not. */
    {
        nifti_image *nim = nim_new(DT_UINT8, 32, 32, 32, 1);
        unsigned char *gz;
        size_t gz_size;
        int i;
        for (i = 0; i < 32768; ++i) {
            ((uint8_t *)nim->data)[i] = (uint8_t)((i * 7919u) ^ (i >> 3));
        }
        nim_write(nim, tmp_path(bad, "cut.nii.gz"));
        gz = test_read_bytes(bad, &gz_size);
        test_write_bytes(bad, gz, gz_size / 2);
        free(gz);
        test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT,
                      "cannot read its 32768 bytes", NULL);
    }

    test_write_text(tmp_path(bad, "text.nii"), "this is not a NIfTI header\n");
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_FORMAT,
                  "is not a NIfTI-1/2 file", "text.nii");
    test_assert_failed(ctx, umbra_volume_load(ctx, tmp_path(bad, "missing.nii"), &vol), UMBRA_ERROR_IO,
                  "cannot open", "missing.nii");
    tmp_path(bad, "dir.nii");
    assert_int_equal(mkdir(bad, 0700), 0);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_IO, "not a regular file",
                  NULL);
    rmdir(bad);
    tmp_path(bad, "fifo.nii.gz");
    assert_int_equal(mkfifo(bad, 0600), 0);
    test_assert_failed(ctx, umbra_volume_load(ctx, bad, &vol), UMBRA_ERROR_IO, "not a regular file",
                  NULL);
    remove(bad);
    test_assert_failed(ctx, umbra_volume_load(ctx, tmp_path(bad, "x.vti"), &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "unknown extension", "VTK (.vti)");
    assert_int_equal(umbra_volume_load_nifti(ctx, path, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(umbra_context_take_error(ctx, NULL), UMBRA_ERROR_INVALID_ARGUMENT);
}

/* ---- the command line ------------------------------------------------------------------------ */

/* umbra-render --volume ct.nii.gz --tf ct_bone.json --technique cssm: a CT-like volume in
 * Hounsfield units (air, a soft-tissue box, a bone ball; stored +1024 with scl_inter -1024). The
 * preset is placed in HU over the volume's range, so the ball (1200 HU) is opaque bone white and
 * the soft tissue nearly clear: the centre of the picture is lit warm white, a corner is the
 * background. */
static void test_cli_renders_nifti_with_preset(void **state)
{
    umbra_context ctx = *state;
    const char *exe = getenv("UMBRA_RENDER") ? getenv("UMBRA_RENDER") : "./umbra-render";
    char vol_path[PATH_MAX_LEN], out_path[PATH_MAX_LEN], preset[PATH_MAX_LEN];
    char cmd[4 * PATH_MAX_LEN];
    nifti_image *nim = nim_new(DT_INT16, 32, 32, 32, 1);
    uint32_t w = 0, h = 0;
    float *rgba = NULL;
    int x, y, z, rc;
    for (z = 0; z < 32; ++z) {
        for (y = 0; y < 32; ++y) {
            for (x = 0; x < 32; ++x) {
                double dx = x - 15.5, dy = y - 15.5, dz = z - 15.5;
                int hu = -1000;
                if (fabs(dx) < 13 && fabs(dy) < 13 && fabs(dz) < 13) {
                    hu = 40;
                }
                if (dx * dx + dy * dy + dz * dz < 64) {
                    hu = 1200;
                }
                ((int16_t *)nim->data)[(z * 32 + y) * 32 + x] = (int16_t)(hu + 1024);
            }
        }
    }
    nim->scl_slope = 1.0;
    nim->scl_inter = -1024.0;
    nim_write(nim, tmp_path(vol_path, "ct.nii.gz"));
    tmp_path(out_path, "ct.png");
    assert_int_equal(access(exe, X_OK), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' --volume '%s' --tf '%s' --technique cssm --size 64x64 --no-ground --out '%s' "
             "2>/dev/null",
             exe, vol_path, source_path(preset, "examples/presets/ct_bone.json"), out_path);
    rc = system(cmd);
    assert_int_equal(rc, 0);
    assert_int_equal(umbra_image_read(ctx, out_path, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 64);
    assert_int_equal(h, 64);
    {
        const float *centre = rgba + 4 * (32 * 64 + 32), *corner = rgba;
        const float *tissue = rgba + 4 * (37 * 64 + 15);
        print_message("centre %g %g %g, corner %g %g %g\n", (double)centre[0],
                      (double)centre[1], (double)centre[2], (double)corner[0], (double)corner[1],
                      (double)corner[2]);
        /* Lit bone (the preset's warm white: r > g > b) against the default background. */
        assert_true(centre[0] > 0.2f && centre[0] > centre[1] && centre[1] > centre[2]);
        assert_float_equal(corner[0], 0.08, 0.01);
        assert_float_equal(corner[2], 0.10, 0.01);
        /* Inside the box's outline, beside the ball: the soft tissue is nearly clear. Placed over
         * the preset's own range instead of the volume's, 40 HU would land at 913 HU and the box
         * would be an opaque white cube: this pixel 0.27 instead of 0.12 (linear). */
        print_message("tissue %g\n", (double)tissue[0]);
        assert_true(tissue[0] < 0.19f);
    }
    free(rgba);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paraview_defaults),
#define T(t) cmocka_unit_test_setup_teardown(t, test_group_setup, test_group_teardown)
        T(test_paraview_rgb_matches_points),
        T(test_paraview_explicit_range),
        T(test_paraview_midpoint_and_sharpness),
        T(test_paraview_default_opacity_ramp),
        T(test_paraview_color_spaces),
        T(test_paraview_picks_preset_by_name),
        T(test_paraview_through_tf_load_and_shipped_presets),
        T(test_paraview_bad_presets_named),
        T(test_paraview_bounded),
        T(test_paraview_bad_arguments),
        T(test_nifti_loads_nii_and_gz),
        T(test_nifti_types_and_scaling),
        T(test_nifti_transforms),
        T(test_nifti_broken_files_refused),
        T(test_cli_renders_nifti_with_preset),
#undef T
    };
    nifti_set_debug_level(0); /* the writer's chatter */
    return cmocka_run_group_tests(tests, NULL, NULL);
}
