// SPDX-License-Identifier: Apache-2.0
/* tests/test_projection.c: the projection render modes (umbra_render_desc.mode,
 * kernels/projection.cl) pinned down against a brute-force projection written here in plain C
 * (double precision, its own camera rays, box intersection, trilinear sampler and table lookup):
 *  - MIP, MinIP and average intensity projection of a random volume on an anisotropic grid,
 *    perspective and orthographic, over a background: every pixel within 1e-4 (2.6e-5
 *    measured: the float kernel's sample positions differ from the double ones by ~1e-6 of the
 *    ray's length, which random data turns into value differences of that order), the sample count the brute
 *    force's within 0.05%;
 *  - with a clip plane and a crop box: the brute force skips the samples outside the region;
 *  - a multi-channel volume: each channel through its own table, colours added (premultiplied),
 *    alpha 1 - prod (1 - a_c);
 *  - refused with a message naming the mode: a shadow technique, a label map, an unknown mode;
 *    an old (umbra 0.5) umbra_render_desc keeps the mode set before.
 * Usage: test_projection [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

/* The group's context (test_group_setup), also used by the helpers below. */
static umbra_context ctx;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    return rc;
}

/* ---- the brute force ----------------------------------------------------------------------- */

typedef struct scene {
    uint32_t dims[3];
    float spacing[3];
    uint32_t channels;
    const float *voxels;       /* normalised, channel c's dims voxels at c * count */
    const float *tf[4];        /* per channel, RGBA entries as given */
    uint32_t tf_n[4];
    umbra_camera cam;
    float background[4];
    float step;                /* voxels (the smallest spacing) */
    umbra_render_mode mode;
    uint32_t planes;           /* clip planes (world = local: no transform) */
    double plane[6][4];
    int crop;
    double crop_min[3], crop_max[3]; /* voxel coordinates */
} scene;

static double sample(const scene *s, uint32_t c, const double p[3])
{
    const size_t count = (size_t)s->dims[0] * s->dims[1] * s->dims[2];
    const float *v = s->voxels + c * count;
    double x[3], f[3];
    size_t i0[3], i1[3];
    for (int a = 0; a < 3; ++a) {
        const double ext = s->dims[a] * (double)s->spacing[a];
        x[a] = (p[a] + 0.5 * ext) / s->spacing[a] - 0.5;
        x[a] = x[a] < 0 ? 0 : (x[a] > s->dims[a] - 1 ? s->dims[a] - 1 : x[a]);
        i0[a] = (size_t)floor(x[a]);
        i1[a] = i0[a] + 1 < s->dims[a] ? i0[a] + 1 : s->dims[a] - 1;
        f[a] = x[a] - (double)i0[a];
    }
    double r = 0.0;
    for (int k = 0; k < 8; ++k) {
        const size_t ix = k & 1 ? i1[0] : i0[0], iy = k & 2 ? i1[1] : i0[1];
        const size_t iz = k & 4 ? i1[2] : i0[2];
        const double w = (k & 1 ? f[0] : 1 - f[0]) * (k & 2 ? f[1] : 1 - f[1]) *
                         (k & 4 ? f[2] : 1 - f[2]);
        r += w * v[(iz * s->dims[1] + iy) * s->dims[0] + ix];
    }
    return r;
}

static void lookup(const float *tf, uint32_t n, double v, double out[4])
{
    const double x = (v < 0 ? 0 : v > 1 ? 1 : v) * (n - 1);
    const uint32_t i = (uint32_t)x < n - 2 ? (uint32_t)x : n - 2;
    const double f = x - i;
    for (int c = 0; c < 4; ++c)
        out[c] = tf[4 * i + c] + (tf[4 * i + 4 + c] - tf[4 * i + c]) * f;
}

