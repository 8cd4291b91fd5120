// SPDX-License-Identifier: Apache-2.0
/* examples/umbra_render_args.c: umbra-render's command line.
 * Why one file past 800 lines: one parser, whose option tables, checks and --help read the same
 * tables. getopt_long over two tables: the
 * fixed options below, and one option per parameter of every shadow technique, made from the
 * technique registry (umbra/registry.h): --<key> with '_' written '-' (--map-size, --taps,
 * --reference-step), the parameter's older spelling where it has one (--nodes, --cone-angle), and
 * --<key> / --no-<key> for a flag (--no-lookup-table). Technique parameters are applied once the
 * technique is known, through umbra_shadow_desc_set_param, which checks their ranges; --help
 * lists them from the same description. Numbers are parsed strictly (whole numbers: decimal
 * digits only, no sign, no trailing text). --opt=value, -o FILE, -s WxH, -t NAME and unambiguous
 * prefixes of long options are accepted. Another program (umbra-view) adds its own options to the
 * same table with parse_args_as; messages, --help and --version then carry its name. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "umbra_render.h"

/* The program being parsed for: messages start with its name (set by parse_args_as). */
static const char *program_name = "umbra-render";

static int parse_floats(const char *s, float *out, int n)
{
    for (int i = 0; i < n; ++i) {
        char *end;
        errno = 0;
        out[i] = strtof(s, &end);
        if (end == s || errno || !isfinite(out[i]))
            return 0;
        s = end;
        if (i + 1 < n) {
            if (*s != ',')
                return 0;
            ++s;
        }
    }
    return *s == 0;
}

/* The one integer parser of the command line: the n characters at s must be decimal digits only
 * (no sign, blank or trailing text; sscanf's %u took "-1" as 4294967295 and 4294967312 as 16) and
 * the value must lie in [lo, hi]. */
static int parse_u32_n(const char *s, size_t n, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v = 0;
    if (n == 0 || n > 10)
        return 0;
    for (size_t i = 0; i < n; ++i) {
        if (s[i] < '0' || s[i] > '9')
            return 0;
        v = 10 * v + (uint64_t)(s[i] - '0');
    }
    if (v < lo || v > hi)
        return 0;
    *out = (uint32_t)v;
    return 1;
}

static int parse_uint(const char *s, uint32_t *out)
{
    return parse_u32_n(s, strlen(s), 0, UINT32_MAX, out);
}

/* count whole numbers in [lo, hi] separated by sep ("64x64", "16x16x16", "0:1"). */
static int parse_u32_list(const char *s, char sep, int count, uint32_t lo, uint32_t hi,
                          uint32_t *out)
{
    for (int i = 0; i < count; ++i) {
        const char *end = i + 1 < count ? strchr(s, sep) : s + strlen(s);
        if (!end || !parse_u32_n(s, (size_t)(end - s), lo, hi, &out[i]))
            return 0;
        s = end + 1;
    }
    return 1;
}

/* The extension of path's last component, lower-cased into ext (size n); "" if none. */
static void path_extension(const char *path, char *ext, size_t n)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t i = 0;
    if (dot && dot != base)
        for (const char *c = dot + 1; *c && i + 1 < n; ++c)
            ext[i++] = (char)((*c >= 'A' && *c <= 'Z') ? *c - 'A' + 'a' : *c);
    ext[i] = '\0';
}

/* The output must be writable before minutes go into the render: a .png or .exr name in an
 * existing, writable directory, and not itself a directory. Returns 0, or prints and returns 1. */
static int check_output(const char *path)
{
    char ext[8], dir[4096];
    struct stat sb;
    path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "png") != 0 && strcmp(ext, "exr") != 0) {
        fprintf(stderr, "%s: --out '%s': the extension must be .png or .exr\n", program_name,
                path);
        return 1;
    }
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(dir, sizeof dir, ".");
    } else if (slash == path) {
        snprintf(dir, sizeof dir, "/");
    } else if ((size_t)(slash - path) < sizeof dir) {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = '\0';
    } else {
        fprintf(stderr, "%s: --out: the directory name is longer than %zu bytes\n",
                program_name, sizeof dir - 1);
        return 1;
    }
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        fprintf(stderr, "%s: --out '%s': the directory '%s' does not exist\n",
                program_name, path, dir);
        return 1;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        fprintf(stderr, "%s: --out '%s': the directory '%s' is not writable\n",
                program_name, path, dir);
        return 1;
    }
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fprintf(stderr, "%s: --out '%s' is a directory\n", program_name, path);
        return 1;
    }
    return 0;
}

#define BAD(...)                                                                               \
    do {                                                                                       \
        fprintf(stderr, "%s: ", program_name);                                                 \
        fprintf(stderr, __VA_ARGS__);                                                          \
        fputc('\n', stderr);                                                                   \
        return 1;                                                                              \
    } while (0)

/* ---- the fixed options ----------------------------------------------------------------------- */

