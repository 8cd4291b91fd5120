// SPDX-License-Identifier: Apache-2.0
/* bench/accuracy_merge.c: `umbra-bench accuracy --merge FILE`, the rows of an earlier run's
 * accuracy.csv kept beside this run's, so that a sweep can be completed scene by scene or
 * technique by technique (the settings measured now replace theirs: same scene, technique and
 * params) and its fronts, plots, headline and summary cover all of it. A row is matched to its
 * setting in the sweep (accuracy_scene_configs) by technique and params, which restores its label
 * and headline row; a row that matches none (a setting no longer swept) is left out with a note. */
#define _POSIX_C_SOURCE 200809L /* fmemopen */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"

#define MERGE_LINE_MAX 4096
#define MERGE_FIELDS_MAX 64

typedef struct merge_file {
    FILE *f;
    char *head[MERGE_FIELDS_MAX];
    int head_count;
    char head_line[MERGE_LINE_MAX];
} merge_file;

/* The merge file as read at the start (the run may overwrite it: --out names its folder). */
static char *merge_text;
static size_t merge_size;

int accuracy_merge_read(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    free(merge_text);
    merge_text = NULL;
    merge_size = 0;
    char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        char *t = realloc(merge_text, merge_size + got + 1);
        if (!t || merge_size + got > ((size_t)64 << 20)) {
            free(t ? t : merge_text);
            merge_text = NULL;
            fclose(f);
            return -1;
        }
        memcpy(t + merge_size, buf, got);
        merge_text = t;
        merge_size += got;
        merge_text[merge_size] = '\0';
    }
    fclose(f);
    return merge_text ? 0 : -1;
}

static int merge_open(merge_file *m)
{
    memset(m, 0, sizeof *m);
    m->f = merge_text ? fmemopen(merge_text, merge_size, "r") : NULL;
    if (!m->f || !fgets(m->head_line, sizeof m->head_line, m->f)) {
        if (m->f)
            fclose(m->f);
        m->f = NULL;
        return -1;
    }
    m->head_count = bench_split_csv(m->head_line, m->head, MERGE_FIELDS_MAX);
    return 0;
}

/* Field `name` of a row, or "" where the file has no such column. */
static const char *field(const merge_file *m, char **f, int n, const char *name)
{
    for (int i = 0; i < m->head_count && i < n; ++i)
        if (strcmp(m->head[i], name) == 0)
            return f[i];
    return "";
}

static double num(const merge_file *m, char **f, int n, const char *name)
{
    const char *s = field(m, f, n, name);
    return strcmp(s, "inf") == 0 ? INFINITY : atof(s);
}

int accuracy_merge_scene_names(char *names, size_t size)
{
    merge_file m;
    if (merge_open(&m) != 0)
        return -1;
    names[0] = '\0';
    char line[MERGE_LINE_MAX], *f[MERGE_FIELDS_MAX];
    while (fgets(line, sizeof line, m.f)) {
        const int n = bench_split_csv(line, f, MERGE_FIELDS_MAX);
        const char *scene = field(&m, f, n, "scene");
        char key[SCENE_NAME_MAX + 2];
        snprintf(key, sizeof key, ",%s,", scene);
        char padded[4096];
        snprintf(padded, sizeof padded, ",%s,", names);
        if (scene[0] && !strstr(padded, key) && strlen(names) + strlen(scene) + 2 < size)
            snprintf(names + strlen(names), size - strlen(names), "%s%s", names[0] ? "," : "",
                     scene);
    }
    fclose(m.f);
    return 0;
}

/* The setting of scene s that row (technique, params) was measured with, or NULL. */
static const config *find_config(const bench_run *B, const scene_spec *s, const char *technique,
                                 const char *params, config_list *L)
{
    for (int pass = 0; pass < 2; ++pass) {
        options o = B->o;
        o.techniques[0] = '\0';
        o.max_map = 1u << 16;
        o.quick = pass == 0 ? B->o.quick : !B->o.quick;
        accuracy_scene_configs(&o, s, L);
        for (int i = 0; i < L->count; ++i)
            if (strcmp(umbra_shadow_technique_name(L->items[i].desc.technique), technique) == 0 &&
                strcmp(L->items[i].params, params) == 0)
                return &L->items[i];
    }
    return NULL;
}

