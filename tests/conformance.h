// SPDX-License-Identifier: Apache-2.0
/* tests/conformance.h: the conformance suite's cases and its table of per-technique error bounds,
 * shared by tests/test_conformance.c (which asserts them for every technique of the registry)
 * and `umbra-bench conformance` (which prints every error against its bound). Public API only.
 *
 * Cases. Each is a small scene: a volume, a transfer function for the light, a light, a camera,
 * render options and, for the cases against the reference, a cloud of query points.
 *   slab, slab_colored  the analytic slab: a homogeneous slab, invisible to the view (its view
 *                       transfer function is transparent), that only shadows the ground plane
 *                       below it; every ground pixel gives its shadow factor S back, compared
 *                       with exp(-sigma_c L), L the light path through the slab (in double),
 *                       grey and with coloured transmission
 *   the others          hard cases, compared with the exact reference at a fine step (0.1
 *                       voxel): its image, and its factors at the query points; points with
 *                       nothing between them and the light must be lit exactly (factor 1)
 * A technique without a light pass (UMBRA_TECHNIQUE_NO_LIGHT: none) is compared with the
 * unshadowed answer instead: factor 1 everywhere, the reference's image under a transparent light
 * transfer function.
 *
 * Bounds (conf_rows). One row per technique setting (the technique's defaults, then its "key=
 * value;..." params, tests/setting.h), one bound per case and measure, set at about 1.5x what the
 * setting measured on PoCL (the measured values are printed by the test and by the bench); the
 * bound CONF_UNSUPPORTED says the technique must refuse the case with UMBRA_ERROR_UNSUPPORTED,
 * CONF_NA that the measure does not apply (a technique without a per-point lookup has no query
 * error). A technique added to the registry needs its rows here: the suite fails for a
 * technique without one. */
#ifndef UMBRA_TESTS_CONFORMANCE_H
#define UMBRA_TESTS_CONFORMANCE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "setting.h"
#include "umbra/umbra.h"

/* ---- the cases ------------------------------------------------------------------------------- */

enum {
    CONF_SLAB,              /* analytic: grey */
    CONF_SLAB_COLORED,      /* analytic: coloured transmission */
    CONF_AXIS_DOWN,         /* directional light straight down the y axis */
    CONF_AXIS_X,            /* directional light along +x (from behind the viewer's side) */
    CONF_GRAZING,           /* directional light 0.06 degrees off a face */
    CONF_POINT_FACE,        /* point light on the top face of the box */
    CONF_POINT_CORNER,      /* point light on a corner */
    CONF_POINT_INSIDE,      /* point light inside the box, in empty space */
    CONF_POINT_IN_MATERIAL, /* point light inside the ball */
    CONF_NEAR_OPAQUE,       /* alpha 0.98 per voxel: hard shadow edges */
    CONF_NEAR_TRANSPARENT,  /* alpha 0.004 over paths of up to 96 voxels */
    CONF_SHARP_TF,          /* a step transfer function: an isosurface that must not shadow
                               itself */
    CONF_CASES
};

static const char *const conf_case_names[CONF_CASES] = {
    "slab", "slab_colored", "axis_down", "axis_x", "grazing", "point_face", "point_corner",
    "point_inside", "point_in_material", "near_opaque", "near_transparent", "sharp_tf",
};

#define CONF_UNSUPPORTED (-1.0) /* the technique refuses the case: UMBRA_ERROR_UNSUPPORTED */
#define CONF_NA (-2.0)          /* the measure does not apply */
#define CONF_FINE_STEP 0.1f     /* the reference's step for the yardstick, voxels */

typedef struct conf_scene {
    umbra_volume volume;
    umbra_transfer_function tf, light_tf; /* light_tf may be NULL: the view's */
    umbra_light light;
    umbra_camera camera;
    umbra_render_desc options;
    uint32_t width, height;
    int analytic;             /* the slab cases */
    double half[3];           /* the box's half extent (world = voxels, spacing 1) */
    double ground_y;          /* the ground plane's height (analytic cases) */
    double sigma[3];          /* extinction per voxel length, per channel (analytic cases) */
    float *points;            /* count query points (world) */
    size_t count;
    float *lit;               /* lit_count points with nothing between them and the light */
    size_t lit_count;
} conf_scene;

