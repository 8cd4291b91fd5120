// SPDX-License-Identifier: Apache-2.0
/* tests/test_deep.c: the deep shadow map (technique "deep", Hadwiger et al. 2006), pinned down.
 *
 *  - homogeneous slab: the map's visibility along texel rays is within epsilon + a stated
 *    discretisation term of exp(-sigma d), with and without the segment table, one ray or the
 *    5-tap pre-filter (whose expectation is the same weighted sum of the sub-rays' exponentials);
 *  - a step transfer function (an isosurface) at a coarse step of 2 voxels: with the segment
 *    table no self-shadowing in front of the surface, without it a large error there;
 *  - the block allocator: chains of distinct blocks, one chain per tile of the right length, no
 *    block shared, node lists well formed; a tiny pool grows and gives the same map, and fails
 *    with a clear error when it may not grow;
 *  - a fixed node budget: memory is map_size^2 x N x node bytes (+ the table) and the error
 *    against the reference does not grow as N grows;
 *  - rendered images against the reference within a measured bound;
 *  - a camera move reuses the map, a light move reuses the table, grey light uses one channel.
 * The lights that stress the projection (axis-aligned, grazing, point lights on and in the box),
 * rebuilds and bad parameters are the conformance suite's (tests/test_conformance.c).
 *
 * Usage: test_deep [filter] (a cmocka test-name glob).
 *
 * Why one file past 800 lines: one test per property of the deep map, each independent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "techniques/deep.h"
#include "test_util.h"

/* ---- helpers --------------------------------------------------------------------------------- */

typedef float (*field_fn)(double x, double y, double z);

/* A float volume of n^3 voxels with spacing 1 (the box is [-n/2, n/2]^3), voxel values f at the
 * voxel centres, value range [0, 1]. */
static umbra_volume make_volume(umbra_context ctx, uint32_t n, field_fn f)
{
    float *data = malloc((size_t)n * n * n * sizeof *data);
    assert_non_null(data);
    const double h = 0.5 * n - 0.5;
    for (uint32_t k = 0; k < n; ++k)
        for (uint32_t j = 0; j < n; ++j)
            for (uint32_t i = 0; i < n; ++i)
                data[((size_t)k * n + j) * n + i] = f(i - h, j - h, k - h);
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = d.dims[1] = d.dims[2] = n;
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    d.brick_size = 8;
    umbra_volume v = NULL;
    umbra_status st = umbra_volume_create(ctx, &d, &v);
    free(data);
    assert_int_equal(st, UMBRA_SUCCESS);
    return v;
}

static umbra_shadow_desc deep_desc(uint32_t map_size, float map_step, float eps, int lut,
                                   uint32_t prefilter, uint32_t max_nodes)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    d.technique = UMBRA_SHADOW_DEEP;
    d.map.size = map_size;
    d.map.step = map_step;
    d.deep.epsilon = eps;
    d.deep.lookup_table = lut;
    d.deep.prefilter = prefilter;
    d.deep.max_nodes = max_nodes;
    return d;
}

static void set_shadow(umbra_renderer r, umbra_shadow_desc d)
{
    assert_int_equal(umbra_renderer_set_shadow(r, &d), UMBRA_SUCCESS);
}

static void query(umbra_renderer r, const float *pts, size_t n, float *rgb)
{
    umbra_status st = umbra_renderer_query_shadow(r, pts, n, rgb);
    if (st != UMBRA_SUCCESS)
        fail_msg("query_shadow: %s", umbra_context_last_message(r->ctx));
}

/* Builds the map (a query builds it) so that r->shadow_params describes it. */
static void build(umbra_renderer r)
{
    float p[3] = {0.0f, 0.0f, 0.0f}, rgb[3];
    query(r, p, 1, rgb);
}

/* Slab test in double precision: the parameter interval where o + t d lies in [lo, hi]^3. */
static int ray_box_d(const double o[3], const double d[3], double lo, double hi, double *t0,
                     double *t1)
{
    double a = -INFINITY, b = INFINITY;
    for (int i = 0; i < 3; ++i) {
        if (fabs(d[i]) < 1e-300) {
            if (o[i] < lo || o[i] > hi)
                return 0;
            continue;
        }
        double ta = (lo - o[i]) / d[i], tb = (hi - o[i]) / d[i];
        a = fmax(a, fmin(ta, tb));
        b = fmin(b, fmax(ta, tb));
    }
    *t0 = fmax(a, 0.0);
    *t1 = b;
    return b > *t0;
}

/* The ray through map position (x, y) in texels of the current orthographic map: the host twin
 * of ls_texel_ray in kernels/common/lightspace.cl, in double precision. */
