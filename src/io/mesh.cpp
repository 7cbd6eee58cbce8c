#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "io/gltf_schema.h"
#include "io/mesh_internal.h"
#include "skybake/error.h"
#include "skybake/files.h"

namespace skybake {

const VertexAttribute* Mesh::find_attribute(std::string_view name) const {
    for (const auto& a : attributes)
        if (a.name == name)
            return &a;
    return nullptr;
}

void Mesh::set_attribute(std::string name, int components, std::vector<float> values) {
    if (!io::is_valid_attribute_name(name))
        throw Error(fmt::format("invalid attribute name '{}': use lower-case letters, digits and '_'", name));
    if (components < 1 || components > 4)
        throw Error(fmt::format("attribute '{}' has {} components; 1 to 4 are allowed", name, components));
    if (values.size() != vertex_count() * std::size_t(components))
        throw Error(fmt::format("attribute '{}' has {} values, expected {} ({} vertices x {})", name, values.size(),
                                vertex_count() * std::size_t(components), vertex_count(), components));
    for (auto& a : attributes)
        if (a.name == name) {
            a.components = components;
            a.values = std::move(values);
            return;
        }
    attributes.push_back({std::move(name), components, std::move(values)});
}

float Bounds::diagonal() const { return glm::length(max - min); }

Bounds compute_bounds(const Mesh& mesh) {
    Bounds b;
    if (mesh.positions.empty())
        return b;
    b.min = b.max = mesh.positions[0];
    for (const auto& p : mesh.positions) {
        b.min = glm::min(b.min, p);
        b.max = glm::max(b.max, p);
    }
    return b;
}

void compute_normals(Mesh& mesh) {
    std::vector<glm::dvec3> acc(mesh.vertex_count(), glm::dvec3(0.0));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
        const glm::dvec3 p0 = mesh.positions[i0], p1 = mesh.positions[i1], p2 = mesh.positions[i2];
        const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0); // length = 2 * area
        acc[i0] += n;
        acc[i1] += n;
        acc[i2] += n;
    }
    mesh.normals.resize(mesh.vertex_count());
    for (std::size_t v = 0; v < acc.size(); ++v) {
        const double len = glm::length(acc[v]);
        mesh.normals[v] = len > 0.0 && std::isfinite(len) ? glm::vec3(acc[v] / len) : glm::vec3(0, 0, 1);
    }
}

void validate_mesh(const Mesh& mesh, const std::string& where) {
    const std::size_t n = mesh.vertex_count();
    if (n == 0 || mesh.indices.empty())
        throw Error("mesh has no triangles", where);
    if (mesh.indices.size() % 3 != 0)
        throw Error(fmt::format("index count {} is not a multiple of 3", mesh.indices.size()), where);
    if (!mesh.normals.empty() && mesh.normals.size() != n)
        throw Error(fmt::format("{} normals for {} vertices", mesh.normals.size(), n), where);
    if (!mesh.colors.empty() && mesh.colors.size() != n)
        throw Error(fmt::format("{} colours for {} vertices", mesh.colors.size(), n), where);
    for (const auto& a : mesh.attributes)
        if (a.components < 1 || a.components > 4 || a.values.size() != n * std::size_t(a.components))
            throw Error(fmt::format("attribute '{}' has {} values for {} vertices x {} components", a.name,
                                    a.values.size(), n, a.components),
                        where);
    for (std::size_t k = 0; k < mesh.texcoords.size(); ++k)
        if (mesh.texcoords[k].size() != n)
            throw Error(fmt::format("UV set {} has {} entries for {} vertices", k, mesh.texcoords[k].size(), n), where);
    if (!mesh.triangle_parts.empty() && mesh.triangle_parts.size() != mesh.indices.size() / 3)
        throw Error(fmt::format("{} triangle parts for {} triangles", mesh.triangle_parts.size(), mesh.indices.size() / 3),
                    where);
    for (std::uint32_t p : mesh.triangle_parts)
        if (p >= mesh.parts.size())
            throw Error(fmt::format("a triangle belongs to part {}, but the mesh has {}", p, mesh.parts.size()), where);
    for (const auto& part : mesh.parts)
        if (part.material < -1 || part.material >= int(mesh.materials.size()))
            throw Error(fmt::format("part '{}' uses material {}, but the mesh has {}", part.name, part.material,
                                    mesh.materials.size()),
                        where);
    for (std::size_t v = 0; v < n; ++v) {
        const auto& p = mesh.positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(fmt::format("vertex {} has a non-finite coordinate ({}, {}, {})", v, p.x, p.y, p.z), where);
    }
    for (std::size_t i = 0; i < mesh.indices.size(); ++i)
        if (mesh.indices[i] >= n)
            throw Error(fmt::format("triangle {} uses vertex index {}, but the mesh has {} vertices", i / 3,
                                    mesh.indices[i], n),
                        where);
}

