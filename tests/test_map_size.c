// SPDX-License-Identifier: Apache-2.0
/* tests/test_map_size.c: map_size UMBRA_MAP_SIZE_AUTO, the light-space map resolution chosen from
 * the volume's footprint as the light sees it (include/umbra/renderer.h has the rule):
 *  - a directional light gets k times the wider side of the box's projection in voxels (the
 *    smallest spacing), k = 1, 3, 2 texels per voxel for threshold, CSSM and deep, rounded up to
 *    a multiple of 32: axis-aligned and oblique directions, anisotropic spacing;
 *  - a point light outside the box gets its frustum measured at the box centre's distance (more
 *    than the directional size when the light is close); one inside gets the octahedral rule;
 *  - the bounds: a tiny volume gets UMBRA_MAP_SIZE_AUTO_MIN, a long one UMBRA_MAP_SIZE_AUTO_MAX;
 *  - map_texels_per_voxel replaces k for every technique (a draft at 1 builds CSSM and deep maps
 *    at the threshold map's size), a fixed size ignores it, a change of it alone rebuilds the
 *    map, and a refused value leaves the renderer's shadow as it was (the refusals themselves,
 *    of every parameter, are tests/test_conformance.c's);
 *  - an auto map renders the same pixels as the same size given explicitly (threshold, CSSM, deep
 *    blocked and fixed-budget), so the sizes auto picks suit the kernels' tiles and taps;
 *  - explicit sizes (not multiples of 32 too) are kept, and umbra_render_stats.map_size reports
 *    the size in use: 0 for techniques without a map, kept while a cached map is reused.
 * The expected sizes are computed here from the box and the light, independently of
 * host/lightspace.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "test_util.h"

/* Texels per voxel of each technique (the header's k). */
static double k_of(umbra_shadow_technique t)
{
    return t == UMBRA_SHADOW_CSSM ? 3.0 : t == UMBRA_SHADOW_DEEP ? 2.0 : 1.0;
}

/* The rule's rounding and bounds, applied to a texel count n. */
static uint32_t round_bound(double n)
{
    uint32_t q = UMBRA_MAP_SIZE_AUTO_ROUND;
    uint32_t m = ((uint32_t)ceil(n) + q - 1) / q * q;
    return m < UMBRA_MAP_SIZE_AUTO_MIN ? UMBRA_MAP_SIZE_AUTO_MIN
           : m > UMBRA_MAP_SIZE_AUTO_MAX ? UMBRA_MAP_SIZE_AUTO_MAX
                                         : m;
}

static umbra_volume make_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                const float spacing[3])
{
    size_t n = (size_t)nx * ny * nz;
    float *data = malloc(n * sizeof *data);
    assert_non_null(data);
    for (size_t i = 0; i < n; ++i)
        data[i] = 0.5f;
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = nx;
    d.dims[1] = ny;
    d.dims[2] = nz;
    for (int a = 0; a < 3; ++a)
        d.spacing[a] = spacing ? spacing[a] : 1.0f;
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    free(data);
    return v;
}

/* The map size a renderer with the given technique and map_size builds for volume v under light
 * (one shadow query builds it), read from the stats; *mode gets the projection used. */
static uint32_t built_size_k(umbra_context ctx, umbra_volume v, umbra_light light,
                             umbra_shadow_technique t, uint32_t map_size, float k,
                             uint32_t *mode)
{
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    assert_int_equal(s.map.size, UMBRA_MAP_SIZE_AUTO); /* the default */
    s.technique = t;
    s.map.size = map_size;
    s.map.texels_per_voxel = k;
    s.map.step = 8.0f; /* the size does not depend on the step; a long one keeps 2048^2 cheap */
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    const float p[3] = {0.0f, 0.0f, 0.0f};
    float f[3];
    assert_int_equal(umbra_renderer_query_shadow(r, p, 1, f), UMBRA_SUCCESS);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    if (mode)
        *mode = r->shadow_params.ls_mode;
    assert_int_equal(st.map_size, r->shadow_params.map_size);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    return st.map_size;
}

static uint32_t built_size(umbra_context ctx, umbra_volume v, umbra_light light,
                           umbra_shadow_technique t, uint32_t map_size, uint32_t *mode)
{
    return built_size_k(ctx, v, light, t, map_size, 0.0f, mode);
}

