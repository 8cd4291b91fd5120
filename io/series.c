// SPDX-License-Identifier: Apache-2.0
/* io/series.c: volumes made of several files: DICOM series (io/dicom.cpp) and TIFF stacks
 * (io/tiff.c), given as a list of files or as one directory.
 *
 * A directory is read one level deep: its regular files whose names do not start with '.', in
 * natural name order (strverscmp: "slice2" before "slice10"), at most SERIES_MAX_FILES of them;
 * subdirectories are not entered. A directory holding .tif / .tiff files is a TIFF stack of just
 * those; any other is a DICOM series of all its files but DICOMDIR (a media index, no image). Every file a directory or list
 * names is opened by umbra's one file opener (regular files only, never blocking). Neither
 * format lets one file name another that umbra would open: DICOMDIR's references are not
 * followed, and OME-TIFF's multi-file datasets (BinaryOnly, UUID FileName) are refused by the
 * TIFF reader's page count. */
#define _GNU_SOURCE

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "io_internal.h"

#define SERIES_MAX_FILES 65536u

typedef enum series_kind { SERIES_DICOM, SERIES_TIFF, SERIES_ANY } series_kind;

static int compare_versions(const void *a, const void *b)
{
    return strverscmp(*(char *const *)a, *(char *const *)b);
}

static int ends_with_nocase(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n > m && strcasecmp(s + n - m, tail) == 0;
}

int umbra__is_tiff_name(const char *name)
{
    return ends_with_nocase(name, ".tif") || ends_with_nocase(name, ".tiff");
}

static int is_directory(const char *path)
{
    struct stat sb;
    return path && stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
}

static void free_list(char **paths, size_t count)
{
    size_t i;
    for (i = 0; paths && i < count; ++i) {
        free(paths[i]);
    }
    free(paths);
}

/* The files of dir that a series of kind takes, as full paths in natural name order. For
 * SERIES_ANY, *kind_out says which: TIFF when any file is named .tif / .tiff, else DICOM. */
static umbra_status list_directory(umbra_context ctx, const char *func, const char *dir,
                                   series_kind kind, series_kind *kind_out, char ***out,
                                   size_t *count)
{
    char buf[256];
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL;
    size_t n = 0, subdirs = 0, tiffs = 0, kept, i, dir_len = strlen(dir);
    umbra_status st = UMBRA_SUCCESS;

    *out = NULL;
    *count = 0;
    if (!d) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot read the directory \"%s\": %s", func,
                           dir, umbra__errno_text(errno, buf, sizeof buf));
    }
    names = malloc(SERIES_MAX_FILES * sizeof *names);
    if (!names) {
        closedir(d);
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory listing \"%s\"",
                           func, dir);
    }
    while ((e = readdir(d)) != NULL) {
        struct stat sb;
        char *path;
        size_t len;
        if (e->d_name[0] == '.') {
            continue;
        }
        len = dir_len + strlen(e->d_name) + 2;
        path = malloc(len);
        if (!path) {
            st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory listing \"%s\"",
                             func, dir);
            break;
        }
        snprintf(path, len, "%s%s%s", dir, dir_len && dir[dir_len - 1] == '/' ? "" : "/",
                 e->d_name);
        /* stat follows a symbolic link: one to a directory is passed over like a directory, one
         * to anything else is named, and the file opener refuses it unless it is a regular
         * file. */
        if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
            ++subdirs;
            free(path);
            continue;
        }
        if (kind == SERIES_TIFF && !umbra__is_tiff_name(e->d_name)) {
            free(path);
            continue;
        }
        if (n == SERIES_MAX_FILES) {
            free(path);
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\" holds more than %u files (the limit of a series)", func,
                             dir, SERIES_MAX_FILES);
            break;
        }
        tiffs += umbra__is_tiff_name(e->d_name) != 0;
        names[n++] = path;
    }
    closedir(d);
    /* A directory holding TIFFs is a stack of them; otherwise a DICOM series, whose DICOMDIR
     * (a media index) is passed over. */
    if (kind == SERIES_ANY) {
        kind = tiffs > 0 ? SERIES_TIFF : SERIES_DICOM;
    }
    for (i = 0, kept = 0; i < n; ++i) {
        const char *base = strrchr(names[i], '/') + 1;
        if (kind == SERIES_TIFF ? umbra__is_tiff_name(base) : strcmp(base, "DICOMDIR") != 0) {
            names[kept++] = names[i];
        } else {
            free(names[i]);
        }
    }
    n = kept;
    if (st == UMBRA_SUCCESS && n == 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds no %sfiles%s (subdirectories are not searched%s)", func,
                         dir, kind == SERIES_TIFF ? ".tif / .tiff " : "",
                         subdirs ? ", only directories" : "",
                         subdirs ? ": name the series' own directory" : "");
    }
    if (st != UMBRA_SUCCESS) {
        free_list(names, n);
        return st;
    }
    qsort(names, n, sizeof *names, compare_versions);
    if (kind_out) {
        *kind_out = kind;
    }
    *out = names;
    *count = n;
    return UMBRA_SUCCESS;
}

static umbra_status check_arguments(umbra_context ctx, const char *func, const char *const *paths,
                                    size_t count, umbra_volume *out)
{
    size_t i;
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", func);
    }
    *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", func);
    }
    if (!paths || count == 0) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: paths is %s and count %zu: give at least one file or a directory",
                           func, paths ? "set" : "NULL", count);
    }
    if (count > SERIES_MAX_FILES) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: %zu files: at most %u", func,
                           count, SERIES_MAX_FILES);
    }
    for (i = 0; i < count; ++i) {
        if (!paths[i]) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: paths[%zu] is NULL", func,
                               i);
        }
        if (count > 1 && is_directory(paths[i])) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: paths[%zu] \"%s\" is a directory: give one directory by "
                               "itself, or a list of files",
                               func, i, paths[i]);
        }
    }
    return UMBRA_SUCCESS;
}

/* The loader of kind (SERIES_ANY: decided by the directory's contents) on paths, a directory
 * being listed first. */
static umbra_status load_series(umbra_context ctx, const char *func, series_kind kind,
                                const char *const *paths, size_t count, umbra_volume *out)
{
    umbra_status st = check_arguments(ctx, func, paths, count, out);
    char **listed = NULL;
    size_t n = 0;
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    if (count == 1 && is_directory(paths[0])) {
        st = list_directory(ctx, func, paths[0], kind, &kind, &listed, &n);
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        paths = (const char *const *)listed;
        count = n;
    }
    st = kind == SERIES_TIFF ? umbra__volume_load_tiff(ctx, func, paths, count, out)
                             : umbra__volume_load_dicom(ctx, func, paths, count, out);
    free_list(listed, n);
    return st;
}

umbra_status umbra_volume_load_dicom(umbra_context ctx, const char *const *paths, size_t count,
                                     umbra_volume *out)
{
    return load_series(ctx, __func__, SERIES_DICOM, paths, count, out);
}

umbra_status umbra_volume_load_tiff(umbra_context ctx, const char *const *paths, size_t count,
                                    umbra_volume *out)
{
    return load_series(ctx, __func__, SERIES_TIFF, paths, count, out);
}

umbra_status umbra__volume_load_directory(umbra_context ctx, const char *func, const char *dir,
                                          umbra_volume *out)
{
    return load_series(ctx, func, SERIES_ANY, &dir, 1, out);
}
