// SPDX-License-Identifier: Apache-2.0
/* io/nifti.c: NIfTI-1 and NIfTI-2 volumes (.nii, .nii.gz).
 *
 * umbra reads the header itself, field by field, in either version and byte order, and reads the
 * voxels with zlib (which reads a plain file as it is), straight into the volume's buffer through
 * umbra_volume_create_filled, or a chunk at a time where they are converted. nifticlib (Debian's
 * libnifti2-dev) gives the quaternion-to-matrix formula and the datatype tables, and nothing of
 * it touches the file. Left to read the file, nifticlib "fixed" what it did not like: a NaN,
 * negative or huge vox_offset became 352 (a cast of NaN to int on the way), NaN and infinite
 * scl_slope, scl_inter, pixdim and quaternion values became 0 or 1, any magic "n+N" was read as
 * NIfTI, NaN and infinite float voxels became 0 (an all-NaN file rendered blank); and it printed
 * "** ERROR ..." to stderr from some paths whatever its debug level (a bad datatype or dim[1]).
 * So here every field umbra uses is checked, and refused with a message naming it and its value:
 *   - sizeof_hdr 348 (NIfTI-1) or 540 (NIfTI-2), in either byte order; magic exactly "n+1\0" or
 *     "n+2\0\r\n\032\n" (a .hdr/.img pair's "ni1" is unsupported);
 *   - dim[0] 1..7, x, y, z sizes of at least 1 and size 1 beyond them; a datatype umbra reads;
 *   - vox_offset a whole number of bytes past the header (352 or 544), with the voxels inside the
 *     file (for .nii.gz: within gzip's largest expansion, 1032:1, of the compressed size, so a
 *     300-byte file cannot ask for gigabytes);
 *   - scl_slope, scl_inter, pixdim[0..3], and with a qform or sform their numbers, finite;
 *   - every float voxel finite, after scaling.
 * The type mapping and scl_slope / scl_inter rule are those documented in umbra/io.h. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <nifti2_io.h>
#include <zlib.h>

#include "nifti.h"

/* deflate never expands a stream by more than this factor (zlib's technical notes). */
#define GZIP_MAX_RATIO 1032u
/* Voxels converted per step: 1 MiB of the widest NIfTI type umbra reads. */
#define CONVERT_CHUNK ((size_t)1 << 17)
/* Bytes read per gzread of voxels kept as they are (gzread counts in int). */
#define READ_CHUNK ((size_t)1 << 30)

void umbra__nifti_volume_free(umbra__nifti_volume *out)
{
    if (out) {
        free(out->voxels);
        out->voxels = NULL;
    }
}

/* ---- the header ---------------------------------------------------------------------------- */

/* What umbra takes from either version's header, in host byte order. */
typedef struct nifti_fields {
    int version;                /* 1 or 2 */
    int swap;                   /* the file's byte order is not the host's */
    int64_t dim[8];
    int datatype;
    double pixdim[8];
    int64_t vox_offset;
    double scl_slope, scl_inter;
    int qform_code, sform_code;
    double quatern[3], qoffset[3]; /* b, c, d; x, y, z */
    double srow[3][4];
} nifti_fields;

static void get_bytes(const unsigned char *b, size_t off, void *v, size_t n, int swap)
{
    memcpy(v, b + off, n);
    if (swap) {
        umbra__swap_bytes(v, 1, n);
    }
}

static int64_t get_int(const unsigned char *b, size_t off, size_t n, int swap)
{
    int16_t i16;
    int32_t i32;
    int64_t i64;
    switch (n) {
    case 2: get_bytes(b, off, &i16, 2, swap); return i16;
    case 4: get_bytes(b, off, &i32, 4, swap); return i32;
    default: get_bytes(b, off, &i64, 8, swap); return i64;
    }
}

static double get_real(const unsigned char *b, size_t off, size_t n, int swap)
{
    float f;
    double d;
    if (n == 4) {
        get_bytes(b, off, &f, 4, swap);
        return f;
    }
    get_bytes(b, off, &d, 8, swap);
    return d;
}

