// SPDX-License-Identifier: Apache-2.0
/* umbra-view: the interactive viewer. Opens what umbra-render opens (every volume format umbra_io
 * reads, or a built-in --scene) with all of umbra-render's options, shows it in a window and
 * re-renders whenever the camera, light, technique, parameters or transfer function change:
 *
 *   left drag: orbit    middle drag or shift+left: pan    wheel: zoom
 *   right drag or ctrl+left: move the light (directional or point)
 *   S: write the frame to --out    G or Tab: panel on/off    P: print the view as umbra-render
 *   options    R: back to the first view    Esc: quit
 *
 * --snapshot OUT.png renders until the shadows are full quality, writes the window's pixels and
 * exits; --frames N --orbit camera|light first replays an orbit of N frames and prints each
 * frame's times; --no-gui hides the panel. Exit status as umbra-render's: 0, 1 bad input, 2 a
 * failure of the device, of memory or of the window. */
#define _POSIX_C_SOURCE 200809L
#include <GLFW/glfw3.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "navigate.h"
#include "view.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* ---- the viewer's own options, in umbra-render's parser's table (umbra_render.h) ----------- */

typedef struct view_options {
    const char *snapshot; /* --snapshot OUT.png */
    int no_gui;
    uint32_t frames;      /* --frames N: the replay's length, 0: none */
    int orbit_light;      /* --orbit light (else camera) */
} view_options;

enum { VIEW_OPT_SNAPSHOT, VIEW_OPT_FRAMES, VIEW_OPT_ORBIT, VIEW_OPT_NO_GUI };

static const program_option view_option_list[] = {
    [VIEW_OPT_SNAPSHOT] = {"snapshot", "OUT.png", "render until the shadows are full quality, "
                                                  "write the window's pixels to OUT.png and exit"},
    [VIEW_OPT_FRAMES] = {"frames", "N", "replay an orbit of N frames (a full turn), print each "
                                        "frame's times, then exit (or take the --snapshot)"},
    [VIEW_OPT_ORBIT] = {"orbit", "camera|light", "what the replay turns about the vertical "
                                                 "(default camera)"},
    [VIEW_OPT_NO_GUI] = {"no-gui", NULL, "hide the panel (G or Tab shows it)"},
};

/* program.take: one of the viewer's options. */
static int view_take(void *user, size_t index, const char *v)
{
    view_options *o = user;
    switch (index) {
    case VIEW_OPT_SNAPSHOT: {
        size_t len = strlen(v);
        if (len < 5 || strcmp(v + len - 4, ".png") != 0) {
            fprintf(stderr, "umbra-view: --snapshot '%s': the name must end in .png\n", v);
            return 1;
        }
        o->snapshot = v;
        return 0;
    }
    case VIEW_OPT_FRAMES: {
        unsigned long f = strspn(v, "0123456789") == strlen(v) ? strtoul(v, NULL, 10) : 0;
        if (f < 1 || f > 100000) {
            fprintf(stderr, "umbra-view: --frames '%s' is not a whole number in [1, 100000]\n",
                    v);
            return 1;
        }
        o->frames = (uint32_t)f;
        return 0;
    }
    case VIEW_OPT_ORBIT:
        if (strcmp(v, "camera") != 0 && strcmp(v, "light") != 0) {
            fprintf(stderr, "umbra-view: --orbit '%s' is not camera or light\n", v);
            return 1;
        }
        o->orbit_light = strcmp(v, "light") == 0;
        return 0;
    default: o->no_gui = 1; return 0;
    }
}

/* ---- transfer function: presets and the edited table --------------------------------------------- */

/* Shows umbra's last error, after what the viewer was doing. */
static void set_message(viewer *v, const char *what)
{
    snprintf(v->message, sizeof v->message, "%s: %s", what,
             umbra_context_last_message(v->s.ctx));
    v->message_is_error = 1;
}

