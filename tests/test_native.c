// SPDX-License-Identifier: Apache-2.0
/* tests/test_native.c: volumes stored on the device in their own type (host/volume.c,
 * kernels/common/sampling.cl).
 *
 *  - uint8, uint16 and int16 volumes (int16 over its whole range, -32768 included) render the
 *    same image as a float volume holding the same values already normalised in double (what
 *    umbra stored before) on both samplers, to 2e-5 per channel: the kernel's float mapping
 *    (s - lo) * scale differs from the double one by a few ulp of the normalised value, and the
 *    image sampler's UNORM texels add their own float rounding (measured on PoCL: 1.2e-7 on the
 *    buffer sampler, 1.9e-6 on the image sampler);
 *  - a given value range narrower than the data (values clamp) renders as the clamped float
 *    volume on both samplers: per-voxel normalisation before blending, not after;
 *  - the device holds 1 byte per uint8 voxel, 2 per uint16/int16 (the image sampler too, where
 *    the device has UNORM 3D images), 4 per float;
 *  - the value range and every brick's and sub-cell's min/max equal a brute-force scan of the
 *    voxels read back from the device, for brick edges that are and are not multiples of 4;
 *  - umbra_volume_create_filled gives the volume umbra_volume_create gives for the same voxels
 *    (both samplers), keeps the buffer the voxels were written into (buffer sampler: no second
 *    copy), returns the fill's failure as is and refuses desc->data. */
#include "internal.h" /* the volume's tables and storage */
#include "test_util.h"
#include "common/umbra_shared.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NX 40
#define NY 36
#define NZ 32
#define N ((size_t)NX * NY * NZ)
#define IMG 40

/* A smooth field in [0,1] with its minimum and maximum both present: a blob plus ripples. */
static double field(size_t i)
{
    const double x = (double)(i % NX) / (NX - 1), y = (double)(i / NX % NY) / (NY - 1),
                 z = (double)(i / ((size_t)NX * NY)) / (NZ - 1);
    if (i == 0)
        return 0.0;
    if (i == N - 1)
        return 1.0;
    double r2 = (x - 0.5) * (x - 0.5) + (y - 0.45) * (y - 0.45) + (z - 0.55) * (z - 0.55);
    double f = exp(-6.0 * r2) * (0.75 + 0.25 * sin(9.0 * x) * cos(7.0 * y + 2.0 * z));
    return f < 0.0 ? 0.0 : (f > 0.999 ? 0.999 : f);
}

typedef struct typed {
    umbra_scalar_type type;
    double lo, hi; /* raw = lo + round(field * (hi - lo)) */
    const char *name;
} typed;

static const typed TYPES[] = {
    {UMBRA_UINT8, 0, 255, "uint8"},
    {UMBRA_UINT16, 1000, 61000, "uint16"},
    {UMBRA_INT16, -1024, 3071, "int16 (CT)"},
    {UMBRA_INT16, -32768, 32767, "int16 (full range)"},
};

/* The raw voxels of t (malloc'ed) and, in norm, the same values mapped through [vlo, vhi] in
 * double and clamped to [0,1], as umbra stored float volumes before. */
static void *make_raw(const typed *t, double vlo, double vhi, float *norm)
{
    void *raw = malloc(N * umbra_scalar_type_size(t->type));
    assert_non_null(raw);
    for (size_t i = 0; i < N; ++i) {
        double v = t->lo + floor(field(i) * (t->hi - t->lo) + 0.5);
        if (t->type == UMBRA_UINT8)
            ((uint8_t *)raw)[i] = (uint8_t)v;
        else if (t->type == UMBRA_UINT16)
            ((uint16_t *)raw)[i] = (uint16_t)v;
        else
            ((int16_t *)raw)[i] = (int16_t)v;
        double x = (v - vlo) / (vhi - vlo);
        norm[i] = x < 0.0 ? 0.0f : (x > 1.0 ? 1.0f : (float)x);
    }
    return raw;
}

static umbra_volume make_volume(umbra_context ctx, const void *data, umbra_scalar_type type,
                                int range_given, double lo, double hi, uint32_t brick)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = type;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.value_range_given = range_given;
    d.value_min = (float)lo;
    d.value_max = (float)hi;
    if (brick)
        d.brick_size = brick;
    umbra_volume v = NULL;
    assert_int_equal(umbra_volume_create(ctx, &d, &v), UMBRA_SUCCESS);
    return v;
}

