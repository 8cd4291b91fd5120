// SPDX-License-Identifier: Apache-2.0
/* umbra/registry.h: the technique registry, read at run time.
 *
 * Every shadow technique is described once, in the library (its descriptor, host/techniques/),
 * and listed once (umbra/techniques/list.h). This header shows the description: each technique's
 * name, doc and flags, and each of its parameters with its type, default, range or allowed set,
 * unit and doc, and reads and sets a parameter of a umbra_shadow_desc by name with its range
 * checked. umbra-render builds its options and --help from it, the Python binding its keywords,
 * a viewer its technique panel.
 *
 * Everything returned is static (owned by the library, valid for the life of the process,
 * unchanged by any call); nothing here needs a context, allocates, blocks or touches the
 * environment, and every function may be called from any thread. */
#ifndef UMBRA_REGISTRY_H
#define UMBRA_REGISTRY_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/error.h"
#include "umbra/renderer.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How a parameter is stored in its technique's struct: float, uint32_t, or int used as a flag. */
typedef enum umbra_param_type {
    UMBRA_PARAM_FLOAT = 0,
    UMBRA_PARAM_UINT = 1,
    UMBRA_PARAM_BOOL = 2
} umbra_param_type;

/* umbra_param_info.flags */
#define UMBRA_PARAM_MIN_EXCLUSIVE 1u /* the range is open at min: (min, ... */
#define UMBRA_PARAM_MAX_EXCLUSIVE 2u /* ... max) */
#define UMBRA_PARAM_ZERO 4u          /* 0 is accepted beside the range or set; zero_doc says what
                                        it means ("auto", "the technique's own") */
#define UMBRA_PARAM_REBUILDS 8u      /* changing it rebuilds the shadow structure; without the
                                        flag only the lookup (or the frame) reads it, and a
                                        change takes effect at the next render without a build */
#define UMBRA_PARAM_MAP 16u          /* one of umbra_shadow_desc.map's fields, shared by every
                                        light-space map (listed by each of them) */

typedef struct umbra_param_info {
    const char *name;      /* its field in the technique's struct ("ray_block" of
                              umbra_cssm_desc; "size" of umbra_map_desc) */
    const char *key;       /* its flat name, unique among the technique's parameters:
                              umbra-render --<key, '_' written '-'>, Python's keyword
                              ("ray_block"; "map_size") */
    const char *alias;     /* another key kept from an earlier version ("nodes": umbra-render's
                              --nodes), or NULL; set/get accept the name, the key or the alias */
    const char *doc;       /* one or two sentences */
    const char *unit;      /* "voxels", "degrees", or NULL */
    umbra_param_type type;
    uint32_t flags;        /* UMBRA_PARAM_* */
    double default_value;  /* what umbra_shadow_desc_init sets */
    double min, max;       /* the range (bounds included unless flagged exclusive); for a set,
                              its smallest and largest value; BOOL: 0 and 1 */
    const double *allowed; /* the values accepted when not NULL (allowed_count of them,
                              ascending): e.g. taps 1, 7, 13, 21 */
    uint32_t allowed_count;
    const char *zero_doc;  /* with UMBRA_PARAM_ZERO: what 0 means; else NULL */
    const char *zero_name; /* a word umbra-render and Python accept for 0 ("auto"), or NULL */
} umbra_param_info;

/* umbra_technique_info.flags */
#define UMBRA_TECHNIQUE_MAP 1u      /* a light-space map: reads umbra_shadow_desc.map (its
                                       parameters include the map's, flagged UMBRA_PARAM_MAP) */
#define UMBRA_TECHNIQUE_GREY 2u     /* carries one grey light channel whatever the transmission
                                       mode (umbra_render_stats.light_channels 1) */
#define UMBRA_TECHNIQUE_FRAME 4u    /* renders the frame itself: no per-point lookup
                                       (umbra_renderer_query_shadow gives UMBRA_ERROR_UNSUPPORTED),
                                       and no light from behind the viewer */
#define UMBRA_TECHNIQUE_NO_LIGHT 8u /* takes no light pass at all (none) */
#define UMBRA_TECHNIQUE_SHADOW_RAYS 16u /* marches a shadow ray from every view sample and query
                                         point (reference): each costs up to the box diagonal
                                         over its light step in samples */
#define UMBRA_TECHNIQUE_CHANNELS 32u /* renders multi-channel volumes and label maps (its light
                                        pass reads the light through the shared per-point
                                        lookup); a technique without it refuses them at render
                                        with UMBRA_ERROR_UNSUPPORTED */

/* umbra_technique_info.rebuilt_by: the renderer's inputs whose change rebuilds the technique's
 * shadow structure (beside its parameters flagged UMBRA_PARAM_REBUILDS; a camera move never
 * does). */