/* Copies tf's table and range into the editor; 0 or -1 when out of memory. */
static int tf_take(viewer *v, umbra_transfer_function tf)
{
    uint32_t n = umbra_transfer_function_size(tf);
    float *rgba = malloc((size_t)n * 4 * sizeof *rgba);
    if (!rgba) {
        snprintf(v->message, sizeof v->message, "out of memory for a %u-entry table", n);
        v->message_is_error = 1;
        return -1;
    }
    memcpy(rgba, umbra_transfer_function_data(tf), (size_t)n * 4 * sizeof *rgba);
    free(v->tf_rgba);
    v->tf_rgba = rgba;
    v->tf_count = n;
    v->tf_has_range = umbra_transfer_function_get_range(tf, v->tf_range);
    float top = 0.0f;
    for (uint32_t i = 0; i < n; ++i)
        top = fmaxf(top, rgba[4 * i + 3]);
    v->tf_curve_top = fminf(1.0f, fmaxf(0.01f, 1.25f * top));
    return 0;
}

int viewer_tf_commit(viewer *v)
{
    umbra_transfer_function tf = NULL;
    umbra_status st = umbra_transfer_function_create(v->s.ctx, v->tf_rgba, v->tf_count, &tf);
    if (st == UMBRA_SUCCESS && v->tf_has_range)
        st = umbra_transfer_function_set_range(tf, v->tf_range[0], v->tf_range[1]);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_set_transfer_function(v->s.renderer, tf);
    if (st != UMBRA_SUCCESS) {
        set_message(v, "transfer function");
        umbra_transfer_function_release(tf);
        return -1;
    }
    umbra_transfer_function_release(v->tf_edit);
    v->tf_edit = tf;
    v->changed |= VIEW_CHANGED_TF;
    return 0;
}

int viewer_tf_load(viewer *v, int k)
{
    umbra_transfer_function tf = NULL;
    if (k >= 0 && (unsigned)k < v->n_presets) {
        if (umbra_transfer_function_load(v->s.ctx, v->presets[k], &tf) != UMBRA_SUCCESS) {
            set_message(v, v->presets[k]);
            return -1;
        }
    } else {
        k = -1;
        umbra_transfer_function_retain(tf = v->s.view_tf);
    }
    int rc = tf_take(v, tf);
    umbra_transfer_function_release(tf);
    if (rc == 0 && (rc = viewer_tf_commit(v)) == 0)
        v->preset = k;
    return rc;
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Adds the .tf and .json files of dir to v->presets. */
static void presets_scan(viewer *v, const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        int tf = len > 3 && strcmp(e->d_name + len - 3, ".tf") == 0;
        int json = len > 5 && strcmp(e->d_name + len - 5, ".json") == 0;
        char **grown = tf || json ? realloc(v->presets, (v->n_presets + 1) * sizeof *grown) : NULL;
        char *path = grown ? malloc(strlen(dir) + len + 2) : NULL;
        if (grown)
            v->presets = grown;
        if (!path)
            continue;
        sprintf(path, "%s/%s", dir, e->d_name);
        v->presets[v->n_presets++] = path;
    }
    if (d)
        closedir(d);
}

/* The shipped presets: those installed with the program (share/umbra/presets beside its bin/),
 * or in the build tree the copies beside it (presets/). */
static void presets_find(viewer *v)
{
    char exe[4096], dir[4200];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = '\0';
    snprintf(dir, sizeof dir, "%s/%s", exe, UMBRA_VIEW_INSTALLED_PRESETS);
    presets_scan(v, dir);
    if (v->n_presets == 0) {
        snprintf(dir, sizeof dir, "%s/presets", exe);
        presets_scan(v, dir);
    }
    if (v->n_presets)
        qsort(v->presets, v->n_presets, sizeof *v->presets, compare_names);
}

/* ---- light, frame and view ------------------------------------------------------------------------ */

void viewer_light_set_type(viewer *v, umbra_light_type type)
{
    umbra_light *l = &v->s.light;
    if (l->type == type)
        return;
    if (type == UMBRA_LIGHT_POINT) {
        float len = sqrtf(l->direction[0] * l->direction[0] + l->direction[1] * l->direction[1] +
                          l->direction[2] * l->direction[2]);
        for (int i = 0; i < 3; ++i)
            l->position[i] = v->center[i] - 1.5f * v->diagonal * l->direction[i] / len;
    } else {
        for (int i = 0; i < 3; ++i)
            l->direction[i] = v->center[i] - l->position[i];
    }
    l->type = type;
    v->changed |= VIEW_CHANGED_LIGHT;
}

