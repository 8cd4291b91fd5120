// SPDX-License-Identifier: Apache-2.0
/* umbra/io.h: umbra_io, the optional file layer: volumes from NRRD, NIfTI-1/2, MetaImage, Voreen .dat
 * and raw files, transfer functions from text files and ParaView JSON presets, images to and from PNG and
 * EXR.
 *
 * It is a library of its own (libumbra_io, CMake target umbra::io, pkg-config umbra-io) that links
 * Teem, OpenImageIO, nifticlib and cJSON, so that libumbra itself depends on OpenCL and the C
 * library only. It is built on libumbra's public API: whatever it loads an application could
 * also hand to umbra_volume_create or umbra_transfer_function_create itself. Errors are recorded
 * on the context like every umbra error. Readers open regular files only. */
#ifndef UMBRA_IO_H
#define UMBRA_IO_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/umbra.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- volumes --------------------------------------------------------------------------------- */

/* Loads a volume by file extension: .nrrd / .nhdr (Teem), .nii / .nii.gz (NIfTI), .mha / .mhd
 * (MetaImage), .dat (Voreen). */
UMBRA_API umbra_status umbra_volume_load(umbra_context ctx, const char *path, umbra_volume *out);

/* The data-file policy. A NRRD ("data file"), MetaImage (ElementDataFile) or Voreen .dat
 * (ObjectFileName) header names a second file holding the voxels. However it is named (relative
 * to the header, absolute, through ".." or symbolic links), that file must resolve (realpath)
 * inside the header's own directory, or inside one of data_roots; anything else is
 * UMBRA_ERROR_IO naming the file, where it resolves to and the header's directory, and nothing
 * of it is read. So a header from elsewhere (an upload) cannot make umbra read another file of
 * the machine. umbra_volume_load and the readers below allow the header's directory only; NRRD
 * and MetaImage data split over several files (LIST, printf-style names) are refused. */
typedef struct umbra_volume_load_options {
    size_t struct_size;             /* sizeof(umbra_volume_load_options); set by
                                       umbra_volume_load_options_init */
    const char *const *data_roots;  /* borrowed for the call: directories (each resolved with
                                       realpath, so it must exist) that data files may also lie
                                       in; "/" allows any file. NULL (default): none */
    size_t data_root_count;         /* entries of data_roots, at most 1024 (default 0) */
} umbra_volume_load_options;

/* Fills options with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_volume_load_options_init(umbra_volume_load_options *options);

/* umbra_volume_load with options (NULL: the defaults, as umbra_volume_load); options are read
 * during the call only. A malformed options struct (struct_size, a NULL or empty root, more than
 * 1024) or a root that cannot be resolved is UMBRA_ERROR_INVALID_ARGUMENT. */
UMBRA_API umbra_status umbra_volume_load_with_options(umbra_context ctx, const char *path,
                                                      const umbra_volume_load_options *options,
                                                      umbra_volume *out);

/* Loads NRRD, attached (.nrrd) or detached (.nhdr + one data file, named relative to the header,
 * under the data-file policy above): types uchar, ushort, short and float; 3-D, or 4-D with a
 * size-1 first axis; encodings raw, gzip, zrl, ascii and hex. With "space directions" the spacing
 * is each direction's length and the volume carries the index-to-world transform (space origin, 0
 * where absent, and the unit directions); a sheared grid is UMBRA_ERROR_UNSUPPORTED. Without them
 * the spacing comes from the header's spacings (1 where absent) and the box is centred. Teem parses
 * the header, umbra reads the data. Header and data must be regular files (a FIFO or device is
 * UMBRA_ERROR_IO, never waited on); the declared sizes are checked against the data before anything
 * is allocated: raw data must fill the rest of its file exactly, gzip can expand at most 1032:1 and
 * zrl 16384:1 (else UMBRA_ERROR_FORMAT naming both sizes). */
UMBRA_API umbra_status umbra_volume_load_nrrd(umbra_context ctx, const char *path,
                                              umbra_volume *out);

/* Loads a Voreen .dat header and its raw file (both regular files), which is looked up relative to
 * the .dat's directory, under the data-file policy above. ObjectFileName, Resolution,
 * SliceThickness and Format (UCHAR, USHORT, SHORT, FLOAT) are required; ObjectModel, if present,
 * must be I. SliceThickness is the spacing; the format has no origin, so the box is centred. */
UMBRA_API umbra_status umbra_volume_load_dat(umbra_context ctx, const char *path,
                                             umbra_volume *out);

/* Loads a single-file NIfTI-1 or NIfTI-2 volume (.nii, or gzip-compressed .nii.gz), either byte
 * order; umbra reads the header and the voxels itself (nifticlib gives the quaternion formula).
 * 3-D, or with every dimension past the third of size 1. Types uint8, uint16, int16 and float32
 * are kept; int8 becomes int16; int32, uint32, int64, uint64 and float64 become float32 (rounded
 * to the nearest float); complex and RGB types are UMBRA_ERROR_UNSUPPORTED. A scl_slope other
 * than 0 (or 1 with scl_inter 0) gives float32 voxels slope * stored + inter, the file's real
 * values (e.g. Hounsfield units). Spacing is the length of each index axis under the sform (when
 * sform_code > 0), else the qform (qform_code > 0), else pixdim (0 read as 1), in the file's
 * units; the sform (else the qform) also places the volume in the file's world (its
 * index-to-world transform; a sheared one is UMBRA_ERROR_UNSUPPORTED). UMBRA_ERROR_FORMAT, naming
 * the field and its value: a sizeof_hdr other than 348 or 540, a magic other than "n+1" or
 * "n+2" ("ni1" pairs are UMBRA_ERROR_UNSUPPORTED), a vox_offset that is not a whole number of
 * bytes past the header, a NaN or infinite scl_slope, scl_inter, pixdim[0..3] or qform/sform
 * number, and any float voxel (after scaling) that is not finite. The header's sizes are checked
 * against the file before the voxels are read. */
