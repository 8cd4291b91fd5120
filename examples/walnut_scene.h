// SPDX-License-Identifier: Apache-2.0
/* examples/walnut_scene.h: the one scene every shadow technique's example renders, so that their
 * images (threshold.png, deep.png, cssm.png, reference.png) can be put side by side: the walnut CT
 * in front of a ground plane, lit by one point light and seen from one camera, like Figure 3 of
 * the CSSM paper (Weidner & Linsen). Header-only and static, so each example_<technique>.c stays a
 * few lines: fill an umbra_shadow_desc and call walnut_example_run().
 *
 * Where the volume comes from, first match wins:
 *   1. argv[1], a volume file (.nhdr / .nrrd / .dat);
 *   2. $UMBRA_DATA_DIR/walnut.nhdr, if that file exists;
 *   3. the built-in "spheres" scene with its own transfer function, so the examples run on a fresh
 *      clone without the data sets.
 * A loaded volume gets the transfer function examples/walnut.tf (found next to this header, or
 * given as argv[2]): the shell and the kernel both translucent, in different colours, so that
 * coloured partial shadows fall inside the nut and on the plane. */
#ifndef UMBRA_EXAMPLES_WALNUT_SCENE_H
#define UMBRA_EXAMPLES_WALNUT_SCENE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "umbra/io.h"

#define WALNUT_IMAGE_WIDTH 800u
#define WALNUT_IMAGE_HEIGHT 600u
#define WALNUT_MAP_SIZE 1024u /* the paper's Figure 3 uses 1024^2 maps */

/* Camera, light and render options for a volume of any size: everything is placed relative to
 * the volume's box (centred on the origin), so the walnut and the fallback scene look alike. */
static inline void walnut_scene_setup(umbra_volume volume, umbra_camera *camera,
                                      umbra_light *light, umbra_render_desc *options)
{
    umbra_volume_info info;
    memset(&info, 0, sizeof info);
    umbra_volume_get_info(volume, &info);
    float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                       info.extent[2] * info.extent[2]);

    /* Seen from the front, a little above and to the right, with room below and behind the
     * volume for the plane and the shadow on it. */
    memset(camera, 0, sizeof *camera);
    camera->projection = UMBRA_PERSPECTIVE;
    camera->eye[0] = 0.45f * diag;
    camera->eye[1] = 0.6f * diag;
    camera->eye[2] = 1.55f * diag;
    camera->target[0] = 0.1f * diag;
    camera->target[1] = -0.3f * info.extent[1];
    camera->up[1] = 1.0f;
    camera->fovy_degrees = 34.0f;
    camera->ortho_height = diag;

    /* A point light above, left and slightly behind: the shadow falls onto the plane to the
     * front-right of the volume, where the camera sees it, and the light's frustum around the box
     * stays narrow (a perspective map, as in the paper). */
    memset(light, 0, sizeof *light);
    light->type = UMBRA_LIGHT_POINT;
    light->position[0] = -1.0f * diag;
    light->position[1] = 1.9f * diag;
    light->position[2] = -0.35f * diag;
    light->color[0] = light->color[1] = light->color[2] = 1.0f;

    umbra_render_desc_init(options);
    options->step = 0.5f;
    options->shading = 1;
    options->kd = 0.7f;
    options->ks = 0.2f;
    options->ambient[0] = options->ambient[1] = options->ambient[2] = 0.2f;
    options->ground_plane = 1;
    options->ground_color[0] = 0.7f;
    options->ground_color[1] = 0.69f;
    options->ground_color[2] = 0.66f;
    options->ground_offset = 0.0f;
    options->background[0] = 0.08f;
    options->background[1] = 0.08f;
    options->background[2] = 0.1f;
    options->background[3] = 1.0f;
    options->transmission = UMBRA_TRANSMISSION_COLORED;
}

static inline int walnut_file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

/* examples/walnut.tf next to this header (__FILE__ is the path the compiler opened it by), else
 * relative to the working directory (the source tree or a build directory inside it). */
static inline int walnut_tf_path(char *buf, size_t size)
{
    const char *here = __FILE__;
    const char *slash = strrchr(here, '/');
    if (slash && (size_t)(slash - here) + 11 < size) {
        snprintf(buf, size, "%.*s/walnut.tf", (int)(slash - here), here);
        if (walnut_file_exists(buf))
            return 1;
    }
    const char *tries[] = {"walnut.tf", "examples/walnut.tf", "../examples/walnut.tf"};
    for (size_t i = 0; i < sizeof tries / sizeof tries[0]; ++i)
        if (walnut_file_exists(tries[i])) {
            snprintf(buf, size, "%s", tries[i]);
            return 1;
        }
    return 0;
}

/* Fills scene (volume, tf, camera, light, options; release it with umbra_scene_release) and
 * *source (a path, or "spheres" for the fallback). Errors are printed to stderr. */