void viewer_save_frame(viewer *v)
{
    if (!v->pixels_ok)
        return;
    if (umbra_image_write(v->s.ctx, v->s.out, v->width, v->height, v->pixels) == UMBRA_SUCCESS) {
        fprintf(stderr, "wrote %s\n", v->s.out);
        snprintf(v->message, sizeof v->message, "wrote %s", v->s.out);
        v->message_is_error = 0;
    } else {
        set_message(v, "save");
    }
}

/* The view as umbra-render options (with the same input options, umbra-render renders this
 * frame): camera, light, rendering options, and the technique with every one of its parameters
 * as umbra-render's parser reads them (param_option_text). */
static void print_view(const viewer *v, FILE *f)
{
    const umbra_camera *c = &v->s.camera;
    const umbra_light *l = &v->s.light;
    const umbra_render_desc *o = &v->s.options;
    fprintf(f, "view: --size %ux%u --technique %s --eye %.9g,%.9g,%.9g --target %.9g,%.9g,%.9g "
               "--up %.9g,%.9g,%.9g --fov %.9g",
            v->width, v->height, umbra_shadow_technique_name(v->s.shadow.technique), c->eye[0],
            c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2], c->up[0], c->up[1],
            c->up[2], c->fovy_degrees);
    if (c->projection == UMBRA_ORTHOGRAPHIC)
        fprintf(f, " --ortho %.9g", c->ortho_height);
    const float *p = l->type == UMBRA_LIGHT_POINT ? l->position : l->direction;
    fprintf(f, " --light-%s %.9g,%.9g,%.9g --light-color %.9g,%.9g,%.9g",
            l->type == UMBRA_LIGHT_POINT ? "pos" : "dir", p[0], p[1], p[2], l->color[0],
            l->color[1], l->color[2]);
    fprintf(f, " --step %.9g %s %s %s%s --interaction %s", o->step,
            o->shading ? "--shading" : "--no-shading", o->ground_plane ? "--ground" : "--no-ground",
            o->transmission == UMBRA_TRANSMISSION_COLORED ? "--colored" : "--grey",
            o->preintegrated ? " --preintegrated" : "",
            o->interaction == UMBRA_INTERACTION_AUTO ? "auto" : "off");
    static const char *const modes[] = {"composite", "mip", "minip", "average"};
    if (o->mode != UMBRA_RENDER_COMPOSITE && (unsigned)o->mode < 4)
        fprintf(f, " --mode %s", modes[o->mode]);
    const umbra_clip_desc *cl = &v->s.clip;
    for (uint32_t i = 0; i < cl->plane_count; ++i)
        fprintf(f, " --clip-plane %.9g,%.9g,%.9g,%.9g", cl->planes[i][0], cl->planes[i][1],
                cl->planes[i][2], cl->planes[i][3]);
    if (cl->crop)
        fprintf(f, " --crop %.9g,%.9g,%.9g,%.9g,%.9g,%.9g", cl->crop_min[0], cl->crop_min[1],
                cl->crop_min[2], cl->crop_max[0], cl->crop_max[1], cl->crop_max[2]);
    /* Every parameter of the technique, by its registry key. */
    const umbra_technique_info *t = umbra_technique_find_id(v->s.shadow.technique);
    for (uint32_t k = 0; t && k < t->param_count; ++k) {
        const umbra_param_info *pi = umbra_technique_param_get(t, k);
        double value;
        char text[128];
        if (umbra_shadow_desc_get_param(&v->s.shadow, t->name, pi->key, &value) == UMBRA_SUCCESS) {
            param_option_text(pi, value, text, sizeof text);
            fprintf(f, " %s", text);
        }
    }
    fputc('\n', f);
    fflush(f);
}

