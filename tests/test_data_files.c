// SPDX-License-Identifier: Apache-2.0
/* tests/test_data_files.c: the data-file policy (#29 item 1). A NRRD, MetaImage or Voreen .dat
 * header names a second file for its voxels; by default that file must resolve inside the
 * header's own directory. Each reader is given each escape (an absolute path, "..", a symbolic
 * link to a file outside, a symbolic link to a directory outside) and must refuse it with
 * UMBRA_ERROR_IO naming the file, before reading a byte of it; the same headers load, with the
 * outside file's exact bytes as voxels, once that directory is a data root
 * (umbra_volume_load_with_options). Data split over several files (NRRD LIST and printf-style
 * names, MetaImage LIST and %d) stays refused whatever is allowed, and malformed options are
 * UMBRA_ERROR_INVALID_ARGUMENT.
 *
 * Layout under the test's temporary directory: hdr/ holds the headers and inside.raw;
 * outside/secret.raw is the file a hostile header wants; hdr/link.raw and hdr/away are symbolic
 * links to outside/secret.raw and outside/. */
#define _XOPEN_SOURCE 700 /* realpath */

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

#include "test_util.h"

#define PATH_LEN 1024

/* 2 x 2 x 2 uchar voxels: the "secret" outside, and the legitimate data inside. */
static const unsigned char secret[8] = {'p', 'a', 's', 's', 'w', 'o', 'r', 'd'};
static const unsigned char inside[8] = {1, 2, 3, 4, 5, 6, 7, 8};

typedef struct dirs {
    char hdr[PATH_LEN], outside[PATH_LEN], secret[PATH_LEN];
    char secret_real[PATH_LEN]; /* as messages name it: realpath'd */
} dirs;

static const char *join(char *buf, const char *dir, const char *name)
{
    int n = snprintf(buf, PATH_LEN, "%s/%s", dir, name);
    assert_true(n > 0 && n < PATH_LEN);
    return buf;
}

/* The layout above, made by the first test that asks for it. */
static void setup_dirs(dirs *d)
{
    char p[PATH_LEN];
    test_tmp_path(d->hdr, sizeof d->hdr, "hdr");
    test_tmp_path(d->outside, sizeof d->outside, "outside");
    join(d->secret, d->outside, "secret.raw");
    if (mkdir(d->hdr, 0700) == 0) {
        assert_int_equal(mkdir(d->outside, 0700), 0);
        test_write_bytes(d->secret, secret, sizeof secret);
        test_write_bytes(join(p, d->hdr, "inside.raw"), inside, sizeof inside);
        assert_int_equal(symlink(d->secret, join(p, d->hdr, "link.raw")), 0);
        assert_int_equal(symlink(d->outside, join(p, d->hdr, "away")), 0);
    }
    assert_non_null(realpath(d->secret, d->secret_real));
}

typedef enum reader { NRRD, METAIMAGE, DAT } reader;

/* Writes a header of the reader's format naming data file name (2 x 2 x 2 uchar) into hdr/,
 * and returns its path in buf. */
static const char *write_header(char *buf, const dirs *d, reader r, const char *name)
{
    char text[2 * PATH_LEN];
    static const char *const files[3] = {"v.nhdr", "v.mhd", "v.dat"};
    switch (r) {
    case NRRD:
        snprintf(text, sizeof text,
                 "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                 "data file: %s\n",
                 name);
        break;
    case METAIMAGE:
        snprintf(text, sizeof text,
                 "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                 "ElementDataFile = %s\n",
                 name);
        break;
    default:
        snprintf(text, sizeof text,
                 "ObjectFileName: %s\nResolution: 2 2 2\nSliceThickness: 1 1 1\nFormat: UCHAR\n",
                 name);
        break;
    }
    join(buf, d->hdr, files[r]);
    test_write_text(buf, text);
    return buf;
}

static void assert_voxels(umbra_volume vol, const unsigned char bytes[8])
{
    static const uint32_t dims[3] = {2, 2, 2};
    static const float spacing[3] = {1, 1, 1};
    double want[8], lo = 255, hi = 0;
    for (int i = 0; i < 8; ++i) {
        want[i] = bytes[i];
        lo = want[i] < lo ? want[i] : lo;
        hi = want[i] > hi ? want[i] : hi;
    }
    test_assert_volume(vol, dims, spacing, want, lo, hi);
}

