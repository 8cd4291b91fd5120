// SPDX-License-Identifier: Apache-2.0
/* tests/test_metrics.c: the accuracy bench's image error measures and scene-file parser.
 *
 * The bench's timing is never tested; what its numbers mean is. The measures (bench/metrics.c)
 * are checked against values computed here by hand: identical images, a known constant offset in
 * display values, and SSIM's symmetry and its drop under noise. The scene parser
 * (bench/scene_file.c) must accept every committed bench/scenes/NAME.scene and reject a malformed
 * file with a message naming the file, the line and the fault. The bench sources are compiled
 * into this test directly (they are a handful of plain functions, not part of the library). */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

#include "../bench/metrics.c"
#include "../bench/scene_file.c"


/* sRGB decoding, written independently of metrics_display: display value -> linear. */
static float srgb_decode(float d)
{
    return d <= 0.04045f ? d / 12.92f : powf((d + 0.055f) / 1.055f, 2.4f);
}

/* w x h premultiplied RGBA, opaque, every channel at the linear value of display value d. */
static float *constant_image(uint32_t w, uint32_t h, float d)
{
    float *img = malloc((size_t)w * h * 4 * sizeof *img);
    assert_non_null(img);
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        img[4 * i] = img[4 * i + 1] = img[4 * i + 2] = srgb_decode(d);
        img[4 * i + 3] = 1.0f;
    }
    return img;
}

/* A smooth pattern with structure at several scales, display values in [0.1, 0.9]. */
static float *pattern_image(uint32_t w, uint32_t h)
{
    float *img = malloc((size_t)w * h * 4 * sizeof *img);
    assert_non_null(img);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            float *p = img + 4 * ((size_t)y * w + x);
            float d = 0.5f + 0.25f * sinf(0.21f * (float)x) * cosf(0.13f * (float)y) +
                      0.15f * sinf(0.05f * (float)(x + 2 * y));
            p[0] = srgb_decode(d);
            p[1] = srgb_decode(0.9f * d + 0.05f);
            p[2] = srgb_decode(1.0f - d);
            p[3] = 1.0f;
        }
    return img;
}

/* ---- metrics --------------------------------------------------------------------------------- */

static void test_display_clamps_and_encodes(void **state)
{
    (void)state;
    assert_true(metrics_display(0.0f) == 0.0f);
    assert_true(metrics_display(1.0f) == 1.0f);
    assert_true(metrics_display(-0.5f) == 0.0f);
    assert_true(metrics_display(7.0f) == 1.0f);
    assert_true(metrics_display(NAN) == 0.0f);
    /* The sRGB curve's two pieces meet at 0.0031308 -> 0.04045. */
    assert_true(fabsf(metrics_display(0.0031308f) - 0.04045f) < 1e-5f);
    for (float d = 0.05f; d < 1.0f; d += 0.05f)
        assert_true(fabsf(metrics_display(srgb_decode(d)) - d) < 1e-5f);
}

static void test_identical_images_have_zero_error(void **state)
{
    (void)state;
    const uint32_t w = 40, h = 30;
    float *a = pattern_image(w, h);
    metrics_error e;
    memset(&e, 0, sizeof e);
    assert_int_equal(metrics_compare(a, a, w, h, &e), 0);
    assert_true(e.rmse == 0.0);
    assert_true(isinf(e.psnr_db) && e.psnr_db > 0.0);
    assert_true(e.max_abs == 0.0);
    assert_true(e.mean_abs == 0.0);
    assert_true(fabs(e.ssim - 1.0) < 1e-12);
    free(a);
}

/* Display values 0.4 and 0.5 everywhere: every channel differs by 0.1, so RMSE = max = mean =
 * 0.1 and PSNR = 20 log10(1/0.1) = 20 dB. Both images are constant, so every window has zero
 * variance and SSIM reduces to its luminance term (2 m1 m2 + C1) / (m1^2 + m2^2 + C1) with the
 * lumas m = 0.4 and 0.5 (luma weights sum to 1). Tolerance: float sRGB round trip, 1e-5. */
