// SPDX-License-Identifier: Apache-2.0
/* example_minimal: the smallest complete use of umbra's API: a built-in scene rendered with the
 * exact reference shadows into a PNG. Usage: example_minimal [out.png] */
#include <stdio.h>
#include <stdlib.h>

#include "umbra/io.h"

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "minimal.png";
    enum { W = 400, H = 300 };
    umbra_context ctx = NULL;
    umbra_scene scene = {0};
    umbra_renderer r = NULL;
    float *rgba = malloc((size_t)W * H * 4 * sizeof *rgba);
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_REFERENCE;

    umbra_status st = umbra_context_create(NULL, &ctx);
    if (!st) st = umbra_scene_create(ctx, "spheres", 96, &scene);
    if (!st) st = umbra_renderer_create(ctx, &r);
    if (!st) st = umbra_renderer_set_volume(r, scene.volume);
    if (!st) st = umbra_renderer_set_transfer_function(r, scene.tf);
    if (!st) st = umbra_renderer_set_camera(r, &scene.camera);
    if (!st) st = umbra_renderer_set_light(r, &scene.light);
    if (!st) st = umbra_renderer_set_options(r, &scene.options);
    if (!st) st = umbra_renderer_set_shadow(r, &shadow);
    if (!st) st = rgba ? umbra_renderer_render(r, W, H, rgba) : UMBRA_ERROR_OUT_OF_MEMORY;
    if (!st) st = umbra_image_write(ctx, out, W, H, rgba);
    if (st)
        fprintf(stderr, "example_minimal: %s: %s\n", umbra_status_to_string(st),
                ctx ? umbra_context_last_message(ctx) : "no OpenCL device");
    else
        printf("wrote %s\n", out);
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    umbra_context_release(ctx);
    free(rgba);
    return st ? 1 : 0;
}
