// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/cssm_shared.h: the colored stochastic shadow map's kernel constants, shared
 * by host/techniques/cssm.c (which fills them and checks the size) and cssm.cl, compiled after
 * kernels/common/umbra_shared.h on both sides. */
#ifndef UMBRA_CSSM_SHARED_H
#define UMBRA_CSSM_SHARED_H

/* The largest block side whose photons share a light ray (the kernel's arrays hold the square of
 * it; the host refuses more). */
#define UMBRA_CSSM_MAX_RAY_BLOCK 3

typedef struct UmbraCssm {
    uint32_t taps;      /* texels per lookup */
    uint32_t seed;      /* of the counter-based random numbers */
    uint32_t ray_block; /* texels per side of a block whose photons share a ray */
    uint32_t pad;
} UmbraCssm;

#endif
