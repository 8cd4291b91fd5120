// SPDX-License-Identifier: Apache-2.0
/* io/dicom.h: what io/dicom_parse.c (umbra's own bounded walk over a DICOM file's structure) and
 * io/dicom.cpp (series assembly, pixel decoding) share. */
#ifndef UMBRA_IO_DICOM_H
#define UMBRA_IO_DICOM_H

#include <stdint.h>

#include "io_internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#define UMBRA__DICOM_MAX_FRAGMENTS 65536u

/* One file's attributes as umbra reads them; the has_* flags say which were present. */
typedef struct umbra__dicom_file {
    char syntax[68];          /* TransferSyntaxUID (0002,0010) */
    int encapsulated;         /* compressed pixel data, in fragments */
    char series[68];          /* SeriesInstanceUID (0020,000E) */
    char photometric[20];     /* PhotometricInterpretation (0028,0004) */
    unsigned rows, cols, bits_allocated, bits_stored, high_bit, pixel_rep, samples, frames;
    int has_rows, has_cols, has_bits_allocated, has_bits_stored, has_high_bit, has_pixel_rep;
    int has_position, has_orientation, has_spacing, has_float_pixels;
    double position[3], orientation[6], spacing[2];
    double slope, intercept, thickness;
    char bad_value[160];      /* the first attribute whose value did not parse, named */
    /* Uncompressed: the pixel data's value; encapsulated: its fragments (the basic offset
     * table left out), in file order. */
    uint64_t pixel_offset, pixel_length;
    int has_pixels, pixels_fragmented;
    uint64_t *fragment_offset, *fragment_length;
    size_t fragments;
    uint64_t file_bytes;
} umbra__dicom_file;

/* Walks path's structure (a DICOM Part 10 file: preamble, "DICM", the file meta group, the data
 * set in implicit or explicit VR little endian, or compressed pixel data in either), checking
 * every element, item and fragment against the bytes that hold it, and reads the attributes
 * above. Never allocates more than the fragment list. On failure out holds nothing to free. */
umbra_status umbra__dicom_parse(umbra_context ctx, const char *func, const char *path,
                                umbra__dicom_file *out);

/* Frees out's fragment list; out may be NULL. */
void umbra__dicom_file_free(umbra__dicom_file *out);

#ifdef __cplusplus
}
#endif
#endif
