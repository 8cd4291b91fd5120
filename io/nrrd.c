// SPDX-License-Identifier: Apache-2.0
/* io/nrrd.c: reading NRRD volumes (attached .nrrd, detached .nhdr).
 *
 * Teem parses the header; umbra reads the data. Left to itself Teem opens data files by name with
 * fopen (a FIFO blocks it forever, "/dev/zero" or "-" for stdin are read as data), allocates the
 * declared size before looking at the file (171 bytes can ask for 4 GiB), and leaks on the error
 * paths of its gzip and ZRL decoders. So umbra reads the header text itself from a regular file,
 * takes out the "data file" line (recognised with Teem's own field table), hands the rest to
 * nrrdStringRead with skipData, and then opens the data (after the header, or the one detached
 * file named relative to the header, under the data-file policy of io/data_file.c) through
 * umbra__file_open, checks the declared size against what the file can hold before allocating
 * anything, and decodes raw, gzip (zlib), ZRL, ascii and hex itself. Limits, all refused with a message naming the value and the limit:
 *   - the header text is at most NRRD_HEADER_MAX bytes;
 *   - raw data must fill the rest of its file exactly (after any line and byte skips); hex needs
 *     two characters a byte, ascii two a value;
 *   - gzip data can expand at most GZIP_MAX_RATIO : 1 (deflate's own bound, 1032:1), ZRL at most
 *     ZRL_MAX_RATIO : 1 (four bytes encode at most 65535 zeros);
 *   - bzip2 and data split over several files are not read.
 *
 * Teem keeps its errors in a process-wide store (biff) and reads the global nrrdStateVerboseIO to
 * decide whether to print. Both are wrong for a library inside another program, so the Teem call
 * runs under one lock, with verbosity off, and its error text is moved straight into the context's
 * message and freed. The header is parsed in the "C" numeric locale.
 *
 * Why one file past 800 lines: the header split, the size checks and the five decoders are one
 * reader whose checks must see each other; splitting would scatter the allocation rules. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include <teem/nrrd.h>
#include <zlib.h>

#include "io_internal.h"

#define NRRD_HEADER_MAX (1u << 20)
#define GZIP_MAX_RATIO 1032u
#define ZRL_MAX_RATIO 16384u
/* Messages quote at most this much of a value taken from a file. */
#define QUOTE_MAX 200

/* Serialises umbra's use of Teem's process-wide state (biff, nrrdStateVerboseIO). It is the one
 * mutable global here, and it exists to contain someone else's. */
static pthread_mutex_t teem_lock = PTHREAD_MUTEX_INITIALIZER;

/* Turns biff's "[nrrd] a\n[nrrd] b\n" into "a; b" in place. */
static void flatten_biff(char *msg)
{
    char *src = msg, *dst = msg;
    while (*src) {
        if (strncmp(src, "[nrrd] ", 7) == 0) {
            src += 7;
        }
        while (*src && *src != '\n') {
            *dst++ = *src++;
        }
        while (*src == '\n') {
            ++src;
        }
        if (*src) {
            *dst++ = ';';
            *dst++ = ' ';
        }
    }
    *dst = '\0';
}

/* World units between samples along one axis: the axis spacing, else the length of its space
 * direction, else 1. */
static float nrrd_axis_spacing(const Nrrd *nrrd, unsigned int axis)
{
    double s = nrrd->axis[axis].spacing;
    if (isfinite(s) && s != 0.0) {
        return (float)fabs(s);
    }
    if (nrrd->spaceDim > 0) {
        s = nrrdSpaceVecNorm(nrrd->spaceDim, nrrd->axis[axis].spaceDirection);
        if (isfinite(s) && s > 0.0) {
            return (float)s;
        }
    }
    return 1.0f;
}

/* The index-to-world transform of a 3-D space: the space origin (0 where absent) and each axis's
 * unit space direction, with the directions' lengths as the spacing. Returns 0 (centred box) when
 * the header has no 3-D space or some axis lacks a finite, non-zero direction. */
