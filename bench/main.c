// SPDX-License-Identifier: Apache-2.0
/* bench/main.c: umbra-bench, the benchmark driver. `umbra-bench <subcommand> [options]` runs one
 * benchmark; each subcommand lives in its own file (see bench/bench.h for how to add one) and is
 * listed in the table below. Results go to stdout as CSV, commentary to stderr. */
#include <stdio.h>
#include <string.h>

#include "bench.h"

static const bench_command commands[] = {
    {"raycast", bench_raycast,
     "view-space ray casting of the bonsai, no shadows: umbra vs the native-C twin (and VTK)"},
    {"convolution", bench_convolution,
     "convolution shadows (paper's Table 1): slice distance x sub-samples x pre-integration"},
    {"accuracy", bench_accuracy,
     "every shadow technique vs the exact reference: error, time, memory (CSV, plots)"},
    {"interactive", bench_interactive,
     "frames of an interactive session: camera orbit, light orbit, opacity edits, per technique"},
    {"builds", bench_builds,
     "light-space map builds at equal map size: threshold, CSSM, deep; grey and coloured"},
    {"progress", bench_progress,
     "how often a long reference render reports progress and how soon a cancel takes effect"},
    {"readme", bench_readme,
     "rewrite the measured blocks of README.md and docs/ from the accuracy results"},
    {"conformance", bench_conformance,
     "every technique's errors in the conformance suite's cases beside the bounds it asserts"},
    {"features", bench_features,
     "the cost of clipping, projection modes, channels, label maps and volume updates (#31)"},
    {"scale", bench_scale,
     "time to first frame, frame times and memory against volume size (128^3 .. 1024^3 and up)"},
    {"distributed", bench_distributed,
     "umbra-render-mpi on 1-8 ranks: volume bytes, bytes sent and stage times per rank"},
};

static void usage(FILE *f)
{
    fprintf(f, "usage: umbra-bench <subcommand> [options]\n"
               "       umbra-bench <subcommand> --help\n"
               "       umbra-bench --version\n\nsubcommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        fprintf(f, "  %-12s %s\n", commands[i].name, commands[i].help);
    fprintf(f, "\nEnvironment: UMBRA_DEVICE picks the OpenCL device, UMBRA_SAMPLER its volume "
               "sampler\n(buffer or image; default: the library's, the buffer), "
               "UMBRA_DATA_DIR where the\nvolumes are, OMP_NUM_THREADS the native-C threads.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("umbra-bench %s (library %s)\n", UMBRA_VERSION_STRING, umbra_version());
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "umbra-bench: unknown subcommand '%s'\n\n", argv[1]);
    usage(stderr);
    return 2;
}
