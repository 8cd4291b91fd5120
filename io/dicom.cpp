// SPDX-License-Identifier: Apache-2.0
/* io/dicom.cpp: volumes from DICOM: a series (a list of files, or a directory's files, see
 * io/series.c) or one single-frame file.
 *
 * A series is read in two passes. The first walks each file's structure with umbra's own bounded
 * parser (io/dicom_parse.c) and checks that the files make one volume: one SeriesInstanceUID, one
 * size, one pixel layout (greyscale, 8 or 16 bits allocated), one orientation
 * (ImageOrientationPatient) and pixel spacing. Slices are sorted by their position
 * (ImagePositionPatient) along the slice normal, row direction x column direction, and must lie
 * on one line along it (no gantry tilt: that would be a sheared grid) at uniform steps (each
 * within 1% of a step of its place; missing slices or mixed thicknesses are refused, naming the
 * slice): the spacing is that step, not SliceThickness. The world transform is DICOM's patient
 * space (LPS millimetres) as written: origin the first slice's position, index axes the row
 * direction, the column direction and the normal; spacing x the column spacing (PixelSpacing[1]),
 * y the row spacing (PixelSpacing[0]). The second pass reads each slice's pixels (uncompressed:
 * straight from the file; RLE Lossless: decoded here) and converts them into the volume's buffer.
 *
 * Why no DICOM library. Debian 12's GDCM (libgdcm-dev 3.0.21) was tried first and cannot take
 * untrusted files: it is built with its assertions on, and its parser aborts the process on a file
 * cut inside an element header (gdcm::ExplicitDataElement::ReadPreValue); libFuzzer on
 * tests/fuzz/fuzz_volume then found its RLE decoder reading past its input (a SEGV in
 * gdcm::RLECodec::DecodeByStreams, seed regress_gdcm_rle_overread) and its JPEG decoder
 * dereferencing NULL (gdcm::JPEGCodec::Decode, seed regress_gdcm_jpeg_null) within two minutes
 * each. So umbra reads the structure and RLE itself, bounded, and refuses JPEG, JPEG-LS and
 * JPEG 2000 data as unsupported, naming the transfer syntax.
 *
 * Values: each slice's RescaleSlope and RescaleIntercept are applied (per slice). Without any
 * rescale the stored type is kept (uint8, uint16, int16; int8 becomes int16). With integer slopes
 * and intercepts the voxels are int16 when the rescaled values fit (known from BitsStored, or else
 * from one extra decoding pass that finds the actual range), otherwise float32; a fractional slope
 * or intercept gives float32. Multi-frame files are refused (their frames are placed by
 * functional groups this reader does not read).
 *
 * Hostile files: uncompressed pixel data must hold every pixel, and compressed pixel data may
 * claim at most 1032 times its bytes, before anything is allocated; at most 65536 files. */
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sys/types.h>
#include <new>
#include <set>
#include <string>
#include <vector>

#include "dicom.h"

