// SPDX-License-Identifier: Apache-2.0
/* bench/scale.c: `umbra-bench scale`, how time and memory grow with the volume.
 *
 * Per size (128^3 .. 1024^3 by default, --max adds a larger one) a procedural volume (the field
 * below) is written in the input type (uint8 by default) to a raw file, then a fresh child
 * process (this executable, hidden mode `scale --child`) creates a context, loads the file with
 * umbra_volume_load_raw (read + conversion + upload + brick tables: what an application pays),
 * renders the first frame (technique none, 512^2) and then frames with none, threshold, CSSM and
 * deep maps at their default settings. The parent reads the child's peak resident memory from
 * wait4 (ru_maxrss), so sizes do not pollute each other; the child reports the rest (times, the
 * library's device byte counts) on a pipe. Generating the file is not timed: the file is read
 * from the page cache (it was just written), so "load" is the library's cost, not the disk's.
 *
 * The field, in normalised coordinates p in [0,1]^3 (x, y, z = 2p - 1): three gyroid octaves
 *     g = sum_k w_k G(2 pi f_k p + phi_k),  G(a) = sin a.x cos a.y + sin a.y cos a.z + sin a.z cos a.x,
 *     f = 2, 6, 18 periods across the box, w = 1, 0.35, 0.12,
 * kept near its zero set (thin sheets, structure at three scales) and inside a ball:
 *     value = clamp(1.25 (1 - |g| / 0.35)) * clamp((0.9 - |x|^2) / 0.25).
 * Outside the ball (half the box) and between the sheets the volume is empty, so empty-space
 * skipping has work to do. The shape is the same at every size; the transfer function's opacity
 * (given per voxel length) is scaled by 128 / largest side so the picture is too: optical depth
 * and early termination do not change with the size, only the number of voxels a ray crosses. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

/* The techniques measured: none, then every light-space map of the registry, in its order
 * (threshold, cssm, deep); a mask of them travels to the child as a number. */
enum { MAX_TECH = 15, MAX_SIZES = 5 };
static umbra_shadow_technique techs[MAX_TECH];
static int ntech;

static void make_techs(void)
{
    ntech = 0;
    techs[ntech++] = UMBRA_SHADOW_NONE;
    for (uint32_t t = 0; t < umbra_technique_count() && ntech < MAX_TECH; ++t)
        if (umbra_technique_get(t)->flags & UMBRA_TECHNIQUE_MAP)
            techs[ntech++] = umbra_technique_get(t)->id;
}

/* What one size measured. The child fills the fields up to peak_rss, the parent the rest. */
typedef struct row {
    double context_ms, load_ms, first_ms, load_hwm, device_bytes, samples;
    double frame_ms[MAX_TECH], build_ms[MAX_TECH], render_ms[MAX_TECH], map_bytes[MAX_TECH];
    double runs[MAX_TECH];
    double peak_rss, gen_ms;
    uint32_t dims[3];
    char status[256];
} row;

typedef struct options {
    uint32_t dims[MAX_SIZES][3];
    int nsizes, runs, plots, techmask;
    uint32_t width, height;
    umbra_scalar_type type;
    const char *results, *tmp, *device;
} options;

static const char *type_name(umbra_scalar_type t)
{
    return t == UMBRA_UINT8 ? "uint8" : t == UMBRA_UINT16 ? "uint16" : t == UMBRA_INT16 ? "int16"
                                                                                        : "float";
}

static double voxels_of(const uint32_t d[3]) { return (double)d[0] * d[1] * d[2]; }

static int cmp_dims(const void *a, const void *b)
{
    double x = voxels_of(a), y = voxels_of(b);
    return (x > y) - (x < y);
}

/* ---- the procedural field ------------------------------------------------------------------- */

static const float oct_f[3] = {2.0f, 6.0f, 18.0f}, oct_w[3] = {1.0f, 0.35f, 0.12f};
static const float oct_phase[3][3] = {{0.3f, 1.1f, 2.0f}, {1.7f, 0.4f, 2.9f}, {2.3f, 3.1f, 0.8f}};

static float clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

/* Writes the field as dims voxels of type to path, one z-slice at a time (host memory stays at a
 * slice whatever the size). Per-axis sin/cos tables make a voxel cost a few multiplications. */