/* The magic's bytes for a message: printable ones as they are, others as \xNN. */
static const char *quote_magic(const unsigned char *m, size_t n, char *buf)
{
    char *p = buf;
    for (size_t i = 0; i < n; ++i) {
        p += m[i] >= 0x20 && m[i] < 0x7f && m[i] != '"' && m[i] != '\\'
                 ? sprintf(p, "%c", m[i])
                 : sprintf(p, "\\x%02x", m[i]);
    }
    return buf;
}

/* The fields of either version, from offsetof in nifticlib's own struct definitions. */
#define FIELD(h, name) offsetof(h, name), sizeof(((h *)0)->name)
#define READ_FIELDS(h, real, integer)                                                             \
    do {                                                                                          \
        for (int i = 0; i < 8; ++i) {                                                             \
            f->dim[i] = get_int(b, offsetof(h, dim) + (size_t)i * (integer), integer, sw);        \
            f->pixdim[i] = get_real(b, offsetof(h, pixdim) + (size_t)i * (real), real, sw);      \
        }                                                                                         \
        f->datatype = (int)get_int(b, FIELD(h, datatype), sw);                                    \
        f->scl_slope = get_real(b, FIELD(h, scl_slope), sw);                                      \
        f->scl_inter = get_real(b, FIELD(h, scl_inter), sw);                                      \
        f->qform_code = (int)get_int(b, FIELD(h, qform_code), sw);                                \
        f->sform_code = (int)get_int(b, FIELD(h, sform_code), sw);                                \
        f->quatern[0] = get_real(b, FIELD(h, quatern_b), sw);                                     \
        f->quatern[1] = get_real(b, FIELD(h, quatern_c), sw);                                     \
        f->quatern[2] = get_real(b, FIELD(h, quatern_d), sw);                                     \
        f->qoffset[0] = get_real(b, FIELD(h, qoffset_x), sw);                                     \
        f->qoffset[1] = get_real(b, FIELD(h, qoffset_y), sw);                                     \
        f->qoffset[2] = get_real(b, FIELD(h, qoffset_z), sw);                                     \
        for (int k = 0; k < 4; ++k) {                                                             \
            f->srow[0][k] = get_real(b, offsetof(h, srow_x) + (size_t)k * (real), real, sw);     \
            f->srow[1][k] = get_real(b, offsetof(h, srow_y) + (size_t)k * (real), real, sw);     \
            f->srow[2][k] = get_real(b, offsetof(h, srow_z) + (size_t)k * (real), real, sw);     \
        }                                                                                         \
    } while (0)

/* Reads the fields from the first got bytes of the file (decompressed) and checks the version,
 * byte order, magic, offsets and every real number umbra uses. */
