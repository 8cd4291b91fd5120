// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/convolution.h: the parameters of the slice-based convolution shadows
 * (technique "convolution", UMBRA_SHADOW_CONVOLUTION: ICS, and SCS with sub-samples). The
 * technique renders the frame itself with view-aligned slices, so it has no per-point lookup
 * (umbra_renderer_query_shadow). The light must come from the viewer's side: a directional light
 * within 80 degrees of the view direction, a point light from which every corner of the box lies
 * within 80 degrees of it; others give UMBRA_ERROR_UNSUPPORTED. The view step and jitter are not
 * used (the slices set the sampling); the ground plane is supported, and
 * umbra_render_desc.preintegrated attenuates the light with each segment's pre-integrated
 * transmittance. */
#ifndef UMBRA_TECHNIQUES_CONVOLUTION_H
#define UMBRA_TECHNIQUES_CONVOLUTION_H

#include <stdint.h>

typedef struct umbra_convolution_desc {
    float slice_distance;     /* voxels between slices, [0.02, 16] (default 0.5) */
    uint32_t subsamples;      /* SCS: volume samples between two slices, 0..64 (default 0); the
                                 volume is sampled every slice_distance / (subsamples + 1) and
                                 the light interpolated between the two slices */
    float cone_angle_degrees; /* half-angle of the cone the kernel spreads the light over per
                                 slice, [0, 60] (default 5; 0: no blur) */
} umbra_convolution_desc;

#endif
