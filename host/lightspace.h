// SPDX-License-Identifier: Apache-2.0
/* host/lightspace.h: the light-space map projection shared by the shadow-map techniques
 * (threshold, deep, CSSM). See kernels/common/lightspace.cl for the kernel side. */
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
 * in include/umbra/renderer.h); S->map_size holds the size used, which the builds must read.
 * Returns the map's texels per voxel of the box as the light sees it (CSSM's ray block follows
 * it; infinite for a box of no extent). */
double umbra__lightspace_setup(umbra_renderer r, uint32_t map_size);

/* The light step of a light-space map in voxels: desc->map.step where set, else (0, the default)
 * the technique's own (umbra_technique_info.map_step of desc->technique). The threshold map and
 * CSSM take one voxel, the deep map half a voxel. Measured with umbra-bench accuracy at auto map
 * sizes on all seven bench scenes (issue #12): a step of 1 instead of 0.5 left the threshold
 * map's RMSE at most 0.2% higher (3% lower on the spheres and the foot) for builds 0.66x-0.80x,
 * and CSSM's within 1.6% either way (its noise, not its step, sets its error) for builds
 * 0.64x-0.83x. Both find their event within a segment from the segment's optical depth, so the
 * step only sets where the volume is sampled: once a voxel, the data's own spacing. The deep
 * map's error grew 1.09x-1.24x at a step of 1 (its nodes follow the sampled visibility; docs/),
 * so it keeps 0.5. A map technique's light_step. */
float umbra__map_light_step(const umbra_shadow_desc *d);

/* The shared map parameters (umbra_shadow_desc.map), the first rows of every light-space map's
 * parameter table. */
#define UMBRA__MAP_PARAMS                                                                      \
    UMBRA__PARAM_KEYED(map, size, "map_size",                                                  \
                       .doc = "map resolution, map_size^2 texels; auto chooses it from the "  \
                              "volume's footprint as the light sees it, "                     \
                              "map_texels_per_voxel texels per voxel",                        \
                       .flags = UMBRA_PARAM_ZERO | UMBRA_PARAM_REBUILDS | UMBRA_PARAM_MAP,    \
                       .default_value = UMBRA_MAP_SIZE_AUTO, .min = 16, .max = 8192,           \
                       .zero_doc = "auto", .zero_name = "auto"),                               \
    UMBRA__PARAM_KEYED(map, texels_per_voxel, "map_texels_per_voxel",                          \
                       .doc = "at auto map size: texels per voxel across the box's "          \
                              "projection; 1 is a draft while the light moves",               \
                       .flags = UMBRA_PARAM_ZERO | UMBRA_PARAM_REBUILDS | UMBRA_PARAM_MAP,    \
                       .default_value = 0, .min = 0.25, .max = 8,                              \
                       .zero_doc = "the technique's own"),                                     \
    UMBRA__PARAM_KEYED(map, step, "map_step",                                                  \
                       .doc = "light-ray step",                                               \
                       .unit = "voxels",                                                       \
                       .flags = UMBRA_PARAM_ZERO | UMBRA_PARAM_REBUILDS | UMBRA_PARAM_MAP,    \
                       .default_value = 0, .min = 0.01, .max = 64,                             \
                       .zero_doc = "the technique's own")

#endif
