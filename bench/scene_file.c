// SPDX-License-Identifier: Apache-2.0
/* bench/scene_file.c: parsing the bench's scene files and turning them into umbra objects.
 * The format is described in scene_file.h and bench/README.md. Every error names the file and
 * line, quotes the offending key or value and says what was expected, so that a typo in a scene
 * file stops the bench before it spends minutes on the wrong picture. */
#define _POSIX_C_SOURCE 200809L

#include "scene_file.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define MAX_TOKENS 8

uint64_t scene_hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

void scene_data_dir(const char *source_dir, char *buf, size_t size)
{
    const char *env = getenv("UMBRA_DATA_DIR");
    if (env && *env)
        snprintf(buf, size, "%s", env);
    else
        snprintf(buf, size, "%s/../shared/data/volumes", source_dir ? source_dir : ".");
}

/* Opens a regular file for reading without blocking on a FIFO or device (a plain fopen of a FIFO
 * waits for a writer forever); NULL for anything else. */
static FILE *open_regular(const char *path)
{
    struct stat sb;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0)
        return NULL;
    int flags = fcntl(fd, F_GETFL);
    FILE *f = NULL;
    if (fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) && flags >= 0 &&
        fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0)
        f = fdopen(fd, "rb");
    if (!f)
        close(fd);
    return f;
}

static int file_exists(const char *path)
{
    FILE *f = open_regular(path);
    if (f)
        fclose(f);
    return f != NULL;
}

int scene_volume_present(const scene_spec *spec)
{
    return spec->builtin || file_exists(spec->volume);
}

