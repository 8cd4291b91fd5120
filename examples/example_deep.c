// SPDX-License-Identifier: Apache-2.0
/* examples/example_deep.c: the walnut scene (examples/walnut_scene.h) with deep shadow maps
 * (Hadwiger et al. 2006): a 1024^2 map compressed within epsilon = 0.02 with the pre-compressed
 * segment table (deep.png), and the same map with a fixed budget of three nodes per texel -- the
 * setting the CSSM paper compares against, four values per node, twelve per texel
 * (deep_3nodes.png). Prints each one's build time, render time and shadow memory.
 *
 * Usage: example_deep [volume.nhdr [transfer_function.tf]] */
#include "walnut_scene.h"

int main(int argc, char **argv)
{
    umbra_shadow_desc shadow;
    umbra_shadow_desc_init(&shadow);
    shadow.technique = UMBRA_SHADOW_DEEP;
    shadow.map.size = WALNUT_MAP_SIZE;
    shadow.deep.epsilon = 0.02f;
    shadow.deep.lookup_table = 1;
    printf("== deep shadow map, epsilon %.2f, unbounded nodes\n", (double)shadow.deep.epsilon);
    int rc = walnut_example_run(argc, argv, &shadow, "deep.png");
    if (rc != 0)
        return rc;
    shadow.deep.max_nodes = 3;
    printf("== deep shadow map, 3 nodes per texel (12 values)\n");
    return walnut_example_run(argc, argv, &shadow, "deep_3nodes.png");
}
