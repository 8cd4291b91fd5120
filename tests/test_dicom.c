// SPDX-License-Identifier: Apache-2.0
/* tests/test_dicom.c: DICOM series and files (umbra_volume_load_dicom, io/dicom.cpp; directories
 * through io/series.c).
 *
 * The files are written here, byte by byte, as DICOM Part 10 files in explicit-VR little endian
 * (the writer below follows PS3.5 and PS3.10; GDCM reads them as any scanner's), so each case can
 * set or break one attribute. The voxel values are an analytic function of (i, j, k) and the
 * slices are written in shuffled order under shuffled names, so a volume read back in the right
 * order, rescaled and placed as ImagePositionPatient and ImageOrientationPatient say, can only
 * come from sorting and rescaling right. Every refusal is checked for its status, a message
 * naming the file and value, and a usable context. The last test runs umbra-render on a
 * directory written here with a preset named by its name. */
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
#include <sys/types.h>
#include <unistd.h>

#include <cmocka.h>

#include "internal.h"
#include "test_util.h"

#define PATH_MAX_LEN 1024
#define NX 6
#define NY 5
#define NZ 8

/* ---- a DICOM writer ---------------------------------------------------------------------- */

typedef struct bytes {
    unsigned char *p;
    size_t n, cap;
} bytes;

static void put(bytes *b, const void *data, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = 2 * (b->n + n) + 256;
        b->p = realloc(b->p, b->cap);
        assert_non_null(b->p);
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
}

