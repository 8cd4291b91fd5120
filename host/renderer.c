// SPDX-License-Identifier: Apache-2.0
/* host/renderer.c: the renderer front end: validated state, what each change invalidates, and
 * the frame loop (tables -> shadow structure -> ray caster or the technique's own renderer). The
 * techniques' descriptors, their parameters and the rebuild key come from host/registry.c.
 *
 * Nothing is rebuilt per frame unless its inputs changed: step-corrected transfer-function tables
 * and brick visibility are keyed by (table id, volume id, step); the shadow structure by the full
 * light key (umbra__light_key); programs by their sources and options (context cache). The
 * tables live in host/tables.c, the frame constants in host/frame.c, rendering into the
 * application's cl_mem in host/render_cl.c, progress and banded launches in host/progress.c, the
 * gradient volume in host/gradient_volume.c, umbra_renderer_query_shadow in host/query_shadow.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gradient_volume.h"
#include "preintegration.h"
#include "renderer_internal.h"

/* ---- defaults ---------------------------------------------------------------------------------- */

/* umbra 0.5.0's umbra_render_desc ended with preintegrated: its size, padding included. */
#define RENDER_DESC_SIZE_0_5                                                                   \
    ((offsetof(umbra_render_desc, preintegrated) + sizeof(int) + _Alignof(umbra_render_desc) -  \
      1) / _Alignof(umbra_render_desc) * _Alignof(umbra_render_desc))
_Static_assert(sizeof(umbra_render_desc) != RENDER_DESC_SIZE_0_5,
               "this layout and umbra 0.5.0's must differ in size");

void umbra_render_desc_init(umbra_render_desc *d)
{
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->struct_size = sizeof *d;
    d->step = 0.5f;
    d->termination = 0.99f;
    d->empty_space_skipping = 1;
    d->kd = 0.8f;
    d->ks = 0.3f;
    d->shininess = 32.0f;
    d->ambient[0] = d->ambient[1] = d->ambient[2] = 0.2f;
    d->ground_color[0] = d->ground_color[1] = d->ground_color[2] = 0.8f;
    d->ground_offset = 0.02f;
    d->transmission = UMBRA_TRANSMISSION_GREY;
}

/* ---- lifetime ------------------------------------------------------------------------------------ */

umbra_status umbra_renderer_create(umbra_context ctx, umbra_renderer *out)
{
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_renderer_create: out is NULL");
    *out = NULL;
    if (!ctx)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    umbra_renderer r = calloc(1, sizeof *r);
    if (!r)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "umbra_renderer_create: out of memory");
    atomic_init(&r->refs, 1);
    r->ctx = ctx;
    umbra_context_retain(ctx);
    umbra_render_desc_init(&r->opts);
    umbra_shadow_desc_init(&r->shadow);
    r->shadow_set = r->shadow;
    r->tech = umbra__technique_by_id(UMBRA_SHADOW_NONE);
    r->light.type = UMBRA_LIGHT_DIRECTIONAL;
    r->light.direction[0] = -0.5f;
    r->light.direction[1] = -1.0f;
    r->light.direction[2] = -0.3f;
    r->light.color[0] = r->light.color[1] = r->light.color[2] = 1.0f;
    *out = r;
    return UMBRA_SUCCESS;
}

void umbra_renderer_retain(umbra_renderer r)
{
    if (r)
        atomic_fetch_add(&r->refs, 1);
}

static void release_kernels(umbra_renderer r)
{
    if (r->render_kernel)
        clReleaseKernel(r->render_kernel);
    if (r->query_kernel)
        clReleaseKernel(r->query_kernel);
    if (r->grad_kernel)
        clReleaseKernel(r->grad_kernel);
    r->render_kernel = r->query_kernel = r->grad_kernel = NULL;
    r->program = NULL; /* owned by the context's cache */
}

/* The last asynchronous frame's kernels, kept for its stats until the next frame. */
static void drop_async_events(umbra_renderer r)
{
    if (r->async_first)
        clReleaseEvent(r->async_first);
    if (r->async_last)
        clReleaseEvent(r->async_last);
    r->async_first = r->async_last = NULL;
}

static void drop_technique(umbra_renderer r)
{
    if (r->tech && r->tech->destroy)
        r->tech->destroy(r);
    r->tech_state = NULL;
    r->built_valid = 0;
}

