// SPDX-License-Identifier: Apache-2.0
/* tests/test_volume_update.c: umbra_volume_update (host/volume_update.c) pinned down:
 *  - after an update, a render equals, bit for bit, that of a fresh volume made from the updated
 *    voxels with the same value range, through a fresh renderer; and the volume's skipping
 *    ranges and clamp flags equal the fresh volume's, entry for entry: a new time step of a
 *    float volume, sub-boxes of uint16, int16 and uint8 volumes, across z-slabs, of a
 *    multi-channel volume and of a label map, on the buffer and the image sampler;
 *  - values brought outside the value range clamp as a fresh volume's do (and stop clamping
 *    when they are gone);
 *  - only the caches that must rebuild do: the shadow structure always (the voxels changed),
 *    the visibility tables only when some brick's or sub-cell's range changed, the
 *    transfer-function tables and resampled transfer functions never;
 *  - bad updates are refused by name and leave the volume as it was; on a volume in UNORM 3D
 *    images a value outside the range is UMBRA_ERROR_UNSUPPORTED.
 * Usage: test_volume_update [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"
#include "test_util.h"

/* The group's context (test_group_setup), also used by the helpers below. */
static umbra_context ctx;

static int setup(void **state)
{
    int rc = test_group_setup(state);
    ctx = *state;
    return rc;
}

#define NX 30
#define NY 26
#define NZ 22
#define COUNT ((size_t)NX * NY * NZ)

typedef struct kind {
    umbra_scalar_type type;
    uint32_t channels;
    int labels;
    float lo, hi;      /* the value range given */
} kind;

/* A field in [0, 1]: a blob and noise, frame t of a series. */
static double field(int x, int y, int z, int t, uint32_t c)
{
    const double cx = 10.0 + 2.0 * t + 3.0 * c, dx = x - cx, dy = y - 13.0, dz = z - 11.0;
    const double r2 = (dx * dx + dy * dy + dz * dz) / 49.0;
    const uint32_t h = (uint32_t)(x * 73856093u) ^ (uint32_t)(y * 19349663u) ^
                       (uint32_t)(z * 83492791u) ^ (uint32_t)(t * 2654435761u);
    return (r2 < 1.0 ? 0.8 * (1.0 - r2) : 0.0) + 0.05 * (double)(h % 1000u) / 1000.0;
}

/* The voxels of frame t (interleaved channels) in k's type, values lo + field (hi - lo). */
static void *frame_data(const kind *k, int t)
{
    const size_t n = COUNT * k->channels, es = umbra_scalar_type_size(k->type);
    unsigned char *d = malloc(n * es);
    assert_non_null(d);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x)
                for (uint32_t c = 0; c < k->channels; ++c) {
                    const size_t i = (((size_t)z * NY + y) * NX + x) * k->channels + c;
                    const double f = field(x, y, z, t, c);
                    const double v = k->labels ? (f > 0.3 ? 1 + (x + t) % 3 : 0)
                                               : k->lo + f * (k->hi - k->lo);
                    switch (k->type) {
                    case UMBRA_UINT8: d[i] = (uint8_t)lround(v); break;
                    case UMBRA_UINT16: ((uint16_t *)d)[i] = (uint16_t)lround(v); break;
                    case UMBRA_INT16: ((int16_t *)d)[i] = (int16_t)lround(v); break;
                    case UMBRA_FLOAT32: ((float *)d)[i] = (float)v; break;
                    }
                }
    return d;
}

static umbra_volume make_volume(umbra_context c, const kind *k, const void *data)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = k->type;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.channels = k->channels;
    d.labels = k->labels;
    d.value_range_given = !k->labels;
    d.value_min = k->lo;
    d.value_max = k->hi;
    d.brick_size = 8;
    umbra_volume v = NULL;
    if (umbra_volume_create(c, &d, &v) != UMBRA_SUCCESS)
        fail_msg("create: %s", umbra_context_last_message(c));
    return v;
}

