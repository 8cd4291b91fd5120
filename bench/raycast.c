// SPDX-License-Identifier: Apache-2.0
/* bench/raycast.c: `umbra-bench raycast`, the foundation's speed check.
 * Why one file past 800 lines: one benchmark, whose options, frames taken in turns and report
 * share one scene and view.
 *
 * One view of each scene, the bonsai CT (or its procedural stand-in, bench_util.c; 8-bit) and the
 * walnut CT (16-bit; skipped when its file is missing), at 512x512, view step 0.5 voxel, no
 * shadows (technique none), no jitter, early ray termination at 0.99 and empty-space skipping on,
 * twice: without shading and with gradient Blinn-Phong shading (--shading or --no-shading times
 * one of the two), rendered by
 *   umbra     umbra_renderer_render on the OpenCL device (PoCL's CPU device here): device time of
 *             the kernel (stats.render_ms) and, as umbra_wall, the wall time of the whole call
 *             including the read-back of the image;
 *   native_c  cpu_render_prepared from tests/reference/cpu_reference.c, the plain-C twin of the
 *             same algorithm, compiled -O3 -march=native with OpenMP over image rows: what
 *             hand-written C reaches on this CPU. Its per-scene preparation (step-corrected tables,
 *             brick visibility) is done once outside the timing, as umbra keeps those between
 *             frames too;
 *   vtk_fixedpoint  VTK's CPU ray caster, vtkFixedPointVolumeRayCastMapper, on the same volume,
 *             view, transfer function and sample distance (bench/vtk_raycast.py, run as a second
 *             process under xvfb-run when there is no display), when a python3 that imports vtk
 *             is found ($UMBRA_PYTHON, python3, /usr/bin/python3): wall time of
 *             vtkRenderWindow::Render of an off-screen window.
 * After the warm-up frames the three take turns frame by frame, so that other processes' load,
 * which on a shared machine changes from second to second, touches all three alike. umbra and
 * native_c take the same samples (the same positions; samples in skipped bricks are not
 * counted) up to float rounding, which gives a handful of rays one sample more or less and those
 * pixels a difference of a few 1e-3; both numbers are checked and reported. Medians, minima and maxima are over the timed frames.
 *
 * The view (also in bench/README.md): a perspective camera with 30 degrees vertical field of
 * view, looking at the volume's centre from 1.5 box diagonals away along (0.35, 0.25, 1), y up
 * (the bonsai stands along +y). The transfer functions: bonsai_tf below, the same control points
 * as bench/scenes/bonsai.tf (foliage translucent green, trunk brown, pot opaque), and walnut_tf,
 * those of examples/walnut.tf (shell and kernel translucent), 256 entries, alpha per voxel step,
 * over each volume's value range; VTK gets the same points. Ambient 0 and a white light make each
 * sample's colour its table colour. The walnut's rows carry the prefix walnut_. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"
#include "cpu_reference.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

static const umbra_tf_point bonsai_tf[] = {
    {0.00f, {0.00f, 0.00f, 0.00f, 0.00f}},
    {0.18f, {0.25f, 0.60f, 0.15f, 0.00f}},
    {0.22f, {0.25f, 0.60f, 0.15f, 0.06f}}, /* foliage */
    {0.38f, {0.30f, 0.55f, 0.15f, 0.06f}},
    {0.42f, {0.55f, 0.35f, 0.15f, 0.00f}},
    {0.46f, {0.55f, 0.35f, 0.15f, 0.25f}}, /* trunk */
    {0.68f, {0.55f, 0.35f, 0.15f, 0.25f}},
    {0.72f, {0.80f, 0.45f, 0.30f, 0.50f}}, /* pot */
    {1.00f, {0.80f, 0.45f, 0.30f, 0.50f}},
};
/* examples/walnut.tf's points (bench/scenes/walnut.scene's transfer function). */
static const umbra_tf_point walnut_tf[] = {
    {0.00f, {0.00f, 0.00f, 0.00f, 0.00f}},
    {0.20f, {0.95f, 0.85f, 0.50f, 0.00f}},
    {0.24f, {0.95f, 0.85f, 0.50f, 0.03f}}, /* kernel */
    {0.31f, {0.95f, 0.85f, 0.50f, 0.03f}},
    {0.335f, {0.80f, 0.40f, 0.15f, 0.02f}},
    {0.37f, {0.80f, 0.36f, 0.12f, 0.07f}}, /* shell */
    {0.50f, {0.80f, 0.36f, 0.12f, 0.07f}},
    {0.60f, {0.90f, 0.90f, 0.90f, 0.30f}}, /* rare dense specks */
    {1.00f, {0.90f, 0.90f, 0.90f, 0.30f}},
};
enum { TF_RESOLUTION = 256 };

/* A scene the benchmark times: its volume file (found as bench_find_volume does) and transfer
 * function; prefix begins its rows' names. */
typedef struct raycast_scene {
    const char *name, *file, *prefix;
    const umbra_tf_point *tf;
    size_t tf_count;
} raycast_scene;

