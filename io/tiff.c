// SPDX-License-Identifier: Apache-2.0
/* io/tiff.c: volumes from TIFF stacks through libtiff (Debian's libtiff-dev): one multi-page TIFF
 * (every full-resolution page a z slice; OME-TIFF too), or a list of single-page TIFFs (a
 * directory's files in name order, see io/series.c), one slice each.
 *
 * umbra decides what it accepts: one sample per pixel (greyscale), 8- or 16-bit integers
 * (unsigned kept; int8 widened to int16) or 32-bit IEEE floats, stripped or tiled, any compression
 * libtiff decodes; every slice the same size and type. Pages marked as reduced-resolution copies
 * (SubfileType bit 0, a pyramid's levels) are not slices and are passed over. OME-TIFF: the
 * OME-XML in the first page's ImageDescription (parsed with expat) gives the spacing
 * (PhysicalSizeX/Y/Z, in PhysicalSizeXUnit; 1 where absent) and must describe one image of one
 * channel and one time point whose SizeZ is the page count. Without it the spacing is 1. TIFF has
 * no world position: the box is centred.
 *
 * Hostile files: each file is opened as every umbra reader opens files (regular files only, never
 * blocking), with memory mapping off (a file cut short while mapped would be SIGBUS, not an
 * error) and libtiff's per-file error and warning handlers, so libtiff prints nothing and its
 * first complaint lands in umbra's message. Sizes are checked before the volume is allocated:
 * the slices may hold at most 1032 times the bytes of their files (deflate's largest expansion),
 * so a small file cannot claim gigabytes; at most 65536 slices; a strip or tile that decodes short
 * fails the load naming the page. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <expat.h>
#include <tiffio.h>

#include "io_internal.h"

#define TIFF_MAX_SLICES 65536u
#define TIFF_MAX_RATIO 1032u
/* libtiff may allocate at most this much at once for one strip or tile. */
#define TIFF_MAX_ALLOC ((tmsize_t)1 << 30)
#define TIFF_MESSAGE_MAX 512

/* libtiff's first error for one file, and the file's name for the message. */
typedef struct tiff_errors {
    char first[TIFF_MESSAGE_MAX];
} tiff_errors;

static int tiff_error_handler(TIFF *tif, void *user, const char *module, const char *fmt,
                              va_list ap)
{
    tiff_errors *e = user;
    (void)tif;
    if (e && e->first[0] == '\0') {
        int n = snprintf(e->first, sizeof e->first, "%s: ", module ? module : "libtiff");
        if (n > 0 && (size_t)n < sizeof e->first) {
            vsnprintf(e->first + n, sizeof e->first - (size_t)n, fmt, ap);
        }
    }
    return 1; /* handled: libtiff's global handler (stderr) is not called */
}

static int tiff_warning_handler(TIFF *tif, void *user, const char *module, const char *fmt,
                                va_list ap)
{
    (void)tif, (void)user, (void)module, (void)fmt, (void)ap;
    return 1; /* dropped: the library never prints */
}

/* Opens path (a regular file, without blocking) for libtiff; *size gets the file's bytes. */
static umbra_status tiff_open(umbra_context ctx, const char *func, const char *path,
                              tiff_errors *errors, TIFF **out, size_t *size)
{
    FILE *f = NULL;
    TIFFOpenOptions *opts = NULL;
    umbra_status st;
    int fd;

    *out = NULL;
    st = umbra__file_open(ctx, func, path, &f, size);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    fd = dup(fileno(f));
    fclose(f);
    opts = TIFFOpenOptionsAlloc();
    if (fd < 0 || !opts) {
        if (fd >= 0) {
            close(fd);
        }
        TIFFOpenOptionsFree(opts);
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: cannot open \"%s\" for libtiff",
                           func, path);
    }
    errors->first[0] = '\0';
    TIFFOpenOptionsSetErrorHandlerExtR(opts, tiff_error_handler, errors);
    TIFFOpenOptionsSetWarningHandlerExtR(opts, tiff_warning_handler, NULL);
    TIFFOpenOptionsSetMaxSingleMemAlloc(opts, TIFF_MAX_ALLOC);
    /* "m": no memory mapping (see the top of the file). TIFFFdOpen owns fd from here on. */
    *out = TIFFFdOpenExt(fd, path, "rm", opts);
    TIFFOpenOptionsFree(opts);
    if (!*out) {
        close(fd);
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" is not a TIFF file libtiff reads%s%s",
                           func, path, errors->first[0] ? ": " : "", errors->first);
    }
    return UMBRA_SUCCESS;
}

