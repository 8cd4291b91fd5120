// SPDX-License-Identifier: Apache-2.0
/* io/nifti.h: the NIfTI reader's host-side result, shared by io/nifti.c and the tests.
 *
 * umbra_volume_load_nifti reads the voxels straight into the volume's buffer; umbra__nifti_read
 * (the tests') reads them into host memory, and this structure also keeps the file's
 * index-to-world matrix, how it was chosen and the scaling applied. */
#ifndef UMBRA_IO_NIFTI_H
#define UMBRA_IO_NIFTI_H

#include <stdint.h>

#include "io_internal.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where index_to_world came from (NIfTI's "methods"). */
typedef enum umbra__nifti_transform {
    UMBRA__NIFTI_PIXDIM = 1, /* neither code set: diag(pixdim), no origin */
    UMBRA__NIFTI_QFORM = 2,  /* qform_code > 0: quaternion, offsets and qfac */
    UMBRA__NIFTI_SFORM = 3   /* sform_code > 0: the srow_x/y/z affine */
} umbra__nifti_transform;

typedef struct umbra__nifti_volume {
    void *voxels;             /* malloc'ed, dims product of type, x fastest */
    umbra_scalar_type type;
    uint32_t dims[3];
    float spacing[3];         /* lengths of index_to_world's first three columns */
    /* (x, y, z, 1) = index_to_world (i, j, k, 1): voxel centre (i, j, k) in the file's world
     * (RAS+ millimetres by the NIfTI convention), row-major. */
    double index_to_world[4][4];
    umbra__nifti_transform transform;
    double slope, inter;      /* scaling applied to the voxels (1 and 0 when none) */
} umbra__nifti_volume;

/* Reads path into *out (voxels converted and scaled as umbra_volume_load_nifti documents). func
 * names the public function in messages. On failure *out holds nothing to free. */
umbra_status umbra__nifti_read(umbra_context ctx, const char *func, const char *path,
                               umbra__nifti_volume *out);

/* Frees out->voxels; out may be NULL. */
void umbra__nifti_volume_free(umbra__nifti_volume *out);

#ifdef __cplusplus
}
#endif
#endif