static void test_constant_offset_gives_known_error(void **state)
{
    (void)state;
    const uint32_t w = 24, h = 20;
    float *a = constant_image(w, h, 0.4f), *b = constant_image(w, h, 0.5f);
    metrics_error e;
    memset(&e, 0, sizeof e);
    assert_int_equal(metrics_compare(a, b, w, h, &e), 0);
    assert_true(fabs(e.rmse - 0.1) < 1e-5);
    assert_true(fabs(e.max_abs - 0.1) < 1e-5);
    assert_true(fabs(e.mean_abs - 0.1) < 1e-5);
    assert_true(fabs(e.psnr_db - 20.0) < 1e-3);
    const double c1 = 1e-4, m1 = 0.4, m2 = 0.5;
    double ssim = (2.0 * m1 * m2 + c1) / (m1 * m1 + m2 * m2 + c1);
    assert_true(fabs(e.ssim - ssim) < 1e-5);
    free(a);
    free(b);
}

/* Noise lowers SSIM below 1, more noise lowers it more, and the measures do not depend on which
 * image is called the reference. */
static void test_ssim_drops_with_noise_and_is_symmetric(void **state)
{
    (void)state;
    const uint32_t w = 64, h = 48;
    float *a = pattern_image(w, h);
    float *b = malloc((size_t)w * h * 4 * sizeof *b), *c = malloc((size_t)w * h * 4 * sizeof *c);
    assert_non_null(b);
    assert_non_null(c);
    uint32_t rng = 12345u;
    for (size_t i = 0; i < (size_t)w * h * 4; ++i) {
        rng = rng * 1664525u + 1013904223u;
        float n = ((float)(rng >> 8) / 16777216.0f - 0.5f) * 0.1f;
        b[i] = (i % 4 == 3) ? 1.0f : a[i] + n;
        c[i] = (i % 4 == 3) ? 1.0f : a[i] + 4.0f * n;
    }
    metrics_error ab, ba, ac;
    memset(&ab, 0, sizeof ab);
    memset(&ba, 0, sizeof ba);
    memset(&ac, 0, sizeof ac);
    assert_int_equal(metrics_compare(a, b, w, h, &ab), 0);
    assert_int_equal(metrics_compare(b, a, w, h, &ba), 0);
    assert_int_equal(metrics_compare(a, c, w, h, &ac), 0);
    assert_true(ab.ssim < 0.999 && ab.ssim > 0.0);
    assert_true(ac.ssim < ab.ssim);
    assert_true(ab.rmse > 0.0 && ac.rmse > ab.rmse);
    assert_true(fabs(ab.ssim - ba.ssim) < 1e-12);
    assert_true(ab.rmse == ba.rmse && ab.max_abs == ba.max_abs && ab.mean_abs == ba.mean_abs);
    free(a);
    free(b);
    free(c);
}

/* An image smaller than the 11x11 window still gets an SSIM (the window shrinks to fit). */
static void test_ssim_small_image(void **state)
{
    (void)state;
    float x[6 * 5], y[6 * 5];
    for (int i = 0; i < 30; ++i) {
        x[i] = (float)(i % 7) / 7.0f;
        y[i] = x[i];
    }
    assert_true(fabs(metrics_ssim(x, y, 6, 5) - 1.0) < 1e-12);
    y[7] += 0.3f;
    double s = metrics_ssim(x, y, 6, 5);
    assert_true(s < 1.0 && s > -1.0);
    assert_true(metrics_ssim(x, y, 0, 5) < -1.5);
}

/* ---- scene files ----------------------------------------------------------------------------- */

static int parse(const char *text, scene_spec *s, char *err, size_t n)
{
    return scene_parse_text(text, "scenes/test.scene", "/data", 0, s, err, n);
}

