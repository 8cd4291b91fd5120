// SPDX-License-Identifier: Apache-2.0
/* io/paraview_color.c: the colour spaces of ParaView presets, as VTK's vtkColorTransferFunction
 * blends between two colour nodes: RGB, HSV (vtkMath's hexcone), CIELAB (vtkMath's sRGB / D65
 * conversions), Moreland's diverging Msh blend and Step. Split from io/paraview.c, which parses
 * the presets and evaluates the table. */
#include <math.h>
#include <string.h>

#include "paraview.h"

#define PV_PI 3.14159265358979323846

static double srgb_to_linear(double c)
{
    return c > 0.04045 ? pow((c + 0.055) / 1.055, 2.4) : c / 12.92;
}

static double linear_to_srgb(double c)
{
    return c > 0.0031308 ? 1.055 * pow(c, 1.0 / 2.4) - 0.055 : 12.92 * c;
}

static double lab_f(double t)
{
    return t > 0.008856 ? cbrt(t) : 7.787 * t + 16.0 / 116.0;
}

static double lab_finv(double t)
{
    double t3 = t * t * t;
    return t3 > 0.008856 ? t3 : (t - 16.0 / 116.0) / 7.787;
}

static void rgb_to_lab(const double rgb[3], double lab[3])
{
    double r = srgb_to_linear(rgb[0]), g = srgb_to_linear(rgb[1]), b = srgb_to_linear(rgb[2]);
    double x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.9505;
    double y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    double z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.089;
    double fx = lab_f(x), fy = lab_f(y), fz = lab_f(z);
    lab[0] = 116.0 * fy - 16.0;
    lab[1] = 500.0 * (fx - fy);
    lab[2] = 200.0 * (fy - fz);
}

/* Back to sRGB; colours outside the gamut are scaled down by their largest channel and negative
 * channels clipped, as VTK does. */
static void lab_to_rgb(const double lab[3], double rgb[3])
{
    double fy = (lab[0] + 16.0) / 116.0;
    double x = 0.9505 * lab_finv(lab[1] / 500.0 + fy);
    double y = lab_finv(fy);
    double z = 1.089 * lab_finv(fy - lab[2] / 200.0);
    double c[3], m;
    int i;
    c[0] = 3.2406 * x - 1.5372 * y - 0.4986 * z;
    c[1] = -0.9689 * x + 1.8758 * y + 0.0415 * z;
    c[2] = 0.0557 * x - 0.2040 * y + 1.0570 * z;
    for (i = 0; i < 3; ++i) {
        c[i] = linear_to_srgb(c[i]);
    }
    m = fmax(c[0], fmax(c[1], c[2]));
    for (i = 0; i < 3; ++i) {
        if (m > 1.0) {
            c[i] /= m;
        }
        rgb[i] = c[i] < 0.0 ? 0.0 : c[i];
    }
}

/* vtkMath::RGBToHSV: hue in [0,1), the six sectors of the hexcone. */
static void rgb_to_hsv(const double rgb[3], double hsv[3])
{
    double r = rgb[0], g = rgb[1], b = rgb[2];
    double cmax = fmax(r, fmax(g, b)), cmin = fmin(r, fmin(g, b)), d = cmax - cmin, h = 0.0;
    hsv[2] = cmax;
    hsv[1] = cmax > 0.0 ? d / cmax : 0.0;
    if (hsv[1] > 0.0) {
        if (r == cmax) {
            h = (g - b) / (6.0 * d);
        } else if (g == cmax) {
            h = 1.0 / 3.0 + (b - r) / (6.0 * d);
        } else {
            h = 2.0 / 3.0 + (r - g) / (6.0 * d);
        }
        if (h < 0.0) {
            h += 1.0;
        }
    }
    hsv[0] = h;
}

/* vtkMath::HSVToRGB. */
static void hsv_to_rgb(const double hsv[3], double rgb[3])
{
    const double sixth = 1.0 / 6.0;
    double h = hsv[0], s = hsv[1], v = hsv[2], r, g, b;
    if (h > sixth && h <= 2 * sixth) {
        r = (2 * sixth - h) / sixth, g = 1.0, b = 0.0;
    } else if (h > 2 * sixth && h <= 0.5) {
        r = 0.0, g = 1.0, b = (h - 2 * sixth) / sixth;
    } else if (h > 0.5 && h <= 4 * sixth) {
        r = 0.0, g = (4 * sixth - h) / sixth, b = 1.0;
    } else if (h > 4 * sixth && h <= 5 * sixth) {
        r = (h - 4 * sixth) / sixth, g = 0.0, b = 1.0;
    } else if (h > 5 * sixth && h <= 1.0) {
        r = 1.0, g = 0.0, b = (1.0 - h) / sixth;
    } else {
        r = 1.0, g = h / sixth, b = 0.0;
    }
    rgb[0] = v * (s * r + (1.0 - s));
    rgb[1] = v * (s * g + (1.0 - s));
    rgb[2] = v * (s * b + (1.0 - s));
}