static void put_u16(bytes *b, uint16_t v)
{
    unsigned char c[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    put(b, c, 2);
}

static void put_u32(bytes *b, uint32_t v)
{
    unsigned char c[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    put(b, c, 4);
}

/* One explicit-VR element; text values are padded to even length (UI with NUL, others with
 * a space). */
static void element(bytes *b, uint16_t group, uint16_t elem, const char vr[3], const void *value,
                    uint32_t n)
{
    int long_form = strcmp(vr, "OB") == 0 || strcmp(vr, "OW") == 0 || strcmp(vr, "UN") == 0;
    uint32_t padded = n + (n & 1);
    put_u16(b, group);
    put_u16(b, elem);
    put(b, vr, 2);
    if (long_form) {
        put_u16(b, 0);
        put_u32(b, padded);
    } else {
        put_u16(b, (uint16_t)padded);
    }
    put(b, value, n);
    if (n & 1) {
        put(b, strcmp(vr, "UI") == 0 || long_form ? "\0" : " ", 1);
    }
}

static void text(bytes *b, uint16_t group, uint16_t elem, const char vr[3], const char *s)
{
    element(b, group, elem, vr, s, (uint32_t)strlen(s));
}

static void us(bytes *b, uint16_t elem, uint16_t v)
{
    unsigned char c[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    element(b, 0x0028, elem, "US", c, 2);
}

/* What one slice file says; the defaults make a valid CT slice of NX x NY. */
typedef struct slice_spec {
    const char *series;
    uint16_t rows, cols, bits_allocated, bits_stored, pixel_rep, samples;
    double position[3], orientation[6], spacing[2];
    double slope, intercept, thickness;
    int no_position, no_rescale;
    int honest_length;        /* the pixel data element's length is pixel_bytes, not the claim */
    const char *syntax;       /* NULL: explicit VR little endian, uncompressed */
    const void *fragment;     /* with syntax: the one compressed fragment (else RLE of pixels) */
    size_t fragment_bytes;
    const void *pixels;       /* rows x cols samples of bits_allocated */
    size_t pixel_bytes;       /* what the pixel data element holds (may be less: truncated) */
} slice_spec;

static slice_spec default_spec(void)
{
    slice_spec s;
    memset(&s, 0, sizeof s);
    s.series = "1.2.826.0.1.3680043.2.1125.7.1";
    s.rows = NY;
    s.cols = NX;
    s.bits_allocated = 16;
    s.bits_stored = 16;
    s.pixel_rep = 1;
    s.samples = 1;
    s.orientation[0] = 1;
    s.orientation[4] = 1;
    s.spacing[0] = s.spacing[1] = 1;
    s.slope = 1;
    s.thickness = 1;
    return s;
}

/* DICOM RLE Lossless (PS3.5 G): a 64-byte header of segment offsets, then one PackBits segment
 * per byte plane, most significant first; literal runs of up to 128 bytes. */
static void rle_encode(const slice_spec *s, bytes *out)
{
    size_t n = (size_t)s->rows * s->cols, planes = s->bits_allocated / 8u, p, i;
    const unsigned char *px = s->pixels;
    uint32_t header[16] = {0};
    bytes seg = {0};
    header[0] = (uint32_t)planes;
    for (p = 0; p < planes; ++p) {
        header[1 + p] = (uint32_t)(64 + seg.n);
        for (i = 0; i < n; i += 128) {
            size_t run = n - i < 128 ? n - i : 128, k;
            unsigned char c = (unsigned char)(run - 1);
            put(&seg, &c, 1);
            for (k = 0; k < run; ++k) {
                /* little-endian samples: plane p (MSB first) is byte planes-1-p */
                put(&seg, px + (i + k) * planes + (planes - 1 - p), 1);
            }
        }
        if (seg.n & 1) {
            put(&seg, "\x80", 1); /* a no-op byte keeps segments even */
        }
    }
    for (i = 0; i < 16; ++i) {
        put_u32(out, header[i]);
    }
    put(out, seg.p, seg.n);
    free(seg.p);
}

static void write_slice(const char *path, const slice_spec *s, int instance)
{
    bytes meta = {0}, b = {0};
    char buf[256];
    static const unsigned char version[2] = {0, 1};
    static const char *const ct = "1.2.840.10008.5.1.4.1.1.2";
    char sop[64];
    FILE *f;
    snprintf(sop, sizeof sop, "1.2.826.0.1.3680043.2.1125.8.%d", instance);
    element(&meta, 0x0002, 0x0001, "OB", version, 2);
    text(&meta, 0x0002, 0x0002, "UI", ct);
    text(&meta, 0x0002, 0x0003, "UI", sop);
    text(&meta, 0x0002, 0x0010, "UI", s->syntax ? s->syntax : "1.2.840.10008.1.2.1");
    text(&meta, 0x0002, 0x0012, "UI", "1.2.826.0.1.3680043.2.1125.1");

    put(&b, (unsigned char[128]){0}, 128);
    put(&b, "DICM", 4);
    {
        unsigned char len[4] = {(unsigned char)meta.n, (unsigned char)(meta.n >> 8),
                                (unsigned char)(meta.n >> 16), (unsigned char)(meta.n >> 24)};
        element(&b, 0x0002, 0x0000, "UL", len, 4);
    }
    put(&b, meta.p, meta.n);
    text(&b, 0x0008, 0x0016, "UI", ct);
    text(&b, 0x0008, 0x0018, "UI", sop);
    text(&b, 0x0008, 0x0060, "CS", "CT");
    snprintf(buf, sizeof buf, "%g", s->thickness);
    text(&b, 0x0018, 0x0050, "DS", buf);
    text(&b, 0x0020, 0x000d, "UI", "1.2.826.0.1.3680043.2.1125.6");
    text(&b, 0x0020, 0x000e, "UI", s->series);
    snprintf(buf, sizeof buf, "%d", instance);
    text(&b, 0x0020, 0x0013, "IS", buf);
    if (!s->no_position) {
        snprintf(buf, sizeof buf, "%.10g\\%.10g\\%.10g", s->position[0], s->position[1],
                 s->position[2]);
        text(&b, 0x0020, 0x0032, "DS", buf);
        snprintf(buf, sizeof buf, "%.10g\\%.10g\\%.10g\\%.10g\\%.10g\\%.10g", s->orientation[0],
                 s->orientation[1], s->orientation[2], s->orientation[3], s->orientation[4],
                 s->orientation[5]);
        text(&b, 0x0020, 0x0037, "DS", buf);
    }
    us(&b, 0x0002, s->samples);
    text(&b, 0x0028, 0x0004, "CS", s->samples == 1 ? "MONOCHROME2" : "RGB");
    us(&b, 0x0010, s->rows);
    us(&b, 0x0011, s->cols);
    snprintf(buf, sizeof buf, "%.10g\\%.10g", s->spacing[0], s->spacing[1]);
    text(&b, 0x0028, 0x0030, "DS", buf);
    us(&b, 0x0100, s->bits_allocated);
    us(&b, 0x0101, s->bits_stored);
    us(&b, 0x0102, (uint16_t)(s->bits_stored - 1));
    us(&b, 0x0103, s->pixel_rep);
    if (!s->no_rescale) {
        snprintf(buf, sizeof buf, "%.10g", s->intercept);
        text(&b, 0x0028, 0x1052, "DS", buf);
        snprintf(buf, sizeof buf, "%.10g", s->slope);
        text(&b, 0x0028, 0x1053, "DS", buf);
    }
    if (s->syntax) {
        /* Encapsulated: an empty basic offset table, one fragment, the sequence delimiter. */
        bytes frag = {0};
        if (s->fragment) {
            put(&frag, s->fragment, s->fragment_bytes);
        } else {
            rle_encode(s, &frag);
        }
        if (frag.n & 1) {
            put(&frag, "\0", 1);
        }
        put_u16(&b, 0x7fe0);
        put_u16(&b, 0x0010);
        put(&b, "OB", 2);
        put_u16(&b, 0);
        put_u32(&b, 0xffffffffu);
        put_u16(&b, 0xfffe), put_u16(&b, 0xe000), put_u32(&b, 0);
        put_u16(&b, 0xfffe), put_u16(&b, 0xe000), put_u32(&b, (uint32_t)frag.n);
        put(&b, frag.p, frag.n);
        put_u16(&b, 0xfffe), put_u16(&b, 0xe0dd), put_u32(&b, 0);
        free(frag.p);
    } else {
        /* The element's length is what the header claims; the bytes may fall short. */
        size_t claim = (size_t)s->rows * s->cols * s->samples * (s->bits_allocated / 8u);
        put_u16(&b, 0x7fe0);
        put_u16(&b, 0x0010);
        put(&b, s->bits_allocated == 8 ? "OB" : "OW", 2);
        put_u16(&b, 0);
        put_u32(&b, s->honest_length ? (uint32_t)s->pixel_bytes : (uint32_t)(claim + (claim & 1)));
        put(&b, s->pixels, s->pixel_bytes);
    }
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b.p, 1, b.n, f), b.n);
    assert_int_equal(fclose(f), 0);
    free(meta.p);
    free(b.p);
}

/* ---- the analytic series ------------------------------------------------------------------ */

/* Hounsfield value of voxel (i, j, k): distinct everywhere, negative and positive. */
static double hu(int i, int j, int k)
{
    return 10.0 * i + 100.0 * j + 1000.0 * k - 3000.0;
}

/* The series' geometry: rows along +y, columns along -z, so the normal is row x col = -x;
 * PixelSpacing 0.7 (rows) \ 0.9 (columns), slices 2.5 apart. */
static const double ROW[3] = {0, 1, 0}, COL[3] = {0, 0, -1}, NORMAL[3] = {-1, 0, 0};
static const double ORIGIN[3] = {12.5, -40.25, 7.0};
#define STEP 2.5

/* Writes the NZ slices of the analytic volume into dir, slice k as file "im<perm[k]>" in the
 * order perm gives, stored as hu + offset with intercept -offset (and slope 1). spec_edit may
 * change slice k's spec. */
static void write_series(const char *dir, double offset, void (*edit)(slice_spec *, int k))
{
    static const int perm[NZ] = {5, 2, 7, 0, 3, 6, 1, 4};
    int16_t pixels[NX * NY];
    char path[2 * PATH_MAX_LEN];
    int n, k, i, j;
    mkdir(dir, 0700);
    for (n = 0; n < NZ; ++n) {
        slice_spec s = default_spec();
        k = perm[n];
        for (j = 0; j < NY; ++j) {
            for (i = 0; i < NX; ++i) {
                pixels[j * NX + i] = (int16_t)(hu(i, j, k) + offset);
            }
        }
        memcpy(s.orientation, ROW, sizeof ROW);
        memcpy(s.orientation + 3, COL, sizeof COL);
        for (i = 0; i < 3; ++i) {
            s.position[i] = ORIGIN[i] + STEP * k * NORMAL[i];
        }
        s.spacing[0] = 0.7;
        s.spacing[1] = 0.9;
        s.intercept = -offset;
        s.thickness = 3.0; /* not the spacing: the positions are */
        s.pixels = pixels;
        s.pixel_bytes = sizeof pixels;
        if (edit) {
            edit(&s, k);
        }
        snprintf(path, sizeof path, "%s/im%d", dir, 10 + 7 * n % 11);
        write_slice(path, &s, k + 1);
    }
}

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_MAX_LEN, name);
}

