// SPDX-License-Identifier: Apache-2.0
/* io/volume_io.c: reading volumes from files.
 *
 * Two readers, both ending in umbra_volume_create: Voreen's .dat text header over a raw file, and
 * plain headerless raw files described by an umbra_raw_desc (NRRD lives in io_nrrd.c). Also what
 * every file reader shares: the one way files are opened (regular files only, never blocking on
 * a FIFO or device), the whole-file reader, strict integer parsing and byte swapping. Text is
 * parsed in the "C" numeric locale whatever the application has set. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "io_internal.h"

/* Messages quote at most this much of a value taken from a file. */
#define QUOTE_MAX 200

/* ---- files -------------------------------------------------------------------------------- */

const char *umbra__errno_text(int err, char *buf, size_t n)
{
    /* strerror_r (XSI form under _POSIX_C_SOURCE) rather than strerror, which may share a
     * static buffer between threads. */
    if (strerror_r(err, buf, n) != 0) {
        snprintf(buf, n, "error %d", err);
    }
    return buf;
}

/* Opens a regular file for reading and returns its size. The open is non-blocking, so a FIFO or
 * a device named as an input cannot block the caller (a plain fopen of a FIFO waits forever for a
 * writer); the file's type is then taken from the descriptor itself (fstat, no race with a
 * rename), anything but a regular file is refused, and only then is the descriptor made blocking
 * again for ordinary reads. */
umbra_status umbra__file_open(umbra_context ctx, const char *func, const char *path, FILE **out,
                              size_t *size)
{
    char buf[256];
    struct stat sb;
    FILE *f = NULL;
    int fd, flags;

    *out = NULL;
    *size = 0;
    fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot open \"%s\": %s", func, path,
                           umbra__errno_text(errno, buf, sizeof buf));
    }
    if (fstat(fd, &sb) != 0) {
        int err = errno;
        close(fd);
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot stat \"%s\": %s", func, path,
                           umbra__errno_text(err, buf, sizeof buf));
    }
    if (!S_ISREG(sb.st_mode)) {
        close(fd);
        return umbra__fail(ctx, UMBRA_ERROR_IO,
                           "%s: \"%s\" is not a regular file (a %s); only regular files are read",
                           func, path,
                           S_ISDIR(sb.st_mode)   ? "directory"
                           : S_ISFIFO(sb.st_mode) ? "FIFO"
                           : S_ISCHR(sb.st_mode)  ? "character device"
                           : S_ISBLK(sb.st_mode)  ? "block device"
                           : S_ISSOCK(sb.st_mode) ? "socket"
                                                  : "special file");
    }
    if (sb.st_size < 0 || (uintmax_t)sb.st_size >= SIZE_MAX) {
        close(fd);
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: \"%s\" is too large to read (%jd bytes)",
                           func, path, (intmax_t)sb.st_size);
    }
    flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0 || !(f = fdopen(fd, "rb"))) {
        int err = errno;
        close(fd);
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot open \"%s\": %s", func, path,
                           umbra__errno_text(err, buf, sizeof buf));
    }
    *out = f;
    *size = (size_t)sb.st_size;
    return UMBRA_SUCCESS;
}

/* Reads exactly size bytes from f, which is path, into dst. */
umbra_status umbra__file_read(umbra_context ctx, const char *func, const char *path, FILE *f,
                              void *dst, size_t size)
{
    char buf[256];
    size_t got = fread(dst, 1, size, f);
    if (got != size) {
        if (ferror(f)) {
            return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot read \"%s\": %s", func, path,
                               umbra__errno_text(errno, buf, sizeof buf));
        }
        return umbra__fail(ctx, UMBRA_ERROR_IO,
                           "%s: \"%s\" ended after %zu of %zu bytes (changed while reading?)",
                           func, path, got, size);
    }
    return UMBRA_SUCCESS;
}

/* The buffer holds one byte more than the file, a NUL, so that text readers can treat it as a
 * string; *size does not count it. */
