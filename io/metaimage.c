// SPDX-License-Identifier: Apache-2.0
/* io/metaimage.c: MetaImage volumes (.mha with the voxels in the same file, .mhd with them in a
 * separate raw or zlib-compressed file), as ITK, 3D Slicer and VTK write them. One file past 800
 * lines: the header reader, the data reader and the fill into the volume's buffer share one
 * parsed header struct and its checks, and nothing else in umbra_io uses them.
 *
 * Why umbra reads MetaImage itself. The one MetaImage library Debian 12 ships is MetaIO, inside
 * ITK (libITKMetaIO-5.2, in libinsighttoolkit5-dev, 33 packages) and again inside VTK
 * (vtkmetaio, libvtk9-dev, 118 packages). It was measured before this file was written (see the
 * docs/usage.md's volume files) and fails what umbra_io must do with a file from anywhere:
 *   - a header "NDims = 5000" followed by 5000 DimSize values makes MET_Read write past its
 *     4096-value field record (valgrind: invalid write of size 8 in MET_Read); upstream MetaIO
 *     still reads arrays of NDims values unchecked;
 *   - a file whose voxel data is short is read "successfully" (MetaImage::ReadStream ignores
 *     M_ReadElements' result), and ITK 5.2's inflate does not report corrupt compressed data;
 *   - it prints to std::cerr and std::cout on every malformed header, with no switch per call;
 *     silencing it would mean swapping the process's std::cerr buffer, which races with the
 *     application's own threads.
 * So the header is parsed here, strictly and bounded, and the data is read with zlib like the
 * NRRD reader's. The format is a list of "Key = Value" lines ending with ElementDataFile; the
 * keys and their meaning follow MetaIO (metaObject.cxx, metaImage.cxx) and ITK's MetaImageIO.
 *
 * The world. ITK writes the image's physical space: Offset (also Position, Origin) is voxel
 * (0, 0, 0)'s centre and TransformMatrix (also Rotation, Orientation) holds, in its values
 * 3a .. 3a+2, the direction of index axis a (ITK's MetaImageIO reads it that way). That space
 * is LPS by ITK's convention (x to the patient's left, y posterior, z superior); umbra keeps it as
 * written, as it keeps a NRRD's space, and does not turn it into NIfTI's RAS.
 * AnatomicalOrientation only describes the axes and is not used. A header with neither an offset
 * nor a matrix places nothing, and the box stays centred. */
#define _GNU_SOURCE /* strtod_l: numbers in the "C" locale whatever the application chose */

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include <zlib.h>

#include "io_internal.h"

/* The header (everything up to and including the ElementDataFile line) must lie within this
 * many bytes; ITK writes about 400. */
#define HEADER_MAX (1u << 20)
/* deflate never expands by more than 1032:1 (zlib's technical notes); + 64 for the framing. */
#define ZLIB_MAX_RATIO 1032u
/* Messages quote at most this much of a value taken from a file. */
#define QUOTE_MAX 120
/* The largest byte count a header may state: fits size_t and long long (and off_t below). */
#define BYTES_MAX ((long long)((uintmax_t)(SIZE_MAX / 2) < (uintmax_t)LLONG_MAX ? SIZE_MAX / 2 \
                                                                                : LLONG_MAX))

/* The MetaIO element types umbra reads (MetaIO's metaTypes.h: MET_LONG is 4 bytes). */
typedef struct met_type {
    const char *name;
    size_t size;
    umbra_scalar_type umbra; /* what it becomes */
} met_type;

enum { T_CHAR, T_UCHAR, T_SHORT, T_USHORT, T_INT, T_UINT, T_LONG, T_ULONG, T_LONG_LONG,
       T_ULONG_LONG, T_FLOAT, T_DOUBLE, T_COUNT };

static const met_type met_types[T_COUNT] = {
    {"MET_CHAR", 1, UMBRA_INT16},       {"MET_UCHAR", 1, UMBRA_UINT8},
    {"MET_SHORT", 2, UMBRA_INT16},      {"MET_USHORT", 2, UMBRA_UINT16},
    {"MET_INT", 4, UMBRA_FLOAT32},      {"MET_UINT", 4, UMBRA_FLOAT32},
    {"MET_LONG", 4, UMBRA_FLOAT32},     {"MET_ULONG", 4, UMBRA_FLOAT32},
    {"MET_LONG_LONG", 8, UMBRA_FLOAT32}, {"MET_ULONG_LONG", 8, UMBRA_FLOAT32},
    {"MET_FLOAT", 4, UMBRA_FLOAT32},    {"MET_DOUBLE", 8, UMBRA_FLOAT32},
};

