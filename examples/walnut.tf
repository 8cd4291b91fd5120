# SPDX-License-Identifier: Apache-2.0
# Walnut CT (examples/walnut_scene.h): shell and kernel both translucent, in different colours,
# so that light passing through them casts coloured partial shadows (CSSM paper, Figure 3).
# Values are normalised to the scan's range: air and noise lie below 0.2, the kernel around 0.29,
# the shell around 0.40. Format: "value r g b a", alpha per voxel step.
resolution 256
0.00   0    0    0    0
0.20   0.95 0.85 0.50 0
0.24   0.95 0.85 0.50 0.03    # kernel: pale yellow, light
0.31   0.95 0.85 0.50 0.03
0.335  0.80 0.40 0.15 0.02
0.37   0.80 0.36 0.12 0.07    # shell: reddish brown, denser
0.50   0.80 0.36 0.12 0.07
0.60   0.90 0.90 0.90 0.3     # rare dense specks
1.00   0.90 0.90 0.90 0.3