umbra_status umbra__read_file(umbra_context ctx, const char *func, const char *path, void **data,
                              size_t *size)
{
    umbra_status st = UMBRA_SUCCESS;
    FILE *f = NULL;
    char *buf = NULL;
    size_t n = 0;

    if (!data || !size) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: data or size is NULL", func);
    }
    *data = NULL;
    *size = 0;
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", func);
    }
    st = umbra__file_open(ctx, func, path, &f, &n);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    buf = malloc(n + 1);
    if (!buf) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes for \"%s\"",
                         func, n + 1, path);
        goto fail;
    }
    st = umbra__file_read(ctx, func, path, f, buf, n);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    buf[n] = '\0';
    fclose(f);
    *data = buf;
    *size = n;
    return UMBRA_SUCCESS;

fail:
    free(buf);
    if (f) {
        fclose(f);
    }
    return st;
}

/* ---- small helpers ------------------------------------------------------------------------ */

int umbra__parse_uint(const char *s, size_t n, uint64_t max, uint64_t *out)
{
    uint64_t v = 0;
    size_t i;
    if (!s || n == 0) {
        return 0;
    }
    for (i = 0; i < n; ++i) {
        unsigned d = (unsigned)((unsigned char)s[i] - '0');
        if (d > 9 || d > max || v > (max - d) / 10) {
            return 0;
        }
        v = 10 * v + d;
    }
    *out = v;
    return 1;
}

static int ascii_lower(int c)
{
    return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c;
}

/* Case-insensitive ASCII comparison of a counted string with a C string. */
static int equal_nocase(const char *s, size_t n, const char *lit)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        if (lit[i] == '\0' ||
            ascii_lower((unsigned char)s[i]) != ascii_lower((unsigned char)lit[i])) {
            return 0;
        }
    }
    return lit[n] == '\0';
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* The extension of path (after the last '.' of the last component), or "" if none. */
static const char *path_extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    return (dot && dot != base) ? dot + 1 : "";
}

int umbra__host_is_big_endian(void)
{
    const uint16_t one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    return first == 0;
}

void umbra__swap_bytes(void *data, size_t count, size_t width)
{
    unsigned char *p = data;
    size_t i, j;
    for (i = 0; i < count; ++i, p += width) {
        for (j = 0; j < width / 2; ++j) {
            unsigned char t = p[j];
            p[j] = p[width - 1 - j];
            p[width - 1 - j] = t;
        }
    }
}

/* Switches this thread to the "C" numeric locale, so "0.5" parses the same whatever locale the
 * application chose; returns what to hand to locale_restore. */
typedef struct locale_switch {
    locale_t c_locale;
    locale_t previous;
} locale_switch;

static locale_switch locale_use_c(void)
{
    locale_switch s = {(locale_t)0, (locale_t)0};
    s.c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (s.c_locale != (locale_t)0) {
        s.previous = uselocale(s.c_locale);
    }
    return s;
}

static void locale_restore(locale_switch s)
{
    if (s.c_locale != (locale_t)0) {
        uselocale(s.previous);
        freelocale(s.c_locale);
    }
}

/* ---- raw ---------------------------------------------------------------------------------- */

void umbra_raw_desc_init(umbra_raw_desc *desc)
{
    if (!desc) {
        return;
    }
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
    desc->type = UMBRA_UINT8;
    desc->spacing[0] = desc->spacing[1] = desc->spacing[2] = 1.0f;
    desc->big_endian = 0;
    desc->header_bytes = 0;
    desc->channels = 1;
}

/* What the raw reader's fill callback reads: the rest of f (path), byte-swapped if need be. */
typedef struct raw_fill {
    umbra_context ctx;
    const char *func, *path;
    FILE *f;
    size_t count, type_size;
    int swap;
} raw_fill;

static umbra_status fill_raw(void *user, void *dst, size_t bytes)
{
    raw_fill *r = user;
    umbra_status st = umbra__file_read(r->ctx, r->func, r->path, r->f, dst, bytes);
    if (st == UMBRA_SUCCESS && r->swap)
        umbra__swap_bytes(dst, r->count, r->type_size);
    return st;
}

