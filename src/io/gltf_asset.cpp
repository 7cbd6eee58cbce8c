// A glTF 2.0 document kept whole, with baked attributes written back into it.
// Khronos Group, "glTF 2.0 Specification", 2017-2021 (section 3.7.2.1: custom
// attributes start with "_"; section 4.4: the GLB container).
//
// tinygltf reads the geometry (read_gltf(), with its bounds checks); the
// document itself is edited as JSON. A tinygltf model written back would
// drop members it does not know and spell defaults it does, so the output
// would differ from the input in more than the new attributes.
#include "skybake/gltf_asset.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <nlohmann/json.hpp>

#include "io/gltf_schema.h"
#include "io/mesh_internal.h"
#include "io/texture_path.h"
#include "skybake/error.h"
#include "skybake/files.h"

namespace skybake {

namespace {

using Json = nlohmann::ordered_json; // keeps the file's key order

constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A; // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;  // "BIN\0"
constexpr int kFloat = 5126;                     // GL_FLOAT
constexpr int kArrayBuffer = 34962;              // GL_ARRAY_BUFFER

std::string lower_ext(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    for (char& c : e)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

std::uint32_t read_u32(const std::string& data, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, data.data() + at, 4);
    return v;
}

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t b0 = bytes[i], b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0,
                            b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
        const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

// A relative URI of the input, as seen from the output's folder.
std::string relocate_uri(const std::string& uri, const std::filesystem::path& from_dir,
                         const std::filesystem::path& to_dir) {
    namespace fs = std::filesystem;
    if (uri.empty() || uri.rfind("data:", 0) == 0 || uri.find("://") != std::string::npos || uri[0] == '/')
        return uri;
    std::error_code ec;
    if (fs::equivalent(from_dir, to_dir, ec))
        return uri;
    const fs::path rel =
        fs::absolute(from_dir).lexically_normal().lexically_relative(fs::absolute(to_dir).lexically_normal());
    if (rel.empty() || rel == ".")
        return uri;
    std::string prefix;
    for (char c : rel.generic_string())
        prefix += c == ' ' ? std::string("%20") : std::string(1, c);
    return prefix + "/" + uri;
}

// The MIME type glTF names for an image file's extension; empty for another.
std::string image_mime_type(const std::string& uri) {
    std::string ext = std::filesystem::path(uri).extension().string();
    for (char& c : ext)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".png")
        return "image/png";
    if (ext == ".jpg" || ext == ".jpeg")
        return "image/jpeg";
    if (ext == ".webp")
        return "image/webp";
    if (ext == ".ktx2")
        return "image/ktx2";
    return {};
}

bool is_direction(const VertexAttribute& a) {
    const std::string_view suffix = "normal";
    return a.components == 3 && a.name.size() >= suffix.size() &&
           a.name.compare(a.name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const char* accessor_type(int components) {
    switch (components) {
    case 1: return "SCALAR";
    case 2: return "VEC2";
    case 3: return "VEC3";
    default: return "VEC4";
    }
}

} // namespace

std::string glb_json_chunk(const std::string& data, const std::string& where) {
    if (data.size() < 20 || read_u32(data, 0) != kGlbMagic)
        throw Error("not a GLB file (no 'glTF' magic)", where);
    const std::uint32_t length = read_u32(data, 12), type = read_u32(data, 16);
    if (type != kChunkJson || length > data.size() - 20)
        throw Error("GLB file has no complete JSON chunk", where);
    return data.substr(20, length);
}

struct GltfAsset::State {
    std::filesystem::path source_dir;
    Json document;
    std::vector<std::vector<unsigned char>> buffers;
    std::vector<io::GltfPrimitiveInstance> instances;
    std::vector<VertexAttribute> loaded_attributes; // to tell new and changed ones
    std::vector<glm::vec4> loaded_colors;
    Mesh mesh;
    ImportReport report;
    std::filesystem::path occlusion_image; // empty: none
    int occlusion_uv_set = 0;
    std::string occlusion_png; // the image's bytes, embedded by a .glb; empty: referenced by URI
    std::optional<ImageBasedLight> light;
};

void GltfAsset::set_image_based_light(ImageBasedLight light) {
    const int n = light.face_size;
    if (n < 1 || n > 8192 || (n & (n - 1)) != 0)
        throw Error(fmt::format("face_size {} is not a power of two from 1 to 8192", n), "light");
    for (const std::string& face : light.faces)
        if (face.size() < 8 || face.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0)
            throw Error("each of the six faces must be PNG bytes", "light");
    for (const glm::vec3& c : light.irradiance)
        if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z))
            throw Error("irradiance coefficients must be finite", "light");
    state_->light = std::move(light);
}

