// SPDX-License-Identifier: Apache-2.0
/* tests/fuzz/fuzz_tf_file.c: libFuzzer harness for the transfer-function text format
 * (umbra_transfer_function_load, io/tf_file.c) and, for inputs that start with '[' or '{',
 * ParaView JSON presets (written as input.json: io/paraview.c, cJSON): any bytes must give a
 * table or a status with a message, never a crash, hang, leak or sanitizer report. */
#define _POSIX_C_SOURCE 200809L

#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    umbra_context ctx = fuzz_context();
    const char *path = fuzz_path(size > 0 && (data[0] == '[' || data[0] == '{') ? "input.json"
                                                                               : "input.tf");
    umbra_transfer_function tf = NULL;
    fuzz_write(path, data, size);
    umbra_status st = umbra_transfer_function_load(ctx, path, &tf);
    if ((st == UMBRA_SUCCESS) != (tf != NULL))
        abort();
    if (st != UMBRA_SUCCESS && umbra_context_last_message(ctx)[0] == '\0')
        abort(); /* every failure says why */
    if (tf) {
        uint32_t n = umbra_transfer_function_size(tf);
        const float *rgba = umbra_transfer_function_data(tf);
        if (n < 2 || n > 65536 || !rgba)
            abort();
        for (uint32_t i = 0; i < 4 * n; ++i)
            if (!(rgba[i] >= 0.0f && rgba[i] <= 1.0f))
                abort(); /* the format only allows [0,1], so the table must stay there */
    }
    umbra_transfer_function_release(tf);
    return 0;
}
