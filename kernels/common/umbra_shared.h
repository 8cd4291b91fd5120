// SPDX-License-Identifier: Apache-2.0
/* kernels/common/umbra_shared.h: structs shared by the host and the kernels.
 *
 * This file is compiled twice: as C by the host (the host modules include it) and as OpenCL C, prepended
 * to every program. Only fixed-width scalars and arrays of them appear here, so the layout is the
 * same on both sides; the host checks the sizes with _Static_assert. Vectors are stored as
 * float[4] and read in kernels with the F3() macro. */
#ifndef UMBRA_SHARED_H
#define UMBRA_SHARED_H

#ifdef __OPENCL_VERSION__
#ifndef UMBRA_PART
#define UMBRA_PART 0 /* 1: the volume is a part of a global grid (umbra/part.h) */
#endif
typedef uint uint32_t;
typedef int int32_t;
#define F3(a) ((float3)((a)[0], (a)[1], (a)[2]))
#else
#include <stdint.h>
#endif

/* Empty-space skipping: each brick of the volume is split into UMBRA_BRICK_CELLS^3 sub-cells of
 * ceil(brick_size / UMBRA_BRICK_CELLS) voxels, one bit each (x fastest) of a 64-bit mask per
 * brick, for the view and for the light transfer function. View rays, the reference's shadow
 * rays and the threshold and CSSM maps' light rays walk the grid of sub-cells, crossing a brick
 * with no visible cell in one step, and take samples only in visible cells (CellWalk,
 * kernels/common/common.cl); host/volume.c keeps the cells' ranges. */
#define UMBRA_BRICK_CELLS 4

/* The frame's sample counter (umbra_render_stats.samples) in UMBRA_COUNT_LANES lanes
 * UMBRA_COUNT_LANE_BYTES apart, each work-group adding to one (UMBRA_COUNT_ADD,
 * kernels/common/common.cl) and the host summing them: with one counter the cores of a CPU
 * device passed its cache line back and forth for every pixel's atomic add, 2.7% of the
 * walnut's unshaded frame on PoCL (docs/performance.md). A lane is read as a 64-bit value; a
 * device without 64-bit atomics counts in its low 32 bits, the high ones stay 0. */
#define UMBRA_COUNT_LANES 8
#define UMBRA_COUNT_LANE_BYTES 128

/* Flags in UmbraFrame.flags. */
#define UMBRA_FLAG_JITTER 1u
#define UMBRA_FLAG_SKIP_EMPTY 2u
#define UMBRA_FLAG_SHADING 4u
#define UMBRA_FLAG_GROUND 8u
#define UMBRA_FLAG_ORTHO 16u
#define UMBRA_FLAG_COLORED 32u
#define UMBRA_FLAG_POINT_LIGHT 64u
/* A part's view rays go on from the colour and opacity the parts in front of it accumulated,
 * read from the output buffer (umbra_renderer_render_part_into, host/part_render.c). */
#define UMBRA_FLAG_PART_FRONT 128u

/* A volume of several channels, or a label map (kernels/common/channels.cl; host/channels.c
 * fills it). Channel c's voxels follow channel c - 1's in the one volume buffer, each channel
 * dims[0] dims[1] dims[2] voxels and a pad element long, normalised through its own value map
 * (UmbraFrame.value_map's three numbers); its view and light tables are entries [at, at + n) of
 * the view and light tables. A label map is one channel whose voxels are labels: entry l of the
 * tables is label l's colour and opacity, labels at or past n are transparent. count 1, labels
 * 0: a plain volume, which reads none of this. */
#define UMBRA_MAX_CHANNELS 4
typedef struct UmbraChannels {
    float value_map[UMBRA_MAX_CHANNELS][4];
    uint32_t view_at[UMBRA_MAX_CHANNELS], view_n[UMBRA_MAX_CHANNELS];
    uint32_t light_at[UMBRA_MAX_CHANNELS], light_n[UMBRA_MAX_CHANNELS];
    uint32_t count;        /* channels, 1 to UMBRA_MAX_CHANNELS */
    uint32_t labels;       /* 1: a label map */
    uint32_t pad[2];
} UmbraChannels;

/* Everything one view-space frame needs: camera, volume geometry, light and shading. World space
 * has the volume's box centred on the origin; "voxel coordinates" put voxel i's centre at i. */
