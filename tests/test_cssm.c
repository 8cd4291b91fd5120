// SPDX-License-Identifier: Apache-2.0
/* tests/test_cssm.c: colored stochastic shadow maps (kernels/techniques/cssm.cl) pinned down.
 *
 * Statistics. A texel's photon is stopped in segment i with probability rho_i given that it got
 * there, so a sample at depth s is lit by that texel with probability P = prod (1 - rho_i) over
 * the segments whose midpoint (the stored depth) lies in front of s: a Bernoulli(P) draw. Texels
 * draw independent random numbers. Query points placed one per texel centre over an N-texel
 * region, m taps each, use every texel of the region's interior exactly m times: the mean factor
 * is a weighted mean of texel draws with weights <= 1/N summing to 1, so its standard deviation
 * is at most sqrt(P (1 - P) / N) whatever m is. The tests allow 5 of those (a false failure once
 * in 1.7 million runs). On a homogeneous slab (alpha a per voxel, step h, a_h = 1 - (1 - a)^h),
 * at depth D = K h below the top face exactly K midpoints lie in front: P = (1 - a_h)^K =
 * (1 - a)^D = exp(-sigma D) exactly. At other depths the count is rounded to the nearest
 * midpoint: P lies within a factor exp(+-sigma h / 2) of exp(-sigma D), and that discretisation
 * error is added to the bound there.
 *
 * The photons of a block of texels share its centre's light ray but draw their own numbers, so
 * the same holds with blocks (checked for the default block of 3 x 3 and for a ray per texel).
 *
 * Also: a coloured light stores three depths from one shared random number per photon, so where
 * t_R >= t_G >= t_B every lookup has l_R >= l_G >= l_B; a block's texels all take its centre
 * ray's depths, whole blocks at the map's edge too, and the default block follows the map's
 * texels per voxel; a separate light transfer function drives
 * generation; the same seed gives the same image bit for bit and another seed a different one;
 * empty-space skipping changes no bit; caching, memory (3 or 1 values per texel) and the error
 * against the exact reference on the spheres scene are bounded. The lights that stress the
 * projection, rebuilds and bad parameters are the conformance suite's (tests/test_conformance.c).
 * Usage: test_cssm [filter] (a cmocka test-name glob). */
#include "shadow_map_test.h"
#include "techniques/cssm_shared.h"
#include "techniques/maps.h"

/* The ray block the last CSSM build used. */
static uint32_t built_ray_block(umbra_renderer r)
{
    const UmbraCssm *P = umbra__map_constants(r);
    assert_non_null(P);
    return P->ray_block;
}

static umbra_context ctx;

static int setup(void **state)
{
    (void)state;
    ctx = test_context();
    return ctx ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    umbra_context_release(ctx);
    return 0;
}

enum { MAP = 256, LO = 24, HI = 232 }; /* texels LO..HI-1 lie >= 20 texels inside the box */
#define REGION ((size_t)(HI - LO) * (HI - LO))

/* Mean factor per channel over one query point per texel centre of the region, on the plane
 * D voxels below the slab's top face (light straight down). */
static void region_mean(umbra_renderer r, float depth, double mean[3])
{
    float probe[3] = {0, 0, 0}, f[3];
    assert_int_equal(umbra_renderer_query_shadow(r, probe, 1, f), UMBRA_SUCCESS); /* builds */
    float *p = malloc(REGION * 3 * sizeof *p), *v = malloc(REGION * 3 * sizeof *v);
    assert_non_null(p);
    assert_non_null(v);
    size_t k = 0;
    for (uint32_t j = LO; j < HI; ++j)
        for (uint32_t i = LO; i < HI; ++i, ++k)
            mt_texel_point(r, i, j, -0.5f * MT_NY + depth, p + 3 * k);
    assert_int_equal(umbra_renderer_query_shadow(r, p, REGION, v), UMBRA_SUCCESS);
    mean[0] = mean[1] = mean[2] = 0.0;
    for (size_t i = 0; i < REGION; ++i)
        for (int c = 0; c < 3; ++c)
            mean[c] += v[3 * i + c] / (double)REGION;
    free(p);
    free(v);
}

