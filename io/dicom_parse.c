// SPDX-License-Identifier: Apache-2.0
/* io/dicom_parse.c: umbra's own walk over a DICOM file's structure (PS3.5 chapter 7, PS3.10
 * chapter 7), bounded, so that no byte of an untrusted file reaches a parser that aborts on it
 * (io/dicom.cpp says why no DICOM library reads it).
 *
 * What is walked: the 128-byte preamble and "DICM"; the file meta group (explicit VR little
 * endian) for the transfer syntax; the data set in implicit or explicit VR little endian, its
 * sequences and items of defined or undefined length nested at most DICOM_MAX_DEPTH deep, every
 * element's value checked to lie inside its container and the file; encapsulated pixel data as
 * items of defined length up to the sequence delimiter. At most DICOM_MAX_ELEMENTS elements and
 * UMBRA__DICOM_MAX_FRAGMENTS fragments. Big-endian and deflated data sets (both retired or rare)
 * are refused as unsupported. The top-level attributes umbra uses are read with their VR checked
 * (explicit files) and their values parsed strictly; everything else is skipped by its length. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "dicom.h"

#define DICOM_MAX_DEPTH 16
#define DICOM_MAX_ELEMENTS (1ul << 22)
#define DICOM_VALUE_MAX 256
#define UNDEFINED 0xffffffffu

typedef struct walker {
    umbra_context ctx;
    const char *func, *path;
    FILE *f;
    uint64_t size;
    umbra__dicom_file *out;
    unsigned long elements;
    size_t fragment_capacity;
} walker;

typedef struct element {
    uint16_t group, elem;
    char vr[3];
    uint32_t length;
    uint64_t at, value; /* where the element and its value start */
} element;

static uint16_t u16(const unsigned char *b)
{
    return (uint16_t)(b[0] | b[1] << 8);
}

static uint32_t u32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static umbra_status overrun(walker *w, uint64_t at, const char *what, uint64_t need,
                            uint64_t end)
{
    return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                       "%s: \"%s\": %s at byte %llu needs %llu bytes, %llu remain in %s "
                       "(truncated or corrupt file?)",
                       w->func, w->path, what, (unsigned long long)at, (unsigned long long)need,
                       (unsigned long long)(end > at ? end - at : 0),
                       end == w->size ? "the file" : "its container");
}

static umbra_status read_at(walker *w, uint64_t pos, void *buf, size_t n)
{
    char text[256];
    if (pos > w->size || n > w->size - pos) {
        return overrun(w, pos, "a read", n, w->size);
    }
    if (fseeko(w->f, (off_t)pos, SEEK_SET) != 0 || fread(buf, 1, n, w->f) != n) {
        return umbra__fail(w->ctx, UMBRA_ERROR_IO, "%s: cannot read \"%s\" at byte %llu: %s",
                           w->func, w->path, (unsigned long long)pos,
                           umbra__errno_text(errno, text, sizeof text));
    }
    return UMBRA_SUCCESS;
}

static int is_vr(const char *vr)
{
    static const char *const known =
        "AE AS AT CS DA DS DT FL FD IS LO LT OB OD OF OL OV OW PN SH SL SQ SS ST SV TM UC UI UL "
        "UN UR US UT UV ";
    const char *p;
    for (p = known; *p; p += 3) {
        if (p[0] == vr[0] && p[1] == vr[1]) {
            return 1;
        }
    }
    return 0;
}

/* VRs whose length takes 4 bytes after 2 reserved ones (PS3.5 7.1.2). */
static int is_long_vr(const char *vr)
{
    static const char *const longs = "OB OD OF OL OV OW SQ SV UC UN UR UT UV ";
    const char *p;
    for (p = longs; *p; p += 3) {
        if (p[0] == vr[0] && p[1] == vr[1]) {
            return 1;
        }
    }
    return 0;
}

