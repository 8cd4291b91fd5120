// SPDX-License-Identifier: Apache-2.0
/* tests/test_io.c: reading and writing files.
 *
 * Volumes (headerless raw, NRRD through Teem, Voreen .dat), transfer-function text files and
 * images (PNG, EXR). Loaded volumes are checked on the device: the normalised float32 voxels are
 * read back and compared with (v - min) / (max - min) computed here. Every failing call is checked
 * for its status, for a message naming the offending path or value, and for leaving the context
 * usable. Files are written into the process's temporary directory; each test removes its own.
 *
 * Why one file past 800 lines: one test per reader case and bad input, each independent; a table
 * of cases more than code. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <teem/nrrd.h>

#include "internal.h"
#include "test_util.h"

#define PATH_MAX_LEN 1024

/* ---- fixtures and helpers ------------------------------------------------------------------ */

/* "<tmpdir>/<name>" into buf. */
static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

/* The volume has these dims and spacing, the data's range [lo, hi], and voxels equal to
 * (raw - lo) / (hi - lo) within 1e-6. */
static void assert_volume(umbra_volume vol, uint32_t nx, uint32_t ny, uint32_t nz,
                          const float spacing[3], const double *raw, double lo, double hi)
{
    umbra_volume_info info;
    const size_t count = (size_t)nx * ny * nz;
    float *vox;
    size_t i;
    assert_non_null(vol);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.dims[0], nx);
    assert_int_equal(info.dims[1], ny);
    assert_int_equal(info.dims[2], nz);
    for (i = 0; i < 3; ++i) {
        assert_float_equal(info.spacing[i], spacing[i], 1e-6);
    }
    assert_float_equal(info.value_min, lo, 1e-6);
    assert_float_equal(info.value_max, hi, 1e-6);
    vox = test_read_voxels(vol);
    for (i = 0; i < count; ++i) {
        double want = (raw[i] - lo) / (hi - lo);
        if (fabs(vox[i] - want) > 1e-6) {
            print_message("voxel %zu: %.9g, expected %.9g\n", i, (double)vox[i], want);
        }
        assert_float_equal(vox[i], want, 1e-6);
    }
    free(vox);
}

static const float unit_spacing[3] = {1.0f, 1.0f, 1.0f};

/* ---- raw ---------------------------------------------------------------------------------- */

static void test_raw_desc_init_sets_defaults(void **state)
{
    umbra_raw_desc desc;
    (void)state;
    memset(&desc, 0xab, sizeof desc);
    umbra_raw_desc_init(&desc);
    assert_int_equal(desc.struct_size, sizeof desc);
    assert_int_equal(desc.type, UMBRA_UINT8);
    assert_float_equal(desc.spacing[0], 1.0, 0.0);
    assert_float_equal(desc.spacing[1], 1.0, 0.0);
    assert_float_equal(desc.spacing[2], 1.0, 0.0);
    assert_int_equal(desc.big_endian, 0);
    assert_int_equal(desc.header_bytes, 0);
    umbra_raw_desc_init(NULL); /* a no-op, not a crash */
}

static void test_raw_little_endian_skips_header_and_normalises(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const uint16_t values[8] = {100, 200, 300, 400, 500, 600, 700, 1100};
    unsigned char bytes[3 + 16] = {0xde, 0xad, 0xbe};
    double raw[8];
    const float spacing[3] = {0.5f, 1.0f, 2.0f};
    umbra_raw_desc desc;
    umbra_volume vol = NULL;
    size_t i;
    for (i = 0; i < 8; ++i) {
        bytes[3 + 2 * i] = (unsigned char)(values[i] & 0xff);
        bytes[3 + 2 * i + 1] = (unsigned char)(values[i] >> 8);
        raw[i] = values[i];
    }
    test_write_bytes(tmp_path(path, "le.raw"), bytes, sizeof bytes);
    umbra_raw_desc_init(&desc);
    desc.type = UMBRA_UINT16;
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    memcpy(desc.spacing, spacing, sizeof spacing);
    desc.header_bytes = 3;
    assert_int_equal(umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 2, 2, spacing, raw, 100.0, 1100.0);
    umbra_volume_release(vol);
    remove(path);
}

static void test_raw_big_endian_swaps(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    /* Byte-swapped, these would be 0x0100, 0x0001, ...: a different order and range. */
    static const uint16_t values[8] = {0x0001, 0x0100, 0x0203, 0x1000,
                                       0x0010, 0x0f00, 0x00ff, 0x0102};
    unsigned char bytes[16];
    double raw[8];
    umbra_raw_desc desc;
    umbra_volume vol = NULL;
    size_t i;
    for (i = 0; i < 8; ++i) {
        bytes[2 * i] = (unsigned char)(values[i] >> 8);
        bytes[2 * i + 1] = (unsigned char)(values[i] & 0xff);
        raw[i] = values[i];
    }
    test_write_bytes(tmp_path(path, "be.raw"), bytes, sizeof bytes);
    umbra_raw_desc_init(&desc);
    desc.type = UMBRA_UINT16;
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    desc.big_endian = 1;
    assert_int_equal(umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 2, 2, unit_spacing, raw, 0x0001, 0x1000);
    umbra_volume_release(vol);
    remove(path);
}

static void test_raw_big_endian_float32_and_int16_swap(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const float fvalues[4] = {-2.5f, 0.0f, 1.25f, 7.5f};
    static const int16_t svalues[4] = {-300, -1, 2, 1000};
    unsigned char bytes[16];
    double raw[4];
    umbra_raw_desc desc;
    umbra_volume vol = NULL;
    size_t i, b;

    for (i = 0; i < 4; ++i) {
        uint32_t u;
        memcpy(&u, &fvalues[i], 4);
        for (b = 0; b < 4; ++b) {
            bytes[4 * i + b] = (unsigned char)(u >> (8 * (3 - b)));
        }
        raw[i] = fvalues[i];
    }
    test_write_bytes(tmp_path(path, "be_float.raw"), bytes, 16);
    umbra_raw_desc_init(&desc);
    desc.type = UMBRA_FLOAT32;
    desc.dims[0] = 4;
    desc.dims[1] = desc.dims[2] = 1;
    desc.big_endian = 1;
    assert_int_equal(umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 4, 1, 1, unit_spacing, raw, -2.5, 7.5);
    umbra_volume_release(vol);
    remove(path);

    for (i = 0; i < 4; ++i) {
        uint16_t u = (uint16_t)svalues[i];
        bytes[2 * i] = (unsigned char)(u >> 8);
        bytes[2 * i + 1] = (unsigned char)(u & 0xff);
        raw[i] = svalues[i];
    }
    test_write_bytes(tmp_path(path, "be_short.raw"), bytes, 8);
    desc.type = UMBRA_INT16;
    vol = NULL;
    assert_int_equal(umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 4, 1, 1, unit_spacing, raw, -300.0, 1000.0);
    umbra_volume_release(vol);
    remove(path);
}