static void ortho_ray(umbra_renderer r, double x, double y, double o[3], double d[3])
{
    const UmbraShadow *S = &r->shadow_params;
    assert_int_equal(S->ls_mode, UMBRA_LS_ORTHO);
    double n = S->map_size;
    double a = x / n / S->ls_window[2] + S->ls_window[0];
    double b = y / n / S->ls_window[3] + S->ls_window[1];
    for (int i = 0; i < 3; ++i) {
        o[i] = a * S->ls_u[i] + b * S->ls_v[i] + (S->near_far[0] - 1.0) * S->ls_w[i];
        d[i] = S->ls_w[i];
    }
}

/* The 5-tap pre-filter of kernels/techniques/deep.cl: (dx, dy, weight). */
static const double prefilter_taps[5][3] = {
    {0.0, 0.0, 0.5},    {-0.5, -0.5, 0.125}, {0.5, -0.5, 0.125},
    {-0.5, 0.5, 0.125}, {0.5, 0.5, 0.125}};

/* Deterministic uniform numbers in [0,1) (xorshift32). */
static double uniform(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return (double)(*s >> 8) / 16777216.0;
}

static float field_sphere(double x, double y, double z)
{
    /* Radius 14 voxels; the scalar falls by 0.02 per voxel outward, 0.5 on the sphere. */
    double v = 0.5 + (14.0 - sqrt(x * x + y * y + z * z)) * 0.02;
    return (float)fmin(fmax(v, 0.0), 1.0);
}

static float field_layers(double x, double y, double z)
{
    /* Density bumps along y (the light's main direction) that vary across x and z, so the
     * visibility along a light ray has several kinks of different heights. */
    double v = 0.5 + 0.45 * sin(0.45 * y + 0.15 * x) * cos(0.12 * z + 0.1 * y);
    return (float)fmin(fmax(v, 0.0), 1.0);
}

/* A grey table of 256 entries: alpha(value) per voxel step from f. */
static umbra_transfer_function grey_tf(umbra_context ctx, float (*alpha)(float))
{
    float t[256 * 4];
    for (int i = 0; i < 256; ++i) {
        t[4 * i] = t[4 * i + 1] = t[4 * i + 2] = 0.8f;
        t[4 * i + 3] = alpha((float)i / 255.0f);
    }
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(ctx, t, 256, &tf), UMBRA_SUCCESS);
    return tf;
}

static float alpha_step(float v) { return v >= 128.0f / 255.0f - 1e-6f ? 0.95f : 0.0f; }
static float alpha_ramp(float v) { return v > 0.3f ? 0.3f * (v - 0.3f) / 0.7f : 0.0f; }

typedef struct layout {
    umbra__deep_info info;
    int32_t *head, *next;
    uint32_t *counts;
    float *nodes;
} layout;
static layout read_layout(umbra_renderer r);
static void free_layout(layout *L);
static const float *layout_node(const layout *L, uint32_t map, uint32_t x, uint32_t y, uint32_t j);

/* ---- homogeneous slab ------------------------------------------------------------------------ */

/* Expected map visibility at parameter t on the texel ray at map position (x, y): the weighted sum
 * over the texel's sub-rays of exp(-sigma * length inside the box up to t). */
static double slab_expected(umbra_renderer r, double x, double y, uint32_t prefilter, double t,
                            double half, double sigma)
{
    double v = 0.0;
    for (uint32_t i = 0; i < prefilter; ++i) {
        double o[3], d[3], t0, t1;
        double w = prefilter == 1 ? 1.0 : prefilter_taps[i][2];
        ortho_ray(r, x + (prefilter == 1 ? 0.0 : prefilter_taps[i][0]),
                  y + (prefilter == 1 ? 0.0 : prefilter_taps[i][1]), o, d);
        if (!ray_box_d(o, d, -half, half, &t0, &t1)) {
            v += w;
            continue;
        }
        double len = fmin(fmax(t - t0, 0.0), t1 - t0);
        v += w * exp(-sigma * len);
    }
    return v;
}

/* Error bound: the compression keeps every point it was given within epsilon. Those points are
 * exact here (a homogeneous medium: the midpoint rule, the segment table and the partial entry /
 * exit steps all give exp(-sigma len) at segment ends, to float precision), and between two of
 * them the true visibility is a convex exponential that the straight line between them misses by
 * at most tau^2 / 8 with tau = sigma h the optical depth of one step. The termination at
 * visibility epsilon / 2 stays inside epsilon. Float rounding of depths and of the light-space
 * fit (positions to ~1e-5 of the box, times sigma) adds under 1e-3. */
