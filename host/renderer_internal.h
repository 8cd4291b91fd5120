// SPDX-License-Identifier: Apache-2.0
/* host/renderer_internal.h: the renderer's state and the shadow-technique interface.
 *
 * A shadow technique is a descriptor (umbra__technique): its public description (name, doc,
 * flags, parameters with their defaults, ranges and docs, which the registry shows through
 * umbra/registry.h), the kernel files compiled into the ray caster for its per-sample lookup
 * (the kernel side of the interface is described in kernels/techniques/none.cl), and its host
 * functions. Each technique defines umbra__technique_<name> in host/techniques/<name>.c; the
 * registry (host/registry.c) lists them from umbra/techniques/list.h. docs/architecture.md says
 * how to add one. */
#ifndef UMBRA_RENDERER_INTERNAL_H
#define UMBRA_RENDERER_INTERNAL_H

#include <math.h>

#include "internal.h"
#include "common/umbra_shared.h"

_Static_assert(sizeof(UmbraChannels) == 4 * 16 + 4 * 16 + 16, "UmbraChannels layout");
_Static_assert(sizeof(UmbraFrame) == 14 * 16 + 2 * 16 + 4 * 12 + sizeof(UmbraChannels) + 4 * 16,
               "UmbraFrame layout");
_Static_assert(sizeof(UmbraClip) == 8 * 16 + 16, "UmbraClip layout");
_Static_assert(sizeof(UmbraShadow) == 6 * 16 + 4 * 4 + sizeof(UmbraClip), "UmbraShadow layout");

/* A parameter: what umbra/registry.h shows, and where its value lives in umbra_shadow_desc. */
typedef struct umbra__param {
    umbra_param_info info;
    size_t offset;
} umbra__param;

/* The most parameters a technique may have (the rebuild key holds them; the registry's tests
 * check every technique against it). */
#define UMBRA__MAX_PARAMS 24

/* umbra__param's type from the C field's: float, uint32_t or int (a flag). */
#define UMBRA__PARAM_TYPE(field)                                                               \
    _Generic((field), float: UMBRA_PARAM_FLOAT, uint32_t: UMBRA_PARAM_UINT, int: UMBRA_PARAM_BOOL)

/* A parameter row of technique member `tech` (its field `field`), the rest of its
 * umbra_param_info given as designated initializers: .doc, .default_value, .min, .max, ... The
 * type comes from the field, the name and key are the field's; UMBRA__PARAM_KEYED gives another
 * key (the flat name, unique among the technique's parameters). */
#define UMBRA__PARAM_KEYED(tech, field, key_, ...)                                             \
    {{.name = #field, .key = key_,                                                             \
      .type = UMBRA__PARAM_TYPE(((umbra_shadow_desc *)0)->tech.field), __VA_ARGS__},           \
     offsetof(umbra_shadow_desc, tech.field)}
#define UMBRA__PARAM(tech, field, ...) UMBRA__PARAM_KEYED(tech, field, #field, __VA_ARGS__)

/* A setting of a technique that `umbra-bench accuracy` sweeps (bench/accuracy.c). params is
 * "key=value;..." (the technique's keys, "auto" for a zero_name, and umbra_render_desc's
 * preintegrated), which the bench sets by name and writes as the setting's CSV field and image
 * name: a setting keeps its name across runs, so recorded results stay comparable. */
typedef struct umbra__setting {
    const char *params;
    const char *label; /* for people: "1024², 13 taps" */
    uint32_t flags;    /* UMBRA__SWEEP_* */
} umbra__setting;

#define UMBRA__SWEEP_QUICK 1u          /* in the quick sweep (--quick) */
#define UMBRA__SWEEP_FULL 2u           /* in the full sweep */
#define UMBRA__SWEEP_PAPERS_CSSM 4u    /* full sweep, scenes marked `papers cssm` only */
#define UMBRA__SWEEP_PAPERS_DEEP 8u    /* full sweep, scenes marked `papers deep` only */
#define UMBRA__SWEEP_HEADLINE 16u      /* the technique's row(s) of the full sweep's headline */
#define UMBRA__SWEEP_HEADLINE_QUICK 32u /* ... and of the quick sweep's */
#define UMBRA__SWEEP_BUILDS 64u        /* a variant of `umbra-bench builds` (bench/builds.c),
                                          named by its label: grey, and for a technique that is
                                          not grey-only also coloured ("-grey", "-colored") */

