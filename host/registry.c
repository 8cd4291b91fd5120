// SPDX-License-Identifier: Apache-2.0
/* host/registry.c: the technique registry. The descriptors (umbra__technique_<name>, one per
 * row of umbra/techniques/list.h, each in host/techniques/<name>.c) are gathered into one table,
 * which gives: the public introspection of umbra/registry.h, parameters read and set by name,
 * every default of umbra_shadow_desc_init, the range checks of umbra_renderer_set_shadow (one
 * message format for all), the technique names, and the rebuild key of each technique's shadow
 * structure. Nothing here names a technique. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer_internal.h"

#define UMBRA__TECHNIQUE_EXTERN(name, NAME, id, member)                                        \
    extern const umbra__technique umbra__technique_##name;
UMBRA_TECHNIQUE_LIST(UMBRA__TECHNIQUE_EXTERN)
#undef UMBRA__TECHNIQUE_EXTERN

#define UMBRA__TECHNIQUE_ENTRY(name, NAME, id, member) &umbra__technique_##name,
static const umbra__technique *const techniques[] = {UMBRA_TECHNIQUE_LIST(UMBRA__TECHNIQUE_ENTRY)};
#undef UMBRA__TECHNIQUE_ENTRY

#define TECHNIQUE_COUNT (sizeof techniques / sizeof techniques[0])

/* The descriptor whose public part is info (info is its first member). */
static const umbra__technique *of_info(const umbra_technique_info *info)
{
    for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
        if (&techniques[i]->info == info)
            return techniques[i];
    return NULL;
}

/* ---- introspection ------------------------------------------------------------------------- */

uint32_t umbra_technique_count(void)
{
    return (uint32_t)TECHNIQUE_COUNT;
}

const umbra_technique_info *umbra_technique_get(uint32_t index)
{
    return index < TECHNIQUE_COUNT ? &techniques[index]->info : NULL;
}

const umbra_technique_info *umbra_technique_find(const char *name)
{
    if (!name)
        return NULL;
    for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
        if (strcmp(techniques[i]->info.name, name) == 0)
            return &techniques[i]->info;
    return NULL;
}

const umbra_technique_info *umbra_technique_find_id(umbra_shadow_technique id)
{
    const umbra__technique *t = umbra__technique_by_id(id);
    return t ? &t->info : NULL;
}

const umbra__technique *umbra__technique_by_id(umbra_shadow_technique id)
{
    for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
        if (techniques[i]->info.id == id)
            return techniques[i];
    return NULL;
}

const umbra_param_info *umbra_technique_param_get(const umbra_technique_info *info,
                                                  uint32_t index)
{
    const umbra__technique *t = of_info(info);
    return t && index < t->info.param_count ? &t->params[index].info : NULL;
}

static const umbra__param *param_find(const umbra__technique *t, const char *name)
{
    for (uint32_t i = 0; t && name && i < t->info.param_count; ++i)
        if (strcmp(t->params[i].info.name, name) == 0 || strcmp(t->params[i].info.key, name) == 0 ||
            (t->params[i].info.alias && strcmp(t->params[i].info.alias, name) == 0))
            return &t->params[i];
    return NULL;
}

const umbra_param_info *umbra_technique_param_find(const umbra_technique_info *info,
                                                   const char *name)
{
    const umbra__param *p = param_find(of_info(info), name);
    return p ? &p->info : NULL;
}

const char *umbra_shadow_technique_name(umbra_shadow_technique id)
{
    const umbra__technique *t = umbra__technique_by_id(id);
    return t ? t->info.name : NULL;
}

umbra_status umbra_shadow_technique_parse(const char *name, umbra_shadow_technique *out)
{
    const umbra_technique_info *t = umbra_technique_find(name);
    if (!t || !out)
        return UMBRA_ERROR_INVALID_ARGUMENT;
    *out = t->id;
    return UMBRA_SUCCESS;
}

/* ---- values ---------------------------------------------------------------------------------- */