static int nrrd_transform(const Nrrd *nrrd, unsigned int first_axis, float spacing[3],
                          float origin[3], float directions[9])
{
    if (nrrd->spaceDim != 3) {
        return 0;
    }
    for (unsigned int a = 0; a < 3; ++a) {
        const double *d = nrrd->axis[first_axis + a].spaceDirection;
        double len = nrrdSpaceVecNorm(3, d);
        if (!isfinite(len) || !(len > 0.0)) {
            return 0;
        }
        spacing[a] = (float)len;
        for (unsigned int k = 0; k < 3; ++k) {
            directions[3 * a + k] = (float)(d[k] / len);
        }
    }
    for (unsigned int k = 0; k < 3; ++k) {
        origin[k] = isfinite(nrrd->spaceOrigin[k]) ? (float)nrrd->spaceOrigin[k] : 0.0f;
    }
    return 1;
}

/* ---- the header ------------------------------------------------------------------------------- */

/* What umbra takes from the header text before Teem sees it. */
typedef struct nrrd_header {
    char *text;           /* the header for Teem: every line but "data file", '\n'-ended */
    char *data_file;      /* the "data file" value, or NULL when the data is attached */
    uint64_t data_offset; /* attached data: where it starts in the header's file */
    int has_blank_line;   /* the header ended with a blank line (attached data may follow) */
} nrrd_header;

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Splits the first bytes of the file (buf, got of them, the whole file when got == file_size)
 * into the header lines up to the first blank line. */
