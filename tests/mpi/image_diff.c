// SPDX-License-Identifier: Apache-2.0
/* tests/mpi/image_diff.c: umbra_image_diff A B BOUND prints the largest difference of two images
 * of the same size (linear premultiplied RGBA, as umbra_image_read gives them) and exits 0 when
 * it is at most BOUND, 1 when it is larger or the sizes differ, 2 when a file cannot be read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "umbra/io.h"

int main(int argc, char **argv)
{
    umbra_context ctx = NULL;
    uint32_t w[2] = {0, 0}, h[2] = {0, 0};
    float *px[2] = {NULL, NULL};
    int rc = 2;
    if (argc != 4) {
        fprintf(stderr, "usage: umbra_image_diff A B BOUND\n");
        return 2;
    }
    const double bound = atof(argv[3]);
    /* Images need no device; a context records the errors. */
    if (umbra_context_create(NULL, &ctx) != UMBRA_SUCCESS)
        return 2;
    for (int i = 0; i < 2; ++i)
        if (umbra_image_read(ctx, argv[1 + i], &w[i], &h[i], &px[i]) != UMBRA_SUCCESS) {
            fprintf(stderr, "umbra_image_diff: %s\n", umbra_context_last_message(ctx));
            goto done;
        }
    rc = 1;
    if (w[0] != w[1] || h[0] != h[1]) {
        fprintf(stderr, "umbra_image_diff: %ux%u against %ux%u\n", w[0], h[0], w[1], h[1]);
        goto done;
    }
    double worst = 0.0;
    for (size_t i = 0; i < (size_t)w[0] * h[0] * 4; ++i) {
        double d = fabs((double)px[0][i] - px[1][i]);
        worst = d > worst || d != d ? d : worst;
    }
    printf("max difference %.3g (bound %.3g)\n", worst, bound);
    rc = worst <= bound ? 0 : 1;
done:
    free(px[0]);
    free(px[1]);
    umbra_context_release(ctx);
    return rc;
}