static void test_raw_size_mismatch_names_both_sizes(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    unsigned char bytes[15] = {0};
    umbra_raw_desc desc;
    umbra_volume vol = (umbra_volume)&desc; /* must be reset to NULL */
    test_write_bytes(tmp_path(path, "short.raw"), bytes, sizeof bytes);
    umbra_raw_desc_init(&desc);
    desc.type = UMBRA_UINT16;
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_ERROR_FORMAT,
                  "holds 15 bytes", "expected 16");
    assert_null(vol);
    assert_true(test_message_contains(ctx, "umbra_volume_load_raw"));

    /* The header counts too: 15 bytes = 16 expected + 1 header byte is still wrong. */
    desc.header_bytes = 1;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol), UMBRA_ERROR_FORMAT,
                  "expected 17", path);
    remove(path);
}

static void test_raw_missing_file_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_raw_desc desc;
    umbra_volume vol = NULL;
    umbra_raw_desc_init(&desc);
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, tmp_path(path, "absent.raw"), &desc, &vol),
                  UMBRA_ERROR_IO, path, "No such file");
    assert_null(vol);
    /* A directory is not a volume either. */
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, test_tmpdir(), &desc, &vol), UMBRA_ERROR_IO,
                  test_tmpdir(), "not a regular file");
}

static void test_raw_invalid_desc_is_invalid_argument(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    unsigned char bytes[8] = {0};
    umbra_raw_desc desc;
    umbra_volume vol = NULL;
    test_write_bytes(tmp_path(path, "eight.raw"), bytes, sizeof bytes);

    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, NULL, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "umbra_volume_load_raw", "desc");
    umbra_raw_desc_init(&desc);
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 2;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, NULL, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "umbra_volume_load_raw", "path");
    desc.struct_size = 0;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "struct_size", NULL);
    umbra_raw_desc_init(&desc);
    desc.dims[0] = 2;
    desc.dims[1] = 0;
    desc.dims[2] = 4;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "2 x 0 x 4", NULL);
    desc.dims[1] = 1;
    desc.type = (umbra_scalar_type)42;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "type 42", NULL);
    desc.type = UMBRA_UINT8;
    desc.spacing[2] = NAN;
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "spacing", NULL);
    desc.spacing[2] = 1.0f;
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 0x80000000u; /* product overflows size_t */
    test_assert_failed(ctx, umbra_volume_load_raw(ctx, path, &desc, &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "too many voxels", NULL);
    assert_null(vol);
    remove(path);
}

/* ---- NRRD --------------------------------------------------------------------------------- */

static void test_nrrd_detached_header_loads(void **state)
{
    umbra_context ctx = *state;
    char nhdr[PATH_MAX_LEN], data[PATH_MAX_LEN];
    /* 3 x 2 x 2 big-endian int16: Teem swaps, the axis order is kept (x fastest). */
    static const int16_t values[12] = {-5, 0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 995};
    const float spacing[3] = {0.5f, 1.0f, 2.0f};
    unsigned char bytes[24];
    double raw[12];
    umbra_volume vol = NULL;
    size_t i;
    for (i = 0; i < 12; ++i) {
        uint16_t u = (uint16_t)values[i];
        bytes[2 * i] = (unsigned char)(u >> 8);
        bytes[2 * i + 1] = (unsigned char)(u & 0xff);
        raw[i] = values[i];
    }
    test_write_bytes(tmp_path(data, "detached_data.raw"), bytes, sizeof bytes);
    test_write_text(tmp_path(nhdr, "detached.nhdr"), "NRRD0004\n"
                                                "# a detached header\n"
                                                "type: short\n"
                                                "dimension: 3\n"
                                                "sizes: 3 2 2\n"
                                                "spacings: 0.5 1 2\n"
                                                "encoding: raw\n"
                                                "endian: big\n"
                                                "data file: detached_data.raw\n");
    assert_int_equal(umbra_volume_load_nrrd(ctx, nhdr, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 3, 2, 2, spacing, raw, -5.0, 995.0);
    umbra_volume_release(vol);

    /* umbra_volume_load picks the NRRD reader by extension. */
    vol = NULL;
    assert_int_equal(umbra_volume_load(ctx, nhdr, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 3, 2, 2, spacing, raw, -5.0, 995.0);
    umbra_volume_release(vol);
    remove(nhdr);
    remove(data);
}

static void test_nrrd_attached_space_directions_give_spacing(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const char header[] = "NRRD0004\n"
                                 "type: uchar\n"
                                 "dimension: 3\n"
                                 "space: right-anterior-superior\n"
                                 "sizes: 2 2 2\n"
                                 "space directions: (0,0.5,0) (2,0,0) (0,0,-3)\n"
                                 "encoding: raw\n"
                                 "\n";
    static const unsigned char voxels[8] = {10, 20, 30, 40, 50, 60, 70, 90};
    const float spacing[3] = {0.5f, 2.0f, 3.0f};
    unsigned char file[sizeof header - 1 + 8];
    double raw[8];
    umbra_volume vol = NULL;
    size_t i;
    memcpy(file, header, sizeof header - 1);
    memcpy(file + sizeof header - 1, voxels, 8);
    for (i = 0; i < 8; ++i) {
        raw[i] = voxels[i];
    }
    /* Upper-case extension: the dispatch ignores case. */
    test_write_bytes(tmp_path(path, "attached.NRRD"), file, sizeof file);
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 2, 2, spacing, raw, 10.0, 90.0);
    umbra_volume_release(vol);
    remove(path);
}

/* Space origin and space directions give the index-to-world transform: the directions' lengths
 * are the spacing, their unit vectors the axes (here a turn with a mirror, as LPS files have). */
static void test_nrrd_space_origin_and_directions_give_world(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const char header[] = "NRRD0004\n"
                                 "type: uchar\n"
                                 "dimension: 3\n"
                                 "space: left-posterior-superior\n"
                                 "sizes: 2 2 2\n"
                                 "space directions: (0,0.5,0) (-2,0,0) (0,0,3)\n"
                                 "space origin: (10,-20,30.5)\n"
                                 "encoding: raw\n"
                                 "\n";
    static const unsigned char voxels[8] = {10, 20, 30, 40, 50, 60, 70, 90};
    static const float spacing[3] = {0.5f, 2.0f, 3.0f};
    static const float dirs[9] = {0, 1, 0, -1, 0, 0, 0, 0, 1};
    /* origin + (d0 s0 + d1 s1 + d2 s2) (2 - 1) / 2 */
    static const float centre[3] = {9.0f, -19.75f, 32.0f};
    unsigned char file[sizeof header - 1 + 8];
    umbra_volume vol = NULL;
    umbra_volume_info info;
    size_t i;
    memcpy(file, header, sizeof header - 1);
    memcpy(file + sizeof header - 1, voxels, 8);
    test_write_bytes(tmp_path(path, "world.nrrd"), file, sizeof file);
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 1);
    assert_float_equal(info.origin[0], 10.0, 1e-6);
    assert_float_equal(info.origin[1], -20.0, 1e-6);
    assert_float_equal(info.origin[2], 30.5, 1e-6);
    for (i = 0; i < 3; ++i) {
        assert_float_equal(info.spacing[i], spacing[i], 1e-6);
        assert_float_equal(info.center[i], centre[i], 1e-5);
    }
    for (i = 0; i < 9; ++i) {
        assert_float_equal(info.directions[i], dirs[i], 1e-6);
    }
    umbra_volume_release(vol);

    /* Without space directions the box stays centred. */
    test_write_text(path, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspacings: 1 2 3\n"
                     "encoding: raw\n\n12345678");
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 0);
    assert_float_equal(info.center[0], 0.0, 0.0);
    assert_float_equal(info.origin[2], -1.5, 1e-6);
    umbra_volume_release(vol);

    /* A sheared grid (axes 45 degrees apart, as a tilted CT gantry makes) is refused. */
    test_write_text(path, "NRRD0004\ntype: uchar\ndimension: 3\nspace: 3D-right-handed\n"
                     "sizes: 2 2 2\nspace directions: (1,0,0) (1,1,0) (0,0,1)\n"
                     "encoding: raw\n\n12345678");
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_UNSUPPORTED,
                  "index axes 0 and 1 meet at 45.000 degrees", "sheared");
    assert_null(vol);
    remove(path);
}

