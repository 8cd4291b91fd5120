// SPDX-License-Identifier: Apache-2.0
/* data.cpp: Volume, VolumeInfo and TransferFunction, the data a renderer draws, bound with NumPy
 * arrays in: a volume from a (z, y, x) array with its spacing and, optionally, its index-to-world
 * transform (origin and axis directions, as a NIfTI affine or a NRRD's space directions give
 * them); a transfer function from a table or control points, optionally over a data range, or
 * from a ParaView preset. Split from objects.cpp (Context, Renderer, Scene) to keep each file
 * readable. */
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "binding.h"

namespace umbra_py
{

namespace
{

using vec3 = std::array<float, 3>;
using range_t = std::pair<float, float>;

/* ---- voxel types ----------------------------------------------------------------------------
 * umbra stores uint8, uint16, int16 and float32; an array of one of them is read in place. Any
 * other real, integer or bool array is converted once into the nearest of them (the rule the
 * Volume docstring and the README state): bool -> uint8 (read in place); float16 and float64 ->
 * float32; every other integer type -> the first of uint8, uint16, int16 that holds all its
 * values, else float32. The conversion writes through umbra_volume_create_filled: on a CPU device
 * straight into the device's mapped buffer, elsewhere into the host buffer umbra uploads from:
 * no copy is made here. */

using convert_fn = void (*)(const void *src, size_t n, void *dst);

struct voxels {
    umbra_scalar_type type = UMBRA_FLOAT32;
    const void *data = nullptr;  /* read in place, or the source of convert */
    size_t count = 0;
    convert_fn convert = nullptr; /* null: in place */
    umbra_context ctx = nullptr;
};

template <class T, class S> void cast_all(const void *src, size_t n, void *dst)
{
    const S *in = static_cast<const S *>(src);
    T *out = static_cast<T *>(dst);
    for (size_t i = 0; i < n; ++i)
        out[i] = static_cast<T>(in[i]);
}

/* Integers into the narrowest stored type that keeps every value exactly, else float32
 * (exact up to 2^24 in magnitude, rounded to nearest beyond). */
template <class S> void from_integers(voxels &v, const S *src, size_t n)
{
    S lo = n ? src[0] : 0, hi = lo;
    for (size_t i = 1; i < n; ++i) {
        lo = src[i] < lo ? src[i] : lo;
        hi = src[i] > hi ? src[i] : hi;
    }
    /* Compared as long double so that uint64 and int64 bounds compare exactly. */
    long double l = (long double)lo, h = (long double)hi;
    if (l >= 0 && h <= UINT8_MAX)
        v.type = UMBRA_UINT8, v.convert = cast_all<uint8_t, S>;
    else if (l >= 0 && h <= UINT16_MAX)
        v.type = UMBRA_UINT16, v.convert = cast_all<uint16_t, S>;
    else if (l >= INT16_MIN && h <= INT16_MAX)
        v.type = UMBRA_INT16, v.convert = cast_all<int16_t, S>;
    else
        v.type = UMBRA_FLOAT32, v.convert = cast_all<float, S>;
}

/* IEEE half to float, exactly (infinities and NaN carried, for umbra_volume_create to name). */
float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, exp = (h >> 10) & 0x1fu, man = h & 0x3ffu;
    if (exp == 0) { /* zero or subnormal: man * 2^-24, exact in float */
        float f = (float)man * 5.9604645e-8f;
        return sign ? -f : f;
    }
    uint32_t bits = sign | (exp == 31 ? 0x7f800000u : (exp + 112u) << 23) | man << 13;
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}

void halves_to_floats(const void *src, size_t n, void *dst)
{
    for (size_t i = 0; i < n; ++i)
        static_cast<float *>(dst)[i] = half_to_float(static_cast<const uint16_t *>(src)[i]);
}

/* float64 becomes float32 rounded to nearest; a finite value past float32's range is refused
 * first, naming it (NaN and infinities go on to umbra_volume_create, which names them). */
void check_float32_range(const double *src, size_t n, const uint32_t dims[3])
{
    for (size_t i = 0; i < n; ++i) {
        double d = src[i];
        if (std::isfinite(d) && std::fabs(d) > FLT_MAX) {
            size_t x = i % dims[0], y = i / dims[0] % dims[1], z = i / dims[0] / dims[1];
            char value[32];
            std::snprintf(value, sizeof value, "%g", d);
            raise_invalid("umbra.Volume: voxel " + std::to_string(i) + " (x " +
                          std::to_string(x) + ", y " + std::to_string(y) + ", z " +
                          std::to_string(z) + ") is " + value +
                          ", beyond float32's range (3.4e38): scale the data first");
        }
    }
}

/* How the voxels of a C-contiguous 3-D array reach umbra, or umbra.Error naming the dtype. */
voxels stored_voxels(const any_array &a, const uint32_t dims[3])
{
    nb::dlpack::dtype t = a.dtype();
    voxels v;
    v.data = a.data();
    v.count = a.size();
    const void *p = v.data;
    size_t n = v.count;
    if (t == nb::dtype<uint8_t>() || t == nb::dtype<bool>())
        v.type = UMBRA_UINT8; /* a NumPy bool is one byte, 0 or 1 */
    else if (t == nb::dtype<uint16_t>())
        v.type = UMBRA_UINT16;
    else if (t == nb::dtype<int16_t>())
        v.type = UMBRA_INT16;
    else if (t == nb::dtype<float>())
        v.type = UMBRA_FLOAT32;
    else if (t == nb::dtype<int8_t>())
        from_integers(v, (const int8_t *)p, n);
    else if (t == nb::dtype<int32_t>())
        from_integers(v, (const int32_t *)p, n);
    else if (t == nb::dtype<uint32_t>())
        from_integers(v, (const uint32_t *)p, n);
    else if (t == nb::dtype<int64_t>())
        from_integers(v, (const int64_t *)p, n);
    else if (t == nb::dtype<uint64_t>())
        from_integers(v, (const uint64_t *)p, n);
    else if (t == nb::dtype<double>()) {
        check_float32_range((const double *)p, n, dims);
        v.type = UMBRA_FLOAT32, v.convert = cast_all<float, double>;
    } else if (t.code == (uint8_t)nb::dlpack::dtype_code::Float && t.bits == 16 && t.lanes == 1)
        v.type = UMBRA_FLOAT32, v.convert = halves_to_floats;
    else
        raise_invalid("umbra.Volume: dtype " + dtype_name(t) +
                      " is not supported; pass a real, integer or bool array (uint8, uint16, "
                      "int16 and float32 are read in place, others converted)");
    return v;
}

umbra_status fill_converted(void *user, void *dst, size_t bytes)
{
    const voxels *v = static_cast<const voxels *>(user);
    if (bytes != v->count * umbra_scalar_type_size(v->type))
        return umbra_context_record_error(v->ctx, UMBRA_ERROR_INVALID_ARGUMENT,
                                          "umbra.Volume: the volume asks for a different number "
                                          "of bytes than the array converts to");
    v->convert(v->data, v->count, dst);
    return UMBRA_SUCCESS;
}

/* A NumPy array nanobind cannot view, of another byte order (a big-endian file's voxels, as
 * nibabel hands them over) or of long double, made native by NumPy first (float64 for long
 * double): one host copy, which a byte swap needs anyway. The layout is kept (order "K"), so a
 * strided array is still refused as such. Anything else is returned as it is. */
nb::object numpy_native(nb::handle data)
{
    nb::object dt = nb::getattr(data, "dtype", nb::none());
    if (dt.is_none() || !nb::hasattr(data, "astype") || !nb::hasattr(dt, "kind"))
        return nb::borrow(data);
    std::string kind = nb::cast<std::string>(nb::str(dt.attr("kind")));
    if (kind.size() != 1 || !std::strchr("biuf", kind[0]))
        return nb::borrow(data);
    if (kind == "f" && nb::cast<size_t>(dt.attr("itemsize")) > 8)
        return data.attr("astype")("float64", "order"_a = "K");
    if (!nb::cast<bool>(dt.attr("isnative")))
        return data.attr("astype")(dt.attr("newbyteorder")("="), "order"_a = "K");
    return nb::borrow(data);
}

/* The image objects Volume.from_nibabel, from_sitk and from_vtk read (by their type's module),
 * refused by the constructor with the method that carries their placement too. */
void refuse_image_object(nb::handle data)
{
    nb::object mod = nb::getattr(data.type(), "__module__", nb::none());
    std::string m = nb::isinstance<nb::str>(mod) ? nb::cast<std::string>(mod) : "";
    auto from = [&](const char *prefix) { return m.compare(0, std::strlen(prefix), prefix) == 0; };
    const char *use = nullptr;
    if (from("nibabel"))
        use = "from_nibabel";
    else if (from("SimpleITK"))
        use = "from_sitk";
    else if (from("vtkmodules") || from("pyvista"))
        use = "from_vtk";
    if (use)
        raise_invalid(std::string("umbra.Volume: data is a ") + nb::type_name(data.type()).c_str() +
                      "; use umbra.Volume." + use +
                      "(context, image), which also takes its spacing, origin and direction");
}

/* NaN and infinite float voxels are refused by umbra_volume_create itself (naming the first one),
 * with or without a given value range, so the binding does not scan the array again. */
Volume make_volume(Context &ctx, nb::handle data, vec3 spacing, std::optional<range_t> value_range,
                   uint32_t brick_size, std::optional<vec3> origin,
                   std::optional<std::array<vec3, 3>> directions, bool labels)
{
    umbra_context c = ctx.get();
    refuse_image_object(data);
    any_array a;
    nb::object held = nb::borrow(data); /* alive until the voxels are on the device */
    if (!nb::try_cast(data, a, false))
        held = numpy_native(data);
    a = as_array(held, "umbra.Volume: data");
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    /* A 4-D (z, y, x, c) array is a volume of c channels, channel fastest as umbra takes it. */
    if (a.ndim() == 4 && (a.shape(3) < 1 || a.shape(3) > UMBRA_MAX_CHANNELS))
        raise_invalid("umbra.Volume: data has shape " + shape_text(a) + ": " +
                      std::to_string(a.shape(3)) + " channels, need 1 to " +
                      std::to_string(UMBRA_MAX_CHANNELS));
    if (a.ndim() != 3 && a.ndim() != 4)
        raise_invalid("umbra.Volume: data has shape " + shape_text(a) +
                      "; need a 3-D array of shape (z, y, x), or (z, y, x, channels)");
    d.channels = a.ndim() == 4 ? (uint32_t)a.shape(3) : 1;
    d.labels = labels ? 1 : 0;
    need_c_contiguous(a, "umbra.Volume: data",
                      "pass numpy.ascontiguousarray(data) (an array of shape (x, y, z) in "
                      "Fortran order, as nibabel returns, is C-contiguous as data.T)");
    for (int i = 0; i < 3; ++i) {
        size_t n = a.shape(2 - i);
        if (n > UINT32_MAX)
            raise_invalid("umbra.Volume: axis of size " + std::to_string(n) + " is too large");
        d.dims[i] = (uint32_t)n;
        d.spacing[i] = spacing[i];
    }
    voxels vox = stored_voxels(a, d.dims);
    vox.ctx = c;
    d.type = vox.type;
    d.data = vox.convert ? nullptr : vox.data;
    if (value_range) {
        d.value_range_given = 1;
        d.value_min = value_range->first;
        d.value_max = value_range->second;
    }
    d.brick_size = brick_size;
    /* Either one places the volume: a missing origin is the world origin, missing directions
     * the identity (index axes i, j, k along world x, y, z). */
    if (origin || directions) {
        d.transform_given = 1;
        vec3 o = origin ? *origin : vec3{0, 0, 0};
        for (int r = 0; r < 3; ++r) {
            d.origin[r] = o[r];
            for (int k = 0; k < 3; ++k)
                d.directions[3 * r + k] = directions ? (*directions)[r][k] : (r == k ? 1.0f : 0.0f);
        }
    }
    umbra_volume v = nullptr;
    check(c, vox.convert ? umbra_volume_create_filled(c, &d, fill_converted, &vox, &v)
                         : umbra_volume_create(c, &d, &v));
    return Volume(c, v);
}

/* Volume.update: the voxels of a sub-box (origin given) or of the whole volume, in place. The
 * array must hold the volume's own type (no conversion: a value the conversion would change
 * could not match a fresh volume's). */
void update_volume(Volume &vol, nb::handle data, std::optional<std::array<uint32_t, 3>> origin)
{
    umbra_volume h = vol.get("Volume");
    umbra_volume_info info;
    check(vol.ctx, umbra_volume_get_info(h, &info));
    any_array a = as_array(data, "umbra.Volume.update: data");
    const size_t want = info.channels > 1 ? 4 : 3;
    if (a.ndim() != want || (want == 4 && a.shape(3) != info.channels))
        raise_invalid("umbra.Volume.update: data has shape " + shape_text(a) + "; need (z, y, x" +
                      (want == 4 ? ", " + std::to_string(info.channels) : std::string()) +
                      ") for this volume");
    need_c_contiguous(a, "umbra.Volume.update: data", "pass numpy.ascontiguousarray(data)");
    static const struct {
        umbra_scalar_type type;
        nb::dlpack::dtype dtype;
        const char *name;
    } types[] = {{UMBRA_UINT8, nb::dtype<uint8_t>(), "uint8"},
                 {UMBRA_UINT16, nb::dtype<uint16_t>(), "uint16"},
                 {UMBRA_INT16, nb::dtype<int16_t>(), "int16"},
                 {UMBRA_FLOAT32, nb::dtype<float>(), "float32"}};
    for (const auto &t : types)
        if (t.type == info.type && a.dtype() != t.dtype)
            raise_invalid("umbra.Volume.update: dtype " + dtype_name(a.dtype()) +
                          " is not the volume's " + t.name + "; pass data.astype(numpy." +
                          t.name + ")");
    umbra_volume_update_desc d;
    umbra_volume_update_desc_init(&d);
    d.data = a.data();
    for (int i = 0; i < 3; ++i) {
        if (a.shape(2 - i) > UINT32_MAX)
            raise_invalid("umbra.Volume.update: axis of size " + std::to_string(a.shape(2 - i)) +
                          " is too large");
        d.size[i] = (uint32_t)a.shape(2 - i);
        d.origin[i] = origin ? (*origin)[i] : 0;
    }
    check(vol.ctx, umbra_volume_update(h, &d));
}

template <size_t N> nb::tuple floats(const float *p)
{
    nb::list l;
    for (size_t i = 0; i < N; ++i)
        l.append(py_float(p[i]));
    return nb::tuple(l);
}

/* The data range of a transfer function, or None. */
nb::object tf_range(umbra_transfer_function t)
{
    float r[2];
    if (!umbra_transfer_function_get_range(t, r))
        return nb::none();
    return floats<2>(r);
}

void tf_set_range(umbra_context c, umbra_transfer_function t, range_t r)
{
    check(c, umbra_transfer_function_set_range(t, r.first, r.second));
}

} // namespace

