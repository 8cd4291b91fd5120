// SPDX-License-Identifier: Apache-2.0
/* tests/test_part.c: a volume split into parts (umbra/part.h, host/part.c, host/part_render.c),
 * in one process, against the single-device render of the whole volume:
 *  - the analytic volume below split 2x1x1, 2x2x1, 2x2x2 and 2x1x1 with an empty part; each part
 *    a part volume with the ghost layers umbra_part_ghost_needed asks for, rendered with
 *    umbra_renderer_render_part, the partial images composited in the order
 *    umbra_part_view_order gives (umbra_part_composite) and put over the background: the image
 *    equals the whole volume's within PART_BOUND (float rounding of the over operator against
 *    one ray's running sum), for a perspective camera looking obliquely and an orthographic one
 *    along an axis, jitter on and off, shading on and off, grey and coloured light, directional
 *    along an axis and oblique, a point light inside and outside the box;
 *  - with early ray termination (0.9) the difference is at most 1 - termination;
 *  - the threshold map and CSSM (grey and coloured transmission) on parts: the march state
 *    passed on in light order (umbra_part_visibility_order from the light), the depths reduced
 *    by umbra_part_minimum: the map equals one device's depth for depth (0 differing), the image
 *    within PART_BOUND;
 *  - the same parts rendered one after another into one frame, each going on from the
 *    accumulation of the parts in front (umbra_renderer_render_part_into): one device's image bit
 *    for bit (memcmp) for none (termination 1 and 0.9), the threshold map and CSSM;
 *  - the deep map on parts (2x1x1, 2x2x1, 2x1x1 with an empty part; a light along z, an oblique
 *    one, a point light inside and outside, grey and coloured light, a smooth and a sharp
 *    transfer function): the visibility passed on in light order, every part's pieces of the
 *    map exported and merged into every part: the image within DEEP_EXACT_BOUND of one device's
 *    at epsilon 0 and DEEP_EPS_BOUND at epsilon 0.02, and as close to the exact reference;
 *  - the host helpers: the visibility order of a 2x2x2 grid from a point and along a direction,
 *    the over operator, the product and minimum;
 *  - bad input, refused naming the value, the context usable after: an offset off the brick
 *    grid, a part that overflows the global grid, dims that do not match, no given value range,
 *    too few ghost layers, the techniques that do not split (reference, convolution) and those
 *    not yet part-aware, the deep map's options that do not split (prefilter 5, a node budget,
 *    a light step above a voxel), the ground plane, a projection mode, a part rendered with
 *    umbra_renderer_render, a threshold part rendered before its depths were imported or after
 *    the light changed, a NaN depth and a transmittance above 1 (each naming the texel), CSSM's
 *    negative or NaN optical depth (naming the texel), a front opacity above 1 (naming the
 *    pixel).
 * Usage: test_part [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "techniques/deep.h"
#include "techniques/maps.h"
#include "test_util.h"

enum { NX = 40, NY = 36, NZ = 44, BS = 8, W = 48, H = 40 };

/* The largest difference measured on PoCL was 3.6e-7 (docs/distributed.md): float rounding of
 * the over operator against one ray's running sum. */
#define PART_BOUND 1e-6f

static float *scene_voxels(void)
{
    float *v = malloc((size_t)NX * NY * NZ * sizeof *v);
    assert_non_null(v);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x) {
                float dx = (x - 17.0f) / 10.0f, dy = (y - 18.0f) / 9.0f, dz = (z - 20.0f) / 12.0f;
                float ex = (x - 27.0f) / 6.0f, ey = (y - 11.0f) / 7.0f, ez = (z - 31.0f) / 8.0f;
                float b = expf(-(dx * dx + dy * dy + dz * dz)) +
                          0.8f * expf(-(ex * ex + ey * ey + ez * ez));
                float s = b + 0.15f * sinf(0.7f * x + 0.45f * z) * cosf(0.5f * y - 0.3f * z);
                v[((size_t)z * NY + y) * NX + x] = s < 0.0f ? 0.0f : (s > 1.0f ? 1.0f : s);
            }
    return v;
}

static umbra_transfer_function scene_tf(umbra_context ctx)
{
    const umbra_tf_point pts[] = {{0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
                                  {0.25f, {0.9f, 0.5f, 0.2f, 0.0f}},
                                  {0.5f, {0.3f, 0.8f, 0.4f, 0.08f}},
                                  {1.0f, {1.0f, 1.0f, 0.9f, 0.3f}}};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf),
                     UMBRA_SUCCESS);
    return tf;
}