static double stat_bound(double p) { return 5.0 * sqrt(p * (1.0 - p) / (double)REGION) + 1e-4; }

static void test_cssm_slab_mean_matches_transmittance(void **state)
{
    (void)state;
    const float a = 0.05f, h = 0.5f;
    const double sigma = -log(1.0 - a);
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, 0.7f, 0.7f, 0.7f, a);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, l, UMBRA_TRANSMISSION_GREY);
    /* Taps, and the block of texels whose photons share a ray: 0 is the default, 3 on this map
     * (5.3 texels per voxel), 1 the paper's ray per texel. */
    const uint32_t taps[] = {1, 7, 13, 21, 1, 13}, block[] = {0, 0, 0, 0, 1, 1};
    /* On segment boundaries (exact), inside a segment (discretised), below the slab (exact). */
    const float depths[] = {10.0f, 20.0f, 10.3f, 40.0f};
    for (int t = 0; t < 6; ++t) {
        umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, taps[t]);
        s.map.step = h;
        s.cssm.seed = 11;
        s.cssm.ray_block = block[t];
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        for (int d = 0; d < 4; ++d) {
            double D = fmin(depths[d], (double)MT_NY);
            double expect = exp(-sigma * D), bound = stat_bound(expect);
            double k = depths[d] / h;
            if (k != floor(k))
                bound += expect * (exp(0.5 * sigma * h) - 1.0);
            double m[3];
            region_mean(r, depths[d], m);
            printf("%2u taps, ray block %u, depth %4.1f: mean %.5f, exp(-sigma d) %.5f, "
                   "bound %.5f\n",
                   taps[t], built_ray_block(r), depths[d], m[0], expect, bound);
            assert_int_equal(built_ray_block(r), block[t] ? block[t] : 3);
            assert_true(m[0] == m[1] && m[1] == m[2]);
            if (!(fabs(m[0] - expect) <= bound))
                fail_msg("%u taps, depth %g: mean factor %.5f, analytic %.5f, bound %.5f",
                         taps[t], depths[d], m[0], expect, bound);
        }
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_cssm_colored_channels_share_random_numbers(void **state)
{
    (void)state;
    const float a = 0.06f, h = 0.5f, t[3] = {0.9f, 0.5f, 0.1f};
    const int K = 24; /* depth K h = 12 voxels */
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function tf = mt_tf(ctx, t[0], t[1], t[2], a);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, tf, l, UMBRA_TRANSMISSION_COLORED);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, 13);
    s.map.step = h;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    double m[3];
    region_mean(r, (float)K * h, m);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.light_channels, 3);
    const double a_h = 1.0 - pow(1.0 - a, h);
    for (int c = 0; c < 3; ++c) {
        double expect = pow(1.0 - a_h * (1.0 - t[c]), K);
        printf("channel %d: mean %.5f, analytic %.5f, bound %.5f\n", c, m[c], expect,
               stat_bound(expect));
        if (!(fabs(m[c] - expect) <= stat_bound(expect)))
            fail_msg("channel %d: mean %.5f, analytic %.5f", c, m[c], expect);
    }
    /* One threshold per photon for all channels and od_R <= od_G <= od_B: a photon stopped in
     * red is stopped in green and blue no later, at every texel, so every lookup is ordered. */
    float p[3 * 64], f[3 * 64];
    for (int i = 0; i < 64; ++i) {
        p[3 * i] = -15.0f + 0.47f * (float)i;
        p[3 * i + 1] = 12.0f - 0.3f * (float)i;
        p[3 * i + 2] = 3.0f - 0.2f * (float)i;
    }
    assert_int_equal(umbra_renderer_query_shadow(r, p, 64, f), UMBRA_SUCCESS);
    for (int i = 0; i < 64; ++i)
        if (!(f[3 * i] >= f[3 * i + 1] && f[3 * i + 1] >= f[3 * i + 2]))
            fail_msg("point %d: factors %g %g %g are not ordered like the transmission", i,
                     f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

static void test_cssm_light_transfer_function_drives_generation(void **state)
{
    (void)state;
    const float a_view = 0.02f, a_light = 0.08f, D = 8.0f;
    umbra_volume vol = test_constant_volume(ctx, MT_NX, MT_NY, MT_NZ, 1.0f);
    umbra_transfer_function view = mt_tf(ctx, 0.7f, 0.7f, 0.7f, a_view);
    umbra_transfer_function light = mt_tf(ctx, 0.3f, 0.3f, 0.3f, a_light);
    umbra_light l = test_directional_light(0, -1, 0);
    umbra_renderer r = test_renderer_transmission(ctx, vol, view, l, UMBRA_TRANSMISSION_GREY);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, MAP, 7);
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    const umbra_transfer_function tfs[] = {view, light, NULL};
    const float alphas[] = {a_view, a_light, a_view};
    for (int i = 0; i < 3; ++i) {
        if (i > 0)
            assert_int_equal(umbra_renderer_set_light_transfer_function(r, tfs[i]),
                             UMBRA_SUCCESS);
        double m[3], expect = pow(1.0 - alphas[i], D);
        region_mean(r, D, m);
        if (!(fabs(m[0] - expect) <= stat_bound(expect)))
            fail_msg("light tf %d: mean %.5f, analytic %.5f", i, m[0], expect);
        umbra_render_stats st;
        assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
        assert_int_equal(st.light_channels, 1);
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(view);
    umbra_transfer_function_release(light);
    umbra_volume_release(vol);
}

/* Spheres 48^3 at 64x64, 13 taps, 128^2 map. */
static void render_spheres(umbra_scene *scene, uint32_t seed, int skip, float *img)
{
    umbra_renderer r = test_renderer_transmission(
        ctx, scene->volume, scene->tf, scene->light, UMBRA_TRANSMISSION_COLORED);
    umbra_render_desc o = scene->options;
    o.empty_space_skipping = skip;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_camera(r, &scene->camera), UMBRA_SUCCESS);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, 128, 13);
    s.cssm.seed = seed;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 64, 64, img), UMBRA_SUCCESS);
    umbra_renderer_release(r);
}

