// SPDX-License-Identifier: Apache-2.0
/* io/paraview.c: transfer functions from ParaView's JSON colour-map presets.
 *
 * ParaView keeps colour maps as JSON (File > Export in the Color Map Editor, or the bundled
 * presets): a list of objects, or one object, each with
 *     "Name"        the preset's name (used to pick one from a list)
 *     "RGBPoints"   [x0, r0, g0, b0, x1, r1, g1, b1, ...]   x ascending, colours in [0,1]
 *     "Points"      [x0, y0, m0, s0, ...]   opacity y in [0,1], midpoint m and sharpness s in
 *                   [0,1] shaping the curve to the next point (optional: without it the
 *                   opacity is ParaView's default ramp, 0 at the first x to 1 at the last)
 *     "ColorSpace"  how colours blend between points: "RGB", "Lab" / "CIELAB", "Diverging" or
 *                   "Step"; "HSV" and "Lab/CIEDE2000" are refused by name (optional: "RGB")
 * Other keys (NanColor, Creator, ...) are ignored. x is in data units (e.g. Hounsfield units).
 *
 * umbra's table is then evaluated entry by entry here, the way VTK evaluates
 * vtkColorTransferFunction and vtkPiecewiseFunction (clamped at both ends): entry i of n at
 * x = lo + i (hi - lo) / (n - 1), where [lo, hi] is the preset's own x range (the smallest and
 * largest x of both arrays) unless the caller gives one. Evaluating rather than handing points to
 * umbra_transfer_function_create_from_points is what lets the non-linear parts (midpoint and
 * sharpness, Lab and diverging blends) come out as ParaView draws them.
 *
 * JSON is parsed by cJSON (Debian's libcjson). Every size a file controls is bounded: the file
 * (PV_MAX_FILE_BYTES), the points per array (PV_MAX_POINTS), JSON nesting (cJSON's own limit).
 * cJSON's parser writes a process-wide error record on every call, so parses are serialised by
 * one lock (the tree it returns is the caller's alone). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "io_internal.h"

#define PV_MAX_FILE_BYTES (64u << 20)
#define PV_MAX_POINTS 65536
#define PV_DEFAULT_RESOLUTION 1024u
#define PV_MIN_RESOLUTION 2u
#define PV_MAX_RESOLUTION 65536u
/* Messages quote at most this much of a name taken from a file. */
#define QUOTE_MAX 200
#define PV_PI 3.14159265358979323846

/* Serialises cJSON_Parse* (its global error record); see the top of the file. */
static pthread_mutex_t cjson_lock = PTHREAD_MUTEX_INITIALIZER;

typedef enum pv_space { PV_RGB, PV_LAB, PV_DIVERGING, PV_STEP } pv_space;

/* A colour node (x, r, g, b) or an opacity node (x, y, midpoint, sharpness). */
typedef struct pv_node {
    double x, v[3];
} pv_node;

typedef struct pv_preset {
    pv_node *color;
    size_t ncolor;
    pv_node *opacity; /* NULL: ParaView's default ramp over [lo, hi] */
    size_t nopacity;
    pv_space space;
    double lo, hi; /* the preset's own x range */
} pv_preset;

void umbra_paraview_options_init(umbra_paraview_options *options)
{
    if (!options) {
        return;
    }
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->preset = NULL;
    options->resolution = PV_DEFAULT_RESOLUTION;
    options->range_given = 0;
    options->range_min = 0.0;
    options->range_max = 1.0;
}

/* ---- colour spaces (VTK's vtkMath conversions: sRGB, D65 white) -------------------------- */

static double srgb_to_linear(double c)
{
    return c > 0.04045 ? pow((c + 0.055) / 1.055, 2.4) : c / 12.92;
}

static double linear_to_srgb(double c)
{
    return c > 0.0031308 ? 1.055 * pow(c, 1.0 / 2.4) - 0.055 : 12.92 * c;
}

static double lab_f(double t)
{
    return t > 0.008856 ? cbrt(t) : 7.787 * t + 16.0 / 116.0;
}

static double lab_finv(double t)
{
    double t3 = t * t * t;
    return t3 > 0.008856 ? t3 : (t - 16.0 / 116.0) / 7.787;
}