/* The element header at pos, inside [pos, end). Items and delimiters (group FFFE) have no VR. */
static umbra_status read_element(walker *w, uint64_t pos, uint64_t end, int explicit_vr,
                                 element *e)
{
    unsigned char b[12];
    umbra_status st;
    memset(e, 0, sizeof *e);
    e->at = pos;
    if (end < pos || end - pos < 8) {
        return overrun(w, pos, "an element header", 8, end);
    }
    if ((st = read_at(w, pos, b, 8)) != UMBRA_SUCCESS) {
        return st;
    }
    e->group = u16(b);
    e->elem = u16(b + 2);
    if (e->group == 0xfffe || !explicit_vr) {
        e->length = u32(b + 4);
        e->value = pos + 8;
        return UMBRA_SUCCESS;
    }
    e->vr[0] = (char)b[4];
    e->vr[1] = (char)b[5];
    if (!is_vr(e->vr)) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": element (%04X,%04X) at byte %llu has VR bytes %02X %02X, "
                           "not a DICOM VR",
                           w->func, w->path, e->group, e->elem, (unsigned long long)pos, b[4],
                           b[5]);
    }
    if (is_long_vr(e->vr)) {
        if (end - pos < 12) {
            return overrun(w, pos, "an element header", 12, end);
        }
        if ((st = read_at(w, pos + 8, b + 8, 4)) != UMBRA_SUCCESS) {
            return st;
        }
        e->length = u32(b + 8);
        e->value = pos + 12;
    } else {
        e->length = u16(b + 6);
        e->value = pos + 8;
    }
    return UMBRA_SUCCESS;
}

/* Strict DS/IS numbers: n values separated by '\', blanks around each. */
static int parse_numbers(const char *s, double *out, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        char *end = NULL;
        while (*s == ' ') {
            ++s;
        }
        if (*s == '\0' || *s == '\\') {
            return 0;
        }
        errno = 0;
        out[i] = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(out[i])) {
            return 0;
        }
        s = end;
        while (*s == ' ') {
            ++s;
        }
        if (i + 1 < n ? *s != '\\' : *s != '\0') {
            return 0;
        }
        ++s;
    }
    return 1;
}

/* The attributes umbra reads, with the VR each must have in an explicit-VR file. */
typedef enum kind { K_STRING, K_US, K_NUMBERS } kind;
typedef struct attribute {
    uint16_t group, elem;
    const char *vr, *name;
    kind kind;
    int count;
} attribute;

static const attribute attributes[] = {
    {0x0020, 0x000e, "UI", "SeriesInstanceUID", K_STRING, 0},
    {0x0028, 0x0004, "CS", "PhotometricInterpretation", K_STRING, 0},
    {0x0028, 0x0002, "US", "SamplesPerPixel", K_US, 1},
    {0x0028, 0x0010, "US", "Rows", K_US, 1},
    {0x0028, 0x0011, "US", "Columns", K_US, 1},
    {0x0028, 0x0100, "US", "BitsAllocated", K_US, 1},
    {0x0028, 0x0101, "US", "BitsStored", K_US, 1},
    {0x0028, 0x0102, "US", "HighBit", K_US, 1},
    {0x0028, 0x0103, "US", "PixelRepresentation", K_US, 1},
    {0x0028, 0x0008, "IS", "NumberOfFrames", K_NUMBERS, 1},
    {0x0020, 0x0032, "DS", "ImagePositionPatient", K_NUMBERS, 3},
    {0x0020, 0x0037, "DS", "ImageOrientationPatient", K_NUMBERS, 6},
    {0x0028, 0x0030, "DS", "PixelSpacing", K_NUMBERS, 2},
    {0x0028, 0x1052, "DS", "RescaleIntercept", K_NUMBERS, 1},
    {0x0028, 0x1053, "DS", "RescaleSlope", K_NUMBERS, 1},
    {0x0018, 0x0050, "DS", "SliceThickness", K_NUMBERS, 1},
};

