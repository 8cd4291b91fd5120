// SPDX-License-Identifier: Apache-2.0
/* tests/test_metaimage.c: MetaImage volumes (.mha, .mhd + .raw / .zraw) through umbra_io.
 *
 * Every file is written here: a header as text, as ITK writes it, followed by (or beside) voxel
 * bytes the test lays out itself, compressed with zlib's compress2 where the header says so. The
 * loaded volume is read back from the device and compared voxel by voxel; its spacing, origin and
 * axis directions are compared with the header's numbers. Broken files (short or long data,
 * bad or huge sizes, unknown types, missing data files, several channels, a hostile NDims, corrupt
 * compression) are refused with a status and a message naming the value, and leave the context
 * usable. Files written by ITK's own MetaIO (shipped in tests/data/metaimage) check the reader
 * against an independent writer. The last test runs umbra-render (./umbra-render in ctest's working directory, or
 * $UMBRA_RENDER) on an .mha file. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <zlib.h>

#include "test_util.h"

#define PATH_MAX_LEN 1024

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

/* header text, then size bytes of data (none when data is NULL), into path. */
static void write_mha(const char *path, const char *header, const void *data, size_t size)
{
    size_t n = strlen(header);
    unsigned char *buf = malloc(n + size + 1);
    assert_non_null(buf);
    memcpy(buf, header, n);
    if (data) {
        memcpy(buf + n, data, size);
    } else {
        size = 0;
    }
    test_write_bytes(path, buf, n + size);
    free(buf);
}

/* zlib-compressed copy of data (malloc'ed), its size in *out_size. */
static unsigned char *zlib_pack(const void *data, size_t size, size_t *out_size)
{
    uLongf n = compressBound((uLong)size);
    unsigned char *z = malloc(n);
    assert_non_null(z);
    assert_int_equal(compress2(z, &n, data, (uLong)size, 6), Z_OK);
    *out_size = n;
    return z;
}

/* Loads path, checks it against dims/spacing/want and releases it. */
static void load_and_check(umbra_context ctx, const char *path, const uint32_t dims[3],
                           const float spacing[3], const double *want, double lo, double hi)
{
    umbra_volume vol = NULL;
    umbra_status st = umbra_volume_load(ctx, path, &vol);
    if (st != UMBRA_SUCCESS) {
        print_message("%s: %s\n", path, umbra_context_last_message(ctx));
    }
    assert_int_equal(st, UMBRA_SUCCESS);
    test_assert_volume(vol, dims, spacing, want, lo, hi);
    umbra_volume_release(vol);
}

/* ---- what loads ------------------------------------------------------------------------------ */

/* uint8 voxels after the header (.mha, LOCAL), spacing from ElementSpacing; no Offset or matrix:
 * the box is centred. */