static void assert_series_volume(umbra_volume vol, umbra_scalar_type type)
{
    umbra_volume_info info;
    const uint32_t dims[3] = {NX, NY, NZ};
    const float spacing[3] = {0.9f, 0.7f, STEP};
    double want[NX * NY * NZ];
    int i, j, k;
    for (k = 0; k < NZ; ++k) {
        for (j = 0; j < NY; ++j) {
            for (i = 0; i < NX; ++i) {
                want[(k * NY + j) * NX + i] = hu(i, j, k);
            }
        }
    }
    test_assert_volume(vol, dims, spacing, want, hu(0, 0, 0), hu(NX - 1, NY - 1, NZ - 1));
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_true(info.transform_given);
    for (i = 0; i < 3; ++i) {
        assert_float_equal(info.origin[i], ORIGIN[i], 1e-5);
        assert_float_equal(info.directions[i], ROW[i], 1e-6);
        assert_float_equal(info.directions[3 + i], COL[i], 1e-6);
        assert_float_equal(info.directions[6 + i], NORMAL[i], 1e-6);
    }
    assert_int_equal(vol->stored_type, type);
}

/* The series written shuffled loads in position order, rescaled to HU, placed in LPS, as int16,
 * whether given as a directory (with a DICOMDIR and a hidden file beside it) or as a list. */
