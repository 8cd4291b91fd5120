// SPDX-License-Identifier: Apache-2.0
/* umbra-render: the command-line front end. Renders a built-in scene or a volume file with a
 * chosen shadow technique into a PNG or EXR and prints each stage's time to stderr.
 * Run with --help for the options. Exit status (as the README states): 0 on success; 1 on bad
 * input: an option, a number, a file that is missing or malformed, an output path that cannot be
 * written (checked before rendering), a request the technique cannot do; 2 on a failure of the
 * device or of memory (no device, an OpenCL error, out of memory), or when writing the image fails
 * after the render; 130 when interrupted (Ctrl-C stops the render between two pieces of device
 * work). The command line and the scene set up from it are shared with umbra-view
 * (umbra_render.h). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "umbra_render.h"

void usage(FILE *f)
{
    fprintf(f,
        "usage: umbra-render [options]\n"
        "  --version             print the version and exit\n"
        "  --scene NAME          built-in scene: spheres (default), slab, marschner-lobb\n"
        "  --scene-size N        built-in scene resolution N^3 (default per scene)\n"
        "  --volume FILE         volume file: .nrrd/.nhdr (Teem), .nii/.nii.gz (NIfTI),\n"
        "                        .mha/.mhd (MetaImage), .dat (Voreen)\n"
        "  --raw FILE --raw-dims XxYxZ --raw-type uint8|uint16|int16|float32 [--raw-big-endian]\n"
        "  --tf FILE             transfer function: text format (see README) or a ParaView\n"
        "                        preset .json (x in the volume's data units)\n"
        "  --tf-preset NAME      the preset to pick from a .json holding several\n"
        "  --light-tf FILE       separate transfer function for the light pass\n"
        "  --tf-range LO,HI      the transfer functions span data values LO..HI (overrides a\n"
        "                        file's range line: an HU preset on data stored as HU + 1024\n"
        "                        takes --tf-range 0,4095)\n"
        "  --size WxH            image size (default 512x512)\n"
        "  --out FILE            output image, .png or .exr (default umbra.png)\n"
        "  --technique NAME      none | reference | threshold | deep | cssm | convolution\n"
        "  --camera-dir X,Y,Z    orbit camera around the box's centre from this direction\n"
        "  --eye X,Y,Z --target X,Y,Z --up X,Y,Z   look-at camera, in the volume's world\n"
        "                        (a NRRD's space; else the box is centred at 0)\n"
        "  --fov DEG             vertical field of view (default 30)\n"
        "  --ortho H             orthographic camera of view height H\n"
        "  --light-dir X,Y,Z     directional light travelling along X,Y,Z\n"
        "  --light-pos X,Y,Z     point light at X,Y,Z (the volume's world)\n"
        "  --light-color R,G,B   light colour (default 1,1,1)\n"
        "  --ambient A           ambient light (default 0.2)\n"
        "  --step S              view sampling step in voxels (default 0.5)\n"
        "  --shading | --no-shading   Blinn-Phong gradient shading\n"
        "  --ground | --no-ground     opaque ground plane receiving shadows\n"
        "  --colored | --grey    transmission colour from the light TF's RGB, or grey\n"
        "  --background R,G,B,A  premultiplied background (default 0.08,0.08,0.1,1)\n"
        "  --jitter              jitter ray starts (seeded by --seed)\n"
        "  --seed N              seed for jitter and stochastic maps\n"
        "  --device SPEC         OpenCL device: P:D indices or a name substring\n"
        "  --progress | --no-progress   progress line on stderr (default: when it is a terminal)\n"
        "  --reference-step S    reference: shadow-ray step in voxels (default 0.25)\n"
        "  --map-size auto|N     light-space map resolution N^2 (default auto: K texels per\n"
        "                        voxel seen from the light, 64..2048; 0 is auto too)\n"
        "  --map-texels-per-voxel K   K for auto (default: threshold 1, cssm 3, deep 2; 1 is\n"
        "                        a draft while the light moves)\n"
        "  --map-step S          light-ray step in voxels (default: threshold and cssm 1,\n"
        "                        deep 0.5; 0 is the default too)\n"
        "  --threshold T --taps 1|7|13|21 --epsilon E --nodes N\n"
        "  --block-size K --prefilter 1|5 --no-lookup-table      light-space map parameters\n"
        "  --ray-block B         cssm: photons of B x B texels share a light ray (default:\n"
        "                        the map's texels per voxel, at most 3; 1: a ray per texel)\n"
        "  --slice-distance S --subsamples N --preintegrated --cone-angle DEG  convolution\n");
}

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
        fprintf(stderr, "umbra-render: --out '%s': the extension must be .png or .exr\n", path);
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
        fprintf(stderr, "umbra-render: --out: the directory name is longer than %zu bytes\n",
                sizeof dir - 1);
        return 1;
    }
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        fprintf(stderr, "umbra-render: --out '%s': the directory '%s' does not exist\n", path,
                dir);
        return 1;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        fprintf(stderr, "umbra-render: --out '%s': the directory '%s' is not writable\n", path,
                dir);
        return 1;
    }
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fprintf(stderr, "umbra-render: --out '%s' is a directory\n", path);
        return 1;
    }
    return 0;
}

/* Exit status for a failed library call, as the README states: 1 for bad input (an argument out
 * of range, a file that cannot be read or is malformed, a request the technique cannot do), 2 for
 * a failure of the device or of memory. */