umbra_status umbra__renderer_busy(umbra_renderer r, const char *fn)
{
    if (pthread_equal(r->busy_thread, pthread_self()))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: renderer %p is in the middle of %s on this thread: a progress "
                           "callback must not call the renderer it reports on", fn, (void *)r,
                           r->busy_fn);
    return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                       "%s: renderer %p is in the middle of %s on another thread: a renderer is "
                       "used by one thread at a time", fn, (void *)r, r->busy_fn);
}

umbra_status umbra__call_begin(umbra_renderer r, const char *fn)
{
    umbra_status st = umbra__check_process(r->ctx, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    r->busy_fn = fn;
    r->busy_thread = pthread_self();
    atomic_store(&r->busy, 1);
    atomic_fetch_add(&r->refs, 1);
    return UMBRA_SUCCESS;
}

void umbra__call_end(umbra_renderer r)
{
    atomic_store(&r->busy, 0);
    umbra_renderer_release(r);
}

void umbra_renderer_release(umbra_renderer r)
{
    if (!r || atomic_fetch_sub(&r->refs, 1) > 1 || umbra__forked(r->ctx))
        return;
    drop_technique(r);
    release_kernels(r);
    drop_async_events(r);
    umbra__preint_release(r->preint);
    cl_mem *mems[] = {&r->frame_buf, &r->shadow_buf, &r->samples_buf, &r->view_tf_buf,
                      &r->light_tf_buf, &r->view_bricks_buf, &r->light_cells_buf, &r->view_cells_buf,
                      &r->out_buf, &r->part_state_buf, &r->grad_buf};
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; ++i)
        umbra__release_mem(mems[i]);
    umbra_volume_release(r->volume);
    umbra_transfer_function_release(r->tf);
    umbra_transfer_function_release(r->light_tf);
    umbra_transfer_function_release(r->view_eff);
    umbra_transfer_function_release(r->light_eff);
    for (int c = 0; c < UMBRA_MAX_CHANNELS; ++c) {
        umbra_transfer_function_release(r->ch_tf[c]);
        umbra_transfer_function_release(r->ch_light_tf[c]);
        umbra_transfer_function_release(r->ch_view_eff[c]);
        umbra_transfer_function_release(r->ch_light_eff[c]);
    }
    umbra__projection_release(r);
    free(r->part_state_in);
    umbra_context_release(r->ctx);
    free(r);
}

/* ---- setters ------------------------------------------------------------------------------------- */

umbra_status umbra_renderer_set_volume(umbra_renderer r, umbra_volume volume)
{
    CHECK_R();
    if (!volume)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_set_volume: volume is NULL");
    if (volume->ctx != r->ctx)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_set_volume: volume belongs to another context");
    umbra_volume_retain(volume);
    umbra_volume_release(r->volume);
    r->volume = volume;
    return UMBRA_SUCCESS;
}