/* ---- OME-XML -------------------------------------------------------------------------------- */

typedef struct ome_info {
    int images, pixels;             /* how many Image and Pixels elements */
    uint64_t size[5];               /* SizeX, SizeY, SizeZ, SizeC, SizeT of the first Pixels */
    double physical[3];             /* PhysicalSizeX/Y/Z (0: absent) */
    char unit[3][16];               /* their units ("" : OME's default, micrometres) */
    int bad;                        /* an attribute did not parse */
    char bad_attr[64];
} ome_info;

/* The local name of an expat name "namespace-URI name" (XML_ParserCreateNS with ' '). */
static const char *local_name(const char *name)
{
    const char *sp = strrchr(name, ' ');
    return sp ? sp + 1 : name;
}

static void ome_start(void *user, const XML_Char *name, const XML_Char **attrs)
{
    static const char *const sizes[5] = {"SizeX", "SizeY", "SizeZ", "SizeC", "SizeT"};
    static const char *const phys[3] = {"PhysicalSizeX", "PhysicalSizeY", "PhysicalSizeZ"};
    static const char *const units[3] = {"PhysicalSizeXUnit", "PhysicalSizeYUnit",
                                         "PhysicalSizeZUnit"};
    ome_info *o = user;
    const char *local = local_name(name);
    int i, k;
    if (strcmp(local, "Image") == 0) {
        ++o->images;
        return;
    }
    if (strcmp(local, "Pixels") != 0 || o->pixels++ > 0) {
        return;
    }
    for (i = 0; attrs[i] && attrs[i + 1]; i += 2) {
        const char *a = local_name(attrs[i]), *v = attrs[i + 1];
        for (k = 0; k < 5; ++k) {
            if (strcmp(a, sizes[k]) == 0 && !umbra__parse_uint(v, strlen(v), UINT32_MAX,
                                                               &o->size[k])) {
                o->bad = 1;
                snprintf(o->bad_attr, sizeof o->bad_attr, "%s", sizes[k]);
            }
        }
        for (k = 0; k < 3; ++k) {
            if (strcmp(a, phys[k]) == 0) {
                char *end = NULL;
                double d = strtod(v, &end);
                if (end == v || *end != '\0' || !(d > 0.0) || !isfinite(d)) {
                    o->bad = 1;
                    snprintf(o->bad_attr, sizeof o->bad_attr, "%s", phys[k]);
                } else {
                    o->physical[k] = d;
                }
            }
            if (strcmp(a, units[k]) == 0) {
                snprintf(o->unit[k], sizeof o->unit[k], "%s", v);
            }
        }
    }
}

/* Metres per OME length unit (the common ones); 0 if unknown. "" is OME's default, µm. */
static double unit_metres(const char *u)
{
    static const struct {
        const char *name;
        double metres;
    } table[] = {{"", 1e-6},     {"\xc2\xb5m", 1e-6}, {"um", 1e-6}, {"nm", 1e-9},
                 {"pm", 1e-12},  {"mm", 1e-3},        {"cm", 1e-2}, {"m", 1.0},
                 {"\xc3\x85", 1e-10}};
    size_t i;
    for (i = 0; i < sizeof table / sizeof table[0]; ++i) {
        if (strcmp(u, table[i].name) == 0) {
            return table[i].metres;
        }
    }
    return 0.0;
}

/* Reads OME-XML (text, NUL-terminated) into *o; returns 0 if it is not well-formed XML. */
static int ome_parse(const char *text, ome_info *o)
{
    XML_Parser p = XML_ParserCreateNS(NULL, ' ');
    int ok;
    memset(o, 0, sizeof *o);
    if (!p) {
        return 0;
    }
    XML_SetUserData(p, o);
    XML_SetStartElementHandler(p, ome_start);
    ok = XML_Parse(p, text, (int)strlen(text), 1) == XML_STATUS_OK;
    XML_ParserFree(p);
    return ok;
}

