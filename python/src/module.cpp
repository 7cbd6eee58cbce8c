// skybake._core: the module, its errors, build facts, progress and images.
#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

#include "common.h"
#include "skybake/core.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/interrupt.h"
#include "skybake/visibility.h"

namespace skybake::python {

// [SECTION] Arrays --------------------------------------------------------------------

const char* dtype_name(const py::dtype& dtype) {
    static thread_local std::string name;
    name = dtype.attr("name").cast<std::string>();
    return name.c_str();
}

py::array_t<float> to_numpy(std::vector<glm::vec3>&& values) {
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    auto* owner = new std::vector<glm::vec3>(std::move(values));
    py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<glm::vec3>*>(p); });
    return py::array_t<float>({py::ssize_t(owner->size()), py::ssize_t(3)},
                              reinterpret_cast<const float*>(owner->data()), free_when_done);
}

// [SECTION] Long calls ----------------------------------------------------------------

namespace {

// SIGINT during a long call is recorded in the library's flag (skybake/interrupt.h),
// which every long loop polls: progress steps, the raster tracer's passes, the
// importer's wait, file writes.
extern "C" void on_sigint(int) {
    request_interrupt(SIGINT);
}

unsigned long g_main_thread = 0; // threading.main_thread().ident
int g_depth = 0;                 // long calls running on the main thread (one unless a callback nests one)

bool on_main_thread() {
    return PyThread_get_thread_ident() == g_main_thread;
}

} // namespace

// A ProgressEvent that owns its strings, as Python sees it: a callback may
// keep it after the operation (and the strings it viewed) has ended.
struct OwnedProgressEvent {
    std::string label;
    std::uint64_t done = 0, total = 0;
    double seconds = 0.0;
    std::string status;
    bool finished = false;
};

struct LongCall::SavedHandler {
    struct sigaction old;
};

LongCall::LongCall(py::object progress) : progress_(std::move(progress)) {
    if (!progress_.is_none() && !PyCallable_Check(progress_.ptr()))
        throw Error("expected a callable or None", "progress");
    // Ctrl-C: Python's own handler only runs on the main thread between
    // bytecodes, which never come while the GIL is released. Catch SIGINT
    // here for the length of the call and stop at the next progress step.
    if (on_main_thread() && g_depth == 0) {
        // A Ctrl-C that came just before (Python's handler recorded it): raise
        // it now rather than after the work.
        if (PyErr_CheckSignals() != 0)
            throw py::error_already_set();
        saved_ = new SavedHandler;
        struct sigaction sa;
        std::memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_sigint;
        sigemptyset(&sa.sa_mask);
        clear_interrupt(); // what an earlier call saw is not this call's
        handler_installed_ = sigaction(SIGINT, &sa, &saved_->old) == 0;
    }
    if (on_main_thread())
        ++g_depth;
    PyObject* callable = progress_.is_none() ? nullptr : progress_.ptr();
    previous_ = set_progress_callback([this, callable](const ProgressEvent& e) {
        if (handler_installed_)
            check_interrupted();
        if (!callable)
            return;
        py::gil_scoped_acquire gil;
        if (error_type_) // the callback raised already: the operation is unwinding
            throw Stopped();
        try {
            // The event's strings view the operation's own; Python keeps a copy.
            py::reinterpret_borrow<py::object>(callable)(OwnedProgressEvent{std::string(e.label), e.done, e.total,
                                                                            e.seconds, std::string(e.status),
                                                                            e.finished});
        } catch (py::error_already_set& err) {
            if (!error_type_) { // keep the first
                error_type_ = err.type();
                error_value_ = err.value();
                error_trace_ = err.trace();
            }
            throw Stopped();
        }
    });
}

LongCall::~LongCall() {
    set_progress_callback(std::move(previous_));
    if (on_main_thread())
        --g_depth;
    if (handler_installed_) {
        sigaction(SIGINT, &saved_->old, nullptr);
        // A Ctrl-C that no KeyboardInterrupt has answered yet (it came after the
        // last step, or while the result was handed back): Python raises it at
        // its next bytecode. Checked after the handler is back, so none is lost.
        if (interrupt_signal() != 0)
            PyErr_SetInterrupt();
        clear_interrupt();
    }
    delete saved_;
}

bool LongCall::interrupted() const {
    return handler_installed_ && interrupt_signal() != 0;
}

void LongCall::raise_stored() {
    if (!error_type_)
        raise_keyboard_interrupt();
    PyErr_Restore(error_type_.release().ptr(), error_value_.release().ptr(), error_trace_.release().ptr());
    throw py::error_already_set();
}

void LongCall::raise_keyboard_interrupt() {
    clear_interrupt(); // answered; a later Ctrl-C is a new one
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
}

// [SECTION] Core ----------------------------------------------------------------------

namespace {

struct BackendInfo {
    std::string name, device, summary;
    std::vector<std::string> methods; // the default first
    bool closest_hit = false;
    bool available = false;
    std::string problem; // why not available; empty if available
};

// The registered backends (skybake/visibility.h, [SECTION] Backends), each
// probed: a GPU, an OpenGL context.
std::vector<BackendInfo> backends() {
    std::vector<BackendInfo> out;
    for (const TracerBackend& b : tracer_backends()) {
        BackendInfo info{b.name, b.device, b.summary, {}, b.closest_hit, true, {}};
        for (TraceMethod m : b.methods)
            info.methods.push_back(trace_method_name(m));
        info.problem = b.problem ? b.problem() : std::string();
        info.available = info.problem.empty();
        out.push_back(std::move(info));
    }
    return out;
}

Image image_from_array(const py::handle& obj, const char* name) {
    const auto arr = checked_array<float>(obj, name, {-1, -1, 3}, /*finite=*/true);
    Image img(int(arr.shape(1)), int(arr.shape(0)));
    std::memcpy(img.rgb.data(), arr.data(), img.rgb.size() * sizeof(float));
    return img;
}

} // namespace