typedef struct umbra__technique {
    umbra_technique_info info;      /* first: umbra_technique_get returns &info */
    const umbra__param *params;     /* info.param_count of them */
    const umbra__setting *sweep;    /* the bench's settings, sweep_count of them */
    uint32_t sweep_count;
    /* The technique's kernel files (paths under kernels/, "techniques/cssm_shared.h",
     * "techniques/cssm.cl"), NULL-terminated, compiled after kernels/common/ and before
     * kernels/raycast.cl into the ray caster; NULL for a technique that renders the frame itself
     * (render != NULL). */
    const char *const *kernel_files;
    /* Step, in voxels, of the light pass: the light transfer function is corrected for it;
     * NULL with UMBRA_TECHNIQUE_NO_LIGHT. */
    float (*light_step)(const umbra_shadow_desc *desc);
    /* What its light rays are called in messages ("shadow" for the reference's); NULL: "light". */
    const char *ray_name;
    /* Checks that the parameter table cannot express (optional); the table's ranges are checked
     * before. */
    umbra_status (*validate)(umbra_renderer r, const umbra_shadow_desc *desc);
    /* (Re)builds the shadow structure for the renderer's current light inputs; adds device time
     * to *ms. Called only when an input in info.rebuilt_by or a parameter flagged
     * UMBRA_PARAM_REBUILDS changed since the last build (optional). */
    umbra_status (*build)(umbra_renderer r, double *ms);
    /* Sets the technique's extra kernel arguments (SHADOW_KERNEL_PARAMS), starting at index first
     * (optional). Called for every render and query: what it reads of r->shadow that is not
     * flagged UMBRA_PARAM_REBUILDS it must pass here, not at build. */
    umbra_status (*bind)(umbra_renderer r, cl_kernel k, cl_uint first);
    /* Renders the whole frame into out instead of the ray caster (optional). */
    umbra_status (*render)(umbra_renderer r, uint32_t width, uint32_t height, cl_mem out,
                           double *ms);
    /* Device bytes held by the shadow structure (optional: 0). */
    size_t (*memory)(umbra_renderer r);
    /* Frees r->tech_state (optional). */
    void (*destroy)(umbra_renderer r);
    /* What shared machinery needs of the technique (optional): a single-layer map's
     * umbra__map_kind (host/techniques/maps.h). */
    const void *data;
} umbra__technique;

/* What a shadow structure depends on; a change of any field means a rebuild. The fields of
 * inputs the technique's info.rebuilt_by leaves out stay zero, and params holds the values of
 * its parameters flagged UMBRA_PARAM_REBUILDS, in table order. */
typedef struct umbra__light_key {
    uint64_t volume_id, light_tf_id;
    umbra_light light;
    int transmission, skip_empty;
    int technique;
    double params[UMBRA__MAX_PARAMS];
    /* Appended for the clip region, multi-channel volumes and volume updates: the clip region
     * in the local frame (UMBRA_REBUILD_CLIP), the volume's voxel version and the light
     * transfer functions of channels 1.. (with UMBRA_REBUILD_VOLUME / _LIGHT_TF). */
    uint64_t volume_version;
    uint64_t channel_light_tf_id[UMBRA_MAX_CHANNELS];
    UmbraClip clip;
} umbra__light_key;

/* How often a renderer has made each of its caches (umbra__renderer_rebuilds, for the tests
 * that pin down what a change invalidates). */
typedef struct umbra__rebuilds {
    uint64_t tables;      /* step-corrected transfer-function tables uploaded (view or light) */
    uint64_t visibility;  /* brick and sub-cell visibility tables made (view or light) */
    uint64_t shadow;      /* shadow structures built */
    uint64_t effective;   /* transfer functions resampled onto a volume's range */
} umbra__rebuilds;