static void test_slab_visibility_within_epsilon_of_exp(void **state)
{
    umbra_context ctx = *state;
    const uint32_t n = 32;
    const double half = 16.0, a = 0.2, sigma = -log(1.0 - a);
    umbra_volume vol = test_constant_volume(ctx, n, n, n, 0.5f);
    umbra_transfer_function tf = test_constant_tf(ctx, 1.0f, (float)a);
    umbra_renderer r = test_renderer_transmission(
        ctx, vol, tf, test_directional_light(0.35f, -1.0f, 0.25f), UMBRA_TRANSMISSION_GREY);
    struct {
        umbra_light light;
        float eps;
        int lut;
        uint32_t prefilter;
    } cases[] = {
        {test_directional_light(0.35f, -1.0f, 0.25f), 0.02f, 1, 1},
        {test_directional_light(0.35f, -1.0f, 0.25f), 0.06f, 1, 1},
        {test_directional_light(0.35f, -1.0f, 0.25f), 0.005f, 1, 1},
        {test_directional_light(0.35f, -1.0f, 0.25f), 0.02f, 1, 5},
        {test_directional_light(0.0f, -1.0f, 0.0f), 0.02f, 1, 5},
        {test_directional_light(-0.8f, -0.3f, 0.6f), 0.02f, 0, 1},
        {test_directional_light(0.35f, -1.0f, 0.25f), 0.02f, 0, 5},
    };
    const uint32_t map = 64;
    const float h = 0.5f;
    const int per_ray = 20;
    float *pts = malloc((size_t)map * map * per_ray * 3 * sizeof *pts);
    float *rgb = malloc((size_t)map * map * per_ray * 3 * sizeof *rgb);
    double *expect = malloc((size_t)map * map * per_ray * sizeof *expect);
    assert_true(pts && rgb && expect);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        assert_int_equal(umbra_renderer_set_light(r, &cases[c].light), UMBRA_SUCCESS);
        set_shadow(r, deep_desc(map, h, cases[c].eps, cases[c].lut, cases[c].prefilter, 0));
        build(r);
        size_t np = 0;
        for (uint32_t j = 0; j < map; j += 3)
            for (uint32_t i = 0; i < map; i += 3) {
                double x = i + 0.5, y = j + 0.5, o[3], d[3], t0, t1;
                ortho_ray(r, x, y, o, d);
                if (!ray_box_d(o, d, -half, half, &t0, &t1))
                    continue;
                for (int q = 0; q < per_ray; ++q) {
                    /* From before the box to beyond it, along the texel's centre ray. */
                    double t = t0 - 1.0 + (t1 - t0 + 3.0) * q / (per_ray - 1);
                    for (int k = 0; k < 3; ++k)
                        pts[3 * np + k] = (float)(o[k] + t * d[k]);
                    expect[np++] = slab_expected(r, x, y, cases[c].prefilter, t, half, sigma);
                }
            }
        assert_true(np > 1000);
        query(r, pts, np, rgb);
        double tau = sigma * h, bound = cases[c].eps + tau * tau / 8.0 + 1e-3, worst = 0.0;
        for (size_t p = 0; p < np; ++p) {
            for (int k = 0; k < 3; ++k)
                assert_true(isfinite(rgb[3 * p + k]));
            worst = fmax(worst, fabs(rgb[3 * p] - expect[p]));
        }
        print_message("slab case %zu (eps %.3f, table %d, prefilter %u): max error %.5f, bound "
                      "%.5f\n", c, (double)cases[c].eps, cases[c].lut, cases[c].prefilter, worst,
                      bound);
        assert_true(worst <= bound);
        umbra_render_stats s;
        assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
        assert_int_equal(s.light_channels, 1); /* grey transmission: one channel */
    }
    free(pts);
    free(rgb);
    free(expect);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

/* ---- isosurface ------------------------------------------------------------------------------ */

/* Points 0.3 voxels in front of the sphere (toward the light) on texel rays that meet it at less
 * than 60 degrees from the normal, and points 2 voxels inside it. The exact visibility in front is
 * 1 (the alpha ramp of the table starts 0.1 voxels outside the radius-14 sphere); inside it is
 * 0.05^2 at most. */
static void iso_points(umbra_renderer r, uint32_t map, float *front, float *inside, size_t *n)
{
    const double R = 14.0;
    *n = 0;
    for (uint32_t j = 0; j < map; ++j)
        for (uint32_t i = 0; i < map; ++i) {
            double o[3], d[3];
            ortho_ray(r, i + 0.5, j + 0.5, o, d);
            double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
            double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - R * R;
            double disc = b * b - c;
            if (disc <= 0.0)
                continue;
            double ts = -b - sqrt(disc);
            double cosi = sqrt(disc) / R; /* cosine between the ray and the surface normal */
            if (cosi < 0.5)
                continue;
            for (int k = 0; k < 3; ++k) {
                front[3 * *n + k] = (float)(o[k] + (ts - 0.3) * d[k]);
                inside[3 * *n + k] = (float)(o[k] + (ts + 2.0) * d[k]);
            }
            ++*n;
        }
}