static umbra_status set_tf(umbra_renderer r, umbra_transfer_function tf,
                           umbra_transfer_function *slot, const char *fn, int allow_null)
{
    if (!tf && !allow_null)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: tf is NULL", fn);
    if (tf && tf->ctx != r->ctx)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: tf belongs to another context", fn);
    umbra_transfer_function_retain(tf);
    umbra_transfer_function_release(*slot);
    *slot = tf;
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_set_transfer_function(umbra_renderer r, umbra_transfer_function tf)
{
    CHECK_R();
    return set_tf(r, tf, &r->tf, "umbra_renderer_set_transfer_function", 0);
}

umbra_status umbra_renderer_set_light_transfer_function(umbra_renderer r,
                                                        umbra_transfer_function tf)
{
    CHECK_R();
    return set_tf(r, tf, &r->light_tf, "umbra_renderer_set_light_transfer_function", 1);
}

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* Finite and within UMBRA_MAX_COORDINATE, so that differences and squared lengths of points
 * stay finite in the kernels' float arithmetic. */
static int coordinate3(const float v[3])
{
    for (int i = 0; i < 3; ++i)
        if (!(fabsf(v[i]) <= UMBRA_MAX_COORDINATE))
            return 0;
    return 1;
}

umbra_status umbra_renderer_set_camera(umbra_renderer r, const umbra_camera *c)
{
    const char *fn = "umbra_renderer_set_camera";
    CHECK_R();
    if (!c)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: camera is NULL", fn);
    if (!coordinate3(c->eye) || !coordinate3(c->target) || !finite3(c->up))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: eye (%g, %g, %g) and target (%g, %g, %g) must be finite and within "
                           "+-%g, up (%g, %g, %g) finite", fn, c->eye[0], c->eye[1], c->eye[2],
                           c->target[0], c->target[1], c->target[2], UMBRA_MAX_COORDINATE,
                           c->up[0], c->up[1], c->up[2]);
    /* In double: products of large finite floats overflow a float. */
    double f[3], side[3], u[3] = {c->up[0], c->up[1], c->up[2]};
    for (int i = 0; i < 3; ++i)
        f[i] = (double)c->target[i] - c->eye[i];
    side[0] = f[1] * u[2] - f[2] * u[1];
    side[1] = f[2] * u[0] - f[0] * u[2];
    side[2] = f[0] * u[1] - f[1] * u[0];
    double lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    double ls = sqrt(side[0] * side[0] + side[1] * side[1] + side[2] * side[2]);
    if (!(lf > 0.0) || !(ls > 1e-6 * lf * lu))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: eye (%g, %g, %g) and target (%g, %g, %g) must differ and up "
                           "(%g, %g, %g) must not be parallel to the view direction", fn,
                           c->eye[0], c->eye[1], c->eye[2], c->target[0], c->target[1],
                           c->target[2], c->up[0], c->up[1], c->up[2]);
    if (c->projection == UMBRA_PERSPECTIVE) {
        if (!(c->fovy_degrees > 0.0f && c->fovy_degrees < 180.0f))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: fovy_degrees %g must lie in (0, 180)", fn, c->fovy_degrees);
    } else if (c->projection == UMBRA_ORTHOGRAPHIC) {
        if (!(c->ortho_height > 0.0f) || !isfinite(c->ortho_height))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ortho_height %g must be finite and > 0", fn, c->ortho_height);
    } else {
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: projection %d is unknown",
                           fn, (int)c->projection);
    }
    r->camera = *c;
    /* Only up's direction matters; a unit up keeps the frame's cross products finite. */
    umbra__normalize3(r->camera.up);
    r->camera_set = 1;
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_set_light(umbra_renderer r, const umbra_light *l)
{
    const char *fn = "umbra_renderer_set_light";
    CHECK_R();
    if (!l)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: light is NULL", fn);
    if (l->type != UMBRA_LIGHT_POINT && l->type != UMBRA_LIGHT_DIRECTIONAL)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: light type %d is unknown",
                           fn, (int)l->type);
    if (!coordinate3(l->position) || !finite3(l->direction))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: position (%g, %g, %g) must be finite and within +-%g, direction "
                           "(%g, %g, %g) finite", fn, l->position[0], l->position[1],
                           l->position[2], UMBRA_MAX_COORDINATE, l->direction[0],
                           l->direction[1], l->direction[2]);
    if (l->type == UMBRA_LIGHT_DIRECTIONAL && !(umbra__len3d(l->direction) > 0.0))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: directional light direction (0, 0, 0) has no direction", fn);
    for (int i = 0; i < 3; ++i)
        if (!(l->color[i] >= 0.0f) || !isfinite(l->color[i]))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: color (%g, %g, %g) must be finite and >= 0", fn, l->color[0],
                               l->color[1], l->color[2]);
    r->light = *l;
    if (l->type == UMBRA_LIGHT_DIRECTIONAL)
        umbra__normalize3(r->light.direction);
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_set_options(umbra_renderer r, const umbra_render_desc *d)
{
    const char *fn = "umbra_renderer_set_options";
    CHECK_R();
    if (!d)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc is NULL", fn);
    /* umbra 0.4's layout ends before preintegrated, which such a caller sets through its shadow
     * description (umbra_renderer_set_shadow): it keeps its value. umbra 0.5.0's ends with
     * preintegrated: the fields after it (interaction) keep theirs. */
    const size_t size_0_4 = offsetof(umbra_render_desc, preintegrated);
    /* umbra 0.5's layout ends with preintegrated: its size with its padding, or without it
     * (offsetof mode). */
    const size_t size_0_5 = RENDER_DESC_SIZE_0_5, end_0_5 = offsetof(umbra_render_desc, mode);
    if (d->struct_size != sizeof *d && d->struct_size != size_0_5 && d->struct_size != end_0_5 &&
        d->struct_size != size_0_4)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: desc->struct_size %zu is none of %zu, umbra 0.5's %zu (%zu "
                           "without padding) and umbra 0.4's %zu: call umbra_render_desc_init",
                           fn, d->struct_size, sizeof *d, size_0_5, end_0_5, size_0_4);
    if (d->struct_size == sizeof *d && (unsigned)d->mode > UMBRA_RENDER_AVERAGE)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: mode %d is unknown (0 composite, 1 mip, 2 minip, 3 average)", fn,
                           (int)d->mode);
    if (!(d->step >= 0.01f && d->step <= 64.0f))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: step %g voxels must lie in [0.01, 64]", fn, d->step);
    if (!(d->termination > 0.0f && d->termination <= 1.0f))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: termination %g must lie in (0, 1]", fn, d->termination);
    if (!(d->kd >= 0.0f) || !(d->ks >= 0.0f) || !(d->shininess > 0.0f) || !isfinite(d->kd) ||
        !isfinite(d->ks) || !isfinite(d->shininess))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: kd %g, ks %g must be >= 0 and shininess %g > 0", fn, d->kd, d->ks,
                           d->shininess);
    for (int i = 0; i < 3; ++i)
        if (!(d->ambient[i] >= 0.0f) || !isfinite(d->ambient[i]) || !(d->ground_color[i] >= 0.0f) ||
            !isfinite(d->ground_color[i]))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: ambient and ground_color must be finite and >= 0", fn);
    for (int i = 0; i < 4; ++i)
        if (!(d->background[i] >= 0.0f) || !isfinite(d->background[i]))
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: background channel %d is %g; must be finite and >= 0", fn, i,
                               d->background[i]);
    if (!isfinite(d->ground_offset))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ground_offset is %g", fn,
                           d->ground_offset);
    if (d->transmission != UMBRA_TRANSMISSION_GREY && d->transmission != UMBRA_TRANSMISSION_COLORED)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: transmission %d is unknown",
                           fn, (int)d->transmission);
    if (d->struct_size == sizeof *d && d->interaction != UMBRA_INTERACTION_OFF &&
        d->interaction != UMBRA_INTERACTION_AUTO)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: interaction %d is unknown (UMBRA_INTERACTION_OFF 0 or _AUTO 1)", fn,
                           (int)d->interaction);
    const int preintegrated = r->opts.preintegrated;
    const umbra_render_mode mode = r->opts.mode;
    const umbra_interaction interaction = r->opts.interaction;
    /* An older layout's bytes up to its last field, never its padding. */
    memcpy(&r->opts, d, d->struct_size == sizeof *d ? sizeof *d
                        : d->struct_size < end_0_5  ? d->struct_size
                                                    : end_0_5);
    r->opts.struct_size = sizeof r->opts;
    if (d->struct_size == size_0_4)
        r->opts.preintegrated = preintegrated;
    if (d->struct_size != sizeof *d) {
        r->opts.mode = mode;
        r->opts.interaction = interaction;
    }
    return UMBRA_SUCCESS;
}