namespace {

constexpr size_t DICOM_MAX_FILES = 65536;
constexpr const char *RLE_LOSSLESS = "1.2.840.10008.1.2.5";
constexpr double DICOM_MAX_RATIO = 1032.0;
/* A slice may sit at most this fraction of the step from its place on the uniform grid. */
constexpr double DICOM_POSITION_TOLERANCE = 0.01;

/* One file's header, as the first pass reads it. */
struct slice_header {
    std::string path, series, photometric, syntax;
    unsigned rows = 0, cols = 0, bits_allocated = 0, bits_stored = 0, high_bit = 0;
    unsigned pixel_rep = 0, samples = 1, frames = 1;
    bool has_position = false, has_orientation = false, has_spacing = false;
    double position[3] = {0, 0, 0}, orientation[6] = {1, 0, 0, 0, 1, 0}, spacing[2] = {1, 1};
    double slope = 1.0, intercept = 0.0, thickness = 0.0;
    bool encapsulated = false;
    size_t file_bytes = 0;
    uint64_t pixel_offset = 0, pixel_length = 0;             /* uncompressed */
    std::vector<std::pair<uint64_t, uint64_t>> fragments;    /* compressed: offset, length */
    double depth = 0.0; /* position along the slice normal */
};

struct dicom_load {
    umbra_context ctx;
    const char *func;
    std::vector<slice_header> slices; /* sorted */
    umbra_scalar_type type = UMBRA_UINT8;
    bool rescale = false;
    uint32_t dims[3] = {0, 0, 0};
};

/* The first pass over one file: umbra's walk over its structure (io/dicom_parse.c), then what
 * the volume needs of it. */
umbra_status read_header(umbra_context ctx, const char *func, const std::string &path,
                         slice_header &h)
{
    umbra__dicom_file d;
    umbra_status st = umbra__dicom_parse(ctx, func, path.c_str(), &d);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    h.path = path;
    h.file_bytes = (size_t)d.file_bytes;
    h.syntax = d.syntax;
    h.encapsulated = d.encapsulated != 0;
    h.series = d.series;
    h.photometric = d.photometric;
    h.rows = d.rows, h.cols = d.cols, h.frames = d.frames, h.samples = d.samples;
    h.bits_allocated = d.bits_allocated, h.bits_stored = d.bits_stored;
    h.pixel_rep = d.pixel_rep;
    h.high_bit = d.has_high_bit ? d.high_bit : (d.bits_stored ? d.bits_stored - 1 : 0);
    h.has_position = d.has_position != 0, h.has_orientation = d.has_orientation != 0;
    h.has_spacing = d.has_spacing != 0;
    std::memcpy(h.position, d.position, sizeof h.position);
    if (d.has_orientation) {
        std::memcpy(h.orientation, d.orientation, sizeof h.orientation);
    }
    if (d.has_spacing) {
        std::memcpy(h.spacing, d.spacing, sizeof h.spacing);
    }
    h.slope = d.slope, h.intercept = d.intercept, h.thickness = d.thickness;
    h.pixel_offset = d.pixel_offset;
    h.pixel_length = d.pixel_length;
    h.fragments.clear();
    for (size_t i = 0; i < d.fragments; ++i) {
        h.fragments.emplace_back(d.fragment_offset[i], d.fragment_length[i]);
    }
    umbra__dicom_file_free(&d);

    const char *missing = !d.has_rows             ? "Rows (0028,0010)"
                          : !d.has_cols           ? "Columns (0028,0011)"
                          : !d.has_bits_allocated ? "BitsAllocated (0028,0100)"
                          : !d.has_bits_stored    ? "BitsStored (0028,0101)"
                          : !d.has_pixel_rep      ? "PixelRepresentation (0028,0103)"
                                                  : nullptr;
    if (missing) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": %s is missing", func,
                           path.c_str(), missing);
    }
    if (d.has_float_pixels) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\" holds float pixel data (7FE0,0008/0009): umbra reads "
                           "integer pixel data",
                           func, path.c_str());
    }
    if (h.rows == 0 || h.cols == 0 || h.frames == 0) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": %u rows x %u columns x %u frames (NumberOfFrames must be "
                           "1..65536)",
                           func, path.c_str(), h.rows, h.cols, h.frames);
    }
    if (h.samples != 1 || (!h.photometric.empty() && h.photometric != "MONOCHROME1" &&
                           h.photometric != "MONOCHROME2")) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": %u samples per pixel, PhotometricInterpretation "
                           "\"%.32s\": umbra reads greyscale (MONOCHROME1/2) images",
                           func, path.c_str(), h.samples, h.photometric.c_str());
    }
    if ((h.bits_allocated != 8 && h.bits_allocated != 16) || h.bits_stored == 0 ||
        h.bits_stored > h.bits_allocated || h.high_bit != h.bits_stored - 1 || h.pixel_rep > 1) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": BitsAllocated %u, BitsStored %u, HighBit %u, "
                           "PixelRepresentation %u: umbra reads 8 or 16 bits allocated, stored "
                           "from bit 0",
                           func, path.c_str(), h.bits_allocated, h.bits_stored, h.high_bit,
                           h.pixel_rep);
    }
    if (h.frames > 1) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\" has %u frames: umbra reads series of single-frame images "
                           "(multi-frame files place their frames in functional groups it does "
                           "not read)",
                           func, path.c_str(), h.frames);
    }
    if (h.has_spacing && !(h.spacing[0] > 0 && h.spacing[1] > 0)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": PixelSpacing %g\\%g must be > 0",
                           func, path.c_str(), h.spacing[0], h.spacing[1]);
    }
    if (h.slope == 0.0) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: \"%s\": RescaleSlope is 0", func,
                           path.c_str());
    }
    if (h.encapsulated && h.syntax != RLE_LOSSLESS) {
        return umbra__fail(ctx, UMBRA_ERROR_UNSUPPORTED,
                           "%s: \"%s\": transfer syntax %s (JPEG, JPEG-LS or JPEG 2000) is not "
                           "decoded: the decoders at hand (GDCM's) crash on malformed data; "
                           "decompress the series first (gdcmconv --raw, dcmdjpeg)",
                           func, path.c_str(), h.syntax.c_str());
    }
    /* The pixel data's claim against the file, before anything is allocated. */
    double claim = (double)h.rows * h.cols * h.frames * (h.bits_allocated / 8);
    double have = 0;
    if (h.encapsulated) {
        for (const auto &fr : h.fragments) {
            have += (double)fr.second;
        }
    } else {
        have = (double)h.pixel_length;
    }
    if ((!h.encapsulated && claim > have) || (h.encapsulated && claim > DICOM_MAX_RATIO * have)) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": %u x %u x %u pixels of %u bits are %.0f bytes, but the "
                           "pixel data holds %s%.0f bytes (truncated file?)",
                           func, path.c_str(), h.cols, h.rows, h.frames, h.bits_allocated, claim,
                           h.encapsulated ? "(compressed at most 1032:1) " : "", have);
    }
    return UMBRA_SUCCESS;
}