static void test_cssm_same_seed_same_image_bitwise(void **state)
{
    (void)state;
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &scene), UMBRA_SUCCESS);
    static float a[64 * 64 * 4], b[64 * 64 * 4], c[64 * 64 * 4], d[64 * 64 * 4];
    render_spheres(&scene, 7, 1, a);
    render_spheres(&scene, 7, 1, b);
    render_spheres(&scene, 8, 1, c);
    render_spheres(&scene, 7, 0, d);
    assert_memory_equal(a, b, sizeof a);
    assert_memory_equal(a, d, sizeof a); /* skipped segments draw no number that matters */
    size_t differ = 0;
    for (size_t i = 0; i < 64 * 64 * 4; ++i)
        differ += a[i] != c[i];
    printf("seed 7 vs 8: %zu of %d values differ\n", differ, 64 * 64 * 4);
    assert_true(differ > 100);
    umbra_scene_release(&scene);
}

static void test_cssm_skipping_changes_nothing(void **state)
{
    (void)state;
    mt_check_skipping_changes_nothing(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 13));
}

static void test_cssm_camera_move_reuses_map(void **state)
{
    (void)state;
    mt_check_reuse_and_memory(ctx, mt_shadow(UMBRA_SHADOW_CSSM, 128, 13), 3, 1);
}

static void test_cssm_taps_read_their_texels(void **state)
{
    (void)state;
    mt_check_taps_read_their_texels(ctx, UMBRA_SHADOW_CSSM);
}

/* Measured on PoCL (spheres 48^3, its light, 96x96, map 256^2, seed 1), with the default block
 * of 3 x 3 texels per light ray: 1 tap 0.0193, 7 taps 0.0079, 13 taps 0.0059, 21 taps 0.0053;
 * with a ray per texel (13 taps) 0.0058. No shadows at all is 0.0252 away, the threshold map
 * 0.030 (13 taps). The error left is noise (1 tap) and the taps' blur. Bounds: 1.2x-1.3x. */
