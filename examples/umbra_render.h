// SPDX-License-Identifier: Apache-2.0
/* examples/umbra_render.h: umbra-render's command line (examples/umbra_render_args.c), read by
 * the program itself (examples/umbra_render.c). */
#ifndef UMBRA_RENDER_H
#define UMBRA_RENDER_H

#include <stdint.h>

#include "umbra/io.h"

typedef struct options {
    const char *scene, *volume, *raw, *tf, *tf_preset, *light_tf, *out, *device;
    int platform_index, device_index; /* -1: not given */
    uint32_t scene_size, width, height;
    umbra_raw_desc raw_desc;
    int have_raw_dims, have_raw_type;
    float camera_dir[3], eye[3], target[3], up[3], fov, ortho;
    int have_camera_dir, have_eye, have_target, have_up;
    float light_dir[3], light_pos[3], light_color[3], ambient, step, background[4];
    int have_light_dir, have_light_pos, have_light_color, have_ambient, have_step;
    float tf_range[2];
    int have_tf_range;
    int shading, ground, colored, jitter, have_seed, have_background; /* -1: scene default */
    int preintegrated;
    umbra_interaction interaction;                                  /* --interaction */
    int progress;                                                   /* -1: when a terminal */
    uint32_t seed;
    umbra_shadow_desc shadow; /* the technique and every parameter given (registry keys) */
    const char *data_roots[1024]; /* --allow-data-root, borrowed from argv */
    size_t data_root_count;
} options;

/* Fills o from the command line. Returns 0, or prints what is wrong to stderr and returns 1 (bad
 * input). --help and --version print and exit(0). */
int parse_args(int argc, char **argv, options *o);

#endif
