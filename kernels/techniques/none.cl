// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/none.cl: the "none" shadow technique: every point is fully lit.
 *
 * The shadow-technique interface, which every technique's kernels/techniques/<name>.cl implements
 * (host/renderer_internal.h lists its kernel files; its constants, if any, are a struct in
 * kernels/techniques/<name>_shared.h that SHADOW_KERNEL_PARAMS takes and its bind function
 * passes):
 *   SHADOW_KERNEL_PARAMS    extra kernel parameters, each with a leading comma (may be empty);
 *                           the host module binds them after the fixed raycast arguments
 *   ShadowRay               per-view-ray state (e.g. where the last lookup ended)
 *   shadow_ray_init(&sr)    resets it at the start of a view ray
 *   SHADOW_FACTOR(sr, p)    RGB shadow factor at world point p; may use the raycast kernel's
 *                           parameters F, vol, g, light_tf, light_cells, S by name */

#define SHADOW_KERNEL_PARAMS

typedef struct ShadowRay {
    int unused;
} ShadowRay;

inline void shadow_ray_init(ShadowRay *sr) { sr->unused = 0; }

#define SHADOW_FACTOR(sr, p) ((float3)(1.0f))