static inline void conf_scene_release(conf_scene *s)
{
    umbra_volume_release(s->volume);
    umbra_transfer_function_release(s->tf);
    umbra_transfer_function_release(s->light_tf);
    free(s->points);
    free(s->lit);
    memset(s, 0, sizeof *s);
}

static inline umbra_light conf_directional(float x, float y, float z)
{
    umbra_light l;
    memset(&l, 0, sizeof l);
    l.type = UMBRA_LIGHT_DIRECTIONAL;
    l.direction[0] = x;
    l.direction[1] = y;
    l.direction[2] = z;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    return l;
}

static inline umbra_light conf_point(float x, float y, float z)
{
    umbra_light l = conf_directional(0.0f, -1.0f, 0.0f);
    l.type = UMBRA_LIGHT_POINT;
    l.position[0] = x;
    l.position[1] = y;
    l.position[2] = z;
    return l;
}

/* A float volume of nx x ny x nz voxels (x fastest) copied from data: unit spacing, value range
 * [0, 1], bricks of brick_size voxels (0: umbra's default). */
static inline umbra_status conf_volume_of(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                          const float *data, uint32_t brick_size,
                                          umbra_volume *out)
{
    umbra_volume_desc vd;
    umbra_volume_desc_init(&vd);
    vd.data = data;
    vd.type = UMBRA_FLOAT32;
    vd.dims[0] = nx;
    vd.dims[1] = ny;
    vd.dims[2] = nz;
    vd.value_range_given = 1;
    vd.value_min = 0.0f;
    vd.value_max = 1.0f;
    if (brick_size)
        vd.brick_size = brick_size;
    return umbra_volume_create(ctx, &vd, out);
}

/* The same with voxel values f(x, y, z) at the voxel centres, box-centred coordinates. */
static inline umbra_status conf_volume(umbra_context ctx, uint32_t nx, uint32_t ny, uint32_t nz,
                                       float (*f)(float, float, float), umbra_volume *out)
{
    float *data = malloc((size_t)nx * ny * nz * sizeof *data);
    if (!data)
        return UMBRA_ERROR_OUT_OF_MEMORY;
    for (uint32_t z = 0; z < nz; ++z)
        for (uint32_t y = 0; y < ny; ++y)
            for (uint32_t x = 0; x < nx; ++x)
                data[((size_t)z * ny + y) * nx + x] = f(x + 0.5f - 0.5f * nx, y + 0.5f - 0.5f * ny,
                                                        z + 0.5f - 0.5f * nz);
    umbra_status st = conf_volume_of(ctx, nx, ny, nz, data, 0, out);
    free(data);
    return st;
}

static inline float conf_one(float x, float y, float z)
{
    (void)x, (void)y, (void)z;
    return 1.0f;
}

/* A ball of radius 6 voxels at (7, -6, 5) with a one-voxel smooth edge; empty around the box's
 * middle. */
static inline float conf_ball(float x, float y, float z)
{
    float dx = x - 7.0f, dy = y + 6.0f, dz = z - 5.0f;
    return fminf(1.0f, fmaxf(0.0f, 0.5f - (sqrtf(dx * dx + dy * dy + dz * dz) - 6.0f)));
}

/* A centred ball of radius 9 whose value ramps from 1 inside to 0 over 4 voxels. */
static inline float conf_ramp_ball(float x, float y, float z)
{
    return fminf(1.0f, fmaxf(0.0f, 0.5f - 0.25f * (sqrtf(x * x + y * y + z * z) - 9.0f)));
}

/* Two soft balls of different density (0.6 and 0.9) over a thin slab (0.35) in a 40 x 32 x 36
 * grid: partial shadows in colour (the rebuild and progressive-shadow cases). */
enum { CONF_TWO_BALLS_NX = 40, CONF_TWO_BALLS_NY = 32, CONF_TWO_BALLS_NZ = 36 };

