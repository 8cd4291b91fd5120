// SPDX-License-Identifier: Apache-2.0
/* host/scene.c: built-in scenes made in code, so the Quick start, tests and examples need no
 * data files. Each scene comes with its transfer function, camera, light and suggested options. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static const char *const scene_names[] = {"spheres", "slab", "marschner-lobb", NULL};

const char *const *umbra_scene_names(void) { return scene_names; }

/* Sphere k: centre and radius as fractions of the box, and the plateau value that the transfer
 * function colours. */
typedef struct sphere {
    float c[3], r, value;
} sphere;

static const sphere spheres[] = {
    {{0.34f, 0.76f, 0.42f}, 0.17f, 1.00f}, /* near-opaque white, high: shadows the red one */
    {{0.58f, 0.44f, 0.50f}, 0.18f, 0.30f}, /* translucent red */
    {{0.28f, 0.24f, 0.66f}, 0.16f, 0.55f}, /* translucent green */
    {{0.74f, 0.20f, 0.26f}, 0.15f, 0.80f}, /* translucent blue */
};

static float smooth_edge(float d, float width)
{
    /* 1 inside, 0 outside, a linear ramp over `width` voxels across the surface */
    float x = 0.5f - d / width;
    return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
}

static void fill_spheres(float *v, uint32_t n)
{
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) {
                float p[3] = {(x + 0.5f) / n, (y + 0.5f) / n, (z + 0.5f) / n};
                float val = 0.0f;
                for (size_t k = 0; k < sizeof spheres / sizeof spheres[0]; ++k) {
                    const sphere *s = &spheres[k];
                    float dx = p[0] - s->c[0], dy = p[1] - s->c[1], dz = p[2] - s->c[2];
                    float d = (sqrtf(dx * dx + dy * dy + dz * dz) - s->r) * (float)n;
                    float w = smooth_edge(d, 1.5f);
                    if (w > 0.0f)
                        val = fmaxf(val, w * s->value);
                }
                v[((size_t)z * n + y) * n + x] = val;
            }
}

static void fill_marschner_lobb(float *v, uint32_t n)
{
    const float fm = 6.0f, a = 0.25f, pi = 3.14159265358979f;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) {
                float px = 2.0f * (x + 0.5f) / n - 1.0f;
                float py = 2.0f * (y + 0.5f) / n - 1.0f;
                float pz = 2.0f * (z + 0.5f) / n - 1.0f;
                float r = sqrtf(px * px + pz * pz);
                float rho_r = cosf(2.0f * pi * fm * cosf(pi * r / 2.0f));
                /* The signal's axis is the world's up (y), so the ground plane sees its rings. */
                v[((size_t)z * n + y) * n + x] =
                    (1.0f - sinf(pi * py / 2.0f) + a * (1.0f + rho_r)) / (2.0f * (1.0f + a));
            }
}

static umbra_status make_volume(umbra_context ctx, const float *data, uint32_t nx, uint32_t ny,
                                uint32_t nz, umbra_volume *out)
{
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.data = data;
    d.type = UMBRA_FLOAT32;
    d.dims[0] = nx;
    d.dims[1] = ny;
    d.dims[2] = nz;
    d.value_range_given = 1;
    d.value_min = 0.0f;
    d.value_max = 1.0f;
    return umbra_volume_create(ctx, &d, out);
}

static void default_light(umbra_light *l)
{
    memset(l, 0, sizeof *l);
    l->type = UMBRA_LIGHT_DIRECTIONAL;
    l->direction[0] = 0.5f;
    l->direction[1] = -1.0f;
    l->direction[2] = 0.2f;
    l->color[0] = l->color[1] = l->color[2] = 1.0f;
}

