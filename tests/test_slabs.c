// SPDX-License-Identifier: Apache-2.0
/* tests/test_slabs.c: volumes split into z-slabs beyond one device allocation (host/
 * volume_slabs.c, kernels/common/sampling.cl), pinned down:
 *  - the slab plan, for every depth and allocation size up to a bound: the fewest slabs, each
 *    within the allocation, and every trilinear footprint (layers z, z + 1) inside the slab the
 *    kernels pick for z;
 *  - refusals name the sizes: beyond the device's global memory, two layers over one allocation,
 *    more than UMBRA__MAX_SLABS slabs, a layer wider than the largest 3D image; the context stays
 *    usable; the NRRD reader's bound on voxels is umbra_volume_create's (2^36);
 *  - with the test knob (umbra__context_limit_alloc) a small volume is split into 3 and into 8
 *    slabs; its voxels read back as the unsplit volume's (also through
 *    umbra_volume_create_filled), and every technique's image (shaded,
 *    directional and point light, coloured transmission) equals the unsplit image up to float
 *    rounding (bit for bit on PoCL); also for uint8 volumes stored as uint8; the same for the
 *    3D-image sampler where the device has float 3D images (ray caster and CSSM; uint8 as
 *    CL_UNORM_INT8 slabs).
 * Usage: test_slabs [filter] (a cmocka test-name glob). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "test_util.h"

enum { NX = 33, NY = 29, NZ = 47, W = 40, H = 36 };

static const size_t LAYER = (size_t)NX * NY * sizeof(float);

/* Smooth blobs and ripples, so that gradients and shadows vary across every slab boundary. */
static float *scene_voxels(void)
{
    float *v = malloc((size_t)NX * NY * NZ * sizeof *v);
    assert_non_null(v);
    for (int z = 0; z < NZ; ++z)
        for (int y = 0; y < NY; ++y)
            for (int x = 0; x < NX; ++x) {
                float dx = (x - 14.0f) / 9.0f, dy = (y - 15.0f) / 8.0f, dz = (z - 20.0f) / 14.0f;
                float ex = (x - 22.0f) / 6.0f, ey = (y - 10.0f) / 7.0f, ez = (z - 33.0f) / 8.0f;
                float b = expf(-(dx * dx + dy * dy + dz * dz)) +
                          0.8f * expf(-(ex * ex + ey * ey + ez * ez));
                float ripple = 0.15f * sinf(0.7f * x + 0.45f * z) * cosf(0.5f * y - 0.3f * z);
                float s = b + ripple;
                v[((size_t)z * NY + y) * NX + x] = s < 0.0f ? 0.0f : (s > 1.0f ? 1.0f : s);
            }
    return v;
}

/* The scene as float32, or quantised to uint8 (range 0..255): stored natively on the device. */
static umbra_volume scene_volume_typed(umbra_context ctx, const float *voxels,
                                       umbra_scalar_type type, uint64_t alloc_limit,
                                       uint32_t want_slabs)
{
    const size_t n = (size_t)NX * NY * NZ;
    uint8_t *bytes = NULL;
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.type = type;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    d.brick_size = 8;
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = type == UMBRA_UINT8 ? 255.0f : 1.0f;
    d.data = voxels;
    if (type == UMBRA_UINT8) {
        bytes = malloc(n);
        assert_non_null(bytes);
        for (size_t i = 0; i < n; ++i)
            bytes[i] = (uint8_t)lrintf(voxels[i] * 255.0f);
        d.data = bytes;
    }
    umbra_volume v = NULL;
    umbra__context_limit_alloc(ctx, alloc_limit);
    umbra_status st = umbra_volume_create(ctx, &d, &v);
    umbra__context_limit_alloc(ctx, 0);
    free(bytes);
    if (st != UMBRA_SUCCESS)
        fail_msg("umbra_volume_create: %s", umbra_context_last_message(ctx));
    assert_int_equal(v->stored_type, type);
    assert_int_equal(v->slab_count, want_slabs);
    return v;
}

static umbra_volume scene_volume(umbra_context ctx, const float *voxels, uint64_t alloc_limit,
                                 uint32_t want_slabs)
{
    return scene_volume_typed(ctx, voxels, UMBRA_FLOAT32, alloc_limit, want_slabs);
}

