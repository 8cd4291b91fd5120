// SPDX-License-Identifier: Apache-2.0
/* tools/umbra_view/present.c: the frame's exact 8-bit sRGB encoding, its texture upload and the
 * window read back into a PNG (present.h). GL 1.1 calls only, which libGL exports. */
#include <GL/gl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "present.h"

/* The PNG encoding of io/image.cpp, value by value: clamp, the piecewise sRGB curve
 * (IEC 61966-2-1), clamp, round to 8 bits. The tables below are built from it, so a window pixel
 * equals the PNG's byte. */
static float clamp01(float v)
{
    return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

static uint8_t encode_direct(float linear)
{
    float v = clamp01(linear);
    float e = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)lrintf(clamp01(e) * 255.0f);
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

void present_init(present *p)
{
    memset(p, 0, sizeof *p);
    /* Non-negative floats order like their bit patterns: bisect on those for the least value of
     * each code. The encoding never falls as the value rises. */
    p->threshold[0] = 0.0f;
    for (int k = 1; k <= 255; ++k) {
        uint32_t lo = 0, hi = float_bits(1.0f);
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (encode_direct(bits_float(mid)) >= k)
                hi = mid;
            else
                lo = mid + 1;
        }
        p->threshold[k] = bits_float(lo);
    }
    p->threshold[256] = INFINITY;
    for (int s = 0; s < 1024; ++s)
        p->start[s] = encode_direct((float)s / 1024.0f);
}

void present_release(present *p)
{
    if (p->texture) {
        GLuint t = p->texture;
        glDeleteTextures(1, &t);
    }
    free(p->rgba8);
    memset(p, 0, sizeof *p);
}

uint8_t present_encode(const present *p, float linear)
{
    if (!(linear > 0.0f))
        return 0;
    if (linear >= 1.0f)
        return 255;
    int k = p->start[(int)(linear * 1024.0f)];
    while (linear >= p->threshold[k + 1])
        ++k;
    return (uint8_t)k;
}

int present_upload(present *p, const float *rgba, uint32_t w, uint32_t h)
{
    size_t n = (size_t)w * h;
    if (w != p->width || h != p->height || !p->rgba8) {
        uint8_t *buf = malloc(4 * n);
        if (!buf)
            return -1;
        free(p->rgba8);
        p->rgba8 = buf;
    }
    for (size_t i = 0; i < n; ++i) {
        const float *s = rgba + 4 * i;
        float a = s[3];
        for (int c = 0; c < 3; ++c)
            p->rgba8[4 * i + c] = present_encode(p, a > 0.0f ? s[c] / a : s[c]);
        p->rgba8[4 * i + 3] = (uint8_t)lrintf(clamp01(a) * 255.0f);
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (!p->texture || w != p->width || h != p->height) {
        GLuint t = p->texture;
        if (!t)
            glGenTextures(1, &t);
        glBindTexture(GL_TEXTURE_2D, t);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, (GLsizei)w, (GLsizei)h, 0, GL_RGBA,
                     GL_UNSIGNED_BYTE, p->rgba8);
        p->texture = t;
        p->width = w;
        p->height = h;
    } else {
        glBindTexture(GL_TEXTURE_2D, p->texture);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, (GLsizei)w, (GLsizei)h, GL_RGBA,
                        GL_UNSIGNED_BYTE, p->rgba8);
    }
    return 0;
}

umbra_status present_write_window(const present *p, umbra_context ctx, const char *path,
                                  uint32_t w, uint32_t h)
{
    size_t n = (size_t)w * h;
    uint8_t *px = malloc(4 * n);
    float *rgba = malloc(16 * n);
    umbra_status st;
    if (!px || !rgba) {
        st = umbra_context_record_error(ctx, UMBRA_ERROR_OUT_OF_MEMORY,
                                        "present_write_window: out of memory for the window's "
                                        "pixels");
        goto done;
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, (GLsizei)w, (GLsizei)h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    /* A value inside each code's interval, so that umbra_image_write's encoding gives the byte
     * back; GL's rows run bottom-up, the image's top-down; the window is opaque. */
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const uint8_t *s = px + 4 * ((size_t)(h - 1 - y) * w + x);
            float *d = rgba + 4 * ((size_t)y * w + x);
            for (int c = 0; c < 3; ++c) {
                int k = s[c];
                d[c] = k == 255 ? 1.0f : 0.5f * (p->threshold[k] + p->threshold[k + 1]);
            }
            d[3] = 1.0f;
        }
    st = umbra_image_write(ctx, path, w, h, rgba);
done:
    free(px);
    free(rgba);
    return st;
}