umbra_status umbra_renderer_set_shadow(umbra_renderer r, const umbra_shadow_desc *desc)
{
    const char *fn = "umbra_renderer_set_shadow";
    CHECK_R();
    if (!desc)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: desc is NULL", fn);
    umbra_shadow_desc d;
    int preintegrated; /* umbra 0.4's layout carries it; -1 otherwise */
    umbra_status st = umbra__shadow_desc_upgrade(r, desc, &d, &preintegrated, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    const umbra__technique *t = umbra__technique_by_id(d.technique);
    if (!t)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: technique %d (unknown) is not in this build's registry", fn,
                           (int)d.technique);
    if ((st = umbra__validate_shadow(r, t, &d, fn)) != UMBRA_SUCCESS)
        return st;
    if (t != r->tech) {
        drop_technique(r);
        release_kernels(r);
        r->tech = t;
    }
    r->shadow = r->shadow_set = d;
    if (preintegrated >= 0)
        r->opts.preintegrated = preintegrated;
    return UMBRA_SUCCESS;
}

/* ---- the frame ---------------------------------------------------------------------------------------- */

umbra_status umbra__check_ready(umbra_renderer r, const char *fn)
{
    if (!r->volume || !r->tf)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: set a volume and a transfer function first (volume %p, tf %p)", fn,
                           (void *)r->volume, (void *)r->tf);
    return umbra__check_kind(r, fn);
}

/* Refuses a step that would take more than UMBRA_MAX_RAY_SAMPLES samples along the box's
 * diagonal (no ray through the box is longer; a shadow or light ray leaves it within that
 * length too), before any work, so that no input makes a ray loop run for minutes or its
 * sample count overflow the kernels' int. Computed in double: the volume's extent may be up to
 * UMBRA_MAX_EXTENT. */
double umbra__ray_samples(umbra_renderer r, float step_voxels)
{
    double diag = 0.0;
    for (int a = 0; a < 3; ++a) {
        double e = (double)r->volume->grid_dims[a] * r->volume->spacing[a];
        diag += e * e;
    }
    return sqrt(diag) / ((double)step_voxels * umbra__voxel_world(r));
}

