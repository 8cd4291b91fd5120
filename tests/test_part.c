// SPDX-License-Identifier: Apache-2.0
/* tests/test_part.c: a volume split into parts (umbra/part.h, host/part.c, host/part_render.c,
 * host/part_light.c), in one process, against the single-device render of the whole volume:
 *  - the analytic volume below split 2x1x1, 2x2x1, 2x2x2 and 2x1x1 with an empty part; each part
 *    a part volume with the ghost layers umbra_part_ghost_needed asks for, rendered with
 *    umbra_renderer_render_part, the partial images composited in the order
 *    umbra_part_view_order gives (umbra_part_composite) and put over the background: the image
 *    equals the whole volume's within PART_BOUND (float rounding of the over operator against
 *    one ray's running sum), for a perspective camera looking obliquely and an orthographic one
 *    along an axis, jitter on and off, shading on and off, grey and coloured light, directional
 *    along an axis and oblique, a point light inside and outside the box;
 *  - with early ray termination (0.9) the difference is at most 1 - termination;
 *  - the same parts rendered one after another into one frame, each going on from the
 *    accumulation of the parts in front (umbra_renderer_render_part_into): one device's image bit
 *    for bit (memcmp) for none (termination 1 and 0.9);
 *  - the host helpers: the visibility order of a 2x2x2 grid from a point and along a direction,
 *    the over operator, the product and minimum;
 *  - bad input, refused naming the value, the context usable after: an offset off the brick
 *    grid, a part that overflows the global grid, dims that do not match, no given value range,
 *    too few ghost layers, the techniques that do not split (reference, convolution) and moments
 *    (no light exchange), the deep map's options that do not split (prefilter 5, a node budget,
 *    a light step above a voxel), the ground plane, a projection mode, a part rendered with
 *    umbra_renderer_render, a threshold part rendered before its depths were imported or after
 *    the light changed, a NaN depth and a transmittance above 1 (each naming the texel), CSSM's
 *    negative or NaN optical depth (naming the texel), a front opacity above 1 (naming the
 *    pixel), the deep map rendered before its pieces were imported and pieces that do not add
 *    up or hold a NaN depth.
 * The light-space maps on parts: tests/test_part_maps.c; the scene: tests/part_scene.h.
 * Usage: test_part [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "part_scene.h"
#include "techniques/deep.h"
#include "techniques/deep_shared.h"
#include "techniques/maps.h"

/* The composited image's largest difference from one device's; *seq_differing counts the floats
 * of the image rendered part after part into one accumulation that differ from it in any bit. */
static float compare_split(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                           const scene *s, const uint32_t *const cuts[3], const uint32_t ncuts[3],
                           int extra_empty, size_t *seq_differing)
{
    umbra_part_desc parts[16];
    const uint32_t n =
        make_parts(cuts, ncuts, extra_empty, umbra_part_ghost_needed(&s->opts), parts);
    float *whole = render_whole(ctx, voxels, tf, s);
    float *seq = NULL;
    float *split = render_parts(ctx, voxels, tf, s, parts, n, &seq);
    float diff = test_max_diff(whole, split, (size_t)W * H * 4, NULL);
    *seq_differing = bits_differing(whole, seq, (size_t)W * H * 4);
    free(seq);
    /* The volume is in the image: a wrong split could not pass by showing nothing. */
    double lit = 0.0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        lit += fabsf(whole[4 * i] - s->opts.background[0]);
    assert_true(lit > 1.0);
    free(whole);
    free(split);
    return diff;
}

