// SPDX-License-Identifier: Apache-2.0
/* host/channels.c: the renderer's side of multi-channel volumes and label maps (volume.h): each
 * channel's transfer functions, and what a frame checks before it renders such a volume. The
 * kernels' side is kernels/common/channels.cl; the tables of every channel are made together in
 * host/tables.c, resampled onto each channel's range in host/world.c. */
#include "renderer_internal.h"

umbra_status umbra_renderer_set_channel_transfer_function(umbra_renderer r, uint32_t channel,
                                                          umbra_transfer_function tf,
                                                          umbra_transfer_function light_tf)
{
    const char *fn = "umbra_renderer_set_channel_transfer_function";
    CHECK_R();
    if (channel >= UMBRA_MAX_CHANNELS)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: channel %u must lie in [0, %d) (UMBRA_MAX_CHANNELS)", fn, channel,
                           UMBRA_MAX_CHANNELS);
    if (!tf)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: tf of channel %u is NULL",
                           fn, channel);
    if (tf->ctx != r->ctx || (light_tf && light_tf->ctx != r->ctx))
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: a transfer function of channel %u belongs to another context", fn,
                           channel);
    umbra_transfer_function *view = channel == 0 ? &r->tf : &r->ch_tf[channel];
    umbra_transfer_function *light = channel == 0 ? &r->light_tf : &r->ch_light_tf[channel];
    umbra_transfer_function_retain(tf);
    umbra_transfer_function_retain(light_tf);
    umbra_transfer_function_release(*view);
    umbra_transfer_function_release(*light);
    *view = tf;
    *light = light_tf;
    return UMBRA_SUCCESS;
}

int umbra__light_tfs_grey(umbra_renderer r)
{
    if (!umbra_transfer_function_is_grey(umbra__light_tf(r)))
        return 0;
    for (uint32_t c = 1; c < r->volume->channels; ++c)
        if (!umbra_transfer_function_is_grey(r->ch_light_eff[c]))
            return 0;
    return 1;
}

umbra_status umbra__check_kind(umbra_renderer r, const char *fn)
{
    umbra_volume v = r->volume;
    const int mixed = v->channels > 1 || v->labels;
    const char *kind = v->labels ? "a label map" : "a multi-channel volume";
    static const char *const modes[] = {"composite", "mip", "minip", "average"};
    for (uint32_t c = 1; c < v->channels; ++c)
        if (!r->ch_tf[c])
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: the volume has %u channels and channel %u has no transfer "
                               "function (umbra_renderer_set_channel_transfer_function)", fn,
                               v->channels, c);
    if (r->opts.mode != UMBRA_RENDER_COMPOSITE) {
        if (r->tech->info.id != UMBRA_SHADOW_NONE)
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: render mode '%s' is a projection without light: it takes no "
                               "shadow technique, and '%s' is set (use technique none, or the "
                               "composite mode)", fn, modes[r->opts.mode], r->tech->info.name);
        if (v->labels)
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: render mode '%s' projects values by their order, and the "
                               "volume is a label map (labels have none): use the composite "
                               "mode", fn, modes[r->opts.mode]);
        return UMBRA_SUCCESS;
    }
    if (!mixed)
        return UMBRA_SUCCESS;
    if (!(r->tech->info.flags & UMBRA_TECHNIQUE_CHANNELS))
        return umbra__fail(r->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: technique '%s' does not render %s: its light pass reads one "
                           "transfer function, not the shared per-point lookup (docs/features.md "
                           "lists the techniques that do)", fn, r->tech->info.name, kind);
    if (r->opts.preintegrated)
        return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: pre-integrated segments integrate one transfer function between "
                           "two values; %s is not one: turn preintegrated off", fn, kind);
    return UMBRA_SUCCESS;
}