static void test_cssm_error_vs_reference_bounded(void **state)
{
    (void)state;
    const uint32_t taps[] = {1, 7, 13, 21, 13}, block[] = {0, 0, 0, 0, 1};
    const double bound[] = {0.024, 0.0095, 0.0075, 0.0068, 0.0078};
    for (int i = 0; i < 5; ++i) {
        umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, 256, taps[i]);
        s.cssm.ray_block = block[i];
        double e = mt_error_vs_reference(ctx, s);
        printf("cssm, %u taps, map 256^2, ray block %s: mean abs error vs reference %.4f "
               "(bound %.4f)\n",
               taps[i], block[i] ? "1" : "default", e, bound[i]);
        assert_true(e <= bound[i]);
    }
}

/* The volume for the block test: the box of MT_NX x MT_NY x MT_NZ voxels holds 1 in the columns
 * x in [BX0, BX1), z in [BZ0, BZ1) (voxel indices, every y) and 0 elsewhere. */
enum { BX0 = 12, BX1 = 30, BZ0 = 20, BZ1 = 36 };

/* Where the ray through world point p (light straight down) meets the columns: 1 inside them by
 * more than 3 voxels, 0 outside by more than 3, -1 between (near a face, whatever the
 * convention of voxel centres). */
static int block_column_hit(const float p[3])
{
    const float x = p[0] + 0.5f * MT_NX, z = p[2] + 0.5f * MT_NZ, m = 3.0f;
    if (x > BX0 + m && x < BX1 - m && z > BZ0 + m && z < BZ1 - m)
        return 1;
    if (x < BX0 - m || x > BX1 + m || z < BZ0 - m || z > BZ1 + m)
        return 0;
    return -1;
}

/* Factors (one tap) at the centre of every texel of r's n^2 map, below the box. */
static float *block_factors(umbra_renderer r, uint32_t n)
{
    const float probe[3] = {0, 0, 0}; /* builds the map, so that its window is known */
    float pf[3];
    assert_int_equal(umbra_renderer_query_shadow(r, probe, 1, pf), UMBRA_SUCCESS);
    float *p = malloc((size_t)n * n * 3 * sizeof *p), *f = malloc((size_t)n * n * 3 * sizeof *f);
    assert_non_null(p);
    assert_non_null(f);
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i)
            mt_texel_point(r, i, j, 0.5f * MT_NY + 4.0f, p + 3 * ((size_t)j * n + i));
    assert_int_equal(umbra_renderer_query_shadow(r, p, (size_t)n * n, f), UMBRA_SUCCESS);
    free(p);
    return f;
}

/* Under a light straight down, opaque columns (a sharp transfer function, so that their faces
 * cut texels) shadow the points below them. With the default block (3 x 3 on a 256^2 map of 48
 * voxels, 5.3 texels per voxel) every texel takes its block's value; 256 = 3 * 85 + 1, so the
 * last block of each row and column is one texel wide (its ray misses the box, as the map's rim
 * of half a texel does). The map was built first from an opaque transfer function (every texel
 * whose ray crosses the box shadowed) and is re-used at the same size, so a texel the build left
 * unwritten would stay shadowed where the columns do not reach. Far from the columns'
 * faces every texel has the value its own position gives; near them, a ray per texel
 * (ray_block 1) splits some blocks, which shows that the scene tells the two apart. The default
 * block follows the map's texels per voxel: 2 at 128^2 (2.7), 1 at 80^2 (1.7). */