/* The keys umbra looks at; each may appear once. Synonyms share a slot. */
enum { K_OBJECT_TYPE, K_NDIMS, K_DIM_SIZE, K_ELEMENT_TYPE, K_SPACING, K_SIZE, K_OFFSET,
       K_MATRIX, K_BINARY, K_MSB, K_COMPRESSED, K_COMPRESSED_SIZE, K_HEADER_SIZE, K_CHANNELS,
       K_DATA_FILE, K_COUNT };

static const struct {
    const char *name;
    int slot;
} met_keys[] = {
    {"ObjectType", K_OBJECT_TYPE},
    {"NDims", K_NDIMS},
    {"DimSize", K_DIM_SIZE},
    {"ElementType", K_ELEMENT_TYPE},
    {"ElementSpacing", K_SPACING},
    {"ElementSize", K_SIZE},
    {"Offset", K_OFFSET},
    {"Position", K_OFFSET},
    {"Origin", K_OFFSET},
    {"TransformMatrix", K_MATRIX},
    {"Rotation", K_MATRIX},
    {"Orientation", K_MATRIX},
    {"BinaryData", K_BINARY},
    {"BinaryDataByteOrderMSB", K_MSB},
    {"ElementByteOrderMSB", K_MSB},
    {"CompressedData", K_COMPRESSED},
    {"CompressedDataSize", K_COMPRESSED_SIZE},
    {"HeaderSize", K_HEADER_SIZE},
    {"ElementNumberOfChannels", K_CHANNELS},
    {"ElementDataFile", K_DATA_FILE},
};

typedef struct met_header {
    const char *value[K_COUNT];   /* NUL-terminated, blanks stripped; NULL where absent */
    const char *key[K_COUNT];     /* the spelling the file used, for messages */
    size_t data_offset;           /* first byte after the ElementDataFile line */
} met_header;

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Splits the header in text (n bytes, NUL-terminated by the caller at n) into *h, cutting values
 * in place. The header ends with the ElementDataFile line; whole says text is the whole file, whose
 * last line may then lack its newline (an .mhd written by hand). */
static umbra_status header_parse(umbra_context ctx, const char *func, const char *path, char *text,
                                 size_t n, int whole, met_header *h)
{
    size_t pos = 0;
    unsigned line_no = 0;

    memset(h, 0, sizeof *h);
    while (pos < n) {
        char *line = text + pos, *end, *sep, *key_end, *value, *value_end;
        size_t len, k;
        int slot = -1;
        ++line_no;
        end = memchr(line, '\n', n - pos);
        if (!end && whole) {
            end = text + n; /* the NUL the caller put there */
        }
        if (!end) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": the header has no ElementDataFile line within its "
                               "first %zu bytes",
                               func, path, n);
        }
        len = (size_t)(end - line);
        if (memchr(line, '\0', len)) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": header line %u holds a NUL byte (not a MetaImage "
                               "header)",
                               func, path, line_no);
        }
        *end = '\0';
        pos += len + (pos + len < n); /* past the newline, if there is one */
        while (is_blank(*line)) {
            ++line;
        }
        if (*line == '\0') {
            continue;
        }
        /* MetaIO ends a key at '=' or ':'. */
        sep = line + strcspn(line, "=:");
        if (*sep == '\0') {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": header line %u \"%.*s\" is not \"Key = Value\"", func,
                               path, line_no, QUOTE_MAX, line);
        }
        for (key_end = sep; key_end > line && is_blank(key_end[-1]); --key_end) {
        }
        *key_end = '\0';
        for (value = sep + 1; is_blank(*value); ++value) {
        }
        for (value_end = value + strlen(value); value_end > value && is_blank(value_end[-1]);
             --value_end) {
        }
        *value_end = '\0';
        /* Keys are case-sensitive, as in MetaIO; others (Comment, Modality, ElementMin, ...,
         * AnatomicalOrientation, CenterOfRotation) are ignored. */
        for (k = 0; k < sizeof met_keys / sizeof met_keys[0]; ++k) {
            if (strcmp(line, met_keys[k].name) == 0) {
                slot = met_keys[k].slot;
                break;
            }
        }
        if (slot < 0) {
            continue;
        }
        if (h->value[slot]) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": header line %u gives %s again (already given as %s)",
                               func, path, line_no, line, h->key[slot]);
        }
        h->value[slot] = value;
        h->key[slot] = line;
        if (slot == K_DATA_FILE) {
            h->data_offset = pos;
            return UMBRA_SUCCESS;
        }
    }
    return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                       "%s: \"%s\": the header has no ElementDataFile line within its first %zu "
                       "bytes",
                       func, path, n);
}

