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
    /* The view table has one entry more, a copy of the last (tf_classify in
     * kernels/common/sampling.cl reads entry i + 1 for i up to count - 1 without a clamp). */
    size_t bytes = ((size_t)tf->count * (light ? 4 : 1) + (light ? 0 : 1)) * 4 * sizeof(float);
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
    if (!light)
        memcpy(t + 4 * (size_t)tf->count, t + 4 * ((size_t)tf->count - 1), 4 * sizeof(float));
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

/* Whether some table entry that values in [minmax[0], minmax[1]] interpolate has alpha > 0; for
 * a label map (labels), whether some label in that range has an entry with alpha > 0 (labels
 * past the table's end are transparent). */
static int range_visible(umbra_transfer_function tf, const uint32_t *visible,
                         const float minmax[2], int labels)
{
    const float last = (float)(tf->count - 1);
    int lo = labels ? (int)minmax[0] : (int)floorf(minmax[0] * last);
    int hi = labels ? (int)minmax[1] : (int)ceilf(minmax[1] * last);
    lo = lo < 0 ? 0 : lo;
    hi = hi > (int)tf->count - 1 ? (int)tf->count - 1 : hi;
    return hi >= lo && visible[hi + 1] > visible[lo];
}

/* The transfer functions of a table set: each channel's (n of them) and their visibility
 * prefixes. */
typedef struct table_set {
    const umbra_transfer_function *tfs;
    uint32_t *visible[UMBRA_MAX_CHANNELS];
    uint32_t n;
} table_set;

/* Whether brick or sub-cell i (per channel, n_per of them) is visible to some channel. */
static int set_visible(umbra_renderer r, const table_set *T, const float *minmax, size_t n_per,
                       size_t i)
{
    for (uint32_t c = 0; c < T->n; ++c)
        if (range_visible(T->tfs[c], T->visible[c], minmax + 2 * (n_per * c + i),
                          r->volume->labels))
            return 1;
    return 0;
}

/* One byte per brick: 1 if some value in the brick's range has alpha > 0 under the set. */
static umbra_status brick_table(umbra_renderer r, const table_set *T, cl_mem *buf)
{
    umbra_volume v = r->volume;
    const size_t n = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    unsigned char *flags = malloc(n);
    for (size_t b = 0; flags && b < n; ++b)
        flags[b] = (unsigned char)set_visible(r, T, v->brick_minmax, n, b);
    return upload_table(r, flags, n, "brick table", buf);
}

/* One 64-bit mask per brick: bit (x + 4 y + 16 z) set if sub-cell (x, y, z) has a value with
 * alpha > 0 under the set (kernels/common/umbra_shared.h, UMBRA_BRICK_CELLS). */
static umbra_status cell_table(umbra_renderer r, const table_set *T, cl_mem *buf)
{
    umbra_volume v = r->volume;
    const size_t n = (size_t)v->brick_counts[0] * v->brick_counts[1] * v->brick_counts[2];
    const uint32_t cells = UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS * UMBRA_BRICK_CELLS;
    uint64_t *masks = calloc(n, sizeof *masks);
    for (size_t b = 0; masks && b < n; ++b)
        for (uint32_t c = 0; c < cells; ++c)
            if (set_visible(r, T, v->cell_minmax, n * cells, b * cells + c))
                masks[b] |= (uint64_t)1 << c;
    return upload_table(r, masks, n * sizeof *masks, "cell table", buf);
}

/* A multi-channel volume's table: each channel's entries after the previous channel's, alphas
 * corrected for step_voxels (the light's, 0, as given), at and n giving each part. */