umbra_status umbra__volume_from_fill(umbra_context ctx, umbra_volume_fill_fn fill, void *user,
                                     umbra_scalar_type type, const uint32_t dims[3],
                                     const float spacing[3], const float *origin,
                                     const float *directions, umbra_volume *out)
{
    return umbra__volume_from_fill_kind(ctx, fill, user, type, dims, spacing, origin, directions,
                                        1, 0, out);
}

umbra_status umbra__volume_from_fill_kind(umbra_context ctx, umbra_volume_fill_fn fill,
                                          void *user, umbra_scalar_type type,
                                          const uint32_t dims[3], const float spacing[3],
                                          const float *origin, const float *directions,
                                          uint32_t channels, int labels, umbra_volume *out)
{
    umbra_volume_desc vd;
    umbra_volume_desc_init(&vd);
    vd.type = type;
    vd.channels = channels;
    vd.labels = labels;
    memcpy(vd.dims, dims, sizeof vd.dims);
    memcpy(vd.spacing, spacing, sizeof vd.spacing);
    if (origin && directions) {
        vd.transform_given = 1;
        memcpy(vd.origin, origin, sizeof vd.origin);
        memcpy(vd.directions, directions, sizeof vd.directions);
    }
    return umbra_volume_create_filled(ctx, &vd, fill, user, out);
}

/* The raw reader behind umbra_volume_load_raw and umbra_volume_load_dat; func names the public
 * function in messages. The file is read straight into the device's buffer
 * (umbra_volume_create_filled): no host copy of the voxels. f, when not NULL, is path already
 * opened (of file_size bytes), and is closed here either way. */
static umbra_status load_raw(umbra_context ctx, const char *func, const char *path, FILE *f,
                             size_t file_size, const umbra_raw_desc *desc, const umbra__box *box,
                             umbra_volume *out)
{
    umbra_status st = UMBRA_SUCCESS;
    size_t type_size, count, data_bytes, expected;
    int i;

    type_size = umbra_scalar_type_size(desc->type);
    if (type_size == 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: scalar type %d is unknown (expected UMBRA_UINT8, UMBRA_UINT16, "
                         "UMBRA_INT16 or UMBRA_FLOAT32)",
                         func, (int)desc->type);
        goto fail;
    }
    if (desc->channels < 1 || desc->channels > UMBRA_MAX_CHANNELS) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: channels %u must lie in [1, %d] (UMBRA_MAX_CHANNELS)", func,
                         desc->channels, UMBRA_MAX_CHANNELS);
        goto fail;
    }
    count = 1;
    for (i = 0; i < 3; ++i) {
        if (desc->dims[i] == 0) {
            st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "%s: dims %u x %u x %u: every size must be > 0", func,
                             desc->dims[0], desc->dims[1], desc->dims[2]);
            goto fail;
        }
        if (count > SIZE_MAX / desc->dims[i] / (i == 2 ? desc->channels : 1)) {
            st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "%s: dims %u x %u x %u: too many voxels", func, desc->dims[0],
                             desc->dims[1], desc->dims[2]);
            goto fail;
        }
        count *= desc->dims[i];
        if (i == 2)
            count *= desc->channels;
        if (!(desc->spacing[i] > 0.0f) || !isfinite(desc->spacing[i])) {
            st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                             "%s: spacing %g x %g x %g: each must be finite and > 0", func,
                             (double)desc->spacing[0], (double)desc->spacing[1],
                             (double)desc->spacing[2]);
            goto fail;
        }
    }
    if (count > SIZE_MAX / type_size || count * type_size > SIZE_MAX - desc->header_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                         "%s: dims %u x %u x %u plus %zu header bytes: too large", func,
                         desc->dims[0], desc->dims[1], desc->dims[2], desc->header_bytes);
        goto fail;
    }
    data_bytes = count * type_size;
    expected = desc->header_bytes + data_bytes;

    /* Check the size before reading, so a wrong header costs nothing on a large file. */
    if (!f) {
        st = umbra__file_open(ctx, func, path, &f, &file_size);
        if (st != UMBRA_SUCCESS) {
            goto fail;
        }
    }
    if (file_size != expected) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu bytes, expected %zu (%zu header bytes + "
                         "%u x %u x %u voxels of %zu bytes%s)",
                         func, path, file_size, expected, desc->header_bytes, desc->dims[0],
                         desc->dims[1], desc->dims[2], type_size * desc->channels,
                         desc->channels > 1 ? ", the channels interleaved" : "");
        goto fail;
    }
    if (desc->header_bytes > 0 && fseeko(f, (off_t)desc->header_bytes, SEEK_SET) != 0) {
        char buf[256];
        st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot skip %zu header bytes of \"%s\": %s",
                         func, desc->header_bytes, path, umbra__errno_text(errno, buf, sizeof buf));
        goto fail;
    }
    raw_fill rf = {ctx, func, path, f, count, type_size,
                   type_size > 1 && (desc->big_endian != 0) != umbra__host_is_big_endian()};
    if (box) {
        st = umbra__box_info(ctx, func, box, desc->type, desc->dims, desc->spacing, NULL, NULL,
                             desc->channels);
        if (st == UMBRA_SUCCESS && !umbra__box_header_only(box)) {
            st = umbra__box_read(ctx, func, path, f, 0, 0, desc->dims,
                                 type_size * desc->channels, rf.swap ? type_size : 0, box);
        }
        goto fail;
    }
    st = umbra__volume_from_fill_kind(ctx, fill_raw, &rf, desc->type, desc->dims, desc->spacing,
                                      NULL, NULL, desc->channels, desc->labels, out);

