// skybake.bake_ao: per-vertex ambient occlusion, shading coefficient, bent
// normals and visibility bits on any backend (skybake/bake.h).
#include <cmath>
#include <limits>
#include <optional>

#include "common.h"
#include "skybake/bake.h"
#include "skybake/bake_job.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"

namespace skybake::python {

namespace {

struct BakeResult {
    py::object ao, shading, bent_normal, bits;
    AoBakeReport report;
    std::uint32_t words_per_vertex = 0;
};

} // namespace

// The tracer for a device, a backend name and an optional method ("" or
// None: the backend's default), resolved by the library as for the CLI.
// Shared with the PRT bindings.
std::unique_ptr<VisibilityTracer> make_tracer(const std::string& device, const std::string& backend,
                                              const std::optional<std::string>& method, std::uint32_t resolution,
                                              TraceMethod* chosen) {
    TracerRequest r;
    r.device = device;
    r.backend = backend;
    r.method = method.value_or("");
    r.resolution = resolution;
    const TracerChoice c = resolve_tracer(r);
    if (chosen)
        *chosen = c.method;
    return make_visibility_tracer(c);
}

BakeOptions bake_options(float max_distance, float offset, const std::string& back_faces, bool normalize) {
    BakeOptions b;
    if (!(max_distance > 0.0f))
        throw Error("must be > 0 (inf: unlimited)", "max_distance");
    if (!(offset >= 0.0f && offset <= kMaxRayOffset)) // NaN and inf fail too
        throw Error("must be in [0, 1e17] mesh units (the tracers' range)", "offset"); // kMaxRayOffset
    b.max_distance = max_distance;
    b.ray_offset = offset;
    b.back_faces = parse_back_faces(back_faces);
    b.normalize = normalize;
    return b;
}

void bind_bake(py::module_& m) {
    py::class_<BakeResult>(m, "BakeResult", "What bake_ao() computed, one entry per vertex.")
        .def_readonly("ao", &BakeResult::ao, "(N,) float32: ambient occlusion (cosine-weighted visibility).")
        .def_readonly("shading", &BakeResult::shading, "(N,) float32: the shading coefficient A.")
        .def_readonly("bent_normal", &BakeResult::bent_normal, "(N, 3) float32, unit.")
        .def_readonly("bits", &BakeResult::bits,
                      "(N, W) uint32 visibility words (bit k % 32 of word k / 32: direction k visible), or None "
                      "without store_bits.")
        .def_property_readonly("backend", [](const BakeResult& r) { return r.report.backend; })
        .def_property_readonly("method", [](const BakeResult& r) { return r.report.method; })
        .def_property_readonly("rule", [](const BakeResult& r) { return r.report.rule; })
        .def_property_readonly("directions", [](const BakeResult& r) { return r.report.directions; })
        .def_property_readonly("rays", [](const BakeResult& r) { return r.report.rays; })
        .def_property_readonly("seconds", [](const BakeResult& r) { return r.report.seconds; })
        .def_property_readonly("build_seconds", [](const BakeResult& r) { return r.report.build_seconds; })
        .def_property_readonly("trace_seconds", [](const BakeResult& r) { return r.report.trace_seconds; })
        .def_property_readonly("ray_offset", [](const BakeResult& r) { return r.report.ray_offset; })
        .def_property_readonly("clamped_vertices", [](const BakeResult& r) { return r.report.clamped_vertices; })
        .def("__repr__", [](const BakeResult& r) {
            return "BakeResult(backend='" + r.report.backend + "', rule='" + r.report.rule +
                   "', vertices=" + std::to_string(r.report.vertices) + ", rays=" + std::to_string(r.report.rays) +
                   ")";
        });

    m.def(
        "bake_ao",
        [](Mesh& mesh, const std::string& rule_spec, const std::string& backend, std::optional<std::string> method,
           std::uint32_t resolution, float max_distance, float offset, const std::string& back_faces, bool normalize,
           bool store_bits, py::object progress, const std::string& device) {
            const SphereRule rule = parse_rule(rule_spec);
            BakeJob job;
            job.rule = rule;
            job.options = bake_options(max_distance, offset, back_faces, normalize);
            job.bits = store_bits;
            job.tracer.device = device;
            job.tracer.backend = backend;
            job.tracer.method = method.value_or("");
            job.tracer.resolution = resolution;
            BakeJobResult done = long_call(std::move(progress), [&] { return run_bake_job(mesh, job); });
            BakeOutputs& out = done.outputs;
            AoBakeReport& report = done.ao;
            BakeResult r;
            const auto n = py::ssize_t(mesh.vertex_count());
            r.ao = to_numpy(std::move(out.ao), {n});
            r.shading = to_numpy(std::move(out.shading), {n});
            r.bent_normal = to_numpy(std::move(out.bent_normal));
            r.words_per_vertex = out.words_per_vertex;
            r.bits = store_bits ? py::object(to_numpy(std::move(out.visibility_bits), {n, py::ssize_t(out.words_per_vertex)}))
                                : py::object(py::none());
            r.report = std::move(report);
            return r;
        },
        py::arg("mesh"), py::arg("rule") = "lebedev:590", py::arg("backend") = "",
        py::arg("method") = py::none(), py::arg("resolution") = 0u,
        py::arg("max_distance") = std::numeric_limits<float>::infinity(), py::arg("offset") = 0.0f,
        py::arg("back_faces") = "occlude", py::arg("normalize") = false, py::arg("store_bits") = false,
        py::arg("progress") = py::none(), py::arg("device") = "auto",
        "Bakes AO, the shading coefficient and bent normals at every vertex, as `skybake ao` does, and also "
        "stores them on the mesh (attributes 'ao', 'shading', 'bent_normal'; colours (AO, AO, AO, 1)); "
        "normals are computed first when the mesh has none. device: 'auto' (a CUDA GPU when one answers, else "
        "the CPU), 'cpu', 'cuda' or 'opengl'; backend: one of backends() ('': the device's first), e.g. "
        "'raster' with method 'cube' or 'directional' and a resolution in texels (0: the default). The GIL is released; "
        "progress(event) is called at most every 100 ms; Ctrl-C or an exception it raises stops the bake.");

    m.def(
        "render_preview",
        [](const Mesh& mesh, const py::handle& values, int width, int height, float azimuth_deg, float elevation_deg,
           float fov_deg, int samples) {
            validate_mesh(mesh, "mesh");
            if (!py::isinstance<py::array>(values))
                throw Error("expected a NumPy array of float32", "values");
            const auto n = py::ssize_t(mesh.vertex_count());
            std::vector<glm::vec3> rgb;
            if (py::reinterpret_borrow<py::array>(values).ndim() == 1) {
                const auto v = checked_array<float>(values, "values", {n}, true);
                rgb.resize(std::size_t(n));
                for (py::ssize_t i = 0; i < n; ++i)
                    rgb[std::size_t(i)] = glm::vec3(v.data()[i]);
            } else {
                rgb = vec3_vector(checked_array<float>(values, "values", {n, 3}, true));
            }
            if (width < 1 || height < 1 || width > 16384 || height > 16384)
                throw Error("width and height must be in 1..16384", "width");
            if (samples < 1 || samples > 8)
                throw Error("must be in 1..8", "samples");
            AoPreviewOptions o;
            o.width = width;
            o.height = height;
            o.azimuth_deg = azimuth_deg;
            o.elevation_deg = elevation_deg;
            o.fov_y_deg = fov_deg;
            o.samples = samples;
            Image img;
            {
                py::gil_scoped_release release;
                img = render_vertex_preview(mesh, rgb, o);
            }
            return image_to_numpy(std::move(img));
        },
        py::arg("mesh"), py::arg("values"), py::arg("width") = 960, py::arg("height") = 720,
        py::arg("azimuth_deg") = 35.0f, py::arg("elevation_deg") = 30.0f, py::arg("fov_deg") = 35.0f,
        py::arg("samples") = 2,
        "Ray-casts the mesh from the previews' camera (framing its bounding sphere from azimuth, elevation) and "
        "shades it by per-vertex values, (N,) grey or (N, 3) linear RGB float32, interpolated: a linear "
        "(H, W, 3) float32 image. For AO as a display value, pass values = srgb_to_linear(ao) and save with "
        "tone='clamp'.");
}

} // namespace skybake::python
