// Shared pieces of the bindings: NumPy arrays in and out, and long calls.
//
// Arrays in: exactly the dtype asked for (no silent conversion or rounding),
// C-contiguous, of the stated shape, finite where it says so; anything else
// raises skybake.Error naming the argument. Read-only inputs are used in
// place (a span over the array's buffer); inputs that a skybake object keeps
// (a mesh's positions) are copied into it.
//
// Arrays out: results computed into a std::vector are moved into a capsule
// and returned as an array over that memory, without a copy.
//
// Long calls (bakes, training, renders) run with the GIL released, route the
// library's progress events to a Python callable, and turn Ctrl-C into
// KeyboardInterrupt at the next progress step.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "skybake/error.h"
#include "skybake/progress.h"

namespace skybake {
struct Image;
}

namespace skybake::python {

namespace py = pybind11;

// [SECTION] Arrays in -----------------------------------------------------------------

const char* dtype_name(const py::dtype& dtype);

template <class T>
const char* expected_dtype_name() {
    if constexpr (std::is_same_v<T, float>)
        return "float32";
    else if constexpr (std::is_same_v<T, double>)
        return "float64";
    else if constexpr (std::is_same_v<T, std::uint32_t>)
        return "uint32";
    else
        static_assert(sizeof(T) == 0, "unsupported dtype");
}

// A NumPy array of T, C-contiguous, whose shape matches `shape` (entries
// < 0 match any extent). Throws skybake::Error (where: name) otherwise;
// with finite, also for a NaN or an infinity.
template <class T>
py::array_t<T> checked_array(const py::handle& obj, const char* name, std::initializer_list<py::ssize_t> shape,
                             bool finite = false) {
    if (!py::isinstance<py::array>(obj))
        throw Error(std::string("expected a NumPy array of ") + expected_dtype_name<T>() + ", got " +
                        std::string(py::str(obj.get_type().attr("__name__"))),
                    name);
    auto arr = py::reinterpret_borrow<py::array>(obj);
    if (arr.dtype().kind() != py::dtype::of<T>().kind() || arr.dtype().itemsize() != py::ssize_t(sizeof(T)))
        throw Error(std::string("expected dtype ") + expected_dtype_name<T>() + ", got " + dtype_name(arr.dtype()) +
                        " (convert with .astype(numpy." + expected_dtype_name<T>() + "))",
                    name);
    if (arr.ndim() != py::ssize_t(shape.size())) {
        std::string want = "(";
        int i = 0;
        for (const py::ssize_t s : shape)
            want += (i++ ? ", " : "") + (s < 0 ? std::string("N") : std::to_string(s));
        want += shape.size() == 1 ? ",)" : ")";
        throw Error("expected an array of shape " + want + ", got " + std::to_string(arr.ndim()) + " dimension(s)",
                    name);
    }
    int axis = 0;
    for (const py::ssize_t s : shape) {
        if (s >= 0 && arr.shape(axis) != s)
            throw Error("expected " + std::to_string(s) + " entries along axis " + std::to_string(axis) + ", got " +
                            std::to_string(arr.shape(axis)),
                        name);
        ++axis;
    }
    if (!(arr.flags() & py::array::c_style))
        throw Error("the array is not C-contiguous (use numpy.ascontiguousarray)", name);
    auto typed = py::array_t<T>::ensure(arr);
    if (!typed || typed.ptr() != arr.ptr()) // read in place: a converted copy would not be
        throw Error(std::string("expected dtype ") + expected_dtype_name<T>() + " in native byte order", name);
    if constexpr (std::is_floating_point_v<T>) {
        if (finite) {
            const T* p = typed.data();
            for (py::ssize_t i = 0, n = typed.size(); i < n; ++i)
                if (!std::isfinite(p[i]))
                    throw Error("entry " + std::to_string(i) + " is not finite", name);
        }
    }
    return typed;
}

// The rows of a checked (N, 3) float32 array as glm::vec3, in place.
inline std::span<const glm::vec3> as_vec3(const py::array_t<float>& arr) {
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    return {reinterpret_cast<const glm::vec3*>(arr.data()), std::size_t(arr.shape(0))};
}

// A copy of a checked (N, 3) float32 array.
inline std::vector<glm::vec3> vec3_vector(const py::array_t<float>& arr) {
    const auto rows = as_vec3(arr);
    return {rows.begin(), rows.end()};
}

// [SECTION] Arrays out ----------------------------------------------------------------

// An array of `shape` over the vector's memory, which the array then owns.
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
    auto* owner = new std::vector<T>(std::move(values));
    py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(shape, owner->data(), free_when_done);
}

// (N, 3) float32 over a vector of glm::vec3.
py::array_t<float> to_numpy(std::vector<glm::vec3>&& values);

// (H, W, 3) float32 over the image's pixels, and a copy of such an array.
py::array_t<float> image_to_numpy(Image&& image);
Image numpy_to_image(const py::handle& rgb, const char* name);

// [SECTION] Long calls ----------------------------------------------------------------

// While alive: the GIL is released, progress events go to `progress` (a
// callable taking a skybake.ProgressEvent, or None) and SIGINT is caught
// (on the main thread) for every call, however many came before. run()
// re-raises what the callback raised, or KeyboardInterrupt; a Ctrl-C that
// came after the work's last step is handed to Python when the call ends, so
// KeyboardInterrupt follows the returned result.
class LongCall {
public:
    explicit LongCall(py::object progress);
    ~LongCall();
    LongCall(const LongCall&) = delete;
    LongCall& operator=(const LongCall&) = delete;

    // Runs f and returns its result, translating the callback's exception and
    // Ctrl-C as above.
    template <class F>
    auto run(F&& f) -> decltype(f()) {
        try {
            py::gil_scoped_release release;
            return f();
        } catch (const Stopped&) {
            raise_stored();
        } catch (const Error&) {
            if (interrupted())
                raise_keyboard_interrupt();
            throw;
        }
        throw Error("unreachable");
    }

private:
    struct Stopped : Error { // thrown through the library by the callback
        Stopped() : Error("stopped by the progress callback") {}
    };
    bool interrupted() const;
    [[noreturn]] void raise_stored();
    [[noreturn]] void raise_keyboard_interrupt();

    py::object progress_;
    ProgressCallback previous_;
    py::object error_type_, error_value_, error_trace_; // what the callback raised (under the GIL)
    bool handler_installed_ = false;
    struct SavedHandler;
    SavedHandler* saved_ = nullptr;
};

// Runs f in a LongCall with progress = the callable or None.
template <class F>
auto long_call(py::object progress, F&& f) -> decltype(f()) {
    LongCall call(std::move(progress));
    return call.run(std::forward<F>(f));
}

// [SECTION] Binding groups --------------------------------------------------------------

void bind_core(py::module_& m);
void bind_mesh(py::module_& m);
void bind_sphere(py::module_& m);
void bind_sky(py::module_& m);
void bind_bake(py::module_& m);
void bind_prt(py::module_& m);

} // namespace skybake::python
