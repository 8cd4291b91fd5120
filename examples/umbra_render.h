// SPDX-License-Identifier: Apache-2.0
/* examples/umbra_render.h: umbra-render's command line (examples/umbra_render_args.c) and the
 * scene it sets up from it (session_begin, examples/umbra_render.c), read by the program itself
 * and by umbra-view (tools/umbra_view/), which takes every umbra-render option through the same
 * parser, adds its own options to the same table, and opens every input the same way. umbra-view
 * compiles umbra_render.c a second time with UMBRA_RENDER_NO_MAIN. */
#ifndef UMBRA_RENDER_H
#define UMBRA_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/io.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct options {
    const char *program; /* the name messages start with: "umbra-render", or the program's */
    const char *scene, *volume, *raw, *tf, *tf_preset, *light_tf, *out, *device;
    int platform_index, device_index; /* -1: not given */
    uint32_t scene_size, width, height;
    umbra_raw_desc raw_desc;
    int have_raw_dims, have_raw_type;
    float camera_dir[3], eye[3], target[3], up[3], fov, ortho;
    int have_camera_dir, have_eye, have_target, have_up;
    float light_dir[3], light_pos[3], light_color[3], ambient, step, background[4];
    int have_light_dir, have_light_pos, have_light_color, have_ambient, have_step;
    float termination;                                              /* --termination */
    int have_termination;
    float tf_range[2];
    int have_tf_range;
    int shading, ground, colored, jitter, have_seed, have_background; /* -1: scene default */
    int preintegrated;
    umbra_interaction interaction;                                  /* --interaction */
    int have_interaction;                                           /* --interaction given */
    int progress;                                                   /* -1: when a terminal */
    uint32_t seed;
    umbra_shadow_desc shadow; /* the technique and every parameter given (registry keys) */
    const char *data_roots[1024]; /* --allow-data-root, borrowed from argv */
    size_t data_root_count;
    umbra_render_mode mode;       /* --mode */
    umbra_clip_desc clip;         /* --clip-plane, --crop */
    const char *channel_tf[UMBRA_MAX_CHANNELS - 1]; /* --channel-tf: channels 1.. */
    uint32_t channel_tf_count;
} options;

/* Fills o from the command line. Returns 0, or prints what is wrong to stderr and returns 1 (bad
 * input). --help and --version print and exit(0). */
int parse_args(int argc, char **argv, options *o);

/* A program that takes umbra-render's options and options of its own (umbra-view). */
typedef struct program_option {
    const char *name; /* the long option, without "--" */
    const char *arg;  /* the value's shape in --help ("N"), NULL for a flag */
    const char *help;
} program_option;

typedef struct program {
    const char *name;  /* what messages, --help's usage line and --version say */
    const char *about; /* a paragraph under --help's usage line, or NULL */
    const program_option *options; /* listed first in --help */
    size_t option_count;           /* at most 16 */
    /* Called for each of the program's options in the order given, with its index in options
     * and its value (NULL for a flag); returns 0, or prints what is wrong and returns 1. */
    int (*take)(void *user, size_t index, const char *value);
    void *user;
} program;

/* parse_args for program p: its options join umbra-render's in the one getopt_long table (so
 * --opt=value and unambiguous prefixes work for both, and a prefix of two is refused), and
 * messages, --help and --version name p->name. */
int parse_args_as(const program *p, int argc, char **argv, options *o);

/* A technique parameter (umbra/registry.h) as --help describes it: "doc, in unit (default D;
 * range or allowed values, or 0: what 0 means)", into text (size bytes, truncated). */
void param_describe(const umbra_param_info *p, char *text, size_t size);
/* The option that sets parameter p to value, as parse_args reads it: "--map-size auto",
 * "--no-lookup-table", "--map-step 0.5" (floats with 9 digits: the value exactly). */
void param_option_text(const umbra_param_info *p, double value, char *text, size_t size);

/* Everything a render needs; released in one place (session_end). */
typedef struct session {
    umbra_context ctx;
    umbra_scene scene;
    umbra_volume volume;
    umbra_transfer_function tf, light_tf;
    umbra_transfer_function channel_tf[UMBRA_MAX_CHANNELS - 1]; /* --channel-tf */
    umbra_renderer renderer;
    float *pixels;
    /* As set on the renderer by session_begin: */
    umbra_volume view_volume;        /* borrowed: volume or scene.volume */
    umbra_transfer_function view_tf; /* borrowed: tf or scene.tf */
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc options;
    umbra_shadow_desc shadow;
    umbra_clip_desc clip;            /* --clip-plane, --crop */
    uint32_t width, height;          /* --size */
    const char *out;                 /* --out, checked to be a writable .png or .exr path */
} session;

/* Sets up s from o: context (its errors printed as "<o->program>: ..."), volume or scene,
 * transfer functions, camera, light, options and shadow technique, on a renderer ready to
 * render. Returns 0 or umbra-render's exit status (the message is on stderr). s must be zeroed
 * first and is released with session_end either way. */
int session_begin(const options *o, session *s);
/* session_begin in two steps: session_open makes s->ctx (quiet: no error callback, nothing
 * printed; the status is returned, the message is on the context when there is one), and
 * session_setup does the rest; a volume already in s->volume (made on s->ctx by the caller) is
 * used instead of o->volume or o->raw, which must still name it. */
umbra_status session_open(const options *o, session *s, int quiet);
int session_setup(const options *o, session *s);
void session_end(session *s);

/* umbra-render's exit status for a failed library call: 1 bad input, 2 device or memory. */
int exit_status(umbra_status st);

/* umbra-render's program: what its main does (compiled with UMBRA_RENDER_NO_MAIN,
 * umbra_render.c leaves main out and keeps this). */
int umbra_render_main(int argc, char **argv);

#ifdef __cplusplus
}
#endif
#endif
