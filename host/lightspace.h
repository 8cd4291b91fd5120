// SPDX-License-Identifier: Apache-2.0
/* host/lightspace.h: the light-space map projection shared by the shadow-map techniques
 * (threshold, deep, CSSM). See kernels/lightspace.cl for the kernel side. */
#ifndef UMBRA_LIGHTSPACE_H
#define UMBRA_LIGHTSPACE_H

#include "renderer_internal.h"

/* Fills the ls_* fields, near_far and map_size of r->shadow_params for the renderer's light and
 * volume box (umbra__frame_update_light must have run). Directional lights get an orthographic
 * map fitted to the box's projection; a point light outside the box a perspective frustum fitted
 * to the box (if its half-angle stays under 70 degrees); a point light on, inside or close to the
 * box an octahedral map over all directions, so no light position is singular. Depth is
 * normalised to [0,1] between the box's nearest and farthest points along the light. map_size
 * UMBRA_MAP_SIZE_AUTO chooses the size from the box's footprint as the light sees it (the rule is
 * in include/umbra/renderer.h); S->map_size holds the size used, which the builds must read. */
void umbra__lightspace_setup(umbra_renderer r, uint32_t map_size);

/* The checks every light-space map makes of desc (map_size, map_texels_per_voxel, map_step), for
 * umbra_renderer_set_shadow; name is the technique's, for the message. */
umbra_status umbra__lightspace_validate(umbra_renderer r, const umbra_shadow_desc *d,
                                        const char *name);

#endif