void GltfAsset::set_occlusion_texture(const std::filesystem::path& image, int uv_set, std::string png) {
    state_->occlusion_image = image;
    state_->occlusion_uv_set = uv_set;
    state_->occlusion_png = std::move(png);
}

GltfAsset::GltfAsset(std::unique_ptr<State> state) : state_(std::move(state)) {}
GltfAsset::GltfAsset(GltfAsset&&) noexcept = default;
GltfAsset& GltfAsset::operator=(GltfAsset&&) noexcept = default;
GltfAsset::~GltfAsset() = default;

Mesh& GltfAsset::mesh() {
    return state_->mesh;
}
const Mesh& GltfAsset::mesh() const {
    return state_->mesh;
}
const ImportReport& GltfAsset::report() const {
    return state_->report;
}
std::size_t GltfAsset::instance_count() const {
    return state_->instances.size();
}

std::size_t GltfAsset::shared_instance_count() const {
    std::map<int, int> first_node; // mesh -> the node that keeps it
    std::size_t shared = 0;
    for (const auto& inst : state_->instances) {
        const auto [it, inserted] = first_node.emplace(inst.mesh, inst.node);
        if (!inserted && it->second != inst.node)
            ++shared;
    }
    return shared;
}

bool GltfAsset::is_gltf2(const std::filesystem::path& path, const ImportLimits& limits) {
    const std::string ext = lower_ext(path);
    if (ext != ".gltf" && ext != ".glb")
        return false;
    const std::string data = read_file(path, limits.max_file_bytes);
    if (data.empty())
        throw Error("file is empty", path.string());
    return io::check_gltf(data.data(), data.size(), ext == ".glb", path.string()) == 2;
}

GltfAsset GltfAsset::load(const std::filesystem::path& path, const ImportLimits& limits) {
    const std::string where = path.string();
    const std::string ext = lower_ext(path);
    if (ext != ".gltf" && ext != ".glb")
        throw Error("not a glTF file; only .gltf and .glb documents can be baked in place", where);
    const bool binary = ext == ".glb";
    const std::string data = read_file(path, limits.max_file_bytes);
    if (data.empty())
        throw Error("file is empty", where);
    if (io::check_gltf(data.data(), data.size(), binary, where) != 2)
        throw Error("glTF 1.0 documents cannot be baked in place; their geometry is read as any other format", where);

    auto state = std::make_unique<State>();
    state->source_dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    io::GltfSceneMap map;
    io::RawImport raw =
        io::read_gltf(data.data(), data.size(), binary, state->source_dir.string(), where, limits, &map);
    state->mesh = io::finish_import(std::move(raw), where, limits, &state->report);
    state->instances = std::move(map.instances);
    state->buffers = std::move(map.buffers);
    state->loaded_attributes = state->mesh.attributes;
    state->loaded_colors = state->mesh.colors;
    try {
        state->document = Json::parse(binary ? glb_json_chunk(data, where) : data);
    } catch (const nlohmann::json::exception& e) {
        throw Error(fmt::format("malformed glTF JSON: {}", e.what()), where);
    }
    return GltfAsset(std::move(state));
}

