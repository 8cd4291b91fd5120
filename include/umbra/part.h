// SPDX-License-Identifier: Apache-2.0
/* umbra/part.h: a volume split into parts, each rendered on its own (another process, another
 * machine), whose images and light-space maps compose into the image of the whole volume
 * (docs/distributed.md). libumbra does no communication: the application (or umbra_mpi) moves
 * the arrays below between parts, and the helpers at the end do the arithmetic on them.
 *
 * A part is an axis-aligned box of a global grid of voxels: its core [offset, offset + size)
 * per axis, offset a multiple of the brick size, and up to UMBRA_PART_MAX_GHOST ghost layers on
 * each face that it carries but does not own (clipped at the global grid's faces). Every part
 * is placed in the world as the global volume would be (the same spacing, the same
 * transform_given/origin/directions, which describe the global grid's voxel (0, 0, 0)), and
 * normalises its values with the same given value range. A renderer given a part volume works
 * in the global box: its camera, light and light-space frame are those of the whole volume, its
 * view rays take the samples one device would take of the whole volume (at t0 + (n + jitter)
 * step from the global box's entry t0, the same per-pixel jitter), and of those the ones whose
 * position lies in the part's core, half-open ([offset, offset + size) in voxel coordinates
 * + 0.5, closed at the global grid's outer faces), so each sample is taken by exactly one part.
 * With jitter the unjittered first sample and the fraction sample after it belong to the part
 * owning the first sample.
 *
 * Ghost layers a part needs beyond each face it shares with another part: 1 (the trilinear
 * footprint), plus 1 with gradient shading, plus ceil(step) with jitter (the fraction sample can
 * lie a step past the face). Fewer ghosts than that are refused at render, naming the face.
 *
 * What a part renders:
 *   - UMBRA_SHADOW_NONE, every option but those listed as refused below;
 *   - UMBRA_SHADOW_THRESHOLD and UMBRA_SHADOW_CSSM, after the light exchange below: their maps
 *     equal one device's map of the whole volume, depth for depth (CSSM: the same photons, seed
 *     and ray blocks, grey or coloured);
 *   - UMBRA_SHADOW_DEEP (the unbounded map, prefilter 1, a light step of at most a voxel; the
 *     rest refused by name), after the light exchange below and the exchange of the map's
 *     pieces (umbra_renderer_part_export_deep): at epsilon 0 its lookups equal one device's to
 *     float rounding; at epsilon > 0 each part compresses its own piece of a texel's visibility
 *     function, so the merged function has a node where the ray enters each part and differs
 *     from one device's by at most 2 epsilon (both lie within epsilon of the same march;
 *     docs/distributed.md gives the measured image differences);
 *   - what each technique exchanges: umbra_renderer_part_light_info;
 *   - refused on a part, each with UMBRA_ERROR_UNSUPPORTED naming the reason: the exact
 *     reference (shadow rays would cross parts) and convolution (slices over the whole view
 *     depth): they do not split; moments; the projection modes (MIP, MinIP, average); volumes
 *     of several channels and label maps; pre-integrated segments (a segment reaches into the
 *     next part); the ground plane; interaction AUTO (drafts change the map size per part);
 *     empty-space skipping is turned off on parts (it changes no pixel, only the work).
 *
 * Early ray termination acts within a part's own segment: with termination below 1 a part
 * behind another still adds what one device would have dropped (at most 1 - termination of the
 * pixel); parts equal one device when termination is 1. Rendered part after part into one frame
 * (umbra_renderer_render_part_into) a ray ends where one device's ends, at any termination. */
#ifndef UMBRA_PART_H
#define UMBRA_PART_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/renderer.h"
#include "umbra/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most ghost layers a part may carry on a face. */
#define UMBRA_PART_MAX_GHOST 16u