static void test_step_tf_lookup_table_prevents_self_shadowing(void **state)
{
    umbra_context ctx = *state;
    const uint32_t map = 64;
    umbra_volume vol = make_volume(ctx, 48, field_sphere);
    umbra_transfer_function tf = grey_tf(ctx, alpha_step);
    umbra_renderer r = test_renderer_transmission(
        ctx, vol, tf, test_directional_light(0.3f, -1.0f, 0.2f), UMBRA_TRANSMISSION_GREY);
    float *front = malloc((size_t)map * map * 3 * sizeof *front);
    float *inside = malloc((size_t)map * map * 3 * sizeof *inside);
    float *rgb = malloc((size_t)map * map * 3 * sizeof *rgb);
    assert_true(front && inside && rgb);
    const float eps = 0.02f;
    double worst_front[2], mean_front[2], worst_inside[2];
    for (int lut = 1; lut >= 0; --lut) {
        set_shadow(r, deep_desc(map, 2.0f, eps, lut, 1, 0));
        build(r);
        size_t n = 0;
        iso_points(r, map, front, inside, &n);
        assert_true(n > 500);
        query(r, front, n, rgb);
        worst_front[lut] = mean_front[lut] = 0.0;
        for (size_t p = 0; p < n; ++p) {
            double e = fabs(1.0 - rgb[3 * p]);
            worst_front[lut] = fmax(worst_front[lut], e);
            mean_front[lut] += e / (double)n;
        }
        query(r, inside, n, rgb);
        worst_inside[lut] = 0.0;
        for (size_t p = 0; p < n; ++p)
            worst_inside[lut] = fmax(worst_inside[lut], rgb[3 * p]);
        print_message("isosurface, table %d: in front max error %.4f mean %.4f; 2 voxels inside "
                      "max visibility %.4f (%zu rays)\n", lut, worst_front[lut], mean_front[lut],
                      worst_inside[lut], n);
    }
    /* With the table: lit in front within epsilon (+ 0.01 for the quantised scalar placing the
     * step up to 1/510 of the value range, 0.05 voxels here, and the trilinear field), and dark
     * inside. Without it, at this step the midpoint sample smears the surface over a whole
     * 2-voxel segment: points in front are darkened (self-shadowing) and points inside lit.
     * Measured on PoCL: with the table 0.0000 in front and 0.017 inside; without it 0.28 at
     * worst and 0.060 on average in front, 0.44 inside. */
    assert_true(worst_front[1] <= eps + 0.01);
    assert_true(worst_inside[1] <= 0.1);
    assert_true(worst_front[0] >= 0.2);
    assert_true(mean_front[0] >= 0.03 && mean_front[0] >= 5.0 * mean_front[1]);
    assert_true(worst_inside[0] >= 0.3);
    free(front);
    free(inside);
    free(rgb);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

/* ---- block allocator ------------------------------------------------------------------------- */


static layout read_layout(umbra_renderer r)
{
    layout L;
    memset(&L, 0, sizeof L);
    assert_int_equal(umbra__deep_get_info(r, &L.info), UMBRA_SUCCESS);
    size_t tiles = (size_t)L.info.tiles_per_row * L.info.tiles_per_row;
    size_t texels = (size_t)r->shadow.map.size * r->shadow.map.size;
    L.head = malloc(tiles * sizeof *L.head);
    L.next = malloc((L.info.used_blocks + 1) * sizeof *L.next);
    L.counts = malloc(texels * sizeof *L.counts);
    L.nodes = malloc(L.info.used_blocks * L.info.block_bytes + 16);
    assert_true(L.head && L.next && L.counts && L.nodes);
    assert_int_equal(umbra__deep_read(r, L.head, L.next, L.counts, L.nodes), UMBRA_SUCCESS);
    return L;
}

static void free_layout(layout *L)
{
    free(L->head);
    free(L->next);
    free(L->counts);
    free(L->nodes);
}

/* Node j of texel (x, y) as (depth, channels...), found by walking the tile's chain. */
static const float *layout_node(const layout *L, uint32_t map, uint32_t x, uint32_t y, uint32_t j)
{
    const uint32_t T = L->info.tile, K = L->info.block_size;
    int32_t b = L->head[(y / T) * L->info.tiles_per_row + x / T];
    for (uint32_t q = 0; q < j / K; ++q)
        b = L->next[b];
    size_t lane = (size_t)(y % T) * T + x % T;
    size_t stride = 1 + L->info.channels;
    (void)map;
    return L->nodes + (((size_t)b * K + j % K) * T * T + lane) * stride;
}

static void check_layout(const layout *L, uint32_t map)
{
    const uint32_t T = L->info.tile, K = L->info.block_size, tpr = L->info.tiles_per_row;
    const size_t used = L->info.used_blocks;
    char *seen = calloc(used + 1, 1);
    assert_non_null(seen);
    size_t chained = 0;
    for (uint32_t ty = 0; ty < tpr; ++ty)
        for (uint32_t tx = 0; tx < tpr; ++tx) {
            uint32_t most = 0;
            for (uint32_t y = ty * T; y < (ty + 1) * T && y < map; ++y)
                for (uint32_t x = tx * T; x < (tx + 1) * T && x < map; ++x)
                    most = L->counts[y * map + x] > most ? L->counts[y * map + x] : most;
            /* The tile's chain: distinct blocks, never one of another tile, exactly as many as
             * its longest node list needs. */
            size_t len = 0;
            for (int32_t b = L->head[ty * tpr + tx]; b >= 0; b = L->next[b]) {
                assert_true((size_t)b < used);
                assert_false(seen[b]);
                seen[b] = 1;
                ++len;
            }
            assert_int_equal(len, (most + K - 1) / K);
            chained += len;
        }
    assert_int_equal(chained, used); /* every block taken belongs to a chain */
    free(seen);
    /* Node lists: start at visibility 1, depths increase, values in [0, 1]. */
    for (uint32_t y = 0; y < map; ++y)
        for (uint32_t x = 0; x < map; ++x) {
            uint32_t c = L->counts[y * map + x];
            assert_true(c == 0 || c >= 2);
            double zprev = -INFINITY;
            for (uint32_t j = 0; j < c; ++j) {
                const float *nd = layout_node(L, map, x, y, j);
                assert_true(isfinite(nd[0]) && nd[0] > zprev);
                zprev = nd[0];
                for (uint32_t ch = 1; ch <= L->info.channels; ++ch) {
                    assert_true(nd[ch] >= 0.0f && nd[ch] <= 1.0f);
                    if (j == 0)
                        assert_true(nd[ch] == 1.0f);
                }
            }
        }
}

static void test_block_allocator_layout_and_pool_growth(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 40, &sc), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(
        ctx, sc.volume, sc.tf, test_directional_light(0.3f, -1.0f, 0.4f),
        UMBRA_TRANSMISSION_COLORED);
    const uint32_t map = 72; /* not a multiple of the tile: the last tiles are partial */
    umbra_shadow_desc d = deep_desc(map, 0.5f, 0.01f, 1, 1, 0);
    d.deep.block_size = 2;
    set_shadow(r, d);
    build(r);
    layout big = read_layout(r);
    print_message("pool %zu blocks, used %zu of %zu bytes, tile %u, %u channels\n",
                  big.info.pool_blocks, big.info.used_blocks, big.info.block_bytes,
                  big.info.tile, big.info.channels);
    assert_int_equal(big.info.channels, 3);
    assert_int_equal(big.info.node_bytes, 16);
    assert_int_equal(big.info.block_bytes, (size_t)2 * big.info.tile * big.info.tile * 16);
    assert_true(big.info.used_blocks > 16);
    check_layout(&big, map);
    /* Memory: used blocks + layout + table. */
    umbra_render_stats s;
    assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
    size_t tiles = (size_t)big.info.tiles_per_row * big.info.tiles_per_row;
    size_t layout_bytes = tiles * 4 + big.info.used_blocks * 4 + (size_t)map * map * 4;
    size_t lut_bytes =
        (size_t)UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_NODES * 16;
    assert_int_equal(s.shadow_memory_bytes,
                     big.info.used_blocks * big.info.block_bytes + layout_bytes + lut_bytes);

    /* A pool of 3 blocks: the build overflows, the pool grows to the count and the build runs
     * again; the map is the same, texel by texel and bit by bit. */
    float probe[3 * 64], rgb_big[3 * 64], rgb_small[3 * 64];
    uint32_t seed = 7;
    for (int i = 0; i < 3 * 64; ++i)
        probe[i] = (float)(40.0 * uniform(&seed) - 20.0);
    query(r, probe, 64, rgb_big);
    assert_int_equal(umbra__deep_set_pool(r, 3, 1), UMBRA_SUCCESS);
    build(r);
    layout small = read_layout(r);
    assert_int_equal(small.info.pool_growths, big.info.pool_growths + 1);
    assert_int_equal(small.info.build_passes, big.info.build_passes + 2);
    assert_int_equal(small.info.used_blocks, big.info.used_blocks);
    assert_int_equal(small.info.lut_builds, big.info.lut_builds);
    check_layout(&small, map);
    size_t stride = 1 + small.info.channels;
    for (uint32_t y = 0; y < map; ++y)
        for (uint32_t x = 0; x < map; ++x) {
            assert_int_equal(small.counts[y * map + x], big.counts[y * map + x]);
            for (uint32_t j = 0; j < big.counts[y * map + x]; ++j)
                assert_memory_equal(layout_node(&small, map, x, y, j),
                                    layout_node(&big, map, x, y, j), stride * sizeof(float));
        }
    query(r, probe, 64, rgb_small);
    assert_memory_equal(rgb_small, rgb_big, sizeof rgb_big);

    /* Growth disallowed: a clear error, nothing rendered from a partial map. */
    assert_int_equal(umbra__deep_set_pool(r, 3, 0), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_query_shadow(r, probe, 64, rgb_small),
                     UMBRA_ERROR_OUT_OF_MEMORY);
    assert_true(test_message_contains(ctx, "may not grow"));
    assert_true(test_message_contains(ctx, "pool holds 3"));
    umbra_context_take_error(ctx, NULL);
    /* Back to automatic sizing: works again. */
    assert_int_equal(umbra__deep_set_pool(r, 0, 1), UMBRA_SUCCESS);
    query(r, probe, 64, rgb_small);
    assert_memory_equal(rgb_small, rgb_big, sizeof rgb_big);
    free_layout(&big);
    free_layout(&small);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

/* ---- fixed node budget ----------------------------------------------------------------------- */

static double mean_abs(const float *a, const float *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        s += fabs((double)a[i] - b[i]);
    return s / (double)n;
}

static void test_fixed_budget_memory_and_error(void **state)
{
    umbra_context ctx = *state;
    const uint32_t map = 64, npts = 4000;
    umbra_volume vol = make_volume(ctx, 40, field_layers);
    umbra_transfer_function tf = grey_tf(ctx, alpha_ramp);
    umbra_renderer r = test_renderer_transmission(
        ctx, vol, tf, test_directional_light(0.2f, -1.0f, 0.3f), UMBRA_TRANSMISSION_GREY);
    float *pts = malloc(npts * 3 * sizeof *pts), *ref = malloc(npts * 3 * sizeof *ref),
          *got = malloc(npts * 3 * sizeof *got);
    assert_true(pts && ref && got);
    /* Points on texel centres' rays, so the comparison measures the visibility functions, not
     * the nearest-texel lookup. */
    set_shadow(r, deep_desc(map, 0.5f, 0.005f, 1, 1, 0));
    build(r);
    uint32_t seed = 12345;
    for (uint32_t p = 0; p < npts;) {
        double o[3], d[3], t0, t1;
        uint32_t i = (uint32_t)(uniform(&seed) * map), j = (uint32_t)(uniform(&seed) * map);
        ortho_ray(r, i + 0.5, j + 0.5, o, d);
        if (!ray_box_d(o, d, -20.0, 20.0, &t0, &t1))
            continue;
        double t = t0 + (t1 - t0) * uniform(&seed);
        for (int k = 0; k < 3; ++k)
            pts[3 * p + k] = (float)(o[k] + t * d[k]);
        ++p;
    }
    umbra_shadow_desc ref_desc;
    umbra_shadow_desc_init(&ref_desc);
    ref_desc.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &ref_desc), UMBRA_SUCCESS);
    query(r, pts, npts, ref);

    const uint32_t budgets[] = {2, 3, 4, 6, 10, 16};
    double err[6];
    for (int b = 0; b < 6; ++b) {
        set_shadow(r, deep_desc(map, 0.5f, 0.005f, 1, 1, budgets[b]));
        query(r, pts, npts, got);
        err[b] = mean_abs(got, ref, 3 * npts);
        umbra_render_stats s;
        umbra__deep_info info;
        assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
        assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_SUCCESS);
        /* One channel (grey): a node is (depth, visibility), 8 bytes. */
        assert_int_equal(info.node_bytes, 8);
        size_t lut = (size_t)UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_RES * UMBRA__DEEP_LUT_NODES * 8;
        assert_int_equal(s.shadow_memory_bytes, (size_t)map * map * budgets[b] * 8 + lut);
        print_message("budget %u nodes: mean abs error vs reference %.5f\n", budgets[b], err[b]);
    }
    set_shadow(r, deep_desc(map, 0.5f, 0.005f, 1, 1, 0));
    query(r, pts, npts, got);
    double unbounded = mean_abs(got, ref, 3 * npts);
    print_message("unbounded (eps 0.005): %.5f\n", unbounded);
    /* The error does not grow with the budget (1e-4: float noise), and the budget matters. */
    for (int b = 1; b < 6; ++b)
        assert_true(err[b] <= err[b - 1] + 1e-4);
    assert_true(err[0] >= 3.0 * err[5]);
    assert_true(unbounded <= err[5] + 1e-4);
    free(pts);
    free(ref);
    free(got);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
}

