// SPDX-License-Identifier: Apache-2.0
/* tests/reference/cpu_reference.h: a plain-C implementation of umbra's ray caster and exact
 * shadow reference, written from the algorithm's description (renderer.h's shading model and
 * kernels/raycast.cl's steps) without sharing code with the library. The tests check the OpenCL
 * kernels against it; umbra-bench times it (OpenMP, -O3) as the native-C baseline. */
#ifndef UMBRA_CPU_REFERENCE_H
#define UMBRA_CPU_REFERENCE_H

#include <stdint.h>

#include "umbra/renderer.h"

typedef struct cpu_scene {
    const float *voxels;          /* normalised values in [0,1], x fastest */
    int dims[3];
    float spacing[3];
    const float *tf;              /* RGBA table as given to umbra (alpha per voxel) */
    int tf_count;
    const float *light_tf;        /* NULL: tf */
    int light_tf_count;
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc opts;
    umbra_shadow_technique shadow;/* UMBRA_SHADOW_NONE or UMBRA_SHADOW_REFERENCE */
    float reference_step;         /* voxels */
    int brick_size;               /* empty-space skipping bricks (as the volume's) */
    int six_sample_shading;       /* nonzero: Blinn-Phong as before issue #12, the gradient from
                                     six trilinear samples and the specular power by powf, for
                                     tests that bound what the faster form changes */
} cpu_scene;

/* Renders w x h premultiplied RGBA floats; returns the number of samples taken (samples skipped
 * in empty bricks are not counted, as on the device), or 0 if out of memory. Parallel over rows
 * with OpenMP. */
uint64_t cpu_render(const cpu_scene *s, uint32_t w, uint32_t h, float *rgba);

/* The per-scene part of cpu_render done once: step-corrected tables and brick visibility (an
 * O(voxels) pass). s is borrowed and must stay unchanged while the result is used. NULL if out of
 * memory. The bench times cpu_render_prepared alone, as umbra keeps these between frames too. */
typedef struct cpu_prepared cpu_prepared;
cpu_prepared *cpu_prepare(const cpu_scene *s);
uint64_t cpu_render_prepared(const cpu_prepared *p, uint32_t w, uint32_t h, float *rgba);
void cpu_prepared_free(cpu_prepared *p); /* NULL is a no-op */

/* The shadow factor at world point p (the exact reference's transmittance). */
void cpu_shadow(const cpu_scene *s, const float p[3], float rgb[3]);

/* The mean depth of the emission along a segment of opacity a, in units of its length, as the
 * ray caster approximates it (kernels/raycast.cl, emission_depth): within 4.7e-4 of
 * 1/tau - (1 - a)/a, tau = -ln(1 - a), for every a in [0, 1]; 0 for a >= 1 or NaN. */
float cpu_emission_depth(float a);

#endif
