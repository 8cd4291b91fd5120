// SPDX-License-Identifier: Apache-2.0
/* umbra/renderer.h: direct volume rendering with shadows.
 *
 * A renderer draws one volume with a view transfer function from a camera, lit by one light, and
 * takes a per-sample RGB shadow factor from the selected shadow technique. Camera, light, ground
 * plane and query points are in the volume's world (volume.h: the centred box unless the volume
 * carries an index-to-world transform). Setters copy their arguments and mark what changed;
 * render() rebuilds only what the change calls for (moving the camera re-uses a shadow map built
 * for the same light, volume and light transfer function).
 *
 * Shading model, shared by every technique. Light is absorbed per channel with extinction
 * sigma (1 - t_c): sigma = -ln(1 - a) per voxel length (the smallest spacing) of the light
 * transfer function's alpha a (interpolated, at most 1 - 2^-24), t the transmission colour, so a
 * length of D voxels at one value passes (1 - a)^(D (1 - t_c)) of channel c (the CSSM paper's
 * rho = a (1 - t) is its one-sample form). The shadow factor S_c at a point is exp(-optical depth)
 * along the path to the light. t is 0 in UMBRA_TRANSMISSION_GREY mode (classic grey shadows) or
 * the RGB of the light transfer function in UMBRA_TRANSMISSION_COLORED mode (coloured shadows:
 * red material lets red light through). A sample of colour c is then lit as
 *     c * (ambient + light * S * (shading ? kd |N.L| : 1)) + (shading ? light * S * ks |N.H|^n : 0)
 * and composited front to back (emission-absorption, Max 1995), with S taken at the mean emission
 * depth of the view segment the sample stands for (kernels/raycast.cl). The ground plane is lit as
 *     ground * (ambient + light * S * max(0, N.L)). */
#ifndef UMBRA_RENDERER_H
#define UMBRA_RENDERER_H

#include <stddef.h>
#include <stdint.h>

#include "umbra/context.h"
#include "umbra/techniques/list.h"
#include "umbra/transfer_function.h"
#include "umbra/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct umbra_renderer_t *umbra_renderer;

typedef enum umbra_projection {
    UMBRA_PERSPECTIVE = 0,
    UMBRA_ORTHOGRAPHIC = 1
} umbra_projection;

/* Bound on the magnitude of every world coordinate the renderer is given (camera eye and target,
 * point-light position): within it, differences and squared lengths stay finite in float.
 * Setters refuse points beyond it with UMBRA_ERROR_INVALID_ARGUMENT naming them. */
#define UMBRA_MAX_COORDINATE 1e18f

/* A look-at camera in the volume's world (volume.h: the box is centred on the origin unless the
 * volume carries an index-to-world transform). Distances and steps keep their meaning: the
 * transform is rigid. eye and target lie within +-UMBRA_MAX_COORDINATE; up is any finite vector
 * not parallel to the view. */
typedef struct umbra_camera {
    umbra_projection projection;
    float eye[3];
    float target[3];
    float up[3];
    float fovy_degrees;   /* perspective: vertical field of view, in (0, 180) */
    float ortho_height;   /* orthographic: height of the view in world units, > 0 */
} umbra_camera;

/* A camera looking at the world origin (the centred box's centre) from direction dir (need not
 * be normalised) at a distance that frames a box of the given diagonal; up is +y. */
UMBRA_API umbra_camera umbra_camera_orbit(const float dir[3], float box_diagonal,
                                          float fovy_degrees);
/* The same around center (world units), e.g. umbra_volume_info.center of a transformed volume. */
UMBRA_API umbra_camera umbra_camera_orbit_at(const float center[3], const float dir[3],
                                             float box_diagonal, float fovy_degrees);

typedef enum umbra_light_type {
    UMBRA_LIGHT_POINT = 0,
    UMBRA_LIGHT_DIRECTIONAL = 1
} umbra_light_type;

