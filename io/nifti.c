// SPDX-License-Identifier: Apache-2.0
/* io/nifti.c: NIfTI-1 and NIfTI-2 volumes through nifticlib (Debian's libnifti2-dev).
 *
 * nifticlib parses the header (either version, byte order, gzip through its znzlib) and reads the
 * voxels (nifti_read_buffer, straight into the volume's buffer through umbra_volume_create_filled,
 * or a chunk at a time where they are converted); this file decides what umbra accepts: single-file .nii / .nii.gz only, three dimensions
 * (higher ones of size 1), the type mapping and scl_slope/scl_inter rule documented in
 * umbra/io.h, and the header's claimed size checked against the file before any voxel buffer is
 * allocated. A gzip file's uncompressed size is not known before decompressing it, so there the
 * claim is bounded by deflate's largest possible ratio (1032:1) over the compressed size, which
 * keeps a 300-byte file from asking for gigabytes.
 *
 * nifticlib prints its complaints to stderr unless its process-wide debug level is 0, and has no
 * getter for it: every nifticlib call runs under one lock with the level at 0, set back to the
 * library's default (1) afterwards. Its messages are therefore lost; the checks here name what is
 * wrong themselves. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <nifti2_io.h>

#include "nifti.h"

/* deflate never expands a stream by more than this factor (zlib's technical notes). */
#define GZIP_MAX_RATIO 1032u
#define NIFTI_DEFAULT_DEBUG 1

/* The one lock for nifticlib's global options (debug level). */
static pthread_mutex_t nifti_lock = PTHREAD_MUTEX_INITIALIZER;

void umbra__nifti_volume_free(umbra__nifti_volume *out)
{
    if (out) {
        free(out->voxels);
        out->voxels = NULL;
    }
}

/* Column c of a 4x4 as a length. */
static double column_length(double m[4][4], int c)
{
    return sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
}

/* Converts count voxels of nifti datatype dt in src to umbra's type, applying slope and inter
 * when scale is set. Returns 0 if a converted value is not a finite float. */
static int convert(const void *src, int dt, size_t count, int scale, double slope, double inter,
                   umbra_scalar_type type, void *dst)
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
        if (scale) {
            v = slope * v + inter;
        }
        if (type == UMBRA_INT16) {
            ((int16_t *)dst)[i] = (int16_t)v; /* only int8 lands here: exact */
        } else {
            float f = (float)v;
            if (!isfinite(f)) {
                return 0;
            }
            ((float *)dst)[i] = f;
        }
    }
    return 1;
}

/* The gzip magic at the start of path (1), plain (0), or unreadable (-1). */
static int is_gzip(const char *path)
{
    unsigned char magic[2] = {0, 0};
    FILE *f = fopen(path, "rb");
    size_t got;
    if (!f) {
        return -1;
    }
    got = fread(magic, 1, 2, f);
    fclose(f);
    return got == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
}

/* What the fill callback reads: the header nifticlib parsed and what was decided from it. */
typedef struct nifti_fill {
    umbra_context ctx;
    const char *func, *path;
    nifti_image *nim;
    size_t count, data_bytes;
    umbra_scalar_type type;
    int scale;
    double slope, inter;
} nifti_fill;

/* Reads and checks path's header into *out (everything but the voxels) and *F. On failure
 * nothing is left to free; on success F->nim is the caller's to nifti_image_free. */