static umbra_transfer_function scene_tf(umbra_context ctx)
{
    const umbra_tf_point pts[] = {{0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
                                  {0.25f, {0.0f, 0.0f, 0.0f, 0.0f}},
                                  {0.45f, {0.9f, 0.5f, 0.2f, 0.08f}},
                                  {0.7f, {0.3f, 0.8f, 0.4f, 0.25f}},
                                  {1.0f, {1.0f, 1.0f, 0.9f, 0.6f}}};
    umbra_transfer_function tf = NULL;
    assert_int_equal(umbra_transfer_function_create_from_points(ctx, pts, 5, 256, &tf),
                     UMBRA_SUCCESS);
    return tf;
}

static void render(umbra_context ctx, umbra_volume vol, umbra_transfer_function tf,
                   const umbra_shadow_desc *shadow, const umbra_light *light, int colored,
                   float *out)
{
    umbra_render_desc o;
    umbra_render_desc_init(&o);
    o.shading = 1;
    o.ground_plane = 1;
    o.transmission = colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    umbra_renderer r = test_renderer(ctx, vol, tf, NULL, light, &o);
    assert_int_equal(umbra_renderer_set_shadow(r, shadow), UMBRA_SUCCESS);
    if (umbra_renderer_render(r, W, H, out) != UMBRA_SUCCESS)
        fail_msg("render: %s", umbra_context_last_message(ctx));
    umbra_renderer_release(r);
}

static double max_diff(const float *a, const float *b, size_t n, double *peak)
{
    double d = 0.0, p = 0.0;
    for (size_t i = 0; i < n; ++i) {
        d = fmax(d, fabs((double)a[i] - b[i]));
        p = fmax(p, fabs((double)a[i]));
    }
    *peak = p;
    return d;
}

/* ---- the plan ----------------------------------------------------------------------------------- */

static void test_slab_plan_covers_every_footprint(void **state)
{
    umbra_context ctx = *state;
    umbra__device_limits lim = {0};
    lim.global_mem = (uint64_t)1 << 40;
    for (uint32_t nz = 1; nz <= 90; ++nz)
        for (uint64_t fit = 1; fit <= 95; ++fit) {
            /* One byte per layer: the allocation limit counts layers, plus the buffer's pad
             * element. */
            const uint32_t dims[3] = {1, 1, nz};
            lim.max_alloc = fit + 1;
            uint32_t count = 0, step = 0;
            uint64_t bytes = 0;
            umbra_status st = umbra__slabs_plan(ctx, dims, 1, 0, &lim, &count, &step, &bytes);
            uint64_t fewest = fit >= nz ? 1 : fit < 2 ? 0 : (nz - 2 + fit - 1) / (fit - 1);
            if (fewest == 0 || fewest > UMBRA__MAX_SLABS) {
                if (st != UMBRA_ERROR_OUT_OF_MEMORY)
                    fail_msg("nz %u, fit %u: status %d, want a refusal", nz, (unsigned)fit, st);
                (void)umbra_context_take_error(ctx, NULL);
                continue;
            }
            if (st != UMBRA_SUCCESS || count != fewest)
                fail_msg("nz %u, fit %u: status %d, %u slabs (fewest %u)", nz, (unsigned)fit, st,
                         count, (unsigned)fewest);
            uint64_t sum = 0;
            for (uint32_t s = 0; s < count; ++s) {
                uint32_t z0 = s * step, z1 = count == 1 ? nz - 1 : z0 + step;
                z1 = z1 > nz - 1 ? nz - 1 : z1;
                if (z0 > z1 || z1 - z0 + 1 > fit)
                    fail_msg("nz %u, fit %u: slab %u holds [%u, %u]", nz, (unsigned)fit, s, z0, z1);
                sum += z1 - z0 + 1;
            }
            assert_int_equal(sum + count, bytes);
            /* The kernels' pick (kernels/common/sampling.cl) for each footprint's first layer. */
            for (uint32_t z = 0; z < nz; ++z) {
                uint32_t s = count == 1 ? 0 : z / step;
                s = s > count - 1 ? count - 1 : s;
                uint32_t z0 = s * step, z1 = count == 1 ? nz - 1 : z0 + step;
                z1 = z1 > nz - 1 ? nz - 1 : z1;
                uint32_t zn = z + 1 < nz ? z + 1 : nz - 1;
                if (z < z0 || zn > z1)
                    fail_msg("nz %u, fit %u: layers %u, %u picked slab %u [%u, %u]", nz,
                             (unsigned)fit, z, zn, s, z0, z1);
            }
        }
}

static void test_slab_plan_refusals_name_the_sizes(void **state)
{
    umbra_context ctx = *state;
    umbra__device_limits lim = {0};
    uint32_t count, step;
    uint64_t bytes;
    const uint32_t big[3] = {2048, 2048, 1536};
    lim.max_alloc = (uint64_t)4 << 30;
    lim.global_mem = (uint64_t)20 << 30;
    /* 6 GiB of uint8 in two slabs of 4 GiB at most; as float32 in seven. */
    assert_int_equal(umbra__slabs_plan(ctx, big, 1, 0, &lim, &count, &step, &bytes),
                     UMBRA_SUCCESS);
    assert_int_equal(count, 2);
    assert_int_equal(step, 768);
    assert_int_equal(bytes, ((uint64_t)1536 + 1) * 2048 * 2048 + 2); /* and two pad bytes */
    test_assert_failed(ctx, umbra__slabs_plan(ctx, big, 4, 0, &lim, &count, &step, &bytes),
                       UMBRA_ERROR_OUT_OF_MEMORY,
                       "2048 x 2048 x 1536 need 25870467100 bytes of device memory (7 slabs",
                       "21474836480 bytes of global memory");
    lim.global_mem = (uint64_t)1 << 40;
    lim.max_alloc = (uint64_t)1 << 30;
    test_assert_failed(ctx, umbra__slabs_plan(ctx, big, 4, 0, &lim, &count, &step, &bytes),
                       UMBRA_ERROR_OUT_OF_MEMORY, "need 25 slabs of at most 63 layers",
                       "at most 8 are supported");
    lim.max_alloc = 2 * 2048 * 2048 * 4 - 1;
    test_assert_failed(ctx, umbra__slabs_plan(ctx, big, 4, 0, &lim, &count, &step, &bytes),
                       UMBRA_ERROR_OUT_OF_MEMORY, "two z-layers (33554436 bytes)",
                       "largest buffer (33554431 bytes)");
    /* Images: the depth is split, a layer larger than the largest image is refused. */
    lim.max_alloc = (uint64_t)1 << 40;
    lim.image_max[0] = lim.image_max[1] = lim.image_max[2] = 2048;
    assert_int_equal(umbra__slabs_plan(ctx, (const uint32_t[3]){512, 512, 5000}, 1, 1, &lim,
                                       &count, &step, &bytes),
                     UMBRA_SUCCESS);
    assert_int_equal(count, 3);
    assert_true(step + 1 <= 2048);
    test_assert_failed(ctx,
                       umbra__slabs_plan(ctx, (const uint32_t[3]){4096, 16, 16}, 1, 1, &lim,
                                         &count, &step, &bytes),
                       UMBRA_ERROR_UNSUPPORTED, "4096 x 16 x 16", "largest 3D image is 2048 x 2048");
}

static void test_volume_create_refuses_what_cannot_split(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = voxels;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    umbra_volume v = NULL;
    char want[128];
    umbra__context_limit_alloc(ctx, LAYER);
    snprintf(want, sizeof want, "two z-layers (%zu bytes)", 2 * LAYER + sizeof(float));
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_OUT_OF_MEMORY, want,
                       "33 x 29 x 47");
    assert_null(v);
    umbra__context_limit_alloc(ctx, 3 * LAYER + sizeof(float));
    test_assert_failed(ctx, umbra_volume_create(ctx, &d, &v), UMBRA_ERROR_OUT_OF_MEMORY,
                       "need 23 slabs of at most 3 layers", NULL);
    assert_null(v);
    umbra__context_limit_alloc(ctx, 0);
    free(voxels);
}

