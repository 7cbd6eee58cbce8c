// A baked mesh's transfer: vec4 attributes "prt_0", ... and the JSON sidecar
// that says how to read them (skybake/prt.h, [SECTION] Files).
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <string_view>

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

// An integer field, refused (a JSON type error) when it is not an integer
// that fits in an int: get<int>() of 1e300 or 2^40 would not be defined.
int json_int(const nlohmann::json& v, const char* field) {
    if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(INT_MAX)) ||
        (!v.is_number_unsigned() && (v.get<std::int64_t>() < INT_MIN || v.get<std::int64_t>() > INT_MAX)))
        throw nlohmann::json::type_error::create(302, fmt::format("{} must be an integer, not {}", field, v.dump()),
                                                 &v);
    return v.get<int>();
}

struct SidecarHeader {
    Transfer transfer; // without coefficients
    std::size_t vertices = 0;
    bool baked_colors = false; // "colors": "white-sky": COLOR_0 is the bake's, not the material's
};

// The sidecar's own checks, before its mesh is read.
SidecarHeader parse_sidecar(std::string_view text, const std::string& side) {
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{} is not valid JSON: {}", side, e.what()), "sidecar");
    }
    SidecarHeader h;
    Transfer& t = h.transfer;
    try {
        if (!j.is_object() || j.value("format", "") != kFormat)
            throw Error(fmt::format("{} is not a skybake-prt sidecar", side), "sidecar");
        if (json_int(j.at("version"), "version") != kVersion)
            throw Error(fmt::format("{}: version {} is not {}", side, j.at("version").dump(), kVersion), "sidecar");
        t.order = json_int(j.at("order"), "order");
        t.coefficients = json_int(j.at("coefficients"), "coefficients");
        t.channels = json_int(j.at("channels"), "channels");
        t.kind = parse_transfer_kind(j.at("kind").get<std::string>());
        t.model = parse_transfer_model(j.at("model").get<std::string>());
        t.bounces = json_int(j.at("bounces"), "bounces");
        t.rule = j.at("rule").get<std::string>();
        h.baked_colors = j.value("colors", "") == "white-sky";
        const nlohmann::json& n = j.at("vertices");
        if (!n.is_number_unsigned())
            throw nlohmann::json::type_error::create(302, "vertices must be a count, not " + n.dump(), &n);
        h.vertices = n.get<std::size_t>();
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{}: missing or wrong field ({})", side, e.what()), "sidecar");
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}", side, e.message()), "sidecar");
    }
    if (t.order < 0 || t.order > kPrtMaxOrder || t.coefficients != sh_count(t.order) ||
        (t.channels != 1 && t.channels != 3))
        throw Error(fmt::format("{}: order {}, {} coefficients and {} channels do not fit together", side, t.order,
                                t.coefficients, t.channels),
                    "sidecar");
    return h;
}

// The mesh's attributes read through the sidecar.
PrtModel attach_transfer(SidecarHeader h, Mesh mesh, const std::string& side, const std::string& mesh_name) {
    PrtModel m;
    m.mesh = std::move(mesh);
    if (h.baked_colors)
        m.mesh.colors.clear(); // the bake's picture of itself, not a colour of the surface
    m.transfer = std::move(h.transfer);
    Transfer& t = m.transfer;
    const std::size_t n = m.mesh.vertex_count();
    if (n != h.vertices)
        throw Error(fmt::format("{} describes {} vertices but {} has {}", side, h.vertices, mesh_name, n), "sidecar");
    const int per_vertex = t.channels * t.coefficients;
    t.coeffs.assign(n * std::size_t(per_vertex), 0.0f);
    for (int a = 0; a < attribute_count(t); ++a) {
        const std::string name = fmt::format("prt_{}", a);
        const VertexAttribute* attr = m.mesh.find_attribute(name);
        if (!attr || attr->components != 4 || attr->values.size() != 4 * n)
            throw Error(fmt::format("{} has no 4-component attribute {} that {} lists", mesh_name, name, side),
                        "sidecar");
        for (std::size_t v = 0; v < n; ++v)
            for (int k = 0; k < 4; ++k)
                if (4 * a + k < per_vertex)
                    t.coeffs[v * std::size_t(per_vertex) + std::size_t(4 * a + k)] =
                        attr->values[4 * v + std::size_t(k)];
    }
    const VertexAttribute* alb = m.mesh.find_attribute("albedo");
    if (!alb || alb->components != 3 || alb->values.size() != 3 * n)
        throw Error(fmt::format("{} has no 3-component albedo attribute", mesh_name), "sidecar");
    m.albedo.resize(n);
    for (std::size_t v = 0; v < n; ++v)
        m.albedo[v] = {alb->values[3 * v], alb->values[3 * v + 1], alb->values[3 * v + 2]};
    if (const VertexAttribute* a = m.mesh.find_attribute("shading"); a && a->components == 1 && a->values.size() == n)
        t.shading = a->values;
    for (float x : t.coeffs)
        if (!std::isfinite(x))
            throw Error(fmt::format("{} has non-finite transfer coefficients", mesh_name), "sidecar");
    return m;
}

} // namespace

std::filesystem::path prt_sidecar_path(const std::filesystem::path& mesh_path) {
    std::filesystem::path p = mesh_path;
    p.replace_extension(".prt.json");
    return p;
}

