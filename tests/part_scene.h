// SPDX-License-Identifier: Apache-2.0
/* tests/part_scene.h: the scene the part tests (tests/test_part.c, tests/test_part_maps.c) split:
 * an analytic volume of two blobs and a ripple, its transfer function, cameras and lights, the
 * parts of a split and their renders against one device's render of the whole volume. */
#ifndef UMBRA_TESTS_PART_SCENE_H
#define UMBRA_TESTS_PART_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "test_util.h"
#include "umbra/part.h"

enum { NX = 40, NY = 36, NZ = 44, BS = 8, W = 48, H = 40 };

/* The largest difference measured on PoCL was 3.6e-7 (docs/distributed.md): float rounding of
 * the over operator against one ray's running sum. */
#define PART_BOUND 1e-6f

/* A scene: camera, light, options. */
typedef struct scene {
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc opts;
} scene;

float *scene_voxels(void);

umbra_transfer_function scene_tf(umbra_context ctx);

const char *take_message(umbra_context ctx);

void volume_desc(umbra_volume_desc *d, const float *data, uint32_t nx, uint32_t ny,
                 uint32_t nz);

scene make_scene(int ortho, int jitter, int shading, int point, int colored);

umbra_renderer scene_renderer(umbra_context ctx, umbra_volume v, umbra_transfer_function tf,
                              const scene *s);

float *render_whole(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                    const scene *s);

/* The voxels of [lo, lo + n) per axis of the global grid; voxels past the grid (a part that
 * overflows it, for the refusal tests) are 0. */
float *sub_box(const float *voxels, const uint32_t lo[3], const uint32_t n[3]);

/* The parts of a split: cuts[a] lists the inner cut positions along axis a (ncuts[a] of them);
 * extra_empty adds an empty part. */
uint32_t make_parts(const uint32_t *const cuts[3], const uint32_t ncuts[3], int extra_empty,
                    uint32_t ghost, umbra_part_desc *parts);

/* The part volume of part p of the scene's voxels: its core and ghost layers (one voxel for an
 * empty part), with the scene's volume description. */
umbra_volume part_volume(umbra_context ctx, const float *voxels, const umbra_part_desc *p);

/* A part volume and a renderer with the shadow sd for each of the n parts; *info gets the
 * volumes' info (the global grid's, the same for every part). */
void part_renderers(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                    const scene *s, const umbra_shadow_desc *sd, const umbra_part_desc *parts,
                    uint32_t n, umbra_volume *vols, umbra_renderer *rs, umbra_volume_info *info);

/* The light's march state passed through the parts in light order
 * (umbra_part_visibility_order): each part imports what the part before it exported (nothing
 * for the first) and exports its own into state (the light info's tau_floats floats). */
void pass_light(const scene *s, const umbra_part_desc *parts, uint32_t n,
                const umbra_volume_info *info, umbra_renderer *rs, float *state);

/* Counts the floats of a and b whose bits differ. */
size_t bits_differing(const float *a, const float *b, size_t count);

/* Renders every part in view order into one frame, each going on from the accumulation of the
 * parts in front (umbra_renderer_render_part_into), and puts the background under it. */
float *render_into_frame(const scene *s, umbra_renderer *rs, const uint32_t *order,
                         uint32_t n);

/* Renders every part, composites in view order, puts the background under it; *seq gets the
 * frame rendered part after part into one accumulation (render_into_frame). */
float *render_parts(umbra_context ctx, const float *voxels, umbra_transfer_function tf,
                    const scene *s, const umbra_part_desc *parts, uint32_t n, float **seq);

/* The inner cuts of the splits: x 16, y 24, z 16. */
extern const uint32_t CX[1], CY[1], CZ[1];

#endif