/* Reads a whole file into a NUL-terminated malloc'ed buffer; NULL if it cannot. */
static char *read_all(const char *path, size_t *n_out)
{
    FILE *f = open_regular(path);
    char *buf = NULL;
    size_t n = 0, cap = 0;
    if (!f)
        return NULL;
    for (;;) {
        if (cap - n < 4096) {
            cap = cap ? 2 * cap : 8192;
            char *grown = realloc(buf, cap + 1);
            if (!grown) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = grown;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return NULL;
    }
    buf[n] = '\0';
    if (n_out)
        *n_out = n;
    return buf;
}

typedef struct parser {
    const char *path;
    int line;
    char *err;
    size_t err_size;
} parser;

static int parse_error(parser *p, const char *fmt, ...)
{
    va_list ap;
    /* Line 0: a whole-file problem (a missing key), reported against the file alone. */
    int n = p->line > 0 ? snprintf(p->err, p->err_size, "%s:%d: ", p->path, p->line)
                        : snprintf(p->err, p->err_size, "%s: ", p->path);
    if (n < 0 || (size_t)n >= p->err_size)
        return -1;
    va_start(ap, fmt);
    vsnprintf(p->err + n, p->err_size - (size_t)n, fmt, ap);
    va_end(ap);
    return -1;
}

static int parse_float(const char *s, float *out)
{
    char *end;
    errno = 0;
    float v = strtof(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

/* Decimal digits only, at most UINT32_MAX: no sign, blank or trailing text. */
static int parse_uint(const char *s, uint32_t *out)
{
    uint64_t v = 0;
    if (!*s)
        return 0;
    for (; *s; ++s) {
        if (*s < '0' || *s > '9')
            return 0;
        v = 10 * v + (uint64_t)(*s - '0');
        if (v > 0xffffffffu)
            return 0;
    }
    *out = (uint32_t)v;
    return 1;
}

/* Looks word up in the '|'-separated list of choices; returns its index or -1. */
static int choice(const char *word, const char *choices)
{
    int index = 0;
    size_t len = strlen(word);
    const char *c = choices;
    while (*c) {
        const char *bar = strchr(c, '|');
        size_t n = bar ? (size_t)(bar - c) : strlen(c);
        if (n == len && strncmp(c, word, n) == 0)
            return index;
        ++index;
        if (!bar)
            break;
        c = bar + 1;
    }
    return -1;
}

/* Joins dir and a relative path (an absolute one is kept). */
static int join_path(char *buf, size_t size, const char *dir, const char *rel)
{
    int n = rel[0] == '/' ? snprintf(buf, size, "%s", rel) : snprintf(buf, size, "%s/%s", dir, rel);
    return n >= 0 && (size_t)n < size;
}

/* The keys whose value is a fixed number of floats. */
typedef struct float_key {
    const char *name;
    int count;       /* values required (ambient also takes 1) */
    size_t value;    /* offsetof the float array in scene_spec */
    size_t have;     /* offsetof the have flag, or (size_t)-1 when "0 means not given" */
    float min, max;
} float_key;

#define F(name, count, field, have, lo, hi) \
    {name, count, offsetof(scene_spec, field), have, lo, hi}
#define HAVE(field) offsetof(scene_spec, field)
#define NO_FLAG ((size_t)-1)

static const float_key float_keys[] = {
    F("eye", 3, eye, HAVE(have_eye), -1e30f, 1e30f),
    F("target", 3, target, HAVE(have_target), -1e30f, 1e30f),
    F("up", 3, up, HAVE(have_up), -1e30f, 1e30f),
    F("fov", 1, fov, HAVE(have_fov), 0.01f, 179.99f),
    F("ortho_height", 1, ortho_height, HAVE(have_ortho), 1e-6f, 1e30f),
    F("light_position", 3, light_position, HAVE(have_light_position), -1e30f, 1e30f),
    F("light_direction", 3, light_direction, HAVE(have_light_direction), -1e30f, 1e30f),
    F("light_color", 3, light_color, HAVE(have_light_color), 0.0f, 1e30f),
    F("step", 1, step, NO_FLAG, 0.01f, 64.0f),
    F("reference_step", 1, reference_step, NO_FLAG, 0.01f, 64.0f),
    F("termination", 1, termination, NO_FLAG, 1e-6f, 1.0f),
    F("kd", 1, kd, HAVE(have_kd), 0.0f, 1e30f),
    F("ks", 1, ks, HAVE(have_ks), 0.0f, 1e30f),
    F("shininess", 1, shininess, HAVE(have_shininess), 1e-6f, 1e30f),
    F("ambient", 3, ambient, HAVE(have_ambient), 0.0f, 1e30f),
    F("ground_color", 3, ground_color, HAVE(have_ground_color), 0.0f, 1e30f),
    F("ground_offset", 1, ground_offset, HAVE(have_ground_offset), -1e30f, 1e30f),
    F("background", 4, background, HAVE(have_background), 0.0f, 1e30f),
};

static const char *const other_keys[] = {
    "volume", "tf", "light_tf", "description", "units", "camera", "light", "size",
    "transmission", "shading", "ground", "quick", "papers",
};

#define KEY_COUNT (sizeof float_keys / sizeof float_keys[0] + \
                   sizeof other_keys / sizeof other_keys[0])

static int known_key_index(const char *key)
{
    for (size_t i = 0; i < sizeof float_keys / sizeof float_keys[0]; ++i)
        if (strcmp(key, float_keys[i].name) == 0)
            return (int)i;
    for (size_t i = 0; i < sizeof other_keys / sizeof other_keys[0]; ++i)
        if (strcmp(key, other_keys[i]) == 0)
            return (int)(sizeof float_keys / sizeof float_keys[0] + i);
    return -1;
}

static int parse_float_key(parser *p, const float_key *k, char **tok, int ntok, scene_spec *s)
{
    int given = ntok - 1;
    int ok_count = given == k->count || (strcmp(k->name, "ambient") == 0 && given == 1);
    if (!ok_count)
        return parse_error(p, "'%s' takes %d number%s, got %d", k->name, k->count,
                    k->count == 1 ? "" : "s", given);
    float *v = (float *)((char *)s + k->value);
    for (int i = 0; i < given; ++i) {
        if (!parse_float(tok[1 + i], &v[i]))
            return parse_error(p, "'%s': '%s' is not a finite number", k->name, tok[1 + i]);
        if (v[i] < k->min || v[i] > k->max)
            return parse_error(p, "'%s': %g must lie in [%g, %g]", k->name, v[i], k->min, k->max);
    }
    if (given == 1 && k->count == 3)
        v[1] = v[2] = v[0];
    if (k->have != NO_FLAG)
        *(int *)((char *)s + k->have) = 1;
    return 0;
}

static int on_off(parser *p, const char *key, char **tok, int ntok, int *out)
{
    if (ntok != 2)
        return parse_error(p, "'%s' takes one word (on|off), got %d", key, ntok - 1);
    int c = choice(tok[1], "on|off|yes|no|1|0");
    if (c < 0)
        return parse_error(p, "'%s': '%s' is not one of on, off, yes, no, 1, 0", key, tok[1]);
    *out = (c % 2) == 0;
    return 0;
}

static int hash_file(parser *p, const char *what, const char *path, scene_spec *s)
{
    size_t n = 0;
    char *text = read_all(path, &n);
    if (!text)
        return parse_error(p, "%s file '%s' cannot be read: %s", what, path, strerror(errno));
    s->hash = scene_hash_bytes(s->hash, text, n);
    free(text);
    return 0;
}

static int parse_line(parser *p, char **tok, int ntok, const char *dir, const char *data_dir,
                      int hash_files, scene_spec *s, unsigned char *seen, const char *raw_rest)
{
    const char *key = tok[0];
    int index = known_key_index(key);
    if (index < 0) {
        char known[1024] = "";
        size_t used = 0;
        for (size_t i = 0; i < KEY_COUNT && used < sizeof known; ++i) {
            const char *name = i < sizeof float_keys / sizeof float_keys[0]
                                   ? float_keys[i].name
                                   : other_keys[i - sizeof float_keys / sizeof float_keys[0]];
            int n = snprintf(known + used, sizeof known - used, "%s%s", i ? ", " : "", name);
            if (n < 0)
                break;
            used += (size_t)n;
        }
        return parse_error(p, "unknown key '%s' (known: %s)", key, known);
    }
    if (seen[index])
        return parse_error(p, "'%s' is given twice", key);
    seen[index] = 1;
    if ((size_t)index < sizeof float_keys / sizeof float_keys[0])
        return parse_float_key(p, &float_keys[index], tok, ntok, s);

    if (strcmp(key, "description") == 0) {
        snprintf(s->description, sizeof s->description, "%s", raw_rest);
        return 0;
    }
    if (strcmp(key, "volume") == 0) {
        if (ntok >= 2 && strcmp(tok[1], "builtin") == 0) {
            if (ntok < 3 || ntok > 4)
                return parse_error(p, "'volume builtin' takes a scene name and an optional "
                                      "resolution");
            int known = 0;
            for (const char *const *n = umbra_scene_names(); *n; ++n)
                known |= strcmp(*n, tok[2]) == 0;
            if (!known)
                return parse_error(p, "'volume builtin': no built-in scene '%s' (known: "
                                      "spheres, slab, marschner-lobb)", tok[2]);
            s->builtin = 1;
            snprintf(s->volume, sizeof s->volume, "%s", tok[2]);
            if (ntok == 4 && (!parse_uint(tok[3], &s->builtin_resolution) ||
                              (s->builtin_resolution != 0 &&
                               (s->builtin_resolution < 4 || s->builtin_resolution > 1024))))
                return parse_error(p, "'volume builtin %s': resolution '%s' must be 0 or lie in "
                               "[4, 1024]", tok[2], tok[3]);
            return 0;
        }
        if (ntok != 2)
            return parse_error(p, "'volume' takes a file path or 'builtin NAME [RES]'");
        if (!join_path(s->volume, sizeof s->volume, data_dir, tok[1]))
            return parse_error(p, "'volume': path '%s' is too long", tok[1]);
        return 0;
    }
    if (strcmp(key, "tf") == 0 || strcmp(key, "light_tf") == 0) {
        int light = key[0] == 'l';
        if (ntok != 2)
            return parse_error(p, "'%s' takes one file path%s", key, light ? "" : " or 'builtin'");
        if (!light && strcmp(tok[1], "builtin") == 0) {
            s->tf_builtin = 1;
            return 0;
        }
        char *dst = light ? s->light_tf : s->tf;
        if (!join_path(dst, SCENE_PATH_MAX, dir, tok[1]))
            return parse_error(p, "'%s': path '%s' is too long", key, tok[1]);
        return hash_files ? hash_file(p, key, dst, s) : 0;
    }
    if (strcmp(key, "units") == 0) {
        int c = ntok == 2 ? choice(tok[1], "diagonal|world") : -1;
        if (c < 0)
            return parse_error(p, "'units' takes diagonal or world");
        s->units_world = c;
        return 0;
    }
    if (strcmp(key, "camera") == 0) {
        int c = ntok == 2 ? choice(tok[1], "perspective|orthographic") : -1;
        if (c < 0)
            return parse_error(p, "'camera' takes perspective or orthographic");
        s->projection = c ? UMBRA_ORTHOGRAPHIC : UMBRA_PERSPECTIVE;
        s->have_projection = 1;
        return 0;
    }
    if (strcmp(key, "light") == 0) {
        int c = ntok == 2 ? choice(tok[1], "point|directional") : -1;
        if (c < 0)
            return parse_error(p, "'light' takes point or directional");
        s->light_type = c ? UMBRA_LIGHT_DIRECTIONAL : UMBRA_LIGHT_POINT;
        s->have_light_type = 1;
        return 0;
    }
    if (strcmp(key, "transmission") == 0) {
        int c = ntok == 2 ? choice(tok[1], "grey|colored|gray|coloured") : -1;
        if (c < 0)
            return parse_error(p, "'transmission' takes grey or colored");
        s->transmission = c % 2 ? UMBRA_TRANSMISSION_COLORED : UMBRA_TRANSMISSION_GREY;
        return 0;
    }
    if (strcmp(key, "size") == 0) {
        if (ntok != 3 || !parse_uint(tok[1], &s->width) || !parse_uint(tok[2], &s->height) ||
            s->width < 8 || s->height < 8 || s->width > 8192 || s->height > 8192)
            return parse_error(p, "'size' takes width and height in [8, 8192]");
        return 0;
    }
    if (strcmp(key, "shading") == 0)
        return on_off(p, key, tok, ntok, &s->shading);
    if (strcmp(key, "ground") == 0)
        return on_off(p, key, tok, ntok, &s->ground);
    if (strcmp(key, "quick") == 0)
        return on_off(p, key, tok, ntok, &s->quick);
    if (strcmp(key, "papers") == 0) {
        int c = ntok == 2 ? choice(tok[1], "no|cssm|deep|cssm,deep|deep,cssm") : -1;
        if (c < 0)
            return parse_error(p, "'papers' takes no, cssm, deep or cssm,deep");
        static const int bits[5] = {0, SCENE_PAPERS_CSSM, SCENE_PAPERS_DEEP,
                                    SCENE_PAPERS_CSSM | SCENE_PAPERS_DEEP,
                                    SCENE_PAPERS_CSSM | SCENE_PAPERS_DEEP};
        s->papers = bits[c];
        return 0;
    }
    /* Unreachable: every key of the tables is handled above. */
    return parse_error(p, "key '%s' has no parser", key);
}

int scene_parse_text(const char *text, const char *path, const char *data_dir, int hash_files,
                     scene_spec *s, char *err, size_t err_size)
{
    parser p = {path, 0, err, err_size};
    unsigned char seen[KEY_COUNT];
    char dir[SCENE_PATH_MAX];
    memset(seen, 0, sizeof seen);
    memset(s, 0, sizeof *s);
    if (err_size)
        err[0] = '\0';
    s->transmission = -1;
    s->shading = -1;
    s->ground = -1;
    s->hash = scene_hash_bytes(SCENE_HASH_INIT, text, strlen(text));
    snprintf(s->path, sizeof s->path, "%s", path);

    /* Stem and directory of the path. */
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (slash)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else
        snprintf(dir, sizeof dir, ".");
    const char *dot = strrchr(base, '.');
    size_t stem = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (stem == 0 || stem >= sizeof s->name)
        return parse_error(&p, "the file name must have a stem of 1 to %d characters",
                    (int)sizeof s->name - 1);
    memcpy(s->name, base, stem);
    s->name[stem] = '\0';
    for (size_t i = 0; i < stem; ++i) {
        char c = s->name[i];
        /* The name becomes part of file names and of the CSV. */
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '-'))
            return parse_error(&p, "scene name '%s' may only hold letters, digits, '_' and '-'",
                               s->name);
    }

    const char *line = text;
    while (*line) {
        ++p.line;
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        char buf[1024];
        if (len >= sizeof buf)
            return parse_error(&p, "line longer than %d characters", (int)sizeof buf - 1);
        memcpy(buf, line, len);
        buf[len] = '\0';
        line = end ? end + 1 : line + len;
        char *hash = strchr(buf, '#');
        if (hash)
            *hash = '\0';
        char *q = buf;
        while (*q == ' ' || *q == '\t' || *q == '\r')
            ++q;
        if (strncmp(q, "description", 11) == 0 &&
            (q[11] == '\0' || q[11] == ' ' || q[11] == '\t')) {
            /* Free text: keep it as written (inner blanks included), trailing blanks trimmed. */
            char *text_start = q + 11;
            while (*text_start == ' ' || *text_start == '\t')
                ++text_start;
            size_t tl = strlen(text_start);
            while (tl && (text_start[tl - 1] == ' ' || text_start[tl - 1] == '\t' ||
                          text_start[tl - 1] == '\r'))
                text_start[--tl] = '\0';
            char dname[] = "description";
            char *dtok[1] = {dname};
            if (parse_line(&p, dtok, 1, dir, data_dir, hash_files, s, seen, text_start) != 0)
                return -1;
            continue;
        }
        char *tok[MAX_TOKENS];
        int ntok = 0;
        for (;;) {
            while (*q == ' ' || *q == '\t' || *q == '\r')
                ++q;
            if (!*q)
                break;
            if (ntok == MAX_TOKENS)
                return parse_error(&p, "too many values after '%s'", tok[0]);
            tok[ntok++] = q;
            while (*q && *q != ' ' && *q != '\t' && *q != '\r')
                ++q;
            if (*q)
                *q++ = '\0';
        }
        if (ntok == 0)
            continue;
        if (parse_line(&p, tok, ntok, dir, data_dir, hash_files, s, seen, "") != 0)
            return -1;
    }

    /* Whole-file checks. */
    p.line = 0;
    if (!s->volume[0])
        return parse_error(&p, "no 'volume' line: every scene needs 'volume builtin NAME' or "
                        "'volume FILE'");
    if (!s->builtin) {
        if (s->tf_builtin || !s->tf[0])
            return parse_error(&p, "volume file '%s' needs a 'tf FILE' line (only built-in volumes "
                            "have their own transfer function)", s->volume);
        if (!s->have_light_type || !s->have_eye)
            return parse_error(&p, "volume file '%s' needs 'light' and 'eye' lines (the camera and "
                            "light must be stated)", s->volume);
    } else if (!s->tf[0]) {
        s->tf_builtin = 1;
    }
    if (s->have_light_type && s->light_type == UMBRA_LIGHT_POINT && !s->have_light_position)
        return parse_error(&p, "'light point' needs a 'light_position X Y Z' line");
    if (s->have_light_type && s->light_type == UMBRA_LIGHT_DIRECTIONAL) {
        if (!s->have_light_direction)
            return parse_error(&p, "'light directional' needs a 'light_direction X Y Z' line");
        const float *d = s->light_direction;
        if (d[0] == 0.0f && d[1] == 0.0f && d[2] == 0.0f)
            return parse_error(&p, "'light_direction 0 0 0' has no direction");
    }
    if (s->have_projection && s->projection == UMBRA_ORTHOGRAPHIC && !s->have_ortho)
        return parse_error(&p, "'camera orthographic' needs an 'ortho_height H' line");
    return 0;
}

