// SPDX-License-Identifier: Apache-2.0
/* host/world.c: the application's world and data units.
 *
 * A volume may carry an index-to-world transform (include/umbra/volume.h); the kernels keep
 * working in the volume's local frame (the centred, axis-aligned box of dims * spacing), and the
 * host maps what the application gives in the world into it: points and directions here, the
 * camera and lights in host/renderer.c, the ground plane (horizontal in the world) here. The map
 * is rigid, so steps, distances and opacities keep their meaning. Without a transform every map
 * copies its input, so default scenes render bit for bit as before.
 *
 * Transfer functions with a data range (include/umbra/transfer_function.h) are resampled onto the
 * volume's normalised range (host/transfer_function.c); the renderer keeps the tables in effect
 * here, and every technique reads those. */
#include <math.h>
#include <string.h>

#include "renderer_internal.h"

static double dot3d(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Largest |cos| between two index axes accepted as a right angle: 1e-3 is 0.057 degrees, what a
 * header printed with 6 digits (or float rounding) leaves; a gantry tilt is degrees. */
#define AXIS_COS_TOLERANCE 1e-3

/* The transform of desc (validated) into v: unit axes, checked for right angles and snapped to an
 * exactly orthonormal set (Gram-Schmidt, keeping axis 0 and the handedness), so the world ->
 * local map is exactly its inverse's transpose and preserves distances. */
umbra_status umbra__volume_set_transform(umbra_context ctx, const umbra_volume_desc *d,
                                         umbra_volume v)
{
    const char *fn = "umbra_volume_create";
    double ax[3][3];
    for (int a = 0; a < 3; ++a)
        v->centre0[a] = (0.5 - 0.5 * (double)d->dims[a]) * (double)d->spacing[a];
    if (!d->transform_given) {
        for (int a = 0; a < 3; ++a) {
            v->origin[a] = v->centre0[a];
            for (int k = 0; k < 3; ++k)
                v->axes[3 * a + k] = a == k ? 1.0 : 0.0;
        }
        return UMBRA_SUCCESS;
    }
    for (int a = 0; a < 3; ++a) {
        if (!isfinite(d->origin[a]))
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: origin (%g, %g, %g) must be finite", fn, d->origin[0],
                               d->origin[1], d->origin[2]);
        for (int k = 0; k < 3; ++k)
            ax[a][k] = d->directions[3 * a + k];
        double len = sqrt(dot3d(ax[a], ax[a]));
        if (!(len > 0.0) || !isfinite(len))
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: direction of index axis %d (%g, %g, %g) must be finite and "
                               "non-zero", fn, a, ax[a][0], ax[a][1], ax[a][2]);
        for (int k = 0; k < 3; ++k)
            ax[a][k] /= len;
    }
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
            double c = dot3d(ax[a], ax[b]);
            if (fabs(c) > AXIS_COS_TOLERANCE)
                return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                                   "%s: index axes %d and %d meet at %.3f degrees; only "
                                   "orthogonal grids are supported (at most %.3f degrees off a "
                                   "right angle), not sheared ones (such as a CT gantry tilt): "
                                   "resample the volume first", fn, a, b,
                                   acos(fmax(-1.0, fmin(1.0, c))) * 57.29577951308232,
                                   asin(AXIS_COS_TOLERANCE) * 57.29577951308232);
        }
    /* Handedness of the given axes, kept by the snapped third axis. */
    double cr[3] = {ax[0][1] * ax[1][2] - ax[0][2] * ax[1][1],
                    ax[0][2] * ax[1][0] - ax[0][0] * ax[1][2],
                    ax[0][0] * ax[1][1] - ax[0][1] * ax[1][0]};
    double hand = dot3d(cr, ax[2]) < 0.0 ? -1.0 : 1.0;
    double c01 = dot3d(ax[0], ax[1]);
    for (int k = 0; k < 3; ++k)
        ax[1][k] -= c01 * ax[0][k];
    double l1 = sqrt(dot3d(ax[1], ax[1]));
    for (int k = 0; k < 3; ++k)
        ax[1][k] /= l1;
    ax[2][0] = hand * (ax[0][1] * ax[1][2] - ax[0][2] * ax[1][1]);
    ax[2][1] = hand * (ax[0][2] * ax[1][0] - ax[0][0] * ax[1][2]);
    ax[2][2] = hand * (ax[0][0] * ax[1][1] - ax[0][1] * ax[1][0]);
    v->transformed = 1;
    for (int a = 0; a < 3; ++a) {
        v->origin[a] = d->origin[a];
        for (int k = 0; k < 3; ++k)
            v->axes[3 * a + k] = ax[a][k];
    }
    return UMBRA_SUCCESS;
}