/* ---- images against the reference ------------------------------------------------------------ */

static void test_render_matches_reference(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &sc), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer(ctx, sc.volume, sc.tf, &sc.camera, &sc.light, &sc.options);
    enum { W = 96, H = 96 };
    float *ref = malloc(W * H * 4 * sizeof *ref), *img = malloc(W * H * 4 * sizeof *img);
    assert_true(ref && img);
    umbra_shadow_desc ref_desc;
    umbra_shadow_desc_init(&ref_desc);
    ref_desc.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &ref_desc), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, W, H, ref), UMBRA_SUCCESS);
    /* Mean absolute error per RGB channel over the image (premultiplied, the ground plane
     * included). Measured on PoCL: 0.0013 (epsilon 0.02), 0.0013 (5-tap pre-filter), 0.0018
     * (no table), 0.0016 (3 nodes). Bounds: about three times that. */
    struct {
        umbra_shadow_desc d;
        double bound;
    } cases[] = {
        {deep_desc(128, 0.5f, 0.02f, 1, 1, 0), 0.004},
        {deep_desc(128, 0.5f, 0.02f, 1, 5, 0), 0.004},
        {deep_desc(128, 0.5f, 0.02f, 0, 1, 0), 0.005},
        {deep_desc(128, 0.5f, 0.02f, 1, 1, 3), 0.005},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        set_shadow(r, cases[c].d);
        assert_int_equal(umbra_renderer_render(r, W, H, img), UMBRA_SUCCESS);
        double e = 0.0;
        for (int i = 0; i < W * H; ++i)
            for (int k = 0; k < 3; ++k)
                e += fabs((double)img[4 * i + k] - ref[4 * i + k]) / (3.0 * W * H);
        print_message("render case %zu: mean abs pixel error vs reference %.5f (bound %.3f)\n",
                      c, e, cases[c].bound);
        assert_true(e <= cases[c].bound);
    }
    free(ref);
    free(img);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