int exit_status(umbra_status st)
{
    switch (st) {
    case UMBRA_SUCCESS: return 0;
    case UMBRA_ERROR_INVALID_ARGUMENT:
    case UMBRA_ERROR_IO:
    case UMBRA_ERROR_FORMAT:
    case UMBRA_ERROR_UNSUPPORTED: return 1;
    default: return 2; /* OUT_OF_MEMORY, OPENCL, BUILD, NO_DEVICE */
    }
}

static void on_error(void *user, umbra_status st, const char *msg)
{
    (void)user;
    if (st == UMBRA_ERROR_CANCELLED)
        return; /* reported as "interrupted" */
    fprintf(stderr, "umbra-render: %s: %s\n", umbra_status_to_string(st), msg);
}

/* Ctrl-C sets the flag; the progress callback, called between pieces of device work, reads it
 * and cancels the render, so the program still cleans up and exits with a message. */
static volatile sig_atomic_t interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    interrupted = 1;
}

typedef struct progress_state {
    int show;          /* print a progress line */
    double start_ms;   /* a line only once a render has run this long: short ones stay quiet */
    int shown;
} progress_state;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int on_progress(void *user, float fraction)
{
    progress_state *p = user;
    if (p->show && (p->shown || now_ms() - p->start_ms > 500.0)) {
        fprintf(stderr, "\rrendering: %5.1f%%", 100.0 * fraction);
        fflush(stderr);
        p->shown = 1;
    }
    return interrupted != 0;
}

#define BAD(...)                                                                               \
    do {                                                                                       \
        fprintf(stderr, "umbra-render: " __VA_ARGS__);                                         \
        fputc('\n', stderr);                                                                   \
        return 1;                                                                              \
    } while (0)

