// SPDX-License-Identifier: Apache-2.0
/* umbra/io.h: umbra_io, the optional file layer: volumes from NRRD, NIfTI-1/2, MetaImage, DICOM,
 * TIFF stacks, Voreen .dat and raw files, transfer functions from text files and ParaView JSON
 * presets, images to and from PNG and EXR.
 *
 * It is a library of its own (libumbra_io, CMake target umbra::io, pkg-config umbra-io) that links
 * Teem, OpenImageIO, nifticlib, cJSON, libtiff and expat, so that libumbra itself depends
 * on OpenCL and the C library only. It is built on libumbra's public API: whatever it loads an
 * application could also hand to umbra_volume_create or umbra_transfer_function_create itself.
 * Errors are recorded on the context like every umbra error. Readers open regular files only. */
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
 * (MetaImage), .dat (Voreen), .tif / .tiff (umbra_volume_load_tiff), .dcm / .dicom / .ima or any
 * file starting with DICOM's preamble (umbra_volume_load_dicom); a directory is a TIFF stack of
 * its .tif / .tiff files when it holds any, else a DICOM series. */
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

/* Loads a DICOM volume (Part 10 files, read by umbra itself: see docs/usage.md): count files of one
 * series in any order, one directory (its files, DICOMDIR and names starting with '.' passed
 * over, subdirectories not entered), or one single-frame file. Greyscale, 8 or 16 bits
 * allocated; implicit or explicit VR little endian, uncompressed or RLE Lossless (JPEG, JPEG-LS,
 * JPEG 2000, multi-frame and big-endian files are UMBRA_ERROR_UNSUPPORTED). Slices are sorted by ImagePositionPatient along
 * the slice normal and must be one series (SeriesInstanceUID), one size and pixel layout, one
 * orientation, on one line along the normal (no gantry tilt) at uniform steps (each within 1% of a
 * step of its place): the z spacing is that step, x and y PixelSpacing's column and row spacing.
 * The volume carries DICOM's patient space (LPS, millimetres): origin the first slice's
 * ImagePositionPatient, axes the row and column directions of ImageOrientationPatient and their
 * normal. RescaleSlope/Intercept are applied per slice: without rescale the stored type is kept
 * (int8 becomes int16); integer rescale gives int16 when the rescaled values fit (else float32);
 * a fractional one float32. Anything else (a second series, another size, a missing or repeated
 * position, uneven spacing, colour, truncated pixel data, compressed data claiming more than
 * 1032 times its bytes) is UMBRA_ERROR_FORMAT or UMBRA_ERROR_UNSUPPORTED naming the file and
 * value; at most 65536 files. */
UMBRA_API umbra_status umbra_volume_load_dicom(umbra_context ctx, const char *const *paths,
                                               size_t count, umbra_volume *out);

/* Loads a TIFF stack through libtiff: one multi-page TIFF (each full-resolution page a z slice;
 * pages marked reduced-resolution are passed over), count single-page TIFFs in the order given,
 * or one directory (its .tif / .tiff files in natural name order: "2" before "10"). Greyscale
 * pages, stripped or tiled, any compression libtiff decodes: 8- and 16-bit unsigned kept, int16
 * kept, int8 becomes int16, 32-bit float kept; every slice the same size and type. OME-TIFF:
 * PhysicalSizeX/Y/Z of its OME-XML (in the x axis's unit) are the spacing, and it must hold one
 * image of one channel and time point; else the spacing is 1. The box is centred. A page that
 * does not decode, slices of different sizes, colour or other sample types, more than 65536
 * slices or slices claiming more than 1032 times their files' bytes are refused with
 * UMBRA_ERROR_FORMAT or UMBRA_ERROR_UNSUPPORTED naming the file and page. */
UMBRA_API umbra_status umbra_volume_load_tiff(umbra_context ctx, const char *const *paths,
                                              size_t count, umbra_volume *out);