typedef struct umbra_light {
    umbra_light_type type;
    float position[3];   /* point light, in the volume's world, within +-UMBRA_MAX_COORDINATE;
                            may lie inside the volume */
    float direction[3];  /* directional light: the direction light travels in, in the volume's
                            world (need not be unit; any finite non-zero vector) */
    float color[3];      /* RGB intensity, each >= 0 */
} umbra_light;

typedef enum umbra_transmission {
    UMBRA_TRANSMISSION_GREY = 0,    /* t = 0: every channel attenuated by the opacity alone */
    UMBRA_TRANSMISSION_COLORED = 1  /* t = RGB of the light transfer function */
} umbra_transmission;

/* Bound on the samples one ray may take: the box diagonal over the step, for view rays (step),
 * shadow rays (reference step) and light rays (map step, slice_distance / (subsamples + 1)). A
 * render (or query) whose volume and steps would exceed it fails with
 * UMBRA_ERROR_INVALID_ARGUMENT naming the count and this limit, before any work: such a volume
 * is too anisotropic or too large for the step (raise the step, or resample the volume). */
#define UMBRA_MAX_RAY_SAMPLES 1048576u

/* Progressive shadows (umbra_render_desc.interaction). With UMBRA_INTERACTION_AUTO a frame whose
 * shadow structure would be rebuilt because its inputs changed since the previous frame (the
 * light, the volume, the light transfer function or the view one it uses, the transmission mode,
 * empty-space skipping, the technique or one of its parameters that rebuild: every input of
 * umbra_technique_info.rebuilt_by and UMBRA_PARAM_REBUILDS) builds the technique's draft instead
 * (umbra_technique_info.draft: a coarser map, a larger error bound), and the next frame whose
 * inputs are those of the frame before it builds the full structure, which equals what a fresh
 * renderer builds bit for bit; a camera move changes none of these inputs, so it keeps the full
 * structure (cached). umbra_render_stats.draft says which one the last frame used: an
 * application that renders only on input events renders once more after the input stops while
 * it is set. The first frame a renderer renders, shadow queries (umbra_renderer_query_shadow)
 * and techniques without a draft always use the full structure. UMBRA_INTERACTION_OFF (the
 * default): every frame uses the full structure. */
typedef enum umbra_interaction {
    UMBRA_INTERACTION_OFF = 0,
    UMBRA_INTERACTION_AUTO = 1
} umbra_interaction;

/* How a frame turns samples into pixels (umbra_render_desc.mode). The projection modes take
 * the volume's normalised value at the view ray's samples (the composite mode's positions:
 * every step inside the volume's box and the clip region, jittered when jitter is set, no
 * empty-space skipping or early termination) and reduce them to one value m per pixel: the
 * largest (MIP), the smallest (MinIP) or their mean (average intensity projection). The pixel is
 * the view transfer function's entry at m, alpha as given (not corrected for the step),
 * premultiplied and over the background: (rgb a, a) + (1 - a) background; a ray that meets no
 * sample shows the background. A volume of several channels projects each channel through its
 * own transfer function and adds the premultiplied colours, alpha 1 - prod (1 - a_c) (additive
 * blending, as microscopy viewers show channels). They draw no light: shadows, shading, the
 * ground plane, transmission, termination and pre-integration do not apply, and a shadow
 * technique other than UMBRA_SHADOW_NONE, or a label map (labels have no order), is refused at
 * render with UMBRA_ERROR_INVALID_ARGUMENT naming the mode. */
typedef enum umbra_render_mode {
    UMBRA_RENDER_COMPOSITE = 0, /* emission-absorption compositing, lit and shadowed (default) */
    UMBRA_RENDER_MIP = 1,       /* maximum intensity projection */
    UMBRA_RENDER_MINIP = 2,     /* minimum intensity projection */
    UMBRA_RENDER_AVERAGE = 3    /* average intensity projection */
} umbra_render_mode;