/* A shadowed render (exact reference shadows, Blinn-Phong shading) of vol into out. */
static void render(umbra_context ctx, umbra_volume vol, float *out)
{
    const umbra_tf_point pts[] = {{0.0f, {0, 0, 0, 0}},
                                  {0.25f, {0.2f, 0.5f, 0.9f, 0.05f}},
                                  {0.55f, {0.9f, 0.6f, 0.3f, 0.4f}},
                                  {1.0f, {1, 1, 1, 0.9f}}};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 4, 256, &tf),
                     UMBRA_SUCCESS);
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    umbra_light l = test_directional_light(0.3f, -1.0f, 0.2f);
    umbra_renderer r = test_renderer(ctx, vol, tf, NULL, &l, &o);
    umbra_shadow_desc s;
    umbra_shadow_desc_init(&s);
    s.technique = UMBRA_SHADOW_REFERENCE;
    assert_int_equal(umbra_renderer_set_shadow(r, &s), UMBRA_SUCCESS);
    assert_int_equal(umbra_renderer_render(r, IMG, IMG, out), UMBRA_SUCCESS);
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
}

static double max_diff(const float *a, const float *b, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; ++i)
        m = fmax(m, fabs((double)a[i] - b[i]));
    return m;
}

/* The image-sampler context, or NULL (with a note) where the device has no 3D images. */
static umbra_context image_context(void)
{
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    d.sampler = UMBRA_SAMPLER_IMAGE;
    if (!getenv("UMBRA_DEVICE"))
        d.device_name = "pthread";
    umbra_context c = NULL;
    if (umbra_context_create(&d, &c) != UMBRA_SUCCESS ||
        umbra_context_sampler(c) != UMBRA_SAMPLER_IMAGE) {
        umbra_context_release(c);
        print_message("  the device has no float 3D images: image sampler not tested\n");
        return NULL;
    }
    return c;
}

/* Renders t's raw volume (range given or not) and the float volume of its normalised values
 * on ctx; returns the largest channel difference. */
static double native_vs_float(umbra_context ctx, const typed *t, int range_given, double vlo,
                              double vhi)
{
    float *norm = malloc(N * sizeof *norm);
    float *a = malloc(IMG * IMG * 4 * sizeof *a), *b = malloc(IMG * IMG * 4 * sizeof *b);
    assert_non_null(norm);
    assert_non_null(a);
    assert_non_null(b);
    void *raw = make_raw(t, vlo, vhi, norm);
    umbra_volume vn = make_volume(ctx, raw, t->type, range_given, vlo, vhi, 0);
    umbra_volume vf = make_volume(ctx, norm, UMBRA_FLOAT32, 1, 0.0, 1.0, 0);
    umbra_volume_info info;
    assert_int_equal(umbra_volume_get_info(vn, &info), UMBRA_SUCCESS);
    assert_true(info.value_min == (float)vlo && info.value_max == (float)vhi);
    render(ctx, vn, a);
    render(ctx, vf, b);
    double sum = 0.0;
    for (size_t i = 0; i < IMG * IMG * 4; ++i)
        sum += b[i];
    assert_true(sum > 0.05 * IMG * IMG); /* something is drawn */
    double err = max_diff(a, b, IMG * IMG * 4);
    umbra_volume_release(vn);
    umbra_volume_release(vf);
    free(raw);
    free(norm);
    free(a);
    free(b);
    return err;
}

static void test_native_types_render_as_normalised_float(void **state)
{
    umbra_context ctxs[2] = {*state, image_context()};
    for (int c = 0; c < 2; ++c) {
        if (!ctxs[c])
            continue;
        for (size_t k = 0; k < sizeof TYPES / sizeof TYPES[0]; ++k) {
            double err = native_vs_float(ctxs[c], &TYPES[k], 0, TYPES[k].lo, TYPES[k].hi);
            print_message("  %s sampler, %s: max |diff| vs float %.2e\n", c ? "image" : "buffer",
                          TYPES[k].name, err);
            assert_true(err <= 2e-5);
        }
    }
    umbra_context_release(ctxs[1]);
}

/* A window narrower than the data, with a fractional end: values below 50.5 and above 200
 * clamp, and a blend across the clamp must be a blend of clamped values. */
static void test_given_range_clamps_before_blending(void **state)
{
    umbra_context ctxs[2] = {*state, image_context()};
    for (int c = 0; c < 2; ++c) {
        if (!ctxs[c])
            continue;
        double err = native_vs_float(ctxs[c], &TYPES[0], 1, 50.5, 200.0);
        print_message("  %s sampler, uint8 in [50.5, 200]: max |diff| vs float %.2e\n",
                      c ? "image" : "buffer", err);
        assert_true(err <= 2e-5);
    }
    umbra_context_release(ctxs[1]);
}