static inline float conf_two_balls(float x, float y, float z)
{
    x += 0.5f * CONF_TWO_BALLS_NX, y += 0.5f * CONF_TWO_BALLS_NY; /* from the corner */
    z += 0.5f * CONF_TWO_BALLS_NZ;
    float d1 = sqrtf((x - 14.0f) * (x - 14.0f) + (y - 20.0f) * (y - 20.0f) +
                     (z - 15.0f) * (z - 15.0f)) - 7.0f;
    float d2 = sqrtf((x - 27.0f) * (x - 27.0f) + (y - 17.0f) * (y - 17.0f) +
                     (z - 22.0f) * (z - 22.0f)) - 5.0f;
    float v = fmaxf(0.6f * fminf(1.0f, fmaxf(0.0f, 0.5f - d1)),
                    0.9f * fminf(1.0f, fmaxf(0.0f, 0.5f - d2)));
    if (y > 5.0f && y < 7.0f)
        v = fmaxf(v, 0.35f);
    return v;
}

/* A two-point transfer function: (r, g, b, a) at 0 and 1. */
static inline umbra_status conf_tf(umbra_context ctx, const float lo[4], const float hi[4],
                                   umbra_transfer_function *out)
{
    float rgba[8];
    memcpy(rgba, lo, sizeof rgba / 2);
    memcpy(rgba + 4, hi, sizeof rgba / 2);
    return umbra_transfer_function_create(ctx, rgba, 2, out);
}

/* The length of the part of p + t d, t in [0, t_max] (d unit), inside the box [-half, half], in
 * double: the analytic path for exp(-sigma d) checks. */
static inline double conf_path_in_box(const double p[3], const double d[3], const double half[3],
                                      double t_max)
{
    double lo = 0.0, hi = t_max;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (p[a] < -half[a] || p[a] > half[a])
                return 0.0;
            continue;
        }
        double ta = (-half[a] - p[a]) / d[a], tb = (half[a] - p[a]) / d[a];
        lo = fmax(lo, fmin(ta, tb));
        hi = fmin(hi, fmax(ta, tb));
    }
    return hi > lo ? hi - lo : 0.0;
}

/* The query cloud: 7^3 points on a grid 1.4 times the box, and the lit points: for a directional
 * light, points upwind of the box; for a point light outside the box, points beyond it; at the
 * empty middle, points 1.5 voxels around it. */
static inline umbra_status conf_points(conf_scene *s)
{
    s->count = 7 * 7 * 7;
    s->points = malloc(s->count * 3 * sizeof *s->points);
    s->lit = malloc(6 * 3 * sizeof *s->lit);
    if (!s->points || !s->lit)
        return UMBRA_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < s->count; ++i)
        for (int a = 0; a < 3; ++a) {
            size_t k = a == 0 ? i % 7 : a == 1 ? i / 7 % 7 : i / 49;
            s->points[3 * i + a] = (float)(s->half[a] * (-1.4 + 2.8 * (double)k / 6.0));
        }
    const umbra_light *l = &s->light;
    const double diag = 2.0 * sqrt(s->half[0] * s->half[0] + s->half[1] * s->half[1] +
                                   s->half[2] * s->half[2]);
    s->lit_count = 0;
    if (l->type == UMBRA_LIGHT_DIRECTIONAL) {
        double len = sqrt((double)l->direction[0] * l->direction[0] +
                          (double)l->direction[1] * l->direction[1] +
                          (double)l->direction[2] * l->direction[2]);
        for (int k = 0; k < 3; ++k, ++s->lit_count)
            for (int a = 0; a < 3; ++a)
                s->lit[3 * k + a] = (float)(-l->direction[a] / len * 2.0 * diag + (k - 1) * 3.0);
        return UMBRA_SUCCESS;
    }
    const float *P = l->position;
    int inside = 1;
    for (int a = 0; a < 3; ++a)
        inside &= fabs(P[a]) < s->half[a];
    if (inside && fabsf(P[0]) + fabsf(P[1]) + fabsf(P[2]) < 1.0f) {
        static const float off[6][3] = {{1.5f, 0, 0}, {-1.5f, 0, 0}, {0, 1.5f, 0},
                                        {0, -1.5f, 0}, {0, 0, 1.5f}, {0, 0, -1.5f}};
        for (int k = 0; k < 6; ++k, ++s->lit_count)
            for (int a = 0; a < 3; ++a)
                s->lit[3 * k + a] = P[a] + off[k][a];
    } else if (!inside) {
        for (int a = 0; a < 3; ++a) {
            float out = P[a] > 0.0f ? 1.0f : -1.0f;
            s->lit[a] = P[a] + (fabs(P[a]) >= s->half[a] - 0.01 ? out * 2.0f : 0.0f);
            s->lit[3 + a] = P[a] * 1.8f + (a == 1 ? 1.0f : 0.0f);
        }
        s->lit_count = 2;
    }
    return UMBRA_SUCCESS;
}

