// SPDX-License-Identifier: Apache-2.0
/* tests/test_tiff.c: TIFF stacks and OME-TIFF (umbra_volume_load_tiff, io/tiff.c; directories
 * through io/series.c).
 *
 * The files are written here with libtiff's writer (strips and tiles, LZW and deflate), with
 * voxel values an analytic function of (i, j, k), so a volume read back equal to it comes from
 * reading every page, strip and tile in the right place. OME-XML is written by hand. Broken
 * files are made by writing a good one and cutting or patching it. Every refusal is checked for
 * its status, a message naming the file and value, and a usable context. The last test runs
 * umbra-render on a stack written here. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>
#include <tiffio.h>

#include "internal.h"
#include "test_util.h"

#define PATH_MAX_LEN 1024

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

/* The value of voxel (i, j, k) of each sample type. */
static double value(int i, int j, int k, int bits, int format)
{
    if (format == SAMPLEFORMAT_IEEEFP) {
        return 0.25 * i - 1.5 * j + 10.0 * k - 7.0;
    }
    if (format == SAMPLEFORMAT_INT) {
        return bits == 8 ? i + 3 * j + 20 * k - 60 : 7 * i - 300 * j + 1000 * k - 2000;
    }
    return bits == 8 ? i + 3 * j + 20 * k : 7 * i + 300 * j + 1000 * k;
}

typedef struct stack_spec {
    uint32_t width, height, pages;
    uint16_t bits, format, samples, compression;
    uint32_t tile;            /* 0: strips of 2 rows */
    const char *description;  /* the first page's ImageDescription */
    int reduced_page;         /* also write a half-size reduced-resolution page after page 0 */
    uint32_t odd_page;        /* 1 + the page written one pixel wider (0: none) */
} stack_spec;

static stack_spec spec(uint32_t w, uint32_t h, uint32_t pages, uint16_t bits, uint16_t format)
{
    stack_spec s;
    memset(&s, 0, sizeof s);
    s.width = w, s.height = h, s.pages = pages, s.bits = bits, s.format = format;
    s.samples = 1;
    s.compression = COMPRESSION_LZW;
    return s;
}

static void write_page(TIFF *t, const stack_spec *s, uint32_t w, uint32_t h, int k, int reduced)
{
    size_t bps = s->bits / 8u, row = (size_t)w * bps * s->samples;
    unsigned char *buf = calloc((size_t)h, row);
    uint32_t x, y;
    assert_non_null(buf);
    for (y = 0; y < h; ++y) {
        for (x = 0; x < w * s->samples; ++x) {
            double v = value((int)(x / s->samples), (int)y, k, s->bits, s->format);
            unsigned char *p = buf + y * row + x * bps;
            if (s->format == SAMPLEFORMAT_IEEEFP && s->bits == 32) {
                float f = (float)v;
                memcpy(p, &f, 4);
            } else if (s->bits == 8) {
                *p = (unsigned char)(int)v;
            } else {
                uint16_t u = (uint16_t)(int)v;
                memcpy(p, &u, 2);
            }
        }
    }
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, w);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, h);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, s->bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, s->samples);
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, s->format);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, s->samples == 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, s->compression);
    if (reduced) {
        TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_REDUCEDIMAGE);
    }
    if (k == 0 && !reduced && s->description) {
        TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, s->description);
    }
    if (s->tile) {
        uint32_t tx, ty, r;
        unsigned char *tilebuf = calloc((size_t)s->tile * s->tile, bps * s->samples);
        assert_non_null(tilebuf);
        TIFFSetField(t, TIFFTAG_TILEWIDTH, s->tile);
        TIFFSetField(t, TIFFTAG_TILELENGTH, s->tile);
        for (ty = 0; ty < h; ty += s->tile) {
            for (tx = 0; tx < w; tx += s->tile) {
                memset(tilebuf, 0, (size_t)s->tile * s->tile * bps * s->samples);
                for (r = 0; r < s->tile && ty + r < h; ++r) {
                    uint32_t cols = w - tx < s->tile ? w - tx : s->tile;
                    memcpy(tilebuf + (size_t)r * s->tile * bps * s->samples,
                           buf + (ty + r) * row + (size_t)tx * bps * s->samples,
                           (size_t)cols * bps * s->samples);
                }
                assert_true(TIFFWriteTile(t, tilebuf, tx, ty, 0, 0) > 0);
            }
        }
        free(tilebuf);
    } else {
        TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 2);
        for (y = 0; y < h; ++y) {
            assert_int_equal(TIFFWriteScanline(t, buf + y * row, y, 0), 1);
        }
    }
    assert_int_equal(TIFFWriteDirectory(t), 1);
    free(buf);
}