/* An asynchronous frame (umbra_renderer_render_to_cl_buffer_async), set on the renderer for the
 * duration of that call; NULL during the blocking calls. */
typedef struct umbra__async {
    cl_uint num_wait;
    const cl_event *wait_list;
    int gated;                               /* the wait list's barrier is enqueued */
    cl_event first, last;                    /* the frame's first and last kernels (retained by
                                                umbra__async_hold), or NULL */
} umbra__async;

struct umbra_renderer_t {
    atomic_int refs;
    umbra_context ctx;
    umbra_volume volume;
    umbra_transfer_function tf, light_tf;   /* light_tf NULL: the view tf */
    umbra_camera camera;
    int camera_set;
    umbra_light light;
    umbra_render_desc opts;
    umbra_shadow_desc shadow;                /* the description the shadow structure in use was
                                                built for: shadow_set, or its draft */
    umbra_shadow_desc shadow_set;            /* what the application set (set_shadow) */
    const umbra__technique *tech;
    void *tech_state;                        /* owned by the technique */

    UmbraFrame frame;                        /* host copy of the per-frame constants */
    UmbraShadow shadow_params;               /* host copy, filled by the renderer + technique */
    uint32_t channels;                       /* light channels simulated: 1 or 3 */

    /* device resources, re-created only when their inputs change */
    cl_mem frame_buf, shadow_buf, samples_buf;
    cl_mem view_tf_buf, light_tf_buf;        /* view: alpha step-corrected; light: as given,
                                                then its interval depth sums (renderer.c) */
    cl_mem view_bricks_buf;                  /* uchar per brick: nonzero if visible (view) */
    cl_mem view_cells_buf, light_cells_buf;  /* ulong per brick: its visible sub-cells; a brick
                                              * is visible if any of them is */
    uint64_t view_tf_key[8], light_tf_key[8];/* what they were made for (host/tables.c): each
                                                channel's tf id, the step, the kind of volume,
                                                its id and its ranges' version */
    umbra__light_key built;                  /* inputs of the current shadow structure */
    int built_valid;
    umbra__light_key last_key;               /* the full structure's inputs at the last frame
                                                (progressive shadows: did they change?) */
    int last_valid;
    cl_mem out_buf;
    size_t out_bytes;
    cl_program program;                      /* the ray caster + technique program in use */
    cl_kernel render_kernel, query_kernel;
    /* The shading gradient volume (kernels/common/sampling.cl, gradient_volume_entry) and its
     * build kernel, from the ray caster's program: made for shaded frames of a plain whole
     * volume in one buffer (host/gradient_volume.c), for the volume id, version and
     * program in grad_key; released for a frame without shading. */
    cl_kernel grad_kernel;
    cl_mem grad_buf;
    uint64_t grad_key[3];
    size_t render_local[2]; /* raycast_render's work-group (umbra__raycast_kernels) */
    struct umbra__preint *preint;            /* pre-integrated ray casting's table, or NULL */
    /* The view and light transfer functions as the volume's normalised range sees them
     * (umbra__tf_for_volume: the set ones, or resampled from their data range), and the
     * (tf id, volume id) each was made for. Every technique reads these. */
    umbra_transfer_function view_eff, light_eff;
    uint64_t view_eff_key[2], light_eff_key[2];
    /* Channels 1.. of a multi-channel volume (umbra_renderer_set_channel_transfer_function; 0
     * is tf and light_tf above): their transfer functions (light NULL: the view one) and those
     * in effect over their channel's range (host/channels.c). */
    umbra_transfer_function ch_tf[UMBRA_MAX_CHANNELS], ch_light_tf[UMBRA_MAX_CHANNELS];
    umbra_transfer_function ch_view_eff[UMBRA_MAX_CHANNELS], ch_light_eff[UMBRA_MAX_CHANNELS];
    uint64_t ch_view_eff_key[UMBRA_MAX_CHANNELS][2], ch_light_eff_key[UMBRA_MAX_CHANNELS][2];
    umbra_clip_desc clip;                    /* umbra_renderer_set_clip's, as given */
    /* The projection modes' program, kernel and uncorrected view tables (host/projection.c). */
    cl_program projection_program;
    cl_kernel projection_kernel;
    cl_mem projection_tf;
    uint64_t projection_key[UMBRA_MAX_CHANNELS];
    umbra__rebuilds rebuilds;