/* Builds case c into *s (released with conf_scene_release, also after a failure). */
static inline umbra_status conf_scene_make(umbra_context ctx, int c, conf_scene *s)
{
    memset(s, 0, sizeof *s);
    umbra_render_desc_init(&s->options);
    s->width = s->height = 40;
    umbra_status st;
    if (c == CONF_SLAB || c == CONF_SLAB_COLORED) {
        /* 24 x 6 x 24 voxels of one value, seen from straight above with an orthographic camera
         * that takes in the slab's shadow on the ground and lit ground around it. */
        static const float clear[4] = {0, 0, 0, 0};
        const float grey[4] = {0.5f, 0.5f, 0.5f, 0.06f}, colour[4] = {0.9f, 0.5f, 0.2f, 0.06f};
        const float *light = c == CONF_SLAB ? grey : colour;
        s->analytic = 1;
        s->width = s->height = 48;
        s->half[0] = s->half[2] = 12.0;
        s->half[1] = 3.0;
        if ((st = conf_volume(ctx, 24, 6, 24, conf_one, &s->volume)) ||
            (st = conf_tf(ctx, clear, clear, &s->tf)) ||
            (st = conf_tf(ctx, light, light, &s->light_tf)))
            return st;
        s->light = conf_directional(0.35f, -1.0f, 0.2f);
        memset(&s->camera, 0, sizeof s->camera);
        s->camera.projection = UMBRA_ORTHOGRAPHIC;
        s->camera.eye[1] = 40.0f;
        s->camera.up[2] = -1.0f;
        s->camera.ortho_height = 44.0f;
        s->camera.fovy_degrees = 30.0f;
        s->options.ground_plane = 1;
        s->options.ground_offset = 0.1f;
        s->options.transmission = c == CONF_SLAB ? UMBRA_TRANSMISSION_GREY
                                                 : UMBRA_TRANSMISSION_COLORED;
        const double diag = sqrt(24.0 * 24 + 6.0 * 6 + 24.0 * 24);
        s->ground_y = -s->half[1] - (double)s->options.ground_offset * diag;
        for (int k = 0; k < 3; ++k)
            s->sigma[k] = -log(1.0 - (double)light[3]) *
                          (c == CONF_SLAB ? 1.0 : 1.0 - (double)light[k]);
        return UMBRA_SUCCESS;
    }
    s->half[0] = s->half[1] = s->half[2] = 16.0;
    const float orbit[3] = {0.6f, 0.45f, 1.0f};
    s->camera = umbra_camera_orbit(orbit, 1.74f * 32.0f, 30.0f);
    s->options.transmission = UMBRA_TRANSMISSION_COLORED;
    s->options.ground_plane = 1;
    const float clear[4] = {0, 0, 0, 0}, orange[4] = {0.9f, 0.4f, 0.1f, 0.3f};
    const float h = 16.0f;
    float (*f)(float, float, float) = conf_ball;
    const float *hi = orange;
    const float dense[4] = {0.9f, 0.4f, 0.1f, 0.98f}, faint[4] = {0.8f, 0.6f, 0.4f, 0.004f};
    uint32_t nx = 32;
    switch (c) {
    case CONF_AXIS_DOWN: s->light = conf_directional(0, -1, 0); break;
    case CONF_AXIS_X: s->light = conf_directional(1, 0, 0); break;
    case CONF_GRAZING: s->light = conf_directional(1, -1e-3f, 0); break;
    case CONF_POINT_FACE: s->light = conf_point(0, h, 0); break;
    case CONF_POINT_CORNER: s->light = conf_point(-h, -h, h); break;
    case CONF_POINT_INSIDE: s->light = conf_point(0, 0, 0); break;
    case CONF_POINT_IN_MATERIAL: s->light = conf_point(5, -4, 3); break;
    case CONF_NEAR_OPAQUE:
        hi = dense;
        s->light = conf_directional(-0.3f, -1.0f, -0.6f);
        break;
    case CONF_NEAR_TRANSPARENT: {
        /* 96 x 32 x 32 voxels of one faint value, lit along its length from the viewer's side. */
        f = conf_one;
        hi = faint;
        nx = 96;
        s->half[0] = 48.0;
        const float along[3] = {1.0f, 0.5f, 0.6f};
        s->camera = umbra_camera_orbit(along, 1.1f * 2.0f * 55.4f, 30.0f);
        s->light = conf_directional(-1.0f, -0.15f, -0.1f);
        break;
    }
    case CONF_SHARP_TF:
        f = conf_ramp_ball;
        s->light = conf_directional(-0.3f, -1.0f, -0.6f);
        break;
    default: return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    if ((st = conf_volume(ctx, nx, 32, 32, f, &s->volume)) != UMBRA_SUCCESS)
        return st;
    if (c == CONF_SHARP_TF) {
        /* Transparent below the value 0.5, 0.9 from there: a sharp surface halfway up the ramp. */
        float rgba[256 * 4];
        for (int i = 0; i < 256; ++i) {
            const float a = i >= 128 ? 0.9f : 0.0f;
            rgba[4 * i] = 0.85f, rgba[4 * i + 1] = 0.8f, rgba[4 * i + 2] = 0.7f;
            rgba[4 * i + 3] = a;
        }
        st = umbra_transfer_function_create(ctx, rgba, 256, &s->tf);
    } else {
        st = conf_tf(ctx, f == conf_one ? hi : clear, hi, &s->tf);
    }
    return st != UMBRA_SUCCESS ? st : conf_points(s);
}

/* ---- rendering a case ------------------------------------------------------------------------ */

/* A renderer on scene s with the technique `technique` and its `params` (tests/setting.h) over
 * the defaults; the reference at CONF_FINE_STEP when technique is NULL; a transparent light
 * transfer function with `unlit`. */
static inline umbra_status conf_renderer(umbra_context ctx, const conf_scene *s,
                                         const char *technique, const char *params, int unlit,
                                         umbra_renderer *out, char *msg, size_t msg_size)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    umbra_render_desc o = s->options;
    umbra_transfer_function clear = NULL;
    umbra_renderer r = NULL;
    umbra_status st;
    msg[0] = '\0';
    if (technique) {
        if (umbra_shadow_technique_parse(technique, &d.technique) != UMBRA_SUCCESS) {
            snprintf(msg, msg_size, "technique '%s' is not in the registry", technique);
            return UMBRA_ERROR_INVALID_ARGUMENT;
        }
        if (setting_apply(&d, &o.preintegrated, params, msg, msg_size) != 0)
            return UMBRA_ERROR_INVALID_ARGUMENT;
    } else {
        d.technique = UMBRA_SHADOW_REFERENCE;
        d.reference.step = CONF_FINE_STEP;
    }
    static const float zero[4] = {0, 0, 0, 0};
    if ((st = umbra_renderer_create(ctx, &r)) || (st = umbra_renderer_set_volume(r, s->volume)) ||
        (st = umbra_renderer_set_transfer_function(r, s->tf)) ||
        (s->light_tf && (st = umbra_renderer_set_light_transfer_function(r, s->light_tf))) ||
        (unlit && ((st = conf_tf(ctx, zero, zero, &clear)) ||
                   (st = umbra_renderer_set_light_transfer_function(r, clear)))) ||
        (st = umbra_renderer_set_camera(r, &s->camera)) ||
        (st = umbra_renderer_set_light(r, &s->light)) ||
        (st = umbra_renderer_set_options(r, &o)) || (st = umbra_renderer_set_shadow(r, &d))) {
        snprintf(msg, msg_size, "%s", umbra_context_last_message(ctx));
        umbra_renderer_release(r);
        r = NULL;
    }
    umbra_transfer_function_release(clear);
    *out = r;
    return st;
}