typedef struct umbra_raw_desc {
    size_t struct_size;      /* sizeof(umbra_raw_desc); set by umbra_raw_desc_init (the layout
                                before channels, offsetof(umbra_raw_desc, channels), is accepted
                                with one channel and no labels) */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* default 1 */
    int big_endian;          /* 0 (default): little-endian */
    size_t header_bytes;     /* bytes to skip at the start of the file (default 0) */
    uint32_t channels;       /* values per voxel, interleaved (umbra_volume_desc.channels;
                                default 1) */
    int labels;              /* nonzero: the voxels are labels (umbra_volume_desc.labels) */
} umbra_raw_desc;

/* Fills desc with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_raw_desc_init(umbra_raw_desc *desc);

/* Loads a headerless raw file (a regular file, else UMBRA_ERROR_IO). The file must hold exactly
 * header_bytes + dims product * type size bytes; any other size is UMBRA_ERROR_FORMAT naming both
 * numbers. */
UMBRA_API umbra_status umbra_volume_load_raw(umbra_context ctx, const char *path,
                                             const umbra_raw_desc *desc, umbra_volume *out);

/* ---- a sub-box of a volume file ---------------------------------------------------------------
 * For a program that holds only a part of a volume in memory (umbra_mpi: each rank its part): the
 * file's header alone, or the voxels of one box of its grid, read row by row (a raw file is read
 * at the box's rows only; gzip or zlib data is inflated as a stream and kept at the box's rows
 * only), never the whole volume in memory. */

/* What a volume file's header declares (umbra_volume_read_box). */
typedef struct umbra_volume_file_info {
    size_t struct_size;      /* sizeof(umbra_volume_file_info); set by umbra_volume_read_box */
    umbra_scalar_type type;  /* the voxels' type as umbra keeps them */
    uint32_t dims[3];
    float spacing[3];
    int transform_given;     /* nonzero: the file places the volume (origin, directions) */
    float origin[3];
    float directions[9];
    uint32_t channels;       /* values per voxel (1, or a raw file's channels) */
} umbra_volume_file_info;

typedef struct umbra_volume_box_desc {
    size_t struct_size;      /* sizeof(umbra_volume_box_desc); set by umbra_volume_box_desc_init */
    uint32_t origin[3];      /* the box's first voxel (default 0) */
    uint32_t size[3];        /* its voxels per axis, origin + size <= dims; all 0 (default): the
                                header only, no voxels */
    const umbra_raw_desc *raw; /* not NULL: path is a headerless raw file so described (borrowed
                                for the call); NULL (default): the format follows the extension */
    const umbra_volume_load_options *options; /* the data-file policy (NULL: the defaults) */
} umbra_volume_box_desc;

/* Fills desc with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_volume_box_desc_init(umbra_volume_box_desc *desc);

/* Reads the header of the volume file path (NRRD .nrrd / .nhdr with raw or gzip encoding; NIfTI
 * .nii / .nii.gz, converted as umbra_volume_load_nifti converts; MetaImage .mha / .mhd, raw or
 * compressed, of the types kept as they are (MET_UCHAR, MET_USHORT, MET_SHORT, MET_FLOAT); Voreen
 * .dat; or a raw file described by desc->raw) into *info and, when desc->size is not all 0, the
 * voxels of the box desc->origin + [0, desc->size) into a malloc'ed *voxels (x fastest, channels
 * interleaved, in info->type, the host's byte order; the caller frees it with free()). The file's
 * size is checked as umbra_volume_load does. A box outside the grid is UMBRA_ERROR_INVALID_ARGUMENT
 * naming it; other encodings and formats are UMBRA_ERROR_UNSUPPORTED. */
UMBRA_API umbra_status umbra_volume_read_box(umbra_context ctx, const char *path,
                                             const umbra_volume_box_desc *desc,
                                             umbra_volume_file_info *info, void **voxels);

