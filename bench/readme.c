// SPDX-License-Identifier: Apache-2.0
/* bench/readme.c: `umbra-bench readme`, which writes the measured sections of the README and of
 * the docs it manages from the recorded results, so that no figure there is typed by hand.
 *
 * The files managed: README.md and docs/accuracy.md, which must hold blocks, and any other
 * .md file in docs/ that holds one (in name order). Each marks each generated block with a pair of HTML
 * comments:
 *
 *     <!-- umbra-bench readme: NAME -->
 *     ... replaced on every run ...
 *     <!-- umbra-bench readme: end -->
 *
 * NAME is one of:
 *   choose    the all-scenes part of the headline table (DIR/headline.md): one row per
 *             technique's headline setting, for the README's "choosing a technique";
 *   headline  the headline table of `umbra-bench accuracy` (DIR/headline.md, itself generated
 *             from accuracy.csv) and the main scene's error-versus-time and error-versus-memory
 *             plots;
 *   gallery   the main scene's pictures from the same run (DIR/images/SCENE/, written by
 *             `--images headline`), one table row each with the build time, render time, memory,
 *             light channels and error read from accuracy.csv;
 *   texel     DIR/texel.md, every scene's plot of RMSE against bytes per map texel, its Pareto
 *             front and the moment map at equal memory.
 * `NAME SUB` takes the block from the results' folder SUB instead (DIR/SUB: a second sweep). 
 * Links are written relative to each file's folder. `--check` changes nothing and exits 1 when a
 * file is out of date (for a pre-commit check and the docs_check test). */
#define _XOPEN_SOURCE 700

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"

#ifndef UMBRA_SOURCE_DIR
#define UMBRA_SOURCE_DIR "."
#endif

#define MARK_BEGIN "<!-- umbra-bench readme: "
#define MARK_END "<!-- umbra-bench readme: end -->"
#define MAX_COLUMNS 64

/* A growing string. */
typedef struct text {
    char *s;
    size_t len, cap;
} text;

static int text_add(text *t, const char *s, size_t n)
{
    if (t->len + n + 1 > t->cap) {
        size_t cap = t->cap ? t->cap : 4096;
        while (cap < t->len + n + 1)
            cap *= 2;
        char *p = realloc(t->s, cap);
        if (!p)
            return -1;
        t->s = p;
        t->cap = cap;
    }
    memcpy(t->s + t->len, s, n);
    t->len += n;
    t->s[t->len] = '\0';
    return 0;
}

static int text_printf(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static int text_printf(text *t, const char *fmt, ...)
{
    char buf[4096];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof buf)
        return -1;
    return text_add(t, buf, (size_t)n);
}

/* The whole file, or NULL (errno set). */
static char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    text t = {0};
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        if (text_add(&t, buf, n) != 0) {
            free(t.s);
            fclose(f);
            errno = ENOMEM;
            return NULL;
        }
    fclose(f);
    if (!t.s)
        text_add(&t, "", 0);
    return t.s;
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

/* The file name `umbra-bench accuracy` gives a setting's picture: "<technique>-<params>" (or the
 * technique alone when params is "-") with every character outside [A-Za-z0-9._-] made '_'. */
static void image_name(const char *technique, const char *params, char *out, size_t size)
{
    if (strcmp(params, "-") == 0)
        snprintf(out, size, "%s", technique);
    else
        snprintf(out, size, "%s-%s", technique, params);
    for (char *s = out; *s; ++s)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              *s == '-' || *s == '.' || *s == '_'))
            *s = '_';
}

static int column(char **header, int n, const char *name)
{
    for (int i = 0; i < n; ++i)
        if (strcmp(header[i], name) == 0)
            return i;
    return -1;
}

/* ---- the blocks ------------------------------------------------------------------------------ */

typedef struct job {
    const char *readme; /* the file being written */
    char results[PATH_MAX]; /* the accuracy results folder */
    char link[PATH_MAX];    /* the same folder as the file links it */
    const char *scene;
} job;

