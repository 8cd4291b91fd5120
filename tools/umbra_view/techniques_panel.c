// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/techniques_panel.c: the technique table of techniques_panel.h, written from
 * the current public API: the fields of umbra_shadow_desc (include/umbra/renderer.h), the ranges
 * umbra_renderer_set_shadow checks, and which technique reads which field. Defaults are not
 * copied: they are read from umbra_shadow_desc_init. When the library's technique registry (its
 * introspection of techniques and parameters) is merged, this file becomes a thin adapter over
 * it or goes away. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "techniques_panel.h"

/* A parameter and where it lives in umbra_shadow_desc; view_param is its first member, so a
 * const view_param * handed out is also a const entry *. */
typedef struct entry {
    view_param p;
    size_t offset;
} entry;

#define FIELD(f) offsetof(umbra_shadow_desc, f)

static const uint32_t taps_choices[] = {1, 7, 13, 21};
static const uint32_t prefilter_choices[] = {1, 5};

static const entry reference_step = {
    {"reference_step", VIEW_PARAM_FLOAT, 0.01, 64, NULL, 0, NULL, 0, 1,
     "shadow-ray step in voxels"}, FIELD(reference_step)};
static const entry map_size = {
    {"map_size", VIEW_PARAM_UINT, 16, 8192, "auto", 512, NULL, 0, 1,
     "map resolution map_size^2; auto chooses it from the volume's footprint seen from the light"},
    FIELD(map_size)};
static const entry map_texels_per_voxel = {
    {"map_texels_per_voxel", VIEW_PARAM_FLOAT, 0.25, 8, "technique's own", 1, NULL, 0, 1,
     "auto map size: texels per voxel across the box's projection (1 is a draft)"},
    FIELD(map_texels_per_voxel)};
static const entry map_step = {
    {"map_step", VIEW_PARAM_FLOAT, 0.01, 64, "technique's own", 1, NULL, 0, 1,
     "light-ray step in voxels"}, FIELD(map_step)};
static const entry threshold = {
    {"threshold", VIEW_PARAM_FLOAT, 0.01, 0.99, NULL, 0, NULL, 0, 0,
     "accumulated light opacity at which a texel's depth is stored"}, FIELD(threshold)};
static const entry taps = {
    {"taps", VIEW_PARAM_UINT, 1, 21, NULL, 0, taps_choices, 4, 0,
     "texels averaged per lookup (radius 0, 4, 7, 10)"}, FIELD(taps)};
static const entry epsilon = {
    {"epsilon", VIEW_PARAM_FLOAT, 0, 1, NULL, 0, NULL, 0, 0,
     "compression error bound of the visibility function"}, FIELD(epsilon)};
static const entry max_nodes = {
    {"max_nodes", VIEW_PARAM_UINT, 2, 64, "unbounded", 8, NULL, 0, 0,
     "fixed budget of nodes per texel"}, FIELD(max_nodes)};
static const entry block_size = {
    {"block_size", VIEW_PARAM_UINT, 1, 256, NULL, 0, NULL, 0, 1, "node layers per block"},
    FIELD(block_size)};
static const entry prefilter = {
    {"prefilter", VIEW_PARAM_UINT, 1, 5, NULL, 0, prefilter_choices, 2, 0,
     "sub-pixel rays per texel"}, FIELD(prefilter)};
static const entry lookup_table = {
    {"lookup_table", VIEW_PARAM_BOOL, 0, 1, NULL, 0, NULL, 0, 0,
     "use the pre-compressed segment table"}, FIELD(lookup_table)};
static const entry seed = {
    {"seed", VIEW_PARAM_UINT, 0, 4294967295.0, NULL, 0, NULL, 0, 0,
     "seed of the stochastic photons: the same seed gives the same map"}, FIELD(seed)};
static const entry ray_block = {
    {"ray_block", VIEW_PARAM_UINT, 1, 3, "map's own", 1, NULL, 0, 0,
     "texels per side of the blocks whose photons share one light ray"}, FIELD(ray_block)};
static const entry slice_distance = {
    {"slice_distance", VIEW_PARAM_FLOAT, 0.02, 16, NULL, 0, NULL, 0, 1, "voxels between slices"},
    FIELD(slice_distance)};
