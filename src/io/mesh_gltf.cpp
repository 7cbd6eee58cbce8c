// glTF 2.0 import and export through tinygltf.
// Khronos Group, "glTF 2.0 Specification", 2017-2021.
//
// glTF goes through tinygltf rather than Assimp because Assimp drops
// application-specific vertex attributes ("_AO"), which skybake writes and
// must read back bit-exactly. Every accessor is bounds-checked here before it
// is read; tinygltf's own checks are not relied upon.
#include <cmath>
#include <cstring>
#include <cctype>
#include <fstream>
#include <functional>
#include <map>
#include <string_view>

#include <fmt/format.h>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
// tinygltf is compiled here from Debian's header rather than linked from its
// libtinygltf.so: that library was built from a header revision whose class
// layout differs from the installed tiny_gltf.h (TinyGLTF::SetFsCallbacks
// writes past the members this header declares). Images are never decoded,
// so stb is left out.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "io/mesh_internal.h"
#include "skybake/error.h"
#include "io/texture_path.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"

namespace skybake::io {

namespace {

constexpr unsigned kMaxNodeDepth = 256;
constexpr std::size_t kMaxUvSets = 8;

struct FsContext {
    std::string base_dir; // empty: no external files (loading from memory)
    std::uint64_t max_bytes;
};

bool fs_exists(const std::string& path, void* user) {
    auto* ctx = static_cast<FsContext*>(user);
    if (ctx->base_dir.empty())
        return false;
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

std::string fs_expand(const std::string& path, void*) { return path; } // no shell expansion

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    auto* ctx = static_cast<FsContext*>(user);
    namespace fs = std::filesystem;
    if (ctx->base_dir.empty()) {
        *err = "external file '" + path + "' cannot be resolved when loading from memory";
        return false;
    }
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec || size > ctx->max_bytes) {
        *err = ec ? "cannot read '" + path + "'" : "'" + path + "' is over the size limit";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    out->resize(size);
    in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size));
    if (!in) {
        *err = "cannot read '" + path + "'";
        return false;
    }
    return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    *err = "writing is not supported here";
    return false;
}

// Images are not needed for lighting; skip decoding them.
// Images are not decoded here; the bytes of an embedded one (a bufferView or
// a data URI) are kept, by image index, for the material that uses it.
struct EmbeddedImages {
    std::map<int, std::vector<unsigned char>> bytes;
};

bool keep_embedded_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                         const unsigned char* data, int size, void* user) {
    if (user && data && size > 0 && (image->bufferView >= 0 || image->uri.rfind("data:", 0) == 0))
        static_cast<EmbeddedImages*>(user)->bytes[index].assign(data, data + size);
    return true;
}

struct AccessorView {
    const unsigned char* data = nullptr;
    std::size_t count = 0, stride = 0;
    int component_type = 0, components = 0;
    bool normalized = false;
};

int components_of(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
    }
}