/* ---- the stack ---------------------------------------------------------------------------- */

typedef struct tiff_page {
    uint32_t width, height;
    uint16_t bits, format, samples;
} tiff_page;

typedef struct tiff_stack {
    umbra_context ctx;
    const char *func;
    const char *const *paths;
    size_t nfiles;
    TIFF *tif;                /* a single multi-page file, kept open from the header pass */
    tdir_t *dirs;             /* its slice pages' directory numbers */
    uint32_t dims[3];
    tiff_page page;
    umbra_scalar_type type;
    tiff_errors errors;
} tiff_stack;

static const char *format_name(uint16_t format)
{
    switch (format) {
    case SAMPLEFORMAT_UINT: return "unsigned";
    case SAMPLEFORMAT_INT: return "signed";
    case SAMPLEFORMAT_IEEEFP: return "float";
    default: return "other";
    }
}

/* The current page's layout, and whether umbra reads it. */
static umbra_status read_page(tiff_stack *S, const char *path, TIFF *tif, tdir_t dir,
                              tiff_page *pg)
{
    uint32_t depth = 1;
    uint16_t photometric = PHOTOMETRIC_MINISBLACK;
    memset(pg, 0, sizeof *pg);
    if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &pg->width) ||
        !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &pg->height) || pg->width == 0 ||
        pg->height == 0) {
        return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\" page %u: no image width and length (or zero)", S->func,
                           path, (unsigned)dir);
    }
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &pg->bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &pg->samples);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &pg->format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_PHOTOMETRIC, &photometric);
    if (TIFFGetField(tif, TIFFTAG_IMAGEDEPTH, &depth) && depth > 1) {
        return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\" page %u has ImageDepth %u (a volumetric SGI TIFF): "
                           "umbra reads a stack of 2D pages",
                           S->func, path, (unsigned)dir, depth);
    }
    if (pg->samples != 1 || photometric == PHOTOMETRIC_PALETTE) {
        return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\" page %u has %u samples per pixel%s: umbra reads "
                           "greyscale (one sample per pixel)",
                           S->func, path, (unsigned)dir, (unsigned)pg->samples,
                           photometric == PHOTOMETRIC_PALETTE ? " (a palette image)" : "");
    }
    if (!((pg->bits == 8 || pg->bits == 16) &&
          (pg->format == SAMPLEFORMAT_UINT || pg->format == SAMPLEFORMAT_INT)) &&
        !(pg->bits == 32 && pg->format == SAMPLEFORMAT_IEEEFP)) {
        return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\" page %u: %u-bit %s samples are not supported (8- or "
                           "16-bit integers, 32-bit floats)",
                           S->func, path, (unsigned)dir, (unsigned)pg->bits,
                           format_name(pg->format));
    }
    return UMBRA_SUCCESS;
}

static int same_page(const tiff_page *a, const tiff_page *b)
{
    return a->width == b->width && a->height == b->height && a->bits == b->bits &&
           a->format == b->format;
}