typedef struct umbra_render_desc {
    size_t struct_size;      /* sizeof(umbra_render_desc); set by umbra_render_desc_init */
    float step;              /* sampling step along view rays, in voxels (default 0.5) */
    int jitter;              /* nonzero: start each ray at a seeded random fraction of a step */
    uint32_t seed;           /* seed for the jitter (and stochastic techniques) */
    float termination;       /* early ray termination once accumulated opacity exceeds this
                                (default 0.99; 1 disables it) */
    int empty_space_skipping;/* nonzero (default): skip bricks the transfer function makes empty */
    int shading;             /* nonzero: gradient Blinn-Phong local shading (default 0). On a
                                whole volume of integers (uint8, or 16-bit spanning at most
                                32767, none outside the value range) the renderer holds a
                                gradient volume for it: 8 bytes per voxel ((x+3)(y+3)(z+3)
                                entries), made at the first shaded frame and after a volume
                                update, freed by an unshaded frame; the image is the same */
    float kd, ks, shininess; /* Blinn-Phong coefficients (defaults 0.8, 0.3, 32) */
    float ambient[3];        /* ambient light (default 0.2 each) */
    float background[4];     /* premultiplied RGBA behind everything (default 0,0,0,0) */
    int ground_plane;        /* nonzero: opaque plane under the volume receives shadows; it is
                                horizontal (normal +y) in the volume's world, also when the
                                volume is rotated */
    float ground_color[3];   /* default 0.8 each */
    float ground_offset;     /* gap between the box's lowest world y (its lowest corner) and
                                the plane, as a fraction of the box diagonal (default 0.02;
                                negative lifts it into the box) */
    umbra_transmission transmission; /* default UMBRA_TRANSMISSION_GREY */
    /* Fields below were added after umbra 0.4; a desc whose struct_size is that layout's size
     * (offsetof(umbra_render_desc, preintegrated)) is accepted and leaves them as they were (a
     * 0.4 caller sets preintegrated through its umbra_shadow_desc). */
    int preintegrated;       /* nonzero: pre-integrated segments (a 2D table over front and back
                                value, rebuilt when the transfer function or the segment length
                                changes): every ray-cast technique pre-integrates the view ray's
                                segments of length `step`, and the convolution technique
                                attenuates the light with the segment's pre-integrated
                                transmittance (default 0) */
    /* Added after umbra 0.5: a desc of that layout's size (RENDER_DESC_SIZE_0_5 in
     * host/renderer.c, or offsetof(umbra_render_desc, mode) without its padding) is accepted and
     * leaves the fields below as they were. */
    umbra_render_mode mode;  /* default UMBRA_RENDER_COMPOSITE */
    umbra_interaction interaction; /* UMBRA_INTERACTION_OFF (default) or _AUTO: progressive
                                      shadows, above */
} umbra_render_desc;

/* Fills desc with the defaults given beside each field (struct_size included); NULL is a no-op. */
UMBRA_API void umbra_render_desc_init(umbra_render_desc *desc);

/* The shadow techniques: UMBRA_SHADOW_NONE (factor 1 everywhere), _REFERENCE, _THRESHOLD, _CSSM,
 * _DEEP and _CONVOLUTION, made from the registry's list (umbra/techniques/list.h). What each one
 * is and does: its header umbra/techniques/<name>.h, and at run time umbra_technique_find_id()
 * (umbra/registry.h). */
typedef enum umbra_shadow_technique {
#define UMBRA__TECHNIQUE_ENUM(name, NAME, id, member) UMBRA_SHADOW_##NAME = id,
    UMBRA_TECHNIQUE_LIST(UMBRA__TECHNIQUE_ENUM)
#undef UMBRA__TECHNIQUE_ENUM
} umbra_shadow_technique;

/* Name used by the CLI ("reference"), or NULL for an unknown value. */
UMBRA_API const char *umbra_shadow_technique_name(umbra_shadow_technique technique);
/* Parses a name; UMBRA_ERROR_INVALID_ARGUMENT for an unknown one. */
UMBRA_API umbra_status umbra_shadow_technique_parse(const char *name, umbra_shadow_technique *out);