/* Appends the lines of s to out, leaving out HTML comments; 0 or -1. */
static int add_lines(text *out, const char *s)
{
    int rc = 0;
    for (const char *line = s; *line && rc == 0;) {
        size_t n = strcspn(line, "\n");
        if (strncmp(line, "<!--", 4) != 0)
            rc = text_add(out, line, n) || text_add(out, "\n", 1);
        line += n + (line[n] == '\n');
    }
    return rc;
}

/* DIR/headline.md into out: the whole table, or (all_scenes) its all-scenes part, from its
 * "**All " line to the end. 0, or -1 after a message. */
static int add_headline(const job *J, text *out, int all_scenes)
{
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/headline.md", J->results);
    char *md = read_file(path);
    if (!md) {
        fprintf(stderr, "readme: cannot read %s: %s (run `umbra-bench accuracy` first)\n", path,
                strerror(errno));
        return -1;
    }
    const char *from = all_scenes ? strstr(md, "\n**All ") : md;
    if (!from)
        fprintf(stderr, "readme: %s has no all-scenes table ('**All N scenes**')\n", path);
    int rc = from ? add_lines(out, from + (from != md)) : -1;
    free(md);
    return rc;
}

static int block_headline(const job *J, text *out)
{
    char path[PATH_MAX + 64];
    int rc = add_headline(J, out, 0);
    const char *kinds[] = {"time", "memory"};
    int plots = 0;
    for (int i = 0; i < 2 && rc == 0; ++i) {
        snprintf(path, sizeof path, "%s/plots/%s-error-vs-%s.png", J->results, J->scene,
                 kinds[i]);
        if (!file_exists(path))
            continue;
        rc = text_printf(out, "%s![%s: error against %s](%s/plots/%s-error-vs-%s.png)",
                         plots++ ? " " : "\n", J->scene, kinds[i], J->link, J->scene, kinds[i]);
    }
    if (plots && rc == 0)
        rc = text_add(out, "\n", 1);
    return rc;
}

/* DIR/texel.md: the maps' error against bytes per texel, its links made relative to the file. */
static int block_texel(const job *J, text *out)
{
    char path[PATH_MAX + 64], link[PATH_MAX + 8];
    snprintf(path, sizeof path, "%s/texel.md", J->results);
    snprintf(link, sizeof link, "%s/", J->link);
    char *md = read_file(path);
    if (!md) {
        fprintf(stderr, "readme: cannot read %s: %s (run `umbra-bench accuracy` first)\n", path,
                strerror(errno));
        return -1;
    }
    text t = {0};
    int rc = add_lines(&t, md);
    free(md);
    for (const char *p = t.s; rc == 0 && p && *p;) {
        const char *at = strstr(p, "](plots/");
        const size_t n = at ? (size_t)(at - p) + 2 : strlen(p);
        rc = text_add(out, p, n) || (at && text_add(out, link, strlen(link)));
        p += n;
    }
    free(t.s);
    return rc;
}

/* The headline table's all-scenes part, for the README's choice of a technique. */
static int block_choose(const job *J, text *out) { return add_headline(J, out, 1); }