/* Decodes the current page into dst (width x height samples of bits, rows top first). */
static umbra_status decode_page(tiff_stack *S, const char *path, TIFF *tif, tdir_t dir,
                                unsigned char *dst)
{
    const tiff_page *pg = &S->page;
    size_t bps = pg->bits / 8, row_bytes = (size_t)pg->width * bps;
    unsigned char *tile = NULL;
    umbra_status st = UMBRA_SUCCESS;

    S->errors.first[0] = '\0';
    if (TIFFIsTiled(tif)) {
        uint32_t tw = 0, th = 0, x, y;
        tmsize_t tile_bytes = TIFFTileSize(tif);
        if (!TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tw) ||
            !TIFFGetField(tif, TIFFTAG_TILELENGTH, &th) || tw == 0 || th == 0 ||
            tile_bytes != (tmsize_t)((uint64_t)tw * th * bps)) {
            return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" page %u: bad tile layout",
                               S->func, path, (unsigned)dir);
        }
        tile = malloc((size_t)tile_bytes);
        if (!tile) {
            return umbra__fail(S->ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                               "%s: cannot allocate a %u x %u tile", S->func, tw, th);
        }
        for (y = 0; y < pg->height && st == UMBRA_SUCCESS; y += th) {
            for (x = 0; x < pg->width && st == UMBRA_SUCCESS; x += tw) {
                uint32_t w = pg->width - x < tw ? pg->width - x : tw;
                uint32_t h = pg->height - y < th ? pg->height - y : th, r;
                if (TIFFReadEncodedTile(tif, TIFFComputeTile(tif, x, y, 0, 0), tile,
                                        tile_bytes) != tile_bytes) {
                    st = umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                                     "%s: \"%s\" page %u: tile at (%u, %u) does not decode%s%s",
                                     S->func, path, (unsigned)dir, x, y,
                                     S->errors.first[0] ? ": " : "", S->errors.first);
                    break;
                }
                for (r = 0; r < h; ++r) {
                    memcpy(dst + (size_t)(y + r) * row_bytes + (size_t)x * bps,
                           tile + (size_t)r * tw * bps, (size_t)w * bps);
                }
            }
        }
        free(tile);
        return st;
    }
    {
        uint32_t rows = 0, y;
        TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows);
        if (rows == 0 || rows > pg->height) {
            rows = pg->height;
        }
        for (y = 0; y < pg->height; y += rows) {
            uint32_t n = pg->height - y < rows ? pg->height - y : rows;
            tmsize_t want = (tmsize_t)((size_t)n * row_bytes);
            if (TIFFReadEncodedStrip(tif, TIFFComputeStrip(tif, y, 0), dst + (size_t)y * row_bytes,
                                     want) != want) {
                return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" page %u: the strip at row %u does not decode to "
                                   "%u rows (truncated?)%s%s",
                                   S->func, path, (unsigned)dir, y, n,
                                   S->errors.first[0] ? ": " : "", S->errors.first);
            }
        }
    }
    return UMBRA_SUCCESS;
}

/* Widens n int8 samples at the front of buf to int16 in place (from the back). */
static void widen_int8(void *buf, size_t n)
{
    const int8_t *s = buf;
    int16_t *d = buf;
    while (n-- > 0) {
        d[n] = s[n];
    }
}

/* umbra_volume_fill_fn: decodes every slice into dst. */
static umbra_status fill_tiff(void *user, void *dst, size_t bytes)
{
    tiff_stack *S = user;
    size_t slice_samples = (size_t)S->dims[0] * S->dims[1];
    size_t out_slice = slice_samples * umbra_scalar_type_size(S->type);
    uint32_t z;
    (void)bytes;
    for (z = 0; z < S->dims[2]; ++z) {
        unsigned char *slice = (unsigned char *)dst + (size_t)z * out_slice;
        umbra_status st;
        if (S->tif) {
            if (!TIFFSetDirectory(S->tif, S->dirs[z])) {
                return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": page %u is gone",
                                   S->func, S->paths[0], (unsigned)S->dirs[z]);
            }
            st = decode_page(S, S->paths[0], S->tif, S->dirs[z], slice);
        } else {
            TIFF *tif = NULL;
            size_t size = 0;
            tiff_page pg;
            st = tiff_open(S->ctx, S->func, S->paths[z], &S->errors, &tif, &size);
            if (st == UMBRA_SUCCESS) {
                st = read_page(S, S->paths[z], tif, 0, &pg);
            }
            if (st == UMBRA_SUCCESS && !same_page(&pg, &S->page)) {
                st = umbra__fail(S->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" changed while reading",
                                 S->func, S->paths[z]);
            }
            if (st == UMBRA_SUCCESS) {
                st = decode_page(S, S->paths[z], tif, 0, slice);
            }
            if (tif) {
                TIFFClose(tif);
            }
        }
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        if (S->page.bits == 8 && S->page.format == SAMPLEFORMAT_INT) {
            widen_int8(slice, slice_samples);
        }
    }
    return UMBRA_SUCCESS;
}