enum {
    OPT_VERSION = 256, OPT_SCENE, OPT_SCENE_SIZE, OPT_VOLUME, OPT_DATA_ROOT, OPT_RAW, OPT_RAW_DIMS,
    OPT_RAW_TYPE, OPT_RAW_BIG_ENDIAN, OPT_TF, OPT_TF_PRESET, OPT_LIGHT_TF, OPT_TF_RANGE, OPT_CAMERA_DIR,
    OPT_EYE, OPT_TARGET, OPT_UP, OPT_FOV, OPT_ORTHO, OPT_LIGHT_DIR, OPT_LIGHT_POS,
    OPT_LIGHT_COLOR, OPT_AMBIENT, OPT_STEP, OPT_SHADING, OPT_NO_SHADING, OPT_GROUND,
    OPT_NO_GROUND, OPT_COLORED, OPT_GREY, OPT_BACKGROUND, OPT_JITTER, OPT_SEED, OPT_PREINTEGRATED,
    OPT_DEVICE, OPT_PROGRESS, OPT_NO_PROGRESS, OPT_INTERACTION, OPT_MODE, OPT_CLIP_PLANE, OPT_CROP,
    OPT_RAW_CHANNELS, OPT_LABELS, OPT_CHANNEL_TF, OPT_TERMINATION,
    OPT_PARAM = 1024,  /* + the index of a technique option */
    OPT_PROGRAM = 2048 /* + the index of an option of the program's own (parse_args_as) */
};
#define MAX_PROGRAM_OPTIONS 16

typedef struct fixed_option {
    const char *name;
    int val;      /* OPT_* or the short option's letter */
    const char *arg; /* the value's shape in --help, NULL for a flag */
    const char *help;
} fixed_option;

