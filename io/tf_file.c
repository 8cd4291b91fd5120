// SPDX-License-Identifier: Apache-2.0
/* io/tf_file.c: reading transfer functions from text files.
 *
 * The format, one item per line:
 *     # a comment, to the end of the line (also after a value)
 *     resolution 256          optional, 2..65536, before the first point; default 256
 *     range -1024 3071        optional, before the first point: values are data values in
 *                             [LO, HI] (finite, LO < HI), e.g. Hounsfield units, and the table
 *                             spans LO..HI (umbra_transfer_function_set_range)
 *     0.00  0 0 0 0           control points "value r g b a", colour in [0,1], value in [0,1]
 *     0.35  1 0.8 0.6 0.05    (or [LO, HI]), values ascending (equal values make a step)
 * Blank lines are ignored; at least one point is required and at most 65536 are allowed
 * (UMBRA_TF_MAX_POINTS); the table build is linear in points + resolution. The table is built by
 * umbra_transfer_function_create_from_points. Numbers are parsed in the "C" locale, so a decimal
 * point is a '.' whatever locale the application has set. A path ending in .json is a ParaView
 * preset (io/paraview.c); a bare name (no '/') that is no file is a preset's name, looked up in
 * the preset search path (io/paraview_search.c). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io_internal.h"

#define TF_DEFAULT_RESOLUTION 256u
#define TF_MIN_RESOLUTION 2
#define TF_MAX_RESOLUTION 65536
/* Messages quote at most this much of a line. */
#define QUOTE_MAX 200

typedef struct token {
    const char *s;
    size_t n;
} token;

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Splits a NUL-terminated line into at most max blank-separated tokens; returns how many there
 * are in all (which may exceed max). */
static size_t split(const char *line, token *tokens, size_t max)
{
    size_t count = 0;
    const char *p = line;
    for (;;) {
        const char *start;
        while (is_blank(*p)) {
            ++p;
        }
        if (*p == '\0') {
            return count;
        }
        start = p;
        while (*p != '\0' && !is_blank(*p)) {
            ++p;
        }
        if (count < max) {
            tokens[count].s = start;
            tokens[count].n = (size_t)(p - start);
        }
        ++count;
    }
}

/* Parses a whole token as a float; the token is followed by a blank or the end of the line. */
static int parse_float(token t, float *out)
{
    char *end = NULL;
    if (t.n == 0) {
        return 0;
    }
    errno = 0;
    *out = strtof(t.s, &end);
    return end == t.s + t.n;
}