typedef struct options {
    const char *scene, *volume, *raw, *tf, *tf_preset, *light_tf, *out, *device;
    int platform_index, device_index; /* -1: not given */
    uint32_t scene_size, width, height;
    umbra_raw_desc raw_desc;
    int have_raw_dims, have_raw_type;
    float camera_dir[3], eye[3], target[3], up[3], fov, ortho;
    int have_camera_dir, have_eye, have_target, have_up;
    float light_dir[3], light_pos[3], light_color[3], ambient, step, background[4];
    int have_light_dir, have_light_pos, have_light_color, have_ambient, have_step;
    float tf_range[2];
    int have_tf_range;
    int shading, ground, colored, jitter, have_seed, have_background; /* -1: scene default */
    int progress;                                                   /* -1: when a terminal */
    uint32_t seed;
    umbra_shadow_desc shadow;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->scene = "spheres";
    o->out = "umbra.png";
    o->width = o->height = 512;
    o->fov = 30.0f;
    o->platform_index = o->device_index = -1;
    o->shading = o->ground = o->colored = o->progress = -1;
    umbra_raw_desc_init(&o->raw_desc);
    umbra_shadow_desc_init(&o->shadow);
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define FLAG(name) (strcmp(a, name) == 0)
#define NEED()                                                                                 \
    do {                                                                                       \
        if (!v)                                                                                \
            BAD("%s needs a value", a);                                                        \
        ++i;                                                                                   \
    } while (0)
        if (FLAG("--help") || FLAG("-h")) {
            usage(stdout);
            exit(0);
        } else if (FLAG("--version")) {
            printf("umbra-render %s (library %s)\n", UMBRA_VERSION_STRING, umbra_version());
            exit(0);
        } else if (FLAG("--scene")) { NEED(); o->scene = v; }
        else if (FLAG("--scene-size")) { NEED(); if (!parse_uint(v, &o->scene_size)) BAD("--scene-size '%s' is not a whole number", v); }
        else if (FLAG("--volume")) { NEED(); o->volume = v; }
        else if (FLAG("--raw")) { NEED(); o->raw = v; }
        else if (FLAG("--raw-dims")) {
            NEED();
            if (!parse_u32_list(v, 'x', 3, 1, UINT32_MAX, o->raw_desc.dims))
                BAD("--raw-dims '%s' is not XxYxZ with whole numbers in [1, %u]", v, UINT32_MAX);
            o->have_raw_dims = 1;
        } else if (FLAG("--raw-type")) {
            NEED();
            static const char *names[] = {"uint8", "uint16", "int16", "float32"};
            int k = -1;
            for (int t = 0; t < 4; ++t)
                if (strcmp(v, names[t]) == 0)
                    k = t;
            if (k < 0)
                BAD("--raw-type '%s' is not uint8, uint16, int16 or float32", v);
            o->raw_desc.type = (umbra_scalar_type)k;
            o->have_raw_type = 1;
        } else if (FLAG("--raw-big-endian")) o->raw_desc.big_endian = 1;
        else if (FLAG("--tf")) { NEED(); o->tf = v; }
        else if (FLAG("--tf-preset")) { NEED(); o->tf_preset = v; }
        else if (FLAG("--light-tf")) { NEED(); o->light_tf = v; }
        else if (FLAG("--tf-range")) { NEED(); if (!parse_floats(v, o->tf_range, 2)) BAD("--tf-range '%s' is not LO,HI", v); o->have_tf_range = 1; }
        else if (FLAG("--size")) {
            NEED();
            uint32_t wh[2];
            if (!parse_u32_list(v, 'x', 2, 1, 16384, wh))
                BAD("--size '%s' is not WxH with whole numbers in [1, 16384]", v);
            o->width = wh[0];
            o->height = wh[1];
        }
        else if (FLAG("--out")) { NEED(); o->out = v; }
        else if (FLAG("--technique")) {
            NEED();
            if (umbra_shadow_technique_parse(v, &o->shadow.technique) != UMBRA_SUCCESS)
                BAD("--technique '%s' is unknown (none, reference, threshold, deep, cssm, convolution)", v);
        }
        else if (FLAG("--camera-dir")) { NEED(); if (!parse_floats(v, o->camera_dir, 3)) BAD("--camera-dir '%s' is not X,Y,Z", v); o->have_camera_dir = 1; }
        else if (FLAG("--eye")) { NEED(); if (!parse_floats(v, o->eye, 3)) BAD("--eye '%s' is not X,Y,Z", v); o->have_eye = 1; }
        else if (FLAG("--target")) { NEED(); if (!parse_floats(v, o->target, 3)) BAD("--target '%s' is not X,Y,Z", v); o->have_target = 1; }
        else if (FLAG("--up")) { NEED(); if (!parse_floats(v, o->up, 3)) BAD("--up '%s' is not X,Y,Z", v); o->have_up = 1; }
        else if (FLAG("--fov")) { NEED(); if (!parse_floats(v, &o->fov, 1)) BAD("--fov '%s' is not a number", v); }
        else if (FLAG("--ortho")) { NEED(); if (!parse_floats(v, &o->ortho, 1) || !(o->ortho > 0)) BAD("--ortho '%s' is not a positive number", v); }
        else if (FLAG("--light-dir")) { NEED(); if (!parse_floats(v, o->light_dir, 3)) BAD("--light-dir '%s' is not X,Y,Z", v); o->have_light_dir = 1; }
        else if (FLAG("--light-pos")) { NEED(); if (!parse_floats(v, o->light_pos, 3)) BAD("--light-pos '%s' is not X,Y,Z", v); o->have_light_pos = 1; }
        else if (FLAG("--light-color")) { NEED(); if (!parse_floats(v, o->light_color, 3)) BAD("--light-color '%s' is not R,G,B", v); o->have_light_color = 1; }
        else if (FLAG("--ambient")) { NEED(); if (!parse_floats(v, &o->ambient, 1)) BAD("--ambient '%s' is not a number", v); o->have_ambient = 1; }
        else if (FLAG("--step")) { NEED(); if (!parse_floats(v, &o->step, 1)) BAD("--step '%s' is not a number", v); o->have_step = 1; }
        else if (FLAG("--background")) { NEED(); if (!parse_floats(v, o->background, 4)) BAD("--background '%s' is not R,G,B,A", v); o->have_background = 1; }
        else if (FLAG("--shading")) o->shading = 1;
        else if (FLAG("--no-shading")) o->shading = 0;
        else if (FLAG("--ground")) o->ground = 1;
        else if (FLAG("--no-ground")) o->ground = 0;
        else if (FLAG("--colored")) o->colored = 1;
        else if (FLAG("--grey")) o->colored = 0;
        else if (FLAG("--jitter")) o->jitter = 1;
        else if (FLAG("--seed")) { NEED(); if (!parse_uint(v, &o->seed)) BAD("--seed '%s' is not a whole number", v); o->have_seed = 1; o->shadow.seed = o->seed; }
        else if (FLAG("--device")) {
            /* P:D (platform and device indices) as the README documents, else a name substring. */
            NEED();
            uint32_t pd[2];
            if (parse_u32_list(v, ':', 2, 0, 1023, pd)) {
                o->platform_index = (int)pd[0];
                o->device_index = (int)pd[1];
            } else if (strchr(v, ':') && strspn(v, "0123456789:") == strlen(v)) {
                BAD("--device '%s': P:D indices must be whole numbers in [0, 1023]", v);
            } else {
                o->device = v;
            }
        }
        else if (FLAG("--progress")) o->progress = 1;
        else if (FLAG("--no-progress")) o->progress = 0;
        else if (FLAG("--reference-step")) { NEED(); if (!parse_floats(v, &o->shadow.reference_step, 1)) BAD("--reference-step '%s' is not a number", v); }
        else if (FLAG("--map-texels-per-voxel")) { NEED(); if (!parse_floats(v, &o->shadow.map_texels_per_voxel, 1)) BAD("--map-texels-per-voxel '%s' is not a number", v); }
        else if (FLAG("--map-size")) { NEED(); if (strcmp(v, "auto") == 0) o->shadow.map_size = UMBRA_MAP_SIZE_AUTO; else if (!parse_uint(v, &o->shadow.map_size)) BAD("--map-size '%s' is not 'auto' or a whole number", v); }
        else if (FLAG("--map-step")) { NEED(); if (!parse_floats(v, &o->shadow.map_step, 1)) BAD("--map-step '%s' is not a number", v); }
        else if (FLAG("--threshold")) { NEED(); if (!parse_floats(v, &o->shadow.threshold, 1)) BAD("--threshold '%s' is not a number", v); }
        else if (FLAG("--taps")) { NEED(); if (!parse_uint(v, &o->shadow.taps)) BAD("--taps '%s' is not a whole number", v); }
        else if (FLAG("--ray-block")) { NEED(); if (!parse_uint(v, &o->shadow.ray_block)) BAD("--ray-block '%s' is not a whole number", v); }
        else if (FLAG("--epsilon")) { NEED(); if (!parse_floats(v, &o->shadow.epsilon, 1)) BAD("--epsilon '%s' is not a number", v); }
        else if (FLAG("--nodes")) { NEED(); if (!parse_uint(v, &o->shadow.max_nodes)) BAD("--nodes '%s' is not a whole number", v); }
        else if (FLAG("--block-size")) { NEED(); if (!parse_uint(v, &o->shadow.block_size)) BAD("--block-size '%s' is not a whole number", v); }
        else if (FLAG("--prefilter")) { NEED(); if (!parse_uint(v, &o->shadow.prefilter)) BAD("--prefilter '%s' is not a whole number", v); }
        else if (FLAG("--no-lookup-table")) o->shadow.lookup_table = 0;
        else if (FLAG("--slice-distance")) { NEED(); if (!parse_floats(v, &o->shadow.slice_distance, 1)) BAD("--slice-distance '%s' is not a number", v); }
        else if (FLAG("--subsamples")) { NEED(); if (!parse_uint(v, &o->shadow.subsamples)) BAD("--subsamples '%s' is not a whole number", v); }
        else if (FLAG("--preintegrated")) o->shadow.preintegrated = 1;
        else if (FLAG("--cone-angle")) { NEED(); if (!parse_floats(v, &o->shadow.cone_angle_degrees, 1)) BAD("--cone-angle '%s' is not a number", v); }
        else BAD("unknown option '%s' (see --help)", a);
#undef FLAG
#undef NEED
    }
    if (o->raw && (!o->have_raw_dims || !o->have_raw_type))
        BAD("--raw needs --raw-dims and --raw-type");
    if (o->have_light_dir && o->have_light_pos)
        BAD("--light-dir and --light-pos exclude each other");
    return check_output(o->out);
}

