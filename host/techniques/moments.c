// SPDX-License-Identifier: Apache-2.0
/* host/techniques/moments.c: the moment shadow map ("moments", kernels/techniques/moments.cl): per
 * texel of a single-layer light-space map (maps.h) and per simulated light channel, the optical
 * depth of the texel's light ray and count power moments of its spread over depth, built in one
 * additive pass, optionally pre-filtered by a separable blur (maps.h's filter passes), and
 * reconstructed at lookup with the Hausdorff bounds of the moment problem (the kernel's header
 * states the method, the bias and the error bound). */
#include "lightspace.h"
#include "techniques/maps.h"
#include "techniques/moments_shared.h"

_Static_assert(sizeof(UmbraMoments) == 32, "UmbraMoments layout");

/* The optical depth at which a channel's march stops: a sample behind it keeps at most
 * exp(-6) = 0.0025 of the light, under one step of an 8-bit display, while the moments then
 * describe only the depth that still matters (the bounds' error scales with the depth they
 * spread: against 12, the bonsai's RMSE is a quarter lower and no other bench scene's changes,
 * docs/moments.md). */
#define DEPTH_CAP 6.0f

static uint32_t words(const umbra_moments_desc *d)
{
    return 1u + (d->bits == 16u ? d->count / 2u : d->count);
}

static uint32_t values(umbra_renderer r)
{
    return r->channels * words(&r->shadow.moments);
}

/* The moment bias when the desc leaves it at 0: the smallest that kept the reconstruction
 * well posed for each count and storage (docs/moments.md). */
static float own_bias(const umbra_moments_desc *d)
{
    const int i = d->count == 4u ? 0 : d->count == 6u ? 1 : 2;
    static const float bias32[3] = {1e-6f, 1e-5f, 1e-4f}, bias16[3] = {5e-5f, 5e-4f, 5e-3f};
    return d->bits == 16u ? bias16[i] : bias32[i];
}

static void lookup_constants(umbra_renderer r, void *out)
{
    const umbra_moments_desc *d = &r->shadow.moments;
    UmbraMoments *P = out;
    P->bias = d->bias > 0.0f ? d->bias : own_bias(d);
    P->overestimation = d->overestimation;
}

static uint32_t build_constants(umbra_renderer r, double texels_per_voxel, void *out)
{
    (void)texels_per_voxel;
    const umbra_moments_desc *d = &r->shadow.moments;
    UmbraMoments *P = out;
    P->count = d->count;
    P->bits = d->bits;
    P->words = words(d);
    P->blur = d->blur;
    P->depth_cap = DEPTH_CAP;
    P->pad = 0;
    lookup_constants(r, out);
    return 1u; /* a work-item per texel */
}

static uint32_t filter_passes(umbra_renderer r)
{
    return r->shadow.moments.blur ? 2u : 0u; /* along x, then y */
}

static const umbra__map_kind kind = {
    .build_kernel = "moments_build",
    .constants_size = sizeof(UmbraMoments),
    .values = values,
    .build_constants = build_constants,
    .lookup_constants = lookup_constants,
    .filter_kernel = "moments_blur",
    .filter_passes = filter_passes,
};

static const double count_set[] = {4, 6, 8};
static const double bits_set[] = {16, 32};

