# SPDX-License-Identifier: Apache-2.0
# CT bone preset in Hounsfield units (HU): air, fat and soft tissue transparent; contrast-filled
# vessels and cancellous bone faint red; cortical bone and metal near-white and dense.
# "range" makes the point values data values: use it on a volume stored in HU (the table is
# resampled onto each volume's own value range; values beyond -1024..3071 take the end points).
# Format: "value r g b a", alpha per voxel step (README, "Transfer-function files").
range -1024 3071
resolution 1024
-1024  0    0    0    0
 150   0.75 0.20 0.15 0
 250   0.80 0.30 0.20 0.03    # contrast-filled vessels, cancellous bone
 500   0.95 0.80 0.65 0.15
1200   1.00 0.96 0.90 0.45    # cortical bone
3071   1.00 1.00 1.00 0.80    # metal (a stent, implants)