void session_end(session *s)
{
    free(s->pixels);
    umbra_renderer_release(s->renderer);
    umbra_transfer_function_release(s->light_tf);
    umbra_transfer_function_release(s->tf);
    umbra_volume_release(s->volume);
    umbra_scene_release(&s->scene);
    umbra_context_release(s->ctx);
}

/* A ParaView preset (its x values are data values: the loaded table carries that range) or
 * umbra's text format. */
static umbra_status load_tf(umbra_context ctx, const char *path, const char *preset,
                            umbra_transfer_function *out)
{
    size_t n = strlen(path);
    if (n > 5 && strcmp(path + n - 5, ".json") == 0) {
        umbra_paraview_options po;
        umbra_paraview_options_init(&po);
        po.preset = preset;
        return umbra_transfer_function_load_paraview(ctx, path, &po, out, NULL);
    }
    return umbra_transfer_function_load(ctx, path, out);
}

/* Everything up to a renderer ready to render: context, volume, transfer functions, camera,
 * light, options and shadow technique, kept in s (umbra_render.h). Returns an exit status. */
static int session_begin(const options *o, session *s)
{
    umbra_context_desc cd;
    umbra_context_desc_init(&cd);
    cd.device_name = o->device;
    cd.platform_index = o->platform_index;
    cd.device_index = o->device_index;
    cd.error_callback = on_error;
    umbra_status st = umbra_context_create(&cd, &s->ctx);
    if (st != UMBRA_SUCCESS)
        return exit_status(st);
    fprintf(stderr, "device: %s\n", umbra_context_device_name(s->ctx));
    double t0 = 0;
    (void)t0;
    umbra_volume vol = NULL;
    umbra_transfer_function tf = NULL;
    umbra_render_desc rd;
    umbra_render_desc_init(&rd);
    umbra_camera cam;
    umbra_light light;
    if (o->volume || o->raw) {
        st = o->volume ? umbra_volume_load(s->ctx, o->volume, &s->volume)
                       : umbra_volume_load_raw(s->ctx, o->raw, &o->raw_desc, &s->volume);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        vol = s->volume;
        umbra_volume_info info;
        umbra_volume_get_info(vol, &info);
        float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                           info.extent[2] * info.extent[2]);
        const float dir[3] = {0.75f, 0.5f, 1.0f};
        /* Around the box's world centre: a NRRD with a space origin is not centred on 0. */
        cam = umbra_camera_orbit_at(info.center, dir, diag, o->fov);
        memset(&light, 0, sizeof light);
        light.type = UMBRA_LIGHT_DIRECTIONAL;
        light.direction[0] = 0.45f;
        light.direction[1] = -1.0f;
        light.direction[2] = 0.25f;
        light.color[0] = light.color[1] = light.color[2] = 1.0f;
        rd.ground_plane = 1;
        if (!o->tf) {
            /* A generic ramp: low values transparent, high values white and denser. */
            const umbra_tf_point pts[] = {{0.0f, {1, 1, 1, 0}}, {0.2f, {1, 1, 1, 0}},
                                          {0.5f, {0.9f, 0.8f, 0.7f, 0.05f}},
                                          {1.0f, {1, 1, 1, 0.4f}}};
            st = umbra_transfer_function_create_from_points(s->ctx, pts, 4, 256, &s->tf);
            if (st != UMBRA_SUCCESS)
                return exit_status(st);
            tf = s->tf;
        }
    } else {
        st = umbra_scene_create(s->ctx, o->scene, o->scene_size, &s->scene);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        vol = s->scene.volume;
        tf = s->scene.tf;
        cam = s->scene.camera;
        light = s->scene.light;
        rd = s->scene.options;
    }
    if (o->tf) {
        st = load_tf(s->ctx, o->tf, o->tf_preset, &s->tf);
        if (st != UMBRA_SUCCESS)
            return exit_status(st);
        tf = s->tf;
    }
    if (o->light_tf &&
        (st = load_tf(s->ctx, o->light_tf, o->tf_preset, &s->light_tf)) != UMBRA_SUCCESS)
        return exit_status(st);
    /* The library checks LO < HI and names the values. */
    if (o->have_tf_range &&
        ((st = umbra_transfer_function_set_range(tf, o->tf_range[0], o->tf_range[1])) !=
             UMBRA_SUCCESS ||
         (s->light_tf && (st = umbra_transfer_function_set_range(s->light_tf, o->tf_range[0],
                                                                 o->tf_range[1])) != UMBRA_SUCCESS)))
        return exit_status(st);

    if (o->have_camera_dir) {
        umbra_volume_info info;
        umbra_volume_get_info(vol, &info);
        float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                           info.extent[2] * info.extent[2]);
        cam = umbra_camera_orbit_at(info.center, o->camera_dir, diag * 1.1f, o->fov);
    }
    if (o->have_eye) memcpy(cam.eye, o->eye, sizeof cam.eye);
    if (o->have_target) memcpy(cam.target, o->target, sizeof cam.target);
    if (o->have_up) memcpy(cam.up, o->up, sizeof cam.up);
    cam.fovy_degrees = o->fov;
    if (o->ortho > 0) {
        cam.projection = UMBRA_ORTHOGRAPHIC;
        cam.ortho_height = o->ortho;
    }
    if (o->have_light_dir) {
        light.type = UMBRA_LIGHT_DIRECTIONAL;
        memcpy(light.direction, o->light_dir, sizeof light.direction);
    }
    if (o->have_light_pos) {
        light.type = UMBRA_LIGHT_POINT;
        memcpy(light.position, o->light_pos, sizeof light.position);
    }
    if (o->have_light_color) memcpy(light.color, o->light_color, sizeof light.color);
    if (o->have_ambient) rd.ambient[0] = rd.ambient[1] = rd.ambient[2] = o->ambient;
    if (o->have_step) rd.step = o->step;
    if (o->shading >= 0) rd.shading = o->shading;
    if (o->ground >= 0) rd.ground_plane = o->ground;
    if (o->colored >= 0) rd.transmission = o->colored ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
    rd.jitter = o->jitter;
    if (o->have_seed) rd.seed = o->seed;
    if (o->have_background) memcpy(rd.background, o->background, sizeof rd.background);
    else { rd.background[0] = 0.08f; rd.background[1] = 0.08f; rd.background[2] = 0.1f; rd.background[3] = 1.0f; }

    if ((st = umbra_renderer_create(s->ctx, &s->renderer)) != UMBRA_SUCCESS)
        return exit_status(st);
    umbra_renderer r = s->renderer;
    if ((st = umbra_renderer_set_volume(r, vol)) ||
        (st = umbra_renderer_set_transfer_function(r, tf)) ||
        (s->light_tf && (st = umbra_renderer_set_light_transfer_function(r, s->light_tf))) ||
        (st = umbra_renderer_set_camera(r, &cam)) || (st = umbra_renderer_set_light(r, &light)) ||
        (st = umbra_renderer_set_options(r, &rd)) ||
        (st = umbra_renderer_set_shadow(r, &o->shadow)))
        return exit_status(st);
    s->view_volume = vol;
    s->view_tf = tf;
    s->camera = cam;
    s->light = light;
    s->options = rd;
    s->shadow = o->shadow;
    s->width = o->width;
    s->height = o->height;
    s->out = o->out;
    return 0;
}

