// SPDX-License-Identifier: Apache-2.0
/* tests/test_read_box.c: umbra_volume_read_box, one box of a volume file without the rest (what
 * each MPI rank reads of its part).
 *
 * Files hold v(x, y, z) = x + 7 y + 131 z (uint16, either byte order; float32 alike), so every
 * voxel of a box read back is checked against the formula at its global position: a box
 * shifted by one voxel or a row read from the wrong place shows. Raw files, detached NRRD (raw
 * and gzip, with a byte skip), attached gzip NRRD, NIfTI (.nii as kept, .nii.gz as int32 converted
 * to float32), MetaImage (.mha big-endian, .mhd with zlib data); the header alone; a box outside the grid and
 * an encoding that is not read by box are refused naming the values. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <nifti2_io.h>
#include <zlib.h>

#include "nifti_test.h"
#include "test_util.h"

#define NX 37
#define NY 20
#define NZ 11

static uint16_t value(uint32_t x, uint32_t y, uint32_t z)
{
    return (uint16_t)(x + 7 * y + 131 * z);
}

/* The whole grid as uint16, big-endian if asked. */
static uint16_t *grid(int big_endian)
{
    uint16_t *v = malloc(sizeof *v * NX * NY * NZ);
    assert_non_null(v);
    for (uint32_t z = 0; z < NZ; ++z)
        for (uint32_t y = 0; y < NY; ++y)
            for (uint32_t x = 0; x < NX; ++x) {
                uint16_t u = value(x, y, z);
                if (big_endian)
                    u = (uint16_t)((u >> 8) | (u << 8));
                v[(z * NY + y) * NX + x] = u;
            }
    return v;
}

static void assert_box(const uint16_t *got, const uint32_t o[3], const uint32_t s[3])
{
    for (uint32_t z = 0; z < s[2]; ++z)
        for (uint32_t y = 0; y < s[1]; ++y)
            for (uint32_t x = 0; x < s[0]; ++x)
                assert_int_equal(got[(z * s[1] + y) * s[0] + x],
                                 value(o[0] + x, o[1] + y, o[2] + z));
}

/* Reads box (o, s) of path and checks it against the formula and the header's dims. */
static void check_box(umbra_context ctx, const char *path, const umbra_raw_desc *raw,
                      const uint32_t o[3], const uint32_t s[3])
{
    umbra_volume_box_desc d;
    umbra_volume_file_info info;
    void *vox = NULL;
    umbra_volume_box_desc_init(&d);
    memcpy(d.origin, o, sizeof d.origin);
    memcpy(d.size, s, sizeof d.size);
    d.raw = raw;
    assert_int_equal(umbra_volume_read_box(ctx, path, &d, &info, &vox), UMBRA_SUCCESS);
    assert_int_equal(info.type, UMBRA_UINT16);
    assert_int_equal(info.dims[0], NX);
    assert_int_equal(info.dims[1], NY);
    assert_int_equal(info.dims[2], NZ);
    assert_non_null(vox);
    assert_box(vox, o, s);
    free(vox);
}

static const uint32_t box_o[3] = {5, 3, 2}, box_s[3] = {16, 9, 7};
static const uint32_t all_o[3] = {0, 0, 0}, all_s[3] = {NX, NY, NZ};

static void test_raw_box_matches_formula(void **state)
{
    umbra_context ctx = *state;
    char path[1024];
    uint16_t *v = grid(1);
    unsigned char header[13] = {0};
    umbra_raw_desc raw;
    test_tmp_path(path, sizeof path, "box.raw");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(header, 1, sizeof header, f), sizeof header);
    assert_int_equal(fwrite(v, sizeof *v, NX * NY * NZ, f), NX * NY * NZ);
    fclose(f);
    umbra_raw_desc_init(&raw);
    raw.type = UMBRA_UINT16;
    raw.dims[0] = NX;
    raw.dims[1] = NY;
    raw.dims[2] = NZ;
    raw.big_endian = 1;
    raw.header_bytes = sizeof header;
    check_box(ctx, path, &raw, box_o, box_s);
    check_box(ctx, path, &raw, all_o, all_s);
    free(v);
}

