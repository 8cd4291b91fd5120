// SPDX-License-Identifier: Apache-2.0
/* bench/accuracy_report.c: `umbra-bench accuracy`, the outputs written from the results table
 * (bench/accuracy.h): the per-scene Pareto fronts, accuracy.csv, the gnuplot plots
 * (bench/plot_accuracy.gp), headline.md (docs/accuracy.md's headline), summary.md and papers.md
 * (the seed papers' timing tables beside ours). Nothing here renders; bench/README.md describes
 * the files. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"

/* ---- Pareto fronts --------------------------------------------------------------------------- */

typedef struct front_point {
    double cost, rmse;
    int row;
} front_point;

static int cmp_front(const void *a, const void *b)
{
    const front_point *x = a, *y = b;
    if (x->cost != y->cost)
        return (x->cost > y->cost) - (x->cost < y->cost);
    return (x->rmse > y->rmse) - (x->rmse < y->rmse);
}

/* Marks, per scene, the runs no other run beats in both cost and error (strictly in one), for
 * three costs: time, memory and, over the light-space maps only, bytes per map texel (memory /
 * map_size^2). The exact reference (error 0 by definition) and, for memory, runs that hold no
 * memory are left out: the plots are logarithmic. Writes the fronts, sorted by cost, to
 * <out>/plots/<scene>-pareto-{time,memory,texel}.dat for gnuplot. */
void accuracy_pareto(bench_run *B)
{
    front_point *pts = malloc((size_t)(B->result_count + 1) * sizeof *pts);
    if (!pts)
        return;
    for (int si = 0; si < B->scene_count; ++si)
        for (int mem = 0; mem < 3; ++mem) { /* 0 time, 1 memory, 2 bytes per map texel */
            int n = 0;
            for (int k = 0; k < B->result_count; ++k) {
                const result *r = &B->results[k];
                if (r->scene == si && !r->cfg.exact && r->err.rmse > 0.0 &&
                    (!mem || r->memory > 0) && (mem < 2 || r->map_size > 0)) {
                    pts[n].cost = mem == 2   ? accuracy_bytes_per_texel(r)
                                  : mem == 1 ? (double)r->memory
                                             : r->total_ms;
                    pts[n].rmse = r->err.rmse;
                    pts[n].row = k;
                    ++n;
                }
            }
            if (n == 0)
                continue;
            qsort(pts, (size_t)n, sizeof *pts, cmp_front);
            char path[4200];
            static const char *const kind[3] = {"time", "memory", "texel"};
            static const char *const unit[3] = {"total_ms", "memory_mib", "bytes_per_texel"};
            snprintf(path, sizeof path, "%s/plots/%s-pareto-%s.dat", B->o.out,
                     B->scenes[si].name, kind[mem]);
            FILE *f = fopen(path, "w");
            if (f)
                fprintf(f, "# %s,rmse,technique and setting\n", unit[mem]);
            double best = INFINITY;
            for (int j = 0; j < n; ++j) {
                result *r = &B->results[pts[j].row];
                if (r->err.rmse < best) {
                    best = r->err.rmse;
                    if (mem == 2)
                        r->pareto_texel = 1;
                    else if (mem)
                        r->pareto_memory = 1;
                    else
                        r->pareto_time = 1;
                    char label[160];
                    snprintf(label, sizeof label, "%s %s",
                             umbra_shadow_technique_name(r->cfg.desc.technique), r->cfg.label);
                    accuracy_sanitize(label, 0);
                    if (f)
                        fprintf(f, "%.6g,%.6g,%s\n",
                                mem == 2 ? pts[j].cost
                                : mem    ? (double)r->memory / 1048576.0
                                         : r->total_ms,
                                r->err.rmse,
                                label);
                }
            }
            if (f)
                fclose(f);
        }
    free(pts);
}

/* ---- output: CSV ----------------------------------------------------------------------------- */

/* Columns of accuracy.csv, in order; plot_accuracy.gp gets the indices it needs from here. */
static const char *const csv_columns[] = {
    "scene", "technique", "label", "params", "width", "height", "runs", "build_ms", "render_ms",
    "total_ms", "build_ms_min", "build_ms_max", "render_ms_min", "render_ms_max", "none_render_ms",
    "render_overhead", "build_over_frame", "reference_ms", "speedup_vs_reference", "memory_bytes",
    "light_channels", "slices", "samples", "rmse", "psnr_db", "max_abs", "mean_abs", "ssim",
    "pareto_time", "pareto_memory", "reference_half_step_rmse", "reference_half_step_max_abs",
    "map_size", "bytes_per_texel", "pareto_texel",
};