/* Where a part lies in the global grid. */
typedef struct umbra_part_desc {
    size_t struct_size;        /* sizeof(umbra_part_desc); set by umbra_part_desc_init */
    uint32_t global_dims[3];   /* voxels of the whole volume per axis, each > 0 */
    uint32_t offset[3];        /* the core's first voxel, a multiple of the volume's brick_size */
    uint32_t size[3];          /* the core's voxels per axis, each > 0, offset + size <=
                                  global_dims; 0 (all three) for an empty part (it owns nothing
                                  and renders a transparent image) */
    uint32_t ghost_lo[3];      /* layers carried below the core on each axis (at most offset and
                                  UMBRA_PART_MAX_GHOST) */
    uint32_t ghost_hi[3];      /* layers carried above it (at most global_dims - offset - size
                                  and UMBRA_PART_MAX_GHOST) */
} umbra_part_desc;

/* Fills desc with zeros and struct_size; NULL is a no-op. */
UMBRA_API void umbra_part_desc_init(umbra_part_desc *desc);

/* The ghost layers a part needs beyond a shared face for the given options (the rule at the top
 * of this file): 1 + shading + (jitter ? ceil(step) : 0). 0 for NULL. */
UMBRA_API uint32_t umbra_part_ghost_needed(const umbra_render_desc *options);

/* umbra_volume_create for a part: desc describes the voxels this part carries, dims = size +
 * ghost_lo + ghost_hi per axis (an empty part: one voxel, which is never read), desc->data holds
 * them (x fastest), desc->value_range_given must be set (the global range), and desc->spacing and
 * the transform are the global volume's. A part whose offset is off the brick grid, which
 * overflows the global grid, carries too many ghosts or whose dims do not match is refused with
 * UMBRA_ERROR_INVALID_ARGUMENT naming the value; so are several channels and label maps
 * (UMBRA_ERROR_UNSUPPORTED). umbra_volume_get_info describes the voxels carried (dims) and the
 * global placement (extent, center and origin are the global volume's). */
UMBRA_API umbra_status umbra_volume_create_part(umbra_context ctx, const umbra_volume_desc *desc,
                                                const umbra_part_desc *part, umbra_volume *out);

/* The part volume was made with, into *out (struct_size set); a volume that is not a part gives
 * the whole grid as its one part (offset 0, size = global_dims = dims, no ghosts) and returns
 * UMBRA_SUCCESS. UMBRA_ERROR_INVALID_ARGUMENT for NULL arguments. */
UMBRA_API umbra_status umbra_volume_get_part(umbra_volume volume, umbra_part_desc *out);

/* A rectangle of the w x h image, pixel (x, y) its top-left, row 0 at the top. */
typedef struct umbra_part_rect {
    uint32_t x, y, width, height;
} umbra_part_rect;

/* The rectangle of the w x h image the part's core box covers from the renderer's camera (every
 * pixel whose ray may take a sample the part owns; empty, width = height = 0, for an empty part
 * or a box behind the camera). */
UMBRA_API umbra_status umbra_renderer_part_rect(umbra_renderer r, uint32_t width, uint32_t height,
                                                umbra_part_rect *out);

/* Renders the part's partial image: the samples it owns of each view ray of the w x h image,
 * composited front to back from transparent black, premultiplied float RGBA, no background.
 * rgba receives rect->width * rect->height * 4 floats, row 0 of the rectangle first; *rect is
 * set as umbra_renderer_part_rect sets it (NULL: not reported; rgba must then hold the rectangle
 * that call would give). The volume must be a part (umbra_volume_create_part); for a light-space
 * technique the light data must have been imported first (umbra_renderer_part_light_info). The
 * partial images of all parts, composited in view order (umbra_part_visibility_order,
 * umbra_part_composite) and put over the background (umbra_part_background), make the image one
 * device renders of the whole volume (the bounds: docs/distributed.md). */
UMBRA_API umbra_status umbra_renderer_render_part(umbra_renderer r, uint32_t width,
                                                  uint32_t height, umbra_part_rect *rect,
                                                  float *rgba);