double umbra__march_cost(umbra_renderer r, int view)
{
    /* The reference marches a shadow ray of up to the diagonal over its step from every view
     * sample or query point; a map's lookup costs about as much as a sample. */
    double shadow = 0.0;
    if ((r->tech->info.flags & UMBRA_TECHNIQUE_SHADOW_RAYS) && r->tech->light_step)
        shadow = umbra__ray_samples(r, r->tech->light_step(&r->shadow));
    return view ? umbra__ray_samples(r, r->opts.step) * (1.0 + shadow) : 1.0 + shadow;
}

static umbra_status check_ray_samples(umbra_renderer r, float step_voxels, const char *what,
                                      const char *fn)
{
    double n = umbra__ray_samples(r, step_voxels);
    double diag = n * step_voxels * umbra__voxel_world(r);
    if (!(n <= (double)UMBRA_MAX_RAY_SAMPLES))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: a %s ray would take up to %.4g samples (box diagonal %g world "
                           "units, step %g voxels of %g); the limit is %u (UMBRA_MAX_RAY_SAMPLES): "
                           "raise the step or resample the volume", fn, what, n, diag,
                           (double)step_voxels, (double)umbra__voxel_world(r),
                           UMBRA_MAX_RAY_SAMPLES);
    return UMBRA_SUCCESS;
}

/* The shadow description of this frame (frame) or query (!frame) into r->shadow: the
 * application's, or under UMBRA_INTERACTION_AUTO its technique's draft where the full
 * structure's inputs changed since the last frame (renderer.h). Returns whether it is a draft;
 * *key receives the full structure's inputs, or the draft's. */
static int choose_shadow(umbra_renderer r, int frame, umbra__light_key *key)
{
    const umbra__technique *t = r->tech;
    umbra__light_key full;
    r->shadow = r->shadow_set;
    umbra__light_key_fill(r, t, &r->shadow_set, &full);
    *key = full;
    if (!frame)
        return 0;
    const int changed = r->last_valid && memcmp(&full, &r->last_key, sizeof full) != 0;
    r->last_key = full;
    r->last_valid = 1;
    umbra_shadow_desc draft;
    /* umbra__draft_desc keeps every value it sets within its parameter's range. */
    if (!changed || r->opts.interaction != UMBRA_INTERACTION_AUTO ||
        !umbra__draft_desc(t, &r->shadow_set, &draft))
        return 0;
    umbra__light_key_fill(r, t, &draft, key);
    if (memcmp(key, &full, sizeof full) == 0)
        return 0; /* the draft changes nothing the structure depends on: it is the full one */
    r->shadow = draft;
    return 1;
}

/* Light tables and the shadow structure, rebuilt only when the light key changed. frame: a
 * render (progressive shadows apply), not a query. */
umbra_status umbra__prepare_shadow(umbra_renderer r, double build_share, int frame)
{
    umbra__frame_update_light(r);
    const umbra__technique *t = r->tech;
    umbra__light_key key;
    const int draft = choose_shadow(r, frame, &key);
    r->stats.draft = draft;
    float light_step = t->light_step ? t->light_step(&r->shadow) : 0.0f;
    umbra_status st = UMBRA_SUCCESS;
    if (t->light_step &&
        (st = check_ray_samples(r, light_step, t->ray_name ? t->ray_name : "light",
                                "umbra_renderer_render")) != UMBRA_SUCCESS)
        return st;
    st = umbra__light_tables(r);
    if (st != UMBRA_SUCCESS)
        return st;
    /* Every frame: a parameter that does not rebuild may set the step (the reference's). */
    r->shadow_params.step = light_step * umbra__voxel_world(r);
    r->stats.shadow_rebuilt = 0;
    r->stats.shadow_build_ms = 0.0;
    if (r->built_valid && memcmp(&key, &r->built, sizeof key) == 0)
        return UMBRA_SUCCESS;
    r->built_valid = 0;
    r->stats.map_size = 0; /* set by umbra__lightspace_setup, for the light-space techniques */
    umbra__progress_phase(r, 0.0, build_share);
    st = umbra__upload_params(r);
    if (st == UMBRA_SUCCESS && t->build)
        st = t->build(r, &r->stats.shadow_build_ms);
    if (st != UMBRA_SUCCESS)
        return st;
    r->built = key;
    r->built_valid = 1;
    r->stats.shadow_rebuilt = 1;
    r->rebuilds.shadow++;
    return UMBRA_SUCCESS;
}

