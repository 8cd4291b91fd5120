# SPDX-License-Identifier: Apache-2.0
# Foot CT: skin and soft tissue faint and reddish, bone opaque white. The bones' shadows fall
# through the translucent tissue onto the ground.
# Format (host/tf_file.c): "value r g b a", alpha per voxel step.
resolution 256
0.00  0    0    0    0
0.10  0.90 0.55 0.45 0
0.14  0.90 0.55 0.45 0.008   # soft tissue
0.30  0.90 0.55 0.45 0.008
0.38  0.95 0.92 0.85 0.0
0.45  0.95 0.92 0.85 0.4     # bone
1.00  0.95 0.92 0.85 0.6