/* size UMBRA_MAP_SIZE_AUTO (the default) lets each build of a light-space map choose its
 * resolution from the volume's footprint as the light sees it: k texels per voxel (the smallest
 * spacing) across the box's projection, k the technique's own (umbra_technique_info's
 * map_texels_per_voxel: 1 for the threshold map, one depth per texel: finer maps sample the same
 * voxels again; 3 for CSSM, whose taps are fixed in texels, radius 4 for 13 taps, so fewer texels
 * per voxel blur the shadow over several voxels; 2 for the deep map, a nearest-texel lookup whose
 * error keeps falling with the size; docs/techniques.md, "Map size"). A directional light's map
 * gets k times the wider side of the box's projection in voxels; a point light's frustum the same
 * measured at the distance of the box's centre (the near side gets more texels per voxel, the far
 * side fewer); a point light inside or near the box (octahedral map over every direction)
 * k sqrt(4 pi) R / voxel, R the distance to the farthest corner. texels_per_voxel replaces k where
 * it is set: an application that rebuilds the map every frame while the user drags the light can
 * ask for 1 (a draft at the threshold map's size, cheaper to build; what it costs and saves:
 * docs/accuracy.md) and go back to 0 when the light stops. The result is rounded up to a
 * multiple of UMBRA_MAP_SIZE_AUTO_ROUND (whole deep-map tiles) and bounded to
 * [UMBRA_MAP_SIZE_AUTO_MIN, UMBRA_MAP_SIZE_AUTO_MAX]. It is chosen again whenever the map is
 * rebuilt (the light or volume changed); umbra_render_stats.map_size says what was chosen. On the
 * walnut (128 x 96 x 114, point light) that is 192^2, 512^2 and 352^2. */
#define UMBRA_MAP_SIZE_AUTO 0u
#define UMBRA_MAP_SIZE_AUTO_MIN 64u
#define UMBRA_MAP_SIZE_AUTO_MAX 2048u
#define UMBRA_MAP_SIZE_AUTO_ROUND 32u

/* What every light-space map (a technique with UMBRA_TECHNIQUE_MAP: threshold, cssm, deep) reads;
 * the others ignore it. Keys (umbra/registry.h): map_size, map_texels_per_voxel, map_step. */
typedef struct umbra_map_desc {
    uint32_t size;          /* map resolution, size^2 texels: UMBRA_MAP_SIZE_AUTO (0, the
                               default: chosen from the scene, rule above) or 16..8192;
                               umbra_render_stats.map_size reports the size built */
    float texels_per_voxel; /* UMBRA_MAP_SIZE_AUTO only: texels per voxel across the box's
                               projection, 0 (the default: the technique's own, rule above) or
                               [0.25, 8]; a fixed size ignores it */
    float step;             /* light-ray step in voxels: 0 (the default: the technique's own,
                               umbra_technique_info.map_step: 1 for the threshold map and CSSM,
                               0.5 for the deep map, docs/techniques.md) or [0.01, 64] */
} umbra_map_desc;

/* The shadow technique and the parameters of every technique, each in its own member (the
 * active technique's are the ones read, validated and compared when deciding a rebuild): the
 * members come from the registry's list (umbra/techniques/list.h), and umbra/registry.h reads
 * and sets any parameter by name with its range checked. Older layouts are accepted by
 * struct_size: umbra 0.4's flat struct (with the 0.4 `preintegrated`, which then sets the
 * renderer's umbra_render_desc.preintegrated), and this struct as an earlier list made it (the
 * techniques appended since take their defaults). */
typedef struct umbra_shadow_desc {
    size_t struct_size;               /* sizeof(umbra_shadow_desc); set by umbra_shadow_desc_init */
    umbra_shadow_technique technique; /* default UMBRA_SHADOW_NONE */
    uint32_t reserved;                /* 0 (umbra_shadow_desc_init); unread. Without it this
                                         layout would have the size of umbra 0.4's, which
                                         struct_size must tell apart */
    umbra_map_desc map;               /* the light-space maps' shared parameters */
#define UMBRA__TECHNIQUE_MEMBER(name, NAME, id, member) member
    UMBRA_TECHNIQUE_LIST(UMBRA__TECHNIQUE_MEMBER)
#undef UMBRA__TECHNIQUE_MEMBER
} umbra_shadow_desc;

/* Fills desc with every parameter's default (the registry's, umbra/registry.h; the headers give
 * them beside each field) and struct_size; NULL is a no-op. */