static void test_scene_parses_all_keys(void **state)
{
    (void)state;
    const char *text =
        "# a comment\n"
        "volume walnut.nhdr\n"
        "tf walnut.tf   # relative to the scene file\n"
        "description  The walnut,  like the CSSM paper  \n"
        "units world\n"
        "camera perspective\n"
        "eye 1 2 3\n"
        "target 0 -0.5 0\n"
        "up 0 1 0\n"
        "fov 34\n"
        "light point\n"
        "light_position -1 1.9 -0.35\n"
        "light_color 1 0.9 0.8\n"
        "size 320 240\n"
        "step 0.5\n"
        "reference_step 0.25\n"
        "transmission colored\n"
        "shading on\n"
        "ambient 0.25\n"
        "ground off\n"
        "background 0.08 0.08 0.1 1\n"
        "quick yes\n"
        "papers cssm,deep\n";
    scene_spec s;
    char err[512];
    assert_int_equal(parse(text, &s, err, sizeof err), 0);
    assert_string_equal(s.name, "test");
    assert_string_equal(s.volume, "/data/walnut.nhdr");
    assert_string_equal(s.tf, "scenes/walnut.tf");
    assert_string_equal(s.description, "The walnut,  like the CSSM paper");
    assert_false(s.builtin);
    assert_true(s.units_world);
    assert_true(s.have_eye && s.eye[2] == 3.0f && s.target[1] == -0.5f && s.fov == 34.0f);
    assert_true(s.have_light_type && s.light_type == UMBRA_LIGHT_POINT);
    assert_true(s.light_position[0] == -1.0f && s.light_color[2] == 0.8f);
    assert_int_equal(s.width, 320);
    assert_int_equal(s.height, 240);
    assert_true(s.step == 0.5f && s.reference_step == 0.25f);
    assert_int_equal(s.transmission, UMBRA_TRANSMISSION_COLORED);
    assert_int_equal(s.shading, 1);
    assert_int_equal(s.ground, 0);
    assert_true(s.have_ambient && s.ambient[0] == 0.25f && s.ambient[2] == 0.25f);
    assert_true(s.have_background && s.background[3] == 1.0f);
    assert_int_equal(s.quick, 1);
    assert_int_equal(s.papers, SCENE_PAPERS_CSSM | SCENE_PAPERS_DEEP);

    /* The hash follows the content. */
    scene_spec t;
    assert_int_equal(parse("volume builtin slab 16\n", &t, err, sizeof err), 0);
    assert_true(t.builtin && t.tf_builtin && t.builtin_resolution == 16);
    uint64_t h1 = t.hash;
    assert_int_equal(parse("volume builtin slab 17\n", &t, err, sizeof err), 0);
    assert_true(t.hash != h1);
}

typedef struct bad_case {
    const char *text;
    const char *message;  /* a part of the expected message */
} bad_case;

static void test_scene_rejects_bad_files_with_clear_messages(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        {"volume builtin slab\ncamra perspective\n", "scenes/test.scene:2: unknown key 'camra'"},
        {"volume builtin slab\nfov abc\n", ":2: 'fov': 'abc' is not a finite number"},
        {"volume builtin slab\nfov 200\n", "'fov': 200 must lie in [0.01, 179.99]"},
        {"volume builtin slab\neye 1 2\n", "'eye' takes 3 numbers, got 2"},
        {"volume builtin slab\nstep 0.5\nstep 1\n", ":3: 'step' is given twice"},
        {"volume builtin cube\n", "no built-in scene 'cube'"},
        {"step 0.5\n", "scenes/test.scene: no 'volume' line"},
        {"volume walnut.nhdr\nlight point\nlight_position 0 1 0\neye 0 0 1\n",
         "needs a 'tf FILE' line"},
        {"volume walnut.nhdr\ntf w.tf\n", "needs 'light' and 'eye' lines"},
        {"volume builtin slab\nlight directional\n", "needs a 'light_direction X Y Z' line"},
        {"volume builtin slab\nlight directional\nlight_direction 0 0 0\n", "has no direction"},
        {"volume builtin slab\ntransmission blue\n", "'transmission' takes grey or colored"},
        {"volume builtin slab\nground maybe\n", "'ground': 'maybe' is not one of on, off"},
        {"volume builtin slab\nsize 4 4\n", "'size' takes width and height in [8, 8192]"},
        {"volume builtin slab\ncamera orthographic\n", "needs an 'ortho_height H' line"},
        {"volume builtin slab\npapers all\n", "'papers' takes no, cssm, deep or cssm,deep"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        scene_spec s;
        char err[1024];
        assert_int_equal(parse(cases[i].text, &s, err, sizeof err), -1);
        if (!strstr(err, cases[i].message)) {
            print_error("case %zu: message '%s' lacks '%s'\n", i, err, cases[i].message);
            fail();
        }
    }
    scene_spec s;
    char err[1024];
    assert_int_equal(scene_parse_file("/nonexistent/x.scene", "/data", &s, err, sizeof err), -1);
    assert_non_null(strstr(err, "/nonexistent/x.scene: cannot read the scene file"));
}