#define UMBRA_REBUILD_LIGHT 1u        /* umbra_renderer_set_light */
#define UMBRA_REBUILD_LIGHT_TF 2u     /* the light transfer function (or the view one it uses) */
#define UMBRA_REBUILD_VOLUME 4u       /* umbra_renderer_set_volume */
#define UMBRA_REBUILD_TRANSMISSION 8u /* umbra_render_desc.transmission */
#define UMBRA_REBUILD_SKIPPING 16u    /* umbra_render_desc.empty_space_skipping */
#define UMBRA_REBUILD_CLIP 32u        /* umbra_renderer_set_clip */
/* All of them: a structure built from the light pass. */
#define UMBRA_REBUILD_LIGHT_PASS                                                               \
    (UMBRA_REBUILD_LIGHT | UMBRA_REBUILD_LIGHT_TF | UMBRA_REBUILD_VOLUME |                     \
     UMBRA_REBUILD_TRANSMISSION | UMBRA_REBUILD_SKIPPING | UMBRA_REBUILD_CLIP)

typedef struct umbra_technique_info {
    umbra_shadow_technique id;
    const char *name;       /* "cssm" */
    const char *title;      /* "colored stochastic shadow map (Weidner & Linsen)" */
    const char *doc;        /* what it is, what it costs, where it is wrong: a paragraph */
    uint32_t flags;         /* UMBRA_TECHNIQUE_* */
    uint32_t rebuilt_by;    /* UMBRA_REBUILD_* */
    uint32_t param_count;   /* umbra_technique_param_get(t, 0 .. param_count - 1) */
    float map_texels_per_voxel; /* UMBRA_TECHNIQUE_MAP: what map.texels_per_voxel 0 means */
    float map_step;             /* UMBRA_TECHNIQUE_MAP: what map.step 0 means, in voxels */
    /* What a draft frame changes (umbra_render_desc.interaction, umbra/renderer.h), as
     * "key<=value;key>=value;key=value" over the parameters the application set: `<=` takes the
     * smaller of the two (a zero that means "the technique's own" counts as that value, and one
     * that means "unbounded" as infinite), `>=` the larger, `=` the value. A draft never asks
     * for finer settings than the full structure's. Where the map's size is fixed (map_size
     * N), a draft's map_texels_per_voxel K makes it N K / map_texels_per_voxel (rounded up to
     * UMBRA_MAP_SIZE_AUTO_ROUND, at least UMBRA_MAP_SIZE_AUTO_MIN, at most N). NULL: the
     * technique has no draft (it rebuilds at full quality, or has nothing to rebuild). */
    const char *draft;
} umbra_technique_info;

/* The number of techniques in this build, and the index-th of them in the registry's order
 * (NULL past the end). */
UMBRA_API uint32_t umbra_technique_count(void);
UMBRA_API const umbra_technique_info *umbra_technique_get(uint32_t index);
/* The technique called name, or with that id; NULL when there is none. */
UMBRA_API const umbra_technique_info *umbra_technique_find(const char *name);
UMBRA_API const umbra_technique_info *umbra_technique_find_id(umbra_shadow_technique id);

/* The index-th parameter of t (NULL past the end or for NULL t), or the one whose name, key or
 * alias is name (NULL when t has none). */
UMBRA_API const umbra_param_info *umbra_technique_param_get(const umbra_technique_info *t,
                                                            uint32_t index);
UMBRA_API const umbra_param_info *umbra_technique_param_find(const umbra_technique_info *t,
                                                             const char *name);

/* Sets parameter `param` (name, key or alias) of technique `technique` in desc to value, after
 * checking it: a whole number for UINT (and within 32 bits), 0 or 1 for BOOL, and within the
 * range or allowed set (or 0 with UMBRA_PARAM_ZERO). technique NULL means every technique that
 * has the parameter, desc->technique first: each is checked before any is set, and a failure
 * names the first technique that refused. On failure nothing is changed and the status is
 * UMBRA_ERROR_INVALID_ARGUMENT (unknown technique or parameter, NULL desc or param, a value out
 * of range) with a message naming the technique, the parameter and the value, e.g.
 * "umbra_shadow_desc_set_param: cssm ray_block 4 must be 0 (the map's own) or lie in [1, 3]",
 * copied into message (truncated to message_size - 1 bytes; message may be NULL when
 * message_size is 0). On success message holds "". */
UMBRA_API umbra_status umbra_shadow_desc_set_param(umbra_shadow_desc *desc, const char *technique,
                                                   const char *param, double value,
                                                   char *message, size_t message_size);

/* The value of parameter `param` (name, key or alias) of technique `technique` in desc, into
 * *value; technique NULL: desc->technique's if it has the parameter, else the first technique's
 * that has it. UMBRA_ERROR_INVALID_ARGUMENT for NULL arguments or an unknown technique or parameter. */
UMBRA_API umbra_status umbra_shadow_desc_get_param(const umbra_shadow_desc *desc,
                                                   const char *technique, const char *param,
                                                   double *value);

#ifdef __cplusplus
}
#endif
#endif