static void test_dicom_series_sorted_rescaled_placed(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = NULL;
    char dir[PATH_MAX_LEN], path[2 * PATH_MAX_LEN];
    char *list[NZ];
    int n;
    tmp_path(dir, "series");
    write_series(dir, 1024.0, NULL);
    snprintf(path, sizeof path, "%s/DICOMDIR", dir);
    test_write_text(path, "not an image: a media index, passed over");
    snprintf(path, sizeof path, "%s/.hidden", dir);
    test_write_text(path, "passed over");

    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_series_volume(vol, UMBRA_INT16);
    umbra_volume_release(vol);

    for (n = 0; n < NZ; ++n) {
        list[n] = malloc(PATH_MAX_LEN + 16);
        snprintf(list[n], PATH_MAX_LEN + 16, "%s/im%d", dir, 10 + 7 * n % 11);
    }
    assert_int_equal(umbra_volume_load_dicom(ctx, (const char *const *)list, NZ, &vol),
                     UMBRA_SUCCESS);
    assert_series_volume(vol, UMBRA_INT16);
    umbra_volume_release(vol);
    /* One file of it by name (no extension: DICOM by its preamble): one slice, SliceThickness
     * deep. */
    assert_int_equal(umbra_volume_load(ctx, list[0], &vol), UMBRA_SUCCESS);
    {
        umbra_volume_info info;
        assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
        assert_int_equal(info.dims[2], 1);
        assert_float_equal(info.spacing[2], 3.0, 1e-6);
        assert_float_equal(info.spacing[0], 0.9, 1e-6);
    }
    umbra_volume_release(vol);
    for (n = 0; n < NZ; ++n) {
        free(list[n]);
    }
}