static void rgb_to_lab(const double rgb[3], double lab[3])
{
    double r = srgb_to_linear(rgb[0]), g = srgb_to_linear(rgb[1]), b = srgb_to_linear(rgb[2]);
    double x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.9505;
    double y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    double z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.089;
    double fx = lab_f(x), fy = lab_f(y), fz = lab_f(z);
    lab[0] = 116.0 * fy - 16.0;
    lab[1] = 500.0 * (fx - fy);
    lab[2] = 200.0 * (fy - fz);
}

/* Back to sRGB; colours outside the gamut are scaled down by their largest channel and negative
 * channels clipped, as VTK does. */
static void lab_to_rgb(const double lab[3], double rgb[3])
{
    double fy = (lab[0] + 16.0) / 116.0;
    double x = 0.9505 * lab_finv(lab[1] / 500.0 + fy);
    double y = lab_finv(fy);
    double z = 1.089 * lab_finv(fy - lab[2] / 200.0);
    double c[3], m;
    int i;
    c[0] = 3.2406 * x - 1.5372 * y - 0.4986 * z;
    c[1] = -0.9689 * x + 1.8758 * y + 0.0415 * z;
    c[2] = 0.0557 * x - 0.2040 * y + 1.0570 * z;
    for (i = 0; i < 3; ++i) {
        c[i] = linear_to_srgb(c[i]);
    }
    m = fmax(c[0], fmax(c[1], c[2]));
    for (i = 0; i < 3; ++i) {
        if (m > 1.0) {
            c[i] /= m;
        }
        rgb[i] = c[i] < 0.0 ? 0.0 : c[i];
    }
}

/* Moreland's Msh space ("Diverging Color Maps for Scientific Visualization", 2009). */
static void lab_to_msh(const double lab[3], double msh[3])
{
    double m = sqrt(lab[0] * lab[0] + lab[1] * lab[1] + lab[2] * lab[2]);
    msh[0] = m;
    msh[1] = m > 0.001 ? acos(lab[0] / m) : 0.0;
    msh[2] = msh[1] > 0.001 ? atan2(lab[2], lab[1]) : 0.0;
}

static void msh_to_lab(const double msh[3], double lab[3])
{
    lab[0] = msh[0] * cos(msh[1]);
    lab[1] = msh[0] * sin(msh[1]) * cos(msh[2]);
    lab[2] = msh[0] * sin(msh[1]) * sin(msh[2]);
}

static double angle_diff(double a, double b)
{
    const double two_pi = 2.0 * PV_PI;
    double d = fabs(a - b);
    d = fmod(d, two_pi);
    return d > PV_PI ? two_pi - d : d;
}

/* The hue an unsaturated colour of magnitude m should take next to the saturated msh. */
static double adjust_hue(const double msh[3], double m)
{
    double spin;
    if (msh[0] >= m - 0.1) {
        return msh[2];
    }
    spin = msh[1] * sqrt(m * m - msh[0] * msh[0]) / (msh[0] * sin(msh[1]));
    return msh[2] > -0.3 * PV_PI ? msh[2] + spin : msh[2] - spin;
}

static void blend_diverging(const double a[3], const double b[3], double s, double out[3])
{
    double lab1[3], lab2[3], msh1[3], msh2[3], msh[3], lab[3];
    int i;
    rgb_to_lab(a, lab1);
    rgb_to_lab(b, lab2);
    lab_to_msh(lab1, msh1);
    lab_to_msh(lab2, msh2);
    /* Two distinct saturated ends get white (of at least magnitude 88) between them. */
    if (msh1[1] > 0.05 && msh2[1] > 0.05 && angle_diff(msh1[2], msh2[2]) > 0.33 * PV_PI) {
        double mid = fmax(88.0, fmax(msh1[0], msh2[0]));
        if (s < 0.5) {
            msh2[0] = mid;
            msh2[1] = 0.0;
            msh2[2] = 0.0;
            s = 2.0 * s;
        } else {
            msh1[0] = mid;
            msh1[1] = 0.0;
            msh1[2] = 0.0;
            s = 2.0 * s - 1.0;
        }
    }
    /* An unsaturated end has no meaningful hue: borrow one from the other end. */
    if (msh1[1] < 0.05 && msh2[1] > 0.05) {
        msh1[2] = adjust_hue(msh2, msh1[0]);
    } else if (msh2[1] < 0.05 && msh1[1] > 0.05) {
        msh2[2] = adjust_hue(msh1, msh2[0]);
    }
    for (i = 0; i < 3; ++i) {
        msh[i] = (1.0 - s) * msh1[i] + s * msh2[i];
    }
    msh_to_lab(msh, lab);
    lab_to_rgb(lab, out);
}