static void test_nrrd_raw_and_gzip_boxes_match_formula(void **state)
{
    umbra_context ctx = *state;
    char hdr[1024], data[1024], gz[1024], att[1024];
    uint16_t *v = grid(0);
    const char skip[5] = "skip!";
    test_tmp_path(hdr, sizeof hdr, "box.nhdr");
    test_tmp_path(data, sizeof data, "box_data.raw");
    test_tmp_path(gz, sizeof gz, "box_gz.nhdr");
    test_tmp_path(att, sizeof att, "box_att.nrrd");
    FILE *f = fopen(data, "wb");
    assert_non_null(f);
    fwrite(v, sizeof *v, NX * NY * NZ, f);
    fclose(f);
    test_write_text(hdr, "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 37 20 11\n"
                         "encoding: raw\nendian: little\ndata file: box_data.raw\n");
    check_box(ctx, hdr, NULL, box_o, box_s);

    /* gzip, detached, with 5 bytes of the inflated stream skipped. */
    char gzdata[1024];
    test_tmp_path(gzdata, sizeof gzdata, "box_data.raw.gz");
    gzFile g = gzopen(gzdata, "wb");
    assert_non_null(g);
    gzwrite(g, skip, sizeof skip);
    gzwrite(g, v, (unsigned)(sizeof *v * NX * NY * NZ));
    gzclose(g);
    test_write_text(gz, "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 37 20 11\n"
                        "encoding: gzip\nendian: little\nbyte skip: 5\n"
                        "data file: box_data.raw.gz\n");
    check_box(ctx, gz, NULL, box_o, box_s);
    check_box(ctx, gz, NULL, all_o, all_s);

    /* gzip, attached after the header's blank line. */
    size_t gz_size = 0;
    unsigned char *gz_bytes = test_read_bytes(gzdata, &gz_size);
    const char *text = "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 37 20 11\n"
                       "encoding: gzip\nendian: little\nbyte skip: 5\n\n";
    f = fopen(att, "wb");
    assert_non_null(f);
    fwrite(text, 1, strlen(text), f);
    fwrite(gz_bytes, 1, gz_size, f);
    fclose(f);
    check_box(ctx, att, NULL, box_o, box_s);
    free(gz_bytes);
    free(v);
}

static void test_nifti_boxes_match_formula(void **state)
{
    umbra_context ctx = *state;
    char nii[1024], gz[1024];
    int64_t dims[8] = {3, NX, NY, NZ, 1, 1, 1, 1};
    umbra_volume_box_desc d;
    umbra_volume_file_info info;
    void *vox = NULL;
    nifti_image *nim = nifti_make_new_nim(dims, DT_UINT16, 1);
    assert_non_null(nim);
    uint16_t *v = grid(0);
    memcpy(nim->data, v, sizeof *v * NX * NY * NZ);
    test_nifti_write(nim, test_tmp_path(nii, sizeof nii, "box.nii"));
    check_box(ctx, nii, NULL, box_o, box_s);

    /* int32 becomes float32, row by row, from a gzip stream. */
    nim = nifti_make_new_nim(dims, DT_INT32, 1);
    assert_non_null(nim);
    for (size_t i = 0; i < (size_t)NX * NY * NZ; ++i)
        ((int32_t *)nim->data)[i] = v[i];
    test_nifti_write(nim, test_tmp_path(gz, sizeof gz, "box.nii.gz"));
    umbra_volume_box_desc_init(&d);
    memcpy(d.origin, box_o, sizeof d.origin);
    memcpy(d.size, box_s, sizeof d.size);
    assert_int_equal(umbra_volume_read_box(ctx, gz, &d, &info, &vox), UMBRA_SUCCESS);
    assert_int_equal(info.type, UMBRA_FLOAT32);
    for (uint32_t z = 0; z < box_s[2]; ++z)
        for (uint32_t y = 0; y < box_s[1]; ++y)
            for (uint32_t x = 0; x < box_s[0]; ++x)
                assert_true(((float *)vox)[(z * box_s[1] + y) * box_s[0] + x] ==
                            (float)value(box_o[0] + x, box_o[1] + y, box_o[2] + z));
    free(vox);
    free(v);
}