UMBRA_API void umbra_shadow_desc_init(umbra_shadow_desc *desc);

/* Creates a renderer on ctx (retained). */
UMBRA_API umbra_status umbra_renderer_create(umbra_context ctx, umbra_renderer *out);
UMBRA_API void umbra_renderer_retain(umbra_renderer r);
UMBRA_API void umbra_renderer_release(umbra_renderer r); /* NULL is a no-op */

/* The volume and transfer functions are retained. The light transfer function drives the light
 * pass (and the transmission colour); NULL (the default) uses the view transfer function. */
UMBRA_API umbra_status umbra_renderer_set_volume(umbra_renderer r, umbra_volume volume);
UMBRA_API umbra_status umbra_renderer_set_transfer_function(umbra_renderer r,
                                                            umbra_transfer_function tf);
UMBRA_API umbra_status umbra_renderer_set_light_transfer_function(umbra_renderer r,
                                                                  umbra_transfer_function tf);
/* Camera, light, options and shadow descriptions are copied and validated. */
UMBRA_API umbra_status umbra_renderer_set_camera(umbra_renderer r, const umbra_camera *camera);
UMBRA_API umbra_status umbra_renderer_set_light(umbra_renderer r, const umbra_light *light);
UMBRA_API umbra_status umbra_renderer_set_options(umbra_renderer r, const umbra_render_desc *desc);
UMBRA_API umbra_status umbra_renderer_set_shadow(umbra_renderer r, const umbra_shadow_desc *desc);

/* The transfer functions of channel `channel` of a multi-channel volume (volume.h; channel 0's
 * are the ones set above, which this call sets too for channel 0): tf, its view transfer
 * function (retained; NULL is refused), and light_tf, its light transfer function (retained;
 * NULL: tf). Each is resampled onto its channel's value range as a single volume's is. The
 * channels mix as emission-absorption media do (docs/features.md): at a sample their
 * extinctions -ln(1 - a_c) add, so the opacity is 1 - prod (1 - a_c), and the colour is the
 * channels' colours weighted by their extinctions; the light is absorbed by the summed
 * extinction, each channel's through its own transmission colour, so shadows take the colour of
 * what casts them. A channel without a transfer function of its own is refused at render
 * (UMBRA_ERROR_INVALID_ARGUMENT naming it). channel lies in [0, UMBRA_MAX_CHANNELS). */
UMBRA_API umbra_status umbra_renderer_set_channel_transfer_function(umbra_renderer r,
                                                                    uint32_t channel,
                                                                    umbra_transfer_function tf,
                                                                    umbra_transfer_function light_tf);

/* Clipping: up to UMBRA_MAX_CLIP_PLANES planes and a crop box cut the volume to the convex
 * region they all keep, for the view and the light alike: what is clipped away is neither seen
 * nor casts a shadow, in every shadow technique (each light ray, shadow ray and convolution
 * slice sees the same region) and in the projection modes. A view ray takes the samples it would
 * take without clipping that lie inside the region (none move), so moving a plane does not shift
 * the sampling of what stays. The ground plane is not clipped, and empty-space skipping is
 * unchanged (the clip applies on top of it). A change rebuilds the shadow structure, not the
 * view tables. With nothing clipped (the default) a frame costs what it did before clipping
 * existed (docs/features.md). */
#define UMBRA_MAX_CLIP_PLANES 6
typedef struct umbra_clip_desc {
    size_t struct_size;      /* sizeof(umbra_clip_desc); set by umbra_clip_desc_init */
    uint32_t plane_count;    /* planes in use, 0 (default) to UMBRA_MAX_CLIP_PLANES */
    float planes[UMBRA_MAX_CLIP_PLANES][4]; /* plane i, (a, b, c, d) in the volume's world,
                                keeps the points with a x + b y + c z + d >= 0; finite, (a, b, c)
                                not zero, and the plane within UMBRA_MAX_COORDINATE of the
                                origin (|d| / |(a, b, c)|) */
    int crop;                /* nonzero: keep only the crop box too (default 0) */
    float crop_min[3], crop_max[3]; /* the crop box in voxel coordinates, voxel (i, j, k)'s centre
                                at (i, j, k), so [-0.5, dims - 0.5] is the whole volume
                                (umbra_clip_desc_init sets 0; read only with crop): finite,
                                min <= max per axis */
} umbra_clip_desc;