py::array_t<float> image_to_numpy(Image&& img) {
    const py::ssize_t h = img.height, w = img.width;
    return to_numpy(std::move(img.rgb), {h, w, 3});
}

Image numpy_to_image(const py::handle& obj, const char* name) {
    return image_from_array(obj, name);
}

void bind_core(py::module_& m) {
    g_main_thread = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();

    static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
    error.doc() = "Raised by skybake with the library's one-line message. Attributes: message (what went wrong) "
                  "and where (the argument, field or file it concerns; may be empty).";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p)
                std::rethrow_exception(p);
        } catch (const Interrupted&) {
            PyErr_SetNone(PyExc_KeyboardInterrupt);
        } catch (const Error& e) {
            py::object value = py::reinterpret_borrow<py::object>(error)(format_error_line(e.message(), e.where()));
            value.attr("message") = e.message();
            value.attr("where") = e.where();
            PyErr_SetObject(error.ptr(), value.ptr());
        }
    });

    m.def("version", &version, "The library's version, e.g. \"0.1.0\".");
    m.def("build_has_cuda", &build_has_cuda, "Whether this build has the CUDA backends (a GPU may still be absent).");
    m.def("cuda_device_count", &cuda_device_count, "CUDA devices usable now (0 without CUDA or a GPU).");
    m.def(
        "set_threads",
        [](int n) {
            if (n < 0)
                throw Error("must be ≥ 0 (0: all hardware threads), got " + std::to_string(n), "count");
            set_thread_count(n);
        },
        py::arg("count"),
        "Limits the worker threads (0: all hardware threads). Results do not depend on it.");
    m.def("threads", &thread_count, "The worker thread count.");
    m.def("set_quiet", &set_quiet, py::arg("quiet"), "Quiet mode: no progress bars or notes on stderr.");

    py::class_<BackendInfo>(m, "Backend", "A visibility backend of this build and whether it can run here.")
        .def_readonly("name", &BackendInfo::name)
        .def_readonly("device", &BackendInfo::device, "Where it runs: 'cpu', 'cuda' or 'opengl'.")
        .def_readonly("summary", &BackendInfo::summary)
        .def_readonly("methods", &BackendInfo::methods, "Its methods, the default first.")
        .def_readonly("closest_hit", &BackendInfo::closest_hit, "Whether it answers ray queries (bounces).")
        .def_readonly("available", &BackendInfo::available)
        .def_readonly("problem", &BackendInfo::problem, "Why it cannot run here; empty if it can.")
        .def("__repr__", [](const BackendInfo& b) {
            return "Backend(name='" + b.name + "', available=" + (b.available ? "True" : "False") +
                   (b.problem.empty() ? "" : ", problem='" + b.problem + "'") + ")";
        });
    m.def("backends", &backends,
          "The visibility backends of this build (embree, brute, raster, and cuda in CUDA builds), each with "
          "whether it can run on this machine (cuda: a GPU; raster: headless OpenGL 4.3).");

    py::class_<OwnedProgressEvent>(m, "ProgressEvent",
                                   "What a long call reports, at most every 100 ms and once at the end.")
        .def_readonly("label", &OwnedProgressEvent::label)
        .def_readonly("done", &OwnedProgressEvent::done, "Units of work done.")
        .def_readonly("total", &OwnedProgressEvent::total, "Units of work in all (0: unknown).")
        .def_readonly("seconds", &OwnedProgressEvent::seconds, "Since the operation began.")
        .def_readonly("status", &OwnedProgressEvent::status)
        .def_readonly("finished", &OwnedProgressEvent::finished)
        .def_property_readonly(
            "fraction", [](const OwnedProgressEvent& e) { return e.total ? double(e.done) / double(e.total) : 0.0; })
        .def("__repr__", [](const OwnedProgressEvent& e) {
            return "ProgressEvent(label='" + e.label + "', done=" + std::to_string(e.done) +
                   ", total=" + std::to_string(e.total) + (e.finished ? ", finished=True)" : ")");
        });

    m.def(
        "save_image",
        [](const std::filesystem::path& path, const py::handle& rgb, float exposure_ev, const std::string& tone) {
            Image img = image_from_array(rgb, "rgb");
            save_image(path, img, ToneMap{exposure_ev, parse_tone_curve(tone)});
        },
        py::arg("path"), py::arg("rgb"), py::arg("exposure_ev") = 0.0f, py::arg("tone") = "aces",
        "Writes a linear (H, W, 3) float32 image: .exr keeps the values, .png tone-maps them (exposure in stops; "
        "tone 'aces', 'reinhard' or 'clamp') to 8-bit sRGB. Atomic.");
    m.def(
        "load_image", [](const std::filesystem::path& path) { return image_to_numpy(load_image(path)); },
        py::arg("path"), "Reads an EXR, HDR or PNG file as a linear (H, W, 3) float32 array.");
}

} // namespace skybake::python

PYBIND11_MODULE(_core, m) {
    using namespace skybake::python;
    m.doc() = "skybake: neural skies and baked visibility (the C++ library's public API)";
    bind_core(m);
    bind_mesh(m);
    bind_sphere(m);
    bind_sky(m);
    bind_bake(m);
    bind_prt(m);
}
