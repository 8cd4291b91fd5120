// SPDX-License-Identifier: Apache-2.0
/* example_reference: the walnut scene of examples/walnut_scene.h (Figure 3 of the CSSM paper)
 * with the exact reference shadows (a shadow ray marched from every sample), the image the
 * shadow-map techniques are compared with. Writes reference.png to the working directory and
 * prints the render time.
 * Usage: example_reference [volume.nhdr [walnut.tf]]
 * (default: $UMBRA_DATA_DIR/walnut.nhdr, else the built-in "spheres" scene) */
#include "walnut_scene.h"

int main(int argc, char **argv)
{
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_REFERENCE;
    return walnut_example_run(argc, argv, &shadow, "reference.png");
}