static umbra_status header_split(umbra_context ctx, const char *func, const char *path,
                                 const char *buf, size_t got, size_t file_size, nrrd_header *h)
{
    /* The fields every NRRD header must have. Checked here, not left to Teem: a header without
     * them reaches Teem's final consistency check, whose error path leaks. */
    static const int required[4] = {nrrdField_type, nrrdField_dimension, nrrdField_sizes,
                                    nrrdField_encoding};
    int seen[4] = {0, 0, 0, 0};
    size_t pos = 0, out = 0, k;
    int field;
    /* Anything else is left to Teem, which names what it expected. */
    const int is_nrrd = got >= 4 && memcmp(buf, "NRRD", 4) == 0;
    h->text = malloc(got + 2);
    if (!h->text) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory for the header of "
                           "\"%s\"", func, path);
    }
    for (;;) {
        const char *line = buf + pos, *eol, *colon;
        size_t len, next;
        if (pos >= got) {
            if (got < file_size) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": the header is longer than %u bytes (the limit)",
                                   func, path, NRRD_HEADER_MAX);
            }
            h->data_offset = file_size;
            break;
        }
        eol = memchr(line, '\n', got - pos);
        if (!eol && got < file_size) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": the header is longer than %u bytes (the limit)", func,
                               path, NRRD_HEADER_MAX);
        }
        len = eol ? (size_t)(eol - line) : got - pos;
        next = pos + len + (eol ? 1 : 0);
        if (memchr(line, '\0', len)) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": NUL byte in the header",
                               func, path);
        }
        if (len == 0 || (len == 1 && line[0] == '\r')) {
            h->has_blank_line = 1;
            h->data_offset = next;
            break;
        }
        /* Teem's own rule (_nrrdReadNrrdParseField): a field is the text before the first ": ",
         * looked up in the nrrdField table; '#' starts a comment. */
        colon = NULL;
        if (line[0] != '#') {
            /* Within this line only: the buffer is not one string, and a search past the line
             * would make a header of many short lines quadratic. */
            for (k = 0; k + 1 < len && k < 64; ++k) {
                if (line[k] == ':' && line[k + 1] == ' ') {
                    colon = line + k;
                    break;
                }
            }
        }
        if (is_nrrd && line[0] != '#' && pos > 0 && !colon) {
            /* Neither a field nor a key/value (":="): Teem refuses such a line too, but leaks on
             * that path (88 bytes a load), so it is refused here first. */
            int keyvalue = 0;
            for (k = 0; k + 1 < len; ++k) {
                keyvalue |= line[k] == ':' && line[k + 1] == '=';
            }
            if (!keyvalue) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": header line \"%.*s\" is neither a field "
                                   "(\"name: value\") nor a key/value (\"key:=value\")",
                                   func, path, (int)(len > QUOTE_MAX ? QUOTE_MAX : len), line);
            }
        }
        if (colon) {
            char key[64];
            memcpy(key, line, (size_t)(colon - line));
            key[colon - line] = '\0';
            field = airEnumVal(nrrdField, key);
            for (k = 0; k < 4; ++k) {
                seen[k] |= field == required[k];
            }
            if (field == nrrdField_data_file) {
                const char *v = colon + 2, *end = line + len;
                while (v < end && is_blank(*v)) {
                    ++v;
                }
                while (end > v && is_blank(end[-1])) {
                    --end;
                }
                if (h->data_file) {
                    return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                       "%s: \"%s\": \"data file\" is given twice", func, path);
                }
                if (end == v || (end - v >= 4 && memcmp(v, "LIST", 4) == 0) ||
                    memchr(v, '%', (size_t)(end - v))) {
                    return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                       "%s: \"%s\": data file \"%.*s\": only one data file, named "
                                       "plainly, is supported (no LIST or %%d sequences)",
                                       func, path, (int)(end - v) > QUOTE_MAX ? QUOTE_MAX
                                                                              : (int)(end - v),
                                       v);
                }
                h->data_file = malloc((size_t)(end - v) + 1);
                if (!h->data_file) {
                    return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                       "%s: out of memory for \"%s\"", func, path);
                }
                memcpy(h->data_file, v, (size_t)(end - v));
                h->data_file[end - v] = '\0';
                pos = next;
                continue;
            }
        }
        memcpy(h->text + out, line, len);
        out += len;
        h->text[out++] = '\n';
        pos = next;
    }
    h->text[out] = '\0';
    for (k = 0; k < 4; ++k) {
        if (!seen[k] && is_nrrd) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": the header has no \"%s\" field (required)", func,
                               path, airEnumStr(nrrdField, required[k]));
        }
    }
    return UMBRA_SUCCESS;
}

/* ---- the data --------------------------------------------------------------------------------- */

/* Inflates exactly n bytes into dst (NULL: discard them) from zs, whose input is already set;
 * concatenated gzip members are read as one stream, as gzip itself does. */
static umbra_status inflate_bytes(umbra_context ctx, const char *func, const char *path,
                                  z_stream *zs, const unsigned char *in_end, unsigned char *dst,
                                  size_t n, size_t total)
{
    unsigned char scratch[16384];
    size_t done = 0;
    while (done < n) {
        size_t want = n - done;
        int rc;
        if (!dst && want > sizeof scratch) {
            want = sizeof scratch;
        }
        if (want > UINT_MAX) {
            want = UINT_MAX;
        }
        if (zs->avail_in == 0) {
            size_t left = (size_t)(in_end - zs->next_in);
            zs->avail_in = (uInt)(left > UINT_MAX ? UINT_MAX : left);
        }
        zs->next_out = dst ? dst + done : scratch;
        zs->avail_out = (uInt)want;
        rc = inflate(zs, Z_NO_FLUSH);
        done += want - zs->avail_out;
        if (rc == Z_STREAM_END && done < n && zs->next_in < in_end) {
            rc = inflateReset(zs) == Z_OK ? Z_OK : Z_DATA_ERROR;
        }
        if (rc == Z_STREAM_END || (rc == Z_BUF_ERROR && zs->next_in >= in_end)) {
            if (done < n) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": the gzip data ends after %zu of the %zu bytes the "
                                   "header declares",
                                   func, path, total - (n - done), total);
            }
        } else if (rc != Z_OK) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": corrupt gzip data (%s)",
                               func, path, zs->msg ? zs->msg : zError(rc));
        }
    }
    return UMBRA_SUCCESS;
}

