// SPDX-License-Identifier: Apache-2.0
/* options.cpp: RenderOptions, ShadowOptions, Camera and Light, the C structs umbra_render_desc,
 * umbra_shadow_desc, umbra_camera and umbra_light bound field by field. Each field is named once,
 * with a pointer to the C member: its type and storage come from the C header, its default from
 * the C desc_init function (never repeated here). A new C field is one more line below.
 * ShadowOptions' parameters come from the technique registry (umbra/registry.h) instead: one
 * property per key (map_size, taps, reference_step, ...), read and set through
 * umbra_shadow_desc_get_param / _set_param, which check the range; a key several techniques
 * have (taps) sets it in each of them and reads the current technique's. */
#include <algorithm>
#include <cctype>
#include <cstring>

#include "binding.h"

namespace umbra_py
{

namespace
{

std::string render_fields, shadow_fields;

template <class T> void add_field(nb::class_<T> &cls, typename Fields<T>::Field f)
{
    auto get = f.get;
    auto set = f.set;
    cls.def_prop_rw(
        f.name.c_str(), [get](const T &d) { return get(d); },
        [set](T &d, nb::handle v) { set(d, v); }, nb::for_setter(nb::arg("value")),
        nb::for_getter(nb::sig(("def " + f.name + "(self, /) -> " + f.type).c_str())),
        nb::for_setter(
            nb::sig(("def " + f.name + "(self, value: " + f.type + ", /) -> None").c_str())),
        f.doc.c_str());
    Fields<T>::all().push_back(std::move(f));
}

template <class T> void field(nb::class_<T> &cls, const char *name, float T::*m, const char *doc)
{
    add_field(cls, {name, "float", doc, [m](const T &d) { return nb::object(py_float(d.*m)); },
                    [m](T &d, nb::handle v) {
                        d.*m = nb::cast<float>(v);
                    }});
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
    std::string type = "tuple[" + std::string("float");
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
    add_field(cls,
              {name, std::string(type) + " | str", doc, [m](const T &d) { return nb::cast(d.*m); },
               [m](T &d, nb::handle v) {
                   d.*m = enum_from<E>(v);
               }});
}

/* "none, reference, ..." for the technique field's doc. */
std::string technique_names()
{
    std::string s;
    for (uint32_t i = 0; i < umbra_technique_count(); ++i)
        s += std::string(i ? ", " : "") + umbra_technique_get(i)->name;
    return "the shadow technique: " + s;
}

/* One property per registry key, in registry order, each set in every technique that has it. */
void shadow_params(nb::class_<umbra_shadow_desc> &so)
{
    std::vector<std::string> seen;
    for (uint32_t t = 0; t < umbra_technique_count(); ++t) {
        const umbra_technique_info *ti = umbra_technique_get(t);
        for (uint32_t k = 0; k < ti->param_count; ++k) {
            const umbra_param_info *p = umbra_technique_param_get(ti, k);
            std::string key = p->key;
            if (std::find(seen.begin(), seen.end(), key) != seen.end())
                continue;
            seen.push_back(key);
            std::string owners;
            for (uint32_t u = 0; u < umbra_technique_count(); ++u)
                if (umbra_technique_param_find(umbra_technique_get(u), p->key))
                    owners += std::string(owners.empty() ? "" : ", ") +
                              umbra_technique_get(u)->name;
            std::string doc =
                owners + ": " + p->doc + (p->unit ? std::string(", in ") + p->unit : "");
            const umbra_param_type type = p->type;
            std::string py_type = type == UMBRA_PARAM_FLOAT  ? "float"
                                  : type == UMBRA_PARAM_UINT ? "int"
                                                             : "bool";
            add_field(so, {key, py_type, doc,
                           [key, type](const umbra_shadow_desc &d) {
                               double v = 0.0;
                               umbra_shadow_desc_get_param(&d, nullptr, key.c_str(), &v);
                               if (type == UMBRA_PARAM_FLOAT)
                                   return nb::object(py_float((float)v));
                               if (type == UMBRA_PARAM_UINT)
                                   return nb::object(nb::int_((uint32_t)v));
                               return nb::object(nb::bool_(v != 0.0));
                           },
                           [key, type](umbra_shadow_desc &d, nb::handle v) {
                               double x;
                               if (type == UMBRA_PARAM_FLOAT) {
                                   x = nb::cast<float>(v);
                               } else if (type == UMBRA_PARAM_UINT) {
                                   if (nb::isinstance<nb::bool_>(v))
                                       throw nb::cast_error();
                                   x = nb::cast<uint32_t>(v);
                               } else {
                                   if (!PyBool_Check(v.ptr()) && !PyLong_Check(v.ptr()))
                                       throw nb::cast_error();
                                   x = PyObject_IsTrue(v.ptr()) ? 1.0 : 0.0;
                               }
                               char msg[1024];
                               if (umbra_shadow_desc_set_param(&d, nullptr, key.c_str(), x, msg,
                                                               sizeof msg) != UMBRA_SUCCESS)
                                   raise_invalid(msg);
                           }});
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

} // namespace

void apply_shadow_kwargs(umbra_shadow_desc &d, const nb::kwargs &kw, const char *what,
                         int *preintegrated)
{
    nb::kwargs first, rest;
    if (preintegrated)
        *preintegrated = -1;
    for (auto [k, v] : kw) {
        std::string key = nb::cast<std::string>(k);
        if (key == "preintegrated") {
            if (!preintegrated)
                throw nb::type_error((std::string(what) + ": preintegrated is a RenderOptions "
                                                          "field since umbra 0.5")
                                         .c_str());
            if (!PyBool_Check(v.ptr()) && !PyLong_Check(v.ptr()))
                throw nb::type_error((std::string(what) + ": preintegrated=" +
                                      nb::cast<std::string>(nb::repr(v)) + " is not a valid bool")
                                         .c_str());
            *preintegrated = PyObject_IsTrue(v.ptr()) ? 1 : 0;
        } else if (key == "technique") {
            first[k] = v;
        } else {
            rest[k] = v;
        }
    }
    apply_kwargs(d, first, what);
    apply_kwargs(d, rest, what);
}

const std::string &render_fields_doc()
{
    return render_fields;
}
const std::string &shadow_fields_doc()
{
    return shadow_fields;
}

void bind_options(nb::module_ &m)
{
    /* ---- option structs, bound field by field through their C definitions ---- */
    nb::class_<umbra_render_desc> ro(m, "RenderOptions");
    ro.def("__init__", [](umbra_render_desc *d, const nb::kwargs &kw) {
        new (d) umbra_render_desc;
        umbra_render_desc_init(d);
        apply_kwargs(*d, kw, "umbra.RenderOptions");
    });
    field(ro, "step", &umbra_render_desc::step, "sampling step along view rays, in voxels");
    flag(ro, "jitter", &umbra_render_desc::jitter,
         "start each ray at a seeded random fraction of a step");
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
    flag(ro, "preintegrated", &umbra_render_desc::preintegrated,
         "pre-integrated segments: the view ray's, and the convolution technique's light");
    enum_field(ro, "interaction", &umbra_render_desc::interaction, "Interaction",
               "progressive shadows: 'auto' renders the technique's draft in a frame after a light "
               "or transfer-function change and the full structure once nothing changes "
               "(RenderStats.draft says which); 'off' (default) always the full one");
    enum_field(ro, "mode", &umbra_render_desc::mode, "RenderMode",
               "composite (lit, shadowed), or a projection: mip, minip, average (technique "
               "none only; docs/features.md)");
    make_repr(ro, "RenderOptions");

    nb::class_<umbra_shadow_desc> so(m, "ShadowOptions");
    so.def("__init__", [](umbra_shadow_desc *d, const nb::kwargs &kw) {
        new (d) umbra_shadow_desc;
        umbra_shadow_desc_init(d);
        apply_shadow_kwargs(*d, kw, "umbra.ShadowOptions");
    });
    enum_field(so, "technique", &umbra_shadow_desc::technique, "Technique",
               technique_names().c_str());
    shadow_params(so);
    make_repr(so, "ShadowOptions");

    nb::class_<umbra_camera> cam(m, "Camera");
    cam.def(
        "__init__",
        [](umbra_camera *c, std::array<float, 3> eye, std::array<float, 3> target,
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
        },
        "eye"_a, "target"_a = std::array<float, 3>{0, 0, 0}, "up"_a = std::array<float, 3>{0, 1, 0},
        "fovy_degrees"_a = 30.0f, "ortho_height"_a = nb::none(),
        "A look-at camera in the volume's world (the centred box's centre is the origin). With "
        "ortho_height the projection is orthographic with that view height; otherwise "
        "perspective with the vertical field of view fovy_degrees (30 as in umbra-render).");
    enum_field(cam, "projection", &umbra_camera::projection, "Projection",
               "perspective or orthographic");
    field(cam, "eye", &umbra_camera::eye, "eye position");
    field(cam, "target", &umbra_camera::target, "point looked at");
    field(cam, "up", &umbra_camera::up, "up direction");
    field(cam, "fovy_degrees", &umbra_camera::fovy_degrees,
          "perspective: vertical field of view, (0, 180)");
    field(cam, "ortho_height", &umbra_camera::ortho_height,
          "orthographic: view height in world units");
    make_repr(cam, "Camera");
    cam.def_static(
        "orbit",
        [](std::array<float, 3> dir, float diag, float fovy, std::array<float, 3> center) {
            return umbra_camera_orbit_at(center.data(), dir.data(), diag, fovy);
        },
        "direction"_a, "box_diagonal"_a, "fovy_degrees"_a = 30.0f,
        "center"_a = std::array<float, 3>{0, 0, 0},
        "umbra_camera_orbit_at: looks at `center` (default the world origin, the centred box's "
        "centre; for a volume with a world transform pass volume.info.center) from `direction` "
        "at a distance that frames a box of the given diagonal (volume.info.diagonal).");

    nb::class_<umbra_light> li(m, "Light");
    li.def_static(
        "directional",
        [](std::array<float, 3> dir, std::array<float, 3> color) {
            umbra_light l;
            std::memset(&l, 0, sizeof l);
            l.type = UMBRA_LIGHT_DIRECTIONAL;
            for (int i = 0; i < 3; ++i) {
                l.direction[i] = dir[i];
                l.color[i] = color[i];
            }
            return l;
        },
        "direction"_a, "color"_a = std::array<float, 3>{1, 1, 1},
        "A directional light travelling along `direction` (need not be unit length).");
    li.def_static(
        "point",
        [](std::array<float, 3> pos, std::array<float, 3> color) {
            umbra_light l;
            std::memset(&l, 0, sizeof l);
            l.type = UMBRA_LIGHT_POINT;
            for (int i = 0; i < 3; ++i) {
                l.position[i] = pos[i];
                l.color[i] = color[i];
            }
            return l;
        },
        "position"_a, "color"_a = std::array<float, 3>{1, 1, 1},
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
    render_fields = field_docs(render_defaults);
    shadow_fields = field_docs(shadow_defaults);
    static std::string ro_doc;
    ro_doc = "umbra_render_desc: how a frame is drawn. RenderOptions(**fields) starts from "
             "umbra_render_desc_init and sets the given fields:\n" +
             render_fields;
    static std::string so_doc;
    so_doc = "umbra_shadow_desc: the shadow technique and its parameters. ShadowOptions(**fields) "
             "starts from umbra_shadow_desc_init and sets the given fields:\n" +
             shadow_fields;
    nb::setattr(ro, "__doc__", nb::str(ro_doc.c_str()));
    nb::setattr(so, "__doc__", nb::str(so_doc.c_str()));
}

} // namespace umbra_py
