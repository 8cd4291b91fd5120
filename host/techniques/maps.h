// SPDX-License-Identifier: Apache-2.0
/* host/techniques/maps.h: what a single-layer light-space map shares (the threshold map and CSSM
 * use it; a map of a fixed number of floats per texel can): a map buffer
 * fitted to the volume's box (host/lightspace.c) that lives as long as the technique and is
 * re-allocated only when its size changes, the build kernel from the technique's own kernel
 * files (and, optionally, filter passes over the built map), and the technique's kernel
 * constants passed to the build and to every lookup. The renderer calls the build only
 * when the light, volume, light transfer function or a parameter that rebuilds changed, so a
 * camera move re-uses the map. */
#ifndef UMBRA_TECHNIQUES_MAPS_H
#define UMBRA_TECHNIQUES_MAPS_H

#include "renderer_internal.h"

/* How one technique's single-layer map is built and looked up. */
typedef struct umbra__map_kind {
    const char *build_kernel; /* in the technique's kernel files: (the common arguments,
                                 constants, map) over a 2D range of blocks of texels */
    size_t constants_size;    /* bytes of the technique's kernel constants (<= 64) */
    /* Floats per texel. */
    uint32_t (*values)(umbra_renderer r);
    /* Fills the constants for a build, after the map was fitted (r->shadow_params holds its
     * projection and step); texels_per_voxel is the map's, as umbra__lightspace_setup said.
     * Returns the side of the square blocks of texels one work-item of the build takes. */
    uint32_t (*build_constants)(umbra_renderer r, double texels_per_voxel, void *constants);
    /* Refreshes, before every lookup, the constants the lookup reads that do not rebuild the
     * map (optional). */
    void (*lookup_constants)(umbra_renderer r, void *constants);
    /* A linear filter over the built map (optional): filter_kernel, in the technique's kernel
     * files, runs filter_passes(r) times after the build kernel (0: not at all), one work-item
     * per texel, with the arguments (shadow parameters, constants, pass index as a uint, the map
     * read, the map written); each pass writes a fresh buffer of the map's size, which becomes
     * the map, so a separable filter is one pass per axis. The buffer a pass read is freed when
     * the build ends: between builds the technique holds only the map. */
    const char *filter_kernel;
    uint32_t (*filter_passes)(umbra_renderer r);
} umbra__map_kind;

/* The technique functions of a single-layer map, whose descriptor's data is its umbra__map_kind:
 * build, bind (the constants and the map, in that order, after the fixed arguments), memory and
 * destroy. */
umbra_status umbra__map_build(umbra_renderer r, double *ms);
umbra_status umbra__map_bind(umbra_renderer r, cl_kernel k, cl_uint first);
size_t umbra__map_memory(umbra_renderer r);
void umbra__map_destroy(umbra_renderer r);

/* The tap counts of a filtered lookup (kernels/common/lightspace.cl's offsets): 1, 7, 13, 21. */
extern const double umbra__map_taps[4];

/* The kernel constants the last build or lookup used (tests read them): constants_size bytes,
 * or NULL before the first build. */
const void *umbra__map_constants(umbra_renderer r);

/* Copies the built map (tests read it) into out, which holds `bytes`: at least the map's size
 * (umbra_render_stats.shadow_memory_bytes). UMBRA_ERROR_INVALID_ARGUMENT before a build or for
 * a smaller out. */
umbra_status umbra__map_read(umbra_renderer r, void *out, size_t bytes);

/* Overwrites the built map with bytes (its whole size) of data: a part's imported depths. */
umbra_status umbra__map_write(umbra_renderer r, const void *data, size_t bytes);

#endif
