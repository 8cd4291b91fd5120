// SPDX-License-Identifier: Apache-2.0
/* data.cpp: Volume, VolumeInfo and TransferFunction, the data a renderer draws, bound with NumPy
 * arrays in: a volume from a (z, y, x) array with its spacing and, optionally, its index-to-world
 * transform (origin and axis directions, as a NIfTI affine or a NRRD's space directions give
 * them); a transfer function from a table or control points, optionally over a data range, or
 * from a ParaView preset. Split from objects.cpp (Context, Renderer, Scene) to keep each file
 * readable. */
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

/* The scalar type of a NumPy dtype, or a clear error naming the supported ones. */
umbra_scalar_type scalar_type_of(nb::dlpack::dtype t)
{
    if (t == nb::dtype<uint8_t>())
        return UMBRA_UINT8;
    if (t == nb::dtype<uint16_t>())
        return UMBRA_UINT16;
    if (t == nb::dtype<int16_t>())
        return UMBRA_INT16;
    if (t == nb::dtype<float>())
        return UMBRA_FLOAT32;
    raise_invalid("umbra.Volume: dtype " + dtype_name(t) +
                  " is not supported; use uint8, uint16, int16 or float32 "
                  "(e.g. data.astype(numpy.float32))");
}

/* NaN and infinite float voxels are refused by umbra_volume_create itself (naming the first one),
 * with or without a given value range, so the binding does not scan the array again. */
Volume make_volume(Context &ctx, nb::handle data, vec3 spacing, std::optional<range_t> value_range,
                   uint32_t brick_size, std::optional<vec3> origin,
                   std::optional<std::array<vec3, 3>> directions)
{
    umbra_context c = ctx.get();
    any_array a = as_array(data, "umbra.Volume: data");
    umbra_volume_desc d;
    umbra_volume_desc_init(&d);
    d.type = scalar_type_of(a.dtype());
    if (a.ndim() != 3)
        raise_invalid("umbra.Volume: data has shape " + shape_text(a) +
                      "; need a 3-D array of shape (z, y, x)");
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
    d.data = a.data();
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
    check(c, umbra_volume_create(c, &d, &v));
    return Volume(c, v);
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

void bind_data(nb::module_ &m)
{
    /* ---- Volume ---- */
    umbra_volume_desc volume_defaults;
    umbra_volume_desc_init(&volume_defaults);
    nb::class_<Volume>(
        m, "Volume",
        "A scalar volume on the device (umbra_volume). Built from a C-contiguous NumPy array of "
        "shape (z, y, x) (x varies fastest, as in umbra), dtype uint8, uint16, int16 or float32; "
        "the array is read in place and copied once, to the device. Float voxels must be finite.")
        .def(
            "__init__",
            [](Volume *self, Context &ctx, nb::handle data, vec3 spacing,
               std::optional<range_t> value_range, uint32_t brick_size, std::optional<vec3> origin,
               std::optional<std::array<vec3, 3>> directions) {
                Volume v =
                    make_volume(ctx, data, spacing, value_range, brick_size, origin, directions);
                new (self) Volume(std::move(v));
            },
            "context"_a, "data"_a, nb::kw_only(),
            "spacing"_a = vec3{volume_defaults.spacing[0], volume_defaults.spacing[1],
                               volume_defaults.spacing[2]},
            "value_range"_a = nb::none(), "brick_size"_a = volume_defaults.brick_size,
            "origin"_a = nb::none(), "directions"_a = nb::none(),
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
