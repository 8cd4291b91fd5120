// SPDX-License-Identifier: Apache-2.0
/* host/techniques/cssm.c: the colored stochastic shadow map ("cssm", Weidner & Linsen,
 * kernels/techniques/cssm.cl): per texel of a single-layer light-space map (maps.h) the depth at
 * which a photon with a random optical-depth threshold is stopped, one per simulated light
 * channel; the lookup counts the taps whose photon got past the sample. */
#include "lightspace.h"
#include "techniques/cssm_shared.h"
#include "techniques/maps.h"

_Static_assert(sizeof(UmbraCssm) == 16, "UmbraCssm layout");

static uint32_t values(umbra_renderer r)
{
    return r->channels; /* one depth per simulated light channel */
}

/* The block whose photons share a light ray (kernels/techniques/cssm.cl), B x B texels: by
 * default B is the map's whole texels per voxel, at most UMBRA_CSSM_MAX_RAY_BLOCK, so that a
 * block never spans more than a voxel of the box as the light sees it. */
static uint32_t default_ray_block(double texels_per_voxel)
{
    if (!(texels_per_voxel >= 1.0)) /* NaN too */
        return 1u;
    return texels_per_voxel >= UMBRA_CSSM_MAX_RAY_BLOCK ? UMBRA_CSSM_MAX_RAY_BLOCK
                                                        : (uint32_t)texels_per_voxel;
}

/* CSSM depths are segment midpoints, unbiased on average (see its kernel): no depth bias, as in
 * the paper. */
static uint32_t build_constants(umbra_renderer r, double texels_per_voxel, void *out)
{
    const umbra_cssm_desc *d = &r->shadow.cssm;
    UmbraCssm *P = out;
    P->taps = d->taps;
    P->seed = d->seed;
    P->ray_block = d->ray_block ? d->ray_block : default_ray_block(texels_per_voxel);
    P->pad = 0;
    return P->ray_block;
}

static void lookup_constants(umbra_renderer r, void *out)
{
    ((UmbraCssm *)out)->taps = r->shadow.cssm.taps;
}

static const umbra__map_kind kind = {
    .build_kernel = "cssm_build",
    .constants_size = sizeof(UmbraCssm),
    .values = values,
    .build_constants = build_constants,
    .lookup_constants = lookup_constants,
};

static const umbra__param params[] = {
    UMBRA__MAP_PARAMS,
    UMBRA__PARAM(cssm, taps,
                 .doc = "texels averaged per lookup (13: the paper's set): more taps reach "
                        "farther (radius 4, 7, 10 for 7, 13, 21), trading noise for a wider blur",
                 .default_value = 13, .min = 1, .max = 21, .allowed = umbra__map_taps,
                 .allowed_count = 4),
    UMBRA__PARAM(cssm, seed,
                 .doc = "seed of the counter-based random numbers: the same seed gives the same "
                        "map and image, bit for bit, on the same device",
                 .flags = UMBRA_PARAM_REBUILDS, .default_value = 1, .min = 0,
                 .max = 4294967295.0),
    UMBRA__PARAM(cssm, ray_block,
                 .doc = "texels per side of the blocks whose photons share one light ray (1: a "
                        "ray per texel, the paper's; the map's own: its whole texels per voxel, "
                        "at most 3)",
                 .flags = UMBRA_PARAM_ZERO | UMBRA_PARAM_REBUILDS, .default_value = 0, .min = 1,
                 .max = UMBRA_CSSM_MAX_RAY_BLOCK, .zero_doc = "the map's own"),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting). */
static const umbra__setting sweep[] = {
    {"", "cssm", UMBRA__SWEEP_BUILDS}, /* 13 taps do not enter a build */
    {"map_size=auto;taps=13;seed=1", "auto size, 13 taps",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"map_size=512;taps=13;seed=1", "512², 13 taps",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE_QUICK},
    {"map_size=1024;taps=13;seed=1", "1024², 13 taps",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL | UMBRA__SWEEP_HEADLINE},
    {"map_size=2048;taps=13;seed=1", "2048², 13 taps",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=4096;taps=13;seed=1", "4096², 13 taps",
     UMBRA__SWEEP_PAPERS_CSSM},
    {"map_size=auto;taps=13;seed=1;map_texels_per_voxel=1", "auto size, 13 taps, draft",
     UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL},
    {"map_size=512;taps=7;seed=1", "512², 7 taps",
     UMBRA__SWEEP_QUICK},
    {"map_size=1024;taps=7;seed=1", "1024², 7 taps",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;taps=21;seed=1", "1024², 21 taps",
     UMBRA__SWEEP_FULL},
    {"map_size=auto;taps=13;seed=1;ray_block=1", "auto size, 13 taps, a ray per texel",
     UMBRA__SWEEP_FULL},
    {"map_size=1024;taps=13;seed=1;ray_block=1", "1024², 13 taps, a ray per texel",
     UMBRA__SWEEP_FULL},
};

static const char *const kernel_files[] = {"techniques/cssm_shared.h", "techniques/cssm.cl",
                                           NULL};

const umbra__technique umbra__technique_cssm = {
    .info = {
        .id = UMBRA_SHADOW_CSSM,
        .name = "cssm",
        .title = "colored stochastic shadow map (Weidner & Linsen)",
        .doc = "Per texel of a light-space map, the depth at which a photon of random "
               "optical-depth threshold is stopped, per light channel: coloured, translucent "
               "shadows in 4 or 12 bytes per texel, at the price of noise that the taps "
               "average.",
        .flags = UMBRA_TECHNIQUE_MAP | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
        /* The lookup averages taps fixed in texels (radius 4 for 13 taps): at one texel per
         * voxel it blurs shadows over 4 voxels; at three its error is within 5% of a 1024^2
         * map's on the walnut and the spheres. */
        .map_texels_per_voxel = 3.0f,
        .map_step = 1.0f, /* lightspace.h: its noise, not its step, sets its error */
        /* The threshold map's size while the light moves: RMSE 1.01x-1.68x the full map's on
         * the seven bench scenes, builds 1.3x-2.9x cheaper (README, "What accuracy costs in
         * time"). */
        .draft = "map_texels_per_voxel<=1",
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
