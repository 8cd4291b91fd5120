// SPDX-License-Identifier: Apache-2.0
/* tests/fuzz/fuzz_scene_file.c: libFuzzer harness for the bench's scene files
 * (bench/scene_file.c, scene_parse_text): any text must parse or give a message "path:line: ...",
 * never a crash or sanitizer report. Parsing opens no file (hash_files 0). */
#define _POSIX_C_SOURCE 200809L

#include <stdlib.h>
#include <string.h>

#include "scene_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static scene_spec spec;
    char err[512];
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    err[0] = '\0';
    int rc = scene_parse_text(text, "/fuzz/scenes/fuzz.scene", "/fuzz/data", 0, &spec, err,
                              sizeof err);
    if (rc != 0 && (rc != -1 || err[0] == '\0'))
        abort(); /* a refusal always says why */
    if (rc == 0 && memchr(spec.volume, '\0', sizeof spec.volume) == NULL)
        abort();
    free(text);
    return 0;
}