/* Parses exactly count numbers separated by blanks from s into out. Returns 0 on any other text
 * and on overflow. */
static int parse_doubles(const char *s, int count, locale_t c_locale, double *out)
{
    int i;
    for (i = 0; i < count; ++i) {
        char *end = NULL;
        while (is_blank(*s)) {
            ++s;
        }
        if (*s == '\0') {
            return 0;
        }
        errno = 0;
        out[i] = strtod_l(s, &end, c_locale);
        if (end == s || errno == ERANGE || !isfinite(out[i]) || (*end != '\0' && !is_blank(*end))) {
            return 0;
        }
        s = end;
    }
    while (is_blank(*s)) {
        ++s;
    }
    return *s == '\0';
}

/* Parses one integer in [lo, hi]. */
static int parse_int(const char *s, long long lo, long long hi, long long *out)
{
    char *end = NULL;
    long long v;
    if (*s == '\0') {
        return 0;
    }
    errno = 0;
    v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        return 0;
    }
    *out = v;
    return 1;
}

/* MetaIO's booleans: True/False (it looks at the first letter: T, t or 1 is true). Returns 1 or 0,
 * or -1 for anything else. */
static int parse_bool(const char *s)
{
    if (strcmp(s, "True") == 0 || strcmp(s, "true") == 0 || strcmp(s, "TRUE") == 0 ||
        strcmp(s, "1") == 0) {
        return 1;
    }
    if (strcmp(s, "False") == 0 || strcmp(s, "false") == 0 || strcmp(s, "FALSE") == 0 ||
        strcmp(s, "0") == 0) {
        return 0;
    }
    return -1;
}

/* Takes the next bytes of decoded voxels (a whole number of them) from the window they were
 * decoded into; returns UMBRA_SUCCESS or a status it recorded. */
typedef umbra_status (*met_sink)(void *user, unsigned char *bytes, size_t n);

/* Inflates exactly n bytes from in (zlib or gzip framing, detected), which must end the stream
 * exactly there. Without a sink they land in dst (n bytes); with one, dst is a window of win
 * bytes (a multiple of the voxel size), handed to sink each time it is full and at the end. */
static umbra_status inflate_exact(umbra_context ctx, const char *func, const char *path,
                                  const unsigned char *in, size_t in_size, unsigned char *dst,
                                  size_t n, size_t win, met_sink sink, void *user)
{
    umbra_status st = UMBRA_SUCCESS;
    z_stream zs;
    size_t in_done = 0, out_done = 0, win_fill = 0;
    int rc = Z_OK;

    memset(&zs, 0, sizeof zs);
    /* 15 + 32: a zlib or gzip header, detected from the data, as MetaIO's inflateInit2(47). */
    if (inflateInit2(&zs, 15 + 32) != Z_OK) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: \"%s\": cannot start zlib", func,
                           path);
    }
    while (rc == Z_OK) {
        size_t in_left = in_size - in_done,
               out_left = sink && win - win_fill < n - out_done ? win - win_fill : n - out_done;
        uInt ai = (uInt)(in_left > UINT_MAX ? UINT_MAX : in_left);
        uInt ao = (uInt)(out_left > UINT_MAX ? UINT_MAX : out_left);
        unsigned char spill;
        zs.next_in = (unsigned char *)(uintptr_t)(in + in_done); /* zlib's API is not const */
        zs.avail_in = ai;
        /* With the output full, one spare byte shows whether the stream goes on. */
        zs.next_out = ao ? dst + (sink ? win_fill : out_done) : &spill;
        zs.avail_out = ao ? ao : 1;
        rc = inflate(&zs, Z_NO_FLUSH);
        in_done += ai - zs.avail_in;
        if (ao) {
            out_done += ao - zs.avail_out;
            win_fill += ao - zs.avail_out;
            if (sink && (win_fill == win || out_done == n)) {
                st = sink(user, dst, win_fill);
                win_fill = 0;
                if (st != UMBRA_SUCCESS) {
                    goto done;
                }
            }
        } else if (zs.avail_out == 0) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": the compressed data holds more than the %zu bytes the "
                             "header declares",
                             func, path, n);
            goto done;
        }
        if (rc == Z_BUF_ERROR && in_done == in_size) {
            break; /* input used up before the stream's end */
        }
        if (rc == Z_BUF_ERROR) {
            rc = Z_OK; /* no progress possible this round only because a buffer was full */
        }
    }
    if (rc == Z_STREAM_END && out_done == n) {
        goto done;
    }
    if (rc == Z_STREAM_END || rc == Z_BUF_ERROR || rc == Z_OK) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": the compressed data ends after %zu of the %zu bytes the "
                         "header declares",
                         func, path, out_done, n);
    } else {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": corrupt compressed data (%s)",
                         func, path, zs.msg ? zs.msg : zError(rc));
    }