/* The part's samples added to the accumulation of the parts in front of it, as one device's ray
 * adds them: frame is the width x height image (premultiplied float RGBA, row 0 at the top, no
 * background) the parts before this one in view order (umbra_part_view_order) rendered into,
 * starting from 0; the pixels of the part's rectangle (*rect, as umbra_renderer_part_rect sets
 * it; NULL: not reported) go on from its colour and opacity, front to back, and are written back;
 * the others are left as they are. After the last part, umbra_part_background gives one device's
 * image bit for bit (the same sums in the same order; early ray termination included: a ray
 * ended in front takes no sample here), where umbra_renderer_render_part's partial images,
 * composited with the over operator, round differently (docs/distributed.md). The price: each
 * part waits for the ones in front of it. A pixel of the rectangle with an opacity outside
 * [0, 1] or a NaN is refused with UMBRA_ERROR_INVALID_ARGUMENT naming it; otherwise as
 * umbra_renderer_render_part. */
UMBRA_API umbra_status umbra_renderer_render_part_into(umbra_renderer r, uint32_t width,
                                                       uint32_t height, umbra_part_rect *rect,
                                                       float *frame);

/* What crosses parts along the light for the renderer's technique, in light order. The threshold
 * map and CSSM exchange UMBRA_PART_LIGHT_TAU_DEPTH, the deep map UMBRA_PART_LIGHT_TAU. */
typedef enum umbra_part_light_kind {
    UMBRA_PART_LIGHT_NOTHING = 0,  /* no light pass (UMBRA_SHADOW_NONE): nothing to exchange */
    UMBRA_PART_LIGHT_TAU = 1,      /* deep map: the visibility per texel passed on in light
                                      order (export after import, as the threshold map's
                                      state), then every part's pieces of the map to every part
                                      (umbra_renderer_part_export_deep, _import_deep) */
    UMBRA_PART_LIGHT_TAU_DEPTH = 2,/* threshold map and CSSM: export the march state at the
                                      part's exit, import the state the part before it left
                                      (light order), export the depths, import their minimum
                                      over all parts */
    UMBRA_PART_LIGHT_DEPTH = 3     /* a map whose local decisions need nothing from the other
                                      parts (segments indexed along the global light ray): export
                                      the depths, import their minimum. umbra's CSSM is not one:
                                      it draws one number per photon and stops it where the
                                      optical depth from the light passes it
                                      (kernels/techniques/cssm.cl), so its part needs tau_in
                                      first and is of kind UMBRA_PART_LIGHT_TAU_DEPTH */
} umbra_part_light_kind;

typedef struct umbra_part_light_info {
    size_t struct_size;            /* sizeof(umbra_part_light_info); set by the caller */
    umbra_part_light_kind kind;
    uint32_t map_size;             /* texels per side of the light-space map (one frame for all
                                      parts: fitted to the global box) */
    uint32_t channels;             /* floats per texel of the transmittance arrays: for the
                                      threshold map 2, its march's state (the product of the
                                      whole segments' 1 - alpha and an optical depth); for CSSM
                                      the optical depth from the light per simulated light
                                      channel (1 grey, 3 coloured transmission; 0 reaching the
                                      first part); for the deep map its whole march state,
                                      6 light channels + 7 floats (the visibility and the
                                      compression's open segment, in the order of
                                      kernels/techniques/deep_shared.h; NULL imports the
                                      light's for the first part) */
    uint32_t depth_channels;       /* floats per texel of the depth arrays: 1 for the threshold
                                      map, CSSM's channels (a photon depth per channel), 0 for
                                      the deep map (it exchanges pieces) */
    size_t tau_floats;             /* map_size^2 * channels, or 0 */
    size_t depth_floats;           /* map_size^2 * depth_channels, or 0 */
    uint32_t node_floats;          /* floats per deep node of umbra_renderer_part_export_deep:
                                      1 + light channels (a depth, then the visibility per
                                      channel); 0 for the other techniques. A caller whose
                                      struct_size ends before it gets the rest filled */
} umbra_part_light_info;