static umbra_status decode_gzip(umbra_context ctx, const char *func, const char *path,
                                const unsigned char *in, size_t in_size, size_t skip,
                                unsigned char *dst, size_t n)
{
    umbra_status st;
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    /* 15 + 32: a gzip or zlib header, detected from the data. */
    if (inflateInit2(&zs, 15 + 32) != Z_OK) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: \"%s\": cannot start zlib",
                           func, path);
    }
    zs.next_in = (unsigned char *)(uintptr_t)in; /* zlib's API is not const */
    zs.avail_in = 0;
    st = inflate_bytes(ctx, func, path, &zs, in + in_size, NULL, skip, skip + n);
    if (st == UMBRA_SUCCESS) {
        st = inflate_bytes(ctx, func, path, &zs, in + in_size, dst, n, skip + n);
    }
    inflateEnd(&zs);
    return st;
}

/* Teem's zero run-length code: a nonzero byte is itself; 0 n (n > 0) is n zeros; 0 0 lo hi is
 * lo + 256 hi zeros. dst is zeroed by the caller. */
static umbra_status decode_zrl(umbra_context ctx, const char *func, const char *path,
                               const unsigned char *in, size_t in_size, unsigned char *dst,
                               size_t n)
{
    size_t i = 0, j = 0;
    while (j < n) {
        size_t run;
        if (i >= in_size) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": the ZRL data ends after %zu of the %zu bytes the "
                               "header declares",
                               func, path, j, n);
        }
        if (in[i] != 0) {
            dst[j++] = in[i++];
            continue;
        }
        if (i + 1 >= in_size) {
            run = n + 1; /* truncated code: reported below */
        } else if (in[i + 1] != 0) {
            run = in[i + 1];
            i += 2;
        } else if (i + 3 < in_size) {
            run = (size_t)in[i + 2] + 256u * in[i + 3];
            i += 4;
        } else {
            run = n + 1;
        }
        if (run > n - j) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": malformed ZRL data at byte %zu (a run past the %zu "
                               "bytes the header declares, or a truncated code)",
                               func, path, i, n);
        }
        j += run;
    }
    return UMBRA_SUCCESS;
}

static int hex_digit(int c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

static umbra_status decode_hex(umbra_context ctx, const char *func, const char *path,
                               const unsigned char *in, size_t in_size, unsigned char *dst,
                               size_t n)
{
    size_t i = 0, j;
    for (j = 0; j < n; ++j) {
        int d[2], k;
        for (k = 0; k < 2; ++k) {
            while (i < in_size && (in[i] == '\n' || is_blank((char)in[i]))) {
                ++i;
            }
            d[k] = i < in_size ? hex_digit(in[i]) : -1;
            if (d[k] < 0) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": hex data: %s at byte %zu of %zu (value %zu of "
                                   "%zu)",
                                   func, path, i < in_size ? "not a hex digit" : "ended", i,
                                   in_size, j, n);
            }
            ++i;
        }
        dst[j] = (unsigned char)(16 * d[0] + d[1]);
    }
    return UMBRA_SUCCESS;
}