static const raycast_scene scenes[] = {
    {"bonsai", "bonsai.nhdr", "", bonsai_tf, sizeof bonsai_tf / sizeof bonsai_tf[0]},
    {"walnut", "walnut.nhdr", "walnut_", walnut_tf, sizeof walnut_tf / sizeof walnut_tf[0]},
};
enum { SCENES = sizeof scenes / sizeof scenes[0] };

static const float view_dir[3] = {0.35f, 0.25f, 1.0f};
static const float view_distance = 1.5f; /* box diagonals */
static const float view_fovy = 30.0f;

typedef struct options {
    int runs, warmup;
    uint32_t width, height;
    float step;
    const char *volume;
    char scenes[64];
    int procedural;
    int vtk;
    const char *results;
    const char *device;
    const char *save;
    int shading; /* -1: both cases (default), 0: unshaded only, 1: shaded only */
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench raycast [options]\n"
            "  --runs N         timed runs per case (default 7), after\n"
            "  --warmup N       untimed warm-up runs (default 2)\n"
            "  --size WxH       image size (default 512x512)\n"
            "  --step S         view step in voxels (default 0.5)\n"
            "  --scenes A,B     bonsai, walnut or both (default bonsai,walnut)\n"
            "  --volume FILE    volume instead of the bonsai (.nrrd/.nhdr/.dat)\n"
            "  --procedural     use the procedural 256^3 stand-in even if the bonsai is present\n"
            "  --shading        time only the shaded case (gradient Blinn-Phong)\n"
            "  --no-shading     time only the unshaded case (default: both, in turn)\n"
            "  --no-vtk         skip the VTK rows\n"
            "  --device SPEC    OpenCL device (P:D or a name substring; default $UMBRA_DEVICE)\n"
            "  --results DIR    also write DIR/raycast.csv and DIR/raycast.md\n"
            "  --save PREFIX    write PREFIX_umbra.png, PREFIX_native_c.png (and _vtk.png)\n"
            "Prints CSV (" BENCH_CSV_HEADER ") on stdout: rows umbra (device time),\n"
            "umbra_wall, native_c and, when python3 imports vtk, vtk_fixedpoint (frames\n"
            "interleaved with umbra's), each again with the suffix _shaded for the shaded case,\n"
            "and the walnut's the same with the prefix walnut_; the ratio of umbra's samples/s\n"
            "to native_c's and of VTK's time per frame to umbra's, per case, on stderr.\n");
}

static int parse(int argc, char **argv, options *o)
{
    o->runs = 7;
    o->warmup = 2;
    o->width = o->height = 512;
    o->step = 0.5f;
    o->volume = NULL;
    snprintf(o->scenes, sizeof o->scenes, "bonsai,walnut");
    o->procedural = 0;
    o->vtk = 1;
    o->results = NULL;
    o->device = NULL;
    o->save = NULL;
    o->shading = -1;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long n;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        } else if (strcmp(a, "--runs") == 0) {
            if (bench_parse_int(v, 1, 1000, &n)) {
                fprintf(stderr, "umbra-bench raycast: --runs '%s': need 1..1000\n", v ? v : "");
                return -1;
            }
            o->runs = (int)n;
            ++i;
        } else if (strcmp(a, "--warmup") == 0) {
            if (bench_parse_int(v, 0, 1000, &n)) {
                fprintf(stderr, "umbra-bench raycast: --warmup '%s': need 0..1000\n", v ? v : "");
                return -1;
            }
            o->warmup = (int)n;
            ++i;
        } else if (strcmp(a, "--size") == 0) {
            if (bench_parse_size(v, &o->width, &o->height)) {
                fprintf(stderr, "umbra-bench raycast: --size '%s': need WxH\n", v ? v : "");
                return -1;
            }
            ++i;
        } else if (strcmp(a, "--step") == 0) {
            if (bench_parse_float(v, 0.01f, 64.0f, &o->step)) {
                fprintf(stderr, "umbra-bench raycast: --step '%s': need 0.01..64\n", v ? v : "");
                return -1;
            }
            ++i;
        } else if (strcmp(a, "--volume") == 0 && v) {
            o->volume = v;
            ++i;
        } else if (strcmp(a, "--scenes") == 0 && v) {
            for (const char *c = v; *c;) {
                size_t n = strcspn(c, ",");
                int known = 0;
                for (int k = 0; k < SCENES; ++k)
                    known |= strlen(scenes[k].name) == n && strncmp(c, scenes[k].name, n) == 0;
                if (!known || n == 0) {
                    fprintf(stderr, "umbra-bench raycast: --scenes '%s': need bonsai, walnut\n",
                            v);
                    return -1;
                }
                c += n + (c[n] == ',');
            }
            snprintf(o->scenes, sizeof o->scenes, "%s", v);
            ++i;
        } else if (strcmp(a, "--device") == 0 && v) {
            o->device = v;
            ++i;
        } else if (strcmp(a, "--results") == 0 && v) {
            o->results = v;
            ++i;
        } else if (strcmp(a, "--save") == 0 && v) {
            o->save = v;
            ++i;
        } else if (strcmp(a, "--procedural") == 0) {
            o->procedural = 1;
        } else if (strcmp(a, "--shading") == 0) {
            o->shading = 1;
        } else if (strcmp(a, "--no-shading") == 0) {
            o->shading = 0;
        } else if (strcmp(a, "--no-vtk") == 0) {
            o->vtk = 0;
        } else {
            fprintf(stderr, "umbra-bench raycast: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return -1;
        }
    }
    return 0;
}

