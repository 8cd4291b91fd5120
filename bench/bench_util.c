// SPDX-License-Identifier: Apache-2.0
/* bench/bench_util.c: see bench.h. Timing, CSV rows, the bonsai (or its procedural stand-in),
 * and a description of the machine. */
#define _POSIX_C_SOURCE 200809L
#include "bench.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "internal.h" /* the volume's device buffer, to read back exactly what umbra samples */

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

/* ---- timing ------------------------------------------------------------------------------------ */

double bench_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

bench_timing bench_timing_of(const double *ms, int n)
{
    bench_timing t = {0.0, 0.0, 0.0, n};
    if (n < 1)
        return t;
    double *s = malloc((size_t)n * sizeof *s);
    if (!s)
        return t;
    memcpy(s, ms, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp_double);
    t.median = n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
    t.min = s[0];
    t.max = s[n - 1];
    free(s);
    return t;
}

void bench_csv_row(FILE *f, const char *name, bench_timing t, uint64_t samples)
{
    if (samples)
        fprintf(f, "%s,%.3f,%.4g,%llu,%.3f,%.3f\n", name, t.median,
                (double)samples / (t.median * 1e-3), (unsigned long long)samples, t.min, t.max);
    else
        fprintf(f, "%s,%.3f,,,%.3f,%.3f\n", name, t.median, t.min, t.max);
}

/* ---- command line ---------------------------------------------------------------------------------- */

/* The bench's one whole-number check: an optional '-' then decimal digits only (strtol alone
 * takes blanks, '+' and wraps nothing but says little), the value in [lo, hi]. */
int bench_in_list(const char *list, const char *name)
{
    const size_t n = strlen(name);
    for (const char *p = list; *p;) {
        const char *comma = strchr(p, ',');
        const size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0)
            return 1;
        if (!comma)
            break;
        p = comma + 1;
    }
    return 0;
}