static double value_of(const umbra__param *p, const umbra_shadow_desc *d)
{
    const char *at = (const char *)d + p->offset;
    float f;
    uint32_t u;
    int b;
    switch (p->info.type) {
    case UMBRA_PARAM_FLOAT: memcpy(&f, at, sizeof f); return f;
    case UMBRA_PARAM_UINT: memcpy(&u, at, sizeof u); return u;
    default: memcpy(&b, at, sizeof b); return b;
    }
}

/* Stores a value already checked (a float, a whole number of 32 bits, or 0/1). */
static void store(const umbra__param *p, umbra_shadow_desc *d, double v)
{
    char *at = (char *)d + p->offset;
    float f = (float)v;
    uint32_t u = (uint32_t)v;
    int b = v != 0.0;
    switch (p->info.type) {
    case UMBRA_PARAM_FLOAT: memcpy(at, &f, sizeof f); break;
    case UMBRA_PARAM_UINT: memcpy(at, &u, sizeof u); break;
    default: memcpy(at, &b, sizeof b); break;
    }
}

/* Appends to buf (size n, holding a string) as snprintf would. */
static void append(char *buf, size_t n, const char *fmt, ...) UMBRA_PRINTF(3, 4);
static void append(char *buf, size_t n, const char *fmt, ...)
{
    size_t used = strlen(buf);
    if (used + 1 >= n)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + used, n - used, fmt, ap);
    va_end(ap);
}

/* Whether v (as the field stores it) lies in p's range or set, or is its zero. */
static int in_range(const umbra__param *p, double v)
{
    const umbra_param_info *i = &p->info;
    if (i->type == UMBRA_PARAM_BOOL)
        return 1; /* a flag: every int is "nonzero" or not */
    if ((i->flags & UMBRA_PARAM_ZERO) && v == 0.0)
        return 1;
    if (i->allowed) {
        for (uint32_t k = 0; k < i->allowed_count; ++k)
            if (v == i->allowed[k])
                return 1;
        return 0;
    }
    /* A float field is compared in float, as it is stored: (float)0.01 is its lower bound. */
    double lo = i->type == UMBRA_PARAM_FLOAT ? (double)(float)i->min : i->min;
    double hi = i->type == UMBRA_PARAM_FLOAT ? (double)(float)i->max : i->max;
    int above = (i->flags & UMBRA_PARAM_MIN_EXCLUSIVE) ? v > lo : v >= lo;
    int below = (i->flags & UMBRA_PARAM_MAX_EXCLUSIVE) ? v < hi : v <= hi;
    return above && below; /* NaN fails both */
}

/* A number as messages show it: whole numbers in full (4294967295, not 4.29497e+09), others as
 * %g (a float 0.3 as 0.3). */
static const char *num(double v, char buf[40])
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, 40, "%.0f", v);
    else
        snprintf(buf, 40, "%g", v);
    return buf;
}

/* "fn: cssm ray_block 4 must be 0 (the map's own) or lie in [1, 3]" into buf; why replaces the
 * range's wording. */
static void describe_refusal(const umbra__technique *t, const umbra__param *p, double v,
                             const char *fn, const char *why, char *buf, size_t n)
{
    const umbra_param_info *i = &p->info;
    char a[40], b[40];
    if (!n)
        return;
    buf[0] = '\0';
    append(buf, n, "%s: %s %s %s%s%s must ", fn, t->info.name, i->key, num(v, a),
           i->unit ? " " : "", i->unit ? i->unit : "");
    if (why) {
        append(buf, n, "%s", why);
        return;
    }
    if (i->flags & UMBRA_PARAM_ZERO)
        append(buf, n, "be 0 (%s) or ", i->zero_doc);
    if (i->allowed) {
        append(buf, n, "%s", i->flags & UMBRA_PARAM_ZERO ? "one of " : "be ");
        for (uint32_t k = 0; k < i->allowed_count; ++k)
            append(buf, n, "%s%s", k == 0 ? "" : k + 1 == i->allowed_count ? " or " : ", ",
                   num(i->allowed[k], a));
        return;
    }
    append(buf, n, "lie in %c%s, %s%c", i->flags & UMBRA_PARAM_MIN_EXCLUSIVE ? '(' : '[',
           num(i->min, a), num(i->max, b), i->flags & UMBRA_PARAM_MAX_EXCLUSIVE ? ')' : ']');
}