void set_white_sky_colors(Mesh& mesh, const Transfer& transfer) {
    const std::size_t n = mesh.vertex_count();
    if (transfer.vertices() != n)
        throw Error(fmt::format("transfer for {} vertices, mesh of {}", transfer.vertices(), n), "transfer");
    const float two_sqrt_pi = 2.0f * std::sqrt(3.14159265358979f);
    mesh.colors.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
        float sum = 0.0f;
        for (int c = 0; c < transfer.channels; ++c)
            sum += transfer.vertex(v, c)[0];
        const float g = std::clamp(two_sqrt_pi * sum / float(transfer.channels), 0.0f, 1.0f);
        mesh.colors[v] = glm::vec4(g, g, g, 1.0f);
    }
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

std::string transfer_sidecar_json(const Transfer& t, std::size_t vertices, const std::string& albedo_source,
                                  bool white_sky_colors) {
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
    if (white_sky_colors)
        j["colors"] = "white-sky";
    return j.dump(2) + "\n";
}

std::string light_json(const ShLight& light, const std::string& source, const std::string& rule,
                       ShConvention convention) {
    std::vector<glm::vec3> coeffs = light.coeffs;
    convert_sh_convention(coeffs, light.order, convention);
    nlohmann::json c = nlohmann::json::array();
    for (const glm::vec3& v : coeffs)
        c.push_back({v.x, v.y, v.z});
    const glm::vec3 d = light.sun_direction, e = light.sun_irradiance;
    nlohmann::json j = {{"format", "skybake-sh-light"},
                        {"version", 1},
                        {"order", light.order},
                        {"coefficients", c},
                        {"sun_direction", {d.x, d.y, d.z}},
                        {"sun_irradiance", {e.x, e.y, e.z}},
                        {"source", source},
                        {"rule", rule},
                        {"sh_convention", sh_convention_name(convention)}};
    return j.dump(1) + "\n";
}

ShLight light_from_json(std::string_view text, const std::string& name) {
    ShLight l;
    try {
        const nlohmann::json j = nlohmann::json::parse(text);
        if (!j.is_object() || j.value("format", "") != "skybake-sh-light" || !j.contains("version") ||
            json_int(j.at("version"), "version") != 1)
            throw Error(fmt::format("{} is not a skybake-sh-light file (version 1)", name), "light");
        l.order = json_int(j.at("order"), "order");
        if (l.order < 0 || l.order > kShMaxL)
            throw Error(fmt::format("{}: order {} is out of range", name, l.order), "light");
        const auto& c = j.at("coefficients");
        if (!c.is_array() || c.size() != std::size_t(sh_count(l.order)))
            throw Error(fmt::format("{}: order {} needs {} coefficients; the file has {}", name, l.order,
                                    sh_count(l.order), c.is_array() ? c.size() : 0),
                        "light");
        auto vec = [&](const nlohmann::json& a) {
            if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
                throw Error(fmt::format("{}: {} is not a finite 3-vector", name, a.dump()), "light");
            const glm::vec3 v(a[0].get<float>(), a[1].get<float>(), a[2].get<float>());
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw Error(fmt::format("{}: {} is not a finite 3-vector", name, a.dump()), "light");
            return v;
        };
        for (const auto& v : c)
            l.coeffs.push_back(vec(v));
        if (j.contains("sh_convention")) {
            if (!j["sh_convention"].is_string())
                throw Error(fmt::format("{}: sh_convention is not a string", name), "light");
            convert_sh_convention(l.coeffs, l.order, parse_sh_convention(j["sh_convention"].get<std::string>()));
        }
        // The sun: a direction (any length but zero) and an
        // irradiance ≥ 0 per channel (zero: no sun).
        const glm::vec3 d = vec(j.at("sun_direction"));
        const float length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        if (!(length > 1e-6f) || !std::isfinite(length))
            throw Error(fmt::format("{}: sun_direction {} is not a direction (zero length)", name,
                                    j.at("sun_direction").dump()),
                        "light");
        // Stored unit; a direction already unit to float rounding is kept as
        // written, so that a file read and written again is unchanged.
        l.sun_direction = std::abs(length - 1.0f) > 1e-5f ? d / length : d;
        l.sun_irradiance = vec(j.at("sun_irradiance"));
        if (l.sun_irradiance.x < 0.0f || l.sun_irradiance.y < 0.0f || l.sun_irradiance.z < 0.0f)
            throw Error(fmt::format("{}: sun_irradiance {} is negative; it is ≥ 0 per channel (0: no sun)", name,
                                    j.at("sun_irradiance").dump()),
                        "light");
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("{} is not a valid light file: {}", name, e.what()), "light");
    } catch (const Error& e) {
        throw Error(e.message(), "light");
    }
    return l;
}

ShLight load_light(const std::filesystem::path& path) {
    std::string text;
    try {
        text = read_file(path, std::uint64_t(64) << 20);
    } catch (const Error& e) {
        throw Error(e.message(), "light");
    }
    return light_from_json(text, path.string());
}

PrtModel prt_from_sidecar_json(std::string_view sidecar, Mesh mesh, const std::string& sidecar_name,
                               const std::string& mesh_name) {
    return attach_transfer(parse_sidecar(sidecar, sidecar_name), std::move(mesh), sidecar_name, mesh_name);
}

PrtModel load_prt(const std::filesystem::path& mesh_path) {
    const std::filesystem::path side = prt_sidecar_path(mesh_path);
    std::error_code ec;
    if (!std::filesystem::exists(side, ec))
        throw Error(fmt::format("no transfer sidecar {} beside {}; bake it with `skybake prt bake`", side.string(),
                                mesh_path.string()),
                    "sidecar");
    SidecarHeader h = parse_sidecar(read_file(side, std::uint64_t(1) << 20), side.string());
    return attach_transfer(std::move(h), load_mesh(mesh_path), side.string(), mesh_path.string());
}

} // namespace skybake