/* Values written out in decimal, separated by blanks, newlines or commas; text is NUL-ended. */
static umbra_status decode_ascii(umbra_context ctx, const char *func, const char *path,
                                 const char *text, umbra_scalar_type type, void *dst, size_t count)
{
    const char *s = text;
    size_t i;
    for (i = 0; i < count; ++i) {
        char *end = NULL;
        while (*s == '\n' || *s == ',' || is_blank(*s)) {
            ++s;
        }
        errno = 0;
        if (type == UMBRA_FLOAT32) {
            float v = strtof(s, &end);
            if (end != s && errno == 0 && isfinite(v)) {
                ((float *)dst)[i] = v;
            } else {
                end = NULL;
            }
        } else {
            long v = strtol(s, &end, 10);
            long lo = type == UMBRA_INT16 ? -32768 : 0;
            long hi = type == UMBRA_UINT8 ? 255 : type == UMBRA_UINT16 ? 65535 : 32767;
            if (end == s || errno != 0 || v < lo || v > hi) {
                end = NULL;
            } else if (type == UMBRA_UINT8) {
                ((uint8_t *)dst)[i] = (uint8_t)v;
            } else if (type == UMBRA_UINT16) {
                ((uint16_t *)dst)[i] = (uint16_t)v;
            } else {
                ((int16_t *)dst)[i] = (int16_t)v;
            }
        }
        if (!end || (*end != '\0' && *end != '\n' && *end != ',' && !is_blank(*end))) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": ascii data: value %zu of %zu (\"%.20s\") is %s", func,
                               path, i, count, s,
                               *s == '\0' ? "missing" : "not a number of the volume's type");
        }
        s = end;
    }
    return UMBRA_SUCCESS;
}

/* ---- the reader ------------------------------------------------------------------------------- */

typedef enum nrrd_encoding { ENC_RAW, ENC_GZIP, ENC_ZRL, ENC_ASCII, ENC_HEX } nrrd_encoding;

/* A 4-D array whose first axis has size 1 (a one-component "vector" volume, as some tools
 * write) is accepted as the 3-D volume it is. */
/* Step 6 of umbra_volume_load_nrrd, the read and decode, as umbra_volume_create_filled's fill:
 * the voxels are decoded straight into the memory the device reads. */
typedef struct nrrd_fill {
    umbra_context ctx;
    const char *func, *data_name;
    FILE *df;
    nrrd_encoding enc;
    size_t remaining, skip, count, type_size;
    umbra_scalar_type type;
    int swap;
} nrrd_fill;

static umbra_status fill_nrrd(void *user, void *dst, size_t bytes)
{
    nrrd_fill *F = user;
    umbra_context ctx = F->ctx;
    const char *func = F->func, *data_name = F->data_name;
    const size_t remaining = F->remaining;
    unsigned char *in = NULL;
    umbra_status st;
    if (F->enc == ENC_RAW) {
        st = umbra__file_read(ctx, func, data_name, F->df, dst, bytes);
    } else {
        in = malloc(remaining + 1);
        if (!in) {
            return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: cannot allocate %zu bytes for the data of \"%s\"", func,
                               remaining + 1, data_name);
        }
        st = umbra__file_read(ctx, func, data_name, F->df, in, remaining);
        if (st != UMBRA_SUCCESS) {
            goto fail;
        }
        in[remaining] = '\0';
        switch (F->enc) {
        case ENC_GZIP:
            st = decode_gzip(ctx, func, data_name, in, remaining, F->skip, dst, bytes);
            break;
        case ENC_ZRL:
            memset(dst, 0, bytes); /* runs of zeros are skipped, not written */
            st = decode_zrl(ctx, func, data_name, in, remaining, dst, bytes);
            break;
        case ENC_HEX: st = decode_hex(ctx, func, data_name, in, remaining, dst, bytes); break;
        default:
            if (memchr(in, '\0', remaining)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": ascii data holds a NUL byte", func, data_name);
            } else {
                st = decode_ascii(ctx, func, data_name, (const char *)in, F->type, dst, F->count);
            }
            break;
        }
    }
    if (st == UMBRA_SUCCESS && F->swap) {
        umbra__swap_bytes(dst, F->count, F->type_size);
    }
fail:
    free(in);
    return st;
}

umbra_status umbra_volume_load_nrrd(umbra_context ctx, const char *path, umbra_volume *out)
{
    return umbra__volume_load_nrrd(ctx, path, NULL, NULL, out);
}