static int write_field(const char *path, const uint32_t dims[3], umbra_scalar_type type)
{
    const size_t tsize = umbra_scalar_type_size(type), nx = dims[0];
    uint32_t nmax = dims[0] > dims[1] ? dims[0] : dims[1];
    nmax = nmax > dims[2] ? nmax : dims[2];
    float *s = malloc(sizeof(float) * 3 * 3 * 2 * nmax), *r2 = malloc(sizeof(float) * 3 * nmax);
    float *line = malloc(sizeof(float) * nx);
    unsigned char *out = malloc(tsize * nx * dims[1]);
    FILE *f = fopen(path, "wb");
    int ok = s && r2 && line && out && f;
    /* s[((k * 3 + axis) * 2 + sc) * nmax + i]: sin (sc 0) / cos (sc 1) of octave k on an axis. */
#define TAB(k, a, sc, i) s[(((size_t)(k) * 3 + (a)) * 2 + (sc)) * nmax + (i)]
    for (int a = 0; ok && a < 3; ++a)
        for (uint32_t i = 0; i < dims[a]; ++i) {
            float p = ((float)i + 0.5f) / (float)dims[a], c = 2.0f * p - 1.0f;
            r2[(size_t)a * nmax + i] = c * c;
            for (int k = 0; k < 3; ++k) {
                float ang = 6.2831853f * oct_f[k] * p + oct_phase[k][a];
                TAB(k, a, 0, i) = sinf(ang);
                TAB(k, a, 1, i) = cosf(ang);
            }
        }
    for (uint32_t z = 0; ok && z < dims[2]; ++z) {
        for (uint32_t y = 0; y < dims[1]; ++y) {
            float ryz = r2[nmax + y] + r2[2 * (size_t)nmax + z];
            for (uint32_t x = 0; x < nx; ++x)
                line[x] = 0.0f;
            for (int k = 0; k < 3; ++k) {
                /* G = sin a.x cos a.y + sin a.y cos a.z + sin a.z cos a.x: the middle term is
                 * constant along the row. */
                float cy = TAB(k, 1, 1, y), mid = TAB(k, 1, 0, y) * TAB(k, 2, 1, z);
                float sz = TAB(k, 2, 0, z);
                for (uint32_t x = 0; x < nx; ++x)
                    line[x] += oct_w[k] * (TAB(k, 0, 0, x) * cy + mid + sz * TAB(k, 0, 1, x));
            }
            for (uint32_t x = 0; x < nx; ++x) {
                float v = clamp01(1.25f * (1.0f - fabsf(line[x]) / 0.35f)) *
                          clamp01((0.9f - r2[x] - ryz) / 0.25f);
                size_t i = (size_t)y * nx + x;
                if (type == UMBRA_UINT8) {
                    out[i] = (unsigned char)lrintf(v * 255.0f);
                } else if (type == UMBRA_FLOAT32) {
                    memcpy(out + 4 * i, &v, 4);
                } else { /* int16 is x - 32768: the top bit flipped in two's complement */
                    uint16_t u = (uint16_t)((unsigned long)lrintf(v * 65535.0f) ^
                                            (type == UMBRA_INT16 ? 0x8000u : 0u));
                    memcpy(out + 2 * i, &u, 2); /* host order; the child tells the loader */
                }
            }
        }
        ok = fwrite(out, tsize * nx, dims[1], f) == dims[1];
    }
#undef TAB
    if (f && fclose(f) != 0)
        ok = 0;
    free(s);
    free(r2);
    free(line);
    free(out);
    return ok ? 0 : -1;
}

/* ---- the child: one size, in a fresh process ------------------------------------------------ */

/* The number after `key` in a /proc file such as /proc/self/status, in bytes (the files give
 * kB), or -1. */
static double proc_bytes(const char *file, const char *key)
{
    FILE *f = fopen(file, "r");
    char line[256];
    double kib = -1.0;
    size_t n = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0)
            kib = strtod(line + n, NULL);
    if (f)
        fclose(f);
    return kib < 0.0 ? -1.0 : kib * 1024.0;
}