static const fixed_option fixed[] = {
    {"help", 'h', NULL, "print this help and exit"},
    {"version", OPT_VERSION, NULL, "print the version and exit"},
    {"scene", OPT_SCENE, "NAME", "built-in scene: spheres (default), slab, marschner-lobb"},
    {"scene-size", OPT_SCENE_SIZE, "N", "built-in scene resolution N^3 (default per scene)"},
    {"volume", OPT_VOLUME, "FILE", "volume file: .nrrd/.nhdr (Teem), .nii/.nii.gz (NIfTI), "
                                   ".mha/.mhd (MetaImage), .dat (Voreen), .dcm or a DICOM "
                                   "series directory, .tif/.tiff (a stack, OME-TIFF too) or a "
                                   "directory of them"},
    {"allow-data-root", OPT_DATA_ROOT, "DIR", "a header's detached data file may also lie under "
                                              "DIR (repeatable; by default only in the header's "
                                              "own directory)"},
    {"raw", OPT_RAW, "FILE", "raw voxels; needs --raw-dims and --raw-type"},
    {"raw-dims", OPT_RAW_DIMS, "XxYxZ", "the raw file's voxels per axis"},
    {"raw-type", OPT_RAW_TYPE, "T", "the raw file's voxel type: uint8, uint16, int16 or float32"},
    {"raw-big-endian", OPT_RAW_BIG_ENDIAN, NULL, "the raw file is big-endian"},
    {"raw-channels", OPT_RAW_CHANNELS, "N", "the raw file holds N interleaved values per voxel: "
                                            "2..4 make a multi-channel volume, each channel "
                                            "with its own range and transfer function "
                                            "(--channel-tf; default 1)"},
    {"labels", OPT_LABELS, NULL, "the raw file's uint8/uint16 voxels are labels: sampled at the "
                                 "nearest voxel, label l taking entry l of the transfer function "
                                 "(in the text format: resolution L, label l's point at value "
                                 "l/(L-1))"},
    {"tf", OPT_TF, "FILE", "transfer function: text format (docs/usage.md) or a ParaView preset "
                           ".json (x in the volume's data units)"},
    {"tf-preset", OPT_TF_PRESET, "NAME", "the preset to pick from a .json holding several"},
    {"light-tf", OPT_LIGHT_TF, "FILE", "separate transfer function for the light pass"},
    {"channel-tf", OPT_CHANNEL_TF, "FILE", "transfer function of the next channel of a "
                                           "multi-channel volume: channel 1, then 2, then 3 "
                                           "(channel 0 takes --tf; repeatable)"},
    {"tf-range", OPT_TF_RANGE, "LO,HI", "the transfer functions span data values LO..HI "
                                        "(overrides a file's range line: an HU preset on data "
                                        "stored as HU + 1024 takes --tf-range 0,4095)"},
    {"size", 's', "WxH", "image size (default 512x512)"},
    {"out", 'o', "FILE", "output image, .png or .exr (default umbra.png)"},
    {"technique", 't', "NAME", "shadow technique (below; default none)"},
    {"camera-dir", OPT_CAMERA_DIR, "X,Y,Z", "orbit camera around the box's centre from this "
                                            "direction"},
    {"eye", OPT_EYE, "X,Y,Z", "look-at camera, in the volume's world (a NRRD's space; else the "
                              "box is centred at 0), with --target and --up"},
    {"target", OPT_TARGET, "X,Y,Z", "the point the look-at camera looks at"},
    {"up", OPT_UP, "X,Y,Z", "the look-at camera's up direction"},
    {"fov", OPT_FOV, "DEG", "vertical field of view (default 30)"},
    {"ortho", OPT_ORTHO, "H", "orthographic camera of view height H"},
    {"light-dir", OPT_LIGHT_DIR, "X,Y,Z", "directional light travelling along X,Y,Z"},
    {"light-pos", OPT_LIGHT_POS, "X,Y,Z", "point light at X,Y,Z (the volume's world)"},
    {"light-color", OPT_LIGHT_COLOR, "R,G,B", "light colour (default 1,1,1)"},
    {"ambient", OPT_AMBIENT, "A", "ambient light (default 0.2)"},
    {"step", OPT_STEP, "S", "view sampling step in voxels (default 0.5)"},
    {"termination", OPT_TERMINATION, "T", "early ray termination once the opacity passes T, in "
                                          "(0, 1]; 1: none (default 0.99)"},
    {"shading", OPT_SHADING, NULL, "Blinn-Phong gradient shading (--no-shading: none)"},
    {"no-shading", OPT_NO_SHADING, NULL, NULL},
    {"ground", OPT_GROUND, NULL, "opaque ground plane receiving shadows (--no-ground: none)"},
    {"no-ground", OPT_NO_GROUND, NULL, NULL},
    {"colored", OPT_COLORED, NULL, "transmission colour from the light TF's RGB (--grey: grey)"},
    {"grey", OPT_GREY, NULL, NULL},
    {"background", OPT_BACKGROUND, "R,G,B,A", "premultiplied background (default "
                                              "0.08,0.08,0.1,1)"},
    {"jitter", OPT_JITTER, NULL, "jitter ray starts (seeded by --seed)"},
    {"seed", OPT_SEED, "N", "seed for the jitter and the stochastic maps (cssm's seed)"},
    {"preintegrated", OPT_PREINTEGRATED, NULL, "pre-integrated segments: the view ray's, and the "
                                               "convolution technique's light"},
    {"interaction", OPT_INTERACTION, "MODE", "off (default) or auto: a frame after a light or "
                                             "transfer-function change uses the technique's "
                                             "draft, the next unchanged one the full map"},
    {"mode", OPT_MODE, "NAME", "render mode: composite (default: lit, shadowed), mip, minip or "
                               "average (intensity projections, unlit: technique none)"},
    {"clip-plane", OPT_CLIP_PLANE, "A,B,C,D", "keep the side a x + b y + c z + d >= 0 of a plane "
                                              "in the volume's world, for the view and the light "
                                              "alike (repeatable, up to 6)"},
    {"crop", OPT_CROP, "X0,Y0,Z0,X1,Y1,Z1", "keep only the box of voxel coordinates [X0, X1] x "
                                            "[Y0, Y1] x [Z0, Z1] (voxel centres at whole "
                                            "numbers), for the view and the light alike"},
    {"device", OPT_DEVICE, "SPEC", "OpenCL device: P:D indices or a name substring"},
    {"progress", OPT_PROGRESS, NULL, "progress line on stderr (default: when it is a terminal; "
                                     "--no-progress: never)"},
    {"no-progress", OPT_NO_PROGRESS, NULL, NULL},
};
#define FIXED_COUNT (sizeof fixed / sizeof fixed[0])

/* ---- the technique options, from the registry ------------------------------------------------ */

/* One long option for a technique parameter's key (shared by every technique with that key). */
typedef struct param_option {
    char name[64];       /* the option, without "--" */
    const char *key;     /* the registry key it sets */
    umbra_param_type type;
    int value;           /* a flag's option: the value it sets (1, or 0 for --no-<key>) */
} param_option;

#define MAX_PARAM_OPTIONS 128
static param_option param_options[MAX_PARAM_OPTIONS];
static int param_option_count;

static int fixed_named(const char *name)
{
    for (size_t i = 0; i < FIXED_COUNT; ++i)
        if (strcmp(fixed[i].name, name) == 0)
            return 1;
    return 0;
}

static void add_param_option(const char *prefix, const char *key_or_alias, const char *key,
                             umbra_param_type type, int value)
{
    char name[64];
    snprintf(name, sizeof name, "%s%s", prefix, key_or_alias);
    for (char *c = name; *c; ++c)
        if (*c == '_')
            *c = '-';
    if (fixed_named(name) || param_option_count >= MAX_PARAM_OPTIONS)
        return; /* --seed is fixed: it sets the key too (apply_seed) */
    for (int i = 0; i < param_option_count; ++i)
        if (strcmp(param_options[i].name, name) == 0)
            return; /* a key several techniques share: one option */
    param_option *p = &param_options[param_option_count++];
    snprintf(p->name, sizeof p->name, "%s", name);
    p->key = key;
    p->type = type;
    p->value = value;
}