/* Whether value may be stored in p at all: a whole number of 32 bits for UINT, 0 or 1 for BOOL,
 * then in range. Writes the refusal into buf. */
static int check_value(const umbra__technique *t, const umbra__param *p, double value,
                       const char *fn, char *buf, size_t n)
{
    const umbra_param_info *i = &p->info;
    double v = value;
    if (i->type == UMBRA_PARAM_UINT && !(v >= 0.0 && v <= 4294967295.0 && v == floor(v))) {
        describe_refusal(t, p, v, fn, "be a whole number in [0, 4294967295]", buf, n);
        return 0;
    }
    if (i->type == UMBRA_PARAM_BOOL && v != 0.0 && v != 1.0) {
        describe_refusal(t, p, v, fn, "be 0 or 1", buf, n);
        return 0;
    }
    if (i->type == UMBRA_PARAM_FLOAT)
        v = (float)v; /* what the field will hold */
    if (!in_range(p, v)) {
        describe_refusal(t, p, v, fn, NULL, buf, n);
        return 0;
    }
    return 1;
}

/* ---- by name --------------------------------------------------------------------------------- */

static void set_message(char *message, size_t size, const char *text)
{
    if (message && size)
        snprintf(message, size, "%s", text);
}

/* The names of every technique, or of t's parameters, "a, b, c", into buf. */
static void list_names(const umbra__technique *t, char *buf, size_t n)
{
    buf[0] = '\0';
    if (t) {
        for (uint32_t i = 0; i < t->info.param_count; ++i)
            append(buf, n, "%s%s", i ? ", " : "", t->params[i].info.key);
    } else {
        for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
            append(buf, n, "%s%s", i ? ", " : "", techniques[i]->info.name);
    }
}

/* The techniques set_param/get_param address: the named one, or (name NULL) every technique that
 * has the parameter, d->technique's first. Returns how many went into out (at most
 * TECHNIQUE_COUNT), or 0 with the reason in buf. */
static size_t address(const umbra_shadow_desc *d, const char *technique, const char *param,
                      const char *fn, const umbra__technique **out, const umbra__param **params,
                      char *buf, size_t n)
{
    char names[512];
    size_t count = 0;
    if (technique) {
        const umbra__technique *t = of_info(umbra_technique_find(technique));
        if (!t) {
            list_names(NULL, names, sizeof names);
            snprintf(buf, n, "%s: technique '%s' is unknown (%s)", fn, technique, names);
            return 0;
        }
        const umbra__param *p = param_find(t, param);
        if (!p) {
            list_names(t, names, sizeof names);
            snprintf(buf, n, "%s: %s has no parameter '%s' (%s)", fn, t->info.name, param,
                     t->info.param_count ? names : "it has none");
            return 0;
        }
        out[0] = t;
        params[0] = p;
        return 1;
    }
    const umbra__technique *own = umbra__technique_by_id(d->technique);
    if (own && param_find(own, param)) {
        out[count] = own;
        params[count++] = param_find(own, param);
    }
    for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
        if (techniques[i] != own && param_find(techniques[i], param)) {
            out[count] = techniques[i];
            params[count++] = param_find(techniques[i], param);
        }
    if (!count)
        snprintf(buf, n, "%s: no technique has a parameter '%s'", fn, param);
    return count;
}