typedef struct UmbraFrame {
    float eye[4];          /* camera position (perspective) or view-plane centre (ortho) */
    float right[4];        /* image-plane x axis, scaled to half the view width at distance 1 */
    float up[4];           /* image-plane y axis, scaled to half the view height at distance 1 */
    float forward[4];      /* unit viewing direction */
    float box_min[4];      /* world-space box of the volume: -extent/2 */
    float box_max[4];      /* +extent/2 */
    float inv_spacing[4];  /* 1 / spacing: world -> voxel units */
    float light[4];        /* point light position, or directional light's unit travel direction */
    float light_color[4];
    float ambient[4];
    float background[4];
    float ground_color[4];
    float ground[4];       /* ground plane n.x + d = 0 as (n, d), n unit, facing +y */
    float value_map[4];    /* stored voxel -> normalised value: clamp((s * [2] - [0]) * [1], 0, 1)
                              for the sampler's stored value s (kernels/common/sampling.cl) */
    int32_t dims[4];       /* voxels per axis */
    int32_t bricks[4];     /* bricks per axis; [3] = brick edge in voxels */
    uint32_t width, height;
    uint32_t flags;
    uint32_t seed;
    float step;            /* view-ray step, world units */
    float step_ref;        /* reference step of the transfer function's alpha (one voxel), world */
    float termination;     /* early ray termination threshold on accumulated opacity */
    float kd, ks, shininess;
    uint32_t tf_size, light_tf_size;
    UmbraChannels ch;      /* a multi-channel volume's channels, or a label map */
    /* A part of a global grid (programs built with UMBRA_PART 1, host/part_render.c): dims
     * above are the global grid's; the carried voxels start at global voxel part_shift
     * (offset - ghost_lo) and number part_dims; the part owns the view samples at voxel
     * coordinates x with part_lo <= x + 0.5 < part_hi (-inf and +inf at the global grid's outer
     * faces). Zero for a whole volume. */
    int32_t part_shift[4];
    int32_t part_dims[4];
    float part_lo[4];
    float part_hi[4];
} UmbraFrame;

/* The clip region (umbra_renderer_set_clip, filled by host/clip.c in the volume's local frame):
 * the points inside the crop box [box_min, box_max] (the volume's box when no crop box is set)
 * and on the kept side n.p + w >= 0 of each of the plane_count planes (n, w), n unit: a convex
 * region, so every ray crosses it in one interval (clip_interval, kernels/common/common.cl). View
 * rays, every light ray and shadow ray and the convolution technique's slices read it: a clipped
 * region is neither seen nor casts a shadow. active 0 (nothing clipped) skips it all. */
#define UMBRA_CLIP_PLANES 6
typedef struct UmbraClip {
    float box_min[4], box_max[4];
    float planes[UMBRA_CLIP_PLANES][4];
    uint32_t active;
    uint32_t plane_count;
    uint32_t pad[2];
} UmbraClip;

/* Light-space map projections (UmbraShadow.ls_mode). */
#define UMBRA_LS_ORTHO 0u       /* directional light: parallel rays, map on a plane */
#define UMBRA_LS_PERSPECTIVE 1u /* point light outside the box: a frustum around it */
#define UMBRA_LS_OCTAHEDRAL 2u  /* point light at, inside or very near the box: every direction */

/* What every technique's light pass shares, filled by the renderer (step) and, for the
 * light-space maps, by host/lightspace.c (the ls_* fields, near_far, map_size), which
 * kernels/common/lightspace.cl reads. Each technique's own parameters go to the kernels in a
 * struct of its own (kernels/techniques/<name>_shared.h), which its bind function passes. */
typedef struct UmbraShadow {
    float ls_u[4], ls_v[4], ls_w[4]; /* light basis: u, v across the map, w along the light */
    float ls_origin[4];       /* point light position */
    float ls_window[4];       /* u_min, v_min, 1/(u_max-u_min), 1/(v_max-v_min): plane units
                                 (ortho) or tangents (perspective) */
    float near_far[4];        /* depth range along the light: near, far, 1/(far-near), unused */
    float step;               /* the light-ray (or the reference's shadow-ray) step, world units */
    uint32_t map_size;        /* light-space maps: texels per side */
    uint32_t ls_mode;         /* light-space maps: UMBRA_LS_* */
    uint32_t pad;
    UmbraClip clip;           /* the clip region, which view rays and light rays share */
} UmbraShadow;

#endif
