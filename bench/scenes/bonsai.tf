# SPDX-License-Identifier: Apache-2.0
# Bonsai CT: thin green foliage, a brown trunk, an opaque pot. The foliage is sparse and
# translucent, the kind of structure that needs partial (not binary) shadows.
# Format (host/tf_file.c): "value r g b a", alpha per voxel step.
resolution 256
0.00  0    0    0    0
0.18  0.25 0.60 0.15 0
0.22  0.25 0.60 0.15 0.06    # foliage
0.38  0.30 0.55 0.15 0.06
0.42  0.55 0.35 0.15 0.0
0.46  0.55 0.35 0.15 0.25    # trunk
0.68  0.55 0.35 0.15 0.25
0.72  0.80 0.45 0.30 0.5     # pot
1.00  0.80 0.45 0.30 0.5
