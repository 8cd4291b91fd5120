// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/navigate.h: the viewer's camera and light motions, on umbra's own camera and
 * light structs (pure math, no window): turntable orbit, pan and zoom of a look-at camera; the
 * light turned about the volume's centre as the mouse drags; orbits about the vertical for
 * replays. Angles are in radians; the vertical is the world's +y (the ground plane's normal). */
#ifndef UMBRA_VIEW_NAVIGATE_H
#define UMBRA_VIEW_NAVIGATE_H

#include "umbra/umbra.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Turns the eye about the target: yaw about the camera's up vector (positive: the eye moves to
 * the right), then pitch (positive: the eye rises), stopping 1 degree short of looking straight
 * along up or down. */
void navigate_orbit(umbra_camera *c, float yaw, float pitch);
/* Moves eye and target together by dx, dy view heights (at the target's distance) to the right
 * and up. */
void navigate_pan(umbra_camera *c, float dx, float dy);
/* Scales the eye's distance to the target (perspective) or the view height (orthographic) by
 * factor (> 0); the distance stays above 1e-4 of what it was. */
void navigate_zoom(umbra_camera *c, float factor);
/* Turns the light about centre as seen by camera c: yaw about the camera's up vector, pitch about
 * its right axis. A directional light's direction turns, a point light's position about centre. */
void navigate_light(umbra_light *l, const umbra_camera *c, const float center[3], float yaw,
                    float pitch);
/* Turns a point about the vertical line through centre (or, as a direction, about +y). */
void navigate_turn_point(float p[3], const float center[3], float angle);
void navigate_turn_direction(float d[3], float angle);

#ifdef __cplusplus
}
#endif
#endif
