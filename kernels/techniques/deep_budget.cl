// SPDX-License-Identifier: Apache-2.0
/* kernels/techniques/deep_budget.cl: the deep shadow map with a fixed node budget (shadow
 * max_nodes,
 * `--nodes N`): deep_build_fixed marches every texel like deep_build (kernels/techniques/deep.cl,
 * whose fit and march this file uses; the host's build program appends it after that file) and
 * keeps at most N nodes per texel in a flat array of map_size^2 x N nodes, for comparisons at
 * equal memory as in the CSSM paper. The deep map paper stores every node; how to choose N of
 * them is ours (below). The lookup is techniques/deep.cl's. */

/* Fixed budget: at most N = max_nodes nodes per texel. The march and the greedy fit run as
 * in deep_build (within epsilon) into a private buffer; at the end of the ray the buffer is
 * reduced to N of its nodes, chosen together to minimise the error against the whole buffer.
 * (The old way, merging the least-cost interior node each time one too many arrived, decided
 * before the rest of the ray was known and compared only a node with its neighbours: with 3
 * nodes it kept a skull's front and stretched the drop behind it over the skin, lighting both.)
 *  - The last node always stays: the visibility behind the volume is exact.
 *  - The first node may go: in front of the first kept node the visibility reads 1, so giving up
 *    a gentle decline in front of a cliff is one of the choices.
 *  - The kept nodes are a subset of the fit's, whose visibility never rises and whose depths
 *    never fall, so the stored function is monotone non-increasing and in [0, 1] too.
 * Error of a choice: the sum over its segments of the integral of |buffer - kept| against a
 * weight w dtau (tau the optical depth; the buffer and the kept function run linearly between the
 * buffer's nodes, and so does their difference, whose absolute value is integrated exactly,
 * through the zero where the kept line crosses the buffer's function). dtau weighs every bit of
 * material alike -- error in empty space costs nothing, so a cliff is never smeared over the skin
 * behind it. For a light outside the box w = sqrt(v) (v the visibility): material deep in shadow
 * counts less than the lit face a camera on the light's side sees (dv = v dtau, the light the
 * material takes out, would go further). For a light at or inside the box (an octahedral map)
 * w = 1: a camera outside sees the far ends of the light's rays, the material deepest in the
 * light's shadow, and an error in the visibility there is as plain as anywhere (a head lit from
 * inside: sqrt(v) kept the inner table of the skull and read its outer table, the one the camera
 * sees, up to 0.1 too bright, in rings where the choice changed from ray to ray). There the
 * greedy fit that feeds the buffer also runs within epsilon / DEEP_FIXED_EPS_DIV, so that the
 * choice has candidate nodes near where the visibility starts to fall (the fit within epsilon
 * puts them where the fall leaves its tolerance, up to a step later); the map keeps at most N of
 * them, and a large budget can then come closer to the reference than the unbounded map. And
 * the flat stretch behind the material (to the box's far side) costs no node of the budget
 * (deep_fixed_trim_tail).
 * Held to the reference by tests/test_deep_budget.c and test_deep_fidelity.c; the measured
 * errors and costs of these choices: docs/hard-cases.md.
 * Buffer: DEEP_FIXED_BUF nodes; a texel whose fit emits more merges the node of least error
 * (against the buffer as it is then, so such errors add up) while it marches, and before the
 * exact choice (dynamic programming, O(N M^3) for M buffered nodes) the buffer is cut the same
 * way to DEEP_FIXED_DP nodes. N >= DEEP_FIXED_DP keeps the greedy cut.
 * Unused slots repeat the last node; a texel without attenuation stores (0, 1). */
#define DEEP_FIXED_BUF 64 /* the largest max_nodes host/techniques/deep.c accepts */
#define DEEP_FIXED_DP 24
#define DEEP_FIXED_EPS_DIV 4.0f

/* Per buffered node also its optical depth tau and the weight w (sqrt(v), or 1 where uniform),
 * the two factors of the error's weight: computed once when the node arrives instead of in every
 * span error that covers it (the exact choice evaluates O(M^3) of them, each a logarithm and a
 * square root per channel). */
typedef struct DeepFixed {
    deep_node n[DEEP_FIXED_BUF];
    light_t tau[DEEP_FIXED_BUF], sq[DEEP_FIXED_BUF];
    int cnt;
    int uniform; /* w = 1 (a light at or inside the box), else sqrt(v) */
} DeepFixed;

inline light_t deep_fixed_tau(light_t v) { return -log(fmax(v, (light_t)(1e-6f))); }

/* The function the kept node a (or, for a = -1, the visibility 1 before b) and b replace the
 * buffer with, at buffered node l (a < l <= b; the value at b is the left limit). */
