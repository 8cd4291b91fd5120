// SPDX-License-Identifier: Apache-2.0
/* host/techniques/none.c: "none", every point fully lit (kernels/techniques/none.cl): no light
 * pass, no parameters, nothing to build. */
#include "renderer_internal.h"

static const char *const kernel_files[] = {"techniques/none.cl", NULL};

const umbra__technique umbra__technique_none = {
    .info = {
        .id = UMBRA_SHADOW_NONE,
        .name = "none",
        .title = "no shadows",
        .doc = "Shadow factor 1 everywhere: the unshadowed frame every overhead is measured "
               "against.",
        .flags = UMBRA_TECHNIQUE_NO_LIGHT | UMBRA_TECHNIQUE_CHANNELS,
    },
    .kernel_files = kernel_files,
};
