// SPDX-License-Identifier: Apache-2.0
/* host/gradient_volume.c: the upkeep of the ray caster's shading gradient volume, the per-voxel
 * central differences of volume_gradient's stencil as int16 (kernels/common/sampling.cl,
 * gradient_volume_entry), filled by raycast_gradient_volume (kernels/raycast.cl) into r->grad_buf
 * and keyed by the volume's id and version and the program (r->grad_key); the renderer
 * (host/renderer.c) asks for it once a frame. */
#include <stdint.h>
#include <string.h>

#include "gradient_volume.h"

umbra_status umbra__gradient_volume(umbra_renderer r, cl_mem *buf, cl_uint *on)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const umbra_volume v = r->volume;
    *buf = r->view_tf_buf;
    *on = 0;
    const uint64_t n[3] = {(uint64_t)v->dims[0] + 3, (uint64_t)v->dims[1] + 3,
                           (uint64_t)v->dims[2] + 3};
    const uint64_t bytes = n[0] * n[1] * n[2] * 8u;
    /* int16 differences are exact for integer voxels loaded as stored that span <= 32767 */
    const int exact = !v->clamps && v->stored_form == UMBRA__STORED_RAW &&
                      (v->stored_type == UMBRA_UINT8 ||
                       ((v->stored_type == UMBRA_UINT16 || v->stored_type == UMBRA_INT16) &&
                        (double)v->value_max - (double)v->value_min <= 32767.0));
    umbra__device_limits lim;
    int wanted = r->opts.shading && r->grad_kernel && exact && !umbra__volume_images(v) &&
                 v->slab_count == 1 && !v->is_part && !v->labels && v->channels <= 1;
    if (wanted && (umbra__device_limits_get(ctx, 0, &lim) != UMBRA_SUCCESS ||
                   bytes > lim.max_alloc || bytes > SIZE_MAX))
        wanted = 0;
    const uint64_t key[3] = {v->id, v->version, (uint64_t)(uintptr_t)r->program};
    if (!wanted || (r->grad_buf && memcmp(key, r->grad_key, sizeof key) != 0))
        umbra__release_mem(&r->grad_buf);
    if (!wanted)
        return UMBRA_SUCCESS;
    if (!r->grad_buf) {
        cl_int err;
        r->grad_buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_WRITE, (size_t)bytes, NULL, &err);
        UMBRA_CL_CHECK(err, "clCreateBuffer");
        /* raycast_gradient_volume(F, vol, out), after the frame's wait list */
        UMBRA_CL(clSetKernelArg(r->grad_kernel, 0, sizeof(cl_mem), &r->frame_buf));
        UMBRA_CL(clSetKernelArg(r->grad_kernel, 1, sizeof(cl_mem), &v->slabs[0]));
        UMBRA_CL(clSetKernelArg(r->grad_kernel, 2, sizeof(cl_mem), &r->grad_buf));
        const size_t global[3] = {(size_t)n[0], (size_t)n[1], (size_t)n[2]};
        if ((st = umbra__frame_gate(r)) != UMBRA_SUCCESS ||
            (st = umbra__enqueue(ctx, r->grad_kernel, 3, global, NULL, NULL)) != UMBRA_SUCCESS)
            goto fail;
        memcpy(r->grad_key, key, sizeof key);
    }
    *buf = r->grad_buf;
    *on = 1;
fail:
    if (st != UMBRA_SUCCESS)
        umbra__release_mem(&r->grad_buf);
    return st;
}