inline light_t deep_fixed_line(const deep_node *n, int a, int b, int l)
{
    if (a < 0)
        return (light_t)(1.0f);
    const float za = DEEP_DEPTH(n[a]), span = DEEP_DEPTH(n[b]) - za;
    float w = span > 0.0f ? (DEEP_DEPTH(n[l]) - za) / span : 1.0f;
    return mix(DEEP_VIS(n[a]), DEEP_VIS(n[b]), w);
}

/* Error of replacing the buffer between kept nodes a and b (indices into n, a < b; a = -1: no
 * kept node before b) by the line from a to b (by 1 for a = -1), integrated against w dtau from
 * a (error 0 there; tau 0 for a = -1) to b, largest over the channels. Between two buffered
 * nodes the difference runs linearly; where its sign changes, |difference| is two triangles
 * (the trapezoid of the two ends' |difference| counted a line crossing the buffer's function as
 * off by that much throughout, and so chose the lines that stay on one side of it). */
inline float deep_fixed_span_error(const DeepFixed *f, int a, int b)
{
    const deep_node *n = f->n;
    light_t sum = (light_t)(0.0f), e_prev = (light_t)(0.0f);
    light_t t_prev = a < 0 ? (light_t)(0.0f) : f->tau[a];
    for (int l = a + 1; l <= b; ++l) {
        const light_t e = DEEP_VIS(n[l]) - deep_fixed_line(n, a, b, l);
        const light_t t = f->tau[l];
        const light_t ae = fabs(e), ap = fabs(e_prev);
        light_t area = 0.5f * (ae + ap);
        if (light_any_gt((light_t)(0.0f), e * e_prev)) /* a sign change: the zero's two triangles */
            area = select(area, 0.5f * (ae * ae + ap * ap) / (ae + ap),
                          e * e_prev < (light_t)(0.0f));
        sum += area * (t - t_prev) * f->sq[l];
        e_prev = e;
        t_prev = t;
    }
    return deep_max_abs(sum);
}

/* Greedy cut: reduces the buffer to `keep` nodes (keep >= 2) by removing, one at a time, the
 * node whose removal adds the least error against the buffer as it is now; compacts the kept
 * nodes to the front. O(cnt^2) span errors per texel. */
inline void deep_fixed_reduce(DeepFixed *f, int keep)
{
    const int m = f->cnt;
    if (m <= keep)
        return;
    char prev[DEEP_FIXED_BUF], next[DEEP_FIXED_BUF];
    float cost[DEEP_FIXED_BUF];
    for (int i = 0; i < m; ++i) {
        prev[i] = (char)(i - 1);
        next[i] = (char)(i + 1);
    }
    for (int i = 0; i < m - 1; ++i)
        cost[i] = deep_fixed_span_error(f, prev[i], next[i]);
    cost[m - 1] = UMBRA_INF; /* the end value stays */
    int head = 0;
    for (int left = m; left > keep; --left) {
        int best = 0;
        for (int i = 1; i < m; ++i)
            if (cost[i] < cost[best])
                best = i;
        const int a = prev[best], b = next[best];
        if (a >= 0)
            next[a] = (char)b;
        else
            head = b;
        prev[b] = (char)a;
        cost[best] = UMBRA_INF;
        if (a >= 0)
            cost[a] = deep_fixed_span_error(f, prev[a], b);
        if (b < m - 1)
            cost[b] = deep_fixed_span_error(f, a, next[b]);
    }
    int c = 0;
    for (int i = head; i < m; i = next[i], ++c) {
        f->n[c] = f->n[i];
        f->tau[c] = f->tau[i];
        f->sq[c] = f->sq[i];
    }
    f->cnt = c;
}

/* Exact choice: reduces the buffer (at most DEEP_FIXED_DP nodes) to the `keep` nodes, the last
 * one among them, whose summed span errors are least: best[k][j] is the least error of k + 1
 * kept nodes ending at node j. */