/* ---- the measures ---------------------------------------------------------------------------- */

/* The slab cases: the shadow factor each ground pixel shows, against the analytic one (1 with
 * unlit). mean over every pixel and channel; max over the pixels away from the shadow's edges
 * (where the analytic factor of no neighbour differs from the pixel's by 0.02 or more). */
static inline void conf_slab_error(const conf_scene *s, const float *img, int unlit, double *mean,
                                   double *max)
{
    const uint32_t W = s->width, H = s->height;
    const double half_h = 0.5 * s->camera.ortho_height, half_w = half_h * W / H;
    const umbra_light *l = &s->light;
    double d[3] = {l->direction[0], l->direction[1], l->direction[2]};
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int a = 0; a < 3; ++a)
        d[a] = -d[a] / len; /* toward the light */
    const double ndl = d[1]; /* the ground's normal is +y */
    double *want = malloc((size_t)W * H * 3 * sizeof *want);
    double sum = 0.0, worst = 0.0;
    if (!want) {
        *mean = *max = INFINITY;
        return;
    }
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const double p[3] = {((x + 0.5) / W * 2.0 - 1.0) * half_w, s->ground_y,
                                 -(1.0 - (y + 0.5) / H * 2.0) * half_h};
            const double L = conf_path_in_box(p, d, s->half, INFINITY);
            for (int k = 0; k < 3; ++k)
                want[3 * ((size_t)y * W + x) + k] = unlit ? 1.0 : exp(-s->sigma[k] * L);
        }
    const double ground = s->options.ground_color[0];
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const size_t i = (size_t)y * W + x;
            int edge = x == 0 || y == 0 || x + 1 == W || y + 1 == H;
            for (int k = 0; k < 3 && !edge; ++k)
                for (int n = 0; n < 4; ++n) {
                    const size_t j = n == 0 ? i - 1 : n == 1 ? i + 1 : n == 2 ? i - W : i + W;
                    edge |= fabs(want[3 * j + k] - want[3 * i + k]) >= 0.02;
                }
            for (int k = 0; k < 3; ++k) {
                const double got = ((double)img[4 * i + k] / ground - s->options.ambient[k]) /
                                   ((double)l->color[k] * ndl);
                const double e = fabs(got - want[3 * i + k]);
                sum += isfinite(e) ? e : 1e9;
                if (!edge && !(e <= worst))
                    worst = isfinite(e) ? e : 1e9;
            }
        }
    free(want);
    *mean = sum / (3.0 * W * H);
    *max = worst;
}

