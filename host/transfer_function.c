// SPDX-License-Identifier: Apache-2.0
/* host/transfer_function.c: RGBA transfer-function tables, host copy plus device copy.
 *
 * Tables are validated once here (finite, in [0,1]) so kernels never see a NaN. Renderers derive
 * step-corrected copies from the host table (host/renderer.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static umbra_status check_rgba(umbra_context ctx, const char *fn, const char *what, uint32_t i,
                               const float *rgba)
{
    static const char ch[] = "rgba";
    for (int c = 0; c < 4; ++c)
        if (!(rgba[c] >= 0.0f && rgba[c] <= 1.0f)) /* false for NaN too */
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: %s %u channel %c is %g; every channel must be finite and in "
                               "[0, 1]", fn, what, i, ch[c], rgba[c]);
    return UMBRA_SUCCESS;
}

static umbra_status tf_make(umbra_context ctx, const char *fn, float *table, uint32_t count,
                            umbra_transfer_function *out)
{
    umbra_status st = umbra__check_process(ctx, fn);
    if (st != UMBRA_SUCCESS) {
        free(table);
        return st;
    }
    umbra_transfer_function tf = calloc(1, sizeof *tf);
    if (!tf) {
        free(table);
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
    }
    atomic_init(&tf->refs, 1);
    tf->ctx = ctx;
    umbra_context_retain(ctx);
    tf->count = count;
    tf->rgba = table;
    tf->id = umbra__next_id(ctx);
    cl_int err;
    tf->buffer = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                (size_t)count * 4 * sizeof(float), table, &err);
    UMBRA_CL_CHECK(err, "clCreateBuffer(transfer function)");
    *out = tf;
    return UMBRA_SUCCESS;
fail:
    umbra_transfer_function_release(tf);
    return st;
}

umbra_status umbra_transfer_function_create(umbra_context ctx, const float *rgba, uint32_t count,
                                            umbra_transfer_function *out)
{
    const char *fn = "umbra_transfer_function_create";
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    *out = NULL;
    if (!ctx || !rgba)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: ctx %p, rgba %p: neither may be NULL", fn, (void *)ctx,
                           (const void *)rgba);
    if (count < 2 || count > 65536)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: count %u must lie in [2, 65536]", fn, count);
    for (uint32_t i = 0; i < count; ++i) {
        umbra_status st = check_rgba(ctx, fn, "entry", i, rgba + 4 * i);
        if (st != UMBRA_SUCCESS)
            return st;
    }
    float *table = malloc((size_t)count * 4 * sizeof *table);
    if (!table)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
    memcpy(table, rgba, (size_t)count * 4 * sizeof *table);
    return tf_make(ctx, fn, table, count, out);
}

umbra_status umbra_transfer_function_create_from_points(umbra_context ctx,
                                                        const umbra_tf_point *points,
                                                        uint32_t count, uint32_t resolution,
                                                        umbra_transfer_function *out)
{
    const char *fn = "umbra_transfer_function_create_from_points";
    if (!out)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", fn);
    *out = NULL;
    if (!ctx || !points || count == 0)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: ctx %p, points %p, count %u: need a context and at least one point",
                           fn, (void *)ctx, (const void *)points, count);
    if (resolution < 2 || resolution > 65536)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: resolution %u must lie in [2, 65536]", fn, resolution);
    if (count > UMBRA_TF_MAX_POINTS)
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: count %u: at most %u control points are allowed", fn, count,
                           UMBRA_TF_MAX_POINTS);
    for (uint32_t i = 0; i < count; ++i) {
        if (!(points[i].value >= 0.0f && points[i].value <= 1.0f))
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: point %u value %g must be finite and in [0, 1]", fn, i,
                               points[i].value);
        if (i > 0 && points[i].value < points[i - 1].value)
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: point %u value %g is below point %u's %g; sort by value", fn, i,
                               points[i].value, i - 1, points[i - 1].value);
        umbra_status st = check_rgba(ctx, fn, "point", i, points[i].rgba);
        if (st != UMBRA_SUCCESS)
            return st;
    }
    float *table = malloc((size_t)resolution * 4 * sizeof *table);
    if (!table)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of host memory", fn);
    /* One merge walk over entries and points: x only grows, so the first point at or above it
     * (j) only moves forward, and the build costs resolution + count steps, not their product. */
    uint32_t j = 0;
    for (uint32_t e = 0; e < resolution; ++e) {
        float x = (float)e / (float)(resolution - 1);
        while (j < count && points[j].value < x)
            ++j;
        for (int c = 0; c < 4; ++c) {
            float val;
            if (j == 0)
                val = points[0].rgba[c];
            else if (j == count)
                val = points[count - 1].rgba[c];
            else {
                const umbra_tf_point *a = &points[j - 1], *b = &points[j];
                float w = b->value > a->value ? (x - a->value) / (b->value - a->value) : 1.0f;
                val = a->rgba[c] + w * (b->rgba[c] - a->rgba[c]);
            }
            table[4 * e + c] = val;
        }
    }
    return tf_make(ctx, fn, table, resolution, out);
}

