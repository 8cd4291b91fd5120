// SPDX-License-Identifier: Apache-2.0
/* umbra/scene.h: built-in scenes made in code, needing no file.
 *
 *   "spheres"        translucent coloured spheres over a ground plane (the default scene)
 *   "slab"           a homogeneous slab, for analytic checks (transmittance exp(-sigma d))
 *   "marschner-lobb" the Marschner-Lobb test signal */
#ifndef UMBRA_SCENE_H
#define UMBRA_SCENE_H

#include <stdint.h>

#include "umbra/renderer.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_scene {
    umbra_volume volume;              /* owned: released by umbra_scene_release */
    umbra_transfer_function tf;       /* owned */
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc options;        /* suggested options (ground plane, transmission...) */
} umbra_scene;

/* Names of the built-in scenes, NULL-terminated. */
UMBRA_API const char *const *umbra_scene_names(void);

/* Builds scene name at resolution^3 voxels (0: the scene's default) on ctx. */
UMBRA_API umbra_status umbra_scene_create(umbra_context ctx, const char *name, uint32_t resolution,
                                          umbra_scene *out);

/* Releases the scene's volume and transfer function and zeroes it; NULL is a no-op. */
UMBRA_API void umbra_scene_release(umbra_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