/* Whether the frame's shadows were a draft (interaction auto: the frame after a light, light
 * transfer function or shadow-parameter change); the loop renders once more when idle, and the
 * library builds the full structure for that frame. */
static int stats_draft(const umbra_render_stats *st)
{
    return st->draft != 0;
}

/* The progress callback: keeps the window answering during a long render, shows the fraction in
 * the title and cancels when the window is closed. */
typedef struct progress {
    viewer *v;
    double start_ms;
    int titled;
} progress;

static int on_progress(void *user, float fraction)
{
    progress *p = user;
    glfwPollEvents();
    if (now_ms() - p->start_ms > 300.0) {
        char title[64];
        snprintf(title, sizeof title, "umbra-view: rendering %.0f%%", 100.0 * fraction);
        glfwSetWindowTitle(p->v->window, title);
        p->titled = 1;
    }
    return glfwWindowShouldClose(p->v->window);
}

/* Sets what changed on the renderer and renders a frame into v->pixels and the texture. A
 * setting the renderer refuses leaves it at its last valid one and the frame is rendered with
 * that. Returns UMBRA_SUCCESS or the first failure (v->message says what; the texture keeps the
 * last good frame). */
static umbra_status render_frame(viewer *v)
{
    umbra_renderer r = v->s.renderer;
    unsigned ch = v->changed;
    umbra_status st, bad = UMBRA_SUCCESS;
    v->changed = 0;
    v->message[0] = '\0';
#define SET(bit, call, what)                                                                   \
    if ((ch & (bit)) && (st = (call)) != UMBRA_SUCCESS && bad == UMBRA_SUCCESS) {              \
        bad = st;                                                                              \
        set_message(v, what);                                                                  \
    }
    SET(VIEW_CHANGED_CAMERA, umbra_renderer_set_camera(r, &v->s.camera), "camera")
    SET(VIEW_CHANGED_LIGHT, umbra_renderer_set_light(r, &v->s.light), "light")
    SET(VIEW_CHANGED_OPTIONS, umbra_renderer_set_options(r, &v->s.options), "options")
    SET(VIEW_CHANGED_SHADOW, umbra_renderer_set_shadow(r, &v->s.shadow), "shadow")
    SET(VIEW_CHANGED_CLIP, umbra_renderer_set_clip(r, &v->s.clip), "clip")
#undef SET
    if (ch & VIEW_CHANGED_SIZE) {
        float *px = malloc((size_t)v->width * v->height * 4 * sizeof *px);
        if (!px) {
            snprintf(v->message, sizeof v->message, "out of memory for a %ux%u frame", v->width,
                     v->height);
            v->message_is_error = 1;
            return UMBRA_ERROR_OUT_OF_MEMORY;
        }
        free(v->pixels);
        v->pixels = px;
        v->pixels_ok = 0;
    }
    progress prog = {v, now_ms(), 0};
    umbra_renderer_set_progress(r, on_progress, &prog);
    double t0 = now_ms();
    st = umbra_renderer_render(r, v->width, v->height, v->pixels);
    double t1 = now_ms();
    if (prog.titled)
        glfwSetWindowTitle(v->window, "umbra-view");
    if (st != UMBRA_SUCCESS) {
        set_message(v, "render");
        v->pixels_ok = 0;
        return st;
    }
    umbra_renderer_get_stats(r, &v->stats);
    v->draft = stats_draft(&v->stats);
    if (present_upload(&v->pr, v->pixels, v->width, v->height) != 0) {
        snprintf(v->message, sizeof v->message, "out of memory for the frame's texture");
        v->message_is_error = 1;
        return UMBRA_ERROR_OUT_OF_MEMORY;
    }
    v->have_frame = v->pixels_ok = 1;
    v->times.umbra_ms = t1 - t0;
    v->times.upload_ms = now_ms() - t1;
    return bad;
}

/* ---- mouse and keys ------------------------------------------------------------------------------ */

typedef enum drag_kind { DRAG_NONE, DRAG_ORBIT, DRAG_PAN, DRAG_LIGHT } drag_kind;

