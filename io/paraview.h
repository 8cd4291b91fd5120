// SPDX-License-Identifier: Apache-2.0
/* io/paraview.h: what io/paraview.c (presets) and io/paraview_color.c (colour blends) share. */
#ifndef UMBRA_IO_PARAVIEW_H
#define UMBRA_IO_PARAVIEW_H

#include "io_internal.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How colours blend between two nodes (a preset's "ColorSpace"). */
typedef enum pv_space { PV_RGB, PV_HSV, PV_LAB, PV_DIVERGING, PV_STEP } pv_space;

/* The colour a fraction s in [0,1] of the way from sRGB colour a to b, as
 * vtkColorTransferFunction blends in space; hsv_wrap: HSV takes the shorter way round the hue
 * circle. */
void umbra__pv_blend(pv_space space, int hsv_wrap, const double a[3], const double b[3], double s,
                     double out[3]);

#ifdef __cplusplus
}
#endif
#endif
