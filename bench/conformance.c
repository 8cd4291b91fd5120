// SPDX-License-Identifier: Apache-2.0
/* bench/conformance.c: `umbra-bench conformance`, the conformance suite's measures against its
 * bounds. It runs the cases of tests/conformance.h (the analytic slab and the hard cases) for
 * every row of its bounds table (every technique of the registry, at its defaults and the
 * settings the table adds) and prints, as a Markdown table on stdout, each error beside its bound
 * and their ratio: how much room each technique has, and where a change moved it. The test
 * (tests/test_conformance.c) asserts the same bounds; this shows them. Exit status 1 when a
 * measure exceeds its bound, as the test would fail. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "conformance.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: umbra-bench conformance [options]\n"
               "  every technique's errors in the conformance suite's cases (tests/conformance.h)\n"
               "  beside the bounds the suite asserts; Markdown on stdout\n"
               "  --techniques A,B  only these techniques' rows\n"
               "  --device SPEC     OpenCL device (P:D or a name substring)\n");
}

static int listed(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && *p;) {
        size_t len = strcspn(p, ",");
        if (len == n && strncmp(p, name, n) == 0)
            return 1;
        p += len + (p[len] == ',');
    }
    return 0;
}

/* "1.2e-03 / 2.0e-03 (0.60)", "refused", "–" into buf. */
static int cell(double got, double bound, char *buf, size_t size)
{
    if (bound == CONF_NA) {
        snprintf(buf, size, "–");
        return 0;
    }
    const int over = !(got <= bound);
    if (bound > 0.0)
        snprintf(buf, size, "%.1e / %.1e (%.2f)%s", got, bound, got / bound,
                 over ? " **over**" : "");
    else
        snprintf(buf, size, "%.1e / 0%s", got, over ? " **over**" : "");
    return over;
}

int bench_conformance(int argc, char **argv)
{
    const char *techniques = NULL, *device = NULL;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(argv[i], "--techniques") == 0 && i + 1 < argc) {
            techniques = argv[++i];
        } else if (strcmp(argv[i], "--device") == 0 && i + 1 < argc) {
            device = argv[++i];
        } else {
            fprintf(stderr, "conformance: unknown option '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    umbra_context ctx = bench_context(device);
    if (!ctx)
        return 2;
    int over = 0, failed = 0;
    printf("# umbra-bench conformance\n\nDevice: %s. Each cell: error / bound (ratio). Slab "
           "cases: the ground's shadow factor against exp(-sigma L), mean over the image and "
           "max away from the shadow's edges; the others: mean |RGB| against the exact "
           "reference's image at %g voxel and mean |factor| against its factors at the query "
           "points.\n\n| setting | case | image (slab: mean) | points (slab: max) |\n"
           "|---|---|---|---|\n", umbra_context_device_name(ctx), (double)CONF_FINE_STEP);
    for (int c = 0; c < CONF_CASES && !failed; ++c) {
        conf_scene s;
        conf_yardstick y[2];
        memset(y, 0, sizeof y);
        char msg[1024];
        if (conf_scene_make(ctx, c, &s) != UMBRA_SUCCESS) {
            fprintf(stderr, "conformance: case %s: %s\n", conf_case_names[c],
                    umbra_context_last_message(ctx));
            conf_scene_release(&s);
            failed = 1;
            break;
        }
        for (int unlit = 0; unlit < 2 && !s.analytic; ++unlit)
            if (conf_yardstick_make(ctx, &s, unlit, &y[unlit], msg, sizeof msg) != UMBRA_SUCCESS) {
                fprintf(stderr, "conformance: case %s: the yardstick failed: %s\n",
                        conf_case_names[c], msg);
                failed = 1;
            }
        for (size_t i = 0; i < CONF_ROWS && !failed; ++i) {
            const conf_row *row = &conf_rows[i];
            const umbra_technique_info *t = umbra_technique_find(row->technique);
            if (!t || (techniques && !listed(techniques, row->technique)))
                continue;
            char name[256], a[96], b[96];
            snprintf(name, sizeof name, "%s%s%s", row->technique, row->params[0] ? " " : "",
                     row->params);
            conf_result res;
            conf_run(ctx, &s, &y[(t->flags & UMBRA_TECHNIQUE_NO_LIGHT) != 0], row, &res);
            if (row->image[c] == CONF_UNSUPPORTED) {
                const int ok = res.status == UMBRA_ERROR_UNSUPPORTED;
                over += !ok;
                printf("| %s | %s | %s | |\n", name, conf_case_names[c],
                       ok ? "refused, as the table says" : "**not refused**");
                continue;
            }
            if (res.status != UMBRA_SUCCESS) {
                printf("| %s | %s | **%s**: %s | |\n", name, conf_case_names[c],
                       umbra_status_to_string(res.status), res.message);
                ++over;
                continue;
            }
            over += cell(res.image, row->image[c], a, sizeof a);
            over += cell(res.point, row->point[c], b, sizeof b);
            over += res.out_of_range != 0 || res.lit_wrong != 0;
            printf("| %s | %s | %s | %s%s |\n", name, conf_case_names[c], a, b,
                   res.out_of_range || res.lit_wrong ? " **values out of range or lit points "
                                                       "shadowed**"
                                                     : "");
            fflush(stdout);
        }
        for (int unlit = 0; unlit < 2; ++unlit)
            conf_yardstick_release(&y[unlit]);
        conf_scene_release(&s);
    }
    umbra_context_release(ctx);
    if (failed)
        return 2;
    printf("\n%d measure(s) over their bound.\n", over);
    return over ? 1 : 0;
}