static void test_device_bytes_are_the_input_type(void **state)
{
    umbra_context ctxs[2] = {*state, image_context()};
    float *norm = malloc(N * sizeof *norm);
    assert_non_null(norm);
    for (int c = 0; c < 2; ++c) {
        if (!ctxs[c])
            continue;
        for (size_t k = 0; k < 3; ++k) {
            void *raw = make_raw(&TYPES[k], TYPES[k].lo, TYPES[k].hi, norm);
            umbra_volume v = make_volume(ctxs[c], raw, TYPES[k].type, 0, 0, 0, 0);
            umbra_volume_info info;
            assert_int_equal(umbra_volume_get_info(v, &info), UMBRA_SUCCESS);
            /* The buffer sampler's one pad element (host/volume.c). */
            size_t want = (N + (c == 0)) * umbra_scalar_type_size(TYPES[k].type);
            int has_format = TYPES[k].type == UMBRA_UINT8 ? ctxs[c]->has_unorm8_r_image3d
                                                          : ctxs[c]->has_unorm16_r_image3d;
            if (c == 1 && !has_format)
                want = N * sizeof(float);
            print_message("  %s sampler, %s: %zu device bytes for %zu voxels\n",
                          c ? "image" : "buffer", TYPES[k].name, info.device_bytes, N);
            assert_int_equal(info.device_bytes, want);
            umbra_volume_release(v);
            free(raw);
        }
        umbra_volume vf = make_volume(ctxs[c], norm, UMBRA_FLOAT32, 0, 0, 0, 0);
        umbra_volume_info info;
        assert_int_equal(umbra_volume_get_info(vf, &info), UMBRA_SUCCESS);
        assert_int_equal(info.device_bytes, (N + (c == 0)) * sizeof(float));
        umbra_volume_release(vf);
    }
    free(norm);
    umbra_context_release(ctxs[1]);
}

/* min/max of the normalised voxels over [lo, hi] per axis (inclusive). */
static void box_range(const float *vox, const uint32_t lo[3], const uint32_t hi[3], float out[2])
{
    out[0] = FLT_MAX;
    out[1] = -FLT_MAX;
    for (uint32_t z = lo[2]; z <= hi[2]; ++z)
        for (uint32_t y = lo[1]; y <= hi[1]; ++y)
            for (uint32_t x = lo[0]; x <= hi[0]; ++x) {
                float v = vox[((size_t)z * NY + y) * NX + x];
                out[0] = fminf(out[0], v);
                out[1] = fmaxf(out[1], v);
            }
}

static void test_brick_and_cell_ranges_match_a_scan(void **state)
{
    umbra_context ctx = *state;
    const uint32_t dims[3] = {NX, NY, NZ};
    float *norm = malloc(N * sizeof *norm);
    assert_non_null(norm);
    const uint32_t bricks[] = {16, 10, 7};
    for (size_t k = 0; k < sizeof TYPES / sizeof TYPES[0]; ++k)
        for (size_t bi = 0; bi < sizeof bricks / sizeof bricks[0]; ++bi) {
            void *raw = make_raw(&TYPES[k], TYPES[k].lo, TYPES[k].hi, norm);
            umbra_volume v = make_volume(ctx, raw, TYPES[k].type, 0, 0, 0, bricks[bi]);
            float *vox = test_read_voxels(v);
            const uint32_t B = bricks[bi], C = (B + UMBRA_BRICK_CELLS - 1) / UMBRA_BRICK_CELLS;
            size_t i = 0, mismatches = 0;
            for (uint32_t bz = 0; bz < v->brick_counts[2]; ++bz)
                for (uint32_t by = 0; by < v->brick_counts[1]; ++by)
                    for (uint32_t bx = 0; bx < v->brick_counts[0]; ++bx, ++i) {
                        const uint32_t b3[3] = {bx, by, bz};
                        uint32_t lo[3], hi[3];
                        float r[2];
                        for (int a = 0; a < 3; ++a) {
                            lo[a] = b3[a] * B;
                            hi[a] = b3[a] * B + B < dims[a] - 1 ? b3[a] * B + B : dims[a] - 1;
                        }
                        box_range(vox, lo, hi, r);
                        mismatches += r[0] != v->brick_minmax[2 * i] ||
                                      r[1] != v->brick_minmax[2 * i + 1];
                        for (uint32_t c = 0; c < 64; ++c) {
                            const uint32_t c3[3] = {c % 4, c / 4 % 4, c / 16};
                            for (int a = 0; a < 3; ++a) {
                                uint32_t s0 = b3[a] * B + c3[a] * C, s1 = s0 + C;
                                lo[a] = s0 < dims[a] - 1 ? s0 : dims[a] - 1;
                                hi[a] = s1 < dims[a] - 1 ? s1 : dims[a] - 1;
                            }
                            box_range(vox, lo, hi, r);
                            mismatches += r[0] != v->cell_minmax[2 * (64 * i + c)] ||
                                          r[1] != v->cell_minmax[2 * (64 * i + c) + 1];
                        }
                    }
            if (mismatches)
                print_message("  %s, bricks of %u: %zu ranges differ from the scan\n",
                              TYPES[k].name, B, mismatches);
            assert_int_equal(mismatches, 0);
            free(vox);
            umbra_volume_release(v);
            free(raw);
        }
    free(norm);
}