/* The NRRD reader takes what umbra_volume_create takes: up to 2^36 voxels. */
static void test_nrrd_bound_is_the_volume_bound(void **state)
{
    umbra_context ctx = *state;
    char path[512];
    test_tmp_path(path, sizeof path, "huge.nhdr");
    test_write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 65536 65536 17\n"
                          "encoding: raw\ndata file: huge.raw\n");
    umbra_volume v = NULL;
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, path, &v), UMBRA_ERROR_FORMAT,
                       "sizes 65536 x 65536 x 17: more than 2^36 voxels", NULL);
    assert_null(v);
    /* 2^36 voxels exactly pass the bound: the missing data file is what fails. */
    test_write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 65536 65536 16\n"
                          "encoding: raw\ndata file: huge.raw\n");
    umbra_status st = umbra_volume_load_nrrd(ctx, path, &v);
    assert_int_not_equal(st, UMBRA_SUCCESS);
    assert_false(test_message_contains(ctx, "2^36"));
    assert_null(v);
    (void)umbra_context_take_error(ctx, NULL);
    remove(path);
}

/* ---- split against unsplit ------------------------------------------------------------------------ */

static umbra_status fill_scene(void *user, void *dst, size_t bytes)
{
    memcpy(dst, user, bytes);
    return UMBRA_SUCCESS;
}