/* The escapes, as a header names them; each resolves to outside/secret.raw. */
typedef struct escape {
    const char *what;
    char name[PATH_LEN];
} escape;

static int escapes(const dirs *d, escape e[4])
{
    e[0].what = "an absolute path";
    snprintf(e[0].name, PATH_LEN, "%s", d->secret);
    e[1].what = "a .. escape";
    snprintf(e[1].name, PATH_LEN, "../outside/secret.raw");
    e[2].what = "a symbolic link to a file outside";
    snprintf(e[2].name, PATH_LEN, "link.raw");
    e[3].what = "a symbolic link to a directory outside";
    snprintf(e[3].name, PATH_LEN, "away/secret.raw");
    return 4;
}

/* Every reader, every escape: refused by default, with the file named, through the reader itself,
 * umbra_volume_load and umbra_volume_load_with_options(NULL). Before the policy all of them
 * loaded the secret's bytes as voxels. */
static void test_data_file_outside_the_header_directory_is_refused(void **state)
{
    umbra_context ctx = *state;
    dirs d;
    escape e[4];
    char hdr[PATH_LEN];
    umbra_volume vol = NULL;
    setup_dirs(&d);
    int n = escapes(&d, e);
    for (int r = NRRD; r <= DAT; ++r) {
        for (int i = 0; i < n; ++i) {
            umbra_status st;
            write_header(hdr, &d, (reader)r, e[i].name);
            print_message("reader %d, %s (\"%s\")\n", r, e[i].what, e[i].name);
            st = r == NRRD        ? umbra_volume_load_nrrd(ctx, hdr, &vol)
                 : r == METAIMAGE ? umbra_volume_load_metaimage(ctx, hdr, &vol)
                                  : umbra_volume_load_dat(ctx, hdr, &vol);
            test_assert_failed(ctx, st, UMBRA_ERROR_IO, e[i].name, "outside");
            assert_null(vol);
            assert_true(test_message_contains(ctx, "secret.raw"));
            test_assert_failed(ctx, umbra_volume_load(ctx, hdr, &vol), UMBRA_ERROR_IO,
                               "the header's directory", d.secret_real);
            test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, NULL, &vol),
                               UMBRA_ERROR_IO, "outside", NULL);
        }
    }
}

/* What stays inside loads: a plain name, a name through a subdirectory and back (".."), and an
 * absolute path into the header's directory. */
static void test_data_file_inside_the_header_directory_loads(void **state)
{
    umbra_context ctx = *state;
    dirs d;
    char hdr[PATH_LEN], name[PATH_LEN], sub[PATH_LEN];
    umbra_volume vol = NULL;
    setup_dirs(&d);
    join(sub, d.hdr, "sub");
    mkdir(sub, 0700);
    for (int r = NRRD; r <= DAT; ++r) {
        const char *names[3] = {"inside.raw", "sub/../inside.raw", NULL};
        join(name, d.hdr, "inside.raw");
        names[2] = name;
        for (int i = 0; i < 3; ++i) {
            write_header(hdr, &d, (reader)r, names[i]);
            assert_int_equal(umbra_volume_load(ctx, hdr, &vol), UMBRA_SUCCESS);
            assert_voxels(vol, inside);
            umbra_volume_release(vol);
            vol = NULL;
        }
    }
}

/* The opt-in: with outside/ as a data root each escape loads, and the voxels are the file's
 * bytes; "/" allows any file; a root elsewhere still refuses, naming the roots. */