static int block_gallery(const job *J, text *out)
{
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/accuracy.csv", J->results);
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "readme: cannot read %s: %s (run `umbra-bench accuracy` first)\n", path,
                strerror(errno));
        return -1;
    }
    char header_line[4096], line[4096];
    char *header[MAX_COLUMNS], *v[MAX_COLUMNS];
    int nh = fgets(header_line, sizeof header_line, f)
                 ? bench_split_csv(header_line, header, MAX_COLUMNS)
                 : 0;
    const char *names[] = {"scene",  "technique",    "label",          "params",
                           "width",  "height",       "build_ms",       "render_ms",
                           "memory_bytes", "light_channels", "rmse", "ssim"};
    enum { SCENE, TECH, LABEL, PARAMS, WIDTH, HEIGHT, BUILD, RENDER, MEM, CHANNELS, RMSE, SSIM,
           NCOL };
    int col[NCOL];
    for (int i = 0; i < NCOL; ++i)
        if ((col[i] = column(header, nh, names[i])) < 0) {
            fprintf(stderr, "readme: %s has no column '%s'\n", path, names[i]);
            fclose(f);
            return -1;
        }
    int rows = 0, rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        int n = bench_split_csv(line, v, MAX_COLUMNS);
        if (n != nh || strcmp(v[col[SCENE]], J->scene) != 0)
            continue;
        char name[512], image[PATH_MAX + 700];
        image_name(v[col[TECH]], v[col[PARAMS]], name, sizeof name);
        snprintf(image, sizeof image, "%s/images/%s/%s.png", J->results, J->scene, name);
        if (!file_exists(image))
            continue;
        if (rows++ == 0)
            rc = text_printf(out, "Pictures %sx%s; times are device times of one frame (medians), "
                                  "from the same run as the headline table.\n\n"
                                  "| picture | technique | setting | build ms | render ms | "
                                  "memory | light channels | RMSE | SSIM |\n"
                                  "|---|---|---|---:|---:|---:|---:|---:|---:|\n",
                             v[col[WIDTH]], v[col[HEIGHT]]);
        char build[32], render[32], mem[32];
        const double build_ms = atof(v[col[BUILD]]);
        if (build_ms > 0.0)
            bench_format_ms(build_ms, build, sizeof build);
        else
            snprintf(build, sizeof build, "–");
        bench_format_ms(atof(v[col[RENDER]]), render, sizeof render);
        bench_format_bytes((size_t)atof(v[col[MEM]]), mem, sizeof mem);
        const int exact = strcmp(v[col[TECH]], "reference") == 0 && atof(v[col[RMSE]]) == 0.0;
        char label[256];
        snprintf(label, sizeof label, "%s", v[col[LABEL]]);
        for (char *s = label; *s; ++s)
            if (*s == ';')
                *s = ','; /* accuracy.csv writes the labels' commas as ';' */
        if (rc == 0)
            rc = text_printf(out, "| ![%s %s](%s/images/%s/%s.png) | %s%s%s | %s | %s | %s | %s "
                                  "| %s | %.4f | %.4f |\n",
                             v[col[TECH]], label, J->link, J->scene, name, exact ? "**" : "",
                             v[col[TECH]], exact ? "**" : "", label, build, render, mem,
                             v[col[CHANNELS]], exact ? 0.0 : atof(v[col[RMSE]]),
                             exact ? 1.0 : atof(v[col[SSIM]]));
    }
    fclose(f);
    if (rc == 0 && rows == 0) {
        fprintf(stderr, "readme: no pictures of scene '%s' under %s/images (run `umbra-bench "
                        "accuracy --images headline`)\n", J->scene, J->results);
        return -1;
    }
    return rc;
}

/* ---- the README ------------------------------------------------------------------------------ */

