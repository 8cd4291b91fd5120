// SPDX-License-Identifier: Apache-2.0
/* host/shadow_desc_compat.c: umbra_shadow_desc layouts older than this build's, recognised by
 * struct_size (include/umbra/renderer.h):
 *   - umbra 0.4's flat struct of every technique's fields (kept below as it was), converted
 *     field by field; its `preintegrated` moved to umbra_render_desc;
 *   - this struct as an earlier technique list made it: the list only grows at its end, so such
 *     a struct is a prefix of this one, and the techniques it lacks take their defaults.
 * The 0.4 layout's fields are named here once; a technique added since has no 0.4 field. */
#include <string.h>

#include "renderer_internal.h"

/* umbra 0.4's umbra_shadow_desc, as its header declared it. */
typedef struct shadow_desc_0_4 {
    size_t struct_size;
    umbra_shadow_technique technique;
    float reference_step;
    uint32_t map_size;
    float map_texels_per_voxel;
    float map_step;
    float threshold;
    uint32_t taps;
    float epsilon;
    uint32_t max_nodes;
    uint32_t block_size;
    uint32_t prefilter;
    int lookup_table;
    uint32_t seed;
    uint32_t ray_block;
    float slice_distance;
    uint32_t subsamples;
    int preintegrated;
    float cone_angle_degrees;
} shadow_desc_0_4;

/* The size of this struct as the 0.5 list (its first) made it: up to the convolution member. */
#define SIZE_0_5                                                                               \
    ((offsetof(umbra_shadow_desc, convolution) + sizeof(umbra_convolution_desc) +              \
      _Alignof(umbra_shadow_desc) - 1) / _Alignof(umbra_shadow_desc) * _Alignof(umbra_shadow_desc))

_Static_assert(sizeof(shadow_desc_0_4) != SIZE_0_5, "the 0.4 and 0.5 layouts differ in size");

static void from_0_4(const shadow_desc_0_4 *o, umbra_shadow_desc *d)
{
    d->technique = o->technique;
    d->reference.step = o->reference_step;
    d->map.size = o->map_size;
    d->map.texels_per_voxel = o->map_texels_per_voxel;
    d->map.step = o->map_step;
    d->threshold.threshold = o->threshold;
    d->threshold.taps = o->taps;
    d->cssm.taps = o->taps;
    d->cssm.seed = o->seed;
    d->cssm.ray_block = o->ray_block;
    d->deep.epsilon = o->epsilon;
    d->deep.max_nodes = o->max_nodes;
    d->deep.block_size = o->block_size;
    d->deep.prefilter = o->prefilter;
    d->deep.lookup_table = o->lookup_table;
    d->convolution.slice_distance = o->slice_distance;
    d->convolution.subsamples = o->subsamples;
    d->convolution.cone_angle_degrees = o->cone_angle_degrees;
}

/* Whether size is that of this struct as a list since 0.5 made it: just past the member of one
 * of its techniques (the end of that technique's last field), rounded up to the struct's
 * alignment. */
static int earlier_list_size(size_t size)
{
    const size_t align = _Alignof(umbra_shadow_desc);
    if (size < SIZE_0_5 || size >= sizeof(umbra_shadow_desc))
        return 0;
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        size_t end = 0;
        for (uint32_t k = 0; k < t->param_count; ++k) {
            const umbra__param *p = (const umbra__param *)umbra_technique_param_get(t, k);
            if (!(p->info.flags & UMBRA_PARAM_MAP) && p->offset + 4 > end)
                end = p->offset + 4; /* every field is 4 bytes */
        }
        if (end && (end + align - 1) / align * align == size)
            return 1;
    }
    return 0;
}

umbra_status umbra__shadow_desc_upgrade(umbra_renderer r, const umbra_shadow_desc *d,
                                        umbra_shadow_desc *out, int *preintegrated,
                                        const char *fn)
{
    *preintegrated = -1;
    umbra_shadow_desc_init(out);
    if (d->struct_size == sizeof *d) {
        *out = *d;
        return UMBRA_SUCCESS;
    }
    if (d->struct_size == sizeof(shadow_desc_0_4)) {
        shadow_desc_0_4 o;
        memcpy(&o, d, sizeof o);
        from_0_4(&o, out);
        *preintegrated = o.preintegrated != 0;
        return UMBRA_SUCCESS;
    }
    if (earlier_list_size(d->struct_size)) {
        memcpy(out, d, d->struct_size);
        out->struct_size = sizeof *out;
        return UMBRA_SUCCESS;
    }
    return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                       "%s: desc->struct_size %zu is neither %zu nor an earlier layout's (0.4: "
                       "%zu, 0.5: %zu): call umbra_shadow_desc_init",
                       fn, d->struct_size, sizeof *d, sizeof(shadow_desc_0_4), (size_t)SIZE_0_5);
}