static const umbra__param params[] = {
    UMBRA__MAP_PARAMS,
    UMBRA__PARAM_KEYED(moments, count, "moments",
                       .doc = "power moments per light channel beside its optical depth: more "
                              "pin the spread over depth down closer, at 4 bytes each (2 at "
                              "16 bits) per texel and channel",
                       .flags = UMBRA_PARAM_REBUILDS, .default_value = 6, .min = 4, .max = 8,
                       .allowed = count_set, .allowed_count = 3),
    UMBRA__PARAM_KEYED(moments, bits, "moment_bits",
                       .doc = "storage of each normalised moment: 32 (float) or 16 (fixed "
                              "point, which needs a larger moment bias)",
                       .flags = UMBRA_PARAM_REBUILDS, .default_value = 32, .min = 16, .max = 32,
                       .allowed = bits_set, .allowed_count = 2),
    UMBRA__PARAM_KEYED(moments, bias, "moment_bias",
                       .doc = "weight of the uniform spread mixed into the moments read, which "
                              "keeps the reconstruction well posed under rounding (and is "
                              "taken back out of the estimate)",
                       .flags = UMBRA_PARAM_ZERO, .default_value = 0, .min = 1e-8, .max = 0.1,
                       .zero_doc = "the technique's own for the count and bits"),
    UMBRA__PARAM_KEYED(moments, overestimation, "moment_overestimation",
                       .doc = "where the estimated shadow factor lies between its bounds' "
                              "lit end (0: the optical depth's lower bound) and dark end (1: "
                              "its upper bound); 0.5, the midpoint, errs least at worst",
                       .default_value = 0.5, .min = 0, .max = 1),
    UMBRA__PARAM_KEYED(moments, blur, "moment_blur",
                       .doc = "radius of a separable binomial pre-filter over the built map "
                              "(0: none)",
                       .unit = "texels", .flags = UMBRA_PARAM_REBUILDS, .default_value = 0,
                       .min = 0, .max = UMBRA_MOMENTS_MAX_BLUR),
};

/* What `umbra-bench accuracy` sweeps (host/renderer_internal.h, umbra__setting): sizes chosen
 * for equal memory with the other maps' 512^2 rows (docs/moments.md): 296^2 at 4 moments and
 * 16 bits (12 bytes per texel and channel) holds what CSSM's 512^2 holds (4); 512^2 at 6 moments
 * and 16 bits (16 bytes per texel and channel) what the deep map's 512^2 with 3 nodes holds in
 * colour (a node of a depth and three channels is 16 bytes: 48 bytes per texel), also at the
 * deep map's light step of half a voxel, so that the two compare at equal memory and equal
 * sampling. The headline row: 512^2 at the defaults (6 moments, 32 bits). */
#define Q (UMBRA__SWEEP_QUICK | UMBRA__SWEEP_FULL)
static const umbra__setting sweep[] = {
    {"", "moments", UMBRA__SWEEP_BUILDS},
    {"map_size=296;moments=4;moment_bits=16", "296², 4 moments, 16 bits", Q},
    {"map_size=512;moments=6;moment_bits=16", "512², 6 moments, 16 bits", Q},
    {"map_size=512;moments=6;moment_bits=16;map_step=0.5", "512², 6 moments, 16 bits, step 0.5",
     Q},
    {"map_size=256;moments=6", "256², 6 moments", Q},
    {"map_size=512;moments=6", "512², 6 moments",
     Q | UMBRA__SWEEP_HEADLINE | UMBRA__SWEEP_HEADLINE_QUICK},
    {"map_size=256;moments=8", "256², 8 moments", Q},
    {"map_size=512;moments=6;moment_overestimation=0", "512², 6 moments, β 0", Q},
};
#undef Q

static const char *const kernel_files[] = {"techniques/moments_shared.h",
                                           "techniques/moments.cl", NULL};

const umbra__technique umbra__technique_moments = {
    .info = {
        .id = UMBRA_SHADOW_MOMENTS,
        .name = "moments",
        .title = "moment shadow map (after Peters & Klein 2015, Muenstermann et al. 2018)",
        .doc = "Per texel of a light-space map and light channel, the ray's optical depth and "
               "a few power moments of its spread over depth, added up in one pass; the lookup "
               "bounds the optical depth in front of a sample from them (the Hausdorff bounds) "
               "and takes a point between the bounds. Smooth, coloured, linearly filterable "
               "shadows in a fixed 4 (1 + moments) bytes per texel and channel; the bounds "
               "widen inside thick, varied material.",
        .flags = UMBRA_TECHNIQUE_MAP | UMBRA_TECHNIQUE_CHANNELS,
        .rebuilt_by = UMBRA_REBUILD_LIGHT_PASS,
        .param_count = sizeof params / sizeof params[0],
        .map_texels_per_voxel = 1.0f,
        .map_step = 1.0f,
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