std::size_t component_bytes(int ct) {
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

class Reader {
public:
    Reader(const tinygltf::Model& model, const std::string& where, const ImportLimits& limits)
        : model_(model), where_(where), limits_(limits) {}

    AccessorView view(int index, const char* what) const {
        if (index < 0 || std::size_t(index) >= model_.accessors.size())
            fail(fmt::format("{} refers to accessor {}, but there are {}", what, index, model_.accessors.size()));
        const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
        if (a.sparse.isSparse)
            fail(fmt::format("accessor {} ({}) is sparse; sparse accessors are not supported", index, what));
        AccessorView v;
        v.count = a.count;
        v.component_type = a.componentType;
        v.components = components_of(a.type);
        v.normalized = a.normalized;
        const std::size_t cb = component_bytes(a.componentType);
        if (v.components == 0 || cb == 0)
            fail(fmt::format("accessor {} ({}) has an unsupported type", index, what));
        const std::size_t elem = cb * std::size_t(v.components);
        if (a.bufferView < 0 || std::size_t(a.bufferView) >= model_.bufferViews.size())
            fail(fmt::format("accessor {} ({}) has no valid bufferView", index, what));
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(a.bufferView)];
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size())
            fail(fmt::format("bufferView {} refers to missing buffer {}", a.bufferView, bv.buffer));
        const tinygltf::Buffer& buf = model_.buffers[std::size_t(bv.buffer)];
        v.stride = bv.byteStride ? bv.byteStride : elem;
        if (v.stride < elem)
            fail(fmt::format("bufferView {} has byteStride {} smaller than its element ({} bytes)", a.bufferView,
                             v.stride, elem));
        // Overflow-safe: every quantity is checked against the buffer size first.
        const std::uint64_t buf_size = buf.data.size();
        if (bv.byteOffset > buf_size || bv.byteLength > buf_size - bv.byteOffset)
            fail(fmt::format("bufferView {} (offset {}, length {}) runs past its buffer of {} bytes", a.bufferView,
                             bv.byteOffset, bv.byteLength, buf_size));
        if (v.count == 0)
            return v;
        if (v.count > (std::uint64_t(1) << 40) / v.stride)
            fail(fmt::format("accessor {} ({}) declares an absurd count {}", index, what, v.count));
        const std::uint64_t need = std::uint64_t(a.byteOffset) + (v.count - 1) * v.stride + elem;
        if (a.byteOffset > bv.byteLength || need > bv.byteLength)
            fail(fmt::format("accessor {} ({}) needs {} bytes but its bufferView has {}", index, what, need,
                             bv.byteLength));
        v.data = buf.data.data() + bv.byteOffset + a.byteOffset;
        return v;
    }

    // Reads component c of element i as float, normalising integers when asked.
    static float read(const AccessorView& v, std::size_t i, int c) {
        const unsigned char* p = v.data + i * v.stride + std::size_t(c) * component_bytes(v.component_type);
        switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p, 4);
            return f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return v.normalized ? float(*p) / 255.0f : float(*p);
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const float f = float(std::int8_t(*p));
            return v.normalized ? std::max(f / 127.0f, -1.0f) : f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t u;
            std::memcpy(&u, p, 2);
            return v.normalized ? float(u) / 65535.0f : float(u);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t s;
            std::memcpy(&s, p, 2);
            return v.normalized ? std::max(float(s) / 32767.0f, -1.0f) : float(s);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            std::uint32_t u;
            std::memcpy(&u, p, 4);
            return float(u);
        }
        }
        return 0.0f;
    }

    static std::uint32_t read_index(const AccessorView& v, std::size_t i) {
        const unsigned char* p = v.data + i * v.stride;
        switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t u;
            std::memcpy(&u, p, 2);
            return u;
        }
        default: {
            std::uint32_t u;
            std::memcpy(&u, p, 4);
            return u;
        }
        }
    }

    [[noreturn]] void fail(const std::string& msg) const { throw Error(msg, where_); }

    void visit(int node_index, const glm::dmat4& parent, unsigned depth) {
        if (depth > kMaxNodeDepth)
            fail(fmt::format("node hierarchy deeper than {} levels (a cycle?)", kMaxNodeDepth));
        if (node_index < 0 || std::size_t(node_index) >= model_.nodes.size())
            fail(fmt::format("reference to node {}, but there are {}", node_index, model_.nodes.size()));
        const tinygltf::Node& node = model_.nodes[std::size_t(node_index)];
        glm::dmat4 local(1.0);
        if (node.matrix.size() == 16) {
            local = glm::make_mat4(node.matrix.data()); // column-major, as glTF
        } else {
            glm::dmat4 t(1.0), r(1.0), s(1.0);
            if (node.translation.size() == 3)
                t = glm::translate(glm::dmat4(1.0), glm::make_vec3(node.translation.data()));
            if (node.rotation.size() == 4)
                r = glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
            if (node.scale.size() == 3)
                s = glm::scale(glm::dmat4(1.0), glm::make_vec3(node.scale.data()));
            local = t * r * s;
        }
        const glm::dmat4 world = parent * local;
        if (node.mesh >= 0) {
            if (std::size_t(node.mesh) >= model_.meshes.size())
                fail(fmt::format("node {} refers to mesh {}, but there are {}", node_index, node.mesh,
                                 model_.meshes.size()));
            append_mesh(model_.meshes[std::size_t(node.mesh)], world, node_index, node.mesh);
        }
        for (int child : node.children)
            visit(child, world, depth + 1);
    }

    void append_mesh(const tinygltf::Mesh& m, const glm::dmat4& world, int node_index, int mesh_index) {
        const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(world));
        // A mirroring transform turns the winding over (glTF 2.0, section 3.7.4).
        const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
        for (std::size_t prim_index = 0; prim_index < m.primitives.size(); ++prim_index) {
            const tinygltf::Primitive& prim = m.primitives[prim_index];
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) {
                ++out.report.non_triangles;
                continue;
            }
            auto pos_it = prim.attributes.find("POSITION");
            if (pos_it == prim.attributes.end())
                fail("a triangle primitive has no POSITION attribute");
            const AccessorView pos = view(pos_it->second, "POSITION");
            if (pos.components != 3 || pos.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
                fail("POSITION must be a float VEC3 accessor");
            Mesh& mesh = out.mesh;
            const std::size_t base = mesh.positions.size();
            check_counts(base + pos.count, mesh.triangle_count(), limits_, where_);
            ++out.report.source_meshes;
            instances.push_back({node_index, mesh_index, int(prim_index), base, pos.count, glm::dmat3(world)});
            const std::size_t first_index = mesh.indices.size();

            for (std::size_t i = 0; i < pos.count; ++i) {
                const glm::dvec4 p = world * glm::dvec4(read(pos, i, 0), read(pos, i, 1), read(pos, i, 2), 1.0);
                mesh.positions.emplace_back(p);
            }
            // Normals
            auto n_it = prim.attributes.find("NORMAL");
            if (n_it != prim.attributes.end()) {
                const AccessorView n = view(n_it->second, "NORMAL");
                if (n.count != pos.count || n.components != 3)
                    fail("NORMAL must be a VEC3 accessor with one entry per vertex");
                for (std::size_t i = 0; i < n.count; ++i)
                    mesh.normals.emplace_back(normal_matrix * glm::dvec3(read(n, i, 0), read(n, i, 1), read(n, i, 2)));
            } else {
                missing_normals = true;
                mesh.normals.resize(mesh.positions.size(), glm::vec3(0.0f));
            }
            // Colours
            auto c_it = prim.attributes.find("COLOR_0");
            if (c_it != prim.attributes.end()) {
                const AccessorView c = view(c_it->second, "COLOR_0");
                if (c.count != pos.count || (c.components != 3 && c.components != 4))
                    fail("COLOR_0 must be a VEC3 or VEC4 accessor with one entry per vertex");
                mesh.colors.resize(base, glm::vec4(1.0f));
                for (std::size_t i = 0; i < c.count; ++i)
                    mesh.colors.emplace_back(read(c, i, 0), read(c, i, 1), read(c, i, 2),
                                             c.components == 4 ? read(c, i, 3) : 1.0f);
                any_colors = true;
            } else {
                mesh.colors.resize(mesh.positions.size(), glm::vec4(1.0f));
            }
            // UV sets
            for (std::size_t k = 0; k < kMaxUvSets; ++k) {
                auto uv_it = prim.attributes.find("TEXCOORD_" + std::to_string(k));
                if (uv_it == prim.attributes.end())
                    break;
                const AccessorView uv = view(uv_it->second, "TEXCOORD");
                if (uv.count != pos.count || uv.components != 2)
                    fail(fmt::format("TEXCOORD_{} must be a VEC2 accessor with one entry per vertex", k));
                if (mesh.texcoords.size() <= k)
                    mesh.texcoords.resize(k + 1);
                mesh.texcoords[k].resize(base, glm::vec2(0.0f));
                for (std::size_t i = 0; i < uv.count; ++i)
                    mesh.texcoords[k].emplace_back(read(uv, i, 0), read(uv, i, 1));
            }
            for (auto& uv : mesh.texcoords)
                uv.resize(mesh.positions.size(), glm::vec2(0.0f));
            // The node's part, with the primitive's material.
            const int material = prim.material >= 0 && std::size_t(prim.material) < model_.materials.size()
                                     ? material_index(prim.material)
                                     : -1;
            mesh.parts.push_back({model_.nodes[std::size_t(node_index)].name, material});
            part_of_primitive = std::uint32_t(mesh.parts.size() - 1);
            // Application-specific attributes: "_AO" -> "ao"
            for (const auto& [semantic, acc] : prim.attributes) {
                if (semantic.size() < 2 || semantic[0] != '_')
                    continue;
                std::string name;
                for (char ch : semantic.substr(1))
                    name += char(std::tolower(static_cast<unsigned char>(ch)));
                if (!is_valid_attribute_name(name))
                    continue;
                const AccessorView a = view(acc, semantic.c_str());
                if (a.count != pos.count)
                    fail(fmt::format("attribute {} has {} entries for {} vertices", semantic, a.count, pos.count));
                VertexAttribute* dst = nullptr;
                for (auto& existing : mesh.attributes)
                    if (existing.name == name)
                        dst = &existing;
                if (!dst) {
                    mesh.attributes.push_back({name, a.components, {}});
                    dst = &mesh.attributes.back();
                }
                if (dst->components != a.components)
                    fail(fmt::format("attribute {} changes component count between primitives", semantic));
                dst->values.resize(base * std::size_t(a.components), 0.0f);
                for (std::size_t i = 0; i < a.count; ++i)
                    for (int k = 0; k < a.components; ++k)
                        dst->values.push_back(read(a, i, k));
            }
            for (auto& attr : mesh.attributes)
                attr.values.resize(mesh.positions.size() * std::size_t(attr.components), 0.0f);
            // Indices
            if (prim.indices >= 0) {
                const AccessorView idx = view(prim.indices, "indices");
                if (idx.components != 1 || (idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                             idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                             idx.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
                    fail("indices must be an unsigned integer SCALAR accessor");
                if (idx.count % 3 != 0)
                    fail(fmt::format("triangle primitive has {} indices, not a multiple of 3", idx.count));
                for (std::size_t i = 0; i < idx.count; ++i) {
                    const std::uint32_t k = read_index(idx, i);
                    if (k >= pos.count)
                        fail(fmt::format("index {} is {}, but the primitive has {} vertices", i, k, pos.count));
                    mesh.indices.push_back(std::uint32_t(base + k));
                }
                check_counts(mesh.positions.size(), mesh.triangle_count(), limits_, where_);
            } else {
                if (pos.count % 3 != 0)
                    fail(fmt::format("non-indexed triangle primitive has {} vertices, not a multiple of 3", pos.count));
                for (std::size_t i = 0; i < pos.count; ++i)
                    mesh.indices.push_back(std::uint32_t(base + i));
            }
            if (mirrored)
                for (std::size_t t = first_index; t + 2 < mesh.indices.size(); t += 3)
                    std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
            mesh.triangle_parts.resize(mesh.indices.size() / 3, part_of_primitive);
        }
    }

    // The Mesh material for glTF material `m`, added on first use.
    int material_index(int m) {
        if (auto it = materials_.find(m); it != materials_.end())
            return it->second;
        const tinygltf::Material& gm = model_.materials[std::size_t(m)];
        MeshMaterial mm;
        mm.name = gm.name;
        const auto& f = gm.pbrMetallicRoughness.baseColorFactor;
        if (f.size() == 4)
            mm.base_color = glm::vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
        const int t = gm.pbrMetallicRoughness.baseColorTexture.index;
        if (t >= 0 && std::size_t(t) < model_.textures.size()) {
            const int i = model_.textures[std::size_t(t)].source;
            if (i >= 0 && std::size_t(i) < model_.images.size()) {
                const tinygltf::Image& image = model_.images[std::size_t(i)];
                const std::string& uri = image.uri;
                if (embedded_) {
                    if (auto it = embedded_->bytes.find(i); it != embedded_->bytes.end()) {
                        mm.base_color_image = it->second;
                        mm.base_color_image_type = image.mimeType;
                    }
                }
                if (mm.base_color_image.empty() && !uri.empty() && uri.rfind("data:", 0) != 0 && !base_dir_.empty()) {
                    const std::string decoded = io::percent_decode(uri);
                    mm.base_color_texture = (std::filesystem::path(base_dir_) / decoded).lexically_normal().string();
                }
            }
            mm.base_color_texcoord = gm.pbrMetallicRoughness.baseColorTexture.texCoord;
        }
        out.mesh.materials.push_back(std::move(mm));
        return materials_[m] = int(out.mesh.materials.size() - 1);
    }

    RawImport out;
    std::vector<GltfPrimitiveInstance> instances;
    std::uint32_t part_of_primitive = 0;
    bool missing_normals = false;
    bool any_colors = false;

    std::string base_dir_;
    const EmbeddedImages* embedded_ = nullptr;

private:
    std::map<int, int> materials_;
    const tinygltf::Model& model_;
    const std::string& where_;
    const ImportLimits& limits_;
};

} // namespace