umbra_status umbra__volume_load_nrrd(umbra_context ctx, const char *path,
                                     const umbra_volume_load_options *options,
                                     const umbra__box *box, umbra_volume *out)
{
    static const char *const enc_names[] = {"raw", "gzip", "zrl", "ascii", "hex"};
    const char *func = "umbra_volume_load_nrrd";
    umbra_status st = UMBRA_SUCCESS;
    nrrd_header h;
    Nrrd *nrrd = NULL;
    NrrdIoState *nio = NULL;
    char *biff_msg = NULL, *head = NULL, *data_path = NULL;
    const char *data_name = path;
    FILE *f = NULL, *df = NULL;
    size_t file_size = 0, got, data_size = 0, type_size, count = 1, bytes, pos, remaining;
    umbra_scalar_type type = UMBRA_UINT8;
    nrrd_encoding enc;
    uint32_t dims[3];
    float spacing[3], origin[3], directions[9];
    unsigned int first_axis = 0, i;
    int parse_failed, verbose, endian, placed;
    long byte_skip;
    locale_t c_locale, previous = (locale_t)0;

    memset(&h, 0, sizeof h);
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

    /* 1. The header text, from a regular file. */
    st = umbra__file_open(ctx, func, path, &f, &file_size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    got = file_size < NRRD_HEADER_MAX ? file_size : NRRD_HEADER_MAX;
    head = malloc(got + 1);
    if (!head) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory for \"%s\"", func,
                         path);
        goto fail;
    }
    st = umbra__file_read(ctx, func, path, f, head, got);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    st = header_split(ctx, func, path, head, got, file_size, &h);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }

    /* 2. Teem parses it; with skipData and no data file it opens and allocates nothing. */
    nrrd = nrrdNew();
    nio = nrrdIoStateNew();
    if (!nrrd || !nio) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory for \"%s\"", func,
                         path);
        goto fail;
    }
    nio->skipData = AIR_TRUE;
    pthread_mutex_lock(&teem_lock);
    verbose = nrrdStateVerboseIO;
    nrrdStateVerboseIO = 0;
    c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (c_locale != (locale_t)0) {
        previous = uselocale(c_locale);
    }
    parse_failed = nrrdStringRead(nrrd, h.text, nio);
    if (c_locale != (locale_t)0) {
        uselocale(previous);
        freelocale(c_locale);
    }
    nrrdStateVerboseIO = verbose;
    if (parse_failed) {
        biff_msg = biffGetDone(NRRD);
    }
    pthread_mutex_unlock(&teem_lock);
    if (parse_failed) {
        if (biff_msg) {
            flatten_biff(biff_msg);
        }
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: cannot read \"%s\": %s", func, path,
                         biff_msg ? biff_msg : "Teem gave no reason");
        goto fail;
    }

    /* 3. What the header declares. */
    switch (nrrd->type) {
    case nrrdTypeUChar: type = UMBRA_UINT8; break;
    case nrrdTypeUShort: type = UMBRA_UINT16; break;
    case nrrdTypeShort: type = UMBRA_INT16; break;
    case nrrdTypeFloat: type = UMBRA_FLOAT32; break;
    default:
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" has type %s; supported are uchar, ushort, short and float",
                         func, path, airEnumStr(nrrdType, nrrd->type));
        goto fail;
    }
    if (nrrd->dim == 4 && nrrd->axis[0].size == 1) {
        first_axis = 1;
    } else if (nrrd->dim != 3) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" has dimension %u; a volume must have 3 (or 4 with a first "
                         "axis of size 1)",
                         func, path, nrrd->dim);
        goto fail;
    }
    type_size = umbra_scalar_type_size(type);
    for (i = 0; i < 3; ++i) {
        size_t size = nrrd->axis[first_axis + i].size;
        if (size == 0 || size > UINT32_MAX) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": axis %u has size %zu", func,
                             path, first_axis + i, size);
            goto fail;
        }
        dims[i] = (uint32_t)size;
        spacing[i] = nrrd_axis_spacing(nrrd, first_axis + i);
        /* umbra_volume_create's bound (volumes beyond one device allocation are split),
         * checked before the product so that it cannot overflow. */
        if (size > ((size_t)1 << 36) / count) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": sizes %zu x %zu x %zu: more than 2^36 voxels (the "
                             "limit)",
                             func, path, nrrd->axis[first_axis].size,
                             nrrd->axis[first_axis + 1].size,
                             first_axis + 2 < nrrd->dim ? nrrd->axis[first_axis + 2].size : 0);
            goto fail;
        }
        count *= size;
    }
    /* With space directions the file places the volume in its world (spacing: their lengths). */
    placed = nrrd_transform(nrrd, first_axis, spacing, origin, directions);
    bytes = count * type_size;
    if (nio->encoding == nrrdEncodingRaw) {
        enc = ENC_RAW;
    } else if (nio->encoding == nrrdEncodingGzip) {
        enc = ENC_GZIP;
    } else if (nio->encoding == nrrdEncodingZRL) {
        enc = ENC_ZRL;
    } else if (nio->encoding == nrrdEncodingAscii) {
        enc = ENC_ASCII;
    } else if (nio->encoding == nrrdEncodingHex) {
        enc = ENC_HEX;
    } else {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": encoding %s is not supported (raw, gzip, zrl, ascii, hex)",
                         func, path, nio->encoding ? nio->encoding->name : "(none)");
        goto fail;
    }
    endian = nio->endian;
    if (type_size > 1 && enc != ENC_ASCII && endian != airEndianLittle &&
        endian != airEndianBig) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": type %s with %s encoding needs an \"endian\" field", func,
                         path, airEnumStr(nrrdType, nrrd->type), enc_names[enc]);
        goto fail;
    }
    byte_skip = nio->byteSkip;
    if (byte_skip < -1 || (byte_skip == -1 && enc != ENC_RAW)) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": byte skip %ld: must be >= 0 (or -1 with raw encoding)",
                         func, path, byte_skip);
        goto fail;
    }

    /* 4. The data file: the header's own (after the blank line), or the named one, under the
     * data-file policy (inside the header's directory or a data root; a regular file like any
     * other input). */
    if (h.data_file) {
        st = umbra__data_file_open(ctx, func, path, h.data_file, options, &data_path, &df,
                                   &data_size);
        if (st != UMBRA_SUCCESS) {
            goto fail;
        }
        data_name = data_path;
        pos = 0;
    } else {
        if (!h.has_blank_line) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": the header ends without a blank line and names no "
                             "\"data file\"",
                             func, path);
            goto fail;
        }
        df = f;
        f = NULL;
        data_size = file_size;
        pos = (size_t)h.data_offset;
    }
    if (fseeko(df, (off_t)pos, SEEK_SET) != 0) {
        char buf[256];
        st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot seek in \"%s\": %s", func, data_name,
                         umbra__errno_text(errno, buf, sizeof buf));
        goto fail;
    }
    for (i = 0; i < nio->lineSkip; ++i) {
        int c;
        while ((c = getc(df)) != EOF && c != '\n') {
        }
        if (c == EOF) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": the data ends while skipping line %u of %u", func,
                             data_name, i + 1, nio->lineSkip);
            goto fail;
        }
    }
    {
        off_t at = ftello(df);
        if (at < 0 || (uint64_t)at > data_size) {
            st = umbra__fail(ctx, UMBRA_ERROR_IO,
                             "%s: \"%s\" changed while being read (now past its %zu bytes)", func,
                             data_name, data_size);
            goto fail;
        }
        pos = (size_t)at;
    }
    remaining = data_size - pos;
    if (enc != ENC_GZIP && byte_skip >= 0) {
        if ((uint64_t)byte_skip > remaining) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": byte skip %ld passes the end of the data (%zu bytes)",
                             func, data_name, byte_skip, remaining);
            goto fail;
        }
        pos += (size_t)byte_skip;
        remaining -= (size_t)byte_skip;
    } else if (byte_skip == -1) {
        /* Raw data at the end of the file, whatever precedes it. */
        if (bytes > remaining) {
            remaining = 0; /* reported below */
        } else {
            pos += remaining - bytes;
            remaining = bytes;
        }
    }

    /* 5. Declared size against the file, before any allocation. */
    {
        int fits;
        const char *limit;
        switch (enc) {
        case ENC_RAW:
            /* Exactly: a data file that is longer (say /etc/passwd named as the data of a small
             * volume) is not this volume's data. */
            fits = bytes == remaining;
            limit = "raw data must fill the file exactly";
            break;
        case ENC_HEX: fits = bytes <= remaining / 2; limit = "hex needs 2 characters a byte"; break;
        case ENC_ASCII:
            fits = count <= remaining / 2 + 1;
            limit = "ascii needs at least 2 characters a value";
            break;
        case ENC_GZIP:
            fits = (uint64_t)bytes + (uint64_t)byte_skip <=
                   (uint64_t)remaining * GZIP_MAX_RATIO + 64;
            limit = "deflate expands at most 1032:1";
            break;
        default:
            fits = (uint64_t)bytes <= (uint64_t)remaining * ZRL_MAX_RATIO + 64;
            limit = "ZRL expands at most 16384:1";
            break;
        }
        if (!fits) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": sizes %u x %u x %u of %zu-byte values (%zu bytes) "
                             "do not match the %zu bytes of %s data in \"%s\" (%s)",
                             func, path, dims[0], dims[1], dims[2], type_size, bytes, remaining,
                             enc_names[enc], data_name, limit);
            goto fail;
        }
    }
    if (fseeko(df, (off_t)pos, SEEK_SET) != 0) {
        char buf[256];
        st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot seek in \"%s\": %s", func, data_name,
                         umbra__errno_text(errno, buf, sizeof buf));
        goto fail;
    }

    /* 6. Read and decode, into the device's buffer (fill_nrrd), or only a box of it. */
    if (box) {
        int swap = type_size > 1 && enc != ENC_ASCII &&
                   (endian == airEndianBig) != (umbra__host_is_big_endian() != 0);
        st = umbra__box_info(ctx, func, box, type, dims, spacing, placed ? origin : NULL,
                             placed ? directions : NULL, 1);
        if (st != UMBRA_SUCCESS || umbra__box_header_only(box))
            goto fail;
        if (enc != ENC_RAW && enc != ENC_GZIP) {
            st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "%s: \"%s\": a box is read from raw or gzip data, not %s", func,
                             path, enc_names[enc]);
            goto fail;
        }
        st = umbra__box_read(ctx, func, data_name, df, enc == ENC_GZIP ? remaining : 0,
                             enc == ENC_GZIP ? (size_t)byte_skip : 0, dims, type_size,
                             swap ? type_size : 0, box);
    } else {
        nrrd_fill F = {ctx, func, data_name, df, enc, remaining, (size_t)byte_skip, count,
                       type_size, type,
                       type_size > 1 && enc != ENC_ASCII &&
                           (endian == airEndianBig) != (umbra__host_is_big_endian() != 0)};
        st = umbra__volume_from_fill(ctx, fill_nrrd, &F, type, dims, spacing,
                                     placed ? origin : NULL, placed ? directions : NULL, out);
    }

fail:
    if (df) {
        fclose(df);
    }
    if (f) {
        fclose(f);
    }
    free(data_path);
    free(biff_msg);
    if (nio) {
        nrrdIoStateNix(nio);
    }
    if (nrrd) {
        nrrdNuke(nrrd);
    }
    free(h.text);
    free(h.data_file);
    free(head);
    return st;
}
