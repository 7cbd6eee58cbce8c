// Mesh import through Assimp, for every format except glTF and PLY.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "io/mesh_internal.h"
#include "io/texture_path.h"
#include "skybake/error.h"

namespace skybake::io {

namespace {

constexpr unsigned kMaxNodeDepth = 256;

struct Flattener {
    const aiScene* scene;
    const ImportLimits& limits;
    const std::string& where;
    RawImport out;
    bool any_missing_normals = false;
    bool any_colors = false;
    std::filesystem::path source_dir{}; // image paths are relative to it
    std::map<unsigned, int> materials{};

    void visit(const aiNode* node, const aiMatrix4x4& parent, unsigned depth) {
        if (depth > kMaxNodeDepth)
            throw Error(fmt::format("scene graph is deeper than {} levels", kMaxNodeDepth), where);
        const aiMatrix4x4 world = parent * node->mTransformation;
        for (unsigned i = 0; i < node->mNumMeshes; ++i) {
            if (node->mMeshes[i] >= scene->mNumMeshes)
                throw Error(fmt::format("node '{}' references mesh {} of {}", node->mName.C_Str(), node->mMeshes[i],
                                        scene->mNumMeshes),
                            where);
            append(scene->mMeshes[node->mMeshes[i]], world, node->mName.C_Str());
        }
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            visit(node->mChildren[c], world, depth + 1);
    }

    // The Mesh material for Assimp's material `index`, added on first use:
    // the base colour (or diffuse) factor and image path.
    int material(unsigned index) {
        if (index >= scene->mNumMaterials)
            return -1;
        if (auto it = materials.find(index); it != materials.end())
            return it->second;
        const aiMaterial* am = scene->mMaterials[index];
        MeshMaterial mm;
        aiString name;
        if (am->Get(AI_MATKEY_NAME, name) == AI_SUCCESS)
            mm.name = name.C_Str();
        aiColor4D c;
        if (am->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || am->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
            mm.base_color = glm::vec4(c.r, c.g, c.b, c.a);
        for (aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
            aiString path;
            unsigned uv = 0;
            if (am->GetTexture(type, 0, &path, nullptr, &uv) != AI_SUCCESS || path.length == 0)
                continue;
            // "*0": embedded in the file, not carried. A path written on another
            // machine is looked for beside the model (io/texture_path.h); one
            // that is nowhere is reported, and the material keeps its colour.
            if (path.C_Str()[0] != '*') {
                if (const auto found = find_texture(path.C_Str(), source_dir))
                    mm.base_color_texture = found->string();
                else if (std::find(out.report.missing_textures.begin(), out.report.missing_textures.end(),
                                   path.C_Str()) == out.report.missing_textures.end())
                    out.report.missing_textures.push_back(path.C_Str()); // once per file
            }
            mm.base_color_texcoord = int(uv);
            break;
        }
        out.mesh.materials.push_back(std::move(mm));
        return materials[index] = int(out.mesh.materials.size() - 1);
    }

    void append(const aiMesh* m, const aiMatrix4x4& world, const std::string& node_name) {
        Mesh& mesh = out.mesh;
        const std::size_t base = mesh.positions.size();
        mesh.parts.push_back({node_name, material(m->mMaterialIndex)});
        const auto part = std::uint32_t(mesh.parts.size() - 1);
        // UV sets, with v flipped to glTF's convention (Assimp's grows upwards).
        for (unsigned k = 0; k < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++k) {
            if (!m->mTextureCoords[k])
                continue;
            if (mesh.texcoords.size() <= k)
                mesh.texcoords.resize(k + 1);
            auto& uv = mesh.texcoords[k];
            uv.resize(base, glm::vec2(0.0f));
            for (unsigned v = 0; v < m->mNumVertices; ++v)
                uv.emplace_back(m->mTextureCoords[k][v].x, 1.0f - m->mTextureCoords[k][v].y);
        }
        for (auto& uv : mesh.texcoords)
            uv.resize(base + m->mNumVertices, glm::vec2(0.0f));
        check_counts(base + m->mNumVertices, mesh.triangle_count() + m->mNumFaces, limits, where);
        ++out.report.source_meshes;
        aiMatrix3x3 normal_matrix(world);
        normal_matrix.Inverse().Transpose();
        for (unsigned v = 0; v < m->mNumVertices; ++v) {
            const aiVector3D p = world * m->mVertices[v];
            mesh.positions.emplace_back(p.x, p.y, p.z);
            if (m->mNormals) {
                const aiVector3D n = normal_matrix * m->mNormals[v];
                mesh.normals.emplace_back(n.x, n.y, n.z);
            } else {
                mesh.normals.emplace_back(0.0f);
            }
            if (m->mColors[0]) {
                const aiColor4D& c = m->mColors[0][v];
                mesh.colors.emplace_back(c.r, c.g, c.b, c.a);
            } else {
                mesh.colors.emplace_back(1.0f);
            }
        }
        any_missing_normals |= m->mNormals == nullptr;
        any_colors |= m->mColors[0] != nullptr;
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            const aiFace& face = m->mFaces[f];
            if (face.mNumIndices != 3) {
                ++out.report.non_triangles;
                continue;
            }
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= m->mNumVertices)
                    throw Error(fmt::format("face {} uses vertex index {}, but its mesh has {} vertices", f,
                                            face.mIndices[k], m->mNumVertices),
                                where);
                mesh.indices.push_back(std::uint32_t(base + face.mIndices[k]));
            }
            mesh.triangle_parts.push_back(part);
        }
    }
};

} // namespace