static void blend(pv_space space, const double a[3], const double b[3], double s, double out[3])
{
    int i;
    if (space == PV_LAB) {
        double la[3], lb[3], l[3];
        rgb_to_lab(a, la);
        rgb_to_lab(b, lb);
        for (i = 0; i < 3; ++i) {
            l[i] = (1.0 - s) * la[i] + s * lb[i];
        }
        lab_to_rgb(l, out);
    } else if (space == PV_DIVERGING) {
        blend_diverging(a, b, s, out);
    } else if (space == PV_STEP) {
        /* vtkColorTransferFunction's step: each node's colour holds until the next node. */
        for (i = 0; i < 3; ++i) {
            out[i] = a[i];
        }
    } else {
        for (i = 0; i < 3; ++i) {
            out[i] = (1.0 - s) * a[i] + s * b[i];
        }
    }
}

/* ---- evaluation ------------------------------------------------------------------------- */

/* The segment of nodes (ascending x) holding x: *i such that node[*i].x <= x < node[*i+1].x;
 * returns 0 with *i = 0 before the first node, *i = n-1 at or after the last (clamped ends). The
 * walk starts from the previous *i, as the table is filled in ascending x. */
static int find_segment(const pv_node *node, size_t n, double x, size_t *i)
{
    if (x < node[0].x) {
        *i = 0;
        return 0;
    }
    while (*i + 1 < n && x >= node[*i + 1].x) {
        ++*i;
    }
    return *i + 1 < n;
}

/* vtkPiecewiseFunction's curve between (x1, y1) and (x2, y2) at s in [0,1): the midpoint moves
 * where the curve reaches the mean, sharpness goes from linear (0) to a step (1). */
static double opacity_curve(double y1, double y2, double midpoint, double sharpness, double s)
{
    double ss, sss, t, v;
    midpoint = fmin(fmax(midpoint, 0.00001), 0.99999);
    s = s < midpoint ? 0.5 * s / midpoint : 0.5 + 0.5 * (s - midpoint) / (1.0 - midpoint);
    if (sharpness > 0.99) {
        return s < 0.5 ? y1 : y2;
    }
    if (sharpness < 0.01) {
        return (1.0 - s) * y1 + s * y2;
    }
    if (s < 0.5) {
        s = 0.5 * pow(2.0 * s, 1.0 + 10.0 * sharpness);
    } else if (s > 0.5) {
        s = 1.0 - 0.5 * pow(2.0 * (1.0 - s), 1.0 + 10.0 * sharpness);
    }
    ss = s * s;
    sss = ss * s;
    t = (1.0 - sharpness) * (y2 - y1);
    v = (2 * sss - 3 * ss + 1) * y1 + (-2 * sss + 3 * ss) * y2 + (sss - 2 * ss + s) * t +
        (sss - ss) * t;
    return fmin(fmax(v, fmin(y1, y2)), fmax(y1, y2));
}

/* Fills n RGBA entries over [lo, hi]. */
static void evaluate(const pv_preset *p, double lo, double hi, uint32_t n, float *rgba)
{
    size_t ci = 0, oi = 0;
    uint32_t e;
    for (e = 0; e < n; ++e) {
        double x = lo + (hi - lo) * ((double)e / (double)(n - 1));
        double rgb[3], a;
        int k;
        if (e == n - 1) {
            x = hi; /* exact, whatever the rounding above */
        }
        if (find_segment(p->color, p->ncolor, x, &ci)) {
            const pv_node *c0 = &p->color[ci], *c1 = &p->color[ci + 1];
            blend(p->space, c0->v, c1->v, (x - c0->x) / (c1->x - c0->x), rgb);
        } else {
            memcpy(rgb, p->color[ci].v, sizeof rgb);
        }
        if (!p->opacity) {
            a = fmin(fmax((x - p->lo) / (p->hi - p->lo), 0.0), 1.0);
        } else if (find_segment(p->opacity, p->nopacity, x, &oi)) {
            const pv_node *o0 = &p->opacity[oi], *o1 = &p->opacity[oi + 1];
            a = opacity_curve(o0->v[0], o1->v[0], o0->v[1], o0->v[2],
                              (x - o0->x) / (o1->x - o0->x));
        } else {
            a = p->opacity[oi].v[0];
        }
        for (k = 0; k < 3; ++k) {
            rgba[4 * e + k] = (float)fmin(fmax(rgb[k], 0.0), 1.0);
        }
        rgba[4 * e + 3] = (float)fmin(fmax(a, 0.0), 1.0);
    }
}

