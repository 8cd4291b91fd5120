// SPDX-License-Identifier: Apache-2.0
/* umbra/volume.h: scalar volumes on the device.
 *
 * A volume is a regular grid of scalars, x fastest, uploaded once. Values are mapped to [0,1]
 * through a value range (given, or the data's min and max) before transfer-function lookup.
 * Per-brick min/max values (bricks of brick_size^3 voxels) are kept for empty-space skipping.
 *
 * World coordinates. Samples are cell centres: the volume's box reaches half a voxel beyond the
 * outer samples and measures dims * spacing. By default the box is centred on the world origin
 * with index axes i, j, k along x, y, z, so voxel (i, j, k) lies at
 *     ((i + 0.5 - dims[0]/2) spacing[0], (j + 0.5 - dims[1]/2) spacing[1], ...).
 * With an index-to-world transform (desc.transform_given, or a NRRD's space origin and space
 * directions) voxel (i, j, k) lies at
 *     origin + i spacing[0] d0 + j spacing[1] d1 + k spacing[2] d2
 * for unit, mutually orthogonal axis directions d0, d1, d2 (a rotation, or a rotation with a
 * mirror). The renderer's camera, light, ground plane and query points are in this world. */
#ifndef UMBRA_VOLUME_H
#define UMBRA_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/context.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_volume_t *umbra_volume;

/* Bound on a volume's world extent, dims * spacing, along each axis: within it the box, its
 * diagonal and a camera framing it stay finite in float. umbra_volume_create (and the loaders)
 * refuse a larger volume with UMBRA_ERROR_INVALID_ARGUMENT naming the extent. */
#define UMBRA_MAX_EXTENT 1e15f

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
    const void *data;        /* dims[0]*dims[1]*dims[2] voxels of type, x fastest; copied.
                                Float voxels must be finite, with or without a given range:
                                UMBRA_ERROR_INVALID_ARGUMENT names the first NaN or infinity */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];        /* world units per voxel, each finite and > 0 (default 1);
                                dims * spacing at most UMBRA_MAX_EXTENT */
    int value_range_given;   /* 0 (default): value range is the data's min and max (a constant
                                volume maps to 0); the mapping is computed in double, so any
                                finite float range works, +-3e38 included */
    float value_min, value_max; /* with value_range_given: maps value_min to 0, value_max to 1;
                                finite, max > min */
    uint32_t brick_size;     /* edge of an empty-space-skipping brick in voxels (default 16) */
    /* Index-to-world transform (see the top of this file). 0 (default): the centred box. */
    int transform_given;
    float origin[3];         /* world position of voxel (0, 0, 0)'s centre */
    float directions[9];     /* world direction of index axis a in directions[3a .. 3a+2]; each
                                non-zero (normalised here) and at most 0.06 degrees from a
                                right angle to the others (snapped to exact right angles); a
                                sheared grid is UMBRA_ERROR_UNSUPPORTED naming the angle */
} umbra_volume_desc;

/* Fills desc with the defaults given beside each field (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_volume_desc_init(umbra_volume_desc *desc);

/* Copies the data to the device, in its own type (1, 2 or 4 bytes per voxel; see
 * umbra_volume_info.device_bytes). Reads desc->data once, in parallel, and keeps no pointer to
 * it. Blocks until the upload is done. A volume larger than the device's largest allocation (or
 * 3D image) is split into up to 8 z-slabs, drawn seamlessly; UMBRA_ERROR_OUT_OF_MEMORY, naming
 * the sizes, when it would not fit the device's global memory or 8 slabs; at most 2^36 voxels. */
UMBRA_API umbra_status umbra_volume_create(umbra_context ctx, const umbra_volume_desc *desc,
                                           umbra_volume *out);

/* Writes the volume's voxels, dims[0]*dims[1]*dims[2] of desc->type, x fastest, into dst (bytes
 * long, borrowed for the call). Returns UMBRA_SUCCESS, or a failure status it has recorded on the
 * context (umbra_context_record_error), which umbra_volume_create_filled returns. */
typedef umbra_status (*umbra_volume_fill_fn)(void *user, void *dst, size_t bytes);

/* umbra_volume_create for voxels that are not in memory yet (a file being read): desc->data must
 * be NULL, and fill(user, dst, bytes) writes them, once, where the device reads them where it can
 * (the buffer sampler's mapped buffer: on a CPU device the voxels then exist once, with no host
 * copy), else into a host buffer freed before return. Blocks. */
UMBRA_API umbra_status umbra_volume_create_filled(umbra_context ctx, const umbra_volume_desc *desc,
                                                  umbra_volume_fill_fn fill, void *user,
                                                  umbra_volume *out);

typedef struct umbra_volume_info {
    uint32_t dims[3];
    float spacing[3];
    float extent[3];         /* dims * spacing: the world-space box size */
    float value_min, value_max;
    uint32_t brick_size;
    uint32_t brick_counts[3];
    size_t device_bytes;     /* device memory held by the voxels: the input type's size per
                                voxel (an image sampler without a UNORM format for it, or a
                                float range too wide for float math, stores 4), plus the
                                buffer's pad element, and for a volume in several slabs the
                                layers neighbouring slabs share */
    int transform_given;     /* nonzero if the volume was made with an index-to-world transform */
    float origin[3];         /* world position of voxel (0, 0, 0)'s centre (also for the centred
                                box: (0.5 - dims/2) * spacing) */
    float directions[9];     /* unit world direction of index axis a in directions[3a .. 3a+2]
                                (the identity for the centred box) */
    float center[3];         /* world position of the box's centre (0 for the centred box) */
} umbra_volume_info;

/* Describes volume in *out (sizes, world placement, value range, device memory).
 * UMBRA_ERROR_INVALID_ARGUMENT for NULL volume or out. */
UMBRA_API umbra_status umbra_volume_get_info(umbra_volume volume, umbra_volume_info *out);

UMBRA_API void umbra_volume_retain(umbra_volume volume);
UMBRA_API void umbra_volume_release(umbra_volume volume); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