static umbra_status parse_fields(umbra_context ctx, const char *func, const char *path,
                                 const unsigned char *b, size_t got, nifti_fields *f)
{
    static const unsigned char magic2[8] = {'n', '+', '2', '\0', '\r', '\n', '\032', '\n'};
    const size_t n1 = sizeof(nifti_1_header), n2 = sizeof(nifti_2_header);
    char quoted[40];
    int32_t size_raw, size_swapped;
    int sw;

    memset(f, 0, sizeof *f);
    if (got < n1) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" is not a NIfTI-1/2 file: it holds %zu bytes, too few for a "
                           "header (%zu bytes for NIfTI-1, %zu for NIfTI-2)",
                           func, path, got, n1, n2);
    }
    memcpy(&size_raw, b, 4);
    size_swapped = size_raw;
    umbra__swap_bytes(&size_swapped, 1, 4);
    if (size_raw == (int32_t)n1 || size_swapped == (int32_t)n1) {
        f->version = 1;
    } else if (size_raw == (int32_t)n2 || size_swapped == (int32_t)n2) {
        f->version = 2;
    } else {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" is not a NIfTI-1/2 file: sizeof_hdr %d is neither %zu "
                           "(NIfTI-1) nor %zu (NIfTI-2), in either byte order",
                           func, path, (int)size_raw, n1, n2);
    }
    sw = f->swap = size_raw != (int32_t)(f->version == 1 ? n1 : n2);
    if (f->version == 2 && got < n2) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" holds %zu bytes, too few for its NIfTI-2 header (%zu)", func,
                           path, got, n2);
    }
    {
        /* A pair's "ni1" / "ni2", or anything but the single-file magic, is not read. */
        const unsigned char *m = b + (f->version == 1 ? offsetof(nifti_1_header, magic)
                                                      : offsetof(nifti_2_header, magic));
        const unsigned char *want = f->version == 1 ? (const unsigned char *)"n+1" : magic2;
        const size_t want_n = f->version == 1 ? 4 : 8;
        char wanted[40];
        if (m[0] == 'n' && m[1] == 'i' && m[2] == "12"[f->version - 1] && m[3] == '\0') {
            return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: \"%s\": magic \"ni%d\": the voxels are in a separate .img "
                               "file (.hdr/.img pairs, ANALYZE and ASCII NIfTI are not supported)",
                               func, path, f->version);
        }
        if (memcmp(m, want, want_n) != 0) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": magic \"%s\" is not NIfTI-%d's \"%s\" (a %zu-byte "
                               "header that is not single-file NIfTI-%d is not read)",
                               func, path, quote_magic(m, want_n, quoted), f->version,
                               quote_magic(want, want_n, wanted), f->version == 1 ? n1 : n2,
                               f->version);
        }
    }
    if (f->version == 1) {
        READ_FIELDS(nifti_1_header, 4, 2);
        {
            float off = (float)get_real(b, FIELD(nifti_1_header, vox_offset), sw);
            /* Checked as a float: a cast of NaN or of 1e20 to an integer is undefined. */
            if (!(off >= (float)n1 + 4.0f) || off > 4.0e18f || off != floorf(off)) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": vox_offset %g is not a whole number of bytes of at "
                                   "least %zu (the header and its extension flags)",
                                   func, path, (double)off, n1 + 4);
            }
            f->vox_offset = (int64_t)off;
        }
    } else {
        READ_FIELDS(nifti_2_header, 8, 8);
        f->vox_offset = get_int(b, FIELD(nifti_2_header, vox_offset), sw);
        if (f->vox_offset < (int64_t)n2 + 4) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": vox_offset %lld is less than %zu (the header and its "
                               "extension flags)",
                               func, path, (long long)f->vox_offset, n2 + 4);
        }
    }

    /* Real numbers: a NaN or infinity is refused, not read as 0 or 1. */
    if (!isfinite(f->scl_slope) || !isfinite(f->scl_inter)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": scl_slope %g or scl_inter %g is not finite", func, path,
                           f->scl_slope, f->scl_inter);
    }
    for (int i = 0; i <= 3; ++i) {
        if (!isfinite(f->pixdim[i])) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\": pixdim[%d] %g is not finite", func, path, i,
                               f->pixdim[i]);
        }
    }
    if (f->qform_code > 0) {
        static const char *const names[6] = {"quatern_b", "quatern_c", "quatern_d",
                                             "qoffset_x", "qoffset_y", "qoffset_z"};
        for (int i = 0; i < 6; ++i) {
            double v = i < 3 ? f->quatern[i] : f->qoffset[i - 3];
            if (!isfinite(v)) {
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": %s %g is not finite (qform_code %d)", func, path,
                                   names[i], v, f->qform_code);
            }
        }
    }
    if (f->sform_code > 0) {
        for (int r = 0; r < 3; ++r) {
            for (int k = 0; k < 4; ++k) {
                if (!isfinite(f->srow[r][k])) {
                    return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                       "%s: \"%s\": srow_%c[%d] %g is not finite (sform_code %d)",
                                       func, path, "xyz"[r], k, f->srow[r][k], f->sform_code);
                }
            }
        }
    }
    return UMBRA_SUCCESS;
}

/* ---- reading --------------------------------------------------------------------------------- */

