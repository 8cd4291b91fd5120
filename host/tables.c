// SPDX-License-Identifier: Apache-2.0
/* host/tables.c: the renderer's per-(transfer function, volume, step) tables: step-corrected
 * transfer-function tables (the light's uncorrected, with per-interval depth integrals), and
 * which bricks and sub-cells of the volume those make visible, uploaded once per key and reused
 * until the key changes (host/renderer.c calls umbra__tables before every frame). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "preintegration.h"
#include "renderer_internal.h"

float umbra__voxel_world(umbra_renderer r)
{
    const float *s = r->volume->spacing;
    return fminf(s[0], fminf(s[1], s[2]));
}

/* The integral over table interval i (from entry i to i + 1, in table units) of the extinction
 * -ln(1 - a) (a at most 1 - 2^-24, kernels/common/common.cl) times 1 - t_c for c = r, g, b and
 * times 1
 * (grey), the entries interpolated linearly: in closed form, in double, as piece_depth in
 * kernels/techniques/reference.cl integrates parts of an interval (the same formula, so that whole
 * and partial intervals agree): from the more transparent end e, with r = (a_o - a_e) /
 * (1 - a_e), the mean extinction is s_e + phi(r) and the mean of tau times it s_e / 2 + psi(r),
 * phi(r) = 1 + (1 - r) ln(1 - r) / r, psi(r) = (-ln(1 - r) (1 - 1 / r^2) + 1 / r + 1 / 2) / 2,
 * summed as their series sum_k r^k / (k (k + 1)) and sum_k r^k / (k (k + 2)) below r = 1/2
 * (60 terms: below 1e-20), where the closed forms cancel. */
static void interval_depths(const float *e, double out[4])
{
    const double amax = 0.99999994039535522;
    double a0 = e[3] < amax ? e[3] : amax, a1 = e[7] < amax ? e[7] : amax;
    const int up = a1 >= a0;
    const float *ce = up ? e : e + 4, *co = up ? e + 4 : e;
    const double ae = up ? a0 : a1, ao = up ? a1 : a0;
    const double se = -log1p(-ae), so = -log1p(-ao), qe = 1.0 - ae;
    const double r = (ao - ae) / qe;
    double phi = 0.0, psi = 0.0;
    if (r < 0.5) {
        for (int k = 60; k >= 1; --k) {
            phi = r * (phi + 1.0 / ((double)k * (k + 1)));
            psi = r * (psi + 1.0 / ((double)k * (k + 2)));
        }
    } else {
        const double lr = so - se, ir = 1.0 / r;
        phi = 1.0 - ((1.0 - ao) / qe) * lr * ir;
        psi = 0.5 * (lr * (1.0 - ir * ir) + ir + 0.5);
    }
    const double m0 = se + phi, m1 = 0.5 * se + psi;
    for (int k = 0; k < 3; ++k) {
        const double fe = 1.0 - (double)ce[k], fo = 1.0 - (double)co[k];
        out[k] = fe * m0 + (fo - fe) * m1;
    }
    out[3] = m0;
}

/* Makes *buf a read-only device copy of host (bytes long, freed here; NULL: out of memory):
 * written into the buffer *buf already is where that has the same size, as after an edit of the
 * transfer function's values (the in-order queue puts the write after the kernels that read the
 * old table), else a new buffer. what names the table in an error. */
static umbra_status upload_table(umbra_renderer r, void *host, size_t bytes, const char *what,
                                 cl_mem *buf)
{
    umbra_context ctx = r->ctx;
    umbra_status st = UMBRA_SUCCESS;
    if (!host)
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_renderer_render: out of memory for the %s", what);
    size_t have = 0;
    cl_int err = CL_SUCCESS;
    if (*buf && clGetMemObjectInfo(*buf, CL_MEM_SIZE, sizeof have, &have, NULL) == CL_SUCCESS &&
        have == bytes) {
        err = clEnqueueWriteBuffer(ctx->queue, *buf, CL_TRUE, 0, bytes, host, 0, NULL, NULL);
        UMBRA_CL_CHECK(err, what);
    } else {
        umbra__release_mem(buf);
        *buf = clCreateBuffer(ctx->cl_ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, host,
                              &err);
        UMBRA_CL_CHECK(err, what);
    }
fail:
    free(host);
    return st;
}