static const char *take_message(umbra_context ctx)
{
    const char *m = NULL;
    umbra_context_take_error(ctx, &m);
    return m ? m : "(no message)";
}

static void volume_desc(umbra_volume_desc *d, const float *data, uint32_t nx, uint32_t ny,
                        uint32_t nz)
{
    umbra_volume_desc_init(d);
    d->data = data;
    d->type = UMBRA_FLOAT32;
    d->dims[0] = nx;
    d->dims[1] = ny;
    d->dims[2] = nz;
    d->value_range_given = 1;
    d->value_min = 0.0f;
    d->value_max = 1.0f;
    d->brick_size = BS;
}

/* A scene: camera, light, options. */
typedef struct scene {
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc opts;
} scene;

static scene make_scene(int ortho, int jitter, int shading, int point, int colored)
{
    scene s;
    const float diag = sqrtf((float)(NX * NX + NY * NY + NZ * NZ));
    const float dir[3] = {0.6f, 0.45f, 1.0f};
    s.camera = umbra_camera_orbit(dir, diag, 30.0f);
    if (ortho) {
        s.camera.projection = UMBRA_ORTHOGRAPHIC;
        s.camera.eye[0] = 0.0f;
        s.camera.eye[1] = 0.0f;
        s.camera.eye[2] = 2.0f * diag;
        s.camera.ortho_height = 1.1f * diag;
    }
    s.light = point ? test_point_light(3.0f, 5.0f, -2.0f)
                    : test_directional_light(0.3f, -1.0f, 0.4f);
    if (point == 2)
        s.light = test_point_light(80.0f, 60.0f, 90.0f);
    if (!point && ortho)
        s.light = test_directional_light(0.0f, 0.0f, -1.0f);
    if (colored) {
        s.light.color[0] = 1.0f;
        s.light.color[1] = 0.7f;
        s.light.color[2] = 0.4f;
    }
    umbra_render_desc_init(&s.opts);
    s.opts.jitter = jitter;
    s.opts.seed = 7u;
    /* Orthographic along z without jitter: a step of one voxel puts samples on the cut planes
     * z = 16 (and on the box's faces), where the half-open intervals decide. */
    s.opts.step = ortho && !jitter ? 1.0f : 0.7f;
    s.opts.shading = shading;
    s.opts.termination = 1.0f;
    s.opts.background[0] = 0.1f;
    s.opts.background[1] = 0.2f;
    s.opts.background[2] = 0.3f;
    s.opts.background[3] = 1.0f;
    return s;
}

static umbra_renderer scene_renderer(umbra_context ctx, umbra_volume v, umbra_transfer_function tf,
                                     const scene *s)
{
    return test_renderer(ctx, v, tf, &s->camera, &s->light, &s->opts);
}

static float *render_whole(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                           const scene *s)
{
    umbra_volume_desc d;
    volume_desc(&d, voxels, NX, NY, NZ);
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    umbra_renderer r = scene_renderer(ctx, v, tf, s);
    float *img = test_render_image(r, W, H);
    umbra_renderer_release(r);
    umbra_volume_release(v);
    return img;
}

/* The voxels of [lo, lo + n) per axis of the global grid; voxels past the grid (a part that
 * overflows it, for the refusal tests) are 0. */
static float *sub_box(const float *voxels, const uint32_t lo[3], const uint32_t n[3])
{
    float *b = calloc((size_t)n[0] * n[1] * n[2], sizeof *b);
    assert_non_null(b);
    const uint32_t nx = lo[0] >= NX ? 0 : (n[0] < NX - lo[0] ? n[0] : NX - lo[0]);
    for (uint32_t z = 0; z < n[2] && lo[2] + z < NZ; ++z)
        for (uint32_t y = 0; y < n[1] && lo[1] + y < NY; ++y)
            memcpy(b + ((size_t)z * n[1] + y) * n[0],
                   voxels + ((size_t)(lo[2] + z) * NY + lo[1] + y) * NX + lo[0],
                   nx * sizeof *b);
    return b;
}

/* The parts of a split: cuts[a] lists the inner cut positions along axis a (ncuts[a] of them);
 * extra_empty adds an empty part. */