/* Converts count voxels of nifti datatype dt in src to umbra's type, applying slope and inter
 * when scale is set. Returns the index of the first whose value is not a finite float (its
 * source value in *bad), or count. */
static size_t convert(const void *src, int dt, size_t count, int scale, double slope, double inter,
                      umbra_scalar_type type, void *dst, double *bad)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        double v;
        switch (dt) {
        case DT_INT8: v = ((const int8_t *)src)[i]; break;
        case DT_UINT8: v = ((const uint8_t *)src)[i]; break;
        case DT_INT16: v = ((const int16_t *)src)[i]; break;
        case DT_UINT16: v = ((const uint16_t *)src)[i]; break;
        case DT_INT32: v = ((const int32_t *)src)[i]; break;
        case DT_UINT32: v = ((const uint32_t *)src)[i]; break;
        case DT_INT64: v = (double)((const int64_t *)src)[i]; break;
        case DT_UINT64: v = (double)((const uint64_t *)src)[i]; break;
        case DT_FLOAT32: v = ((const float *)src)[i]; break;
        default: v = ((const double *)src)[i]; break; /* DT_FLOAT64 */
        }
        *bad = v;
        if (scale) {
            v = slope * v + inter;
        }
        if (type == UMBRA_INT16) {
            ((int16_t *)dst)[i] = (int16_t)v; /* only int8 lands here: exact */
        } else {
            float f = (float)v;
            if (!isfinite(f)) {
                return i;
            }
            ((float *)dst)[i] = f;
        }
    }
    return count;
}

/* What the fill callback reads: the open file, where its voxels are and what they become. */
typedef struct nifti_fill {
    umbra_context ctx;
    const char *func, *path;
    gzFile gz;                  /* the file (zlib reads a plain one as it is) */
    int64_t vox_offset;
    int datatype, nbyper, swap;
    uint32_t dims[3];
    size_t count, data_bytes;
    umbra_scalar_type type;
    int scale;
    double slope, inter;
} nifti_fill;

static void nifti_fill_close(nifti_fill *F)
{
    if (F->gz) {
        gzclose(F->gz);
        F->gz = NULL;
    }
}

/* Reads n bytes of F's file into dst. */
static int read_exactly(nifti_fill *F, void *dst, size_t n)
{
    unsigned char *p = dst;
    while (n > 0) {
        unsigned want = (unsigned)(n < READ_CHUNK ? n : READ_CHUNK);
        int got = gzread(F->gz, p, want);
        if (got != (int)want) {
            return 0;
        }
        p += want;
        n -= want;
    }
    return 1;
}

/* Opens path (a regular file, never blocking on a FIFO), reads and checks its header into *out
 * (everything but the voxels) and *F, which holds the open file. On failure nothing is left
 * open; on success the caller closes F with nifti_fill_close. */
