// SPDX-License-Identifier: Apache-2.0
/* objects.cpp: Context, Renderer and Scene: umbra's C objects wrapped so that they close
 * deterministically (close(), with) and may be collected in any order (each wrapper retains the
 * C objects it needs, its context included), with NumPy arrays in and out. Volume and
 * TransferFunction are in data.cpp.
 *
 * Progress and Ctrl-C. Every renderer carries a C progress callback (on_progress) for its whole
 * life: it runs the Python progress callable, if any, and checks for signals, so that Ctrl-C
 * cancels a long render between two bands of device work and surfaces as KeyboardInterrupt. The
 * GIL stays held during renders: the callback runs on the calling thread and may call Python
 * directly. Other Python threads run only while the callable runs Python code; one that reaches
 * the renderer then is refused (Renderer::refuse_busy), as the callable itself is. */
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "binding.h"

namespace umbra_py
{

namespace
{

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

/* set_shadow(**params) and render(**params): a ShadowOptions from the C defaults and params;
 * `preintegrated`, a render option since umbra 0.5, is kept as a keyword and sets the options. */
void renderer_set_shadow_kwargs(Renderer &r, const nb::kwargs &kw, const char *what)
{
    umbra_shadow_desc d;
    umbra_shadow_desc_init(&d);
    int preintegrated;
    apply_shadow_kwargs(d, kw, what, &preintegrated);
    if (preintegrated >= 0) {
        umbra_render_desc o = r.options;
        o.preintegrated = preintegrated;
        renderer_set_options(r, o);
    }
    renderer_set_shadow(r, d);
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

/* set_clip(planes=..., crop=...): every plane (a, b, c, d) keeps a x + b y + c z + d >= 0 in
 * the world; crop is ((x0, y0, z0), (x1, y1, z1)) in voxels, or None. The C call checks the
 * values and names the bad one. */
void renderer_set_clip(Renderer &r, const std::vector<std::array<float, 4>> &planes,
                       std::optional<std::array<std::array<float, 3>, 2>> crop)
{
    umbra_clip_desc d;
    umbra_clip_desc_init(&d);
    if (planes.size() > UMBRA_MAX_CLIP_PLANES)
        raise_invalid("umbra.Renderer.set_clip: " + std::to_string(planes.size()) +
                      " planes, at most " + std::to_string(UMBRA_MAX_CLIP_PLANES));
    d.plane_count = (uint32_t)planes.size();
    for (size_t i = 0; i < planes.size(); ++i)
        for (int k = 0; k < 4; ++k)
            d.planes[i][k] = planes[i][k];
    if (crop) {
        d.crop = 1;
        for (int k = 0; k < 3; ++k) {
            d.crop_min[k] = (*crop)[0][k];
            d.crop_max[k] = (*crop)[1][k];
        }
    }
    check(r.ctx, umbra_renderer_set_clip(r.get(), &d));
    r.clip = d;
}

nb::object clip_planes(const Renderer &r)
{
    nb::list l;
    for (uint32_t i = 0; i < r.clip.plane_count; ++i)
        l.append(nb::make_tuple(py_float(r.clip.planes[i][0]), py_float(r.clip.planes[i][1]),
                                py_float(r.clip.planes[i][2]), py_float(r.clip.planes[i][3])));
    return nb::list(l);
}

nb::object clip_crop(const Renderer &r)
{
    if (!r.clip.crop)
        return nb::none();
    const float *a = r.clip.crop_min, *b = r.clip.crop_max;
    return nb::make_tuple(nb::make_tuple(py_float(a[0]), py_float(a[1]), py_float(a[2])),
                          nb::make_tuple(py_float(b[0]), py_float(b[1]), py_float(b[2])));
}

void renderer_set_channel_tf(Renderer &r, uint32_t channel, nb::handle t, nb::handle lt)
{
    umbra_transfer_function h = nb::cast<TransferFunction &>(t).get("TransferFunction");
    umbra_transfer_function lh =
        lt.is_none() ? nullptr : nb::cast<TransferFunction &>(lt).get("TransferFunction");
    check(r.ctx, umbra_renderer_set_channel_transfer_function(r.get(), channel, h, lh));
    if (channel == 0) { /* channel 0's are the renderer's own */
        r.tf = nb::borrow(t);
        r.light_tf = nb::borrow(lt);
    } else {
        r.channel_tf[channel] = nb::borrow(t);
        r.channel_light_tf[channel] = nb::borrow(lt);
    }
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

/* umbra_progress_callback: nonzero cancels. A Python exception (the callable's, or
 * KeyboardInterrupt from PyErr_CheckSignals) is left in Python's error indicator and cancels;
 * finish_call raises it once the C call has returned. Nothing calls Python after that. */
int on_progress(void *user, float fraction)
{
    Renderer &r = *(Renderer *)user;
    if (r.python_error)
        return 1;
    if (PyErr_CheckSignals() != 0) {
        r.python_error = true;
        return 1;
    }
    if (r.progress.is_none())
        return 0;
    try {
        nb::object f = r.progress; /* the callable may replace itself */
        nb::object res = f(py_float(fraction));
        /* Truth-testing the result runs Python (__bool__, __len__) and may raise: that exception
         * cancels like the callable's own. */
        int cancel = PyObject_IsTrue(res.ptr());
        if (cancel < 0) {
            r.python_error = true;
            return 1;
        }
        return cancel;
    } catch (nb::python_error &e) {
        e.restore();
        r.python_error = true;
        return 1;
    }
}

/* The Python garbage collector's view of a Renderer: the objects it holds. A progress callable
 * often refers back to the renderer (a bound method of an object that owns it, a closure, a
 * module's globals): without these slots such a cycle would never be collected. */
int renderer_traverse(PyObject *self, visitproc visit, void *arg)
{
    Py_VISIT(Py_TYPE(self));
    if (!nb::inst_ready(self))
        return 0;
    Renderer *r = nb::inst_ptr<Renderer>(self);
    Py_VISIT(r->progress.ptr());
    Py_VISIT(r->volume.ptr());
    Py_VISIT(r->tf.ptr());
    Py_VISIT(r->light_tf.ptr());
    for (int c = 0; c < UMBRA_MAX_CHANNELS; ++c) {
        Py_VISIT(r->channel_tf[c].ptr());
        Py_VISIT(r->channel_light_tf[c].ptr());
    }
    return 0;
}

/* Breaks a cycle by dropping the callable only: the C renderer keeps its own references on the
 * volume and transfer functions, so the getters stay right. */
int renderer_clear(PyObject *self)
{
    Renderer *r = nb::inst_ptr<Renderer>(self);
    r->progress = nb::none();
    return 0;
}

PyType_Slot renderer_slots[] = {{Py_tp_traverse, (void *)renderer_traverse},
                                {Py_tp_clear, (void *)renderer_clear},
                                {0, nullptr}};

/* Marks a renderer busy for the length of a C call that reports progress. */
struct Busy {
    Renderer &r;
    explicit Busy(Renderer &rr) : r(rr)
    {
        r.busy = true;
        r.busy_thread = PyThread_get_thread_ident();
    }
    ~Busy() { r.busy = false; }
    Busy(const Busy &) = delete;
};

void renderer_close(Renderer &r)
{
    if (r.busy)
        r.refuse_busy("closed");
    r.close();
}

/* Raises what a C call with progress reports ended in: the Python exception that cancelled it
 * (the C status, CANCELLED, is then dropped from the context) or umbra.Error. */
void finish_call(Renderer &r, umbra_status st)
{
    if (r.python_error) {
        r.python_error = false;
        if (st != UMBRA_SUCCESS)
            umbra_context_take_error(r.ctx, nullptr);
        throw nb::python_error();
    }
    check(r.ctx, st);
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
                d.cache_dir =
                    cache_dir ? path_arg(*cache_dir, "umbra.Context: cache_dir") : nullptr;
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
            [](Context &c, const std::string &path,
               std::optional<std::vector<std::string>> data_roots) {
                const char *p = path_arg(path, "umbra.Context.load_volume: path");
                std::vector<const char *> roots; /* into data_roots, alive for the call */
                if (data_roots)
                    for (const std::string &r : *data_roots)
                        roots.push_back(path_arg(r, "umbra.Context.load_volume: data_roots entry"));
                umbra_volume_load_options o;
                umbra_volume_load_options_init(&o);
                o.data_roots = roots.empty() ? nullptr : roots.data();
                o.data_root_count = roots.size();
                umbra_volume v = nullptr;
                check(c.get(), umbra_volume_load_with_options(c.get(), p, &o, &v));
                return Volume(c.h, v);
            },
            "path"_a, nb::kw_only(), "data_roots"_a = nb::none(),
            "Loads .nrrd/.nhdr (Teem), .nii/.nii.gz (NIfTI-1/2, nifticlib), .mha/.mhd "
            "(MetaImage), .dat (Voreen), .tif/.tiff (TIFF stacks, OME-TIFF), .dcm (DICOM), or a "
            "directory (a DICOM series, or a TIFF stack when it holds .tif files) through "
            "umbra_io, with the file's spacing and world transform (NRRD space directions, "
            "NIfTI sform/qform, MetaImage Offset and TransformMatrix, DICOM patient space). A "
            "detached data file (NRRD 'data file', MetaImage ElementDataFile, Voreen "
            "ObjectFileName) must lie in the header's own directory (after symbolic links and "
            "'..'), else umbra.Error ERROR_IO naming it; data_roots, a list of directories, "
            "allows those too ('/' allows any file).")
        .def(
            "load_volume",
            [](Context &c, const std::vector<std::string> &paths) {
                std::vector<const char *> p;
                bool tiff = !paths.empty();
                for (const std::string &s : paths) {
                    p.push_back(path_arg(s, "umbra.Context.load_volume: paths entry"));
                    size_t dot = s.rfind('.');
                    std::string ext = dot == std::string::npos ? "" : s.substr(dot);
                    tiff &= ext == ".tif" || ext == ".tiff" || ext == ".TIF" || ext == ".TIFF";
                }
                umbra_volume v = nullptr;
                check(c.get(), tiff ? umbra_volume_load_tiff(c.get(), p.data(), p.size(), &v)
                                    : umbra_volume_load_dicom(c.get(), p.data(), p.size(), &v));
                return Volume(c.h, v);
            },
            "paths"_a,
            "Loads a list of files as one volume: single-page TIFFs (all named .tif/.tiff) as "
            "slices in the order given (umbra_volume_load_tiff), else the files of one DICOM "
            "series in any order, sorted by position (umbra_volume_load_dicom).")
        .def(
            "load_transfer_function",
            [](Context &c, const std::string &path) {
                umbra_transfer_function t = nullptr;
                const char *p = path_arg(path, "umbra.Context.load_transfer_function: path");
                check(c.get(), umbra_transfer_function_load(c.get(), p, &t));
                return TransferFunction(c.h, t);
            },
            "path"_a,
            "Loads umbra's transfer-function text format through umbra_io, or a ParaView JSON "
            "preset (a path ending in .json) with load_paraview's defaults.")
        .def("load_paraview", &load_paraview, "path"_a, nb::kw_only(), "preset"_a = nb::none(),
             "resolution"_a = 1024, "range"_a = nb::none(),
             "A ParaView JSON preset, as TransferFunction.load_paraview(context, path, ...).")
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
                const char *p = path_arg(path, "umbra.Context.write_image: path");
                check(c.get(), umbra_image_write(c.get(), p, (uint32_t)a.shape(1),
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
                check(c.get(), umbra_image_read(c.get(),
                                                path_arg(path, "umbra.Context.read_image: path"),
                                                &w, &h, &p));
                nb::capsule owner(p, [](void *q) noexcept { std::free(q); });
                return float_out(p, {h, w, 4}, owner);
            },
            "path"_a, "Reads a PNG or EXR as an (H, W, 4) float32 linear premultiplied array.");

    bind_data(m);

    /* ---- RenderStats ---- */
    nb::class_<umbra_render_stats>(m, "RenderStats", "umbra_render_stats of the last render")
        .def_ro("shadow_build_ms", &umbra_render_stats::shadow_build_ms)
        .def_ro("render_ms", &umbra_render_stats::render_ms)
        .def_prop_ro("shadow_rebuilt",
                     [](const umbra_render_stats &s) { return s.shadow_rebuilt != 0; })
        .def_ro("shadow_memory_bytes", &umbra_render_stats::shadow_memory_bytes)
        .def_ro("light_channels", &umbra_render_stats::light_channels)
        .def_ro("slices", &umbra_render_stats::slices)
        .def_ro("samples", &umbra_render_stats::samples)
        .def_ro("map_size", &umbra_render_stats::map_size,
                "light-space techniques: texels per side of the map in use (the size auto "
                "chose), else 0")
        .def_prop_ro(
            "draft", [](const umbra_render_stats &s) { return s.draft != 0; },
            "the last frame used its technique's draft (RenderOptions.interaction 'auto'): "
            "render again with nothing changed for the full structure");

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
        "transfer function stay).",
        nb::type_slots(renderer_slots))
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
                    umbra_clip_desc_init(&self->clip);
                    check(c, umbra_renderer_create(c, &self->h));
                    self->ctx = c;
                    umbra_context_retain(c);
                    /* self lives inside its Python object and never moves. */
                    check(c, umbra_renderer_set_progress(self->h, on_progress, self));
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
        .def("close", &renderer_close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Renderer &r) { return r.h == nullptr; })
        .def(
            "__enter__", [](nb::handle self) { return nb::borrow(self); },
            nb::sig("def __enter__(self) -> Renderer"))
        .def(
            "__exit__", [](Renderer &r, nb::args) { renderer_close(r); },
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
        .def("set_clip", &renderer_set_clip, nb::kw_only(),
             "planes"_a = std::vector<std::array<float, 4>>{}, "crop"_a = nb::none(),
             "umbra_renderer_set_clip: keeps only the region every plane and the crop box keep, "
             "for the view and the light alike (a clipped-away occluder casts no shadow, in "
             "every technique). planes: up to 6 (a, b, c, d) in the volume's world, each "
             "keeping a x + b y + c z + d >= 0. crop: ((x0, y0, z0), (x1, y1, z1)) in voxel "
             "coordinates (voxel (i, j, k)'s centre at (i, j, k)), or None. Replaces the "
             "previous region; set_clip() clips nothing. A bad value raises umbra.Error naming "
             "it and changes nothing.")
        .def_prop_ro("clip_planes", &clip_planes,
                     nb::sig("def clip_planes(self, /) -> list[tuple[float, float, float, "
                             "float]]"),
                     "The clip planes set with set_clip.")
        .def_prop_ro("crop", &clip_crop,
                     nb::sig("def crop(self, /) -> tuple[tuple[float, float, float], "
                             "tuple[float, float, float]] | None"),
                     "The crop box set with set_clip, or None.")
        .def("set_channel_tf", &renderer_set_channel_tf, "channel"_a, "tf"_a,
             "light_tf"_a.none() = nb::none(),
             "umbra_renderer_set_channel_transfer_function: the transfer functions of channel "
             "`channel` of a multi-channel volume (channel 0's are tf and light_tf). The "
             "channels mix as emission-absorption media: colours weighted by extinction, the "
             "light absorbed by the summed extinction, so shadows take the colour of what casts "
             "them. Every channel needs one before render().")
        .def(
            "set_shadow",
            [](Renderer &r, const nb::kwargs &kw) {
                renderer_set_shadow_kwargs(r, kw, "umbra.Renderer.set_shadow");
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
                if (kw.size())
                    renderer_set_shadow_kwargs(r, kw, "umbra.Renderer.render");
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
                umbra_status st;
                {
                    Busy busy(r);
                    st = umbra_renderer_render(h, width, height, dst);
                }
                finish_call(r, st);
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
                umbra_status st;
                {
                    Busy busy(r);
                    st = umbra_renderer_query_shadow(h, p, n, o.data());
                }
                finish_call(r, st);
                return o;
            },
            "points"_a,
            "The current technique's RGB shadow factor at N world-space points: an (N, 3) float32 "
            "array in, an (N, 3) float32 array out. Builds the shadow structure if needed.")
        .def_prop_rw(
            "progress", [](const Renderer &r) { return r.progress; },
            [](Renderer &r, nb::handle f) {
                if (!r.h) /* not get(): the callable may replace itself during a call */
                    raise_closed("Renderer");
                if (!f.is_none() && !PyCallable_Check(f.ptr()))
                    throw nb::type_error(("umbra.Renderer.progress: a " +
                                          std::string(nb::type_name(f.type()).c_str()) +
                                          " is not callable; pass f(fraction) or None")
                                             .c_str());
                r.progress = nb::borrow(f);
            },
            nb::for_setter(nb::arg("value").none()),
            nb::for_getter(nb::sig("def progress(self, /) -> typing.Callable[[float], "
                                   "bool | None] | None")),
            nb::for_setter(nb::sig("def progress(self, value: typing.Callable[[float], bool | "
                                   "None] | None, /) -> None")),
            "A callable f(fraction) run during render() and query_shadow() between pieces of "
            "device work, with the fraction done: in [0, 1], non-decreasing, exactly 1 in the "
            "last call of a call that succeeds. A true return value cancels: the call raises "
            "umbra.Error with status ERROR_CANCELLED and the renderer stays usable. An exception "
            "raised by f, or by truth-testing its result, cancels the same way and propagates. "
            "Ctrl-C cancels every render (with or without f) at the next piece and raises "
            "KeyboardInterrupt. Neither f nor another thread may use this renderer while the "
            "call runs (RuntimeError). None: no callable.")
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
