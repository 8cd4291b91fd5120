// SPDX-License-Identifier: Apache-2.0
/* example_convolution: the convolution-shadow paper's Figure 1 with umbra.
 *
 * Renders the carp CT (argv[1], else $UMBRA_DATA_DIR/carp_half.nhdr when it exists, else the
 * built-in "spheres" scene) five ways, as in the figure, plus umbra's exact shadows to compare:
 *   (a) ray casting with Blinn-Phong shading, no shadows          convolution_a_phong.png
 *   (b) ICS, slice distance 0.33 voxel: the reference setting     convolution_b_ics_0.33.png
 *   (c) ICS, slice distance 1 voxel                               convolution_c_ics_1.png
 *   (d) SCS, 1.3 voxel with 4 sub-samples (volume step 0.26)      convolution_d_scs_1.3_n4.png
 *   (e) SCS, 1.5 voxel with 5 sub-samples (volume step 0.25)      convolution_e_scs_1.5_n5.png
 *   (f) pre-integrated SCS, 1.5 voxel with 5 sub-samples          convolution_f_pi_scs_1.5_n5.png
 *   (r) the exact reference (a shadow ray per sample)             convolution_r_reference.png
 * and prints each frame's time, its number of slices, and its mean absolute difference from (b)
 * and from (r). argv[2] may name a transfer-function file (default: the carp's, as in
 * bench/scenes/carp.tf). Usage: example_convolution [volume.nhdr [tf.txt]] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "umbra/io.h"

/* Translucent flesh, opaque bone (bench/scenes/carp.tf). */
static const umbra_tf_point carp_tf[] = {
    {0.00f, {0.00f, 0.00f, 0.00f, 0.000f}}, {0.28f, {0.85f, 0.55f, 0.40f, 0.000f}},
    {0.33f, {0.85f, 0.55f, 0.40f, 0.012f}}, {0.42f, {0.85f, 0.55f, 0.40f, 0.012f}},
    {0.47f, {0.95f, 0.93f, 0.85f, 0.350f}}, {1.00f, {0.95f, 0.93f, 0.85f, 0.600f}},
};

typedef struct setting {
    const char *label, *file;
    umbra_shadow_technique technique;
    float slice_distance;
    uint32_t subsamples;
    int preintegrated, shading;
} setting;

static const setting settings[] = {
    {"(r) exact reference", "convolution_r_reference.png", UMBRA_SHADOW_REFERENCE, 0, 0, 0, 0},
    {"(a) ray casting, Blinn-Phong", "convolution_a_phong.png", UMBRA_SHADOW_NONE, 0, 0, 0, 1},
    {"(b) ICS 0.33 voxel", "convolution_b_ics_0.33.png", UMBRA_SHADOW_CONVOLUTION, 0.33f, 0, 0, 0},
    {"(c) ICS 1 voxel", "convolution_c_ics_1.png", UMBRA_SHADOW_CONVOLUTION, 1.0f, 0, 0, 0},
    {"(d) SCS 1.3 voxel, 4 sub-samples", "convolution_d_scs_1.3_n4.png", UMBRA_SHADOW_CONVOLUTION,
     1.3f, 4, 0, 0},
    {"(e) SCS 1.5 voxel, 5 sub-samples", "convolution_e_scs_1.5_n5.png", UMBRA_SHADOW_CONVOLUTION,
     1.5f, 5, 0, 0},
    {"(f) pre-integrated SCS 1.5, 5 sub-samples", "convolution_f_pi_scs_1.5_n5.png",
     UMBRA_SHADOW_CONVOLUTION, 1.5f, 5, 1, 0},
};
enum { NSET = sizeof settings / sizeof settings[0] };

static double mean_abs_diff(const float *a, const float *b, size_t pixels)
{
    double s = 0.0;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c)
            s += fabs((double)a[4 * i + c] - b[4 * i + c]);
    return s / (3.0 * pixels);
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

static void on_error(void *user, umbra_status st, const char *msg)
{
    (void)user;
    fprintf(stderr, "example_convolution: %s: %s\n", umbra_status_to_string(st), msg);
}

