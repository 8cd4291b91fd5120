// SPDX-License-Identifier: Apache-2.0
/* tests/test_nifti_hostile.c: hostile NIfTI files (#29 item 5). Before, nifticlib quietly "fixed"
 * what it did not like: a NaN, negative or huge vox_offset became 352 (or 544), a NaN or infinite
 * scl_slope, scl_inter or pixdim became 0 or 1, any magic "n+N" or a NIfTI-2 magic in a NIfTI-1
 * header was read, NaN and infinite float voxels became 0 (an all-NaN file rendered blank); and
 * it printed "** ERROR ..." to stderr from inside the library. Each case here is a valid file
 * (written with nifticlib, tests/nifti_test.h) with one field patched: it must be refused with
 * UMBRA_ERROR_FORMAT (or UNSUPPORTED) naming the field and the value, and nothing may appear on
 * stderr. Both versions and both byte orders are covered; the gzip form goes through the same
 * checks. */
#define _GNU_SOURCE

#include <fcntl.h>
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
#include <nifti2_io.h>

#include "nifti_test.h"
#include "test_util.h"

#define PATH_LEN 1024

static const char *tmp_path(char *buf, const char *name)
{
    return test_tmp_path(buf, PATH_LEN, name);
}

/* Loads path with stderr (fd 2) captured; *err receives what was printed (NUL-terminated). */
static umbra_status load_capturing_stderr(umbra_context ctx, const char *path, umbra_volume *vol,
                                          char *err, size_t err_size)
{
    char cap[PATH_LEN];
    int saved, fd;
    ssize_t n;
    umbra_status st;
    tmp_path(cap, "stderr.txt");
    fflush(stderr);
    fd = open(cap, O_RDWR | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    saved = dup(2);
    assert_true(saved >= 0);
    assert_int_equal(dup2(fd, 2), 2);
    st = umbra_volume_load(ctx, path, vol);
    fflush(stderr);
    assert_int_equal(dup2(saved, 2), 2);
    close(saved);
    n = pread(fd, err, err_size - 1, 0);
    err[n > 0 ? n : 0] = '\0';
    close(fd);
    return st;
}

/* Refused with status, a message holding needle and needle2 (if not NULL), and a silent stderr. */
static void assert_refused_quietly(umbra_context ctx, const char *path, umbra_status status,
                                   const char *needle, const char *needle2)
{
    char err[4096];
    umbra_volume vol = NULL;
    umbra_status st = load_capturing_stderr(ctx, path, &vol, err, sizeof err);
    if (err[0]) {
        print_message("%s: stderr got \"%s\"\n", path, err);
    }
    assert_string_equal(err, "");
    test_assert_failed(ctx, st, status, needle, needle2);
    assert_null(vol);
}

static unsigned char *test_copy(const unsigned char *b, size_t size)
{
    unsigned char *c = malloc(size);
    assert_non_null(c);
    memcpy(c, b, size);
    return c;
}

/* The size bytes at b, written as a .nii, are refused as assert_refused_quietly says. */
static void refused(umbra_context ctx, const unsigned char *b, size_t size, umbra_status status,
                    const char *needle, const char *needle2)
{
    char path[PATH_LEN];
    test_write_bytes(tmp_path(path, "hostile.nii"), b, size);
    assert_refused_quietly(ctx, path, status, needle, needle2);
}

/* A 2 x 2 x 2 float32 (or uint8) NIfTI-version nver file at path, voxels 0..7, pixdim 1, as
 * nifticlib writes it (host byte order); returns its bytes. */
static unsigned char *valid_file(const char *path, int nver, int datatype, size_t *size)
{
    int64_t dims[8] = {3, 2, 2, 2, 1, 1, 1, 1};
    nifti_image *nim = nifti_make_new_nim(dims, datatype, 1);
    assert_non_null(nim);
    for (int i = 0; i < 8; ++i) {
        if (datatype == DT_FLOAT32) {
            ((float *)nim->data)[i] = (float)i;
        } else {
            ((uint8_t *)nim->data)[i] = (uint8_t)i;
        }
    }
    nim->nifti_type = nver == 2 ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
    test_nifti_write(nim, path);
    return test_read_bytes(path, size);
}

static void put(unsigned char *b, size_t off, const void *v, size_t n)
{
    memcpy(b + off, v, n);
}
static void put_f32(unsigned char *b, size_t off, float v) { put(b, off, &v, 4); }
static void put_f64(unsigned char *b, size_t off, double v) { put(b, off, &v, 8); }
static void put_i16(unsigned char *b, size_t off, int16_t v) { put(b, off, &v, 2); }
static void put_i64(unsigned char *b, size_t off, int64_t v) { put(b, off, &v, 8); }

#define N1(field) offsetof(nifti_1_header, field)
#define N2(field) offsetof(nifti_2_header, field)

/* The valid files load (the patches below are what breaks them). */
static void test_the_valid_files_load(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN], err[4096];
    umbra_volume vol = NULL;
    size_t size;
    for (int nver = 1; nver <= 2; ++nver) {
        free(valid_file(tmp_path(path, nver == 1 ? "good1.nii" : "good2.nii"), nver, DT_FLOAT32,
                        &size));
        assert_int_equal(size, nver == 1 ? 352 + 32 : 544 + 32);
        assert_int_equal(load_capturing_stderr(ctx, path, &vol, err, sizeof err), UMBRA_SUCCESS);
        assert_string_equal(err, "");
        test_assert_volume(vol, (const uint32_t[3]){2, 2, 2}, (const float[3]){1, 1, 1},
                           (const double[8]){0, 1, 2, 3, 4, 5, 6, 7}, 0.0, 7.0);
        umbra_volume_release(vol);
        vol = NULL;
    }
}

