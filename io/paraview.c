// SPDX-License-Identifier: Apache-2.0
/* io/paraview.c: transfer functions from ParaView's JSON colour-map presets.
 *
 * ParaView keeps colour maps as JSON (File > Export in the Color Map Editor, or the bundled
 * presets): a list of objects, or one object, each with
 *     "Name"          the preset's name (used to pick one from a list, or from the search path)
 *     "RGBPoints"     [x0, r0, g0, b0, x1, r1, g1, b1, ...]   x ascending, colours in [0,1]
 *     "Points"        [x0, y0, m0, s0, ...]   opacity y in [0,1], midpoint m and sharpness s in
 *                     [0,1] shaping the curve to the next point (optional: ParaView's presets
 *                     carry none; umbra then uses its documented default, see below)
 *     "ColorSpace"    how colours blend between points: "RGB", "HSV", "Lab" / "CIELAB",
 *                     "Diverging" or "Step"; "Lab/CIEDE2000" is refused by name (optional: "RGB")
 *     "HSVWrap"       HSV blends take the shorter way round the hue circle (optional: false,
 *                     ParaView's default)
 *     "IndexedColors" [r0, g0, b0, r1, ...]   a categorical preset: colour k % n for the k-th
 *                     annotated value
 *     "Annotations"   [value0, label0, value1, label1, ...]   the categories' data values
 *                     (numbers or numeric strings); without it the values are 0 .. n-1
 * Other keys (NanColor, Creator, ...) are ignored. x is in data units (e.g. Hounsfield units).
 *
 * umbra's table is then evaluated entry by entry here, the way VTK evaluates
 * vtkColorTransferFunction and vtkPiecewiseFunction (clamped at both ends): entry i of n at
 * x = lo + i (hi - lo) / (n - 1), where [lo, hi] is the preset's own x range (the smallest and
 * largest x of both arrays; for a categorical preset its values +-0.5) unless the caller gives
 * one. Evaluating rather than handing points to umbra_transfer_function_create_from_points is
 * what lets the non-linear parts (midpoint and sharpness, HSV, Lab and diverging blends) come
 * out as ParaView draws them. A categorical preset becomes a step table: an entry within 0.5 of
 * an annotated value takes that category's colour, any other entry is transparent black.
 * Without "Points" the opacity is options->default_opacity: a linear ramp from 0 at the lowest x
 * to it at the highest, or that constant for every category.
 *
 * JSON is parsed by cJSON (Debian's libcjson). Every size a file controls is bounded: the file
 * (PV_MAX_FILE_BYTES), the JSON values in it (PV_MAX_VALUES, counted by a scan of the text before
 * cJSON allocates anything: cJSON keeps ~80 bytes per value, so a 62 MiB file of "0," took 2.8 GB
 * and 14 s before the count existed), the points per array (PV_MAX_POINTS), JSON nesting
 * (cJSON's own limit). cJSON's parser writes a process-wide error record on every call, so parses
 * are serialised by one lock (the tree it returns is the caller's alone). Finding a preset by
 * name in the search path lives in io/paraview_search.c. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "paraview.h"

#define PV_MAX_FILE_BYTES (64u << 20)
#define PV_MAX_POINTS 65536
/* Two arrays of PV_MAX_POINTS points at 4 numbers each are 2^19 values: twice that leaves room
 * for files of many presets (ParaView 5.11's 195 presets are about 17,000 values). */
#define PV_MAX_VALUES (1u << 20)
/* A categorical preset's table gives each annotated value at least this many entries. */
#define PV_ENTRIES_PER_CATEGORY 4
#define PV_DEFAULT_RESOLUTION 1024u
#define PV_MIN_RESOLUTION 2u
#define PV_MAX_RESOLUTION 65536u
/* Messages quote at most this much of a name taken from a file. */
#define QUOTE_MAX 200

/* Serialises cJSON_Parse* (its global error record); see the top of the file. */
static pthread_mutex_t cjson_lock = PTHREAD_MUTEX_INITIALIZER;

/* A colour node (x, r, g, b), an opacity node (x, y, midpoint, sharpness) or a category (its
 * value x and colour). */
typedef struct pv_node {
    double x, v[3];
} pv_node;