static void test_cssm_photons_of_a_block_share_its_ray(void **state)
{
    (void)state;
    enum { N = 256, B = 3 };
    float *data = malloc((size_t)MT_NX * MT_NY * MT_NZ * sizeof *data);
    assert_non_null(data);
    for (uint32_t z = 0; z < MT_NZ; ++z)
        for (uint32_t y = 0; y < MT_NY; ++y)
            for (uint32_t x = 0; x < MT_NX; ++x)
                data[((size_t)z * MT_NY + y) * MT_NX + x] =
                    x >= BX0 && x < BX1 && z >= BZ0 && z < BZ1 ? 1.0f : 0.0f;
    umbra_volume vol = test_volume(ctx, MT_NX, MT_NY, MT_NZ, data);
    free(data);
    float sharp_rgba[64 * 4] = {0}, opaque_rgba[8] = {0, 0, 0, 1, 0, 0, 0, 1};
    for (int i = 32; i < 64; ++i)
        sharp_rgba[4 * i + 3] = 1.0f;
    umbra_transfer_function sharp = NULL, opaque = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, sharp_rgba, 64, &sharp), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_create(ctx, opaque_rgba, 2, &opaque), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(ctx, vol, opaque, test_directional_light(0, -1, 0),
                                                  UMBRA_TRANSMISSION_GREY);
    umbra_shadow_desc s = mt_shadow(UMBRA_SHADOW_CSSM, N, 1);
    int split_blocks[2] = {0, 0};
    for (int v = 0; v < 2; ++v) {
        s.cssm.ray_block = v == 0 ? 0 : 1;
        assert_int_equal(umbra_renderer_set_light_transfer_function(r, opaque), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        float *f = block_factors(r, N);
        for (uint32_t j = 0; j < N; ++j)
            for (uint32_t i = 0; i < N; ++i) {
                float p[3];
                mt_texel_point(r, i, j, 0.0f, p);
                if (fabsf(p[0]) < 0.5f * MT_NX - 1.0f && fabsf(p[2]) < 0.5f * MT_NZ - 1.0f)
                    assert_true(f[3 * ((size_t)j * N + i)] == 0.0f);
            }
        free(f);
        assert_int_equal(umbra_renderer_set_light_transfer_function(r, sharp), UMBRA_SUCCESS);
        f = block_factors(r, N);
        assert_int_equal(built_ray_block(r), v == 0 ? B : 1);
        size_t checked = 0;
        for (uint32_t j = 0; j < N; ++j)
            for (uint32_t i = 0; i < N; ++i) {
                const float got = f[3 * ((size_t)j * N + i)];
                float p[3];
                mt_texel_point(r, i, j, 0.0f, p);
                const int hit = block_column_hit(p);
                if (hit >= 0) {
                    if (got != (hit ? 0.0f : 1.0f))
                        fail_msg("ray block %u: texel (%u, %u) factor %g, %s the columns", v ? 1 : B,
                                 i, j, (double)got, hit ? "under" : "beside");
                    ++checked;
                }
                const uint32_t i0 = i / B * B, j0 = j / B * B; /* the default block's corner */
                if (got != f[3 * ((size_t)j0 * N + i0)])
                    split_blocks[v]++;
            }
        assert_true(checked > (size_t)N * N / 2);
        free(f);
    }
    printf("blocks of 3 x 3 with texels of two values: %d with the default block, %d with a ray "
           "per texel\n", split_blocks[0], split_blocks[1]);
    assert_int_equal(split_blocks[0], 0);
    assert_true(split_blocks[1] > 0);
    const uint32_t sizes[] = {128, 80}, expect[] = {2, 1};
    s.cssm.ray_block = 0;
    for (int k = 0; k < 2; ++k) {
        s.map.size = sizes[k];
        assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
        free(block_factors(r, sizes[k]));
        assert_int_equal(built_ray_block(r), expect[k]);
    }
    umbra_renderer_release(r);
    umbra_transfer_function_release(sharp);
    umbra_transfer_function_release(opaque);
    umbra_volume_release(vol);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cssm_slab_mean_matches_transmittance),
        cmocka_unit_test(test_cssm_colored_channels_share_random_numbers),
        cmocka_unit_test(test_cssm_light_transfer_function_drives_generation),
        cmocka_unit_test(test_cssm_same_seed_same_image_bitwise),
        cmocka_unit_test(test_cssm_camera_move_reuses_map),
        cmocka_unit_test(test_cssm_skipping_changes_nothing),
        cmocka_unit_test(test_cssm_taps_read_their_texels),
        cmocka_unit_test(test_cssm_error_vs_reference_bounded),
        cmocka_unit_test(test_cssm_photons_of_a_block_share_its_ray),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