/* NaN and infinite float32 voxels, and an all-NaN file: refused, not zeroed. */
static void test_nifti_non_finite_float_voxels_are_refused(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN], bad[PATH_LEN];
    size_t size;
    for (int nver = 1; nver <= 2; ++nver) {
        unsigned char *b = valid_file(tmp_path(path, "f.nii"), nver, DT_FLOAT32, &size);
        size_t off = size - 8 * sizeof(float);
        float nan = NAN, inf = INFINITY;
        put(b, off + 5 * sizeof(float), &nan, sizeof nan);
        refused(ctx, b, size, UMBRA_ERROR_FORMAT, "voxel 5 (x 1, y 0, z 1) is nan",
                "must be finite");
        put(b, off + 5 * sizeof(float), &inf, sizeof inf);
        refused(ctx, b, size, UMBRA_ERROR_FORMAT, "voxel 5", "is inf");
        for (int i = 0; i < 8; ++i) {
            put(b, off + i * sizeof(float), &nan, sizeof nan);
        }
        tmp_path(bad, "all_nan.nii.gz");
        {
            znzFile z = znzopen(bad, "wb", 1);
            assert_int_equal(znzwrite(b, 1, size, z), size);
            Xznzclose(&z);
        }
        assert_refused_quietly(ctx, bad, UMBRA_ERROR_FORMAT, "voxel 0", "is nan");
        free(b);
    }
}

/* vox_offset NaN, negative, past the file, beyond any integer, or not a whole number. */
static void test_nifti_bad_vox_offset_is_refused(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN];
    size_t size;
    unsigned char *b = valid_file(tmp_path(path, "u1.nii"), 1, DT_UINT8, &size);
    static const struct {
        float v;
        const char *shown;
    } cases[] = {{NAN, "nan"}, {-1000.0f, "-1000"}, {1e20f, "1e+20"}, {3e9f, "3000000000"},
                 {100.0f, "100"}, {352.5f, "352.5"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        put_f32(b, N1(vox_offset), cases[i].v);
        refused(ctx, b, size, UMBRA_ERROR_FORMAT, "vox_offset", cases[i].shown);
    }
    /* Past the end of the file: the size check names both numbers. */
    put_f32(b, N1(vox_offset), 4096.0f);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "holds 360 bytes", "4096 + 8");
    free(b);

    b = valid_file(tmp_path(path, "u2.nii"), 2, DT_UINT8, &size);
    put_i64(b, N2(vox_offset), -1000);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "vox_offset", "-1000");
    put_i64(b, N2(vox_offset), INT64_MAX);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "vox_offset", "9223372036854775807");
    free(b);
}

/* scl_slope / scl_inter and pixdim that are NaN or infinite. */
static void test_nifti_non_finite_slope_and_pixdim_are_refused(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN];
    size_t size;
    unsigned char *b = valid_file(tmp_path(path, "u1.nii"), 1, DT_UINT8, &size);
    unsigned char *keep = test_copy(b, size); /* the valid file, to start each case from */
    put_f32(b, N1(scl_slope), NAN);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "scl_slope nan", "finite");
    put_f32(b, N1(scl_slope), INFINITY);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "scl_slope inf", NULL);
    put_f32(b, N1(scl_slope), 2.0f);
    put_f32(b, N1(scl_inter), -INFINITY);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "scl_inter -inf", NULL);
    memcpy(b, keep, size);
    for (int k = 0; k <= 3; ++k) {
        put_f32(b, N1(pixdim) + 4 * (size_t)k, k == 2 ? INFINITY : NAN);
        char needle[32];
        snprintf(needle, sizeof needle, "pixdim[%d] %s", k, k == 2 ? "inf" : "nan");
        refused(ctx, b, size, UMBRA_ERROR_FORMAT, needle, NULL);
        memcpy(b, keep, size);
    }
    /* With a qform or sform, their own numbers must be finite too (nifticlib made them 0). */
    put_i16(b, N1(qform_code), 1);
    put_f32(b, N1(quatern_c), NAN);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "quatern_c nan", NULL);
    memcpy(b, keep, size);
    put_i16(b, N1(sform_code), 1);
    put_f32(b, N1(srow_y) + 4, INFINITY);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "srow_y[1] inf", NULL);
    free(keep);
    free(b);

    b = valid_file(tmp_path(path, "u2.nii"), 2, DT_UINT8, &size);
    put_f64(b, N2(scl_slope), NAN);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "scl_slope nan", NULL);
    put_f64(b, N2(scl_slope), 1.0);
    put_f64(b, N2(pixdim) + 8, -INFINITY);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "pixdim[1] -inf", NULL);
    free(b);
}

