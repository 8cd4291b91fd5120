// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/techniques_panel.h: the shadow techniques and their parameters as a table,
 * the one thing umbra-view's technique panel (panel.cpp) walks: each technique's parameters with
 * their type, valid range, default and a line of documentation, and get/set of a parameter of
 * umbra_shadow_desc. The table is built from the current public API in techniques_panel.c; the
 * library's technique registry will provide the same by name, and then replaces that one file.
 * Nothing else in the viewer names a technique or a parameter. */
#ifndef UMBRA_VIEW_TECHNIQUES_PANEL_H
#define UMBRA_VIEW_TECHNIQUES_PANEL_H

#include <stdint.h>

#include "umbra/umbra.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum view_param_kind {
    VIEW_PARAM_FLOAT = 0, /* float field */
    VIEW_PARAM_UINT = 1,  /* uint32_t field */
    VIEW_PARAM_BOOL = 2   /* int field, 0 or 1 */
} view_param_kind;

typedef struct view_param {
    const char *name;       /* the umbra_shadow_desc field, e.g. "map_size" */
    view_param_kind kind;
    double min, max;        /* valid range of a non-zero value (see zero) */
    const char *zero;       /* non-NULL: 0 is valid too and means this ("auto"), outside [min,max] */
    double nonzero;         /* the value a control takes when it leaves 0 (with zero) */
    const uint32_t *choices;/* non-NULL: the only valid values (n_choices of them) */
    unsigned n_choices;
    int logarithmic;        /* a range over orders of magnitude: a logarithmic slider */
    const char *doc;        /* one line for a tooltip */
} view_param;

/* The techniques, in the order a panel lists them. */
unsigned view_technique_count(void);
umbra_shadow_technique view_technique_at(unsigned i);

/* The parameters technique t reads; *count receives how many (0 for an unknown t). */
const view_param *const *view_technique_params(umbra_shadow_technique t, unsigned *count);

/* The parameter's value in d, as a double; its value in umbra_shadow_desc_init's defaults. */
double view_param_get(const umbra_shadow_desc *d, const view_param *p);
double view_param_default(const view_param *p);
/* Stores v into d (rounded for whole numbers, clamped to what the field's type holds); the
 * renderer's umbra_renderer_set_shadow is what checks the range. */
void view_param_set(umbra_shadow_desc *d, const view_param *p, double v);

#ifdef __cplusplus
}
#endif
#endif
