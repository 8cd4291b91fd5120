// SPDX-License-Identifier: Apache-2.0
/* examples/umbra_render.h: what umbra-render (examples/umbra_render.c) shares with umbra-view
 * (tools/umbra_view/): its command line and the scene set up from it, so that the viewer takes
 * every umbra-render option and opens every input the same way. umbra-view compiles
 * umbra_render.c a second time with UMBRA_RENDER_NO_MAIN. */
#ifndef UMBRA_EXAMPLES_UMBRA_RENDER_H
#define UMBRA_EXAMPLES_UMBRA_RENDER_H

#include <stdint.h>
#include <stdio.h>

#include "umbra/io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Everything the render needs; released in one place (session_end). */
typedef struct session {
    umbra_context ctx;
    umbra_scene scene;
    umbra_volume volume;
    umbra_transfer_function tf, light_tf;
    umbra_renderer renderer;
    float *pixels;
    /* As set on the renderer by session_begin / session_open: */
    umbra_volume view_volume;         /* borrowed: s->volume or s->scene.volume */
    umbra_transfer_function view_tf;  /* borrowed: s->tf or s->scene.tf */
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc options;
    umbra_shadow_desc shadow;
    uint32_t width, height;           /* --size */
    const char *out;                  /* --out, checked to be a writable .png or .exr path */
} session;

/* umbra-render's program: what its main does (examples/umbra_render.c, compiled with
 * UMBRA_RENDER_NO_MAIN, leaves main out and keeps this). */
int umbra_render_main(int argc, char **argv);

/* Prints umbra-render's option list. */
void usage(FILE *f);

/* Parses umbra-render's options (--help and --version print and exit(0)) and sets up s with a
 * renderer ready to render. Returns 0, or the exit status umbra-render would give (a message is
 * on stderr). s must be zeroed first and is released with session_end either way. */
int session_open(int argc, char **argv, session *s);
void session_end(session *s);

/* umbra-render's exit status for a failed library call: 1 bad input, 2 device or memory. */
int exit_status(umbra_status st);

#ifdef __cplusplus
}
#endif
#endif
