/* objects.cpp: Context, Volume, TransferFunction, Renderer and Scene: umbra's C objects wrapped so
 * that they close deterministically (close(), with) and may be collected in any order (each
 * wrapper retains the C objects it needs, its context included), with NumPy arrays in and out. */
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "binding.h"

namespace umbra_py
{

namespace
{

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

Volume make_volume(Context &ctx, nb::handle data, std::array<float, 3> spacing,
                   std::optional<std::pair<float, float>> value_range, uint32_t brick_size)
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
    if (value_range && d.type == UMBRA_FLOAT32) {
        /* umbra_volume_create scans for NaN and infinity only when it computes the range itself;
         * with a given range a NaN would reach the device and the picture. */
        const float *p = (const float *)d.data;
        size_t n = (size_t)d.dims[0] * d.dims[1] * d.dims[2];
        for (size_t i = 0; i < n; ++i)
            if (!std::isfinite(p[i])) {
                size_t x = i % d.dims[0], y = i / d.dims[0] % d.dims[1],
                       z = i / ((size_t)d.dims[0] * d.dims[1]);
                raise_invalid("umbra.Volume: voxel " + std::to_string(i) + " (z " +
                              std::to_string(z) + ", y " + std::to_string(y) + ", x " +
                              std::to_string(x) + ") is " +
                              (std::isnan(p[i]) ? "nan"
                               : p[i] > 0       ? "inf"
                                                : "-inf") +
                              "; float volumes must be finite");
            }
    }
    if (value_range) {
        d.value_range_given = 1;
        d.value_min = value_range->first;
        d.value_max = value_range->second;
    }
    d.brick_size = brick_size;
    umbra_volume v = nullptr;
    check(c, umbra_volume_create(c, &d, &v));
    return Volume(c, v);
}

/* ---- renderer helpers --------------------------------------------------------------------------- */

void renderer_set_shadow(Renderer &r, const umbra_shadow_desc &d)
{
    check(r.ctx, umbra_renderer_set_shadow(r.get(), &d));
    r.shadow = d;
}

void renderer_set_options(Renderer &r, const umbra_render_desc &d)
{
    check(r.ctx, umbra_renderer_set_options(r.get(), &d));
    r.options = d;
}

void renderer_set_volume(Renderer &r, nb::handle v)
{
    Volume &vol = nb::cast<Volume &>(v);
    check(r.ctx, umbra_renderer_set_volume(r.get(), vol.get("Volume")));
    r.volume = nb::borrow(v);
}

void renderer_set_tf(Renderer &r, nb::handle t)
{
    TransferFunction &tf = nb::cast<TransferFunction &>(t);
    check(r.ctx, umbra_renderer_set_transfer_function(r.get(), tf.get("TransferFunction")));
    r.tf = nb::borrow(t);
}

void renderer_set_light_tf(Renderer &r, nb::handle t)
{
    umbra_transfer_function h = nullptr;
    if (!t.is_none())
        h = nb::cast<TransferFunction &>(t).get("TransferFunction");
    check(r.ctx, umbra_renderer_set_light_transfer_function(r.get(), h));
    r.light_tf = nb::borrow(t);
}

void renderer_set_camera(Renderer &r, const umbra_camera &c)
{
    check(r.ctx, umbra_renderer_set_camera(r.get(), &c));
    r.camera = c;
}

void renderer_set_light(Renderer &r, const umbra_light &l)
{
    check(r.ctx, umbra_renderer_set_light(r.get(), &l));
    r.light = l;
}
} // namespace