fail:
    if (f) {
        fclose(f);
    }
    return st;
}

/* umbra_volume_load_raw, or with a box (out unused) umbra_volume_read_box on a raw file. */
static umbra_status raw_checked(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                const umbra__box *box, umbra_volume *out)
{
    const char *func = box ? "umbra_volume_read_box" : "umbra_volume_load_raw";
    if (!out && !box) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", func);
    }
    if (out)
        *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", func);
    }
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", func);
    }
    if (!desc) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc is NULL", func);
    }
    if (desc->struct_size != sizeof(umbra_raw_desc) &&
        desc->struct_size != offsetof(umbra_raw_desc, channels)) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size is %zu, expected %zu (call umbra_raw_desc_init)",
                           func, desc->struct_size, sizeof(umbra_raw_desc));
    }
    umbra_raw_desc d;
    umbra_raw_desc_init(&d);
    memcpy(&d, desc, desc->struct_size);
    d.struct_size = sizeof d;
    return load_raw(ctx, func, path, NULL, 0, &d, box, out);
}

umbra_status umbra_volume_load_raw(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                   umbra_volume *out)
{
    return raw_checked(ctx, path, desc, NULL, out);
}

umbra_status umbra__box_load_raw(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                 const umbra__box *box)
{
    return raw_checked(ctx, path, desc, box, NULL);
}

/* ---- Voreen .dat ------------------------------------------------------------------------ */

/* Parses exactly n numbers separated by blanks from s (NUL-terminated). Integers (at most
 * UINT32_MAX) when ints is set (into u), else floats (into f). Returns 0 on any stray text. */
static int parse_numbers(const char *s, int n, int ints, uint64_t *u, float *f)
{
    int i;
    for (i = 0; i < n; ++i) {
        const char *end = s;
        while (is_space(*s)) {
            ++s;
        }
        if (*s == '\0' || *s == '-' || *s == '+') {
            return 0;
        }
        if (ints) {
            for (end = s; *end != '\0' && !is_space(*end); ++end) {
            }
            if (!umbra__parse_uint(s, (size_t)(end - s), UINT32_MAX, &u[i])) {
                return 0;
            }
        } else {
            char *fend = NULL;
            errno = 0;
            f[i] = strtof(s, &fend);
            end = fend;
            if (end == s || errno == ERANGE || (*end != '\0' && !is_space(*end))) {
                return 0;
            }
        }
        s = end;
    }
    while (is_space(*s)) {
        ++s;
    }
    return *s == '\0';
}

