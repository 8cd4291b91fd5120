// SPDX-License-Identifier: Apache-2.0
/* host/part_render.c: the renderer's side of a part (umbra/part.h): its screen rectangle, its
 * view segment rendered into a partial image, and the light data that crosses parts. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"

umbra_status umbra_renderer_part_rect(umbra_renderer r, uint32_t width, uint32_t height,
                                      umbra_part_rect *out)
{
    (void)width;
    (void)height;
    (void)out;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_rect: not implemented yet");
}

umbra_status umbra_renderer_render_part(umbra_renderer r, uint32_t width, uint32_t height,
                                        umbra_part_rect *rect, float *rgba)
{
    (void)width;
    (void)height;
    (void)rect;
    (void)rgba;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_render_part: not implemented yet");
}

umbra_status umbra_renderer_part_light_info(umbra_renderer r, umbra_part_light_info *out)
{
    (void)out;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_light_info: not implemented yet");
}

umbra_status umbra_renderer_part_export_transmittance(umbra_renderer r, float *tau_exit)
{
    (void)tau_exit;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_export_transmittance: not implemented yet");
}

umbra_status umbra_renderer_part_import_transmittance(umbra_renderer r, const float *tau_in)
{
    (void)tau_in;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_import_transmittance: not implemented yet");
}

umbra_status umbra_renderer_part_export_depths(umbra_renderer r, float *depths)
{
    (void)depths;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_export_depths: not implemented yet");
}

umbra_status umbra_renderer_part_import_depths(umbra_renderer r, const float *depths)
{
    (void)depths;
    return umbra__fail(r ? r->ctx : NULL, UMBRA_ERROR_UNSUPPORTED,
                       "umbra_renderer_part_import_depths: not implemented yet");
}
