// SPDX-License-Identifier: Apache-2.0
// io/image.cpp: writing and reading images through OpenImageIO.
//
// umbra renders premultiplied linear RGBA floats. EXR stores them as they are. PNG cannot: it
// holds unassociated 8-bit values, by convention sRGB-encoded, so writing un-premultiplies,
// clamps and encodes with the exact piecewise sRGB curve, and reading does the inverse. That work
// is done here rather than by OpenImageIO (whose PNG plugin would premultiply in its own way), so
// the plugin is told the alpha is already unassociated.
//
// This is the library's one C++ file: every entry point is extern "C", catches every exception
// and reports through umbra__fail like the rest of the library.
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "umbra/umbra.h"

#include "io_internal.h"

namespace {

// Larger images are refused as an argument error before any allocation.
const uint32_t max_image_side = 65536;

enum class image_kind { unknown, png, exr };

// The format of path by its extension, case-insensitive; ext receives the extension (for the
// error message).
image_kind kind_of(const char *path, std::string &ext)
{
    const char *slash = std::strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = std::strrchr(base, '.');
    ext.clear();
    if (!dot || dot == base) {
        return image_kind::unknown;
    }
    for (const char *p = dot + 1; *p; ++p) {
        char c = *p;
        ext.push_back((c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c);
    }
    if (ext == "png") {
        return image_kind::png;
    }
    if (ext == "exr") {
        return image_kind::exr;
    }
    return image_kind::unknown;
}

// The sRGB transfer functions (IEC 61966-2-1), piecewise and exact, on [0,1].
float srgb_encode(float linear)
{
    return linear <= 0.0031308f ? 12.92f * linear
                                : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float encoded)
{
    return encoded <= 0.04045f ? encoded / 12.92f
                               : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

// Clamps to [0,1]; NaN becomes 0.
float clamp01(float v)
{
    return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

uint8_t quantize8(float v)
{
    return static_cast<uint8_t>(std::lrint(clamp01(v) * 255.0f));
}

// OpenImageIO keeps a per-thread error string as well as one per ImageInput/ImageOutput; take
// (and so clear) both, so that no error is left pending for OpenImageIO to complain about.
std::string oiio_error(const std::string &own)
{
    std::string global = OIIO::geterror();
    std::string msg = own.empty() ? global : own;
    if (msg.empty()) {
        msg = "OpenImageIO gave no reason";
    }
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) {
        msg.pop_back();
    }
    return msg;
}

umbra_status write_png(umbra_context ctx, const char *path, uint32_t width, uint32_t height,
                       const float *rgba)
{
    const size_t n = static_cast<size_t>(width) * height;
    std::vector<uint8_t> px(4 * n);
    for (size_t i = 0; i < n; ++i) {
        const float *src = rgba + 4 * i;
        float a = src[3];
        for (int c = 0; c < 3; ++c) {
            float v = src[c];
            if (a > 0.0f) {
                v /= a;
            }
            px[4 * i + c] = quantize8(srgb_encode(clamp01(v)));
        }
        px[4 * i + 3] = quantize8(a);
    }

    std::string name(path);
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(name);
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: no PNG writer for \"%s\": %s",
                           path, oiio_error("").c_str());
    }
    OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), 4,
                         OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(name, spec)) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: cannot create \"%s\": %s",
                           path, oiio_error(out->geterror()).c_str());
    }
    bool ok = out->write_image(OIIO::TypeDesc::UINT8, px.data());
    ok = out->close() && ok;
    if (!ok) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: cannot write \"%s\": %s",
                           path, oiio_error(out->geterror()).c_str());
    }
    return UMBRA_SUCCESS;
}

umbra_status write_exr(umbra_context ctx, const char *path, uint32_t width, uint32_t height,
                       const float *rgba)
{
    std::string name(path);
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(name);
    if (!out) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: no EXR writer for \"%s\": %s",
                           path, oiio_error("").c_str());
    }
    OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), 4,
                         OIIO::TypeDesc::FLOAT);
    spec.attribute("oiio:ColorSpace", "Linear");
    if (!out->open(name, spec)) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: cannot create \"%s\": %s",
                           path, oiio_error(out->geterror()).c_str());
    }
    bool ok = out->write_image(OIIO::TypeDesc::FLOAT, rgba);
    ok = out->close() && ok;
    if (!ok) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: cannot write \"%s\": %s",
                           path, oiio_error(out->geterror()).c_str());
    }
    return UMBRA_SUCCESS;
}

