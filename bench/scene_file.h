// SPDX-License-Identifier: Apache-2.0
/* bench/scene_file.h: the bench's scene files (bench/scenes/NAME.scene).
 *
 * A scene file states everything that fixes one benchmark image: the volume, its transfer
 * function(s), camera, light, image size, view step, transmission mode, shading and ground plane.
 * The format (documented for users in bench/README.md), one "key value..." item per line, '#'
 * starts a comment, blank lines are ignored, numbers in the "C" locale:
 *
 *   volume builtin NAME [RES]   a built-in scene (umbra/scene.h) at RES^3 voxels (0: its default)
 *   volume FILE                 a .nhdr/.nrrd/.dat file: absolute, or relative to the data
 *                               directory ($UMBRA_DATA_DIR, else <source>/../shared/data/volumes)
 *   tf FILE | builtin           transfer function (text format of io/tf_file.c), relative to the
 *                               scene file's directory; builtin (the default for built-in volumes)
 *                               keeps the built-in scene's own
 *   light_tf FILE               optional separate transfer function for the light pass
 *   description TEXT...         one line for the summary
 *   units diagonal | world      unit of eye, target, ortho_height and light_position: multiples
 *                               of the volume box's diagonal (default) or world units; eye,
 *                               target and light_position are relative to the box's centre
 *   camera perspective | orthographic
 *   eye X Y Z / target X Y Z / up X Y Z / fov DEG / ortho_height H
 *   light point | directional
 *   light_position X Y Z / light_direction X Y Z / light_color R G B
 *   size W H                    image size of the full sweep (--quick caps the longer side)
 *   step S                      view sampling step in voxels
 *   reference_step S            shadow-ray step of the exact reference image (default 0.25)
 *   termination T               early ray termination opacity
 *   transmission grey | colored
 *   shading on | off / kd K / ks K / shininess N / ambient A [A A]
 *   ground on | off / ground_color R G B / ground_offset F
 *   background R G B A          premultiplied
 *   quick yes | no              whether --quick includes this scene (default no)
 *   papers cssm | deep | cssm,deep | no
 *                               the seed papers' settings the full sweep adds for this scene:
 *                               cssm = 2048^2 and 4096^2 maps (CSSM paper, Tables 3-4), deep =
 *                               the deep-map paper's Table 1 settings (default no)
 *
 * A built-in volume takes every item the file leaves out from the built-in scene (its camera,
 * light and options). A volume file needs tf, light and eye; what else is left out takes the
 * renderer defaults (umbra_render_desc_init), a perspective camera with up (0,1,0) and fov 30
 * looking at the origin, and a white light. Each key may appear once. */
#ifndef UMBRA_BENCH_SCENE_FILE_H
#define UMBRA_BENCH_SCENE_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/io.h"

#define SCENE_PATH_MAX 4096
#define SCENE_PAPERS_CSSM 1
#define SCENE_PAPERS_DEEP 2
#define SCENE_NAME_MAX 64

typedef struct scene_spec {
    char name[SCENE_NAME_MAX];         /* the file's stem ("walnut") */
    char path[SCENE_PATH_MAX];         /* the scene file */
    char description[256];
    int builtin;                       /* nonzero: volume names a built-in scene */
    char volume[SCENE_PATH_MAX];       /* built-in name, or the resolved volume path */
    uint32_t builtin_resolution;
    char tf[SCENE_PATH_MAX];           /* resolved path; "" with tf_builtin */
    int tf_builtin;
    char light_tf[SCENE_PATH_MAX];     /* resolved path or "" */
    int units_world;

    int have_projection, have_eye, have_target, have_up, have_fov, have_ortho;
    umbra_projection projection;
    float eye[3], target[3], up[3], fov, ortho_height;

    int have_light_type, have_light_position, have_light_direction, have_light_color;
    umbra_light_type light_type;
    float light_position[3], light_direction[3], light_color[3];

    uint32_t width, height;            /* 0: not given (512 x 512) */
    float step, reference_step, termination; /* 0: not given */
    int transmission;                  /* -1: not given */
    int shading, ground;               /* -1: not given */
    int have_kd, have_ks, have_shininess, have_ambient, have_ground_color, have_ground_offset,
        have_background;
    float kd, ks, shininess, ambient[3], ground_color[3], ground_offset, background[4];
    int quick;
    int papers;                        /* SCENE_PAPERS_* bits */

    uint64_t hash;                     /* FNV-1a of the scene file and its tf files' contents */
} scene_spec;

/* The directory volume files are resolved against: $UMBRA_DATA_DIR if set and not empty, else
 * source_dir/../shared/data/volumes. Writes into buf (size bytes). */
void scene_data_dir(const char *source_dir, char *buf, size_t size);

/* Parses scene text (NUL-terminated) named path (used for the stem, for messages and to resolve
 * relative tf paths) with volumes resolved against data_dir. Returns 0, or -1 with a message
 * "path:line: what is wrong" in err (err_size bytes). Does not open any file, except that with
 * hash_files nonzero the tf files' contents are added to spec->hash (a missing tf file is then an
 * error naming it). */
int scene_parse_text(const char *text, const char *path, const char *data_dir, int hash_files,
                     scene_spec *spec, char *err, size_t err_size);

/* Reads and parses the file at path (as above, with hash_files set). */
int scene_parse_file(const char *path, const char *data_dir, scene_spec *spec, char *err,
                     size_t err_size);

/* Nonzero when the scene's volume file exists (always for built-in volumes). */
int scene_volume_present(const scene_spec *spec);

/* 64-bit FNV-1a of n bytes, continuing from h (start with SCENE_HASH_INIT). */
#define SCENE_HASH_INIT 14695981039346656037ull
uint64_t scene_hash_bytes(uint64_t h, const void *data, size_t n);

/* Creates the scene on ctx: volume, transfer functions, camera, light and options (the light
 * transfer function, if any, goes to *light_tf; release it with umbra_transfer_function_release).
 * On failure the reason is on ctx (umbra_context_last_message) and nothing is left allocated. */
umbra_status scene_create(umbra_context ctx, const scene_spec *spec, umbra_scene *scene,
                          umbra_transfer_function *light_tf);

#endif