static uint32_t make_parts(const uint32_t *const cuts[3], const uint32_t ncuts[3], int extra_empty,
                           uint32_t ghost, umbra_part_desc *parts)
{
    const uint32_t g[3] = {NX, NY, NZ};
    uint32_t n = 0;
    for (uint32_t k = 0; k <= ncuts[2]; ++k)
        for (uint32_t j = 0; j <= ncuts[1]; ++j)
            for (uint32_t i = 0; i <= ncuts[0]; ++i) {
                const uint32_t idx[3] = {i, j, k};
                umbra_part_desc *p = &parts[n++];
                umbra_part_desc_init(p);
                for (int a = 0; a < 3; ++a) {
                    const uint32_t lo = idx[a] == 0 ? 0 : cuts[a][idx[a] - 1];
                    const uint32_t hi = idx[a] == ncuts[a] ? g[a] : cuts[a][idx[a]];
                    p->global_dims[a] = g[a];
                    p->offset[a] = lo;
                    p->size[a] = hi - lo;
                    p->ghost_lo[a] = lo < ghost ? lo : ghost;
                    p->ghost_hi[a] = g[a] - hi < ghost ? g[a] - hi : ghost;
                }
            }
    if (extra_empty) {
        umbra_part_desc *p = &parts[n++];
        umbra_part_desc_init(p);
        for (int a = 0; a < 3; ++a)
            p->global_dims[a] = g[a];
    }
    return n;
}

/* Counts the floats of a and b whose bits differ. */
static size_t bits_differing(const float *a, const float *b, size_t count)
{
    size_t n = 0;
    for (size_t i = 0; i < count; ++i)
        n += memcmp(&a[i], &b[i], sizeof a[i]) != 0;
    return n;
}

/* Renders every part in view order into one frame, each going on from the accumulation of the
 * parts in front (umbra_renderer_render_part_into), and puts the background under it. */
static float *render_into_frame(const scene *s, umbra_renderer *rs, const uint32_t *order,
                                uint32_t n)
{
    float *frame = calloc((size_t)W * H * 4, sizeof *frame);
    assert_non_null(frame);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_part_rect rect, want;
        assert_int_equal(umbra_renderer_render_part_into(rs[order[i]], W, H, &rect, frame),
                         UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_rect(rs[order[i]], W, H, &want), UMBRA_SUCCESS);
        assert_memory_equal(&rect, &want, sizeof rect);
    }
    umbra_part_background(frame, (size_t)W * H, s->opts.background);
    return frame;
}

/* Renders every part, composites in view order, puts the background under it; *seq gets the
 * frame rendered part after part into one accumulation (render_into_frame). */
static float *render_parts(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                           const scene *s, const umbra_part_desc *parts, uint32_t n, float **seq)
{
    float *frame = calloc((size_t)W * H * 4, sizeof *frame);
    float *part_img = malloc((size_t)W * H * 4 * sizeof *part_img);
    umbra_part_rect *rects = calloc(n, sizeof *rects);
    float **imgs = calloc(n, sizeof *imgs);
    uint32_t *order = calloc(n, sizeof *order);
    umbra_renderer *rs = calloc(n, sizeof *rs);
    umbra_volume *vs = calloc(n, sizeof *vs);
    assert_true(frame && part_img && rects && imgs && order && rs && vs);
    umbra_volume_info info;
    memset(&info, 0, sizeof info);
    for (uint32_t i = 0; i < n; ++i) {
        const umbra_part_desc *p = &parts[i];
        const int empty = p->size[0] == 0;
        uint32_t lo[3], dims[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = p->offset[a] - p->ghost_lo[a];
            dims[a] = empty ? 1 : p->ghost_lo[a] + p->size[a] + p->ghost_hi[a];
        }
        float *box = sub_box(voxels, lo, dims);
        umbra_volume_desc d;
        volume_desc(&d, box, dims[0], dims[1], dims[2]);
        umbra_volume v = NULL;
        umbra_status st = umbra_volume_create_part(ctx, &d, p, &v);
        if (st != UMBRA_SUCCESS)
            fail_msg("part %u: %s", i, take_message(ctx));
        free(box);
        assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
        umbra_renderer r = scene_renderer(ctx, v, tf, s);
        st = umbra_renderer_render_part(r, W, H, &rects[i], part_img);
        if (st != UMBRA_SUCCESS)
            fail_msg("part %u: %s", i, take_message(ctx));
        umbra_part_rect again;
        assert_int_equal(umbra_renderer_part_rect(r, W, H, &again), UMBRA_SUCCESS);
        assert_memory_equal(&again, &rects[i], sizeof again);
        if (empty)
            assert_int_equal(rects[i].width * rects[i].height, 0);
        imgs[i] = malloc((size_t)rects[i].width * rects[i].height * 4 * sizeof(float) + 1);
        memcpy(imgs[i], part_img, (size_t)rects[i].width * rects[i].height * 4 * sizeof(float));
        rs[i] = r;
        vs[i] = v;
    }
    assert_int_equal(umbra_part_view_order(parts, n, &info, &s->camera, order), UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i)
        assert_int_equal(umbra_part_composite(frame, W, H, imgs[order[i]], &rects[order[i]]),
                         UMBRA_SUCCESS);
    umbra_part_background(frame, (size_t)W * H, s->opts.background);
    *seq = render_into_frame(s, rs, order, n);
    for (uint32_t i = 0; i < n; ++i) {
        free(imgs[i]);
        umbra_renderer_release(rs[i]);
        umbra_volume_release(vs[i]);
    }
    free(rs);
    free(vs);
    free(imgs);
    free(rects);
    free(order);
    free(part_img);
    return frame;
}

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