static void write_stack(const char *path, const stack_spec *s)
{
    TIFF *t = TIFFOpen(path, "w");
    uint32_t k;
    assert_non_null(t);
    for (k = 0; k < s->pages; ++k) {
        write_page(t, s, s->width + (s->odd_page == k + 1), s->height, (int)k, 0);
        if (k == 0 && s->reduced_page) {
            write_page(t, s, s->width / 2, s->height / 2, 0, 1);
        }
    }
    TIFFClose(t);
}

/* vol holds value(i, j, k) for the stack of s, with unit spacing and the centred box. */
static void assert_stack(umbra_volume vol, const stack_spec *s, umbra_scalar_type type,
                         const float spacing[3])
{
    const uint32_t dims[3] = {s->width, s->height, s->pages};
    const float one[3] = {1, 1, 1};
    size_t n = (size_t)s->width * s->height * s->pages;
    double *want = malloc(n * sizeof *want), lo, hi;
    umbra_volume_info info;
    uint32_t i, j, k;
    assert_non_null(want);
    for (k = 0; k < s->pages; ++k) {
        for (j = 0; j < s->height; ++j) {
            for (i = 0; i < s->width; ++i) {
                want[((size_t)k * s->height + j) * s->width + i] =
                    value((int)i, (int)j, (int)k, s->bits, s->format);
            }
        }
    }
    lo = hi = want[0];
    for (i = 0; i < n; ++i) {
        lo = fmin(lo, want[i]);
        hi = fmax(hi, want[i]);
    }
    test_assert_volume(vol, dims, spacing ? spacing : one, want, lo, hi);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_false(info.transform_given);
    assert_int_equal(vol->stored_type, type);
    free(want);
}

/* Multi-page stacks of every sample type, stripped (LZW) and tiled (deflate, tiles past the
 * edge), with a reduced-resolution page among them that is passed over. */
static void test_tiff_stacks_of_every_type(void **state)
{
    umbra_context ctx = *state;
    struct {
        stack_spec s;
        umbra_scalar_type type;
    } cases[5];
    char path[PATH_MAX_LEN];
    size_t c;
    cases[0].s = spec(7, 5, 4, 16, SAMPLEFORMAT_UINT), cases[0].type = UMBRA_UINT16;
    cases[1].s = spec(20, 18, 3, 32, SAMPLEFORMAT_IEEEFP), cases[1].type = UMBRA_FLOAT32;
    cases[1].s.tile = 16, cases[1].s.compression = COMPRESSION_ADOBE_DEFLATE;
    cases[2].s = spec(6, 4, 3, 8, SAMPLEFORMAT_UINT), cases[2].type = UMBRA_UINT8;
    cases[2].s.reduced_page = 1;
    cases[3].s = spec(6, 4, 3, 8, SAMPLEFORMAT_INT), cases[3].type = UMBRA_INT16;
    cases[4].s = spec(5, 6, 2, 16, SAMPLEFORMAT_INT), cases[4].type = UMBRA_INT16;
    cases[4].s.compression = COMPRESSION_NONE;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        umbra_volume vol = NULL;
        print_message("case %zu\n", c);
        tmp_path(path, "stack.tif");
        write_stack(path, &cases[c].s);
        assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
        assert_stack(vol, &cases[c].s, cases[c].type, NULL);
        umbra_volume_release(vol);
    }
}

/* A directory of single-page TIFFs in natural name order (s2 before s10), other files beside
 * them passed over; the same files as a list in the order given. */
static void test_tiff_directory_and_list(void **state)
{
    umbra_context ctx = *state;
    static const char *const names[4] = {"s1.tif", "s2.tif", "s10.TIF", "s11.tiff"};
    char dir[PATH_MAX_LEN], path[2 * PATH_MAX_LEN], *list[4];
    stack_spec s = spec(6, 5, 4, 16, SAMPLEFORMAT_UINT);
    umbra_volume vol = NULL;
    int k;
    tmp_path(dir, "slices");
    assert_int_equal(mkdir(dir, 0700), 0);
    for (k = 0; k < 4; ++k) {
        TIFF *t;
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        t = TIFFOpen(path, "w");
        assert_non_null(t);
        write_page(t, &s, s.width, s.height, k, 0);
        TIFFClose(t);
        list[k] = strdup(path);
    }
    snprintf(path, sizeof path, "%s/README.txt", dir);
    test_write_text(path, "microscope notes\n");
    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_stack(vol, &s, UMBRA_UINT16, NULL);
    umbra_volume_release(vol);
    assert_int_equal(umbra_volume_load_tiff(ctx, (const char *const *)list, 4, &vol),
                     UMBRA_SUCCESS);
    assert_stack(vol, &s, UMBRA_UINT16, NULL);
    umbra_volume_release(vol);
    for (k = 0; k < 4; ++k) {
        free(list[k]);
    }
}