static umbra_status nifti_header(umbra_context ctx, const char *func, const char *path,
                                 umbra__nifti_volume *out, nifti_fill *F)
{
    umbra_status st = UMBRA_SUCCESS;
    nifti_image *nim = NULL;
    struct stat sb;
    size_t count = 1, data_bytes, i;
    umbra_scalar_type type;
    int gz, scale, r, c;
    double slope, inter;
    char ebuf[256];

    memset(out, 0, sizeof *out);
    memset(F, 0, sizeof *F);
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", func);
    }
    /* Refuse what is not a regular file before nifticlib opens it (a FIFO would block). */
    if (stat(path, &sb) != 0) {
        int err = errno;
        if (strerror_r(err, ebuf, sizeof ebuf) != 0) {
            snprintf(ebuf, sizeof ebuf, "error %d", err);
        }
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot open \"%s\": %s", func, path, ebuf);
    }
    if (!S_ISREG(sb.st_mode)) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: \"%s\" is not a regular file", func, path);
    }
    gz = is_gzip(path);
    if (gz < 0) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot open \"%s\"", func, path);
    }

    pthread_mutex_lock(&nifti_lock);
    nifti_set_debug_level(0);
    nim = nifti_image_read(path, 0);
    nifti_set_debug_level(NIFTI_DEFAULT_DEBUG);
    pthread_mutex_unlock(&nifti_lock);
    if (!nim) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" is not a NIfTI-1/2 file nifticlib can read (bad magic, "
                           "sizeof_hdr, dimensions or extension; or truncated)",
                           func, path);
    }
    if (nim->nifti_type != NIFTI_FTYPE_NIFTI1_1 && nim->nifti_type != NIFTI_FTYPE_NIFTI2_1) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: \"%s\" is not a single-file NIfTI (nifti_type %d: ANALYZE, .hdr/.img "
                         "pairs and ASCII NIfTI are not supported)",
                         func, path, nim->nifti_type);
        goto fail;
    }
    if (!nim->iname || !nim->fname || strcmp(nim->iname, nim->fname) != 0) {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: \"%s\": the voxels are in another file (\"%s\")", func, path,
                         nim->iname ? nim->iname : "");
        goto fail;
    }

    /* Dimensions: x, y, z of at least 1, everything past z of size 1. */
    for (i = 1; i <= 7; ++i) {
        int64_t n = i <= (size_t)nim->dim[0] ? nim->dim[i] : 1;
        if (nim->dim[0] < 1 || nim->dim[0] > 7 || n < 1 || (i > 3 && n != 1) ||
            n > (int64_t)UINT32_MAX) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": dim %lld (of %lld) is %lld; a volume needs x, y, z "
                             "sizes of 1..%u and size 1 beyond them",
                             func, path, (long long)i, (long long)nim->dim[0], (long long)n,
                             UINT32_MAX);
            goto fail;
        }
        if (i <= 3) {
            if (count > SIZE_MAX / (size_t)n) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %lld x %lld x %lld voxels "
                                 "are too many", func, path, (long long)nim->nx,
                                 (long long)nim->ny, (long long)nim->nz);
                goto fail;
            }
            count *= (size_t)n;
            out->dims[i - 1] = (uint32_t)n;
        }
    }

    switch (nim->datatype) {
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
                         func, path, nifti_datatype_string(nim->datatype), nim->datatype);
        goto fail;
    }
    if (nim->nbyper < 1 || count > SIZE_MAX / (size_t)nim->nbyper) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %zu voxels of %d bytes: too large",
                         func, path, count, nim->nbyper);
        goto fail;
    }
    data_bytes = count * (size_t)nim->nbyper;
    if (nim->iname_offset < 0 || (uint64_t)nim->iname_offset > SIZE_MAX - data_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": vox_offset %lld is invalid", func,
                         path, (long long)nim->iname_offset);
        goto fail;
    }
    if (!gz && (uintmax_t)sb.st_size < (uintmax_t)nim->iname_offset + data_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %jd bytes; its header claims %lld + %zu (vox_offset + "
                         "%u x %u x %u voxels of %d bytes)",
                         func, path, (intmax_t)sb.st_size, (long long)nim->iname_offset,
                         data_bytes, out->dims[0], out->dims[1], out->dims[2], nim->nbyper);
        goto fail;
    }
    if (gz && ((uintmax_t)nim->iname_offset + data_bytes) / GZIP_MAX_RATIO >
                  (uintmax_t)sb.st_size) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %jd compressed bytes, too few for the %lld + %zu its "
                         "header claims (gzip expands at most %ux)",
                         func, path, (intmax_t)sb.st_size, (long long)nim->iname_offset,
                         data_bytes, GZIP_MAX_RATIO);
        goto fail;
    }

    /* The index-to-world matrix and, from its columns, the spacing. */
    if (nim->sform_code > 0) {
        out->transform = UMBRA__NIFTI_SFORM;
        for (r = 0; r < 4; ++r) {
            for (c = 0; c < 4; ++c) {
                out->index_to_world[r][c] = nim->sto_xyz.m[r][c];
            }
        }
    } else if (nim->qform_code > 0) {
        out->transform = UMBRA__NIFTI_QFORM;
        for (r = 0; r < 4; ++r) {
            for (c = 0; c < 4; ++c) {
                out->index_to_world[r][c] = nim->qto_xyz.m[r][c];
            }
        }
    } else {
        out->transform = UMBRA__NIFTI_PIXDIM;
        for (c = 0; c < 3; ++c) {
            /* nifticlib already reads a pixdim of 0 as 1 and drops the sign (tested); kept so the
             * matrix stays valid whatever a future nifticlib does. */
            double d = fabs(nim->pixdim[c + 1]);
            out->index_to_world[c][c] = d > 0.0 ? d : 1.0;
        }
        out->index_to_world[3][3] = 1.0;
    }
    for (c = 0; c < 3; ++c) {
        double len = column_length(out->index_to_world, c);
        float f = (float)len;
        if (!(len > 0.0) || !isfinite(f)) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": index axis %d has spacing %g under the %s; it must be "
                             "finite and > 0",
                             func, path, c, len,
                             out->transform == UMBRA__NIFTI_SFORM   ? "sform"
                             : out->transform == UMBRA__NIFTI_QFORM ? "qform"
                                                                    : "pixdim");
            goto fail;
        }
        out->spacing[c] = f;
    }

    /* NIfTI: a slope of 0 means no scaling. Non-finite slopes or intercepts are refused rather
     * than guessed at. */
    slope = nim->scl_slope;
    inter = nim->scl_inter;
    if (!isfinite(slope) || !isfinite(inter)) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": scl_slope %g or scl_inter %g is "
                         "not finite", func, path, slope, inter);
        goto fail;
    }
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
    F->nim = nim;
    F->count = count;
    F->data_bytes = data_bytes;
    F->type = type;
    F->scale = scale;
    F->slope = slope;
    F->inter = inter;
    return UMBRA_SUCCESS;