/* Describes the exchange the renderer's current technique and light need (the map size is
 * chosen here as the build would choose it). UMBRA_ERROR_UNSUPPORTED naming the technique for
 * one that does not split or is not yet part-aware. */
UMBRA_API umbra_status umbra_renderer_part_light_info(umbra_renderer r,
                                                      umbra_part_light_info *out);

/* Light pass 1: marches the part's own segments of every light ray (those whose midpoint its
 * core owns, at the global ray's t0 + (k + 1/2) step; for the deep map the segments of its
 * global depth grid), going on from the imported state, and
 * writes the state at their end per texel (info.tau_floats floats, texel (u, v) at
 * (v * map_size + u) * channels; the imported state where the ray misses the part). The state
 * is the light's from the light to the part's exit, not the part's own, so parts pass it on in
 * light order: the part after this one on a texel's ray imports this part's export. Walking
 * the parts in umbra_part_visibility_order from the light, each importing the array the one
 * before exported, does that for every texel at once; the march is then one device's, bit for
 * bit (a product of the parts' own transmittances, umbra_part_multiply, would round
 * differently). Builds (blocks) when the light inputs or the imported state changed. */
UMBRA_API umbra_status umbra_renderer_part_export_transmittance(umbra_renderer r, float *tau_exit);

/* Sets the state reaching the part along each light ray (info.tau_floats floats, as the part
 * before it exported them; NULL: the light's, transmittance 1 and optical depth 0, for the first
 * part on every ray). Copied; the next build marches from it. A value outside its field's range
 * (a transmittance or visibility outside [0, 1], a negative optical depth, a deep count that is
 * not an integer) or NaN is refused naming the texel, the field and the value, and so is a deep
 * state whose fields no march leaves together (points fed before the fit's origin is emitted, an
 * origin visibility below 1 before it is, an empty window of slopes). CSSM's photons of a
 * ray block share a ray: the block's first texel's state is the one its build goes on from, and
 * the export writes the end state to every texel of the block. */
UMBRA_API umbra_status umbra_renderer_part_import_transmittance(umbra_renderer r,
                                                                const float *tau_in);

/* Builds the part's depth map if needed (after the import of the state for the threshold map)
 * and writes its depths (info.depth_floats floats; the map's "never" depth where nothing happens
 * in the part). */
UMBRA_API umbra_status umbra_renderer_part_export_depths(umbra_renderer r, float *depths);

/* Sets the depths the lookups compare against: the element-wise minimum of all parts' exported
 * depths (umbra_part_minimum). Copied into the built map. NaN is refused naming the texel. A
 * part renders a threshold map or CSSM only after this import, and only while no light input
 * has changed since (else UMBRA_ERROR_INVALID_ARGUMENT: exchange again). A CSSM part stores the
 * depth of the photons it stopped and the "never" depth for those stopped before it (the imported
 * optical depth passed their threshold) or after it, so the minimum is one device's map. */
UMBRA_API umbra_status umbra_renderer_part_import_depths(umbra_renderer r, const float *depths);

/* The deep map's pieces (UMBRA_PART_LIGHT_TAU). After the import of the visibility reaching
 * it (umbra_renderer_part_import_transmittance, in light order as for the threshold map; for
 * the deep map info.channels floats per texel, the visibility per light channel), a part's map
 * holds per texel the nodes of the light-ray segments whose midpoint its core owns: its piece
 * of the texel's visibility function, depths in the global light frame. Every part's lookups
 * need the whole function of the texels its samples fall in (a texel's ray can run through a
 * neighbour's core at the sample's depth), so the pieces of all parts are gathered and each
 * part merges them into its map.
 *
 * Export: builds if needed, writes the node count of each texel (info.map_size^2 counts) and,
 * unless nodes is NULL, the nodes in texel order (1 + info.channels floats each: depth, then
 * visibility per channel); *node_count is the capacity of nodes in nodes (ignored for NULL)
 * and is set to the number of nodes. A capacity below it is refused naming both. */
