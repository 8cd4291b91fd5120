// SPDX-License-Identifier: Apache-2.0
/* tests/setting.h: a technique setting written as text, "key=value;key=value", as the bench's
 * sweep (host/renderer_internal.h, umbra__setting) and the conformance suite's rows
 * (tests/conformance.h) write them: each key is one of the technique's parameters (its key or
 * alias, set through umbra_shadow_desc_set_param, which checks the range; the parameter's
 * zero_name, "auto", stands for 0), or umbra_render_desc's `preintegrated`. Shared by
 * umbra-bench and the tests; public API only. */
#ifndef UMBRA_TESTS_SETTING_H
#define UMBRA_TESTS_SETTING_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "umbra/umbra.h"

/* Sets the parameters of `params` for desc->technique in desc (and *preintegrated, if the
 * setting names it). Returns 0, or -1 with the reason in msg (msg_size bytes). */
static inline int setting_apply(umbra_shadow_desc *desc, int *preintegrated, const char *params,
                                char *msg, size_t msg_size)
{
    const umbra_technique_info *t = umbra_technique_find_id(desc->technique);
    char buf[512];
    if (!t || strlen(params) >= sizeof buf) {
        snprintf(msg, msg_size, "setting '%s': no such technique, or too long", params);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", params);
    for (char *kv = buf; *kv;) {
        char *next = kv + strcspn(kv, ";");
        if (*next)
            *next++ = '\0';
        char *eq = strchr(kv, '=');
        if (!eq) {
            snprintf(msg, msg_size, "%s setting '%s': '%s' is not key=value", t->name, params, kv);
            return -1;
        }
        *eq = '\0';
        const char *key = kv, *text = eq + 1;
        char *end;
        double v = strtod(text, &end);
        const int number = end != text && *end == '\0';
        if (strcmp(key, "preintegrated") == 0 && number) {
            if (preintegrated)
                *preintegrated = v != 0.0;
        } else {
            const umbra_param_info *p = umbra_technique_param_find(t, key);
            if (p && p->zero_name && strcmp(text, p->zero_name) == 0)
                v = 0.0;
            else if (!number)
                v = NAN; /* refused below, with the message naming it */
            if (umbra_shadow_desc_set_param(desc, t->name, key, v, msg, msg_size) !=
                UMBRA_SUCCESS)
                return -1;
        }
        kv = next;
    }
    return 0;
}

#endif