/* Fills desc with the defaults beside each field (nothing clipped; struct_size included); NULL
 * is a no-op. */
UMBRA_API void umbra_clip_desc_init(umbra_clip_desc *desc);

/* Copies and validates the clip region (NULL: nothing clipped). A bad value is refused with
 * UMBRA_ERROR_INVALID_ARGUMENT naming the plane or axis and the value, and changes nothing. The
 * crop box is in voxels and follows the volume; the planes are in the world and stay there when
 * the volume changes. */
UMBRA_API umbra_status umbra_renderer_set_clip(umbra_renderer r, const umbra_clip_desc *desc);

/* Renders width x height premultiplied RGBA floats, row 0 at the top, into rgba (4*w*h floats,
 * borrowed). Blocks until done. */
UMBRA_API umbra_status umbra_renderer_render(umbra_renderer r, uint32_t width, uint32_t height,
                                             float *rgba);

/* Renders into the application's buffer (retained during the call; a writable buffer of the
 * context's cl_context of at least 16*w*h bytes, same layout as above; anything else is refused,
 * context.h contract point 2). Blocks until done. */
UMBRA_API umbra_status umbra_renderer_render_to_cl_buffer(umbra_renderer r, uint32_t width,
                                                          uint32_t height, cl_mem rgba);

/* As umbra_renderer_render_to_cl_buffer, for applications that pipeline: the frame's commands
 * wait for the num_wait events of wait_list (events of the context's cl_context, e.g. the
 * application's user events or the commands that last wrote rgba; wait_list is borrowed, may be
 * NULL when num_wait is 0) and *done receives a new event (the caller releases it) that completes
 * when rgba holds the frame. On failure *done is NULL and rgba's contents are unspecified.
 *
 * What happens on the host before the call returns: whatever the frame needs that is not yet
 * built is built and waited for, ahead of the wait list: kernel programs (the first use of a
 * technique), step-corrected transfer-function tables, pre-integration tables and the shadow
 * structure (after the light, volume, light transfer function or shadow description changed).
 * Such a build waits for the commands already in the queue, which on an in-order application
 * queue includes earlier asynchronous frames still waiting on their own wait lists: change the
 * light only once those can complete. When nothing needs building (e.g. only the camera moved)
 * the call waits for nothing. Per-frame constants are copied at the call; the renderer, volume,
 * transfer functions and rgba may be changed or released as soon as it returns (OpenCL keeps
 * what the enqueued commands use until they complete).
 *
 * *done is the frame's last kernel (the ray caster's; the convolution technique's resolve): its
 * profiling counters, when the queue has profiling, time that kernel, which for every technique
 * but convolution is the frame's device work. Until *done has completed the stats have
 * render_timing UMBRA_TIMING_NONE, render_ms 0 and samples 0 (the call does not wait for them);
 * once it has, umbra_renderer_get_stats gives the frame's device time (first kernel's start to
 * last kernel's end, UMBRA_TIMING_DEVICE) until the next frame. Samples stay 0.
 *
 * A wait-list event that ends in an error (clSetUserEventStatus with a negative status, a failed
 * command) fails the frame: none of its commands run, rgba is left as it was, and *done ends with
 * a negative status, as do later frames queued behind it on the same in-order queue. An event
 * that has already failed at the call is refused (UMBRA_ERROR_INVALID_ARGUMENT): PoCL would never
 * run the frame. umbra holds every command of the frame until it has ended: PoCL 3.1 aborts the
 * process when such a failure reaches a command nobody holds, so commands the application queues
 * behind a wait-list event or behind *done need events it holds until they end too. */
UMBRA_API umbra_status umbra_renderer_render_to_cl_buffer_async(umbra_renderer r, uint32_t width,
                                                                uint32_t height, cl_mem rgba,
                                                                cl_uint num_wait,
                                                                const cl_event *wait_list,
                                                                cl_event *done);