done:
    inflateEnd(&zs);
    return st;
}

/* Converts count voxels of MetaIO type t in src (host byte order) to umbra's type in dst.
 * Returns 0 if a value is not a finite float32. */
static int convert(const void *src, int t, size_t count, void *dst)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        double v;
        switch (t) {
        case T_CHAR: ((int16_t *)dst)[i] = ((const int8_t *)src)[i]; continue;
        case T_INT:
        case T_LONG: v = ((const int32_t *)src)[i]; break;
        case T_UINT:
        case T_ULONG: v = ((const uint32_t *)src)[i]; break;
        case T_LONG_LONG: v = (double)((const int64_t *)src)[i]; break;
        case T_ULONG_LONG: v = (double)((const uint64_t *)src)[i]; break;
        default: v = ((const double *)src)[i]; break; /* T_DOUBLE */
        }
        {
            float f = (float)v;
            if (!isfinite(f)) {
                return 0;
            }
            ((float *)dst)[i] = f;
        }
    }
    return 1;
}

/* What the header says, checked. */
typedef struct met_image {
    uint32_t dims[3];
    size_t count;               /* dims product */
    int type;                   /* index into met_types */
    float spacing[3], origin[3], dirs[9];
    int placed;                 /* Offset or TransformMatrix given: the volume carries them */
    int msb, compressed;
    long long header_size;      /* HeaderSize: bytes to skip, or -1 (0 when absent) */
    long long compressed_size;  /* CompressedDataSize (0 when absent) */
    const char *data_file;      /* ElementDataFile, in the header text */
} met_image;

/* Checks what the header says and fills *m: the grid, its type and place, and where the voxels
 * are. Nothing is allocated. */
