// SPDX-License-Identifier: Apache-2.0
/* tests/nifti_test.h: writing NIfTI test files with nifticlib, in either version.
 *
 * nifticlib 3.0.1 cannot write a single-file NIfTI-2 itself: nifti_set_filenames makes every
 * ".nii" NIfTI-1, and with nifti_type NIFTI_FTYPE_NIFTI2_1 nifti_image_write treats the file as a
 * header/image pair whose image, opened second under the same name, truncates the header (a
 * 2 x 2 x 2 uint8 file came out as its 8 voxel bytes). So NIfTI-2 files are written here from
 * nifticlib's own header conversion (nifti_convert_nim2n2hdr), its magic, four zero extension
 * bytes and the voxels. */
#ifndef UMBRA_TEST_NIFTI_TEST_H
#define UMBRA_TEST_NIFTI_TEST_H

#include <string.h>

#include <nifti2_io.h>

/* Writes nim (its nifti_type says the version: NIFTI_FTYPE_NIFTI2_1 for NIfTI-2, else NIfTI-1)
 * to path (.nii, or gzip-compressed .nii.gz), then frees it. */
static inline void test_nifti_write(nifti_image *nim, const char *path)
{
    int type = nim->nifti_type;
    nifti_2_header h;
    unsigned char ext[4] = {0, 0, 0, 0};
    znzFile z;
    assert_int_equal(nifti_set_filenames(nim, path, 0, 1), 0);
    if (type != NIFTI_FTYPE_NIFTI2_1) {
        nifti_image_write(nim);
        nifti_image_free(nim);
        return;
    }
    nim->nifti_type = type;
    assert_int_equal(nifti_convert_nim2n2hdr(nim, &h), 0);
    memcpy(h.magic, "n+2\0\r\n\032\n", 8);
    h.vox_offset = (int64_t)sizeof h + 4;
    z = znzopen(path, "wb", nifti_is_gzfile(path));
    assert_false(znz_isnull(z));
    assert_int_equal(znzwrite(&h, 1, sizeof h, z), sizeof h);
    assert_int_equal(znzwrite(ext, 1, 4, z), 4);
    assert_int_equal(znzwrite(nim->data, 1, nim->nvox * (size_t)nim->nbyper, z),
                     nim->nvox * (size_t)nim->nbyper);
    Xznzclose(&z);
    nifti_image_free(nim);
}

#endif