static void test_nrrd_4d_with_leading_size1_axis_loads(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const char header[] = "NRRD0004\n"
                                 "type: float\n"
                                 "dimension: 4\n"
                                 "sizes: 1 2 1 2\n"
                                 "spacings: nan 4 5 6\n"
                                 "encoding: raw\n"
                                 "endian: little\n"
                                 "\n";
    static const float voxels[4] = {0.25f, -1.0f, 3.0f, 1.0f};
    const float spacing[3] = {4.0f, 5.0f, 6.0f};
    unsigned char file[sizeof header - 1 + 16];
    double raw[4];
    umbra_volume vol = NULL;
    size_t i;
    memcpy(file, header, sizeof header - 1);
    memcpy(file + sizeof header - 1, voxels, 16); /* this host is little-endian */
    for (i = 0; i < 4; ++i) {
        raw[i] = voxels[i];
    }
    test_write_bytes(tmp_path(path, "four_d.nrrd"), file, sizeof file);
    assert_int_equal(umbra_volume_load_nrrd(ctx, path, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 1, 2, spacing, raw, -1.0, 3.0);
    umbra_volume_release(vol);
    remove(path);
}

static void test_nrrd_broken_header_is_format_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_volume vol = (umbra_volume)&path;
    test_write_text(tmp_path(path, "garbage.nrrd"), "this is not a nrrd file\n\x01\x02\x03");
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, path, &vol), UMBRA_ERROR_FORMAT, path,
                  "umbra_volume_load_nrrd");
    assert_null(vol);
    /* Teem's own reason is in the message, and nothing is left in its process-wide store. */
    assert_true(test_message_contains(ctx, "couldn't parse"));
    assert_int_equal(biffCheck(NRRD), 0);
    remove(path);
}

/* Like the .dat reader's raw file: a data file that cannot be opened is an I/O error. */
static void test_nrrd_missing_data_file_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_volume vol = NULL;
    test_write_text(tmp_path(path, "orphan.nhdr"), "NRRD0004\n"
                                              "type: uchar\n"
                                              "dimension: 3\n"
                                              "sizes: 2 2 2\n"
                                              "encoding: raw\n"
                                              "data file: orphan_absent.raw\n");
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, path, &vol), UMBRA_ERROR_IO,
                  "orphan_absent.raw", "No such file");
    assert_int_equal(biffCheck(NRRD), 0);
    remove(path);
}

static void test_nrrd_missing_file_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_volume vol = NULL;
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, tmp_path(path, "absent.nhdr"), &vol),
                  UMBRA_ERROR_IO, path, "No such file");
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_IO, path, NULL);
}

static void test_nrrd_unsupported_type_names_type(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const char header[] = "NRRD0004\n"
                                 "type: double\n"
                                 "dimension: 3\n"
                                 "sizes: 1 1 1\n"
                                 "encoding: raw\n"
                                 "endian: little\n"
                                 "\n";
    unsigned char file[sizeof header - 1 + 8] = {0};
    umbra_volume vol = NULL;
    memcpy(file, header, sizeof header - 1);
    test_write_bytes(tmp_path(path, "double.nrrd"), file, sizeof file);
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, path, &vol), UMBRA_ERROR_FORMAT,
                  "type double", path);
    assert_null(vol);
    remove(path);
}

static void test_nrrd_2d_is_format_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const char header[] = "NRRD0004\n"
                                 "type: uchar\n"
                                 "dimension: 2\n"
                                 "sizes: 2 2\n"
                                 "encoding: raw\n"
                                 "\n";
    unsigned char file[sizeof header - 1 + 4] = {0};
    umbra_volume vol = NULL;
    memcpy(file, header, sizeof header - 1);
    test_write_bytes(tmp_path(path, "image.nrrd"), file, sizeof file);
    test_assert_failed(ctx, umbra_volume_load_nrrd(ctx, path, &vol), UMBRA_ERROR_FORMAT,
                  "dimension 2", path);
    remove(path);
}