static umbra_status header_interpret(umbra_context ctx, const char *func, const char *path,
                                     const met_header *h, locale_t c_locale, met_image *m)
{
    double dims_d[3], spacing_d[3] = {1, 1, 1}, offset_d[3] = {0, 0, 0},
                      matrix_d[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    long long ndims = 0, channels = 1;
    int binary = 1, i;

    memset(m, 0, sizeof *m);
    m->count = 1;
    m->type = -1;
    if (h->value[K_OBJECT_TYPE] && strcmp(h->value[K_OBJECT_TYPE], "Image") != 0) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": ObjectType \"%.*s\" is not "
                           "Image", func, path, QUOTE_MAX, h->value[K_OBJECT_TYPE]);
    }
    if (!h->value[K_NDIMS] || !parse_int(h->value[K_NDIMS], LLONG_MIN, LLONG_MAX, &ndims) ||
        ndims != 3) {
        /* A number other than 3 is a shape umbra does not read; anything else a broken header. */
        return umbra__fail(ctx, h->value[K_NDIMS] && ndims != 0 ? UMBRA_ERROR_UNSUPPORTED
                                                             : UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": NDims \"%.*s\": umbra reads 3-D volumes (NDims = 3)", func,
                           path, QUOTE_MAX, h->value[K_NDIMS] ? h->value[K_NDIMS] : "(missing)");
    }
    if (!h->value[K_DIM_SIZE] || !parse_doubles(h->value[K_DIM_SIZE], 3, c_locale, dims_d)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": DimSize \"%.*s\" is not three "
                           "sizes", func, path, QUOTE_MAX,
                           h->value[K_DIM_SIZE] ? h->value[K_DIM_SIZE] : "(missing)");
    }
    for (i = 0; i < 3; ++i) {
        /* MetaIO keeps sizes in an int. */
        if (!(dims_d[i] >= 1.0 && dims_d[i] <= (double)INT32_MAX) ||
            dims_d[i] != floor(dims_d[i])) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": DimSize \"%.*s\": each size "
                               "must be an integer in 1..%d", func, path, QUOTE_MAX,
                               h->value[K_DIM_SIZE], INT32_MAX);
        }
        m->dims[i] = (uint32_t)dims_d[i];
        if (m->count > SIZE_MAX / m->dims[i]) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": DimSize %s: too many voxels",
                               func, path, h->value[K_DIM_SIZE]);
        }
        m->count *= m->dims[i];
    }
    if (!h->value[K_ELEMENT_TYPE]) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" has no ElementType", func, path);
    }
    for (i = 0; i < T_COUNT; ++i) {
        if (strcmp(h->value[K_ELEMENT_TYPE], met_types[i].name) == 0) {
            m->type = i;
        }
    }
    if (m->type < 0) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": ElementType \"%.*s\" is not supported (MET_UCHAR, "
                           "MET_CHAR, MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_ULONG, "
                           "MET_LONG, MET_ULONG_LONG, MET_LONG_LONG, MET_FLOAT, MET_DOUBLE)",
                           func, path, QUOTE_MAX, h->value[K_ELEMENT_TYPE]);
    }
    if (h->value[K_CHANNELS] &&
        (!parse_int(h->value[K_CHANNELS], LLONG_MIN, LLONG_MAX, &channels) || channels != 1)) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": ElementNumberOfChannels "
                           "\"%.*s\": umbra reads one scalar per voxel (1)", func, path, QUOTE_MAX,
                           h->value[K_CHANNELS]);
    }
    {
        /* Booleans: BinaryData (default True: ITK always writes it), byte order, compression. */
        const int slots[3] = {K_BINARY, K_MSB, K_COMPRESSED};
        int *dst[3];
        dst[0] = &binary;
        dst[1] = &m->msb;
        dst[2] = &m->compressed;
        for (i = 0; i < 3; ++i) {
            if (h->value[slots[i]]) {
                int b = parse_bool(h->value[slots[i]]);
                if (b < 0) {
                    return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s \"%.*s\" is not "
                                       "True or False", func, path, h->key[slots[i]], QUOTE_MAX,
                                       h->value[slots[i]]);
                }
                *dst[i] = b;
            }
        }
    }
    if (!binary) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": BinaryData False (voxels as "
                           "text) is not supported", func, path);
    }
    if (h->value[K_HEADER_SIZE] &&
        !parse_int(h->value[K_HEADER_SIZE], -1, BYTES_MAX, &m->header_size)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": HeaderSize \"%.*s\" is not -1 or "
                           "a byte count", func, path, QUOTE_MAX, h->value[K_HEADER_SIZE]);
    }
    if (h->value[K_COMPRESSED_SIZE] &&
        !parse_int(h->value[K_COMPRESSED_SIZE], 1, BYTES_MAX, &m->compressed_size)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": CompressedDataSize \"%.*s\" is "
                           "not a byte count > 0",
                           func, path, QUOTE_MAX, h->value[K_COMPRESSED_SIZE]);
    }

    /* Where the voxels are in the world. */
    if ((h->value[K_SPACING] && !parse_doubles(h->value[K_SPACING], 3, c_locale, spacing_d)) ||
        (!h->value[K_SPACING] && h->value[K_SIZE] &&
         !parse_doubles(h->value[K_SIZE], 3, c_locale, spacing_d))) {
        int k = h->value[K_SPACING] ? K_SPACING : K_SIZE;
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s \"%.*s\" is not three finite "
                           "numbers", func, path, h->key[k], QUOTE_MAX, h->value[k]);
    }
    for (i = 0; i < 3; ++i) {
        m->spacing[i] = (float)spacing_d[i];
        if (!(m->spacing[i] > 0.0f) || !isfinite(m->spacing[i])) {
            int k = h->value[K_SPACING] ? K_SPACING : K_SIZE;
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": %s \"%.*s\": each spacing must be a finite float > 0",
                               func, path, h->key[k], QUOTE_MAX, h->value[k]);
        }
    }
    if (h->value[K_OFFSET] && !parse_doubles(h->value[K_OFFSET], 3, c_locale, offset_d)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s \"%.*s\" is not three finite "
                           "numbers", func, path, h->key[K_OFFSET], QUOTE_MAX, h->value[K_OFFSET]);
    }
    if (h->value[K_MATRIX] && !parse_doubles(h->value[K_MATRIX], 9, c_locale, matrix_d)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s \"%.*s\" is not nine finite "
                           "numbers", func, path, h->key[K_MATRIX], QUOTE_MAX, h->value[K_MATRIX]);
    }
    for (i = 0; i < 3; ++i) {
        m->origin[i] = (float)offset_d[i];
        if (!isfinite(m->origin[i])) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s \"%.*s\" is beyond float "
                               "range",
                               func, path, h->key[K_OFFSET], QUOTE_MAX, h->value[K_OFFSET]);
        }
    }
    for (i = 0; i < 9; ++i) {
        m->dirs[i] = (float)matrix_d[i]; /* umbra_volume_create normalises and checks them */
    }

    m->placed = h->value[K_OFFSET] || h->value[K_MATRIX];
    m->data_file = h->value[K_DATA_FILE];
    return UMBRA_SUCCESS;
}

