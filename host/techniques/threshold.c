// SPDX-License-Identifier: Apache-2.0
/* host/techniques/threshold.c: the opacity-threshold shadow map ("threshold",
 * kernels/techniques/threshold.cl): one grey depth per texel of a single-layer light-space map
 * (maps.h), where the accumulated light opacity first passes the threshold; the lookup tests a
 * sample against it, averaged over the taps. */
#include "lightspace.h"
#include "techniques/maps.h"
#include "techniques/threshold_shared.h"

_Static_assert(sizeof(UmbraThreshold) == 16, "UmbraThreshold layout");

static uint32_t values(umbra_renderer r)
{
    (void)r;
    return 1u; /* one depth, a binary test: grey light only */
}

static uint32_t build_constants(umbra_renderer r, double texels_per_voxel, void *out)
{
    (void)texels_per_voxel;
    const UmbraShadow *S = &r->shadow_params;
    UmbraThreshold *P = out;
    P->threshold = r->shadow.threshold.threshold;
    P->taps = r->shadow.threshold.taps;
    /* The map stores an exact crossing depth from the texel centre's ray; a sample half a texel
     * beside that ray on a surface oblique to the light sees a slightly different crossing, and
     * would shadow itself (acne) without a margin. Half a light step (in normalised depth) covers
     * slopes up to step / texel and stays inside the +-1 step the crossing is promised to. */
    P->depth_bias = 0.5f * S->step * S->near_far[2];
    P->pad = 0;
    return 1u; /* a work-item per texel */
}

static void lookup_constants(umbra_renderer r, void *out)
{
    ((UmbraThreshold *)out)->taps = r->shadow.threshold.taps;
}

static const umbra__map_kind kind = {
    .build_kernel = "threshold_build",
    .constants_size = sizeof(UmbraThreshold),
    .values = values,
    .build_constants = build_constants,
    .lookup_constants = lookup_constants,
};

static const umbra__param params[] = {
    UMBRA__MAP_PARAMS,
    UMBRA__PARAM(threshold, threshold,
                 .doc = "accumulated light opacity at which a texel's depth is stored",
                 .flags = UMBRA_PARAM_MIN_EXCLUSIVE | UMBRA_PARAM_MAX_EXCLUSIVE |
                          UMBRA_PARAM_REBUILDS,
                 .default_value = 0.5, .min = 0, .max = 1),
    UMBRA__PARAM(threshold, taps,
                 .doc = "texels averaged per lookup (percentage-closer filtering at CSSM's tap "
                        "offsets)",
                 .default_value = 13, .min = 1, .max = 21, .allowed = umbra__map_taps,
                 .allowed_count = 4),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting). */
static const umbra__setting sweep[] = {
    /* The builds' baseline, and a threshold march as long as the deep map's: stopped where the
     * deep map's stops (visibility below epsilon / 2 = 0.01), at its step of half a voxel. */
    {"threshold=0.5", "threshold", UMBRA__SWEEP_BUILDS},
    {"threshold=0.99;map_step=0.5", "threshold-0.99", UMBRA__SWEEP_BUILDS},
    {"map_size=auto;taps=1;threshold=0.5", "auto size, opacity 0.5",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"map_size=512;taps=1;threshold=0.5", "512², opacity 0.5",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE_QUICK},
    {"map_size=1024;taps=1;threshold=0.5", "1024², opacity 0.5",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE},
    {"map_size=2048;taps=1;threshold=0.5", "2048², opacity 0.5",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=4096;taps=1;threshold=0.5", "4096², opacity 0.5",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=auto;taps=13;threshold=0.5", "auto size, opacity 0.5, 13 taps",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;taps=13;threshold=0.5", "1024², opacity 0.5, 13 taps",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;taps=1;threshold=0.25", "1024², opacity 0.25",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;taps=1;threshold=0.75", "1024², opacity 0.75",
     UMBRA__SWEEP_FULL},
};

static const char *const kernel_files[] = {"techniques/threshold_shared.h",
                                           "techniques/threshold.cl", NULL};

const umbra__technique umbra__technique_threshold = {
    .info = {
        .id = UMBRA_SHADOW_THRESHOLD,
        .name = "threshold",
        .title = "opacity-threshold shadow map",
        .doc = "One depth per texel of a light-space map, where the accumulated light opacity "
               "first passes the threshold; the lookup is binary (shadowed behind it), averaged "
               "over the taps. Fast and small (4 bytes per texel), but grey and hard: it ignores "
               "the transmission colour and turns translucent material's partial shadows into "
               "full ones.",
        .flags = UMBRA_TECHNIQUE_MAP | UMBRA_TECHNIQUE_GREY | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
        /* One depth per texel: a texel per voxel resolves what the volume holds (finer maps
         * sample the same voxels again). */
        .map_texels_per_voxel = 1.0f,
        .map_step = 1.0f, /* lightspace.h: the step only sets where the volume is sampled */
        /* No draft: at one texel per voxel its full map rebuilds within issue #28's 2.5x of an
         * unshadowed frame while the light moves (README, "Interactive sessions"). */
        .draft = NULL,
    },
    .params = params,
    .sweep = sweep,
    .sweep_count = sizeof sweep / sizeof sweep[0],
    .kernel_files = kernel_files,
    .light_step = umbra__map_light_step,
    .build = umbra__map_build,
    .bind = umbra__map_bind,
    .memory = umbra__map_memory,
    .destroy = umbra__map_destroy,
    .data = &kind,
};