static umbra_camera bench_camera(const bench_volume *v)
{
    float diag = 0.0f, len = 0.0f;
    for (int a = 0; a < 3; ++a) {
        float e = (float)v->dims[a] * v->spacing[a];
        diag += e * e;
        len += view_dir[a] * view_dir[a];
    }
    diag = sqrtf(diag);
    len = sqrtf(len);
    umbra_camera c;
    memset(&c, 0, sizeof c);
    c.projection = UMBRA_PERSPECTIVE;
    for (int a = 0; a < 3; ++a)
        c.eye[a] = view_dir[a] / len * view_distance * diag;
    c.up[1] = 1.0f;
    c.fovy_degrees = view_fovy;
    c.ortho_height = diag;
    return c;
}

/* ---- VTK -------------------------------------------------------------------------------------- */

/* A python3 that imports VTK's volume rendering, or NULL. */
static const char *find_vtk_python(void)
{
    static const char *const fixed[] = {"python3", "/usr/bin/python3"};
    const char *env = getenv("UMBRA_PYTHON");
    const char *cands[3];
    int n = 0;
    if (env && *env)
        cands[n++] = env;
    cands[n++] = fixed[0];
    cands[n++] = fixed[1];
    char cmd[1200];
    for (int i = 0; i < n; ++i) {
        snprintf(cmd, sizeof cmd,
                 "'%s' -c 'import vtkmodules.vtkRenderingVolume, vtkmodules.vtkRenderingVolumeOpenGL2' >/dev/null 2>&1", cands[i]);
        if (system(cmd) == 0)
            return cands[i];
    }
    return NULL;
}

/* bench/vtk_raycast.py --serve, running beside umbra-bench: a frame per request. */
typedef struct vtk_peer {
    pid_t pid;
    FILE *to, *from;
} vtk_peer;

/* Starts the script on the benchmark's view; 0 once it has set up and warmed up. */
static int vtk_start(const options *o, const raycast_scene *sc, const bench_volume *v,
                     const umbra_camera *cam, const umbra_render_desc *shaded,
                     const umbra_light *light, float step_world, vtk_peer *peer, char *why,
                     size_t why_size)
{
    memset(peer, 0, sizeof *peer);
    peer->pid = -1;
    const char *py = find_vtk_python();
    if (!py) {
        snprintf(why, why_size, "no python3 imports vtk (Debian: apt-get install python3-vtk9)");
        return -1;
    }
    if (!v->path[0]) {
        snprintf(why, why_size, "the volume has no file VTK could read");
        return -1;
    }
    /* VTK's render window needs an X display; Xvfb provides one on a headless machine. */
    const char *display = getenv("DISPLAY");
    int xvfb = !(display && *display) && system("command -v xvfb-run >/dev/null 2>&1") == 0;
    char tf[1024] = "";
    size_t len = 0;
    for (size_t i = 0; i < sc->tf_count && len < sizeof tf; ++i)
        len += (size_t)snprintf(tf + len, sizeof tf - len, "%s%g,%g,%g,%g,%g", i ? ";" : "",
                                sc->tf[i].value, sc->tf[i].rgba[0], sc->tf[i].rgba[1],
                                sc->tf[i].rgba[2], sc->tf[i].rgba[3]);
    char save[600] = "";
    if (o->save)
        snprintf(save, sizeof save, " --save '%s_%svtk.png'", o->save, sc->prefix);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "exec %s'%s' '%s/bench/vtk_raycast.py' --serve --nrrd '%s' --size %u %u "
             "--eye %.9g %.9g %.9g --target %.9g %.9g %.9g --up %.9g %.9g %.9g --fovy %.9g "
             "--step %.9g --range %.9g %.9g --tf '%s' --warmup %d --shading %.9g %.9g %.9g "
             "--light %.9g %.9g %.9g%s",
             xvfb ? "xvfb-run -a " : "", py, UMBRA_SOURCE_DIR, v->path, o->width, o->height,
             cam->eye[0], cam->eye[1], cam->eye[2], cam->target[0], cam->target[1],
             cam->target[2], cam->up[0], cam->up[1], cam->up[2], cam->fovy_degrees, step_world,
             v->value_min, v->value_max, tf, o->warmup, shaded->kd, shaded->ks,
             shaded->shininess, light->direction[0], light->direction[1], light->direction[2],
             save);
    int in[2], out[2];
    if (pipe(in) != 0)
        goto broken;
    if (pipe(out) != 0) {
        close(in[0]);
        close(in[1]);
        goto broken;
    }
    fflush(NULL);
    peer->pid = fork();
    if (peer->pid == 0) {
        dup2(in[0], STDIN_FILENO);
        dup2(out[1], STDOUT_FILENO);
        close(in[0]);
        close(in[1]);
        close(out[0]);
        close(out[1]);
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    close(in[0]);
    close(out[1]);
    if (peer->pid < 0) {
        close(in[1]);
        close(out[0]);
        goto broken;
    }
    peer->to = fdopen(in[1], "w");
    peer->from = fdopen(out[0], "r");
    if (!peer->to || !peer->from)
        goto broken;
    char line[256];
    while (fgets(line, sizeof line, peer->from))
        if (strncmp(line, "ready", 5) == 0)
            return 0;
broken:
    snprintf(why, why_size, "bench/vtk_raycast.py did not start (run it by hand to see why)");
    return -1;
}