/* ---- caching and channels -------------------------------------------------------------------- */

static void test_camera_move_reuses_map_light_move_reuses_table(void **state)
{
    umbra_context ctx = *state;
    umbra_scene sc;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 32, &sc), UMBRA_SUCCESS);
    umbra_renderer r = test_renderer_transmission(
        ctx, sc.volume, sc.tf, test_directional_light(0.3f, -1.0f, 0.2f),
        UMBRA_TRANSMISSION_COLORED);
    set_shadow(r, deep_desc(64, 0.5f, 0.02f, 1, 1, 0));
    float img[32 * 32 * 4];
    umbra_render_stats s;
    umbra__deep_info a, b;
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
    assert_int_equal(s.shadow_rebuilt, 1);
    assert_int_equal(s.light_channels, 3);
    assert_int_equal(umbra__deep_get_info(r, &a), UMBRA_SUCCESS);
    assert_int_equal(a.builds, 1);
    assert_int_equal(a.lut_builds, 1);

    /* Camera move: the same map. */
    float dir[3] = {-0.4f, 0.3f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 60.0f, 30.0f);
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
    assert_int_equal(s.shadow_rebuilt, 0);
    assert_true(s.shadow_build_ms == 0.0);
    assert_int_equal(umbra__deep_get_info(r, &b), UMBRA_SUCCESS);
    assert_int_equal(b.builds, 1);

    /* Light move, then a new epsilon: the map is rebuilt, the table is not. */
    umbra_light l = test_directional_light(-0.5f, -1.0f, 0.1f);
    assert_int_equal(umbra_renderer_set_light(r, &l), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
    assert_int_equal(s.shadow_rebuilt, 1);
    set_shadow(r, deep_desc(64, 0.5f, 0.06f, 1, 1, 0));
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    /* The table off and on again: still the cached one. */
    set_shadow(r, deep_desc(64, 0.5f, 0.06f, 0, 1, 0));
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    set_shadow(r, deep_desc(64, 0.5f, 0.06f, 1, 1, 0));
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    assert_int_equal(umbra__deep_get_info(r, &b), UMBRA_SUCCESS);
    assert_int_equal(b.builds, 5);
    assert_int_equal(b.lut_builds, 1);

    /* Another step (a draft's) builds a second table and keeps the first: back and forth
     * between the two builds no table again, and both are counted in the memory. */
    const size_t one_table = b.lut_bytes;
    float full_img[32 * 32 * 4];
    assert_int_equal(umbra_renderer_render(r, 32, 32, full_img), UMBRA_SUCCESS);
    for (int pass = 0; pass < 2; ++pass) {
        set_shadow(r, deep_desc(64, 1.0f, 0.06f, 1, 1, 0));
        assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
        set_shadow(r, deep_desc(64, 0.5f, 0.06f, 1, 1, 0));
        assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
        assert_memory_equal(img, full_img, sizeof img); /* the table the step asks for */
    }
    assert_int_equal(umbra__deep_get_info(r, &b), UMBRA_SUCCESS);
    assert_int_equal(b.lut_builds, 2);
    assert_int_equal(b.lut_bytes, 2 * one_table);

    /* A grey light transfer function: one channel, 8-byte nodes, a new table (its key holds
     * the channel count and the table's id). */
    umbra_transfer_function grey = test_constant_tf(ctx, 0.5f, 0.05f);
    assert_int_equal(umbra_renderer_set_light_transfer_function(r, grey), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, 32, 32, img), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_get_stats(r, &s), UMBRA_SUCCESS);
    assert_int_equal(s.light_channels, 1);
    assert_int_equal(umbra__deep_get_info(r, &b), UMBRA_SUCCESS);
    assert_int_equal(b.channels, 1);
    assert_int_equal(b.node_bytes, 8);
    assert_int_equal(b.lut_builds, 3);
    assert_int_equal(b.lut_bytes, one_table / 2); /* the other transfer function's are gone */
    umbra_transfer_function_release(grey);
    umbra_renderer_release(r);
    umbra_scene_release(&sc);
}