umbra_status read_image(umbra_context ctx, const char *path, image_kind kind, uint32_t *width,
                        uint32_t *height, float **rgba)
{
    // Tell a file that cannot be opened (an I/O error) from one OpenImageIO cannot parse, and
    // refuse anything but a regular file before OpenImageIO opens it by name: a FIFO would block
    // it forever.
    std::FILE *probe = nullptr;
    std::size_t probe_size = 0;
    umbra_status st = umbra__file_open(ctx, "umbra_image_read", path, &probe, &probe_size);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    std::fclose(probe);

    // Raw PNG values, un-premultiplied: the sRGB decode must come before premultiplying.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    std::string name(path);
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(name, &config);
    if (!in) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "umbra_image_read: cannot read \"%s\": %s",
                           path, oiio_error("").c_str());
    }
    const OIIO::ImageSpec &spec = in->spec();
    const int nch = spec.nchannels;
    if (spec.deep || spec.depth > 1) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "umbra_image_read: \"%s\" is a deep or volume image", path);
    }
    if (nch < 1 || nch > 4) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "umbra_image_read: \"%s\" has %d channels; 1 to 4 are supported", path,
                           nch);
    }
    if (spec.width < 1 || spec.height < 1 || static_cast<uint32_t>(spec.width) > max_image_side ||
        static_cast<uint32_t>(spec.height) > max_image_side) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "umbra_image_read: \"%s\" is %d x %d; each side must be in 1..%u",
                           path, spec.width, spec.height, max_image_side);
    }
    const uint32_t w = static_cast<uint32_t>(spec.width);
    const uint32_t h = static_cast<uint32_t>(spec.height);
    const size_t n = static_cast<size_t>(w) * h;
    std::vector<float> pixels(n * static_cast<size_t>(nch));
    if (!in->read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, pixels.data())) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "umbra_image_read: cannot read \"%s\": %s",
                           path, oiio_error(in->geterror()).c_str());
    }
    in->close();

    // Channels by count: Y, Y A, R G B, R G B A.
    const bool has_alpha = nch == 2 || nch == 4;
    const int alpha_channel = nch == 2 ? 1 : 3;
    const bool is_png = kind == image_kind::png;
    // Allocated last, with malloc (the caller frees it with free), after everything that may
    // throw, so that it cannot leak.
    float *result = static_cast<float *>(std::malloc(4 * n * sizeof(float)));
    if (!result) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_image_read: cannot allocate %u x %u RGBA floats for \"%s\"", w,
                           h, path);
    }
    for (size_t i = 0; i < n; ++i) {
        const float *src = &pixels[i * static_cast<size_t>(nch)];
        float *dst = result + 4 * i;
        float a = has_alpha ? src[alpha_channel] : 1.0f;
        for (int c = 0; c < 3; ++c) {
            dst[c] = nch < 3 ? src[0] : src[c];
        }
        if (is_png) {
            for (int c = 0; c < 3; ++c) {
                dst[c] = srgb_decode(dst[c]) * a;
            }
        }
        dst[3] = a;
    }
    *width = w;
    *height = h;
    *rgba = result;
    return UMBRA_SUCCESS;
}

} // namespace

extern "C" umbra_status umbra_image_write(umbra_context ctx, const char *path, uint32_t width,
                                          uint32_t height, const float *rgba)
{
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_image_write: path is NULL");
    }
    if (!rgba) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_image_write: rgba is NULL (writing \"%s\")", path);
    }
    if (width < 1 || height < 1 || width > max_image_side || height > max_image_side) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_image_write: size %u x %u: each side must be in 1..%u", width,
                           height, max_image_side);
    }
    try {
        std::string ext;
        switch (kind_of(path, ext)) {
        case image_kind::png:
            return write_png(ctx, path, width, height, rgba);
        case image_kind::exr:
            return write_exr(ctx, path, width, height, rgba);
        case image_kind::unknown:
            break;
        }
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_image_write: \"%s\": unknown extension \"%s\"; supported are "
                           ".png and .exr",
                           path, ext.c_str());
    } catch (const std::bad_alloc &) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_image_write: out of memory writing \"%s\"", path);
    } catch (const std::exception &e) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_write: writing \"%s\": %s", path,
                           e.what());
    } catch (...) {
        return umbra__fail(ctx, UMBRA_ERROR_IO,
                           "umbra_image_write: writing \"%s\": unknown exception", path);
    }
}

extern "C" umbra_status umbra_image_read(umbra_context ctx, const char *path, uint32_t *width,
                                         uint32_t *height, float **rgba)
{
    if (!width || !height || !rgba) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                           "umbra_image_read: width, height or rgba is NULL");
    }
    *width = 0;
    *height = 0;
    *rgba = nullptr;
    if (!path) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "umbra_image_read: path is NULL");
    }
    try {
        std::string ext;
        image_kind kind = kind_of(path, ext);
        if (kind == image_kind::unknown) {
            return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                               "umbra_image_read: \"%s\": unknown extension \"%s\"; supported "
                               "are .png and .exr",
                               path, ext.c_str());
        }
        return read_image(ctx, path, kind, width, height, rgba);
    } catch (const std::bad_alloc &) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                           "umbra_image_read: out of memory reading \"%s\"", path);
    } catch (const std::exception &e) {
        return umbra__fail(ctx, UMBRA_ERROR_IO, "umbra_image_read: reading \"%s\": %s", path,
                           e.what());
    } catch (...) {
        return umbra__fail(ctx, UMBRA_ERROR_IO,
                           "umbra_image_read: reading \"%s\": unknown exception", path);
    }
}