/* Loads path, renders, prints "key value" lines to stdout. Returns the exit status. */
static int child_run(const char *path, const uint32_t dims[3], umbra_scalar_type type,
                     uint32_t w, uint32_t h, int runs, int techmask, const char *device)
{
    umbra_volume vol = NULL;
    umbra_transfer_function tf = NULL;
    umbra_renderer r = NULL;
    float *rgba = malloc(sizeof(float) * 4 * w * h);
    int rc = 1;
    double t0 = bench_now_ms();
    umbra_context ctx = bench_context(device);
    if (!ctx || !rgba)
        goto done;
    printf("context_ms %.3f\n", bench_now_ms() - t0);

    umbra_raw_desc rd;
    umbra_raw_desc_init(&rd);
    rd.type = type;
    const uint16_t one = 1;
    rd.big_endian = *(const unsigned char *)&one == 0; /* the file is in host order */
    memcpy(rd.dims, dims, sizeof rd.dims);
    t0 = bench_now_ms();
    if (umbra_volume_load_raw(ctx, path, &rd, &vol) != UMBRA_SUCCESS)
        goto fail;
    printf("load_ms %.3f\nload_hwm %.0f\n", bench_now_ms() - t0, proc_bytes("/proc/self/status", "VmHWM:"));
    umbra_volume_info info;
    umbra_volume_get_info(vol, &info);
    printf("device_bytes %zu\n", info.device_bytes);
    fflush(stdout);

    /* The picture is the same at every size: opacity per voxel scaled by 128 / largest side. */
    uint32_t n = dims[0] > dims[1] ? dims[0] : dims[1];
    n = n > dims[2] ? n : dims[2];
    const float e = 128.0f / (float)n;
    umbra_tf_point pts[] = {{0.00f, {0.0f, 0.0f, 0.0f, 0.0f}},
                            {0.30f, {0.2f, 0.4f, 0.9f, 0.0f}},
                            {0.45f, {0.2f, 0.5f, 0.9f, 1.0f - powf(1.0f - 0.04f, e)}},
                            {0.75f, {0.9f, 0.6f, 0.2f, 1.0f - powf(1.0f - 0.10f, e)}},
                            {1.00f, {1.0f, 0.9f, 0.8f, 1.0f - powf(1.0f - 0.30f, e)}}};
    float dir[3] = {0.35f, 0.25f, 1.0f};
    float diag = sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                       info.extent[2] * info.extent[2]);
    umbra_camera cam = umbra_camera_orbit(dir, diag, 30.0f);
    umbra_light light = {UMBRA_LIGHT_DIRECTIONAL, {0, 0, 0}, {-0.5f, -1.0f, -0.3f}, {1, 1, 1}};

    /* First frame: everything up to the first picture that the load did not do (renderer,
     * transfer-function and brick tables, program builds from PoCL's cache, warm after the
     * parent's warm-up child). */
    t0 = bench_now_ms();
    if (umbra_transfer_function_create_from_points(ctx, pts, 5, 256, &tf) != UMBRA_SUCCESS ||
        umbra_renderer_create(ctx, &r) != UMBRA_SUCCESS ||
        umbra_renderer_set_volume(r, vol) != UMBRA_SUCCESS ||
        umbra_renderer_set_transfer_function(r, tf) != UMBRA_SUCCESS ||
        umbra_renderer_set_camera(r, &cam) != UMBRA_SUCCESS ||
        umbra_renderer_set_light(r, &light) != UMBRA_SUCCESS ||
        umbra_renderer_render(r, w, h, rgba) != UMBRA_SUCCESS)
        goto fail;
    printf("first_ms %.3f\n", bench_now_ms() - t0);
    fflush(stdout);

    for (int t = 0; t < ntech; ++t) {
        if (!(techmask & (1 << t)))
            continue;
        umbra_shadow_desc sd;
        umbra_shadow_desc_init(&sd);
        sd.technique = techs[t];
        const char *name = umbra_shadow_technique_name(techs[t]);
        double warm = bench_now_ms();
        if (umbra_renderer_set_shadow(r, &sd) != UMBRA_SUCCESS ||
            umbra_renderer_render(r, w, h, rgba) != UMBRA_SUCCESS) {
            /* One technique failing (e.g. out of device memory) leaves the others to measure. */
            fprintf(stderr, "umbra-bench scale: %s: %s\n", name, umbra_context_last_message(ctx));
            continue;
        }
        warm = bench_now_ms() - warm;
        /* The first frame's device times (program builds are host time) are a sample too; a
         * slow setting (over 20 s) keeps just that one, others get `runs` more. */
        double fr[65], bu[65], re[65];
        umbra_render_stats st = {0};
        if (umbra_renderer_get_stats(r, &st) != UMBRA_SUCCESS)
            goto fail;
        int nr = warm > 20000.0 ? 1 : runs + 1;
        bu[0] = st.shadow_build_ms;
        re[0] = st.render_ms;
        fr[0] = bu[0] + re[0];
        for (int k = 1; k < nr; ++k) {
            /* Every timed frame rebuilds the map: the light alternates by one ulp of red. */
            light.color[0] = k % 2 ? 1.0f : nextafterf(1.0f, 0.0f);
            if (umbra_renderer_set_light(r, &light) != UMBRA_SUCCESS ||
                umbra_renderer_render(r, w, h, rgba) != UMBRA_SUCCESS ||
                umbra_renderer_get_stats(r, &st) != UMBRA_SUCCESS)
                goto fail;
            bu[k] = st.shadow_build_ms;
            re[k] = st.render_ms;
            fr[k] = bu[k] + re[k];
        }
        double f = bench_timing_of(fr, nr).median, b = bench_timing_of(bu, nr).median,
               rr = bench_timing_of(re, nr).median;
        printf("frame_ms.%d %.3f\nbuild_ms.%d %.3f\nrender_ms.%d %.3f\nmap_bytes.%d %zu\n"
               "runs.%d %d\n",
               t, f, t, b, t, rr, t, st.shadow_memory_bytes, t, nr);
        if (techs[t] == UMBRA_SHADOW_NONE)
            printf("samples %llu\n", (unsigned long long)st.samples);
        fflush(stdout);
    }
    rc = 0;
    goto done;