static void store(umbra__dicom_file *d, const attribute *a, const char *text, unsigned us,
                  const double *num)
{
    switch (a->elem | (unsigned)a->group << 16) {
    case 0x0020000e: snprintf(d->series, sizeof d->series, "%s", text); break;
    case 0x00280004: snprintf(d->photometric, sizeof d->photometric, "%s", text); break;
    case 0x00280002: d->samples = us; break;
    case 0x00280010: d->rows = us, d->has_rows = 1; break;
    case 0x00280011: d->cols = us, d->has_cols = 1; break;
    case 0x00280100: d->bits_allocated = us, d->has_bits_allocated = 1; break;
    case 0x00280101: d->bits_stored = us, d->has_bits_stored = 1; break;
    case 0x00280102: d->high_bit = us, d->has_high_bit = 1; break;
    case 0x00280103: d->pixel_rep = us, d->has_pixel_rep = 1; break;
    case 0x00280008: d->frames = num[0] >= 1 && num[0] <= 65536 && num[0] == floor(num[0])
                                     ? (unsigned)num[0]
                                     : 0;
        break;
    case 0x00200032: memcpy(d->position, num, 3 * sizeof *num), d->has_position = 1; break;
    case 0x00200037: memcpy(d->orientation, num, 6 * sizeof *num), d->has_orientation = 1; break;
    case 0x00280030: memcpy(d->spacing, num, 2 * sizeof *num), d->has_spacing = 1; break;
    case 0x00281052: d->intercept = num[0]; break;
    case 0x00281053: d->slope = num[0]; break;
    case 0x00180050: d->thickness = num[0]; break;
    default: break;
    }
}

/* Reads a top-level element's value if umbra uses it. */
static umbra_status take_value(walker *w, const element *e, int explicit_vr)
{
    const attribute *a = NULL;
    char text[DICOM_VALUE_MAX + 1];
    unsigned char raw[DICOM_VALUE_MAX];
    double num[6] = {0, 0, 0, 0, 0, 0};
    size_t i, n;
    umbra_status st;
    if (e->group == 0x7fe0 && (e->elem == 0x0008 || e->elem == 0x0009)) {
        w->out->has_float_pixels = 1;
        return UMBRA_SUCCESS;
    }
    for (i = 0; i < sizeof attributes / sizeof attributes[0]; ++i) {
        if (attributes[i].group == e->group && attributes[i].elem == e->elem) {
            a = &attributes[i];
        }
    }
    if (!a) {
        return UMBRA_SUCCESS;
    }
    if (explicit_vr && strcmp(e->vr, a->vr) != 0 && strcmp(e->vr, "UN") != 0) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": %s (%04X,%04X) has VR %s, not %s", w->func, w->path,
                           a->name, a->group, a->elem, e->vr, a->vr);
    }
    if (e->length > DICOM_VALUE_MAX || (a->kind == K_US && e->length != 2)) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": %s (%04X,%04X) is %u bytes long (expected %s)", w->func,
                           w->path, a->name, a->group, a->elem, e->length,
                           a->kind == K_US ? "2" : "at most 256");
    }
    if ((st = read_at(w, e->value, raw, e->length)) != UMBRA_SUCCESS) {
        return st;
    }
    if (a->kind == K_US) {
        store(w->out, a, "", u16(raw), num);
        return UMBRA_SUCCESS;
    }
    n = e->length;
    while (n > 0 && (raw[n - 1] == ' ' || raw[n - 1] == '\0')) {
        --n;
    }
    for (i = 0; i < n; ++i) {
        if (raw[i] < 0x20 || raw[i] > 0x7e) {
            return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": %s (%04X,%04X) holds a byte 0x%02X that is not text",
                               w->func, w->path, a->name, a->group, a->elem, raw[i]);
        }
        text[i] = (char)raw[i];
    }
    text[n] = '\0';
    if (a->kind == K_NUMBERS && !parse_numbers(text, num, a->count)) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": %s (%04X,%04X) \"%.64s\" is not %d finite number%s",
                           w->func, w->path, a->name, a->group, a->elem, text, a->count,
                           a->count > 1 ? "s separated by '\\'" : "");
    }
    store(w->out, a, text, 0, num);
    return UMBRA_SUCCESS;
}

