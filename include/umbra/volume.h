// SPDX-License-Identifier: Apache-2.0
/* umbra/volume.h: scalar volumes on the device.
 *
 * A volume is a regular grid of scalars, x fastest, uploaded once (and changed in place by
 * umbra_volume_update). Values are mapped to [0,1] through a value range (given, or the data's
 * min and max) before transfer-function lookup. Per-brick min/max values (bricks of
 * brick_size^3 voxels) are kept for empty-space skipping.
 *
 * Two kinds besides the plain scalar volume (docs/features.md says which technique renders
 * which): a multi-channel volume (channels 2 to UMBRA_MAX_CHANNELS: several scalars per voxel,
 * say a microscope's stains, each with its own value range and transfer function,
 * umbra_renderer_set_channel_transfer_function) and a label map (labels: integer labels, a
 * segmentation, sampled at the nearest voxel, each label's colour and opacity the entry of that
 * index in the transfer function).
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

/* The most channels a volume may have, and the most labels a label map may hold (labels 0 to
 * UMBRA_MAX_LABELS - 1: uint16 voxels). */
#define UMBRA_MAX_CHANNELS 4
#define UMBRA_MAX_LABELS 65536u

typedef struct umbra_volume_desc {
    size_t struct_size;      /* sizeof(umbra_volume_desc); set by umbra_volume_desc_init (the
                                layout before channels, offsetof(umbra_volume_desc, channels), is
                                accepted with one channel and no labels) */
    const void *data;        /* dims[0]*dims[1]*dims[2] voxels of type, x fastest (with several
                                channels, channels values per voxel, channel fastest); copied.
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
    uint32_t channels;       /* values per voxel, 1 (default) to UMBRA_MAX_CHANNELS. Each channel
                                has its own value range (the given one for all, or each its
                                data's) and is stored apart on the device; a multi-channel
                                volume is kept in one device buffer on every sampler, so all its
                                channels must fit one allocation (else UMBRA_ERROR_OUT_OF_MEMORY
                                naming the sizes) */
    int labels;              /* nonzero: a label map. The voxels (uint8 or uint16, one channel)
                                are labels, sampled at the nearest voxel without interpolation;
                                the value range is not used; kept in a device buffer on every
                                sampler (default 0) */
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
    /* Appended after umbra 0.5. */
    uint32_t channels;       /* values per voxel (value_min, value_max are channel 0's) */
    int labels;              /* nonzero for a label map */
    float channel_min[UMBRA_MAX_CHANNELS], channel_max[UMBRA_MAX_CHANNELS]; /* each channel's
                                value range (unused channels 0) */
    uint64_t version;        /* 0 when made, one more for each umbra_volume_update */
    umbra_scalar_type type;  /* the voxels' type as given at creation (umbra_volume_update's
                                data is of this type) */
} umbra_volume_info;

/* Describes volume in *out (sizes, world placement, value range, device memory).
 * UMBRA_ERROR_INVALID_ARGUMENT for NULL volume or out. */
UMBRA_API umbra_status umbra_volume_get_info(umbra_volume volume, umbra_volume_info *out);

/* A change of a volume's voxels in place: a sub-box, or (size 0) all of them, e.g. the next
 * time step of a series. */
typedef struct umbra_volume_update_desc {
    size_t struct_size;      /* sizeof(umbra_volume_update_desc); set by
                                umbra_volume_update_desc_init */
    const void *data;        /* size[0]*size[1]*size[2] voxels of the volume's type (x fastest,
                                channels interleaved as at creation); copied. Float voxels must
                                be finite */
    uint32_t origin[3];      /* the sub-box's first voxel (default 0) */
    uint32_t size[3];        /* its voxels per axis, each > 0 and origin + size <= dims; all 0
                                (default): the whole volume (origin must then be 0) */
} umbra_volume_update_desc;

/* Fills desc with the defaults given beside each field (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_volume_update_desc_init(umbra_volume_update_desc *desc);

/* Writes desc's voxels into volume, in place: the dims, type, channels, value range (the mapping
 * to [0,1] made at creation: values outside it now clamp, so give a value range covering the
 * series at creation), bricks and placement stay. Blocks until the voxels are on the device.
 * What each renderer keeps is invalidated as little as it can be: the empty-space-skipping
 * ranges of the bricks and sub-cells the box touches are recomputed (read back from the device
 * around the box), and a renderer remakes its visibility tables only if some range changed; the
 * light structures (shadow maps, every technique's) rebuild at the next render; transfer-
 * function tables, resampled transfer functions, programs and pre-integration tables stay. A
 * render after the update equals, bit for bit, one of a volume made from the updated voxels
 * with the same value range. Commands already queued (an asynchronous frame) run first and see
 * the old voxels; like a shadow build, the call waits for them. The volume must not be rendered
 * on another thread during the call. A bad desc (a box outside the volume, NaN voxels) is
 * refused with UMBRA_ERROR_INVALID_ARGUMENT naming the value and leaves the volume unchanged;
 * on a volume stored as a UNORM 3D image (the image sampler) an update with values outside the
 * value range is UMBRA_ERROR_UNSUPPORTED (that storage cannot clamp before it filters). */
UMBRA_API umbra_status umbra_volume_update(umbra_volume volume,
                                           const umbra_volume_update_desc *desc);

UMBRA_API void umbra_volume_retain(umbra_volume volume);
UMBRA_API void umbra_volume_release(umbra_volume volume); /* NULL is a no-op */

#ifdef __cplusplus
}
#endif
#endif