static void test_volume_load_unknown_extension(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = (umbra_volume)state;
    test_assert_failed(ctx, umbra_volume_load(ctx, "/no/such/dir/volume.raw", &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "/no/such/dir/volume.raw", ".nrrd");
    assert_null(vol);
    assert_true(test_message_contains(ctx, ".nhdr"));
    assert_true(test_message_contains(ctx, ".dat"));
    test_assert_failed(ctx, umbra_volume_load(ctx, "no_extension", &vol),
                  UMBRA_ERROR_INVALID_ARGUMENT, "no_extension", NULL);
    test_assert_failed(ctx, umbra_volume_load(ctx, NULL, &vol), UMBRA_ERROR_INVALID_ARGUMENT,
                  "umbra_volume_load", "path");
}

static void test_walnut_loads_with_expected_dims_and_range(void **state)
{
    umbra_context ctx = *state;
    const char *path = UMBRA_SHARED_DIR "/data/volumes/walnut.nhdr";
    umbra_volume vol = NULL;
    umbra_volume_info info;
    FILE *f = fopen(path, "rb");
    if (!f) {
        skip(); /* the shared data set is optional */
    }
    fclose(f);
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.dims[0], 128);
    assert_int_equal(info.dims[1], 96);
    assert_int_equal(info.dims[2], 114);
    assert_float_equal(info.spacing[0], 1.0, 0.0);
    /* uint16 CT values; the range was measured from walnut.raw. */
    assert_float_equal(info.value_min, 0.0, 0.0);
    assert_float_equal(info.value_max, 22526.0, 0.0);
    umbra_volume_release(vol);
}

/* ---- Voreen .dat ------------------------------------------------------------------------ */