#define OME_HEAD                                                                                \
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>"                                                \
    "<OME xmlns=\"http://www.openmicroscopy.org/Schemas/OME/2016-06\">"                         \
    "<Image ID=\"Image:0\"><Pixels ID=\"Pixels:0\" DimensionOrder=\"XYZCT\" Type=\"uint16\" "
#define OME_TAIL "><TiffData/></Pixels></Image></OME>"

/* OME-XML's physical sizes become the spacing, in the x axis's unit (nm converted to um). */
static void test_ome_tiff_spacing(void **state)
{
    umbra_context ctx = *state;
    stack_spec s = spec(7, 5, 4, 16, SAMPLEFORMAT_UINT);
    const float spacing[3] = {0.5f, 0.25f, 2.0f};
    char path[PATH_MAX_LEN];
    umbra_volume vol = NULL;
    s.description = OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"4\" SizeC=\"1\" SizeT=\"1\" "
                             "PhysicalSizeX=\"0.5\" PhysicalSizeY=\"0.25\" "
                             "PhysicalSizeYUnit=\"\xc2\xb5m\" PhysicalSizeZ=\"2000\" "
                             "PhysicalSizeZUnit=\"nm\"" OME_TAIL;
    tmp_path(path, "cells.ome.tif");
    write_stack(path, &s);
    assert_int_equal(umbra_volume_load(ctx, path, &vol), UMBRA_SUCCESS);
    assert_stack(vol, &s, UMBRA_UINT16, spacing);
    umbra_volume_release(vol);
}

/* Sets ImageWidth and ImageLength of a little-endian TIFF's first page to n, in place. */
static void patch_size(unsigned char *data, size_t size, uint32_t n)
{
    uint32_t ifd = (uint32_t)data[4] | (uint32_t)data[5] << 8 | (uint32_t)data[6] << 16 |
                   (uint32_t)data[7] << 24;
    unsigned entries, e, patched = 0;
    assert_true(data[0] == 'I' && ifd + 2 <= size);
    entries = data[ifd] | (unsigned)data[ifd + 1] << 8;
    for (e = 0; e < entries; ++e) {
        unsigned char *p = data + ifd + 2 + 12 * e;
        unsigned tag = p[0] | (unsigned)p[1] << 8, type = p[2] | (unsigned)p[3] << 8;
        assert_true((size_t)(p + 12 - data) <= size);
        if (tag == 256 || tag == 257) {
            memset(p + 8, 0, 4);
            p[8] = (unsigned char)n;
            p[9] = (unsigned char)(n >> 8);
            if (type == 4) {
                p[10] = (unsigned char)(n >> 16);
                p[11] = (unsigned char)(n >> 24);
            }
            ++patched;
        }
    }
    assert_int_equal(patched, 2);
}

typedef struct bad_ome {
    const char *xml;
    umbra_status status;
    const char *needle;
} bad_ome;

