// SPDX-License-Identifier: Apache-2.0
/* bench/metrics.h: image error measures for comparing a technique's image with the exact
 * reference of the same scene and view.
 *
 * Every measure is taken on display values: the premultiplied RGB the renderer writes (the image as
 * seen over black, which is what a PNG of an opaque-background scene shows), clamped to [0,1] and
 * sRGB-encoded, so that an error in a dark shadow counts as much as the eye sees it. Peak value 1.
 *   RMSE      root mean square over all pixels and the three colour channels
 *   PSNR      20 log10(1 / RMSE) in dB; +infinity for identical images (printed "inf")
 *   max abs   largest absolute difference in any channel of any pixel
 *   mean abs  mean absolute difference over pixels and channels (the convolution paper's
 *             "average pixel difference")
 *   SSIM      mean structural similarity (Wang et al. 2004) of the luma Y' = 0.2126 R' +
 *             0.7152 G' + 0.0722 B' of the display values: 11x11 Gaussian window, sigma 1.5,
 *             K1 = 0.01, K2 = 0.03, L = 1, averaged over the window positions that lie wholly
 *             inside the image (the window shrinks to the image for images under 11 pixels). */
#ifndef UMBRA_BENCH_METRICS_H
#define UMBRA_BENCH_METRICS_H

#include <stddef.h>
#include <stdint.h>

typedef struct metrics_error {
    double rmse;
    double psnr_db;   /* +INFINITY when rmse == 0 */
    double max_abs;
    double mean_abs;
    double ssim;
} metrics_error;

/* The display value of one linear premultiplied channel: clamp to [0,1], then sRGB-encode. */
float metrics_display(float linear);

/* Luma of w*h premultiplied RGBA pixels (4 floats each, borrowed) into y (w*h floats). */
void metrics_luma(const float *rgba, size_t pixels, float *y);

/* Mean SSIM of two w x h single-channel images with values in [0,1]. Returns a negative value
 * (-2) if a scratch allocation fails or an argument is NULL or zero. */
double metrics_ssim(const float *x, const float *y, uint32_t w, uint32_t h);

/* Compares two w x h premultiplied RGBA images (test against reference). Returns 0 on success,
 * -1 on a NULL or zero argument or a failed allocation. The measures are symmetric in a and b. */
int metrics_compare(const float *a, const float *b, uint32_t w, uint32_t h, metrics_error *out);

#endif