static void test_dat_loads(void **state)
{
    umbra_context ctx = *state;
    char dat[PATH_MAX_LEN], data[PATH_MAX_LEN];
    static const uint16_t values[12] = {7, 1, 2, 3, 4, 5, 6, 8, 9, 10, 11, 3000};
    const float spacing[3] = {1.0f, 0.5f, 2.0f};
    double raw[12];
    umbra_volume vol = NULL;
    size_t i;
    for (i = 0; i < 12; ++i) {
        raw[i] = values[i];
    }
    test_write_bytes(tmp_path(data, "voreen_data.raw"), values, sizeof values);
    /* The raw file is named relative to the .dat (the tests do not run in tmpdir); keys Voreen
     * writes that umbra does not need are ignored; CRLF line ends are fine. */
    test_write_text(tmp_path(dat, "voreen.dat"), "ObjectFileName:\tvoreen_data.raw\r\n"
                                            "TaggedFileName: ---\r\n"
                                            "Resolution: 2 3 2\r\n"
                                            "SliceThickness: 1 0.5 2\r\n"
                                            "Format: USHORT\r\n"
                                            "NbrTags: 0\r\n"
                                            "ObjectType: TEXTURE_VOLUME_OBJECT\r\n"
                                            "ObjectModel: I\r\n"
                                            "GridType: EQUIDISTANT\r\n");
    assert_int_equal(umbra_volume_load_dat(ctx, dat, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 3, 2, spacing, raw, 1.0, 3000.0);
    umbra_volume_release(vol);

    vol = NULL;
    assert_int_equal(umbra_volume_load(ctx, dat, &vol), UMBRA_SUCCESS);
    assert_volume(vol, 2, 3, 2, spacing, raw, 1.0, 3000.0);
    umbra_volume_release(vol);
    remove(dat);
    remove(data);
}

static void test_dat_missing_key(void **state)
{
    umbra_context ctx = *state;
    char dat[PATH_MAX_LEN], data[PATH_MAX_LEN];
    static const unsigned char voxels[8] = {0};
    umbra_volume vol = NULL;
    test_write_bytes(tmp_path(data, "nores_data.raw"), voxels, sizeof voxels);
    test_write_text(tmp_path(dat, "nores.dat"), "ObjectFileName: nores_data.raw\n"
                                           "SliceThickness: 1 1 1\n"
                                           "Format: UCHAR\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT, "Resolution",
                  dat);
    test_write_text(dat, "ObjectFileName: nores_data.raw\n"
                    "Resolution: 2 2 2\n"
                    "Format: UCHAR\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT,
                  "SliceThickness", dat);
    assert_null(vol);
    remove(dat);
    remove(data);
}

static void test_dat_bad_values_are_named(void **state)
{
    umbra_context ctx = *state;
    char dat[PATH_MAX_LEN], data[PATH_MAX_LEN];
    static const unsigned char voxels[8] = {0};
    umbra_volume vol = NULL;
    test_write_bytes(tmp_path(data, "bad_data.raw"), voxels, sizeof voxels);
    tmp_path(dat, "bad.dat");
    test_write_text(dat, "ObjectFileName: bad_data.raw\nResolution: 2 2 2\nSliceThickness: 1 1 1\n"
                    "Format: DOUBLE\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT, "DOUBLE", dat);
    test_write_text(dat, "ObjectFileName: bad_data.raw\nResolution: 2 x 2\nSliceThickness: 1 1 1\n"
                    "Format: UCHAR\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT, "2 x 2", dat);
    test_write_text(dat, "ObjectFileName: bad_data.raw\nResolution: 2 2 2\nSliceThickness: 1 -1 1\n"
                    "Format: UCHAR\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT, "1 -1 1", dat);
    test_write_text(dat, "ObjectFileName: bad_data.raw\nResolution: 2 2 2\nSliceThickness: 1 1 1\n"
                    "Format: UCHAR\nObjectModel: RGBA\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT, "RGBA", dat);
    /* A raw file of the wrong size is reported with both sizes, under the .dat loader's name. */
    test_write_text(dat, "ObjectFileName: bad_data.raw\nResolution: 2 2 3\nSliceThickness: 1 1 1\n"
                    "Format: UCHAR\n");
    test_assert_failed(ctx, umbra_volume_load_dat(ctx, dat, &vol), UMBRA_ERROR_FORMAT,
                  "umbra_volume_load_dat", "holds 8 bytes, expected 12");
    assert_null(vol);
    remove(dat);
    remove(data);
}

/* ---- transfer-function files -------------------------------------------------------------- */

static void test_tf_file_parses_points(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    const float *table;
    /* entry i lies at i/4: 0, 0.25, 0.5, 0.75, 1 */
    static const float want[5][4] = {{0.0f, 0.0f, 0.0f, 0.0f},
                                     {0.5f, 0.25f, 0.125f, 0.5f},
                                     {1.0f, 0.5f, 0.25f, 1.0f},
                                     {1.0f, 0.75f, 0.5f, 1.0f},
                                     {1.0f, 1.0f, 0.75f, 1.0f}};
    size_t i, c;
    test_write_text(tmp_path(path, "points.tf"), "# a comment line\r\n"
                                            "\r\n"
                                            "   resolution 5   # trailing comment\r\n"
                                            "0.0   0 0 0 0\r\n"
                                            "\t0.5 1 0.5 0.25 1   # the knee\r\n"
                                            "   \r\n"
                                            "1.0 1 1 0.75 1"); /* no final newline */
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_non_null(tf);
    assert_int_equal(umbra_transfer_function_size(tf), 5);
    table = umbra_transfer_function_data(tf);
    for (i = 0; i < 5; ++i) {
        for (c = 0; c < 4; ++c) {
            assert_float_equal(table[4 * i + c], want[i][c], 1e-6);
        }
    }
    umbra_transfer_function_release(tf);
    remove(path);
}

static void test_tf_file_default_resolution_is_256(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    const float *table;
    uint32_t i;
    test_write_text(tmp_path(path, "one.tf"), "0.5 0.2 0.4 0.6 0.8\n");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 256);
    table = umbra_transfer_function_data(tf);
    for (i = 0; i < 256; ++i) {
        assert_float_equal(table[4 * i + 0], 0.2, 1e-6);
        assert_float_equal(table[4 * i + 3], 0.8, 1e-6);
    }
    umbra_transfer_function_release(tf);
    remove(path);
}

static void test_tf_file_bad_line_names_line_number(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], needle[PATH_MAX_LEN + 8];
    umbra_transfer_function tf = (umbra_transfer_function)state;
    test_write_text(tmp_path(path, "short_line.tf"), "# header\n"
                                                "0 0 0 0 0\n"
                                                "\n"
                                                "0.5 1 1\n"
                                                "1 1 1 1 1\n");
    snprintf(needle, sizeof needle, "%s:4:", path);
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "\"0.5 1 1\"");
    assert_null(tf);

    test_write_text(path, "0 0 0 0 0\n0.5 1 one 1 1\n");
    snprintf(needle, sizeof needle, "%s:2:", path);
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "green \"one\" is not a number");

    test_write_text(path, "0 0 0 0 0\n0.5 1 1 1 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "6 fields");

    test_write_text(path, "0 0 0 0 0\n0.5 1 1 1 1x\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "\"1x\"");
    remove(path);
}

static void test_tf_file_nan_rejected(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], needle[PATH_MAX_LEN + 8];
    umbra_transfer_function tf = NULL;
    tmp_path(path, "nan.tf");
    snprintf(needle, sizeof needle, "%s:2:", path);
    test_write_text(path, "0 0 0 0 0\n0.5 1 nan 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "green \"nan\" is not a finite number");
    test_write_text(path, "0 0 0 0 0\ninf 1 1 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "value \"inf\" is not a finite number");
    test_write_text(path, "0 0 0 0 0\n1 1 1 1 1e99\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "alpha \"1e99\" is not in [0,1]");
    assert_null(tf);
    remove(path);
}

static void test_tf_file_out_of_range_or_descending_rejected(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], needle[PATH_MAX_LEN + 8];
    umbra_transfer_function tf = NULL;
    tmp_path(path, "range.tf");
    snprintf(needle, sizeof needle, "%s:2:", path);
    test_write_text(path, "0 0 0 0 0\n0.5 1.5 1 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "red \"1.5\" is not in [0,1]");
    test_write_text(path, "0 0 0 0 0\n-0.25 1 1 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "value \"-0.25\"");
    test_write_text(path, "0.6 0 0 0 0\n0.5 1 1 1 1\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "ascending");

    /* Equal values are a step, not an error. */
    test_write_text(path, "0 0 0 0 0\n0.5 0 0 0 0\n0.5 1 1 1 1\n1 1 1 1 1\n");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    umbra_transfer_function_release(tf);
    remove(path);
}

static void test_tf_file_bad_resolution_rejected(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], needle[PATH_MAX_LEN + 8];
    umbra_transfer_function tf = NULL;
    tmp_path(path, "res.tf");
    snprintf(needle, sizeof needle, "%s:1:", path);
    test_write_text(path, "resolution 1\n0 0 0 0 0\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "resolution 1");
    test_write_text(path, "resolution 65537\n0 0 0 0 0\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "2..65536");
    test_write_text(path, "resolution 12.5\n0 0 0 0 0\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "12.5");
    test_write_text(path, "resolution\n0 0 0 0 0\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  NULL);
    snprintf(needle, sizeof needle, "%s:2:", path);
    test_write_text(path, "0 0 0 0 0\nresolution 16\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, needle,
                  "before the first control point");

    test_write_text(path, "resolution 65536\n0 0 0 0 0\n");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_size(tf), 65536);
    umbra_transfer_function_release(tf);
    remove(path);
}

/* "range LO HI": point values are data values in [LO, HI] and the table spans that range. */
static void test_tf_file_range_in_data_units(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    float range[2];
    static const float alpha[5] = {0.0f, 0.0f, 0.5f, 1.0f, 1.0f}; /* at 0, 100, .., 400 */
    uint32_t i;
    test_write_text(tmp_path(path, "hu.tf"), "# Hounsfield-like units\n"
                                        "range 0 400   # data units\n"
                                        "resolution 5\n"
                                        "100 0 0 0 0\n"
                                        "300 1 1 1 1\n");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_get_range(tf, range), 1);
    assert_float_equal(range[0], 0.0, 0.0);
    assert_float_equal(range[1], 400.0, 0.0);
    assert_int_equal(umbra_transfer_function_size(tf), 5);
    for (i = 0; i < 5; ++i) {
        assert_float_equal(umbra_transfer_function_data(tf)[4 * i + 3], alpha[i], 1e-6);
    }
    umbra_transfer_function_release(tf);
    tf = NULL;
    /* Without the line there is no range. */
    test_write_text(path, "0 0 0 0 0\n1 1 1 1 1\n");
    assert_int_equal(umbra_transfer_function_load(ctx, path, &tf), UMBRA_SUCCESS);
    assert_int_equal(umbra_transfer_function_get_range(tf, range), 0);
    umbra_transfer_function_release(tf);
    remove(path);
}

static void test_tf_file_bad_range_rejected(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN], needle[PATH_MAX_LEN + 8];
    umbra_transfer_function tf = NULL;
    static const struct {
        const char *text, *message;
        int line;
    } cases[] = {
        {"range 5 5\n5 0 0 0 0\n", "range LO 5 must be below HI 5", 1},
        {"range 3071 -1024\n0 0 0 0 0\n", "range LO 3071 must be below HI -1024", 1},
        {"range nan 1\n0 0 0 0 0\n", "two finite numbers", 1},
        {"range 0 inf\n0 0 0 0 0\n", "two finite numbers", 1},
        {"range 0 1e99\n0 0 0 0 0\n", "two finite numbers", 1},
        {"range 0\n0 0 0 0 0\n", "\"range LO HI\"", 1},
        {"range 0 1 2\n0 0 0 0 0\n", "\"range LO HI\"", 1},
        {"range 0 x\n0 0 0 0 0\n", "two finite numbers", 1},
        {"0 0 0 0 0\nrange 0 1\n", "before the first control point", 2},
        {"range 0 1\nrange 0 2\n0 0 0 0 0\n", "once", 2},
        {"range 0 400\n100 0 0 0 0\n401 1 1 1 1\n", "value \"401\" is outside the range [0, 400]", 3},
        {"range -1024 3071\n-2000 0 0 0 0\n", "outside the range [-1024, 3071]", 2},
        {"range 0 400\n300 0 0 0 0\n200 1 1 1 1\n", "ascending", 3},
        {"range 0 400\n100 2 0 0 0\n", "red \"2\" is not in [0,1]", 2},
    };
    size_t i;
    tmp_path(path, "bad_range.tf");
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        test_write_text(path, cases[i].text);
        snprintf(needle, sizeof needle, "%s:%d:", path, cases[i].line);
        test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT,
                      needle, cases[i].message);
        assert_null(tf);
    }
    remove(path);
}

