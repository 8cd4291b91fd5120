/* umbra_python.cpp: the Python module umbra._umbra, a nanobind binding of umbra's public C API
 * (umbra/umbra.h) and of its file layer (umbra/io.h).
 *
 * What it is for: NumPy arrays in and out without copies where the C API allows it (a volume is
 * read from the caller's array in place and copied once, to the device; renders and shadow
 * queries write straight into the array handed back), every failure raised as umbra.Error with
 * umbra's status and message, and objects that close deterministically and may be collected in
 * any order. Each wrapper holds its own reference (umbra_*_retain) on the C objects it needs,
 * including its context, so no Python-side ordering is required.
 *
 * The option structs (umbra_render_desc, umbra_shadow_desc, umbra_camera, umbra_light) are bound
 * through their C definitions: each field is named once below with a pointer to the C member, and
 * its type, storage and default come from the C header and the C desc_init functions. A new C
 * field is one more field(...) line. The file is long (~800 lines) because it is one binding of
 * one API; splitting it would scatter the shared helpers. */
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "umbra/io.h"
#include "umbra/umbra.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

/* ---- errors --------------------------------------------------------------------------------- */

/* umbra.Error, created at import; the module holds the reference. */
PyObject *error_type = nullptr;

nb::object status_object(umbra_status st)
{
    /* A status this binding does not list yet (a newer library) stays a plain int. */
    nb::object obj;
    try {
        obj = nb::cast(st);
    } catch (...) {
        obj = nb::int_((int)st);
    }
    return obj;
}

[[noreturn]] void raise_error(umbra_status st, const std::string &message)
{
    std::string text = std::string(umbra_status_to_string(st)) + ": " + message;
    nb::object exc = nb::borrow(error_type)(nb::str(text.c_str()));
    nb::setattr(exc, "status", status_object(st));
    nb::setattr(exc, "message", nb::str(message.c_str()));
    PyErr_SetObject(error_type, exc.ptr());
    throw nb::python_error();
}

[[noreturn]] void raise_invalid(const std::string &message)
{
    raise_error(UMBRA_ERROR_INVALID_ARGUMENT, message);
}

/* Raises the context's message for a failed call, and clears the context's sticky error so the
 * next failure reports its own. */
void check(umbra_context ctx, umbra_status st)
{
    if (st == UMBRA_SUCCESS)
        return;
    std::string message = ctx ? umbra_context_last_message(ctx) : "";
    if (ctx)
        umbra_context_take_error(ctx, nullptr);
    raise_error(st, message);
}

[[noreturn]] void raise_closed(const char *what)
{
    throw nb::value_error((std::string("umbra.") + what + " is closed").c_str());
}

/* ---- arrays ----------------------------------------------------------------------------------- */

using any_array = nb::ndarray<nb::ro>;
using float_out = nb::ndarray<nb::numpy, float>;

std::string dtype_name(nb::dlpack::dtype t)
{
    const char *kind = "unknown";
    switch ((nb::dlpack::dtype_code)t.code) {
    case nb::dlpack::dtype_code::Int: kind = "int"; break;
    case nb::dlpack::dtype_code::UInt: kind = "uint"; break;
    case nb::dlpack::dtype_code::Float: kind = "float"; break;
    case nb::dlpack::dtype_code::Complex: kind = "complex"; break;
    case nb::dlpack::dtype_code::Bool: return "bool";
    default: break;
    }
    return kind + std::to_string(t.bits);
}