static int kept(const scene *s, const double p[3])
{
    for (uint32_t i = 0; i < s->planes; ++i)
        if (s->plane[i][0] * p[0] + s->plane[i][1] * p[1] + s->plane[i][2] * p[2] + s->plane[i][3] <
            0.0)
            return 0;
    for (int a = 0; s->crop && a < 3; ++a) {
        const double x = (p[a] + 0.5 * s->dims[a] * s->spacing[a]) / s->spacing[a] - 0.5;
        if (x < s->crop_min[a] || x > s->crop_max[a])
            return 0;
    }
    return 1;
}

/* One pixel: premultiplied RGBA; *taken the samples reduced. */
static void brute_pixel(const scene *s, uint32_t w, uint32_t h, uint32_t px, uint32_t py,
                        double out[4], uint64_t *taken)
{
    double fw[3], up[3], rt[3], o[3], d[3];
    double len = 0;
    for (int a = 0; a < 3; ++a) {
        fw[a] = (double)s->cam.target[a] - s->cam.eye[a];
        len += fw[a] * fw[a];
    }
    for (int a = 0; a < 3; ++a)
        fw[a] /= sqrt(len);
    const double *u = (double[3]){s->cam.up[0], s->cam.up[1], s->cam.up[2]};
    rt[0] = fw[1] * u[2] - fw[2] * u[1];
    rt[1] = fw[2] * u[0] - fw[0] * u[2];
    rt[2] = fw[0] * u[1] - fw[1] * u[0];
    len = sqrt(rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]);
    for (int a = 0; a < 3; ++a)
        rt[a] /= len;
    up[0] = rt[1] * fw[2] - rt[2] * fw[1];
    up[1] = rt[2] * fw[0] - rt[0] * fw[2];
    up[2] = rt[0] * fw[1] - rt[1] * fw[0];
    const int ortho = s->cam.projection == UMBRA_ORTHOGRAPHIC;
    const double hh = ortho ? 0.5 * s->cam.ortho_height
                            : tan(0.5 * s->cam.fovy_degrees * 3.14159265358979 / 180.0);
    const double hw = hh * w / h;
    const double sx = (px + 0.5) / w * 2 - 1, sy = 1 - (py + 0.5) / h * 2;
    len = 0;
    for (int a = 0; a < 3; ++a) {
        o[a] = s->cam.eye[a] + (ortho ? sx * hw * rt[a] + sy * hh * up[a] : 0.0);
        d[a] = ortho ? fw[a] : fw[a] + sx * hw * rt[a] + sy * hh * up[a];
        len += d[a] * d[a];
    }
    for (int a = 0; a < 3; ++a)
        d[a] /= sqrt(len);
    double t0 = -INFINITY, t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        const double half = 0.5 * s->dims[a] * (double)s->spacing[a];
        const double ta = (-half - o[a]) / d[a], tb = (half - o[a]) / d[a];
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }
    t0 = fmax(t0, 0.0);
    float vox = s->spacing[0];
    vox = s->spacing[1] < vox ? s->spacing[1] : vox;
    vox = s->spacing[2] < vox ? s->spacing[2] : vox;
    const double step = (double)s->step * vox;
    double m[4], keep = 1.0;
    uint64_t n = 0;
    /* The samples lie at t0 + k step, k = 0, 1, ... below t1. */
    for (uint32_t c = 0; c < s->channels; ++c)
        m[c] = s->mode == UMBRA_RENDER_MINIP ? 1.0 : 0.0;
    for (uint64_t k = 0;; ++k) {
        const double t = t0 + (double)k * step;
        if (!(t < t1))
            break;
        const double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        if (!kept(s, p))
            continue;
        ++n;
        for (uint32_t c = 0; c < s->channels; ++c) {
            const double v = sample(s, c, p);
            m[c] = s->mode == UMBRA_RENDER_MIP     ? fmax(m[c], v)
                   : s->mode == UMBRA_RENDER_MINIP ? fmin(m[c], v)
                                                   : m[c] + v;
        }
    }
    *taken = n;
    if (!n) {
        for (int k = 0; k < 4; ++k)
            out[k] = s->background[k];
        return;
    }
    out[0] = out[1] = out[2] = 0.0;
    for (uint32_t c = 0; c < s->channels; ++c) {
        double e[4];
        lookup(s->tf[c], s->tf_n[c], s->mode == UMBRA_RENDER_AVERAGE ? m[c] / n : m[c], e);
        for (int k = 0; k < 3; ++k)
            out[k] += e[k] * e[3];
        keep *= 1.0 - e[3];
    }
    out[3] = 1.0 - keep;
    for (int k = 0; k < 4; ++k)
        out[k] += keep * s->background[k];
}