typedef struct input {
    drag_kind drag;
    double x, y;     /* the cursor at the last frame */
    double scroll;   /* wheel steps since the last frame */
    int keys[16];    /* keys pressed since the last frame (callbacks: a press and release
                        between two frames is not lost) */
    int n_keys;
} input;

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    ((input *)glfwGetWindowUserPointer(w))->scroll += dy;
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    (void)mods;
    input *in = glfwGetWindowUserPointer(w);
    if (action == GLFW_PRESS && in->n_keys < (int)(sizeof in->keys / sizeof in->keys[0]))
        in->keys[in->n_keys++] = key;
}

/* The mouse's drags and wheel into camera and light moves (not while the drag began on the
 * panel), then the keys pressed since the last frame; returns 1 to quit. */
static int handle_input(viewer *v, input *in, const umbra_camera *first_camera)
{
    GLFWwindow *w = v->window;
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    int wh = 1;
    glfwGetWindowSize(w, NULL, &wh);
    float dx = (float)(x - in->x), dy = (float)(y - in->y);
    in->x = x;
    in->y = y;
    int left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    int middle = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
    int right = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    int shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    int ctrl = glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
               glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
    if (!left && !middle && !right)
        in->drag = DRAG_NONE;
    else if (in->drag == DRAG_NONE && !panel_wants_mouse())
        in->drag = right || (left && ctrl) ? DRAG_LIGHT
                   : middle || (left && shift) ? DRAG_PAN
                                               : DRAG_ORBIT;
    const float radians_per_pixel = 0.01f;
    if (in->drag != DRAG_NONE && (dx != 0.0f || dy != 0.0f)) {
        if (in->drag == DRAG_ORBIT) {
            navigate_orbit(&v->s.camera, -dx * radians_per_pixel, dy * radians_per_pixel);
            v->changed |= VIEW_CHANGED_CAMERA;
        } else if (in->drag == DRAG_PAN) {
            navigate_pan(&v->s.camera, dx / (float)(wh > 0 ? wh : 1), -dy / (float)(wh > 0 ? wh : 1));
            v->changed |= VIEW_CHANGED_CAMERA;
        } else {
            navigate_light(&v->s.light, &v->s.camera, v->center, dx * radians_per_pixel,
                           dy * radians_per_pixel);
            v->changed |= VIEW_CHANGED_LIGHT;
        }
    }
    if (in->scroll != 0.0 && !panel_wants_mouse()) {
        navigate_zoom(&v->s.camera, powf(0.9f, (float)in->scroll));
        v->changed |= VIEW_CHANGED_CAMERA;
    }
    in->scroll = 0.0;
    int n = in->n_keys, quit = 0;
    in->n_keys = 0;
    if (panel_wants_keyboard())
        return 0; /* typing into a field of the panel */
    for (int i = 0; i < n; ++i)
        switch (in->keys[i]) {
        case GLFW_KEY_S: viewer_save_frame(v); break;
        case GLFW_KEY_G:
        case GLFW_KEY_TAB: v->show_panel = !v->show_panel; break;
        case GLFW_KEY_P: print_view(v, stdout); break;
        case GLFW_KEY_R:
            v->s.camera = *first_camera;
            v->changed |= VIEW_CHANGED_CAMERA;
            break;
        case GLFW_KEY_ESCAPE: quit = 1; break;
        default: break;
        }
    return quit;
}

/* ---- the window loop ------------------------------------------------------------------------------ */