namespace io {

bool is_valid_attribute_name(std::string_view name) {
    if (name.empty() || name.size() > 64 || !(name[0] >= 'a' && name[0] <= 'z'))
        return false;
    for (char c : name)
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'))
            return false;
    return true;
}

void check_counts(std::uint64_t vertices, std::uint64_t triangles, const ImportLimits& limits,
                  const std::string& where) {
    if (vertices > limits.max_vertices)
        throw Error(fmt::format("file declares {} vertices, over the limit of {}", vertices, limits.max_vertices),
                    where);
    if (triangles > limits.max_triangles)
        throw Error(fmt::format("file declares {} triangles, over the limit of {}", triangles, limits.max_triangles),
                    where);
}

Mesh finish_import(RawImport raw, const std::string& where, const ImportLimits& limits, ImportReport* report) {
    Mesh& mesh = raw.mesh;
    ImportReport& rep = raw.report;
    if (mesh.vertex_count() == 0 || mesh.indices.empty())
        throw Error("file contains no triangles", where);
    check_counts(mesh.vertex_count(), mesh.triangle_count(), limits, where);
    validate_mesh(mesh, where);

    // Drop degenerate triangles: repeated indices or zero area.
    std::size_t kept = 0;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
        const bool degenerate = a == b || b == c || a == c || !(glm::dot(n, n) > 0.0f);
        if (degenerate) {
            ++rep.degenerate_triangles;
            continue;
        }
        if (!mesh.triangle_parts.empty())
            mesh.triangle_parts[kept / 3] = mesh.triangle_parts[t / 3];
        mesh.indices[kept++] = a;
        mesh.indices[kept++] = b;
        mesh.indices[kept++] = c;
    }
    mesh.indices.resize(kept);
    if (!mesh.triangle_parts.empty())
        mesh.triangle_parts.resize(kept / 3);
    if (mesh.indices.empty())
        throw Error(fmt::format("all {} triangles are degenerate (zero area)", rep.degenerate_triangles), where);

    // Normals: keep the file's when every one is finite and non-zero. Those of
    // unit length to float precision are kept bit for bit (so that a save and
    // load round trip is exact); the others are normalised.
    bool usable = mesh.normals.size() == mesh.vertex_count();
    if (usable)
        for (auto& n : mesh.normals) {
            const double len = glm::length(glm::dvec3(n));
            if (!std::isfinite(len) || len < 1e-12) {
                usable = false;
                break;
            }
            if (std::abs(len - 1.0) > 0x1.0p-22)
                n = glm::vec3(glm::dvec3(n) / len);
        }
    rep.normals_present = usable;
    if (!usable)
        compute_normals(mesh);
    if (report)
        *report = rep;
    return std::move(mesh);
}

} // namespace io