int bench_parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    if (!s || (!(s[0] >= '0' && s[0] <= '9') && !(s[0] == '-' && s[1] >= '0' && s[1] <= '9')))
        return -1;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (*end || errno || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

int bench_parse_float(const char *s, float lo, float hi, float *out)
{
    char *end;
    errno = 0;
    float v = s ? strtof(s, &end) : 0.0f;
    if (!s || !*s || *end || errno || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

/* "WxH", each side a whole number in [1, 16384] (sscanf's %u took "-1" and wrapped 2^32 + 64). */
int bench_parse_size(const char *s, uint32_t *w, uint32_t *h)
{
    const char *x = s ? strchr(s, 'x') : NULL;
    char side[16];
    long a, b;
    if (!x || (size_t)(x - s) >= sizeof side)
        return -1;
    memcpy(side, s, (size_t)(x - s));
    side[x - s] = '\0';
    if (bench_parse_int(side, 1, 16384, &a) != 0 || bench_parse_int(x + 1, 1, 16384, &b) != 0)
        return -1;
    *w = (uint32_t)a;
    *h = (uint32_t)b;
    return 0;
}

static void print_error(void *user, umbra_status status, const char *message)
{
    (void)user;
    fprintf(stderr, "umbra-bench: %s: %s\n", umbra_status_to_string(status), message);
}

umbra_context bench_context(const char *device)
{
    umbra_context_desc d;
    umbra_context_desc_init(&d);
    /* "P:D" (platform and device indices), as --help documents; anything else is a name. */
    const char *colon = device ? strchr(device, ':') : NULL;
    char platform[16];
    long p, q;
    if (colon && (size_t)(colon - device) < sizeof platform) {
        memcpy(platform, device, (size_t)(colon - device));
        platform[colon - device] = '\0';
    }
    if (colon && (size_t)(colon - device) < sizeof platform &&
        bench_parse_int(platform, 0, 1023, &p) == 0 && bench_parse_int(colon + 1, 0, 1023, &q) == 0) {
        d.platform_index = (int)p;
        d.device_index = (int)q;
    } else {
        d.device_name = device;
    }
    /* The sampler, to compare the two back ends on one device (AUTO, the library's, otherwise). */
    const char *sampler = getenv("UMBRA_SAMPLER");
    if (sampler && strcmp(sampler, "buffer") == 0) {
        d.sampler = UMBRA_SAMPLER_BUFFER;
    } else if (sampler && strcmp(sampler, "image") == 0) {
        d.sampler = UMBRA_SAMPLER_IMAGE;
    } else if (sampler && *sampler) {
        fprintf(stderr, "umbra-bench: UMBRA_SAMPLER=%s: expected buffer or image\n", sampler);
        return NULL;
    }
    d.error_callback = print_error; /* creation failures have no context to keep the message */
    umbra_context ctx = NULL;
    if (umbra_context_create(&d, &ctx) != UMBRA_SUCCESS)
        return NULL;
    /* From here on the subcommands print umbra_context_last_message where they fail. */
    umbra_context_set_error_callback(ctx, NULL, NULL);
    return ctx;
}

/* ---- the machine --------------------------------------------------------------------------------------- */

void bench_cpu_model(char *buf, size_t size)
{
    snprintf(buf, size, "unknown CPU");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        char line[512];
        while (fgets(line, sizeof line, f))
            if (strncmp(line, "model name", 10) == 0) {
                const char *v = strchr(line, ':');
                v = v ? v + 1 : line;
                while (*v == ' ' || *v == '\t')
                    ++v;
                snprintf(buf, size, "%s", v);
                buf[strcspn(buf, "\n")] = 0;
                break;
            }
        fclose(f);
    }
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    size_t len = strlen(buf);
    if (n > 0 && len + 16 < size)
        snprintf(buf + len, size - len, ", %ld CPUs online", n);
}

void bench_device_description(umbra_context ctx, char *buf, size_t size)
{
    cl_uint units = 0;
    cl_device_id dev = umbra_context_cl_device(ctx);
    clGetDeviceInfo(dev, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof units, &units, NULL);
    snprintf(buf, size, "%s (%u compute units, %s sampler)", umbra_context_device_name(ctx), units,
             umbra_context_sampler(ctx) == UMBRA_SAMPLER_IMAGE ? "image" : "buffer");
}

/* ---- results files ------------------------------------------------------------------------------ */

FILE *bench_results_open(const char *dir, const char *subcommand, const char *ext)
{
    char path[1200];
    mkdir(dir, 0777); /* may exist already; fopen below reports real trouble */
    snprintf(path, sizeof path, "%s/%s.%s", dir, subcommand, ext);
    FILE *f = fopen(path, "w");
    if (!f)
        fprintf(stderr, "umbra-bench %s: cannot write %s\n", subcommand, path);
    return f;
}

void bench_results_header(FILE *f, const char *subcommand, int argc, char **argv,
                          const char *device)
{
    char cpu[600], date[64];
    time_t now = time(NULL);
    strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    bench_cpu_model(cpu, sizeof cpu);
    fprintf(f, "# umbra-bench %s\n\n- date: %s\n- command: `", subcommand, date);
    for (int i = 0; i < argc; ++i)
        fprintf(f, "%s%s", i ? " " : "umbra-bench ", argv[i]);
    fprintf(f, "`\n- OpenCL device: %s\n- CPU: %s\n", device, cpu);
}

/* ---- the procedural stand-in for the bonsai ---------------------------------------------------------------
 *
 * A 256^3 uint8 volume built to load a ray caster the way the bonsai CT does, not to look like
 * it in detail. y is up, as in the bonsai. Values are chosen in the bonsai's ranges, so the
 * benchmark's transfer function (bench/raycast.c) classifies them alike:
 *   - CT noise 0..11 everywhere (transparent; most of the volume, as in the scan);
 *   - a pot: an elliptic bowl shell around the bottom, value 205, filled with soil of value 150
 *     (the opaque part of the bonsai);
 *   - a tapering, slightly bent trunk of value 150 and 14 branches of value 140 (opaque-ish);
 *   - foliage: 900 small porous blobs of value 60..95 in a canopy ellipsoid (the sparse,
 *     translucent part, which is where a ray caster spends most of its samples).
 * Everything comes from an integer hash, so the volume is the same on every machine. */

static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

static float unit(uint32_t seed, uint32_t i) { return (float)(hash32(seed ^ hash32(i)) >> 8) / 16777216.0f; }

enum { PN = 256 };

/* Stamps a ball of radius r at (x, y, z): voxels inside take max(current, value - falloff). */
static void stamp_ball(uint8_t *v, float x, float y, float z, float r, int value, int porous)
{
    int x0 = (int)floorf(x - r), x1 = (int)ceilf(x + r);
    int y0 = (int)floorf(y - r), y1 = (int)ceilf(y + r);
    int z0 = (int)floorf(z - r), z1 = (int)ceilf(z + r);
    for (int k = z0 < 0 ? 0 : z0; k <= z1 && k < PN; ++k)
        for (int j = y0 < 0 ? 0 : y0; j <= y1 && j < PN; ++j)
            for (int i = x0 < 0 ? 0 : x0; i <= x1 && i < PN; ++i) {
                float dx = (float)i - x, dy = (float)j - y, dz = (float)k - z;
                float d = sqrtf(dx * dx + dy * dy + dz * dz);
                if (d > r)
                    continue;
                size_t idx = ((size_t)k * PN + (size_t)j) * PN + (size_t)i;
                if (porous && (hash32((uint32_t)idx * 2654435761u) & 3u) == 0)
                    continue; /* leaves leave gaps */
                int val = value - (int)(20.0f * d / r);
                if (val > v[idx])
                    v[idx] = (uint8_t)val;
            }
}

static void stamp_segment(uint8_t *v, const float a[3], const float b[3], float r0, float r1,
                          int value)
{
    float dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    int n = (int)ceilf(sqrtf(dx * dx + dy * dy + dz * dz)) + 1;
    for (int s = 0; s <= n; ++s) {
        float t = (float)s / (float)n;
        stamp_ball(v, a[0] + t * dx, a[1] + t * dy, a[2] + t * dz, r0 + t * (r1 - r0), value, 0);
    }
}

static uint8_t *procedural_bonsai(void)
{
    const size_t count = (size_t)PN * PN * PN;
    uint8_t *v = malloc(count);
    if (!v)
        return NULL;
    for (size_t i = 0; i < count; ++i)
        v[i] = (uint8_t)(hash32((uint32_t)i) % 12u);
    /* the pot: a bowl shell (y from 12 to 70) and soil up to y = 62 */
    const float cx = 128.0f, cz = 128.0f;
    for (int k = 0; k < PN; ++k)
        for (int j = 12; j <= 70; ++j)
            for (int i = 0; i < PN; ++i) {
                float ex = ((float)i - cx) / 110.0f, ez = ((float)k - cz) / 80.0f;
                float ey = (70.0f - (float)j) / 58.0f;
                float rr = sqrtf(ex * ex + ez * ez + ey * ey);
                size_t idx = ((size_t)k * PN + (size_t)j) * PN + (size_t)i;
                if (rr <= 1.0f && rr > 0.92f)
                    v[idx] = (uint8_t)(200 + hash32((uint32_t)idx) % 12u);
                else if (rr <= 0.92f && j <= 62)
                    v[idx] = (uint8_t)(140 + hash32((uint32_t)idx) % 20u);
            }
    /* the trunk, bent towards +x, and its branches */
    float prev[3] = {cx, 62.0f, cz};
    for (int s = 1; s <= 8; ++s) {
        float t = (float)s / 8.0f;
        float cur[3] = {cx + 30.0f * sinf(2.2f * t), 62.0f + 120.0f * t, cz + 10.0f * t};
        stamp_segment(v, prev, cur, 11.0f - 6.0f * (t - 0.125f), 11.0f - 6.0f * t, 150);
        memcpy(prev, cur, sizeof prev);
    }
    float tips[14][3];
    for (int b = 0; b < 14; ++b) {
        float t = 0.45f + 0.55f * unit(1u, (uint32_t)b);
        float base[3] = {cx + 30.0f * sinf(2.2f * t), 62.0f + 120.0f * t, cz + 10.0f * t};
        float ang = 6.2831853f * ((float)b / 14.0f + 0.1f * unit(2u, (uint32_t)b));
        float len = 45.0f + 40.0f * unit(3u, (uint32_t)b);
        tips[b][0] = base[0] + len * cosf(ang);
        tips[b][1] = base[1] + 15.0f + 25.0f * unit(4u, (uint32_t)b);
        tips[b][2] = base[2] + len * sinf(ang);
        stamp_segment(v, base, tips[b], 4.0f, 2.0f, 140);
    }
    /* foliage: blobs in the canopy, denser around the branch tips */
    for (int f = 0; f < 900; ++f) {
        float x, y, z;
        if (f % 3 == 0) {
            const float *tip = tips[f % 14];
            x = tip[0] + 30.0f * (unit(5u, (uint32_t)f) - 0.5f);
            y = tip[1] + 20.0f * (unit(6u, (uint32_t)f) - 0.5f);
            z = tip[2] + 30.0f * (unit(7u, (uint32_t)f) - 0.5f);
        } else {
            float u = unit(8u, (uint32_t)f) * 2.0f - 1.0f, w = unit(9u, (uint32_t)f) * 2.0f - 1.0f;
            float h = unit(10u, (uint32_t)f) * 2.0f - 1.0f;
            x = cx + 15.0f + 95.0f * u;
            y = 195.0f + 40.0f * h;
            z = cz + 90.0f * w * sqrtf(fmaxf(0.0f, 1.0f - u * u));
        }
        float r = 4.0f + 4.0f * unit(11u, (uint32_t)f);
        int value = 75 + (int)(20.0f * unit(12u, (uint32_t)f));
        stamp_ball(v, x, y, z, r, value, 1);
    }
    return v;
}

/* Writes data as NAME.raw plus a detached NRRD header NAME.nhdr into a fresh scratch directory. */
static int write_nrrd(const uint8_t *data, bench_volume *out)
{
    const char *base = getenv("TMPDIR");
    snprintf(out->tmpdir, sizeof out->tmpdir, "%s/umbra-bench-XXXXXX", base && *base ? base : "/tmp");
    if (!mkdtemp(out->tmpdir)) {
        fprintf(stderr, "umbra-bench: mkdtemp(%s) failed: %s\n", out->tmpdir, strerror(errno));
        out->tmpdir[0] = 0;
        return -1;
    }
    char raw[512];
    snprintf(raw, sizeof raw, "%s/bonsai_procedural.raw", out->tmpdir);
    snprintf(out->path, sizeof out->path, "%s/bonsai_procedural.nhdr", out->tmpdir);
    FILE *f = fopen(raw, "wb");
    size_t n = (size_t)PN * PN * PN;
    int ok = f && fwrite(data, 1, n, f) == n;
    if (f && fclose(f) != 0)
        ok = 0;
    FILE *h = ok ? fopen(out->path, "w") : NULL;
    if (h) {
        fprintf(h, "NRRD0004\n# umbra-bench procedural stand-in for the bonsai CT\ntype: uint8\n"
                   "dimension: 3\nsizes: %d %d %d\nspacings: 1 1 1\nencoding: raw\n"
                   "data file: bonsai_procedural.raw\n",
                PN, PN, PN);
        ok = fclose(h) == 0;
    } else {
        ok = 0;
    }
    if (!ok)
        fprintf(stderr, "umbra-bench: could not write %s\n", out->path);
    return ok ? 0 : -1;
}

/* ---- loading --------------------------------------------------------------------------------------------------- */

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* The normalised voxels exactly as the device holds them. */
static int read_back(umbra_context ctx, bench_volume *out)
{
    umbra_volume v = out->volume;
    size_t n = (size_t)v->dims[0] * v->dims[1] * v->dims[2];
    out->voxels = malloc(n * sizeof *out->voxels);
    if (!out->voxels)
        return -1;
    if (umbra__volume_read_normalised(v, out->voxels) != UMBRA_SUCCESS) {
        fprintf(stderr, "umbra-bench: reading the volume back failed: %s\n",
                umbra_context_last_message(ctx));
        return -1;
    }
    return 0;
}

int bench_volume_load_bonsai(umbra_context ctx, const char *path, int procedural,
                             bench_volume *out)
{
    memset(out, 0, sizeof *out);
    char candidates[3][1024];
    int nc = 0;
    const char *data_dir = getenv("UMBRA_DATA_DIR");
    if (path) {
        snprintf(candidates[nc++], sizeof candidates[0], "%s", path);
    } else if (!procedural) {
        if (data_dir && *data_dir) {
            snprintf(candidates[nc++], sizeof candidates[0], "%s/bonsai.nhdr", data_dir);
            snprintf(candidates[nc++], sizeof candidates[0], "%s/volumes/bonsai.nhdr", data_dir);
        }
        snprintf(candidates[nc++], sizeof candidates[0],
                 "%s/../shared/data/volumes/bonsai.nhdr", UMBRA_SOURCE_DIR);
    }
    for (int i = 0; i < nc && !out->volume; ++i) {
        if (!exists(candidates[i])) {
            if (path) {
                fprintf(stderr, "umbra-bench: volume %s does not exist\n", path);
                return -1;
            }
            continue;
        }
        umbra_status st = umbra_volume_load(ctx, candidates[i], &out->volume);
        if (st != UMBRA_SUCCESS) {
            fprintf(stderr, "umbra-bench: %s\n", umbra_context_last_message(ctx));
            return -1;
        }
        /* candidates[i] and path hold the same 1024 bytes at most */
        memcpy(out->path, candidates[i], sizeof out->path);
        memcpy(out->description, candidates[i], sizeof out->path);
    }
    if (!out->volume) {
        uint8_t *data = procedural_bonsai();
        if (!data) {
            fprintf(stderr, "umbra-bench: out of memory for the procedural volume\n");
            return -1;
        }
        umbra_volume_desc d;
        umbra_volume_desc_init(&d);
        d.data = data;
        d.type = UMBRA_UINT8;
        d.dims[0] = d.dims[1] = d.dims[2] = PN;
        d.value_range_given = 1;
        d.value_min = 0.0f;
        d.value_max = 255.0f;
        umbra_status st = umbra_volume_create(ctx, &d, &out->volume);
        int written = st == UMBRA_SUCCESS ? write_nrrd(data, out) : -1;
        free(data);
        if (st != UMBRA_SUCCESS) {
            fprintf(stderr, "umbra-bench: %s\n", umbra_context_last_message(ctx));
            return -1;
        }
        if (written != 0)
            out->path[0] = 0; /* umbra and native C still run; peers are skipped */
        snprintf(out->description, sizeof out->description,
                 "procedural 256^3 uint8 stand-in for the bonsai (%s)",
                 procedural ? "--procedural" : "bonsai.nhdr not found");
    }
    umbra_volume_info info;
    umbra_volume_get_info(out->volume, &info);
    memcpy(out->dims, info.dims, sizeof out->dims);
    memcpy(out->spacing, info.spacing, sizeof out->spacing);
    out->value_min = info.value_min;
    out->value_max = info.value_max;
    fprintf(stderr, "volume: %s, %u x %u x %u, value range [%g, %g]\n", out->description,
            out->dims[0], out->dims[1], out->dims[2], out->value_min, out->value_max);
    return read_back(ctx, out);
}

void bench_volume_free(bench_volume *v)
{
    if (!v)
        return;
    umbra_volume_release(v->volume);
    free(v->voxels);
    if (v->tmpdir[0]) {
        char p[600];
        snprintf(p, sizeof p, "%s/bonsai_procedural.raw", v->tmpdir);
        remove(p);
        snprintf(p, sizeof p, "%s/bonsai_procedural.nhdr", v->tmpdir);
        remove(p);
        rmdir(v->tmpdir);
    }
    memset(v, 0, sizeof *v);
}

void bench_format_bytes(size_t b, char *buf, size_t size)
{
    if (b == 0)
        snprintf(buf, size, "0");
    else if (b >= (size_t)1 << 30)
        snprintf(buf, size, "%.2f GiB", (double)b / (double)((size_t)1 << 30));
    else if (b >= (size_t)1 << 20)
        snprintf(buf, size, "%.1f MiB", (double)b / (double)((size_t)1 << 20));
    else
        snprintf(buf, size, "%.1f KiB", (double)b / 1024.0);
}

void bench_format_ms(double ms, char *buf, size_t size)
{
    if (ms >= 100.0)
        snprintf(buf, size, "%.0f", ms);
    else if (ms >= 10.0)
        snprintf(buf, size, "%.1f", ms);
    else
        snprintf(buf, size, "%.2f", ms);
}

/* Splits a CSV line (no quoting: accuracy.csv has none) in place; returns the field count. */
int bench_split_csv(char *line, char **fields, int max)
{
    int n = 0;
    line[strcspn(line, "\r\n")] = '\0';
    for (char *p = line; n < max;) {
        fields[n++] = p;
        char *comma = strchr(p, ',');
        if (!comma)
            break;
        *comma = '\0';
        p = comma + 1;
    }
    return n;
}