static const uint32_t CX[] = {16}, CY[] = {24}, CZ[] = {16};

/* The threshold map or CSSM on parts: each part's march goes on from the state the part before
 * it on the light's rays left (imported, exported, in light order), the depths reduce by a
 * minimum, and every part renders with the minimum. Returns the image's largest difference and
 * counts the depths that differ from one device's map in *differing. */
static float compare_map(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                         const scene *s, const uint32_t ncuts[3], int extra_empty,
                         umbra_shadow_technique technique, size_t *differing,
                         size_t *seq_differing)
{
    const uint32_t *const cuts[3] = {CX, CY, CZ};
    umbra_part_desc parts[16];
    const uint32_t n = make_parts(cuts, ncuts, extra_empty, umbra_part_ghost_needed(&s->opts),
                                  parts);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = technique;
    sd.map.size = 96;
    /* CSSM simulates three channels with coloured transmission (the scene's light transfer
     * function is not grey), one otherwise; the threshold map one depth and a state of two. */
    const int cssm = technique == UMBRA_SHADOW_CSSM;
    const uint32_t ch = cssm && s->opts.transmission == UMBRA_TRANSMISSION_COLORED ? 3u : 1u;

    /* One device. */
    umbra_volume_desc d;
    volume_desc(&d, voxels, NX, NY, NZ);
    umbra_volume whole_v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &whole_v), UMBRA_SUCCESS);
    umbra_renderer whole_r = scene_renderer(ctx, whole_v, tf, s);
    assert_int_equal(umbra_renderer_set_shadow(whole_r, &sd), UMBRA_SUCCESS);
    float *whole = test_render_image(whole_r, W, H);
    const size_t texels = (size_t)sd.map.size * sd.map.size, values = texels * ch;
    float *whole_map = malloc(values * sizeof *whole_map);
    assert_non_null(whole_map);
    assert_int_equal(umbra__map_read(whole_r, whole_map, values * sizeof *whole_map),
                     UMBRA_SUCCESS);

    /* The parts. */
    umbra_volume vols[16];
    umbra_renderer rs[16];
    umbra_volume_info info;
    for (uint32_t i = 0; i < n; ++i) {
        const umbra_part_desc *p = &parts[i];
        const int empty = p->size[0] == 0;
        uint32_t lo[3], dims[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = p->offset[a] - p->ghost_lo[a];
            dims[a] = empty ? 1 : p->ghost_lo[a] + p->size[a] + p->ghost_hi[a];
        }
        float *box = sub_box(voxels, lo, dims);
        volume_desc(&d, box, dims[0], dims[1], dims[2]);
        assert_int_equal(umbra_volume_create_part(ctx, &d, p, &vols[i]), UMBRA_SUCCESS);
        free(box);
        assert_int_equal(umbra_volume_get_info(vols[i], &info), UMBRA_SUCCESS);
        rs[i] = scene_renderer(ctx, vols[i], tf, s);
        assert_int_equal(umbra_renderer_set_shadow(rs[i], &sd), UMBRA_SUCCESS);
    }
    umbra_part_light_info li = {.struct_size = sizeof li};
    assert_int_equal(umbra_renderer_part_light_info(rs[0], &li), UMBRA_SUCCESS);
    assert_int_equal(li.kind, UMBRA_PART_LIGHT_TAU_DEPTH);
    assert_int_equal(li.map_size, sd.map.size);
    assert_int_equal(li.channels, cssm ? ch : 2u);
    assert_int_equal(li.depth_channels, ch);
    assert_int_equal(li.depth_floats, values);
    float *state = malloc(li.tau_floats * sizeof *state);
    float *depth = malloc(li.depth_floats * sizeof *depth);
    float *acc = malloc(li.depth_floats * sizeof *acc);
    uint32_t order[16];
    assert_true(state && depth && acc);
    const int point = s->light.type == UMBRA_LIGHT_POINT;
    assert_int_equal(umbra_part_visibility_order(parts, n, &info,
                                                 point ? s->light.position : s->light.direction,
                                                 point, order),
                     UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer r = rs[order[i]];
        assert_int_equal(umbra_renderer_part_import_transmittance(r, i ? state : NULL),
                         UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_export_transmittance(r, state), UMBRA_SUCCESS);
    }
    for (size_t t = 0; t < li.depth_floats; ++t)
        acc[t] = INFINITY;
    for (uint32_t i = 0; i < n; ++i) {
        assert_int_equal(umbra_renderer_part_export_depths(rs[i], depth), UMBRA_SUCCESS);
        umbra_part_minimum(acc, depth, li.depth_floats);
    }
    *differing = 0;
    for (size_t t = 0; t < values; ++t)
        *differing += memcmp(&acc[t], &whole_map[t], sizeof acc[t]) != 0;
    float *frame = calloc((size_t)W * H * 4, sizeof *frame);
    float *img = malloc((size_t)W * H * 4 * sizeof *img);
    assert_true(frame && img);
    assert_int_equal(umbra_part_view_order(parts, n, &info, &s->camera, order), UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer r = rs[order[i]];
        umbra_part_rect rect;
        assert_int_equal(umbra_renderer_part_import_depths(r, acc), UMBRA_SUCCESS);
        if (umbra_renderer_render_part(r, W, H, &rect, img) != UMBRA_SUCCESS)
            fail_msg("part %u: %s", order[i], take_message(ctx));
        assert_int_equal(umbra_part_composite(frame, W, H, img, &rect), UMBRA_SUCCESS);
    }
    umbra_part_background(frame, (size_t)W * H, s->opts.background);
    const float diff = test_max_diff(whole, frame, (size_t)W * H * 4, NULL);
    float *seq = render_into_frame(s, rs, order, n);
    *seq_differing = bits_differing(whole, seq, (size_t)W * H * 4);
    free(seq);
    /* The map holds shadow: some texel has a depth; with three channels, some texel's channels
     * stopped their photons at different depths (the colour is simulated, not one channel
     * copied). */
    size_t hit = 0, coloured = 0;
    for (size_t t = 0; t < values; ++t)
        hit += isfinite(whole_map[t]) && whole_map[t] < 1.5f;
    for (size_t t = 0; ch == 3 && t < texels; ++t)
        coloured += whole_map[3 * t] != whole_map[3 * t + 1] ||
                    whole_map[3 * t + 1] != whole_map[3 * t + 2];
    assert_true(hit > 10);
    assert_true(ch == 1 || coloured > 10);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer_release(rs[i]);
        umbra_volume_release(vols[i]);
    }
    umbra_renderer_release(whole_r);
    umbra_volume_release(whole_v);
    free(whole);
    free(whole_map);
    free(state);
    free(depth);
    free(acc);
    free(frame);
    free(img);
    return diff;
}