std::string shape_text(const any_array &a)
{
    std::string s = "(";
    for (size_t i = 0; i < a.ndim(); ++i)
        s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

/* Takes any object as a host array without copying; a clear error for anything else. */
any_array as_array(nb::handle obj, const char *what)
{
    any_array a;
    if (!nb::try_cast(obj, a, false))
        raise_invalid(std::string(what) + ": a " + nb::type_name(obj.type()).c_str() +
                      " is not an array; pass a NumPy array (native byte order)");
    if (a.device_type() != nb::device::cpu::value)
        raise_invalid(std::string(what) + ": the array is not in host memory");
    return a;
}

void need_c_contiguous(const any_array &a, const char *what, const char *hint)
{
    int64_t expect = 1;
    for (size_t i = a.ndim(); i-- > 0;) {
        if (a.shape(i) != 1 && a.stride(i) != expect) {
            std::string strides;
            for (size_t k = 0; k < a.ndim(); ++k)
                strides += (k ? ", " : "") + std::to_string(a.stride(k));
            raise_invalid(std::string(what) + ": the array is not C-contiguous (shape " +
                          shape_text(a) + ", strides (" + strides + ") in elements); " + hint);
        }
        expect *= (int64_t)a.shape(i);
    }
}

const float *float_rows(const any_array &a, size_t cols, const char *what, const char *layout)
{
    if (a.dtype() != nb::dtype<float>())
        raise_invalid(std::string(what) + ": dtype " + dtype_name(a.dtype()) +
                      " is not float32; pass array.astype(numpy.float32)");
    if (a.ndim() != 2 || a.shape(1) != cols)
        raise_invalid(std::string(what) + ": shape " + shape_text(a) + " is not " + layout);
    need_c_contiguous(a, what, "pass numpy.ascontiguousarray(array)");
    return (const float *)a.data();
}

/* A new float32 NumPy array of the given shape that owns its memory. */
float_out new_float_array(std::initializer_list<size_t> shape)
{
    size_t n = 1;
    for (size_t s : shape)
        n *= s;
    float *p = new (std::nothrow) float[n ? n : 1];
    if (!p)
        raise_error(UMBRA_ERROR_OUT_OF_MEMORY, "cannot allocate " + std::to_string(n * 4) +
                                                   " bytes for the result");
    nb::capsule owner(p, [](void *q) noexcept { delete[] (float *)q; });
    return float_out(p, shape, owner);
}

/* ---- fields of the C option structs ------------------------------------------------------------
 * Each bound struct T keeps a table of its fields: name, doc, getter and a setter from any Python
 * object (for keyword arguments). The Python properties come from the same table. */

template <class T> struct Fields {
    struct Field {
        std::string name, type, doc;
        std::function<nb::object(const T &)> get;
        std::function<void(T &, nb::handle)> set;
    };
    static std::vector<Field> &all()
    {
        static std::vector<Field> v;
        return v;
    }
    static const Field *find(const std::string &name)
    {
        for (const Field &f : all())
            if (f.name == name)
                return &f;
        return nullptr;
    }
    static std::string names()
    {
        std::string s;
        for (const Field &f : all())
            s += (s.empty() ? "" : ", ") + f.name;
        return s;
    }
};

template <class E> E enum_from(nb::handle v)
{
    if (nb::isinstance<nb::str>(v)) {
        std::string s = nb::cast<std::string>(v);
        for (char &c : s)
            c = (char)std::toupper((unsigned char)c);
        nb::handle type = nb::type<E>();
        if (nb::hasattr(type, s.c_str()))
            return nb::cast<E>(type.attr(s.c_str()));
        throw nb::cast_error();
    }
    return nb::cast<E>(v);
}

template <class T> void add_field(nb::class_<T> &cls, typename Fields<T>::Field f)
{
    auto get = f.get;
    auto set = f.set;
    cls.def_prop_rw(f.name.c_str(), [get](const T &d) { return get(d); },
                    [set](T &d, nb::handle v) { set(d, v); }, nb::for_setter(nb::arg("value")),
                    nb::for_getter(nb::sig(("def " + f.name + "(self, /) -> " + f.type).c_str())),
                    nb::for_setter(nb::sig(("def " + f.name + "(self, value: " + f.type +
                                            ", /) -> None").c_str())),
                    f.doc.c_str());
    Fields<T>::all().push_back(std::move(f));
}

/* A float32 as the shortest decimal that reads back to it (0.02, not 0.019999999552965164), so
 * reprs and docstrings show the numbers the C defaults were written as. */
nb::float_ py_float(float x)
{
    if (!std::isfinite(x))
        return nb::float_((double)x);
    char buf[32];
    for (int prec = 1; prec <= 9; ++prec) {
        std::snprintf(buf, sizeof buf, "%.*g", prec, (double)x);
        if (std::strtof(buf, nullptr) == x)
            break;
    }
    return nb::float_(std::strtod(buf, nullptr));
}

template <class T> void field(nb::class_<T> &cls, const char *name, float T::*m, const char *doc)
{
    add_field(cls, {name, "float", doc, [m](const T &d) { return nb::object(py_float(d.*m)); },
                    [m](T &d, nb::handle v) { d.*m = nb::cast<float>(v); }});
}

template <class T> void field(nb::class_<T> &cls, const char *name, uint32_t T::*m, const char *doc)
{
    add_field(cls, {name, "int", doc, [m](const T &d) { return nb::object(nb::int_(d.*m)); },
                    [m](T &d, nb::handle v) {
                        if (nb::isinstance<nb::bool_>(v))
                            throw nb::cast_error();
                        d.*m = nb::cast<uint32_t>(v);
                    }});
}

/* int fields of the C structs are flags ("nonzero: ..."): bound as bool. */
template <class T> void flag(nb::class_<T> &cls, const char *name, int T::*m, const char *doc)
{
    add_field(cls, {name, "bool", doc, [m](const T &d) { return nb::object(nb::bool_(d.*m != 0)); },
                    [m](T &d, nb::handle v) {
                        if (!PyBool_Check(v.ptr()) && !PyLong_Check(v.ptr()))
                            throw nb::cast_error();
                        d.*m = PyObject_IsTrue(v.ptr()) ? 1 : 0;
                    }});
}

template <class T, size_t N>
void field(nb::class_<T> &cls, const char *name, float (T::*m)[N], const char *doc)
{
    std::string type = "tuple[" + std::string("float") ;
    for (size_t i = 1; i < N; ++i)
        type += ", float";
    type += "]";
    add_field(cls, {name, type, doc,
                    [m](const T &d) {
                        nb::list l;
                        for (size_t i = 0; i < N; ++i)
                            l.append(py_float((d.*m)[i]));
                        return nb::object(nb::tuple(l));
                    },
                    [m](T &d, nb::handle v) {
                        auto a = nb::cast<std::array<float, N>>(v);
                        for (size_t i = 0; i < N; ++i)
                            (d.*m)[i] = a[i];
                    }});
}

template <class T, class E>
void enum_field(nb::class_<T> &cls, const char *name, E T::*m, const char *type, const char *doc)
{
    add_field(cls, {name, std::string(type) + " | str", doc,
                    [m](const T &d) { return nb::cast(d.*m); },
                    [m](T &d, nb::handle v) { d.*m = enum_from<E>(v); }});
}

template <class T> void apply_kwargs(T &d, const nb::kwargs &kw, const char *what)
{
    for (auto [k, v] : kw) {
        std::string key = nb::cast<std::string>(k);
        const auto *f = Fields<T>::find(key);
        if (!f)
            throw nb::type_error((std::string(what) + ": unknown parameter '" + key +
                                  "'; the parameters are " + Fields<T>::names())
                                     .c_str());
        try {
            f->set(d, v);
        } catch (const nb::cast_error &) {
            std::string r = nb::cast<std::string>(nb::repr(v));
            throw nb::type_error((std::string(what) + ": " + key + "=" + r + " is not a valid " +
                                  f->type)
                                     .c_str());
        }
    }
}

template <class T> std::string repr_of(const T &d, const char *name)
{
    std::string s = std::string("umbra.") + name + "(";
    bool first = true;
    for (const auto &f : Fields<T>::all()) {
        s += (first ? "" : ", ") + f.name + "=" + nb::cast<std::string>(nb::repr(f.get(d)));
        first = false;
    }
    return s + ")";
}

/* "name: type = default  doc" per field, the defaults read from an initialised C struct. */
template <class T> std::string field_docs(const T &defaults)
{
    std::string s;
    for (const auto &f : Fields<T>::all())
        s += "    " + f.name + " (" + f.type + ", default " +
             nb::cast<std::string>(nb::repr(f.get(defaults))) + "): " + f.doc + "\n";
    return s;
}

template <class T> void make_repr(nb::class_<T> &cls, const char *name)
{
    cls.def("__repr__", [name](const T &d) { return repr_of(d, name); });
    cls.def("__eq__", [](const T &a, const T &b) {
        for (const auto &f : Fields<T>::all())
            if (!f.get(a).equal(f.get(b)))
                return false;
        return true;
    });
}

/* ---- the object wrappers ------------------------------------------------------------------------ */

struct Context {
    umbra_context h = nullptr;
    Context() = default;
    Context(const Context &) = delete;
    ~Context() { close(); }
    void close()
    {
        umbra_context_release(h);
        h = nullptr;
    }
    umbra_context get() const
    {
        if (!h)
            raise_closed("Context");
        return h;
    }
};

/* Volumes and transfer functions hold a reference on their context for error messages (the C
 * objects hold one too). */
template <class H, void (*Release)(H), void (*Retain)(H)> struct Handle {
    H h = nullptr;
    umbra_context ctx = nullptr;
    Handle() = default;
    Handle(umbra_context c, H adopted) : h(adopted), ctx(c) { umbra_context_retain(ctx); }
    Handle(const Handle &) = delete;
    Handle(Handle &&o) noexcept : h(o.h), ctx(o.ctx) { o.h = nullptr, o.ctx = nullptr; }
    ~Handle() { close(); }
    void close()
    {
        Release(h);
        umbra_context_release(ctx);
        h = nullptr;
        ctx = nullptr;
    }
    H get(const char *what) const
    {
        if (!h)
            raise_closed(what);
        return h;
    }
};

using Volume = Handle<umbra_volume, umbra_volume_release, umbra_volume_retain>;
using TransferFunction = Handle<umbra_transfer_function, umbra_transfer_function_release,
                                umbra_transfer_function_retain>;

struct Renderer {
    umbra_renderer h = nullptr;
    umbra_context ctx = nullptr;
    /* What was set, for the getters (the C renderer holds its own references). */
    nb::object volume = nb::none(), tf = nb::none(), light_tf = nb::none();
    std::optional<umbra_camera> camera;
    std::optional<umbra_light> light;
    umbra_render_desc options;
    umbra_shadow_desc shadow;
    Renderer() = default;
    Renderer(const Renderer &) = delete;
    ~Renderer() { close(); }
    void close()
    {
        umbra_renderer_release(h);
        umbra_context_release(ctx);
        h = nullptr;
        ctx = nullptr;
        volume = tf = light_tf = nb::none();
    }
    umbra_renderer get() const
    {
        if (!h)
            raise_closed("Renderer");
        return h;
    }
};

struct Scene {
    nb::object context, volume, tf;
    umbra_camera camera;
    umbra_light light;
    umbra_render_desc options;
};

struct VolumeInfo {
    umbra_volume_info info;
};

Context &context_of(nb::handle ctx)
{
    Context *c = nullptr;
    if (!nb::try_cast(ctx, c) || !c)
        throw nb::type_error("expected an umbra.Context");
    c->get();
    return *c;
}

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

NB_MODULE(_umbra, m)
{
    m.doc() = "umbra: shadows in direct volume rendering (OpenCL). The compiled binding of the C "
              "API; import the package umbra rather than this module.";

    /* ---- enums ---- */
    nb::enum_<umbra_status>(m, "Status", "umbra_status: the result of a call.")
        .value("SUCCESS", UMBRA_SUCCESS)
        .value("ERROR_INVALID_ARGUMENT", UMBRA_ERROR_INVALID_ARGUMENT,
               "a NULL pointer, a zero size, a NaN, a value out of range")
        .value("ERROR_OUT_OF_MEMORY", UMBRA_ERROR_OUT_OF_MEMORY, "host or device allocation failed")
        .value("ERROR_OPENCL", UMBRA_ERROR_OPENCL, "an OpenCL call failed")
        .value("ERROR_BUILD", UMBRA_ERROR_BUILD, "a kernel program failed to build")
        .value("ERROR_IO", UMBRA_ERROR_IO, "a file could not be opened, read or written")
        .value("ERROR_FORMAT", UMBRA_ERROR_FORMAT, "a file's contents are malformed")
        .value("ERROR_UNSUPPORTED", UMBRA_ERROR_UNSUPPORTED,
               "a valid request this device or technique cannot do")
        .value("ERROR_NO_DEVICE", UMBRA_ERROR_NO_DEVICE, "no OpenCL device matched the request");

    nb::enum_<umbra_shadow_technique>(m, "Technique", "umbra_shadow_technique; keyword arguments "
                                                      "also take the CLI's names ('cssm').")
        .value("NONE", UMBRA_SHADOW_NONE, "no shadows")
        .value("REFERENCE", UMBRA_SHADOW_REFERENCE, "exact: a shadow ray from every sample")
        .value("THRESHOLD", UMBRA_SHADOW_THRESHOLD, "opacity-threshold shadow map")
        .value("DEEP", UMBRA_SHADOW_DEEP, "deep shadow map (Hadwiger et al. 2006)")
        .value("CSSM", UMBRA_SHADOW_CSSM, "colored stochastic shadow map (Weidner & Linsen)")
        .value("CONVOLUTION", UMBRA_SHADOW_CONVOLUTION, "slice-based convolution shadows");

    nb::enum_<umbra_transmission>(m, "Transmission", "umbra_transmission")
        .value("GREY", UMBRA_TRANSMISSION_GREY, "every channel attenuated by the opacity alone")
        .value("COLORED", UMBRA_TRANSMISSION_COLORED, "transmission colour from the light TF's RGB");

    nb::enum_<umbra_projection>(m, "Projection", "umbra_projection")
        .value("PERSPECTIVE", UMBRA_PERSPECTIVE)
        .value("ORTHOGRAPHIC", UMBRA_ORTHOGRAPHIC);

    nb::enum_<umbra_light_type>(m, "LightType", "umbra_light_type")
        .value("POINT", UMBRA_LIGHT_POINT)
        .value("DIRECTIONAL", UMBRA_LIGHT_DIRECTIONAL);

    nb::enum_<umbra_sampler_kind>(m, "Sampler", "umbra_sampler_kind: how volumes are sampled")
        .value("AUTO", UMBRA_SAMPLER_AUTO, "buffer on CPU devices, image on GPUs")
        .value("BUFFER", UMBRA_SAMPLER_BUFFER)
        .value("IMAGE", UMBRA_SAMPLER_IMAGE);

    /* ---- umbra.Error ---- */
    error_type = PyErr_NewExceptionWithDoc(
        "umbra.Error",
        "An umbra call failed. .status is the umbra.Status, .message umbra's message, which names "
        "the function and the offending value.",
        nullptr, nullptr);
    m.attr("Error") = nb::steal(error_type);

    m.def("version", []() { return std::string(umbra_version()); },
          "The C library's version, 'MAJOR.MINOR.PATCH'.");
    m.def("scene_names", []() {
        std::vector<std::string> v;
        for (const char *const *n = umbra_scene_names(); *n; ++n)
            v.push_back(*n);
        return v;
    }, "Names of the built-in scenes.");
    m.def("technique_names", []() {
        std::vector<std::string> v;
        for (int t = 0;; ++t) {
            const char *n = umbra_shadow_technique_name((umbra_shadow_technique)t);
            if (!n)
                break;
            v.push_back(n);
        }
        return v;
    }, "Names of the shadow techniques, in the order of umbra.Technique.");

    /* ---- option structs, bound field by field through their C definitions ---- */
    nb::class_<umbra_render_desc> ro(m, "RenderOptions");
    ro.def("__init__", [](umbra_render_desc *d, const nb::kwargs &kw) {
        new (d) umbra_render_desc;
        umbra_render_desc_init(d);
        apply_kwargs(*d, kw, "umbra.RenderOptions");
    });
    field(ro, "step", &umbra_render_desc::step, "sampling step along view rays, in voxels");
    flag(ro, "jitter", &umbra_render_desc::jitter, "start each ray at a seeded random fraction of a step");
    field(ro, "seed", &umbra_render_desc::seed, "seed for the jitter (and stochastic techniques)");
    field(ro, "termination", &umbra_render_desc::termination,
          "early ray termination once accumulated opacity exceeds this (1 disables it)");
    flag(ro, "empty_space_skipping", &umbra_render_desc::empty_space_skipping,
         "skip bricks the transfer function makes empty");
    flag(ro, "shading", &umbra_render_desc::shading, "gradient Blinn-Phong local shading");
    field(ro, "kd", &umbra_render_desc::kd, "Blinn-Phong diffuse coefficient");
    field(ro, "ks", &umbra_render_desc::ks, "Blinn-Phong specular coefficient");
    field(ro, "shininess", &umbra_render_desc::shininess, "Blinn-Phong exponent");
    field(ro, "ambient", &umbra_render_desc::ambient, "ambient light RGB");
    field(ro, "background", &umbra_render_desc::background, "premultiplied RGBA behind everything");
    flag(ro, "ground_plane", &umbra_render_desc::ground_plane,
         "an opaque plane under the volume receives shadows");
    field(ro, "ground_color", &umbra_render_desc::ground_color, "RGB of the ground plane");
    field(ro, "ground_offset", &umbra_render_desc::ground_offset,
          "gap between the box's lowest y and the plane, a fraction of the box diagonal");
    enum_field(ro, "transmission", &umbra_render_desc::transmission, "Transmission",
               "grey shadows, or coloured from the light transfer function's RGB");
    make_repr(ro, "RenderOptions");

    nb::class_<umbra_shadow_desc> so(m, "ShadowOptions");
    so.def("__init__", [](umbra_shadow_desc *d, const nb::kwargs &kw) {
        new (d) umbra_shadow_desc;
        umbra_shadow_desc_init(d);
        apply_kwargs(*d, kw, "umbra.ShadowOptions");
    });
    enum_field(so, "technique", &umbra_shadow_desc::technique, "Technique",
               "none, reference, threshold, deep, cssm or convolution");
    field(so, "reference_step", &umbra_shadow_desc::reference_step,
          "reference: shadow-ray step in voxels");
    field(so, "map_size", &umbra_shadow_desc::map_size, "light-space maps: map_size^2 texels");
    field(so, "map_step", &umbra_shadow_desc::map_step, "light-space maps: light-ray step in voxels");
    field(so, "threshold", &umbra_shadow_desc::threshold,
          "threshold map: accumulated light opacity in (0, 1) at which the depth is stored");
    field(so, "taps", &umbra_shadow_desc::taps,
          "CSSM / filtered threshold: texels averaged per lookup, 1, 7, 13 or 21");
    field(so, "epsilon", &umbra_shadow_desc::epsilon, "deep map: compression error bound in [0, 1]");
    field(so, "max_nodes", &umbra_shadow_desc::max_nodes,
          "deep map: nodes per texel, 0 (unbounded) or 2..64");
    field(so, "block_size", &umbra_shadow_desc::block_size, "deep map: node layers per block, 1..256");
    field(so, "prefilter", &umbra_shadow_desc::prefilter, "deep map: sub-pixel rays per texel, 1 or 5");
    flag(so, "lookup_table", &umbra_shadow_desc::lookup_table,
         "deep map: use the pre-compressed segment table");
    field(so, "seed", &umbra_shadow_desc::seed, "CSSM: seed of the random numbers");
    field(so, "slice_distance", &umbra_shadow_desc::slice_distance,
          "convolution: voxels between slices, [0.02, 16]");
    field(so, "subsamples", &umbra_shadow_desc::subsamples,
          "convolution (SCS): volume samples between two slices, 0..64");
    flag(so, "preintegrated", &umbra_shadow_desc::preintegrated, "pre-integrated segments");
    field(so, "cone_angle_degrees", &umbra_shadow_desc::cone_angle_degrees,
          "convolution: half-angle of the blur cone per slice, [0, 60]");
    make_repr(so, "ShadowOptions");

    nb::class_<umbra_camera> cam(m, "Camera");
    cam.def("__init__", [](umbra_camera *c, std::array<float, 3> eye, std::array<float, 3> target,
                           std::array<float, 3> up, float fovy, std::optional<float> ortho) {
        new (c) umbra_camera;
        std::memset(c, 0, sizeof *c);
        for (int i = 0; i < 3; ++i) {
            c->eye[i] = eye[i];
            c->target[i] = target[i];
            c->up[i] = up[i];
        }
        c->fovy_degrees = fovy;
        c->projection = ortho ? UMBRA_ORTHOGRAPHIC : UMBRA_PERSPECTIVE;
        c->ortho_height = ortho ? *ortho : 0.0f;
    }, "eye"_a, "target"_a = std::array<float, 3>{0, 0, 0}, "up"_a = std::array<float, 3>{0, 1, 0},
       "fovy_degrees"_a = 30.0f, "ortho_height"_a = nb::none(),
       "A look-at camera in world space (the volume's box is centred on the origin). With "
       "ortho_height the projection is orthographic with that view height; otherwise "
       "perspective with the vertical field of view fovy_degrees (30 as in umbra-render).");
    enum_field(cam, "projection", &umbra_camera::projection, "Projection", "perspective or orthographic");
    field(cam, "eye", &umbra_camera::eye, "eye position");
    field(cam, "target", &umbra_camera::target, "point looked at");
    field(cam, "up", &umbra_camera::up, "up direction");
    field(cam, "fovy_degrees", &umbra_camera::fovy_degrees, "perspective: vertical field of view, (0, 180)");
    field(cam, "ortho_height", &umbra_camera::ortho_height, "orthographic: view height in world units");
    make_repr(cam, "Camera");
    cam.def_static("orbit", [](std::array<float, 3> dir, float diag, float fovy) {
        return umbra_camera_orbit(dir.data(), diag, fovy);
    }, "direction"_a, "box_diagonal"_a, "fovy_degrees"_a = 30.0f,
       "umbra_camera_orbit: looks at the centre from `direction` at a distance that frames a box "
       "of the given diagonal.");

    nb::class_<umbra_light> li(m, "Light");
    li.def_static("directional", [](std::array<float, 3> dir, std::array<float, 3> color) {
        umbra_light l;
        std::memset(&l, 0, sizeof l);
        l.type = UMBRA_LIGHT_DIRECTIONAL;
        for (int i = 0; i < 3; ++i) {
            l.direction[i] = dir[i];
            l.color[i] = color[i];
        }
        return l;
    }, "direction"_a, "color"_a = std::array<float, 3>{1, 1, 1},
       "A directional light travelling along `direction` (need not be unit length).");
    li.def_static("point", [](std::array<float, 3> pos, std::array<float, 3> color) {
        umbra_light l;
        std::memset(&l, 0, sizeof l);
        l.type = UMBRA_LIGHT_POINT;
        for (int i = 0; i < 3; ++i) {
            l.position[i] = pos[i];
            l.color[i] = color[i];
        }
        return l;
    }, "position"_a, "color"_a = std::array<float, 3>{1, 1, 1},
       "A point light at `position` (world units, volume centred on the origin).");
    enum_field(li, "type", &umbra_light::type, "LightType", "point or directional");
    field(li, "position", &umbra_light::position, "point light: world-space position");
    field(li, "direction", &umbra_light::direction, "directional light: direction of travel");
    field(li, "color", &umbra_light::color, "RGB intensity, each >= 0");
    make_repr(li, "Light");

    /* Docstrings that list every field with its C default, built once from desc_init. */
    umbra_render_desc render_defaults;
    umbra_render_desc_init(&render_defaults);
    umbra_shadow_desc shadow_defaults;
    umbra_shadow_desc_init(&shadow_defaults);
    static const std::string render_fields = field_docs(render_defaults);
    static const std::string shadow_fields = field_docs(shadow_defaults);
    static const std::string ro_doc =
        "umbra_render_desc: how a frame is drawn. RenderOptions(**fields) starts from "
        "umbra_render_desc_init and sets the given fields:\n" + render_fields;
    static const std::string so_doc =
        "umbra_shadow_desc: the shadow technique and its parameters. ShadowOptions(**fields) "
        "starts from umbra_shadow_desc_init and sets the given fields:\n" + shadow_fields;
    nb::setattr(ro, "__doc__", nb::str(ro_doc.c_str()));
    nb::setattr(so, "__doc__", nb::str(so_doc.c_str()));

    /* ---- Context ---- */
    umbra_context_desc context_defaults;
    umbra_context_desc_init(&context_defaults);
    nb::class_<Context>(m, "Context",
        "The OpenCL device umbra runs on (umbra_context). Use it as a context manager or call "
        "close(); objects made on it keep the device alive until they are closed or collected. "
        "One thread at a time.")
        .def("__init__", [](Context *self, std::optional<std::string> device, int platform_index,
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
        }, "device"_a = nb::none(), "platform_index"_a = context_defaults.platform_index,
           "device_index"_a = context_defaults.device_index,
           "sampler"_a = context_defaults.sampler, "cache_dir"_a = nb::none(),
           "use_environment"_a = context_defaults.use_environment != 0,
           "device: a substring of the platform or device name, or None. With the defaults the "
           "environment variable UMBRA_DEVICE ('P:D' or a name) is honoured. cache_dir: PoCL's "
           "kernel cache (default $POCL_CACHE_DIR, else a directory under the temporary one).")
        .def("close", &Context::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Context &c) { return c.h == nullptr; })
        .def("__enter__", [](nb::handle self) { return nb::borrow(self); })
        .def("__exit__", [](Context &c, nb::args) { c.close(); })
        .def_prop_ro("device_name", [](const Context &c) {
            return std::string(umbra_context_device_name(c.get()));
        }, "'platform / device'")
        .def_prop_ro("sampler", [](const Context &c) { return umbra_context_sampler(c.get()); },
                     "The sampler back end in use (never AUTO).")
        .def("load_volume", [](Context &c, const std::string &path) {
            umbra_volume v = nullptr;
            check(c.get(), umbra_volume_load(c.get(), path.c_str(), &v));
            return Volume(c.h, v);
        }, "path"_a, "Loads .nrrd/.nhdr (Teem) or .dat (Voreen) through umbra_io.")
        .def("load_transfer_function", [](Context &c, const std::string &path) {
            umbra_transfer_function t = nullptr;
            check(c.get(), umbra_transfer_function_load(c.get(), path.c_str(), &t));
            return TransferFunction(c.h, t);
        }, "path"_a, "Loads umbra's transfer-function text format through umbra_io.")
        .def("write_image", [](Context &c, const std::string &path, nb::handle rgba) {
            any_array a = as_array(rgba, "umbra.Context.write_image: rgba");
            if (a.ndim() != 3 || a.shape(2) != 4)
                raise_invalid("umbra.Context.write_image: rgba shape " + shape_text(a) +
                              " is not (height, width, 4)");
            if (a.dtype() != nb::dtype<float>())
                raise_invalid("umbra.Context.write_image: dtype " + dtype_name(a.dtype()) +
                              " is not float32");
            need_c_contiguous(a, "umbra.Context.write_image: rgba", "pass numpy.ascontiguousarray(rgba)");
            if (a.shape(0) > UINT32_MAX || a.shape(1) > UINT32_MAX)
                raise_invalid("umbra.Context.write_image: image too large");
            check(c.get(), umbra_image_write(c.get(), path.c_str(), (uint32_t)a.shape(1),
                                             (uint32_t)a.shape(0), (const float *)a.data()));
        }, "path"_a, "rgba"_a,
           "Writes an (H, W, 4) float32 premultiplied RGBA image: .png (8-bit sRGB) or .exr "
           "(linear float).")
        .def("read_image", [](Context &c, const std::string &path) {
            uint32_t w = 0, h = 0;
            float *p = nullptr;
            check(c.get(), umbra_image_read(c.get(), path.c_str(), &w, &h, &p));
            nb::capsule owner(p, [](void *q) noexcept { std::free(q); });
            return float_out(p, {h, w, 4}, owner);
        }, "path"_a, "Reads a PNG or EXR as an (H, W, 4) float32 linear premultiplied array.");

    /* ---- Volume ---- */
    umbra_volume_desc volume_defaults;
    umbra_volume_desc_init(&volume_defaults);
    nb::class_<Volume>(m, "Volume",
        "A scalar volume on the device (umbra_volume). Built from a C-contiguous NumPy array of "
        "shape (z, y, x) (x varies fastest, as in umbra), dtype uint8, uint16, int16 or float32; "
        "the array is read in place and copied once, to the device.")
        .def("__init__", [](Volume *self, nb::handle ctx, nb::handle data, std::array<float, 3> spacing,
                            std::optional<std::pair<float, float>> value_range, uint32_t brick_size) {
            Volume v = make_volume(context_of(ctx), data, spacing, value_range, brick_size);
            new (self) Volume(std::move(v));
        }, "context"_a, "data"_a, nb::kw_only(),
           "spacing"_a = std::array<float, 3>{volume_defaults.spacing[0], volume_defaults.spacing[1],
                                             volume_defaults.spacing[2]},
           "value_range"_a = nb::none(), "brick_size"_a = volume_defaults.brick_size,
           "spacing: world units per voxel as (sx, sy, sz), x first like umbra's dims, i.e. the "
           "reverse of the array's (z, y, x) axis order (SimpleITK's GetSpacing() order). "
           "value_range: (min, max) mapped to [0, 1] before the transfer function; None: the "
           "data's min and max. brick_size: edge of an empty-space-skipping brick in voxels.")
        .def("close", &Volume::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Volume &v) { return v.h == nullptr; })
        .def("__enter__", [](nb::handle self) { return nb::borrow(self); })
        .def("__exit__", [](Volume &v, nb::args) { v.close(); })
        .def_prop_ro("info", [](const Volume &v) {
            VolumeInfo i;
            check(v.ctx, umbra_volume_get_info(v.get("Volume"), &i.info));
            return i;
        }, "umbra_volume_get_info: dims, spacing, extent, value range, bricks, device bytes.")
        .def_prop_ro("shape", [](const Volume &v) {
            umbra_volume_info i;
            check(v.ctx, umbra_volume_get_info(v.get("Volume"), &i));
            return nb::make_tuple(i.dims[2], i.dims[1], i.dims[0]);
        }, "(z, y, x), the shape of the array it was made from");

    nb::class_<VolumeInfo>(m, "VolumeInfo", "umbra_volume_info (x, y, z order)")
        .def_prop_ro("dims", [](const VolumeInfo &i) {
            return nb::make_tuple(i.info.dims[0], i.info.dims[1], i.info.dims[2]); },
            nb::sig("def dims(self, /) -> tuple[int, int, int]"), "(x, y, z) voxels")
        .def_prop_ro("spacing", [](const VolumeInfo &i) {
            return nb::make_tuple(py_float(i.info.spacing[0]), py_float(i.info.spacing[1]),
                                 py_float(i.info.spacing[2])); },
            nb::sig("def spacing(self, /) -> tuple[float, float, float]"), "world units per voxel, (x, y, z)")
        .def_prop_ro("extent", [](const VolumeInfo &i) {
            return nb::make_tuple(py_float(i.info.extent[0]), py_float(i.info.extent[1]),
                                 py_float(i.info.extent[2])); },
            nb::sig("def extent(self, /) -> tuple[float, float, float]"),
            "dims * spacing: the world-space box size, (x, y, z)")
        .def_prop_ro("value_range", [](const VolumeInfo &i) {
            return nb::make_tuple(py_float(i.info.value_min), py_float(i.info.value_max)); },
            nb::sig("def value_range(self, /) -> tuple[float, float]"),
            "the values mapped to 0 and 1 before the transfer function")
        .def_prop_ro("brick_size", [](const VolumeInfo &i) { return i.info.brick_size; })
        .def_prop_ro("brick_counts", [](const VolumeInfo &i) {
            return nb::make_tuple(i.info.brick_counts[0], i.info.brick_counts[1],
                                 i.info.brick_counts[2]); },
            nb::sig("def brick_counts(self, /) -> tuple[int, int, int]"))
        .def_prop_ro("device_bytes", [](const VolumeInfo &i) { return i.info.device_bytes; });

    /* ---- TransferFunction ---- */
    nb::class_<TransferFunction>(m, "TransferFunction",
        "A 1-D RGBA transfer function (umbra_transfer_function): entries spread evenly over the "
        "volume's normalised value range [0, 1], linearly interpolated; alpha is the opacity of "
        "one sample per voxel.")
        .def("__init__", [](TransferFunction *self, nb::handle ctx, nb::handle table) {
            umbra_context c = context_of(ctx).get();
            any_array a = as_array(table, "umbra.TransferFunction: table");
            const float *p = float_rows(a, 4, "umbra.TransferFunction: table", "(N, 4) RGBA");
            if (a.shape(0) > UINT32_MAX)
                raise_invalid("umbra.TransferFunction: table too long");
            umbra_transfer_function t = nullptr;
            check(c, umbra_transfer_function_create(c, p, (uint32_t)a.shape(0), &t));
            new (self) TransferFunction(c, t);
        }, "context"_a, "table"_a,
           "table: an (N, 4) float32 array of RGBA rows in [0, 1], N >= 2 (copied).")
        .def_static("from_points", [](nb::handle ctx, std::vector<std::array<float, 5>> points,
                                      uint32_t resolution) {
            umbra_context c = context_of(ctx).get();
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
                         c, pts.empty() ? nullptr : pts.data(), (uint32_t)pts.size(), resolution, &t));
            return TransferFunction(c, t);
        }, "context"_a, "points"_a, "resolution"_a = 256,
           "Control points (value, r, g, b, a), value in [0, 1] of the normalised range, sorted; "
           "a list of 5-tuples or an (N, 5) array. The table gets `resolution` entries (256 as in "
           "umbra's transfer-function files).")
        .def("close", &TransferFunction::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const TransferFunction &t) { return t.h == nullptr; })
        .def("__enter__", [](nb::handle self) { return nb::borrow(self); })
        .def("__exit__", [](TransferFunction &t, nb::args) { t.close(); })
        .def("__len__", [](const TransferFunction &t) {
            return umbra_transfer_function_size(t.get("TransferFunction")); })
        .def_prop_ro("table", [](const TransferFunction &t) {
            umbra_transfer_function h = t.get("TransferFunction");
            /* A read-only view that keeps the table alive even if this object is closed. */
            umbra_transfer_function_retain(h);
            nb::capsule owner(h, [](void *q) noexcept {
                umbra_transfer_function_release((umbra_transfer_function)q);
            });
            size_t n = umbra_transfer_function_size(h);
            return nb::ndarray<nb::numpy, const float>(umbra_transfer_function_data(h), {n, 4}, owner);
        }, nb::rv_policy::automatic, "The (N, 4) float32 RGBA table, a read-only view (no copy).")
        .def_prop_ro("is_grey", [](const TransferFunction &t) {
            return umbra_transfer_function_is_grey(t.get("TransferFunction")) != 0;
        }, "True when every visible entry has r == g == b (one light channel suffices).");

    /* ---- RenderStats ---- */
    nb::class_<umbra_render_stats>(m, "RenderStats", "umbra_render_stats of the last render")
        .def_ro("shadow_build_ms", &umbra_render_stats::shadow_build_ms)
        .def_ro("render_ms", &umbra_render_stats::render_ms)
        .def_prop_ro("shadow_rebuilt", [](const umbra_render_stats &s) { return s.shadow_rebuilt != 0; })
        .def_ro("shadow_memory_bytes", &umbra_render_stats::shadow_memory_bytes)
        .def_ro("light_channels", &umbra_render_stats::light_channels)
        .def_ro("slices", &umbra_render_stats::slices)
        .def_ro("samples", &umbra_render_stats::samples);

    /* ---- Renderer ---- */
    static const std::string set_shadow_doc =
        "Selects the shadow technique: ShadowOptions(**params), i.e. every parameter not given "
        "takes its C default (umbra_shadow_desc_init), not its previous value. Parameters:\n" +
        shadow_fields;
    static const std::string set_options_doc =
        "Sets the render options: `base` (a RenderOptions, e.g. a Scene's; default the C "
        "defaults) with the given fields replaced. Fields:\n" + render_fields;
    static const std::string render_doc =
        "Renders width x height premultiplied RGBA into a new (height, width, 4) float32 array "
        "(row 0 at the top), or into `out`, an array of that shape, dtype and C order. Keyword "
        "arguments, if any, first select the shadow technique as set_shadow(**params) does, "
        "e.g. render(512, 512, technique='cssm', taps=7). Blocks until done.";

    nb::class_<Renderer>(m, "Renderer",
        "Draws one volume with a transfer function from a camera, lit by one light, with a shadow "
        "technique (umbra_renderer). Setters validate at once and raise umbra.Error; render() "
        "rebuilds only what changed (a shadow map is reused while the light, volume and light "
        "transfer function stay).")
        .def("__init__", [](Renderer *self, nb::handle ctx, nb::handle volume, nb::handle tf,
                            nb::handle light_tf, std::optional<umbra_camera> camera,
                            std::optional<umbra_light> light, std::optional<umbra_render_desc> options,
                            std::optional<umbra_shadow_desc> shadow) {
            umbra_context c = context_of(ctx).get();
            new (self) Renderer;
            umbra_render_desc_init(&self->options);
            umbra_shadow_desc_init(&self->shadow);
            check(c, umbra_renderer_create(c, &self->h));
            self->ctx = c;
            umbra_context_retain(c);
            if (!volume.is_none())
                renderer_set_volume(*self, volume);
            if (!tf.is_none())
                renderer_set_tf(*self, tf);
            if (!light_tf.is_none())
                renderer_set_light_tf(*self, light_tf);
            if (camera)
                renderer_set_camera(*self, *camera);
            if (light)
                renderer_set_light(*self, *light);
            if (options)
                renderer_set_options(*self, *options);
            if (shadow)
                renderer_set_shadow(*self, *shadow);
        }, "context"_a, "volume"_a = nb::none(), "tf"_a = nb::none(), nb::kw_only(),
           "light_tf"_a = nb::none(), "camera"_a = nb::none(), "light"_a = nb::none(),
           "options"_a = nb::none(), "shadow"_a = nb::none(),
           "Without a camera the renderer frames the volume; without a light it uses its default "
           "directional light.")
        .def("close", &Renderer::close, "Drops this object's reference; idempotent.")
        .def_prop_ro("closed", [](const Renderer &r) { return r.h == nullptr; })
        .def("__enter__", [](nb::handle self) { return nb::borrow(self); })
        .def("__exit__", [](Renderer &r, nb::args) { r.close(); })
        .def_prop_rw("volume", [](const Renderer &r) { return r.volume; },
                     [](Renderer &r, nb::handle v) { renderer_set_volume(r, v); },
                     nb::for_getter(nb::sig("def volume(self, /) -> Volume | None")),
                     nb::for_setter(nb::sig("def volume(self, value: Volume, /) -> None")),
                     "The volume (retained by the renderer).")
        .def_prop_rw("tf", [](const Renderer &r) { return r.tf; },
                     [](Renderer &r, nb::handle t) { renderer_set_tf(r, t); },
                     nb::for_getter(nb::sig("def tf(self, /) -> TransferFunction | None")),
                     nb::for_setter(nb::sig("def tf(self, value: TransferFunction, /) -> None")),
                     "The view transfer function.")
        .def_prop_rw("light_tf", [](const Renderer &r) { return r.light_tf; },
                     [](Renderer &r, nb::handle t) { renderer_set_light_tf(r, t); },
                     nb::for_getter(nb::sig("def light_tf(self, /) -> TransferFunction | None")),
                     nb::for_setter(nb::sig("def light_tf(self, value: TransferFunction | None, /) -> None")),
                     "The light pass's transfer function; None: the view transfer function.")
        .def_prop_rw("camera", [](const Renderer &r) { return r.camera; },
                     [](Renderer &r, const umbra_camera &c) { renderer_set_camera(r, c); },
                     "The camera (None until set: the renderer frames the volume).")
        .def_prop_rw("light", [](const Renderer &r) { return r.light; },
                     [](Renderer &r, const umbra_light &l) { renderer_set_light(r, l); },
                     "The light (None until set: the renderer's default directional light).")
        .def_prop_rw("options", [](const Renderer &r) { return r.options; },
                     [](Renderer &r, const umbra_render_desc &d) { renderer_set_options(r, d); },
                     "A copy of the render options; assign a RenderOptions to change them.")
        .def_prop_rw("shadow", [](const Renderer &r) { return r.shadow; },
                     [](Renderer &r, const umbra_shadow_desc &d) { renderer_set_shadow(r, d); },
                     "A copy of the shadow options; assign a ShadowOptions to change them.")
        .def("set_shadow", [](Renderer &r, const nb::kwargs &kw) {
            umbra_shadow_desc d;
            umbra_shadow_desc_init(&d);
            apply_kwargs(d, kw, "umbra.Renderer.set_shadow");
            renderer_set_shadow(r, d);
        }, nb::sig("def set_shadow(self, **params: typing.Any) -> None"), set_shadow_doc.c_str())
        .def("set_options", [](Renderer &r, std::optional<umbra_render_desc> base, const nb::kwargs &kw) {
            umbra_render_desc d;
            umbra_render_desc_init(&d);
            if (base)
                d = *base;
            apply_kwargs(d, kw, "umbra.Renderer.set_options");
            renderer_set_options(r, d);
        }, "base"_a = nb::none(), "params"_a,
           nb::sig("def set_options(self, base: RenderOptions | None = None, **params: typing.Any) -> None"),
           set_options_doc.c_str())
        .def("render", [](Renderer &r, uint32_t width, uint32_t height, nb::handle out,
                          const nb::kwargs &kw) {
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
                    raise_invalid("umbra.Renderer.render: out must be a writable float32 array");
                if (o.ndim() != 3 || o.shape(0) != height || o.shape(1) != width || o.shape(2) != 4)
                    raise_invalid("umbra.Renderer.render: out has shape " +
                                  shape_text(any_array(o)) + ", not (" + std::to_string(height) +
                                  ", " + std::to_string(width) + ", 4)");
                need_c_contiguous(any_array(o), "umbra.Renderer.render: out",
                                  "pass an array made with numpy.empty((h, w, 4), numpy.float32)");
                dst = o.data();
                result = nb::borrow(out);
            }
            check(r.ctx, umbra_renderer_render(h, width, height, dst));
            return result;
        }, "width"_a, "height"_a, nb::kw_only(), "out"_a = nb::none(), "params"_a,
           nb::sig("def render(self, width: int, height: int, *, out: numpy.typing.NDArray[numpy.float32] | None = None, "
                   "**params: typing.Any) -> numpy.typing.NDArray[numpy.float32]"),
           render_doc.c_str())
        .def("query_shadow", [](Renderer &r, nb::handle points) {
            umbra_renderer h = r.get();
            any_array a = as_array(points, "umbra.Renderer.query_shadow: points");
            const float *p = float_rows(a, 3, "umbra.Renderer.query_shadow: points", "(N, 3)");
            size_t n = a.shape(0);
            /* The C call does not look inside the points; a NaN would give a meaningless factor. */
            for (size_t i = 0; i < 3 * n; ++i)
                if (!std::isfinite(p[i]))
                    raise_invalid("umbra.Renderer.query_shadow: point " + std::to_string(i / 3) +
                                  " has a non-finite coordinate (" + std::to_string(p[i]) + ")");
            float_out o = new_float_array({n, 3});
            check(r.ctx, umbra_renderer_query_shadow(h, p, n, o.data()));
            return o;
        }, "points"_a,
           "The current technique's RGB shadow factor at N world-space points: an (N, 3) float32 "
           "array in, an (N, 3) float32 array out. Builds the shadow structure if needed.")
        .def_prop_ro("stats", [](const Renderer &r) {
            umbra_render_stats s;
            check(r.ctx, umbra_renderer_get_stats(r.get(), &s));
            return s;
        }, "Timings and sizes of the last render (RenderStats).");

    /* ---- Scene ---- */
    nb::class_<Scene>(m, "Scene",
        "A built-in scene made in code (umbra_scene_create): its volume, transfer function, "
        "camera, light and suggested render options.")
        .def("__init__", [](Scene *self, nb::handle ctx, const std::string &name, uint32_t resolution) {
            umbra_context c = context_of(ctx).get();
            umbra_scene s;
            check(c, umbra_scene_create(c, name.c_str(), resolution, &s));
            /* The wrappers take their own references; the scene struct is released at once. */
            umbra_volume_retain(s.volume);
            umbra_transfer_function_retain(s.tf);
            nb::object vol = nb::cast(Volume(c, s.volume), nb::rv_policy::move);
            nb::object tf = nb::cast(TransferFunction(c, s.tf), nb::rv_policy::move);
            new (self) Scene{nb::borrow(ctx), vol, tf, s.camera, s.light, s.options};
            umbra_scene_release(&s);
        }, "context"_a, "name"_a = "spheres", "resolution"_a = 0,
           "name: one of scene_names(). resolution: voxels per side (0: the scene's default).")
        .def_prop_ro("volume", [](const Scene &s) { return s.volume; },
                     nb::sig("def volume(self, /) -> Volume"))
        .def_prop_ro("tf", [](const Scene &s) { return s.tf; },
                     nb::sig("def tf(self, /) -> TransferFunction"))
        .def_ro("camera", &Scene::camera)
        .def_ro("light", &Scene::light)
        .def_ro("options", &Scene::options)
        .def("renderer", [](const Scene &s) {
            nb::object r = nb::type<Renderer>()(s.context, s.volume, s.tf, "camera"_a = s.camera,
                                                 "light"_a = s.light, "options"_a = s.options);
            return r;
        }, nb::sig("def renderer(self) -> Renderer"),
           "A Renderer set up with the scene's volume, transfer function, camera, light and "
           "options (as umbra-render --scene draws it, apart from the CLI's background).");
}