void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The stored value range of a slice's pixel layout. */
void stored_range(const slice_header &h, double *lo, double *hi)
{
    if (h.pixel_rep) {
        *lo = -std::ldexp(1.0, (int)h.bits_stored - 1);
        *hi = std::ldexp(1.0, (int)h.bits_stored - 1) - 1;
    } else {
        *lo = 0;
        *hi = std::ldexp(1.0, (int)h.bits_stored) - 1;
    }
}

/* Reads count bytes at offset of path into dst. */
umbra_status read_bytes(dicom_load &L, const std::string &path, FILE *f, uint64_t offset,
                        size_t count, char *dst)
{
    if (fseeko(f, (off_t)offset, SEEK_SET) != 0 || std::fread(dst, 1, count, f) != count) {
        return umbra__fail(L.ctx, UMBRA_ERROR_IO,
                           "%s: \"%s\" ended before its pixel data (changed since its header was "
                           "read?)",
                           L.func, path.c_str());
    }
    return UMBRA_SUCCESS;
}

/* DICOM RLE Lossless (PS3.5 annex G) of one frame, decoded by umbra (see the top of the file). The fragment starts
 * with 16 little-endian uint32: the segment count (one per byte of a sample, most significant
 * first) and each segment's offset; each segment is PackBits of rows x columns bytes. Returns
 * NULL on success, else what is wrong. */
const char *rle_decode(const std::vector<char> &in, const slice_header &h, char *out)
{
    const size_t n = (size_t)h.rows * h.cols, planes = h.bits_allocated / 8;
    const unsigned char *p = reinterpret_cast<const unsigned char *>(in.data());
    uint32_t header[16];
    if (in.size() < 64) {
        return "the RLE header is cut short";
    }
    for (int i = 0; i < 16; ++i) {
        header[i] = (uint32_t)p[4 * i] | (uint32_t)p[4 * i + 1] << 8 |
                    (uint32_t)p[4 * i + 2] << 16 | (uint32_t)p[4 * i + 3] << 24;
    }
    if (header[0] != planes) {
        return "the RLE segment count does not match BitsAllocated";
    }
    for (size_t s = 0; s < planes; ++s) {
        size_t at = header[1 + s], end = s + 1 < planes ? header[2 + s] : in.size(), got = 0;
        if (at < 64 || at > end || end > in.size()) {
            return "an RLE segment offset lies outside the fragment";
        }
        while (got < n) {
            if (at >= end) {
                return "an RLE segment ends before its plane is full";
            }
            int c = (signed char)p[at++];
            if (c >= 0) {
                size_t run = (size_t)c + 1;
                if (run > end - at || run > n - got) {
                    return "an RLE literal run overruns its segment or plane";
                }
                for (size_t k = 0; k < run; ++k, ++got) {
                    out[got * planes + (planes - 1 - s)] = (char)p[at + k];
                }
                at += run;
            } else if (c != -128) {
                size_t run = (size_t)(1 - c);
                if (at >= end || run > n - got) {
                    return "an RLE replicate run overruns its segment or plane";
                }
                for (size_t k = 0; k < run; ++k, ++got) {
                    out[got * planes + (planes - 1 - s)] = (char)p[at];
                }
                ++at;
            }
        }
    }
    return nullptr;
}