/* The OME-XML of the open file's first page, if any, into the spacing. */
static umbra_status ome_spacing(tiff_stack *S, const char *path, uint32_t pages, float spacing[3])
{
    const char *desc = NULL;
    ome_info o;
    double m0;
    int k;
    if (!TIFFGetField(S->tif, TIFFTAG_IMAGEDESCRIPTION, &desc) || !desc ||
        !strstr(desc, "<OME") || !(strncmp(desc, "<?xml", 5) == 0 || desc[0] == '<')) {
        return UMBRA_SUCCESS;
    }
    if (!ome_parse(desc, &o)) {
        return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": the OME-XML in ImageDescription is not well-formed",
                           S->func, path);
    }
    if (o.bad) {
        return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": OME-XML Pixels attribute %s does not parse", S->func, path,
                           o.bad_attr);
    }
    if (o.images > 1 || o.pixels != 1) {
        return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": the OME-XML describes %d images: umbra reads files of "
                           "one",
                           S->func, path, o.images > 1 ? o.images : o.pixels);
    }
    if ((o.size[3] > 1 || o.size[4] > 1)) {
        return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": OME SizeC %llu, SizeT %llu: umbra reads one channel at "
                           "one time point",
                           S->func, path, (unsigned long long)o.size[3],
                           (unsigned long long)o.size[4]);
    }
    if (o.size[0] != S->dims[0] || o.size[1] != S->dims[1] || o.size[2] != pages) {
        return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": OME Size %llu x %llu x %llu does not match the file's "
                           "%u x %u pixels in %u pages",
                           S->func, path, (unsigned long long)o.size[0],
                           (unsigned long long)o.size[1], (unsigned long long)o.size[2],
                           S->dims[0], S->dims[1], pages);
    }
    m0 = unit_metres(o.unit[0]);
    for (k = 0; k < 3; ++k) {
        double m = unit_metres(o.unit[k]);
        if (m == 0.0) {
            return umbra__fail(S->ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: \"%s\": OME unit \"%.15s\" is not a length umbra knows "
                               "(pm, nm, um, mm, cm, m, Angstrom)",
                               S->func, path, o.unit[k]);
        }
        /* In the x unit, so the three axes agree. */
        spacing[k] = o.physical[k] > 0.0 ? (float)(o.physical[k] * m / m0) : 1.0f;
    }
    return UMBRA_SUCCESS;
}

/* The header pass over a single file (nfiles 1: its full-resolution pages) or a list (one page
 * each): sizes, type and spacing, all checked before anything is allocated. */