typedef struct fill_src {
    const void *data;
    size_t bytes;
    int fail;
    umbra_context ctx;
} fill_src;

static umbra_status fill_copy(void *user, void *dst, size_t bytes)
{
    fill_src *f = user;
    if (f->fail)
        return umbra_context_record_error(f->ctx, UMBRA_ERROR_IO, "fill_copy: the source failed");
    assert_int_equal(bytes, f->bytes);
    memcpy(dst, f->data, bytes);
    return UMBRA_SUCCESS;
}

static void test_filled_volume_equals_created_volume(void **state)
{
    umbra_context ctxs[2] = {*state, image_context()};
    float *norm = malloc(N * sizeof *norm);
    assert_non_null(norm);
    for (int c = 0; c < 2; ++c) {
        if (!ctxs[c])
            continue;
        for (size_t k = 0; k < sizeof TYPES / sizeof TYPES[0]; ++k) {
            void *raw = make_raw(&TYPES[k], TYPES[k].lo, TYPES[k].hi, norm);
            umbra_volume a = make_volume(ctxs[c], raw, TYPES[k].type, 0, 0, 0, 0), b = NULL;
            umbra_volume_desc d;
            umbra_volume_desc_init(&d);
            d.type = TYPES[k].type;
            d.dims[0] = NX;
            d.dims[1] = NY;
            d.dims[2] = NZ;
            fill_src src = {raw, N * umbra_scalar_type_size(d.type), 0, ctxs[c]};
            assert_int_equal(umbra_volume_create_filled(ctxs[c], &d, fill_copy, &src, &b),
                             UMBRA_SUCCESS);
            if (c == 0) {
                /* No copy: the volume keeps the buffer the voxels were written into. */
                cl_mem_flags flags = 0;
                assert_int_equal(clGetMemObjectInfo(b->slabs[0], CL_MEM_FLAGS, sizeof flags,
                                                    &flags, NULL),
                                 CL_SUCCESS);
                assert_true(flags & CL_MEM_ALLOC_HOST_PTR);
            }
            umbra_volume_info ia, ib;
            assert_int_equal(umbra_volume_get_info(a, &ia), UMBRA_SUCCESS);
            assert_int_equal(umbra_volume_get_info(b, &ib), UMBRA_SUCCESS);
            assert_true(ia.value_min == ib.value_min && ia.value_max == ib.value_max);
            assert_int_equal(ia.device_bytes, ib.device_bytes);
            float *va = test_read_voxels(a), *vb = test_read_voxels(b);
            assert_memory_equal(va, vb, N * sizeof *va);
            size_t nb = (size_t)a->brick_counts[0] * a->brick_counts[1] * a->brick_counts[2];
            assert_memory_equal(a->cell_minmax, b->cell_minmax, 2 * 64 * nb * sizeof(float));
            assert_memory_equal(a->brick_minmax, b->brick_minmax, 2 * nb * sizeof(float));
            free(va);
            free(vb);
            umbra_volume_release(a);
            umbra_volume_release(b);

            /* The fill's failure comes back as it recorded it; the context still works. */
            src.fail = 1;
            test_assert_failed(ctxs[c], umbra_volume_create_filled(ctxs[c], &d, fill_copy, &src, &b),
                               UMBRA_ERROR_IO, "the source failed", NULL);
            assert_null(b);
            d.data = raw;
            test_assert_failed(ctxs[c], umbra_volume_create_filled(ctxs[c], &d, fill_copy, &src, &b),
                               UMBRA_ERROR_INVALID_ARGUMENT, "desc->data must be NULL", NULL);
            free(raw);
        }
    }
    free(norm);
    umbra_context_release(ctxs[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_native_types_render_as_normalised_float),
        cmocka_unit_test(test_given_range_clamps_before_blending),
        cmocka_unit_test(test_device_bytes_are_the_input_type),
        cmocka_unit_test(test_brick_and_cell_ranges_match_a_scan),
        cmocka_unit_test(test_filled_volume_equals_created_volume),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