int scene_parse_file(const char *path, const char *data_dir, scene_spec *spec, char *err,
                     size_t err_size)
{
    char *text = read_all(path, NULL);
    if (!text) {
        snprintf(err, err_size, "%s: cannot read the scene file: %s", path, strerror(errno));
        return -1;
    }
    if (strlen(text) == 0 && err_size) {
        free(text);
        snprintf(err, err_size, "%s: the scene file is empty", path);
        return -1;
    }
    int rc = scene_parse_text(text, path, data_dir, 1, spec, err, err_size);
    free(text);
    return rc;
}

umbra_status scene_create(umbra_context ctx, const scene_spec *s, umbra_scene *scene,
                          umbra_transfer_function *light_tf)
{
    umbra_status st = UMBRA_SUCCESS;
    memset(scene, 0, sizeof *scene);
    *light_tf = NULL;
    if (s->builtin) {
        st = umbra_scene_create(ctx, s->volume, s->builtin_resolution, scene);
        if (st != UMBRA_SUCCESS)
            return st;
        if (!s->tf_builtin) {
            umbra_transfer_function_release(scene->tf);
            scene->tf = NULL;
        }
    } else {
        umbra_render_desc_init(&scene->options);
        st = umbra_volume_load(ctx, s->volume, &scene->volume);
        if (st != UMBRA_SUCCESS)
            goto fail;
        const float dir[3] = {0.0f, 0.0f, 1.0f};
        scene->camera = umbra_camera_orbit(dir, 1.0f, 30.0f);
        scene->camera.target[0] = scene->camera.target[1] = scene->camera.target[2] = 0.0f;
        scene->light.color[0] = scene->light.color[1] = scene->light.color[2] = 1.0f;
    }
    if (!scene->tf && (st = umbra_transfer_function_load(ctx, s->tf, &scene->tf)) != UMBRA_SUCCESS)
        goto fail;
    if (s->light_tf[0] &&
        (st = umbra_transfer_function_load(ctx, s->light_tf, light_tf)) != UMBRA_SUCCESS)
        goto fail;

    umbra_volume_info info;
    if ((st = umbra_volume_get_info(scene->volume, &info)) != UMBRA_SUCCESS)
        goto fail;
    float unit = s->units_world
                     ? 1.0f
                     : sqrtf(info.extent[0] * info.extent[0] + info.extent[1] * info.extent[1] +
                             info.extent[2] * info.extent[2]);
    umbra_camera *c = &scene->camera;
    if (s->have_projection)
        c->projection = s->projection;
    for (int i = 0; i < 3; ++i) {
        if (s->have_eye)
            c->eye[i] = s->eye[i] * unit;
        if (s->have_target)
            c->target[i] = s->target[i] * unit;
        if (s->have_up)
            c->up[i] = s->up[i];
    }
    if (s->have_fov)
        c->fovy_degrees = s->fov;
    if (s->have_ortho)
        c->ortho_height = s->ortho_height * unit;
    umbra_light *l = &scene->light;
    if (s->have_light_type)
        l->type = s->light_type;
    for (int i = 0; i < 3; ++i) {
        if (s->have_light_position)
            l->position[i] = s->light_position[i] * unit;
        if (s->have_light_direction)
            l->direction[i] = s->light_direction[i];
        if (s->have_light_color)
            l->color[i] = s->light_color[i];
    }
    /* Scene coordinates are relative to the box's centre; a volume with an index-to-world
     * transform (a NRRD's space origin) has its centre elsewhere in its world. */
    for (int i = 0; i < 3; ++i) {
        c->eye[i] += info.center[i];
        c->target[i] += info.center[i];
        if (l->type == UMBRA_LIGHT_POINT)
            l->position[i] += info.center[i];
    }
    umbra_render_desc *o = &scene->options;
    if (s->step > 0.0f)
        o->step = s->step;
    if (s->termination > 0.0f)
        o->termination = s->termination;
    if (s->transmission >= 0)
        o->transmission = (umbra_transmission)s->transmission;
    if (s->shading >= 0)
        o->shading = s->shading;
    if (s->ground >= 0)
        o->ground_plane = s->ground;
    if (s->have_kd)
        o->kd = s->kd;
    if (s->have_ks)
        o->ks = s->ks;
    if (s->have_shininess)
        o->shininess = s->shininess;
    for (int i = 0; i < 3; ++i) {
        if (s->have_ambient)
            o->ambient[i] = s->ambient[i];
        if (s->have_ground_color)
            o->ground_color[i] = s->ground_color[i];
    }
    if (s->have_ground_offset)
        o->ground_offset = s->ground_offset;
    if (s->have_background)
        memcpy(o->background, s->background, sizeof o->background);
    return UMBRA_SUCCESS;
fail:
    umbra_transfer_function_release(*light_tf);
    *light_tf = NULL;
    umbra_scene_release(scene);
    return st;
}