/* One frame, shaded or not; its wall time in ms, or a negative value if the peer failed. */
static double vtk_frame(vtk_peer *peer, int shaded)
{
    char line[256];
    double ms;
    if (fputs(shaded ? "frame shaded\n" : "frame\n", peer->to) == EOF || fflush(peer->to) != 0)
        return -1.0;
    while (fgets(line, sizeof line, peer->from))
        if (sscanf(line, "ms %lf", &ms) == 1)
            return ms;
    return -1.0;
}

/* Ends the peer; 0 if it exited cleanly. */
static int vtk_stop(vtk_peer *peer)
{
    int status = -1;
    if (peer->to) {
        fputs("quit\n", peer->to);
        fclose(peer->to);
    }
    if (peer->from) {
        char line[256];
        while (fgets(line, sizeof line, peer->from))
            ; /* drain until the script exits */
        fclose(peer->from);
    }
    if (peer->pid > 0 && waitpid(peer->pid, &status, 0) != peer->pid)
        status = -1;
    memset(peer, 0, sizeof *peer);
    return status == 0 ? 0 : -1;
}

/* ---- the report ------------------------------------------------------------------------------------ */

typedef struct row {
    const char *name;
    bench_timing t;
    uint64_t samples;
} row;

/* One of the two views the benchmark times: without shading (the foundation's check) or with
 * gradient Blinn-Phong shading; everything else alike. */
typedef struct bench_case {
    const raycast_scene *scene;
    const bench_volume *vol;
    int shading;
    const char *suffix; /* "" or "_shaded": appended to the row names */
    char names[4][48];  /* the rows' names: the scene's prefix, the renderer, the suffix */
    umbra_renderer r;
    cpu_scene cs; /* cpu_prepare keeps a pointer to it */
    cpu_prepared *prepared;
    float *img_umbra, *img_native;
    double *t_dev, *t_wall, *t_native, *t_vtk;
    uint64_t samples_umbra, samples_native;
    double diff; /* largest pixel difference umbra vs native C */
    double diff_six; /* shaded: umbra vs the C twin's shading before issue #12; else -1 */
    double ratio, vtk_ratio;
    row rows[4];
    int nrows;
} bench_case;

/* The 1-minute load average from /proc/loadavg (Linux), or a negative value. */
static double load_average(void)
{
    double load = -1.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &load) != 1)
            load = -1.0;
        fclose(f);
    }
    return load;
}

/* The scenes' load averages (1 minute) before and after their frames. */
typedef struct scene_load {
    const raycast_scene *scene;
    double before, after;
} scene_load;

