// SPDX-License-Identifier: Apache-2.0
/* io/box.c: umbra_volume_read_box, one box of a volume file's grid read without the rest.
 *
 * The readers (io/nrrd.c, io/volume_io.c) parse and check their headers as they do for a whole
 * volume and then, given a box request, hand their data file here instead of to
 * umbra_volume_create_filled: raw data is read at the box's rows alone (one seek and one read a
 * row), deflated data (gzip or zlib) is inflated as a stream through a fixed buffer and only the
 * box's rows are kept. Memory is the box's voxels plus that buffer, whatever the file's size. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <zlib.h>

#include "io_internal.h"

#define BOX_CHUNK (256u * 1024u)

void umbra_volume_box_desc_init(umbra_volume_box_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    desc->struct_size = sizeof *desc;
}

int umbra__box_header_only(const umbra__box *box)
{
    const uint32_t *s = box->desc->size;
    return s[0] == 0 && s[1] == 0 && s[2] == 0;
}

umbra_status umbra__box_info(umbra_context ctx, const char *func, const umbra__box *box,
                             umbra_scalar_type type, const uint32_t dims[3],
                             const float spacing[3], const float *origin,
                             const float *directions, uint32_t channels)
{
    umbra_volume_file_info *info = box->info;
    const umbra_volume_box_desc *d = box->desc;
    memset(info, 0, sizeof *info);
    info->struct_size = sizeof *info;
    info->type = type;
    memcpy(info->dims, dims, sizeof info->dims);
    memcpy(info->spacing, spacing, sizeof info->spacing);
    info->channels = channels;
    if (origin && directions) {
        info->transform_given = 1;
        memcpy(info->origin, origin, sizeof info->origin);
        memcpy(info->directions, directions, sizeof info->directions);
    }
    if (umbra__box_header_only(box))
        return UMBRA_SUCCESS;
    for (int a = 0; a < 3; ++a) {
        if (d->size[a] == 0 || d->origin[a] >= dims[a] || d->size[a] > dims[a] - d->origin[a]) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: box origin %u %u %u size %u x %u x %u does not lie in the "
                               "%u x %u x %u grid (every size > 0)",
                               func, d->origin[0], d->origin[1], d->origin[2], d->size[0],
                               d->size[1], d->size[2], dims[0], dims[1], dims[2]);
        }
    }
    return UMBRA_SUCCESS;
}

/* A deflated stream read forward: the decompressed bytes before `at` are dropped. */
typedef struct inflater {
    z_stream z;
    FILE *f;
    size_t compressed_left; /* bytes of the file still to feed */
    uint64_t at;            /* decompressed bytes produced so far */
    unsigned char in[BOX_CHUNK];
    unsigned char drop[BOX_CHUNK];
} inflater;

/* Produces decompressed bytes until `at` reaches off + n, keeping [off, off + n) in dst. */
static int inflate_to(inflater *s, uint64_t off, unsigned char *dst, size_t n)
{
    while (s->at < off + n) {
        unsigned char *out;
        size_t want;
        if (s->at < off) {
            uint64_t gap = off - s->at;
            want = gap < BOX_CHUNK ? (size_t)gap : BOX_CHUNK;
            out = s->drop;
        } else {
            want = (size_t)(off + n - s->at);
            out = dst + (s->at - off);
        }
        if (s->z.avail_in == 0) {
            size_t take = s->compressed_left < BOX_CHUNK ? s->compressed_left : BOX_CHUNK;
            if (take == 0 || fread(s->in, 1, take, s->f) != take)
                return 0;
            s->compressed_left -= take;
            s->z.next_in = s->in;
            s->z.avail_in = (uInt)take;
        }
        s->z.next_out = out;
        s->z.avail_out = (uInt)want;
        int rc = inflate(&s->z, Z_NO_FLUSH);
        s->at += want - s->z.avail_out;
        if (rc == Z_STREAM_END && s->at < off + n)
            return 0;
        if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR)
            return 0;
    }
    return 1;
}