/* Copies the box [o, o + n) of src (the whole volume's voxels) into a new buffer. */
static void *box_of(const kind *k, const void *src, const uint32_t o[3], const uint32_t n[3])
{
    const size_t es = umbra_scalar_type_size(k->type) * k->channels;
    unsigned char *b = malloc((size_t)n[0] * n[1] * n[2] * es);
    assert_non_null(b);
    for (uint32_t z = 0; z < n[2]; ++z)
        for (uint32_t y = 0; y < n[1]; ++y)
            memcpy(b + (((size_t)z * n[1] + y) * n[0]) * es,
                   (const unsigned char *)src +
                       ((((size_t)(o[2] + z) * NY + o[1] + y) * NX) + o[0]) * es,
                   n[0] * es);
    return b;
}

/* A renderer of technique t with every channel's transfer function. */
static umbra_renderer make_renderer(umbra_context c, umbra_volume vol, const kind *k,
                                    umbra_shadow_technique t)
{
    const float ramp[4 * 4] = {1.0f, 0.9f, 0.7f, 0.0f, 0.9f, 0.6f, 0.3f, 0.05f,
                               0.8f, 0.4f, 0.3f, 0.3f, 0.7f, 0.3f, 0.9f, 0.6f};
    const float labels[4 * 4] = {0, 0, 0, 0, 1, 0, 0, 0.5f, 0, 1, 0, 0.3f, 0, 0, 1, 0.8f};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create(c, k->labels ? labels : ramp, 4, &tf),
                     UMBRA_SUCCESS);
    umbra_renderer r = NULL;
    assert_int_equal(umbra_renderer_create(c, &r), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_volume(r, vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_set_transfer_function(r, tf), UMBRA_SUCCESS);
    for (uint32_t ch = 1; ch < k->channels; ++ch)
        assert_int_equal(umbra_renderer_set_channel_transfer_function(r, ch, tf, NULL),
                         UMBRA_SUCCESS);
    umbra_transfer_function_release(tf);
    const float dir[3] = {0.6f, 0.4f, 1.0f};
    umbra_camera cam = umbra_camera_orbit(dir, 48.0f, 30.0f);
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    umbra_light light = test_directional_light(-0.5f, -1.0f, -0.3f);
    assert_int_equal(umbra_renderer_set_light(r, &light), UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    assert_int_equal(umbra_renderer_set_options(r, &o), UMBRA_SUCCESS);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    sd.technique = t;
    assert_int_equal(umbra_renderer_set_shadow(r, &sd), UMBRA_SUCCESS);
    return r;
}

#define W 40
#define H 32

static float *render(umbra_renderer r)
{
    float *img = malloc((size_t)W * H * 4 * sizeof *img);
    assert_non_null(img);
    if (umbra_renderer_render(r, W, H, img) != UMBRA_SUCCESS)
        fail_msg("render: %s", umbra_context_last_message(r->ctx));
    return img;
}

/* The updated volume's state and render against a fresh volume of data (and fresh renderer). */
static void assert_as_fresh(umbra_context c, umbra_renderer r, const kind *k, const void *data,
                            umbra_shadow_technique t)
{
    umbra_volume v = r->volume, f = make_volume(c, k, data);
    const size_t nb = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const size_t nc = nb * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    assert_memory_equal(v->brick_minmax, f->brick_minmax, 2 * nb * k->channels * sizeof(float));
    assert_memory_equal(v->cell_minmax, f->cell_minmax, 2 * nc * k->channels * sizeof(float));
    assert_memory_equal(v->cell_clamps, f->cell_clamps, nc * k->channels);
    assert_int_equal(v->clamp_cells, f->clamp_cells);
    assert_int_equal(v->clamps, f->clamps);
    umbra_renderer fr = make_renderer(c, f, k, t);
    float *a = render(r), *b = render(fr);
    assert_memory_equal(a, b, (size_t)W * H * 4 * sizeof(float));
    free(a);
    free(b);
    umbra_renderer_release(fr);
    umbra_volume_release(f);
}

/* Updates the box [o, o + n) of r's volume to frame t's voxels there, in `data` (the volume's
 * voxels, updated in place), and checks the result against a fresh volume. */
static void update_box(umbra_context c, umbra_renderer r, const kind *k, void *data, int t,
                       const uint32_t o[3], const uint32_t n[3], umbra_shadow_technique tech)
{
    void *next = frame_data(k, t);
    const size_t es = umbra_scalar_type_size(k->type) * k->channels;
    for (uint32_t z = 0; z < n[2]; ++z)
        for (uint32_t y = 0; y < n[1]; ++y) {
            const size_t i = (((size_t)(o[2] + z) * NY + o[1] + y) * NX + o[0]) * es;
            memcpy((unsigned char *)data + i, (unsigned char *)next + i, n[0] * es);
        }
    umbra_volume_update_desc u;
    umbra_volume_update_desc_init(&u);
    void *box = box_of(k, data, o, n);
    u.data = box;
    memcpy(u.origin, o, sizeof u.origin);
    memcpy(u.size, n, sizeof u.size);
    if (umbra_volume_update(r->volume, &u) != UMBRA_SUCCESS)
        fail_msg("update: %s", umbra_context_last_message(c));
    assert_as_fresh(c, r, k, data, tech);
    free(box);
    free(next);
}

static void test_time_step_equals_fresh_volume(void **state)
{
    (void)state;
    const kind k = {UMBRA_FLOAT32, 1, 0, -1.0f, 3.0f};
    void *d0 = frame_data(&k, 0), *d1 = frame_data(&k, 1);
    umbra_volume v = make_volume(ctx, &k, d0);
    umbra_renderer r = make_renderer(ctx, v, &k, UMBRA_SHADOW_THRESHOLD);
    free(render(r));
    const umbra__rebuilds before = r->rebuilds;
    umbra_volume_update_desc u;
    umbra_volume_update_desc_init(&u);
    u.data = d1;
    assert_int_equal(umbra_volume_update(v, &u), UMBRA_SUCCESS);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.version, 1);
    float *img = render(r);
    free(img);
    umbra_render_stats st;
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    /* The blob moved: ranges changed, both visibility tables are remade, nothing else. */
    assert_int_equal(r->rebuilds.visibility, before.visibility + 2);
    assert_int_equal(r->rebuilds.tables, before.tables);
    assert_int_equal(r->rebuilds.effective, before.effective);
    assert_as_fresh(ctx, r, &k, d1, UMBRA_SHADOW_THRESHOLD);
    /* The same voxels again: no range changes, so no visibility tables; the map rebuilds. */
    const umbra__rebuilds again = r->rebuilds;
    assert_int_equal(umbra_volume_update(v, &u), UMBRA_SUCCESS);
    free(render(r));
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 1);
    assert_int_equal(r->rebuilds.visibility, again.visibility);
    assert_int_equal(r->rebuilds.tables, again.tables);
    /* A camera move after it rebuilds nothing. */
    const float dir[3] = {-0.3f, 0.8f, 0.5f};
    umbra_camera cam = umbra_camera_orbit(dir, 48.0f, 30.0f);
    assert_int_equal(umbra_renderer_set_camera(r, &cam), UMBRA_SUCCESS);
    free(render(r));
    assert_int_equal(umbra_renderer_get_stats(r, &st), UMBRA_SUCCESS);
    assert_int_equal(st.shadow_rebuilt, 0);
    umbra_renderer_release(r);
    umbra_volume_release(v);
    free(d0);
    free(d1);
}