/* Voxels read and converted per step where the file's type is not umbra's (1 MiB of 8-byte
 * ones). */
#define CONVERT_CHUNK ((size_t)1 << 17)

/* What the fill callback reads: f (path) from its voxels on, raw or packed_n compressed bytes. */
typedef struct met_fill {
    umbra_context ctx;
    const char *func, *path;
    FILE *f;
    int compressed;
    size_t packed_n;           /* compressed bytes */
    int type;                  /* index into met_types */
    size_t count, done;        /* voxels in all and converted so far */
    int swap;                  /* the file's byte order is not the host's */
    unsigned char *dst;        /* the fill buffer, of met_types[type].umbra */
} met_fill;

/* met_sink: swaps and converts the next n bytes of voxels into the fill buffer. */
static umbra_status met_convert(void *user, unsigned char *bytes, size_t n)
{
    met_fill *F = user;
    size_t in = met_types[F->type].size, k = n / in;
    if (F->swap) {
        umbra__swap_bytes(bytes, k, in);
    }
    if (!convert(bytes, F->type, k,
                 F->dst + F->done * umbra_scalar_type_size(met_types[F->type].umbra))) {
        return umbra__fail(F->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": a %s voxel is not a finite "
                           "float32", F->func, F->path, met_types[F->type].name);
    }
    F->done += k;
    return UMBRA_SUCCESS;
}

/* umbra_volume_fill_fn: decodes the voxels into dst. A type umbra keeps (uchar, short, ushort,
 * float) is read or inflated into dst itself and swapped there; the others go through a
 * CONVERT_CHUNK window, so that no second full-size copy of the voxels exists. Compressed data
 * is held whole while it inflates (its size is the file's). */