/* One file's pixels into buf (resized): uncompressed read straight from the file, RLE decoded
 * here from the fragment umbra located; other compressed syntaxes refused (see the top). */
umbra_status decode(dicom_load &L, const slice_header &h, std::vector<char> &buf)
{
    size_t want = (size_t)h.rows * h.cols * h.frames * (h.bits_allocated / 8);
    FILE *f = nullptr;
    size_t size = 0;
    umbra_status st = umbra__file_open(L.ctx, L.func, h.path.c_str(), &f, &size);
    if (st != UMBRA_SUCCESS) {
        return st;
    }
    if (size != h.file_bytes) {
        std::fclose(f);
        return umbra__fail(L.ctx, UMBRA_ERROR_IO, "%s: \"%s\" changed size since it was read",
                           L.func, h.path.c_str());
    }
    buf.resize(want);
    if (!h.encapsulated) {
        st = read_bytes(L, h.path, f, h.pixel_offset, want, buf.data());
        std::fclose(f);
        if (st == UMBRA_SUCCESS && h.bits_allocated == 16 && umbra__host_is_big_endian()) {
            umbra__swap_bytes(buf.data(), want / 2, 2);
        }
        return st;
    }
    if (h.syntax == RLE_LOSSLESS) {
        std::vector<char> frag;
        const char *why = h.fragments.size() == 1 ? nullptr
                                                  : "RLE has one fragment per frame, the file more";
        if (!why) {
            frag.resize((size_t)h.fragments[0].second);
            st = read_bytes(L, h.path, f, h.fragments[0].first, frag.size(), frag.data());
        }
        std::fclose(f);
        if (st == UMBRA_SUCCESS && !why) {
            why = rle_decode(frag, h, buf.data());
        }
        if (st == UMBRA_SUCCESS && why) {
            st = umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                             "%s: \"%s\": cannot decode the RLE pixel data: %s", L.func,
                             h.path.c_str(), why);
        }
        if (st == UMBRA_SUCCESS && h.bits_allocated == 16 && umbra__host_is_big_endian()) {
            umbra__swap_bytes(buf.data(), want / 2, 2);
        }
        return st;
    }
    std::fclose(f);
    return umbra__fail(L.ctx, UMBRA_ERROR_UNSUPPORTED, "%s: \"%s\": transfer syntax %s", L.func,
                       h.path.c_str(), h.syntax.c_str()); /* read_header refused it already */
}

/* Stored sample i of a decoded buffer, masked to BitsStored (and sign-extended). */
double stored_value(const slice_header &h, const char *buf, size_t i)
{
    uint32_t raw;
    if (h.bits_allocated == 8) {
        raw = (unsigned char)buf[i];
    } else {
        uint16_t v;
        std::memcpy(&v, buf + 2 * i, 2);
        raw = v;
    }
    raw &= (uint32_t)((1ull << h.bits_stored) - 1);
    if (h.pixel_rep && (raw >> (h.bits_stored - 1)) & 1u) {
        return (double)raw - std::ldexp(1.0, (int)h.bits_stored);
    }
    return (double)raw;
}

/* Converts n samples of buf into dst of L.type, applying slope and intercept. Returns false on a
 * value that does not fit (only possible for float32 beyond its range). */
