// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/moments_shared.h: the moment shadow map's kernel constants, shared by
 * host/techniques/moments.c (which fills them and checks the size) and moments.cl, compiled after
 * kernels/common/umbra_shared.h on both sides. */
#ifndef UMBRA_MOMENTS_SHARED_H
#define UMBRA_MOMENTS_SHARED_H

/* The most power moments per channel (the kernels' arrays hold this many). */
#define UMBRA_MOMENTS_MAX 8
/* The largest pre-filter radius in texels. */
#define UMBRA_MOMENTS_MAX_BLUR 4

typedef struct UmbraMoments {
    uint32_t count;       /* power moments per channel: 4, 6 or 8 */
    uint32_t bits;        /* 32: the normalised moments as floats; 16: as signed 16-bit fixed
                             point, two to a 32-bit word */
    uint32_t words;       /* 32-bit words per channel and texel: the optical depth, then the
                             moments (count at 32 bits, count / 2 at 16) */
    uint32_t blur;        /* the pre-filter's radius in texels (0: none) */
    float bias;           /* the moment bias alpha the lookup mixes in */
    float overestimation; /* beta: the estimate is lower + beta (upper - lower) */
    float depth_cap;      /* optical depth at which a channel's march stops */
    uint32_t pad;
} UmbraMoments;

#endif