/* Magic: only "n+1\0" (NIfTI-1) and "n+2\0\r\n\032\n" (NIfTI-2) are single-file NIfTI. */
static void test_nifti_bad_magic_is_refused(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN];
    size_t size;
    unsigned char *b = valid_file(tmp_path(path, "u1.nii"), 1, DT_UINT8, &size);
    static const char *const magics[] = {"n+5", "n+2", "N+1", "xyz"};
    for (size_t i = 0; i < sizeof magics / sizeof magics[0]; ++i) {
        put(b, N1(magic), magics[i], 4);
        refused(ctx, b, size, UMBRA_ERROR_FORMAT, "magic", magics[i]);
    }
    put(b, N1(magic), "ni1", 4);
    refused(ctx, b, size, UMBRA_ERROR_UNSUPPORTED, "ni1", ".hdr/.img");
    free(b);

    b = valid_file(tmp_path(path, "u2.nii"), 2, DT_UINT8, &size);
    put(b, N2(magic), "n+2\0\r\n\032X", 8);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "magic", "NIfTI-2");
    put(b, N2(magic), "n+1\0\r\n\032\n", 8);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "magic", "n+1");
    free(b);
}

/* What made nifticlib print: a sizeof_hdr of neither version, datatype 0 (DT_UNKNOWN), dim[1]
 * of 0, a zero-length and a truncated header. Refused in umbra's words, nothing on stderr. */
static void test_nifti_never_prints(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN];
    size_t size;
    unsigned char *b = valid_file(tmp_path(path, "u1.nii"), 1, DT_UINT8, &size);
    unsigned char *keep = test_copy(b, size); /* the valid file, to start each case from */
    put_i16(b, N1(datatype), DT_UNKNOWN);
    refused(ctx, b, size, UMBRA_ERROR_UNSUPPORTED, "datatype", "(0)");
    memcpy(b, keep, size);
    put_i16(b, N1(dim) + 2, 0);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "dim 1 (of 3) is 0", NULL);
    memcpy(b, keep, size);
    put_i16(b, N1(dim) + 6, -4);
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "dim 3 (of 3) is -4", NULL);
    memcpy(b, keep, size);
    {
        int32_t s = 349;
        put(b, 0, &s, 4);
    }
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "sizeof_hdr 349", "348");
    refused(ctx, keep, 200, UMBRA_ERROR_FORMAT, "holds 200 bytes", NULL);
    refused(ctx, keep, 0, UMBRA_ERROR_FORMAT, "holds 0 bytes", NULL);
    free(keep);
    free(b);
}

/* The other byte order: a big-endian file (on this little-endian host) is swapped and read, and
 * its hostile fields are seen after the swap. */
static void test_nifti_swapped_byte_order(void **state)
{
    umbra_context ctx = *state;
    char path[PATH_LEN], bad[PATH_LEN];
    umbra_volume vol = NULL;
    size_t size;
    unsigned char *b = valid_file(tmp_path(path, "f1.nii"), 1, DT_FLOAT32, &size);
    nifti_1_header h;
    memcpy(&h, b, sizeof h);
    nifti_swap_as_nifti1(&h);
    memcpy(b, &h, sizeof h);
    nifti_swap_4bytes(8, b + size - 32);
    test_write_bytes(tmp_path(bad, "big1.nii"), b, size);
    assert_int_equal(umbra_volume_load(ctx, bad, &vol), UMBRA_SUCCESS);
    test_assert_volume(vol, (const uint32_t[3]){2, 2, 2}, (const float[3]){1, 1, 1},
                       (const double[8]){0, 1, 2, 3, 4, 5, 6, 7}, 0.0, 7.0);
    umbra_volume_release(vol);
    {
        float v = NAN;
        nifti_swap_4bytes(1, &v);
        put(b, N1(scl_slope), &v, 4);
    }
    refused(ctx, b, size, UMBRA_ERROR_FORMAT, "scl_slope nan", NULL);
    free(b);
}

int main(void)
{
#define T(t) cmocka_unit_test(t)
    const struct CMUnitTest tests[] = {
        T(test_the_valid_files_load),
        T(test_nifti_non_finite_float_voxels_are_refused),
        T(test_nifti_bad_vox_offset_is_refused),
        T(test_nifti_non_finite_slope_and_pixdim_are_refused),
        T(test_nifti_bad_magic_is_refused),
        T(test_nifti_never_prints),
        T(test_nifti_swapped_byte_order),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