static void make_unsigned(slice_spec *s, int k)
{
    (void)k;
    s->pixel_rep = 0;
}

static void make_fractional(slice_spec *s, int k)
{
    (void)k;
    s->slope = 0.5;
}

static void make_identity(slice_spec *s, int k)
{
    (void)k;
    s->no_rescale = 1;
    s->pixel_rep = 0;
}

/* The storage type: integer rescale whose declared range does not fit int16 but whose values
 * do is int16 (a CT in 16 unsigned stored bits, intercept -32768: the range is measured); a
 * fractional slope float32 (exact values); values past int16 float32; no rescale keeps uint16. */
static void test_dicom_storage_type_is_chosen_honestly(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = NULL;
    char dir[PATH_MAX_LEN];
    umbra_volume_info info;

    tmp_path(dir, "unsigned");
    write_series(dir, 32768.0, make_unsigned);
    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_series_volume(vol, UMBRA_INT16);
    umbra_volume_release(vol);

    tmp_path(dir, "fractional");
    write_series(dir, 0.0, make_fractional);
    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_int_equal(vol->stored_type, UMBRA_FLOAT32);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_float_equal(info.value_min, 0.5 * hu(0, 0, 0), 1e-3);
    assert_float_equal(info.value_max, 0.5 * hu(NX - 1, NY - 1, NZ - 1), 1e-3);
    umbra_volume_release(vol);

    /* Stored hu + 3000 unsigned, no rescale: kept as uint16. */
    tmp_path(dir, "identity");
    write_series(dir, 3000.0, make_identity);
    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_int_equal(vol->stored_type, UMBRA_UINT16);
    assert_int_equal(umbra_volume_get_info(vol, &info), UMBRA_SUCCESS);
    assert_float_equal(info.value_min, 0.0, 0.0);
    assert_float_equal(info.value_max, hu(NX - 1, NY - 1, NZ - 1) + 3000.0, 0.0);
    umbra_volume_release(vol);
}

/* ---- hostile series -------------------------------------------------------------------------- */

static void other_series(slice_spec *s, int k)
{
    if (k == 3) {
        s->series = "1.2.3.4.5";
    }
}

static void other_size(slice_spec *s, int k)
{
    if (k == 4) {
        s->rows = NY - 1;
        s->pixel_bytes = (size_t)NX * (NY - 1) * 2;
    }
}

static void truncated(slice_spec *s, int k)
{
    if (k == 6) {
        s->pixel_bytes = 20;
    }
}

static void huge_claim(slice_spec *s, int k)
{
    if (k == 1) {
        s->rows = 65535;
        s->cols = 65535;
        s->honest_length = 1; /* a well-formed file whose header claims 8 GiB of pixels */
    }
}

static void missing_slice(slice_spec *s, int k)
{
    if (k >= 5) {
        s->position[0] -= STEP; /* slice 4 to 5 is two steps */
    }
}

static void same_position(slice_spec *s, int k)
{
    if (k == 2) {
        s->position[0] = ORIGIN[0] - STEP; /* where slice 1 is */
    }
}

static void tilted(slice_spec *s, int k)
{
    s->position[1] += 0.3 * k; /* each slice shifted along its rows: a gantry tilt */
}

static void colour(slice_spec *s, int k)
{
    (void)k;
    s->samples = 3;
    s->honest_length = 1;
}

static void no_position(slice_spec *s, int k)
{
    s->no_position = k == 7;
}

static void bits32(slice_spec *s, int k)
{
    (void)k;
    s->bits_allocated = 32;
    s->bits_stored = 32;
    s->honest_length = 1;
}

static void bad_orientation(slice_spec *s, int k)
{
    if (k == 0) {
        s->orientation[5] = -0.9; /* column no longer at a right angle, nor matching */
    }
}

typedef struct hostile_case {
    const char *name;
    void (*edit)(slice_spec *, int);
    umbra_status status;
    const char *needle, *needle2;
} hostile_case;