/* A transfer function with a sharp step (opacity 0 to 0.7 between 0.40 and 0.42): isosurface
 * shadows whose edges cross the shared faces. */
static umbra_transfer_function sharp_tf(umbra_context ctx)
{
    const umbra_tf_point pts[] = {{0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
                                  {0.40f, {0.9f, 0.5f, 0.2f, 0.0f}},
                                  {0.42f, {0.8f, 0.8f, 0.7f, 0.7f}},
                                  {1.0f, {1.0f, 1.0f, 0.9f, 0.8f}}};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf),
                     UMBRA_SUCCESS);
    return tf;
}

typedef struct deep_result {
    float max_diff, rmse;     /* parts' image against one device's deep image */
    float err_one, err_parts; /* each against the exact reference (largest difference) */
    size_t nodes_one, nodes_parts;
} deep_result;

static float rmse(const float *a, const float *b, size_t count)
{
    double sum = 0.0;
    for (size_t i = 0; i < count; ++i)
        sum += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return (float)sqrt(sum / (double)count);
}

/* The deep map on parts: the visibility passed on in light order, each part's pieces exported,
 * all pieces imported into every part, every part rendered. */
static deep_result compare_deep(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                                const scene *s, const uint32_t ncuts[3], int extra_empty,
                                float epsilon)
{
    const uint32_t *const cuts[3] = {CX, CY, CZ};
    umbra_part_desc parts[16];
    const uint32_t n = make_parts(cuts, ncuts, extra_empty, umbra_part_ghost_needed(&s->opts),
                                  parts);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = UMBRA_SHADOW_DEEP;
    sd.map.size = 96;
    sd.deep.epsilon = epsilon;
    deep_result res;
    memset(&res, 0, sizeof res);

    umbra_volume_desc d;
    volume_desc(&d, voxels, NX, NY, NZ);
    umbra_volume whole_v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &whole_v), UMBRA_SUCCESS);
    umbra_renderer whole_r = scene_renderer(ctx, whole_v, tf, s);
    assert_int_equal(umbra_renderer_set_shadow(whole_r, &sd), UMBRA_SUCCESS);
    float *whole = test_render_image(whole_r, W, H);
    umbra__deep_info di;
    assert_int_equal(umbra__deep_get_info(whole_r, &di), UMBRA_SUCCESS);
    {
        const size_t texels = (size_t)sd.map.size * sd.map.size;
        uint32_t *c = malloc(texels * sizeof *c);
        assert_non_null(c);
        assert_int_equal(umbra__deep_read(whole_r, NULL, NULL, c, NULL), UMBRA_SUCCESS);
        for (size_t t = 0; t < texels; ++t)
            res.nodes_one += c[t];
        free(c);
    }
    umbra_shadow_desc ref;
    umbra_shadow_desc_init(&ref);
    ref.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(whole_r, &ref), UMBRA_SUCCESS);
    float *exact = test_render_image(whole_r, W, H);

    umbra_volume vols[16];
    umbra_renderer rs[16];
    umbra_volume_info info;
    for (uint32_t i = 0; i < n; ++i) {
        const umbra_part_desc *p = &parts[i];
        const int empty = p->size[0] == 0;
        uint32_t lo[3], dims[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = p->offset[a] - p->ghost_lo[a];
            dims[a] = empty ? 1 : p->ghost_lo[a] + p->size[a] + p->ghost_hi[a];
        }
        float *box = sub_box(voxels, lo, dims);
        volume_desc(&d, box, dims[0], dims[1], dims[2]);
        assert_int_equal(umbra_volume_create_part(ctx, &d, p, &vols[i]), UMBRA_SUCCESS);
        free(box);
        assert_int_equal(umbra_volume_get_info(vols[i], &info), UMBRA_SUCCESS);
        rs[i] = scene_renderer(ctx, vols[i], tf, s);
        assert_int_equal(umbra_renderer_set_shadow(rs[i], &sd), UMBRA_SUCCESS);
    }
    umbra_part_light_info li = {.struct_size = sizeof li};
    assert_int_equal(umbra_renderer_part_light_info(rs[0], &li), UMBRA_SUCCESS);
    assert_int_equal(li.kind, UMBRA_PART_LIGHT_TAU);
    assert_int_equal(li.map_size, sd.map.size);
    assert_int_equal(li.depth_floats, 0);
    const size_t texels = (size_t)li.map_size * li.map_size, nf = 1 + li.channels;
    float *state = malloc(li.tau_floats * sizeof *state);
    uint32_t *counts = malloc(n * texels * sizeof *counts);
    uint32_t order[16];
    assert_true(state && counts);
    const int point = s->light.type == UMBRA_LIGHT_POINT;
    assert_int_equal(umbra_part_visibility_order(parts, n, &info,
                                                 point ? s->light.position : s->light.direction,
                                                 point, order),
                     UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer r = rs[order[i]];
        assert_int_equal(umbra_renderer_part_import_transmittance(r, i ? state : NULL),
                         UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_export_transmittance(r, state), UMBRA_SUCCESS);
    }
    /* The pieces: counts first, then the nodes, one part after another. */
    size_t total = 0, at[17];
    for (uint32_t i = 0; i < n; ++i) {
        size_t k = 0;
        assert_int_equal(umbra_renderer_part_export_deep(rs[i], counts + i * texels, NULL, &k),
                         UMBRA_SUCCESS);
        at[i] = total;
        total += k;
    }
    at[n] = total;
    res.nodes_parts = total;
    float *nodes = malloc((total ? total : 1) * nf * sizeof *nodes);
    assert_non_null(nodes);
    for (uint32_t i = 0; i < n; ++i) {
        size_t k = at[i + 1] - at[i];
        assert_int_equal(umbra_renderer_part_export_deep(rs[i], counts + i * texels,
                                                         nodes + at[i] * nf, &k),
                         UMBRA_SUCCESS);
        assert_int_equal(k, at[i + 1] - at[i]);
    }
    float *frame = calloc((size_t)W * H * 4, sizeof *frame);
    float *img = malloc((size_t)W * H * 4 * sizeof *img);
    assert_true(frame && img);
    assert_int_equal(umbra_part_view_order(parts, n, &info, &s->camera, order), UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer r = rs[order[i]];
        umbra_part_rect rect;
        assert_int_equal(umbra_renderer_part_import_deep(r, n, counts, nodes, total),
                         UMBRA_SUCCESS);
        if (umbra_renderer_render_part(r, W, H, &rect, img) != UMBRA_SUCCESS)
            fail_msg("part %u: %s", order[i], take_message(ctx));
        assert_int_equal(umbra_part_composite(frame, W, H, img, &rect), UMBRA_SUCCESS);
    }
    umbra_part_background(frame, (size_t)W * H, s->opts.background);
    res.max_diff = test_max_diff(whole, frame, (size_t)W * H * 4, NULL);
    res.rmse = rmse(whole, frame, (size_t)W * H * 4);
    res.err_one = test_max_diff(exact, whole, (size_t)W * H * 4, NULL);
    res.err_parts = test_max_diff(exact, frame, (size_t)W * H * 4, NULL);
    /* The map holds shadow: the deep image is not the unshadowed one. */
    assert_true(res.nodes_one > 100);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer_release(rs[i]);
        umbra_volume_release(vols[i]);
    }
    umbra_renderer_release(whole_r);
    umbra_volume_release(whole_v);
    free(whole);
    free(exact);
    free(state);
    free(counts);
    free(nodes);
    free(frame);
    free(img);
    return res;
}