    umbra_render_stats stats;
    umbra__async *async;                     /* the asynchronous frame in progress, or NULL */
    int part_call;                           /* umbra_renderer_render_part is rendering */
    int part_front;                          /* ... going on from the front state in out_buf */
    /* A part's light exchange (host/part_light.c): the march state imported (host, NULL: none
     * yet), its device copy the build reads and writes, and the shadow build count at the last
     * import of depths. */
    float *part_state_in;
    size_t part_state_floats;
    cl_mem part_state_buf;
    uint64_t part_depths_at;
    int part_depths_valid;
    cl_event async_first, async_last;        /* the last asynchronous frame's first and last
                                                kernels (retained) until the next frame: its
                                                device time for umbra_renderer_get_stats */
    umbra_progress_callback progress;        /* optional: umbra_renderer_set_progress */
    void *progress_user;
    double progress_lo, progress_hi;         /* the current phase's share of the call */
    double progress_last;                    /* last fraction reported (kept non-decreasing) */
    double band_samples;                     /* test knob: samples per band, 0: the default */
    /* The render or query call in progress (umbra__call_begin): its name and thread. Any call
     * on the renderer meanwhile, from its progress callback or another thread, is refused. */
    atomic_int busy;
    const char *busy_fn;
    pthread_t busy_thread;
};

/* Samples per band of a banded launch (umbra__run_2d, umbra__band_plan), by the caller's
 * estimate of the samples a work-item marches; bands hold four work-groups per compute unit on
 * a CPU, one per unit and at least UMBRA__BAND_MIN_ITEMS work-items on a GPU, so that the
 * device stays busy. */
#define UMBRA__BAND_SAMPLES 16777216.0
#define UMBRA__BAND_MIN_ITEMS 16384.0

/* An upper bound on the samples one ray with the given step (in voxels) takes in the volume's
 * box: its diagonal over the step. */
double umbra__ray_samples(umbra_renderer r, float step_voxels);

/* A call's work is split into phases (the shadow build, then the frame), each a share [lo, hi]
 * of the fraction reported: begin starts a call at 0 with the phase [0, 1]; end makes the last
 * report of a call that succeeded exactly 1 (a request to stop then comes too late to matter). */
void umbra__progress_begin(umbra_renderer r);
void umbra__progress_phase(umbra_renderer r, double lo, double hi);
void umbra__progress_end(umbra_renderer r);

/* Reports that fraction (0..1) of the current phase is done to the progress callback, if any.
 * Returns UMBRA_ERROR_CANCELLED (recorded with fn's name) if the callback asks to stop. */
umbra_status umbra__progress(umbra_renderer r, double fraction, const char *fn);

/* Runs a 2D kernel over global[0] x global[1] work-items (rounded up to local, NULL: 8 x 8) and
 * waits, adding its device time to *ms. With a progress callback the range is split into bands
 * (umbra__band_plan), each one launch with a global offset, one band in flight while the
 * previous one is waited for and reported; the callback can cancel between bands. cost is an
 * upper bound on the samples one work-item marches (shadow and light rays included). The
 * kernel must index by global id. */
umbra_status umbra__run_2d(umbra_renderer r, cl_kernel k, const size_t global[2],
                           const size_t *local, double cost, double *ms, const char *fn);

/* The band umbra__run_2d launches at a time, in work-items along x and y (tile; the whole
 * rounded-up range without a progress callback): whole rows of work-groups of about
 * UMBRA__BAND_SAMPLES samples (or r->band_samples) at cost samples per work-item, or, where one
 * row of work-groups holds more, one row of them and as many columns as the budget allows; at
 * least the work-groups host/progress.c's band_groups asks for, except under the knob. */