/* ---- parsing ------------------------------------------------------------------------------ */

/* 1-based line and column of byte offset off in text. */
static void text_position(const char *text, size_t off, unsigned long *line, unsigned long *col)
{
    size_t i;
    *line = 1;
    *col = 1;
    for (i = 0; i < off; ++i) {
        if (text[i] == '\n') {
            ++*line;
            *col = 1;
        } else {
            ++*col;
        }
    }
}

/* Reads the array key of preset obj into nodes of 4 numbers each. Colours (opacity == 0) need
 * r, g, b in [0,1]; opacity nodes need y, midpoint and sharpness in [0,1]. x must be finite and
 * ascending (equal x make a step). A missing key is *nodes = NULL and success. */
static umbra_status read_nodes(umbra_context ctx, const char *func, const char *path,
                               const char *name, const cJSON *obj, const char *key, int opacity,
                               pv_node **nodes, size_t *count)
{
    static const char *const color_names[4] = {"x", "red", "green", "blue"};
    static const char *const opacity_names[4] = {"x", "opacity", "midpoint", "sharpness"};
    const char *const *names = opacity ? opacity_names : color_names;
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(obj, key);
    const cJSON *item;
    size_t n = 0, i = 0;
    pv_node *out;

    *nodes = NULL;
    *count = 0;
    if (!arr) {
        return UMBRA_SUCCESS;
    }
    if (!cJSON_IsArray(arr)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": %s is not an array of numbers", func, path,
                           QUOTE_MAX, name, key);
    }
    cJSON_ArrayForEach(item, arr)
    {
        if (++n > 4u * PV_MAX_POINTS) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: preset \"%.*s\": %s has more than %d points (the limit)",
                               func, path, QUOTE_MAX, name, key, PV_MAX_POINTS);
        }
    }
    if (n == 0 || n % 4 != 0) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": %s has %zu numbers; expected a positive "
                           "multiple of 4 (%s)",
                           func, path, QUOTE_MAX, name, key, n,
                           opacity ? "x, opacity, midpoint, sharpness" : "x, r, g, b");
    }
    out = malloc((n / 4) * sizeof *out);
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu points",
                           func, n / 4);
    }
    cJSON_ArrayForEach(item, arr)
    {
        size_t p = i / 4, k = i % 4;
        double v;
        if (!cJSON_IsNumber(item)) {
            free(out);
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: preset \"%.*s\": %s[%zu] (%s of point %zu) is not a "
                               "number",
                               func, path, QUOTE_MAX, name, key, i, names[k], p);
        }
        v = item->valuedouble;
        if (!isfinite(v)) {
            free(out);
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: preset \"%.*s\": %s[%zu] (%s of point %zu) is not finite",
                               func, path, QUOTE_MAX, name, key, i, names[k], p);
        }
        if (k > 0 && (v < 0.0 || v > 1.0)) {
            free(out);
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: preset \"%.*s\": %s[%zu] = %g (%s of point %zu) is not in "
                               "[0,1]",
                               func, path, QUOTE_MAX, name, key, i, v, names[k], p);
        }
        if (k == 0) {
            if (p > 0 && v < out[p - 1].x) {
                double prev = out[p - 1].x;
                free(out);
                return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                   "%s: %s: preset \"%.*s\": %s point %zu has x = %g below point "
                                   "%zu's %g (x must ascend)",
                                   func, path, QUOTE_MAX, name, key, p, v, p - 1, prev);
            }
            out[p].x = v;
        } else {
            out[p].v[k - 1] = v;
        }
        ++i;
    }
    *nodes = out;
    *count = n / 4;
    return UMBRA_SUCCESS;
}