fail:
    fprintf(stderr, "umbra-bench scale: %s\n", umbra_context_last_message(ctx));
    printf("error %s\n", umbra_context_last_message(ctx));
done:
    umbra_renderer_release(r);
    umbra_transfer_function_release(tf);
    umbra_volume_release(vol);
    umbra_context_release(ctx);
    free(rgba);
    return rc;
}

/* ---- the parent ------------------------------------------------------------------------------ */

/* Fills from the child's "key value" lines. */
static void parse_line(row *R, char *line)
{
    struct { const char *key; double *v; } keys[] = {
        {"context_ms", &R->context_ms}, {"load_ms", &R->load_ms}, {"first_ms", &R->first_ms},
        {"load_hwm", &R->load_hwm}, {"device_bytes", &R->device_bytes}, {"samples", &R->samples}};
    line[strcspn(line, "\n")] = 0;
    char *sp = strchr(line, ' ');
    if (!sp)
        return;
    *sp++ = 0;
    if (strcmp(line, "error") == 0) {
        snprintf(R->status, sizeof R->status, "failed: %s", sp);
        return;
    }
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; ++i)
        if (strcmp(line, keys[i].key) == 0)
            *keys[i].v = strtod(sp, NULL);
    char *dot = strchr(line, '.');
    int t = dot ? atoi(dot + 1) : -1;
    if (!dot || t < 0 || t >= ntech)
        return;
    *dot = 0;
    double *dst = strcmp(line, "frame_ms") == 0    ? R->frame_ms
                  : strcmp(line, "build_ms") == 0  ? R->build_ms
                  : strcmp(line, "render_ms") == 0 ? R->render_ms
                  : strcmp(line, "map_bytes") == 0 ? R->map_bytes
                  : strcmp(line, "runs") == 0      ? R->runs
                                                   : NULL;
    if (dst)
        dst[t] = strtod(sp, NULL);
}

/* Runs `umbra-bench scale --child ...` on path and fills R (peak RSS from wait4). */
static void run_child(const options *o, const char *path, const uint32_t dims[3], row *R)
{
    char dims_s[48], image[32], runs[16], mask[16];
    snprintf(dims_s, sizeof dims_s, "%ux%ux%u", dims[0], dims[1], dims[2]);
    snprintf(image, sizeof image, "%ux%u", o->width, o->height);
    snprintf(runs, sizeof runs, "%d", o->runs);
    snprintf(mask, sizeof mask, "%d", o->techmask);
    int fd[2];
    fflush(NULL);
    if (pipe(fd) != 0) {
        snprintf(R->status, sizeof R->status, "failed: pipe: %s", strerror(errno));
        return;
    }
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], STDOUT_FILENO);
        close(fd[1]);
        execl("/proc/self/exe", "umbra-bench", "scale", "--child", path, dims_s, type_name(o->type),
              image, runs, mask, o->device ? o->device : "", (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    if (pid < 0) {
        close(fd[0]);
        snprintf(R->status, sizeof R->status, "failed: fork: %s", strerror(errno));
        return;
    }
    FILE *in = fdopen(fd[0], "r");
    char line[9000];
    while (in && fgets(line, sizeof line, in))
        parse_line(R, line);
    if (in)
        fclose(in);
    else
        close(fd[0]);
    int ws = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &ws, 0, &ru) < 0 && errno == EINTR)
        ;
    R->peak_rss = (double)ru.ru_maxrss * 1024.0; /* Linux: KiB */
    if (!R->status[0] && !(WIFEXITED(ws) && WEXITSTATUS(ws) == 0))
        snprintf(R->status, sizeof R->status, "failed: child %s %d",
                 WIFSIGNALED(ws) ? "killed by signal" : "exit status",
                 WIFSIGNALED(ws) ? WTERMSIG(ws) : WEXITSTATUS(ws));
    if (!R->status[0])
        snprintf(R->status, sizeof R->status, "ok");
}

/* "WxHxD", digits and 'x' only (sscanf alone takes "-1" and blanks), each side in [2, 65536]. */
static int parse_dims(const char *s, uint32_t d[3])
{
    char tail;
    if (!s || strspn(s, "0123456789x") != strlen(s) ||
        sscanf(s, "%ux%ux%u%c", &d[0], &d[1], &d[2], &tail) != 3)
        return -1;
    return d[0] < 2 || d[1] < 2 || d[2] < 2 || d[0] > 65536 || d[1] > 65536 || d[2] > 65536 ? -1 : 0;
}

static void git_commit(char *buf, size_t size)
{
    snprintf(buf, size, "unknown");
    FILE *p = popen("git -C '" UMBRA_SOURCE_DIR "' describe --always --dirty 2>/dev/null", "r");
    char line[64] = "";
    if (p && fgets(line, sizeof line, p) && line[0] != '\n') {
        line[strcspn(line, "\n")] = 0;
        snprintf(buf, size, "%s", line);
    }
    if (p)
        pclose(p);
}

