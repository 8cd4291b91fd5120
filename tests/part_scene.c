// SPDX-License-Identifier: Apache-2.0
/* tests/part_scene.c: tests/part_scene.h. */
#include "part_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const uint32_t CX[1] = {16}, CY[1] = {24}, CZ[1] = {16};

float *scene_voxels(void)
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

umbra_transfer_function scene_tf(umbra_context ctx)
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

const char *take_message(umbra_context ctx)
{
    const char *m = NULL;
    umbra_context_take_error(ctx, &m);
    return m ? m : "(no message)";
}

void volume_desc(umbra_volume_desc *d, const float *data, uint32_t nx, uint32_t ny,
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


scene make_scene(int ortho, int jitter, int shading, int point, int colored)
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

umbra_renderer scene_renderer(umbra_context ctx, umbra_volume v, umbra_transfer_function tf,
                              const scene *s)
{
    return test_renderer(ctx, v, tf, &s->camera, &s->light, &s->opts);
}

float *render_whole(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
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
float *sub_box(const float *voxels, const uint32_t lo[3], const uint32_t n[3])
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
uint32_t make_parts(const uint32_t *const cuts[3], const uint32_t ncuts[3], int extra_empty,
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

/* The part volume of part p of the scene's voxels: its core and ghost layers (one voxel for an
 * empty part), with the scene's volume description. */
umbra_volume part_volume(umbra_context ctx, const float *voxels, const umbra_part_desc *p)
{
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
    if (umbra_volume_create_part(ctx, &d, p, &v) != UMBRA_SUCCESS)
        fail_msg("part at (%u, %u, %u): %s", p->offset[0], p->offset[1], p->offset[2],
                 take_message(ctx));
    free(box);
    return v;
}

/* A part volume and a renderer with the shadow sd for each of the n parts; *info gets the
 * volumes' info (the global grid's, the same for every part). */
void part_renderers(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                    const scene *s, const umbra_shadow_desc *sd, const umbra_part_desc *parts,
                    uint32_t n, umbra_volume *vols, umbra_renderer *rs, umbra_volume_info *info)
{
    for (uint32_t i = 0; i < n; ++i) {
        vols[i] = part_volume(ctx, voxels, &parts[i]);
        assert_int_equal(umbra_volume_get_info(vols[i], info), UMBRA_SUCCESS);
        rs[i] = scene_renderer(ctx, vols[i], tf, s);
        assert_int_equal(umbra_renderer_set_shadow(rs[i], sd), UMBRA_SUCCESS);
    }
}

/* The light's march state passed through the parts in light order
 * (umbra_part_visibility_order): each part imports what the part before it exported (nothing
 * for the first) and exports its own into state (the light info's tau_floats floats). */
void pass_light(const scene *s, const umbra_part_desc *parts, uint32_t n,
                const umbra_volume_info *info, umbra_renderer *rs, float *state)
{
    uint32_t order[16];
    assert_true(n <= 16);
    const int point = s->light.type == UMBRA_LIGHT_POINT;
    assert_int_equal(umbra_part_visibility_order(parts, n, info,
                                                 point ? s->light.position : s->light.direction,
                                                 point, order),
                     UMBRA_SUCCESS);
    for (uint32_t i = 0; i < n; ++i) {
        umbra_renderer r = rs[order[i]];
        assert_int_equal(umbra_renderer_part_import_transmittance(r, i ? state : NULL),
                         UMBRA_SUCCESS);
        assert_int_equal(umbra_renderer_part_export_transmittance(r, state), UMBRA_SUCCESS);
    }
}

/* Counts the floats of a and b whose bits differ. */
size_t bits_differing(const float *a, const float *b, size_t count)
{
    size_t n = 0;
    for (size_t i = 0; i < count; ++i)
        n += memcmp(&a[i], &b[i], sizeof a[i]) != 0;
    return n;
}

/* Renders every part in view order into one frame, each going on from the accumulation of the
 * parts in front (umbra_renderer_render_part_into), and puts the background under it. */
float *render_into_frame(const scene *s, umbra_renderer *rs, const uint32_t *order,
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
float *render_parts(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
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
        umbra_volume v = part_volume(ctx, voxels, p);
        assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
        umbra_renderer r = scene_renderer(ctx, v, tf, s);
        const umbra_status st = umbra_renderer_render_part(r, W, H, &rects[i], part_img);
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
