// SPDX-License-Identifier: Apache-2.0
/* umbra/techniques/list.h: the technique registry's list, one row per shadow technique.
 *
 *   X(name, NAME, id, member)
 *
 * name    the technique's name: umbra-render --technique, Python's technique=, the viewer's
 *         panel (umbra_technique_find); its host descriptor is umbra__technique_<name>
 *         (host/techniques/<name>.c), which holds everything else about it: its parameters with
 *         their defaults, ranges and docs, its kernels, what rebuilds it (umbra/registry.h)
 * NAME    its constant, UMBRA_SHADOW_<NAME> of umbra_shadow_technique
 * id      that constant's value; never reused
 * member  its parameters' member of umbra_shadow_desc, a struct its header
 *         umbra/techniques/<name>.h defines; empty for a technique without parameters
 *
 * Everything that lists techniques (the enum, umbra_shadow_desc, the library's descriptor
 * table, the CLI's options, the Python keywords, the bench's sweep, the conformance suite) is
 * made from this list and the descriptors. Rows are only ever appended: umbra_shadow_desc grows
 * at its end, so a caller built against an earlier list passes its smaller struct_size and the
 * techniques it does not know take their defaults. */
#ifndef UMBRA_TECHNIQUES_LIST_H
#define UMBRA_TECHNIQUES_LIST_H

#include "umbra/techniques/convolution.h"
#include "umbra/techniques/cssm.h"
#include "umbra/techniques/deep.h"
#include "umbra/techniques/moments.h"
#include "umbra/techniques/reference.h"
#include "umbra/techniques/threshold.h"

#define UMBRA_TECHNIQUE_LIST(X)                                                                \
    X(none, NONE, 0, /* no parameters */)                                                     \
    X(reference, REFERENCE, 1, umbra_reference_desc reference;)                                \
    X(threshold, THRESHOLD, 2, umbra_threshold_desc threshold;)                                \
    X(cssm, CSSM, 4, umbra_cssm_desc cssm;)                                                    \
    X(deep, DEEP, 3, umbra_deep_desc deep;)                                                    \
    X(convolution, CONVOLUTION, 5, umbra_convolution_desc convolution;)                        \
    X(moments, MOMENTS, 6, umbra_moments_desc moments;)

#endif