static void csv_header(FILE *f)
{
    fprintf(f, "size,nx,ny,nz,type,voxels,load_ms,first_frame_ms,time_to_first_frame_ms,"
               "context_ms,samples_none");
    for (int t = 0; t < ntech; ++t) {
        const char *s = umbra_shadow_technique_name(techs[t]);
        fprintf(f, ",%s_frame_ms,%s_build_ms,%s_render_ms,%s_map_bytes", s, s, s, s);
    }
    fprintf(f, ",peak_rss_bytes,load_peak_rss_bytes,volume_device_bytes,"
               "device_bytes_per_voxel,status\n");
}

static void csv_row(FILE *f, const row *R, umbra_scalar_type type)
{
    fprintf(f, "%ux%ux%u,%u,%u,%u,%s,%.0f,", R->dims[0], R->dims[1], R->dims[2], R->dims[0],
            R->dims[1], R->dims[2], type_name(type), voxels_of(R->dims));
    if (R->first_ms > 0.0)
        fprintf(f, "%.1f,%.1f,%.1f,%.1f,", R->load_ms, R->first_ms, R->load_ms + R->first_ms,
                R->context_ms);
    else
        fprintf(f, ",,,,");
    if (R->samples > 0.0)
        fprintf(f, "%.0f", R->samples);
    for (int t = 0; t < ntech; ++t)
        if (R->runs[t] > 0.0)
            fprintf(f, ",%.1f,%.1f,%.1f,%.0f", R->frame_ms[t], R->build_ms[t], R->render_ms[t],
                    R->map_bytes[t]);
        else
            fprintf(f, ",,,,");
    if (R->peak_rss > 0.0 && R->device_bytes > 0.0)
        fprintf(f, ",%.0f,%.0f,%.0f,%.3f", R->peak_rss, R->load_hwm, R->device_bytes,
                R->device_bytes / voxels_of(R->dims));
    else
        fprintf(f, ",,,,");
    fputs(",\"", f);
    for (const char *c = R->status; *c; ++c)
        fputc(*c == '"' ? '\'' : *c, f); /* library messages may quote paths */
    fputs("\"\n", f);
}

/* /proc/loadavg as it reads: a loaded machine (other processes on the 2 cores) slows frames. */
static void load_average(char *buf, size_t size)
{
    FILE *f = fopen("/proc/loadavg", "r");
    if (!f || !fgets(buf, (int)size, f))
        snprintf(buf, size, "?");
    if (f)
        fclose(f);
    buf[strcspn(buf, "\n")] = 0;
}

static void fmt_ms(double ms, char *b, size_t n)
{
    if (ms > 0.0)
        bench_format_ms(ms, b, n);
    else
        snprintf(b, n, "–");
}