static void make_param_options(void)
{
    param_option_count = 0;
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        for (uint32_t k = 0; k < ti->param_count; ++k) {
            const umbra_param_info *p = umbra_technique_param_get(ti, k);
            const char *names[2] = {p->key, p->alias};
            for (int n = 0; n < 2; ++n) {
                if (!names[n])
                    continue;
                add_param_option("", names[n], p->key, p->type, 1);
                if (p->type == UMBRA_PARAM_BOOL)
                    add_param_option("no-", names[n], p->key, p->type, 0);
            }
        }
    }
}

/* Whether some technique has a parameter with this key. */
static int registry_has(const char *key)
{
    for (uint32_t t = 0; t < umbra_technique_count(); ++t)
        if (umbra_technique_param_find(umbra_technique_get(t), key))
            return 1;
    return 0;
}

/* ---- --help ---------------------------------------------------------------------------------- */

/* Prints text from column `indent`, wrapped before column 100, continuing at column `indent`;
 * the first line starts at column `at`. */
static void wrap(FILE *f, const char *text, int at, int indent)
{
    int col = at;
    while (*text) {
        size_t word = strcspn(text, " ");
        if (col > indent && col + 1 + (int)word > 99) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            fputc(' ', f);
            ++col;
        } else {
            for (; col < indent; ++col)
                fputc(' ', f);
        }
        fprintf(f, "%.*s", (int)word, text);
        col += (int)word;
        text += word;
        while (*text == ' ')
            ++text;
    }
    fputc('\n', f);
}

/* A number for --help: whole numbers in full (4294967295), others as %g. */
static const char *num(double v, char buf[40])
{
    snprintf(buf, 40, v == floor(v) && fabs(v) < 1e15 ? "%.0f" : "%g", v);
    return buf;
}

/* A key as an option's name: '_' written '-' ("map_size" -> "map-size"). */
static void key_option(const char *key, char *opt, size_t n)
{
    snprintf(opt, n, "%s", key);
    for (char *c = opt; *c; ++c)
        if (*c == '_')
            *c = '-';
}

void param_describe(const umbra_param_info *p, char *text, size_t size)
{
    char range[256] = "", def[40];
    if (p->type == UMBRA_PARAM_BOOL) {
        snprintf(range, sizeof range, "on or off");
    } else {
        size_t n = 0;
        char a[40], b[40];
        if (p->allowed) {
            for (uint32_t i = 0; i < p->allowed_count; ++i)
                n += (size_t)snprintf(range + n, sizeof range - n, "%s%s", i ? "|" : "",
                                      num(p->allowed[i], a));
        } else {
            n += (size_t)snprintf(range, sizeof range, "%s%s..%s%s",
                                  p->flags & UMBRA_PARAM_MIN_EXCLUSIVE ? "(" : "",
                                  num(p->min, a), num(p->max, b),
                                  p->flags & UMBRA_PARAM_MAX_EXCLUSIVE ? ")" : "");
        }
        if (p->flags & UMBRA_PARAM_ZERO)
            snprintf(range + n, sizeof range - n, ", or 0: %s", p->zero_doc);
    }
    if (p->type == UMBRA_PARAM_BOOL)
        snprintf(def, sizeof def, "%s", p->default_value != 0.0 ? "on" : "off");
    else if (p->zero_name && p->default_value == 0.0)
        snprintf(def, sizeof def, "%s", p->zero_name);
    else
        num(p->default_value, def);
    snprintf(text, size, "%s%s%s (default %s; %s)", p->doc, p->unit ? ", in " : "",
             p->unit ? p->unit : "", def, range);
}

void param_option_text(const umbra_param_info *p, double value, char *text, size_t size)
{
    char opt[64];
    key_option(p->key, opt, sizeof opt);
    if (p->type == UMBRA_PARAM_BOOL)
        snprintf(text, size, "--%s%s", value != 0.0 ? "" : "no-", opt);
    else if (p->zero_name && value == 0.0)
        snprintf(text, size, "--%s %s", opt, p->zero_name);
    else
        snprintf(text, size, p->type == UMBRA_PARAM_FLOAT ? "--%s %.9g" : "--%s %.0f", opt, value);
}

/* A parameter's lines in --help: its options, the value's shape and what it accepts
 * ("auto|N", "1|7|13|21"), then param_describe's text. */
static void param_help(FILE *f, const umbra_param_info *p)
{
    char left[160], text[1024];
    const char *shape = p->type == UMBRA_PARAM_FLOAT ? "X" : "N";
    char opt[64];
    key_option(p->key, opt, sizeof opt);
    if (p->type == UMBRA_PARAM_BOOL)
        snprintf(left, sizeof left, "    --%s | --no-%s", opt, opt);
    else
        snprintf(left, sizeof left, "    --%s %s%s%s", opt, p->zero_name ? p->zero_name : "",
                 p->zero_name ? "|" : "", shape);
    if (p->alias) {
        size_t n = strlen(left);
        snprintf(left + n, sizeof left - n, " (--%s)", p->alias);
        for (char *c = left + n; *c; ++c)
            if (*c == '_')
                *c = '-';
    }
    param_describe(p, text, sizeof text);
    fprintf(f, "%s", left);
    int col = (int)strlen(left);
    if (col >= 33) {
        fputc('\n', f);
        col = 0;
    }
    wrap(f, text, col, 34);
}

