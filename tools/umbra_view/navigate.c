// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/navigate.c: camera and light motions (navigate.h), Rodrigues rotations in
 * float on umbra's camera and light. */
#include <math.h>

#include "navigate.h"

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Normalises v in place; returns 0 (and leaves v) if it has no length. */
static int normalize3(float v[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 0.0f) || !isfinite(l))
        return 0;
    for (int i = 0; i < 3; ++i)
        v[i] /= l;
    return 1;
}

/* Rotates v by angle about the unit axis (right-handed). */
static void rotate3(float v[3], const float axis[3], float angle)
{
    float c = cosf(angle), s = sinf(angle), k[3];
    cross3(axis, v, k);
    float d = dot3(axis, v) * (1.0f - c);
    for (int i = 0; i < 3; ++i)
        v[i] = v[i] * c + k[i] * s + axis[i] * d;
}

/* The camera's unit up and right axes; 0 if the camera is degenerate. */
static int camera_axes(const umbra_camera *c, float up[3], float right[3])
{
    float fwd[3] = {c->target[0] - c->eye[0], c->target[1] - c->eye[1], c->target[2] - c->eye[2]};
    for (int i = 0; i < 3; ++i)
        up[i] = c->up[i];
    if (!normalize3(up) || !normalize3(fwd))
        return 0;
    cross3(fwd, up, right);
    return normalize3(right);
}

void navigate_orbit(umbra_camera *c, float yaw, float pitch)
{
    float up[3], right[3], v[3];
    if (!camera_axes(c, up, right))
        return;
    for (int i = 0; i < 3; ++i)
        v[i] = c->eye[i] - c->target[i];
    rotate3(v, up, yaw);
    rotate3(right, up, yaw);
    /* The pitch is limited so that the view never lines up with up (the camera would flip). */
    float len = sqrtf(dot3(v, v));
    float polar = acosf(fmaxf(-1.0f, fminf(1.0f, dot3(v, up) / len)));
    const float margin = 0.0174533f; /* 1 degree */
    float to = fmaxf(margin, fminf(3.14159265f - margin, polar - pitch));
    rotate3(v, right, to - polar); /* about right, +angle lowers the eye */
    for (int i = 0; i < 3; ++i)
        c->eye[i] = c->target[i] + v[i];
}

void navigate_pan(umbra_camera *c, float dx, float dy)
{
    float up[3], right[3], cam_up[3];
    if (!camera_axes(c, up, right))
        return;
    float fwd[3] = {c->target[0] - c->eye[0], c->target[1] - c->eye[1], c->target[2] - c->eye[2]};
    float dist = sqrtf(dot3(fwd, fwd));
    normalize3(fwd);
    cross3(right, fwd, cam_up);
    float h = c->projection == UMBRA_ORTHOGRAPHIC
                  ? c->ortho_height
                  : 2.0f * dist * tanf(0.5f * c->fovy_degrees * 3.14159265f / 180.0f);
    for (int i = 0; i < 3; ++i) {
        float m = (right[i] * dx + cam_up[i] * dy) * h;
        c->eye[i] -= m;
        c->target[i] -= m;
    }
}

void navigate_zoom(umbra_camera *c, float factor)
{
    if (!(factor > 0.0f) || !isfinite(factor))
        return;
    if (c->projection == UMBRA_ORTHOGRAPHIC) {
        c->ortho_height *= factor;
        return;
    }
    for (int i = 0; i < 3; ++i)
        c->eye[i] = c->target[i] + (c->eye[i] - c->target[i]) * factor;
}

void navigate_light(umbra_light *l, const umbra_camera *c, const float center[3], float yaw,
                    float pitch)
{
    float up[3], right[3];
    if (!camera_axes(c, up, right))
        return;
    if (l->type == UMBRA_LIGHT_DIRECTIONAL) {
        rotate3(l->direction, up, yaw);
        rotate3(l->direction, right, pitch);
        return;
    }
    float v[3];
    for (int i = 0; i < 3; ++i)
        v[i] = l->position[i] - center[i];
    rotate3(v, up, yaw);
    rotate3(v, right, pitch);
    for (int i = 0; i < 3; ++i)
        l->position[i] = center[i] + v[i];
}

void navigate_turn_point(float p[3], const float center[3], float angle)
{
    float v[3] = {p[0] - center[0], p[1] - center[1], p[2] - center[2]};
    navigate_turn_direction(v, angle);
    for (int i = 0; i < 3; ++i)
        p[i] = center[i] + v[i];
}

void navigate_turn_direction(float d[3], float angle)
{
    const float y[3] = {0.0f, 1.0f, 0.0f};
    rotate3(d, y, angle);
}
