// SPDX-License-Identifier: Apache-2.0
/* no_images.c: an application on a umbra_io built with UMBRA_IO_IMAGES=OFF (tests/consumer/
 * check.sh builds both). Volumes still load; the image functions refuse with
 * UMBRA_ERROR_UNSUPPORTED, a message naming the file and the option, and cleared outputs; the
 * context stays usable after them.
 * Usage: no_images DIR   (a writable directory for the little NRRD it loads) */
#include <stdio.h>
#include <string.h>

#include <umbra/io.h>
#include <umbra/umbra.h>

static int fail(const char *what, umbra_context ctx)
{
    fprintf(stderr, "no_images: %s (%s)\n", what, ctx ? umbra_context_last_message(ctx) : "");
    return 1;
}

/* A 2 x 3 x 4 uchar NRRD with its data attached, the voxel values 0..23. */
static int write_nrrd(const char *path)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    fputs("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n\n", f);
    for (int i = 0; i < 24; ++i)
        fputc(i, f);
    return fclose(f);
}

static int loads_volume(umbra_context ctx, const char *path)
{
    umbra_volume v = NULL;
    umbra_volume_info info;
    int ok = umbra_volume_load_nrrd(ctx, path, &v) == UMBRA_SUCCESS &&
             umbra_volume_get_info(v, &info) == UMBRA_SUCCESS && info.dims[0] == 2 &&
             info.dims[1] == 3 && info.dims[2] == 4 && info.value_max == 23.0f;
    umbra_volume_release(v);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc != 2)
        return fail("usage: no_images DIR", NULL);
    char nrrd[4096];
    snprintf(nrrd, sizeof nrrd, "%s/cube.nrrd", argv[1]);
    if (write_nrrd(nrrd) != 0)
        return fail("cannot write the test NRRD", NULL);
    umbra_context ctx = NULL;
    if (umbra_context_create(NULL, &ctx) != UMBRA_SUCCESS)
        return fail("no context", NULL);
    int bad = 0;
    if (!loads_volume(ctx, nrrd))
        bad = fail("the NRRD did not load as written", ctx);

    const float px[4] = {0.25f, 0.5f, 0.75f, 1.0f};
    if (umbra_image_write(ctx, "picture.png", 1, 1, px) != UMBRA_ERROR_UNSUPPORTED)
        bad = fail("umbra_image_write did not refuse", ctx);
    const char *msg = umbra_context_last_message(ctx);
    if (!strstr(msg, "picture.png") || !strstr(msg, "UMBRA_IO_IMAGES=OFF"))
        bad = fail("umbra_image_write's message names neither the file nor the option", ctx);

    uint32_t w = 7, h = 7;
    float *rgba = (float *)px;
    if (umbra_image_read(ctx, "picture.exr", &w, &h, &rgba) != UMBRA_ERROR_UNSUPPORTED ||
        w != 0 || h != 0 || rgba != NULL)
        bad = fail("umbra_image_read did not refuse with its outputs cleared", ctx);
    if (!strstr(umbra_context_last_message(ctx), "picture.exr"))
        bad = fail("umbra_image_read's message does not name the file", ctx);

    if (!loads_volume(ctx, nrrd)) /* the context is still usable */
        bad = fail("no volume loads after the refusals", ctx);
    umbra_context_release(ctx);
    if (!bad)
        printf("no_images: volumes load, images are refused (UMBRA_ERROR_UNSUPPORTED)\n");
    return bad;
}