RawImport read_gltf(const void* data, std::size_t size, bool binary, const std::string& base_dir,
                    const std::string& where, const ImportLimits& limits, GltfSceneMap* scene) {
    tinygltf::TinyGLTF loader;
    FsContext fs_ctx{base_dir, limits.max_file_bytes};
    loader.SetFsCallbacks({fs_exists, fs_expand, fs_read, fs_write, &fs_ctx});
    EmbeddedImages embedded;
    loader.SetImageLoader(keep_embedded_image, &embedded);
    tinygltf::Model model;
    std::string err, warn;
    const auto* bytes = static_cast<const unsigned char*>(data);
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes, unsigned(size), base_dir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, static_cast<const char*>(data), unsigned(size),
                                                 base_dir);
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) { // JSON type errors in malformed files
        throw Error(fmt::format("malformed glTF: {}", e.what()), where);
    }
    if (!ok) {
        std::string first = err.substr(0, err.find('\n'));
        if (first.empty())
            first = "unknown reason";
        throw Error(fmt::format("cannot read glTF: {}", first), where);
    }

    Reader reader(model, where, limits);
    reader.base_dir_ = base_dir;
    reader.embedded_ = &embedded;
    reader.out.report.format = binary ? "glb" : "gltf";
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        const std::size_t s = model.defaultScene >= 0 && std::size_t(model.defaultScene) < model.scenes.size()
                                  ? std::size_t(model.defaultScene)
                                  : 0;
        roots = model.scenes[s].nodes;
    } else {
        // No scene: every node that is nobody's child is a root.
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && std::size_t(c) < is_child.size())
                    is_child[std::size_t(c)] = true;
        for (std::size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i])
                roots.push_back(int(i));
    }
    for (int r : roots)
        reader.visit(r, glm::dmat4(1.0), 0);
    if (reader.missing_normals)
        reader.out.mesh.normals.clear();
    if (!reader.any_colors)
        reader.out.mesh.colors.clear();
    if (scene) {
        scene->instances = std::move(reader.instances);
        scene->buffers.clear();
        for (auto& b : model.buffers)
            scene->buffers.push_back(std::move(b.data));
    }
    return std::move(reader.out);
}