static umbra_status fill_met(void *user, void *dst, size_t bytes)
{
    met_fill *F = user;
    umbra_status st = UMBRA_SUCCESS;
    size_t in = met_types[F->type].size, data_bytes = F->count * in;
    int keep = F->type == T_UCHAR || F->type == T_USHORT || F->type == T_SHORT ||
               F->type == T_FLOAT;
    unsigned char *packed = NULL, *window = NULL;

    if (bytes != F->count * umbra_scalar_type_size(met_types[F->type].umbra)) {
        return umbra__fail(F->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: \"%s\": the fill buffer "
                           "holds %zu bytes, not %zu voxels of %zu bytes", F->func, F->path,
                           bytes, F->count, umbra_scalar_type_size(met_types[F->type].umbra));
    }
    F->dst = dst;
    F->done = 0;
    if (!keep) {
        window = malloc(CONVERT_CHUNK * in);
        if (!window) {
            return umbra__fail(F->ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu "
                               "bytes to convert the voxels of \"%s\"", F->func,
                               CONVERT_CHUNK * in, F->path);
        }
    }
    if (F->compressed) {
        packed = malloc(F->packed_n ? F->packed_n : 1);
        if (!packed) {
            st = umbra__fail(F->ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes "
                             "for the compressed voxels of \"%s\"", F->func, F->packed_n,
                             F->path);
            goto done;
        }
        st = umbra__file_read(F->ctx, F->func, F->path, F->f, packed, F->packed_n);
        if (st == UMBRA_SUCCESS) {
            st = keep ? inflate_exact(F->ctx, F->func, F->path, packed, F->packed_n, dst,
                                      data_bytes, 0, NULL, NULL)
                      : inflate_exact(F->ctx, F->func, F->path, packed, F->packed_n, window,
                                      data_bytes, CONVERT_CHUNK * in, met_convert, F);
        }
    } else if (keep) {
        st = umbra__file_read(F->ctx, F->func, F->path, F->f, dst, data_bytes);
    } else {
        while (st == UMBRA_SUCCESS && F->done < F->count) {
            size_t k = F->count - F->done < CONVERT_CHUNK ? F->count - F->done : CONVERT_CHUNK;
            st = umbra__file_read(F->ctx, F->func, F->path, F->f, window, k * in);
            if (st == UMBRA_SUCCESS) {
                st = met_convert(F, window, k * in);
            }
        }
    }
    if (st == UMBRA_SUCCESS && keep && F->swap) {
        umbra__swap_bytes(dst, F->count, in);
    }
done:
    free(packed);
    free(window);
    return st;
}

umbra_status umbra_volume_load_metaimage(umbra_context ctx, const char *path, umbra_volume *out)
{
    return umbra__volume_load_metaimage(ctx, path, NULL, NULL, out);
}

