// SPDX-License-Identifier: Apache-2.0
/* umbra-render: the command-line front end. Renders a built-in scene or a volume file with a
 * chosen shadow technique into a PNG or EXR and prints each stage's time to stderr.
 * Run with --help for the options (examples/umbra_render_args.c parses them: the fixed ones and
 * every shadow technique's parameters from the technique registry). Exit status (as the README
 * states): 0 on success; 1 on bad input: an option, a number, a file that is missing or
 * malformed, an output path that cannot be written (checked before rendering), a request the
 * technique cannot do; 2 on a failure of the device or of memory (no device, an OpenCL error, out
 * of memory), or when writing the image fails after the render; 130 when interrupted (Ctrl-C
 * stops the render between two pieces of device work). The scene set up from the command line
 * (session_begin) is shared with umbra-view (umbra_render.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "umbra_render.h"

/* Exit status for a failed library call, as the README states: 1 for bad input (an argument out
 * of range, a file that cannot be read or is malformed, a request the technique cannot do), 2 for
 * a failure of the device or of memory. */
int exit_status(umbra_status st)
{
    switch (st) {
    case UMBRA_SUCCESS: return 0;
    case UMBRA_ERROR_INVALID_ARGUMENT:
    case UMBRA_ERROR_IO:
    case UMBRA_ERROR_FORMAT:
    case UMBRA_ERROR_UNSUPPORTED: return 1;
    default: return 2; /* OUT_OF_MEMORY, OPENCL, BUILD, NO_DEVICE */
    }
}

/* user: the program's name. */
static void on_error(void *user, umbra_status st, const char *msg)
{
    if (st == UMBRA_ERROR_CANCELLED)
        return; /* reported as "interrupted" */
    fprintf(stderr, "%s: %s: %s\n", (const char *)user, umbra_status_to_string(st), msg);
}

/* Ctrl-C sets the flag; the progress callback, called between pieces of device work, reads it
 * and cancels the render, so the program still cleans up and exits with a message. */
static volatile sig_atomic_t interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    interrupted = 1;
}

typedef struct progress_state {
    int show;          /* print a progress line */
    double start_ms;   /* a line only once a render has run this long: short ones stay quiet */
    int shown;
} progress_state;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int on_progress(void *user, float fraction)
{
    progress_state *p = user;
    if (p->show && (p->shown || now_ms() - p->start_ms > 500.0)) {
        fprintf(stderr, "\rrendering: %5.1f%%", 100.0 * fraction);
        fflush(stderr);
        p->shown = 1;
    }
    return interrupted != 0;
}

void session_end(session *s)
{
    free(s->pixels);
    umbra_renderer_release(s->renderer);
    umbra_transfer_function_release(s->light_tf);
    umbra_transfer_function_release(s->tf);
    for (int c = 0; c < UMBRA_MAX_CHANNELS - 1; ++c)
        umbra_transfer_function_release(s->channel_tf[c]);
    umbra_volume_release(s->volume);
    umbra_scene_release(&s->scene);
    umbra_context_release(s->ctx);
}

/* A ParaView preset (its x values are data values: the loaded table carries that range) or
 * umbra's text format. */
static umbra_status load_tf(umbra_context ctx, const char *path, const char *preset,
                            umbra_transfer_function *out)
{
    size_t n = strlen(path);
    if (n > 5 && strcmp(path + n - 5, ".json") == 0) {
        umbra_paraview_options po;
        umbra_paraview_options_init(&po);
        po.preset = preset;
        return umbra_transfer_function_load_paraview(ctx, path, &po, out, NULL);
    }
    return umbra_transfer_function_load(ctx, path, out);
}

umbra_status session_open(const options *o, session *s, int quiet)
{
    umbra_context_desc cd;
    umbra_context_desc_init(&cd);
    cd.device_name = o->device;
    cd.platform_index = o->platform_index;
    cd.device_index = o->device_index;
    if (!quiet) {
        cd.error_callback = on_error;
        cd.error_user = (void *)o->program; /* only read: a string with the program's life */
    }
    umbra_status st = umbra_context_create(&cd, &s->ctx);
    if (st == UMBRA_SUCCESS && !quiet)
        fprintf(stderr, "device: %s\n", umbra_context_device_name(s->ctx));
    return st;
}

int session_begin(const options *o, session *s)
{
    umbra_status st = session_open(o, s, 0);
    if (st != UMBRA_SUCCESS)
        return exit_status(st);
    return session_setup(o, s);
}