// --- export ------------------------------------------------------------------------------

namespace {

template <class T>
int add_view(tinygltf::Model& model, const T* data, std::size_t bytes, int target) {
    auto& buf = model.buffers[0].data;
    while (buf.size() % 4)
        buf.push_back(0);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf.size();
    bv.byteLength = bytes;
    bv.target = target;
    const auto* p = reinterpret_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    model.bufferViews.push_back(bv);
    return int(model.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model& model, int view, int component_type, int type, std::size_t count) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component_type;
    a.type = type;
    a.count = count;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
}

int vec_type(int components) {
    switch (components) {
    case 1: return TINYGLTF_TYPE_SCALAR;
    case 2: return TINYGLTF_TYPE_VEC2;
    case 3: return TINYGLTF_TYPE_VEC3;
    default: return TINYGLTF_TYPE_VEC4;
    }
}

} // namespace

// A URI for `image` as seen from `folder`: relative when it can be, with
// spaces percent-encoded.
std::string image_uri(const std::string& image, const std::filesystem::path& folder) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path rel = fs::absolute(fs::path(image), ec).lexically_normal();
    const fs::path base = fs::absolute(folder.empty() ? fs::path(".") : folder, ec).lexically_normal();
    if (const fs::path r = rel.lexically_relative(base); !r.empty())
        rel = r;
    std::string uri;
    for (char c : rel.generic_string())
        uri += c == ' ' ? std::string("%20") : std::string(1, c);
    return uri;
}