static void test_metaimage_uint8_mha(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {3, 4, 5};
    const float spacing[3] = {0.5f, 1.5f, 2.0f};
    char path[PATH_MAX_LEN];
    unsigned char data[60];
    double want[60];
    umbra_volume vol = NULL;
    umbra_volume_info info;
    int i;
    for (i = 0; i < 60; ++i) {
        data[i] = (unsigned char)(i * 3 % 61);
        want[i] = data[i];
    }
    write_mha(tmp_path(path, "u8.mha"),
              "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
              "CompressedData = False\nElementSpacing = 0.5 1.5 2\nDimSize = 3 4 5\n"
              "Comment = an unknown key is ignored\nElementType = MET_UCHAR\n"
              "ElementDataFile = LOCAL\n",
              data, sizeof data);
    load_and_check(ctx, path, dims, spacing, want, 0.0, 60.0);
    assert_int_equal(umbra_volume_load_metaimage(ctx, path, &vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 0);
    assert_float_equal(info.center[0], 0.0, 0.0);
    umbra_volume_release(vol);
}

/* Element types: big-endian int16 in a .mhd + .raw pair (CRLF line ends, no newline at the end),
 * float32, int8 (int16), uint32 and float64 (float32); ElementSize stands in for a missing
 * ElementSpacing. */
static void test_metaimage_types(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {2, 2, 2};
    const float unit[3] = {1, 1, 1}, sized[3] = {0.25f, 0.5f, 4.0f};
    char path[PATH_MAX_LEN], raw[PATH_MAX_LEN];
    double want[8];
    int i;

    {
        /* int16, most significant byte first, in a separate file named relative to the .mhd. */
        unsigned char be[16];
        for (i = 0; i < 8; ++i) {
            int16_t v = (int16_t)(i * 1000 - 3000);
            uint16_t u = (uint16_t)v;
            be[2 * i] = (unsigned char)(u >> 8);
            be[2 * i + 1] = (unsigned char)(u & 0xff);
            want[i] = v;
        }
        test_write_bytes(tmp_path(raw, "i16.raw"), be, sizeof be);
        write_mha(tmp_path(path, "i16.mhd"),
                  "ObjectType = Image\r\nNDims = 3\r\nDimSize = 2 2 2\r\n"
                  "ElementByteOrderMSB = True\r\nElementType = MET_SHORT\r\n"
                  "ElementDataFile = i16.raw",
                  NULL, 0); /* the last line without its newline, as a hand-written .mhd may be */
        load_and_check(ctx, path, dims, unit, want, -3000.0, 4000.0);
    }
    {
        float f[8];
        for (i = 0; i < 8; ++i) {
            f[i] = 0.125f * (float)i - 0.5f;
            want[i] = f[i];
        }
        write_mha(tmp_path(path, "f32.mha"),
                  "NDims = 3\nDimSize = 2 2 2\nElementSize = 0.25 0.5 4\n"
                  "ElementType = MET_FLOAT\nElementDataFile = LOCAL\n",
                  f, sizeof f);
        load_and_check(ctx, path, dims, sized, want, -0.5, 0.375);
    }
    {
        int8_t c[8];
        for (i = 0; i < 8; ++i) {
            c[i] = (int8_t)(i * 30 - 128);
            want[i] = c[i];
        }
        write_mha(tmp_path(path, "i8.mha"),
                  "NDims = 3\nDimSize = 2 2 2\nElementType = MET_CHAR\nElementDataFile = LOCAL\n",
                  c, sizeof c);
        load_and_check(ctx, path, dims, unit, want, -128.0, 82.0);
    }
    {
        uint32_t u[8];
        for (i = 0; i < 8; ++i) {
            u[i] = (uint32_t)i * 500000000u;
            want[i] = u[i];
        }
        write_mha(tmp_path(path, "u32.mha"),
                  "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UINT\nElementDataFile = LOCAL\n",
                  u, sizeof u);
        load_and_check(ctx, path, dims, unit, want, 0.0, 3.5e9);
    }
    {
        double d[8];
        for (i = 0; i < 8; ++i) {
            d[i] = -1e5 + 12345.5 * i;
            want[i] = (float)d[i];
        }
        write_mha(tmp_path(path, "f64.mha"),
                  "NDims = 3\nDimSize = 2 2 2\nElementType = MET_DOUBLE\nElementDataFile = LOCAL\n",
                  d, sizeof d);
        load_and_check(ctx, path, dims, unit, want, -1e5, -1e5 + 12345.5 * 7);
    }
}

/* Offset and TransformMatrix place the volume: voxel (i, j, k) at offset + i s0 d0 + j s1 d1 +
 * k s2 d2, with d_a the matrix's values 3a..3a+2 (ITK's reading); Position / Orientation are the
 * same keys; AnatomicalOrientation is not used. */
static void test_metaimage_world(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_MAX_LEN];
    unsigned char data[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    const float origin[3] = {10, -20, 30}, dirs[9] = {0, 1, 0, -1, 0, 0, 0, 0, 1};
    umbra_volume vol = NULL;
    umbra_volume_info info;
    int pass, r;
    for (pass = 0; pass < 2; ++pass) {
        write_mha(tmp_path(path, pass ? "w2.mha" : "w1.mha"),
                  pass ? "ObjectType = Image\nNDims = 3\nPosition = 10 -20 30\n"
                         "Orientation = 0 1 0 -1 0 0 0 0 1\nAnatomicalOrientation = LPS\n"
                         "ElementSpacing = 2 3 4\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                         "ElementDataFile = LOCAL\n"
                       : "ObjectType = Image\nNDims = 3\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\n"
                         "Offset = 10 -20 30\nCenterOfRotation = 0 0 0\n"
                         "AnatomicalOrientation = RAI\nElementSpacing = 2 3 4\n"
                         "DimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
                  data, sizeof data);
        assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
        assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
        assert_int_equal(info.transform_given, 1);
        for (r = 0; r < 3; ++r) {
            assert_float_equal(info.origin[r], origin[r], 1e-6);
            assert_float_equal(info.spacing[r], 2.0 + r, 1e-6);
        }
        for (r = 0; r < 9; ++r) {
            assert_float_equal(info.directions[r], dirs[r], 1e-6);
        }
        /* The box's centre is where the transform puts index (0.5, 0.5, 0.5): 10 + 0.5 * 3 * -1,
         * -20 + 0.5 * 2 * 1, 30 + 0.5 * 4. */
        assert_float_equal(info.center[0], 8.5, 1e-5);
        assert_float_equal(info.center[1], -19.0, 1e-5);
        assert_float_equal(info.center[2], 32.0, 1e-5);
        umbra_volume_release(vol);
        vol = NULL;
    }
    /* An offset alone: identity directions. */
    write_mha(tmp_path(path, "w3.mha"),
              "NDims = 3\nOrigin = 1 2 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
              "ElementDataFile = LOCAL\n",
              data, sizeof data);
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_int_equal(info.transform_given, 1);
    assert_float_equal(info.origin[2], 3.0, 0.0);
    assert_float_equal(info.directions[0], 1.0, 0.0);
    assert_float_equal(info.directions[4], 1.0, 0.0);
    assert_float_equal(info.directions[8], 1.0, 0.0);
    umbra_volume_release(vol);
}

/* CompressedData: zlib after the header with CompressedDataSize (.mha, as ITK writes it), a
 * .zraw holding only the stream (no size given), and uncompressed data files with HeaderSize
 * (bytes to skip, or -1: the voxels end the file). */
static void test_metaimage_compressed_and_header_size(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {16, 8, 4};
    const float unit[3] = {1, 1, 1};
    char path[PATH_MAX_LEN], raw[PATH_MAX_LEN], header[512];
    uint16_t data[512];
    unsigned char padded[16 + sizeof data];
    double want[512];
    unsigned char *z;
    size_t zn;
    int i;
    for (i = 0; i < 512; ++i) {
        data[i] = (uint16_t)((i / 16) * 100 + (i % 7)); /* runs that compress */
        want[i] = data[i];
    }
    z = zlib_pack(data, sizeof data, &zn);
    assert_true(zn < sizeof data);
    snprintf(header, sizeof header,
             "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
             "CompressedData = True\nCompressedDataSize = %zu\nDimSize = 16 8 4\n"
             "ElementType = MET_USHORT\nElementDataFile = LOCAL\n",
             zn);
    write_mha(tmp_path(path, "z.mha"), header, z, zn);
    load_and_check(ctx, path, dims, unit, want, 0.0, 3106.0);

    test_write_bytes(tmp_path(raw, "z.zraw"), z, zn);
    write_mha(tmp_path(path, "z.mhd"),
              "NDims = 3\nCompressedData = True\nDimSize = 16 8 4\nElementType = MET_USHORT\n"
              "ElementDataFile = z.zraw\n",
              NULL, 0);
    load_and_check(ctx, path, dims, unit, want, 0.0, 3106.0);
    free(z);

    memset(padded, 0xAB, 16);
    memcpy(padded + 16, data, sizeof data);
    test_write_bytes(tmp_path(raw, "pad.raw"), padded, sizeof padded);
    write_mha(tmp_path(path, "skip.mhd"),
              "NDims = 3\nHeaderSize = 16\nDimSize = 16 8 4\nElementType = MET_USHORT\n"
              "ElementDataFile = pad.raw\n",
              NULL, 0);
    load_and_check(ctx, path, dims, unit, want, 0.0, 3106.0);
    write_mha(tmp_path(path, "end.mhd"),
              "NDims = 3\nHeaderSize = -1\nDimSize = 16 8 4\nElementType = MET_USHORT\n"
              "ElementDataFile = pad.raw\n",
              NULL, 0);
    load_and_check(ctx, path, dims, unit, want, 0.0, 3106.0);
}

/* Files ITK's own MetaIO wrote (tests/data/metaimage/make_files.cpp): int16 compressed in an .mha
 * and raw in an .mhd + .raw pair with an offset and a permuting matrix, float32 in .mhd + .zraw,
 * uint8 in an .mha; the values are the generator's formulas. */
static void test_metaimage_itk_written_files(void **state)
{
    umbra_context ctx = *state;
    static const uint32_t dims[3] = {5, 4, 3};
    const float spacing[3] = {0.7f, 1.3f, 2.1f};
    static const char *const names[4] = {"itk_short_z.mha", "itk_short.mhd", "itk_float_z.mhd",
                                         "itk_u8.mha"};
    const float offset[3] = {12.5f, -30.0f, 4.0f}, dirs[9] = {0, 0, 1, 1, 0, 0, 0, 1, 0};
    char path[PATH_MAX_LEN];
    double want[60];
    int f, i;
    for (f = 0; f < 4; ++f) {
        umbra_volume vol = NULL;
        umbra_volume_info info;
        double lo = 1e30, hi = -1e30;
        for (i = 0; i < 60; ++i) {
            want[i] = f < 2 ? -1000.0 + 37.0 * i : f == 2 ? 0.25 * i - 3.0 : (double)(i * 7 % 256);
            lo = want[i] < lo ? want[i] : lo;
            hi = want[i] > hi ? want[i] : hi;
        }
        snprintf(path, sizeof path, "%s/metaimage/%s", UMBRA_TEST_DATA_DIR, names[f]);
        load_and_check(ctx, path, dims, spacing, want, lo, hi);
        assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
        assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
        assert_int_equal(info.transform_given, 1); /* ITK always writes Offset and the matrix */
        for (i = 0; i < 3; ++i) {
            assert_float_equal(info.origin[i], f < 2 ? offset[i] : 0.0f, 1e-6);
        }
        for (i = 0; i < 9; ++i) {
            assert_float_equal(info.directions[i], f < 2 ? dirs[i] : (i % 4 == 0), 1e-6);
        }
        umbra_volume_release(vol);
    }
}

/* ---- what is refused --------------------------------------------------------------------------- */

#define HEAD3 "ObjectType = Image\nNDims = 3\n"

/* One .mha of header + size data bytes must fail with status and a message holding needle (and
 * needle2). */
static void refused(umbra_context ctx, const char *name, const char *header, const void *data,
                    size_t size, umbra_status status, const char *needle, const char *needle2)
{
    char path[PATH_MAX_LEN];
    umbra_volume vol = (umbra_volume)(uintptr_t)1;
    write_mha(tmp_path(path, name), header, data, size);
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), status, needle, needle2);
    assert_null(vol);
}

