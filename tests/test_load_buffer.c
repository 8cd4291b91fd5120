// SPDX-License-Identifier: Apache-2.0
/* tests/test_load_buffer.c: the NIfTI and MetaImage loaders decode into the volume's own buffer.
 *
 * umbra_volume_create_filled hands its fill callback the mapped CL_MEM_ALLOC_HOST_PTR buffer the
 * volume keeps (buffer sampler), while umbra_volume_create copies host voxels into a buffer made
 * without that flag: a loaded volume whose buffer has the flag was decoded in place, with no
 * second full-size host copy. Each file is also read back voxel by voxel, with volumes large
 * enough (163840 voxels) that the converted types (NIfTI int8 -> int16, MetaImage MET_INT ->
 * float32, big-endian and zlib-compressed) cross the loaders' 131072-voxel conversion chunks. */
#include "internal.h" /* the volume's slabs */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#define NX 64
#define NY 64
#define NZ 40
#define N ((size_t)NX * NY * NZ)
#define PATH_LEN 1024

/* The file's value at voxel i, per type: both ends of each range appear. */
static double value_s8(size_t i) { return (double)(int)((i * 7u) % 256u) - 128.0; }
static double value_u8(size_t i) { return (double)((i * 13u) % 256u); }
static double value_i32(size_t i) { return 3.0 * (double)i - 1000.0; }

/* The volume was decoded into the buffer it keeps, and holds f's values (normalised). */
static void assert_loaded(umbra_volume vol, double (*f)(size_t))
{
    cl_mem_flags flags = 0;
    umbra_volume_info info;
    assert_int_equal(clGetMemObjectInfo(vol->slabs[0], CL_MEM_FLAGS, sizeof flags, &flags, NULL),
                     CL_SUCCESS);
    assert_true(flags & CL_MEM_ALLOC_HOST_PTR);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.dims[0] * info.dims[1] * info.dims[2], N);
    float *got = test_read_voxels(vol);
    double lo = info.value_min, hi = info.value_max;
    for (size_t i = 0; i < N; ++i) {
        double want = (f(i) - lo) / (hi - lo);
        if (fabs(got[i] - want) > 1e-6) {
            fail_msg("voxel %zu: %g, expected %g", i, (double)got[i], want);
        }
    }
    free(got);
}

/* A single-file NIfTI-1 (.nii): 348-byte header, 4 extension bytes, voxels at 352. */
static void write_nii(const char *path, int16_t datatype, int16_t bitpix, const void *voxels,
                      size_t bytes)
{
    unsigned char h[352] = {0};
    int32_t sizeof_hdr = 348;
    int16_t dim[8] = {3, NX, NY, NZ, 1, 1, 1, 1};
    float pixdim[8] = {1, 1, 1, 1, 0, 0, 0, 0}, vox_offset = 352.0f;
    memcpy(h, &sizeof_hdr, 4);
    memcpy(h + 40, dim, sizeof dim);
    memcpy(h + 70, &datatype, 2);
    memcpy(h + 72, &bitpix, 2);
    memcpy(h + 76, pixdim, sizeof pixdim);
    memcpy(h + 108, &vox_offset, 4);
    memcpy(h + 344, "n+1", 4);
    unsigned char *file = malloc(sizeof h + bytes);
    assert_non_null(file);
    memcpy(file, h, sizeof h);
    memcpy(file + sizeof h, voxels, bytes);
    test_write_bytes(path, file, sizeof h + bytes);
    free(file);
}