static int csv_column(const char *name)
{
    for (size_t i = 0; i < sizeof csv_columns / sizeof csv_columns[0]; ++i)
        if (strcmp(csv_columns[i], name) == 0)
            return (int)i + 1;
    return 0;
}

/* Opens DIR/name for writing (DIR the --out directory); where that fails, notes why, counts a
 * failure and returns NULL. */
static FILE *open_output(bench_run *B, const char *name)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", B->o.out, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        accuracy_add_note(B, "cannot write %s: %s", path, strerror(errno));
        ++B->failures;
    }
    return f;
}

void accuracy_write_csv(bench_run *B)
{
    FILE *f = open_output(B, "accuracy.csv");
    if (!f)
        return;
    for (size_t i = 0; i < sizeof csv_columns / sizeof csv_columns[0]; ++i)
        fprintf(f, "%s%s", i ? "," : "", csv_columns[i]);
    fputc('\n', f);
    for (int k = 0; k < B->result_count; ++k) {
        const result *r = &B->results[k];
        char label[128], params[192];
        snprintf(label, sizeof label, "%s", r->cfg.label);
        snprintf(params, sizeof params, "%s", r->cfg.params);
        accuracy_sanitize(label, 0);
        accuracy_sanitize(params, 0);
        double total = r->total_ms;
        fprintf(f, "%s,%s,%s,%s,%u,%u,%d,", B->scenes[r->scene].name,
                umbra_shadow_technique_name(r->cfg.desc.technique), label, params, r->width,
                r->height, r->runs);
        fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,", r->build_ms, r->render_ms, total,
                r->build_min, r->build_max, r->render_min, r->render_max, r->none_ms);
        if (r->none_ms > 0.0)
            fprintf(f, "%.4f,%.4f,", r->render_ms / r->none_ms, r->build_ms / r->none_ms);
        else
            fprintf(f, ",,");
        fprintf(f, "%.4f,%.4f,%zu,%u,%u,%llu,", r->reference_ms,
                total > 0.0 ? r->reference_ms / total : 0.0, r->memory, r->channels, r->slices,
                (unsigned long long)r->samples);
        fprintf(f, "%.6g,", r->err.rmse);
        if (isinf(r->err.psnr_db))
            fprintf(f, "inf,");
        else
            fprintf(f, "%.3f,", r->err.psnr_db);
        fprintf(f, "%.6g,%.6g,%.6f,%d,%d,", r->err.max_abs, r->err.mean_abs, r->err.ssim,
                r->pareto_time, r->pareto_memory);
        if (r->ref_unc.rmse >= 0.0)
            fprintf(f, "%.6g,%.6g,", r->ref_unc.rmse, r->ref_unc.max_abs);
        else
            fprintf(f, ",,");
        fprintf(f, "%u,", r->map_size);
        if (r->map_size > 0 && r->memory > 0)
            fprintf(f, "%.6g,%d\n", accuracy_bytes_per_texel(r), r->pareto_texel);
        else
            fprintf(f, ",\n");
    }
    fclose(f);
}

/* ---- output: plots --------------------------------------------------------------------------- */

/* gnuplot single-quoted string: a quote is doubled. */
static void gp_string(FILE *f, const char *name, const char *value)
{
    fprintf(f, "%s = '", name);
    for (const char *p = value; *p; ++p) {
        if (*p == '\'')
            fputc('\'', f);
        fputc(*p, f);
    }
    fprintf(f, "'\n");
}