static int write_results(const options *o, int argc, char **argv, const char *device,
                         const bench_case *cases, int ncases, const umbra_render_desc *shaded,
                         const scene_load *loads, int nscenes)
{
    FILE *f = bench_results_open(o->results, "raycast", "csv");
    if (!f)
        return -1;
    fprintf(f, "%s\n", BENCH_CSV_HEADER);
    for (int c = 0; c < ncases; ++c)
        for (int i = 0; i < cases[c].nrows; ++i)
            bench_csv_row(f, cases[c].rows[i].name, cases[c].rows[i].t, cases[c].rows[i].samples);
    fclose(f);
    if (!(f = bench_results_open(o->results, "raycast", "md")))
        return -1;
    bench_results_header(f, "raycast", argc, argv, device);
#ifdef _OPENMP
    fprintf(f, "- native C: OpenMP, %d threads\n", omp_get_max_threads());
#else
    fprintf(f, "- native C: built without OpenMP (1 thread)\n");
#endif
    for (int c = 0; c < ncases; ++c)
        if (c == 0 || cases[c].vol != cases[c - 1].vol)
            fprintf(f, "- volume%s%s: %s (%u x %u x %u), transfer function: %s (bench/raycast.c)\n",
                    cases[c].scene->prefix[0] ? " of the rows " : "",
                    cases[c].scene->prefix[0] ? cases[c].scene->prefix : "",
                    cases[c].vol->description, cases[c].vol->dims[0], cases[c].vol->dims[1],
                    cases[c].vol->dims[2],
                    strcmp(cases[c].scene->name, "walnut") == 0 ? "examples/walnut.tf's points"
                                                                : "bench/scenes/bonsai.tf's "
                                                                  "points");
    fprintf(f, "- view: %ux%u, step %g voxel, no shadows, early termination 0.99, empty-space "
               "skipping (camera and transfer function: bench/README.md)\n",
            o->width, o->height, o->step);
    fprintf(f, "- shading: rows without a suffix none; rows `_shaded` gradient Blinn-Phong, kd %g, "
               "ks %g, shininess %g, ambient 0, one directional white light from +y (VTK: the "
               "same coefficients and light)\n",
            shaded->kd, shaded->ks, shaded->shininess);
    fprintf(f, "- medians of %d frames after %d warm-up frames; umbra, native C and VTK take "
               "turns frame by frame, unshaded and shaded in the same turn, one scene after the "
               "other\n",
            o->runs, o->warmup);
    for (int k = 0; k < nscenes; ++k)
        if (loads[k].before >= 0.0 && loads[k].after >= 0.0)
            fprintf(f, "- load average (1 minute) before / after the %s's frames: %.1f / %.1f "
                       "(the three renderers use every CPU; a load above that means other "
                       "processes shared the machine: compare the ratios of one run, not times "
                       "across runs)\n",
                    loads[k].scene->name, loads[k].before, loads[k].after);
    fprintf(f, "\n");
    fprintf(f, "| case | ms median | samples/s | samples | ms min | ms max |\n"
               "|---|---:|---:|---:|---:|---:|\n");
    for (int c = 0; c < ncases; ++c)
        for (int i = 0; i < cases[c].nrows; ++i) {
            const row *rw = &cases[c].rows[i];
            if (rw->samples)
                fprintf(f, "| %s | %.1f | %.3g | %llu | %.1f | %.1f |\n", rw->name, rw->t.median,
                        (double)rw->samples / (rw->t.median * 1e-3),
                        (unsigned long long)rw->samples, rw->t.min, rw->t.max);
            else
                fprintf(f, "| %s | %.1f | | | %.1f | %.1f |\n", rw->name, rw->t.median,
                        rw->t.min, rw->t.max);
        }
    fprintf(f, "\n");
    for (int c = 0; c < ncases; ++c) {
        const bench_case *bc = &cases[c];
        const char *what = bc->shading ? "shaded" : "unshaded";
        fprintf(f, "%s, %s: umbra / native C samples per second **%.2f** (target >= 0.9)",
                bc->scene->name, what, bc->ratio);
        if (bc->vtk_ratio > 0.0)
            fprintf(f, "; VTK / umbra time per frame **%.2f** (target %s)", bc->vtk_ratio,
                    bc->shading ? ">= 1.0" : ">= 1.2");
        if (bc->samples_umbra == bc->samples_native)
            fprintf(f, "; samples identical (%llu)", (unsigned long long)bc->samples_umbra);
        else
            fprintf(f, "; samples %llu vs %llu (float rounding at brick faces and ray ends)",
                    (unsigned long long)bc->samples_umbra,
                    (unsigned long long)bc->samples_native);
        fprintf(f, "; largest pixel difference umbra vs native C %.2e", bc->diff);
        if (bc->diff_six >= 0.0)
            fprintf(f, ", vs the C twin shading as before issue #12 (six-sample gradient, powf) "
                       "%.2e", bc->diff_six);
        fprintf(f, ".\n\n");
    }
    fclose(f);
    fprintf(stderr, "wrote %s/raycast.csv and %s/raycast.md\n", o->results, o->results);
    return 0;
}

static void save_png(umbra_context ctx, const char *prefix, const char *name, uint32_t w,
                     uint32_t h, const float *rgba)
{
    char path[600];
    snprintf(path, sizeof path, "%s_%s.png", prefix, name);
    if (umbra_image_write(ctx, path, w, h, rgba) != UMBRA_SUCCESS)
        fprintf(stderr, "umbra-bench raycast: %s\n", umbra_context_last_message(ctx));
}

/* ---- the benchmark ------------------------------------------------------------------------------------ */

/* Renders one umbra frame: device and wall milliseconds, samples. */
static int umbra_frame(umbra_context ctx, umbra_renderer r, const options *o, float *rgba,
                       double *dev_ms, double *wall_ms, uint64_t *samples)
{
    double t0 = bench_now_ms();
    if (umbra_renderer_render(r, o->width, o->height, rgba) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench raycast: %s\n", umbra_context_last_message(ctx));
        return -1;
    }
    *wall_ms = bench_now_ms() - t0;
    umbra_render_stats st;
    umbra_renderer_get_stats(r, &st);
    *dev_ms = st.render_ms;
    *samples = st.samples;
    return 0;
}

