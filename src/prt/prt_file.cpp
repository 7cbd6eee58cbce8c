// A baked mesh's transfer: vec4 attributes "prt_0", ... and the JSON sidecar
// that says how to read them (skybake/prt.h, [SECTION] Files).
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/prt.h"

namespace skybake {

namespace {

constexpr const char* kFormat = "skybake-prt";
constexpr int kVersion = 1;

int attribute_count(const Transfer& t) {
    return (t.channels * t.coefficients + 3) / 4;
}

} // namespace

std::filesystem::path prt_sidecar_path(const std::filesystem::path& mesh_path) {
    std::filesystem::path p = mesh_path;
    p.replace_extension(".prt.json");
    return p;
}

void set_transfer_attributes(Mesh& mesh, const Transfer& transfer, std::span<const glm::vec3> albedo) {
    const std::size_t n = mesh.vertex_count();
    if (transfer.vertices() != n)
        throw Error(fmt::format("transfer for {} vertices, mesh of {}", transfer.vertices(), n), "transfer");
    if (albedo.size() != n)
        throw Error(fmt::format("{} albedo values for {} vertices", albedo.size(), n), "albedo");
    const int per_vertex = transfer.channels * transfer.coefficients;
    for (int a = 0; a < attribute_count(transfer); ++a) {
        std::vector<float> values(4 * n, 0.0f);
        for (std::size_t v = 0; v < n; ++v)
            for (int k = 0; k < 4; ++k) {
                const int i = 4 * a + k;
                if (i < per_vertex)
                    values[4 * v + std::size_t(k)] = transfer.coeffs[v * std::size_t(per_vertex) + std::size_t(i)];
            }
        mesh.set_attribute(fmt::format("prt_{}", a), 4, std::move(values));
    }
    std::vector<float> rgb(3 * n);
    for (std::size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c)
            rgb[3 * v + std::size_t(c)] = albedo[v][c];
    mesh.set_attribute("albedo", 3, std::move(rgb));
    if (transfer.shading.size() == n)
        mesh.set_attribute("shading", 1, transfer.shading);
}

std::string transfer_sidecar_json(const Transfer& t, std::size_t vertices, const std::string& albedo_source) {
    nlohmann::json attrs = nlohmann::json::array();
    for (int a = 0; a < attribute_count(t); ++a)
        attrs.push_back(fmt::format("prt_{}", a));
    nlohmann::json j = {{"format", kFormat},
                        {"version", kVersion},
                        {"order", t.order},
                        {"coefficients", t.coefficients},
                        {"channels", t.channels},
                        {"kind", transfer_kind_name(t.kind)},
                        {"model", transfer_model_name(t.model)},
                        {"bounces", t.bounces},
                        {"rule", t.rule},
                        {"albedo", albedo_source.starts_with('[') ? nlohmann::json::parse(albedo_source)
                                                                  : nlohmann::json(albedo_source)},
                        {"vertices", vertices},
                        {"attributes", attrs}};
    return j.dump(2) + "\n";
}

std::string light_json(const ShLight& light, const std::string& source, const std::string& rule) {
    nlohmann::json c = nlohmann::json::array();
    for (const glm::vec3& v : light.coeffs)
        c.push_back({v.x, v.y, v.z});
    const glm::vec3 d = light.sun_direction, e = light.sun_irradiance;
    nlohmann::json j = {{"format", "skybake-sh-light"},
                        {"version", 1},
                        {"order", light.order},
                        {"coefficients", c},
                        {"sun_direction", {d.x, d.y, d.z}},
                        {"sun_irradiance", {e.x, e.y, e.z}},
                        {"source", source},
                        {"rule", rule}};
    return j.dump(1) + "\n";
}

ShLight load_light(const std::filesystem::path& path) {
    ShLight l;
    try {
        const nlohmann::json j = nlohmann::json::parse(read_file(path, std::uint64_t(64) << 20));
        if (!j.is_object() || j.value("format", "") != "skybake-sh-light" || j.at("version").get<int>() != 1)
            throw Error(fmt::format("{} is not a skybake-sh-light file (version 1)", path.string()), "light");
        l.order = j.at("order").get<int>();
        if (l.order < 0 || l.order > kShMaxL)
            throw Error(fmt::format("{}: order {} is out of range", path.string(), l.order), "light");
        const auto& c = j.at("coefficients");
        if (!c.is_array() || c.size() != std::size_t(sh_count(l.order)))
            throw Error(fmt::format("{}: order {} needs {} coefficients; the file has {}", path.string(), l.order,
                                    sh_count(l.order), c.is_array() ? c.size() : 0),
                        "light");
        auto vec = [&](const nlohmann::json& a) {
            const glm::vec3 v(a.at(0).get<float>(), a.at(1).get<float>(), a.at(2).get<float>());
            if (a.size() != 3 || !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw Error(fmt::format("{}: {} is not a finite 3-vector", path.string(), a.dump()), "light");
            return v;
        };
        for (const auto& v : c)
            l.coeffs.push_back(vec(v));
        l.sun_direction = vec(j.at("sun_direction"));
        l.sun_irradiance = vec(j.at("sun_irradiance"));
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{} is not a valid light file: {}", path.string(), e.what()), "light");
    } catch (const Error& e) {
        throw Error(e.message(), "light");
    }
    return l;
}

PrtModel load_prt(const std::filesystem::path& mesh_path) {
    const std::filesystem::path side = prt_sidecar_path(mesh_path);
    std::error_code ec;
    if (!std::filesystem::exists(side, ec))
        throw Error(fmt::format("no transfer sidecar {} beside {}; bake it with `skybake prt bake`", side.string(),
                                mesh_path.string()),
                    "sidecar");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(read_file(side, std::uint64_t(1) << 20));
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{} is not valid JSON: {}", side.string(), e.what()), "sidecar");
    }
    PrtModel m;
    Transfer& t = m.transfer;
    std::size_t vertices = 0;
    try {
        if (!j.is_object() || j.value("format", "") != kFormat)
            throw Error(fmt::format("{} is not a skybake-prt sidecar", side.string()), "sidecar");
        if (j.at("version").get<int>() != kVersion)
            throw Error(fmt::format("{}: version {} is not {}", side.string(), j.at("version").dump(), kVersion),
                        "sidecar");
        t.order = j.at("order").get<int>();
        t.coefficients = j.at("coefficients").get<int>();
        t.channels = j.at("channels").get<int>();
        t.kind = parse_transfer_kind(j.at("kind").get<std::string>());
        t.model = parse_transfer_model(j.at("model").get<std::string>());
        t.bounces = j.at("bounces").get<int>();
        t.rule = j.at("rule").get<std::string>();
        vertices = j.at("vertices").get<std::size_t>();
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{}: missing or wrong field ({})", side.string(), e.what()), "sidecar");
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}", side.string(), e.message()), "sidecar");
    }
    if (t.order < 0 || t.order > kPrtMaxOrder || t.coefficients != sh_count(t.order) ||
        (t.channels != 1 && t.channels != 3))
        throw Error(fmt::format("{}: order {}, {} coefficients and {} channels do not fit together", side.string(),
                                t.order, t.coefficients, t.channels),
                    "sidecar");
    m.mesh = load_mesh(mesh_path);
    const std::size_t n = m.mesh.vertex_count();
    if (n != vertices)
        throw Error(
            fmt::format("{} describes {} vertices but {} has {}", side.string(), vertices, mesh_path.string(), n),
            "sidecar");
    const int per_vertex = t.channels * t.coefficients;
    t.coeffs.assign(n * std::size_t(per_vertex), 0.0f);
    for (int a = 0; a < attribute_count(t); ++a) {
        const std::string name = fmt::format("prt_{}", a);
        const VertexAttribute* attr = m.mesh.find_attribute(name);
        if (!attr || attr->components != 4 || attr->values.size() != 4 * n)
            throw Error(fmt::format("{} has no 4-component attribute {} that {} lists", mesh_path.string(), name,
                                    side.string()),
                        "sidecar");
        for (std::size_t v = 0; v < n; ++v)
            for (int k = 0; k < 4; ++k)
                if (4 * a + k < per_vertex)
                    t.coeffs[v * std::size_t(per_vertex) + std::size_t(4 * a + k)] =
                        attr->values[4 * v + std::size_t(k)];
    }
    const VertexAttribute* alb = m.mesh.find_attribute("albedo");
    if (!alb || alb->components != 3)
        throw Error(fmt::format("{} has no 3-component albedo attribute", mesh_path.string()), "sidecar");
    m.albedo.resize(n);
    for (std::size_t v = 0; v < n; ++v)
        m.albedo[v] = {alb->values[3 * v], alb->values[3 * v + 1], alb->values[3 * v + 2]};
    if (const VertexAttribute* a = m.mesh.find_attribute("shading"); a && a->components == 1)
        t.shading = a->values;
    for (float x : t.coeffs)
        if (!std::isfinite(x))
            throw Error(fmt::format("{} has non-finite transfer coefficients", mesh_path.string()), "sidecar");
    return m;
}

} // namespace skybake