void write_glb(const std::filesystem::path& tmp, const Mesh& mesh) {
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "skybake";
    model.buffers.resize(1);

    // Materials. A base colour image is embedded (the material's own bytes,
    // or its file when that is a PNG or JPEG), so that the .glb travels whole;
    // other images (the occlusion image a bake writes beside the output, a
    // TGA) are referenced from the output's folder. One image and texture per
    // file or embedded image, however many materials use it.
    std::map<std::string, int> texture_of;
    const auto new_texture = [&](tinygltf::Image image) {
        model.images.push_back(std::move(image));
        tinygltf::Texture texture;
        texture.source = int(model.images.size() - 1);
        model.textures.push_back(texture);
        return int(model.textures.size() - 1);
    };
    const auto referenced = [&](const std::string& file) {
        const std::string uri = image_uri(file, tmp.parent_path());
        if (auto it = texture_of.find("uri:" + uri); it != texture_of.end())
            return it->second;
        tinygltf::Image image;
        image.uri = uri;
        return texture_of["uri:" + uri] = new_texture(std::move(image));
    };
    const auto embedded = [&](const std::vector<unsigned char>& bytes, const std::string& mime) {
        const std::string key =
            fmt::format("bytes:{}:{}:{}", mime, bytes.size(),
                        std::hash<std::string_view>{}(std::string_view(reinterpret_cast<const char*>(bytes.data()),
                                                                       bytes.size())));
        if (auto it = texture_of.find(key); it != texture_of.end())
            return it->second;
        tinygltf::Image image;
        image.mimeType = mime;
        image.bufferView = add_view(model, bytes.data(), bytes.size(), 0);
        return texture_of[key] = new_texture(std::move(image));
    };
    const auto base_color = [&](const MeshMaterial& m) {
        if (!m.base_color_image.empty() && (m.base_color_image_type == "image/png" ||
                                            m.base_color_image_type == "image/jpeg"))
            return embedded(m.base_color_image, m.base_color_image_type);
        std::string ext = std::filesystem::path(m.base_color_texture).extension().string();
        for (char& c : ext)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        std::error_code ec;
        if ((ext == ".png" || ext == ".jpg" || ext == ".jpeg") &&
            std::filesystem::is_regular_file(m.base_color_texture, ec)) {
            // Materials sharing a file: read it once.
            if (auto it = texture_of.find("file:" + m.base_color_texture); it != texture_of.end())
                return it->second;
            const std::string data = read_file(m.base_color_texture);
            return texture_of["file:" + m.base_color_texture] = embedded(
                       std::vector<unsigned char>(data.begin(), data.end()), ext == ".png" ? "image/png" : "image/jpeg");
        }
        return referenced(m.base_color_texture);
    };
    for (const MeshMaterial& m : mesh.materials) {
        tinygltf::Material gm;
        gm.name = m.name;
        gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a};
        if (!m.base_color_texture.empty() || !m.base_color_image.empty()) {
            gm.pbrMetallicRoughness.baseColorTexture.index = base_color(m);
            gm.pbrMetallicRoughness.baseColorTexture.texCoord = m.base_color_texcoord;
        }
        if (!m.occlusion_texture.empty()) {
            gm.occlusionTexture.index = m.occlusion_image.empty() ? referenced(m.occlusion_texture)
                                                                  : embedded(m.occlusion_image, "image/png");
            gm.occlusionTexture.texCoord = m.occlusion_texcoord;
        }
        model.materials.push_back(gm);
    }

    // One glTF mesh and node per part; a mesh without parts is one part.
    const std::size_t groups = mesh.triangle_parts.empty() ? 1 : mesh.parts.size();
    std::vector<std::vector<std::uint32_t>> group_triangles(groups);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
        group_triangles[mesh.triangle_parts.empty() ? 0 : mesh.triangle_parts[t]].push_back(std::uint32_t(t));

    Mesh copy_for_normals;
    const std::vector<glm::vec3>* all_normals = &mesh.normals;
    if (all_normals->empty()) {
        copy_for_normals.positions = mesh.positions;
        copy_for_normals.indices = mesh.indices;
        compute_normals(copy_for_normals);
        all_normals = &copy_for_normals.normals;
    }
    tinygltf::Scene scene;
    for (std::size_t g = 0; g < groups; ++g) {
        if (groups > 1 && group_triangles[g].empty())
            continue;
        // The group's vertices, in the mesh's order; all of them for a mesh of one part.
        std::vector<std::uint32_t> used;
        std::vector<std::uint32_t> local(mesh.vertex_count(), 0);
        if (groups == 1) {
            used.resize(mesh.vertex_count());
            for (std::size_t v = 0; v < used.size(); ++v)
                used[v] = local[v] = std::uint32_t(v);
        } else {
            std::vector<bool> in(mesh.vertex_count(), false);
            for (std::uint32_t t : group_triangles[g])
                for (int k = 0; k < 3; ++k)
                    in[mesh.indices[3 * t + std::size_t(k)]] = true;
            for (std::size_t v = 0; v < in.size(); ++v)
                if (in[v]) {
                    local[v] = std::uint32_t(used.size());
                    used.push_back(std::uint32_t(v));
                }
        }
        auto gather = [&](const auto& src) {
            std::vector<std::decay_t<decltype(src[0])>> out;
            out.reserve(used.size());
            for (std::uint32_t v : used)
                out.push_back(src[v]);
            return out;
        };
        tinygltf::Primitive prim;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        const std::size_t n = used.size();

        const std::vector<glm::vec3> positions = gather(mesh.positions);
        const int pv = add_view(model, positions.data(), n * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
        const int pa = add_accessor(model, pv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
        glm::vec3 lo = positions[0], hi = positions[0]; // POSITION requires min and max
        for (const glm::vec3& p : positions)
            lo = glm::min(lo, p), hi = glm::max(hi, p);
        model.accessors[std::size_t(pa)].minValues = {lo.x, lo.y, lo.z};
        model.accessors[std::size_t(pa)].maxValues = {hi.x, hi.y, hi.z};
        prim.attributes["POSITION"] = pa;

        const std::vector<glm::vec3> normals = gather(*all_normals);
        const int nv = add_view(model, normals.data(), n * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
        prim.attributes["NORMAL"] = add_accessor(model, nv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);

        if (!mesh.colors.empty()) {
            const std::vector<glm::vec4> colors = gather(mesh.colors);
            const int cv = add_view(model, colors.data(), n * sizeof(glm::vec4), TINYGLTF_TARGET_ARRAY_BUFFER);
            prim.attributes["COLOR_0"] = add_accessor(model, cv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, n);
        }
        for (std::size_t k = 0; k < mesh.texcoords.size(); ++k) {
            const std::vector<glm::vec2> uv = gather(mesh.texcoords[k]);
            const int tv = add_view(model, uv.data(), n * sizeof(glm::vec2), TINYGLTF_TARGET_ARRAY_BUFFER);
            prim.attributes["TEXCOORD_" + std::to_string(k)] =
                add_accessor(model, tv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n);
        }
        for (const auto& a : mesh.attributes) {
            std::vector<float> values;
            values.reserve(n * std::size_t(a.components));
            for (std::uint32_t v : used)
                for (int c = 0; c < a.components; ++c)
                    values.push_back(a.values[std::size_t(v) * std::size_t(a.components) + std::size_t(c)]);
            const int av = add_view(model, values.data(), values.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
            prim.attributes[gltf_attribute_name(a.name)] =
                add_accessor(model, av, TINYGLTF_COMPONENT_TYPE_FLOAT, vec_type(a.components), n);
        }
        std::vector<std::uint32_t> indices;
        if (groups == 1 && mesh.triangle_parts.empty()) {
            indices = mesh.indices;
        } else {
            for (std::uint32_t t : group_triangles[g])
                for (int k = 0; k < 3; ++k)
                    indices.push_back(local[mesh.indices[3 * t + std::size_t(k)]]);
        }
        const int iv = add_view(model, indices.data(), indices.size() * sizeof(std::uint32_t),
                                TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        prim.indices =
            add_accessor(model, iv, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());

        tinygltf::Mesh gm;
        tinygltf::Node node;
        if (!mesh.triangle_parts.empty()) {
            prim.material = mesh.parts[g].material;
            gm.name = node.name = mesh.parts[g].name;
        }
        gm.primitives.push_back(prim);
        model.meshes.push_back(gm);
        node.mesh = int(model.meshes.size() - 1);
        model.nodes.push_back(node);
        scene.nodes.push_back(int(model.nodes.size() - 1));
    }
    model.scenes.push_back(scene);
    model.defaultScene = 0;

    std::ofstream out(tmp, std::ios::binary);
    if (!out)
        throw Error("cannot create file", tmp.string());
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, false, true) || !out.flush())
        throw Error("cannot write glTF binary", tmp.string());
}

} // namespace skybake::io

namespace skybake {

std::string base64_encode(std::string_view bytes) {
    return tinygltf::base64_encode(reinterpret_cast<const unsigned char*>(bytes.data()),
                                   static_cast<unsigned int>(bytes.size()));
}

} // namespace skybake