void umbra__band_plan(umbra_renderer r, const size_t global[2], const size_t local[2],
                      double cost, size_t tile[2]);

/* With a progress callback on a CPU device (or under the knob), halves the work-group local
 * (x or y, the longer first) while a band of the fewest work-groups (band_groups) would hold
 * more than a band's samples at cost samples per work-item: a reference render at a fine shadow step
 * marches millions of samples per pixel. For kernels that index by global id only and use no
 * local memory (the ray caster): the image does not change. */
void umbra__band_local(umbra_renderer r, double cost, size_t local[2]);

/* An upper bound on the samples one ray cast by the renderer's kernel marches per pixel or
 * point: the view samples, each with its shadow ray for the reference technique (view 0: a
 * shadow query, the shadow ray alone). */
double umbra__march_cost(umbra_renderer r, int view);

/* The view transfer function in effect, over the volume's normalised range (valid once a render
 * or query has begun). */
umbra_transfer_function umbra__view_tf(umbra_renderer r);
/* The light transfer function in effect (the view one unless a light one was set), likewise. */
umbra_transfer_function umbra__light_tf(umbra_renderer r);

/* Brings r->view_eff and r->light_eff up to date with the transfer functions and volume set
 * (host/world.c). */
umbra_status umbra__effective_tfs(umbra_renderer r);

/* The ground plane (n.p + w = 0 in v's local frame) horizontal in v's world, gap world units below
 * the box's lowest corner; ext is the box size. */
void umbra__ground_plane(umbra_volume v, const float ext[3], float gap, float plane[4]);

/* World units of one voxel step (the smallest spacing). */
float umbra__voxel_world(umbra_renderer r);

/* Fills r->frame's volume and light fields from the current state (the camera part is filled at
 * render time). Techniques may rely on it during build. */
void umbra__frame_update_light(umbra_renderer r);

/* Nonzero when every channel's light transfer function in effect is grey (host/channels.c). */
int umbra__light_tfs_grey(umbra_renderer r);

/* Refuses, naming fn, what the frame cannot render with the renderer's volume, mode and
 * technique: a channel without a transfer function, a projection mode with a shadow technique
 * or a label map, a multi-channel volume or label map with a technique without
 * UMBRA_TECHNIQUE_CHANNELS or with pre-integration (host/channels.c). */
umbra_status umbra__check_kind(umbra_renderer r, const char *fn);

/* The projection modes (host/projection.c): the kernel for r->opts.mode with every argument
 * set for a frame into out, and the work-group it runs in; _release frees what they keep. */
umbra_status umbra__projection_kernel(umbra_renderer r, cl_mem out, cl_kernel *k,
                                      size_t local[2]);
void umbra__projection_release(umbra_renderer r);

/* The ray caster's work-group for kernel k: 32 x 8 where the kernel and device allow 256, else
 * 8 x 8 (host/renderer.c). */
void umbra__choose_local(umbra_renderer r, cl_kernel k, size_t local[2]);

/* Refuses a call named fn on a renderer without a volume and a transfer function, or whose
 * technique cannot render the volume's kind (host/renderer.c). */
umbra_status umbra__check_ready(umbra_renderer r, const char *fn);

/* The ray caster's program for the current technique and options, and its kernels
 * (r->render_kernel, query_kernel, grad_kernel), made again when the program changes
 * (host/renderer.c). */
umbra_status umbra__raycast_kernels(umbra_renderer r);

/* r->shadow_params.clip from the clip region set and the volume's placement (host/clip.c);
 * called by umbra__frame_update_light. */
void umbra__clip_update(umbra_renderer r);

/* Makes sure r->light_tf_buf holds the light table (alphas as given: the kernels correct per
 * sample, kernels/common/common.cl) and r->light_cells_buf the visibility of each brick's sub-cells
 * under it. */
umbra_status umbra__light_tables(umbra_renderer r);

/* ---- shared between host/renderer.c, tables.c, frame.c and render_cl.c ---------------------- */