/* Mean absolute difference over n values; infinite if any is not finite. */
static inline double conf_mean_abs(const float *a, const float *b, size_t n, size_t stride)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (size_t k = 0; k < 3; ++k) {
            const double e = fabs((double)a[stride * i + k] - b[stride * i + k]);
            if (!isfinite(e))
                return INFINITY;
            sum += e;
        }
    return sum / (3.0 * n);
}

/* ---- the bounds ------------------------------------------------------------------------------ */

typedef struct conf_row {
    const char *technique; /* its registry name */
    const char *params;    /* over its defaults, "" for none */
    /* Per case: the slab cases' mean error of the ground's factor; the others' mean error of the
     * image's RGB against the reference's image. */
    double image[CONF_CASES];
    /* Per case: the slab cases' largest error away from the shadow's edges; the others' mean
     * error of the factors at the query points against the reference's. */
    double point[CONF_CASES];
} conf_row;

#define U CONF_UNSUPPORTED
#define NA CONF_NA
/* Cases, in order: slab, slab_colored, axis_down, axis_x, grazing, point_face, point_corner,
 * point_inside, point_in_material, near_opaque, near_transparent, sharp_tf. */
static const conf_row conf_rows[] = {
    {"none", "",
     {1e-5, 1e-5, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6},
     {1e-5, 1e-5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}},
    {"reference", "",
     {2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5},
     {2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 2e-5, 3e-5, 3e-5, 1e-4, 3e-5, 2e-5, 2e-5}},
    {"threshold", "",
     {0.15, 0.075, 0.012, 0.0045, 0.0045, 0.027, 0.0051, 0.027, 0.16, 0.0084, 0.0026, 0.025},
     {0.5, 0.42, 0.011, 0.0078, 0.0078, 0.026, 0.02, 0.037, 0.73, 0.02, 0.041, 0.04}},
    {"cssm", "",
     {0.056, 0.04, 0.0052, 0.00084, 0.00083, 0.011, 0.00056, 0.0089, 0.032, 0.0035, 0.0012,
      0.011},
     {0.55, 0.63, 0.0041, 0.0066, 0.0057, 0.01, 0.011, 0.017, 0.15, 0.0064, 0.03, 0.016}},
    {"deep", "",
     {0.0023, 0.0012, 0.00092, 0.00013, 0.00013, 0.0014, 0.00014, 0.00073, 0.00085, 0.00093,
      4.1e-5, 0.0036},
     {2e-5, 3e-5, 0.00044, 0.0017, 0.00087, 0.0014, 0.0013, 0.0016, 0.0033, 0.0019, 0.0009,
      0.0024}},
    {"deep", "max_nodes=4",
     {0.0023, 0.0012, 0.0011, 0.00032, 0.00031, 0.0015, 0.00031, 0.00092, 0.0011, 0.00098,
      4.1e-5, 0.0038},
     {2e-5, 3e-5, 0.0005, 0.0018, 0.00098, 0.0017, 0.0015, 0.0019, 0.0039, 0.0022, 0.0009,
      0.0036}},
    {"convolution", "",
     {0.015, 0.0072, 0.0025, U, U, U, U, U, U, 0.0038, 0.00083, 0.012},
     {0.075, 0.064, NA, U, U, U, U, U, U, NA, NA, NA}},
    {"moments", "",
     {6e-4, 3e-4, 9.5e-4, 4e-4, 4e-4, 9.2e-4, 2.6e-4, 3.7e-4, 7.6e-4, 9.9e-4, 1.9e-5, 0.0089},
     {7.6e-5, 6.6e-5, 6.3e-4, 7.2e-4, 7.2e-4, 8.9e-4, 9.4e-4, 7.5e-4, 3.4e-3, 2e-3, 8.2e-4,
      3.6e-3}},
    {"moments", "moments=4;moment_bits=16",
     {7.8e-4, 4e-4, 1e-3, 5e-4, 5e-4, 1e-3, 3.5e-4, 4.9e-4, 8.4e-4, 1.2e-3, 3.4e-5, 0.011},
     {9.6e-4, 8.3e-4, 1e-3, 9.2e-4, 9.2e-4, 1.1e-3, 1.2e-3, 9.6e-4, 3.6e-3, 2.4e-3, 1.4e-3,
      5.2e-3}},
};
#undef U
#undef NA