static void test_split_voxels_read_back_unchanged(void **state)
{
    umbra_context ctx = *state;
    float *voxels = scene_voxels();
    umbra_volume whole = scene_volume(ctx, voxels, 0, 1);
    umbra_volume split = scene_volume(ctx, voxels, 7 * LAYER + sizeof(float), 8);
    assert_int_equal(split->slab_step, 6);
    /* Seven shared layers and eight pad elements. */
    assert_int_equal(split->device_bytes, (NZ + 7) * LAYER + 8 * sizeof(float));
    float *a = test_read_voxels(whole), *b = test_read_voxels(split);
    assert_memory_equal(a, b, (size_t)NX * NY * NZ * sizeof *a);
    free(a);
    free(b);
    umbra_volume_release(whole);
    umbra_volume_release(split);
    /* umbra_volume_create_filled: one mapped buffer where the volume fits one, else slabs. */
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.type = UMBRA_FLOAT32;
    d.dims[0] = NX;
    d.dims[1] = NY;
    d.dims[2] = NZ;
    umbra__context_limit_alloc(ctx, 20 * LAYER + sizeof(float));
    assert_int_equal(umbra_volume_create_filled(ctx, &d, fill_scene, voxels, &split),
                     UMBRA_SUCCESS);
    umbra__context_limit_alloc(ctx, 0);
    assert_int_equal(split->slab_count, 3);
    assert_int_equal(umbra_volume_create_filled(ctx, &d, fill_scene, voxels, &whole),
                     UMBRA_SUCCESS);
    assert_int_equal(whole->slab_count, 1);
    a = test_read_voxels(whole);
    b = test_read_voxels(split);
    assert_memory_equal(a, b, (size_t)NX * NY * NZ * sizeof *a);
    free(a);
    free(b);
    umbra_volume_release(whole);
    umbra_volume_release(split);
    whole = scene_volume_typed(ctx, voxels, UMBRA_UINT8, 0, 1);
    split = scene_volume_typed(ctx, voxels, UMBRA_UINT8, 7 * LAYER / 4 + 1, 8);
    assert_int_equal(split->device_bytes, (NZ + 7) * LAYER / 4 + 8);
    a = test_read_voxels(whole);
    b = test_read_voxels(split);
    assert_memory_equal(a, b, (size_t)NX * NY * NZ * sizeof *a);
    free(a);
    free(b);
    umbra_volume_release(whole);
    umbra_volume_release(split);
    free(voxels);
}

typedef struct technique_case {
    const char *name;
    umbra_shadow_technique technique;
    uint32_t max_nodes;
    int point_light;
    int colored;
} technique_case;

static const technique_case cases[] = {
    {"none", UMBRA_SHADOW_NONE, 0, 0, 0},
    {"reference", UMBRA_SHADOW_REFERENCE, 0, 0, 1},
    {"threshold", UMBRA_SHADOW_THRESHOLD, 0, 0, 0},
    {"threshold, point light", UMBRA_SHADOW_THRESHOLD, 0, 1, 0},
    {"cssm", UMBRA_SHADOW_CSSM, 0, 0, 1},
    {"deep", UMBRA_SHADOW_DEEP, 0, 0, 1},
    {"deep, point light", UMBRA_SHADOW_DEEP, 0, 1, 0},
    {"deep, 4 nodes", UMBRA_SHADOW_DEEP, 4, 0, 0},
    {"convolution", UMBRA_SHADOW_CONVOLUTION, 0, 0, 1},
};

/* The cases[] in mask (bit c for cases[c]) with the volume unsplit and split into `slabs` slabs
 * (the allocation limit fit_layers * LAYER); tol bounds |split - unsplit|. Each case compiles its
 * programs twice (unsplit, split), so the lists are kept short. */
