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
UMBRA_API size_t umbra_scalar_type_size(umbra_scalar_type type);

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

UMBRA_API void umbra_volume_desc_init(umbra_volume_desc *desc);

/* Copies the data to the device. Blocks until the upload is done. */
UMBRA_API umbra_status umbra_volume_create(umbra_context ctx, const umbra_volume_desc *desc,
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

UMBRA_API umbra_status umbra_volume_get_info(umbra_volume volume, umbra_volume_info *out);

UMBRA_API void umbra_volume_retain(umbra_volume volume);
UMBRA_API void umbra_volume_release(umbra_volume volume); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