umbra_status umbra__box_read(umbra_context ctx, const char *func, const char *name, FILE *f,
                             size_t compressed, size_t skip, const uint32_t dims[3],
                             size_t voxel_bytes, size_t swap_width, const umbra__box *box)
{
    const umbra_volume_box_desc *d = box->desc;
    const size_t row = (size_t)d->size[0] * voxel_bytes;
    const size_t rows = (size_t)d->size[1] * d->size[2];
    unsigned char *dst = NULL;
    inflater *s = NULL;
    umbra_status st = UMBRA_SUCCESS;
    char buf[256];
    off_t start = ftello(f);

    if (start < 0) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot tell the position in \"%s\": %s",
                           func, name, umbra__errno_text(errno, buf, sizeof buf));
    }
    if (rows != 0 && row > SIZE_MAX / rows) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: box %u x %u x %u: too large",
                           func, d->size[0], d->size[1], d->size[2]);
    }
    dst = malloc(row * rows > 0 ? row * rows : 1);
    if (!dst) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "%s: cannot allocate %zu bytes for a box of \"%s\"", func, row * rows,
                           name);
    }
    if (compressed) {
        s = calloc(1, sizeof *s);
        if (!s || inflateInit2(&s->z, 15 + 32) != Z_OK) { /* 15 + 32: gzip or zlib header */
            free(s);
            s = NULL;
            st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot start inflating \"%s\"",
                             func, name);
            goto fail;
        }
        s->f = f;
        s->compressed_left = compressed;
    }
    for (size_t r = 0; r < rows; ++r) {
        uint64_t y = d->origin[1] + r % d->size[1], z = d->origin[2] + r / d->size[1];
        uint64_t off = ((z * dims[1] + y) * dims[0] + d->origin[0]) * voxel_bytes;
        unsigned char *out = dst + r * row;
        if (s) {
            if (!inflate_to(s, off + skip, out, row)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: \"%s\": the deflated data ends or is corrupt before byte "
                                 "%llu of the voxels",
                                 func, name, (unsigned long long)(off + row));
                goto fail;
            }
        } else {
            if (fseeko(f, start + (off_t)off, SEEK_SET) != 0) {
                st = umbra__fail(ctx, UMBRA_ERROR_IO, "%s: cannot seek in \"%s\": %s", func, name,
                                 umbra__errno_text(errno, buf, sizeof buf));
                goto fail;
            }
            st = umbra__file_read(ctx, func, name, f, out, row);
            if (st != UMBRA_SUCCESS)
                goto fail;
        }
    }
    if (swap_width > 1)
        umbra__swap_bytes(dst, row * rows / swap_width, swap_width);
    *box->voxels = dst;
    dst = NULL;
fail:
    if (s) {
        inflateEnd(&s->z);
        free(s);
    }
    free(dst);
    return st;
}

static int ends_with_nocase(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; ++i) {
        char a = s[n - m + i], b = tail[i];
        if (a >= 'A' && a <= 'Z')
            a = (char)(a - 'A' + 'a');
        if (a != b)
            return 0;
    }
    return 1;
}

umbra_status umbra_volume_read_box(umbra_context ctx, const char *path,
                                   const umbra_volume_box_desc *desc,
                                   umbra_volume_file_info *info, void **voxels)
{
    umbra_status st;
    void *got = NULL;
    umbra__box box;
    if (!info || !voxels || !desc || !path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: %s is NULL", __func__,
                           !info ? "info" : !voxels ? "voxels" : !desc ? "desc" : "path");
    }
    *voxels = NULL;
    if (desc->struct_size != sizeof *desc) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size is %zu, expected %zu (call "
                           "umbra_volume_box_desc_init)",
                           __func__, desc->struct_size, sizeof *desc);
    }
    st = umbra__load_options_check(ctx, __func__, desc->options);
    if (st != UMBRA_SUCCESS)
        return st;
    box.desc = desc;
    box.info = info;
    box.voxels = &got;
    if (desc->raw) {
        st = umbra__box_load_raw(ctx, path, desc->raw, &box);
    } else if (ends_with_nocase(path, ".nrrd") || ends_with_nocase(path, ".nhdr")) {
        st = umbra__volume_load_nrrd(ctx, path, desc->options, &box, NULL);
    } else if (ends_with_nocase(path, ".mha") || ends_with_nocase(path, ".mhd")) {
        st = umbra__volume_load_metaimage(ctx, path, desc->options, &box, NULL);
    } else if (ends_with_nocase(path, ".nii") || ends_with_nocase(path, ".nii.gz")) {
        st = umbra__nifti_read_box(ctx, path, &box);
    } else if (ends_with_nocase(path, ".dat")) {
        st = umbra__volume_load_dat(ctx, path, desc->options, &box, NULL);
    } else {
        st = umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                         "%s: \"%s\": a box is read from NRRD (.nrrd, .nhdr), NIfTI (.nii, "
                         ".nii.gz), MetaImage (.mha, .mhd), Voreen .dat and raw files "
                         "(desc->raw); load other formats whole",
                         __func__, path);
    }
    if (st != UMBRA_SUCCESS) {
        free(got);
        return st;
    }
    *voxels = got;
    return UMBRA_SUCCESS;
}