/* The bounds the deep map on parts keeps against one device's deep render (docs/distributed.md):
 * at epsilon 0 (every march point that bends the function a node, so the parts' merged
 * function is one device's) float rounding: DEEP_EXACT_BOUND (measured on PoCL: 1.8e-7). At
 * epsilon 0.02 each part's compression restarts at its first segment, and both functions lie
 * within epsilon of the same march, so a visibility differs by at most 2 epsilon; the image
 * differed by at most 5.3e-3 (RMSE at most 2.2e-4) over the cases below, and the test holds it
 * to DEEP_EPS_BOUND = epsilon / 2. */
#define DEEP_EXACT_BOUND 1e-5f
#define DEEP_EPS_BOUND 0.01f

static void test_deep_splits_match_one_device(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_transfer_function tfs[2] = {scene_tf(ctx), sharp_tf(ctx)};
    const uint32_t split_2x1x1[3] = {1, 0, 0}, split_2x2x1[3] = {1, 1, 0};
    const uint32_t *splits[] = {split_2x1x1, split_2x2x1, split_2x1x1};
    /* ortho (axis-aligned light along z), jitter, shading, point light (1 inside, 2 outside),
     * coloured light */
    const int cases[][5] = {{1, 0, 0, 0, 0}, {0, 0, 0, 0, 0}, {0, 1, 1, 1, 1}, {0, 0, 1, 2, 0}};
    const float eps[2] = {0.0f, 0.02f};
    float worst[2] = {0.0f, 0.0f};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const scene s = make_scene(cases[c][0], cases[c][1], cases[c][2], cases[c][3], cases[c][4]);
        for (int t = 0; t < 2; ++t)
            for (int k = 0; k < 3; ++k)
                for (int e = 0; e < 2; ++e) {
                    deep_result q = compare_deep(ctx, voxels, tfs[t], &s, splits[k], k == 2,
                                                 eps[e]);
                    printf("deep case %zu tf %d split %d eps %g: max |diff| %.3g rmse %.3g; vs "
                           "reference one %.3g parts %.3g; nodes one %zu parts %zu\n",
                           c, t, k, (double)eps[e], (double)q.max_diff, (double)q.rmse,
                           (double)q.err_one, (double)q.err_parts, q.nodes_one, q.nodes_parts);
                    if (q.max_diff > worst[e])
                        worst[e] = q.max_diff;
                    assert_true(q.max_diff <= (e ? DEEP_EPS_BOUND : DEEP_EXACT_BOUND));
                    /* The parts' map is as accurate as one device's. */
                    assert_true(q.err_parts <= q.err_one + (e ? DEEP_EPS_BOUND
                                                              : DEEP_EXACT_BOUND));
                }
    }
    printf("deep: largest difference %.3g at epsilon 0 (bound %.3g), %.3g at 0.02 (bound %.3g)\n",
           (double)worst[0], (double)DEEP_EXACT_BOUND, (double)worst[1], (double)DEEP_EPS_BOUND);
    umbra_transfer_function_release(tfs[0]);
    umbra_transfer_function_release(tfs[1]);
    free(voxels);
}