/* Evaluates the current technique's shadow factor at count points in the volume's world (3 floats
 * each, borrowed) into rgb (3 floats each). Builds the shadow structure first if needed. */
UMBRA_API umbra_status umbra_renderer_query_shadow(umbra_renderer r, const float *points,
                                                   size_t count, float *rgb);

/* Where a time in umbra_render_stats comes from (context.h contract point 4). */
typedef enum umbra_timing {
    UMBRA_TIMING_NONE = 0,   /* not measured (nothing was built, nothing rendered yet, or the
                                frame was asynchronous): the time is 0 */
    UMBRA_TIMING_DEVICE = 1, /* device time from the events' profiling counters */
    UMBRA_TIMING_WALL = 2    /* host wall clock from enqueue to completion (a queue without
                                CL_QUEUE_PROFILING_ENABLE): includes work queued ahead */
} umbra_timing;

typedef struct umbra_render_stats {
    double shadow_build_ms;      /* time of the last shadow build (0 if it was reused), as
                                    shadow_build_timing says */
    double render_ms;            /* time of the last render, as render_timing says */
    int shadow_rebuilt;          /* nonzero if the last render rebuilt the shadow structure */
    size_t shadow_memory_bytes;  /* device memory the shadow structure holds */
    uint32_t light_channels;     /* 1 or 3: light channels the technique simulates */
    uint32_t slices;             /* convolution: slices in the last frame (each one kernel
                                    launch), else 0 */
    uint64_t samples;            /* view samples taken in the last render (skipped ones excluded) */
    umbra_timing shadow_build_timing; /* what shadow_build_ms measures */
    umbra_timing render_timing;  /* what render_ms measures */
    uint32_t map_size;           /* light-space techniques: texels per side of the map in use
                                    (the size UMBRA_MAP_SIZE_AUTO chose, or the one given);
                                    0 for the others. Fields are only ever appended here */
    int draft;                   /* nonzero if the last frame used its technique's draft
                                    (umbra_render_desc.interaction AUTO, the shadow inputs
                                    changed since the frame before): rendering again with
                                    nothing changed builds the full structure */
} umbra_render_stats;

/* Copies the last render's figures into *out. UMBRA_ERROR_INVALID_ARGUMENT for NULL r or out. */
UMBRA_API umbra_status umbra_renderer_get_stats(umbra_renderer r, umbra_render_stats *out);

/* Progress and cancellation of long calls. Called on the calling thread during
 * umbra_renderer_render, umbra_renderer_render_to_cl_buffer and umbra_renderer_query_shadow
 * (and the shadow build of an asynchronous frame), between pieces of device work (bands of the
 * image, the query points or the shadow map, groups of convolution slices), with the fraction
 * of the call's work done: in [0, 1], non-decreasing, and exactly 1 in the last call of a call
 * that succeeds. Pieces are sized to about 2^24 samples of the work's upper bound, shadow and
 * light rays included (a reference render marches a shadow ray from every view sample), but at
 * least four work-groups per compute unit on a CPU, so that reports come at most a fraction of a
 * second apart and a cancel takes effect within two pieces (measured: docs/performance.md,
 * "Progress and cancel that follow the work"). Return nonzero to cancel: the
 * call waits for the piece in flight, then returns UMBRA_ERROR_CANCELLED; the renderer stays
 * usable (the next render rebuilds what was cut short). The callback must not call this
 * renderer: any call on it from the callback (or from another thread meanwhile) is refused with
 * UMBRA_ERROR_INVALID_ARGUMENT naming the call in progress; releasing it is allowed, the render
 * finishes first. */
typedef int (*umbra_progress_callback)(void *user, float fraction);

/* Installs (or with NULL removes) the progress callback; user is passed to it (borrowed). With a
 * callback, long launches are split into bands, which changes no pixel. */
UMBRA_API umbra_status umbra_renderer_set_progress(umbra_renderer r, umbra_progress_callback cb,
                                                   void *user);

#ifdef __cplusplus
}
#endif
#endif