/* The ray caster's work-group: 32 x 8 work-items where the kernel and device allow 256, else
 * 8 x 8. PoCL compiles a work-group function for each local size, and on this machine's CPU the
 * one for 64 work-items rendered the same frames 1.3x-1.9x slower than the one for 256 on the
 * walnut and the carp (16-bit) and the spheres (float; the time went into the kernel, not the
 * runtime), and as fast on the bonsai and the foot (8-bit) and the Marschner-Lobb volume
 * (float). The shape did not matter (32 x 8, 8 x 32 and 256 x 1 alike; 16 x 4 and 64 x 1 as
 * slow as 8 x 8). The shadow builds keep 8 x 8: with 256 work-items CSSM's blocks left too few
 * work-groups for two cores. Issue #12, docs/performance.md. */
void umbra__choose_local(umbra_renderer r, cl_kernel k, size_t local[2])
{
    size_t kernel_wg = 0, device_wg = 0, items[3] = {0, 0, 0};
    local[0] = local[1] = 8;
    if (clGetKernelWorkGroupInfo(k, r->ctx->device, CL_KERNEL_WORK_GROUP_SIZE,
                                 sizeof kernel_wg, &kernel_wg, NULL) != CL_SUCCESS ||
        clGetDeviceInfo(r->ctx->device, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof device_wg,
                        &device_wg, NULL) != CL_SUCCESS ||
        clGetDeviceInfo(r->ctx->device, CL_DEVICE_MAX_WORK_ITEM_SIZES, sizeof items, items,
                        NULL) != CL_SUCCESS)
        return; /* 8 x 8, as every kernel of the library may assume */
    if (kernel_wg >= 256 && device_wg >= 256 && items[0] >= 32 && items[1] >= 8)
        local[0] = 32;
}

umbra_status umbra__raycast_kernels(umbra_renderer r)
{
    char options[256];
    /* common/lightspace.cl: the map projection the light-space techniques' lookups need. */
    static const char *const common[] = {"common/common.cl", "common/sampling.cl",
                                         "common/channels.cl",
                                         "common/lightspace.cl", "common/preintegration.cl"};
    const char *files[16];
    static const char *const after[] = {"raycast.cl", NULL};
    const size_t nfiles = umbra__program_files(r->tech, common, 5, after, files, 16);
    cl_program program;
    umbra__build_options(r, options, sizeof options);
    umbra_status st = umbra__program_get(r->ctx, files, nfiles, options, &program);
    if (st != UMBRA_SUCCESS || program == r->program)
        return st;
    release_kernels(r);
    st = umbra__kernel_create(r->ctx, program, "raycast_render", &r->render_kernel);
    if (st == UMBRA_SUCCESS)
        st = umbra__kernel_create(r->ctx, program, "raycast_query_shadow", &r->query_kernel);
    if (st == UMBRA_SUCCESS)
        st = umbra__kernel_create(r->ctx, program, "raycast_gradient_volume", &r->grad_kernel);
    if (st != UMBRA_SUCCESS) {
        release_kernels(r);
        return st;
    }
    umbra__choose_local(r, r->render_kernel, r->render_local);
    r->program = program;
    return UMBRA_SUCCESS;
}

static umbra_timing measured_timing(umbra_renderer r)
{
    return r->ctx->profiling ? UMBRA_TIMING_DEVICE : UMBRA_TIMING_WALL;
}

/* Sets every argument of the ray caster for a frame into out. */
static umbra_status bind_raycast(umbra_renderer r, cl_mem out, const char *fn)
{
    umbra_context ctx = r->ctx;
    cl_uint next = 0;
    umbra_status st = umbra__bind_common(r, r->render_kernel, &next);
    if (st != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof(cl_mem), &out));
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof(cl_mem), &r->samples_buf));
    /* Pre-integrated ray casting (umbra_render_desc.preintegrated): the view table for the view
     * step; any buffer stands in for it when the mode is off (table size 0). */
    cl_mem preint = r->view_tf_buf;
    cl_uint preint_size = 0;
    if (r->opts.preintegrated) {
        st = umbra__preint_ensure(ctx, fn, &r->preint, umbra__view_tf(r), r->opts.step,
                                  UMBRA__PREINT_VIEW, 0, &preint, NULL);
        if (st != UMBRA_SUCCESS)
            return st;
        preint_size = UMBRA__PREINT_SIZE;
    }
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof(cl_mem), &preint));
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof preint_size, &preint_size));
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof(cl_mem), &r->view_cells_buf));
    cl_mem grad;
    cl_uint grad_on;
    if ((st = umbra__gradient_volume(r, &grad, &grad_on)) != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof(cl_mem), &grad));
    UMBRA_CL(clSetKernelArg(r->render_kernel, next++, sizeof grad_on, &grad_on));
    if (r->tech->bind)
        st = r->tech->bind(r, r->render_kernel, next);