inline void deep_fixed_optimal(DeepFixed *f, int keep)
{
    const int m = f->cnt;
    if (m <= keep)
        return;
    float best_prev[DEEP_FIXED_DP], best_cur[DEEP_FIXED_DP];
    char parent[DEEP_FIXED_DP][DEEP_FIXED_DP]; /* [kept count - 1][last kept index] */
    for (int j = 0; j < m; ++j) {
        best_prev[j] = j == 0 ? 0.0f : deep_fixed_span_error(f, -1, j);
        parent[0][j] = -1;
    }
    for (int k = 1; k < keep; ++k) {
        for (int j = 0; j < m; ++j) {
            float best = UMBRA_INF;
            char arg = -1;
            /* j is the (k + 1)-th kept node: at least k nodes before it; the last kept node can
             * only be m - 1. */
            if (j >= k && (k < keep - 1 || j == m - 1))
                for (int i = j - 1; i >= k - 1; --i) {
                    if (!(best_prev[i] < best))
                        continue;
                    float e = best_prev[i] + deep_fixed_span_error(f, i, j);
                    if (e < best) {
                        best = e;
                        arg = (char)i;
                    }
                }
            best_cur[j] = best;
            parent[k][j] = arg;
        }
        for (int j = 0; j < m; ++j)
            best_prev[j] = best_cur[j];
    }
    int idx[DEEP_FIXED_DP];
    int j = m - 1;
    for (int k = keep - 1; k >= 0; --k) {
        idx[k] = j;
        j = parent[k][j];
    }
    for (int k = 0; k < keep; ++k)
        f->n[k] = f->n[idx[k]]; /* tau and sq are not needed after the exact choice */
    f->cnt = keep;
}

inline void deep_fixed_add(DeepFixed *f, deep_node e)
{
    if (f->cnt == DEEP_FIXED_BUF)
        deep_fixed_reduce(f, DEEP_FIXED_BUF - 1);
    f->tau[f->cnt] = deep_fixed_tau(DEEP_VIS(e));
    f->sq[f->cnt] = f->uniform ? (light_t)(1.0f) : sqrt(DEEP_VIS(e));
    f->n[f->cnt++] = e;
}

/* A light at or inside the box: the buffer's last nodes that lie within tol of the end value
 * (the flat stretch from the material's far side to the box's) become one node at the first of
 * them, holding the end value, so that the budget does not spend a node on the flat stretch
 * (a point light among the spheres: 3 nodes then cover a sphere with two lines, not one). The
 * function moves by at most tol there and still never rises; the first node stays. */
inline void deep_fixed_trim_tail(DeepFixed *f, float tol)
{
    const int m = f->cnt;
    if (m < 3)
        return;
    const light_t v_end = DEEP_VIS(f->n[m - 1]);
    int k = m - 1;
    while (k > 1 && !light_any_gt(DEEP_VIS(f->n[k - 1]) - v_end, (light_t)(tol)))
        --k;
    if (k == m - 1)
        return;
    f->n[k] = DEEP_NODE(DEEP_DEPTH(f->n[k]), v_end);
    f->tau[k] = f->tau[m - 1];
    f->sq[k] = f->sq[m - 1];
    f->cnt = k + 1;
}

__kernel void deep_build_fixed(__global const UmbraFrame *F, VOLUME_PARAM,
                               __global const float4 *view_tf, __global const float4 *light_tf,
                               __global const uchar *view_bricks,
                               __global const ulong *light_cells, __global const UmbraShadow *S,
                               __global const UmbraDeep *D, __global const deep_node *lut,
                               uint use_lut, float eps,
                               __global deep_node *out)
{
    (void)view_tf;
    (void)view_bricks;
    const int n = (int)S->map_size;
    const int gx = (int)get_global_id(0), gy = (int)get_global_id(1);
    if (gx >= n || gy >= n)
        return;
    const int N = (int)D->max_nodes;
    const VolGeom g = vol_geom(F);
    __global deep_node *o = out + (size_t)(gy * n + gx) * (size_t)N;
    DeepTexel st;
    deep_texel_init(&st, S, g, (int2)(gx, gy), eps);
    deep_node e[DEEP_MAX_EMIT];
    DeepFixed fx;
    fx.cnt = 0;
    /* A light at or inside the box: w = 1, and candidates from a finer fit (the march still
     * stops where the unbounded map's does, so the end value is the same). */
    fx.uniform = S->ls_mode == UMBRA_LS_OCTAHEDRAL;
    if (fx.uniform)
        st.eps = eps / DEEP_FIXED_EPS_DIV;
    while (!st.done) {
        int ne = deep_step(&st, F, vol, g, light_tf, light_cells, S, lut, use_lut, e);
        for (int q = 0; q < ne; ++q)
            deep_fixed_add(&fx, e[q]);
    }
    if (fx.uniform && fx.cnt > N)
        deep_fixed_trim_tail(&fx, st.eps);
    if (fx.cnt > N) {
        deep_fixed_reduce(&fx, N < DEEP_FIXED_DP ? DEEP_FIXED_DP : N);
        if (N < DEEP_FIXED_DP)
            deep_fixed_optimal(&fx, N);
    }
    for (int q = 0; q < fx.cnt; ++q)
        o[q] = fx.n[q];
    deep_node fill = fx.cnt > 0 ? fx.n[fx.cnt - 1] : DEEP_NODE(0.0f, (light_t)(1.0f));
    for (int q = fx.cnt; q < N; ++q)
        o[q] = fill;
}
