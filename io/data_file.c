// SPDX-License-Identifier: Apache-2.0
/* io/data_file.c: the data-file policy, where a header may send a reader for its voxels.
 *
 * NRRD ("data file"), MetaImage (ElementDataFile) and Voreen .dat (ObjectFileName) headers name a
 * second file. Read as written, a five-line header from anywhere (an upload) could name the
 * system's password file, "../../x" or a symbolic link out of its folder, and umbra would render
 * those bytes, where they can be read back from the image. So every such file is opened here:
 * its name is joined to the header's directory (unless absolute), resolved with realpath (every
 * symbolic link and ".." followed), and must then lie inside the header's own (resolved)
 * directory or inside one of the caller's data roots (umbra_volume_load_options), else the load
 * is UMBRA_ERROR_IO naming the file, where it resolves to and what is allowed. The file is then
 * opened by name as every input is (umbra__file_open: regular files only, never blocking), and
 * the descriptor must be the file that was checked (same device and inode), so a link swapped
 * between the check and the open is refused too. A directory that the attacker can keep changing
 * while the load runs (swapping one of the resolved path's own directories for a link between the
 * open and the last check) is beyond what a path check can close.
 *
 * Also here: umbra_volume_load_with_options, the by-extension loader that passes the options on to
 * the readers that have detached data. */
#define _XOPEN_SOURCE 700 /* realpath */

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io_internal.h"

/* Messages quote at most this much of a name taken from a file. */
#define QUOTE_MAX 200

void umbra_volume_load_options_init(umbra_volume_load_options *options)
{
    if (!options) {
        return;
    }
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->data_roots = NULL;
    options->data_root_count = 0;
}

umbra_status umbra__load_options_check(umbra_context ctx, const char *func,
                                       const umbra_volume_load_options *options)
{
    size_t i;
    if (!options) {
        return UMBRA_SUCCESS;
    }
    if (options->struct_size != sizeof(umbra_volume_load_options)) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: options->struct_size is %zu, expected %zu (call "
                           "umbra_volume_load_options_init)",
                           func, options->struct_size, sizeof(umbra_volume_load_options));
    }
    if (options->data_root_count > UMBRA_DATA_ROOTS_MAX) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: options->data_root_count is %zu; at most %d data roots", func,
                           options->data_root_count, UMBRA_DATA_ROOTS_MAX);
    }
    if (options->data_root_count > 0 && !options->data_roots) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: options->data_roots is NULL with data_root_count %zu", func,
                           options->data_root_count);
    }
    for (i = 0; i < options->data_root_count; ++i) {
        if (!options->data_roots[i] || options->data_roots[i][0] == '\0') {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: options->data_roots[%zu] is %s; each must name a directory",
                               func, i, options->data_roots[i] ? "empty" : "NULL");
        }
    }
    return UMBRA_SUCCESS;
}

/* 1 if the resolved path p is dir or lies below it (dir resolved too, without a trailing slash
 * except for "/" itself). */
static int path_within(const char *p, const char *dir)
{
    size_t n = strlen(dir);
    if (n == 1 && dir[0] == '/') {
        return 1;
    }
    return strncmp(p, dir, n) == 0 && (p[n] == '/' || p[n] == '\0');
}

/* The header's directory as written ("." when the path has no slash, "/" for a file at the
 * root), malloc'ed. */
static char *header_dir(const char *header_path)
{
    const char *slash = strrchr(header_path, '/');
    size_t n = !slash ? 1 : slash == header_path ? 1 : (size_t)(slash - header_path);
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, slash ? header_path : ".", n);
        d[n] = '\0';
    }
    return d;
}

/* name joined to the header's directory unless absolute, malloc'ed. */
static char *join_to_header(const char *header_path, const char *name)
{
    const char *slash = strrchr(header_path, '/');
    size_t dir = (name[0] == '/' || !slash) ? 0 : (size_t)(slash - header_path) + 1;
    char *p = malloc(dir + strlen(name) + 1);
    if (p) {
        memcpy(p, header_path, dir);
        strcpy(p + dir, name);
    }
    return p;
}