fail:
    return st;
}

/* Renders the frame into out. Blocking frames wait for it; asynchronous ones (r->async) only
 * enqueue it, gated on their wait list. */
umbra_status umbra__render_into(umbra_renderer r, uint32_t width, uint32_t height, cl_mem out)
{
    const char *fn = "umbra_renderer_render";
    umbra_context ctx = r->ctx;
    umbra_status st = umbra__check_ready(r, fn);
    cl_event ev = NULL;
    if (st == UMBRA_SUCCESS && r->volume->is_part && !r->part_call)
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: the volume is a part of a global grid: render it with "
                           "umbra_renderer_render_part (umbra/part.h)", fn);
    if (st == UMBRA_SUCCESS)
        st = umbra__effective_tfs(r);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra__progress_begin(r);
    drop_async_events(r);
    /* The convolution technique's slices set its view sampling (bounded with its light step). */
    if (!r->tech->render && (st = check_ray_samples(r, r->opts.step, "view", fn)) != UMBRA_SUCCESS)
        return st;
    /* A shadow build, if one is needed, is the first half of the progress reported. */
    st = umbra__prepare_shadow(r, 0.5, 1);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra__progress_phase(r, r->progress_last, 1.0);
    umbra_transfer_function view_tfs[UMBRA_MAX_CHANNELS];
    umbra__channel_tfs(r, 0, view_tfs);
    st = umbra__tables(r, view_tfs, r->opts.step, r->view_tf_key, &r->view_tf_buf,
                       &r->view_bricks_buf, &r->view_cells_buf);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra__frame_update_view(r, width, height);
    r->stats.slices = 0;
    r->stats.render_timing = r->async ? UMBRA_TIMING_NONE : measured_timing(r);
    if (r->tech->render) {
        st = umbra__upload_params(r);
        if (st == UMBRA_SUCCESS)
            st = r->tech->render(r, width, height, out, &r->stats.render_ms);
        r->stats.samples = 0;
        return st;
    }
    const int composite = r->opts.mode == UMBRA_RENDER_COMPOSITE;
    st = composite ? umbra__raycast_kernels(r) : UMBRA_SUCCESS;
    if (st == UMBRA_SUCCESS)
        st = umbra__ensure_buffer(r, &r->samples_buf, UMBRA_COUNT_LANES * UMBRA_COUNT_LANE_BYTES,
                                  CL_MEM_READ_WRITE);
    if (st == UMBRA_SUCCESS)
        st = umbra__upload_params(r);
    if (st != UMBRA_SUCCESS)
        return st;
    cl_ulong zero = 0;
    /* The kernel of the frame: the ray caster, or a projection mode's (host/projection.c). */
    cl_kernel kernel = r->render_kernel;
    size_t local[2] = {r->render_local[0], r->render_local[1]};
    if (!composite && (st = umbra__projection_kernel(r, out, &kernel, local)) != UMBRA_SUCCESS)
        return st;
    if (composite && (st = bind_raycast(r, out, fn)) != UMBRA_SUCCESS)
        goto fail;
    size_t global[2] = {width, height};
    if ((st = umbra__frame_gate(r)) != UMBRA_SUCCESS)
        goto fail;
    /* A fill copies its pattern at the call: nothing points into this stack frame later. */
    UMBRA_CL(clEnqueueFillBuffer(ctx->queue, r->samples_buf, &zero, sizeof zero, 0,
                                 UMBRA_COUNT_LANES * UMBRA_COUNT_LANE_BYTES, 0, NULL, &ev));
    st = umbra__async_hold(r, ev, 0);
    clReleaseEvent(ev);
    ev = NULL;
    if (st != UMBRA_SUCCESS)
        goto fail;
    if (r->async) {
        /* An asynchronous frame is one launch, not waited for: no bands, no progress. */
        r->stats.render_ms = 0.0;
        r->stats.samples = 0;
        if ((st = umbra__enqueue(ctx, kernel, 2, global, local, &ev)) == UMBRA_SUCCESS)
            st = umbra__async_hold(r, ev, 1);
        goto fail; /* done or failed: the caller hands out the frame's last kernel */
    }
    double ms = 0.0;
    const double cost = umbra__march_cost(r, 1);
    umbra__band_local(r, cost, local);
    st = umbra__run_2d(r, kernel, global, local, cost, &ms, fn);
    if (st != UMBRA_SUCCESS)
        goto fail;
    r->stats.render_ms = ms;
    cl_ulong lanes[UMBRA_COUNT_LANES * UMBRA_COUNT_LANE_BYTES / sizeof(cl_ulong)];
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, r->samples_buf, CL_TRUE, 0, sizeof lanes, lanes, 0,
                                 NULL, NULL));
    /* Devices without 64-bit atomics count in the low 32 bits of each lane only. */
    cl_ulong samples = 0;
    for (size_t i = 0; i < UMBRA_COUNT_LANES; ++i)
        samples += lanes[i * (UMBRA_COUNT_LANE_BYTES / sizeof(cl_ulong))];
    r->stats.samples = samples;