static umbra_status tiff_header(tiff_stack *S, float spacing[3], size_t *file_bytes)
{
    umbra_status st = UMBRA_SUCCESS;
    size_t f;
    spacing[0] = spacing[1] = spacing[2] = 1.0f;
    *file_bytes = 0;
    if (S->nfiles == 1) {
        const char *path = S->paths[0];
        tdir_t dir = 0;
        uint32_t pages = 0;
        size_t size = 0;
        st = tiff_open(S->ctx, S->func, path, &S->errors, &S->tif, &size);
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        *file_bytes = size;
        S->dirs = malloc(TIFF_MAX_SLICES * sizeof *S->dirs);
        if (!S->dirs) {
            return umbra__fail(S->ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory", S->func);
        }
        do {
            uint32_t subfile = 0;
            tiff_page pg;
            TIFFGetFieldDefaulted(S->tif, TIFFTAG_SUBFILETYPE, &subfile);
            if (subfile & FILETYPE_REDUCEDIMAGE) {
                continue;
            }
            st = read_page(S, path, S->tif, dir, &pg);
            if (st != UMBRA_SUCCESS) {
                return st;
            }
            if (pages == 0) {
                S->page = pg;
            } else if (!same_page(&pg, &S->page)) {
                return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" page %u is %u x %u of %u-bit %s, page %u %u x %u "
                                   "of %u-bit %s: every slice must match",
                                   S->func, path, (unsigned)dir, pg.width, pg.height,
                                   (unsigned)pg.bits, format_name(pg.format), (unsigned)S->dirs[0],
                                   S->page.width, S->page.height, (unsigned)S->page.bits,
                                   format_name(S->page.format));
            }
            if (pages == TIFF_MAX_SLICES) {
                return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" has more than %u pages (the limit)", S->func,
                                   path, TIFF_MAX_SLICES);
            }
            S->dirs[pages++] = dir;
        } while (++dir != 0 && TIFFReadDirectory(S->tif));
        if (S->errors.first[0]) {
            /* TIFFReadDirectory stops on a bad directory as on the last one: say which. */
            return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\" after page %u: %s", S->func,
                               path, (unsigned)(dir - 1), S->errors.first);
        }
        S->dims[0] = S->page.width;
        S->dims[1] = S->page.height;
        S->dims[2] = pages;
        if (!TIFFSetDirectory(S->tif, S->dirs[0])) {
            return umbra__fail(S->ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": cannot return to page %u",
                               S->func, path, (unsigned)S->dirs[0]);
        }
        return ome_spacing(S, path, pages, spacing);
    }
    if (S->nfiles > TIFF_MAX_SLICES) {
        return umbra__fail(S->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "%s: %zu files: at most %u slices", S->func, S->nfiles,
                           TIFF_MAX_SLICES);
    }
    for (f = 0; f < S->nfiles && st == UMBRA_SUCCESS; ++f) {
        TIFF *tif = NULL;
        size_t size = 0;
        tiff_page pg;
        st = tiff_open(S->ctx, S->func, S->paths[f], &S->errors, &tif, &size);
        if (st != UMBRA_SUCCESS) {
            break;
        }
        *file_bytes += size;
        st = read_page(S, S->paths[f], tif, 0, &pg);
        if (st == UMBRA_SUCCESS && TIFFReadDirectory(tif)) {
            st = umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\" has several pages: a list of files takes one page each "
                             "(load a multi-page TIFF by itself)",
                             S->func, S->paths[f]);
        }
        if (st == UMBRA_SUCCESS && f == 0) {
            S->page = pg;
        } else if (st == UMBRA_SUCCESS && !same_page(&pg, &S->page)) {
            st = umbra__fail(S->ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\" is %u x %u of %u-bit %s, \"%s\" %u x %u of %u-bit %s: "
                             "every slice must match",
                             S->func, S->paths[f], pg.width, pg.height, (unsigned)pg.bits,
                             format_name(pg.format), S->paths[0], S->page.width, S->page.height,
                             (unsigned)S->page.bits, format_name(S->page.format));
        }
        TIFFClose(tif);
    }
    S->dims[0] = S->page.width;
    S->dims[1] = S->page.height;
    S->dims[2] = (uint32_t)S->nfiles;
    return st;
}

umbra_status umbra__volume_load_tiff(umbra_context ctx, const char *func, const char *const *paths,
                                     size_t count, umbra_volume *out)
{
    tiff_stack S;
    umbra_status st;
    float spacing[3];
    size_t file_bytes = 0;
    double bytes;

    memset(&S, 0, sizeof S);
    S.ctx = ctx;
    S.func = func;
    S.paths = paths;
    S.nfiles = count;
    st = tiff_header(&S, spacing, &file_bytes);
    if (st != UMBRA_SUCCESS) {
        goto done;
    }
    bytes = (double)S.dims[0] * S.dims[1] * S.dims[2] * (S.page.bits / 8);
    if (bytes > (double)TIFF_MAX_RATIO * (double)file_bytes) {
        st = umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                         "%s: \"%s\"%s: %u x %u x %u samples of %u bits are %.0f bytes, more than "
                         "%u times the %zu bytes of the file%s (deflate's largest expansion)",
                         func, paths[0], count > 1 ? " ..." : "", S.dims[0], S.dims[1], S.dims[2],
                         (unsigned)S.page.bits, bytes, TIFF_MAX_RATIO, file_bytes,
                         count > 1 ? "s" : "");
        goto done;
    }
    S.type = S.page.bits == 32   ? UMBRA_FLOAT32
             : S.page.bits == 8  ? (S.page.format == SAMPLEFORMAT_INT ? UMBRA_INT16 : UMBRA_UINT8)
             : S.page.format == SAMPLEFORMAT_INT ? UMBRA_INT16
                                                 : UMBRA_UINT16;
    st = umbra__volume_from_fill(ctx, fill_tiff, &S, S.type, S.dims, spacing, NULL, NULL, out);

done:
    if (S.tif) {
        TIFFClose(S.tif);
    }
    free(S.dirs);
    return st;
}