static void test_sub_boxes_equal_fresh_volumes(void **state)
{
    (void)state;
    const kind kinds[] = {
        {UMBRA_UINT16, 1, 0, 100.0f, 4000.0f},
        {UMBRA_INT16, 1, 0, -2000.0f, 1500.0f},
        {UMBRA_UINT8, 1, 0, 0.0f, 255.0f},
        {UMBRA_FLOAT32, 3, 0, 0.0f, 1.0f},
        {UMBRA_UINT8, 1, 1, 0.0f, 0.0f},
    };
    /* Boxes: inside one brick, across bricks and the volume's far faces, one voxel. */
    const uint32_t boxes[3][2][3] = {{{9, 10, 3}, {5, 4, 3}},
                                     {{13, 6, 9}, {17, 20, 13}},
                                     {{29, 0, 21}, {1, 1, 1}}};
    const umbra_shadow_technique techs[3] = {UMBRA_SHADOW_DEEP, UMBRA_SHADOW_CSSM,
                                             UMBRA_SHADOW_REFERENCE};
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; ++i) {
        void *d = frame_data(&kinds[i], 0);
        umbra_volume v = make_volume(ctx, &kinds[i], d);
        for (int b = 0; b < 3; ++b) {
            umbra_renderer r = make_renderer(ctx, v, &kinds[i], techs[b]);
            free(render(r));
            update_box(ctx, r, &kinds[i], d, b + 1, boxes[b][0], boxes[b][1], techs[b]);
            umbra_renderer_release(r);
        }
        print_message("kind %zu: three boxes as fresh volumes\n", i);
        umbra_volume_release(v);
        free(d);
    }
}