static void test_tiff_hostile_files_refused(void **state)
{
    umbra_context ctx = *state;
    static const bad_ome omes[] = {
        {OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"2\" SizeC=\"2\" SizeT=\"1\"" OME_TAIL,
         UMBRA_ERROR_UNSUPPORTED, "SizeC 2"},
        {OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"3\" SizeC=\"1\" SizeT=\"1\"" OME_TAIL,
         UMBRA_ERROR_FORMAT, "does not match"},
        {OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"4\" PhysicalSizeX=\"-1\"" OME_TAIL,
         UMBRA_ERROR_FORMAT, "PhysicalSizeX does not parse"},
        {OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"4\" PhysicalSizeX=\"1\" "
                  "PhysicalSizeXUnit=\"furlong\"" OME_TAIL,
         UMBRA_ERROR_UNSUPPORTED, "furlong"},
        {OME_HEAD "SizeX=\"7\" SizeY=\"5\" SizeZ=\"4\"><Pixels" OME_TAIL, UMBRA_ERROR_FORMAT,
         "not well-formed"},
    };
    char path[PATH_MAX_LEN], dir[PATH_MAX_LEN], cut[PATH_MAX_LEN];
    umbra_volume vol = NULL;
    stack_spec s;
    unsigned char *data;
    size_t size = 0, c;
    const char *two[2];

    for (c = 0; c < sizeof omes / sizeof omes[0]; ++c) {
        print_message("ome case %zu\n", c);
        s = spec(7, 5, 4, 16, SAMPLEFORMAT_UINT);
        s.description = omes[c].xml;
        tmp_path(path, "bad.ome.tif");
        write_stack(path, &s);
        test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), omes[c].status,
                           omes[c].needle, "bad.ome.tif");
    }

    s = spec(7, 5, 4, 16, SAMPLEFORMAT_UINT);
    s.odd_page = 3;
    tmp_path(path, "odd.tif");
    write_stack(path, &s);
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_FORMAT,
                       "page 2 is 8 x 5", "every slice must match");

    s = spec(7, 5, 2, 8, SAMPLEFORMAT_UINT);
    s.samples = 3;
    tmp_path(path, "rgb.tif");
    write_stack(path, &s);
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_UNSUPPORTED,
                       "3 samples per pixel", "greyscale");

    s = spec(7, 5, 2, 16, SAMPLEFORMAT_IEEEFP); /* half floats */
    tmp_path(path, "half.tif");
    write_stack(path, &s);
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_UNSUPPORTED,
                       "16-bit float samples are not supported", NULL);

    /* Cut inside the last page's strips (uncompressed, so the strip is short). */
    s = spec(40, 30, 3, 16, SAMPLEFORMAT_UINT);
    s.compression = COMPRESSION_NONE;
    tmp_path(path, "whole.tif");
    write_stack(path, &s);
    data = test_read_bytes(path, &size);
    tmp_path(cut, "cut.tif");
    test_write_bytes(cut, data, size - 1500);
    free(data);
    test_assert_failed(ctx, umbra_volume_load(ctx, cut, &vol), UMBRA_ERROR_FORMAT, "cut.tif",
                       NULL);

    /* A deflate file whose first page claims 40000 x 40000 pixels (its ImageWidth and
     * ImageLength patched): the claim is refused from the file's size before anything is
     * allocated. */
    s = spec(100, 100, 1, 16, SAMPLEFORMAT_UINT);
    s.compression = COMPRESSION_ADOBE_DEFLATE;
    tmp_path(path, "claim.tif");
    write_stack(path, &s);
    data = test_read_bytes(path, &size);
    patch_size(data, size, 40000);
    test_write_bytes(path, data, size);
    free(data);
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_FORMAT,
                       "more than 1032 times", "40000 x 40000 x 1");

    tmp_path(path, "text.tif");
    test_write_text(path, "not a TIFF at all\n");
    test_assert_failed(ctx, umbra_volume_load(ctx, path, &vol), UMBRA_ERROR_FORMAT,
                       "is not a TIFF file", NULL);

    /* A multi-page file in a list. */
    s = spec(7, 5, 2, 16, SAMPLEFORMAT_UINT);
    tmp_path(path, "two.tif");
    write_stack(path, &s);
    two[0] = path;
    two[1] = path;
    test_assert_failed(ctx, umbra_volume_load_tiff(ctx, two, 2, &vol), UMBRA_ERROR_FORMAT,
                       "has several pages", NULL);

    tmp_path(dir, "no_tiffs");
    assert_int_equal(mkdir(dir, 0700), 0);
    two[0] = dir;
    test_assert_failed(ctx, umbra_volume_load_tiff(ctx, two, 1, &vol), UMBRA_ERROR_FORMAT,
                       "holds no .tif / .tiff files", NULL);
    assert_null(vol);
}

/* umbra-render --volume stack.tif --tf "Cool to Warm" --technique cssm: exit 0 and a lit
 * volume in the middle of the picture. */
static void test_cli_renders_tiff_stack(void **state)
{
    char path[PATH_MAX_LEN];
    stack_spec s = spec(24, 24, 24, 16, SAMPLEFORMAT_UINT);
    tmp_path(path, "cli.tif");
    write_stack(path, &s);
    test_cli_renders_with_named_preset(*state, path, "tiff.png");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tiff_stacks_of_every_type),
        cmocka_unit_test(test_tiff_directory_and_list),
        cmocka_unit_test(test_ome_tiff_spacing),
        cmocka_unit_test(test_tiff_hostile_files_refused),
        cmocka_unit_test(test_cli_renders_tiff_stack),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
