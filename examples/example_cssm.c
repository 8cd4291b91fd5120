// SPDX-License-Identifier: Apache-2.0
/* example_cssm: the walnut scene of examples/walnut_scene.h (Figure 3 of the CSSM paper) with the
 * colored stochastic shadow map, 13 taps, as in the paper's Figure 3(c). Writes cssm.png to the
 * working directory and prints the shadow build time, render time and shadow memory.
 * Usage: example_cssm [volume.nhdr [walnut.tf]]
 * (default: $UMBRA_DATA_DIR/walnut.nhdr, else the built-in "spheres" scene) */
#include "walnut_scene.h"

int main(int argc, char **argv)
{
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_CSSM;
    shadow.map.size = WALNUT_MAP_SIZE;
    shadow.cssm.taps = 13;
    shadow.cssm.seed = 1;
    return walnut_example_run(argc, argv, &shadow, "cssm.png");
}