void GltfAsset::save(const std::filesystem::path& path) const {
    const std::string where = path.string();
    const std::string ext = lower_ext(path);
    if (ext != ".glb" && ext != ".gltf")
        throw Error(fmt::format("cannot write a glTF document as '{}'; use .glb or .gltf", ext), where);
    const State& s = *state_;
    const Mesh& mesh = s.mesh;
    std::size_t loaded_vertices = 0;
    for (const auto& inst : s.instances)
        loaded_vertices = std::max(loaded_vertices, inst.first_vertex + inst.vertex_count);
    if (mesh.vertex_count() != loaded_vertices)
        throw Error(fmt::format("the mesh has {} vertices but the document's scene has {}; a GltfAsset's mesh "
                                "may gain attributes but not change its vertices",
                                mesh.vertex_count(), loaded_vertices),
                    where);
    validate_mesh(mesh, "mesh to write to " + where);

    // The attributes to write: new ones, and those a bake changed.
    std::vector<const VertexAttribute*> fresh;
    for (const auto& a : mesh.attributes) {
        const auto old = std::find_if(s.loaded_attributes.begin(), s.loaded_attributes.end(),
                                      [&](const VertexAttribute& b) { return b.name == a.name; });
        const bool same = old != s.loaded_attributes.end() && old->components == a.components &&
                          old->values.size() == a.values.size() &&
                          std::memcmp(old->values.data(), a.values.data(), a.values.size() * sizeof(float)) == 0;
        if (!same)
            fresh.push_back(&a);
    }

    // New colours (a bake's AO as grey) as a four-component attribute.
    VertexAttribute colors{"color", 4, {}};
    if (!mesh.colors.empty() &&
        (mesh.colors.size() != s.loaded_colors.size() ||
         std::memcmp(mesh.colors.data(), s.loaded_colors.data(), mesh.colors.size() * sizeof(glm::vec4)) != 0))
        for (const glm::vec4& c : mesh.colors)
            colors.values.insert(colors.values.end(), {c.r, c.g, c.b, c.a});

    Json doc = s.document;
    if (!doc.contains("buffers") || !doc["buffers"].is_array() || doc["buffers"].empty() || s.buffers.empty())
        throw Error("the document has no buffer to append to", where);
    std::vector<unsigned char> bin = s.buffers[0];
    bin.resize(doc["buffers"][0].value("byteLength", std::size_t(0)), 0); // a GLB chunk may carry padding
    // Every top-level member this function adds is added here, before any
    // reference into the document is taken: an ordered_json object keeps its
    // members in a vector, so a member added later would move the others and
    // leave those references dangling.
    const auto ensure_array = [&doc](const char* key) {
        if (!doc.contains(key) || !doc[key].is_array())
            doc[key] = Json::array();
    };
    ensure_array("bufferViews");
    ensure_array("accessors");
    if (!s.occlusion_image.empty()) {
        ensure_array("images");
        ensure_array("textures");
        ensure_array("materials");
    }
    if (s.light) {
        ensure_array("images");
        ensure_array("scenes");
        ensure_array("extensionsUsed");
        if (!doc.contains("extensions") || !doc["extensions"].is_object())
            doc["extensions"] = Json::object();
    }
    if (!doc.contains("asset") || !doc["asset"].is_object())
        doc["asset"] = Json::object();
    Json& views = doc["bufferViews"];
    Json& accessors = doc["accessors"];
    // Appends `bytes` to buffer 0 at a 4-byte boundary as a new bufferView
    // (with `target` where it is not 0); returns the view's index.
    const auto append_view = [&](const void* bytes, std::size_t size, int target) {
        while (bin.size() % 4)
            bin.push_back(0);
        const std::size_t offset = bin.size();
        bin.resize(offset + size);
        if (size)
            std::memcpy(bin.data() + offset, bytes, size);
        Json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
        if (target)
            view["target"] = target;
        views.push_back(view);
        return views.size() - 1;
    };
    Json& meshes = doc["meshes"];
    const Json original_meshes = meshes;

    std::map<int, int> first_node;      // mesh -> the node that keeps it
    std::map<int, int> target_mesh;     // node -> the mesh its attributes go to
    std::set<std::pair<int, int>> done; // (node, primitive) written
    std::vector<float> local;
    for (const auto& inst : s.instances) {
        if (!done.insert({inst.node, inst.primitive}).second)
            continue; // a node reached twice (an invalid hierarchy): its first visit counts
        if (!target_mesh.count(inst.node)) {
            const auto [it, inserted] = first_node.emplace(inst.mesh, inst.node);
            if (inserted || it->second == inst.node) {
                target_mesh[inst.node] = inst.mesh;
            } else {
                meshes.push_back(original_meshes[std::size_t(inst.mesh)]);
                target_mesh[inst.node] = int(meshes.size() - 1);
                doc["nodes"][std::size_t(inst.node)]["mesh"] = target_mesh[inst.node];
            }
        }
        Json& prim = meshes[std::size_t(target_mesh[inst.node])]["primitives"][std::size_t(inst.primitive)];
        const glm::dmat3 mesh_from_world_normal = glm::transpose(inst.world_from_mesh);
        const auto append = [&](const VertexAttribute* a, const std::string& key) {
            const std::size_t c = std::size_t(a->components);
            local.assign(a->values.begin() + std::ptrdiff_t(inst.first_vertex * c),
                         a->values.begin() + std::ptrdiff_t((inst.first_vertex + inst.vertex_count) * c));
            if (is_direction(*a))
                for (std::size_t v = 0; v < inst.vertex_count; ++v) {
                    glm::dvec3 d =
                        mesh_from_world_normal * glm::dvec3(local[3 * v], local[3 * v + 1], local[3 * v + 2]);
                    const double len = glm::length(d);
                    d = len > 0.0 ? d / len : d;
                    local[3 * v] = float(d.x), local[3 * v + 1] = float(d.y), local[3 * v + 2] = float(d.z);
                }
            const std::size_t view = append_view(local.data(), local.size() * sizeof(float), kArrayBuffer);
            accessors.push_back({{"bufferView", view},
                                 {"componentType", kFloat},
                                 {"count", inst.vertex_count},
                                 {"type", accessor_type(a->components)}});
            prim["attributes"][key] = accessors.size() - 1;
        };
        for (const VertexAttribute* a : fresh)
            append(a, gltf_attribute_name(a->name));
        // Baked colours (AO as grey, for viewers) only where the file has none.
        if (!colors.values.empty() && !prim["attributes"].contains("COLOR_0"))
            append(&colors, "COLOR_0");
    }

    // The input's images (before the AO image, whose URI is already written
    // from the output's folder). A .glb embeds each one whose file exists, so
    // that the file travels alone; otherwise the URI is rewritten to be seen
    // from the output's folder.
    const std::filesystem::path out_dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    if (doc.contains("images") && doc["images"].is_array())
        for (Json& image : doc["images"]) {
            if (!image.contains("uri") || !image["uri"].is_string())
                continue;
            const std::string uri = image["uri"].get<std::string>();
            const std::string mime = image_mime_type(uri);
            const bool local = !uri.empty() && uri.rfind("data:", 0) != 0 && uri.find("://") == std::string::npos;
            const std::filesystem::path file = s.source_dir / io::percent_decode(uri);
            std::error_code ec;
            if (ext == ".glb" && local && !mime.empty() && std::filesystem::is_regular_file(file, ec)) {
                const std::string bytes = read_file(file);
                image.erase("uri");
                image["bufferView"] = append_view(bytes.data(), bytes.size(), 0);
                image["mimeType"] = mime;
            } else {
                image["uri"] = relocate_uri(uri, s.source_dir, out_dir);
            }
        }

    if (!s.occlusion_image.empty()) {
        // One image and texture, referenced from every baked primitive's
        // material. A document baked before names the image already: the same
        // entries are used again, so that baking twice adds nothing.
        std::error_code ec;
        std::string uri;
        for (char c : std::filesystem::absolute(s.occlusion_image, ec)
                          .lexically_normal()
                          .lexically_relative(std::filesystem::absolute(out_dir, ec).lexically_normal())
                          .generic_string())
            uri += c == ' ' ? std::string("%20") : std::string(1, c);
        Json& images = doc["images"];
        Json& textures = doc["textures"];
        std::size_t image = images.size(), texture = textures.size();
        const bool embed = ext == ".glb" && !s.occlusion_png.empty();
        // An embedded image carries the file's name as its name.
        for (std::size_t i = 0; i < images.size() && image == images.size(); ++i)
            if (images[i].is_object() &&
                (images[i].value("uri", std::string()) == uri ||
                 (images[i].value("name", std::string()) == uri && images[i].contains("bufferView"))))
                image = i;
        if (image == images.size())
            images.push_back(Json::object());
        if (embed) {
            images[image] = {{"name", uri},
                             {"bufferView", append_view(s.occlusion_png.data(), s.occlusion_png.size(), 0)},
                             {"mimeType", "image/png"}};
        } else {
            images[image] = {{"uri", uri}};
        }
        for (std::size_t t = 0; t < textures.size() && texture == textures.size(); ++t)
            if (textures[t].is_object() && textures[t].contains("source") && textures[t]["source"] == image &&
                !textures[t].contains("extensions"))
                texture = t;
        if (texture == textures.size())
            textures.push_back({{"source", image}});
        const Json occlusion = {{"index", texture}, {"texCoord", s.occlusion_uv_set}};
        std::set<std::size_t> wired;
        int bare = -1; // the material for primitives without one
        for (const auto& [node, m] : target_mesh)
            for (Json& prim : meshes[std::size_t(m)]["primitives"]) {
                if (prim.value("mode", 4) != 4)
                    continue;
                if (!prim.contains("material")) {
                    if (bare < 0) {
                        doc["materials"].push_back({{"name", "skybake occlusion"}});
                        bare = int(doc["materials"].size() - 1);
                    }
                    prim["material"] = bare;
                }
                const std::size_t mat = prim["material"].get<std::size_t>();
                if (mat < doc["materials"].size() && wired.insert(mat).second)
                    doc["materials"][mat]["occlusionTexture"] = occlusion;
            }
    }

    if (s.light) {
        // EXT_lights_image_based: the light at the root, its faces as images
        // (one mip), and the default scene pointing at it.
        const ImageBasedLight& l = *s.light;
        Json faces = Json::array();
        for (const std::string& png : l.faces) {
            Json image = {{"mimeType", "image/png"}};
            if (ext == ".glb") {
                image["bufferView"] = append_view(png.data(), png.size(), 0);
            } else {
                image = {{"uri", "data:image/png;base64," + base64(std::vector<unsigned char>(png.begin(), png.end()))}};
            }
            doc["images"].push_back(image);
            faces.push_back(doc["images"].size() - 1);
        }
        Json irradiance = Json::array();
        for (const glm::vec3& c : l.irradiance)
            irradiance.push_back({c.x, c.y, c.z});
        Json& root = doc["extensions"]["EXT_lights_image_based"];
        if (!root.is_object())
            root = Json::object();
        if (!root.contains("lights") || !root["lights"].is_array())
            root["lights"] = Json::array();
        root["lights"].push_back({{"name", l.name},
                                  {"intensity", 1.0},
                                  {"rotation", {0.0, 0.0, 0.0, 1.0}},
                                  {"irradianceCoefficients", irradiance},
                                  {"specularImageSize", l.face_size},
                                  {"specularImages", Json::array({faces})}});
        const std::size_t light = root["lights"].size() - 1;
        Json& scenes = doc["scenes"];
        if (scenes.empty())
            scenes.push_back(Json::object());
        std::size_t scene = doc.contains("scene") && doc["scene"].is_number_unsigned() ? doc["scene"].get<std::size_t>() : 0;
        if (scene >= scenes.size())
            scene = 0;
        scenes[scene]["extensions"]["EXT_lights_image_based"] = {{"light", light}};
        Json& used = doc["extensionsUsed"];
        if (std::find(used.begin(), used.end(), "EXT_lights_image_based") == used.end())
            used.push_back("EXT_lights_image_based");
    }

    Json& asset = doc["asset"];
    const std::string generator = asset.value("generator", std::string());
    if (generator.find("skybake") == std::string::npos)
        asset["generator"] = generator.empty() ? std::string("skybake") : generator + ", skybake";

    Json& buffers = doc["buffers"];
    for (std::size_t i = 1; i < buffers.size(); ++i)
        if (buffers[i].contains("uri") && buffers[i]["uri"].is_string())
            buffers[i]["uri"] = relocate_uri(buffers[i]["uri"].get<std::string>(), s.source_dir, out_dir);
    buffers[0]["byteLength"] = bin.size();
    if (ext == ".glb")
        buffers[0].erase("uri");
    else
        buffers[0]["uri"] = "data:application/octet-stream;base64," + base64(bin);

    write_file_atomic(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out)
            throw Error("cannot create file", tmp.string());
        std::string text = doc.dump();
        if (ext == ".glb") {
            while (text.size() % 4)
                text += ' ';
            while (bin.size() % 4)
                bin.push_back(0);
            const std::uint32_t header[3] = {kGlbMagic, 2, std::uint32_t(12 + 8 + text.size() + 8 + bin.size())};
            const std::uint32_t json_head[2] = {std::uint32_t(text.size()), kChunkJson};
            const std::uint32_t bin_head[2] = {std::uint32_t(bin.size()), kChunkBin};
            out.write(reinterpret_cast<const char*>(header), sizeof header);
            out.write(reinterpret_cast<const char*>(json_head), sizeof json_head);
            out.write(text.data(), std::streamsize(text.size()));
            out.write(reinterpret_cast<const char*>(bin_head), sizeof bin_head);
            out.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
        } else {
            out << text;
        }
        if (!out.flush())
            throw Error("cannot write glTF", tmp.string());
    });
}

} // namespace skybake