umbra_status umbra_scene_create(umbra_context ctx, const char *name, uint32_t res,
                                umbra_scene *out)
{
    const char *fn = "umbra_scene_create";
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    memset(out, 0, sizeof *out);
    if (!ctx || !name)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx %p, name %p: neither may "
                           "be NULL", fn, (void *)ctx, (const void *)name);
    if (res != 0 && (res < 4 || res > 1024))
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: resolution %u must be 0 (default) or lie in [4, 1024]", fn, res);
    umbra_status st = UMBRA_SUCCESS;
    float *data = NULL;
    umbra_render_desc_init(&out->options);
    out->options.ground_color[0] = out->options.ground_color[1] = out->options.ground_color[2] = 0.55f;
    default_light(&out->light);
    float diag = 0.0f;
    if (strcmp(name, "spheres") == 0) {
        uint32_t n = res ? res : 128;
        data = malloc((size_t)n * n * n * sizeof *data);
        if (!data)
            goto oom;
        fill_spheres(data, n);
        if ((st = make_volume(ctx, data, n, n, n, &out->volume)) != UMBRA_SUCCESS)
            goto fail;
        /* Bands around each sphere's plateau value; alpha is per voxel. Saturated colours make
         * coloured shadows in UMBRA_TRANSMISSION_COLORED mode (a red sphere passes red light). */
        const umbra_tf_point pts[] = {
            {0.00f, {0.0f, 0.0f, 0.0f, 0.0f}},  {0.22f, {0.9f, 0.1f, 0.08f, 0.0f}},
            {0.26f, {0.9f, 0.1f, 0.08f, 0.06f}}, {0.34f, {0.9f, 0.1f, 0.08f, 0.06f}},
            {0.38f, {0.1f, 0.85f, 0.15f, 0.0f}}, {0.47f, {0.1f, 0.85f, 0.15f, 0.0f}},
            {0.51f, {0.1f, 0.85f, 0.15f, 0.05f}}, {0.59f, {0.1f, 0.85f, 0.15f, 0.05f}},
            {0.63f, {0.1f, 0.2f, 0.95f, 0.0f}}, {0.72f, {0.1f, 0.2f, 0.95f, 0.0f}},
            {0.76f, {0.1f, 0.2f, 0.95f, 0.08f}}, {0.84f, {0.1f, 0.2f, 0.95f, 0.08f}},
            {0.88f, {0.95f, 0.95f, 0.9f, 0.0f}}, {0.93f, {0.95f, 0.95f, 0.9f, 0.0f}},
            {0.97f, {0.95f, 0.95f, 0.9f, 0.6f}}, {1.00f, {0.95f, 0.95f, 0.9f, 0.6f}},
        };
        if ((st = umbra_transfer_function_create_from_points(ctx, pts, 16, 256, &out->tf)))
            goto fail;
        out->options.ground_plane = 1;
        out->options.transmission = UMBRA_TRANSMISSION_COLORED;
        diag = 0.75f * sqrtf(3.0f) * (float)n; /* frame the spheres, not the whole box */
    } else if (strcmp(name, "slab") == 0) {
        uint32_t n = res ? res : 64, h = n / 4 ? n / 4 : 1;
        data = malloc((size_t)n * h * n * sizeof *data);
        if (!data)
            goto oom;
        for (size_t i = 0; i < (size_t)n * h * n; ++i)
            data[i] = 1.0f;
        if ((st = make_volume(ctx, data, n, h, n, &out->volume)) != UMBRA_SUCCESS)
            goto fail;
        /* Constant grey material: transmittance through d voxels is (1 - 0.03)^d. */
        const umbra_tf_point pts[] = {{0.0f, {0.7f, 0.7f, 0.7f, 0.03f}}};
        if ((st = umbra_transfer_function_create_from_points(ctx, pts, 1, 2, &out->tf)))
            goto fail;
        out->options.ground_plane = 1;
        out->options.ground_offset = 0.1f;
        diag = sqrtf(2.0f * n * n + (float)h * h);
        out->light.direction[0] = 0.3f;
        out->light.direction[2] = 0.2f;
    } else if (strcmp(name, "marschner-lobb") == 0) {
        uint32_t n = res ? res : 64;
        data = malloc((size_t)n * n * n * sizeof *data);
        if (!data)
            goto oom;
        fill_marschner_lobb(data, n);
        if ((st = make_volume(ctx, data, n, n, n, &out->volume)) != UMBRA_SUCCESS)
            goto fail;
        const umbra_tf_point pts[] = {
            {0.0f, {1.0f, 0.8f, 0.4f, 0.0f}}, {0.45f, {1.0f, 0.8f, 0.4f, 0.0f}},
            {0.5f, {1.0f, 0.75f, 0.35f, 0.35f}}, {0.55f, {1.0f, 0.8f, 0.4f, 0.0f}},
            {1.0f, {1.0f, 0.8f, 0.4f, 0.0f}},
        };
        if ((st = umbra_transfer_function_create_from_points(ctx, pts, 5, 256, &out->tf)))
            goto fail;
        out->options.ground_plane = 1;
        out->options.shading = 1;
        diag = sqrtf(3.0f) * (float)n;
    } else {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: unknown scene '%s' (known: spheres, slab, marschner-lobb)", fn,
                           name);
    }
    free(data);
    const float dir[3] = {0.75f, 0.5f, 1.0f};
    out->camera = umbra_camera_orbit(dir, diag, 30.0f);
    out->camera.target[1] = -0.08f * diag; /* look a little down, to show the plane */
    return UMBRA_SUCCESS;
oom:
    st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory for scene '%s'", fn, name);
fail:
    free(data);
    umbra_scene_release(out);
    return st;
}

void umbra_scene_release(umbra_scene *scene)
{
    if (!scene)
        return;
    umbra_volume_release(scene->volume);
    umbra_transfer_function_release(scene->tf);
    memset(scene, 0, sizeof *scene);
}
