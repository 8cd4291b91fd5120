// SPDX-License-Identifier: Apache-2.0
/* support.cpp: the helpers of the Python binding (binding.h): umbra.Error and the checks that turn
 * a wrong NumPy array into a message naming its dtype, shape or strides. */
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>

#include "binding.h"

namespace umbra_py
{

/* ---- errors --------------------------------------------------------------------------------- */

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

const char *path_arg(const std::string &path, const char *what)
{
    size_t at = path.find('\0');
    if (at != std::string::npos) {
        std::string shown = nb::cast<std::string>(nb::repr(nb::str(path.data(), path.size())));
        throw nb::value_error((std::string(what) + " " + shown + " contains a NUL character (at " +
                               std::to_string(at) + "); a file name cannot, and it is refused "
                               "rather than cut there")
                                  .c_str());
    }
    return path.c_str();
}

/* ---- arrays ----------------------------------------------------------------------------------- */

std::string dtype_name(nb::dlpack::dtype t)
{
    const char *kind = "unknown";
    switch ((nb::dlpack::dtype_code)t.code) {
    case nb::dlpack::dtype_code::Int:
        kind = "int";
        break;
    case nb::dlpack::dtype_code::UInt:
        kind = "uint";
        break;
    case nb::dlpack::dtype_code::Float:
        kind = "float";
        break;
    case nb::dlpack::dtype_code::Complex:
        kind = "complex";
        break;
    case nb::dlpack::dtype_code::Bool:
        return "bool";
    default:
        break;
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
    /* An empty array has no layout to get wrong, and its strides are whatever the exporter says
     * (NumPy 2 gives (0, 0) for shape (0, 3)): its size is checked by the caller. */
    if (a.size() == 0)
        return;
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
        raise_error(UMBRA_ERROR_OUT_OF_MEMORY,
                    "cannot allocate " + std::to_string(n * 4) + " bytes for the result");
    nb::capsule owner(p, [](void *q) noexcept { delete[](float *) q; });
    return float_out(p, shape, owner);
}

/* Shortest decimal first, so reprs and docstrings show the numbers the C defaults were written
 * as. */
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

} // namespace umbra_py