int session_setup(const options *o, session *s)
{
    umbra_status st;
    umbra_volume vol = NULL;
    umbra_transfer_function tf = NULL;
    umbra_render_desc rd;
    umbra_render_desc_init(&rd);
    umbra_camera cam;
    umbra_light light;
    if (o->volume || o->raw) {
        umbra_volume_load_options lo;
        umbra_volume_load_options_init(&lo);
        lo.data_roots = o->data_roots;
        lo.data_root_count = o->data_root_count;
        /* A volume the caller made (umbra-render-mpi: this rank's part) is used as given. */
        st = s->volume ? UMBRA_SUCCESS
             : o->volume ? umbra_volume_load_with_options(s->ctx, o->volume, &lo, &s->volume)
                         : umbra_volume_load_raw(s->ctx, o->raw, &o->raw_desc, &s->volume);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        vol = s->volume;
        umbra_volume_info info;
        umbra_volume_get_info(vol, &info);
        float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                           info.extent[2] * info.extent[2]);
        const float dir[3] = {0.75f, 0.5f, 1.0f};
        /* Around the box's world centre: a NRRD with a space origin is not centred on 0. */
        cam = umbra_camera_orbit_at(info.center, dir, diag, o->fov);
        memset(&light, 0, sizeof light);
        light.type = UMBRA_LIGHT_DIRECTIONAL;
        light.direction[0] = 0.45f;
        light.direction[1] = -1.0f;
        light.direction[2] = 0.25f;
        light.color[0] = light.color[1] = light.color[2] = 1.0f;
        rd.ground_plane = 1;
        if (!o->tf) {
            /* A generic ramp: low values transparent, high values white and denser. */
            const umbra_tf_point pts[] = {{0.0f, {1, 1, 1, 0}}, {0.2f, {1, 1, 1, 0}},
                                          {0.5f, {0.9f, 0.8f, 0.7f, 0.05f}},
                                          {1.0f, {1, 1, 1, 0.4f}}};
            st = umbra_transfer_function_create_from_points(s->ctx, pts, 4, 256, &s->tf);
            if (st != UMBRA_SUCCESS)
                return exit_status(st);
            tf = s->tf;
        }
    } else {
        st = umbra_scene_create(s->ctx, o->scene, o->scene_size, &s->scene);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        vol = s->scene.volume;
        tf = s->scene.tf;
        cam = s->scene.camera;
        light = s->scene.light;
        rd = s->scene.options;
    }
    if (o->tf) {
        st = load_tf(s->ctx, o->tf, o->tf_preset, &s->tf);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        tf = s->tf;
    }
    if (o->light_tf &&
        (st = load_tf(s->ctx, o->light_tf, o->tf_preset, &s->light_tf)) != UMBRA_SUCCESS)
        return exit_status(st);
    for (uint32_t c = 0; c < o->channel_tf_count; ++c)
        if ((st = load_tf(s->ctx, o->channel_tf[c], o->tf_preset, &s->channel_tf[c])) !=
            UMBRA_SUCCESS)
            return exit_status(st);
    /* The library checks LO < HI and names the values. */
    if (o->have_tf_range &&
        ((st = umbra_transfer_function_set_range(tf, o->tf_range[0], o->tf_range[1])) !=
             UMBRA_SUCCESS ||
         (s->light_tf && (st = umbra_transfer_function_set_range(s->light_tf, o->tf_range[0],
                                                                 o->tf_range[1])) != UMBRA_SUCCESS)))
        return exit_status(st);

    if (o->have_camera_dir) {
        umbra_volume_info info;
        umbra_volume_get_info(vol, &info);
        float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                           info.extent[2] * info.extent[2]);
        cam = umbra_camera_orbit_at(info.center, o->camera_dir, diag * 1.1f, o->fov);
    }
    if (o->have_eye) memcpy(cam.eye, o->eye, sizeof cam.eye);
    if (o->have_target) memcpy(cam.target, o->target, sizeof cam.target);
    if (o->have_up) memcpy(cam.up, o->up, sizeof cam.up);
    cam.fovy_degrees = o->fov;
    if (o->ortho > 0) {
        cam.projection = UMBRA_ORTHOGRAPHIC;
        cam.ortho_height = o->ortho;
    }
    if (o->have_light_dir) {
        light.type = UMBRA_LIGHT_DIRECTIONAL;
        memcpy(light.direction, o->light_dir, sizeof light.direction);
    }
    if (o->have_light_pos) {
        light.type = UMBRA_LIGHT_POINT;
        memcpy(light.position, o->light_pos, sizeof light.position);
    }
    if (o->have_light_color) memcpy(light.color, o->light_color, sizeof light.color);
    if (o->have_ambient) rd.ambient[0] = rd.ambient[1] = rd.ambient[2] = o->ambient;
    if (o->have_step) rd.step = o->step;
    if (o->have_termination) rd.termination = o->termination;
    if (o->shading >= 0) rd.shading = o->shading;
    if (o->ground >= 0) rd.ground_plane = o->ground;
    if (o->colored >= 0) rd.transmission = o->colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    rd.jitter = o->jitter;
    rd.preintegrated = o->preintegrated;
    rd.interaction = o->interaction;
    rd.mode = o->mode;
    if (o->have_seed) rd.seed = o->seed;
    if (o->have_background) memcpy(rd.background, o->background, sizeof rd.background);
    else { rd.background[0] = 0.08f; rd.background[1] = 0.08f; rd.background[2] = 0.1f; rd.background[3] = 1.0f; }

    if ((st = umbra_renderer_create(s->ctx, &s->renderer)) != UMBRA_SUCCESS)
        return exit_status(st);
    umbra_renderer r = s->renderer;
    if ((st = umbra_renderer_set_volume(r, vol)) ||
        (st = umbra_renderer_set_transfer_function(r, tf)) ||
        (s->light_tf && (st = umbra_renderer_set_light_transfer_function(r, s->light_tf))) ||
        (st = umbra_renderer_set_camera(r, &cam)) || (st = umbra_renderer_set_light(r, &light)) ||
        (st = umbra_renderer_set_options(r, &rd)) ||
        (st = umbra_renderer_set_shadow(r, &o->shadow)) ||
        (st = umbra_renderer_set_clip(r, &o->clip)))
        return exit_status(st);
    /* Channels 1.. of a multi-channel volume: their own transfer functions, else channel 0's. */
    umbra_volume_info vinfo;
    umbra_volume_get_info(vol, &vinfo);
    if (o->channel_tf_count >= vinfo.channels && o->channel_tf_count > 0) {
        fprintf(stderr, "%s: %u --channel-tf for a volume of %u channel%s\n", o->program,
                o->channel_tf_count, vinfo.channels, vinfo.channels == 1 ? "" : "s");
        return 1;
    }
    for (uint32_t c = 1; c < vinfo.channels; ++c)
        if ((st = umbra_renderer_set_channel_transfer_function(
                 r, c, c <= o->channel_tf_count ? s->channel_tf[c - 1] : tf, NULL)) !=
            UMBRA_SUCCESS)
            return exit_status(st);
    s->view_volume = vol;
    s->view_tf = tf;
    s->camera = cam;
    s->light = light;
    s->options = rd;
    s->shadow = o->shadow;
    s->clip = o->clip;
    s->width = o->width;
    s->height = o->height;
    s->out = o->out;
    return 0;
}

