// SPDX-License-Identifier: Apache-2.0
/* example_threshold: the walnut scene of examples/walnut_scene.h (Figure 3 of the CSSM paper)
 * with the opacity-threshold shadow map: threshold 0.5 and one tap, the paper's "traditional
 * shadow map" of Figure 3(a). Writes threshold.png to the working directory and prints the shadow
 * build time, render time and shadow memory.
 * Usage: example_threshold [volume.nhdr [walnut.tf]]
 * (default: $UMBRA_DATA_DIR/walnut.nhdr, else the built-in "spheres" scene) */
#include "walnut_scene.h"

int main(int argc, char **argv)
{
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_THRESHOLD;
    shadow.map.size = WALNUT_MAP_SIZE;
    shadow.threshold.threshold = 0.5f;
    shadow.threshold.taps = 1;
    return walnut_example_run(argc, argv, &shadow, "threshold.png");
}