/* Sets up one case's umbra renderer and native-C twin; 0 on success. */
static int case_setup(umbra_context ctx, const options *o, bench_volume *vol,
                      umbra_transfer_function tf, const umbra_camera *cam,
                      const umbra_light *light, const umbra_render_desc *ro,
                      const umbra_shadow_desc *sh, bench_case *bc)
{
    size_t npix = (size_t)o->width * o->height;
    bc->img_umbra = malloc(npix * 4 * sizeof(float));
    bc->img_native = malloc(npix * 4 * sizeof(float));
    bc->t_dev = malloc((size_t)o->runs * sizeof(double));
    bc->t_wall = malloc((size_t)o->runs * sizeof(double));
    bc->t_native = malloc((size_t)o->runs * sizeof(double));
    bc->t_vtk = malloc((size_t)o->runs * sizeof(double));
    if (!bc->img_umbra || !bc->img_native || !bc->t_dev || !bc->t_wall || !bc->t_native ||
        !bc->t_vtk) {
        fprintf(stderr, "umbra-bench raycast: out of memory\n");
        return -1;
    }
    if (umbra_renderer_create(ctx, &bc->r) != UMBRA_SUCCESS ||
        umbra_renderer_set_volume(bc->r, vol->volume) != UMBRA_SUCCESS ||
        umbra_renderer_set_transfer_function(bc->r, tf) != UMBRA_SUCCESS ||
        umbra_renderer_set_camera(bc->r, cam) != UMBRA_SUCCESS ||
        umbra_renderer_set_light(bc->r, light) != UMBRA_SUCCESS ||
        umbra_renderer_set_options(bc->r, ro) != UMBRA_SUCCESS ||
        umbra_renderer_set_shadow(bc->r, sh) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench raycast: %s\n", umbra_context_last_message(ctx));
        return -1;
    }
    /* native C, on the very same normalised voxels, table and view */
    cpu_scene *cs = &bc->cs;
    memset(cs, 0, sizeof *cs);
    cs->voxels = vol->voxels;
    for (int a = 0; a < 3; ++a) {
        cs->dims[a] = (int)vol->dims[a];
        cs->spacing[a] = vol->spacing[a];
    }
    cs->tf = umbra_transfer_function_data(tf);
    cs->tf_count = (int)umbra_transfer_function_size(tf);
    cs->camera = *cam;
    cs->light = *light;
    cs->opts = *ro;
    cs->shadow = UMBRA_SHADOW_NONE;
    cs->reference_step = sh->reference.step;
    umbra_volume_info info;
    umbra_volume_get_info(vol->volume, &info);
    cs->brick_size = (int)info.brick_size;
    bc->prepared = cpu_prepare(cs);
    if (!bc->prepared) {
        fprintf(stderr, "umbra-bench raycast: out of memory in cpu_prepare\n");
        return -1;
    }
    return 0;
}

static void case_free(bench_case *bc)
{
    cpu_prepared_free(bc->prepared);
    umbra_renderer_release(bc->r);
    free(bc->img_umbra);
    free(bc->img_native);
    free(bc->t_dev);
    free(bc->t_wall);
    free(bc->t_native);
    free(bc->t_vtk);
}

/* The shaded case's image against the C twin shading as before issue #12 (untimed): what the
 * faster gradient and specular power changed, on this volume. 0 on success. */
static int six_sample_diff(const bench_case *bc, const options *o, double *diff)
{
    size_t npix = (size_t)o->width * o->height;
    cpu_scene cs = bc->cs;
    cs.six_sample_shading = 1;
    float *img = malloc(npix * 4 * sizeof(float));
    cpu_prepared *prep = cpu_prepare(&cs);
    if (!img || !prep) {
        fprintf(stderr, "umbra-bench raycast: out of memory\n");
        free(img);
        cpu_prepared_free(prep);
        return -1;
    }
    cpu_render_prepared(prep, o->width, o->height, img);
    *diff = 0.0;
    for (size_t i = 0; i < npix * 4; ++i) {
        double d = fabs((double)bc->img_umbra[i] - (double)img[i]);
        *diff = d > *diff ? d : *diff;
    }
    cpu_prepared_free(prep);
    free(img);
    return 0;
}

/* A case's row name: the scene's prefix, base and the case's suffix, in the case's storage. */
static const char *row_name(bench_case *bc, int slot, const char *base)
{
    snprintf(bc->names[slot], sizeof bc->names[slot], "%s%s%s", bc->scene->prefix, base,
             bc->suffix);
    return bc->names[slot];
}

/* Fills a case's rows and ratios after its timed frames, and reports them on stderr. */
static void case_report(bench_case *bc, const options *o, int vtk_ran)
{
    size_t npix = (size_t)o->width * o->height;
    bc->diff = 0.0;
    for (size_t i = 0; i < npix * 4; ++i) {
        double d = fabs((double)bc->img_umbra[i] - (double)bc->img_native[i]);
        bc->diff = d > bc->diff ? d : bc->diff;
    }
    bc->nrows = 0;
    bc->rows[bc->nrows++] = (row){row_name(bc, 0, "umbra"), bench_timing_of(bc->t_dev, o->runs),
                                  bc->samples_umbra};
    bc->rows[bc->nrows++] = (row){row_name(bc, 1, "umbra_wall"),
                                  bench_timing_of(bc->t_wall, o->runs), bc->samples_umbra};
    bc->rows[bc->nrows++] = (row){row_name(bc, 2, "native_c"),
                                  bench_timing_of(bc->t_native, o->runs), bc->samples_native};
    bc->vtk_ratio = 0.0;
    if (vtk_ran) {
        bc->rows[bc->nrows++] = (row){row_name(bc, 3, "vtk_fixedpoint"),
                                      bench_timing_of(bc->t_vtk, o->runs), 0};
        bc->vtk_ratio = bc->rows[3].t.median / bc->rows[0].t.median;
    }
    double sps_umbra = (double)bc->samples_umbra / bc->rows[0].t.median;
    double sps_native = (double)bc->samples_native / bc->rows[2].t.median;
    bc->ratio = sps_umbra / sps_native;
    const char *what = bc->shading ? "shaded" : "unshaded";
    const char *scene = bc->scene->name;
    if (bc->diff_six >= 0.0)
        fprintf(stderr, "%s, shaded: umbra vs the C twin shading as before issue #12 (six-sample "
                        "gradient, powf): largest pixel difference %.2e\n", scene, bc->diff_six);
    /* Both take the same samples up to float rounding: a last-bit difference in a ray's
     * direction (OpenCL's normalize() against the C twin's 1/sqrtf) can move a sample across a
     * brick face or the ray's end, so a few rays in a million take one sample more or less. */
    fprintf(stderr, "%s, %s: umbra vs native C: samples %llu vs %llu (%+.1e relative), largest "
                    "pixel difference %.2e\n",
            scene, what, (unsigned long long)bc->samples_umbra,
            (unsigned long long)bc->samples_native,
            ((double)bc->samples_umbra - (double)bc->samples_native) / (double)bc->samples_native,
            bc->diff);
    fprintf(stderr, "%s, %s: ratio umbra/native_c samples/s: %.3f (target >= 0.9)\n", scene, what,
            bc->ratio);
    if (bc->vtk_ratio > 0.0)
        fprintf(stderr, "%s, %s: ratio vtk_fixedpoint/umbra ms per frame: %.3f (target %s)\n",
                scene, what, bc->vtk_ratio, bc->shading ? ">= 1.0" : ">= 1.2");
}