static inline umbra_status walnut_scene_open(umbra_context ctx, int argc, char **argv,
                                             umbra_scene *scene, char *source, size_t source_size)
{
    umbra_status st;
    char path[4096] = "";
    memset(scene, 0, sizeof *scene);
    const char *dir = getenv("UMBRA_DATA_DIR");
    if (argc > 1)
        snprintf(path, sizeof path, "%s", argv[1]);
    else if (dir && *dir) {
        snprintf(path, sizeof path, "%s/walnut.nhdr", dir);
        if (!walnut_file_exists(path))
            path[0] = '\0';
    }
    if (!path[0]) {
        snprintf(source, source_size, "spheres");
        st = umbra_scene_create(ctx, "spheres", 96, scene);
    } else {
        char tf[4096];
        snprintf(source, source_size, "%s", path);
        if (argc > 2)
            snprintf(tf, sizeof tf, "%s", argv[2]);
        else if (!walnut_tf_path(tf, sizeof tf)) {
            fprintf(stderr, "walnut.tf not found next to %s or in ., examples/, ../examples/; "
                            "pass it as the second argument\n", __FILE__);
            return UMBRA_ERROR_IO;
        }
        st = umbra_volume_load(ctx, path, &scene->volume);
        if (st == UMBRA_SUCCESS)
            st = umbra_transfer_function_load(ctx, tf, &scene->tf);
    }
    if (st != UMBRA_SUCCESS) {
        fprintf(stderr, "%s: %s\n", umbra_status_to_string(st), umbra_context_last_message(ctx));
        umbra_scene_release(scene);
        return st;
    }
    walnut_scene_setup(scene->volume, &scene->camera, &scene->light, &scene->options);
    return UMBRA_SUCCESS;
}

/* The whole example: renders the scene with the given shadow description into png (in the
 * working directory) and prints the shadow build time, render time and shadow memory. The first
 * frame compiles the kernels, so the numbers come from a second render with a fresh build (the
 * light is set again, which invalidates the map) to time a warm build. Returns the exit status. */
static inline int walnut_example_run(int argc, char **argv, const umbra_shadow_desc *shadow,
                                     const char *png)
{
    const uint32_t w = WALNUT_IMAGE_WIDTH, h = WALNUT_IMAGE_HEIGHT;
    umbra_context ctx = NULL;
    umbra_renderer r = NULL;
    umbra_scene scene;
    char source[4096];
    float *rgba = malloc((size_t)w * h * 4 * sizeof *rgba);
    umbra_render_stats stats;
    memset(&scene, 0, sizeof scene);
    memset(&stats, 0, sizeof stats);

    umbra_status st = rgba ? umbra_context_create(NULL, &ctx) : UMBRA_ERROR_OUT_OF_MEMORY;
    if (st != UMBRA_SUCCESS) {
        fprintf(stderr, "%s: no OpenCL context\n", umbra_status_to_string(st));
        free(rgba);
        return 1;
    }
    st = walnut_scene_open(ctx, argc, argv, &scene, source, sizeof source);
    if (!st) st = umbra_renderer_create(ctx, &r);
    if (!st) st = umbra_renderer_set_volume(r, scene.volume);
    if (!st) st = umbra_renderer_set_transfer_function(r, scene.tf);
    if (!st) st = umbra_renderer_set_camera(r, &scene.camera);
    if (!st) st = umbra_renderer_set_light(r, &scene.light);
    if (!st) st = umbra_renderer_set_options(r, &scene.options);
    if (!st) st = umbra_renderer_set_shadow(r, shadow);
    if (!st) st = umbra_renderer_render(r, w, h, rgba);
    /* A different light, then the real one again: two rebuilds with warm kernels. */
    if (!st) {
        umbra_light other = scene.light;
        other.color[0] *= 0.5f;
        st = umbra_renderer_set_light(r, &other);
        if (!st) st = umbra_renderer_render(r, w, h, rgba);
        if (!st) st = umbra_renderer_set_light(r, &scene.light);
        if (!st) st = umbra_renderer_render(r, w, h, rgba);
    }
    if (!st) st = umbra_renderer_get_stats(r, &stats);
    if (!st) st = umbra_image_write(ctx, png, w, h, rgba);
    if (st) {
        fprintf(stderr, "%s: %s\n", umbra_status_to_string(st), umbra_context_last_message(ctx));
    } else {
        printf("scene: %s\n", source);
        printf("device: %s\n", umbra_context_device_name(ctx));
        printf("technique: %s (%u light channel%s)\n",
               umbra_shadow_technique_name(shadow->technique), stats.light_channels,
               stats.light_channels == 1 ? "" : "s");
        printf("shadow build: %.2f ms\n", stats.shadow_build_ms);
        printf("render: %.2f ms (%ux%u)\n", stats.render_ms, w, h);
        printf("shadow memory: %zu bytes\n", stats.shadow_memory_bytes);
        printf("wrote %s\n", png);
    }
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    umbra_context_release(ctx);
    free(rgba);
    return st ? 1 : 0;
}

#endif