umbra_status umbra__volume_load_metaimage(umbra_context ctx, const char *path,
                                          const umbra_volume_load_options *options,
                                          const umbra__box *box, umbra_volume *out)
{
    static const char *const func = "umbra_volume_load_metaimage";
    umbra_status st = UMBRA_SUCCESS;
    locale_t c_locale = (locale_t)0;
    FILE *f = NULL, *df = NULL;
    char *text = NULL, *dpath = NULL;
    size_t file_size = 0, head_n, data_size = 0, type_size, data_bytes, start, avail;
    met_header h;
    met_image m;
    const char *df_name;
    int local;

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
    c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (c_locale == (locale_t)0) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot make the \"C\" locale",
                           func);
    }

    /* The header: at most HEADER_MAX bytes from the start of the file. */
    st = umbra__file_open(ctx, func, path, &f, &file_size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    head_n = file_size < HEADER_MAX ? file_size : HEADER_MAX;
    text = malloc(head_n + 1);
    if (!text) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes for the "
                         "header of \"%s\"", func, head_n + 1, path);
        goto fail;
    }
    st = umbra__file_read(ctx, func, path, f, text, head_n);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    text[head_n] = '\0';
    st = header_parse(ctx, func, path, text, head_n, head_n == file_size, &h);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }

    st = header_interpret(ctx, func, path, &h, c_locale, &m);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }

    /* Where the voxels are on disk, and how many bytes they take: known before any allocation. */
    type_size = met_types[m.type].size;
    if (m.count > SIZE_MAX / type_size) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": DimSize %s of %zu bytes: too large",
                         func, path, h.value[K_DIM_SIZE], type_size);
        goto fail;
    }
    data_bytes = m.count * type_size;
    df_name = m.data_file;
    local = strcmp(df_name, "LOCAL") == 0 || strcmp(df_name, "Local") == 0 ||
            strcmp(df_name, "local") == 0;
    if (!local && (strncmp(df_name, "LIST", 4) == 0 || strchr(df_name, '%'))) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": ElementDataFile \"%.*s\": "
                         "slices in several files are not supported (one LOCAL or one data "
                         "file)", func, path, QUOTE_MAX, df_name);
        goto fail;
    }
    if (df_name[0] == '\0') {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": ElementDataFile is empty", func,
                         path);
        goto fail;
    }
    if (local && m.header_size != 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": HeaderSize %lld with "
                         "ElementDataFile LOCAL is not supported", func, path, m.header_size);
        goto fail;
    }
    if (m.compressed && m.header_size != 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": HeaderSize %lld with "
                         "CompressedData True is not supported", func, path, m.header_size);
        goto fail;
    }
    if (local) {
        df = f;
        f = NULL;
        data_size = file_size;
        start = h.data_offset;
    } else {
        fclose(f);
        f = NULL;
        /* Under the data-file policy: inside the header's directory or a data root. */
        st = umbra__data_file_open(ctx, func, path, df_name, options, &dpath, &df, &data_size);
        if (st != UMBRA_SUCCESS) {
            goto fail;
        }
        /* HeaderSize -1: the voxels are the file's last bytes. */
        start = m.header_size >= 0 ? (size_t)m.header_size
                                 : (data_size >= data_bytes ? data_size - data_bytes : 0);
    }
    if (start > data_size) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" holds %zu bytes, fewer than the %zu "
                         "before the voxels", func, local ? path : dpath, data_size, start);
        goto fail;
    }
    avail = data_size - start;
    if (!m.compressed && avail != data_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu bytes of voxels after byte %zu, expected %zu "
                         "(DimSize %s of %s, %zu bytes each)",
                         func, local ? path : dpath, avail, start, data_bytes,
                         h.value[K_DIM_SIZE], met_types[m.type].name, type_size);
        goto fail;
    }
    if (m.compressed) {
        size_t packed_n = m.compressed_size > 0 ? (size_t)m.compressed_size : avail;
        if (packed_n > avail) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": CompressedDataSize %zu, but "
                             "only %zu bytes follow the header",
                             func, local ? path : dpath, packed_n, avail);
            goto fail;
        }
        if (data_bytes / ZLIB_MAX_RATIO > packed_n + 64) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": %zu compressed bytes cannot hold the %zu bytes of "
                             "DimSize %s of %s (deflate expands at most %ux)",
                             func, local ? path : dpath, packed_n, data_bytes,
                             h.value[K_DIM_SIZE], met_types[m.type].name, ZLIB_MAX_RATIO);
            goto fail;
        }
        avail = packed_n;
    }

    /* Read: straight into the volume's buffer (umbra_volume_create_filled). */
    if (fseeko(df, (off_t)start, SEEK_SET) != 0) {
        char buf[256];
        st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot seek to byte %zu of \"%s\": %s", func,
                         start, local ? path : dpath, umbra__errno_text(errno, buf, sizeof buf));
        goto fail;
    }
    if (box) {
        int keep = m.type == T_UCHAR || m.type == T_USHORT || m.type == T_SHORT ||
                   m.type == T_FLOAT;
        int swap = type_size > 1 && (m.msb != 0) != umbra__host_is_big_endian();
        st = umbra__box_info(ctx, func, box, met_types[m.type].umbra, m.dims, m.spacing,
                             m.placed ? m.origin : NULL, m.placed ? m.dirs : NULL, 1);
        if (st != UMBRA_SUCCESS || umbra__box_header_only(box))
            goto fail;
        if (!keep) {
            st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                             "%s: \"%s\": a box is read of MET_UCHAR, MET_USHORT, MET_SHORT "
                             "and MET_FLOAT voxels, not %s (load it whole)",
                             func, path, met_types[m.type].name);
            goto fail;
        }
        st = umbra__box_read(ctx, func, local ? path : dpath, df, m.compressed ? avail : 0, 0,
                             m.dims, type_size, swap ? type_size : 0, box);
    } else {
        met_fill F = {ctx, func, local ? path : dpath, df, m.compressed, avail, m.type,
                      m.count, 0, type_size > 1 && (m.msb != 0) != umbra__host_is_big_endian(),
                      NULL};
        st = umbra__volume_from_fill(ctx, fill_met, &F, met_types[m.type].umbra, m.dims,
                                     m.spacing, m.placed ? m.origin : NULL,
                                     m.placed ? m.dirs : NULL, out);
    }

fail:
    free(dpath);
    free(text);
    if (df) {
        fclose(df);
    }
    if (f) {
        fclose(f);
    }
    if (c_locale != (locale_t)0) {
        freelocale(c_locale);
    }
    return st;
}
