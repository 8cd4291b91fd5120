// SPDX-License-Identifier: Apache-2.0
/* io/paraview_search.c: finding a ParaView preset by its name (umbra_transfer_function_load_paraview
 * with no path, umbra_transfer_function_load with a name, `--tf "Cool to Warm"`).
 *
 * The search path, in order (umbra/io.h and the README say the same):
 *   1. each directory of $UMBRA_PRESET_PATH (':'-separated), when set;
 *   2. the presets installed with umbra: share/umbra/presets of the prefix holding the library
 *      (or the program that links umbra_io statically), found from the loaded object's own path
 *      (dladdr), so a prefix moved elsewhere still finds its presets; in a build tree the copy
 *      CMake puts in <build>/share/umbra/presets;
 *   3. the current directory.
 * In each directory the regular files ending in ".json" are read in name order (at most
 * SEARCH_MAX_FILES of them); the first holding a preset whose "Name" is the one asked for wins.
 * A file that is not a readable preset file is passed over (it may be any JSON). */
#define _GNU_SOURCE

#include <dirent.h>
#include <dlfcn.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io_internal.h"

/* How many .json files of one directory are looked at. */
#define SEARCH_MAX_FILES 4096
/* Messages name at most this much of the directories searched. */
#define DIRS_QUOTE_MAX 2000

#ifndef UMBRA_PRESETS_FROM_LIBDIR
#define UMBRA_PRESETS_FROM_LIBDIR "../share/umbra/presets"
#endif
#ifndef UMBRA_PRESETS_FROM_BINDIR
#define UMBRA_PRESETS_FROM_BINDIR "../share/umbra/presets"
#endif

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int has_json_suffix(const char *name)
{
    size_t n = strlen(name);
    return n > 5 && strcmp(name + n - 5, ".json") == 0 && name[0] != '.';
}

/* Looks for name in the .json files of dir; returns a malloc'ed path, or NULL. *files counts the
 * files read. */
static char *search_dir(const char *dir, const char *name, size_t *files)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL, *found = NULL;
    size_t n = 0, i;

    if (!d) {
        return NULL;
    }
    names = malloc(SEARCH_MAX_FILES * sizeof *names);
    while (names && n < SEARCH_MAX_FILES && (e = readdir(d)) != NULL) {
        if (has_json_suffix(e->d_name) && (names[n] = strdup(e->d_name)) != NULL) {
            ++n;
        }
    }
    closedir(d);
    if (!names) {
        return NULL;
    }
    qsort(names, n, sizeof *names, compare_names);
    for (i = 0; i < n && !found; ++i) {
        size_t len = strlen(dir) + strlen(names[i]) + 2;
        char *path = malloc(len);
        struct stat sb;
        if (path) {
            snprintf(path, len, "%s/%s", dir, names[i]);
            if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode)) {
                ++*files;
                if (umbra__paraview_file_holds(path, name)) {
                    found = path;
                    path = NULL;
                }
            }
            free(path);
        }
    }
    for (i = 0; i < n; ++i) {
        free(names[i]);
    }
    free(names);
    return found;
}

/* Any object of this file: its address tells dladdr which loaded file holds umbra_io. */
static const char object_anchor = 0;

/* The directory of the file holding this code: a shared libumbra_io, or the program linking it
 * statically. Writes it to dir (PATH_MAX bytes); 0 if it cannot be told. */
static int object_dir(char dir[PATH_MAX])
{
    Dl_info info;
    char *slash;
    const char *file = "/proc/self/exe";
    memset(&info, 0, sizeof info);
    /* dladdr names a shared library by the path it was loaded from (absolute unless
     * LD_LIBRARY_PATH was relative) and the main program by argv[0]: for that, /proc. */
    if (dladdr(&object_anchor, &info) != 0 && info.dli_fname &&
        info.dli_fname[0] == '/') {
        file = info.dli_fname;
    }
    if (!realpath(file, dir)) {
        return 0;
    }
    slash = strrchr(dir, '/');
    if (!slash) {
        return 0;
    }
    *slash = '\0';
    return 1;
}

/* Appends dir to the list of searched directories quoted in the message. */
static void note_dir(char *list, size_t size, const char *dir)
{
    size_t used = strlen(list), n = strlen(dir);
    if (used + n + 3 < size) {
        if (used) {
            memcpy(list + used, ", ", 2);
            used += 2;
        }
        memcpy(list + used, dir, n + 1);
    }
}

umbra_status umbra__paraview_find(umbra_context ctx, const char *func, const char *name,
                                  int also_file, char **found)
{
    char searched[DIRS_QUOTE_MAX] = "";
    char base[PATH_MAX], dir[PATH_MAX + 64];
    const char *env = getenv("UMBRA_PRESET_PATH");
    const char *const installed[3] = {UMBRA_PRESETS_FROM_LIBDIR, UMBRA_PRESETS_FROM_BINDIR,
                                      "share/umbra/presets"};
    size_t files = 0;
    int i;

    *found = NULL;
    if (env && env[0] != '\0') {
        const char *p = env;
        while (*p && !*found) {
            const char *colon = strchr(p, ':');
            size_t len = colon ? (size_t)(colon - p) : strlen(p);
            if (len > 0 && len < sizeof dir) {
                memcpy(dir, p, len);
                dir[len] = '\0';
                note_dir(searched, sizeof searched, dir);
                *found = search_dir(dir, name, &files);
            }
            p += len + (colon ? 1 : 0);
        }
    }
    if (!*found && object_dir(base)) {
        char seen[3][PATH_MAX];
        int nseen = 0, j, dup;
        for (i = 0; i < 3 && !*found; ++i) {
            snprintf(dir, sizeof dir, "%s/%s", base, installed[i]);
            if (!realpath(dir, seen[nseen])) {
                continue; /* not there */
            }
            for (j = 0, dup = 0; j < nseen; ++j) {
                dup |= strcmp(seen[j], seen[nseen]) == 0;
            }
            if (!dup) {
                note_dir(searched, sizeof searched, seen[nseen]);
                *found = search_dir(seen[nseen++], name, &files);
            }
        }
    }
    if (!*found) {
        note_dir(searched, sizeof searched, ".");
        *found = search_dir(".", name, &files);
    }
    if (*found) {
        return UMBRA_SUCCESS;
    }
    return umbra__fail(ctx, UMBRA_ERROR_IO,
                       "%s: %s\"%.200s\"%s in the preset search path ($UMBRA_PRESET_PATH, then "
                       "the installed presets, then the current directory: %s; %zu .json files "
                       "read)",
                       func, also_file ? "" : "no preset named ", name,
                       also_file ? " is neither a file nor the name of a preset" : "", searched,
                       files);
}