static int median_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *x, uint32_t n)
{
    qsort(x, n, sizeof *x, median_cmp);
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

/* Runs until the window closes, or until the replay and snapshot are done. Returns the exit
 * status. */
static int run(viewer *v, const view_options *o)
{
    input in;
    memset(&in, 0, sizeof in);
    glfwSetWindowUserPointer(v->window, &in);
    glfwSetScrollCallback(v->window, on_scroll); /* before the GUI's, which chain to these */
    glfwSetKeyCallback(v->window, on_key);
    if (panel_init(v) != 0) {
        fprintf(stderr, "umbra-view: the GUI's OpenGL 3 backend did not start\n");
        return 2;
    }
    glfwGetCursorPos(v->window, &in.x, &in.y);
    const umbra_camera first_camera = v->s.camera;
    /* Replay: frame 0 is the first view (a warm-up: programs compile), frames 1..N turn. */
    uint32_t frame = 0, replay = o->frames;
    double *ms = replay ? calloc(4 * (size_t)replay, sizeof *ms) : NULL;
    if (replay && !ms) {
        fprintf(stderr, "umbra-view: out of memory\n");
        return 2;
    }
    int rc = -1;
    while (rc < 0) {
        int replaying = replay && frame <= replay;
        int busy = v->changed || v->draft || replaying || o->snapshot;
        if (busy)
            glfwPollEvents();
        else
            glfwWaitEventsTimeout(0.25);
        double t0 = now_ms(); /* a frame's time starts after the wait for events */
        if (glfwWindowShouldClose(v->window)) {
            rc = 0;
            break;
        }
        int fw, fh;
        glfwGetFramebufferSize(v->window, &fw, &fh);
        if (fw > 0 && fh > 0 && ((uint32_t)fw != v->width || (uint32_t)fh != v->height)) {
            v->width = (uint32_t)fw;
            v->height = (uint32_t)fh;
            v->changed |= VIEW_CHANGED_SIZE;
        }
        panel_frame(v);
        if (handle_input(v, &in, &first_camera)) {
            rc = 0;
            break;
        }
        if (replaying && frame > 0) {
            const float turn = 6.28318531f / (float)replay;
            if (o->orbit_light) {
                if (v->s.light.type == UMBRA_LIGHT_POINT)
                    navigate_turn_point(v->s.light.position, v->center, turn);
                else
                    navigate_turn_direction(v->s.light.direction, turn);
                v->changed |= VIEW_CHANGED_LIGHT;
            } else {
                navigate_turn_point(v->s.camera.eye, v->s.camera.target, turn);
                v->changed |= VIEW_CHANGED_CAMERA;
            }
        }
        /* A frame when something changed, and once more when idle after a draft. */
        int rendered = 0;
        if (v->changed || (v->draft && !in.drag)) {
            umbra_status st = render_frame(v);
            rendered = v->pixels_ok;
            if (st == UMBRA_ERROR_CANCELLED) { /* the window was closed during the render */
                rc = 0;
                break;
            }
            if (st != UMBRA_SUCCESS && (replaying || o->snapshot)) {
                rc = exit_status(st); /* the library's message is on stderr */
                break;
            }
        }
        double t1 = now_ms();
        glViewport(0, 0, (GLsizei)v->width, (GLsizei)v->height);
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        panel_draw(v);
        /* The snapshot: once the replay is over, in the frame after the last render (so that
         * the panel shows that render's figures), when the shadows are full quality. */
        int done_replay = !replay || frame > replay;
        if (o->snapshot && done_replay && v->pixels_ok && !rendered && !v->draft &&
            !v->changed) {
            const int *rect = v->panel;
            if (present_write_window(&v->pr, v->s.ctx, o->snapshot, v->width, v->height) !=
                UMBRA_SUCCESS) {
                rc = 2;
                break;
            }
            fprintf(stderr, "wrote %s (%ux%u window", o->snapshot, v->width, v->height);
            if (rect[2] > 0)
                fprintf(stderr, "; panel at %d,%d size %dx%d", rect[0], rect[1], rect[2], rect[3]);
            fprintf(stderr, ")\n");
            print_view(v, stdout);
            rc = 0;
        }
        glfwSwapBuffers(v->window);
        double t2 = now_ms();
        if (rendered) {
            v->times.draw_ms = t2 - t1;
            v->times.frame_ms = t2 - t0;
        }
        if (replaying && rendered) {
            if (frame > 0) {
                printf("frame %u/%u: %.1f ms (umbra %.1f ms: shadow build %.1f ms %s, render "
                       "%.1f ms; upload %.1f ms; draw %.1f ms)\n",
                       frame, replay, v->times.frame_ms, v->times.umbra_ms,
                       v->stats.shadow_build_ms,
                       !v->stats.shadow_rebuilt ? "reused"
                       : v->stats.draft         ? "rebuilt, draft"
                                                : "rebuilt",
                       v->stats.render_ms, v->times.upload_ms, v->times.draw_ms);
                double *row = ms + 4 * (size_t)(frame - 1);
                row[0] = v->times.frame_ms;
                row[1] = v->times.umbra_ms;
                row[2] = v->times.upload_ms;
                row[3] = v->times.draw_ms;
            }
            if (++frame > replay) {
                double *tmp = malloc(replay * sizeof *tmp);
                if (tmp) {
                    double med[4];
                    for (int k = 0; k < 4; ++k) {
                        for (uint32_t i = 0; i < replay; ++i)
                            tmp[i] = ms[4 * (size_t)i + k];
                        med[k] = median(tmp, replay);
                    }
                    printf("median of %u frames (%s orbit, %ux%u, %s): %.1f ms (umbra %.1f ms; "
                           "upload %.1f ms; draw %.1f ms)\n",
                           replay, o->orbit_light ? "light" : "camera", v->width, v->height,
                           umbra_shadow_technique_name(v->s.shadow.technique), med[0], med[1],
                           med[2], med[3]);
                    free(tmp);
                }
                fflush(stdout);
                if (!o->snapshot)
                    rc = 0;
            }
        }
    }
    free(ms);
    panel_shutdown();
    return rc;
}

static void on_glfw_error(int code, const char *message)
{
    fprintf(stderr, "umbra-view: GLFW error 0x%x: %s\n", code, message);
}

int main(int argc, char **argv)
{
    view_options o;
    memset(&o, 0, sizeof o);
    const program prog = {
        "umbra-view",
        "interactive; every umbra-render option applies: --size WxH is the window's size, --out "
        "FILE is where S writes the frame; --interaction is auto unless given. Mouse: left "
        "orbit, middle or shift+left pan, wheel zoom, right or ctrl+left light. Keys: S save "
        "frame, G/Tab panel, P print view options, R reset view, Esc quit.",
        view_option_list, sizeof view_option_list / sizeof view_option_list[0], view_take, &o};
    options args;
    int rc = parse_args_as(&prog, argc, argv, &args);
    if (rc)
        return rc;
    /* A viewer is where the light is dragged: drafts while it moves, the full map when it
     * stops, unless the command line says otherwise. */
    if (!args.have_interaction)
        args.interaction = UMBRA_INTERACTION_AUTO;
    viewer v;
    memset(&v, 0, sizeof v);
    v.preset = -1;
    v.show_panel = !o.no_gui;
    present_init(&v.pr);
    if ((rc = session_begin(&args, &v.s)) != 0)
        goto done;
    umbra_volume_info info;
    umbra_volume_get_info(v.s.view_volume, &info);
    memcpy(v.center, info.center, sizeof v.center);
    v.diagonal = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                       info.extent[2] * info.extent[2]);
    presets_find(&v);
    if (tf_take(&v, v.s.view_tf) != 0) {
        rc = 2;
        goto done;
    }
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "umbra-view: GLFW could not start (is there a display? DISPLAY=%s)\n",
                getenv("DISPLAY") ? getenv("DISPLAY") : "");
        rc = 2;
        goto done;
    }
    v.window = glfwCreateWindow((int)v.s.width, (int)v.s.height, "umbra-view", NULL, NULL);
    if (!v.window) {
        fprintf(stderr, "umbra-view: no %ux%u OpenGL window could be made\n", v.s.width,
                v.s.height);
        rc = 2;
    } else {
        glfwMakeContextCurrent(v.window);
        glfwSwapInterval(0); /* frames as fast as umbra renders them; idle waits on events */
        rc = run(&v, &o);
        present_release(&v.pr);
        glfwDestroyWindow(v.window);
    }
    glfwTerminate();
done:
    free(v.pixels);
    free(v.tf_rgba);
    for (unsigned i = 0; i < v.n_presets; ++i)
        free(v.presets[i]);
    free(v.presets);
    umbra_transfer_function_release(v.tf_edit);
    session_end(&v.s);
    return rc;
}