static umbra_status nifti_header(umbra_context ctx, const char *func, const char *path,
                                 umbra__nifti_volume *out, nifti_fill *F)
{
    umbra_status st = UMBRA_SUCCESS;
    unsigned char head[sizeof(nifti_2_header)], magic[2] = {0, 0};
    nifti_fields h;
    FILE *f = NULL;
    size_t file_size = 0, count = 1, data_bytes, got;
    umbra_scalar_type type;
    int gz, scale, fd, r, c, nbyper = 0, swapsize = 0, read_n;
    double slope, inter;

    memset(out, 0, sizeof *out);
    memset(F, 0, sizeof *F);
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", func);
    }
    st = umbra__file_open(ctx, func, path, &f, &file_size);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    fd = dup(fileno(f));
    gz = pread(fileno(f), magic, 2, 0) == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
    fclose(f);
    if (fd < 0 || lseek(fd, 0, SEEK_SET) != 0 || !(F->gz = gzdopen(fd, "rb"))) {
        char ebuf[256];
        int err = errno;
        if (fd >= 0) {
            close(fd);
        }
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot read \"%s\": %s", func, path,
                           umbra__errno_text(err, ebuf, sizeof ebuf));
    }
    gzbuffer(F->gz, 1u << 17);
    read_n = gzread(F->gz, head, sizeof head);
    got = read_n > 0 ? (size_t)read_n : 0;
    st = parse_fields(ctx, func, path, head, got, &h);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }

    /* Dimensions: x, y, z of at least 1, everything past z of size 1. */
    for (int i = 1; i <= 7; ++i) {
        int64_t n = i <= h.dim[0] ? h.dim[i] : 1;
        if (h.dim[0] < 1 || h.dim[0] > 7 || n < 1 || (i > 3 && n != 1) ||
            n > (int64_t)UINT32_MAX) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": dim %d (of %lld) is %lld; a volume needs x, y, z "
                             "sizes of 1..%u and size 1 beyond them",
                             func, path, i, (long long)h.dim[0], (long long)n, UINT32_MAX);
            goto fail;
        }
        if (i <= 3) {
            if (count > SIZE_MAX / (size_t)n) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %lld x %lld x %lld voxels "
                                 "are too many", func, path, (long long)h.dim[1],
                                 (long long)h.dim[2], (long long)h.dim[3]);
                goto fail;
            }
            count *= (size_t)n;
            out->dims[i - 1] = (uint32_t)n;
        }
    }

    switch (h.datatype) {
    case DT_UINT8: type = UMBRA_UINT8; break;
    case DT_UINT16: type = UMBRA_UINT16; break;
    case DT_INT16: type = UMBRA_INT16; break;
    case DT_FLOAT32: type = UMBRA_FLOAT32; break;
    case DT_INT8: type = UMBRA_INT16; break;
    case DT_INT32:
    case DT_UINT32:
    case DT_INT64:
    case DT_UINT64:
    case DT_FLOAT64: type = UMBRA_FLOAT32; break;
    default:
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: \"%s\" has datatype %s (%d); supported are uint8, int8, uint16, "
                         "int16, uint32, int32, uint64, int64, float32 and float64",
                         func, path, nifti_datatype_string(h.datatype), h.datatype);
        goto fail;
    }
    nifti_datatype_sizes(h.datatype, &nbyper, &swapsize);
    if (nbyper < 1 || count > SIZE_MAX / (size_t)nbyper) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %zu voxels of %d bytes: too large",
                         func, path, count, nbyper);
        goto fail;
    }
    data_bytes = count * (size_t)nbyper;
    if ((uint64_t)h.vox_offset > SIZE_MAX - data_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": vox_offset %lld is past any file",
                         func, path, (long long)h.vox_offset);
        goto fail;
    }
    if (!gz && (uintmax_t)file_size < (uintmax_t)h.vox_offset + data_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu bytes; its header claims %lld + %zu (vox_offset + "
                         "%u x %u x %u voxels of %d bytes)",
                         func, path, file_size, (long long)h.vox_offset, data_bytes, out->dims[0],
                         out->dims[1], out->dims[2], nbyper);
        goto fail;
    }
    if (gz && ((uintmax_t)h.vox_offset + data_bytes) / GZIP_MAX_RATIO > (uintmax_t)file_size) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu compressed bytes, too few for the %lld + %zu its "
                         "header claims (gzip expands at most %ux)",
                         func, path, file_size, (long long)h.vox_offset, data_bytes,
                         GZIP_MAX_RATIO);
        goto fail;
    }

    /* The index-to-world matrix and, from its columns, the spacing. A pixdim of 0 is read as 1,
     * as nifticlib does (and its quaternion formula reads any pixdim <= 0 as 1). */
    if (h.sform_code > 0) {
        out->transform = UMBRA__NIFTI_SFORM;
        for (r = 0; r < 3; ++r) {
            for (c = 0; c < 4; ++c) {
                out->index_to_world[r][c] = h.srow[r][c];
            }
        }
        out->index_to_world[3][3] = 1.0;
    } else if (h.qform_code > 0) {
        double d[3];
        for (c = 0; c < 3; ++c) {
            d[c] = h.pixdim[c + 1] != 0.0 ? h.pixdim[c + 1] : 1.0;
        }
        nifti_dmat44 q = nifti_quatern_to_dmat44(h.quatern[0], h.quatern[1], h.quatern[2],
                                                 h.qoffset[0], h.qoffset[1], h.qoffset[2], d[0],
                                                 d[1], d[2], h.pixdim[0] < 0.0 ? -1.0 : 1.0);
        out->transform = UMBRA__NIFTI_QFORM;
        for (r = 0; r < 4; ++r) {
            for (c = 0; c < 4; ++c) {
                out->index_to_world[r][c] = q.m[r][c];
            }
        }
    } else {
        out->transform = UMBRA__NIFTI_PIXDIM;
        for (c = 0; c < 3; ++c) {
            double d = fabs(h.pixdim[c + 1]);
            out->index_to_world[c][c] = d > 0.0 ? d : 1.0;
        }
        out->index_to_world[3][3] = 1.0;
    }
    for (c = 0; c < 3; ++c) {
        double len = sqrt(out->index_to_world[0][c] * out->index_to_world[0][c] +
                          out->index_to_world[1][c] * out->index_to_world[1][c] +
                          out->index_to_world[2][c] * out->index_to_world[2][c]);
        float fl = (float)len;
        if (!(len > 0.0) || !isfinite(fl)) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": index axis %d has spacing %g under the %s; it must be "
                             "finite and > 0",
                             func, path, c, len,
                             out->transform == UMBRA__NIFTI_SFORM   ? "sform"
                             : out->transform == UMBRA__NIFTI_QFORM ? "qform"
                                                                    : "pixdim");
            goto fail;
        }
        out->spacing[c] = fl;
    }

    /* NIfTI: a slope of 0 means no scaling. */
    slope = h.scl_slope;
    inter = h.scl_inter;
    scale = slope != 0.0 && !(slope == 1.0 && inter == 0.0);
    if (scale) {
        type = UMBRA_FLOAT32;
    } else {
        slope = 1.0;
        inter = 0.0;
    }
    out->slope = slope;
    out->inter = inter;
    out->type = type;

    F->ctx = ctx;
    F->func = func;
    F->path = path;
    F->vox_offset = h.vox_offset;
    F->datatype = h.datatype;
    F->nbyper = nbyper;
    F->swap = h.swap && nbyper > 1;
    memcpy(F->dims, out->dims, sizeof F->dims);
    F->count = count;
    F->data_bytes = data_bytes;
    F->type = type;
    F->scale = scale;
    F->slope = slope;
    F->inter = inter;
    return UMBRA_SUCCESS;