static const entry subsamples = {
    {"subsamples", VIEW_PARAM_UINT, 0, 64, NULL, 0, NULL, 0, 0,
     "volume samples between two slices (SCS)"}, FIELD(subsamples)};
static const entry cone_angle = {
    {"cone_angle_degrees", VIEW_PARAM_FLOAT, 0, 60, NULL, 0, NULL, 0, 0,
     "half-angle of the cone the light spreads over per slice"}, FIELD(cone_angle_degrees)};
static const entry preintegrated = {
    {"preintegrated", VIEW_PARAM_BOOL, 0, 1, NULL, 0, NULL, 0, 0,
     "pre-integrated segments along the view ray (and the convolution's light)"},
    FIELD(preintegrated)};

static const view_param *const none_params[] = {&preintegrated.p};
static const view_param *const reference_params[] = {&reference_step.p, &preintegrated.p};
static const view_param *const threshold_params[] = {
    &map_size.p, &map_texels_per_voxel.p, &map_step.p, &threshold.p, &taps.p, &preintegrated.p};
static const view_param *const deep_params[] = {
    &map_size.p, &map_texels_per_voxel.p, &map_step.p, &epsilon.p, &max_nodes.p,
    &block_size.p, &prefilter.p, &lookup_table.p, &preintegrated.p};
static const view_param *const cssm_params[] = {
    &map_size.p, &map_texels_per_voxel.p, &map_step.p, &taps.p, &seed.p, &ray_block.p,
    &preintegrated.p};
static const view_param *const convolution_params[] = {
    &slice_distance.p, &subsamples.p, &cone_angle.p, &preintegrated.p};

#define COUNT(a) (unsigned)(sizeof(a) / sizeof((a)[0]))

static const struct {
    umbra_shadow_technique technique;
    const view_param *const *params;
    unsigned count;
} techniques[] = {
    {UMBRA_SHADOW_NONE, none_params, COUNT(none_params)},
    {UMBRA_SHADOW_REFERENCE, reference_params, COUNT(reference_params)},
    {UMBRA_SHADOW_THRESHOLD, threshold_params, COUNT(threshold_params)},
    {UMBRA_SHADOW_DEEP, deep_params, COUNT(deep_params)},
    {UMBRA_SHADOW_CSSM, cssm_params, COUNT(cssm_params)},
    {UMBRA_SHADOW_CONVOLUTION, convolution_params, COUNT(convolution_params)},
};

unsigned view_technique_count(void) { return COUNT(techniques); }

umbra_shadow_technique view_technique_at(unsigned i)
{
    return i < COUNT(techniques) ? techniques[i].technique : UMBRA_SHADOW_NONE;
}

const view_param *const *view_technique_params(umbra_shadow_technique t, unsigned *count)
{
    for (unsigned i = 0; i < COUNT(techniques); ++i)
        if (techniques[i].technique == t) {
            *count = techniques[i].count;
            return techniques[i].params;
        }
    *count = 0;
    return NULL;
}

double view_param_get(const umbra_shadow_desc *d, const view_param *p)
{
    const char *field = (const char *)d + ((const entry *)p)->offset;
    float f;
    uint32_t u;
    int b;
    switch (p->kind) {
    case VIEW_PARAM_FLOAT: memcpy(&f, field, sizeof f); return f;
    case VIEW_PARAM_UINT: memcpy(&u, field, sizeof u); return u;
    default: memcpy(&b, field, sizeof b); return b != 0;
    }
}

double view_param_default(const view_param *p)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    return view_param_get(&d, p);
}

void view_param_set(umbra_shadow_desc *d, const view_param *p, double v)
{
    char *field = (char *)d + ((const entry *)p)->offset;
    if (!isfinite(v))
        return;
    if (p->kind == VIEW_PARAM_FLOAT) {
        float f = (float)v;
        memcpy(field, &f, sizeof f);
    } else if (p->kind == VIEW_PARAM_UINT) {
        double r = nearbyint(v);
        uint32_t u = r <= 0 ? 0u : r >= 4294967295.0 ? UINT32_MAX : (uint32_t)r;
        memcpy(field, &u, sizeof u);
    } else {
        int b = v != 0;
        memcpy(field, &b, sizeof b);
    }
}
