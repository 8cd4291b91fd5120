// SPDX-License-Identifier: Apache-2.0
/* binding.h: what the parts of the Python module umbra._umbra share: errors raised as umbra.Error,
 * checks of NumPy arrays, the field tables of the bound C option structs, and the wrappers that
 * hold umbra's C objects. module.cpp makes the module; options.cpp binds the option structs
 * field by field through their C definitions; objects.cpp binds Context, Renderer (with its
 * progress callback) and Scene; data.cpp binds Volume, VolumeInfo and TransferFunction;
 * support.cpp holds the helpers' definitions. */
#ifndef UMBRA_PYTHON_BINDING_H
#define UMBRA_PYTHON_BINDING_H

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
#include <stdexcept>
#include <string>
#include <vector>

#include "umbra/io.h"
#include "umbra/umbra.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace umbra_py
{

/* ---- errors (support.cpp) ---------------------------------------------------------------------- */

/* umbra.Error, created at import; the module holds the reference. */
extern PyObject *error_type;
/* Raises umbra.Error with .status (umbra.Status, or an int for a status not bound yet) and
 * .message. */
[[noreturn]] void raise_error(umbra_status st, const std::string &message);
[[noreturn]] void raise_invalid(const std::string &message);
/* Nothing for UMBRA_SUCCESS; otherwise raises the context's message for the failed call and clears
 * the context's sticky error, so that the next failure reports its own. */
void check(umbra_context ctx, umbra_status st);
/* ValueError, as for a closed file. */
[[noreturn]] void raise_closed(const char *what);
/* path as a C string, or ValueError naming what ("umbra.Context.load_volume: path") when it holds
 * a NUL character, at which C would cut it ("a.png\x00.txt" would write a.png). */
const char *path_arg(const std::string &path, const char *what);

/* ---- arrays (support.cpp) ---------------------------------------------------------------------- */

using any_array = nb::ndarray<nb::ro>;
using float_out = nb::ndarray<nb::numpy, float>;

std::string dtype_name(nb::dlpack::dtype t);
std::string shape_text(const any_array &a);
/* Any object as a host array without copying, or umbra.Error naming what it got. */
any_array as_array(nb::handle obj, const char *what);
void need_c_contiguous(const any_array &a, const char *what, const char *hint);
/* The rows of an (N, cols) C-contiguous float32 array, or umbra.Error naming what is wrong. */
const float *float_rows(const any_array &a, size_t cols, const char *what, const char *layout);
/* A new float32 NumPy array of the given shape that owns its memory. */
float_out new_float_array(std::initializer_list<size_t> shape);
/* A float32 as the shortest decimal that reads back to it (0.02, not 0.019999999552965164). */
nb::float_ py_float(float x);

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
            throw nb::type_error(
                (std::string(what) + ": " + key + "=" + r + " is not a valid " + f->type).c_str());
        }
    }
}

/* A ShadowOptions' keyword arguments: the technique first (a key means the current technique's
 * parameter where it has one), then the parameters. `preintegrated`, a ShadowOptions field until
 * umbra 0.4 and a RenderOptions one since, goes to *preintegrated (-1 when not given) where the
 * caller takes it (Renderer.set_shadow, render), else is refused with a TypeError saying where it
 * went (options.cpp). */
void apply_shadow_kwargs(umbra_shadow_desc &d, const nb::kwargs &kw, const char *what,
                         int *preintegrated = nullptr);

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
    umbra_clip_desc clip;
    /* Channels 1.. of a multi-channel volume: their transfer functions (None: not set). */
    nb::object channel_tf[UMBRA_MAX_CHANNELS] = {nb::none(), nb::none(), nb::none(), nb::none()};
    nb::object channel_light_tf[UMBRA_MAX_CHANNELS] = {nb::none(), nb::none(), nb::none(),
                                                       nb::none()};
    /* The Python progress callable (None: none), and whether a Python exception (the callable's,
     * or KeyboardInterrupt from a signal) cancelled the call in flight and waits in Python's
     * error indicator to be raised when the C call returns. */
    nb::object progress = nb::none();
    bool python_error = false;
    /* True during a C call that reports progress, made on thread busy_thread (Python's thread
     * ident): neither the callable nor another thread (which runs while the callable runs Python
     * code) may use this renderer then (the C renderer is in the middle of the call), so get()
     * and close() refuse, saying which of the two it is. */
    bool busy = false;
    unsigned long busy_thread = 0;
    /* The refusal: RuntimeError naming what was attempted (what: "used", "closed"). */
    [[noreturn]] void refuse_busy(const char *what) const
    {
        if (busy_thread == PyThread_get_thread_ident())
            throw std::runtime_error(std::string("umbra.Renderer: ") + what +
                                     " from its own progress callback, which must not call the "
                                     "renderer it reports on");
        throw std::runtime_error(std::string("umbra.Renderer: ") + what +
                                 " while another thread renders with it (a renderer is used by "
                                 "one thread at a time: give each thread its own, or hold a lock "
                                 "around its calls)");
    }
    Renderer() = default;
    Renderer(const Renderer &) = delete;
    ~Renderer() { close(); }
    void close()
    {
        umbra_renderer_release(h);
        umbra_context_release(ctx);
        h = nullptr;
        ctx = nullptr;
        volume = tf = light_tf = progress = nb::none();
        for (int c = 0; c < UMBRA_MAX_CHANNELS; ++c)
            channel_tf[c] = channel_light_tf[c] = nb::none();
    }
    umbra_renderer get() const
    {
        if (busy)
            refuse_busy("used");
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

/* ---- the parts of the module --------------------------------------------------------------------- */

void bind_options(nb::module_ &m);
void bind_objects(nb::module_ &m);
/* Volume, VolumeInfo, TransferFunction (data.cpp); called by bind_objects after Context. */
void bind_data(nb::module_ &m);
/* Context.load_paraview and TransferFunction.load_paraview. */
TransferFunction load_paraview(Context &ctx, const std::string &path,
                               std::optional<std::string> preset, uint32_t resolution,
                               std::optional<std::pair<double, double>> range);
/* "name (type, default D): doc" lines of RenderOptions / ShadowOptions, D read from the C
 * desc_init functions; filled by bind_options. */
const std::string &render_fields_doc();
const std::string &shadow_fields_doc();

} // namespace umbra_py
#endif