static void test_dicom_hostile_series_refused(void **state)
{
    umbra_context ctx = *state;
    static const hostile_case cases[] = {
        {"mixed", other_series, UMBRA_ERROR_FORMAT, "of series \"1.2.3.4.5\"",
         "SeriesInstanceUID"},
        {"sizes", other_size, UMBRA_ERROR_FORMAT, "every slice of a series must match", NULL},
        {"truncated", truncated, UMBRA_ERROR_FORMAT, "(7FE0,0010)", "needs 60 bytes, 20 remain"},
        {"huge", huge_claim, UMBRA_ERROR_FORMAT, "65535 x 65535 x 1 pixels",
         "8589672450 bytes"},
        {"missing", missing_slice, UMBRA_ERROR_FORMAT, "uniformly spaced", "missing slice"},
        {"duplicate", same_position, UMBRA_ERROR_FORMAT, "same position", NULL},
        {"tilted", tilted, UMBRA_ERROR_UNSUPPORTED, "within the slice plane", "gantry"},
        {"colour", colour, UMBRA_ERROR_UNSUPPORTED, "3 samples per pixel", "greyscale"},
        {"noposition", no_position, UMBRA_ERROR_FORMAT, "no ImagePositionPatient", NULL},
        {"bits32", bits32, UMBRA_ERROR_UNSUPPORTED, "BitsAllocated 32", NULL},
        {"orientation", bad_orientation, UMBRA_ERROR_FORMAT, "differ in ImageOrientationPatient",
         NULL},
    };
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        char dir[PATH_MAX_LEN];
        umbra_volume vol = NULL;
        print_message("case %s\n", cases[c].name);
        tmp_path(dir, cases[c].name);
        write_series(dir, 1024.0, cases[c].edit);
        test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), cases[c].status,
                           cases[c].needle, cases[c].needle2);
        assert_null(vol);
    }
}

/* Files that are not a series: a stray text file in a series directory, an empty directory,
 * one of only subdirectories, a FIFO in a list, a file cut inside its header, bad arguments. */