/* Every scene the bench ships parses, with its transfer-function files present. */
static void test_committed_scenes_parse(void **state)
{
    (void)state;
    /* This file's directory (CMake compiles it by its absolute path), then ../bench/scenes. */
    char dir_path[2048];
    const char *slash = strrchr(__FILE__, '/');
    snprintf(dir_path, sizeof dir_path, "%.*s/../bench/scenes",
             slash ? (int)(slash - __FILE__) : 1, slash ? __FILE__ : ".");
    DIR *dir = opendir(dir_path);
    assert_non_null(dir);
    int count = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        size_t n = strlen(e->d_name);
        if (n < 7 || strcmp(e->d_name + n - 6, ".scene") != 0)
            continue;
        char path[4200], err[1024];
        snprintf(path, sizeof path, "%s/%s", dir_path, e->d_name);
        scene_spec s;
        if (scene_parse_file(path, "/data", &s, err, sizeof err) != 0) {
            print_error("%s\n", err);
            fail();
        }
        ++count;
    }
    closedir(dir);
    assert_true(count >= 3);
}

/* A built-in volume with overrides: the scene keeps the built-in's transfer function and takes
 * the file's camera and options, diagonal units scaled by the box diagonal. */
static void test_scene_create_applies_overrides(void **state)
{
    (void)state;
    umbra_context ctx = test_context();
    const char *text = "volume builtin slab 16\n"
                       "eye 0 0 2\n"
                       "light directional\n"
                       "light_direction 0 -1 0\n"
                       "ground off\n"
                       "step 0.75\n";
    scene_spec s;
    char err[512];
    assert_int_equal(parse(text, &s, err, sizeof err), 0);
    umbra_scene scene;
    umbra_transfer_function light_tf = NULL;
    assert_int_equal(scene_create(ctx, &s, &scene, &light_tf), UMBRA_SUCCESS);
    assert_null(light_tf);
    assert_non_null(scene.tf);
    /* slab 16: 16 x 4 x 16 voxels of spacing 1. */
    float diag = sqrtf(16.0f * 16.0f * 2.0f + 4.0f * 4.0f);
    assert_true(fabsf(scene.camera.eye[2] - 2.0f * diag) < 1e-4f * diag);
    assert_true(scene.camera.eye[0] == 0.0f);
    assert_int_equal(scene.light.type, UMBRA_LIGHT_DIRECTIONAL);
    assert_true(scene.light.direction[1] == -1.0f);
    assert_int_equal(scene.options.ground_plane, 0);
    assert_true(scene.options.step == 0.75f);
    umbra_scene_release(&scene);

    /* A volume file that is not there fails cleanly, with the path in the message. */
    assert_int_equal(parse("volume no_such_volume.nhdr\ntf t.tf\nlight point\n"
                           "light_position 0 1 0\neye 0 0 2\n", &s, err, sizeof err), 0);
    assert_false(scene_volume_present(&s));
    assert_int_not_equal(scene_create(ctx, &s, &scene, &light_tf), UMBRA_SUCCESS);
    assert_true(test_message_contains(ctx, "no_such_volume.nhdr"));
    assert_null(scene.volume);
    umbra_context_release(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_display_clamps_and_encodes),
        cmocka_unit_test(test_identical_images_have_zero_error),
        cmocka_unit_test(test_constant_offset_gives_known_error),
        cmocka_unit_test(test_ssim_drops_with_noise_and_is_symmetric),
        cmocka_unit_test(test_ssim_small_image),
        cmocka_unit_test(test_scene_parses_all_keys),
        cmocka_unit_test(test_scene_rejects_bad_files_with_clear_messages),
        cmocka_unit_test(test_committed_scenes_parse),
        cmocka_unit_test(test_scene_create_applies_overrides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