static int run(const options *o, session *s)
{
    int rc = session_begin(o, s);
    if (rc)
        return rc;
    umbra_renderer r = s->renderer;
    s->pixels = malloc((size_t)o->width * o->height * 4 * sizeof(float));
    if (!s->pixels) {
        fprintf(stderr, "umbra-render: out of memory for a %ux%u image\n", o->width, o->height);
        return 2;
    }
    progress_state prog = {o->progress < 0 ? isatty(STDERR_FILENO) : o->progress, now_ms(), 0};
    umbra_renderer_set_progress(r, on_progress, &prog);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    umbra_status rst = umbra_renderer_render(r, o->width, o->height, s->pixels);
    if (prog.shown)
        fputc('\n', stderr);
    if (rst == UMBRA_ERROR_CANCELLED) {
        fprintf(stderr, "umbra-render: interrupted\n");
        return 130;
    }
    if (rst != UMBRA_SUCCESS)
        return exit_status(rst);
    umbra_render_stats stats;
    umbra_renderer_get_stats(r, &stats);
    fprintf(stderr, "technique: %s (%u light channel%s)\n",
            umbra_shadow_technique_name(o->shadow.technique), stats.light_channels,
            stats.light_channels == 1 ? "" : "s");
    fprintf(stderr, "shadow build: %.2f ms%s\n", stats.shadow_build_ms,
            stats.draft ? " (draft)" : "");
    fprintf(stderr, "render: %.2f ms (%llu samples)\n", stats.render_ms,
            (unsigned long long)stats.samples);
    fprintf(stderr, "shadow memory: %zu bytes\n", stats.shadow_memory_bytes);
    if (stats.slices)
        fprintf(stderr, "slices: %u\n", stats.slices);
    if (stats.map_size)
        fprintf(stderr, "map size: %u x %u%s\n", stats.map_size, stats.map_size,
                o->shadow.map.size == UMBRA_MAP_SIZE_AUTO ? " (auto)" : "");
    /* The path was checked before the render; failing now (a full disk) is not bad input. */
    if (umbra_image_write(s->ctx, o->out, o->width, o->height, s->pixels) != UMBRA_SUCCESS)
        return 2;
    fprintf(stderr, "wrote %s\n", o->out);
    return 0;
}

int umbra_render_main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return 1;
    session s;
    memset(&s, 0, sizeof s);
    int rc = run(&o, &s);
    session_end(&s);
    return rc;
}

#ifndef UMBRA_RENDER_NO_MAIN
int main(int argc, char **argv)
{
    return umbra_render_main(argc, argv);
}
#endif