/* One option's line(s) in --help: its short form if val is a letter, its value's shape (arg,
 * NULL for a flag) and its help wrapped from column 34. */
static void option_help(FILE *f, int val, const char *name, const char *arg, const char *help)
{
    char left[96];
    int n = val < 256 ? snprintf(left, sizeof left, "  -%c, --%s%s%s", val, name,
                                 arg ? " " : "", arg ? arg : "")
                      : snprintf(left, sizeof left, "      --%s%s%s", name, arg ? " " : "",
                                 arg ? arg : "");
    fprintf(f, "%s", left);
    if (n >= 33) {
        fputc('\n', f);
        n = 0;
    }
    wrap(f, help, n, 34);
}

/* prog: the program whose own options come first (NULL: umbra-render alone). */
static void usage(FILE *f, const program *prog)
{
    fprintf(f, "usage: %s [options]\n", program_name);
    if (prog && prog->about)
        wrap(f, prog->about, 0, 2);
    for (size_t i = 0; prog && i < prog->option_count; ++i)
        option_help(f, 256, prog->options[i].name, prog->options[i].arg,
                    prog->options[i].help);
    for (size_t i = 0; i < FIXED_COUNT; ++i)
        if (fixed[i].help)
            option_help(f, fixed[i].val, fixed[i].name, fixed[i].arg, fixed[i].help);
    fprintf(f, "\nShadow techniques (--technique NAME) and their parameters:\n");
    char maps[256] = "";
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        char head[160];
        snprintf(head, sizeof head, "  %s: %s", ti->name, ti->title);
        fprintf(f, "%s", head);
        if (ti->flags & UMBRA_TECHNIQUE_MAP) {
            size_t n = strlen(maps);
            snprintf(maps + n, sizeof maps - n, "%s%s (texels per voxel %g, step %g)",
                     n ? ", " : "", ti->name, ti->map_texels_per_voxel, ti->map_step);
            fprintf(f, " (light-space map: the map options below)");
        }
        fputc('\n', f);
        for (uint32_t k = 0; k < ti->param_count; ++k) {
            const umbra_param_info *p = umbra_technique_param_get(ti, k);
            if (!(p->flags & UMBRA_PARAM_MAP))
                param_help(f, p);
        }
    }
    char text[512];
    snprintf(text, sizeof text, "light-space maps, the options every map takes (0: the "
             "technique's own, %s):", maps);
    wrap(f, text, 0, 2);
    const umbra_technique_info *shown = NULL;
    for (uint32_t t = 0; t < umbra_technique_count() && !shown; ++t)
        if (umbra_technique_get(t)->flags & UMBRA_TECHNIQUE_MAP)
            shown = umbra_technique_get(t);
    for (uint32_t k = 0; shown && k < shown->param_count; ++k) {
        const umbra_param_info *p = umbra_technique_param_get(shown, k);
        if (p->flags & UMBRA_PARAM_MAP)
            param_help(f, p);
    }
}

/* ---- parsing --------------------------------------------------------------------------------- */

/* A technique parameter given on the command line, applied once the technique is known. */
typedef struct given {
    const char *key;
    const char *option; /* as typed, for messages */
    const char *text;   /* the value, NULL for a flag */
    double value;       /* a flag's */
} given;

/* Sets key in o->shadow: in the chosen technique if it has it, else in every technique that
 * does (so the value is still range-checked). */
static int apply_param(options *o, const given *g)
{
    const umbra_technique_info *chosen = umbra_technique_find_id(o->shadow.technique);
    const umbra_param_info *p = umbra_technique_param_find(chosen, g->key);
    const char *tech = p ? chosen->name : NULL;
    if (!p)
        for (uint32_t t = 0; t < umbra_technique_count() && !p; ++t)
            p = umbra_technique_param_find(umbra_technique_get(t), g->key);
    double v = g->value;
    if (g->text) {
        uint32_t u;
        float x;
        if (p->zero_name && strcmp(g->text, p->zero_name) == 0)
            v = 0.0;
        else if (p->type == UMBRA_PARAM_FLOAT) {
            if (!parse_floats(g->text, &x, 1))
                BAD("--%s '%s' is not a number", g->option, g->text);
            v = x;
        } else {
            if (!parse_uint(g->text, &u))
                BAD("--%s '%s' is not %sa whole number", g->option, g->text,
                    p->zero_name ? "'auto' or " : "");
            v = u;
        }
    }
    char msg[1024];
    umbra_status st = umbra_shadow_desc_set_param(&o->shadow, tech, g->key, v, msg, sizeof msg);
    if (st != UMBRA_SUCCESS)
        BAD("%s: %s", umbra_status_to_string(st), msg);
    return 0;
}