/* vtkColorTransferFunction's HSV blend: hue, saturation and value each linear; with wrap the
 * hue takes the shorter way round (ParaView's default is without). */
static void blend_hsv(const double a[3], const double b[3], double s, int wrap, double out[3])
{
    double h1[3], h2[3], h[3];
    int i;
    rgb_to_hsv(a, h1);
    rgb_to_hsv(b, h2);
    if (wrap && fabs(h1[0] - h2[0]) > 0.5) {
        if (h1[0] > h2[0]) {
            h1[0] -= 1.0;
        } else {
            h2[0] -= 1.0;
        }
    }
    for (i = 0; i < 3; ++i) {
        h[i] = (1.0 - s) * h1[i] + s * h2[i];
    }
    if (h[0] < 0.0) {
        h[0] += 1.0;
    }
    hsv_to_rgb(h, out);
}

/* Moreland's Msh space ("Diverging Color Maps for Scientific Visualization", 2009). */
static void lab_to_msh(const double lab[3], double msh[3])
{
    double m = sqrt(lab[0] * lab[0] + lab[1] * lab[1] + lab[2] * lab[2]);
    msh[0] = m;
    msh[1] = m > 0.001 ? acos(lab[0] / m) : 0.0;
    msh[2] = msh[1] > 0.001 ? atan2(lab[2], lab[1]) : 0.0;
}

static void msh_to_lab(const double msh[3], double lab[3])
{
    lab[0] = msh[0] * cos(msh[1]);
    lab[1] = msh[0] * sin(msh[1]) * cos(msh[2]);
    lab[2] = msh[0] * sin(msh[1]) * sin(msh[2]);
}

static double angle_diff(double a, double b)
{
    const double two_pi = 2.0 * PV_PI;
    double d = fabs(a - b);
    d = fmod(d, two_pi);
    return d > PV_PI ? two_pi - d : d;
}

/* The hue an unsaturated colour of magnitude m should take next to the saturated msh. */
static double adjust_hue(const double msh[3], double m)
{
    double spin;
    if (msh[0] >= m - 0.1) {
        return msh[2];
    }
    spin = msh[1] * sqrt(m * m - msh[0] * msh[0]) / (msh[0] * sin(msh[1]));
    return msh[2] > -0.3 * PV_PI ? msh[2] + spin : msh[2] - spin;
}

static void blend_diverging(const double a[3], const double b[3], double s, double out[3])
{
    double lab1[3], lab2[3], msh1[3], msh2[3], msh[3], lab[3];
    int i;
    rgb_to_lab(a, lab1);
    rgb_to_lab(b, lab2);
    lab_to_msh(lab1, msh1);
    lab_to_msh(lab2, msh2);
    /* Two distinct saturated ends get white (of at least magnitude 88) between them. */
    if (msh1[1] > 0.05 && msh2[1] > 0.05 && angle_diff(msh1[2], msh2[2]) > 0.33 * PV_PI) {
        double mid = fmax(88.0, fmax(msh1[0], msh2[0]));
        if (s < 0.5) {
            msh2[0] = mid;
            msh2[1] = 0.0;
            msh2[2] = 0.0;
            s = 2.0 * s;
        } else {
            msh1[0] = mid;
            msh1[1] = 0.0;
            msh1[2] = 0.0;
            s = 2.0 * s - 1.0;
        }
    }
    /* An unsaturated end has no meaningful hue: borrow one from the other end. */
    if (msh1[1] < 0.05 && msh2[1] > 0.05) {
        msh1[2] = adjust_hue(msh2, msh1[0]);
    } else if (msh2[1] < 0.05 && msh1[1] > 0.05) {
        msh2[2] = adjust_hue(msh1, msh2[0]);
    }
    for (i = 0; i < 3; ++i) {
        msh[i] = (1.0 - s) * msh1[i] + s * msh2[i];
    }
    msh_to_lab(msh, lab);
    lab_to_rgb(lab, out);
}

void umbra__pv_blend(pv_space space, int hsv_wrap, const double a[3], const double b[3], double s,
                     double out[3])
{
    int i;
    if (space == PV_HSV) {
        blend_hsv(a, b, s, hsv_wrap, out);
    } else if (space == PV_LAB) {
        double la[3], lb[3], l[3];
        rgb_to_lab(a, la);
        rgb_to_lab(b, lb);
        for (i = 0; i < 3; ++i) {
            l[i] = (1.0 - s) * la[i] + s * lb[i];
        }
        lab_to_rgb(l, out);
    } else if (space == PV_DIVERGING) {
        blend_diverging(a, b, s, out);
    } else if (space == PV_STEP) {
        /* vtkColorTransferFunction's step: each node's colour holds until the next node. */
        for (i = 0; i < 3; ++i) {
            out[i] = a[i];
        }
    } else {
        for (i = 0; i < 3; ++i) {
            out[i] = (1.0 - s) * a[i] + s * b[i];
        }
    }
}