static void compare_techniques(umbra_context ctx, umbra_scalar_type type, unsigned mask,
                               uint64_t fit_layers, uint32_t slabs, double tol)
{
    float *voxels = scene_voxels();
    /* fit_layers layers and a buffer's pad element (kernels/common/sampling.cl reads x pairs). */
    const size_t esize = umbra_scalar_type_size(type);
    const uint64_t limit = fit_layers * (LAYER / sizeof(float) * esize) + esize;
    umbra_volume vols[2] = {scene_volume_typed(ctx, voxels, type, 0, 1),
                            scene_volume_typed(ctx, voxels, type, limit, slabs)};
    umbra_transfer_function tf = scene_tf(ctx);
    const size_t n = (size_t)W * H * 4;
    float *img[2];
    for (int i = 0; i < 2; ++i) {
        img[i] = malloc(n * sizeof *img[i]);
        assert_non_null(img[i]);
    }
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        if (!(mask & (1u << c)))
            continue;
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = cases[c].technique;
        sd.map.size = 96;
        sd.deep.max_nodes = cases[c].max_nodes;
        sd.reference.step = 0.5f;
        /* The convolution technique wants the light from the viewer's side. */
        umbra_light light = cases[c].technique == UMBRA_SHADOW_CONVOLUTION
                                ? test_directional_light(-0.5f, -0.4f, -1.0f)
                            : cases[c].point_light ? test_point_light(10.0f, 40.0f, 30.0f)
                                                   : test_directional_light(0.3f, -1.0f, 0.45f);
        for (int i = 0; i < 2; ++i)
            render(ctx, vols[i], tf, &sd, &light, cases[c].colored, img[i]);
        double peak, d = max_diff(img[0], img[1], n, &peak);
        print_message("  %-24s %-7s %u slabs: max |split - unsplit| %.2e (image peak %.2f)\n",
                      cases[c].name, type == UMBRA_UINT8 ? "uint8" : "float32", slabs, d, peak);
        if (!(peak > 0.05))
            fail_msg("%s: the image is empty (peak %g): nothing compared", cases[c].name, peak);
        if (!(d <= tol))
            fail_msg("%s, %u slabs: max |split - unsplit| %g > %g", cases[c].name, slabs, d, tol);
    }
    for (int i = 0; i < 2; ++i) {
        free(img[i]);
        umbra_volume_release(vols[i]);
    }
    umbra_transfer_function_release(tf);
    free(voxels);
}

static void test_split_images_match_unsplit_buffer_sampler(void **state)
{
    umbra_context ctx = *state;
    assert_int_equal(umbra_context_sampler(ctx), UMBRA_SAMPLER_BUFFER);
    /* Every technique in 3 slabs (with the buffer sampler a split volume samples bit for bit as
     * a whole one; the bound leaves room for a compiler's different contraction), the most
     * slabs with the ray caster alone. */
    compare_techniques(ctx, UMBRA_FLOAT32, ~0u, 20, 3, 1e-6);
    compare_techniques(ctx, UMBRA_FLOAT32, 1u << 0, 7, 8, 1e-6);
    /* Stored as uint8 on the device (the 6 GiB scans this is for). */
    compare_techniques(ctx, UMBRA_UINT8, (1u << 0) | (1u << 4), 20, 3, 1e-6);
}

static void test_split_images_match_unsplit_image_sampler(void **state)
{
    (void)state;
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    d.sampler = UMBRA_SAMPLER_IMAGE;
    if (!getenv("UMBRA_DEVICE"))
        d.device_name = "pthread";
    umbra_context ctx = NULL;
    if (umbra_context_create(&d, &ctx) != UMBRA_SUCCESS ||
        umbra_context_sampler(ctx) != UMBRA_SAMPLER_IMAGE) {
        umbra_context_release(ctx);
        print_message("  the device has no float 3D images: image back end not tested\n");
        skip();
    }
    /* The split images address their slabs with unnormalised coordinates, the whole image with
     * normalised ones: the filter's weights differ by rounding. */
    compare_techniques(ctx, UMBRA_FLOAT32, (1u << 0) | (1u << 4), 20, 3, 1e-4);
    /* uint8 as CL_UNORM_INT8 slabs (copied as given; float32 goes through the staged upload). */
    compare_techniques(ctx, UMBRA_UINT8, 1u << 0, 20, 3, 1e-4);
    umbra_context_release(ctx);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab_plan_covers_every_footprint),
        cmocka_unit_test(test_slab_plan_refusals_name_the_sizes),
        cmocka_unit_test(test_volume_create_refuses_what_cannot_split),
        cmocka_unit_test(test_nrrd_bound_is_the_volume_bound),
        cmocka_unit_test(test_split_voxels_read_back_unchanged),
        cmocka_unit_test(test_split_images_match_unsplit_buffer_sampler),
        cmocka_unit_test(test_split_images_match_unsplit_image_sampler),
    };
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