/* The walnut's file: $UMBRA_DATA_DIR/NAME or $UMBRA_DATA_DIR/volumes/NAME, else
 * UMBRA_SOURCE_DIR/../shared/data/volumes/NAME; 0 and the path in out if one exists. */
static int find_volume(const char *name, char *out, size_t size)
{
    const char *data_dir = getenv("UMBRA_DATA_DIR");
    char c[3][1100];
    int n = 0;
    if (data_dir && *data_dir) {
        snprintf(c[n++], sizeof c[0], "%s/%s", data_dir, name);
        snprintf(c[n++], sizeof c[0], "%s/volumes/%s", data_dir, name);
    }
    snprintf(c[n++], sizeof c[0], "%s/../shared/data/volumes/%s", UMBRA_SOURCE_DIR, name);
    for (int i = 0; i < n; ++i) {
        FILE *f = fopen(c[i], "rb");
        size_t len = strlen(c[i]);
        if (f) {
            fclose(f);
            if (len >= size)
                return -1;
            memcpy(out, c[i], len + 1);
            return 0;
        }
    }
    return -1;
}

/* One scene: its volume, transfer function and cases (unshaded, shaded, as o->shading says)
 * appended to cases[*ncases], VTK started for it, warm-up and timed frames in turn, the rows
 * reported. 1 when the scene was skipped (its volume is missing), -1 on failure. */
