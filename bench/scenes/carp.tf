# SPDX-License-Identifier: Apache-2.0
# Carp CT (carp_half): translucent flesh, opaque bright bone, so that the skeleton casts soft
# partial shadows through the body (convolution-shadow paper, Figure 1). Values are normalised to
# the scan's range: water and noise below 0.28, flesh around 0.35-0.40, bone above 0.45.
# Format (host/tf_file.c): "value r g b a", alpha per voxel step.
resolution 256
0.00  0    0    0    0
0.28  0.85 0.55 0.40 0
0.33  0.85 0.55 0.40 0.03    # flesh
0.42  0.85 0.55 0.40 0.03
0.47  0.95 0.93 0.85 0.35    # bone
1.00  0.95 0.93 0.85 0.6