static void test_metaimage_boxes_match_formula(void **state)
{
    umbra_context ctx = *state;
    char mha[1024], mhd[1024], zraw[1024];
    uint16_t *v = grid(1);
    const size_t bytes = sizeof *v * NX * NY * NZ;
    const char *head = "ObjectType = Image\nNDims = 3\nDimSize = 37 20 11\n"
                       "ElementType = MET_USHORT\nBinaryData = True\n"
                       "BinaryDataByteOrderMSB = True\nElementDataFile = LOCAL\n";
    FILE *f = fopen(test_tmp_path(mha, sizeof mha, "box.mha"), "wb");
    assert_non_null(f);
    fwrite(head, 1, strlen(head), f);
    fwrite(v, 1, bytes, f);
    fclose(f);
    check_box(ctx, mha, NULL, box_o, box_s);

    /* zlib-compressed data file (.zraw). */
    uLongf packed_n = compressBound(bytes);
    unsigned char *packed = malloc(packed_n);
    assert_non_null(packed);
    assert_int_equal(compress(packed, &packed_n, (const Bytef *)v, bytes), Z_OK);
    test_write_bytes(test_tmp_path(zraw, sizeof zraw, "box.zraw"), packed, packed_n);
    test_write_text(test_tmp_path(mhd, sizeof mhd, "box.mhd"),
                    "ObjectType = Image\nNDims = 3\nDimSize = 37 20 11\n"
                    "ElementType = MET_USHORT\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
                    "CompressedData = True\nElementDataFile = box.zraw\n");
    check_box(ctx, mhd, NULL, box_o, box_s);
    free(packed);
    free(v);
}

static void test_header_only_and_bad_boxes_refused(void **state)
{
    umbra_context ctx = *state;
    char hdr[1024], data[1024], hex[1024];
    umbra_volume_box_desc d;
    umbra_volume_file_info info;
    void *vox = (void *)&d;
    uint16_t *v = grid(0);
    test_tmp_path(hdr, sizeof hdr, "box2.nhdr");
    test_tmp_path(data, sizeof data, "box2_data.raw");
    test_tmp_path(hex, sizeof hex, "box2_hex.nhdr");
    test_write_bytes(data, v, sizeof *v * NX * NY * NZ);
    test_write_text(hdr, "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 37 20 11\n"
                         "spacings: 0.5 1 2\nencoding: raw\nendian: little\n"
                         "data file: box2_data.raw\n");
    umbra_volume_box_desc_init(&d);
    assert_int_equal(umbra_volume_read_box(ctx, hdr, &d, &info, &vox), UMBRA_SUCCESS);
    assert_null(vox);
    assert_int_equal(info.dims[0], NX);
    assert_int_equal(info.dims[2], NZ);
    assert_true(info.spacing[0] == 0.5f && info.spacing[2] == 2.0f);
    assert_int_equal(info.channels, 1);

    d.origin[0] = 30;
    d.size[0] = 8; /* 30 + 8 > 37 */
    d.size[1] = d.size[2] = 1;
    test_assert_failed(ctx, umbra_volume_read_box(ctx, hdr, &d, &info, &vox),
                       UMBRA_ERROR_INVALID_ARGUMENT, "origin 30 0 0 size 8 x 1 x 1",
                       "37 x 20 x 11");
    assert_null(vox);

    test_write_text(hex, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1 1 1\nencoding: hex\n\n"
                         "ab\n");
    d.origin[0] = 0;
    d.size[0] = 1;
    test_assert_failed(ctx, umbra_volume_read_box(ctx, hex, &d, &info, &vox),
                       UMBRA_ERROR_UNSUPPORTED, "raw or gzip", "hex");
    test_assert_failed(ctx, umbra_volume_read_box(ctx, "x.vti", &d, &info, &vox),
                       UMBRA_ERROR_UNSUPPORTED, "x.vti", NULL);
    d.struct_size = 3;
    test_assert_failed(ctx, umbra_volume_read_box(ctx, hdr, &d, &info, &vox),
                       UMBRA_ERROR_INVALID_ARGUMENT, "struct_size", NULL);
    free(v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_raw_box_matches_formula),
        cmocka_unit_test(test_nrrd_raw_and_gzip_boxes_match_formula),
        cmocka_unit_test(test_nifti_boxes_match_formula),
        cmocka_unit_test(test_metaimage_boxes_match_formula),
        cmocka_unit_test(test_header_only_and_bad_boxes_refused),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