umbra_status umbra__data_file_open(umbra_context ctx, const char *func, const char *header_path,
                                   const char *name, const umbra_volume_load_options *options,
                                   char **shown, FILE **out, size_t *size)
{
    umbra_status st = UMBRA_SUCCESS;
    char *joined = NULL, *resolved = NULL, *dir = NULL, *dir_real = NULL, *root_real = NULL;
    char ebuf[256];
    struct stat opened, checked;
    FILE *f = NULL;
    size_t i, roots = options ? options->data_root_count : 0;
    int allowed = 0;

    *shown = NULL;
    *out = NULL;
    *size = 0;
    joined = join_to_header(header_path, name);
    dir = header_dir(header_path);
    if (!joined || !dir) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory for \"%s\"", func,
                         header_path);
        goto fail;
    }
    resolved = realpath(joined, NULL);
    if (!resolved) {
        st = umbra__fail(ctx, UMBRA_ERROR_IO,
                         "%s: cannot open \"%s\" (the data file of \"%s\"): %s", func, joined,
                         header_path, umbra__errno_text(errno, ebuf, sizeof ebuf));
        goto fail;
    }
    dir_real = realpath(dir, NULL);
    if (!dir_real) {
        st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot resolve \"%s\", the directory of \"%s\": "
                         "%s", func, dir, header_path, umbra__errno_text(errno, ebuf, sizeof ebuf));
        goto fail;
    }
    allowed = path_within(resolved, dir_real);
    for (i = 0; i < roots && !allowed; ++i) {
        const char *root = options->data_roots[i];
        root_real = realpath(root, NULL);
        if (!root_real) {
            st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "%s: data root \"%s\" (options->data_roots[%zu]) cannot be resolved: "
                             "%s", func, root, i, umbra__errno_text(errno, ebuf, sizeof ebuf));
            goto fail;
        }
        allowed = path_within(resolved, root_real);
        free(root_real);
        root_real = NULL;
    }
    if (!allowed) {
        st = umbra__fail(ctx, UMBRA_ERROR_IO,
                         "%s: \"%s\" names the data file \"%.*s\", which resolves to \"%s\", "
                         "outside \"%s\" (the header's directory)%s; a data file must lie in "
                         "the header's directory unless its location is allowed "
                         "(umbra_volume_load_options data_roots, umbra-render --allow-data-root, "
                         "Python data_roots=)",
                         func, header_path, QUOTE_MAX, name, resolved, dir_real,
                         roots ? " and outside every data root given" : "");
        goto fail;
    }
    st = umbra__file_open(ctx, func, joined, &f, size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    /* The file opened must be the one checked: a link swapped in between is refused. */
    if (fstat(fileno(f), &opened) != 0 || stat(resolved, &checked) != 0 ||
        opened.st_dev != checked.st_dev || opened.st_ino != checked.st_ino) {
        st = umbra__fail(ctx, UMBRA_ERROR_IO,
                         "%s: \"%s\" changed while it was opened (it no longer is \"%s\")", func,
                         joined, resolved);
        goto fail;
    }
    *shown = joined;
    *out = f;
    joined = NULL;
    f = NULL;

fail:
    if (f) {
        fclose(f);
        *size = 0;
    }
    free(joined);
    free(resolved);
    free(dir);
    free(dir_real);
    free(root_real);
    return st;
}

/* ---- by extension, with options ------------------------------------------------------------ */

/* 1 if path ends in suffix (ASCII, case-insensitive). */
static int ends_with_nocase(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix), i;
    if (n < k) {
        return 0;
    }
    for (i = 0; i < k; ++i) {
        char a = path[n - k + i], b = suffix[i];
        if (a >= 'A' && a <= 'Z') {
            a = (char)(a - 'A' + 'a');
        }
        if (a != b) {
            return 0;
        }
    }
    return 1;
}

umbra_status umbra_volume_load_with_options(umbra_context ctx, const char *path,
                                            const umbra_volume_load_options *options,
                                            umbra_volume *out)
{
    umbra_status st;
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", __func__);
    }
    st = umbra__load_options_check(ctx, __func__, options);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    /* The formats with detached data; every other one has nothing to allow. */
    if (ends_with_nocase(path, ".nrrd") || ends_with_nocase(path, ".nhdr")) {
        return umbra__volume_load_nrrd(ctx, path, options, NULL, out);
    }
    if (ends_with_nocase(path, ".mha") || ends_with_nocase(path, ".mhd")) {
        return umbra__volume_load_metaimage(ctx, path, options, NULL, out);
    }
    if (ends_with_nocase(path, ".dat")) {
        return umbra__volume_load_dat(ctx, path, options, NULL, out);
    }
    return umbra_volume_load(ctx, path, out);
}