/* Whether this run measured the setting (scene si, technique, params). */
static int measured(const bench_run *B, int measured_count, int si, const config *c)
{
    for (int k = 0; k < measured_count; ++k) {
        const result *r = &B->results[k];
        if (r->scene == si && r->cfg.desc.technique == c->desc.technique &&
            strcmp(r->cfg.params, c->params) == 0)
            return 1;
    }
    return 0;
}

static int by_order(const void *a, const void *b)
{
    const result *x = a, *y = b;
    return x->order < y->order ? -1 : x->order > y->order;
}

void accuracy_merge_rows(bench_run *B)
{
    merge_file m;
    if (merge_open(&m) != 0) {
        accuracy_add_note(B, "--merge %s: cannot read it", B->o.merge);
        ++B->failures;
        return;
    }
    static config_list L; /* large; one merge per process */
    const int measured_count = B->result_count;
    int kept = 0, unmatched = 0;
    char line[MERGE_LINE_MAX], *f[MERGE_FIELDS_MAX];
    while (fgets(line, sizeof line, m.f)) {
        const int n = bench_split_csv(line, f, MERGE_FIELDS_MAX);
        const int si = accuracy_scene_index(B, field(&m, f, n, "scene"));
        if (si < 0)
            continue;
        const config *c =
            find_config(B, &B->scenes[si], field(&m, f, n, "technique"), field(&m, f, n, "params"), &L);
        if (!c) {
            ++unmatched;
            continue;
        }
        if (measured(B, measured_count, si, c))
            continue;
        result *r = accuracy_new_result(B);
        if (!r)
            break;
        r->scene = si;
        r->cfg = *c;
        r->width = (uint32_t)num(&m, f, n, "width");
        r->height = (uint32_t)num(&m, f, n, "height");
        r->runs = (int)num(&m, f, n, "runs");
        r->build_ms = num(&m, f, n, "build_ms");
        r->render_ms = num(&m, f, n, "render_ms");
        r->total_ms = num(&m, f, n, "total_ms");
        r->build_min = num(&m, f, n, "build_ms_min");
        r->build_max = num(&m, f, n, "build_ms_max");
        r->render_min = num(&m, f, n, "render_ms_min");
        r->render_max = num(&m, f, n, "render_ms_max");
        r->none_ms = num(&m, f, n, "none_render_ms");
        r->reference_ms = num(&m, f, n, "reference_ms");
        r->reference_cached = r->runs < 0;
        r->memory = (size_t)num(&m, f, n, "memory_bytes");
        r->channels = (uint32_t)num(&m, f, n, "light_channels");
        r->slices = (uint32_t)num(&m, f, n, "slices");
        r->samples = (uint64_t)num(&m, f, n, "samples");
        r->map_size = (uint32_t)num(&m, f, n, "map_size");
        if (c->desc.map.size == UMBRA_MAP_SIZE_AUTO && r->map_size) /* as accuracy_run.c */
            snprintf(r->cfg.label + strlen(r->cfg.label),
                     sizeof r->cfg.label - strlen(r->cfg.label), " (%u²)", r->map_size);
        r->err.rmse = num(&m, f, n, "rmse");
        r->err.psnr_db = num(&m, f, n, "psnr_db");
        r->err.max_abs = num(&m, f, n, "max_abs");
        r->err.mean_abs = num(&m, f, n, "mean_abs");
        r->err.ssim = num(&m, f, n, "ssim");
        const char *unc = field(&m, f, n, "reference_half_step_rmse");
        r->ref_unc.rmse = unc[0] ? atof(unc) : -1.0;
        r->ref_unc.max_abs = num(&m, f, n, "reference_half_step_max_abs");
        ++kept;
    }
    fclose(m.f);
    /* The sweep's order: by scene, then by the setting's place in the scene's list. */
    for (int k = 0; k < B->result_count; ++k) {
        result *r = &B->results[k];
        const config *c = find_config(B, &B->scenes[r->scene],
                                      umbra_shadow_technique_name(r->cfg.desc.technique),
                                      r->cfg.params, &L);
        r->order = r->scene * MAX_CONFIGS * 2 + (c ? (int)(c - L.items) : MAX_CONFIGS);
    }
    qsort(B->results, (size_t)B->result_count, sizeof B->results[0], by_order);
    free(merge_text);
    merge_text = NULL;
    accuracy_add_note(B, "%d rows kept from %s (--merge), measured in an earlier run%s", kept,
                      B->o.merge, unmatched ? "; rows of settings no longer swept left out" : "");
}
