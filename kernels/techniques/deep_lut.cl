// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/deep_lut.cl: the deep shadow map's pre-compressed segment table (shadow
 * lookup_table, on by default), which deep_step (kernels/techniques/deep.cl) reads for every
 * segment inside the box. It uses that file's greedy fit: the host's build program appends this
 * file after it (host/techniques/deep.c, ensure_program). */

/* ---- the pre-compressed segment table -------------------------------------------------------
 * Entry (i_f, i_b) covers a segment of one light step h whose scalar runs linearly from
 * s_f = i_f / (R-1) to s_b = i_b / (R-1). Its visibility is integrated at DEEP_LUT_SUBSTEPS
 * midpoint sub-steps of h / DEEP_LUT_SUBSTEPS each (the extinction of kernels/common/common.cl),
 * then compressed with deep.cl's fit within DEEP_LUT_TOL, or, where that needs more than
 * DEEP_LUT_INTERIOR interior nodes, within the smallest tolerance that needs no more. The end
 * value is exact (the fit pins the last point). Stored: DEEP_LUT_NODES nodes (x in (0, 1],
 * visibility factor), the last one at x = 1; unused interior slots repeat the end node.
 * Global size R x R; F supplies the light table size and the colour flag. */
inline int deep_lut_fit(const light_t *v, float tol, int limit, deep_node *out)
{
    DeepFit f;
    deep_fit_init(&f); /* origin (0, 1): the segment start, implicit in the table */
    deep_node e[3];
    int count = 0;
    for (int j = 1; j <= DEEP_LUT_SUBSTEPS; ++j) {
        int n = 0;
        deep_fit_push(&f, (float)j / (float)DEEP_LUT_SUBSTEPS, v[j], tol, e, &n);
        if (j == DEEP_LUT_SUBSTEPS)
            deep_fit_finish(&f, e, &n);
        for (int q = 0; q < n; ++q) {
            /* The fit's first node is the last point at visibility 1 (an isosurface's front,
             * kept exactly, so nothing in front of it is shadowed); at x = 0 it is implicit. */
            if (DEEP_DEPTH(e[q]) <= 0.0f)
                continue;
            if (out && count < DEEP_LUT_NODES)
                out[count] = e[q];
            ++count;
        }
        /* The last point always adds the end node: more than limit + 1 cannot fit. */
        if (count > limit + (j == DEEP_LUT_SUBSTEPS))
            return count;
    }
    return count - 1; /* the last node is the end, at x = 1 */
}

__kernel void deep_lut(__global const UmbraFrame *F, __global const float4 *light_tf,
                       __global deep_node *lut, float h_vox)
{
    const int i_f = get_global_id(0), i_b = get_global_id(1);
    if (i_f >= DEEP_LUT_RES || i_b >= DEEP_LUT_RES)
        return;
    const float sf = (float)i_f / (float)(DEEP_LUT_RES - 1);
    const float sb = (float)i_b / (float)(DEEP_LUT_RES - 1);
    const uint n_tf = F->light_tf_size, flags = F->flags;
    const float frac = 1.0f / (float)DEEP_LUT_SUBSTEPS;
    light_t v[DEEP_LUT_SUBSTEPS + 1];
    v[0] = (light_t)(1.0f);
    for (int j = 0; j < DEEP_LUT_SUBSTEPS; ++j) {
        float s = mix(sf, sb, ((float)j + 0.5f) * frac);
        float4 c = tf_lookup(light_tf, n_tf, s);
        /* light_pass(c, frac h_vox, flags) (the segment is one step of h_vox voxels), with the
         * fast exp2 / log2: this loop is the table's cost */
        const float l2 = native_log2(fmax(1.0f - c.w, 1.0f - UMBRA_ALPHA_MAX)) * (frac * h_vox);
        v[j + 1] = v[j] * native_exp2(l2 * light_absorbed(c, flags));
    }
    deep_node out[DEEP_LUT_NODES];
    const light_t end = v[DEEP_LUT_SUBSTEPS];
    for (int q = 0; q < DEEP_LUT_NODES; ++q)
        out[q] = DEEP_NODE(1.0f, end);
    if (!deep_all_one(end)) {
        /* As few nodes as keep the entry within DEEP_LUT_TOL (a smooth segment needs none, so
         * the map's fit gets one point per step there); where that takes more than
         * DEEP_LUT_INTERIOR (a sharp feature), the smallest tolerance that needs no more, by
         * bisection between DEEP_LUT_TOL and the error of the straight line from 1 to the end
         * value (which needs none): 8 halvings, within 1/256 of that error of the optimum for
         * this greedy fit. Every feasible fit writes its nodes as it goes, so none is fitted
         * again: the entry is the first fit's if it is feasible, else the last feasible
         * halving's, else the line's. Fitting the chosen tolerance once more, as this did
         * before, cost the table more CPU time for the same table bit for bit
         * (docs/performance-log.md, "Behind the kernels' comments"; issue #12). */
        int interior = deep_lut_fit(v, DEEP_LUT_TOL, DEEP_LUT_INTERIOR, out);
        if (interior > DEEP_LUT_INTERIOR) {
            float lo = DEEP_LUT_TOL, hi = DEEP_LUT_TOL;
            for (int j = 1; j < DEEP_LUT_SUBSTEPS; ++j) {
                float x = (float)j / (float)DEEP_LUT_SUBSTEPS;
                hi = fmax(hi, deep_max_abs(v[j] - mix((light_t)(1.0f), end, x)));
            }
            hi = hi * 1.001f + 1e-6f; /* rounding must not make the straight line infeasible */
            deep_node tried[DEEP_LUT_NODES];
            for (int it = 0; it < 8; ++it) {
                float mid = 0.5f * (lo + hi);
                int k = deep_lut_fit(v, mid, DEEP_LUT_INTERIOR, tried);
                if (k <= DEEP_LUT_INTERIOR) {
                    hi = mid;
                    interior = k;
                    for (int q = 0; q < k; ++q)
                        out[q] = tried[q];
                } else {
                    lo = mid;
                }
            }
            if (interior > DEEP_LUT_INTERIOR) /* no halving was feasible: the line's */
                interior = deep_lut_fit(v, hi, DEEP_LUT_NODES, out);
        }
        interior = min(interior, DEEP_LUT_INTERIOR);
        out[interior] = DEEP_NODE(1.0f, end);
        for (int q = interior + 1; q < DEEP_LUT_NODES; ++q)
            out[q] = out[interior];
    }
    __global deep_node *dst = lut + ((size_t)i_f * DEEP_LUT_RES + (size_t)i_b) * DEEP_LUT_NODES;
    for (int q = 0; q < DEEP_LUT_NODES; ++q)
        dst[q] = out[q];
}