umbra_status umbra_volume_load_dat(umbra_context ctx, const char *path, umbra_volume *out)
{
    return umbra__volume_load_dat(ctx, path, NULL, NULL, out);
}

umbra_status umbra__volume_load_dat(umbra_context ctx, const char *path,
                                    const umbra_volume_load_options *options,
                                    const umbra__box *box, umbra_volume *out)
{
    static const char *const func = "umbra_volume_load_dat";
    umbra_status st = UMBRA_SUCCESS;
    char *text = NULL, *raw_path = NULL, *line, *next;
    void *buf = NULL;
    FILE *raw_file = NULL;
    size_t size = 0, raw_size = 0;
    const char *object_file = NULL, *resolution = NULL, *thickness = NULL, *format = NULL;
    uint64_t res[3] = {0, 0, 0};
    umbra_raw_desc raw;
    locale_switch loc;
    int ok, i;

    if (!out && !box) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", func);
    }
    if (out)
        *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", func);
    }
    st = umbra__read_file(ctx, func, path, &buf, &size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    text = buf;
    if (memchr(text, '\0', size)) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" is not a text file (NUL byte)",
                         func, path);
        goto fail;
    }

    /* "Key: value" lines; unknown keys are ignored, a repeated key keeps its last value. Values
     * point into text, cut at the end of their line. */
    for (line = text; line; line = next) {
        char *colon, *key, *key_end, *value, *value_end;
        next = strchr(line, '\n');
        if (next) {
            *next++ = '\0';
        }
        colon = strchr(line, ':');
        if (!colon) {
            continue;
        }
        for (key = line; is_space(*key); ++key) {
        }
        for (key_end = colon; key_end > key && is_space(key_end[-1]); --key_end) {
        }
        for (value = colon + 1; is_space(*value); ++value) {
        }
        for (value_end = value + strlen(value); value_end > value && is_space(value_end[-1]);
             --value_end) {
        }
        *value_end = '\0';
        if (equal_nocase(key, (size_t)(key_end - key), "ObjectFileName")) {
            object_file = value;
        } else if (equal_nocase(key, (size_t)(key_end - key), "Resolution")) {
            resolution = value;
        } else if (equal_nocase(key, (size_t)(key_end - key), "SliceThickness")) {
            thickness = value;
        } else if (equal_nocase(key, (size_t)(key_end - key), "Format")) {
            format = value;
        } else if (equal_nocase(key, (size_t)(key_end - key), "ObjectModel")) {
            if (!equal_nocase(value, strlen(value), "I")) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": ObjectModel \"%.*s\" is not supported (only I, one "
                                 "scalar per voxel)",
                                 func, path, QUOTE_MAX, value);
                goto fail;
            }
        }
    }
    {
        const char *keys[4] = {"ObjectFileName", "Resolution", "SliceThickness", "Format"};
        const char *values[4];
        values[0] = object_file;
        values[1] = resolution;
        values[2] = thickness;
        values[3] = format;
        for (i = 0; i < 4; ++i) {
            if (!values[i] || values[i][0] == '\0') {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" has no value for key %s",
                                 func, path, keys[i]);
                goto fail;
            }
        }
    }

    umbra_raw_desc_init(&raw);
    loc = locale_use_c();
    ok = parse_numbers(resolution, 3, 1, res, NULL);
    locale_restore(loc);
    if (!ok || res[0] == 0 || res[1] == 0 || res[2] == 0 || res[0] > UINT32_MAX ||
        res[1] > UINT32_MAX || res[2] > UINT32_MAX) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": Resolution \"%.*s\" is not three sizes > 0", func,
                         path, QUOTE_MAX, resolution);
        goto fail;
    }
    for (i = 0; i < 3; ++i) {
        raw.dims[i] = (uint32_t)res[i];
    }
    loc = locale_use_c();
    ok = parse_numbers(thickness, 3, 0, NULL, raw.spacing);
    locale_restore(loc);
    if (!ok || !(raw.spacing[0] > 0.0f) || !(raw.spacing[1] > 0.0f) ||
        !(raw.spacing[2] > 0.0f) || !isfinite(raw.spacing[0]) || !isfinite(raw.spacing[1]) ||
        !isfinite(raw.spacing[2])) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": SliceThickness \"%.*s\" is not three finite numbers > 0",
                         func, path, QUOTE_MAX, thickness);
        goto fail;
    }
    if (equal_nocase(format, strlen(format), "UCHAR")) {
        raw.type = UMBRA_UINT8;
    } else if (equal_nocase(format, strlen(format), "USHORT")) {
        raw.type = UMBRA_UINT16;
    } else if (equal_nocase(format, strlen(format), "SHORT")) {
        raw.type = UMBRA_INT16;
    } else if (equal_nocase(format, strlen(format), "FLOAT")) {
        raw.type = UMBRA_FLOAT32;
    } else {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": Format \"%.*s\" is not supported (UCHAR, USHORT, SHORT, "
                         "FLOAT)",
                         func, path, QUOTE_MAX, format);
        goto fail;
    }

    /* The raw file is named relative to the directory of the .dat, under the data-file policy
     * (inside that directory or a data root). */
    st = umbra__data_file_open(ctx, func, path, object_file, options, &raw_path, &raw_file,
                               &raw_size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    st = load_raw(ctx, func, raw_path, raw_file, raw_size, &raw, box, out);

fail:
    free(raw_path);
    free(buf);
    return st;
}

