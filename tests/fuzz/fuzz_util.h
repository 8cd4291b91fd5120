// SPDX-License-Identifier: Apache-2.0
/* tests/fuzz/fuzz_util.h: what the libFuzzer harnesses share. The loaders take paths, so each
 * input is written to a file in a per-process directory under $TMPDIR and loaded from there; the
 * context (PoCL) is created once per process and reused, as an application would. */
#ifndef UMBRA_FUZZ_UTIL_H
#define UMBRA_FUZZ_UTIL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "umbra/io.h"

/* "<dir>/<name>" in this process's scratch directory (created on first use). */
static const char *fuzz_path(const char *name)
{
    static char dir[512];
    static char buf[1024];
    if (!dir[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/umbra-fuzz-XXXXXX", tmp && *tmp ? tmp : "/tmp");
        if (!mkdtemp(dir))
            abort();
    }
    snprintf(buf, sizeof buf, "%s/%s", dir, name);
    return buf;
}

static void fuzz_write(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        abort();
}

/* One context for the whole run; every failure must leave it usable, which the next input
 * checks by using it again. */
static umbra_context fuzz_context(void)
{
    static umbra_context ctx;
    if (!ctx) {
        umbra_context_desc desc;
        umbra_context_desc_init(&desc);
        if (umbra_context_create(&desc, &ctx) != UMBRA_SUCCESS)
            abort();
    }
    /* A failed load leaves a sticky error: take it, so each input starts clean. */
    umbra_context_take_error(ctx, NULL);
    return ctx;
}

#endif