static void test_threshold_splits_match_one_device(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_transfer_function tf = scene_tf(ctx);
    const uint32_t split_2x1x1[3] = {1, 0, 0}, split_2x2x1[3] = {1, 1, 0},
                   split_2x2x2[3] = {1, 1, 1};
    const uint32_t *splits[] = {split_2x1x1, split_2x2x1, split_2x2x2, split_2x1x1};
    const int cases[][5] = {{0, 0, 0, 0, 0}, {0, 1, 1, 1, 1}, {1, 0, 1, 0, 1}, {1, 1, 0, 2, 0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const scene s = make_scene(cases[c][0], cases[c][1], cases[c][2], cases[c][3], cases[c][4]);
        for (int k = 0; k < 4; ++k) {
            size_t differing = 0, seq = 0;
            float d = compare_map(ctx, voxels, tf, &s, splits[k], k == 3, UMBRA_SHADOW_THRESHOLD,
                                  &differing, &seq);
            printf("threshold case %zu split %d: max |diff| %.3g, %zu differing depths; part "
                   "after part: %zu floats differ\n", c, k, (double)d, differing, seq);
            assert_int_equal(differing, 0);
            assert_true(d <= PART_BOUND);
            assert_int_equal(seq, 0);
        }
    }
    umbra_transfer_function_release(tf);
    free(voxels);
}

/* CSSM on parts: the optical depth per light channel passed on in light order, the photons an
 * earlier part stopped skipped, the stored depths reduced by a minimum: the map equals one
 * device's depth for depth, the image within PART_BOUND. Grey and coloured transmission (three
 * channels), a directional light along an axis and oblique, a point light inside and outside. */
static void test_cssm_splits_match_one_device(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_transfer_function tf = scene_tf(ctx);
    const uint32_t split_2x1x1[3] = {1, 0, 0}, split_2x2x1[3] = {1, 1, 0},
                   split_2x2x2[3] = {1, 1, 1};
    const uint32_t *splits[] = {split_2x1x1, split_2x2x1, split_2x2x2, split_2x1x1};
    /* ortho, jitter, shading, point (1 inside, 2 outside), coloured */
    const int cases[][5] = {{0, 0, 0, 0, 0}, {0, 0, 1, 0, 1}, {0, 1, 1, 1, 1},
                            {1, 0, 1, 0, 1}, {1, 1, 0, 2, 0}, {1, 0, 0, 0, 0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        scene s = make_scene(cases[c][0], cases[c][1], cases[c][2], cases[c][3], cases[c][4]);
        if (cases[c][4])
            s.opts.transmission = UMBRA_TRANSMISSION_COLORED;
        for (int k = 0; k < 4; ++k) {
            size_t differing = 0, seq = 0;
            float d = compare_map(ctx, voxels, tf, &s, splits[k], k == 3, UMBRA_SHADOW_CSSM,
                                  &differing, &seq);
            printf("cssm case %zu split %d: max |diff| %.3g, %zu differing depths; part after "
                   "part: %zu floats differ\n", c, k, (double)d, differing, seq);
            assert_int_equal(differing, 0);
            assert_true(d <= PART_BOUND);
            assert_int_equal(seq, 0);
        }
    }
    umbra_transfer_function_release(tf);
    free(voxels);
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
        const size_t texels = (size_t)li.map_size * li.map_size, nf = 1 + li.channels;
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
        cmocka_unit_test(test_threshold_splits_match_one_device),
        cmocka_unit_test(test_cssm_splits_match_one_device),
        cmocka_unit_test(test_deep_splits_match_one_device),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