typedef struct pv_preset {
    pv_node *color;   /* continuous: RGBPoints; categorical: the categories, ascending x */
    size_t ncolor;
    int categorical;
    pv_node *opacity; /* NULL: the default opacity (see the top of the file) */
    size_t nopacity;
    pv_space space;
    int hsv_wrap;
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
    options->default_opacity = UMBRA_PARAVIEW_DEFAULT_OPACITY;
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

/* The category nearest x among n ascending values, walking on from *i (the table is filled in
 * ascending x); returns 1 if it lies within 0.5 of x. */
static int find_category(const pv_node *node, size_t n, double x, size_t *i)
{
    while (*i + 1 < n && fabs(node[*i + 1].x - x) <= fabs(node[*i].x - x)) {
        ++*i;
    }
    return fabs(node[*i].x - x) <= 0.5;
}

/* Fills n RGBA entries over [lo, hi]; default_opacity as options->default_opacity. */
static void evaluate(const pv_preset *p, double lo, double hi, double default_opacity,
                     uint32_t n, float *rgba)
{
    size_t ci = 0, oi = 0;
    uint32_t e;
    for (e = 0; e < n; ++e) {
        double x = lo + (hi - lo) * ((double)e / (double)(n - 1));
        double rgb[3], a;
        int k, inside = 1;
        if (e == n - 1) {
            x = hi; /* exact, whatever the rounding above */
        }
        if (p->categorical) {
            inside = find_category(p->color, p->ncolor, x, &ci);
            memcpy(rgb, p->color[ci].v, sizeof rgb);
        } else if (find_segment(p->color, p->ncolor, x, &ci)) {
            const pv_node *c0 = &p->color[ci], *c1 = &p->color[ci + 1];
            umbra__pv_blend(p->space, p->hsv_wrap, c0->v, c1->v, (x - c0->x) / (c1->x - c0->x), rgb);
        } else {
            memcpy(rgb, p->color[ci].v, sizeof rgb);
        }
        if (!p->opacity) {
            a = p->categorical ? default_opacity
                               : default_opacity * fmin(fmax((x - p->lo) / (p->hi - p->lo), 0.0),
                                                        1.0);
        } else if (find_segment(p->opacity, p->nopacity, x, &oi)) {
            const pv_node *o0 = &p->opacity[oi], *o1 = &p->opacity[oi + 1];
            a = opacity_curve(o0->v[0], o1->v[0], o0->v[1], o0->v[2],
                              (x - o0->x) / (o1->x - o0->x));
        } else {
            a = p->opacity[oi].v[0];
        }
        if (!inside) {
            rgb[0] = rgb[1] = rgb[2] = a = 0.0; /* a value no category claims */
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

static int compare_nodes(const void *a, const void *b)
{
    double x = ((const pv_node *)a)->x, y = ((const pv_node *)b)->x;
    return (x > y) - (x < y);
}

/* An annotated value: a number, or a string holding one JSON number (ParaView writes both). */
static int annotation_value(const cJSON *item, double *v)
{
    if (cJSON_IsNumber(item)) {
        *v = item->valuedouble;
        return isfinite(*v);
    }
    if (cJSON_IsString(item) && item->valuestring[0] != '\0') {
        cJSON *n;
        int ok;
        pthread_mutex_lock(&cjson_lock);
        n = cJSON_ParseWithOpts(item->valuestring, NULL, 1);
        pthread_mutex_unlock(&cjson_lock);
        ok = cJSON_IsNumber(n) && isfinite(n->valuedouble);
        if (ok) {
            *v = n->valuedouble;
        }
        cJSON_Delete(n);
        return ok;
    }
    return 0;
}

/* A categorical preset: IndexedColors (r, g, b triples in [0,1]) for the values of Annotations
 * (value, label pairs), or for 0 .. n-1 without it; category k takes colour k % n. The categories
 * land in p->color in ascending value, which must be distinct. */
static umbra_status read_categorical(umbra_context ctx, const char *func, const char *path,
                                     const char *name, const cJSON *obj, const cJSON *colors,
                                     pv_preset *p)
{
    const cJSON *ann = cJSON_GetObjectItemCaseSensitive(obj, "Annotations");
    const cJSON *item;
    size_t ncolors = 0, nann = 0, ncat, i = 0, k;
    double *rgb = NULL;
    umbra_status st = UMBRA_SUCCESS;

    if (!cJSON_IsArray(colors)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": IndexedColors is not an array of numbers",
                           func, path, QUOTE_MAX, name);
    }
    cJSON_ArrayForEach(item, colors)
    {
        ++ncolors;
    }
    if (ncolors == 0 || ncolors % 3 != 0 || ncolors > 3u * PV_MAX_POINTS) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": IndexedColors has %zu numbers; expected a "
                           "positive multiple of 3 (r, g, b), at most %d colours",
                           func, path, QUOTE_MAX, name, ncolors, PV_MAX_POINTS);
    }
    if (ann && !cJSON_IsArray(ann)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": Annotations is not an array", func, path,
                           QUOTE_MAX, name);
    }
    cJSON_ArrayForEach(item, ann)
    {
        ++nann;
    }
    if (ann && (nann == 0 || nann % 2 != 0 || nann > 2u * PV_MAX_POINTS)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": Annotations has %zu items; expected value, "
                           "label pairs, at most %d",
                           func, path, QUOTE_MAX, name, nann, PV_MAX_POINTS);
    }
    ncat = ann ? nann / 2 : ncolors / 3;
    rgb = malloc(ncolors * sizeof *rgb);
    p->color = malloc(ncat * sizeof *p->color);
    if (!rgb || !p->color) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu categories",
                         func, ncat);
        goto done;
    }
    cJSON_ArrayForEach(item, colors)
    {
        if (!cJSON_IsNumber(item) || !(item->valuedouble >= 0.0 && item->valuedouble <= 1.0)) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s: preset \"%.*s\": IndexedColors[%zu] is not a number in "
                             "[0,1]",
                             func, path, QUOTE_MAX, name, i);
            goto done;
        }
        rgb[i++] = item->valuedouble;
    }
    for (k = 0; k < ncat; ++k) {
        memcpy(p->color[k].v, rgb + 3 * (k % (ncolors / 3)), sizeof p->color[k].v);
        p->color[k].x = (double)k;
    }
    if (ann) {
        k = 0;
        cJSON_ArrayForEach(item, ann)
        {
            if (k % 2 == 0 && !annotation_value(item, &p->color[k / 2].x)) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s: preset \"%.*s\": Annotations[%zu] (the value of "
                                 "category %zu) is not a finite number",
                                 func, path, QUOTE_MAX, name, k, k / 2);
                goto done;
            }
            ++k;
        }
        qsort(p->color, ncat, sizeof *p->color, compare_nodes);
        for (k = 1; k < ncat; ++k) {
            if (p->color[k].x == p->color[k - 1].x) {
                st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                                 "%s: %s: preset \"%.*s\": Annotations name the value %g twice",
                                 func, path, QUOTE_MAX, name, p->color[k].x);
                goto done;
            }
        }
    }
    p->ncolor = ncat;
    p->categorical = 1;
    p->lo = p->color[0].x - 0.5;
    p->hi = p->color[ncat - 1].x + 0.5;

