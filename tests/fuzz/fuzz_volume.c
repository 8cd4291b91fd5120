// SPDX-License-Identifier: Apache-2.0
/* tests/fuzz/fuzz_volume.c: libFuzzer harness for the volume readers through the public API. The
 * first byte picks the reader: 0 an attached NRRD (.nrrd), 1 a detached NRRD (.nhdr) whose data
 * file "data.raw" holds what follows the first "@@" in the input, 2 a Voreen .dat over "data.raw"
 * the same way, 3 a headerless raw file with dims, type and header bytes taken from the next four
 * bytes, 4 a MetaImage .mha, 5 a MetaImage .mhd over "data.raw" as for 1 and 2 (its ElementDataFile
 * must say data.raw to reach it), 6 a NIfTI-1/2 .nii, 7 the same bytes gzip-compressed as a
 * .nii.gz, 8 a DICOM file (.dcm: umbra's structure walk, then GDCM's decoders), 9 a TIFF (.tif:
 * libtiff, OME-XML through expat). Everything must end in a volume or a status with a message,
 * never a crash, leak or sanitizer report, and the context must stay usable (the next input uses
 * it).
 *
 * Speed: the loaders refuse any size the file cannot hold, so with libFuzzer's -max_len 4096 raw
 * volumes stay small; only ZRL can legitimately expand 4 kB into 64 MB of voxels, so inputs that
 * name that encoding and declare more than 2^20 voxels are skipped (they would make each run take
 * a second without reaching new code). */
#define _POSIX_C_SOURCE 200809L

#include <ctype.h>

#include <zlib.h>

#include "fuzz_util.h"

/* The product of the numbers after the first "sizes:" in text (0 if none). */
static double declared_voxels(const char *text)
{
    const char *s = strstr(text, "sizes:");
    double product = 1.0;
    int any = 0;
    if (!s)
        return 0.0;
    for (s += 6; *s && *s != '\n';) {
        if (isdigit((unsigned char)*s)) {
            product *= strtod(s, (char **)&s);
            any = 1;
        } else {
            ++s;
        }
    }
    return any ? product : 0.0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const names[10] = {"input.nrrd", "input.nhdr", "input.dat", NULL,
                                          "input.mha",  "input.mhd",  "input.nii", "input.nii.gz",
                                          "input.dcm",  "input.tif"};
    if (size < 1)
        return 0;
    umbra_context ctx = fuzz_context();
    umbra_volume vol = NULL;
    umbra_status st;
    int mode = data[0] % 10;
    ++data;
    --size;
    if (mode != 3) {
        char *text = malloc(size + 1);
        if (!text)
            return 0;
        memcpy(text, data, size);
        text[size] = '\0';
        for (char *p = text; *p; ++p)
            *p = (char)tolower((unsigned char)*p);
        int skip = strstr(text, "zrl") && declared_voxels(text) > 1048576.0;
        free(text);
        if (skip)
            return 0;
        const uint8_t *split = NULL;
        for (size_t i = 0; mode > 0 && mode != 4 && mode < 6 && i + 1 < size; ++i)
            if (data[i] == '@' && data[i + 1] == '@') {
                split = data + i;
                break;
            }
        size_t head = split ? (size_t)(split - data) : size;
        if (mode == 7) {
            gzFile gz = gzopen(fuzz_path(names[mode]), "wb");
            if (!gz || (size > 0 && gzwrite(gz, data, (unsigned)size) != (int)size))
                abort();
            gzclose(gz);
        } else {
            fuzz_write(fuzz_path(names[mode]), data, head);
        }
        if (split)
            fuzz_write(fuzz_path("data.raw"), split + 2, size - head - 2);
        else
            unlink(fuzz_path("data.raw"));
        st = umbra_volume_load(ctx, fuzz_path(names[mode]), &vol);
    } else {
        if (size < 4)
            return 0;
        umbra_raw_desc desc;
        umbra_raw_desc_init(&desc);
        desc.dims[0] = 1u + data[0] % 16;
        desc.dims[1] = 1u + data[1] % 16;
        desc.dims[2] = 1u + data[2] % 16;
        desc.type = (umbra_scalar_type)(data[3] % 5); /* 4: not a type, must be refused */
        desc.big_endian = (data[3] >> 3) & 1;
        desc.header_bytes = (data[3] >> 4) & 7;
        fuzz_write(fuzz_path("input.raw"), data + 4, size - 4);
        st = umbra_volume_load_raw(ctx, fuzz_path("input.raw"), &desc, &vol);
    }
    if ((st == UMBRA_SUCCESS) != (vol != NULL))
        abort();
    if (st != UMBRA_SUCCESS && umbra_context_last_message(ctx)[0] == '\0')
        abort();
    if (vol) {
        umbra_volume_info info;
        if (umbra_volume_get_info(vol, &info) != UMBRA_SUCCESS || info.dims[0] == 0 ||
            !(info.value_min <= info.value_max))
            abort();
    }
    umbra_volume_release(vol);
    return 0;
}
