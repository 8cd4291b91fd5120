// SPDX-License-Identifier: Apache-2.0
/* bench/metrics.c: RMSE, PSNR, maximum and mean absolute error and SSIM of two rendered images
 * (definitions in metrics.h). Plain C, no OpenCL, so that tests/test_metrics.c can check it
 * against hand-computed values. */
#include "metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SSIM_WINDOW 11
#define SSIM_SIGMA 1.5
#define SSIM_C1 (0.01 * 0.01) /* (K1 L)^2 with L = 1 */
#define SSIM_C2 (0.03 * 0.03) /* (K2 L)^2 */

float metrics_display(float linear)
{
    /* NaN compares false everywhere: map it to 0 rather than letting it poison the sums, so a
     * broken image shows up as a large error instead of a NaN row. */
    if (!(linear > 0.0f))
        return 0.0f;
    if (linear >= 1.0f)
        return 1.0f;
    if (linear <= 0.0031308f)
        return 12.92f * linear;
    return 1.055f * powf(linear, 1.0f / 2.4f) - 0.055f;
}

void metrics_luma(const float *rgba, size_t pixels, float *y)
{
    for (size_t i = 0; i < pixels; ++i)
        y[i] = 0.2126f * metrics_display(rgba[4 * i]) + 0.7152f * metrics_display(rgba[4 * i + 1]) +
               0.0722f * metrics_display(rgba[4 * i + 2]);
}

/* Filters src (w x h) with the 1-D kernel k of n taps along x, keeping only the outputs whose
 * window lies inside the image: dst is (w - n + 1) x h. */
static void filter_x(const double *src, uint32_t w, uint32_t h, const double *k, uint32_t n,
                     double *dst)
{
    uint32_t ow = w - n + 1;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            double s = 0.0;
            for (uint32_t i = 0; i < n; ++i)
                s += k[i] * src[(size_t)y * w + x + i];
            dst[(size_t)y * ow + x] = s;
        }
}

/* The same along y: src is w x h, dst is w x (h - n + 1). */
static void filter_y(const double *src, uint32_t w, uint32_t h, const double *k, uint32_t n,
                     double *dst)
{
    uint32_t oh = h - n + 1;
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            double s = 0.0;
            for (uint32_t i = 0; i < n; ++i)
                s += k[i] * src[(size_t)(y + i) * w + x];
            dst[(size_t)y * w + x] = s;
        }
}

double metrics_ssim(const float *x, const float *y, uint32_t w, uint32_t h)
{
    if (!x || !y || w == 0 || h == 0)
        return -2.0;
    uint32_t n = SSIM_WINDOW;
    if (n > w)
        n = w;
    if (n > h)
        n = h;
    double k[SSIM_WINDOW], sum = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        double d = (double)i - 0.5 * (double)(n - 1);
        k[i] = exp(-d * d / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
        sum += k[i];
    }
    for (uint32_t i = 0; i < n; ++i)
        k[i] /= sum;

    size_t px = (size_t)w * h;
    uint32_t ow = w - n + 1, oh = h - n + 1;
    size_t opx = (size_t)ow * oh;
    /* Five moment images (x, y, xx, yy, xy), one row-filtered scratch, five outputs. */
    double *in = malloc(5 * px * sizeof *in);
    double *tmp = malloc((size_t)ow * h * sizeof *tmp);
    double *out = malloc(5 * opx * sizeof *out);
    double result = -2.0;
    if (!in || !tmp || !out)
        goto done;
    for (size_t i = 0; i < px; ++i) {
        double a = x[i], b = y[i];
        in[i] = a;
        in[px + i] = b;
        in[2 * px + i] = a * a;
        in[3 * px + i] = b * b;
        in[4 * px + i] = a * b;
    }
    for (int m = 0; m < 5; ++m) {
        filter_x(in + (size_t)m * px, w, h, k, n, tmp);
        filter_y(tmp, ow, h, k, n, out + (size_t)m * opx);
    }
    double total = 0.0;
    for (size_t i = 0; i < opx; ++i) {
        double mx = out[i], my = out[opx + i];
        double vx = out[2 * opx + i] - mx * mx, vy = out[3 * opx + i] - my * my;
        double cxy = out[4 * opx + i] - mx * my;
        total += ((2.0 * mx * my + SSIM_C1) * (2.0 * cxy + SSIM_C2)) /
                 ((mx * mx + my * my + SSIM_C1) * (vx + vy + SSIM_C2));
    }
    result = total / (double)opx;
done:
    free(in);
    free(tmp);
    free(out);
    return result;
}

int metrics_compare(const float *a, const float *b, uint32_t w, uint32_t h, metrics_error *out)
{
    if (!a || !b || !out || w == 0 || h == 0)
        return -1;
    memset(out, 0, sizeof *out);
    size_t px = (size_t)w * h;
    double sq = 0.0, abs_sum = 0.0, max_abs = 0.0;
    for (size_t i = 0; i < px; ++i)
        for (int c = 0; c < 3; ++c) {
            double d =
                (double)metrics_display(a[4 * i + c]) - (double)metrics_display(b[4 * i + c]);
            double ad = fabs(d);
            sq += d * d;
            abs_sum += ad;
            if (ad > max_abs)
                max_abs = ad;
        }
    out->rmse = sqrt(sq / (double)(3 * px));
    out->psnr_db = out->rmse > 0.0 ? 20.0 * log10(1.0 / out->rmse) : INFINITY;
    out->max_abs = max_abs;
    out->mean_abs = abs_sum / (double)(3 * px);

    float *ya = malloc(px * sizeof *ya), *yb = malloc(px * sizeof *yb);
    if (!ya || !yb) {
        free(ya);
        free(yb);
        return -1;
    }
    metrics_luma(a, px, ya);
    metrics_luma(b, px, yb);
    out->ssim = metrics_ssim(ya, yb, w, h);
    free(ya);
    free(yb);
    return out->ssim < -1.5 ? -1 : 0;
}