done:
    free(rgb);
    return st;
}

static umbra_status read_preset(umbra_context ctx, const char *func, const char *path,
                                const cJSON *obj, pv_preset *p)
{
    const cJSON *space = cJSON_GetObjectItemCaseSensitive(obj, "ColorSpace");
    const cJSON *name_item = cJSON_GetObjectItemCaseSensitive(obj, "Name");
    const cJSON *indexed = cJSON_GetObjectItemCaseSensitive(obj, "IndexedColors");
    const cJSON *wrap = cJSON_GetObjectItemCaseSensitive(obj, "HSVWrap");
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
        } else if (strcmp(s, "HSV") == 0) {
            p->space = PV_HSV;
        } else if (strcmp(s, "Lab") == 0 || strcmp(s, "CIELAB") == 0) {
            p->space = PV_LAB;
        } else if (strcmp(s, "Diverging") == 0) {
            p->space = PV_DIVERGING;
        } else if (strcmp(s, "Step") == 0) {
            p->space = PV_STEP;
        } else if (strcmp(s, "Lab/CIEDE2000") == 0) {
            return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: %s: preset \"%.*s\": ColorSpace \"Lab/CIEDE2000\" is not "
                               "supported (VTK blends it along a shortest path through a grid "
                               "of Lab colours; none of ParaView 5.11's presets uses it): use "
                               "\"Lab\"",
                               func, path, QUOTE_MAX, name);
        } else {
            return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: %s: preset \"%.*s\": ColorSpace \"%.*s\" is not supported "
                               "(RGB, HSV, Lab, CIELAB, Diverging, Step)",
                               func, path, QUOTE_MAX, name, QUOTE_MAX, s);
        }
    }
    if (wrap && !cJSON_IsBool(wrap) && !cJSON_IsNumber(wrap)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: %s: preset \"%.*s\": HSVWrap is not a boolean", func, path,
                           QUOTE_MAX, name);
    }
    p->hsv_wrap = cJSON_IsTrue(wrap) || (cJSON_IsNumber(wrap) && wrap->valuedouble != 0.0);
    if (indexed) {
        /* ParaView applies a preset with IndexedColors as a categorical (indexed) map. */
        st = read_categorical(ctx, func, path, name, obj, indexed, p);
    } else {
        st = read_nodes(ctx, func, path, name, obj, "RGBPoints", 0, &p->color, &p->ncolor);
        if (st == UMBRA_SUCCESS && !p->color) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s: preset \"%.*s\" has neither RGBPoints nor IndexedColors",
                             func, path, QUOTE_MAX, name);
        }
    }
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    st = read_nodes(ctx, func, path, name, obj, "Points", 1, &p->opacity, &p->nopacity);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    if (!p->categorical) {
        p->lo = p->color[0].x;
        p->hi = p->color[p->ncolor - 1].x;
    }
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