/* The preset object named want (or the first when want is NULL) in root, a list or one object. */
static umbra_status find_preset(umbra_context ctx, const char *func, const char *path,
                                const cJSON *root, const char *want, const cJSON **out)
{
    const cJSON *item;
    size_t index = 0;
    *out = NULL;
    if (cJSON_IsObject(root)) {
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(root, "Name"));
        if (want && (!name || strcmp(name, want) != 0)) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: no preset named \"%.*s\" (the file holds one preset, "
                               "\"%.*s\")",
                               func, path, QUOTE_MAX, want, QUOTE_MAX, name ? name : "");
        }
        *out = root;
        return UMBRA_SUCCESS;
    }
    if (!cJSON_IsArray(root)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: expected a preset object or a list of them at the top level",
                           func, path);
    }
    cJSON_ArrayForEach(item, root)
    {
        const char *name;
        if (!cJSON_IsObject(item)) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: list item %zu is not a preset object", func, path, index);
        }
        name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(item, "Name"));
        if (!want || (name && strcmp(name, want) == 0)) {
            *out = item;
            return UMBRA_SUCCESS;
        }
        ++index;
    }
    if (want) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: %s: no preset named \"%.*s\" among %zu",
                           func, path, QUOTE_MAX, want, index);
    }
    return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: %s: the list of presets is empty", func,
                       path);
}

static umbra_status read_preset(umbra_context ctx, const char *func, const char *path,
                                const cJSON *obj, pv_preset *p)
{
    const cJSON *space = cJSON_GetObjectItemCaseSensitive(obj, "ColorSpace");
    const cJSON *name_item = cJSON_GetObjectItemCaseSensitive(obj, "Name");
    const char *name = cJSON_IsString(name_item) ? name_item->valuestring : "";
    umbra_status st;

    if (name_item && !cJSON_IsString(name_item)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: %s: a preset's Name is not a string",
                           func, path);
    }
    p->space = PV_RGB;
    if (space) {
        const char *s = cJSON_GetStringValue(space);
        if (!s) {
            return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                               "%s: %s: preset \"%.*s\": ColorSpace is not a string", func, path,
                               QUOTE_MAX, name);
        }
        if (strcmp(s, "RGB") == 0) {
            p->space = PV_RGB;
        } else if (strcmp(s, "Lab") == 0 || strcmp(s, "CIELAB") == 0) {
            p->space = PV_LAB;
        } else if (strcmp(s, "Diverging") == 0) {
            p->space = PV_DIVERGING;
        } else if (strcmp(s, "Step") == 0) {
            p->space = PV_STEP;
        } else {
            return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: %s: preset \"%.*s\": ColorSpace \"%.*s\" is not supported "
                               "(RGB, Lab, CIELAB, Diverging, Step)",
                               func, path, QUOTE_MAX, name, QUOTE_MAX, s);
        }
    }
    st = read_nodes(ctx, func, path, name, obj, "RGBPoints", 0, &p->color, &p->ncolor);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    if (!p->color) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\" has no RGBPoints%s", func, path, QUOTE_MAX,
                           name,
                           cJSON_GetObjectItemCaseSensitive(obj, "IndexedColors")
                               ? " (categorical IndexedColors presets are not supported)"
                               : "");
    }
    st = read_nodes(ctx, func, path, name, obj, "Points", 1, &p->opacity, &p->nopacity);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    p->lo = p->color[0].x;
    p->hi = p->color[p->ncolor - 1].x;
    if (p->opacity) {
        p->lo = fmin(p->lo, p->opacity[0].x);
        p->hi = fmax(p->hi, p->opacity[p->nopacity - 1].x);
    }
    if (!(p->hi > p->lo) || !isfinite(p->hi - p->lo)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": its points span [%g, %g]; they need two "
                           "distinct x a finite distance apart",
                           func, path, QUOTE_MAX, name, p->lo, p->hi);
    }
    return UMBRA_SUCCESS;
}

