// SPDX-License-Identifier: Apache-2.0
/* host/techniques/reference.c: the exact "reference" (kernels/techniques/reference.cl): a shadow
 * ray marched toward the light from every sample. It keeps no structure: its light pass is the
 * light tables the renderer keeps and the step in the shared constants. */
#include "renderer_internal.h"

static float light_step(const umbra_shadow_desc *d) { return d->reference.step; }

static const umbra__param params[] = {
    UMBRA__PARAM_KEYED(reference, step, "reference_step",
                       .doc = "shadow-ray step", .unit = "voxels", .default_value = 0.25,
                       .min = 0.01, .max = 64),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting). */
static const umbra__setting sweep[] = {
    {"reference_step=0.5", "step 0.5",
     UMBRA__SWEEP_FULL},
    {"reference_step=1", "step 1",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE | UMBRA__SWEEP_HEADLINE_QUICK},
    {"reference_step=2", "step 2",
     UMBRA__SWEEP_FULL},
};

static const char *const kernel_files[] = {"techniques/reference.cl", NULL};

const umbra__technique umbra__technique_reference = {
    .info = {
        .id = UMBRA_SHADOW_REFERENCE,
        .name = "reference",
        .title = "exact reference",
        .doc = "A shadow ray marched toward the light from every sample, the shading model's "
               "optical depth integrated along it: exact up to its step, and the yardstick of "
               "every other technique; slow (a ray per sample).",
        .flags = UMBRA_TECHNIQUE_SHADOW_RAYS | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
    },
    .params = params,
    .sweep = sweep,
    .sweep_count = sizeof sweep / sizeof sweep[0],
    .kernel_files = kernel_files,
    .light_step = light_step,
    .ray_name = "shadow",
};
