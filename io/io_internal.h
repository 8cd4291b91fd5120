// SPDX-License-Identifier: Apache-2.0
/* io/io_internal.h: what the readers and writers of umbra_io share.
 *
 * umbra_io is built on libumbra's public API alone (it never sees host/internal.h), so that the
 * core can keep every internal symbol hidden. Errors are recorded on the context through the
 * public umbra_context_record_error; umbra__fail below is io's own formatting wrapper over it,
 * static inline so that each library keeps its own and a program linking both statically sees no
 * clash. */
#ifndef UMBRA_IO_INTERNAL_H
#define UMBRA_IO_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "umbra/io.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define UMBRA_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define UMBRA_PRINTF(f, a)
#endif

#define UMBRA_MESSAGE_MAX 8192

/* Records status and a formatted message on ctx (which may be NULL: the message is then dropped)
 * and returns status, as the core's umbra__fail does. */
static inline umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt,
                                       ...) UMBRA_PRINTF(3, 4);
static inline umbra_status umbra__fail(umbra_context ctx, umbra_status status, const char *fmt,
                                       ...)
{
    char message[UMBRA_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    return umbra_context_record_error(ctx, status, message);
}

/* Reads a whole file into a malloc'ed buffer, followed by one NUL byte not counted in *size (the
 * text parsers rely on it). Regular files only (see umbra__file_open). */
umbra_status umbra__read_file(umbra_context ctx, const char *func, const char *path, void **data,
                              size_t *size);

/* Opens path for reading if it is a regular file, without ever blocking (a FIFO or device is
 * refused, not waited on), and gives its size. The FILE is the caller's to fclose. Every reader of
 * umbra opens its files through this. func names the public function in messages. */
umbra_status umbra__file_open(umbra_context ctx, const char *func, const char *path, FILE **out,
                              size_t *size);

/* At most this many data roots in umbra_volume_load_options (io.h says so). */
#define UMBRA_DATA_ROOTS_MAX 1024

/* NULL (the defaults), or options whose struct_size and data roots are well formed; else
 * UMBRA_ERROR_INVALID_ARGUMENT naming the field. */
umbra_status umbra__load_options_check(umbra_context ctx, const char *func,
                                       const umbra_volume_load_options *options);

/* Opens the data file a header (header_path) names (name, as written in it) under the data-file
 * policy (io/data_file.c): it must resolve inside the header's directory or one of options'
 * data roots (options checked, or NULL). Gives the FILE (the caller's to fclose), its size, and
 * in *shown the name joined to the header's directory, for messages (malloc'ed, the caller's to
 * free). On failure nothing is left to free. */
umbra_status umbra__data_file_open(umbra_context ctx, const char *func, const char *header_path,
                                   const char *name, const umbra_volume_load_options *options,
                                   char **shown, FILE **out, size_t *size);

/* A request of umbra_volume_read_box (io/box.c): the box to read, where its header and voxels go. */
typedef struct umbra__box {
    const umbra_volume_box_desc *desc;
    umbra_volume_file_info *info;
    void **voxels;
} umbra__box;

/* Nonzero when box asks for the header only (its size all 0). */
int umbra__box_header_only(const umbra__box *box);
/* Fills box->info from what a header declares and checks the box lies in dims. */
umbra_status umbra__box_info(umbra_context ctx, const char *func, const umbra__box *box,
                             umbra_scalar_type type, const uint32_t dims[3],
                             const float spacing[3], const float *origin,
                             const float *directions, uint32_t channels);
/* Reads box's voxels of a dims grid (voxel_bytes each) from f, whose position is the data's start:
 * raw (compressed 0), or a gzip or zlib stream of `compressed` bytes whose first skip inflated bytes
 * precede the voxels. swap_width > 1 swaps each value of that many bytes. */
umbra_status umbra__box_read(umbra_context ctx, const char *func, const char *name, FILE *f,
                             size_t compressed, size_t skip, const uint32_t dims[3],
                             size_t voxel_bytes, size_t swap_width, const umbra__box *box);
/* umbra_volume_read_box on a NIfTI file (io/nifti.c: any type it loads, converted as it loads
 * it; .nii.gz inflated as a stream). */
umbra_status umbra__nifti_read_box(umbra_context ctx, const char *path, const umbra__box *box);
/* umbra_volume_read_box on a headerless raw file. */
umbra_status umbra__box_load_raw(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                 const umbra__box *box);

/* The readers with detached data, with options (checked, or NULL); the public loaders call them
 * with NULL. Messages name the public reader (umbra_volume_load_nrrd, ...). With a box (else
 * NULL) they read that box of the file (umbra_volume_read_box) and make no volume (out unused). */
umbra_status umbra__volume_load_nrrd(umbra_context ctx, const char *path,
                                     const umbra_volume_load_options *options,
                                     const umbra__box *box, umbra_volume *out);
umbra_status umbra__volume_load_metaimage(umbra_context ctx, const char *path,
                                          const umbra_volume_load_options *options,
                                          const umbra__box *box, umbra_volume *out);
umbra_status umbra__volume_load_dat(umbra_context ctx, const char *path,
                                    const umbra_volume_load_options *options,
                                    const umbra__box *box, umbra_volume *out);

/* Reads exactly size bytes of f (which is path) into dst, or fails naming how many came. */
umbra_status umbra__file_read(umbra_context ctx, const char *func, const char *path, FILE *f,
                              void *dst, size_t size);

/* strerror_r into buf; thread-safe. */
const char *umbra__errno_text(int err, char *buf, size_t n);

/* The one integer parser of the file readers: the n characters at s must be decimal digits only
 * (no sign, blank or other trailing text) and the value at most max. Returns 1 and sets *out, else
 * 0 (also on overflow). */
int umbra__parse_uint(const char *s, size_t n, uint64_t max, uint64_t *out);

int umbra__host_is_big_endian(void);
void umbra__swap_bytes(void *data, size_t count, size_t width);

/* A volume whose voxels fill writes (umbra_volume_create_filled): straight into the device's
 * buffer where it can. origin and directions (9 floats, unit axis directions) give the
 * index-to-world transform, or are NULL for the centred box. */
umbra_status umbra__volume_from_fill(umbra_context ctx, umbra_volume_fill_fn fill, void *user,
                                     umbra_scalar_type type, const uint32_t dims[3],
                                     const float spacing[3], const float *origin,
                                     const float *directions, umbra_volume *out);
/* The same for a volume of `channels` interleaved values per voxel, or a label map. */
umbra_status umbra__volume_from_fill_kind(umbra_context ctx, umbra_volume_fill_fn fill,
                                          void *user, umbra_scalar_type type,
                                          const uint32_t dims[3], const float spacing[3],
                                          const float *origin, const float *directions,
                                          uint32_t channels, int labels, umbra_volume *out);

/* io/tiff.c and io/dicom.cpp: the stack readers behind umbra_volume_load_tiff and
 * umbra_volume_load_dicom, on count files (count 1: one file; never a directory, io/series.c
 * lists those). func names the public function in messages. */
umbra_status umbra__volume_load_tiff(umbra_context ctx, const char *func, const char *const *paths,
                                     size_t count, umbra_volume *out);
umbra_status umbra__volume_load_dicom(umbra_context ctx, const char *func,
                                      const char *const *paths, size_t count, umbra_volume *out);

/* io/series.c: a directory as a TIFF stack (when it holds .tif / .tiff files) or a DICOM series;
 * and whether a file name is a TIFF's. */
umbra_status umbra__volume_load_directory(umbra_context ctx, const char *func, const char *dir,
                                          umbra_volume *out);
int umbra__is_tiff_name(const char *name);

/* io/paraview.c: nonzero if the ParaView preset file path holds a preset named name (nothing is
 * recorded anywhere: a file that is not a preset file just holds none). */
int umbra__paraview_file_holds(const char *path, const char *name);

/* io/paraview_search.c: the first file of the preset search path (see there) holding a preset
 * named name, in a malloc'ed *found. Else UMBRA_ERROR_IO naming the directories searched; with
 * also_file the message says name was not a file either. */
umbra_status umbra__paraview_find(umbra_context ctx, const char *func, const char *name,
                                  int also_file, char **found);

#ifdef __cplusplus
}
#endif
#endif