UMBRA_API umbra_status umbra_volume_load_nifti(umbra_context ctx, const char *path,
                                               umbra_volume *out);

/* Loads a MetaImage volume (ITK's format): .mha with the voxels after the header (ElementDataFile =
 * LOCAL) or .mhd naming one data file (.raw, or zlib/gzip-compressed .zraw), relative to the
 * header, under the data-file policy above; header and data must be regular files. NDims 3, one
 * channel; BinaryData True; byte order from BinaryDataByteOrderMSB / ElementByteOrderMSB;
 * CompressedData with or without CompressedDataSize; HeaderSize (a count of bytes to skip, or -1:
 * the voxels end the file) for uncompressed data files. MET_UCHAR, MET_USHORT, MET_SHORT and
 * MET_FLOAT are kept; MET_CHAR becomes int16; MET_INT, MET_UINT, MET_LONG, MET_ULONG,
 * MET_LONG_LONG, MET_ULONG_LONG and MET_DOUBLE become float32. Spacing is ElementSpacing (else
 * ElementSize, else 1). With Offset (or Position, Origin) or TransformMatrix (or Rotation,
 * Orientation; values 3a..3a+2 are index axis a's direction) the volume carries that index-to-world
 * transform, in the file's world as written (ITK's LPS); with neither the box is centred. The sizes
 * are checked against the file before any voxel buffer is allocated: raw data must fill the rest of
 * its file exactly, compressed data can expand at most 1032:1 and must end exactly at the declared
 * size; anything else, a repeated or malformed key, is UMBRA_ERROR_FORMAT naming the value; what
 * umbra does not read (several channels or files, ASCII voxels, other types) is
 * UMBRA_ERROR_UNSUPPORTED. */
UMBRA_API umbra_status umbra_volume_load_metaimage(umbra_context ctx, const char *path,
                                                   umbra_volume *out);

typedef struct umbra_raw_desc {
    size_t struct_size;      /* sizeof(umbra_raw_desc); set by umbra_raw_desc_init */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* default 1 */
    int big_endian;          /* 0 (default): little-endian */
    size_t header_bytes;     /* bytes to skip at the start of the file (default 0) */
} umbra_raw_desc;

/* Fills desc with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_raw_desc_init(umbra_raw_desc *desc);

/* Loads a headerless raw file (a regular file, else UMBRA_ERROR_IO). The file must hold exactly
 * header_bytes + dims product * type size bytes; any other size is UMBRA_ERROR_FORMAT naming both
 * numbers. */
UMBRA_API umbra_status umbra_volume_load_raw(umbra_context ctx, const char *path,
                                             const umbra_raw_desc *desc, umbra_volume *out);

/* ---- transfer functions ---------------------------------------------------------------------- */

/* Reads the text format documented in the README (and io/tf_file.c): '#' comments, optional
 * lines "resolution N" (2..65536, default 256) and "range LO HI" (finite, LO < HI) before the
 * first point, then one control point "value r g b a" per line (at most UMBRA_TF_MAX_POINTS),
 * values ascending (equal values make a step): in [0,1] of the volume's normalised range, or with
 * a range, data values in [LO, HI]. The file must be a regular file; errors are UMBRA_ERROR_IO or
 * UMBRA_ERROR_FORMAT naming path:line and the value. A path ending in .json is read
 * as a ParaView preset with umbra_transfer_function_load_paraview's defaults. */
UMBRA_API umbra_status umbra_transfer_function_load(umbra_context ctx, const char *path,
                                                    umbra_transfer_function *out);

/* Options for ParaView presets; umbra_paraview_options_init sets the defaults. */
typedef struct umbra_paraview_options {
    size_t struct_size;      /* sizeof(umbra_paraview_options); set by
                                umbra_paraview_options_init */
    const char *preset;      /* the "Name" to pick in a file of several; NULL (default): the
                                first */
    uint32_t resolution;     /* table entries, 2..65536 (default 1024) */
    int range_given;         /* 0 (default): the table spans the preset's own x range */
    double range_min, range_max; /* with range_given: the data values the table spans */
} umbra_paraview_options;

/* Fills options with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_paraview_options_init(umbra_paraview_options *options);

/* Reads a ParaView JSON colour-map preset (RGBPoints, Points with midpoint and sharpness,
 * ColorSpace RGB / Lab / CIELAB / Diverging / Step; see the README) and evaluates it into a table
 * of options->resolution entries over a data range: the preset's own (smallest to largest x of its
 * points) or options' range, and gives the table that data range
 * (umbra_transfer_function_set_range), so renderers place it over each volume's values in data
 * units (e.g. Hounsfield units). options may be NULL (defaults). range, if not NULL, receives
 * the data range the table spans. Malformed files are UMBRA_ERROR_FORMAT naming the key and
 * point; unsupported colour spaces UMBRA_ERROR_UNSUPPORTED. */
UMBRA_API umbra_status umbra_transfer_function_load_paraview(umbra_context ctx, const char *path,
                                                             const umbra_paraview_options *options,
                                                             umbra_transfer_function *out,
                                                             double range[2]);

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