std::string first_non_finite_obj_vertex(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::string line;
    std::size_t number = 0, vertex = 0;
    while (std::getline(in, line)) {
        ++number;
        if (line.size() < 2 || line[0] != 'v' || !std::isspace(static_cast<unsigned char>(line[1])))
            continue;
        ++vertex;
        std::istringstream fields(line.substr(2));
        std::string token;
        for (int k = 0; k < 3 && fields >> token; ++k) {
            const double x = std::strtod(token.c_str(), nullptr);
            if (!std::isfinite(x)) {
                if (line.size() > 80)
                    line = line.substr(0, 80) + "...";
                return fmt::format("line {}: vertex {} has a non-finite coordinate '{}' ({})", number, vertex, token,
                                   line);
            }
        }
    }
    return {};
}

void precheck_for_assimp(const std::string& ext, const void* data, std::size_t size, const std::string& where,
                         const ImportLimits& limits) {
    // OFF: "OFF\n V F E". Assimp trusts F and can spend minutes or all memory
    // on a file that declares billions of faces; every face needs at least
    // two characters, every vertex six.
    if (ext != "off")
        return;
    std::string_view text(static_cast<const char*>(data), std::min<std::size_t>(size, 4096));
    std::size_t pos = 0;
    auto token = [&]() -> std::string_view {
        for (;;) {
            while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos])))
                ++pos;
            if (pos < text.size() && text[pos] == '#') { // comment to end of line
                while (pos < text.size() && text[pos] != '\n')
                    ++pos;
                continue;
            }
            break;
        }
        const std::size_t start = pos;
        while (pos < text.size() && !std::isspace(static_cast<unsigned char>(text[pos])))
            ++pos;
        return text.substr(start, pos - start);
    };
    // Assimp accepts any first token that contains "OFF" (COFF, NOFF, OFF007, ...).
    const std::string_view magic = token();
    if (magic.find("OFF") == std::string_view::npos)
        return; // not OFF: let Assimp explain
    std::uint64_t counts[2] = {0, 0};
    for (auto& c : counts) {
        const std::string_view t = token();
        const auto r = std::from_chars(t.data(), t.data() + t.size(), c);
        if (r.ec != std::errc() || r.ptr != t.data() + t.size())
            throw Error(fmt::format("bad OFF header: expected a count, found '{}'", t), where);
    }
    if (counts[0] > size / 6 || counts[1] > size / 2)
        throw Error(fmt::format("OFF header declares {} vertices and {} faces, more than a {}-byte file can hold",
                                counts[0], counts[1], size),
                    where);
    check_counts(counts[0], counts[1], limits, where);
}

namespace {

RawImport read_assimp_here(const void* data, std::size_t size, const std::string& extension_hint,
                           const std::string& where, const ImportLimits& limits, const std::filesystem::path* path) {
    Assimp::Importer importer;
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                           aiProcess_ValidateDataStructure;
    // From a path, Assimp can follow references to side files (materials, buffers).
    const aiScene* scene = path ? importer.ReadFile(path->string(), flags)
                                : importer.ReadFileFromMemory(data, size, flags, extension_hint.c_str());
    if (!scene) {
        std::string why = importer.GetErrorString();
        if (why.empty())
            why = "unknown reason";
        throw Error(fmt::format("cannot read mesh: {}", why), where);
    }
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
        throw Error("file has no complete geometry (Assimp marked the scene incomplete)", where);
    if (!scene->mRootNode || scene->mNumMeshes == 0)
        throw Error("file contains no meshes", where);

    Flattener flat{scene, limits, where, {}};
    if (path)
        flat.source_dir = path->has_parent_path() ? path->parent_path() : std::filesystem::path(".");
    flat.out.report.format = extension_hint;
    flat.visit(scene->mRootNode, aiMatrix4x4(), 0);
    if (flat.any_missing_normals)
        flat.out.mesh.normals.clear();
    if (!flat.any_colors)
        flat.out.mesh.colors.clear();
    return std::move(flat.out);
}

} // namespace

RawImport read_assimp(const void* data, std::size_t size, const std::string& extension_hint, const std::string& where,
                      const ImportLimits& limits, const std::filesystem::path* path) {
    // Assimp is not robust against hostile files: isolate it (see isolated_import.cpp).
    return run_isolated([&] { return read_assimp_here(data, size, extension_hint, where, limits, path); }, where,
                        limits);
}

} // namespace skybake::io
