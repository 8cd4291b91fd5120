// SPDX-License-Identifier: Apache-2.0
/* consumer.c: the smallest application on libumbra alone (no umbra_io). It renders the built-in
 * scene with the exact reference shadows and checks the picture is not empty; before that it
 * reads the technique registry (every technique has a name, the reference a step parameter it
 * sets by name).
 * Usage: consumer_c            render; exit 0 on success
 *        consumer_c --idle     load the library, do no OpenCL work, print peak RSS (kB) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <umbra/umbra.h>

static long peak_rss_kb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmHWM:", 6) == 0)
            kb = strtol(line + 6, NULL, 10);
    if (f)
        fclose(f);
    return kb;
}

int main(int argc, char **argv)
{
    if (strcmp(umbra_version(), UMBRA_VERSION_STRING) != 0) {
        fprintf(stderr, "consumer_c: library %s, headers %s\n", umbra_version(),
                UMBRA_VERSION_STRING);
        return 1;
    }
    if (argc > 1 && strcmp(argv[1], "--idle") == 0) {
        printf("umbra %s, peak RSS %ld kB\n", umbra_version(), peak_rss_kb());
        return 0;
    }
    enum { W = 96, H = 72 };
    static float rgba[W * H * 4];
    umbra_context ctx = NULL;
    umbra_scene scene = {0};
    umbra_renderer r = NULL;
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_REFERENCE;
    for (uint32_t i = 0; i < umbra_technique_count(); ++i)
        if (!umbra_technique_get(i)->name[0])
            return 1;
    char msg[256];
    if (umbra_shadow_desc_set_param(&shadow, "reference", "reference_step", 0.5, msg,
                                    sizeof msg) != UMBRA_SUCCESS ||
        shadow.reference.step != 0.5f) {
        fprintf(stderr, "consumer_c: %s\n", msg);
        return 1;
    }

    umbra_status st = umbra_context_create(NULL, &ctx);
    if (!st) st = umbra_scene_create(ctx, "spheres", 48, &scene);
    if (!st) st = umbra_renderer_create(ctx, &r);
    if (!st) st = umbra_renderer_set_volume(r, scene.volume);
    if (!st) st = umbra_renderer_set_transfer_function(r, scene.tf);
    if (!st) st = umbra_renderer_set_camera(r, &scene.camera);
    if (!st) st = umbra_renderer_set_light(r, &scene.light);
    if (!st) st = umbra_renderer_set_options(r, &scene.options);
    if (!st) st = umbra_renderer_set_shadow(r, &shadow);
    if (!st) st = umbra_renderer_render(r, W, H, rgba);
    if (st)
        fprintf(stderr, "consumer_c: %s: %s\n", umbra_status_to_string(st),
                ctx ? umbra_context_last_message(ctx) : "no context");
    double alpha = 0;
    for (int i = 0; i < W * H; ++i)
        alpha += rgba[4 * i + 3];
    umbra_renderer_release(r);
    umbra_scene_release(&scene);
    umbra_context_release(ctx);
    if (st)
        return 1;
    printf("umbra %s: rendered %dx%d, mean alpha %.3f, peak RSS %ld kB\n", umbra_version(), W, H,
           alpha / (W * H), peak_rss_kb());
    return alpha > 0 ? 0 : 1;
}