UMBRA_API umbra_status umbra_renderer_part_export_deep(umbra_renderer r, uint32_t *counts,
                                                       float *nodes, size_t *node_count);

/* Import: the pieces of `parts` parts (every part's, this one's included, in any order): counts
 * holds parts x info.map_size^2 counts (part-major, as each export wrote them), nodes their node
 * arrays one after another (node_count nodes in all). Merged per texel in depth order (the
 * pieces of a texel lie in disjoint depth ranges) into this part's map, laid out in blocks as a
 * build lays them out, so the lookup is one device's. Counts that do not add up to node_count,
 * a NaN depth or a visibility outside [0, 1] are refused naming the value. A part renders the
 * deep map only after this import, and only while no light input has changed since. */
UMBRA_API umbra_status umbra_renderer_part_import_deep(umbra_renderer r, uint32_t parts,
                                                       const uint32_t *counts,
                                                       const float *nodes, size_t node_count);

/* ---- Host helpers: pure functions on the arrays above (no context, no device). ---- */

/* The visibility order of count parts (descs[i], all of one global grid) seen from a point
 * (is_point nonzero: a camera's eye or a point light) or along a direction (the direction
 * light travels or the view looks in), in the world of volume info `placement`
 * (umbra_volume_get_info of any of the parts): order[0] is the part met first. Parts that no
 * ray meets in either order keep an order consistent with the others. UMBRA_ERROR_INVALID_ARGUMENT
 * for NULL arguments, count 0, a zero direction, or parts of different global grids. */
UMBRA_API umbra_status umbra_part_visibility_order(const umbra_part_desc *descs, uint32_t count,
                                                   const umbra_volume_info *placement,
                                                   const float where[3], int is_point,
                                                   uint32_t *order);

/* The same for a camera (its eye for perspective, its viewing direction for orthographic). */
UMBRA_API umbra_status umbra_part_view_order(const umbra_part_desc *descs, uint32_t count,
                                             const umbra_volume_info *placement,
                                             const umbra_camera *camera, uint32_t *order);

/* frame = frame over part: the partial image part (rect->width x rect->height, premultiplied
 * RGBA, as umbra_renderer_render_part writes it) composited behind the width x height image
 * frame (premultiplied RGBA, the parts before it already in): C = C_frame + (1 - a_frame)
 * C_part per channel, alpha alike. Start frame at 0 and add the parts in view order. A rect
 * outside the image is refused with UMBRA_ERROR_INVALID_ARGUMENT. */
UMBRA_API umbra_status umbra_part_composite(float *frame, uint32_t width, uint32_t height,
                                            const float *part, const umbra_part_rect *rect);

/* out = front over back, per pixel (count premultiplied RGBA pixels; out may be front or
 * back): the associative, non-commutative operator a compositor reduces with. */
UMBRA_API void umbra_part_over(const float *front, const float *back, float *out, size_t count);

/* Puts a composited image over the background as one device does: C + (1 - a) background, for
 * count pixels, one fused multiply-add per channel as the ray caster's (the same rounding). */
UMBRA_API void umbra_part_background(float *rgba, size_t count, const float background[4]);

/* acc[i] *= t[i] for count floats: one step of the prefix product of exit transmittances in
 * light order (tau_in of a part is the product over the parts before it). */
UMBRA_API void umbra_part_multiply(float *acc, const float *t, size_t count);

/* acc[i] = min(acc[i], d[i]) for count floats: the reduction of exported depths. */
UMBRA_API void umbra_part_minimum(float *acc, const float *d, size_t count);

#ifdef __cplusplus
}
#endif
#endif