static void test_dicom_hostile_files_refused(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = NULL;
    char dir[PATH_MAX_LEN], path[2 * PATH_MAX_LEN], sub[2 * PATH_MAX_LEN];
    const char *one[1];
    size_t size = 0;
    unsigned char *data;

    tmp_path(dir, "stray");
    write_series(dir, 1024.0, NULL);
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    test_write_text(path, "scanner notes\n");
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_FORMAT, "notes.txt",
                       "is not a DICOM file");

    tmp_path(dir, "empty");
    assert_int_equal(mkdir(dir, 0700), 0);
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_FORMAT,
                       "holds no files", NULL);
    snprintf(sub, sizeof sub, "%s/SERIES1", dir);
    assert_int_equal(mkdir(sub, 0700), 0);
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_FORMAT,
                       "only directories", "name the series' own directory");

    tmp_path(path, "fifo.dcm");
    assert_int_equal(mkfifo(path, 0600), 0);
    one[0] = path;
    test_assert_failed(ctx, umbra_volume_load_dicom(ctx, one, 1, &vol), UMBRA_ERROR_IO,
                       "not a regular file", "FIFO");

    /* A slice cut short inside its header. */
    tmp_path(dir, "stray");
    snprintf(path, sizeof path, "%s/im10", dir);
    data = test_read_bytes(path, &size);
    tmp_path(path, "cut.dcm");
    test_write_bytes(path, data, 300);
    free(data);
    one[0] = path;
    test_assert_failed(ctx, umbra_volume_load_dicom(ctx, one, 1, &vol), UMBRA_ERROR_FORMAT,
                       "cut.dcm", "truncated");

    test_assert_failed(ctx, umbra_volume_load_dicom(ctx, NULL, 1, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "paths is NULL", NULL);
    test_assert_failed(ctx, umbra_volume_load_dicom(ctx, one, 0, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "count 0", NULL);
    {
        const char *two[2] = {path, dir};
        test_assert_failed(ctx, umbra_volume_load_dicom(ctx, two, 2, &vol),
                           UMBRA_ERROR_INVALID_ARGUMENT, "is a directory", NULL);
    }
    assert_null(vol);
}

static void make_rle(slice_spec *s, int k)
{
    (void)k;
    s->syntax = "1.2.840.10008.1.2.5";
}

static const unsigned char junk[40] = {0xff, 0xd8, 0xff, 0xc3, 0x00, 0x0b, 0x10, 0xff, 0xff,
                                       0x7f, 0xff, 0x01, 0x11, 0x00, 0xff, 0xda, 0x00, 0x08,
                                       0x01, 0x01, 0x00, 0x01, 0x00, 0x00, 0x12, 0x34};

static void make_junk_jpeg(slice_spec *s, int k)
{
    (void)k;
    s->syntax = "1.2.840.10008.1.2.4.70"; /* JPEG lossless, first order */
    s->fragment = junk;
    s->fragment_bytes = sizeof junk;
}

/* An RLE header of 2 segments whose second starts past the fragment's end. */
static const unsigned char bad_rle[80] = {2, 0, 0, 0, 64, 0, 0, 0, 0x0f, 0x27};

static void make_junk_rle(slice_spec *s, int k)
{
    (void)k;
    s->syntax = "1.2.840.10008.1.2.5";
    s->fragment = bad_rle;
    s->fragment_bytes = sizeof bad_rle;
}

static void make_junk_j2k(slice_spec *s, int k)
{
    (void)k;
    s->syntax = "1.2.840.10008.1.2.4.90"; /* JPEG 2000 lossless */
    s->fragment = junk;
    s->fragment_bytes = sizeof junk;
}

/* RLE Lossless (decoded by umbra) gives the same volume as the uncompressed series; junk in the
 * place of an RLE fragment is refused with a message naming the fault; JPEG and JPEG 2000 data
 * are refused as unsupported, naming the transfer syntax, before any pixel is read. */
static void test_dicom_compressed_series(void **state)
{
    umbra_context ctx = *state;
    umbra_volume vol = NULL;
    char dir[PATH_MAX_LEN];
    tmp_path(dir, "rle");
    write_series(dir, 1024.0, make_rle);
    assert_int_equal(umbra_volume_load(ctx, dir, &vol), UMBRA_SUCCESS);
    assert_series_volume(vol, UMBRA_INT16);
    umbra_volume_release(vol);
    tmp_path(dir, "junk_rle");
    write_series(dir, 1024.0, make_junk_rle);
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_FORMAT,
                       "cannot decode the RLE pixel data", "segment offset lies outside");
    tmp_path(dir, "junk_jpeg");
    write_series(dir, 1024.0, make_junk_jpeg);
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_UNSUPPORTED,
                       "1.2.840.10008.1.2.4.70", "is not decoded");
    tmp_path(dir, "junk_j2k");
    write_series(dir, 1024.0, make_junk_j2k);
    test_assert_failed(ctx, umbra_volume_load(ctx, dir, &vol), UMBRA_ERROR_UNSUPPORTED,
                       "1.2.840.10008.1.2.4.90", "decompress the series first");
    assert_null(vol);
}

/* umbra-render --volume DIR/ --tf "Cool to Warm" --technique cssm on the series: exit 0 and a
 * picture whose centre is the lit volume, not the background. */
static void test_cli_renders_dicom_directory_with_named_preset(void **state)
{
    char dir[PATH_MAX_LEN], arg[PATH_MAX_LEN + 2];
    tmp_path(dir, "cli_series");
    write_series(dir, 1024.0, NULL);
    snprintf(arg, sizeof arg, "%s/", dir);
    test_cli_renders_with_named_preset(*state, arg, "dicom.png");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dicom_series_sorted_rescaled_placed),
        cmocka_unit_test(test_dicom_storage_type_is_chosen_honestly),
        cmocka_unit_test(test_dicom_hostile_series_refused),
        cmocka_unit_test(test_dicom_hostile_files_refused),
        cmocka_unit_test(test_dicom_compressed_series),
        cmocka_unit_test(test_cli_renders_dicom_directory_with_named_preset),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