/* Rewrites every marked block of src into out; 0, or -1 after a message. */
static int regenerate(const job *J, const char *src, text *out)
{
    const char *p = src;
    int blocks = 0;
    for (;;) {
        const char *begin = strstr(p, MARK_BEGIN);
        while (begin && strncmp(begin, MARK_END, strlen(MARK_END)) == 0)
            begin = strstr(begin + 1, MARK_BEGIN);
        if (!begin)
            break;
        const char *name = begin + strlen(MARK_BEGIN);
        const char *close = strstr(name, " -->");
        const char *end = close ? strstr(close, MARK_END) : NULL;
        if (!close || !end) {
            fprintf(stderr, "readme: %s: a block opened with '%.40s' has no '%s'\n", J->readme,
                    begin, MARK_END);
            return -1;
        }
        char block[64];
        snprintf(block, sizeof block, "%.*s", (int)(close - name), name);
        /* "NAME SUB": the block from the results' folder SUB (a folder name, no "..") */
        job K = *J;
        char *arg = strchr(block, ' ');
        if (arg) {
            *arg++ = '\0';
            const size_t rl = strlen(K.results), ll = strlen(K.link), al = strlen(arg);
            if (strstr(arg, "..") || strchr(arg, ' ') || rl + al + 2 > sizeof K.results ||
                ll + al + 2 > sizeof K.link) {
                fprintf(stderr, "readme: %s: bad folder '%s' in block '%s'\n", J->readme, arg,
                        block);
                return -1;
            }
            K.results[rl] = '/';
            memcpy(K.results + rl + 1, arg, al + 1);
            K.link[ll] = '/';
            memcpy(K.link + ll + 1, arg, al + 1);
        }
        const char *after_open = close + 4;
        if (*after_open == '\n')
            ++after_open;
        if (text_add(out, p, (size_t)(after_open - p)) != 0)
            return -1;
        int rc;
        if (strcmp(block, "headline") == 0)
            rc = block_headline(&K, out);
        else if (strcmp(block, "choose") == 0)
            rc = block_choose(&K, out);
        else if (strcmp(block, "gallery") == 0)
            rc = block_gallery(&K, out);
        else if (strcmp(block, "texel") == 0)
            rc = block_texel(&K, out);
        else {
            fprintf(stderr, "readme: %s: unknown block '%s' (choose, headline, gallery, texel)\n",
                    J->readme, block);
            rc = -1;
        }
        if (rc != 0)
            return -1;
        p = end;
        ++blocks;
    }
    if (blocks == 0) {
        fprintf(stderr, "readme: %s has no '%sNAME -->' blocks\n", J->readme, MARK_BEGIN);
        return -1;
    }
    return text_add(out, p, strlen(p));
}

/* J->link: J->results as seen from the file's folder (relative when it lies inside it). */
static void link_path(job *J)
{
    char dir[PATH_MAX], rdir[PATH_MAX], racc[PATH_MAX];
    size_t len = strlen(J->readme);
    if (len >= sizeof dir)
        len = sizeof dir - 1;
    memcpy(dir, J->readme, len);
    dir[len] = '\0';
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(dir, sizeof dir, ".");
    snprintf(J->link, sizeof J->link, "%s", J->results);
    if (!realpath(dir, rdir) || !realpath(J->results, racc))
        return;
    /* The longest common prefix of whole components; then one "../" per component of rdir
     * past it. With nothing in common but the root, the absolute path. */
    size_t common = 0;
    for (size_t i = 0;; ++i) {
        const int rend = rdir[i] == '\0' || rdir[i] == '/';
        const int aend = racc[i] == '\0' || racc[i] == '/';
        if (rend && aend)
            common = i;
        if (rdir[i] == '\0' || racc[i] == '\0' || rdir[i] != racc[i])
            break;
    }
    if (common == 0) {
        snprintf(J->link, sizeof J->link, "%s", racc);
        return;
    }
    char up[PATH_MAX] = "";
    size_t n = 0;
    for (const char *s = rdir + common; *s && n + 4 < sizeof up; ++s)
        if (*s == '/') {
            memcpy(up + n, "../", 4);
            n += 3;
        }
    const char *rest = racc + common + (racc[common] == '/');
    if (snprintf(J->link, sizeof J->link, "%s%s", up, *rest ? rest : ".") >= (int)sizeof J->link)
        snprintf(J->link, sizeof J->link, "%s", racc); /* too deep for a relative link */
}

static void usage(FILE *f)
{
    fprintf(f, "usage: umbra-bench readme [--readme FILE] [--results DIR] [--scene NAME] "
               "[--check]\n"
               "  rewrites the '" MARK_BEGIN "NAME [SUB] -->' blocks (NAME: choose,\n"
               "  headline, gallery or texel; SUB: a folder of the results) of README.md,\n"
               "  docs/accuracy.md and any other docs/*.md holding one, from the results of\n"
               "  `umbra-bench accuracy`\n"
               "  --readme FILE   only this file\n"
               "  --results DIR   default <source>/bench/results/accuracy\n"
               "  --scene NAME    the scene of the plots and pictures (default walnut)\n"
               "  --check         change nothing; exit 1 if a file is out of date\n");
}

