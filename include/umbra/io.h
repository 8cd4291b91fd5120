/* umbra/io.h: umbra_io, the optional file layer: volumes from NRRD, Voreen .dat and raw files,
 * transfer functions from text files, images to and from PNG and EXR.
 *
 * It is a library of its own (libumbra_io, CMake target umbra::io, pkg-config umbra-io) that links
 * Teem and OpenImageIO, so that libumbra itself depends on OpenCL and the C library only. It is
 * built on libumbra's public API: whatever it loads an application could also hand to
 * umbra_volume_create or umbra_transfer_function_create itself. Errors are recorded on the
 * context like every umbra error. Readers open regular files only. */
#ifndef UMBRA_IO_H
#define UMBRA_IO_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/umbra.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- volumes --------------------------------------------------------------------------------- */

/* Loads a volume by file extension: .nrrd / .nhdr (Teem), .dat (Voreen). */
UMBRA_API umbra_status umbra_volume_load(umbra_context ctx, const char *path, umbra_volume *out);

/* Loads NRRD, attached (.nrrd) or detached (.nhdr + data file), through Teem: types uchar, ushort,
 * short and float; 3-D, or 4-D with a size-1 first axis. With "space directions" the spacing is
 * each direction's length and the volume carries the index-to-world transform (space origin, 0
 * where absent, and the unit directions); a sheared grid is UMBRA_ERROR_UNSUPPORTED. Without them
 * the spacing comes from the header's spacings (1 where absent) and the box is centred. */
UMBRA_API umbra_status umbra_volume_load_nrrd(umbra_context ctx, const char *path, umbra_volume *out);

/* Loads a Voreen .dat header and its raw file, which is looked up relative to the .dat's
 * directory. ObjectFileName, Resolution, SliceThickness and Format (UCHAR, USHORT, SHORT, FLOAT)
 * are required; ObjectModel, if present, must be I. SliceThickness is the spacing; the format
 * has no origin, so the box is centred. */
UMBRA_API umbra_status umbra_volume_load_dat(umbra_context ctx, const char *path, umbra_volume *out);

typedef struct umbra_raw_desc {
    size_t struct_size;      /* sizeof(umbra_raw_desc); set by umbra_raw_desc_init */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* default 1 */
    int big_endian;          /* 0 (default): little-endian */
    size_t header_bytes;     /* bytes to skip at the start of the file (default 0) */
} umbra_raw_desc;

UMBRA_API void umbra_raw_desc_init(umbra_raw_desc *desc);

/* Loads a headerless raw file. The file must hold exactly header_bytes + dims product * type size
 * bytes; any other size is UMBRA_ERROR_FORMAT naming both numbers. */
UMBRA_API umbra_status umbra_volume_load_raw(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                             umbra_volume *out);

/* ---- transfer functions ---------------------------------------------------------------------- */

/* Reads the text format documented in the README (and io/tf_file.c): '#' comments, optional
 * lines "resolution N" (default 256) and "range LO HI" (finite, LO < HI) before the first point,
 * then one control point "value r g b a" per line, values ascending (equal values make a step):
 * in [0,1] of the volume's normalised range, or with a range, data values in [LO, HI].
 * UMBRA_ERROR_FORMAT names the line and value for anything else. */
UMBRA_API umbra_status umbra_transfer_function_load(umbra_context ctx, const char *path,
                                                    umbra_transfer_function *out);

/* ---- images ------------------------------------------------------------------------------------
 * The format follows the extension: .png is written as 8-bit sRGB-encoded RGBA (colour
 * un-premultiplied, clamped), .exr as linear float RGBA as rendered. */

/* Writes width x height premultiplied RGBA floats (borrowed), row 0 at the top. Errors are
 * recorded on ctx. */
UMBRA_API umbra_status umbra_image_write(umbra_context ctx, const char *path, uint32_t width,
                                         uint32_t height, const float *rgba);

/* Reads an image as linear premultiplied RGBA floats into a malloc'ed buffer the caller frees
 * with free(). PNG values are decoded from sRGB; missing channels are filled (alpha 1). */
UMBRA_API umbra_status umbra_image_read(umbra_context ctx, const char *path, uint32_t *width,
                                        uint32_t *height, float **rgba);

#ifdef __cplusplus
}
#endif
#endif