static int run_scene(umbra_context ctx, const options *o, const raycast_scene *sc,
                     bench_volume *vol, bench_case *cases, int *ncases,
                     const umbra_render_desc *ro, const umbra_render_desc *ro_shaded,
                     scene_load *load)
{
    int status = -1;
    umbra_transfer_function tf = NULL;
    vtk_peer peer = {-1, NULL, NULL};
    int vtk_running = 0;
    const int first = *ncases;
    if (strcmp(sc->name, "bonsai") == 0) {
        if (bench_volume_load_bonsai(ctx, o->volume, o->procedural, vol) != 0)
            return -1;
    } else {
        char path[1100];
        if (find_volume(sc->file, path, sizeof path) != 0) {
            fprintf(stderr, "%s: skipped: %s not found (set UMBRA_DATA_DIR)\n", sc->name,
                    sc->file);
            return 1;
        }
        if (bench_volume_load_bonsai(ctx, path, 0, vol) != 0)
            return -1;
    }
    umbra_camera cam = bench_camera(vol);
    umbra_light light;
    memset(&light, 0, sizeof light);
    light.type = UMBRA_LIGHT_DIRECTIONAL;
    light.direction[1] = -1.0f;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;
    umbra_shadow_desc sh;
    umbra_shadow_desc_init(&sh);
    sh.technique = UMBRA_SHADOW_NONE;
    if (umbra_transfer_function_create_from_points(ctx, sc->tf, sc->tf_count, TF_RESOLUTION,
                                                   &tf) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench raycast: %s\n", umbra_context_last_message(ctx));
        goto done;
    }
    for (int shading = 0; shading < 2; ++shading) {
        if (o->shading >= 0 && o->shading != shading)
            continue;
        bench_case *bc = &cases[(*ncases)++];
        bc->scene = sc;
        bc->vol = vol;
        bc->shading = shading;
        bc->suffix = shading ? "_shaded" : "";
        if (case_setup(ctx, o, vol, tf, &cam, &light, shading ? ro_shaded : ro, &sh, bc) != 0)
            goto done;
    }
    bench_case *cs = cases + first;
    const int n = *ncases - first;

    /* VTK in its own process, set up and warmed up (with and without shading, so that its
     * gradient encoding is done) before the timed frames. */
    if (o->vtk) {
        char why[256];
        float voxel = fminf(vol->spacing[0], fminf(vol->spacing[1], vol->spacing[2]));
        signal(SIGPIPE, SIG_IGN); /* a peer that dies shows as a failed write, not a signal */
        if (vtk_start(o, sc, vol, &cam, ro_shaded, &light, o->step * voxel, &peer, why,
                      sizeof why) == 0)
            vtk_running = 1;
        else
            fprintf(stderr, "%s: vtk_fixedpoint: skipped: %s\n", sc->name, why);
        if (!vtk_running)
            vtk_stop(&peer);
    }

    /* Warm-up, then the timed frames: umbra, native C and VTK take turns frame by frame, both
     * cases in each turn, so that a change in the machine's load (other processes) during the
     * measurement touches all alike. */
    double dev, wall;
    load->scene = sc;
    load->before = load_average();
    for (int i = 0; i < o->warmup; ++i)
        for (int c = 0; c < n; ++c) {
            bench_case *bc = &cs[c];
            if (umbra_frame(ctx, bc->r, o, bc->img_umbra, &dev, &wall, &bc->samples_umbra) != 0)
                goto done;
            bc->samples_native = cpu_render_prepared(bc->prepared, o->width, o->height,
                                                     bc->img_native);
        }
    for (int i = 0; i < o->runs; ++i)
        for (int c = 0; c < n; ++c) {
            bench_case *bc = &cs[c];
            if (umbra_frame(ctx, bc->r, o, bc->img_umbra, &bc->t_dev[i], &bc->t_wall[i],
                            &bc->samples_umbra) != 0)
                goto done;
            double t0 = bench_now_ms();
            bc->samples_native = cpu_render_prepared(bc->prepared, o->width, o->height,
                                                     bc->img_native);
            bc->t_native[i] = bench_now_ms() - t0;
            if (vtk_running && (bc->t_vtk[i] = vtk_frame(&peer, bc->shading)) < 0.0) {
                fprintf(stderr, "%s: vtk_fixedpoint: dropped: bench/vtk_raycast.py stopped "
                                "answering\n", sc->name);
                vtk_stop(&peer);
                vtk_running = 0;
            }
        }
    load->after = load_average();
    if (vtk_running && vtk_stop(&peer) != 0)
        fprintf(stderr, "%s: vtk_fixedpoint: bench/vtk_raycast.py exited with an error\n",
                sc->name);
    for (int c = 0; c < n; ++c) {
        cs[c].diff_six = -1.0;
        if (cs[c].shading && six_sample_diff(&cs[c], o, &cs[c].diff_six) != 0)
            goto done;
        case_report(&cs[c], o, vtk_running);
    }
    if (o->save)
        for (int c = 0; c < n; ++c) {
            char n_umbra[64], n_native[64];
            snprintf(n_umbra, sizeof n_umbra, "%sumbra%s", sc->prefix, cs[c].suffix);
            snprintf(n_native, sizeof n_native, "%snative_c%s", sc->prefix, cs[c].suffix);
            save_png(ctx, o->save, n_umbra, o->width, o->height, cs[c].img_umbra);
            save_png(ctx, o->save, n_native, o->width, o->height, cs[c].img_native);
        }
    status = 0;
done:
    if (vtk_running)
        vtk_stop(&peer);
    umbra_transfer_function_release(tf);
    return status;
}

static int scene_selected(const options *o, const char *name)
{
    size_t n = strlen(name);
    for (const char *c = o->scenes; *c;) {
        size_t k = strcspn(c, ",");
        if (k == n && strncmp(c, name, n) == 0)
            return 1;
        c += k + (c[k] == ',');
    }
    return 0;
}

int bench_raycast(int argc, char **argv)
{
    options o;
    if (parse(argc, argv, &o) != 0)
        return 2;
    int status = 1;
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    bench_volume vols[SCENES];
    bench_case cases[2 * SCENES];
    scene_load loads[SCENES];
    int ncases = 0, nscenes = 0;
    memset(vols, 0, sizeof vols);
    memset(cases, 0, sizeof cases);
    char device[700];
    bench_device_description(ctx, device, sizeof device);
    fprintf(stderr, "device: %s\n", device);
    umbra_render_desc ro;
    umbra_render_desc_init(&ro);
    ro.step = o.step;
    ro.ambient[0] = ro.ambient[1] = ro.ambient[2] = 0.0f;
    umbra_render_desc ro_shaded = ro;
    ro_shaded.shading = 1; /* kd, ks, shininess: the defaults */
    for (int k = 0; k < SCENES; ++k) {
        if (!scene_selected(&o, scenes[k].name))
            continue;
        int rc = run_scene(ctx, &o, &scenes[k], &vols[k], cases, &ncases, &ro, &ro_shaded,
                           &loads[nscenes]);
        if (rc < 0)
            goto done;
        nscenes += rc == 0;
    }
    printf("%s\n", BENCH_CSV_HEADER);
    for (int c = 0; c < ncases; ++c)
        for (int i = 0; i < cases[c].nrows; ++i)
            bench_csv_row(stdout, cases[c].rows[i].name, cases[c].rows[i].t,
                          cases[c].rows[i].samples);
    fflush(stdout);
    /* A results file that cannot be written fails the run (the message is on stderr). */
    status = o.results && write_results(&o, argc, argv, device, cases, ncases, &ro_shaded, loads,
                                        nscenes) != 0;
done:
    for (int c = 0; c < 2 * SCENES; ++c)
        case_free(&cases[c]);
    for (int k = 0; k < SCENES; ++k)
        bench_volume_free(&vols[k]);
    umbra_context_release(ctx);
    return status;
}