fail:
    nifti_fill_close(F);
    return st;
}

/* umbra_volume_fill_fn: reads the voxels at vox_offset into dst, which holds F->count voxels of
 * F->type, swapping their bytes where the file's order is not the host's. A file type umbra keeps
 * as it is lands in dst directly (float32 then checked for NaN and infinity); one converted
 * (scl_slope, int8, 32- and 64-bit types) is read a chunk at a time and converted into dst, so
 * no second full-size copy exists. */
static umbra_status fill_nifti(void *user, void *dst, size_t bytes)
{
    nifti_fill *F = user;
    size_t out_size = umbra_scalar_type_size(F->type), done = 0, bad_at = F->count;
    size_t in_size = (size_t)F->nbyper;
    unsigned char *chunk = NULL;
    double bad_value = 0.0;
    int keep = !F->scale && ((F->datatype == DT_UINT8 && F->type == UMBRA_UINT8) ||
                             (F->datatype == DT_UINT16 && F->type == UMBRA_UINT16) ||
                             (F->datatype == DT_INT16 && F->type == UMBRA_INT16) ||
                             (F->datatype == DT_FLOAT32 && F->type == UMBRA_FLOAT32));

    if (bytes != F->count * out_size) {
        return umbra__fail(F->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: \"%s\": the fill buffer holds %zu bytes, not the %zu of %zu voxels",
                           F->func, F->path, bytes, F->count * out_size, F->count);
    }
    if (gzseek(F->gz, (z_off_t)F->vox_offset, SEEK_SET) != (z_off_t)F->vox_offset) {
        goto short_data;
    }
    if (keep) {
        if (!read_exactly(F, dst, F->data_bytes)) {
            goto short_data;
        }
        if (F->swap) {
            umbra__swap_bytes(dst, F->count, in_size);
        }
        if (F->datatype == DT_FLOAT32) {
            const float *v = dst;
            for (size_t i = 0; i < F->count && bad_at == F->count; ++i) {
                if (!isfinite(v[i])) {
                    bad_at = i;
                    bad_value = v[i];
                }
            }
        }
    } else {
        chunk = malloc(CONVERT_CHUNK * in_size);
        if (!chunk) {
            return umbra__fail(F->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: cannot allocate %zu bytes to convert the voxels of \"%s\"",
                               F->func, CONVERT_CHUNK * in_size, F->path);
        }
        while (done < F->count && bad_at == F->count) {
            size_t n = F->count - done < CONVERT_CHUNK ? F->count - done : CONVERT_CHUNK, at;
            if (!read_exactly(F, chunk, n * in_size)) {
                free(chunk);
                goto short_data;
            }
            if (F->swap) {
                umbra__swap_bytes(chunk, n, in_size);
            }
            at = convert(chunk, F->datatype, n, F->scale, F->slope, F->inter, F->type,
                         (unsigned char *)dst + done * out_size, &bad_value);
            if (at < n) {
                bad_at = done + at;
            }
            done += n;
        }
        free(chunk);
    }
    if (bad_at < F->count) {
        const size_t nx = F->dims[0], ny = F->dims[1];
        char scaling[96] = "";
        if (F->scale) {
            snprintf(scaling, sizeof scaling, ", times scl_slope %g plus scl_inter %g", F->slope,
                     F->inter);
        }
        return umbra__fail(F->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": voxel %zu (x %zu, y %zu, z %zu) is %g (%s%s): not a finite "
                           "float32; voxels must be finite",
                           F->func, F->path, bad_at, bad_at % nx, bad_at / nx % ny,
                           bad_at / (nx * ny), bad_value, nifti_datatype_string(F->datatype),
                           scaling);
    }
    return UMBRA_SUCCESS;

short_data:
    return umbra__fail(F->ctx, UMBRA_ERROR_FORMAT,
                       "%s: \"%s\": cannot read its %zu bytes of voxels (truncated or corrupt "
                       "data)",
                       F->func, F->path, F->data_bytes);
}

