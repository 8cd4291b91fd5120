// SPDX-License-Identifier: Apache-2.0
/* host/progress.c: progress reports and cancellation for the renderer's long calls.
 *
 * A render, shadow build or query reports the fraction of its work done to the application's
 * callback between pieces of device work, and stops when the callback asks it to. For that, a
 * long 2D launch runs in bands of rows (each one launch with a global offset, of about
 * UMBRA__BAND_SAMPLES samples), one band queued while the previous one is waited for, so the
 * device never idles and a cancel waits for at most two bands. Without a callback a launch is
 * one band, as before. */
#include <math.h>

#include "renderer_internal.h"

umbra_status umbra_renderer_set_progress(umbra_renderer r, umbra_progress_callback cb, void *user)
{
    if (!r)
        return UMBRA_ERROR_INVALID_ARGUMENT;
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

umbra_status umbra__run_2d(umbra_renderer r, cl_kernel k, const size_t global[2],
                           const size_t *local_in, double cost, double *ms, const char *fn)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    const size_t local[2] = {local_in ? local_in[0] : 8, local_in ? local_in[1] : 8};
    const size_t gx = round_up(global[0], local[0]), gy = round_up(global[1], local[1]);
    size_t rows = gy;
    if (r->progress) {
        double budget = r->band_samples > 0.0 ? r->band_samples : UMBRA__BAND_SAMPLES;
        double want = budget / ((double)gx * fmax(cost, 1.0));
        if (!(r->band_samples > 0.0)) /* the tests' knob may go below the minimum */
            want = fmax(want, UMBRA__BAND_MIN_ITEMS / (double)gx);
        if (want < (double)gy)
            rows = round_up(want < 1.0 ? 1 : (size_t)want, local[1]);
    }
    const size_t bands = (gy + rows - 1) / rows;
    cl_event ev[2] = {NULL, NULL};
    double t0 = umbra__now_ms(), device = 0.0;
    int device_ok = 1;
    /* Band b + 1 is queued before band b is waited for, so the device never idles between bands. */
    for (size_t b = 0; b <= bands; ++b) {
        if (b < bands) {
            const size_t offset[2] = {0, b * rows};
            const size_t size[2] = {gx, rows < gy - b * rows ? rows : gy - b * rows};
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