static umbra_status channel_tables(umbra_renderer r, const table_set *T, float step_voxels,
                                   uint32_t at[UMBRA_MAX_CHANNELS],
                                   uint32_t cnt[UMBRA_MAX_CHANNELS], cl_mem *buf)
{
    size_t total = 0;
    for (uint32_t c = 0; c < T->n; ++c)
        total += T->tfs[c]->count;
    float *t = malloc(total * 4 * sizeof *t);
    if (!t)
        return upload_table(r, NULL, total * 16, "channels' transfer functions", buf);
    size_t k = 0;
    for (uint32_t c = 0; c < T->n; ++c) {
        const umbra_transfer_function tf = T->tfs[c];
        at[c] = (uint32_t)k;
        cnt[c] = tf->count;
        for (uint32_t i = 0; i < tf->count; ++i, ++k) {
            memcpy(t + 4 * k, tf->rgba + 4 * i, 3 * sizeof(float));
            double a = tf->rgba[4 * i + 3];
            t[4 * k + 3] = step_voxels == 0.0f ? (float)a
                           : a < 1.0 ? (float)-expm1((double)step_voxels * log1p(-a))
                                     : 1.0f;
        }
    }
    return upload_table(r, t, total * 4 * sizeof *t, "channels' transfer functions", buf);
}

umbra_status umbra__tables(umbra_renderer r, const umbra_transfer_function *tfs,
                           float step_voxels, uint64_t key[8], cl_mem *tf_buf, cl_mem *brick_buf,
                           cl_mem *cell_buf)
{
    umbra_volume v = r->volume;
    const uint32_t n = v->channels;
    uint32_t bits;
    memcpy(&bits, &step_voxels, sizeof bits);
    /* What the table depends on (the transfer functions, the step, the kind of volume) and
     * what the visibility depends on besides (the volume and its ranges). */
    uint64_t want[8] = {0, 0, 0, 0, bits, (uint64_t)n | (uint64_t)v->labels << 8, v->id,
                        v->ranges_version};
    for (uint32_t c = 0; c < n; ++c)
        want[c] = tfs[c]->id;
    UmbraChannels *ch = &r->frame.ch;
    uint32_t *at = step_voxels == 0.0f ? ch->light_at : ch->view_at;
    uint32_t *cnt = step_voxels == 0.0f ? ch->light_n : ch->view_n;
    for (uint32_t c = 0; c < UMBRA_MAX_CHANNELS; ++c)
        at[c] = cnt[c] = 0;
    uint32_t k = 0;
    for (uint32_t c = 0; c < n; ++c) {
        at[c] = k;
        cnt[c] = tfs[c]->count;
        k += tfs[c]->count;
    }
    const int table = !*tf_buf || memcmp(want, key, 6 * sizeof want[0]) != 0;
    const int vis = table || !*cell_buf || (brick_buf && !*brick_buf) ||
                    memcmp(want, key, sizeof want) != 0;
    if (!vis)
        return UMBRA_SUCCESS;
    memset(key, 0, 8 * sizeof key[0]);
    table_set T = {.tfs = tfs, .n = n};
    umbra_status st = UMBRA_SUCCESS;
    if (table) {
        st = n == 1 ? corrected_table(r, tfs[0], step_voxels, tf_buf)
                    : channel_tables(r, &T, step_voxels, at, cnt, tf_buf);
        r->rebuilds.tables++;
    }
    for (uint32_t c = 0; c < n && st == UMBRA_SUCCESS; ++c)
        if (!(T.visible[c] = visible_prefix(tfs[c])))
            st = umbra__fail(r->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                             "umbra_renderer_render: out of memory for the visibility tables");
    if (st == UMBRA_SUCCESS && brick_buf)
        st = brick_table(r, &T, brick_buf);
    if (st == UMBRA_SUCCESS)
        st = cell_table(r, &T, cell_buf);
    for (uint32_t c = 0; c < n; ++c)
        free(T.visible[c]);
    r->rebuilds.visibility++;
    if (st == UMBRA_SUCCESS)
        memcpy(key, want, sizeof want);
    return st;
}

void umbra__channel_tfs(umbra_renderer r, int light, umbra_transfer_function *out)
{
    out[0] = light ? umbra__light_tf(r) : umbra__view_tf(r);
    for (uint32_t c = 1; c < r->volume->channels; ++c)
        out[c] = light ? r->ch_light_eff[c] : r->ch_view_eff[c];
}

umbra_status umbra__light_tables(umbra_renderer r)
{
    umbra_transfer_function tfs[UMBRA_MAX_CHANNELS];
    umbra__channel_tfs(r, 1, tfs);
    return umbra__tables(r, tfs, 0.0f, r->light_tf_key, &r->light_tf_buf, NULL,
                         &r->light_cells_buf);
}