static umbra_status walk(walker *w, uint64_t pos, uint64_t end, int undefined, int explicit_vr,
                         int depth, uint64_t *after);

/* read_element for the next element of a data set or sequence, counted against the limit. */
static umbra_status next_element(walker *w, uint64_t pos, uint64_t end, int explicit_vr,
                                 element *e)
{
    if (++w->elements > DICOM_MAX_ELEMENTS) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": more than %lu elements",
                           w->func, w->path, DICOM_MAX_ELEMENTS);
    }
    return read_element(w, pos, end, explicit_vr, e);
}

/* Marks the (one) top-level pixel data element found. */
static umbra_status found_pixels(walker *w)
{
    if (w->out->has_pixels) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": two pixel data elements",
                           w->func, w->path);
    }
    w->out->has_pixels = 1;
    return UMBRA_SUCCESS;
}

/* The items of a sequence whose value starts at pos: to end (defined length), or to its
 * delimiter (undefined: end is the container's end). */
static umbra_status sequence(walker *w, uint64_t pos, uint64_t end, int undefined,
                             int explicit_vr, int depth, uint64_t *after)
{
    umbra_status st;
    if (depth > DICOM_MAX_DEPTH) {
        return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": sequences nested deeper than %d at byte %llu", w->func,
                           w->path, DICOM_MAX_DEPTH, (unsigned long long)pos);
    }
    for (;;) {
        element e;
        if (!undefined && pos == end) {
            *after = pos;
            return UMBRA_SUCCESS;
        }
        if ((st = next_element(w, pos, end, 0, &e)) != UMBRA_SUCCESS) {
            return st;
        }
        if (e.group == 0xfffe && e.elem == 0xe0dd && undefined) {
            *after = e.value;
            return UMBRA_SUCCESS;
        }
        if (e.group != 0xfffe || e.elem != 0xe000) {
            return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": (%04X,%04X) at byte %llu inside a sequence, where "
                               "an item (FFFE,E000) belongs",
                               w->func, w->path, e.group, e.elem, (unsigned long long)pos);
        }
        if (e.length == UNDEFINED) {
            st = walk(w, e.value, end, 1, explicit_vr, depth + 1, &pos);
        } else if (e.length > end - e.value) {
            return overrun(w, e.value, "an item", e.length, end);
        } else {
            st = walk(w, e.value, e.value + e.length, 0, explicit_vr, depth + 1, &pos);
        }
        if (st != UMBRA_SUCCESS) {
            return st;
        }
    }
}

/* Encapsulated pixel data from pos: the basic offset table, then the fragments, then the
 * sequence delimiter (PS3.5 A.4). */