int session_open(int argc, char **argv, session *s)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    return rc ? rc : session_begin(&o, s);
}

static int run(const options *o, session *s)
{
    int rc = session_begin(o, s);
    if (rc)
        return rc;
    umbra_renderer r = s->renderer;
    s->pixels = malloc((size_t)o->width * o->height * 4 * sizeof(float));
    if (!s->pixels) {
        fprintf(stderr, "umbra-render: out of memory for a %ux%u image\n", o->width, o->height);
        return 2;
    }
    progress_state prog = {o->progress < 0 ? isatty(STDERR_FILENO) : o->progress, now_ms(), 0};
    umbra_renderer_set_progress(r, on_progress, &prog);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    umbra_status rst = umbra_renderer_render(r, o->width, o->height, s->pixels);
    if (prog.shown)
        fputc('\n', stderr);
    if (rst == UMBRA_ERROR_CANCELLED) {
        fprintf(stderr, "umbra-render: interrupted\n");
        return 130;
    }
    if (rst != UMBRA_SUCCESS)
        return exit_status(rst);
    umbra_render_stats stats;
    umbra_renderer_get_stats(r, &stats);
    fprintf(stderr, "technique: %s (%u light channel%s)\n",
            umbra_shadow_technique_name(o->shadow.technique), stats.light_channels,
            stats.light_channels == 1 ? "" : "s");
    fprintf(stderr, "shadow build: %.2f ms\n", stats.shadow_build_ms);
    fprintf(stderr, "render: %.2f ms (%llu samples)\n", stats.render_ms,
            (unsigned long long)stats.samples);
    fprintf(stderr, "shadow memory: %zu bytes\n", stats.shadow_memory_bytes);
    if (stats.slices)
        fprintf(stderr, "slices: %u\n", stats.slices);
    if (stats.map_size)
        fprintf(stderr, "map size: %u x %u%s\n", stats.map_size, stats.map_size,
                o->shadow.map_size == UMBRA_MAP_SIZE_AUTO ? " (auto)" : "");
    /* The path was checked before the render; failing now (a full disk) is not bad input. */
    if (umbra_image_write(s->ctx, o->out, o->width, o->height, s->pixels) != UMBRA_SUCCESS)
        return 2;
    fprintf(stderr, "wrote %s\n", o->out);
    return 0;
}

int umbra_render_main(int argc, char **argv)
{
    options o;
    if (parse_args(argc, argv, &o) != 0)
        return 1;
    session s;
    memset(&s, 0, sizeof s);
    int rc = run(&o, &s);
    session_end(&s);
    return rc;
}

#ifndef UMBRA_RENDER_NO_MAIN
int main(int argc, char **argv)
{
    return umbra_render_main(argc, argv);
}
#endif