/* A copy of tf with alpha corrected for a step of step_voxels: 1 - (1 - a)^step, computed as
 * -expm1(step log1p(-a)) in double so that near-transparent entries keep their precision (as
 * alpha_for_length in kernels/common/common.cl). step_voxels 0 makes the light table: the alphas as
 * given (kernels convert the interpolated alpha to extinction per sample,
 * kernels/common/common.cl),
 * followed by 2 count float4: for each entry k, the sum over the intervals before it of
 * interval_depths (r, g, b, grey), as a float pair hi, lo (hi + lo, the double sum to ~1e-14),
 * from which the exact reference takes the depth of whole table intervals with two loads and no
 * cancellation (kernels/techniques/reference.cl), then count float4 holding each entry's extinction
 * -ln(1 - a) (a clamped to 1 - 2^-24) in x, so that it takes no log at a table entry. */
static umbra_status corrected_table(umbra_renderer r, umbra_transfer_function tf, float step_voxels,
                                    cl_mem *buf)
{
    const int light = step_voxels == 0.0f;
    size_t bytes = (size_t)tf->count * 4 * sizeof(float) * (light ? 4 : 1);
    float *t = malloc(bytes);
    if (!t) /* upload_table reports it */
        return upload_table(r, NULL, bytes, "corrected transfer function", buf);
    for (uint32_t i = 0; i < tf->count; ++i) {
        memcpy(t + 4 * i, tf->rgba + 4 * i, 3 * sizeof(float));
        double a = tf->rgba[4 * i + 3];
        t[4 * i + 3] = light ? (float)a
                       : a < 1.0 ? (float)-expm1((double)step_voxels * log1p(-a))
                                 : 1.0f;
    }
    if (light) {
        double sum[4] = {0, 0, 0, 0}, d[4];
        float *p = t + 4 * (size_t)tf->count;
        for (uint32_t k = 0; k < tf->count; ++k) {
            for (int c = 0; c < 4; ++c) {
                float hi = (float)sum[c];
                p[8 * k + c] = hi;
                p[8 * k + 4 + c] = (float)(sum[c] - (double)hi);
            }
            if (k + 1 < tf->count) {
                interval_depths(tf->rgba + 4 * k, d);
                for (int c = 0; c < 4; ++c)
                    sum[c] += d[c];
            }
        }
        float *e = t + 12 * (size_t)tf->count;
        for (uint32_t k = 0; k < tf->count; ++k) {
            double a = tf->rgba[4 * k + 3] < 0.99999994039535522 ? tf->rgba[4 * k + 3]
                                                                 : 0.99999994039535522;
            e[4 * k] = (float)-log1p(-a);
            e[4 * k + 1] = e[4 * k + 2] = e[4 * k + 3] = 0.0f;
        }
    }
    return upload_table(r, t, bytes, "corrected transfer function", buf);
}

/* For each entry i of tf, visible[i] = how many entries before i have alpha > 0 (count + 1
 * values, malloc'ed; NULL: out of memory), so that whether a value range reaches a visible entry
 * is one subtraction per brick or sub-cell (a bonsai's 262144 sub-cells used to scan their
 * entries one by one: 10 to 14 ms of every transfer-function edit on the 2-core CPU). */
static uint32_t *visible_prefix(umbra_transfer_function tf)
{
    uint32_t *visible = malloc(((size_t)tf->count + 1) * sizeof *visible);
    if (!visible)
        return NULL;
    visible[0] = 0;
    for (uint32_t i = 0; i < tf->count; ++i)
        visible[i + 1] = visible[i] + (tf->rgba[4 * i + 3] > 0.0f);
    return visible;
}