static void test_data_roots_allow_other_locations(void **state)
{
    umbra_context ctx = *state;
    dirs d;
    escape e[4];
    char hdr[PATH_LEN], other[PATH_LEN];
    umbra_volume vol = NULL;
    umbra_volume_load_options o;
    setup_dirs(&d);
    int n = escapes(&d, e);
    test_tmp_path(other, sizeof other, "other");
    mkdir(other, 0700);
    for (int r = NRRD; r <= DAT; ++r) {
        for (int i = 0; i < n; ++i) {
            const char *roots[2] = {other, d.outside};
            write_header(hdr, &d, (reader)r, e[i].name);
            umbra_volume_load_options_init(&o);
            o.data_roots = roots;
            o.data_root_count = 2;
            assert_int_equal(umbra_volume_load_with_options(ctx, hdr, &o, &vol), UMBRA_SUCCESS);
            assert_voxels(vol, secret);
            umbra_volume_release(vol);
            vol = NULL;

            roots[0] = "/";
            o.data_root_count = 1;
            assert_int_equal(umbra_volume_load_with_options(ctx, hdr, &o, &vol), UMBRA_SUCCESS);
            assert_voxels(vol, secret);
            umbra_volume_release(vol);
            vol = NULL;

            roots[0] = other;
            test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                               UMBRA_ERROR_IO, "outside every data root given", d.secret_real);
        }
    }
    /* Formats without detached data pass through unchanged. */
    umbra_volume_load_options_init(&o);
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, "x.vti", &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "unknown extension", NULL);
}

/* Several data files: refused by name even when everything is allowed. */
static void test_multi_file_data_is_refused_whatever_is_allowed(void **state)
{
    umbra_context ctx = *state;
    static const char *const nrrd_forms[3] = {"LIST", "LIST 2", "slice%03d.raw 0 1 1"};
    static const char *const met_forms[2] = {"LIST", "slice%03d.raw 0 1 1"};
    const char *roots[1] = {"/"};
    dirs d;
    char hdr[PATH_LEN];
    umbra_volume vol = NULL;
    umbra_volume_load_options o;
    setup_dirs(&d);
    umbra_volume_load_options_init(&o);
    o.data_roots = roots;
    o.data_root_count = 1;
    for (int i = 0; i < 3; ++i) {
        char name[64];
        snprintf(name, sizeof name, "%s\ninside.raw\ninside.raw", nrrd_forms[i]);
        write_header(hdr, &d, NRRD, name);
        test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                           UMBRA_ERROR_FORMAT, "only one data file", nrrd_forms[i]);
    }
    for (int i = 0; i < 2; ++i) {
        write_header(hdr, &d, METAIMAGE, met_forms[i]);
        test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                           UMBRA_ERROR_UNSUPPORTED, "several files", met_forms[i]);
    }
}

static void test_load_options_are_checked(void **state)
{
    umbra_context ctx = *state;
    dirs d;
    char hdr[PATH_LEN], missing[PATH_LEN];
    const char *roots[2] = {NULL, ""};
    umbra_volume vol = NULL;
    umbra_volume_load_options o;
    setup_dirs(&d);
    write_header(hdr, &d, NRRD, "link.raw");

    umbra_volume_load_options_init(&o);
    assert_int_equal(o.struct_size, sizeof o);
    assert_null(o.data_roots);
    assert_int_equal(o.data_root_count, 0);
    umbra_volume_load_options_init(NULL);

    o.struct_size = 8;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "struct_size is 8", NULL);
    umbra_volume_load_options_init(&o);
    o.data_root_count = 1;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "data_roots is NULL", NULL);
    o.data_roots = roots;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "data_roots[0] is NULL", NULL);
    /* Every root is checked before any is used, even when the first allows the file. */
    roots[0] = d.outside;
    o.data_root_count = 2;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "data_roots[1] is empty", NULL);
    o.data_root_count = 1025;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "1025", "at most 1024");
    roots[0] = join(missing, d.hdr, "no_such_dir");
    o.data_root_count = 1;
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, hdr, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "no_such_dir", "cannot be resolved");
    test_assert_failed(ctx, umbra_volume_load_with_options(ctx, NULL, &o, &vol),
                       UMBRA_ERROR_INVALID_ARGUMENT, "path is NULL", NULL);
    assert_int_equal(umbra_volume_load_with_options(ctx, hdr, &o, NULL),
                     UMBRA_ERROR_INVALID_ARGUMENT);
    umbra_context_take_error(ctx, NULL);
    assert_null(vol);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_data_file_outside_the_header_directory_is_refused),
        cmocka_unit_test(test_data_file_inside_the_header_directory_loads),
        cmocka_unit_test(test_data_roots_allow_other_locations),
        cmocka_unit_test(test_multi_file_data_is_refused_whatever_is_allowed),
        cmocka_unit_test(test_load_options_are_checked),
    };
    return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