int parse_args(int argc, char **argv, options *o)
{
    return parse_args_as(NULL, argc, argv, o);
}

int parse_args_as(const program *p, int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    program_name = p ? p->name : "umbra-render";
    o->program = program_name;
    o->scene = "spheres";
    o->out = "umbra.png";
    o->width = o->height = 512;
    o->fov = 30.0f;
    o->platform_index = o->device_index = -1;
    o->shading = o->ground = o->colored = o->progress = -1;
    umbra_raw_desc_init(&o->raw_desc);
    umbra_shadow_desc_init(&o->shadow);
    umbra_clip_desc_init(&o->clip);
    make_param_options();

    struct option longopts[FIXED_COUNT + MAX_PARAM_OPTIONS + MAX_PROGRAM_OPTIONS + 1];
    size_t n = 0;
    size_t own = p ? p->option_count : 0;
    if (own > MAX_PROGRAM_OPTIONS)
        BAD("%zu options of its own, at most %d", own, MAX_PROGRAM_OPTIONS);
    for (size_t i = 0; i < own; ++i) {
        int taken = fixed_named(p->options[i].name);
        for (int k = 0; k < param_option_count; ++k)
            taken |= strcmp(param_options[k].name, p->options[i].name) == 0;
        if (taken)
            BAD("--%s is umbra-render's option too", p->options[i].name);
        longopts[n++] = (struct option){p->options[i].name,
                                        p->options[i].arg ? required_argument : no_argument,
                                        NULL, OPT_PROGRAM + (int)i};
    }
    for (size_t i = 0; i < FIXED_COUNT; ++i)
        longopts[n++] = (struct option){fixed[i].name,
                                        fixed[i].arg ? required_argument : no_argument, NULL,
                                        fixed[i].val};
    for (int i = 0; i < param_option_count; ++i)
        longopts[n++] = (struct option){param_options[i].name,
                                        param_options[i].type == UMBRA_PARAM_BOOL
                                            ? no_argument
                                            : required_argument,
                                        NULL, OPT_PARAM + i};
    longopts[n] = (struct option){NULL, 0, NULL, 0};

    given *givens = calloc((size_t)argc + 1, sizeof *givens);
    int ngiven = 0, rc = 1;
    if (!givens)
        BAD("out of memory");
    opterr = 0; /* the messages below name the option and say where to look */
    optind = 1;
    for (;;) {
        int index = -1;
        int c = getopt_long(argc, argv, ":ho:s:t:", longopts, &index);
        if (c == -1)
            break;
        const char *v = optarg;
#define FAIL(...)                                                                              \
    do {                                                                                       \
        fprintf(stderr, "%s: ", program_name);                                                 \
        fprintf(stderr, __VA_ARGS__);                                                          \
        fputc('\n', stderr);                                                                   \
        goto done;                                                                             \
    } while (0)
        switch (c) {
        case '?': {
            if (optopt && optopt < 256 && argv[optind - 1][1] != '-')
                FAIL("unknown option '-%c' (see --help)", optopt);
            if (optopt) /* a long option given a value it does not take */
                FAIL("%.*s takes no value", (int)strcspn(argv[optind - 1], "="),
                     argv[optind - 1]);
            /* A prefix of several options, or of none. */
            const char *typed = argv[optind - 1] + 2;
            size_t len = strcspn(typed, "=");
            char matches[512] = "";
            for (size_t i = 0; longopts[i].name; ++i)
                if (strncmp(longopts[i].name, typed, len) == 0) {
                    size_t m = strlen(matches);
                    snprintf(matches + m, sizeof matches - m, "%s--%s", m ? ", " : "",
                             longopts[i].name);
                }
            if (matches[0])
                FAIL("option '%.*s' is ambiguous: %s", (int)len + 2, argv[optind - 1], matches);
            FAIL("unknown option '%s' (see --help)", argv[optind - 1]);
        }
        case ':':
            FAIL("%s needs a value", argv[optind - 1]);
        case 'h':
            usage(stdout, p);
            free(givens);
            exit(0);
        case OPT_VERSION:
            printf("%s %s (library %s)\n", program_name, UMBRA_VERSION_STRING, umbra_version());
            free(givens);
            exit(0);
        case OPT_SCENE: o->scene = v; break;
        case OPT_SCENE_SIZE:
            if (!parse_uint(v, &o->scene_size))
                FAIL("--scene-size '%s' is not a whole number", v);
            break;
        case OPT_VOLUME: o->volume = v; break;
        case OPT_DATA_ROOT:
            if (o->data_root_count == sizeof o->data_roots / sizeof o->data_roots[0])
                FAIL("at most %zu --allow-data-root", o->data_root_count);
            o->data_roots[o->data_root_count++] = v;
            break;
        case OPT_RAW: o->raw = v; break;
        case OPT_RAW_DIMS:
            if (!parse_u32_list(v, 'x', 3, 1, UINT32_MAX, o->raw_desc.dims))
                FAIL("--raw-dims '%s' is not XxYxZ with whole numbers in [1, %u]", v, UINT32_MAX);
            o->have_raw_dims = 1;
            break;
        case OPT_RAW_TYPE: {
            static const char *names[] = {"uint8", "uint16", "int16", "float32"};
            int k = -1;
            for (int t = 0; t < 4; ++t)
                if (strcmp(v, names[t]) == 0)
                    k = t;
            if (k < 0)
                FAIL("--raw-type '%s' is not uint8, uint16, int16 or float32", v);
            o->raw_desc.type = (umbra_scalar_type)k;
            o->have_raw_type = 1;
            break;
        }
        case OPT_RAW_BIG_ENDIAN: o->raw_desc.big_endian = 1; break;
        case OPT_TF: o->tf = v; break;
        case OPT_TF_PRESET: o->tf_preset = v; break;
        case OPT_LIGHT_TF: o->light_tf = v; break;
        case OPT_TF_RANGE:
            if (!parse_floats(v, o->tf_range, 2))
                FAIL("--tf-range '%s' is not LO,HI", v);
            o->have_tf_range = 1;
            break;
        case 's': {
            uint32_t wh[2];
            if (!parse_u32_list(v, 'x', 2, 1, 16384, wh))
                FAIL("--size '%s' is not WxH with whole numbers in [1, 16384]", v);
            o->width = wh[0];
            o->height = wh[1];
            break;
        }
        case 'o': o->out = v; break;
        case 't':
            if (umbra_shadow_technique_parse(v, &o->shadow.technique) != UMBRA_SUCCESS) {
                char names[256] = "";
                for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
                    size_t m = strlen(names);
                    snprintf(names + m, sizeof names - m, "%s%s", t ? ", " : "",
                             umbra_technique_get(t)->name);
                }
                FAIL("--technique '%s' is unknown (%s)", v, names);
            }
            break;
        case OPT_CAMERA_DIR:
            if (!parse_floats(v, o->camera_dir, 3))
                FAIL("--camera-dir '%s' is not X,Y,Z", v);
            o->have_camera_dir = 1;
            break;
        case OPT_EYE:
            if (!parse_floats(v, o->eye, 3))
                FAIL("--eye '%s' is not X,Y,Z", v);
            o->have_eye = 1;
            break;
        case OPT_TARGET:
            if (!parse_floats(v, o->target, 3))
                FAIL("--target '%s' is not X,Y,Z", v);
            o->have_target = 1;
            break;
        case OPT_UP:
            if (!parse_floats(v, o->up, 3))
                FAIL("--up '%s' is not X,Y,Z", v);
            o->have_up = 1;
            break;
        case OPT_FOV:
            if (!parse_floats(v, &o->fov, 1))
                FAIL("--fov '%s' is not a number", v);
            break;
        case OPT_ORTHO:
            if (!parse_floats(v, &o->ortho, 1) || !(o->ortho > 0))
                FAIL("--ortho '%s' is not a positive number", v);
            break;
        case OPT_LIGHT_DIR:
            if (!parse_floats(v, o->light_dir, 3))
                FAIL("--light-dir '%s' is not X,Y,Z", v);
            o->have_light_dir = 1;
            break;
        case OPT_LIGHT_POS:
            if (!parse_floats(v, o->light_pos, 3))
                FAIL("--light-pos '%s' is not X,Y,Z", v);
            o->have_light_pos = 1;
            break;
        case OPT_LIGHT_COLOR:
            if (!parse_floats(v, o->light_color, 3))
                FAIL("--light-color '%s' is not R,G,B", v);
            o->have_light_color = 1;
            break;
        case OPT_AMBIENT:
            if (!parse_floats(v, &o->ambient, 1))
                FAIL("--ambient '%s' is not a number", v);
            o->have_ambient = 1;
            break;
        case OPT_STEP:
            if (!parse_floats(v, &o->step, 1))
                FAIL("--step '%s' is not a number", v);
            o->have_step = 1;
            break;
        case OPT_TERMINATION:
            if (!parse_floats(v, &o->termination, 1))
                FAIL("--termination '%s' is not a number", v);
            o->have_termination = 1;
            break;
        case OPT_BACKGROUND:
            if (!parse_floats(v, o->background, 4))
                FAIL("--background '%s' is not R,G,B,A", v);
            o->have_background = 1;
            break;
        case OPT_SHADING: o->shading = 1; break;
        case OPT_NO_SHADING: o->shading = 0; break;
        case OPT_GROUND: o->ground = 1; break;
        case OPT_NO_GROUND: o->ground = 0; break;
        case OPT_COLORED: o->colored = 1; break;
        case OPT_GREY: o->colored = 0; break;
        case OPT_JITTER: o->jitter = 1; break;
        case OPT_PREINTEGRATED: o->preintegrated = 1; break;
        case OPT_INTERACTION:
            o->have_interaction = 1;
            if (strcmp(v, "off") == 0)
                o->interaction = UMBRA_INTERACTION_OFF;
            else if (strcmp(v, "auto") == 0)
                o->interaction = UMBRA_INTERACTION_AUTO;
            else
                FAIL("--interaction '%s' is neither off nor auto", v);
            break;
        case OPT_SEED:
            if (!parse_uint(v, &o->seed))
                FAIL("--seed '%s' is not a whole number", v);
            o->have_seed = 1;
            /* Also the stochastic techniques' seed, a registry key. */
            if (registry_has("seed"))
                givens[ngiven++] = (given){"seed", "seed", v, 0.0};
            break;
        case OPT_DEVICE: {
            /* P:D (platform and device indices) as docs/usage.md has it, else a name substring. */
            uint32_t pd[2];
            if (parse_u32_list(v, ':', 2, 0, 1023, pd)) {
                o->platform_index = (int)pd[0];
                o->device_index = (int)pd[1];
            } else if (strchr(v, ':') && strspn(v, "0123456789:") == strlen(v)) {
                FAIL("--device '%s': P:D indices must be whole numbers in [0, 1023]", v);
            } else {
                o->device = v;
            }
            break;
        }
        case OPT_PROGRESS: o->progress = 1; break;
        case OPT_NO_PROGRESS: o->progress = 0; break;
        case OPT_MODE: {
            static const char *names[] = {"composite", "mip", "minip", "average"};
            int k = -1;
            for (int m = 0; m < 4; ++m)
                if (strcmp(v, names[m]) == 0)
                    k = m;
            if (k < 0)
                FAIL("--mode '%s' is not composite, mip, minip or average", v);
            o->mode = (umbra_render_mode)k;
            break;
        }
        case OPT_CLIP_PLANE:
            if (o->clip.plane_count == UMBRA_MAX_CLIP_PLANES)
                FAIL("at most %d --clip-plane", UMBRA_MAX_CLIP_PLANES);
            if (!parse_floats(v, o->clip.planes[o->clip.plane_count], 4))
                FAIL("--clip-plane '%s' is not A,B,C,D", v);
            o->clip.plane_count++;
            break;
        case OPT_CROP: {
            float b[6];
            if (!parse_floats(v, b, 6))
                FAIL("--crop '%s' is not X0,Y0,Z0,X1,Y1,Z1", v);
            o->clip.crop = 1;
            memcpy(o->clip.crop_min, b, sizeof o->clip.crop_min);
            memcpy(o->clip.crop_max, b + 3, sizeof o->clip.crop_max);
            break;
        }
        case OPT_RAW_CHANNELS:
            if (!parse_u32_n(v, strlen(v), 1, UMBRA_MAX_CHANNELS, &o->raw_desc.channels))
                FAIL("--raw-channels '%s' is not a whole number in [1, %d]", v,
                     UMBRA_MAX_CHANNELS);
            break;
        case OPT_LABELS: o->raw_desc.labels = 1; break;
        case OPT_CHANNEL_TF:
            if (o->channel_tf_count == UMBRA_MAX_CHANNELS - 1)
                FAIL("at most %d --channel-tf (channels 1 to %d)", UMBRA_MAX_CHANNELS - 1,
                     UMBRA_MAX_CHANNELS - 1);
            o->channel_tf[o->channel_tf_count++] = v;
            break;
        default:
            if (c >= OPT_PROGRAM) {
                if (p->take(p->user, (size_t)(c - OPT_PROGRAM), v) != 0)
                    goto done;
            } else {
                const param_option *po = &param_options[c - OPT_PARAM];
                givens[ngiven++] = (given){po->key, po->name, v, (double)po->value};
            }
            break;
        }
#undef FAIL
    }
    if (optind < argc) {
        fprintf(stderr, "%s: unexpected argument '%s' (see --help)\n", program_name, argv[optind]);
        goto done;
    }
    /* In the order given, now that the technique is known: a later value wins. */
    for (int i = 0; i < ngiven; ++i)
        if (apply_param(o, &givens[i]) != 0)
            goto done;
    if (o->raw && (!o->have_raw_dims || !o->have_raw_type)) {
        fprintf(stderr, "%s: --raw needs --raw-dims and --raw-type\n", program_name);
        goto done;
    }
    if ((o->raw_desc.channels > 1 || o->raw_desc.labels) && !o->raw) {
        fprintf(stderr, "%s: --raw-channels and --labels describe a --raw file\n",
                program_name);
        goto done;
    }
    if (o->have_light_dir && o->have_light_pos) {
        fprintf(stderr, "%s: --light-dir and --light-pos exclude each other\n", program_name);
        goto done;
    }
    rc = check_output(o->out);
done:
    free(givens);
    return rc;
}