/* ---- transfer functions ---------------------------------------------------------------------- */

/* Reads the text format documented in docs/usage.md (and io/tf_file.c): '#' comments, optional
 * lines "resolution N" (2..65536, default 256) and "range LO HI" (finite, LO < HI) before the
 * first point, then one control point "value r g b a" per line (at most UMBRA_TF_MAX_POINTS),
 * values ascending (equal values make a step): in [0,1] of the volume's normalised range, or with
 * a range, data values in [LO, HI]. The file must be a regular file; errors are UMBRA_ERROR_IO or
 * UMBRA_ERROR_FORMAT naming path:line and the value. A path ending in .json is read
 * as a ParaView preset with umbra_transfer_function_load_paraview's defaults; a bare name (no
 * '/') that is no file is a preset's name, looked up in the preset search path (as
 * umbra_transfer_function_load_paraview with no path), e.g. "Cool to Warm". */
UMBRA_API umbra_status umbra_transfer_function_load(umbra_context ctx, const char *path,
                                                    umbra_transfer_function *out);

/* The opacity a ParaView preset without "Points" gets (ParaView's own presets carry none): a
 * linear ramp from 0 at the preset's lowest x to this at its highest, or this for every category
 * of a categorical preset. An opacity is per voxel, as in umbra's own format. */
#define UMBRA_PARAVIEW_DEFAULT_OPACITY 0.1

/* Options for ParaView presets; umbra_paraview_options_init sets the defaults. */
typedef struct umbra_paraview_options {
    size_t struct_size;      /* sizeof(umbra_paraview_options); set by
                                umbra_paraview_options_init */
    const char *preset;      /* the "Name" to pick in a file of several; NULL (default): the
                                first. With no path, the name looked up in the preset search
                                path */
    uint32_t resolution;     /* table entries, 2..65536 (default 1024); a categorical preset
                                gets more where its categories need them (4 per unit of value) */
    int range_given;         /* 0 (default): the table spans the preset's own x range */
    double range_min, range_max; /* with range_given: the data values the table spans */
    /* Added in 0.5; a struct_size of 0.4's layout (offsetof this field) gets its default. */
    double default_opacity;  /* in [0,1]: the opacity of a preset without "Points" (default
                                UMBRA_PARAVIEW_DEFAULT_OPACITY) */
} umbra_paraview_options;

/* Fills options with the defaults (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_paraview_options_init(umbra_paraview_options *options);

/* Reads a ParaView JSON colour-map preset (RGBPoints, Points with midpoint and sharpness,
 * ColorSpace RGB / HSV / Lab / CIELAB / Diverging / Step, HSVWrap; categorical IndexedColors with
 * Annotations; see docs/usage.md) and evaluates it into a table of options->resolution entries
 * over a data range: the preset's own (smallest to largest x of its points; a categorical
 * preset's values +-0.5) or options' range, and gives the table that data range
 * (umbra_transfer_function_set_range), so renderers place it over each volume's values in data
 * units (e.g. Hounsfield units). A categorical preset is a step table: values within 0.5 of an
 * annotated value take its colour, others are transparent. options may be NULL (defaults).
 * path NULL: options->preset is looked up by name in the preset search path, in order: each
 * directory of $UMBRA_PRESET_PATH (':'-separated), the presets installed with umbra
 * (<prefix>/share/umbra/presets, found from the library's own location; <build>/share/umbra/
 * presets in a build tree), the current directory; in each, the .json files in name order, the
 * first holding that Name wins (else UMBRA_ERROR_IO naming the directories). range, if not NULL,
 * receives the data range the table spans. Malformed files are UMBRA_ERROR_FORMAT naming the key
 * and point; a file of more than 64 MiB or 2^20 JSON values is refused before it is parsed;
 * the Lab/CIEDE2000 colour space is UMBRA_ERROR_UNSUPPORTED. */
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