#define CONF_ROWS (sizeof conf_rows / sizeof conf_rows[0])

/* The errors of one row on one case, as conf_run measures them. */
typedef struct conf_result {
    umbra_status status;  /* of the render; UMBRA_ERROR_UNSUPPORTED for a refused case */
    char message[1024];
    double image, point;  /* as conf_row */
    size_t lit_wrong;     /* lit points whose factor is not exactly 1 */
    size_t out_of_range;  /* factors not in [0, 1], pixels not finite or negative */
} conf_result;

/* The yardstick of one case: the reference's (or unlit: the unshadowed) image and factors. */
typedef struct conf_yardstick {
    float *image, *factors;
} conf_yardstick;

static inline void conf_yardstick_release(conf_yardstick *y)
{
    free(y->image);
    free(y->factors);
    memset(y, 0, sizeof *y);
}

static inline umbra_status conf_yardstick_make(umbra_context ctx, const conf_scene *s, int unlit,
                                               conf_yardstick *y, char *msg, size_t msg_size)
{
    memset(y, 0, sizeof *y);
    y->image = malloc((size_t)s->width * s->height * 4 * sizeof *y->image);
    y->factors = malloc((s->count ? s->count : 1) * 3 * sizeof *y->factors);
    if (!y->image || !y->factors)
        return UMBRA_ERROR_OUT_OF_MEMORY;
    umbra_renderer r;
    umbra_status st = conf_renderer(ctx, s, NULL, "", unlit, &r, msg, msg_size);
    if (st == UMBRA_SUCCESS)
        st = umbra_renderer_render(r, s->width, s->height, y->image);
    if (st == UMBRA_SUCCESS && s->count)
        st = umbra_renderer_query_shadow(r, s->points, s->count, y->factors);
    if (st != UMBRA_SUCCESS && !msg[0])
        snprintf(msg, msg_size, "%s", umbra_context_last_message(ctx));
    umbra_renderer_release(r);
    return st;
}