static void write_md(FILE *f, const row *rows, int n, const options *o, const char *machine,
                     const char *device, const char *commit, const char *started,
                     const char *load_start)
{
    char load_end[64];
    load_average(load_end, sizeof load_end);
    umbra_shadow_desc sd;
    umbra_shadow_desc_init(&sd);
    char map[32];
    if (sd.map.size)
        snprintf(map, sizeof map, "%u²", sd.map.size);
    else
        snprintf(map, sizeof map, "auto");
    fprintf(f, "# umbra-bench scale\n\n- Started: %s; umbra commit %s\n- CPU: %s\n- OpenCL device: "
               "%s\n- Load average (1, 5, 15 min, running/total, last pid) at the start %s, at the end %s\n"
               "- Volume: the procedural gyroid field of `bench/scale.c`, %s, written to a raw "
               "file and loaded with `umbra_volume_load_raw` in a fresh process per size\n"
               "- Frames: %ux%u, view step 0.5 voxel, directional light; shadow maps at the "
               "defaults (map %s); frame = device time of build + render, median of the first and %d more "
               "(only the first where it took over 20 s), every timed frame rebuilding the map\n\n",
            started, commit, machine, device, load_start, load_end, type_name(o->type), o->width, o->height, map, o->runs);
    fprintf(f, "| size | voxels | load ms | first frame ms | to first frame ms | none ms | "
               "threshold ms | cssm ms | deep ms | samples (none) | peak RSS | device B/voxel |\n"
               "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int i = 0; i < n; ++i) {
        const row *R = &rows[i];
        char c[8][32];
        fmt_ms(R->load_ms, c[0], 32);
        fmt_ms(R->first_ms, c[1], 32);
        fmt_ms(R->first_ms > 0.0 ? R->load_ms + R->first_ms : 0.0, c[2], 32);
        for (int t = 0; t < ntech; ++t)
            fmt_ms(R->runs[t] > 0.0 ? R->frame_ms[t] : 0.0, c[3 + t], 32);
        bench_format_bytes((size_t)R->peak_rss, c[7], 32);
        char smp[32] = "–";
        if (R->samples > 0.0)
            snprintf(smp, sizeof smp, "%.3g", R->samples);
        fprintf(f, "| %ux%ux%u | %.3g | %s | %s | %s | %s | %s | %s | %s | %s | %s | ",
                R->dims[0], R->dims[1], R->dims[2], voxels_of(R->dims), c[0], c[1], c[2], c[3],
                c[4], c[5], c[6], smp, R->peak_rss > 0.0 ? c[7] : "–");
        if (R->device_bytes > 0.0)
            fprintf(f, "%.2f |\n", R->device_bytes / voxels_of(R->dims));
        else
            fprintf(f, "– |\n");
    }
    for (int i = 0; i < n; ++i) /* issue 14's targets on the 2-core 24 GiB machine */
        if (voxels_of(rows[i].dims) == 1073741824.0 && o->type == UMBRA_UINT8 &&
            rows[i].first_ms > 0.0)
            fprintf(f, "\nTargets at 1024³ uint8: peak RSS %.2f GiB (target <= 2.5: %s), time to "
                       "first frame %.1f s (target <= 4: %s).\n",
                    rows[i].peak_rss / 1073741824.0, rows[i].peak_rss <= 2.5 * 1073741824.0 ? "met"
                                                                                     : "not met",
                    (rows[i].load_ms + rows[i].first_ms) / 1e3,
                    rows[i].load_ms + rows[i].first_ms <= 4000.0 ? "met" : "not met");
    fprintf(f, "\nNot measured or failed:");
    int any = 0;
    for (int i = 0; i < n; ++i)
        if (strcmp(rows[i].status, "ok") != 0) {
            fprintf(f, "\n- %ux%ux%u: %s", rows[i].dims[0], rows[i].dims[1], rows[i].dims[2],
                    rows[i].status);
            any = 1;
        }
    fprintf(f, "%s\n\nload = `umbra_volume_load_raw` (read from the page cache, conversion, upload, "
               "brick tables); first frame = renderer set-up and the first unshadowed frame, wall "
               "time; peak RSS = the child's `ru_maxrss` (on PoCL the device buffers live in host "
               "memory and count here); device B/voxel = `umbra_volume_info.device_bytes` / "
               "voxels. Plot: `scale.png`.\n",
            any ? "" : " nothing");
}

/* bench/plot_scale.gp draws DIR/scale.png from DIR/scale.csv; skipped if gnuplot is absent. */
static void write_plot(const char *dir)
{
    FILE *gp = popen("gnuplot >/dev/null 2>&1", "w");
    if (gp)
        fprintf(gp, "csv = '%s/scale.csv'\nout = '%s/scale.png'\nload '%s/bench/plot_scale.gp'\n",
                dir, dir, UMBRA_SOURCE_DIR);
    int rc = gp ? pclose(gp) : -1;
    if (rc != 0)
        fprintf(stderr, "umbra-bench scale: plot skipped: gnuplot failed or is missing (status %d; "
                        "Debian: apt-get install gnuplot-nox)\n", rc);
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: umbra-bench scale [options]\n"
            "  Time to first frame, frame times (none, threshold, cssm, deep), peak host memory\n"
            "  and device bytes per voxel for procedural volumes of growing size, each size in a\n"
            "  fresh process: 128^3, 256^3, 512^3, 1024^3. CSV on stdout. The raw files go to\n"
            "  $TMPDIR (default /tmp), one at a time.\n"
            "  --quick            128^3 and 256^3, --runs 1 (a minute or two)\n"
            "  --max WxHxD        add a larger size, e.g. 2048x2048x1536\n"
            "  --type T           uint8 (default), uint16, int16 or float\n"
            "  --techniques A,B   of none and the light-space maps (default all)\n"
            "  --size WxH         image size (default 512x512)\n"
            "  --runs N           timed frames per technique after the first (default 3)\n"
            "  --results DIR      also write DIR/scale.csv, DIR/scale.md, DIR/scale.png\n"
            "  --no-plots         no gnuplot\n"
            "  --device SPEC      OpenCL device (name or P:D)\n");
}

static int parse_techniques(const char *s, int *mask)
{
    char buf[128];
    if (strlen(s) >= sizeof buf)
        return -1;
    strcpy(buf, s);
    *mask = 0;
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        umbra_shadow_technique t;
        int found = -1;
        if (umbra_shadow_technique_parse(tok, &t) == UMBRA_SUCCESS)
            for (int k = 0; k < ntech; ++k)
                found = techs[k] == t ? k : found;
        if (found < 0)
            return -1;
        *mask |= 1 << found;
    }
    return *mask ? 0 : -1;
}