fail:
    if (ev)
        clReleaseEvent(ev);
    return st;
}

umbra_status umbra__check_size(umbra_renderer r, uint32_t width, uint32_t height, const char *fn)
{
    if (width == 0 || height == 0 || width > 16384 || height > 16384)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: size %u x %u must lie in [1, 16384] per side", fn, width, height);
    return UMBRA_SUCCESS;
}

static umbra_status render_host(umbra_renderer r, uint32_t width, uint32_t height, float *rgba)
{
    const char *fn = "umbra_renderer_render";
    umbra_context ctx = r->ctx;
    if (!rgba)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: rgba is NULL", fn);
    umbra_status st = umbra__check_size(r, width, height, fn);
    if (st != UMBRA_SUCCESS)
        return st;
    size_t bytes = (size_t)width * height * 4 * sizeof(float);
    if (r->out_bytes != bytes)
        umbra__release_mem(&r->out_buf);
    st = umbra__ensure_buffer(r, &r->out_buf, bytes, CL_MEM_WRITE_ONLY);
    if (st != UMBRA_SUCCESS)
        return st;
    r->out_bytes = bytes;
    st = umbra__render_into(r, width, height, r->out_buf);
    if (st != UMBRA_SUCCESS)
        return st;
    UMBRA_CL(clEnqueueReadBuffer(ctx->queue, r->out_buf, CL_TRUE, 0, bytes, rgba, 0, NULL, NULL));
    umbra__progress_end(r);
fail:
    return st;
}

umbra_status umbra_renderer_render(umbra_renderer r, uint32_t width, uint32_t height, float *rgba)
{
    CHECK_R();
    umbra_status st = umbra__call_begin(r, __func__);
    if (st == UMBRA_SUCCESS) {
        st = render_host(r, width, height, rgba);
        umbra__call_end(r);
    }
    return st;
}

umbra_status umbra_renderer_get_stats(umbra_renderer r, umbra_render_stats *out)
{
    CHECK_R();
    if (!out)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_renderer_get_stats: out is NULL");
    *out = r->stats;
    /* An asynchronous frame's device time, from its first kernel's start to its last kernel's
     * end, once that has completed. */
    cl_int status = CL_QUEUED;
    cl_ulong a = 0, b = 0;
    if (r->async_last && r->ctx->profiling &&
        clGetEventInfo(r->async_last, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status,
                       NULL) == CL_SUCCESS &&
        status == CL_COMPLETE &&
        clGetEventProfilingInfo(r->async_first, CL_PROFILING_COMMAND_START, sizeof a, &a, NULL) ==
            CL_SUCCESS &&
        clGetEventProfilingInfo(r->async_last, CL_PROFILING_COMMAND_END, sizeof b, &b, NULL) ==
            CL_SUCCESS &&
        b >= a) {
        out->render_ms = (double)(b - a) * 1e-6;
        out->render_timing = UMBRA_TIMING_DEVICE;
    }
    out->shadow_build_timing = r->stats.shadow_rebuilt ? measured_timing(r) : UMBRA_TIMING_NONE;
    const uint32_t flags = r->tech->info.flags;
    out->light_channels = (flags & UMBRA_TECHNIQUE_NO_LIGHT) ? 0
                          : (flags & UMBRA_TECHNIQUE_GREY)   ? 1
                                                             : r->channels;
    out->shadow_memory_bytes = r->tech->memory ? r->tech->memory(r) : 0;
    return UMBRA_SUCCESS;
}