/* Every public renderer call starts with this: a NULL renderer has no context to record on; a
 * renderer in the middle of a render or query (called from its progress callback, or from
 * another thread) is refused. */
#define CHECK_R(fn)                                                                            \
    if (!r)                                                                                    \
        return UMBRA_ERROR_INVALID_ARGUMENT;                                                   \
    if (atomic_load(&r->busy))                                                                 \
        return umbra__renderer_busy(r, __func__);

/* UMBRA_ERROR_INVALID_ARGUMENT for fn called on r while r->busy_fn runs, naming both and the
 * rule broken. */
umbra_status umbra__renderer_busy(umbra_renderer r, const char *fn);

/* Starts a render or query call named fn (after CHECK_R): refuses a forked child
 * (umbra__check_process), marks r busy and holds a reference, so that the progress callback
 * releasing r cannot free it under the call. umbra__call_end undoes both; r may be gone after
 * it. */
umbra_status umbra__call_begin(umbra_renderer r, const char *fn);
void umbra__call_end(umbra_renderer r);

/* Small vector helpers (lengths in double, so 1e20 does not overflow a float square). */
static inline double umbra__len3d(const float v[3])
{
    return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
}

static inline void umbra__normalize3(float v[3])
{
    double l = umbra__len3d(v);
    if (l > 0.0)
        for (int i = 0; i < 3; ++i)
            v[i] = (float)(v[i] / l);
}

static inline void umbra__cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Releases *m if set and clears it. */
static inline void umbra__release_mem(cl_mem *m)
{
    if (*m)
        clReleaseMemObject(*m);
    *m = NULL;
}

/* The table of tfs (one per channel of the volume) for step_voxels (0: the light's,
 * uncorrected) into *tf_buf, and, where the buffers are given, the bricks and sub-cells they make
 * visible; the table is remade only when the transfer functions or the step change, the
 * visibility also when the volume or its ranges do (key; host/tables.c). Sets the parts of the
 * frame's UmbraChannels the table's channels take. */
umbra_status umbra__tables(umbra_renderer r, const umbra_transfer_function *tfs,
                           float step_voxels, uint64_t key[8], cl_mem *tf_buf,
                           cl_mem *bricks_buf, cl_mem *cells_buf);

/* The view (light 0) or light transfer functions in effect, one per channel of the volume. */
void umbra__channel_tfs(umbra_renderer r, int light, umbra_transfer_function *out);

/* The part fields of r->frame (host/part_render.c): zero for a whole volume; for a part its
 * shift, carried dims and owned box, and with view set no background and no empty-space skipping
 * (a partial image is composited before the background; skipping changes no pixel). */
void umbra__part_frame(umbra_renderer r, int view);

/* Binds a part's march state (n^2 texels) as argument index of a map's build kernel, uploading
 * the imported state (or the light's: transmittance 1) first (host/part_light.c). */
umbra_status umbra__part_bind_build(umbra_renderer r, cl_kernel k, cl_uint index, uint32_t n);

/* Light tables and the shadow structure, rebuilt only when the light key changed
 * (host/renderer.c). frame: a render (progressive shadows apply), not a query. */
umbra_status umbra__prepare_shadow(umbra_renderer r, double build_share, int frame);

/* The view part of the frame constants for a width x height image (host/frame.c). */
void umbra__frame_update_view(umbra_renderer r, uint32_t width, uint32_t height);

/* Makes *buf a buffer of at least bytes (reallocated when smaller). */
umbra_status umbra__ensure_buffer(umbra_renderer r, cl_mem *buf, size_t bytes,
                                  cl_mem_flags flags);

/* Renders the frame into out (host/renderer.c): blocking frames wait for it; asynchronous ones
 * (r->async) only enqueue it, gated on their wait list. */
umbra_status umbra__render_into(umbra_renderer r, uint32_t width, uint32_t height, cl_mem out);

/* Refuses a zero or oversized image, naming fn. */
umbra_status umbra__check_size(umbra_renderer r, uint32_t width, uint32_t height, const char *fn);