/* An upper bound on the JSON values cJSON would make of text (size bytes, NUL-terminated):
 * every value but a container's first follows a comma, and every container opens with a bracket,
 * so values <= commas + brackets + 1, counted outside strings. One pass, no allocation. */
static size_t count_values(const char *text, size_t size)
{
    size_t i, n = 1;
    int in_string = 0;
    for (i = 0; i < size; ++i) {
        char c = text[i];
        if (in_string) {
            if (c == '\\') {
                ++i;
            } else if (c == '"') {
                in_string = 0;
            }
        } else if (c == '"') {
            in_string = 1;
        } else if (c == ',' || c == '[' || c == '{') {
            ++n;
        }
    }
    return n;
}

/* Reads path and parses it into *root (the caller's to cJSON_Delete), every limit of the top of
 * the file checked on the way. */
static umbra_status parse_file(umbra_context ctx, const char *func, const char *path,
                               cJSON **root)
{
    umbra_status st = UMBRA_SUCCESS;
    void *buf = NULL;
    size_t size = 0, values;
    const char *end = NULL;
    struct stat sb;

    *root = NULL;
    /* The size limit is checked before reading; umbra__read_file checks the file is regular. */
    if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode) && (uintmax_t)sb.st_size > PV_MAX_FILE_BYTES) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" holds %jd bytes, more than a preset may (%u)", func, path,
                           (intmax_t)sb.st_size, PV_MAX_FILE_BYTES);
    }
    st = umbra__read_file(ctx, func, path, &buf, &size);
    if (st != UMBRA_SUCCESS) {
        goto done;
    }
    if (size > PV_MAX_FILE_BYTES) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds %zu bytes, more than a preset may (%u)", func, path,
                         size, PV_MAX_FILE_BYTES);
        goto done;
    }
    /* With require_null_terminated cJSON wants the terminating NUL inside the length; a NUL
     * within the file would end the text early, so it is refused first. */
    if (memchr(buf, '\0', size)) {
        unsigned long line = 0, col = 0;
        text_position(buf, (size_t)((const char *)memchr(buf, '\0', size) - (const char *)buf),
                      &line, &col);
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: %s:%lu:%lu: NUL byte (not a text file?)",
                         func, path, line, col);
        goto done;
    }
    values = count_values(buf, size);
    if (values > PV_MAX_VALUES) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\" holds up to %zu JSON values, more than a preset file may "
                         "(%u)",
                         func, path, values, PV_MAX_VALUES);
        goto done;
    }
    pthread_mutex_lock(&cjson_lock);
    *root = cJSON_ParseWithLengthOpts(buf, size + 1, &end, 1);
    pthread_mutex_unlock(&cjson_lock);
    if (!*root) {
        unsigned long line = 0, col = 0;
        size_t off = (end && end >= (const char *)buf && end <= (const char *)buf + size)
                         ? (size_t)(end - (const char *)buf)
                         : size;
        text_position(buf, off, &line, &col);
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: %s:%lu:%lu: malformed JSON (or nested deeper than %d)", func, path,
                         line, col, CJSON_NESTING_LIMIT);
    }