bool convert(const dicom_load &L, const slice_header &h, const char *buf, size_t n, double slope,
             double intercept, void *dst)
{
    for (size_t i = 0; i < n; ++i) {
        double v = stored_value(h, buf, i) * slope + intercept;
        /* The type was chosen so that every value fits; clamped all the same, so that a file
         * changed between the passes cannot make a conversion undefined. */
        switch (L.type) {
        case UMBRA_UINT8: static_cast<uint8_t *>(dst)[i] = (uint8_t)std::clamp(v, 0.0, 255.0); break;
        case UMBRA_UINT16:
            static_cast<uint16_t *>(dst)[i] = (uint16_t)std::clamp(v, 0.0, 65535.0);
            break;
        case UMBRA_INT16:
            static_cast<int16_t *>(dst)[i] = (int16_t)std::clamp(v, -32768.0, 32767.0);
            break;
        default: {
            float fv = (float)v;
            if (!std::isfinite(fv)) {
                return false;
            }
            static_cast<float *>(dst)[i] = fv;
        }
        }
    }
    return true;
}

umbra_status fill_dicom(void *user, void *dst, size_t bytes)
{
    dicom_load &L = *static_cast<dicom_load *>(user);
    size_t per_file = (size_t)L.dims[0] * L.dims[1];
    size_t type_size = umbra_scalar_type_size(L.type);
    std::vector<char> buf;
    (void)bytes;
    try {
        for (size_t k = 0; k < L.slices.size(); ++k) {
            const slice_header &h = L.slices[k];
            umbra_status st = decode(L, h, buf);
            if (st != UMBRA_SUCCESS) {
                return st;
            }
            if (!convert(L, h, buf.data(), per_file, h.slope, h.intercept,
                         static_cast<char *>(dst) + k * per_file * type_size)) {
                return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\": a rescaled value is beyond float32", L.func,
                                   L.slices[k].path.c_str());
            }
        }
    } catch (const std::bad_alloc &) {
        return umbra__fail(L.ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory decoding DICOM",
                           L.func);
    } catch (const std::exception &e) {
        return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT, "%s: reading DICOM failed: %.200s", L.func, e.what());
    }
    return UMBRA_SUCCESS;
}

/* Chooses the voxel type (see the top of the file); may decode every slice once to find the
 * rescaled range. */
umbra_status choose_type(dicom_load &L)
{
    const slice_header &h0 = L.slices[0];
    bool integral = true;
    double lo = 0, hi = 0, slo, shi;
    L.rescale = false;
    stored_range(h0, &slo, &shi);
    for (const slice_header &h : L.slices) {
        L.rescale |= h.slope != 1.0 || h.intercept != 0.0;
        integral &= h.slope == std::floor(h.slope) && h.intercept == std::floor(h.intercept);
        double a = h.slope * slo + h.intercept, b = h.slope * shi + h.intercept;
        lo = std::min(lo, std::min(a, b));
        hi = std::max(hi, std::max(a, b));
    }
    if (!L.rescale) {
        L.type = h0.bits_allocated == 8 ? (h0.pixel_rep ? UMBRA_INT16 : UMBRA_UINT8)
                                        : (h0.pixel_rep ? UMBRA_INT16 : UMBRA_UINT16);
        return UMBRA_SUCCESS;
    }
    if (!integral) {
        L.type = UMBRA_FLOAT32;
        return UMBRA_SUCCESS;
    }
    if (lo >= -32768 && hi <= 32767) {
        L.type = UMBRA_INT16;
        return UMBRA_SUCCESS;
    }
    /* The declared range does not fit int16: the actual values may (a CT in 16 stored bits). */
    std::vector<char> buf;
    size_t n = (size_t)L.dims[0] * L.dims[1];
    lo = 0, hi = 0;
    bool first = true;
    for (const slice_header &h : L.slices) {
        umbra_status st = decode(L, h, buf);
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        for (size_t i = 0; i < n; ++i) {
            double v = stored_value(h, buf.data(), i) * h.slope + h.intercept;
            if (first || v < lo) {
                lo = v;
            }
            if (first || v > hi) {
                hi = v;
            }
            first = false;
        }
    }
    L.type = lo >= -32768 && hi <= 32767 ? UMBRA_INT16 : UMBRA_FLOAT32;
    return UMBRA_SUCCESS;
}