void accuracy_write_plots(bench_run *B)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/bench/plot_accuracy.gp", UMBRA_SOURCE_DIR);
    if (!accuracy_file_exists(script)) {
        accuracy_add_note(B, "plots skipped: %s not found", script);
        return;
    }
    for (int si = 0; si < B->scene_count; ++si) {
        /* Techniques present in this scene, with a fixed style index each across all plots;
         * for the memory plot only those that hold memory (the axis is logarithmic). */
        char techs[256] = "", styles[64] = "", techs_mem[256] = "", styles_mem[64] = "";
        char techs_map[256] = "", styles_map[64] = "";
        int any = 0, any_mem = 0, any_map = 0;
        /* The registry's order gives each technique its style (bench/plot_accuracy.gp). */
        for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
            const umbra_technique_info *ti = umbra_technique_get(t);
            int has = 0, has_mem = 0, has_map = 0;
            for (int k = 0; k < B->result_count; ++k) {
                const result *r = &B->results[k];
                if (r->scene == si && r->cfg.desc.technique == ti->id && !r->cfg.exact &&
                    r->err.rmse > 0.0) {
                    has = 1;
                    has_mem |= r->memory > 0;
                    has_map |= r->memory > 0 && r->map_size > 0;
                }
            }
            const char *name = ti->name;
            if (has) {
                size_t n = strlen(techs), m = strlen(styles);
                snprintf(techs + n, sizeof techs - n, "%s%s", any ? " " : "", name);
                snprintf(styles + m, sizeof styles - m, "%s%u", any ? " " : "", t + 1);
                any = 1;
            }
            if (has_mem) {
                size_t n = strlen(techs_mem), m = strlen(styles_mem);
                snprintf(techs_mem + n, sizeof techs_mem - n, "%s%s", any_mem ? " " : "", name);
                snprintf(styles_mem + m, sizeof styles_mem - m, "%s%u", any_mem ? " " : "", t + 1);
                any_mem = 1;
            }
            if (has_map) {
                size_t n = strlen(techs_map), m = strlen(styles_map);
                snprintf(techs_map + n, sizeof techs_map - n, "%s%s", any_map ? " " : "", name);
                snprintf(styles_map + m, sizeof styles_map - m, "%s%u", any_map ? " " : "", t + 1);
                any_map = 1;
            }
        }
        if (!any)
            continue;
        const scene_spec *spec = &B->scenes[si];
        char buf[4200];
        FILE *gp = popen("gnuplot 2>&1", "w");
        if (!gp) {
            accuracy_add_note(B, "plots skipped: cannot run gnuplot");
            return;
        }
        snprintf(buf, sizeof buf, "%s/accuracy.csv", B->o.out);
        gp_string(gp, "csv", buf);
        gp_string(gp, "scene", spec->name);
        gp_string(gp, "scene_title", spec->description[0] ? spec->description : spec->name);
        gp_string(gp, "techniques", techs);
        gp_string(gp, "styles", styles);
        gp_string(gp, "techniques_memory", techs_mem);
        gp_string(gp, "styles_memory", styles_mem);
        snprintf(buf, sizeof buf, "%s/plots/%s-pareto-time.dat", B->o.out, spec->name);
        gp_string(gp, "pareto_time", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-pareto-memory.dat", B->o.out, spec->name);
        gp_string(gp, "pareto_memory", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-error-vs-time.png", B->o.out, spec->name);
        gp_string(gp, "out_time", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-error-vs-memory.png", B->o.out, spec->name);
        gp_string(gp, "out_memory", any_mem ? buf : "");
        snprintf(buf, sizeof buf, "%s/plots/%s-pareto-texel.dat", B->o.out, spec->name);
        gp_string(gp, "pareto_texel", buf);
        snprintf(buf, sizeof buf, "%s/plots/%s-error-vs-bytes-per-texel.png", B->o.out,
                 spec->name);
        gp_string(gp, "out_texel", any_map ? buf : "");
        gp_string(gp, "techniques_texel", techs_map);
        gp_string(gp, "styles_texel", styles_map);
        fprintf(gp, "c_scene = %d\nc_tech = %d\nc_total = %d\nc_rmse = %d\nc_mem = %d\n"
                    "c_exact_ref = %d\nc_width = %d\nc_height = %d\nc_bpt = %d\n",
                csv_column("scene"), csv_column("technique"), csv_column("total_ms"),
                csv_column("rmse"), csv_column("memory_bytes"), csv_column("reference_ms"),
                csv_column("width"), csv_column("height"), csv_column("bytes_per_texel"));
        gp_string(gp, "script", script);
        fprintf(gp, "load script\n");
        int rc = pclose(gp);
        if (rc != 0) {
            accuracy_add_note(B, "plots for %s: gnuplot exited with status %d (is gnuplot "
                                 "installed? Debian: apt-get install gnuplot-nox)", spec->name, rc);
            return;
        }
    }
}

/* ---- output: Markdown ------------------------------------------------------------------------ */

static const result *find_headline(const bench_run *B, int si, int h)
{
    for (int k = 0; k < B->result_count; ++k)
        if (B->results[k].scene == si && B->results[k].cfg.headline == h)
            return &B->results[k];
    return NULL;
}

/* Whether scene si has any result (a scene whose volume is missing has none). */
static int scene_has_results(const bench_run *B, int si)
{
    for (int k = 0; k < B->result_count; ++k)
        if (B->results[k].scene == si)
            return 1;
    return 0;
}

static int main_scene(const bench_run *B)
{
    int first = -1;
    for (int si = 0; si < B->scene_count; ++si) {
        if (!scene_has_results(B, si))
            continue;
        if (strcmp(B->scenes[si].name, B->o.main_scene) == 0)
            return si;
        if (first < 0)
            first = si;
    }
    return first;
}

static void fmt_ratio(double x, char *buf, size_t size)
{
    if (!(x > 0.0) || !isfinite(x))
        snprintf(buf, size, "–");
    else if (x >= 100.0)
        snprintf(buf, size, "%.0f×", x);
    else if (x >= 10.0)
        snprintf(buf, size, "%.1f×", x);
    else
        snprintf(buf, size, "%.2f×", x);
}

/* The headline table for one scene (si >= 0), or geometric means over all scenes (si < 0). */
static void headline_table(const bench_run *B, FILE *f, int si)
{
    fprintf(f, "| technique | render overhead over unshadowed | map build / unshadowed frame | "
               "RMSE | reference's own RMSE | SSIM | memory | speed-up over exact reference |%s\n"
               "|---|---|---|---|---|---|---|---|%s\n", si < 0 ? " scenes |" : "",
            si < 0 ? "---|" : "");
    int rows = 0;
    for (int k = 0; k < B->result_count; ++k)
        rows = B->results[k].cfg.headline > rows ? B->results[k].cfg.headline : rows;
    for (int h = H_NONE; h <= rows; ++h) {
        double lo = 0, lb = 0, rm = 0, ss = 0, lmem = 0, lsp = 0, ru = 0;
        int n = 0, nb = 0, nmem = 0, nu = 0;
        const result *any = NULL;
        for (int s = 0; s < B->scene_count; ++s) {
            if (si >= 0 && s != si)
                continue;
            const result *r = find_headline(B, s, h);
            if (!r || !(r->none_ms > 0.0))
                continue;
            lo += log(r->render_ms / r->none_ms);
            if (r->build_ms > 0.0) {
                lb += log(r->build_ms / r->none_ms);
                ++nb;
            }
            rm += r->err.rmse;
            if (r->ref_unc.rmse >= 0.0) {
                ru += r->ref_unc.rmse;
                ++nu;
            }
            ss += r->err.ssim;
            if (r->memory > 0) {
                lmem += log((double)r->memory);
                ++nmem;
            }
            lsp += log(r->reference_ms / r->total_ms);
            any = r;
            ++n;
        }
        if (n == 0)
            continue;
        char o[32], b[32], m[32], sp[32];
        fmt_ratio(exp(lo / n), o, sizeof o);
        if (nb)
            fmt_ratio(exp(lb / nb), b, sizeof b);
        else
            snprintf(b, sizeof b, "–");
        if (nmem)
            bench_format_bytes((size_t)exp(lmem / nmem), m, sizeof m);
        else
            snprintf(m, sizeof m, "0");
        fmt_ratio(exp(lsp / n), sp, sizeof sp);
        char name[160];
        if (h == H_NONE)
            snprintf(name, sizeof name, "none (unshadowed)");
        else
            snprintf(name, sizeof name, "%s, %s",
                     umbra_shadow_technique_name(any->cfg.desc.technique), any->cfg.label);
        char u[32] = "–";
        if (nu)
            snprintf(u, sizeof u, "%.1e", ru / nu);
        fprintf(f, "| %s | %s | %s | %.4f | %s | %.4f | %s | %s |", name, o, b, rm / n, u, ss / n, m,
                sp);
        if (si < 0)
            fprintf(f, " %d |", n);
        fprintf(f, "\n");
    }
}

void accuracy_write_headline(bench_run *B)
{
    FILE *f = open_output(B, "headline.md");
    if (!f)
        return;
    int ms = main_scene(B);
    int nscenes = 0;
    char names[1024] = "";
    for (int si = 0; si < B->scene_count; ++si) {
        if (!scene_has_results(B, si))
            continue;
        size_t n = strlen(names);
        snprintf(names + n, sizeof names - n, "%s%s", nscenes ? ", " : "", B->scenes[si].name);
        ++nscenes;
    }
    fprintf(f, "<!-- generated by `umbra-bench accuracy%s` from accuracy.csv; do not edit -->\n",
            B->o.quick ? " --quick" : "");
    if (ms >= 0) {
        const result *none = find_headline(B, ms, H_NONE);
        char t[32] = "?";
        if (none)
            bench_format_ms(none->render_ms, t, sizeof t);
        fprintf(f, "**%s** (%ux%u, unshadowed frame %s ms):\n\n", B->scenes[ms].name,
                none ? none->width : 0, none ? none->height : 0, t);
        headline_table(B, f, ms);
    }
    fprintf(f, "\n**All %d scenes** (%s): ratios, memory and speed-ups are geometric means, RMSE "
               "and SSIM arithmetic means over the scenes where the setting ran:\n\n",
            nscenes, names);
    headline_table(B, f, -1);
    fprintf(f, "\nRender overhead: render time with shadows over the unshadowed render of the same "
               "view; build: the shadow structure's construction over one unshadowed frame (paid "
               "when the light or the transfer function changes); RMSE and SSIM against the "
               "exact reference (display values, `bench/metrics.h`); the reference's own RMSE: "
               "the exact reference at its step against the exact reference at half that step, "
               "the yardstick's uncertainty (an RMSE near it is not a measured error); speed-up: "
               "the exact "
               "reference's render time over build + render. %s%s. %s.\n",
            B->o.report ? "Measured in earlier runs (their rows joined by --report; the "
                          "summary's notes)" : "Device: ",
            B->o.report ? "" : B->device, B->started);
    fclose(f);
}

void accuracy_write_summary(bench_run *B)
{
    FILE *f = open_output(B, "summary.md");
    if (!f)
        return;
    char path[4200];
    fprintf(f, "# umbra-bench accuracy%s\n\nWhat accuracy costs in time: every shadow technique "
               "against the exact reference, per scene. Generated by `umbra-bench accuracy%s`; "
               "the raw numbers are in `accuracy.csv`, the method in `bench/README.md`.\n\n",
            B->o.quick ? " --quick" : "", B->o.quick ? " --quick" : "");
    accuracy_write_machine(B, f);
    fprintf(f, "\n## Headline\n\n");
    FILE *h = NULL;
    snprintf(path, sizeof path, "%s/headline.md", B->o.out);
    h = fopen(path, "r");
    if (h) {
        char line[2048];
        while (fgets(line, sizeof line, h))
            if (strncmp(line, "<!--", 4) != 0)
                fputs(line, f);
        fclose(h);
    }
    for (int si = 0; si < B->scene_count; ++si) {
        const scene_spec *spec = &B->scenes[si];
        int rows = 0;
        for (int k = 0; k < B->result_count; ++k)
            rows += B->results[k].scene == si;
        fprintf(f, "\n## %s\n\n%s. Scene file `bench/scenes/%s.scene`.\n\n", spec->name,
                spec->description[0] ? spec->description : spec->name, spec->name);
        if (!B->present[si]) {
            fprintf(f, "Skipped: volume `%s` is not present.\n", spec->volume);
            continue;
        }
        if (rows == 0) {
            fprintf(f, "No results (see the notes).\n");
            continue;
        }
        fprintf(f, "![error vs time](plots/%s-error-vs-time.png) "
                   "![error vs memory](plots/%s-error-vs-memory.png)\n\n", spec->name,
                spec->name);
        for (int k = 0; k < B->result_count; ++k)
            if (B->results[k].scene == si) {
                const result *r = &B->results[k];
                if (r->ref_unc.rmse >= 0.0)
                    fprintf(f, "The reference's own uncertainty (its step %g against half of it): "
                               "RMSE %.1e, max %.1e; column \"ref ±\" below.\n\n",
                            r->cfg.desc.technique == UMBRA_SHADOW_REFERENCE
                                ? r->cfg.desc.reference.step
                                : accuracy_exact_step(spec),
                            r->ref_unc.rmse, r->ref_unc.max_abs);
                else
                    fprintf(f, "The reference's own uncertainty could not be measured.\n\n");
                break;
            }
        fprintf(f, "| technique | setting | build ms | render ms | overhead | build/frame | "
                   "memory | ch | RMSE | ref ± | PSNR dB | max | SSIM | speed-up | runs | front |\n"
                   "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int k = 0; k < B->result_count; ++k) {
            const result *r = &B->results[k];
            if (r->scene != si)
                continue;
            char b[32], rd[32], ov[32], bf[32], mem[32], sp[32], psnr[32], runs[32];
            bench_format_ms(r->build_ms, b, sizeof b);
            bench_format_ms(r->render_ms, rd, sizeof rd);
            fmt_ratio(r->none_ms > 0 ? r->render_ms / r->none_ms : 0, ov, sizeof ov);
            fmt_ratio(r->none_ms > 0 ? r->build_ms / r->none_ms : 0, bf, sizeof bf);
            bench_format_bytes(r->memory, mem, sizeof mem);
            fmt_ratio(r->reference_ms / r->total_ms, sp, sizeof sp);
            if (isinf(r->err.psnr_db))
                snprintf(psnr, sizeof psnr, "∞");
            else
                snprintf(psnr, sizeof psnr, "%.1f", r->err.psnr_db);
            if (r->runs < 0)
                snprintf(runs, sizeof runs, "cached");
            else
                snprintf(runs, sizeof runs, "%d", r->runs ? r->runs : 1);
            char unc_s[32] = "–";
            if (r->ref_unc.rmse >= 0.0)
                snprintf(unc_s, sizeof unc_s, "%.1e", r->ref_unc.rmse);
            fprintf(f, "| %s | %s | %s | %s | %s | %s | %s | %u | %.4f | %s | %s | %.3f | %.4f | "
                       "%s | %s | %s |\n",
                    umbra_shadow_technique_name(r->cfg.desc.technique), r->cfg.label, b, rd, ov,
                    bf, mem, r->channels, r->err.rmse, unc_s, psnr, r->err.max_abs, r->err.ssim,
                    sp, runs,
                    r->pareto_time ? (r->pareto_memory ? "time, memory" : "time")
                                   : (r->pareto_memory ? "memory" : ""));
        }
    }
    fprintf(f, "\n## Notes\n\n");
    if (B->notes.count == 0)
        fprintf(f, "None: every setting ran.\n");
    for (int i = 0; i < B->notes.count; ++i)
        fprintf(f, "- %s\n", B->notes.items[i]);
    fclose(f);
}

/* ---- output: the papers' tables -------------------------------------------------------------- */

static const result *find_run(const bench_run *B, int si, umbra_shadow_technique t,
                              uint32_t map, uint32_t taps, float eps, uint32_t nodes,
                              uint32_t prefilter)
{
    for (int k = 0; k < B->result_count; ++k) {
        const result *r = &B->results[k];
        const umbra_shadow_desc *d = &r->cfg.desc;
        if (r->scene != si || d->technique != t || d->map.size != map)
            continue;
        if (t == UMBRA_SHADOW_THRESHOLD &&
            (d->threshold.taps != taps || d->threshold.threshold != 0.5f))
            continue;
        if (t == UMBRA_SHADOW_CSSM && (d->cssm.taps != taps || d->cssm.ray_block != 0))
            continue;
        if (t == UMBRA_SHADOW_DEEP && (d->deep.epsilon != eps || d->deep.max_nodes != nodes ||
                                       d->deep.prefilter != prefilter))
            continue;
        return r;
    }
    return NULL;
}

/* Mean over the scenes (only scene `only` if >= 0) that have all three techniques at all three
 * sizes: build times, or render times with render set. */
static int cssm_tables_mean(const bench_run *B, int only, int render, double out[3][3],
                            int *nscenes)
{
    static const uint32_t maps[3] = {1024, 2048, 4096};
    memset(out, 0, 9 * sizeof(double));
    int n = 0;
    for (int si = 0; si < B->scene_count; ++si) {
        double v[3][3];
        int ok = only < 0 || si == only;
        for (int m = 0; m < 3 && ok; ++m) {
            const result *rr[3] = {
                find_run(B, si, UMBRA_SHADOW_THRESHOLD, maps[m], 1, 0, 0, 0),
                find_run(B, si, UMBRA_SHADOW_DEEP, maps[m], 0, 0.02f, 3, 1),
                find_run(B, si, UMBRA_SHADOW_CSSM, maps[m], 13, 0, 0, 0),
            };
            for (int t = 0; t < 3; ++t) {
                if (!rr[t]) {
                    ok = 0;
                    break;
                }
                v[m][t] = render ? rr[t]->render_ms : rr[t]->build_ms;
            }
        }
        if (!ok)
            continue;
        for (int m = 0; m < 3; ++m)
            for (int t = 0; t < 3; ++t)
                out[m][t] += v[m][t];
        ++n;
    }
    for (int m = 0; m < 3 && n; ++m)
        for (int t = 0; t < 3; ++t)
            out[m][t] /= n;
    *nscenes = n;
    return n > 0;
}

static void cssm_table(FILE *f, const char *title, const double paper[3][3], double ours[3][3],
                       const char *whose)
{
    static const char *const tech[3] = {"threshold map", "deep map (3 nodes)", "CSSM (13 taps)"};
    static const char *const sizes[3] = {"1024²", "2048²", "4096²"};
    fprintf(f, "%s — %s\n\n| map | technique | paper ms | ours ms | paper: ÷ threshold | ours: "
               "÷ threshold | paper: ÷ 1024² | ours: ÷ 1024² |\n"
               "|---|---|---|---|---|---|---|---|\n", title, whose);
    for (int m = 0; m < 3; ++m)
        for (int t = 0; t < 3; ++t) {
            char o[32], pr[32], orr[32], ps[32], os[32];
            bench_format_ms(ours[m][t], o, sizeof o);
            fmt_ratio(paper[m][t] / paper[m][0], pr, sizeof pr);
            fmt_ratio(ours[m][0] > 0 ? ours[m][t] / ours[m][0] : 0, orr, sizeof orr);
            fmt_ratio(paper[m][t] / paper[0][t], ps, sizeof ps);
            fmt_ratio(ours[0][t] > 0 ? ours[m][t] / ours[0][t] : 0, os, sizeof os);
            fprintf(f, "| %s | %s | %.1f | %s | %s | %s | %s | %s |\n", sizes[m], tech[t],
                    paper[m][t], o, pr, orr, ps, os);
        }
    fprintf(f, "\n");
}

void accuracy_write_papers(bench_run *B)
{
    FILE *f = open_output(B, "papers.md");
    if (!f)
        return;
    fprintf(f, "# The seed papers' timing tables, re-measured\n\n"
               "Generated by `umbra-bench accuracy%s` from the same runs as `accuracy.csv`. The "
               "papers timed GPUs of their day; umbra here runs on a CPU through PoCL, so absolute "
               "times do not compare. What does compare is the shape: each technique's cost "
               "relative to another measured on the same machine, and how cost grows with the map "
               "size. Those ratios stand next to the papers'.\n\n", B->o.quick ? " --quick" : "");
    accuracy_write_machine(B, f);

    /* CSSM paper (Weidner & Linsen), Tables 3 and 4: ms, rows 1024/2048/4096, columns threshold
     * shadow map, deep shadow map (3 nodes per channel), CSSM (13 offsets). */
    static const double paper_gen[3][3] = {{1.0, 1.1, 1.2}, {2.9, 3.3, 3.6}, {8.5, 10.5, 11.1}};
    static const double paper_ren[3][3] = {{3.2, 3.3, 4.9}, {3.2, 3.1, 4.7}, {3.3, 3.4, 4.9}};
    fprintf(f, "\n## CSSM paper, Tables 3 and 4 (Weidner & Linsen)\n\n"
               "Generation (shadow-map build) and rendering times at 1024², 2048² and 4096² for "
               "the opacity-threshold map (opacity 0.5), the deep shadow map with 3 nodes per "
               "colour channel and CSSM with 13 taps. The paper's numbers are averages over "
               "several data sets on its GPU; ours are medians on the scenes marked `papers "
               "cssm` (the walnut: the paper's Figure 3 data set), averaged if several. "
               "Ratios: each technique over the threshold map at the same size, and each size "
               "over 1024² for the same technique.\n\n");
    int n = 0;
    double ours[3][3];
    if (cssm_tables_mean(B, -1, 0, ours, &n)) {
        char names[256] = "";
        /* Room for the longest names plus the prefix: a possible truncation is a -Werror at -O0
         * (the Debug build), where GCC cannot see the names are short. */
        char whose[sizeof names + 32];
        for (int si = 0, k = 0; si < B->scene_count; ++si) {
            double dummy[3][3];
            int one = 0;
            if (cssm_tables_mean(B, si, 0, dummy, &one)) {
                size_t len = strlen(names);
                snprintf(names + len, sizeof names - len, "%s%s", k++ ? ", " : "",
                         B->scenes[si].name);
            }
        }
        if (n == 1)
            snprintf(whose, sizeof whose, "ours: %s", names);
        else
            snprintf(whose, sizeof whose, "ours: mean over %s", names);
        cssm_table(f, "**Table 3, generation**", paper_gen, ours, whose);
        cssm_tables_mean(B, -1, 1, ours, &n);
        cssm_table(f, "**Table 4, rendering**", paper_ren, ours, whose);
        int w = accuracy_scene_index(B, "walnut"), nw = 0;
        if (n > 1 && w >= 0 && cssm_tables_mean(B, w, 0, ours, &nw)) {
            cssm_table(f, "**Table 3, generation**", paper_gen, ours, "ours: walnut");
            cssm_tables_mean(B, w, 1, ours, &nw);
            cssm_table(f, "**Table 4, rendering**", paper_ren, ours, "ours: walnut");
        }
    } else {
        fprintf(f, "Not measured in this run: it needs threshold, deep (3 nodes) and CSSM at "
                   "1024², 2048² and 4096² (the full sweep on a scene marked `papers cssm`; "
                   "`--quick` and `--max-map` below 4096 leave them out).\n\n");
    }

    /* Deep-map paper (Hadwiger et al.), Table 1: construction speed in fps for 128^2..512^2 maps
     * at epsilon 0.02 and 0.06, 5-tap pre-filter, CT hand 256x128x256, ATI X1800. */
    static const char *const paper_fps[3][2] = {{"2–3", "5–6"}, {"1–2", "2–3"},
                                                {"0.3–0.5", "1–1.5"}};
    static const double paper_mid[3][2] = {{2.5, 5.5}, {1.5, 2.5}, {0.4, 1.25}};
    fprintf(f, "\n## Deep-shadow-map paper, Table 1 (Hadwiger et al.)\n\n"
               "Construction speed of the deep shadow map (frames per second of map building "
               "alone) at 128², 256² and 512² with error bounds ε = 0.02 and 0.06 and a 5-tap "
               "pre-filter. The paper's hand CT (256×128×256) is not available; the foot CT "
               "(256³) stands in for it where present, else the first scene measured. The "
               "paper's fps include its multi-pass rendering and copies into a 3D texture, "
               "which a single OpenCL kernel does not need; compare the ratios: ε = 0.06 over "
               "ε = 0.02 (the paper: larger ε builds faster because fewer nodes are written) and "
               "each size over 128².\n\n");
    int fs = accuracy_scene_index(B, "foot");
    if (fs < 0 || !find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5))
        for (int si = 0; si < B->scene_count; ++si)
            if (find_run(B, si, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5)) {
                fs = si;
                break;
            }
    if (fs >= 0 && find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5)) {
        static const uint32_t sizes[3] = {128, 256, 512};
        fprintf(f, "Scene: %s.\n\n| map | ε | paper fps | ours ms | ours fps | memory | paper: "
                   "fps(0.06) ÷ fps(0.02) | ours | paper: time ÷ 128² | ours |\n"
                   "|---|---|---|---|---|---|---|---|---|---|\n", B->scenes[fs].name);
        const result *base[2] = {find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.02f, 0, 5),
                                 find_run(B, fs, UMBRA_SHADOW_DEEP, 128, 0, 0.06f, 0, 5)};
        for (int s = 0; s < 3; ++s) {
            const result *r[2] = {find_run(B, fs, UMBRA_SHADOW_DEEP, sizes[s], 0, 0.02f, 0, 5),
                                  find_run(B, fs, UMBRA_SHADOW_DEEP, sizes[s], 0, 0.06f, 0, 5)};
            for (int e = 0; e < 2; ++e) {
                if (!r[e])
                    continue;
                char ms[32], mem[32], pe[32] = "", oe[32] = "", ps[32], os[32];
                bench_format_ms(r[e]->build_ms, ms, sizeof ms);
                bench_format_bytes(r[e]->memory, mem, sizeof mem);
                if (e == 1 && r[0]) {
                    fmt_ratio(paper_mid[s][1] / paper_mid[s][0], pe, sizeof pe);
                    fmt_ratio(r[0]->build_ms / r[1]->build_ms, oe, sizeof oe);
                }
                fmt_ratio(paper_mid[0][e] / paper_mid[s][e], ps, sizeof ps);
                fmt_ratio(base[e] ? r[e]->build_ms / base[e]->build_ms : 0, os, sizeof os);
                fprintf(f, "| %u² | %.2f | %s | %s | %.1f | %s | %s | %s | %s | %s |\n", sizes[s],
                        e ? 0.06 : 0.02, paper_fps[s][e], ms, 1000.0 / r[e]->build_ms, mem, pe,
                        oe, ps, os);
            }
        }
        fprintf(f, "\nPaper ratios use the midpoints of its fps ranges.\n");
    } else {
        fprintf(f, "Not measured in this run (the full sweep measures it; `--quick` does not).\n");
    }

    fprintf(f, "\n## Convolution-shadow paper, Table 1\n\n"
               "Re-measured by `umbra-bench convolution` (slice distance 0.2–0.8 voxel × 0–3 "
               "sub-samples, time per frame and mean absolute pixel difference): see "
               "`bench/results/convolution.md`. This sweep's convolution rows (`accuracy.csv`, "
               "technique `convolution`) add the error against the exact reference.\n");
    fclose(f);
}

