// The registry of visibility backends (skybake/visibility.h, [SECTION]
// Backends) and the one place where a device, a backend, a method and a
// resolution are resolved into a tracer.
#include <algorithm>
#include <mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "skybake/error.h"
#include "skybake/visibility.h"

// The backends of this build: SKYBAKE_TRACER_BACKENDS in src/CMakeLists.txt,
// one SKYBAKE_TRACER_BACKEND(name) line each, in order of preference.
#define SKYBAKE_TRACER_BACKEND(name) void skybake_register_##name##_tracer();
#include "tracer_backends.inc"
#undef SKYBAKE_TRACER_BACKEND

namespace skybake {

namespace {

std::deque<TracerBackend>& registry() {
    static std::deque<TracerBackend> backends; // a deque: references stay valid as backends are added
    return backends;
}

std::recursive_mutex& registry_mutex() {
    static std::recursive_mutex m;
    return m;
}

thread_local bool t_registering_built_in = false;

// Registers the build's backends once, before the first look-up and before
// any other registration, so that they come first.
void register_built_in() {
    static std::once_flag once;
    std::call_once(once, [] {
        t_registering_built_in = true;
#define SKYBAKE_TRACER_BACKEND(name) skybake_register_##name##_tracer();
#include "tracer_backends.inc"
#undef SKYBAKE_TRACER_BACKEND
        t_registering_built_in = false;
    });
}

std::string method_list(const TracerBackend& b) {
    std::vector<std::string> names;
    for (std::size_t i = 0; i < b.methods.size(); ++i)
        names.push_back(fmt::format("{}{}", trace_method_name(b.methods[i]), i == 0 ? " (default)" : ""));
    return fmt::format("{}", fmt::join(names, ", "));
}

bool owns(const TracerBackend& b, TraceMethod m) {
    return std::find(b.methods.begin(), b.methods.end(), m) != b.methods.end();
}

std::string names_where(bool (*keep)(const TracerBackend&)) {
    std::vector<std::string> names;
    for (const TracerBackend& b : tracer_backends())
        if (keep(b))
            names.push_back(b.name);
    return fmt::format("{}", fmt::join(names, ", "));
}

std::vector<std::string> device_names() {
    std::vector<std::string> out{"auto"};
    for (const TracerBackend& b : tracer_backends())
        if (std::find(out.begin(), out.end(), b.device) == out.end())
            out.push_back(b.device);
    return out;
}

// The first backend registered on `device` (with closest hits when asked), or nullptr.
const TracerBackend* first_on(const std::string& device, bool closest_hit) {
    for (const TracerBackend& b : tracer_backends())
        if (b.device == device && (!closest_hit || b.closest_hit))
            return &b;
    return nullptr;
}

bool available(const TracerBackend& b) {
    return !b.problem || b.problem().empty();
}

} // namespace

void register_tracer_backend(TracerBackend backend) {
    if (!t_registering_built_in)
        register_built_in();
    std::lock_guard lock(registry_mutex());
    if (backend.name.empty())
        throw Error("a backend needs a name", "backend");
    for (const TracerBackend& b : registry())
        if (b.name == backend.name)
            throw Error(fmt::format("a backend named '{}' is registered already", backend.name), "backend");
    if (backend.methods.empty() || !backend.make_tracer || backend.device.empty())
        throw Error(fmt::format("backend '{}' needs a device, at least one method and a tracer factory",
                                backend.name),
                    "backend");
    if (backend.closest_hit != bool(backend.make_ray_queries))
        throw Error(fmt::format("backend '{}': closest_hit and make_ray_queries go together", backend.name),
                    "backend");
    registry().push_back(std::move(backend));
}

const std::deque<TracerBackend>& tracer_backends() {
    register_built_in();
    return registry();
}

const TracerBackend& find_tracer_backend(const std::string& name) {
    for (const TracerBackend& b : tracer_backends())
        if (b.name == name)
            return b;
    throw Error(fmt::format("unknown visibility backend '{}'; the backends are {}", name,
                            names_where([](const TracerBackend&) { return true; })),
                "backend");
}

std::vector<std::string> visibility_backend_names() {
    std::vector<std::string> out;
    for (const TracerBackend& b : tracer_backends())
        out.push_back(b.name);
    return out;
}

TraceMethod default_trace_method(const std::string& backend) {
    return find_tracer_backend(backend).methods.front();
}

TracerChoice resolve_tracer(const TracerRequest& r) {
    const std::vector<std::string> devices = device_names();
    if (std::find(devices.begin(), devices.end(), r.device) == devices.end())
        throw Error(fmt::format("unknown device '{}'; use {}", r.device, fmt::join(devices, ", ")), "device");
    const TracerBackend* b = nullptr;
    if (!r.backend.empty()) {
        b = &find_tracer_backend(r.backend);
        if (r.device != "auto" && r.device != b->device) {
            std::vector<std::string> there;
            for (const TracerBackend& x : tracer_backends())
                if (x.device == r.device)
                    there.push_back(x.name);
            throw Error(fmt::format("the {} backend runs on {}, not {}; drop the device (auto) or pick a backend "
                                    "of {}: {}",
                                    b->name, b->device, r.device, r.device, fmt::join(there, ", ")),
                        "device");
        }
    } else if (r.device == "auto") {
        // A GPU when one answers, else the CPU.
        const TracerBackend* gpu = first_on("cuda", r.closest_hit);
        b = gpu && available(*gpu) ? gpu : first_on("cpu", r.closest_hit);
    } else {
        b = first_on(r.device, r.closest_hit);
    }
    if (!b)
        throw Error(fmt::format("no backend on {} answers closest hits; those that do: {}", r.device,
                                names_where([](const TracerBackend& x) { return x.closest_hit; })),
                    "backend");
    if (r.closest_hit && !b->closest_hit)
        throw Error(fmt::format("this bake needs closest hits (bounces), which the {} backend does not answer; use "
                                "{}",
                                b->name, names_where([](const TracerBackend& x) { return x.closest_hit; })),
                    "backend");
    TracerChoice c;
    c.backend = b;
    c.device = b->device;
    c.method = b->methods.front();
    if (!r.method.empty()) {
        c.method = parse_trace_method(r.method);
        if (!owns(*b, c.method)) {
            std::string owner;
            for (const TracerBackend& x : tracer_backends())
                if (owner.empty() && owns(x, c.method))
                    owner = x.name;
            throw Error(fmt::format("the {} method is the {} backend's; the {} backend has {}", r.method, owner,
                                    b->name, method_list(*b)),
                        "method");
        }
    }
    if (r.resolution != 0 && !b->resolution)
        throw Error(fmt::format("a resolution is for a backend that renders ({}); the {} backend traces rays",
                                names_where([](const TracerBackend& x) { return x.resolution; }), b->name),
                    "resolution");
    c.resolution = r.resolution;
    return c;
}

std::unique_ptr<VisibilityTracer> make_visibility_tracer(const TracerChoice& c) {
    if (!c.backend)
        throw Error("no backend chosen", "backend");
    return c.backend->make_tracer(c.method, c.resolution);
}

std::unique_ptr<RayQueries> make_ray_queries(const TracerChoice& c) {
    if (!c.backend)
        throw Error("no backend chosen", "backend");
    if (!c.backend->make_ray_queries)
        throw Error(fmt::format("the {} backend answers no single ray queries; use {}", c.backend->name,
                                names_where([](const TracerBackend& x) { return x.closest_hit; })),
                    "backend");
    return c.backend->make_ray_queries();
}

std::unique_ptr<RayQueries> make_ray_queries(const std::string& name) {
    TracerRequest r;
    r.backend = name;
    return make_ray_queries(resolve_tracer(r));
}

std::unique_ptr<VisibilityTracer> make_visibility_tracer(const std::string& name, TraceMethod method,
                                                         std::uint32_t resolution) {
    TracerRequest r;
    r.backend = name;
    r.method = trace_method_name(method);
    r.resolution = resolution;
    TracerChoice c = resolve_tracer(r);
    return make_visibility_tracer(c);
}

} // namespace skybake
