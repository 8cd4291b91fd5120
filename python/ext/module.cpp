// SPDX-License-Identifier: Apache-2.0
/* module.cpp: the Python module umbra._umbra, a nanobind binding of umbra's public C API
 * (umbra/umbra.h) and of its file layer (umbra/io.h); the package umbra re-exports it.
 *
 * What it is for: NumPy arrays in and out without copies where the C API allows it (a volume is
 * read from the caller's array in place and copied once, to the device; renders and shadow
 * queries write straight into the array handed back), every failure raised as umbra.Error with
 * umbra's status and message, and objects that close deterministically and may be collected in
 * any order. This file makes the module: the enums, umbra.Error and the free functions; the
 * option structs are in options.cpp, the objects in objects.cpp. */
#include "binding.h"

using namespace umbra_py;

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
        .value("ERROR_NO_DEVICE", UMBRA_ERROR_NO_DEVICE, "no OpenCL device matched the request")
        .value("ERROR_CANCELLED", UMBRA_ERROR_CANCELLED,
               "the progress callback asked to stop; the renderer stays usable");

    /* One value per technique of the registry (umbra/registry.h), its name in capitals. */
    nb::enum_<umbra_shadow_technique> technique(m, "Technique",
                                                "umbra_shadow_technique; keyword arguments "
                                                "also take the CLI's names ('cssm').");
    static std::vector<std::string> technique_names(umbra_technique_count());
    for (uint32_t i = 0; i < umbra_technique_count(); ++i) {
        const umbra_technique_info *t = umbra_technique_get(i);
        for (const char *c = t->name; *c; ++c)
            technique_names[i] += (char)std::toupper((unsigned char)*c);
        technique.value(technique_names[i].c_str(), t->id, t->title);
    }

    nb::enum_<umbra_transmission>(m, "Transmission", "umbra_transmission")
        .value("GREY", UMBRA_TRANSMISSION_GREY, "every channel attenuated by the opacity alone")
        .value("COLORED", UMBRA_TRANSMISSION_COLORED,
               "transmission colour from the light TF's RGB");

    nb::enum_<umbra_interaction>(m, "Interaction",
                                 "umbra_interaction: progressive shadows (RenderOptions."
                                 "interaction)")
        .value("OFF", UMBRA_INTERACTION_OFF, "every frame uses the full shadow structure")
        .value("AUTO", UMBRA_INTERACTION_AUTO,
               "a frame after a light or transfer-function change uses the technique's draft, "
               "the next frame with nothing changed the full structure");
    nb::enum_<umbra_render_mode>(m, "RenderMode", "umbra_render_mode: how a view ray combines "
                                                  "its samples")
        .value("COMPOSITE", UMBRA_RENDER_COMPOSITE,
               "emission-absorption compositing, lit and shadowed")
        .value("MIP", UMBRA_RENDER_MIP, "maximum intensity projection")
        .value("MINIP", UMBRA_RENDER_MINIP, "minimum intensity projection")
        .value("AVERAGE", UMBRA_RENDER_AVERAGE, "average intensity projection");

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

    m.attr("MAP_SIZE_AUTO") = UMBRA_MAP_SIZE_AUTO;
    /* Set by python/CMakeLists.txt from UMBRA_IO_IMAGES: the wheel is built without
     * OpenImageIO. */
    m.attr("has_image_io") = nb::bool_(UMBRA_PY_IMAGE_IO != 0);

    m.def(
        "version", []() { return std::string(umbra_version()); },
        "The C library's version, 'MAJOR.MINOR.PATCH'.");
    m.def(
        "scene_names",
        []() {
            std::vector<std::string> v;
            for (const char *const *n = umbra_scene_names(); *n; ++n)
                v.push_back(*n);
            return v;
        },
        "Names of the built-in scenes.");
    m.def(
        "technique_names",
        []() {
            std::vector<std::string> v;
            for (int t = 0;; ++t) {
                const char *n = umbra_shadow_technique_name((umbra_shadow_technique)t);
                if (!n)
                    break;
                v.push_back(n);
            }
            return v;
        },
        "Names of the shadow techniques, in the order of umbra.Technique.");

    bind_options(m);
    bind_objects(m);
}