umbra_status umbra__nifti_read(umbra_context ctx, const char *func, const char *path,
                               umbra__nifti_volume *out)
{
    nifti_fill F;
    umbra_status st = nifti_header(ctx, func, path, out, &F);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    out->voxels = malloc(F.count * umbra_scalar_type_size(F.type));
    if (!out->voxels) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "%s: cannot allocate %zu voxels for \"%s\"", func, F.count, path);
    } else {
        st = fill_nifti(&F, out->voxels, F.count * umbra_scalar_type_size(F.type));
    }
    nifti_fill_close(&F);
    if (st != UMBRA_SUCCESS) {
        umbra__nifti_volume_free(out);
    }
    return st;
}

/* The file's world as the volume's: origin = the last column, index axis a's direction = column
 * a over its length; 0 when the header places nothing (the box stays centred). */
static int nifti_placement(const umbra__nifti_volume *nv, float origin[3], float directions[9])
{
    for (int r = 0; r < 3; ++r) {
        origin[r] = (float)nv->index_to_world[r][3];
        for (int a = 0; a < 3; ++a)
            directions[3 * a + r] = (float)(nv->index_to_world[r][a] / nv->spacing[a]);
    }
    return nv->transform != UMBRA__NIFTI_PIXDIM;
}

umbra_status umbra__nifti_read_box(umbra_context ctx, const char *path, const umbra__box *box)
{
    const char *func = "umbra_volume_read_box";
    umbra__nifti_volume nv;
    nifti_fill F;
    float origin[3], directions[9];
    unsigned char *row = NULL, *dst = NULL;
    umbra_status st = nifti_header(ctx, func, path, &nv, &F);
    if (st != UMBRA_SUCCESS)
        return st;
    int placed = nifti_placement(&nv, origin, directions);
    st = umbra__box_info(ctx, func, box, nv.type, nv.dims, nv.spacing, placed ? origin : NULL,
                         placed ? directions : NULL, 1);
    if (st != UMBRA_SUCCESS || umbra__box_header_only(box))
        goto done;
    {
        const umbra_volume_box_desc *d = box->desc;
        const size_t in_size = (size_t)F.nbyper, out_size = umbra_scalar_type_size(F.type);
        const size_t n = d->size[0], rows = (size_t)d->size[1] * d->size[2];
        double bad_value = 0.0;
        int finite = 1;
        const int keep = !F.scale && ((F.datatype == DT_UINT8 && F.type == UMBRA_UINT8) ||
                                      (F.datatype == DT_UINT16 && F.type == UMBRA_UINT16) ||
                                      (F.datatype == DT_INT16 && F.type == UMBRA_INT16) ||
                                      (F.datatype == DT_FLOAT32 && F.type == UMBRA_FLOAT32));
        row = malloc(n * in_size);
        dst = malloc(n * rows * out_size);
        if (!row || !dst) {
            st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "%s: cannot allocate a box of %zu voxels of \"%s\"", func, n * rows,
                             path);
            goto done;
        }
        /* Rows in file order, so gzseek only moves forward (inflating what lies between). */
        for (size_t r = 0; r < rows; ++r) {
            uint64_t y = d->origin[1] + r % d->size[1], z = d->origin[2] + r / d->size[1];
            uint64_t at = (uint64_t)F.vox_offset +
                          ((z * nv.dims[1] + y) * nv.dims[0] + d->origin[0]) * in_size;
            if (gzseek(F.gz, (z_off_t)at, SEEK_SET) != (z_off_t)at || !read_exactly(&F, row,
                                                                                 n * in_size)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": cannot read its %zu bytes of voxels (truncated or "
                                 "corrupt data)",
                                 func, path, F.data_bytes);
                goto done;
            }
            if (F.swap)
                umbra__swap_bytes(row, n, in_size);
            if (keep) {
                memcpy(dst + r * n * out_size, row, n * in_size);
                for (size_t i = 0; F.datatype == DT_FLOAT32 && i < n && finite; ++i) {
                    float v = ((const float *)row)[i];
                    if (!isfinite(v)) {
                        finite = 0;
                        bad_value = v;
                    }
                }
            }
            if (keep ? !finite : convert(row, F.datatype, n, F.scale, F.slope, F.inter, F.type,
                                      dst + r * n * out_size, &bad_value) < n) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": a voxel of row y %llu, z %llu is %g: not a finite "
                                 "float32; voxels must be finite",
                                 func, path, (unsigned long long)y, (unsigned long long)z,
                                 bad_value);
                goto done;
            }
        }
        *box->voxels = dst;
        dst = NULL;
    }
done:
    free(row);
    free(dst);
    nifti_fill_close(&F);
    return st;
}

umbra_status umbra_volume_load_nifti(umbra_context ctx, const char *path, umbra_volume *out)
{
    umbra__nifti_volume nv;
    nifti_fill F;
    float origin[3], directions[9];
    umbra_status st;

    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", __func__);
    }
    st = nifti_header(ctx, __func__, path, &nv, &F);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    /* The file's world (RAS+ by NIfTI's convention) becomes the volume's. A header with
     * neither sform nor qform places nothing, and the box stays centred. */
    int placed = nifti_placement(&nv, origin, directions);
    /* The voxels go straight into the volume's buffer (umbra_volume_create_filled). */
    st = umbra__volume_from_fill(ctx, fill_nifti, &F, nv.type, nv.dims, nv.spacing,
                                 placed ? origin : NULL, placed ? directions : NULL, out);
    nifti_fill_close(&F);
    return st;
}
