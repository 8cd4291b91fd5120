// SPDX-License-Identifier: Apache-2.0
/* host/techniques/basic.c: the two techniques that need no shadow structure: "none" (every point
 * fully lit) and the exact "reference" (a shadow ray per sample, kernels/shadow_reference.c). */
#include "renderer_internal.h"

static float reference_light_step(const umbra_shadow_desc *d) { return d->reference_step; }

const umbra__technique umbra__technique_none = {
    .id = UMBRA_SHADOW_NONE,
    .kernel_file = "techniques/none.cl",
    .light_step = reference_light_step,
};

const umbra__technique umbra__technique_reference = {
    .id = UMBRA_SHADOW_REFERENCE,
    .kernel_file = "techniques/reference.cl",
    .light_step = reference_light_step,
};