/* ---- the device's ----------------------------------------------------------------------------- */

static umbra_volume make_volume(const scene *s)
{
    const size_t count = (size_t)s->dims[0] * s->dims[1] * s->dims[2];
    float *inter = malloc(count * s->channels * sizeof *inter);
    assert_non_null(inter);
    for (size_t i = 0; i < count; ++i)
        for (uint32_t c = 0; c < s->channels; ++c)
            inter[i * s->channels + c] = s->voxels[c * count + i];
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = inter;
    d.type = UMBRA_FLOAT32;
    memcpy(d.dims, s->dims, sizeof d.dims);
    memcpy(d.spacing, s->spacing, sizeof d.spacing);
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    d.channels = s->channels;
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    free(inter);
    return v;
}

/* Renders s on the device and compares every pixel and the sample count with the brute force. */
static void check_scene(const scene *s, uint32_t w, uint32_t h, uint32_t min_hit)
{
    umbra_volume vol = make_volume(s);
    umbra_transfer_function tfs[4] = {NULL};
    for (uint32_t c = 0; c < s->channels; ++c)
        assert_int_equal(umbra_transfer_function_create(ctx, s->tf[c], s->tf_n[c], &tfs[c]),
                         UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.step = s->step;
    o.mode = s->mode;
    memcpy(o.background, s->background, sizeof o.background);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_renderer r = test_renderer(ctx, vol, tfs[0], &s->cam, &light, &o);
    for (uint32_t c = 1; c < s->channels; ++c)
        assert_int_equal(umbra_renderer_set_channel_transfer_function(r, c, tfs[c], NULL),
                         UMBRA_SUCCESS);
    umbra_clip_desc clip;
    umbra_clip_desc_init(&clip);
    clip.plane_count = s->planes;
    for (uint32_t i = 0; i < s->planes; ++i)
        for (int k = 0; k < 4; ++k)
            clip.planes[i][k] = (float)s->plane[i][k];
    clip.crop = s->crop;
    for (int a = 0; a < 3; ++a) {
        clip.crop_min[a] = (float)s->crop_min[a];
        clip.crop_max[a] = (float)s->crop_max[a];
    }
    assert_int_equal(umbra_renderer_set_clip(r, &clip), UMBRA_SUCCESS);
    float *img = malloc((size_t)w * h * 4 * sizeof *img);
    assert_non_null(img);
    assert_int_equal(umbra_renderer_render(r, w, h, img), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    uint64_t samples = 0, lit = 0;
    double worst = 0.0;
    for (uint32_t py = 0; py < h; ++py)
        for (uint32_t px = 0; px < w; ++px) {
            double want[4];
            uint64_t n;
            brute_pixel(s, w, h, px, py, want, &n);
            samples += n;
            lit += n > 0;
            for (int k = 0; k < 4; ++k) {
                const double e = fabs(img[4 * ((size_t)py * w + px) + k] - want[k]);
                if (e > worst)
                    worst = e;
                if (e > 1e-4)
                    fail_msg("mode %d pixel (%u, %u) channel %d: %g, brute force %g", (int)s->mode,
                             px, py, k, img[4 * ((size_t)py * w + px) + k], want[k]);
            }
        }
    print_message("mode %d: %llu samples (device %llu), %llu pixels hit, worst %.3g\n",
                  (int)s->mode, (unsigned long long)samples, (unsigned long long)st.samples,
                  (unsigned long long)lit, worst);
    assert_true(lit >= min_hit); /* the volume fills a good part of the image */
    assert_true(llabs((long long)st.samples - (long long)samples) <= (long long)(samples / 2000));
    free(img);
    umbra_renderer_release(r);
    for (uint32_t c = 0; c < s->channels; ++c)
        umbra_transfer_function_release(tfs[c]);
    umbra_volume_release(vol);
}

static float *random_voxels(const uint32_t dims[3], uint32_t channels, uint32_t seed)
{
    const size_t n = (size_t)dims[0] * dims[1] * dims[2] * channels;
    float *v = malloc(n * sizeof *v);
    assert_non_null(v);
    uint32_t x = seed;
    for (size_t i = 0; i < n; ++i) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        v[i] = (float)(x >> 8) / 16777216.0f;
    }
    return v;
}

static const float tf_a[5 * 4] = {0.1f, 0.0f, 0.3f, 0.05f, 0.9f, 0.2f, 0.1f, 0.3f, 0.2f,
                                  0.8f,  0.3f, 0.6f, 0.7f, 0.7f, 0.1f, 0.8f, 1.0f, 1.0f,
                                  1.0f,  0.95f};
static const float tf_b[3 * 4] = {0.0f, 0.2f, 0.0f, 0.0f, 0.0f, 1.0f, 0.4f,
                                  0.5f, 0.3f, 0.2f, 1.0f, 0.9f};

static scene base_scene(const float *voxels, uint32_t channels)
{
    scene s;
    memset(&s, 0, sizeof s);
    s.dims[0] = 23;
    s.dims[1] = 19;
    s.dims[2] = 14;
    s.spacing[0] = 1.0f;
    s.spacing[1] = 1.25f;
    s.spacing[2] = 0.8f;
    s.channels = channels;
    s.voxels = voxels;
    s.tf[0] = tf_a;
    s.tf_n[0] = 5;
    s.tf[1] = tf_b;
    s.tf_n[1] = 3;
    const float dir[3] = {0.5f, 0.35f, 1.0f};
    s.cam = umbra_camera_orbit(dir, 30.0f, 30.0f);
    s.background[0] = 0.1f;
    s.background[1] = 0.05f;
    s.background[2] = 0.2f;
    s.background[3] = 1.0f;
    s.step = 0.7f;
    return s;
}

static void test_projections_match_brute_force(void **state)
{
    (void)state;
    const uint32_t dims[3] = {23, 19, 14};
    float *voxels = random_voxels(dims, 1, 12345u);
    scene s = base_scene(voxels, 1);
    const umbra_render_mode modes[3] = {UMBRA_RENDER_MIP, UMBRA_RENDER_MINIP,
                                        UMBRA_RENDER_AVERAGE};
    for (int m = 0; m < 3; ++m) {
        s.mode = modes[m];
        s.cam.projection = UMBRA_PERSPECTIVE;
        check_scene(&s, 48, 40, 800);
        s.cam.projection = UMBRA_ORTHOGRAPHIC;
        s.cam.ortho_height = 30.0f;
        check_scene(&s, 40, 36, 800);
    }
    free(voxels);
}

static void test_projections_respect_the_clip_region(void **state)
{
    (void)state;
    const uint32_t dims[3] = {23, 19, 14};
    float *voxels = random_voxels(dims, 1, 777u);
    scene s = base_scene(voxels, 1);
    s.planes = 2;
    const double n1 = sqrt(0.3 * 0.3 + 1.0 + 0.2 * 0.2);
    s.plane[0][0] = 0.3 / n1;
    s.plane[0][1] = 1.0 / n1;
    s.plane[0][2] = 0.2 / n1;
    s.plane[0][3] = 1.5;
    s.plane[1][0] = -1.0;
    s.plane[1][3] = 6.0;
    s.crop = 1;
    const double lo[3] = {2.1, -3.0, 1.3}, hi[3] = {20.6, 16.2, 12.7};
    memcpy(s.crop_min, lo, sizeof lo);
    memcpy(s.crop_max, hi, sizeof hi);
    const umbra_render_mode modes[3] = {UMBRA_RENDER_MIP, UMBRA_RENDER_MINIP,
                                        UMBRA_RENDER_AVERAGE};
    for (int m = 0; m < 3; ++m) {
        s.mode = modes[m];
        check_scene(&s, 48, 40, 300);
    }
    free(voxels);
}

static void test_projections_of_two_channels_add(void **state)
{
    (void)state;
    const uint32_t dims[3] = {23, 19, 14};
    float *voxels = random_voxels(dims, 2, 4242u);
    scene s = base_scene(voxels, 2);
    const umbra_render_mode modes[3] = {UMBRA_RENDER_MIP, UMBRA_RENDER_MINIP,
                                        UMBRA_RENDER_AVERAGE};
    for (int m = 0; m < 3; ++m) {
        s.mode = modes[m];
        check_scene(&s, 40, 32, 500);
    }
    free(voxels);
}

static void test_projection_refusals(void **state)
{
    (void)state;
    umbra_volume vol = test_constant_volume(ctx, 8, 8, 8, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.5f);
    umbra_light light = test_directional_light(0.0f, -1.0f, 0.0f);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.mode = UMBRA_RENDER_MIP;
    umbra_renderer r = test_renderer(ctx, vol, tf, NULL, &light, &o);
    float img[4 * 4 * 4];
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_THRESHOLD;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render(r, 4, 4, img), UMBRA_ERROR_INVALID_ARGUMENT,
                       "render mode 'mip'", "'threshold'");
    sd.technique = UMBRA_SHADOW_NONE;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 4, 4, img), UMBRA_SUCCESS);
    /* An unknown mode is refused by name and changes nothing. */
    o.mode = (umbra_render_mode)7;
    test_assert_failed(ctx, umbra_renderer_set_options(r, &o), UMBRA_ERROR_INVALID_ARGUMENT,
                       "mode 7 is unknown", NULL);
    /* umbra 0.5's layout (no mode) keeps the mode set before: MIP of a constant 0.5 volume under
     * a constant tf is (1 * 0.5, 0.5) over the black background. */
    umbra_render_desc old;
    umbra_render_desc_init(&old);
    old.struct_size = offsetof(umbra_render_desc, mode);
    old.mode = UMBRA_RENDER_COMPOSITE;
    assert_int_equal(umbra_renderer_set_options(r, &old), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 4, 4, img), UMBRA_SUCCESS);
    assert_float_equal(img[4 * 5 + 3], 0.5f, 1e-6f);
    assert_float_equal(img[4 * 5 + 0], 0.5f, 1e-6f);
    umbra_renderer_release(r);
    umbra_volume_release(vol);

    /* A label map has no order to project. */
    const uint8_t labels[8] = {0, 1, 2, 3, 0, 1, 2, 3};
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = labels;
    d.dims[0] = d.dims[1] = d.dims[2] = 2;
    d.labels = 1;
    assert_int_equal(umbra_volume_create(ctx, &d, &vol), UMBRA_SUCCESS);
    o.mode = UMBRA_RENDER_AVERAGE;
    r = test_renderer(ctx, vol, tf, NULL, &light, &o);
    test_assert_failed(ctx, umbra_renderer_render(r, 4, 4, img), UMBRA_ERROR_INVALID_ARGUMENT,
                       "render mode 'average'", "label map");
    umbra_renderer_release(r);
    umbra_volume_release(vol);
    umbra_transfer_function_release(tf);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_projections_match_brute_force),
        cmocka_unit_test(test_projections_respect_the_clip_region),
        cmocka_unit_test(test_projections_of_two_channels_add),
        cmocka_unit_test(test_projection_refusals),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