static void test_auto_directional_follows_the_projected_box(void **state)
{
    umbra_context ctx = *state;
    uint32_t mode;
    umbra_volume v = make_volume(ctx, 100, 40, 70, NULL);
    /* Down y the map spans x (100 voxels) and z (70): the wider side. */
    assert_int_equal(built_size(ctx, v, test_directional_light(0, -1, 0), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, &mode),
                     round_bound(100.0));
    assert_int_equal(mode, UMBRA_LS_ORTHO);
    assert_int_equal(round_bound(100.0), 128);
    /* Along x it spans y (40) and z (70). */
    assert_int_equal(built_size(ctx, v, test_directional_light(1, 0, 0), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(70.0));
    umbra_volume_release(v);

    /* A 60^3 cube seen along (1, 1, 0): z (60) and the face diagonal (60 sqrt 2). */
    v = make_volume(ctx, 60, 60, 60, NULL);
    assert_int_equal(built_size(ctx, v, test_directional_light(1, 1, 0), UMBRA_SHADOW_CSSM,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(k_of(UMBRA_SHADOW_CSSM) * 60.0 * sqrt(2.0)));
    /* The same light gives each technique its own texels per voxel: 64, 192, 128. */
    assert_int_equal(built_size(ctx, v, test_directional_light(0, 0, -1), UMBRA_SHADOW_CSSM,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(3.0 * 60.0));
    assert_int_equal(built_size(ctx, v, test_directional_light(0, 0, -1), UMBRA_SHADOW_DEEP,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(2.0 * 60.0));
    assert_int_equal(built_size(ctx, v, test_directional_light(0, 0, -1), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(60.0));
    umbra_volume_release(v);

    /* Anisotropic spacing: a voxel is the smallest spacing (0.5), so 64 x 64 voxels of 0.5 x 1
     * world units look 128 voxels wide along y. */
    const float spacing[3] = {0.5f, 1.0f, 1.0f};
    v = make_volume(ctx, 64, 64, 64, spacing);
    assert_int_equal(built_size(ctx, v, test_directional_light(0, 0, 1), UMBRA_SHADOW_DEEP,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(k_of(UMBRA_SHADOW_DEEP) * 128.0));
    umbra_volume_release(v);
}

static void test_auto_point_light_frustum_and_inside(void **state)
{
    umbra_context ctx = *state;
    uint32_t mode;
    umbra_volume v = make_volume(ctx, 60, 60, 60, NULL);
    /* Light 150 above the centre: the frustum's tangent window is set by the near face's corners
     * (30 / 120 each side), measured at the centre's distance 150: 75 texels, more than the
     * directional 60 because the light is close. */
    uint32_t near = built_size(ctx, v, test_point_light(0, 150, 0), UMBRA_SHADOW_THRESHOLD,
                               UMBRA_MAP_SIZE_AUTO, &mode);
    assert_int_equal(mode, UMBRA_LS_PERSPECTIVE);
    assert_int_equal(near, round_bound(60.0 / 120.0 * 150.0));
    /* Far away it tends to the directional size. */
    assert_int_equal(built_size(ctx, v, test_point_light(0, 3000, 0), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(60.0 / 2970.0 * 3000.0));
    assert_int_equal(round_bound(60.0 / 2970.0 * 3000.0), round_bound(60.0));
    /* Inside the box: the octahedral map, sqrt(4 pi) R texels with R the farthest corner. */
    assert_int_equal(built_size(ctx, v, test_point_light(10, 0, 0), UMBRA_SHADOW_CSSM,
                                UMBRA_MAP_SIZE_AUTO, &mode),
                     round_bound(k_of(UMBRA_SHADOW_CSSM) * sqrt(4.0 * 3.14159265358979) *
                                 sqrt(40.0 * 40.0 + 2 * 30.0 * 30.0)));
    assert_int_equal(mode, UMBRA_LS_OCTAHEDRAL);
    assert_int_equal(built_size(ctx, v, test_point_light(0, 0, 0), UMBRA_SHADOW_DEEP,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     round_bound(k_of(UMBRA_SHADOW_DEEP) * sqrt(4.0 * 3.14159265358979) *
                                 sqrt(3.0) * 30.0));
    umbra_volume_release(v);
}

static void test_auto_is_bounded(void **state)
{
    umbra_context ctx = *state;
    umbra_volume v = make_volume(ctx, 16, 16, 16, NULL);
    assert_int_equal(built_size(ctx, v, test_directional_light(0, -1, 0), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     UMBRA_MAP_SIZE_AUTO_MIN);
    umbra_volume_release(v);
    /* 4 x 8 x 8 voxels, 600 world units long in x: 2400 voxels of the smallest spacing. */
    const float spacing[3] = {600.0f, 1.0f, 1.0f};
    v = make_volume(ctx, 4, 8, 8, spacing);
    assert_int_equal(built_size(ctx, v, test_directional_light(0, -1, 0), UMBRA_SHADOW_THRESHOLD,
                                UMBRA_MAP_SIZE_AUTO, NULL),
                     UMBRA_MAP_SIZE_AUTO_MAX);
    umbra_volume_release(v);
}

/* A sphere of density in a 48^3 box, lit from above-left, rendered into img (w x h x 4). */
static void render_sphere(umbra_renderer r, umbra_shadow_desc s, uint32_t w, uint32_t h,
                          float *img, umbra_render_stats *st)
{
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, w, h, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, st), UMBRA_SUCCESS);
}

static void test_auto_renders_as_the_same_explicit_size(void **state)
{
    umbra_context ctx = *state;
    enum { N = 48, W = 48, H = 40 };
    float *data = malloc(N * N * N * sizeof *data);
    assert_non_null(data);
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = 0; x < N; ++x) {
                float dx = x - 20.0f, dy = y - 26.0f, dz = z - 24.0f;
                data[(z * N + y) * N + x] = sqrtf(dx * dx + dy * dy + dz * dz) < 14.0f ? 1.0f : 0.0f;
            }
    umbra_volume v = test_volume(ctx, N, N, N, data);
    free(data);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.0f);
    float rgba[8] = {1, 1, 1, 0, 0.9f, 0.6f, 0.3f, 0.3f};
    umbra_transfer_function_release(tf);
    assert_int_equal(umbra_transfer_function_create(ctx, rgba, 2, &tf), UMBRA_SUCCESS);
    umbra_light light = test_point_light(-40.0f, 60.0f, 20.0f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    float *a = malloc(W * H * 4 * sizeof *a), *b = malloc(W * H * 4 * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    const umbra_shadow_technique techs[4] = {UMBRA_SHADOW_THRESHOLD, UMBRA_SHADOW_CSSM,
                                             UMBRA_SHADOW_DEEP, UMBRA_SHADOW_DEEP};
    for (int t = 0; t < 4; ++t) {
        umbra_shadow_desc s;
        umbra_shadow_desc_init(&s);
        s.technique = techs[t];
        s.deep.max_nodes = t == 3 ? 4 : 0; /* deep: blocked tiles, then the fixed budget */
        umbra_render_stats st;
        render_sphere(r, s, W, H, a, &st);
        uint32_t chosen = st.map_size;
        assert_true(chosen >= UMBRA_MAP_SIZE_AUTO_MIN && chosen <= UMBRA_MAP_SIZE_AUTO_MAX);
        assert_int_equal(chosen % UMBRA_MAP_SIZE_AUTO_ROUND, 0);
        assert_int_equal(st.shadow_rebuilt, 1);
        s.map.size = chosen;
        render_sphere(r, s, W, H, b, &st);
        assert_int_equal(st.map_size, chosen);
        assert_int_equal(st.shadow_rebuilt, 1); /* another description: rebuilt, not reused */
        assert_memory_equal(a, b, W * H * 4 * sizeof *a);
    }
    free(a);
    free(b);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_explicit_sizes_kept_and_stats_report_them(void **state)
{
    umbra_context ctx = *state;
    umbra_volume v = make_volume(ctx, 40, 40, 40, NULL);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_light light = test_directional_light(0.3f, -1.0f, 0.2f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    float img[16 * 12 * 4];
    umbra_render_stats st;
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_THRESHOLD;
    s.map.size = 100; /* not a multiple of the rounding: kept as given */
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.map_size, 100);
    assert_int_equal(st.shadow_memory_bytes, 100 * 100 * 4);
    s.technique = UMBRA_SHADOW_DEEP;
    s.map.size = 40; /* not a whole number of deep tiles */
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.map_size, 40);
    /* A camera move reuses the map and still reports its size. */
    umbra_camera cam = umbra_camera_orbit((const float[3]){1, 0.5f, 1}, 70.0f, 30.0f);
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 16, 12, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 0);
    assert_int_equal(st.map_size, 40);
    /* Techniques without a map report 0. */
    s.technique = UMBRA_SHADOW_REFERENCE;
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.map_size, 0);
    s.technique = UMBRA_SHADOW_NONE;
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.map_size, 0);
    /* Sizes outside [16, 8192] other than 0 are refused, naming the value and the rule. */
    s.technique = UMBRA_SHADOW_CSSM;
    s.map.size = 15;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "map_size 15 must be 0 (auto) or lie in [16, 8192]"));
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

static void test_texels_per_voxel_replaces_the_techniques_k(void **state)
{
    umbra_context ctx = *state;
    umbra_volume v = make_volume(ctx, 60, 60, 60, NULL);
    const umbra_light down = test_directional_light(0, 0, -1);
    /* A draft (1 texel per voxel): CSSM and deep at the threshold map's size, not 192 and 128. */
    const umbra_shadow_technique ts[3] = {UMBRA_SHADOW_THRESHOLD, UMBRA_SHADOW_CSSM,
                                          UMBRA_SHADOW_DEEP};
    for (int i = 0; i < 3; ++i) {
        assert_int_equal(built_size_k(ctx, v, down, ts[i], UMBRA_MAP_SIZE_AUTO, 1.0f, NULL),
                         round_bound(60.0));
        assert_int_equal(built_size_k(ctx, v, down, ts[i], UMBRA_MAP_SIZE_AUTO, 4.5f, NULL),
                         round_bound(4.5 * 60.0));
    }
    assert_int_equal(round_bound(4.5 * 60.0), 288);
    /* The bounds still hold, and a fixed size ignores it. */
    assert_int_equal(built_size_k(ctx, v, down, UMBRA_SHADOW_DEEP, UMBRA_MAP_SIZE_AUTO, 0.25f, NULL),
                     UMBRA_MAP_SIZE_AUTO_MIN);
    assert_int_equal(built_size_k(ctx, v, down, UMBRA_SHADOW_CSSM, 100, 1.0f, NULL), 100);
    umbra_volume_release(v);

    /* A change of it alone rebuilds the map at the new size; the same value again reuses it. */
    v = make_volume(ctx, 40, 40, 40, NULL);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &down, NULL);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    assert_true(s.map.texels_per_voxel == 0.0f); /* the default: the technique's own */
    s.technique = UMBRA_SHADOW_CSSM;
    float img[16 * 12 * 4];
    umbra_render_stats st;
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.map_size, round_bound(3.0 * 40.0));
    s.map.texels_per_voxel = 1.0f;
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_int_equal(st.map_size, round_bound(40.0));
    render_sphere(r, s, 16, 12, img, &st);
    assert_int_equal(st.shadow_rebuilt, 0);

    /* A refused value (tests/test_conformance.c checks every one) leaves the shadow as it was. */
    umbra_shadow_desc b = s;
    b.map.texels_per_voxel = 8.5f;
    assert_int_equal(umbra_renderer_set_shadow(r, &b), UMBRA_ERROR_INVALID_ARGUMENT);
    umbra_context_take_error(ctx, NULL);
    assert_int_equal(umbra_renderer_render(r, 16, 12, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.map_size, round_bound(40.0));
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

/* map_step 0, the default, is the technique's own light step: the same map and image as that
 * step given explicitly (threshold and CSSM 1 voxel, deep 0.5), not those of another step. */
static void test_map_step_default_is_the_techniques_own(void **state)
{
    umbra_context ctx = *state;
    enum { W = 32, H = 24 };
    umbra_volume v = make_volume(ctx, 40, 40, 40, NULL);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, 0.05f);
    umbra_light light = test_point_light(-30.0f, 50.0f, 20.0f);
    umbra_renderer r = test_renderer(ctx, v, tf, NULL, &light, NULL);
    float *a = malloc(W * H * 4 * sizeof *a), *b = malloc(W * H * 4 * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    const struct {
        umbra_shadow_technique t;
        float own, other; /* the technique's step, and one whose image differs */
    } cases[3] = {{UMBRA_SHADOW_THRESHOLD, 1.0f, 0.25f},
                  {UMBRA_SHADOW_CSSM, 1.0f, 0.5f},
                  {UMBRA_SHADOW_DEEP, 0.5f, 1.0f}};
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    assert_true(s.map.step == 0.0f);
    umbra_render_stats st;
    for (int i = 0; i < 3; ++i) {
        s.technique = cases[i].t;
        s.map.step = 0.0f;
        render_sphere(r, s, W, H, a, &st);
        s.map.step = cases[i].own;
        render_sphere(r, s, W, H, b, &st);
        assert_int_equal(st.shadow_rebuilt, 1);
        assert_memory_equal(a, b, W * H * 4 * sizeof *a);
        s.map.step = cases[i].other;
        render_sphere(r, s, W, H, b, &st);
        assert_true(memcmp(a, b, W * H * 4 * sizeof *a) != 0);
    }
    free(a);
    free(b);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(v);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_auto_directional_follows_the_projected_box),
        cmocka_unit_test(test_auto_point_light_frustum_and_inside),
        cmocka_unit_test(test_auto_is_bounded),
        cmocka_unit_test(test_auto_renders_as_the_same_explicit_size),
        cmocka_unit_test(test_explicit_sizes_kept_and_stats_report_them),
        cmocka_unit_test(test_texels_per_voxel_replaces_the_techniques_k),
        cmocka_unit_test(test_map_step_default_is_the_techniques_own),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