umbra_status umbra_transfer_function_load_paraview(umbra_context ctx, const char *path,
                                                   const umbra_paraview_options *options,
                                                   umbra_transfer_function *out, double range[2])
{
    umbra_status st = UMBRA_SUCCESS;
    umbra_paraview_options opt;
    void *buf = NULL;
    size_t size = 0;
    cJSON *root = NULL;
    const cJSON *obj = NULL;
    const char *end = NULL;
    pv_preset preset;
    float *rgba = NULL;
    double lo, hi;
    struct stat sb;

    memset(&preset, 0, sizeof preset);
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", __func__);
    }
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: path is NULL", __func__);
    }
    umbra_paraview_options_init(&opt);
    if (options) {
        if (options->struct_size != sizeof opt) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: options->struct_size is %zu, expected %zu (call "
                               "umbra_paraview_options_init)",
                               __func__, options->struct_size, sizeof opt);
        }
        opt = *options;
    }
    if (opt.resolution < PV_MIN_RESOLUTION || opt.resolution > PV_MAX_RESOLUTION) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: resolution %u is not in %u..%u", __func__, opt.resolution,
                           PV_MIN_RESOLUTION, PV_MAX_RESOLUTION);
    }
    if (opt.range_given && (!isfinite(opt.range_min) || !isfinite(opt.range_max) ||
                            !(opt.range_max > opt.range_min) ||
                            !isfinite(opt.range_max - opt.range_min))) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: range [%g, %g] is not finite with min < max", __func__,
                           opt.range_min, opt.range_max);
    }
    /* The size limit is checked before reading; umbra__read_file checks the file is regular. */
    if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode) && (uintmax_t)sb.st_size > PV_MAX_FILE_BYTES) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" holds %jd bytes, more than a preset may (%u)", __func__,
                           path, (intmax_t)sb.st_size, PV_MAX_FILE_BYTES);
    }
    st = umbra__read_file(ctx, __func__, path, &buf, &size);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    if (size > PV_MAX_FILE_BYTES) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu bytes, more than a preset may (%u)", __func__, path,
                         size, PV_MAX_FILE_BYTES);
        goto fail;
    }
    /* With require_null_terminated cJSON wants the terminating NUL inside the length; a NUL
     * within the file would end the text early, so it is refused first. */
    if (memchr(buf, '\0', size)) {
        unsigned long line = 0, col = 0;
        text_position(buf, (size_t)((const char *)memchr(buf, '\0', size) - (const char *)buf),
                      &line, &col);
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: %s:%lu:%lu: NUL byte (not a text file?)",
                         __func__, path, line, col);
        goto fail;
    }
    pthread_mutex_lock(&cjson_lock);
    root = cJSON_ParseWithLengthOpts(buf, size + 1, &end, 1);
    pthread_mutex_unlock(&cjson_lock);
    if (!root) {
        unsigned long line = 0, col = 0;
        size_t off = (end && end >= (const char *)buf && end <= (const char *)buf + size)
                         ? (size_t)(end - (const char *)buf)
                         : size;
        text_position(buf, off, &line, &col);
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: %s:%lu:%lu: malformed JSON (or nested deeper than %d)", __func__,
                         path, line, col, CJSON_NESTING_LIMIT);
        goto fail;
    }
    st = find_preset(ctx, __func__, path, root, opt.preset, &obj);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    st = read_preset(ctx, __func__, path, obj, &preset);
    if (st != UMBRA_SUCCESS) {
        goto fail;
    }
    lo = opt.range_given ? opt.range_min : preset.lo;
    hi = opt.range_given ? opt.range_max : preset.hi;
    rgba = malloc((size_t)opt.resolution * 4 * sizeof *rgba);
    if (!rgba) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %u table entries",
                         __func__, opt.resolution);
        goto fail;
    }
    evaluate(&preset, lo, hi, opt.resolution, rgba);
    /* The table spans lo..hi in data units: the renderer places it over each volume's range. */
    st = umbra_transfer_function_create(ctx, rgba, opt.resolution, out);
    if (st == UMBRA_SUCCESS) {
        st = umbra_transfer_function_set_range(*out, (float)lo, (float)hi);
        if (st != UMBRA_SUCCESS) {
            umbra_transfer_function_release(*out);
            *out = NULL;
        }
    }
    if (st == UMBRA_SUCCESS && range) {
        range[0] = lo;
        range[1] = hi;
    }

fail:
    free(rgba);
    free(preset.color);
    free(preset.opacity);
    cJSON_Delete(root);
    free(buf);
    return st;
}