static umbra_status fragments(walker *w, uint64_t pos, uint64_t *after)
{
    umbra__dicom_file *d = w->out;
    int first = 1;
    umbra_status st;
    for (;;) {
        element e;
        if ((st = read_element(w, pos, w->size, 0, &e)) != UMBRA_SUCCESS) {
            return st;
        }
        if (e.group == 0xfffe && e.elem == 0xe0dd) {
            *after = e.value;
            return UMBRA_SUCCESS;
        }
        if (e.group != 0xfffe || e.elem != 0xe000 || e.length == UNDEFINED) {
            return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": (%04X,%04X) at byte %llu in the encapsulated pixel "
                               "data, where a fragment item of defined length belongs",
                               w->func, w->path, e.group, e.elem, (unsigned long long)pos);
        }
        if (e.length > w->size - e.value) {
            return overrun(w, e.value, "a pixel data fragment", e.length, w->size);
        }
        if (!first) {
            if (d->fragments == UMBRA__DICOM_MAX_FRAGMENTS) {
                return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": more than %u pixel data fragments", w->func,
                                   w->path, UMBRA__DICOM_MAX_FRAGMENTS);
            }
            if (d->fragments == w->fragment_capacity) {
                size_t cap = w->fragment_capacity ? 2 * w->fragment_capacity : 16;
                uint64_t *o = realloc(d->fragment_offset, cap * sizeof *o);
                uint64_t *l = o ? realloc(d->fragment_length, cap * sizeof *l) : NULL;
                if (o) {
                    d->fragment_offset = o;
                }
                if (!l) {
                    return umbra__fail(w->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                       "%s: out of memory for %zu fragments", w->func, cap);
                }
                d->fragment_length = l;
                w->fragment_capacity = cap;
            }
            d->fragment_offset[d->fragments] = e.value;
            d->fragment_length[d->fragments] = e.length;
            ++d->fragments;
        }
        first = 0;
        pos = e.value + e.length;
    }
}

/* The elements of a data set from pos: to end, or with undefined to its item delimiter. */
static umbra_status walk(walker *w, uint64_t pos, uint64_t end, int undefined, int explicit_vr,
                         int depth, uint64_t *after)
{
    umbra_status st;
    for (;;) {
        element e;
        if (!undefined && pos == end) {
            *after = pos;
            return UMBRA_SUCCESS;
        }
        if ((st = next_element(w, pos, end, explicit_vr, &e)) != UMBRA_SUCCESS) {
            return st;
        }
        if (e.group == 0xfffe) {
            if (e.elem == 0xe00d && undefined && depth > 0) {
                *after = e.value;
                return UMBRA_SUCCESS;
            }
            return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": item tag (FFFE,%04X) at byte %llu outside a sequence",
                               w->func, w->path, e.elem, (unsigned long long)pos);
        }
        if (e.length == UNDEFINED) {
            if (depth == 0 && e.group == 0x7fe0 && e.elem == 0x0010) {
                w->out->pixels_fragmented = 1;
                if ((st = found_pixels(w)) == UMBRA_SUCCESS) {
                    st = fragments(w, e.value, &pos);
                }
            } else if (explicit_vr && strcmp(e.vr, "SQ") != 0 && strcmp(e.vr, "UN") != 0) {
                return umbra__fail(w->ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": element (%04X,%04X) of VR %s at byte %llu has "
                                   "undefined length",
                                   w->func, w->path, e.group, e.elem, e.vr,
                                   (unsigned long long)pos);
            } else {
                /* A sequence; UN of undefined length holds implicit VR (CP 246). */
                st = sequence(w, e.value, end, 1, explicit_vr && strcmp(e.vr, "SQ") == 0,
                              depth + 1, &pos);
            }
            if (st != UMBRA_SUCCESS) {
                return st;
            }
            continue;
        }
        if (e.length > end - e.value) {
            char what[64];
            snprintf(what, sizeof what, "the value of element (%04X,%04X)", e.group, e.elem);
            return overrun(w, e.value, what, e.length, end);
        }
        if (explicit_vr && strcmp(e.vr, "SQ") == 0) {
            uint64_t seq_end = 0;
            st = sequence(w, e.value, e.value + e.length, 0, 1, depth + 1, &seq_end);
        } else if (depth == 0 && e.group == 0x7fe0 && e.elem == 0x0010) {
            w->out->pixel_offset = e.value;
            w->out->pixel_length = e.length;
            st = found_pixels(w);
        } else {
            st = depth == 0 ? take_value(w, &e, explicit_vr) : UMBRA_SUCCESS;
        }
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        pos = e.value + e.length;
    }
}