/* Regenerates one file (J->readme); with check, only compares. 0, or 1 after a message. */
static int process_file(job *J, int check)
{
    link_path(J);
    char *src = read_file(J->readme);
    if (!src) {
        fprintf(stderr, "readme: cannot read %s: %s\n", J->readme, strerror(errno));
        return 1;
    }
    text out = {0};
    int rc = regenerate(J, src, &out) == 0 ? 0 : 1;
    if (rc == 0 && strcmp(out.s, src) != 0) {
        if (check) {
            fprintf(stderr, "readme: %s is out of date: run umbra-bench readme\n", J->readme);
            rc = 1;
        } else {
            FILE *f = fopen(J->readme, "wb");
            if (!f || fwrite(out.s, 1, out.len, f) != out.len) {
                fprintf(stderr, "readme: cannot write %s: %s\n", J->readme, strerror(errno));
                rc = 1;
            }
            if (f && fclose(f) != 0)
                rc = 1;
            if (rc == 0)
                fprintf(stderr, "readme: updated %s\n", J->readme);
        }
    } else if (rc == 0) {
        fprintf(stderr, "readme: %s is up to date\n", J->readme);
    }
    free(out.s);
    free(src);
    return rc;
}

#define MAX_FILES 64

static int compare_names(const void *a, const void *b)
{
    return strcmp((const char *)a, (const char *)b);
}

/* The files to manage: README.md, docs/accuracy.md, then every other .md file in docs/ that
 * holds a block, in name order. Returns their count. */
static int managed_files(char (*files)[PATH_MAX])
{
    int n = 0;
    snprintf(files[n++], PATH_MAX, "%s/README.md", UMBRA_SOURCE_DIR);
    snprintf(files[n++], PATH_MAX, "%s/docs/accuracy.md", UMBRA_SOURCE_DIR);
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s/docs", UMBRA_SOURCE_DIR);
    DIR *d = opendir(dir);
    if (!d)
        return n;
    static char names[MAX_FILES][256];
    int m = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL && m < MAX_FILES;) {
        const size_t len = strlen(e->d_name);
        if (len < 4 || len >= sizeof names[0] || strcmp(e->d_name + len - 3, ".md") != 0 ||
            strcmp(e->d_name, "accuracy.md") == 0)
            continue;
        snprintf(names[m++], sizeof names[0], "%s", e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)m, sizeof names[0], compare_names);
    for (int i = 0; i < m && n < MAX_FILES; ++i) {
        const size_t dl = strlen(dir), nl = strlen(names[i]);
        if (dl + 1 + nl >= PATH_MAX)
            continue;
        char *path = files[n];
        memcpy(path, dir, dl);
        path[dl] = '/';
        memcpy(path + dl + 1, names[i], nl + 1);
        char *text = read_file(path);
        if (text && strstr(text, MARK_BEGIN))
            ++n;
        free(text);
    }
    return n;
}

int bench_readme(int argc, char **argv)
{
    job J;
    memset(&J, 0, sizeof J);
    const char *only = NULL;
    snprintf(J.results, sizeof J.results, "%s/bench/results/accuracy", UMBRA_SOURCE_DIR);
    J.scene = "walnut";
    int check = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--check") == 0) {
            check = 1;
        } else if (i + 1 < argc && strcmp(a, "--readme") == 0) {
            only = argv[++i];
        } else if (i + 1 < argc && strcmp(a, "--results") == 0) {
            snprintf(J.results, sizeof J.results, "%s", argv[++i]);
        } else if (i + 1 < argc && strcmp(a, "--scene") == 0) {
            J.scene = argv[++i];
        } else {
            fprintf(stderr, "readme: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return 2;
        }
    }
    if (only) {
        J.readme = only;
        return process_file(&J, check);
    }
    static char files[MAX_FILES][PATH_MAX];
    const int n = managed_files(files);
    int rc = 0;
    for (int f = 0; f < n; ++f) {
        J.readme = files[f];
        rc |= process_file(&J, check);
    }
    return rc;
}