void bind_objects(nb::module_ &m)
{
    /* ---- Context ---- */
    umbra_context_desc context_defaults;
    umbra_context_desc_init(&context_defaults);
    nb::class_<Context>(
        m, "Context",
        "The OpenCL device umbra runs on (umbra_context). Use it as a context manager or call "
        "close(); objects made on it keep the device alive until they are closed or collected. "
        "One thread at a time.")
        .def(
            "__init__",
            [](Context *self, std::optional<std::string> device, int platform_index,
               int device_index, nb::handle sampler, std::optional<std::string> cache_dir,
               bool use_environment) {
                new (self) Context;
                umbra_context_desc d;
                umbra_context_desc_init(&d);
                d.device_name = device ? device->c_str() : nullptr;
                d.platform_index = platform_index;
                d.device_index = device_index;
                d.sampler = enum_from<umbra_sampler_kind>(sampler);
                d.cache_dir = cache_dir ? cache_dir->c_str() : nullptr;
                d.use_environment = use_environment;
                std::string message;
                d.error_callback = [](void *user, umbra_status, const char *msg) {
                    *(std::string *)user = msg;
                };
                d.error_user = &message;
                umbra_status st = umbra_context_create(&d, &self->h);
                if (st != UMBRA_SUCCESS)
                    raise_error(st, message);
                /* The callback's string dies here: later errors are read with take_error. */
                umbra_context_set_error_callback(self->h, nullptr, nullptr);
            },
            "device"_a = nb::none(), "platform_index"_a = context_defaults.platform_index,
            "device_index"_a = context_defaults.device_index,
            "sampler"_a = context_defaults.sampler, "cache_dir"_a = nb::none(),
            "use_environment"_a = context_defaults.use_environment != 0,
            "device: a substring of the platform or device name, or None. With the defaults the "
            "environment variable UMBRA_DEVICE ('P:D' or a name) is honoured. cache_dir: PoCL's "
            "kernel cache (default $POCL_CACHE_DIR, else a directory under the temporary one).")
        .def("close", &Context::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Context &c) { return c.h == nullptr; })
        .def(
            "__enter__", [](nb::handle self) { return nb::borrow(self); },
            nb::sig("def __enter__(self) -> Context"))
        .def(
            "__exit__", [](Context &c, nb::args) { c.close(); },
            nb::sig("def __exit__(self, *args: object) -> None"))
        .def_prop_ro(
            "device_name",
            [](const Context &c) { return std::string(umbra_context_device_name(c.get())); },
            "'platform / device'")
        .def_prop_ro(
            "sampler", [](const Context &c) { return umbra_context_sampler(c.get()); },
            "The sampler back end in use (never AUTO).")
        .def(
            "load_volume",
            [](Context &c, const std::string &path) {
                umbra_volume v = nullptr;
                check(c.get(), umbra_volume_load(c.get(), path.c_str(), &v));
                return Volume(c.h, v);
            },
            "path"_a, "Loads .nrrd/.nhdr (Teem) or .dat (Voreen) through umbra_io.")
        .def(
            "load_transfer_function",
            [](Context &c, const std::string &path) {
                umbra_transfer_function t = nullptr;
                check(c.get(), umbra_transfer_function_load(c.get(), path.c_str(), &t));
                return TransferFunction(c.h, t);
            },
            "path"_a, "Loads umbra's transfer-function text format through umbra_io.")
        .def(
            "write_image",
            [](Context &c, const std::string &path, nb::handle rgba) {
                any_array a = as_array(rgba, "umbra.Context.write_image: rgba");
                if (a.ndim() != 3 || a.shape(2) != 4)
                    raise_invalid("umbra.Context.write_image: rgba shape " + shape_text(a) +
                                  " is not (height, width, 4)");
                if (a.dtype() != nb::dtype<float>())
                    raise_invalid("umbra.Context.write_image: dtype " + dtype_name(a.dtype()) +
                                  " is not float32");
                need_c_contiguous(a, "umbra.Context.write_image: rgba",
                                  "pass numpy.ascontiguousarray(rgba)");
                if (a.shape(0) > UINT32_MAX || a.shape(1) > UINT32_MAX)
                    raise_invalid("umbra.Context.write_image: image too large");
                check(c.get(), umbra_image_write(c.get(), path.c_str(), (uint32_t)a.shape(1),
                                                 (uint32_t)a.shape(0), (const float *)a.data()));
            },
            "path"_a, "rgba"_a,
            "Writes an (H, W, 4) float32 premultiplied RGBA image: .png (8-bit sRGB) or .exr "
            "(linear float).")
        .def(
            "read_image",
            [](Context &c, const std::string &path) {
                uint32_t w = 0, h = 0;
                float *p = nullptr;
                check(c.get(), umbra_image_read(c.get(), path.c_str(), &w, &h, &p));
                nb::capsule owner(p, [](void *q) noexcept { std::free(q); });
                return float_out(p, {h, w, 4}, owner);
            },
            "path"_a, "Reads a PNG or EXR as an (H, W, 4) float32 linear premultiplied array.");

    /* ---- Volume ---- */
    umbra_volume_desc volume_defaults;
    umbra_volume_desc_init(&volume_defaults);
    nb::class_<Volume>(
        m, "Volume",
        "A scalar volume on the device (umbra_volume). Built from a C-contiguous NumPy array of "
        "shape (z, y, x) (x varies fastest, as in umbra), dtype uint8, uint16, int16 or float32; "
        "the array is read in place and copied once, to the device.")
        .def(
            "__init__",
            [](Volume *self, Context &ctx, nb::handle data, std::array<float, 3> spacing,
               std::optional<std::pair<float, float>> value_range, uint32_t brick_size) {
                Volume v = make_volume(ctx, data, spacing, value_range, brick_size);
                new (self) Volume(std::move(v));
            },
            "context"_a, "data"_a, nb::kw_only(),
            "spacing"_a =
                std::array<float, 3>{volume_defaults.spacing[0], volume_defaults.spacing[1],
                                     volume_defaults.spacing[2]},
            "value_range"_a = nb::none(), "brick_size"_a = volume_defaults.brick_size,
            "spacing: world units per voxel as (sx, sy, sz), x first like umbra's dims, i.e. the "
            "reverse of the array's (z, y, x) axis order (SimpleITK's GetSpacing() order). "
            "value_range: (min, max) mapped to [0, 1] before the transfer function; None: the "
            "data's min and max. brick_size: edge of an empty-space-skipping brick in voxels.")
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
            "umbra_volume_get_info: dims, spacing, extent, value range, bricks, device bytes.")
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
            "spacing",
            [](const VolumeInfo &i) {
                return nb::make_tuple(py_float(i.info.spacing[0]), py_float(i.info.spacing[1]),
                                      py_float(i.info.spacing[2]));
            },
            nb::sig("def spacing(self, /) -> tuple[float, float, float]"),
            "world units per voxel, (x, y, z)")
        .def_prop_ro(
            "extent",
            [](const VolumeInfo &i) {
                return nb::make_tuple(py_float(i.info.extent[0]), py_float(i.info.extent[1]),
                                      py_float(i.info.extent[2]));
            },
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
        .def_prop_ro("device_bytes", [](const VolumeInfo &i) { return i.info.device_bytes; });

    /* ---- TransferFunction ---- */
    nb::class_<TransferFunction>(
        m, "TransferFunction",
        "A 1-D RGBA transfer function (umbra_transfer_function): entries spread evenly over the "
        "volume's normalised value range [0, 1], linearly interpolated; alpha is the opacity of "
        "one sample per voxel.")
        .def(
            "__init__",
            [](TransferFunction *self, Context &ctx, nb::handle table) {
                umbra_context c = ctx.get();
                any_array a = as_array(table, "umbra.TransferFunction: table");
                const float *p = float_rows(a, 4, "umbra.TransferFunction: table", "(N, 4) RGBA");
                if (a.shape(0) > UINT32_MAX)
                    raise_invalid("umbra.TransferFunction: table too long");
                umbra_transfer_function t = nullptr;
                check(c, umbra_transfer_function_create(c, p, (uint32_t)a.shape(0), &t));
                new (self) TransferFunction(c, t);
            },
            "context"_a, "table"_a,
            "table: an (N, 4) float32 array of RGBA rows in [0, 1], N >= 2 (copied).")
        .def_static(
            "from_points",
            [](Context &ctx, std::vector<std::array<float, 5>> points, uint32_t resolution) {
                umbra_context c = ctx.get();
                std::vector<umbra_tf_point> pts(points.size());
                for (size_t i = 0; i < points.size(); ++i) {
                    pts[i].value = points[i][0];
                    for (int k = 0; k < 4; ++k)
                        pts[i].rgba[k] = points[i][k + 1];
                }
                if (pts.size() > UINT32_MAX)
                    raise_invalid("umbra.TransferFunction.from_points: too many points");
                umbra_transfer_function t = nullptr;
                check(c, umbra_transfer_function_create_from_points(
                             c, pts.empty() ? nullptr : pts.data(), (uint32_t)pts.size(),
                             resolution, &t));
                return TransferFunction(c, t);
            },
            "context"_a, "points"_a, "resolution"_a = 256,
            "Control points (value, r, g, b, a), value in [0, 1] of the normalised range, sorted; "
            "a list of 5-tuples or an (N, 5) array. The table gets `resolution` entries (256 as in "
            "umbra's transfer-function files).")
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

    /* ---- RenderStats ---- */
    nb::class_<umbra_render_stats>(m, "RenderStats", "umbra_render_stats of the last render")
        .def_ro("shadow_build_ms", &umbra_render_stats::shadow_build_ms)
        .def_ro("render_ms", &umbra_render_stats::render_ms)
        .def_prop_ro("shadow_rebuilt",
                     [](const umbra_render_stats &s) { return s.shadow_rebuilt != 0; })
        .def_ro("shadow_memory_bytes", &umbra_render_stats::shadow_memory_bytes)
        .def_ro("light_channels", &umbra_render_stats::light_channels)
        .def_ro("slices", &umbra_render_stats::slices)
        .def_ro("samples", &umbra_render_stats::samples);

    /* ---- Renderer ---- */
    static const std::string set_shadow_doc =
        "Selects the shadow technique: ShadowOptions(**params), i.e. every parameter not given "
        "takes its C default (umbra_shadow_desc_init), not its previous value. Parameters:\n" +
        shadow_fields_doc();
    static const std::string set_options_doc =
        "Sets the render options: `base` (a RenderOptions, e.g. a Scene's; default the C "
        "defaults) with the given fields replaced. Fields:\n" +
        render_fields_doc();
    static const std::string render_doc =
        "Renders width x height premultiplied RGBA into a new (height, width, 4) float32 array "
        "(row 0 at the top), or into `out`, an array of that shape, dtype and C order. Keyword "
        "arguments, if any, first select the shadow technique as set_shadow(**params) does, "
        "e.g. render(512, 512, technique='cssm', taps=7). Blocks until done.";

    nb::class_<Renderer>(
        m, "Renderer",
        "Draws one volume with a transfer function from a camera, lit by one light, with a shadow "
        "technique (umbra_renderer). Setters validate at once and raise umbra.Error; render() "
        "rebuilds only what changed (a shadow map is reused while the light, volume and light "
        "transfer function stay).")
        .def(
            "__init__",
            [](Renderer *self, Context &ctx, Volume *volume, TransferFunction *tf,
               TransferFunction *light_tf, std::optional<umbra_camera> camera,
               std::optional<umbra_light> light, std::optional<umbra_render_desc> options,
               std::optional<umbra_shadow_desc> shadow) {
                umbra_context c = ctx.get();
                new (self) Renderer;
                /* nanobind runs no destructor for an __init__ that raised: release here what was
             * made, or a failing setter would leak the renderer and all it retains. */
                try {
                    umbra_render_desc_init(&self->options);
                    umbra_shadow_desc_init(&self->shadow);
                    check(c, umbra_renderer_create(c, &self->h));
                    self->ctx = c;
                    umbra_context_retain(c);
                    if (volume)
                        renderer_set_volume(*self, nb::find(volume));
                    if (tf)
                        renderer_set_tf(*self, nb::find(tf));
                    if (light_tf)
                        renderer_set_light_tf(*self, nb::find(light_tf));
                    if (camera)
                        renderer_set_camera(*self, *camera);
                    if (light)
                        renderer_set_light(*self, *light);
                    if (options)
                        renderer_set_options(*self, *options);
                    if (shadow)
                        renderer_set_shadow(*self, *shadow);
                } catch (...) {
                    self->~Renderer();
                    throw;
                }
            },
            "context"_a, "volume"_a.none() = nb::none(), "tf"_a.none() = nb::none(), nb::kw_only(),
            "light_tf"_a.none() = nb::none(), "camera"_a = nb::none(), "light"_a = nb::none(),
            "options"_a = nb::none(), "shadow"_a = nb::none(),
            "Without a camera the renderer frames the volume; without a light it uses its default "
            "directional light.")
        .def("close", &Renderer::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Renderer &r) { return r.h == nullptr; })
        .def(
            "__enter__", [](nb::handle self) { return nb::borrow(self); },
            nb::sig("def __enter__(self) -> Renderer"))
        .def(
            "__exit__", [](Renderer &r, nb::args) { r.close(); },
            nb::sig("def __exit__(self, *args: object) -> None"))
        .def_prop_rw(
            "volume", [](const Renderer &r) { return r.volume; },
            [](Renderer &r, nb::handle v) { renderer_set_volume(r, v); },
            nb::for_getter(nb::sig("def volume(self, /) -> Volume | None")),
            nb::for_setter(nb::sig("def volume(self, value: Volume, /) -> None")),
            "The volume (retained by the renderer).")
        .def_prop_rw(
            "tf", [](const Renderer &r) { return r.tf; },
            [](Renderer &r, nb::handle t) { renderer_set_tf(r, t); },
            nb::for_getter(nb::sig("def tf(self, /) -> TransferFunction | None")),
            nb::for_setter(nb::sig("def tf(self, value: TransferFunction, /) -> None")),
            "The view transfer function.")
        .def_prop_rw(
            "light_tf", [](const Renderer &r) { return r.light_tf; },
            [](Renderer &r, nb::handle t) { renderer_set_light_tf(r, t); },
            nb::for_getter(nb::sig("def light_tf(self, /) -> TransferFunction | None")),
            nb::for_setter(
                nb::sig("def light_tf(self, value: TransferFunction | None, /) -> None")),
            "The light pass's transfer function; None: the view transfer function.")
        .def_prop_rw(
            "camera", [](const Renderer &r) { return r.camera; },
            [](Renderer &r, const umbra_camera &c) { renderer_set_camera(r, c); },
            "The camera (None until set: the renderer frames the volume).")
        .def_prop_rw(
            "light", [](const Renderer &r) { return r.light; },
            [](Renderer &r, const umbra_light &l) { renderer_set_light(r, l); },
            "The light (None until set: the renderer's default directional light).")
        .def_prop_rw(
            "options", [](const Renderer &r) { return r.options; },
            [](Renderer &r, const umbra_render_desc &d) { renderer_set_options(r, d); },
            "A copy of the render options; assign a RenderOptions to change them.")
        .def_prop_rw(
            "shadow", [](const Renderer &r) { return r.shadow; },
            [](Renderer &r, const umbra_shadow_desc &d) { renderer_set_shadow(r, d); },
            "A copy of the shadow options; assign a ShadowOptions to change them.")
        .def(
            "set_shadow",
            [](Renderer &r, const nb::kwargs &kw) {
                umbra_shadow_desc d;
                umbra_shadow_desc_init(&d);
                apply_kwargs(d, kw, "umbra.Renderer.set_shadow");
                renderer_set_shadow(r, d);
            },
            nb::sig("def set_shadow(self, **params: typing.Any) -> None"), set_shadow_doc.c_str())
        .def(
            "set_options",
            [](Renderer &r, std::optional<umbra_render_desc> base, const nb::kwargs &kw) {
                umbra_render_desc d;
                umbra_render_desc_init(&d);
                if (base)
                    d = *base;
                apply_kwargs(d, kw, "umbra.Renderer.set_options");
                renderer_set_options(r, d);
            },
            "base"_a = nb::none(), "params"_a,
            nb::sig("def set_options(self, base: RenderOptions | None = None, **params: "
                    "typing.Any) -> None"),
            set_options_doc.c_str())
        .def(
            "render",
            [](Renderer &r, uint32_t width, uint32_t height, nb::handle out, const nb::kwargs &kw) {
                umbra_renderer h = r.get();
                if (kw.size()) {
                    umbra_shadow_desc d;
                    umbra_shadow_desc_init(&d);
                    apply_kwargs(d, kw, "umbra.Renderer.render");
                    renderer_set_shadow(r, d);
                }
                nb::object result;
                float *dst = nullptr;
                if (out.is_none()) {
                    float_out a = new_float_array({height, width, 4});
                    dst = a.data();
                    result = nb::cast(a);
                } else {
                    nb::ndarray<float> o;
                    if (!nb::try_cast(out, o, false))
                        raise_invalid(
                            "umbra.Renderer.render: out must be a writable float32 array");
                    if (o.ndim() != 3 || o.shape(0) != height || o.shape(1) != width ||
                        o.shape(2) != 4)
                        raise_invalid("umbra.Renderer.render: out has shape " +
                                      shape_text(any_array(o)) + ", not (" +
                                      std::to_string(height) + ", " + std::to_string(width) +
                                      ", 4)");
                    need_c_contiguous(
                        any_array(o), "umbra.Renderer.render: out",
                        "pass an array made with numpy.empty((h, w, 4), numpy.float32)");
                    dst = o.data();
                    result = nb::borrow(out);
                }
                check(r.ctx, umbra_renderer_render(h, width, height, dst));
                return result;
            },
            "width"_a, "height"_a, nb::kw_only(), "out"_a = nb::none(), "params"_a,
            nb::sig("def render(self, width: int, height: int, *, out: "
                    "numpy.typing.NDArray[numpy.float32] | None = None, "
                    "**params: typing.Any) -> numpy.typing.NDArray[numpy.float32]"),
            render_doc.c_str())
        .def(
            "query_shadow",
            [](Renderer &r, nb::handle points) {
                umbra_renderer h = r.get();
                any_array a = as_array(points, "umbra.Renderer.query_shadow: points");
                const float *p = float_rows(a, 3, "umbra.Renderer.query_shadow: points", "(N, 3)");
                size_t n = a.shape(0);
                /* The C call does not look inside the points; a NaN would give a meaningless factor. */
                for (size_t i = 0; i < 3 * n; ++i)
                    if (!std::isfinite(p[i]))
                        raise_invalid("umbra.Renderer.query_shadow: point " +
                                      std::to_string(i / 3) + " has a non-finite coordinate (" +
                                      std::to_string(p[i]) + ")");
                float_out o = new_float_array({n, 3});
                check(r.ctx, umbra_renderer_query_shadow(h, p, n, o.data()));
                return o;
            },
            "points"_a,
            "The current technique's RGB shadow factor at N world-space points: an (N, 3) float32 "
            "array in, an (N, 3) float32 array out. Builds the shadow structure if needed.")
        .def_prop_ro(
            "stats",
            [](const Renderer &r) {
                umbra_render_stats s;
                check(r.ctx, umbra_renderer_get_stats(r.get(), &s));
                return s;
            },
            "Timings and sizes of the last render (RenderStats).");

    /* ---- Scene ---- */
    nb::class_<Scene>(
        m, "Scene",
        "A built-in scene made in code (umbra_scene_create): its volume, transfer function, "
        "camera, light and suggested render options.")
        .def(
            "__init__",
            [](Scene *self, Context &ctx, const std::string &name, uint32_t resolution) {
                umbra_context c = ctx.get();
                umbra_scene s;
                check(c, umbra_scene_create(c, name.c_str(), resolution, &s));
                /* The wrappers take their own references; the scene struct is released at once. */
                umbra_volume_retain(s.volume);
                umbra_transfer_function_retain(s.tf);
                nb::object vol = nb::cast(Volume(c, s.volume), nb::rv_policy::move);
                nb::object tf = nb::cast(TransferFunction(c, s.tf), nb::rv_policy::move);
                new (self) Scene{nb::find(&ctx), vol, tf, s.camera, s.light, s.options};
                umbra_scene_release(&s);
            },
            "context"_a, "name"_a = "spheres", "resolution"_a = 0,
            "name: one of scene_names(). resolution: voxels per side (0: the scene's default).")
        .def_prop_ro(
            "volume", [](const Scene &s) { return s.volume; },
            nb::sig("def volume(self, /) -> Volume"))
        .def_prop_ro(
            "tf", [](const Scene &s) { return s.tf; },
            nb::sig("def tf(self, /) -> TransferFunction"))
        .def_ro("camera", &Scene::camera)
        .def_ro("light", &Scene::light)
        .def_ro("options", &Scene::options)
        .def(
            "renderer",
            [](const Scene &s) {
                nb::object r =
                    nb::type<Renderer>()(s.context, s.volume, s.tf, "camera"_a = s.camera,
                                         "light"_a = s.light, "options"_a = s.options);
                return r;
            },
            nb::sig("def renderer(self) -> Renderer"),
            "A Renderer set up with the scene's volume, transfer function, camera, light and "
            "options (as umbra-render --scene draws it, apart from the CLI's background).");
}

} // namespace umbra_py