static int parse_type(const char *s, umbra_scalar_type *t)
{
    for (int k = UMBRA_UINT8; k <= UMBRA_FLOAT32; ++k)
        if (strcmp(s, type_name((umbra_scalar_type)k)) == 0)
            return *t = (umbra_scalar_type)k, 0;
    return -1;
}

int bench_scale(int argc, char **argv)
{
    options o;
    memset(&o, 0, sizeof o);
    o.runs = 3;
    o.plots = 1;
    make_techs();
    o.techmask = (1 << ntech) - 1;
    o.width = o.height = 512;
    o.type = UMBRA_UINT8;
    const char *maxdims = NULL, *tmpenv = getenv("TMPDIR");
    int nsizes = 4;
    o.tmp = tmpenv && *tmpenv ? tmpenv : "/tmp";

    if (argc == 9 && strcmp(argv[1], "--child") == 0) {
        uint32_t d[3], w, h;
        long runs, mask;
        umbra_scalar_type t;
        if (parse_dims(argv[3], d) != 0 || parse_type(argv[4], &t) != 0 ||
            bench_parse_size(argv[5], &w, &h) != 0 || bench_parse_int(argv[6], 1, 64, &runs) != 0 ||
            bench_parse_int(argv[7], 1, (1L << ntech) - 1, &mask) != 0)
            return 2;
        return child_run(argv[2], d, t, w, h, (int)runs, (int)mask, argv[8][0] ? argv[8] : NULL);
    }
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        long n;
        int bad = 0, takes = 1;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--quick") == 0) {
            nsizes = 2;
            o.runs = 1;
            takes = 0;
        } else if (strcmp(a, "--no-plots") == 0) {
            o.plots = 0;
            takes = 0;
        } else if (!v) {
            bad = 1;
        } else if (strcmp(a, "--max") == 0) {
            maxdims = v;
        } else if (strcmp(a, "--type") == 0) {
            bad = parse_type(v, &o.type);
        } else if (strcmp(a, "--techniques") == 0) {
            bad = parse_techniques(v, &o.techmask);
        } else if (strcmp(a, "--size") == 0) {
            bad = bench_parse_size(v, &o.width, &o.height);
        } else if (strcmp(a, "--runs") == 0) {
            bad = bench_parse_int(v, 1, 64, &n);
            o.runs = (int)n;
        } else if (strcmp(a, "--results") == 0) {
            o.results = v;
        } else if (strcmp(a, "--device") == 0) {
            o.device = v;
        } else {
            bad = 1;
        }
        if (bad) {
            fprintf(stderr, "umbra-bench scale: bad option %s%s%s\n", a, v && takes ? " " : "",
                    v && takes ? v : "");
            usage(stderr);
            return 2;
        }
        i += takes;
    }
    for (int k = 0; k < nsizes; ++k)
        o.dims[k][0] = o.dims[k][1] = o.dims[k][2] = 128u << k; /* 128^3 .. 1024^3 */
    o.nsizes = nsizes;
    if (maxdims && parse_dims(maxdims, o.dims[o.nsizes++]) != 0) {
        fprintf(stderr, "umbra-bench scale: bad --max %s (WxHxD, each 2..65536)\n", maxdims);
        return 2;
    }

    /* Smallest first: each size's checks predict from the ones before. */
    qsort(o.dims, (size_t)o.nsizes, sizeof o.dims[0], cmp_dims);

    /* The machine, then the device's memory for the up-front checks. */
    char machine[256], device[512], commit[64], started[64];
    bench_cpu_model(machine, sizeof machine);
    git_commit(commit, sizeof commit);
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(started, sizeof started, "%Y-%m-%d %H:%M UTC", &tm);
    char load_start[64];
    load_average(load_start, sizeof load_start);
    umbra_context ctx = bench_context(o.device);
    if (!ctx)
        return 1;
    bench_device_description(ctx, device, sizeof device);
    cl_ulong global_mem = 0;
    clGetDeviceInfo(umbra_context_cl_device(ctx), CL_DEVICE_GLOBAL_MEM_SIZE, sizeof global_mem,
                    &global_mem, NULL);
    umbra_context_release(ctx);
    fprintf(stderr, "scale: %s; %s; device memory %.1f GiB; commit %s\n", machine, device,
            (double)global_mem / 1073741824.0, commit);

    char path[600];
    snprintf(path, sizeof path, "%s/umbra-scale-%ld.raw", o.tmp, (long)getpid());
    row rows[MAX_SIZES], warm;
    memset(rows, 0, sizeof rows);
    memset(&warm, 0, sizeof warm);
    /* A small unreported run first builds every kernel into PoCL's cache, so that first frames
     * measure umbra, not the one-time compilation of the OpenCL C on this machine. */
    const uint32_t wd[3] = {32, 32, 32};
    options ow = o;
    ow.runs = 1;
    ow.width = ow.height = 64;
    if (write_field(path, wd, o.type) == 0)
        run_child(&ow, path, wd, &warm);
    remove(path);
    fprintf(stderr, "scale: warm-up (32^3, kernels into the cache): %s\n", warm.status);

    int measured = 0, failures = 0;
    size_t tsize = umbra_scalar_type_size(o.type);
    csv_header(stdout);
    for (int s = 0; s < o.nsizes; ++s) {
        row *R = &rows[s];
        memcpy(R->dims, o.dims[s], sizeof R->dims);
        double vox = voxels_of(R->dims), bytes = vox * (double)tsize;
        /* Predictions from what the last sizes measured (no constants): peak RSS linear in the
         * voxels through the last two sizes (proportional from one), device bytes per voxel as
         * the library reported for the last size. */
        const row *p1 = NULL, *p2 = NULL;
        for (int k = s - 1; k >= 0 && !p1; --k)
            if (strcmp(rows[k].status, "ok") == 0)
                p1 = &rows[k];
        for (int k = (int)(p1 ? p1 - rows : 0) - 1; k >= 0 && p1 && !p2; --k)
            if (strcmp(rows[k].status, "ok") == 0)
                p2 = &rows[k];
        double rss = 0.0, dev = 0.0;
        if (p1 && p2 && voxels_of(p1->dims) > voxels_of(p2->dims))
            rss = p1->peak_rss + (p1->peak_rss - p2->peak_rss) /
                                     (voxels_of(p1->dims) - voxels_of(p2->dims)) *
                                     (vox - voxels_of(p1->dims));
        else if (p1)
            rss = p1->peak_rss * vox / voxels_of(p1->dims);
        if (p1)
            dev = p1->device_bytes / voxels_of(p1->dims) * vox;
        struct statvfs fs;
        double disk = statvfs(o.tmp, &fs) == 0 ? (double)fs.f_bavail * (double)fs.f_frsize : 0.0;
        double avail = proc_bytes("/proc/meminfo", "MemAvailable:");
        if (disk < bytes * 1.05 + 1e9)
            snprintf(R->status, sizeof R->status,
                     "skipped: the raw file needs %.2f GiB, %s has %.2f GiB free", bytes / 1073741824.0,
                     o.tmp, disk / 1073741824.0);
        else if (rss > 0.9 * avail)
            snprintf(R->status, sizeof R->status,
                     "skipped: predicted peak RSS %.2f GiB (from the sizes measured before) > 90%% "
                     "of the %.2f GiB available",
                     rss / 1073741824.0, avail / 1073741824.0);
        else if (dev > (double)global_mem)
            snprintf(R->status, sizeof R->status,
                     "skipped: predicted volume device bytes %.2f GiB > device memory %.2f GiB",
                     dev / 1073741824.0, (double)global_mem / 1073741824.0);
        if (R->status[0]) {
            fprintf(stderr, "scale: %ux%ux%u %s\n", R->dims[0], R->dims[1], R->dims[2], R->status);
            continue;
        }
        fprintf(stderr, "scale: %ux%ux%u %s (%.2f GiB file): writing ...\n", R->dims[0], R->dims[1],
                R->dims[2], type_name(o.type), bytes / 1073741824.0);
        double t0 = bench_now_ms();
        if (write_field(path, R->dims, o.type) != 0) {
            snprintf(R->status, sizeof R->status, "failed: could not write the raw file in %.120s: "
                     "%.80s", o.tmp, strerror(errno));
        } else {
            R->gen_ms = bench_now_ms() - t0;
            fprintf(stderr, "scale:   written in %.1f s; measuring in a fresh process ...\n",
                    R->gen_ms / 1e3);
            run_child(&o, path, R->dims, R);
        }
        remove(path);
        measured += strcmp(R->status, "ok") == 0;
        failures += strncmp(R->status, "failed", 6) == 0;
        csv_row(stdout, R, o.type);
        fflush(stdout);
    }
    if (o.results) {
        char f1[700];
        snprintf(f1, sizeof f1, "%s/scale.csv", o.results);
        FILE *f = fopen(f1, "w");
        if (f) {
            csv_header(f);
            for (int s = 0; s < o.nsizes; ++s)
                csv_row(f, &rows[s], o.type);
            fclose(f);
        }
        snprintf(f1, sizeof f1, "%s/scale.md", o.results);
        FILE *m = f ? fopen(f1, "w") : NULL;
        if (m) {
            write_md(m, rows, o.nsizes, &o, machine, device, commit, started, load_start);
            fclose(m);
        }
        if (!f || !m) {
            fprintf(stderr, "umbra-bench scale: cannot write %s\n", f1);
            return 1;
        }
        if (o.plots && measured > 0)
            write_plot(o.results);
    }
    return failures ? 1 : 0;
}