namespace {

std::string lower_ext(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    if (!e.empty() && e[0] == '.')
        e.erase(0, 1);
    for (char& c : e)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

Mesh load_impl(const void* data, std::size_t size, const std::string& ext, const std::string& base_dir,
               const std::string& where, ImportReport* report, const ImportLimits& limits) {
    if (size == 0)
        throw Error("file is empty", where);
    if (size > limits.max_file_bytes)
        throw Error(fmt::format("file is {} bytes, over the limit of {}", size, limits.max_file_bytes), where);
    io::RawImport raw;
    // glTF 1.0 (e.g. the original CesiumMilkTruck) is read by Assimp.
    if ((ext == "gltf" || ext == "glb") && io::check_gltf(data, size, ext == "glb", where) == 2)
        raw = io::read_gltf(data, size, ext == "glb", base_dir, where, limits);
    else if (ext == "ply")
        raw = io::read_ply(data, size, where, limits);
    else if (io::precheck_for_assimp(ext, data, size, where, limits); base_dir.empty())
        raw = io::read_assimp(data, size, ext, where, limits);
    else { // from a path, so that Assimp can follow side files
        const std::filesystem::path path = where;
        raw = io::read_assimp(data, size, ext, where, limits, &path);
    }
    return io::finish_import(std::move(raw), where, limits, report);
}

} // namespace

Mesh load_mesh(const std::filesystem::path& path, ImportReport* report, const ImportLimits& limits) {
    const std::string where = path.string();
    const std::string ext = lower_ext(path);
    if (ext == "gltf" || ext == "glb" || ext == "ply") {
        const std::string data = read_file(path, limits.max_file_bytes);
        const std::string base = path.has_parent_path() ? path.parent_path().string() : std::string(".");
        return load_impl(data.data(), data.size(), ext, base, where, report, limits);
    }
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw Error("file not found", where);
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error("not a regular file", where);
    const auto size = std::filesystem::file_size(path, ec);
    if (ec)
        throw Error(fmt::format("cannot read file: {}", ec.message()), where);
    if (size == 0)
        throw Error("file is empty", where);
    if (size > limits.max_file_bytes)
        throw Error(fmt::format("file is {} bytes, over the limit of {}", size, limits.max_file_bytes), where);
    {
        std::ifstream in(path, std::ios::binary);
        std::string head(std::min<std::uintmax_t>(size, 4096), '\0');
        in.read(head.data(), std::streamsize(head.size()));
        io::precheck_for_assimp(ext, head.data(), std::size_t(size), where, limits);
    }
    try {
        return io::finish_import(io::read_assimp(nullptr, 0, ext, where, limits, &path), where, limits, report);
    } catch (const Error& e) {
        // Assimp's OBJ reader turns "v nan 1 0" into (nan, nan, nan) and may
        // renumber vertices: name the file's own line instead.
        if (ext == "obj" && e.message().find("non-finite coordinate") != std::string::npos)
            if (const std::string line = io::first_non_finite_obj_vertex(path); !line.empty())
                throw Error(line, where);
        throw;
    }
}

Mesh load_mesh_from_memory(const void* data, std::size_t size, const std::string& extension_hint,
                           ImportReport* report, const ImportLimits& limits) {
    std::string ext = extension_hint;
    if (!ext.empty() && ext[0] == '.')
        ext.erase(0, 1);
    for (char& c : ext)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    // No base folder: external buffers cannot be resolved from memory.
    return load_impl(data, size, ext, std::string(), "memory." + ext, report, limits);
}

void save_mesh(const std::filesystem::path& path, const Mesh& mesh, const ExportOptions& options) {
    const std::string where = path.string();
    validate_mesh(mesh, "mesh to write to " + where);
    for (const auto& a : mesh.attributes)
        if (!io::is_valid_attribute_name(a.name))
            throw Error(fmt::format("invalid attribute name '{}'", a.name), where);
    const std::string ext = lower_ext(path);
    if (ext == "glb")
        write_file_atomic(path, [&](const std::filesystem::path& tmp) { io::write_glb(tmp, mesh); });
    else if (ext == "ply")
        write_file_atomic(path, [&](const std::filesystem::path& tmp) { io::write_ply(tmp, mesh, options.ply_encoding); });
    else
        throw Error(fmt::format("cannot write '.{}' meshes; use .glb or .ply", ext), where);
}

std::string gltf_attribute_name(std::string_view name) {
    std::string s = "_";
    for (char c : name)
        s += char(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

} // namespace skybake