static void test_updates_across_slabs_and_on_images(void **state)
{
    (void)state;
    /* Slabs: a largest allocation of 8 layers of float voxels. */
    umbra_context sctx = test_context();
    umbra__context_limit_alloc(sctx, (uint64_t)NX * NY * 4 * 8);
    const kind f = {UMBRA_FLOAT32, 1, 0, 0.0f, 1.0f};
    void *d = frame_data(&f, 0);
    umbra_volume v = make_volume(sctx, &f, d);
    assert_true(v->slab_count > 2);
    umbra_renderer r = make_renderer(sctx, v, &f, UMBRA_SHADOW_THRESHOLD);
    const uint32_t o[3] = {4, 3, 5}, n[3] = {20, 18, 14};
    update_box(sctx, r, &f, d, 2, o, n, UMBRA_SHADOW_THRESHOLD);
    umbra_renderer_release(r);
    umbra_volume_release(v);
    free(d);
    umbra_context_release(sctx);

    /* The image sampler: int16 in a biased UNORM image, float normalised in a float image. */
    umbra_context_desc cd;
    umbra_context_desc_init(&cd);
    cd.sampler = UMBRA_SAMPLER_IMAGE;
    umbra_context ictx = NULL;
    assert_int_equal(umbra_context_create(&cd, &ictx), UMBRA_SUCCESS);
    const kind ik[2] = {{UMBRA_INT16, 1, 0, -2000.0f, 1500.0f}, {UMBRA_FLOAT32, 1, 0, 0.0f, 1.0f}};
    for (int i = 0; i < 2; ++i) {
        d = frame_data(&ik[i], 0);
        v = make_volume(ictx, &ik[i], d);
        r = make_renderer(ictx, v, &ik[i], UMBRA_SHADOW_DEEP);
        update_box(ictx, r, &ik[i], d, 1, o, n, UMBRA_SHADOW_DEEP);
        if (v->stored_form != UMBRA__STORED_NORMALISED) {
            /* A value outside the range cannot be clamped by a UNORM image's filter. */
            int16_t out_of_range = 1600;
            umbra_volume_update_desc u;
            umbra_volume_update_desc_init(&u);
            u.data = &out_of_range;
            u.size[0] = u.size[1] = u.size[2] = 1;
            test_assert_failed(ictx, umbra_volume_update(v, &u), UMBRA_ERROR_UNSUPPORTED,
                               "is 1600, outside the volume's value range [-2000, 1500]",
                               "UNORM 3D images");
            assert_as_fresh(ictx, r, &ik[i], d, UMBRA_SHADOW_DEEP);
        }
        umbra_renderer_release(r);
        umbra_volume_release(v);
        free(d);
    }
    umbra_context_release(ictx);
}