TransferFunction load_paraview(Context &ctx, const std::string &path,
                               std::optional<std::string> preset, uint32_t resolution,
                               std::optional<std::pair<double, double>> range)
{
    umbra_context c = ctx.get();
    umbra_paraview_options o;
    umbra_paraview_options_init(&o);
    o.preset = preset ? preset->c_str() : nullptr;
    o.resolution = resolution;
    if (range) {
        o.range_given = 1;
        o.range_min = range->first;
        o.range_max = range->second;
    }
    umbra_transfer_function t = nullptr;
    check(c, umbra_transfer_function_load_paraview(
                 c, path_arg(path, "umbra.TransferFunction.load_paraview: path"), &o, &t, nullptr));
    return TransferFunction(c, t);
}

/* Volume.from_* are written in Python (umbra/_adapters.py): they read the other libraries'
 * objects through those libraries and end in the Volume constructor. */
auto adapter(const char *name)
{
    return [name](nb::args args, nb::kwargs kwargs) {
        return nb::module_::import_("umbra._adapters").attr(name)(*args, **kwargs);
    };
}

void bind_data(nb::module_ &m)
{
    /* ---- Volume ---- */
    umbra_volume_desc volume_defaults;
    umbra_volume_desc_init(&volume_defaults);
    nb::class_<Volume>(
        m, "Volume",
        "A scalar volume on the device (umbra_volume). Built from a C-contiguous array of shape "
        "(z, y, x) (x varies fastest, as in umbra) of any real, integer or bool dtype. uint8, "
        "uint16, int16 and float32 are stored as they are: the array is read in place and "
        "copied once, to the device. Any other dtype is converted once into the nearest of "
        "them, on the way to the device (umbra_volume_create_filled: on a CPU device straight "
        "into the device's buffer, elsewhere into a host buffer freed before return): bool -> "
        "uint8 (read in place); float16, float64 -> float32 (a finite value beyond float32's "
        "range is refused); int8, int32, uint32, int64, uint64 -> the first of uint8, uint16, "
        "int16 that holds every value, else float32 (exact up to 2^24); a big-endian or long "
        "double array is first made native by NumPy (long double as float64). Float voxels "
        "must be finite. From nibabel, SimpleITK or VTK/pyvista images: Volume.from_nibabel, from_sitk, "
        "from_vtk.")
        .def(
            "__init__",
            [](Volume *self, Context &ctx, nb::handle data, vec3 spacing,
               std::optional<range_t> value_range, uint32_t brick_size, std::optional<vec3> origin,
               std::optional<std::array<vec3, 3>> directions, bool labels) {
                Volume v = make_volume(ctx, data, spacing, value_range, brick_size, origin,
                                       directions, labels);
                new (self) Volume(std::move(v));
            },
            "context"_a, "data"_a, nb::kw_only(),
            "spacing"_a = vec3{volume_defaults.spacing[0], volume_defaults.spacing[1],
                               volume_defaults.spacing[2]},
            "value_range"_a = nb::none(), "brick_size"_a = volume_defaults.brick_size,
            "origin"_a = nb::none(), "directions"_a = nb::none(),
            "labels"_a = volume_defaults.labels != 0,
            "data: (z, y, x), or (z, y, x, c) for a volume of c channels (1 to 4: one transfer "
            "function each, Renderer.set_channel_tf). labels: the voxels (uint8 or uint16, one "
            "channel) are labels, sampled at the nearest voxel; the transfer function's entry "
            "i is label i's colour and opacity (umbra_volume_desc.labels).\n"
            "spacing: world units per voxel as (sx, sy, sz), x first like umbra's dims, i.e. the "
            "reverse of the array's (z, y, x) axis order (SimpleITK's GetSpacing() order). "
            "value_range: (min, max) mapped to [0, 1] before the transfer function; None: the "
            "data's min and max. brick_size: edge of an empty-space-skipping brick in voxels.\n"
            "origin, directions: the index-to-world transform. Voxel data[k, j, i] lies at "
            "origin + i*sx*directions[0] + j*sy*directions[1] + k*sz*directions[2]: origin is "
            "the world position of voxel (0, 0, 0)'s centre, directions[a] the world direction "
            "of index axis a, x first like spacing (rows, not the array's axis order). The "
            "directions must be non-zero and at right angles (normalised here; a sheared grid is "
            "ERROR_UNSUPPORTED). Either one alone takes the other's default (origin (0, 0, 0), "
            "directions the identity); neither: the box is centred on the world origin. From a "
            "NIfTI affine A (nibabel's img.affine, index (i, j, k) = (x, y, z)): spacing = "
            "|A[:3, a]| per column a, origin = A[:3, 3], directions = (A[:3, :3] / spacing).T.")
        .def_static("from_nibabel", adapter("from_nibabel"),
                    nb::sig("def from_nibabel(context: Context, image: object, /, "
                            "**kwargs: object) -> Volume"),
                    "A nibabel image (NIfTI, MGH, ...: anything with dataobj and affine), "
                    "scaled by its scl_slope/scl_inter as nibabel reads it, placed by its affine "
                    "(RAS+). 3-D, or with every axis past the third of size 1. kwargs: "
                    "value_range, brick_size, as for Volume().")
        .def_static("from_sitk", adapter("from_sitk"),
                    nb::sig("def from_sitk(context: Context, image: object, /, "
                            "**kwargs: object) -> Volume"),
                    "A 3-D scalar SimpleITK.Image with its spacing, origin and direction (ITK's "
                    "physical space, LPS). kwargs: value_range, brick_size.")
        .def_static("from_vtk", adapter("from_vtk"),
                    nb::sig("def from_vtk(context: Context, image: object, /, "
                            "array: str | None = None, **kwargs: object) -> Volume"),
                    "A vtkImageData or pyvista.ImageData with its spacing, origin, direction "
                    "matrix and extent. array: the name of a one-component point- or "
                    "cell-data array (None: the active point scalars, else the only point "
                    "array, else the same for cell data; cell data are voxels centred in the "
                    "cells). kwargs: value_range, brick_size.")
        .def("update", &update_volume, "data"_a, nb::kw_only(), "origin"_a = nb::none(),
             "umbra_volume_update: writes data, of the volume's own dtype and shape (z, y, x) "
             "(or (z, y, x, channels)), into the volume in place: at voxel origin (x, y, z) as a "
             "sub-box, or, without origin, as all of it (the next time step of a series). The "
             "value range stays the one set at creation (values outside it clamp). Renderers "
             "rebuild only what the change touches (their shadow structures, and visibility "
             "tables where a brick's range changed); a render then equals, bit for bit, one of "
             "a fresh volume of the new voxels with the same value range. info.version counts "
             "the updates.")
        .def("close", &Volume::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Volume &v) { return v.h == nullptr; })
        .def(
            "__enter__", [](nb::handle self) { return nb::borrow(self); },
            nb::sig("def __enter__(self) -> Volume"))
        .def(
            "__exit__", [](Volume &v, nb::args) { v.close(); },
            nb::sig("def __exit__(self, *args: object) -> None"))
        .def_prop_ro(
            "info",
            [](const Volume &v) {
                VolumeInfo i;
                check(v.ctx, umbra_volume_get_info(v.get("Volume"), &i.info));
                return i;
            },
            "umbra_volume_get_info: dims, spacing, extent, value range, bricks, device bytes, "
            "world transform and centre.")
        .def_prop_ro(
            "shape",
            [](const Volume &v) {
                umbra_volume_info i;
                check(v.ctx, umbra_volume_get_info(v.get("Volume"), &i));
                return nb::make_tuple(i.dims[2], i.dims[1], i.dims[0]);
            },
            "(z, y, x), the shape of the array it was made from");

    nb::class_<VolumeInfo>(m, "VolumeInfo", "umbra_volume_info (x, y, z order)")
        .def_prop_ro(
            "dims",
            [](const VolumeInfo &i) {
                return nb::make_tuple(i.info.dims[0], i.info.dims[1], i.info.dims[2]);
            },
            nb::sig("def dims(self, /) -> tuple[int, int, int]"), "(x, y, z) voxels")
        .def_prop_ro(
            "spacing", [](const VolumeInfo &i) { return floats<3>(i.info.spacing); },
            nb::sig("def spacing(self, /) -> tuple[float, float, float]"),
            "world units per voxel, (x, y, z)")
        .def_prop_ro(
            "extent", [](const VolumeInfo &i) { return floats<3>(i.info.extent); },
            nb::sig("def extent(self, /) -> tuple[float, float, float]"),
            "dims * spacing: the world-space box size, (x, y, z)")
        .def_prop_ro(
            "value_range",
            [](const VolumeInfo &i) {
                return nb::make_tuple(py_float(i.info.value_min), py_float(i.info.value_max));
            },
            nb::sig("def value_range(self, /) -> tuple[float, float]"),
            "the values mapped to 0 and 1 before the transfer function")
        .def_prop_ro("channels", [](const VolumeInfo &i) { return i.info.channels; },
                     "values per voxel (1 to 4)")
        .def_prop_ro(
            "labels", [](const VolumeInfo &i) { return i.info.labels != 0; },
            "True for a label map")
        .def_prop_ro(
            "channel_ranges",
            [](const VolumeInfo &i) {
                nb::list l;
                for (uint32_t c = 0; c < i.info.channels; ++c)
                    l.append(nb::make_tuple(py_float(i.info.channel_min[c]),
                                            py_float(i.info.channel_max[c])));
                return nb::tuple(l);
            },
            nb::sig("def channel_ranges(self, /) -> tuple[tuple[float, float], ...]"),
            "each channel's value range (min, max)")
        .def_prop_ro("version", [](const VolumeInfo &i) { return i.info.version; },
                     "0 when made, one more for each Volume.update")
        .def_prop_ro("brick_size", [](const VolumeInfo &i) { return i.info.brick_size; })
        .def_prop_ro(
            "brick_counts",
            [](const VolumeInfo &i) {
                return nb::make_tuple(i.info.brick_counts[0], i.info.brick_counts[1],
                                      i.info.brick_counts[2]);
            },
            nb::sig("def brick_counts(self, /) -> tuple[int, int, int]"))
        .def_prop_ro("device_bytes", [](const VolumeInfo &i) { return i.info.device_bytes; })
        .def_prop_ro(
            "transform_given", [](const VolumeInfo &i) { return i.info.transform_given != 0; },
            "True if the volume was made with an index-to-world transform (origin, directions)")
        .def_prop_ro(
            "origin", [](const VolumeInfo &i) { return floats<3>(i.info.origin); },
            nb::sig("def origin(self, /) -> tuple[float, float, float]"),
            "world position of voxel (0, 0, 0)'s centre (also for the centred box)")
        .def_prop_ro(
            "directions",
            [](const VolumeInfo &i) {
                const float *d = i.info.directions;
                return nb::make_tuple(floats<3>(d), floats<3>(d + 3), floats<3>(d + 6));
            },
            nb::sig("def directions(self, /) -> tuple[tuple[float, float, float], "
                    "tuple[float, float, float], tuple[float, float, float]]"),
            "unit world direction of index axis x, y, z (one row each; the identity for the "
            "centred box)")
        .def_prop_ro(
            "center", [](const VolumeInfo &i) { return floats<3>(i.info.center); },
            nb::sig("def center(self, /) -> tuple[float, float, float]"),
            "world position of the box's centre (what a camera should look at)")
        .def_prop_ro(
            "diagonal",
            [](const VolumeInfo &i) {
                const float *e = i.info.extent;
                return py_float(std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
            },
            "length of the box's diagonal in world units (for Camera.orbit)");

    /* ---- TransferFunction ---- */
    nb::class_<TransferFunction>(
        m, "TransferFunction",
        "A 1-D RGBA transfer function (umbra_transfer_function): entries spread evenly over the "
        "volume's normalised value range [0, 1], or with a data range over data values lo..hi in "
        "the volume's own units (e.g. Hounsfield units, whatever the volume's value_range), "
        "linearly interpolated; alpha is the opacity of one sample per voxel.")
        .def(
            "__init__",
            [](TransferFunction *self, Context &ctx, nb::handle table,
               std::optional<range_t> range) {
                umbra_context c = ctx.get();
                any_array a = as_array(table, "umbra.TransferFunction: table");
                const float *p = float_rows(a, 4, "umbra.TransferFunction: table", "(N, 4) RGBA");
                if (a.shape(0) > UINT32_MAX)
                    raise_invalid("umbra.TransferFunction: table too long");
                umbra_transfer_function t = nullptr;
                check(c, umbra_transfer_function_create(c, p, (uint32_t)a.shape(0), &t));
                TransferFunction tf(c, t);
                if (range)
                    tf_set_range(c, t, *range);
                new (self) TransferFunction(std::move(tf));
            },
            "context"_a, "table"_a, nb::kw_only(), "range"_a = nb::none(),
            "table: an (N, 4) float32 array of RGBA rows in [0, 1], N >= 2 (copied). range: "
            "(lo, hi), the data values the first and last rows stand for; None: the volume's "
            "normalised range.")
        .def_static(
            "from_points",
            [](Context &ctx, std::vector<std::array<float, 5>> points, uint32_t resolution,
               std::optional<range_t> range) {
                umbra_context c = ctx.get();
                if (range && !(std::isfinite(range->first) && std::isfinite(range->second) &&
                               range->first < range->second))
                    raise_invalid("umbra.TransferFunction.from_points: range (" +
                                  std::to_string(range->first) + ", " +
                                  std::to_string(range->second) + ") must be finite with lo < hi");
                std::vector<umbra_tf_point> pts(points.size());
                for (size_t i = 0; i < points.size(); ++i) {
                    float v = points[i][0];
                    if (range) {
                        /* Data values, as in umbra's text format with a "range" line. */
                        double lo = range->first, hi = range->second;
                        if (!(v >= lo && v <= hi))
                            raise_invalid("umbra.TransferFunction.from_points: point " +
                                          std::to_string(i) + " value " + std::to_string(v) +
                                          " is outside the range [" + std::to_string(lo) + ", " +
                                          std::to_string(hi) + "]");
                        v = (float)((v - lo) / (hi - lo));
                    }
                    pts[i].value = v;
                    for (int k = 0; k < 4; ++k)
                        pts[i].rgba[k] = points[i][k + 1];
                }
                if (pts.size() > UINT32_MAX)
                    raise_invalid("umbra.TransferFunction.from_points: too many points");
                umbra_transfer_function t = nullptr;
                check(c, umbra_transfer_function_create_from_points(
                             c, pts.empty() ? nullptr : pts.data(), (uint32_t)pts.size(),
                             resolution, &t));
                TransferFunction tf(c, t);
                if (range)
                    tf_set_range(c, t, *range);
                return tf;
            },
            "context"_a, "points"_a, "resolution"_a = 256, nb::kw_only(), "range"_a = nb::none(),
            "Control points (value, r, g, b, a), sorted by value; a list of 5-tuples or an (N, 5) "
            "array. Without a range the values are in [0, 1] of the volume's normalised range; "
            "with range=(lo, hi) they are data values in [lo, hi] (as in umbra's text format with "
            "a 'range' line) and the table spans lo..hi. The table gets `resolution` entries (256 "
            "as in umbra's transfer-function files).")
        .def_static("load_paraview", &load_paraview, "context"_a, "path"_a, nb::kw_only(),
                    "preset"_a = nb::none(), "resolution"_a = 1024, "range"_a = nb::none(),
                    "Reads a ParaView JSON colour-map preset (umbra_transfer_function_load_"
                    "paraview): preset, the 'Name' to pick from a file of several (None: the "
                    "first); resolution, table entries (2..65536); range, (lo, hi) data values "
                    "the table spans (None: the preset's own x range). The table carries that "
                    "data range. Malformed files raise umbra.Error ERROR_FORMAT naming the key.")
        .def("close", &TransferFunction::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const TransferFunction &t) { return t.h == nullptr; })
        .def(
            "__enter__", [](nb::handle self) { return nb::borrow(self); },
            nb::sig("def __enter__(self) -> TransferFunction"))
        .def(
            "__exit__", [](TransferFunction &t, nb::args) { t.close(); },
            nb::sig("def __exit__(self, *args: object) -> None"))
        .def("__len__",
             [](const TransferFunction &t) {
                 return umbra_transfer_function_size(t.get("TransferFunction"));
             })
        .def_prop_rw(
            "range", [](const TransferFunction &t) { return tf_range(t.get("TransferFunction")); },
            [](TransferFunction &t, range_t r) {
                tf_set_range(t.ctx, t.get("TransferFunction"), r);
            },
            nb::for_getter(nb::sig("def range(self, /) -> tuple[float, float] | None")),
            nb::for_setter(nb::sig("def range(self, value: tuple[float, float], /) -> None")),
            "(lo, hi): the data values the table spans (umbra_transfer_function_set_range), or "
            "None for the volume's normalised range. Renderers pick a change up at their next "
            "render.")
        .def_prop_ro(
            "table",
            [](const TransferFunction &t) {
                umbra_transfer_function h = t.get("TransferFunction");
                /* A read-only view that keeps the table alive even if this object is closed. */
                umbra_transfer_function_retain(h);
                nb::capsule owner(h, [](void *q) noexcept {
                    umbra_transfer_function_release((umbra_transfer_function)q);
                });
                size_t n = umbra_transfer_function_size(h);
                return nb::ndarray<nb::numpy, const float>(umbra_transfer_function_data(h), {n, 4},
                                                           owner);
            },
            nb::rv_policy::automatic, "The (N, 4) float32 RGBA table, a read-only view (no copy).")
        .def_prop_ro(
            "is_grey",
            [](const TransferFunction &t) {
                return umbra_transfer_function_is_grey(t.get("TransferFunction")) != 0;
            },
            "True when every visible entry has r == g == b (one light channel suffices).");
}

} // namespace umbra_py