umbra_status umbra_transfer_function_load(umbra_context ctx, const char *path,
                                          umbra_transfer_function *out)
{
    static const char *const names[5] = {"value", "red", "green", "blue", "alpha"};
    umbra_status st = UMBRA_SUCCESS;
    void *buf = NULL;
    char *text, *line, *next;
    size_t size = 0, count = 0, capacity = 0;
    umbra_tf_point *points = NULL;
    uint32_t resolution = TF_DEFAULT_RESOLUTION;
    int have_resolution = 0, have_range = 0;
    float range_lo = 0.0f, range_hi = 1.0f;
    unsigned long line_no = 0;
    locale_t c_locale = (locale_t)0, previous = (locale_t)0;

    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", __func__);
    }
    if (path && strlen(path) > 5 && strcmp(path + strlen(path) - 5, ".json") == 0) {
        return umbra_transfer_function_load_paraview(ctx, path, NULL, out, NULL);
    }
    if (path && path[0] != '\0' && !strchr(path, '/') && access(path, F_OK) != 0 &&
        errno == ENOENT) {
        /* A bare name that is no file: a preset's name, looked up in the preset search path. */
        umbra_paraview_options po;
        char *found = NULL;
        umbra_paraview_options_init(&po);
        po.preset = path;
        st = umbra__paraview_find(ctx, __func__, path, 1, &found);
        if (st == UMBRA_SUCCESS) {
            st = umbra_transfer_function_load_paraview(ctx, found, &po, out, NULL);
        }
        free(found);
        return st;
    }
    st = umbra__read_file(ctx, __func__, path, &buf, &size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    text = buf; /* umbra__read_file NUL-terminates */

    c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (c_locale != (locale_t)0) {
        previous = uselocale(c_locale);
    }

    for (line = text; line < text + size; line = next) {
        token tok[5];
        size_t ntok, i, len;
        char *hash, *end;

        ++line_no;
        end = memchr(line, '\n', (size_t)(text + size - line));
        if (!end) {
            end = text + size;
        }
        next = end + 1;
        len = (size_t)(end - line);
        if (memchr(line, '\0', len)) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s:%lu: NUL byte in the line (not a text file?)", __func__, path,
                             line_no);
            goto fail;
        }
        *end = '\0';
        hash = strchr(line, '#');
        if (hash) {
            *hash = '\0';
        }
        while (is_blank(*line)) {
            ++line;
        }
        len = strlen(line);
        while (len > 0 && is_blank(line[len - 1])) {
            line[--len] = '\0';
        }
        ntok = split(line, tok, 5);
        if (ntok == 0) {
            continue;
        }

        if (tok[0].n == 10 && memcmp(tok[0].s, "resolution", 10) == 0) {
            if (have_resolution || count > 0) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": resolution must be given once, before the "
                                 "first control point",
                                 __func__, path, line_no, QUOTE_MAX, line);
                goto fail;
            }
            uint64_t r = 0;
            if (ntok != 2 || !umbra__parse_uint(tok[1].s, tok[1].n, TF_MAX_RESOLUTION, &r) ||
                r < TF_MIN_RESOLUTION) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": expected \"resolution N\" with an "
                                 "integer N in %d..%d",
                                 __func__, path, line_no, QUOTE_MAX, line, TF_MIN_RESOLUTION,
                                 TF_MAX_RESOLUTION);
                goto fail;
            }
            resolution = (uint32_t)r;
            have_resolution = 1;
            continue;
        }

        if (tok[0].n == 5 && memcmp(tok[0].s, "range", 5) == 0) {
            if (have_range || count > 0) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": range must be given once, before the "
                                 "first control point",
                                 __func__, path, line_no, QUOTE_MAX, line);
                goto fail;
            }
            /* An overflowing "1e99" parses to inf and is refused as not finite. */
            if (ntok != 3 || !parse_float(tok[1], &range_lo) || !parse_float(tok[2], &range_hi) ||
                !isfinite(range_lo) || !isfinite(range_hi)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": expected \"range LO HI\" with two "
                                 "finite numbers",
                                 __func__, path, line_no, QUOTE_MAX, line);
                goto fail;
            }
            if (!(range_hi > range_lo)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": range LO %g must be below HI %g",
                                 __func__, path, line_no, QUOTE_MAX, line, (double)range_lo,
                                 (double)range_hi);
                goto fail;
            }
            have_range = 1;
            continue;
        }

        if (ntok != 5) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s:%lu: \"%.*s\": expected a control point \"value r g b a\" "
                             "(5 numbers), \"resolution N\" or \"range LO HI\", got %zu fields",
                             __func__, path, line_no, QUOTE_MAX, line, ntok);
            goto fail;
        }
        if (count == UMBRA_TF_MAX_POINTS) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s:%lu: control point %zu: at most %u are allowed", __func__,
                             path, line_no, count + 1, UMBRA_TF_MAX_POINTS);
            goto fail;
        }
        if (count == capacity) {
            size_t grown = capacity ? 2 * capacity : 16;
            umbra_tf_point *p;
            p = realloc(points, grown * sizeof *points);
            if (!p) {
                st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                 "%s: %s:%lu: cannot allocate %zu control points", __func__, path,
                                 line_no, grown);
                goto fail;
            }
            points = p;
            capacity = grown;
        }
        for (i = 0; i < 5; ++i) {
            float v = 0.0f;
            if (!parse_float(tok[i], &v)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": %s \"%.*s\" is not a number", __func__,
                                 path, line_no, QUOTE_MAX, line, names[i], (int)tok[i].n,
                                 tok[i].s);
                goto fail;
            }
            /* "nan" and "inf" are not finite; "1e99" is finite but overflows to inf (ERANGE)
             * and is reported as out of range. */
            if (!isfinite(v) && errno != ERANGE) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": %s \"%.*s\" is not a finite number",
                                 __func__, path, line_no, QUOTE_MAX, line, names[i], (int)tok[i].n,
                                 tok[i].s);
                goto fail;
            }
            if (i == 0 && have_range) {
                if (v < range_lo || v > range_hi) {
                    st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                     "%s: %s:%lu: \"%.*s\": value \"%.*s\" is outside the "
                                     "range [%g, %g]",
                                     __func__, path, line_no, QUOTE_MAX, line, (int)tok[i].n,
                                     tok[i].s, (double)range_lo, (double)range_hi);
                    goto fail;
                }
                /* Kept in data units until the table is built (ordering is checked on them). */
                points[count].value = v;
                continue;
            }
            if (v < 0.0f || v > 1.0f) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s:%lu: \"%.*s\": %s \"%.*s\" is not in [0,1]", __func__,
                                 path, line_no, QUOTE_MAX, line, names[i], (int)tok[i].n,
                                 tok[i].s);
                goto fail;
            }
            if (i == 0) {
                points[count].value = v;
            } else {
                points[count].rgba[i - 1] = v;
            }
        }
        if (count > 0 && points[count].value < points[count - 1].value) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s:%lu: \"%.*s\": value %g is below the previous point's %g "
                             "(points must be in ascending order)",
                             __func__, path, line_no, QUOTE_MAX, line,
                             (double)points[count].value, (double)points[count - 1].value);
            goto fail;
        }
        ++count;
    }
    if (count == 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: %s: no control points (lines \"value r g b a\")", __func__, path);
        goto fail;
    }
    if (have_range) {
        /* Data values to the table's [0,1], in double so that the ends land on 0 and 1. */
        for (size_t k = 0; k < count; ++k) {
            double u = ((double)points[k].value - range_lo) / ((double)range_hi - range_lo);
            points[k].value = (float)(u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u));
        }
    }
    st = umbra_transfer_function_create_from_points(ctx, points, (uint32_t)count, resolution, out);
    if (st == UMBRA_SUCCESS && have_range) {
        st = umbra_transfer_function_set_range(*out, range_lo, range_hi);
        if (st != UMBRA_SUCCESS) {
            umbra_transfer_function_release(*out);
            *out = NULL;
        }
    }

fail:
    if (c_locale != (locale_t)0) {
        uselocale(previous);
        freelocale(c_locale);
    }
    free(points);
    free(buf);
    return st;
}