int main(int argc, char **argv)
{
    int rc = 1;
    umbra_context ctx = NULL;
    umbra_scene scene;
    memset(&scene, 0, sizeof scene);
    umbra_volume volume = NULL;
    umbra_transfer_function tf = NULL;
    umbra_renderer r = NULL;
    float *img[NSET] = {NULL};

    umbra_context_desc cd;
    umbra_context_desc_init(&cd);
    cd.error_callback = on_error;
    if (umbra_context_create(&cd, &ctx) != UMBRA_SUCCESS)
        return 1;

    char path[1024] = "";
    const char *dir = getenv("UMBRA_DATA_DIR");
    if (argc > 1)
        snprintf(path, sizeof path, "%s", argv[1]);
    else if (dir && *dir)
        snprintf(path, sizeof path, "%s/carp_half.nhdr", dir);
    int carp = path[0] && (argc > 1 || file_exists(path));

    umbra_render_desc rd;
    umbra_render_desc_init(&rd);
    umbra_camera cam;
    umbra_light light;
    memset(&light, 0, sizeof light);
    light.type = UMBRA_LIGHT_DIRECTIONAL;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;
    uint32_t w = 256, h = 128;
    if (carp) {
        if (umbra_volume_load(ctx, path, &volume) != UMBRA_SUCCESS)
            goto done;
        umbra_status st = argc > 2 ? umbra_transfer_function_load(ctx, argv[2], &tf)
                                   : umbra_transfer_function_create_from_points(ctx, carp_tf, 6,
                                                                                256, &tf);
        if (st != UMBRA_SUCCESS)
            goto done;
        /* From the fish's side (y), x up, its length (z) filling 90% of the width; the light
         * from the viewer's side, 36 degrees off the view axis, casting the bones' shadows
         * down and back through the flesh. */
        umbra_volume_info info;
        umbra_volume_get_info(volume, &info);
        const float d[3] = {0.15f, 1.0f, 0.2f};
        float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        float dist = 0.5f * info.extent[2] / 0.9f /
                         (tanf(15.0f * 3.14159265f / 180.0f) * (float)w / (float)h) +
                     0.5f * info.extent[1];
        memset(&cam, 0, sizeof cam);
        cam.projection = UMBRA_PERSPECTIVE;
        for (int a = 0; a < 3; ++a)
            cam.eye[a] = d[a] / len * dist;
        cam.up[0] = 1.0f;
        cam.fovy_degrees = 30.0f;
        light.direction[0] = -0.7f;
        light.direction[1] = -0.7f;
        light.direction[2] = -0.1f;
        printf("volume: %s\n", path);
    } else {
        if (umbra_scene_create(ctx, "spheres", 96, &scene) != UMBRA_SUCCESS)
            goto done;
        volume = scene.volume;
        tf = scene.tf;
        cam = scene.camera;
        rd = scene.options;
        light.direction[0] = -0.3f;
        light.direction[1] = -1.0f;
        light.direction[2] = -0.6f;
        w = h = 192;
        printf("volume: built-in spheres scene (set UMBRA_DATA_DIR or pass carp_half.nhdr)\n");
    }
    rd.ambient[0] = rd.ambient[1] = rd.ambient[2] = 0.25f;
    rd.background[0] = 0.08f;
    rd.background[1] = 0.08f;
    rd.background[2] = 0.1f;
    rd.background[3] = 1.0f;
    if (umbra_renderer_create(ctx, &r) || umbra_renderer_set_volume(r, volume) ||
        umbra_renderer_set_transfer_function(r, tf) || umbra_renderer_set_camera(r, &cam) ||
        umbra_renderer_set_light(r, &light))
        goto done;
    printf("%-44s %10s %7s %12s %12s\n", "", "ms", "slices", "diff vs (b)", "diff vs (r)");
    for (int i = 0; i < NSET; ++i) {
        const setting *s = &settings[i];
        img[i] = malloc((size_t)w * h * 4 * sizeof(float));
        if (!img[i])
            goto done;
        rd.shading = s->shading;
        rd.step = s->technique == UMBRA_SHADOW_NONE ? 0.5f : 0.33f;
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = s->technique;
        rd.preintegrated = 0;
        if (s->technique == UMBRA_SHADOW_CONVOLUTION) {
            sd.convolution.slice_distance = s->slice_distance;
            sd.convolution.subsamples = s->subsamples;
            rd.preintegrated = s->preintegrated;
        }
        if (umbra_renderer_set_options(r, &rd) || umbra_renderer_set_shadow(r, &sd) ||
            umbra_renderer_render(r, w, h, img[i]) ||
            umbra_image_write(ctx, s->file, w, h, img[i]))
            goto done;
        umbra_render_stats st;
        umbra_renderer_get_stats(r, &st);
        char slices[16] = "-";
        if (st.slices)
            snprintf(slices, sizeof slices, "%u", st.slices);
        printf("%-44s %10.1f %7s ", s->label, st.render_ms + st.shadow_build_ms, slices);
        if (i >= 2)
            printf("%12.5f %12.5f\n", mean_abs_diff(img[i], img[2], (size_t)w * h),
                   mean_abs_diff(img[i], img[0], (size_t)w * h));
        else
            printf("%12s %12.5f\n", "", mean_abs_diff(img[i], img[0], (size_t)w * h));
    }
    printf("wrote convolution_*.png\n");
    rc = 0;
done:
    for (int i = 0; i < NSET; ++i)
        free(img[i]);
    umbra_renderer_release(r);
    if (scene.volume) {
        umbra_scene_release(&scene);
    } else {
        umbra_transfer_function_release(tf);
        umbra_volume_release(volume);
    }
    umbra_context_release(ctx);
    return rc;
}