/* ---- by extension ------------------------------------------------------------------------ */

/* Nonzero if path starts with DICOM's 128-byte preamble and "DICM". */
static int has_dicom_magic(const char *path)
{
    unsigned char head[132];
    FILE *f = NULL;
    size_t size = 0;
    int yes = 0;
    if (umbra__file_open(NULL, __func__, path, &f, &size) != UMBRA_SUCCESS) {
        return 0;
    }
    yes = size >= sizeof head && fread(head, 1, sizeof head, f) == sizeof head &&
          memcmp(head + 128, "DICM", 4) == 0;
    fclose(f);
    return yes;
}

umbra_status umbra_volume_load(umbra_context ctx, const char *path, umbra_volume *out)
{
    const char *ext;
    struct stat sb;
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", __func__);
    }
    ext = path_extension(path);
    if (equal_nocase(ext, strlen(ext), "nrrd") || equal_nocase(ext, strlen(ext), "nhdr")) {
        return umbra_volume_load_nrrd(ctx, path, out);
    }
    if (equal_nocase(ext, strlen(ext), "dat")) {
        return umbra_volume_load_dat(ctx, path, out);
    }
    if (equal_nocase(ext, strlen(ext), "nii") ||
        (equal_nocase(ext, strlen(ext), "gz") && strlen(path) >= 7 &&
         equal_nocase(path + strlen(path) - 7, 7, ".nii.gz"))) {
        return umbra_volume_load_nifti(ctx, path, out);
    }
    if (equal_nocase(ext, strlen(ext), "mha") || equal_nocase(ext, strlen(ext), "mhd")) {
        return umbra_volume_load_metaimage(ctx, path, out);
    }
    /* After the single-file formats, which refuse a directory by name as not a regular file. */
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        return umbra__volume_load_directory(ctx, __func__, path, out);
    }
    if (umbra__is_tiff_name(path)) {
        return umbra_volume_load_tiff(ctx, &path, 1, out);
    }
    if (equal_nocase(ext, strlen(ext), "dcm") || equal_nocase(ext, strlen(ext), "dicom") ||
        equal_nocase(ext, strlen(ext), "ima") || has_dicom_magic(path)) {
        return umbra_volume_load_dicom(ctx, &path, 1, out);
    }
    return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                       "%s: \"%s\": unknown extension; supported are .nrrd, .nhdr (NRRD), .nii, "
                       ".nii.gz (NIfTI), .mha, .mhd (MetaImage), .dat (Voreen), .tif, .tiff (TIFF "
                       "stacks), .dcm or a file starting with DICOM's preamble, and a directory "
                       "(a DICOM series or TIFF stack); VTK (.vti) is not supported; load "
                       "headerless raw files with umbra_volume_load_raw",
                       __func__, path);
}
