#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""tests/viewer/make_nut.py OUT.nhdr: writes a walnut-like CT volume (NRRD header OUT.nhdr and raw
uint16 data beside it), so that the viewer's test sees what the walnut's would without the shared
data sets: 128 x 96 x 114 voxels like the walnut, values normalised like examples/walnut.tf
expects (air below 0.2, a folded kernel around 0.29, a wrinkled shell around 0.40, a few dense
specks up to 1). Deterministic: no random numbers."""
import os
import sys

import numpy as np


def main():
    out = sys.argv[1]
    nx, ny, nz = 128, 96, 114
    z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    # Coordinates in [-1, 1] of an ellipsoid filling most of the box.
    u = (x + 0.5 - nx / 2) / (0.44 * nx)
    v = (y + 0.5 - ny / 2) / (0.42 * ny)
    w = (z + 0.5 - nz / 2) / (0.42 * nz)
    r = np.sqrt(u * u + v * v + w * w)
    theta = np.arctan2(v, u)
    phi = np.arccos(np.clip(w / np.maximum(r, 1e-6), -1, 1))
    surface = 1.0 + 0.05 * np.sin(7 * theta) * np.sin(5 * phi)  # the wrinkles of the shell
    value = 0.08 + 0.04 * np.sin(0.9 * x) * np.sin(1.1 * y) * np.sin(0.7 * z)  # air, "noise"
    shell = np.abs(r - 0.9 * surface) < 0.06
    folds = np.sin(9 * u) * np.sin(7 * v) + 0.6 * np.sin(11 * w)  # the kernel's lobes
    kernel = (r < 0.75 * surface) & (folds > 0.15) & (np.abs(u) > 0.06)  # split in two halves
    value = np.where(kernel, 0.29, value)
    value = np.where(shell, 0.40, value)
    specks = (np.abs(r - 0.5) < 0.03) & (np.sin(13 * theta) * np.sin(11 * phi) > 0.95)
    value = np.where(specks, 1.0, value)
    value[0, 0, 0] = 1.0  # the normalised range reaches 1 even without specks
    data = np.round(value * 4000).astype("<u2")
    raw = os.path.splitext(out)[0] + ".raw"
    data.tofile(raw)
    with open(out, "w") as f:
        f.write("NRRD0004\n# walnut-like test volume (tests/viewer/make_nut.py)\n"
                "type: uint16\ndimension: 3\nsizes: %d %d %d\nspacings: 1 1 1\n"
                "encoding: raw\nendian: little\ndata file: %s\n" % (nx, ny, nz, os.path.basename(raw)))


if __name__ == "__main__":
    main()