static void test_nifti_decodes_into_the_volume_buffer(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN];
    umbra_volume vol = NULL;
    uint8_t *u8 = malloc(N);
    int8_t *s8 = malloc(N);
    assert_non_null(u8);
    assert_non_null(s8);
    for (size_t i = 0; i < N; ++i) {
        u8[i] = (uint8_t)value_u8(i);
        s8[i] = (int8_t)value_s8(i);
    }
    /* uint8: kept as it is, read straight into the buffer. */
    write_nii(test_tmp_path(path, sizeof path, "u8.nii"), 2 /* DT_UINT8 */, 8, u8, N);
    assert_int_equal(umbra_volume_load_nifti(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_u8);
    umbra_volume_release(vol);
    /* int8: widened to int16 a chunk at a time into the buffer. */
    write_nii(test_tmp_path(path, sizeof path, "s8.nii"), 256 /* DT_INT8 */, 8, s8, N);
    assert_int_equal(umbra_volume_load_nifti(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_s8);
    umbra_volume_release(vol);
    free(u8);
    free(s8);
}

/* An .mha with the header's element type and options, followed by data. */
static void write_mha(const char *path, const char *type, const char *extra, const void *data,
                      size_t bytes)
{
    char head[512];
    int n = snprintf(head, sizeof head,
                     "ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = %s\n"
                     "ElementSpacing = 1 1 1\n%sElementDataFile = LOCAL\n",
                     NX, NY, NZ, type, extra);
    assert_true(n > 0 && (size_t)n < sizeof head);
    unsigned char *file = malloc((size_t)n + bytes);
    assert_non_null(file);
    memcpy(file, head, (size_t)n);
    memcpy(file + n, data, bytes);
    test_write_bytes(path, file, (size_t)n + bytes);
    free(file);
}

static void test_metaimage_decodes_into_the_volume_buffer(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN], extra[128];
    umbra_volume vol = NULL;
    uint8_t *u8 = malloc(N);
    unsigned char *be = malloc(4 * N);
    int32_t *i32 = malloc(4 * N);
    uLongf packed_n = compressBound(4 * N);
    unsigned char *packed = malloc(packed_n);
    assert_true(u8 && be && i32 && packed);
    for (size_t i = 0; i < N; ++i) {
        u8[i] = (uint8_t)value_u8(i);
        i32[i] = (int32_t)value_i32(i);
        uint32_t u = (uint32_t)i32[i];
        be[4 * i] = (unsigned char)(u >> 24);
        be[4 * i + 1] = (unsigned char)(u >> 16);
        be[4 * i + 2] = (unsigned char)(u >> 8);
        be[4 * i + 3] = (unsigned char)u;
    }
    /* MET_UCHAR: kept, read straight into the buffer. */
    write_mha(test_tmp_path(path, sizeof path, "u8.mha"), "MET_UCHAR", "", u8, N);
    assert_int_equal(umbra_volume_load_metaimage(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_u8);
    umbra_volume_release(vol);
    /* MET_INT, big-endian: swapped and converted to float32 chunk by chunk. */
    write_mha(test_tmp_path(path, sizeof path, "i32be.mha"), "MET_INT",
              "ElementByteOrderMSB = True\n", be, 4 * N);
    assert_int_equal(umbra_volume_load_metaimage(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_i32);
    umbra_volume_release(vol);
    /* MET_INT, zlib: inflated through the conversion window. */
    assert_int_equal(compress2(packed, &packed_n, (const Bytef *)i32, 4 * N, 6), Z_OK);
    snprintf(extra, sizeof extra, "CompressedData = True\nCompressedDataSize = %lu\n",
             (unsigned long)packed_n);
    write_mha(test_tmp_path(path, sizeof path, "i32z.mha"), "MET_INT", extra, packed, packed_n);
    assert_int_equal(umbra_volume_load_metaimage(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_i32);
    umbra_volume_release(vol);
    /* MET_UCHAR, zlib: inflated straight into the buffer. */
    packed_n = compressBound(4 * N);
    assert_int_equal(compress2(packed, &packed_n, u8, N, 6), Z_OK);
    snprintf(extra, sizeof extra, "CompressedData = True\nCompressedDataSize = %lu\n",
             (unsigned long)packed_n);
    write_mha(test_tmp_path(path, sizeof path, "u8z.mha"), "MET_UCHAR", extra, packed, packed_n);
    assert_int_equal(umbra_volume_load_metaimage(ctx, path, &vol), UMBRA_SUCCESS);
    assert_loaded(vol, value_u8);
    umbra_volume_release(vol);
    free(u8);
    free(be);
    free(i32);
    free(packed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nifti_decodes_into_the_volume_buffer),
        cmocka_unit_test(test_metaimage_decodes_into_the_volume_buffer),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
