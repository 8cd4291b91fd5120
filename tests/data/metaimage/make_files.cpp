// SPDX-License-Identifier: Apache-2.0
/* tests/data/metaimage/make_files.cpp: how the itk_* files beside it were made, with ITK's own
 * MetaIO writer (Debian 12, libinsighttoolkit5-dev 5.2.1), so that test_metaimage checks umbra's
 * reader against files it did not write. Not built by CMake (umbra does not depend on ITK):
 *     g++ -I/usr/include/ITK-5.2 make_files.cpp -lITKMetaIO-5.2 -o make_files && ./make_files
 * Voxel i (x fastest) holds: short -1000 + 37 i, float 0.25 i - 3, uchar 7 i mod 256. */
#include <metaImage.h>

int main()
{
    int dims[3] = {5, 4, 3};
    double spacing[3] = {0.7, 1.3, 2.1};
    double offset[3] = {12.5, -30, 4};
    double matrix[9] = {0, 0, 1, 1, 0, 0, 0, 1, 0}; /* index axis a's direction: values 3a..3a+2 */

    MetaImage s(3, dims, spacing, MET_SHORT, 1, nullptr);
    for (int i = 0; i < 60; ++i) {
        s.ElementData(i, -1000 + 37 * i);
    }
    s.Offset(offset);
    s.TransformMatrix(matrix);
    s.CompressedData(true);
    s.Write("itk_short_z.mha");
    s.CompressedData(false);
    s.Write("itk_short.mhd", "itk_short.raw");

    MetaImage f(3, dims, spacing, MET_FLOAT, 1, nullptr);
    for (int i = 0; i < 60; ++i) {
        f.ElementData(i, 0.25 * i - 3);
    }
    f.CompressedData(true);
    f.Write("itk_float_z.mhd", "itk_float_z.zraw");

    MetaImage u(3, dims, spacing, MET_UCHAR, 1, nullptr);
    for (int i = 0; i < 60; ++i) {
        u.ElementData(i, (i * 7) % 256);
    }
    u.Write("itk_u8.mha");
    return 0;
}