umbra_status umbra_shadow_desc_set_param(umbra_shadow_desc *d, const char *technique,
                                         const char *param, double value, char *message,
                                         size_t message_size)
{
    const char *fn = "umbra_shadow_desc_set_param";
    char buf[UMBRA_MESSAGE_MAX];
    const umbra__technique *ts[TECHNIQUE_COUNT];
    const umbra__param *ps[TECHNIQUE_COUNT];
    if (!d || !param) {
        snprintf(buf, sizeof buf, "%s: desc %p and param %p must not be NULL", fn, (void *)d,
                 (const void *)param);
        set_message(message, message_size, buf);
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    size_t count = address(d, technique, param, fn, ts, ps, buf, sizeof buf);
    for (size_t i = 0; i < count; ++i)
        if (!check_value(ts[i], ps[i], value, fn, buf, sizeof buf)) {
            count = 0;
            break;
        }
    if (!count) {
        set_message(message, message_size, buf);
        return UMBRA_ERROR_INVALID_ARGUMENT;
    }
    for (size_t i = 0; i < count; ++i)
        store(ps[i], d, value);
    set_message(message, message_size, "");
    return UMBRA_SUCCESS;
}

umbra_status umbra_shadow_desc_get_param(const umbra_shadow_desc *d, const char *technique,
                                         const char *param, double *value)
{
    char buf[1024];
    const umbra__technique *ts[TECHNIQUE_COUNT];
    const umbra__param *ps[TECHNIQUE_COUNT];
    if (!d || !param || !value ||
        !address(d, technique, param, "umbra_shadow_desc_get_param", ts, ps, buf, sizeof buf))
        return UMBRA_ERROR_INVALID_ARGUMENT;
    *value = value_of(ps[0], d);
    return UMBRA_SUCCESS;
}

/* ---- what the renderer asks ------------------------------------------------------------------ */

void umbra_shadow_desc_init(umbra_shadow_desc *d)
{
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->struct_size = sizeof *d;
    d->technique = UMBRA_SHADOW_NONE;
    for (size_t i = 0; i < TECHNIQUE_COUNT; ++i)
        for (uint32_t k = 0; k < techniques[i]->info.param_count; ++k)
            store(&techniques[i]->params[k], d, techniques[i]->params[k].info.default_value);
}

umbra_status umbra__validate_shadow(umbra_renderer r, const umbra__technique *t,
                                    const umbra_shadow_desc *d, const char *fn)
{
    char buf[UMBRA_MESSAGE_MAX];
    for (uint32_t k = 0; k < t->info.param_count; ++k) {
        const umbra__param *p = &t->params[k];
        double v = value_of(p, d);
        if (!in_range(p, v)) {
            describe_refusal(t, p, v, fn, NULL, buf, sizeof buf);
            return umbra__fail(r->ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s", buf);
        }
    }
    return t->validate ? t->validate(r, d) : UMBRA_SUCCESS;
}

void umbra__light_key_fill(umbra_renderer r, const umbra__technique *t,
                           const umbra_shadow_desc *desc, umbra__light_key *key)
{
    const uint32_t by = t->info.rebuilt_by;
    memset(key, 0, sizeof *key);
    key->technique = (int)t->info.id;
    if (by & UMBRA_REBUILD_VOLUME) {
        key->volume_id = r->volume->id;
        key->volume_version = r->volume->version;
    }
    if (by & UMBRA_REBUILD_LIGHT_TF) {
        key->light_tf_id = umbra__light_tf(r)->id;
        for (uint32_t c = 1; c < r->volume->channels; ++c)
            key->channel_light_tf_id[c] = r->ch_light_eff[c] ? r->ch_light_eff[c]->id : 0;
    }
    if (by & UMBRA_REBUILD_CLIP)
        key->clip = r->shadow_params.clip;
    if (by & UMBRA_REBUILD_LIGHT)
        key->light = r->light;
    if (by & UMBRA_REBUILD_TRANSMISSION)
        key->transmission = (int)r->opts.transmission;
    if (by & UMBRA_REBUILD_SKIPPING)
        key->skip_empty = r->opts.empty_space_skipping;
    for (uint32_t k = 0, n = 0; k < t->info.param_count && n < UMBRA__MAX_PARAMS; ++k)
        if (t->params[k].info.flags & UMBRA_PARAM_REBUILDS)
            key->params[n++] = value_of(&t->params[k], desc);
}

/* ---- drafts ---------------------------------------------------------------------------------- */

/* The value a zero of p stands for in a draft's comparison: a map's texels per voxel or step
 * "the technique's own" is the technique's; any other zero ("unbounded") is infinite. */
static double zero_means(const umbra__technique *t, const umbra__param *p)
{
    if (p->offset == offsetof(umbra_shadow_desc, map.texels_per_voxel))
        return t->info.map_texels_per_voxel;
    if (p->offset == offsetof(umbra_shadow_desc, map.step))
        return t->info.map_step;
    return INFINITY;
}

/* Applies one "key<=v", "key>=v" or "key=v" of a draft string to d; 0 if it does not parse, names
 * no parameter of t, or gives a value the parameter refuses. */
static int apply_draft_term(const umbra__technique *t, const char *term, size_t len,
                            umbra_shadow_desc *d)
{
    char buf[96];
    if (len == 0 || len >= sizeof buf)
        return 0;
    memcpy(buf, term, len);
    buf[len] = '\0';
    char *eq = strchr(buf, '=');
    if (!eq || eq == buf)
        return 0;
    char op = '=';
    if (eq[-1] == '<' || eq[-1] == '>') {
        op = eq[-1];
        eq[-1] = '\0';
    }
    *eq = '\0';
    const umbra__param *p = param_find(t, buf);
    if (!p)
        return 0;
    char *end;
    double v = strtod(eq + 1, &end);
    if (p->info.zero_name && strcmp(eq + 1, p->info.zero_name) == 0)
        v = 0.0;
    else if (end == eq + 1 || *end)
        return 0;
    if (op != '=') {
        const double z = (p->info.flags & UMBRA_PARAM_ZERO) ? zero_means(t, p) : 0.0;
        double have = value_of(p, d);
        if ((p->info.flags & UMBRA_PARAM_ZERO) && have == 0.0)
            have = z;
        double want = op == '<' ? fmin(have, v) : fmax(have, v);
        if (want == have)
            return 1; /* the full setting is already as coarse: kept as the application set it */
        v = want;
    }
    if (!in_range(p, v))
        return 0;
    store(p, d, v);
    return 1;
}

int umbra__draft_desc(const umbra__technique *t, const umbra_shadow_desc *desc,
                      umbra_shadow_desc *out)
{
    *out = *desc;
    const char *s = t->info.draft;
    if (!s)
        return 0;
    while (*s) {
        size_t len = strcspn(s, ";");
        if (!apply_draft_term(t, s, len, out)) {
            *out = *desc;
            return 0;
        }
        s += len + (s[len] == ';');
    }
    /* A fixed map size: the draft's texels per voxel scale it (the full map's are the
     * technique's own there). */
    const float k = out->map.texels_per_voxel, k_full = desc->map.texels_per_voxel;
    if ((t->info.flags & UMBRA_TECHNIQUE_MAP) && desc->map.size != UMBRA_MAP_SIZE_AUTO &&
        k != k_full && k > 0.0f && t->info.map_texels_per_voxel > 0.0f) {
        const uint32_t n = desc->map.size, q = UMBRA_MAP_SIZE_AUTO_ROUND;
        double want = ceil((double)n * k / t->info.map_texels_per_voxel);
        uint32_t m = want >= (double)n ? n : ((uint32_t)want + q - 1) / q * q;
        m = m < UMBRA_MAP_SIZE_AUTO_MIN ? UMBRA_MAP_SIZE_AUTO_MIN : m;
        out->map.size = m < n ? m : n;
        out->map.texels_per_voxel = k_full;
    }
    return memcmp(out, desc, sizeof *out) != 0;
}

size_t umbra__program_files(const umbra__technique *t, const char *const *common, size_t ncommon,
                            const char *const *after, const char **files, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < ncommon; ++i, ++n)
        if (n < max)
            files[n] = common[i];
    for (const char *const *f = t->kernel_files; f && *f; ++f, ++n)
        if (n < max)
            files[n] = *f;
    for (const char *const *f = after; f && *f; ++f, ++n)
        if (n < max)
            files[n] = *f;
    return n;
}