/* Marks the point in a frame after which commands must wait for an asynchronous frame's wait
 * list (a no-op for blocking frames): the renderer or technique calls it once, after everything
 * that waits on the host (builds, blocking reads) and before the first command that writes the
 * output. Enqueues a barrier on the wait list; the in-order queue holds everything after it. */
umbra_status umbra__frame_gate(umbra_renderer r);

/* Every command an asynchronous frame enqueues after its gate passes its event here (a no-op
 * for blocking frames; the caller keeps its own reference). PoCL 3.1 aborts the process
 * (pocl_update_event_failed) when the failure of a wait-list event reaches a command whose
 * event nobody holds, as happens to commands enqueued without an event: each is held until it
 * completes (a callback then releases it). PoCL calls no callback for an event that ends in an
 * error, so the events of a failed frame are kept, a few hundred bytes. kernel: the command is
 * one of the frame's kernels (the first starts the frame's device time, the last is *done). */
umbra_status umbra__async_hold(umbra_renderer r, cl_event e, int kernel);

/* Copies r->frame and r->shadow_params into fresh device buffers (r->frame_buf, r->shadow_buf):
 * nothing waits on the queue, and commands already enqueued keep the constants they were
 * enqueued with. */
umbra_status umbra__upload_params(umbra_renderer r);

/* The OpenCL build options every program of this renderer uses: the sampler and the number of
 * light channels. */
void umbra__build_options(umbra_renderer r, char *buf, size_t size);

/* Sets the arguments the ray caster and every light-space kernel share, in this order:
 * frame, volume, view tf, light tf, view bricks, light bricks, shadow params. Returns the next
 * free index through *next. */
umbra_status umbra__bind_common(umbra_renderer r, cl_kernel k, cl_uint *next);

/* ---- the registry (host/registry.c) ------------------------------------------------------- */

/* The descriptor with that id, or NULL. */
const umbra__technique *umbra__technique_by_id(umbra_shadow_technique id);

/* The technique's own kernel files (t->kernel_files) inserted into a program's file list: the
 * common files first, then the technique's, then those of `after` (NULL-terminated; may be NULL);
 * writes at most max (the caller's array) and returns how many the lists hold: a count above max
 * (which umbra__program_get refuses before it reads a file) says the array was too small. */
size_t umbra__program_files(const umbra__technique *t, const char *const *common, size_t ncommon,
                            const char *const *after, const char **files, size_t max);

/* Refuses, naming fn, a desc whose parameters of technique t (and the shared map's, for a map)
 * lie outside their ranges; then t's own validate. */
umbra_status umbra__validate_shadow(umbra_renderer r, const umbra__technique *t,
                                    const umbra_shadow_desc *d, const char *fn);

/* Fills key with what technique t's structure depends on (info.rebuilt_by and its parameters
 * flagged UMBRA_PARAM_REBUILDS, as desc sets them). */
void umbra__light_key_fill(umbra_renderer r, const umbra__technique *t,
                           const umbra_shadow_desc *desc, umbra__light_key *key);

/* Technique t's draft of desc (t->info.draft applied, umbra/registry.h) into *out; returns 0,
 * with *out = *desc, where t has no draft or its draft string does not apply (the registry's
 * tests check every technique's). */
int umbra__draft_desc(const umbra__technique *t, const umbra_shadow_desc *desc,
                      umbra_shadow_desc *out);

/* Converts a desc of an older layout (struct_size tells which) into *out, or refuses it naming
 * fn; *preintegrated is set to the 0.4 layout's preintegrated (-1 for a newer layout, which has
 * none). host/shadow_desc_compat.c. */
umbra_status umbra__shadow_desc_upgrade(umbra_renderer r, const umbra_shadow_desc *d,
                                        umbra_shadow_desc *out, int *preintegrated,
                                        const char *fn);

/* Replaces *buf with a new read-only buffer holding bytes of data (a technique's kernel
 * constants): nothing waits on the queue, and commands already enqueued keep the buffer they
 * were enqueued with. */
umbra_status umbra__upload_constants(umbra_renderer r, const void *data, size_t bytes,
                                     cl_mem *buf);

#endif