/* Orders the slices along their normal and derives the geometry (see the top of the file). */
umbra_status assemble(dicom_load &L, float spacing[3], float origin[3], float directions[9],
                      bool *placed)
{
    std::vector<slice_header> &s = L.slices;
    const slice_header &a = s[0];
    for (size_t k = 0; k < s.size() && s.size() > 1; ++k) {
        if (!s[k].has_position || !s[k].has_orientation) {
            return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\" has no ImagePositionPatient / "
                               "ImageOrientationPatient: the slices of a series cannot be "
                               "ordered without them",
                               L.func, s[k].path.c_str());
        }
    }
    for (size_t k = 1; k < s.size(); ++k) {
        const slice_header &b = s[k];
        if (b.series != a.series) {
            return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\" is of series \"%.64s\", \"%s\" of \"%.64s\": a volume "
                               "is one series (SeriesInstanceUID); load each by itself",
                               L.func, b.path.c_str(), b.series.c_str(), a.path.c_str(),
                               a.series.c_str());
        }
        if (b.rows != a.rows || b.cols != a.cols || b.bits_allocated != a.bits_allocated ||
            b.bits_stored != a.bits_stored || b.pixel_rep != a.pixel_rep) {
            return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                               "%s: \"%s\" is %u x %u of %u/%u bits (%s), \"%s\" %u x %u of %u/%u "
                               "bits (%s): every slice of a series must match",
                               L.func, b.path.c_str(), b.cols, b.rows, b.bits_stored,
                               b.bits_allocated, b.pixel_rep ? "signed" : "unsigned",
                               a.path.c_str(), a.cols, a.rows, a.bits_stored, a.bits_allocated,
                               a.pixel_rep ? "signed" : "unsigned");
        }
        if (b.frames != 1 || a.frames != 1) {
            return umbra__fail(L.ctx, UMBRA_ERROR_UNSUPPORTED,
                               "%s: \"%s\" has %u frames: a multi-frame file is loaded by itself",
                               L.func, (b.frames != 1 ? b : a).path.c_str(),
                               b.frames != 1 ? b.frames : a.frames);
        }
        for (int i = 0; i < 6; ++i) {
            if (std::fabs(b.orientation[i] - a.orientation[i]) > 1e-4 ||
                b.has_orientation != a.has_orientation) {
                return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" and \"%s\" differ in ImageOrientationPatient: a "
                                   "volume has one orientation",
                                   L.func, b.path.c_str(), a.path.c_str());
            }
        }
        for (int i = 0; i < 2; ++i) {
            if (std::fabs(b.spacing[i] - a.spacing[i]) > 1e-4 * a.spacing[i]) {
                return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" has PixelSpacing %g\\%g, \"%s\" %g\\%g", L.func,
                                   b.path.c_str(), b.spacing[0], b.spacing[1], a.path.c_str(),
                                   a.spacing[0], a.spacing[1]);
            }
        }
    }
    double row[3] = {a.orientation[0], a.orientation[1], a.orientation[2]};
    double col[3] = {a.orientation[3], a.orientation[4], a.orientation[5]};
    double normal[3];
    cross(row, col, normal);
    double nlen = std::sqrt(dot(normal, normal));
    if (!(nlen > 0.5)) {
        return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                           "%s: \"%s\": ImageOrientationPatient %g\\%g\\%g\\%g\\%g\\%g is not two "
                           "unit directions at a right angle",
                           L.func, a.path.c_str(), row[0], row[1], row[2], col[0], col[1],
                           col[2]);
    }
    for (double &v : normal) {
        v /= nlen;
    }
    spacing[0] = (float)a.spacing[1];
    spacing[1] = (float)a.spacing[0];
    spacing[2] = a.thickness > 0 ? (float)a.thickness : 1.0f;
    *placed = a.has_position && a.has_orientation;
    if (s.size() > 1) {
        for (slice_header &h : s) {
            h.depth = dot(h.position, normal);
        }
        std::stable_sort(s.begin(), s.end(), [](const slice_header &x, const slice_header &y) {
            return x.depth < y.depth;
        });
        size_t n = s.size();
        double step = (s[n - 1].depth - s[0].depth) / (double)(n - 1);
        for (size_t k = 1; k < n; ++k) {
            if (!(s[k].depth - s[k - 1].depth > 1e-3 * std::min(a.spacing[0], a.spacing[1]))) {
                return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" and \"%s\" lie at the same position along the "
                                   "slice normal (%g): several acquisitions, echoes or time "
                                   "points in one series? Load them apart",
                                   L.func, s[k - 1].path.c_str(), s[k].path.c_str(), s[k].depth);
            }
        }
        for (size_t k = 0; k < n; ++k) {
            double want = s[0].depth + step * (double)k;
            if (std::fabs(s[k].depth - want) > DICOM_POSITION_TOLERANCE * step) {
                double gap = s[k > 0 ? k : 1].depth - s[k > 0 ? k - 1 : 0].depth;
                return umbra__fail(L.ctx, UMBRA_ERROR_FORMAT,
                                   "%s: \"%s\" lies at %g along the slice normal, %g from its "
                                   "place on the uniform grid of step %g (gap to the previous "
                                   "slice %g): slices must be uniformly spaced (a missing slice, "
                                   "or mixed spacing? resample first)",
                                   L.func, s[k].path.c_str(), s[k].depth, s[k].depth - want, step,
                                   gap);
            }
            double off[3];
            for (int i = 0; i < 3; ++i) {
                off[i] = s[k].position[i] - s[0].position[i] - (s[k].depth - s[0].depth) * normal[i];
            }
            if (std::sqrt(dot(off, off)) > DICOM_POSITION_TOLERANCE * step) {
                return umbra__fail(L.ctx, UMBRA_ERROR_UNSUPPORTED,
                                   "%s: \"%s\" is offset %g within the slice plane from the first "
                                   "slice: the slices do not stack along their normal (a tilted "
                                   "gantry makes a sheared grid; resample first)",
                                   L.func, s[k].path.c_str(), std::sqrt(dot(off, off)));
            }
        }
        spacing[2] = (float)step;
    }
    for (int i = 0; i < 3; ++i) {
        origin[i] = (float)s[0].position[i];
        directions[i] = (float)row[i];
        directions[3 + i] = (float)col[i];
        directions[6 + i] = (float)normal[i];
    }
    L.dims[0] = a.cols;
    L.dims[1] = a.rows;
    L.dims[2] = (uint32_t)s.size();
    return UMBRA_SUCCESS;
}

} // namespace