void umbra__dicom_file_free(umbra__dicom_file *out)
{
    if (out) {
        free(out->fragment_offset);
        free(out->fragment_length);
        out->fragment_offset = out->fragment_length = NULL;
        out->fragments = 0;
    }
}

umbra_status umbra__dicom_parse(umbra_context ctx, const char *func, const char *path,
                                umbra__dicom_file *out)
{
    walker w;
    unsigned char head[132];
    uint64_t pos = 132, end = 0;
    size_t size = 0;
    umbra_status st;
    int explicit_vr;

    memset(out, 0, sizeof *out);
    out->samples = 1;
    out->frames = 1;
    out->slope = 1.0;
    memset(&w, 0, sizeof w);
    w.ctx = ctx;
    w.func = func;
    w.path = path;
    w.out = out;
    st = umbra__file_open(ctx, func, path, &w.f, &size);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    w.size = out->file_bytes = size;
    if (size < sizeof head || fread(head, 1, sizeof head, w.f) != sizeof head ||
        memcmp(head + 128, "DICM", 4) != 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" is not a DICOM file (no 128-byte preamble and \"DICM\"; "
                         "umbra reads DICOM Part 10 files)",
                         func, path);
        goto fail;
    }
    /* The file meta group, explicit VR little endian. */
    for (;;) {
        unsigned char g[2];
        element e;
        if (pos + 2 > size || (st = read_at(&w, pos, g, 2)) != UMBRA_SUCCESS || u16(g) != 2) {
            break;
        }
        if ((st = read_element(&w, pos, size, 1, &e)) != UMBRA_SUCCESS) {
            goto fail;
        }
        if (e.length == UNDEFINED || e.length > size - e.value) {
            st = overrun(&w, pos, "a file meta element", e.length, size);
            goto fail;
        }
        if (e.elem == 0x0010) {
            unsigned char raw[64];
            size_t n = e.length;
            if (n == 0 || n > sizeof raw) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": TransferSyntaxUID is %zu bytes long", func, path, n);
                goto fail;
            }
            if ((st = read_at(&w, e.value, raw, n)) != UMBRA_SUCCESS) {
                goto fail;
            }
            while (n > 0 && (raw[n - 1] == '\0' || raw[n - 1] == ' ')) {
                --n;
            }
            memcpy(out->syntax, raw, n);
            out->syntax[n] = '\0';
        }
        pos = e.value + e.length;
    }
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    if (out->syntax[0] == '\0') {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": the file meta group names no TransferSyntaxUID (0002,0010)",
                         func, path);
        goto fail;
    }
    if (strcmp(out->syntax, "1.2.840.10008.1.2.2") == 0 ||
        strcmp(out->syntax, "1.2.840.10008.1.2.1.99") == 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: \"%s\": transfer syntax %s (%s) is not supported", func, path,
                         out->syntax,
                         out->syntax[19] == '2' ? "explicit VR big endian, retired"
                                                : "deflated explicit VR little endian");
        goto fail;
    }
    explicit_vr = strcmp(out->syntax, "1.2.840.10008.1.2") != 0;
    out->encapsulated = explicit_vr && strcmp(out->syntax, "1.2.840.10008.1.2.1") != 0;
    st = walk(&w, pos, size, 0, explicit_vr, 0, &end);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    if (!out->has_pixels) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" has no pixel data (7FE0,0010)",
                         func, path);
        goto fail;
    }
    if (out->encapsulated != out->pixels_fragmented ||
        (out->encapsulated && out->fragments == 0)) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\": transfer syntax %s %s compressed, but the pixel data is %s",
                         func, path, out->syntax, out->encapsulated ? "is" : "is not",
                         out->encapsulated ? (out->pixels_fragmented ? "no fragments"
                                                                     : "not in fragments")
                                           : "in fragments");
        goto fail;
    }
    fclose(w.f);
    return UMBRA_SUCCESS;

fail:
    fclose(w.f);
    umbra__dicom_file_free(out);
    return st;
}