/* Whether some table entry that values in [minmax[0], minmax[1]] interpolate has alpha > 0. */
static int range_visible(umbra_transfer_function tf, const uint32_t *visible,
                         const float minmax[2])
{
    const float last = (float)(tf->count - 1);
    int lo = (int)floorf(minmax[0] * last), hi = (int)ceilf(minmax[1] * last);
    lo = lo < 0 ? 0 : lo;
    hi = hi > (int)tf->count - 1 ? (int)tf->count - 1 : hi;
    return hi >= lo && visible[hi + 1] > visible[lo];
}

/* One byte per brick: 1 if some value in the brick's range has alpha > 0 under tf (visible:
 * visible_prefix's). */
static umbra_status brick_table(umbra_renderer r, umbra_transfer_function tf,
                                const uint32_t *visible, cl_mem *buf)
{
    umbra_volume v = r->volume;
    const size_t n = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    unsigned char *flags = malloc(n);
    for (size_t b = 0; flags && b < n; ++b)
        flags[b] = (unsigned char)range_visible(tf, visible, v->brick_minmax + 2 * b);
    return upload_table(r, flags, n, "brick table", buf);
}

/* One 64-bit mask per brick: bit (x + 4 y + 16 z) set if sub-cell (x, y, z) has a value with
 * alpha > 0 under tf (kernels/common/umbra_shared.h, UMBRA_BRICK_CELLS; visible as above). */
static umbra_status cell_table(umbra_renderer r, umbra_transfer_function tf,
                               const uint32_t *visible, cl_mem *buf)
{
    umbra_volume v = r->volume;
    const size_t n = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const uint32_t cells = UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    uint64_t *masks = calloc(n, sizeof *masks);
    for (size_t b = 0; masks && b < n; ++b)
        for (uint32_t c = 0; c < cells; ++c)
            if (range_visible(tf, visible, v->cell_minmax + 2 * (b * cells + c)))
                masks[b] |= (uint64_t)1 << c;
    return upload_table(r, masks, n * sizeof *masks, "cell table", buf);
}

/* The step-corrected table of tf, its cell masks and, with brick_buf, its brick table, kept while
 * tf, the volume and the step stay the same. */
umbra_status umbra__tables(umbra_renderer r, umbra_transfer_function tf, float step_voxels,
                           uint64_t key[3], cl_mem *tf_buf, cl_mem *brick_buf, cl_mem *cell_buf)
{
    uint32_t bits;
    memcpy(&bits, &step_voxels, sizeof bits);
    uint64_t want[3] = {tf->id, r->volume->id, bits};
    if (*tf_buf && *cell_buf && (!brick_buf || *brick_buf) && memcmp(want, key, sizeof want) == 0)
        return UMBRA_SUCCESS;
    umbra_status st = corrected_table(r, tf, step_voxels, tf_buf);
    uint32_t *visible = st == UMBRA_SUCCESS ? visible_prefix(tf) : NULL;
    if (st == UMBRA_SUCCESS && !visible)
        st = umbra__fail(r->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                         "umbra_renderer_render: out of memory for the visibility tables");
    if (st == UMBRA_SUCCESS && brick_buf)
        st = brick_table(r, tf, visible, brick_buf);
    if (st == UMBRA_SUCCESS)
        st = cell_table(r, tf, visible, cell_buf);
    free(visible);
    if (st == UMBRA_SUCCESS)
        memcpy(key, want, sizeof want);
    else
        memset(key, 0, 3 * sizeof key[0]);
    return st;
}

umbra_status umbra__light_tables(umbra_renderer r)
{
    return umbra__tables(r, umbra__light_tf(r), 0.0f, r->light_tf_key, &r->light_tf_buf, NULL,
                  &r->light_cells_buf);
}