static void test_metaimage_broken_files_refused(void **state)
{
    umbra_context ctx = *state;
    unsigned char data[64] = {0};
    char path[PATH_MAX_LEN], header[16384];
    size_t n;
    int i;

    /* Data one byte short, one byte long. */
    refused(ctx, "short.mha", HEAD3 "DimSize = 4 4 4\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 63, UMBRA_ERROR_FORMAT, "holds 63 bytes",
            "expected 64");
    refused(ctx, "long.mhd", HEAD3 "DimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 9, UMBRA_ERROR_FORMAT, "holds 9 bytes",
            "expected 8");
    /* Sizes: zero, missing, fractional, too few, beyond int. */
    refused(ctx, "zero.mha", HEAD3 "DimSize = 4 0 4\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 0, UMBRA_ERROR_FORMAT, "DimSize \"4 0 4\"",
            "1..2147483647");
    refused(ctx, "nodims.mha", HEAD3 "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8,
            UMBRA_ERROR_FORMAT, "DimSize \"(missing)\"", NULL);
    refused(ctx, "frac.mha", HEAD3 "DimSize = 2 2.5 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT, "DimSize \"2 2.5 2\"", NULL);
    refused(ctx, "two.mha", HEAD3 "DimSize = 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 4, UMBRA_ERROR_FORMAT, "DimSize \"2 2\"",
            "three sizes");
    refused(ctx, "int.mha", HEAD3 "DimSize = 2 2 3000000000\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT, "3000000000", NULL);
    /* A huge claim in a small file: refused by size before any allocation (1e15 bytes). */
    refused(ctx, "huge.mha", HEAD3 "DimSize = 100000 100000 100000\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 64, UMBRA_ERROR_FORMAT, "holds 64 bytes",
            "expected 1000000000000000");
    /* The same compressed: bounded by deflate's ratio. */
    refused(ctx, "hugez.mha", HEAD3 "CompressedData = True\nDimSize = 100000 100000 100000\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 64, UMBRA_ERROR_FORMAT,
            "64 compressed bytes cannot hold the 1000000000000000", "1032");
    /* Types and shapes umbra does not read. */
    refused(ctx, "type.mha", HEAD3 "DimSize = 2 2 2\nElementType = MET_FOO\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_UNSUPPORTED,
            "ElementType \"MET_FOO\"", "MET_UCHAR");
    refused(ctx, "notype.mha", HEAD3 "DimSize = 2 2 2\nElementDataFile = LOCAL\n", data, 8,
            UMBRA_ERROR_FORMAT, "no ElementType", NULL);
    refused(ctx, "rgb.mha", HEAD3 "DimSize = 2 2 2\nElementNumberOfChannels = 3\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 24,
            UMBRA_ERROR_UNSUPPORTED, "ElementNumberOfChannels \"3\"", NULL);
    refused(ctx, "ndx.mha", "NDims = three\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT, "NDims \"three\"", NULL);
    refused(ctx, "nd4.mha", "NDims = 4\nDimSize = 2 2 2 1\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_UNSUPPORTED, "NDims \"4\"", NULL);
    refused(ctx, "tube.mha", "ObjectType = Tube\nNDims = 3\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8,
            UMBRA_ERROR_UNSUPPORTED, "ObjectType \"Tube\"", NULL);
    refused(ctx, "ascii.mha", HEAD3 "BinaryData = False\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8,
            UMBRA_ERROR_UNSUPPORTED, "BinaryData False", NULL);
    refused(ctx, "list.mhd", HEAD3 "DimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LIST\n", NULL, 0, UMBRA_ERROR_UNSUPPORTED,
            "ElementDataFile \"LIST\"", NULL);
    refused(ctx, "pattern.mhd", HEAD3 "DimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = slice%03d.raw 1 2 1\n", NULL, 0, UMBRA_ERROR_UNSUPPORTED,
            "slice%03d.raw", NULL);
    /* The header itself: a key twice, a line that is no key, no data line, bad booleans and
     * numbers, a non-positive spacing. */
    refused(ctx, "twice.mha", HEAD3 "DimSize = 2 2 2\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT, "line 4 gives DimSize again",
            NULL);
    refused(ctx, "offset2.mha", HEAD3 "Offset = 0 0 0\nOrigin = 1 1 1\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "gives Origin again (already given as Offset)", NULL);
    refused(ctx, "nokey.mha", HEAD3 "DimSize 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "line 3 \"DimSize 2 2 2\" is not \"Key = Value\"", NULL);
    refused(ctx, "nodata.mha", HEAD3 "DimSize = 2 2 2\nElementType = MET_UCHAR\n", NULL, 0,
            UMBRA_ERROR_FORMAT, "no ElementDataFile line", NULL);
    refused(ctx, "bool.mha", HEAD3 "CompressedData = Maybe\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "CompressedData \"Maybe\"", NULL);
    refused(ctx, "spacing.mha", HEAD3 "ElementSpacing = 1 -2 1\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "ElementSpacing \"1 -2 1\"", "> 0");
    refused(ctx, "matrix.mha", HEAD3 "TransformMatrix = 1 0 0 0 1 0 0 0\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "TransformMatrix \"1 0 0 0 1 0 0 0\"", "nine");
    refused(ctx, "offset.mha", HEAD3 "Offset = 1 nan 3\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_FORMAT,
            "Offset \"1 nan 3\"", NULL);
    /* A sheared matrix is the volume's refusal, naming the angle. */
    refused(ctx, "shear.mha", HEAD3 "TransformMatrix = 1 0 0 1 1 0 0 0 1\nDimSize = 2 2 2\n"
            "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", data, 8,
            UMBRA_ERROR_UNSUPPORTED, "degrees", NULL);
    refused(ctx, "hsize.mha", HEAD3 "HeaderSize = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = LOCAL\n", data, 8, UMBRA_ERROR_UNSUPPORTED, "HeaderSize 3", NULL);
    /* The header ITK's MetaIO overflows its field record on (NDims 5000 and 5000 sizes). */
    n = (size_t)snprintf(header, sizeof header, "ObjectType = Image\nNDims = 5000\nDimSize =");
    for (i = 0; i < 5000 && n + 3 < sizeof header; ++i) {
        n += (size_t)snprintf(header + n, sizeof header - n, " 1");
    }
    snprintf(header + n, sizeof header - n, "\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n");
    refused(ctx, "ndims.mha", header, data, 1, UMBRA_ERROR_UNSUPPORTED, "NDims \"5000\"", NULL);
    /* Binary junk: no header. */
    refused(ctx, "junk.mha", "\x7f", "\0\x01\n", 3, UMBRA_ERROR_FORMAT, "line 1 holds a NUL byte",
            NULL);

    /* A float64 voxel beyond float32. */
    {
        double d[8] = {0, 0, 0, 0, 0, 0, 0, 1e300};
        refused(ctx, "big.mha", HEAD3 "DimSize = 2 2 2\nElementType = MET_DOUBLE\n"
                "ElementDataFile = LOCAL\n", d, sizeof d, UMBRA_ERROR_FORMAT,
                "MET_DOUBLE voxel is not a finite float32", NULL);
    }

    /* Compressed data: corrupt, short of the size declared, longer than it, or a declared
     * compressed size past the end of the file. */
    {
        unsigned char vals[64], *z, *bad;
        size_t zn;
        for (i = 0; i < 64; ++i) {
            vals[i] = (unsigned char)i;
        }
        z = zlib_pack(vals, 64, &zn);
        bad = malloc(zn);
        assert_non_null(bad);
        memcpy(bad, z, zn);
        bad[zn / 2] ^= 0x55;
        bad[zn / 2 + 1] ^= 0xff;
        refused(ctx, "corrupt.mha", HEAD3 "CompressedData = True\nDimSize = 4 4 4\n"
                "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", bad, zn, UMBRA_ERROR_FORMAT,
                "\"", "compressed data");
        refused(ctx, "zshort.mha", HEAD3 "CompressedData = True\nDimSize = 4 4 4\n"
                "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", z, zn - 6,
                UMBRA_ERROR_FORMAT, "the compressed data ends after", "of the 64 bytes");
        refused(ctx, "zlong.mha", HEAD3 "CompressedData = True\nDimSize = 4 4 2\n"
                "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", z, zn, UMBRA_ERROR_FORMAT,
                "holds more than the 32 bytes", NULL);
        snprintf(header, sizeof header, HEAD3 "CompressedData = True\nCompressedDataSize = %zu\n"
                 "DimSize = 4 4 4\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n", zn + 1);
        refused(ctx, "zsize.mha", header, z, zn, UMBRA_ERROR_FORMAT, "CompressedDataSize", NULL);
        free(bad);
        free(z);
    }

    /* A missing data file, named in the message. */
    refused(ctx, "missing.mhd", HEAD3 "DimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = missing.raw\n", NULL, 0, UMBRA_ERROR_IO, "cannot open",
            "missing.raw");
    /* A data file too short for HeaderSize -1. */
    test_write_bytes(tmp_path(path, "four.raw"), data, 4);
    refused(ctx, "end.mhd", HEAD3 "HeaderSize = -1\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
            "ElementDataFile = four.raw\n", NULL, 0, UMBRA_ERROR_FORMAT, "holds 4 bytes",
            "expected 8");
    /* A missing header, and the direct call's arguments. */
    test_assert_failed(ctx, umbra_volume_load_metaimage(ctx, tmp_path(path, "none.mha"), NULL),
                       UMBRA_ERROR_INVALID_ARGUMENT, "out is NULL", NULL);
    {
        umbra_volume vol = NULL;
        test_assert_failed(ctx, umbra_volume_load(ctx, tmp_path(path, "none.mha"), &vol),
                           UMBRA_ERROR_IO, "cannot open", "none.mha");
        test_assert_failed(ctx, umbra_volume_load_metaimage(ctx, NULL, &vol),
                           UMBRA_ERROR_INVALID_ARGUMENT, "path is NULL", NULL);
    }
}

/* ---- the command line ------------------------------------------------------------------------ */

/* umbra-render --volume ball.mha: a bright ball in a dark box, written as ITK would (offset,
 * matrix, compressed); the centre of the picture shows the ball, a corner the background. */
static void test_cli_renders_mha(void **state)
{
    umbra_context ctx = *state;
    const char *exe = getenv("UMBRA_RENDER") ? getenv("UMBRA_RENDER") : "./umbra-render";
    char vol_path[PATH_MAX_LEN], out_path[PATH_MAX_LEN], header[512], cmd[3 * PATH_MAX_LEN];
    unsigned char *vox = malloc(32 * 32 * 32), *z;
    uint32_t w = 0, h = 0;
    float *rgba = NULL;
    size_t zn;
    int x, y, k, rc;
    assert_non_null(vox);
    for (k = 0; k < 32; ++k) {
        for (y = 0; y < 32; ++y) {
            for (x = 0; x < 32; ++x) {
                double dx = x - 15.5, dy = y - 15.5, dz = k - 15.5;
                vox[(k * 32 + y) * 32 + x] = dx * dx + dy * dy + dz * dz < 100 ? 255 : 0;
            }
        }
    }
    z = zlib_pack(vox, 32 * 32 * 32, &zn);
    snprintf(header, sizeof header,
             "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
             "CompressedData = True\nCompressedDataSize = %zu\n"
             "TransformMatrix = 1 0 0 0 -1 0 0 0 -1\nOffset = -40 12 7\n"
             "CenterOfRotation = 0 0 0\nAnatomicalOrientation = RPS\n"
             "ElementSpacing = 1 1 1\nDimSize = 32 32 32\nElementType = MET_UCHAR\n"
             "ElementDataFile = LOCAL\n",
             zn);
    write_mha(tmp_path(vol_path, "ball.mha"), header, z, zn);
    free(z);
    free(vox);
    tmp_path(out_path, "ball.png");
    assert_int_equal(access(exe, X_OK), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' --volume '%s' --technique none --size 48x48 --no-ground --out '%s' 2>/dev/null",
             exe, vol_path, out_path);
    rc = system(cmd);
    assert_int_equal(rc, 0);
    assert_int_equal(umbra_image_read(ctx, out_path, &w, &h, &rgba), UMBRA_SUCCESS);
    assert_int_equal(w, 48);
    assert_int_equal(h, 48);
    {
        const float *centre = rgba + 4 * (24 * 48 + 24), *corner = rgba;
        print_message("centre %g %g %g, corner %g %g %g\n", (double)centre[0], (double)centre[1],
                      (double)centre[2], (double)corner[0], (double)corner[1], (double)corner[2]);
        assert_true(centre[0] > 0.3f);
        assert_float_equal(corner[0], 0.08, 0.01);
    }
    free(rgba);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
#define T(t) cmocka_unit_test_setup_teardown(t, test_group_setup, test_group_teardown)
        T(test_metaimage_uint8_mha),
        T(test_metaimage_types),
        T(test_metaimage_world),
        T(test_metaimage_compressed_and_header_size),
        T(test_metaimage_itk_written_files),
        T(test_metaimage_broken_files_refused),
        T(test_cli_renders_mha),
#undef T
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
