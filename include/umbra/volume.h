/* umbra/volume.h: scalar volumes on the device.
 *
 * A volume is a regular grid of scalars, x fastest, uploaded once. Values are mapped to [0,1]
 * through a value range (given, or the data's min and max) before transfer-function lookup. The
 * volume's box in world space is centred on the origin and measures dims * spacing. Per-brick
 * min/max values (bricks of brick_size^3 voxels) are kept for empty-space skipping. */
#ifndef UMBRA_VOLUME_H
#define UMBRA_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/context.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_volume_t *umbra_volume;

typedef enum umbra_scalar_type {
    UMBRA_UINT8 = 0,
    UMBRA_UINT16 = 1,
    UMBRA_INT16 = 2,
    UMBRA_FLOAT32 = 3
} umbra_scalar_type;

/* Bytes per voxel of type, or 0 for an unknown type. */
size_t umbra_scalar_type_size(umbra_scalar_type type);

typedef struct umbra_volume_desc {
    size_t struct_size;      /* sizeof(umbra_volume_desc); set by umbra_volume_desc_init */
    const void *data;        /* dims[0]*dims[1]*dims[2] voxels of type, x fastest; copied */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* world units per voxel, each > 0 (default 1) */
    int value_range_given;   /* 0 (default): value range is the data's min and max */
    float value_min, value_max; /* with value_range_given: maps value_min to 0, value_max to 1 */
    uint32_t brick_size;     /* edge of an empty-space-skipping brick in voxels (default 16) */
} umbra_volume_desc;

void umbra_volume_desc_init(umbra_volume_desc *desc);

/* Copies the data to the device. Blocks until the upload is done. */
umbra_status umbra_volume_create(umbra_context ctx, const umbra_volume_desc *desc,
                                 umbra_volume *out);

/* Loads a volume by file extension: .nrrd / .nhdr (Teem), .dat (Voreen). */
umbra_status umbra_volume_load(umbra_context ctx, const char *path, umbra_volume *out);

/* Loads NRRD, attached (.nrrd) or detached (.nhdr + one data file, relative to the header unless
 * absolute): types uchar, ushort, short and float; 3-D, or 4-D with a size-1 first axis; encodings
 * raw, gzip, zrl, ascii and hex. Spacing comes from the header's spacings or space directions (1
 * where absent). Teem parses the header, umbra reads the data. Header and data must be regular
 * files (a FIFO or device is UMBRA_ERROR_IO, never waited on); the declared sizes are checked
 * against the data before anything is allocated: raw data must fill the rest of its file exactly,
 * gzip can expand at most 1032:1 and zrl 16384:1 (else UMBRA_ERROR_FORMAT naming both sizes). */
umbra_status umbra_volume_load_nrrd(umbra_context ctx, const char *path, umbra_volume *out);

/* Loads a Voreen .dat header and its raw file (both regular files), which is looked up relative
 * to the .dat's directory. ObjectFileName, Resolution, SliceThickness and Format (UCHAR, USHORT, SHORT, FLOAT)
 * are required; ObjectModel, if present, must be I. */
umbra_status umbra_volume_load_dat(umbra_context ctx, const char *path, umbra_volume *out);

typedef struct umbra_raw_desc {
    size_t struct_size;      /* sizeof(umbra_raw_desc); set by umbra_raw_desc_init */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* default 1 */
    int big_endian;          /* 0 (default): little-endian */
    size_t header_bytes;     /* bytes to skip at the start of the file (default 0) */
} umbra_raw_desc;

void umbra_raw_desc_init(umbra_raw_desc *desc);

/* Loads a headerless raw file (a regular file, else UMBRA_ERROR_IO). The file must hold exactly header_bytes + dims product * type size
 * bytes; any other size is UMBRA_ERROR_FORMAT naming both numbers. */
umbra_status umbra_volume_load_raw(umbra_context ctx, const char *path, const umbra_raw_desc *desc,
                                   umbra_volume *out);

typedef struct umbra_volume_info {
    uint32_t dims[3];
    float spacing[3];
    float extent[3];         /* dims * spacing: the world-space box size */
    float value_min, value_max;
    uint32_t brick_size;
    uint32_t brick_counts[3];
    size_t device_bytes;     /* device memory held by the volume and its brick table */
} umbra_volume_info;

umbra_status umbra_volume_get_info(umbra_volume volume, umbra_volume_info *out);

void umbra_volume_retain(umbra_volume volume);
void umbra_volume_release(umbra_volume volume); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