static void test_splits_match_one_device(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_transfer_function tf = scene_tf(ctx);
    const uint32_t *const cuts[3] = {CX, CY, CZ};
    const uint32_t split_2x1x1[3] = {1, 0, 0}, split_2x2x1[3] = {1, 1, 0},
                   split_2x2x2[3] = {1, 1, 1};
    /* ortho, jitter, shading, point light (1 inside, 2 outside), coloured light */
    const int cases[][5] = {{0, 0, 0, 0, 0}, {0, 1, 0, 0, 0}, {0, 1, 1, 1, 1}, {1, 0, 1, 0, 1},
                            {1, 1, 0, 2, 0}, {0, 0, 1, 2, 1}};
    float worst = 0.0f;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const scene s = make_scene(cases[c][0], cases[c][1], cases[c][2], cases[c][3], cases[c][4]);
        const uint32_t *splits[] = {split_2x1x1, split_2x2x1, split_2x2x2, split_2x1x1};
        for (int k = 0; k < 4; ++k) {
            size_t seq = 0;
            float d = compare_split(ctx, voxels, tf, &s, cuts, splits[k], k == 3, &seq);
            printf("case %zu split %d: max |diff| %.3g; part after part: %zu floats differ\n", c,
                   k, (double)d, seq);
            if (d > worst)
                worst = d;
            assert_true(d <= PART_BOUND);
            assert_int_equal(seq, 0);
        }
    }
    printf("largest difference over all splits and cases: %.3g (bound %.3g)\n", (double)worst,
           (double)PART_BOUND);
    umbra_transfer_function_release(tf);
    free(voxels);
}

/* With termination < 1 a part behind another still adds what one device dropped. */
static void test_termination_bound(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_transfer_function tf = scene_tf(ctx);
    const uint32_t *const cuts[3] = {CX, CY, CZ};
    const uint32_t split[3] = {1, 1, 1};
    scene s = make_scene(0, 1, 0, 0, 0);
    s.opts.termination = 0.9f;
    size_t seq = 0;
    float d = compare_split(ctx, voxels, tf, &s, cuts, split, 0, &seq);
    printf("termination 0.9: max |diff| %.3g; part after part: %zu floats differ\n", (double)d,
           seq);
    assert_true(d <= 1.0f - s.opts.termination + PART_BOUND);
    /* A part after the others goes on from their opacity, so it ends where one device ends. */
    assert_int_equal(seq, 0);
    umbra_transfer_function_release(tf);
    free(voxels);
}