static void test_values_outside_the_range_clamp_as_fresh(void **state)
{
    (void)state;
    const kind k = {UMBRA_FLOAT32, 1, 0, 0.0f, 1.0f};
    float *d = frame_data(&k, 0);
    umbra_volume v = make_volume(ctx, &k, d);
    assert_int_equal(v->clamps, 0);
    umbra_renderer r = make_renderer(ctx, v, &k, UMBRA_SHADOW_THRESHOLD);
    free(render(r));
    const uint32_t o[3] = {12, 8, 6}, n[3] = {6, 7, 5};
    float *hot = malloc((size_t)n[0] * n[1] * n[2] * sizeof *hot), *orig = box_of(&k, d, o, n);
    assert_non_null(hot);
    for (size_t i = 0; i < (size_t)n[0] * n[1] * n[2]; ++i)
        hot[i] = 1.7f; /* past the range's end: clamps to 1 */
    umbra_volume_update_desc u;
    umbra_volume_update_desc_init(&u);
    u.data = hot;
    memcpy(u.origin, o, sizeof o);
    memcpy(u.size, n, sizeof n);
    assert_int_equal(umbra_volume_update(v, &u), UMBRA_SUCCESS);
    for (uint32_t z = 0; z < n[2]; ++z)
        for (uint32_t y = 0; y < n[1]; ++y)
            for (uint32_t x = 0; x < n[0]; ++x)
                d[((size_t)(o[2] + z) * NY + o[1] + y) * NX + o[0] + x] = 1.7f;
    assert_int_equal(v->clamps, 1);
    assert_as_fresh(ctx, r, &k, d, UMBRA_SHADOW_THRESHOLD);
    /* The old voxels back: nothing clamps any more. */
    u.data = orig;
    assert_int_equal(umbra_volume_update(v, &u), UMBRA_SUCCESS);
    for (uint32_t z = 0; z < n[2]; ++z)
        for (uint32_t y = 0; y < n[1]; ++y)
            memcpy(d + ((size_t)(o[2] + z) * NY + o[1] + y) * NX + o[0],
                   orig + ((size_t)z * n[1] + y) * n[0], n[0] * sizeof *d);
    assert_int_equal(v->clamps, 0);
    assert_as_fresh(ctx, r, &k, d, UMBRA_SHADOW_THRESHOLD);
    umbra_renderer_release(r);
    umbra_volume_release(v);
    free(hot);
    free(orig);
    free(d);
}

static void test_bad_updates_refused(void **state)
{
    (void)state;
    const kind k = {UMBRA_FLOAT32, 2, 0, 0.0f, 1.0f};
    float *d = frame_data(&k, 0);
    umbra_volume v = make_volume(ctx, &k, d);
    umbra_renderer r = make_renderer(ctx, v, &k, UMBRA_SHADOW_NONE);
    float *before = render(r);
    float vox[2 * 8] = {0};
    umbra_volume_update_desc u;
    umbra_volume_update_desc_init(&u);
    test_assert_failed(ctx, umbra_volume_update(v, NULL), UMBRA_ERROR_INVALID_ARGUMENT,
                       "umbra_volume_update: desc is NULL", NULL);
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "desc->data is NULL", NULL);
    u.data = vox;
    u.struct_size = 4;
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "struct_size 4", "umbra_volume_update_desc_init");
    u.struct_size = sizeof u;
    u.origin[0] = 29;
    u.size[0] = u.size[1] = u.size[2] = 2;
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "the box at (29, 0, 0) of 2 x 2 x 2 voxels", "30 x 26 x 22");
    u.origin[0] = 0;
    u.size[1] = 0;
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "every size > 0", NULL);
    u.size[0] = u.size[2] = 0;
    u.origin[2] = 3;
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "origin (0, 0, 3) must then be 0", NULL);
    u.origin[2] = 1;
    u.size[0] = u.size[1] = u.size[2] = 2;
    vox[2 * 5 + 1] = NAN; /* voxel 5 of the box, channel 1 */
    test_assert_failed(ctx, umbra_volume_update(v, &u), UMBRA_ERROR_INVALID_ARGUMENT,
                       "voxel 5 of the box (x 1, y 0, z 2 of the volume, channel 1) is nan",
                       NULL);
    assert_int_equal(umbra_volume_update(NULL, &u), UMBRA_ERROR_INVALID_ARGUMENT);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
    assert_int_equal(info.version, 0);
    float *after = render(r);
    assert_memory_equal(before, after, (size_t)W * H * 4 * sizeof(float));
    free(before);
    free(after);
    umbra_renderer_release(r);
    umbra_volume_release(v);
    free(d);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_time_step_equals_fresh_volume),
        cmocka_unit_test(test_sub_boxes_equal_fresh_volumes),
        cmocka_unit_test(test_updates_across_slabs_and_on_images),
        cmocka_unit_test(test_values_outside_the_range_clamp_as_fresh),
        cmocka_unit_test(test_bad_updates_refused),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, setup, test_group_teardown);
}
