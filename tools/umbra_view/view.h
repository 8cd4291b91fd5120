// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/view.h: umbra-view's state, shared by the window loop (main.c) and the panel
 * (panel.cpp). The renderer and everything it renders come from umbra-render's own set-up
 * (examples/umbra_render.h); the viewer keeps the copies of camera, light, options and shadow
 * description it edits and sets them on the renderer before the next frame. */
#ifndef UMBRA_VIEW_VIEW_H
#define UMBRA_VIEW_VIEW_H

#include <stdint.h>

#include "present.h"
#include "umbra_render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What changed since the last frame, to be set on the renderer. */
enum {
    VIEW_CHANGED_CAMERA = 1,
    VIEW_CHANGED_LIGHT = 2,
    VIEW_CHANGED_OPTIONS = 4,
    VIEW_CHANGED_SHADOW = 8,
    VIEW_CHANGED_TF = 16,
    VIEW_CHANGED_SIZE = 32,
    VIEW_CHANGED_CLIP = 64
};

typedef struct view_frame_times {
    double frame_ms;   /* the whole loop iteration: events, panel, render, upload, draw */
    double umbra_ms;   /* umbra_renderer_render, wall clock */
    double upload_ms;  /* sRGB encoding and texture upload */
    double draw_ms;    /* panel and frame drawn, buffers swapped */
} view_frame_times;

typedef struct viewer {
    session s;                 /* ctx, renderer, and camera/light/options/shadow as edited */
    present pr;
    struct GLFWwindow *window;
    unsigned changed;          /* VIEW_CHANGED_* since the last frame */
    float center[3], diagonal; /* the volume's box in the world */
    uint32_t width, height;    /* the frame, = the window's framebuffer */
    float *pixels;             /* the last frame, premultiplied RGBA floats */
    int have_frame;            /* the texture holds a frame */
    int pixels_ok;             /* pixels hold the frame the texture shows */
    int show_panel;
    int panel[4];              /* the panel's rectangle in window pixels (x, y from the top left,
                                  w, h), all 0 when hidden; set by panel_frame */
    /* Transfer function: the table being edited (4*tf_count floats), its data range if it has
     * one, and the function made from it that the renderer uses (owned; NULL: s.view_tf). */
    float *tf_rgba;
    uint32_t tf_count;
    int tf_has_range;
    float tf_range[2];
    float tf_curve_top;        /* the opacity at the top of the curve editor */
    umbra_transfer_function tf_edit;
    char **presets;            /* transfer-function files offered in the panel */
    unsigned n_presets;
    int preset;                /* index into presets, -1: the volume's or scene's own */
    /* The last frame. */
    umbra_render_stats stats;
    view_frame_times times;
    int draft;                 /* its shadows are a draft (a full frame follows when idle) */
    char message[1024];        /* the last error or notice, shown in the panel; "" when none */
    int message_is_error;
} viewer;

/* Makes the edited table (tf_rgba) the renderer's transfer function; 0 or -1 (message set). */
int viewer_tf_commit(viewer *v);
/* Loads preset k (or with k < 0 the volume's or scene's own function) into the editor and
 * commits it; 0 or -1 (message set). */
int viewer_tf_load(viewer *v, int k);
/* Turns a directional light into a point light at 1.5 box diagonals from the centre along the
 * light's way back, or a point light into a light travelling from where it was to the centre. */
void viewer_light_set_type(viewer *v, umbra_light_type type);
/* Writes the last frame to s.out (umbra_image_write: .png or .exr, as umbra-render would). */
void viewer_save_frame(viewer *v);

/* The panel (panel.cpp), Dear ImGui over GLFW and OpenGL 3. */
int panel_init(viewer *v);            /* 0, or -1 if the backends could not start */
void panel_shutdown(void);
void panel_frame(viewer *v);          /* starts a GUI frame; the panel edits v (v->changed) */
void panel_draw(viewer *v);           /* draws the frame's texture, then the panel */
int panel_wants_mouse(void);          /* the mouse is over the panel */
int panel_wants_keyboard(void);       /* a text field has the keyboard */

#ifdef __cplusplus
}
#endif
#endif