static void test_host_helpers(void **state)
{
    (void)state;
    /* A 2x2x2 grid of 8^3 parts in a 16^3 grid, unit spacing, centred box. */
    umbra_part_desc parts[8];
    for (uint32_t i = 0; i < 8; ++i) {
        umbra_part_desc_init(&parts[i]);
        for (int a = 0; a < 3; ++a) {
            parts[i].global_dims[a] = 16;
            parts[i].offset[a] = (i >> a) & 1 ? 8 : 0;
            parts[i].size[a] = 8;
        }
    }
    umbra_volume_info info;
    memset(&info, 0, sizeof info);
    for (int a = 0; a < 3; ++a) {
        info.spacing[a] = 1.0f;
        info.origin[a] = -7.5f;
        info.directions[4 * a] = 1.0f;
    }
    uint32_t order[8];
    /* From a point beyond the +x +y +z corner: part 7 first, part 0 last. */
    const float eye[3] = {20.0f, 30.0f, 40.0f};
    assert_int_equal(umbra_part_visibility_order(parts, 8, &info, eye, 1, order), UMBRA_SUCCESS);
    assert_int_equal(order[0], 7);
    assert_int_equal(order[7], 0);
    /* Every part after all parts nearer the eye along each axis. */
    uint32_t rank[8];
    for (uint32_t i = 0; i < 8; ++i)
        rank[order[i]] = i;
    for (uint32_t i = 0; i < 8; ++i)
        for (int a = 0; a < 3; ++a)
            if (!((i >> a) & 1))
                assert_true(rank[i | (1u << a)] < rank[i]);
    /* Along +x (light travelling to +x): the x = 0 parts first. */
    const float dir[3] = {1.0f, 0.0f, 0.0f};
    assert_int_equal(umbra_part_visibility_order(parts, 8, &info, dir, 0, order), UMBRA_SUCCESS);
    for (uint32_t i = 0; i < 4; ++i)
        assert_int_equal(parts[order[i]].offset[0], 0);
    /* From a point inside part 0's box: part 0 first. */
    const float inside[3] = {-3.0f, -3.0f, -3.0f};
    assert_int_equal(umbra_part_visibility_order(parts, 8, &info, inside, 1, order), UMBRA_SUCCESS);
    assert_int_equal(order[0], 0);
    assert_int_equal(order[7], 7);
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    assert_int_equal(umbra_part_visibility_order(parts, 8, &info, zero, 0, order),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    /* over: front (0.2, 0.1, 0, 0.5) over back (0.4, 0.4, 0.4, 0.8). */
    const float front[4] = {0.2f, 0.1f, 0.0f, 0.5f}, back[4] = {0.4f, 0.4f, 0.4f, 0.8f};
    float out[4];
    umbra_part_over(front, back, out, 1);
    assert_float_equal(out[0], 0.4f, 1e-7f);
    assert_float_equal(out[1], 0.3f, 1e-7f);
    assert_float_equal(out[2], 0.2f, 1e-7f);
    assert_float_equal(out[3], 0.9f, 1e-7f);
    /* A rectangle outside the frame is refused. */
    float frame[4 * 4 * 4] = {0};
    const umbra_part_rect bad = {3, 0, 2, 1};
    assert_int_equal(umbra_part_composite(frame, 4, 4, front, &bad), UMBRA_ERROR_INVALID_ARGUMENT);
    const umbra_part_rect one = {1, 2, 1, 1};
    assert_int_equal(umbra_part_composite(frame, 4, 4, front, &one), UMBRA_SUCCESS);
    assert_float_equal(frame[4 * (2 * 4 + 1) + 3], 0.5f, 0.0f);
    float acc[3] = {1.0f, 0.5f, 0.25f};
    const float t[3] = {0.5f, 0.5f, 2.0f};
    umbra_part_multiply(acc, t, 3);
    assert_float_equal(acc[0], 0.5f, 0.0f);
    assert_float_equal(acc[1], 0.25f, 0.0f);
    assert_float_equal(acc[2], 0.5f, 0.0f);
    const float dd[3] = {0.7f, INFINITY, 0.1f};
    umbra_part_minimum(acc, dd, 3);
    assert_float_equal(acc[0], 0.5f, 0.0f);
    assert_float_equal(acc[1], 0.25f, 0.0f);
    assert_float_equal(acc[2], 0.1f, 0.0f);
}

/* A part descriptor of the global NX x NY x NZ grid: [x0, x0 + sx) x everything, ghosts g. */
static void slab_part(umbra_part_desc *p, uint32_t x0, uint32_t sx, uint32_t g)
{
    umbra_part_desc_init(p);
    const uint32_t gd[3] = {NX, NY, NZ};
    for (int a = 0; a < 3; ++a) {
        p->global_dims[a] = gd[a];
        p->size[a] = gd[a];
    }
    p->offset[0] = x0;
    p->size[0] = sx;
    p->ghost_lo[0] = x0 < g ? x0 : g;
    p->ghost_hi[0] = NX - x0 - sx < g ? NX - x0 - sx : g;
}

static umbra_status try_part(umbra_context ctx, const float *voxels, const umbra_part_desc *p,
                             int given, umbra_volume *out)
{
    const uint32_t lo[3] = {p->offset[0] - p->ghost_lo[0], 0, 0};
    const uint32_t n[3] = {p->ghost_lo[0] + p->size[0] + p->ghost_hi[0], NY, NZ};
    float *box = sub_box(voxels, lo, n);
    umbra_volume_desc d;
    volume_desc(&d, box, n[0], n[1], n[2]);
    d.value_range_given = given;
    umbra_status st = umbra_volume_create_part(ctx, &d, p, out);
    free(box);
    return st;
}

static void test_bad_input_refused(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_part_desc p;
    umbra_volume v = NULL;
    slab_part(&p, 12, 16, 2); /* 12 is off the 8-voxel brick grid */
    test_assert_failed(ctx, try_part(ctx, voxels, &p, 1, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "offset[0] (x) 12", "brick size 8");
    assert_null(v);
    slab_part(&p, 32, 8, 0);
    p.size[0] = 16; /* 32 + 16 > 40 */
    p.ghost_hi[0] = 0;
    test_assert_failed(ctx, try_part(ctx, voxels, &p, 1, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "= 48 overflows global_dims 40", NULL);
    slab_part(&p, 16, 16, 2);
    p.ghost_hi[0] = 3; /* the voxels carry 2 */
    umbra_part_desc q = p;
    q.ghost_hi[0] = 2;
    {
        const uint32_t lo[3] = {14, 0, 0}, n[3] = {20, NY, NZ};
        float *box = sub_box(voxels, lo, n);
        umbra_volume_desc d;
        volume_desc(&d, box, n[0], n[1], n[2]);
        test_assert_failed(ctx, umbra_volume_create_part(ctx, &d, &p, &v),
                           UMBRA_ERROR_INVALID_ARGUMENT, "desc->dims[0] (x) 20",
                           "ghost_lo + size + ghost_hi = 21");
        free(box);
    }
    test_assert_failed(ctx, try_part(ctx, voxels, &q, 0, &v), UMBRA_ERROR_INVALID_ARGUMENT,
                       "value_range_given", NULL);

    /* A good part, then what it cannot render. */
    slab_part(&p, 16, 16, 1);
    assert_int_equal(try_part(ctx, voxels, &p, 1, &v), UMBRA_SUCCESS);
    umbra_transfer_function tf = scene_tf(ctx);
    scene s = make_scene(0, 0, 0, 0, 0);
    umbra_renderer r = scene_renderer(ctx, v, tf, &s);
    float *img = malloc((size_t)W * H * 4 * sizeof *img);
    assert_non_null(img);
    umbra_part_rect rect;
    assert_int_equal(umbra_renderer_render_part(r, W, H, &rect, img), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render(r, W, H, img), UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_render_part", NULL);
    /* Shading needs two ghost layers; this part carries one. */
    s.opts.shading = 1;
    assert_int_equal(umbra_renderer_set_options(r, &s.opts), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                       UMBRA_ERROR_INVALID_ARGUMENT, "ghost_lo[0] (x) is 1", "need 2");
    s.opts.shading = 0;
    s.opts.ground_plane = 1;
    assert_int_equal(umbra_renderer_set_options(r, &s.opts), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                       UMBRA_ERROR_UNSUPPORTED, "ground_plane", NULL);
    s.opts.ground_plane = 0;
    s.opts.mode = UMBRA_RENDER_MIP;
    assert_int_equal(umbra_renderer_set_options(r, &s.opts), UMBRA_SUCCESS);
    test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                       UMBRA_ERROR_UNSUPPORTED, "projection mode", NULL);
    s.opts.mode = UMBRA_RENDER_COMPOSITE;
    assert_int_equal(umbra_renderer_set_options(r, &s.opts), UMBRA_SUCCESS);
    const struct {
        umbra_shadow_technique t;
        const char *needle;
    } refused[] = {{UMBRA_SHADOW_REFERENCE, "technique reference does not split"},
                   {UMBRA_SHADOW_CONVOLUTION, "technique convolution does not split"},
                   {UMBRA_SHADOW_MOMENTS, "technique moments is refused on a part"},
                   {UMBRA_SHADOW_DEEP, "prefilter 5 is refused on a part"},
                   {UMBRA_SHADOW_DEEP, "max_nodes 3 is refused on a part"},
                   {UMBRA_SHADOW_DEEP, "a light step of 2 voxels is refused"}};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; ++i) {
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = refused[i].t;
        if (strstr(refused[i].needle, "prefilter"))
            sd.deep.prefilter = 5;
        if (strstr(refused[i].needle, "max_nodes"))
            sd.deep.max_nodes = 3;
        if (strstr(refused[i].needle, "light step"))
            sd.map.step = 2.0f;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                           UMBRA_ERROR_UNSUPPORTED, refused[i].needle, NULL);
    }
    /* The threshold map renders on a part only after the exchange, and again after a light
     * change. */
    {
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = UMBRA_SHADOW_THRESHOLD;
        sd.map.size = 64;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                           UMBRA_ERROR_INVALID_ARGUMENT, "import the depths", NULL);
        umbra_part_light_info li = {.struct_size = sizeof li};
        assert_int_equal(umbra_renderer_part_light_info(r, &li), UMBRA_SUCCESS);
        float *dep = malloc(li.depth_floats * sizeof *dep);
        float *st = malloc(li.tau_floats * sizeof *st);
        assert_true(dep && st);
        assert_int_equal(umbra_renderer_part_export_depths(r, dep), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_import_depths(r, dep), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render_part(r, W, H, &rect, img), UMBRA_SUCCESS);
        umbra_light l = test_directional_light(1.0f, -1.0f, 0.0f);
        assert_int_equal(umbra_renderer_set_light(r, &l), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                           UMBRA_ERROR_INVALID_ARGUMENT, "after the last light build", NULL);
        dep[5] = NAN;
        test_assert_failed(ctx, umbra_renderer_part_import_depths(r, dep),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 5 (5, 0)", "NaN");
        for (size_t i = 0; i < li.tau_floats; ++i)
            st[i] = 0.5f;
        st[2 * 7] = 1.5f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, st),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 7 (7, 0)", "[0, 1]");
        free(dep);
        free(st);
    }
    /* CSSM's state is an optical depth per channel: a negative one or NaN is refused naming the
     * texel. */
    {
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = UMBRA_SHADOW_CSSM;
        sd.map.size = 64;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                           UMBRA_ERROR_INVALID_ARGUMENT, "technique cssm: import the depths",
                           NULL);
        umbra_part_light_info li = {.struct_size = sizeof li};
        assert_int_equal(umbra_renderer_part_light_info(r, &li), UMBRA_SUCCESS);
        assert_int_equal(li.kind, UMBRA_PART_LIGHT_TAU_DEPTH);
        assert_int_equal(li.channels, 1);
        float *st = calloc(li.tau_floats, sizeof *st);
        assert_non_null(st);
        st[9] = -0.25f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, st),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 9 (9, 0)", "-0.25");
        st[9] = NAN;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, st),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 9 (9, 0)", "nan");
        free(st);
    }
    /* A frame to go on from with an opacity above 1 in the part's rectangle, naming the pixel. */
    {
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        float *frame = calloc((size_t)W * H * 4, sizeof *frame);
        assert_non_null(frame);
        assert_int_equal(umbra_renderer_part_rect(r, W, H, &rect), UMBRA_SUCCESS);
        assert_true(rect.width > 1 && rect.height > 1);
        char where[64];
        snprintf(where, sizeof where, "frame pixel (%u, %u)", rect.x + 1, rect.y + 1);
        frame[((size_t)(rect.y + 1) * W + rect.x + 1) * 4 + 3] = 1.5f;
        test_assert_failed(ctx, umbra_renderer_render_part_into(r, W, H, &rect, frame),
                           UMBRA_ERROR_INVALID_ARGUMENT, where, "opacity in [0, 1]");
        test_assert_failed(ctx, umbra_renderer_render_part_into(r, W, H, &rect, NULL),
                           UMBRA_ERROR_INVALID_ARGUMENT, "frame is NULL", NULL);
        free(frame);
    }
    /* The deep map renders on a part only after its pieces are imported; pieces that do not
     * add up, or hold a NaN depth, are refused. */
    {
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = UMBRA_SHADOW_DEEP;
        sd.map.size = 32;
        assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                           UMBRA_ERROR_INVALID_ARGUMENT, "import the pieces", NULL);
        umbra_part_light_info li = {.struct_size = sizeof li};
        assert_int_equal(umbra_renderer_part_light_info(r, &li), UMBRA_SUCCESS);
        assert_int_equal(li.kind, UMBRA_PART_LIGHT_TAU);
        /* Its state is the whole march's (kernels/techniques/deep_shared.h): with one light
         * channel 13 floats a texel, a node 2. A bad value is refused naming the texel, the
         * field and the value (the table in host/part_light.c, shared with threshold and
         * CSSM): a visibility above 1, a count that is not an integer, a NaN depth. */
        assert_int_equal(li.channels, DEEP_PART_STATE_FLOATS(1));
        assert_int_equal(li.node_floats, 2);
        const size_t per = li.channels;
        float *vis = malloc(li.tau_floats * sizeof *vis);
        assert_non_null(vis);
        assert_int_equal(umbra_renderer_part_import_transmittance(r, NULL), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_export_transmittance(r, vis), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_import_transmittance(r, vis), UMBRA_SUCCESS);
        vis[3 * per] = 1.5f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 3 (3, 0): visibility 1.5",
                           "[0, 1]");
        vis[3 * per] = 1.0f;
        const float points5 = vis[5 * per + 9];
        vis[5 * per + 9] = 2.5f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT,
                           "texel 5 (5, 0): points since the origin 2.5", "be an integer");
        vis[5 * per + 9] = points5;
        const float depth6 = vis[6 * per + 1];
        vis[6 * per + 1] = NAN;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 6 (6, 0): fit origin depth nan",
                           NULL);
        /* Fields that each lie in range but no march leaves together (deep_state_check): points
         * fed before the origin is emitted, an origin visibility below 1 before it is, an empty
         * window of slopes. Offsets with one channel: v0 2, lo 7, hi 8, points 9, emitted 10. */
        vis[6 * per + 1] = depth6;
        float *t4 = vis + 4 * per;
        t4[10] = 0.0f;
        t4[9] = 3.0f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 4 (4, 0): points since",
                           "not emitted"); /* the texel's count: no channel named */
        t4[9] = 0.0f;
        t4[2] = 0.5f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT, "texel 4 (4, 0), channel 0: fit origin",
                           "origin visibility 0.5");
        t4[10] = 1.0f;
        t4[9] = 1.0f;
        t4[7] = 0.25f;
        t4[8] = -0.25f;
        test_assert_failed(ctx, umbra_renderer_part_import_transmittance(r, vis),
                           UMBRA_ERROR_INVALID_ARGUMENT, "lowest slope must not exceed",
                           "slopes [0.25, -0.25]");
        t4[8] = 0.25f; /* one slope: a consistent state, taken */
        assert_int_equal(umbra_renderer_part_import_transmittance(r, vis), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_import_transmittance(r, NULL), UMBRA_SUCCESS);
        free(vis);
        const size_t texels = (size_t)li.map_size * li.map_size, nf = li.node_floats;
        uint32_t *counts = malloc(texels * sizeof *counts);
        size_t k = 0;
        assert_non_null(counts);
        assert_int_equal(umbra_renderer_part_export_deep(r, counts, NULL, &k), UMBRA_SUCCESS);
        assert_true(k > 0);
        float *nodes = malloc(k * nf * sizeof *nodes);
        assert_non_null(nodes);
        size_t small = k - 1;
        test_assert_failed(ctx, umbra_renderer_part_export_deep(r, counts, nodes, &small),
                           UMBRA_ERROR_INVALID_ARGUMENT, "nodes holds", NULL);
        assert_int_equal(umbra_renderer_part_export_deep(r, counts, nodes, &k), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_part_import_deep(r, 1, counts, nodes, k + 1),
                           UMBRA_ERROR_INVALID_ARGUMENT, "add up to", NULL);
        const float depth = nodes[0];
        nodes[0] = NAN;
        test_assert_failed(ctx, umbra_renderer_part_import_deep(r, 1, counts, nodes, k),
                           UMBRA_ERROR_INVALID_ARGUMENT, "node 0: depth", NULL);
        nodes[0] = depth;
        assert_int_equal(umbra_renderer_part_import_deep(r, 1, counts, nodes, k), UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_render_part(r, W, H, &rect, img), UMBRA_SUCCESS);
        test_assert_failed(ctx, umbra_renderer_part_import_depths(r, img),
                           UMBRA_ERROR_INVALID_ARGUMENT, "not depths", NULL);
        free(counts);
        free(nodes);
    }
    /* A whole volume is not a part. */
    umbra_renderer_release(r);
    umbra_volume w = test_volume(ctx, NX, NY, NZ, voxels);
    r = scene_renderer(ctx, w, tf, &s);
    test_assert_failed(ctx, umbra_renderer_render_part(r, W, H, &rect, img),
                       UMBRA_ERROR_INVALID_ARGUMENT, "not a part", NULL);
    umbra_part_desc whole;
    assert_int_equal(umbra_volume_get_part(w, &whole), UMBRA_SUCCESS);
    assert_int_equal(whole.size[0], NX);
    assert_int_equal(whole.offset[0], 0);
    umbra_renderer_release(r);
    umbra_volume_release(w);
    umbra_volume_release(v);
    umbra_transfer_function_release(tf);
    free(img);
    free(voxels);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_host_helpers),
        cmocka_unit_test(test_bad_input_refused),
        cmocka_unit_test(test_splits_match_one_device),
        cmocka_unit_test(test_termination_bound),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