static void test_tf_file_without_points_rejected(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    test_write_text(tmp_path(path, "empty.tf"), "# only a comment\nresolution 16\n\n");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, path,
                  "no control points");
    test_write_bytes(path, "0 0 0 0 0\n\0\n", 12);
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, path, &tf), UMBRA_ERROR_FORMAT, path,
                  "NUL");
    assert_null(tf);
    remove(path);
}

static void test_tf_file_missing_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    umbra_transfer_function tf = NULL;
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, tmp_path(path, "absent.tf"), &tf),
                  UMBRA_ERROR_IO, path, "umbra_transfer_function_load");
    test_assert_failed(ctx, umbra_transfer_function_load(ctx, NULL, &tf),
                  UMBRA_ERROR_INVALID_ARGUMENT, "path", NULL);
    assert_null(tf);
}

/* ---- images ------------------------------------------------------------------------------- */

static double srgb_encode(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double srgb_decode(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

static uint32_t crc32_update(uint32_t crc, const unsigned char *p, size_t n)
{
    size_t i;
    int k;
    crc = ~crc;
    for (i = 0; i < n; ++i) {
        crc ^= p[i];
        for (k = 0; k < 8; ++k) {
            crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* Appends a PNG chunk (length, type, data, CRC) at out, returns the bytes written. */
static size_t png_chunk(unsigned char *out, const char *type, const unsigned char *data,
                        size_t n)
{
    put_be32(out, (uint32_t)n);
    memcpy(out + 4, type, 4);
    if (n) {
        memcpy(out + 8, data, n);
    }
    put_be32(out + 8 + n, crc32_update(0, out + 4, 4 + n));
    return 12 + n;
}

/* Writes an 8-bit PNG byte by byte, its pixels in one stored (uncompressed) deflate block, so the
 * file holds exactly the given values whatever umbra's writer does. colour_type: 0 grey, 2 RGB,
 * 4 grey+alpha, 6 RGBA. */
static void write_png_by_hand(const char *path, uint32_t w, uint32_t h, int colour_type,
                              int channels, const unsigned char *pixels)
{
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char ihdr[13], file[1024], zlib[600];
    size_t raw_len = (size_t)h * (1 + (size_t)w * (size_t)channels), pos = 0, z = 0, i;
    uint32_t a = 1, b = 0;
    uint32_t y;
    assert_true(raw_len <= 512);
    put_be32(ihdr, w);
    put_be32(ihdr + 4, h);
    ihdr[8] = 8;
    ihdr[9] = (unsigned char)colour_type;
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    zlib[z++] = 0x78;
    zlib[z++] = 0x01;
    zlib[z++] = 0x01; /* final block, stored */
    zlib[z++] = (unsigned char)(raw_len & 0xff);
    zlib[z++] = (unsigned char)(raw_len >> 8);
    zlib[z++] = (unsigned char)(~raw_len & 0xff);
    zlib[z++] = (unsigned char)((~raw_len >> 8) & 0xff);
    for (y = 0; y < h; ++y) {
        zlib[z++] = 0; /* filter: none */
        memcpy(zlib + z, pixels + (size_t)y * w * (size_t)channels, (size_t)w * (size_t)channels);
        z += (size_t)w * (size_t)channels;
    }
    for (i = 7; i < z; ++i) { /* Adler-32 of the uncompressed data */
        a = (a + zlib[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    put_be32(zlib + z, (b << 16) | a);
    z += 4;
    memcpy(file, signature, 8);
    pos = 8;
    pos += png_chunk(file + pos, "IHDR", ihdr, sizeof ihdr);
    pos += png_chunk(file + pos, "IDAT", zlib, z);
    pos += png_chunk(file + pos, "IEND", NULL, 0);
    test_write_bytes(path, file, pos);
}

static void test_image_png_read_decodes_srgb_and_premultiplies(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    /* 188 and 128 fall on the power segment of the sRGB curve, 10 on the linear one. */
    static const unsigned char pixels[8] = {188, 10, 255, 255, 255, 0, 128, 128};
    const double want[8] = {srgb_decode(188 / 255.0), srgb_decode(10 / 255.0), 1.0, 1.0,
                            128 / 255.0, 0.0, srgb_decode(128 / 255.0) * (128 / 255.0),
                            128 / 255.0};
    uint32_t w = 0, h = 0;
    float *rgba = NULL;
    size_t i;
    write_png_by_hand(tmp_path(path, "by_hand.png"), 2, 1, 6, 4, pixels);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 2);
    assert_int_equal(h, 1);
    for (i = 0; i < 8; ++i) {
        assert_float_equal(rgba[i], want[i], 1e-6);
    }
    free(rgba);
    remove(path);
}

static void test_image_png_grey_reads_as_opaque_rgb(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    static const unsigned char grey[6] = {0, 10, 188, 255, 128, 64};
    static const unsigned char grey_alpha[4] = {188, 255, 188, 0};
    uint32_t w = 0, h = 0, i;
    float *rgba = NULL;
    write_png_by_hand(tmp_path(path, "grey.png"), 3, 2, 0, 1, grey);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 3);
    assert_int_equal(h, 2);
    for (i = 0; i < 6; ++i) {
        double v = srgb_decode(grey[i] / 255.0);
        assert_float_equal(rgba[4 * i + 0], v, 1e-6);
        assert_float_equal(rgba[4 * i + 1], v, 1e-6);
        assert_float_equal(rgba[4 * i + 2], v, 1e-6);
        assert_float_equal(rgba[4 * i + 3], 1.0, 0.0);
    }
    free(rgba);
    rgba = NULL;

    write_png_by_hand(path, 2, 1, 4, 2, grey_alpha);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 2);
    assert_int_equal(h, 1);
    assert_float_equal(rgba[0], srgb_decode(188 / 255.0), 1e-6);
    assert_float_equal(rgba[2], srgb_decode(188 / 255.0), 1e-6);
    assert_float_equal(rgba[3], 1.0, 0.0);
    assert_float_equal(rgba[4], 0.0, 0.0); /* alpha 0: premultiplied colour is 0 */
    assert_float_equal(rgba[7], 0.0, 0.0);
    free(rgba);
    remove(path);
}

static void test_image_png_roundtrip(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    enum { W = 16, H = 8 };
    float in[W * H * 4];
    float *out = NULL;
    uint32_t w = 0, h = 0, x, y;
    int c;
    /* Premultiplied colours: alpha from 0 to 1 down the rows, un-premultiplied colour ramps
     * across, so every alpha meets dark and bright values. */
    for (y = 0; y < H; ++y) {
        for (x = 0; x < W; ++x) {
            float *p = in + 4 * (y * W + x);
            float a = (float)y / (H - 1);
            p[0] = a * (float)x / (W - 1);
            p[1] = a * (float)(W - 1 - x) / (W - 1);
            p[2] = a * 0.003f * (float)x; /* near the linear segment */
            p[3] = a;
        }
    }
    assert_int_equal(umbra_image_write(ctx, tmp_path(path, "roundtrip.png"), W, H, in),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &out), UMBRA_SUCCESS);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (y = 0; y < H; ++y) {
        for (x = 0; x < W; ++x) {
            const float *p = in + 4 * (y * W + x), *q = out + 4 * (y * W + x);
            assert_float_equal(q[3], p[3], 0.5 / 255 + 1e-6);
            if (p[3] == 0.0f) {
                for (c = 0; c < 3; ++c) {
                    assert_float_equal(q[c], 0.0, 0.0);
                }
                continue;
            }
            /* Compare the un-premultiplied colour where it was quantised: in sRGB. */
            for (c = 0; c < 3; ++c) {
                double got = srgb_encode(q[c] / q[3]), want = srgb_encode(p[c] / p[3]);
                if (fabs(got - want) > 1.0 / 255) {
                    print_message("pixel %u,%u channel %d: %.6f, expected %.6f\n", x, y, c, got,
                                  want);
                }
                assert_float_equal(got, want, 1.0 / 255);
            }
        }
    }
    free(out);
    remove(path);
}

static void test_image_png_clamps_out_of_range(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    const float in[8] = {2.0f, -1.0f, NAN, 1.0f, 0.1f, 0.2f, 0.3f, 1.5f};
    float *out = NULL;
    uint32_t w = 0, h = 0;
    assert_int_equal(umbra_image_write(ctx, tmp_path(path, "clamp.png"), 2, 1, in),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &out), UMBRA_SUCCESS);
    assert_float_equal(out[0], 1.0, 0.0);
    assert_float_equal(out[1], 0.0, 0.0);
    assert_float_equal(out[2], 0.0, 0.0);
    assert_float_equal(out[3], 1.0, 0.0);
    assert_float_equal(out[7], 1.0, 0.0); /* alpha clamped to 1 */
    /* colour divided by alpha 1.5 before clamping */
    assert_float_equal(srgb_encode(out[4]), srgb_encode(0.1 / 1.5), 0.5 / 255 + 1e-6);
    free(out);
    remove(path);
}

static void test_image_exr_roundtrip_exact(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    enum { W = 5, H = 3 };
    float in[W * H * 4];
    float *out = NULL;
    uint32_t w = 0, h = 0;
    size_t i;
    for (i = 0; i < W * H * 4; ++i) {
        /* values beyond [0,1], negative and tiny: EXR keeps linear floats as they are */
        in[i] = (float)((double)i * 0.173 - 1.0) * (i % 3 == 0 ? 1000.0f : 1.0f) + 1e-7f;
    }
    assert_int_equal(umbra_image_write(ctx, tmp_path(path, "roundtrip.exr"), W, H, in),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &out), UMBRA_SUCCESS);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    assert_memory_equal(out, in, sizeof in);
    free(out);
    remove(path);

    /* Upper-case extensions work too. */
    out = NULL;
    assert_int_equal(umbra_image_write(ctx, tmp_path(path, "upper.EXR"), W, H, in),
                     UMBRA_SUCCESS);
    assert_int_equal(umbra_image_read(ctx, path, &w, &h, &out), UMBRA_SUCCESS);
    assert_memory_equal(out, in, sizeof in);
    free(out);
    remove(path);
}

static void test_image_unknown_extension(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    const float px[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    uint32_t w = 7, h = 7;
    float *out = (float *)state;
    test_assert_failed(ctx, umbra_image_write(ctx, tmp_path(path, "picture.tiff"), 1, 1, px),
                  UMBRA_ERROR_INVALID_ARGUMENT, "\"tiff\"", path);
    assert_true(test_message_contains(ctx, ".png"));
    assert_true(test_message_contains(ctx, ".exr"));
    test_assert_failed(ctx, umbra_image_write(ctx, tmp_path(path, "no_extension"), 1, 1, px),
                  UMBRA_ERROR_INVALID_ARGUMENT, "no_extension", NULL);
    test_assert_failed(ctx, umbra_image_read(ctx, tmp_path(path, "picture.jpg"), &w, &h, &out),
                  UMBRA_ERROR_INVALID_ARGUMENT, "\"jpg\"", path);
    assert_null(out);
    assert_int_equal(w, 0);
    assert_int_equal(h, 0);
}

static void test_image_invalid_arguments(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    const float px[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    uint32_t w, h;
    float *out = NULL;
    tmp_path(path, "invalid.png");
    test_assert_failed(ctx, umbra_image_write(ctx, path, 0, 1, px), UMBRA_ERROR_INVALID_ARGUMENT,
                  "0 x 1", NULL);
    test_assert_failed(ctx, umbra_image_write(ctx, path, 1, 65537, px), UMBRA_ERROR_INVALID_ARGUMENT,
                  "1 x 65537", NULL);
    test_assert_failed(ctx, umbra_image_write(ctx, path, 1, 1, NULL), UMBRA_ERROR_INVALID_ARGUMENT,
                  "rgba is NULL", NULL);
    test_assert_failed(ctx, umbra_image_write(ctx, NULL, 1, 1, px), UMBRA_ERROR_INVALID_ARGUMENT,
                  "path is NULL", NULL);
    test_assert_failed(ctx, umbra_image_read(ctx, path, &w, NULL, &out), UMBRA_ERROR_INVALID_ARGUMENT,
                  "umbra_image_read", NULL);
    test_assert_failed(ctx, umbra_image_read(ctx, NULL, &w, &h, &out), UMBRA_ERROR_INVALID_ARGUMENT,
                  "path is NULL", NULL);
}

static void test_image_read_missing_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    uint32_t w, h;
    float *out = NULL;
    test_assert_failed(ctx, umbra_image_read(ctx, tmp_path(path, "absent.png"), &w, &h, &out),
                  UMBRA_ERROR_IO, path, "No such file");
    assert_null(out);
}

static void test_image_read_garbage_is_format_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    uint32_t w, h;
    float *out = NULL;
    test_write_text(tmp_path(path, "garbage.png"), "not a PNG at all, just text\n");
    test_assert_failed(ctx, umbra_image_read(ctx, path, &w, &h, &out), UMBRA_ERROR_FORMAT, path,
                  "umbra_image_read");
    assert_null(out);
    test_write_text(tmp_path(path, "garbage.exr"), "not an EXR either\n");
    test_assert_failed(ctx, umbra_image_read(ctx, path, &w, &h, &out), UMBRA_ERROR_FORMAT, path,
                  NULL);
    remove(path);
    tmp_path(path, "garbage.png");
    remove(path);
}

static void test_image_write_to_missing_directory_is_io_error(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    const float px[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    test_assert_failed(ctx, umbra_image_write(ctx, tmp_path(path, "no_dir/out.png"), 1, 1, px),
                  UMBRA_ERROR_IO, path, "umbra_image_write");
    test_assert_failed(ctx, umbra_image_write(ctx, path, 1, 1, px), UMBRA_ERROR_IO, path, NULL);
    tmp_path(path, "no_dir/out.exr");
    test_assert_failed(ctx, umbra_image_write(ctx, path, 1, 1, px), UMBRA_ERROR_IO, path, NULL);
}

/* ---- main ------------------------------------------------------------------------------- */

#define IO_TEST(t) cmocka_unit_test_setup_teardown(t, test_group_setup, test_group_teardown)

int main(void)
{
    const struct CMUnitTest tests[] = {
        IO_TEST(test_raw_desc_init_sets_defaults),
        IO_TEST(test_raw_little_endian_skips_header_and_normalises),
        IO_TEST(test_raw_big_endian_swaps),
        IO_TEST(test_raw_big_endian_float32_and_int16_swap),
        IO_TEST(test_raw_size_mismatch_names_both_sizes),
        IO_TEST(test_raw_missing_file_is_io_error),
        IO_TEST(test_raw_invalid_desc_is_invalid_argument),
        IO_TEST(test_nrrd_detached_header_loads),
        IO_TEST(test_nrrd_attached_space_directions_give_spacing),
        IO_TEST(test_nrrd_space_origin_and_directions_give_world),
        IO_TEST(test_nrrd_4d_with_leading_size1_axis_loads),
        IO_TEST(test_nrrd_broken_header_is_format_error),
        IO_TEST(test_nrrd_missing_data_file_is_io_error),
        IO_TEST(test_nrrd_missing_file_is_io_error),
        IO_TEST(test_nrrd_unsupported_type_names_type),
        IO_TEST(test_nrrd_2d_is_format_error),
        IO_TEST(test_volume_load_unknown_extension),
        IO_TEST(test_walnut_loads_with_expected_dims_and_range),
        IO_TEST(test_dat_loads),
        IO_TEST(test_dat_missing_key),
        IO_TEST(test_dat_bad_values_are_named),
        IO_TEST(test_tf_file_parses_points),
        IO_TEST(test_tf_file_default_resolution_is_256),
        IO_TEST(test_tf_file_bad_line_names_line_number),
        IO_TEST(test_tf_file_nan_rejected),
        IO_TEST(test_tf_file_range_in_data_units),
        IO_TEST(test_tf_file_bad_range_rejected),
        IO_TEST(test_tf_file_out_of_range_or_descending_rejected),
        IO_TEST(test_tf_file_bad_resolution_rejected),
        IO_TEST(test_tf_file_without_points_rejected),
        IO_TEST(test_tf_file_missing_is_io_error),
        IO_TEST(test_image_png_read_decodes_srgb_and_premultiplies),
        IO_TEST(test_image_png_grey_reads_as_opaque_rgb),
        IO_TEST(test_image_png_roundtrip),
        IO_TEST(test_image_png_clamps_out_of_range),
        IO_TEST(test_image_exr_roundtrip_exact),
        IO_TEST(test_image_unknown_extension),
        IO_TEST(test_image_invalid_arguments),
        IO_TEST(test_image_read_missing_is_io_error),
        IO_TEST(test_image_read_garbage_is_format_error),
        IO_TEST(test_image_write_to_missing_directory_is_io_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