extern "C" umbra_status umbra__volume_load_dicom(umbra_context ctx, const char *func,
                                                 const char *const *paths, size_t count,
                                                 umbra_volume *out)
{
    dicom_load L;
    L.ctx = ctx;
    L.func = func;
    float spacing[3], origin[3], directions[9];
    bool placed = false;
    if (count > DICOM_MAX_FILES) {
        return umbra__fail(ctx, UMBRA_ERROR_INVALID_ARGUMENT, "%s: %zu files: at most %zu", func,
                           count, DICOM_MAX_FILES);
    }
    try {
        L.slices.resize(count);
        for (size_t k = 0; k < count; ++k) {
            umbra_status st = read_header(ctx, func, paths[k], L.slices[k]);
            if (st != UMBRA_SUCCESS) {
                return st;
            }
        }
        umbra_status st = assemble(L, spacing, origin, directions, &placed);
        if (st == UMBRA_SUCCESS) {
            st = choose_type(L);
        }
        if (st != UMBRA_SUCCESS) {
            return st;
        }
        return umbra__volume_from_fill(ctx, fill_dicom, &L, L.type, L.dims, spacing,
                                       placed ? origin : nullptr, placed ? directions : nullptr,
                                       out);
    } catch (const std::bad_alloc &) {
        return umbra__fail(ctx, UMBRA_ERROR_OUT_OF_MEMORY, "%s: out of memory reading DICOM",
                           func);
    } catch (const std::exception &e) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: reading DICOM failed: %.200s", func, e.what());
    } catch (...) {
        return umbra__fail(ctx, UMBRA_ERROR_FORMAT, "%s: reading DICOM failed", func);
    }
}