void umbra__volume_point_to_local(umbra_volume v, const float w[3], float out[3])
{
    if (!v->transformed) {
        memcpy(out, w, 3 * sizeof *out);
        return;
    }
    double q[3] = {(double)w[0] - v->origin[0], (double)w[1] - v->origin[1],
                   (double)w[2] - v->origin[2]};
    for (int a = 0; a < 3; ++a)
        out[a] = (float)(dot3d(v->axes + 3 * a, q) + v->centre0[a]);
}

void umbra__volume_dir_to_local(umbra_volume v, const float w[3], float out[3])
{
    if (!v->transformed) {
        memcpy(out, w, 3 * sizeof *out);
        return;
    }
    double q[3] = {w[0], w[1], w[2]};
    for (int a = 0; a < 3; ++a)
        out[a] = (float)dot3d(v->axes + 3 * a, q);
}

void umbra__volume_point_to_world(umbra_volume v, const float l[3], double out[3])
{
    if (!v->transformed) {
        for (int k = 0; k < 3; ++k)
            out[k] = l[k];
        return;
    }
    for (int k = 0; k < 3; ++k) {
        out[k] = v->origin[k];
        for (int a = 0; a < 3; ++a)
            out[k] += v->axes[3 * a + k] * ((double)l[a] - v->centre0[a]);
    }
}

/* The ground plane as (n, w), n.p + w = 0 in the local frame: horizontal (y up) in the world,
 * gap below the box's lowest world point. Without a transform that is n = (0, 1, 0) and
 * w = -y0, computed as it always was. */
void umbra__ground_plane(umbra_volume v, const float ext[3], float gap, float plane[4])
{
    if (!v->transformed) {
        float y0 = -0.5f * ext[1] - gap;
        plane[0] = 0.0f;
        plane[1] = 1.0f;
        plane[2] = 0.0f;
        plane[3] = -y0;
        return;
    }
    double lowest = INFINITY;
    for (int c = 0; c < 8; ++c) {
        float corner[3];
        double w[3];
        for (int a = 0; a < 3; ++a)
            corner[a] = ((c >> a) & 1 ? 0.5f : -0.5f) * ext[a];
        umbra__volume_point_to_world(v, corner, w);
        lowest = fmin(lowest, w[1]);
    }
    /* World plane y = y0; with w = origin + sum_a axes_a (l_a - centre0_a), its local normal is
     * n_a = axes_a.y and n.l + (origin.y - y0 - n.centre0) = 0. */
    double y0 = lowest - gap, off = v->origin[1] - y0;
    for (int a = 0; a < 3; ++a) {
        plane[a] = (float)v->axes[3 * a + 1];
        off -= v->axes[3 * a + 1] * v->centre0[a];
    }
    plane[3] = (float)off;
}

umbra_transfer_function umbra__view_tf(umbra_renderer r) { return r->view_eff; }
umbra_transfer_function umbra__light_tf(umbra_renderer r) { return r->light_eff; }

/* Keeps *eff equal to umbra__tf_for_volume(tf, channel c's range), re-made when either changed
 * (a volume's ranges never change: an update keeps them). A label map's table is indexed by
 * label, whatever data range it was given: it is used as it is. */
static umbra_status effective_tf(umbra_renderer r, umbra_transfer_function tf, uint32_t c,
                                 umbra_transfer_function *eff, uint64_t key[2])
{
    const uint64_t want[2] = {tf->id, r->volume->id};
    if (*eff && memcmp(want, key, sizeof want) == 0)
        return UMBRA_SUCCESS;
    umbra_transfer_function made = tf;
    umbra_status st = UMBRA_SUCCESS;
    if (r->volume->labels)
        umbra_transfer_function_retain(tf);
    else
        st = umbra__tf_for_volume(tf, r->volume->channel_range[c][0],
                                  r->volume->channel_range[c][1], &made);
    if (st != UMBRA_SUCCESS)
        return st;
    umbra_transfer_function_release(*eff);
    *eff = made;
    memcpy(key, want, sizeof want);
    r->rebuilds.effective++;
    return UMBRA_SUCCESS;
}

umbra_status umbra__effective_tfs(umbra_renderer r)
{
    umbra_status st = effective_tf(r, r->tf, 0, &r->view_eff, r->view_eff_key);
    if (st == UMBRA_SUCCESS)
        st = effective_tf(r, r->light_tf ? r->light_tf : r->tf, 0, &r->light_eff,
                          r->light_eff_key);
    /* Channels 1.. of a multi-channel volume (umbra__check_channels has found them set). */
    for (uint32_t c = 1; c < r->volume->channels && st == UMBRA_SUCCESS; ++c) {
        st = effective_tf(r, r->ch_tf[c], c, &r->ch_view_eff[c], r->ch_view_eff_key[c]);
        if (st == UMBRA_SUCCESS)
            st = effective_tf(r, r->ch_light_tf[c] ? r->ch_light_tf[c] : r->ch_tf[c], c,
                              &r->ch_light_eff[c], r->ch_light_eff_key[c]);
    }
    return st;
}
