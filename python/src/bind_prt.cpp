// Precomputed radiance transfer: the transfer bake, SH lights (the sky, maps,
// constants), relighting and the asset files (skybake/prt.h).
#include <cstring>
#include <functional>
#include <optional>

#include "common.h"
#include "skybake/bake.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/prt.h"
#include "skybake/sky_source.h"
#include "skybake/bake_job.h"

namespace skybake::python {

BakeOptions bake_options(float max_distance, float offset, const std::string& back_faces, bool normalize);

namespace {

glm::vec3 vec3_arg(const std::vector<float>& v, const char* name) {
    if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        throw Error("expected 3 finite values", name);
    return {v[0], v[1], v[2]};
}

py::tuple vec3_tuple(const glm::vec3& v) {
    return py::make_tuple(v.x, v.y, v.z);
}

std::vector<glm::vec3> albedo_arg(const py::handle& obj, std::size_t vertices) {
    const auto arr = checked_array<float>(obj, "albedo", {py::ssize_t(vertices), 3}, true);
    return vec3_vector(arr);
}

} // namespace

void bind_prt(py::module_& m) {
    py::class_<Transfer>(m, "Transfer", "Per-vertex SH transfer vectors of a PRT bake.")
        .def_readonly("order", &Transfer::order)
        .def_readonly("coefficients", &Transfer::coefficients, "(order + 1)².")
        .def_readonly("channels", &Transfer::channels, "1 (grey) or 3 (RGB, interreflected).")
        .def_property_readonly("kind", [](const Transfer& t) { return std::string(transfer_kind_name(t.kind)); })
        .def_property_readonly("model", [](const Transfer& t) { return std::string(transfer_model_name(t.model)); })
        .def_readonly("bounces", &Transfer::bounces)
        .def_readonly("rule", &Transfer::rule)
        .def_property_readonly("vertex_count", &Transfer::vertices)
        .def_property_readonly(
            "coeffs",
            [](const Transfer& t) {
                std::vector<float> c = t.coeffs;
                return to_numpy(std::move(c),
                                {py::ssize_t(t.vertices()), py::ssize_t(t.channels), py::ssize_t(t.coefficients)});
            },
            "(V, channels, coefficients) float32, a copy; column sh_index(l, m).")
        .def_property_readonly(
            "shading",
            [](const Transfer& t) {
                std::vector<float> a = t.shading;
                return to_numpy(std::move(a), {py::ssize_t(t.shading.size())});
            },
            "(V,) float32: the shading coefficient A (empty when unknown).")
        .def("__repr__", [](const Transfer& t) {
            return "Transfer(order=" + std::to_string(t.order) + ", kind='" + transfer_kind_name(t.kind) +
                   "', vertices=" + std::to_string(t.vertices()) + ")";
        });

    m.def(
        "bake_transfer",
        [](Mesh& mesh, const std::string& rule_spec, int order, const std::string& kind, const std::string& model,
           int bounces, const py::handle& albedo, const std::string& backend, std::optional<std::string> method,
           std::uint32_t resolution, float max_distance, py::object progress, const std::string& device) {
            const SphereRule rule = parse_rule(rule_spec);
            TransferOptions t;
            t.order = order;
            t.kind = parse_transfer_kind(kind);
            t.model = parse_transfer_model(model);
            t.bounces = bounces;
            BakeJob job;
            job.rule = rule;
            job.options = bake_options(max_distance, 0.0f, "occlude", false);
            job.shading = false;
            job.transfer = t;
            if (albedo.is_none()) { // glTF's base colour, at each hit as `prt bake --albedo material`
                job.albedo_images = base_color_images(mesh);
                job.albedo = mesh_albedo(mesh, job.albedo_images);
            } else {
                job.albedo = albedo_arg(albedo, mesh.vertex_count());
            }
            job.tracer.device = device;
            job.tracer.backend = backend;
            job.tracer.method = method.value_or("");
            job.tracer.resolution = resolution;
            Transfer out = long_call(std::move(progress), [&] { return run_bake_job(mesh, job).transfer; });
            return out;
        },
        py::arg("mesh"), py::arg("rule") = "lebedev:590", py::arg("order") = 3, py::arg("kind") = "shadowed",
        py::arg("model") = "prt", py::arg("bounces") = 0, py::arg("albedo") = py::none(),
        py::arg("backend") = "", py::arg("method") = py::none(), py::arg("resolution") = 0u,
        py::arg("max_distance") = std::numeric_limits<float>::infinity(), py::arg("progress") = py::none(),
        py::arg("device") = "auto",
        "The diffuse transfer of every vertex: kind 'unshadowed', 'shadowed' or 'interreflected' (bounces ≥ 1, "
        "a backend with ray queries); model 'prt' or 'shading-coefficient'. albedo (V, 3) float32 is used by the "
        "bounces (default: the vertex colours, else 0.8). Normals are computed when the mesh has none.");

    py::class_<ShLight>(m, "ShLight", "RGB radiance in SH, and the sun as a direct light.")
        .def_readonly("order", &ShLight::order)
        .def_property_readonly(
            "coeffs",
            [](const ShLight& l) {
                std::vector<glm::vec3> c = l.coeffs;
                return to_numpy(std::move(c));
            },
            "((order + 1)², 3) float32, a copy; row sh_index(l, m).")
        .def_property_readonly("sun_direction", [](const ShLight& l) { return vec3_tuple(l.sun_direction); })
        .def_property_readonly("sun_irradiance", [](const ShLight& l) { return vec3_tuple(l.sun_irradiance); })
        .def(
            "to_json",
            [](const ShLight& l, const std::string& source, const std::string& rule) {
                return light_json(l, source, rule);
            },
            py::arg("source") = "python", py::arg("rule") = "", "The light file's JSON (`skybake sky sh`).")
        .def("__repr__", [](const ShLight& l) { return "ShLight(order=" + std::to_string(l.order) + ")"; });

    m.def(
        "sky_light",
        [](const SkySource& sky, double sun_elevation_deg, double sun_azimuth_deg, double altitude_km, bool sun,
           int order, const std::string& rule_spec, std::optional<std::vector<float>> ground_albedo) {
            const SphereRule rule = parse_rule(rule_spec);
            SkyLightSettings s{sun_elevation_deg, sun_azimuth_deg, altitude_km, sun};
            if (ground_albedo)
                s.ground_albedo = ground_albedo->size() == 1 ? glm::vec3((*ground_albedo)[0])
                                                             : vec3_arg(*ground_albedo, "ground_albedo");
            py::gil_scoped_release release;
            return sky_light(sky, s, order, rule);
        },
        py::arg("sky"), py::arg("sun_elevation_deg") = 30.0, py::arg("sun_azimuth_deg") = 0.0,
        py::arg("altitude_km") = 0.0, py::arg("sun") = true, py::arg("order") = 3, py::arg("rule") = kSkyLightRule,
        py::arg("ground_albedo") = py::none(),
        "The sky (+y up; azimuth 0 towards +z, 90 towards +x) projected on SH, with the transmitted sun; "
        "ground_albedo ([a] or [r, g, b] in [0, 1]) adds the lit ground below the horizon (`sky sh --ground-albedo`).");
    m.def(
        "constant_light",
        [](const std::vector<float>& radiance, int order) {
            return constant_light(vec3_arg(radiance, "radiance"), order);
        },
        py::arg("radiance"), py::arg("order") = 3, "The same RGB radiance from every direction.");
    m.def(
        "equirect_light",
        [](const py::handle& rgb, int order, const std::string& rule_spec) {
            const Image img = numpy_to_image(rgb, "rgb");
            const SphereRule rule = parse_rule(rule_spec);
            py::gil_scoped_release release;
            return equirect_light(img, order, rule);
        },
        py::arg("rgb"), py::arg("order") = 3, py::arg("rule") = "lebedev:2030",
        "An equirectangular (H, 2H, 3) float32 map (top row: the zenith, +y) projected on SH.");
    m.def("sun_direction", [](double e, double a) { return vec3_tuple(sun_direction(e, a)); },
          py::arg("elevation_deg"), py::arg("azimuth_deg"), "World direction (+y up) towards the sun.");

    m.def(
        "relight",
        [](const Transfer& transfer, const ShLight& light, const py::handle& albedo, const py::handle& normals,
           const py::handle& sun_visible) {
            const std::size_t v = transfer.vertices();
            const auto rho = checked_array<float>(albedo, "albedo", {py::ssize_t(v), 3}, true);
            std::optional<py::array_t<float>> n, vis;
            if (!normals.is_none())
                n = checked_array<float>(normals, "normals", {py::ssize_t(v), 3}, true);
            if (!sun_visible.is_none())
                vis = checked_array<float>(sun_visible, "sun_visible", {py::ssize_t(v)}, true);
            if (n.has_value() != vis.has_value())
                throw Error("the sun needs both normals and sun_visible (or neither)", "sun_visible");
            std::vector<glm::vec3> out;
            {
                py::gil_scoped_release release;
                out = relight(transfer, light, as_vec3(rho), n ? as_vec3(*n) : std::span<const glm::vec3>{},
                              vis ? std::span<const float>(vis->data(), v) : std::span<const float>{});
            }
            return to_numpy(std::move(out));
        },
        py::arg("transfer"), py::arg("light"), py::arg("albedo"), py::arg("normals") = py::none(),
        py::arg("sun_visible") = py::none(),
        "Outgoing radiance (V, 3) float32: albedo Σ L_lm T_lm, plus the sun where normals (V, 3) and "
        "sun_visible (V,) (1 lit, 0 shadowed) are given. Inputs are read in place.");
    m.def(
        "sun_visibility",
        [](const Mesh& mesh, const std::vector<float>& direction, const std::string& backend) {
            const glm::vec3 d = vec3_arg(direction, "direction");
            validate_mesh(mesh, "mesh");
            if (mesh.normals.size() != mesh.vertex_count())
                throw Error("the mesh has no normals (call compute_normals())", "mesh");
            std::vector<float> out;
            {
                py::gil_scoped_release release;
                const auto queries = make_ray_queries(backend);
                queries->set_mesh(mesh);
                out = sun_visibility(mesh, d, *queries);
            }
            const auto n = py::ssize_t(out.size());
            return to_numpy(std::move(out), {n});
        },
        py::arg("mesh"), py::arg("direction"), py::arg("backend") = "embree",
        "Per-vertex visibility (V,) float32 of a direction (1 or 0), one occlusion ray per vertex.");

    // As `skybake prt bake` writes its outputs: the attributes, COLOR_0 = the
    // white-sky transfer where the mesh has no colours, the sidecar; both
    // files or neither.
    const auto write_prt = [](const std::filesystem::path& path, Mesh& mesh, const Transfer& transfer,
                              const py::handle& albedo, const std::function<void(const std::filesystem::path&)>& save) {
        const std::vector<glm::vec3> rho =
            albedo.is_none() ? mesh_albedo(mesh) : albedo_arg(albedo, mesh.vertex_count());
        const std::string source = !albedo.is_none() ? "array"
                                   : !mesh.materials.empty() && !mesh.triangle_parts.empty()
                                       ? "material"
                                       : (mesh.colors.size() == mesh.vertex_count() ? "vertex-colors"
                                                                                    : "[0.8, 0.8, 0.8]");
        py::gil_scoped_release release;
        const bool had_colors = mesh.colors.size() == mesh.vertex_count();
        set_transfer_attributes(mesh, transfer, rho);
        if (!had_colors)
            set_white_sky_colors(mesh, transfer);
        OutputSet files;
        save(files.stage(path));
        const std::string side = transfer_sidecar_json(transfer, mesh.vertex_count(), source, !had_colors);
        write_stream_atomic(files.stage(prt_sidecar_path(path)), [&](std::ostream& out) { out << side; });
        files.commit();
    };
    m.def(
        "save_prt",
        [write_prt](const std::filesystem::path& path, const py::object& mesh, const Transfer& transfer,
                    const py::handle& albedo) {
            if (py::isinstance<BakeFile>(mesh)) {
                BakeFile& file = mesh.cast<BakeFile&>();
                write_prt(path, file.mesh(), transfer, albedo,
                          [&](const std::filesystem::path& tmp) { file.save(tmp); });
                return;
            }
            Mesh& m = mesh.cast<Mesh&>();
            write_prt(path, m, transfer, albedo, [&](const std::filesystem::path& tmp) { save_mesh(tmp, m); });
        },
        py::arg("path"), py::arg("mesh"), py::arg("transfer"), py::arg("albedo") = py::none(),
        "Writes a baked mesh (.glb or .ply: attributes prt_0 ..., albedo, and COLOR_0 = the vertex under a white "
        "sky where the mesh has no colours) and its sidecar PATH.prt.json, as `skybake prt bake` does; both or "
        "neither. With a BakeFile for `mesh`, a glTF 2.0 input keeps its whole document.");
    m.def(
        "load_prt",
        [](const std::filesystem::path& path) {
            PrtModel model;
            {
                py::gil_scoped_release release;
                model = load_prt(path);
            }
            return py::make_tuple(std::move(model.mesh), std::move(model.transfer), to_numpy(std::move(model.albedo)));
        },
        py::arg("path"), "(mesh, transfer, albedo) of a baked mesh with its sidecar.");
    m.def(
        "export_prt_glsl",
        [](int order, int channels, const std::string& function_name, bool es) {
            PrtShaderOptions o;
            o.function_name = function_name;
            o.es = es;
            return export_prt_glsl(order, channels, o);
        },
        py::arg("order") = 3, py::arg("channels") = 1, py::arg("function_name") = "skybake_prt",
        py::arg("es") = false,
        "GLSL of NAME_diffuse(prt[], light[], albedo) for engines; es=True: GLSL ES 3.00 (WebGL 2), highp.");
}

} // namespace skybake::python