/* Renders case s with row's setting and measures it against y (the yardstick for the row:
 * unlit for a technique without a light pass). */
static inline void conf_run(umbra_context ctx, const conf_scene *s, const conf_yardstick *y,
                            const conf_row *row, conf_result *out)
{
    memset(out, 0, sizeof *out);
    const umbra_technique_info *t = umbra_technique_find(row->technique);
    const int unlit = t && (t->flags & UMBRA_TECHNIQUE_NO_LIGHT);
    const size_t px = (size_t)s->width * s->height;
    float *img = malloc(px * 4 * sizeof *img);
    float *f = malloc(((s->count > s->lit_count ? s->count : s->lit_count) + 1) * 3 * sizeof *f);
    umbra_renderer r = NULL;
    out->image = out->point = INFINITY;
    if (!img || !f) {
        out->status = UMBRA_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    out->status = conf_renderer(ctx, s, row->technique, row->params, 0, &r, out->message,
                                sizeof out->message);
    if (out->status == UMBRA_SUCCESS)
        out->status = umbra_renderer_render(r, s->width, s->height, img);
    if (out->status != UMBRA_SUCCESS) {
        if (!out->message[0])
            snprintf(out->message, sizeof out->message, "%s", umbra_context_last_message(ctx));
        umbra_context_take_error(ctx, NULL);
        goto done;
    }
    for (size_t i = 0; i < px * 4; ++i)
        out->out_of_range += !(img[i] >= 0.0f) || !isfinite(img[i]);
    if (s->analytic) {
        conf_slab_error(s, img, unlit, &out->image, &out->point);
        goto done;
    }
    out->image = conf_mean_abs(img, y->image, px, 4);
    out->point = CONF_NA;
    if (t && (t->flags & UMBRA_TECHNIQUE_FRAME))
        goto done;
    if ((out->status = umbra_renderer_query_shadow(r, s->points, s->count, f)) != UMBRA_SUCCESS)
        goto done;
    for (size_t i = 0; i < s->count * 3; ++i)
        out->out_of_range += !(f[i] >= 0.0f && f[i] <= 1.0f);
    if (unlit) {
        double sum = 0.0;
        for (size_t i = 0; i < s->count * 3; ++i)
            sum += fabs(f[i] - 1.0);
        out->point = sum / (3.0 * s->count);
    } else {
        out->point = conf_mean_abs(f, y->factors, s->count, 3);
    }
    if (s->lit_count &&
        (out->status = umbra_renderer_query_shadow(r, s->lit, s->lit_count, f)) != UMBRA_SUCCESS)
        goto done;
    for (size_t i = 0; i < s->lit_count * 3; ++i)
        out->lit_wrong += f[i] != 1.0f;
done:
    if (out->status != UMBRA_SUCCESS && !out->message[0])
        snprintf(out->message, sizeof out->message, "%s", umbra_context_last_message(ctx));
    umbra_renderer_release(r);
    free(img);
    free(f);
}

#endif