/* Empty-space skipping of the light rays (whole bricks, and segments whose two ends lie in
 * sub-cells the light transfer function leaves empty, with jumps over them) changes nothing, bit
 * for bit: a skipped segment is one the march would find flat, and a flat segment gives the fit
 * no points either way (kernels/techniques/deep.cl, deep_step). The spheres at 64x64 with
 * skipping off and on, for the scene's light and a point light above a corner, the unbounded map
 * and a budget of 3 nodes, with and without the segment table and with the 5-ray pre-filter.
 * Until 2026-12-03 the skip fed the fit no points where the march fed it flat ones, and its jumps
 * located their exits afresh: the images differed by up to 5.8e-4 (unbounded) and 0.079 (3
 * nodes, a flipped choice of nodes); the parts, which do not skip, inherited that difference. */
static void test_skipping_changes_nothing(void **state)
{
    umbra_context ctx = *state;
    umbra_scene scene;
    assert_int_equal(umbra_scene_create(ctx, "spheres", 48, &scene), UMBRA_SUCCESS);
    const umbra_light lights[2] = {scene.light, test_point_light(30.0f, 45.0f, -25.0f)};
    enum { W = 64, H = 64 };
    static float img[2][W * H * 4];
    for (int l = 0; l < 2; ++l)
        for (int v = 0; v < 6; ++v) {
            /* modes v / 2: the table, no table, the table with the 5-ray pre-filter */
            const int mode = v / 2;
            umbra_shadow_desc d =
                deep_desc(128, 0.5f, 0.02f, mode != 1, mode == 2 ? 5u : 1u, v & 1 ? 3u : 0u);
            for (int skip = 0; skip < 2; ++skip) {
                umbra_render_desc o = scene.options;
                o.empty_space_skipping = skip;
                umbra_renderer r =
                    test_renderer(ctx, scene.volume, scene.tf, &scene.camera, &lights[l], &o);
                assert_int_equal(umbra_renderer_set_shadow(r, &d), UMBRA_SUCCESS);
                assert_int_equal(umbra_renderer_render(r, W, H, img[skip]), UMBRA_SUCCESS);
                umbra_renderer_release(r);
            }
            double worst = 0.0, sum = 0.0;
            for (size_t i = 0; i < W * H * 4; ++i) {
                double e = fabs((double)img[0][i] - img[1][i]);
                worst = fmax(worst, e);
                sum += e;
            }
            const double mean = sum / (W * H * 4);
            printf("light %d, %s, table %d, prefilter %u: skipping on/off |diff| max %.2e, "
                   "mean %.2e\n", l, v & 1 ? "3 nodes" : "unbounded", mode != 1, d.deep.prefilter,
                   worst, mean);
            assert_memory_equal(img[0], img[1], sizeof img[0]);
        }
    umbra_scene_release(&scene);
}

/* The test hooks refuse a renderer of another technique. */
static void test_hooks_refuse_another_technique(void **state)
{
    umbra_context ctx = *state;
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(ctx, &r), UMBRA_SUCCESS);
    umbra__deep_info info;
    assert_int_equal(umbra__deep_get_info(r, &info), UMBRA_ERROR_INVALID_ARGUMENT);
    assert_true(test_message_contains(ctx, "not 'deep'"));
    umbra_context_take_error(ctx, NULL);
    umbra_renderer_release(r);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab_visibility_within_epsilon_of_exp),
        cmocka_unit_test(test_step_tf_lookup_table_prevents_self_shadowing),
        cmocka_unit_test(test_block_allocator_layout_and_pool_growth),
        cmocka_unit_test(test_fixed_budget_memory_and_error),
        cmocka_unit_test(test_render_matches_reference),
        cmocka_unit_test(test_camera_move_reuses_map_light_move_reuses_table),
        cmocka_unit_test(test_skipping_changes_nothing),
        cmocka_unit_test(test_hooks_refuse_another_technique),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