done:
    free(buf);
    return st;
}

int umbra__paraview_file_holds(const char *path, const char *name)
{
    cJSON *root = NULL;
    const cJSON *obj = NULL;
    int found = parse_file(NULL, __func__, path, &root) == UMBRA_SUCCESS &&
                find_preset(NULL, __func__, path, root, name, &obj) == UMBRA_SUCCESS;
    cJSON_Delete(root);
    return found;
}

umbra_status umbra_transfer_function_load_paraview(umbra_context ctx, const char *path,
                                                   const umbra_paraview_options *options,
                                                   umbra_transfer_function *out, double range[2])
{
    umbra_status st = UMBRA_SUCCESS;
    umbra_paraview_options opt;
    cJSON *root = NULL;
    const cJSON *obj = NULL;
    char *found = NULL;
    pv_preset preset;
    float *rgba = NULL;
    double lo, hi;
    uint32_t resolution;

    memset(&preset, 0, sizeof preset);
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: out is NULL", __func__);
    }
    *out = NULL;
    if (!ctx) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: ctx is NULL", __func__);
    }
    umbra_paraview_options_init(&opt);
    if (options) {
        /* 0.4's layout ended before default_opacity: such callers get its default. */
        const size_t v04 = offsetof(umbra_paraview_options, default_opacity);
        if (options->struct_size != sizeof opt && options->struct_size != v04) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "%s: options->struct_size is %zu, neither %zu nor 0.4's %zu (call "
                               "umbra_paraview_options_init)",
                               __func__, options->struct_size, sizeof opt, v04);
        }
        memcpy(&opt, options, options->struct_size);
        opt.struct_size = sizeof opt;
    }
    if (!path && !opt.preset) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: path is NULL and options->preset names no preset to look up",
                           __func__);
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
    if (!(opt.default_opacity >= 0.0 && opt.default_opacity <= 1.0)) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: default_opacity %g is not in [0,1]", __func__,
                           opt.default_opacity);
    }
    if (!path) {
        st = umbra__paraview_find(ctx, __func__, opt.preset, 0, &found);
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        path = found;
    }
    st = parse_file(ctx, __func__, path, &root);
    if (st != UMBRA_SUCCESS) {
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
    resolution = opt.resolution;
    if (preset.categorical && (hi - lo) * PV_ENTRIES_PER_CATEGORY + 1 > resolution) {
        /* A step table must resolve every category: more entries, within the limit. */
        double need = ceil((hi - lo) * PV_ENTRIES_PER_CATEGORY) + 1;
        if (need > PV_MAX_RESOLUTION) {
            st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                             "%s: %s: categorical preset over [%g, %g] needs %.0f table entries "
                             "(%d per unit of value), more than %u",
                             __func__, path, lo, hi, need, PV_ENTRIES_PER_CATEGORY,
                             PV_MAX_RESOLUTION);
            goto fail;
        }
        resolution = (uint32_t)need;
    }
    rgba = malloc((size_t)resolution * 4 * sizeof *rgba);
    if (!rgba) {
        st = umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %u table entries",
                         __func__, resolution);
        goto fail;
    }
    evaluate(&preset, lo, hi, opt.default_opacity, resolution, rgba);
    /* The table spans lo..hi in data units: the renderer places it over each volume's range. */
    st = umbra_transfer_function_create(ctx, rgba, resolution, out);
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
    free(found);
    return st;
}
