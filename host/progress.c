// SPDX-License-Identifier: Apache-2.0
/* host/progress.c: progress reports and cancellation for the renderer's long calls.
 *
 * A render, shadow build or query reports the fraction of its work done to the application's
 * callback between pieces of device work, and stops when the callback asks it to. For that, a
 * long 2D launch runs in bands (each one launch with a global offset) of about
 * UMBRA__BAND_SAMPLES samples by the caller's estimate of the samples one work-item marches:
 * whole rows of work-groups where a row holds fewer samples than that, else tiles of one row of
 * work-groups and as many columns as the budget allows, but never fewer work-groups than
 * band_groups says. One band is queued while the previous one is waited for, so the
 * device never idles and a cancel waits for at most two bands. Without a callback a launch is
 * one band, as before. */
#include <math.h>

#include "renderer_internal.h"

umbra_status umbra_renderer_set_progress(umbra_renderer r, umbra_progress_callback cb, void *user)
{
    CHECK_R();
    r->progress = cb;
    r->progress_user = user;
    return UMBRA_SUCCESS;
}

void umbra__progress_phase(umbra_renderer r, double lo, double hi)
{
    r->progress_lo = lo;
    r->progress_hi = hi;
}

void umbra__progress_begin(umbra_renderer r)
{
    r->progress_last = 0.0;
    umbra__progress_phase(r, 0.0, 1.0);
}

umbra_status umbra__progress(umbra_renderer r, double fraction, const char *fn)
{
    if (!r->progress)
        return UMBRA_SUCCESS;
    double f = r->progress_lo + (r->progress_hi - r->progress_lo) * fraction;
    f = f > 1.0 ? 1.0 : f;
    f = f < r->progress_last ? r->progress_last : f; /* a repeated pass does not go back */
    r->progress_last = f;
    if (r->progress(r->progress_user, (float)f))
        return umbra__fail(r->ctx, UMBRA_ERROR_CANCELLED,
                           "%s: cancelled by the progress callback at %.1f%%", fn, 100.0 * f);
    return UMBRA_SUCCESS;
}

void umbra__progress_end(umbra_renderer r)
{
    if (r->progress && r->progress_last < 1.0) {
        r->progress_last = 1.0;
        (void)r->progress(r->progress_user, 1.0f);
    }
}

static size_t round_up(size_t x, size_t m) { return (x + m - 1) / m * m; }

/* The samples a band may hold, and whether the tests' knob set them (it may go below the
 * smallest band the device would otherwise get). */
static double band_budget(umbra_renderer r, int *knob)
{
    *knob = r->band_samples > 0.0;
    return *knob ? r->band_samples : UMBRA__BAND_SAMPLES;
}

/* The fewest work-groups a band holds: launches on the in-order queue run one after the other,
 * so a band keeps every compute unit busy only with a group for each. On a CPU four for each:
 * a costly group (a pixel whose view ray crosses the volume) then does not leave a core idle
 * while the others finish theirs (reference, step 0.05, 96^2: the bands cost 0.93x of the
 * unbanded frame's time with four, 1.08x with one). *cpu: whether the device is a CPU (a GPU
 * gets bands of at least UMBRA__BAND_MIN_ITEMS work-items). */
static double band_groups(umbra_context ctx, int *cpu)
{
    cl_uint units = 1;
    cl_device_type type = CL_DEVICE_TYPE_CPU;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof units, &units, NULL) !=
            CL_SUCCESS ||
        units == 0)
        units = 1;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) != CL_SUCCESS)
        type = CL_DEVICE_TYPE_CPU;
    *cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
    return (*cpu ? 4.0 : 1.0) * (double)units;
}

void umbra__band_local(umbra_renderer r, double cost, size_t local[2])
{
    if (!r->progress)
        return;
    int knob, cpu = 1;
    const double budget = band_budget(r, &knob);
    const double groups = knob ? 1.0 : band_groups(r->ctx, &cpu);
    if (!knob && !cpu)
        return;
    /* Halving the longer side keeps the group as square as it can be. */
    while (local[0] * local[1] > 1 && groups * (double)(local[0] * local[1]) * fmax(cost, 1.0) >
                                          budget) {
        if (local[0] >= local[1])
            local[0] /= 2;
        else
            local[1] /= 2;
    }
}

void umbra__band_plan(umbra_renderer r, const size_t global[2], const size_t local[2],
                      double cost, size_t tile[2])
{
    const size_t gx = round_up(global[0], local[0]), gy = round_up(global[1], local[1]);
    tile[0] = gx;
    tile[1] = gy;
    if (!r->progress)
        return;
    int knob, cpu = 1;
    const double budget = band_budget(r, &knob);
    double items = budget / fmax(cost, 1.0);
    if (!knob) {
        double least = band_groups(r->ctx, &cpu) * (double)(local[0] * local[1]);
        items = fmax(items, cpu ? least : fmax(least, UMBRA__BAND_MIN_ITEMS));
    }
    if (items >= (double)gx * (double)local[1]) {
        double rows = floor(items / (double)gx / (double)local[1]) * (double)local[1];
        tile[1] = rows < (double)gy ? (size_t)rows : gy;
    } else {
        double cols = fmax(floor(items / (double)local[1] / (double)local[0]), 1.0) *
                      (double)local[0];
        tile[0] = cols < (double)gx ? (size_t)cols : gx;
        tile[1] = local[1] < gy ? local[1] : gy;
    }
}

umbra_status umbra__run_2d(umbra_renderer r, cl_kernel k, const size_t global[2],
                           const size_t *local_in, double cost, double *ms, const char *fn)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t local[2] = {local_in ? local_in[0] : 8, local_in ? local_in[1] : 8};
    const size_t gx = round_up(global[0], local[0]), gy = round_up(global[1], local[1]);
    size_t tile[2];
    umbra__band_plan(r, global, local, cost, tile);
    const size_t across = (gx + tile[0] - 1) / tile[0];
    const size_t bands = across * ((gy + tile[1] - 1) / tile[1]);
    cl_event ev[2] = {NULL, NULL};
    double t0 = umbra__now_ms(), device = 0.0;
    int device_ok = 1;
    /* Band b + 1 is queued before band b is waited for, so the device never idles between bands. */
    for (size_t b = 0; b <= bands; ++b) {
        if (b < bands) {
            const size_t offset[2] = {(b % across) * tile[0], (b / across) * tile[1]};
            const size_t size[2] = {tile[0] < gx - offset[0] ? tile[0] : gx - offset[0],
                                    tile[1] < gy - offset[1] ? tile[1] : gy - offset[1]};
            UMBRA_CL(clEnqueueNDRangeKernel(ctx->queue, k, 2, offset, size, local, 0, NULL,
                                            &ev[b % 2]));
            UMBRA_CL(clFlush(ctx->queue));
        }
        if (b > 0) {
            cl_event *e = &ev[(b - 1) % 2];
            UMBRA_CL(clWaitForEvents(1, e));
            double t = umbra__event_ms(*e);
            device += t;
            device_ok = device_ok && t >= 0.0;
            clReleaseEvent(*e);
            *e = NULL;
            if ((st = umbra__progress(r, (double)b / (double)bands, fn)) != UMBRA_SUCCESS)
                goto fail;
        }
    }
    *ms += device_ok ? device : umbra__now_ms() - t0;
fail:
    /* A cancelled call returns with nothing of it left running on the device. */
    for (int i = 0; i < 2; ++i)
        if (ev[i]) {
            clWaitForEvents(1, &ev[i]);
            clReleaseEvent(ev[i]);
        }
    return st;
}