umbra_status umbra_transfer_function_set_range(umbra_transfer_function tf, float lo, float hi)
{
    const char *fn = "umbra_transfer_function_set_range";
    if (!tf)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    if (!isfinite(lo) || !isfinite(hi) || !(hi > lo))
        return umbra__fail(tf->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: range [%g, %g] must be finite with hi > lo", fn, lo, hi);
    tf->range_given = 1;
    tf->range_lo = lo;
    tf->range_hi = hi;
    tf->id = umbra__next_id(tf->ctx); /* renderers re-derive their tables from it */
    return UMBRA_SUCCESS;
}

int umbra_transfer_function_get_range(umbra_transfer_function tf, float range[2])
{
    if (!tf || !tf->range_given)
        return 0;
    if (range) {
        range[0] = tf->range_lo;
        range[1] = tf->range_hi;
    }
    return 1;
}

/* The most entries a resampled table gets, as many as a table may have. */
#define TF_RESAMPLE_MAX 65536.0
/* Resampled entries per source entry over the same data interval. Linear interpolation of the
 * resampled table departs from tf's own (piecewise linear) function only next to tf's entries, by
 * at most the slope change there times a quarter of the new spacing: for a jump of J between two
 * neighbouring entries of tf, J / 64. */
#define TF_RESAMPLE_FACTOR 16.0

umbra_status umbra__tf_for_volume(umbra_transfer_function tf, float value_min, float value_max,
                                  umbra_transfer_function *out)
{
    const char *fn = "umbra_renderer_render";
    if (!tf->range_given) {
        umbra_transfer_function_retain(tf);
        *out = tf;
        return UMBRA_SUCCESS;
    }
    const double lo = tf->range_lo, hi = tf->range_hi, vmin = value_min, vmax = value_max;
    const double last = (double)tf->count - 1.0;
    double n = ceil(TF_RESAMPLE_FACTOR * last * (vmax - vmin) / (hi - lo)) + 1.0;
    n = fmin(TF_RESAMPLE_MAX, fmax(n, (double)tf->count));
    const uint32_t count = (uint32_t)n;
    float *table = malloc((size_t)count * 4 * sizeof *table);
    if (!table)
        return umbra__fail(tf->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "%s: out of host memory for a %u-entry transfer function", fn, count);
    for (uint32_t e = 0; e < count; ++e) {
        double x = vmin + (vmax - vmin) * (double)e / (double)(count - 1);
        double s = (x - lo) / (hi - lo) * last;
        s = fmin(fmax(s, 0.0), last);
        uint32_t i = (uint32_t)s;
        i = i + 1 > (uint32_t)last ? (uint32_t)last - 1 : i;
        double w = s - (double)i;
        for (int c = 0; c < 4; ++c) {
            double v = (1.0 - w) * tf->rgba[4 * i + c] + w * tf->rgba[4 * (i + 1) + c];
            table[4 * e + c] = (float)fmin(1.0, fmax(0.0, v));
        }
    }
    return tf_make(tf->ctx, fn, table, count, out);
}

uint32_t umbra_transfer_function_size(umbra_transfer_function tf) { return tf ? tf->count : 0; }
const float *umbra_transfer_function_data(umbra_transfer_function tf) { return tf ? tf->rgba : NULL; }

int umbra_transfer_function_is_grey(umbra_transfer_function tf)
{
    if (!tf)
        return 1;
    /* Lookups interpolate between neighbours, so an entry matters if it or a neighbour is
     * non-transparent: a red entry of alpha 0 next to a grey one of alpha 0.3 tints the mix. */
    for (uint32_t i = 0; i < tf->count; ++i) {
        const float *e = tf->rgba + 4 * i;
        int seen = e[3] > 0.0f || (i > 0 && e[-1] > 0.0f) || (i + 1 < tf->count && e[7] > 0.0f);
        if (seen && (e[0] != e[1] || e[1] != e[2]))
            return 0;
    }
    return 1;
}

void umbra_transfer_function_retain(umbra_transfer_function tf)
{
    if (tf)
        atomic_fetch_add(&tf->refs, 1);
}

void umbra_transfer_function_release(umbra_transfer_function tf)
{
    if (!tf || atomic_fetch_sub(&tf->refs, 1) > 1 || umbra__forked(tf->ctx))
        return;
    if (tf->buffer)
        clReleaseMemObject(tf->buffer);
    free(tf->rgba);
    umbra_context_release(tf->ctx);
    free(tf);
}