fail:
    if (nim) {
        nifti_image_free(nim);
    }
    return st;
}

/* Voxels converted per step: 1 MiB of the widest NIfTI type umbra reads. */
#define CONVERT_CHUNK ((size_t)1 << 17)

/* umbra_volume_fill_fn: reads the voxels at vox_offset (through znzlib, so .nii.gz too) into dst,
 * which holds F->count voxels of F->type. nifticlib's nifti_read_buffer swaps the bytes and
 * zeroes non-finite floats as nifti_image_load did. A file type umbra keeps as it is lands in
 * dst directly; one converted (scl_slope, int8, 32- and 64-bit types) is read a chunk at a time
 * and converted into dst, so no second full-size copy exists. */
static umbra_status fill_nifti(void *user, void *dst, size_t bytes)
{
    nifti_fill *F = user;
    nifti_image *nim = F->nim;
    enum { OK, NO_OPEN, SHORT, NOT_FINITE } why = OK; /* reported after the unlock */
    size_t out_size = umbra_scalar_type_size(F->type), done = 0, in_size = (size_t)nim->nbyper;
    unsigned char *chunk = NULL;
    znzFile fp = NULL;
    int keep = !F->scale && ((nim->datatype == DT_UINT8 && F->type == UMBRA_UINT8) ||
                             (nim->datatype == DT_UINT16 && F->type == UMBRA_UINT16) ||
                             (nim->datatype == DT_INT16 && F->type == UMBRA_INT16) ||
                             (nim->datatype == DT_FLOAT32 && F->type == UMBRA_FLOAT32));

    if (bytes != F->count * out_size) {
        return umbra__fail(F->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: \"%s\": the fill buffer holds %zu bytes, not the %zu of %zu voxels",
                           F->func, F->path, bytes, F->count * out_size, F->count);
    }
    if (!keep) {
        chunk = malloc(CONVERT_CHUNK * in_size);
        if (!chunk) {
            return umbra__fail(F->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: cannot allocate %zu bytes to convert the voxels of \"%s\"",
                               F->func, CONVERT_CHUNK * in_size, F->path);
        }
    }
    /* Every nifticlib call under the lock with its printing off, as in nifti_header. */
    pthread_mutex_lock(&nifti_lock);
    nifti_set_debug_level(0);
    fp = znzopen(nim->iname, "rb", nifti_is_gzfile(nim->iname));
    if (znz_isnull(fp)) {
        why = NO_OPEN;
    } else if (znzseek(fp, (znz_off_t)nim->iname_offset, SEEK_SET) < 0) {
        why = SHORT; /* gzseek gives the new offset, fseek 0: only -1 is a failure */
    } else if (keep) {
        if (nifti_read_buffer(fp, dst, (int64_t)F->data_bytes, nim) != (int64_t)F->data_bytes)
            why = SHORT;
    } else {
        while (done < F->count) {
            size_t n = F->count - done < CONVERT_CHUNK ? F->count - done : CONVERT_CHUNK;
            if (nifti_read_buffer(fp, chunk, (int64_t)(n * in_size), nim) !=
                (int64_t)(n * in_size)) {
                why = SHORT;
                break;
            }
            if (!convert(chunk, nim->datatype, n, F->scale, F->slope, F->inter, F->type,
                         (unsigned char *)dst + done * out_size)) {
                why = NOT_FINITE;
                break;
            }
            done += n;
        }
    }
    if (!znz_isnull(fp)) {
        znzclose(fp);
    }
    nifti_set_debug_level(NIFTI_DEFAULT_DEBUG);
    pthread_mutex_unlock(&nifti_lock);
    free(chunk);

    if (why == NO_OPEN) {
        return umbra__fail(F->ctx, UMBRA_ERROR_IO, "%s: cannot open \"%s\" to read its voxels",
                           F->func, F->path);
    }
    if (why == SHORT) {
        return umbra__fail(F->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": cannot read its %zu bytes of voxels (truncated or corrupt "
                           "data)",
                           F->func, F->path, F->data_bytes);
    }
    if (why == NOT_FINITE) {
        return umbra__fail(F->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": a voxel (%s, times scl_slope %g plus scl_inter %g) is "
                           "not a finite float32",
                           F->func, F->path, nifti_datatype_string(nim->datatype), F->slope,
                           F->inter);
    }
    return UMBRA_SUCCESS;
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
    nifti_image_free(F.nim);
    if (st != UMBRA_SUCCESS) {
        umbra__nifti_volume_free(out);
    }
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
    /* The file's world (RAS+ by NIfTI's convention) becomes the volume's: origin = the last
     * column, index axis a's direction = column a over its length. A header with neither sform
     * nor qform places nothing, and the box stays centred. */
    for (int r = 0; r < 3; ++r) {
        origin[r] = (float)nv.index_to_world[r][3];
        for (int a = 0; a < 3; ++a)
            directions[3 * a + r] = (float)(nv.index_to_world[r][a] / nv.spacing[a]);
    }
    /* The voxels go straight into the volume's buffer (umbra_volume_create_filled). */
    st = umbra__volume_from_fill(ctx, fill_nifti, &F, nv.type, nv.dims, nv.spacing,
                                 nv.transform != UMBRA__NIFTI_PIXDIM ? origin : NULL,
                                 nv.transform != UMBRA__NIFTI_PIXDIM ? directions : NULL, out);
    nifti_image_free(F.nim);
    return st;
}
