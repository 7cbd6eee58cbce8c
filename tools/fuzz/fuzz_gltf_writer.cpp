// libFuzzer target: GltfAsset::save driven the way the commands drive it, on
// documents with and without each optional array. gltf_asset fuzzes the
// reader; this one fuzzes the edits a bake makes before it writes:
//
//   byte 0: what to do (bits below); byte 1: top-level members to remove
//   before the load (bit i: kOptional[i]); byte 2: the occlusion texture's UV
//   set; the rest: a .gltf (byte 0 bit 0 clear) or .glb file.
//
// Removing members turns every sample document into the shapes real exporters
// write: Blender's untextured materials have no "images", "textures" or
// "samplers"; a mesh without a material has no "materials".
//
// What must hold: whatever loads saves or throws skybake::Error; what was
// saved loads again with the same vertices and the attributes added; with an
// occlusion texture, the output has exactly one image naming it, and every
// triangle primitive's material reads it through a texture that exists.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <nlohmann/json.hpp>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

enum : std::uint8_t {
    kInputGlb = 1 << 0,
    kOutputGlb = 1 << 1,
    kAddScalar = 1 << 2,    // "ao", one component
    kAddDirection = 1 << 3, // "bent_normal", a direction (rotated per instance)
    kAddColors = 1 << 4,    // AO as grey COLOR_0
    kAddTexture = 1 << 5,   // set_occlusion_texture
    kTwice = 1 << 6,        // load what was saved, bake it again, save again
    kSpaceInName = 1 << 7,  // the AO image's file name has a space (URI-escaped)
};

constexpr const char* kOptional[8] = {"images", "textures", "samplers", "materials",
                                      "animations", "skins", "scenes", "extensionsUsed"};

std::uint32_t u32(const std::string& s, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, s.data() + at, 4);
    return v;
}

void put_u32(std::string& s, std::uint32_t v) {
    s.append(reinterpret_cast<const char*>(&v), 4);
}

// The file with the members in `strip` removed; unchanged where its JSON does not parse.
std::string strip_members(const std::string& file, bool glb, std::uint8_t strip) {
    if (strip == 0)
        return file;
    std::string json = file, rest;
    if (glb) {
        if (file.size() < 20 || u32(file, 16) != 0x4E4F534A || u32(file, 12) > file.size() - 20)
            return file;
        json = file.substr(20, u32(file, 12));
        rest = file.substr(20 + json.size());
    }
    Json doc = Json::parse(json, nullptr, false);
    if (doc.is_discarded() || !doc.is_object())
        return file;
    for (int i = 0; i < 8; ++i)
        if (strip & (1 << i)) {
            doc.erase(kOptional[i]);
            if (i == 6)
                doc.erase("scene");
        }
    std::string text = doc.dump();
    if (!glb)
        return text;
    while (text.size() % 4)
        text += ' ';
    std::string out;
    put_u32(out, 0x46546C67);
    put_u32(out, 2);
    put_u32(out, std::uint32_t(12 + 8 + text.size() + rest.size()));
    put_u32(out, std::uint32_t(text.size()));
    put_u32(out, 0x4E4F534A);
    return out + text + rest;
}

Json output_json(const fs::path& path) {
    const std::string data = skybake::read_file(path);
    if (path.extension() == ".gltf")
        return Json::parse(data);
    if (data.size() < 20)
        std::abort();
    return Json::parse(data.substr(20, u32(data, 12)));
}

void check_occlusion(const fs::path& out, const std::string& uri, const std::string& baked_attribute) {
    const Json doc = output_json(out);
    int naming = 0;
    for (const Json& image : doc.at("images"))
        naming += image.contains("uri") && image["uri"] == uri;
    if (naming != 1)
        std::abort(); // the AO image is missing or written more than once
    const Json& materials = doc.at("materials");
    const Json& textures = doc.at("textures");
    // A baked primitive (it has the new attribute; meshes no scene reaches are
    // not baked) reads the AO image as its material's occlusion.
    for (const Json& mesh : doc.at("meshes"))
        for (const Json& prim : mesh.at("primitives")) {
            if (prim.value("mode", 4) != 4 || !prim.at("attributes").contains(baked_attribute))
                continue;
            const std::size_t m = prim.at("material").get<std::size_t>();
            const Json& tex = materials.at(m).at("occlusionTexture");
            const std::size_t t = tex.at("index").get<std::size_t>();
            const std::size_t source = textures.at(t).at("source").get<std::size_t>();
            if (doc["images"].at(source).value("uri", std::string()) != uri)
                std::abort(); // a primitive's occlusion reads another image
        }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 4 || size > (1 << 20))
        return 0;
    static const fs::path dir = [] {
        const fs::path d = fs::temp_directory_path() / ("skybake-fuzz-gltf-writer-" + std::to_string(getpid()));
        fs::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(fs::temp_directory_path() / ("skybake-fuzz-gltf-writer-" + std::to_string(getpid())), ec);
        });
        return d;
    }();
    const std::uint8_t what = data[0], strip = data[1];
    const int uv_set = data[2] % 3;
    const bool glb_in = what & kInputGlb;
    const fs::path in = dir / (glb_in ? "in.glb" : "in.gltf");
    const fs::path out = dir / ((what & kOutputGlb) ? "out.glb" : "out.gltf");
    const fs::path again = dir / ((what & kOutputGlb) ? "again.gltf" : "again.glb");
    const fs::path image = dir / ((what & kSpaceInName) ? "baked ao.png" : "baked_ao.png");
    const std::string uri = (what & kSpaceInName) ? "baked%20ao.png" : "baked_ao.png";
    {
        const std::string file = strip_members(std::string(reinterpret_cast<const char*>(data + 3), size - 3), glb_in,
                                               strip);
        std::ofstream f(in, std::ios::binary | std::ios::trunc);
        f.write(file.data(), std::streamsize(file.size()));
    }
    skybake::ImportLimits limits;
    limits.max_file_bytes = 1 << 22;
    limits.max_vertices = limits.max_triangles = 1 << 20;
    limits.isolate_parsers = false;

    // One bake's edits, as `ao` makes them.
    const auto bake = [&](skybake::GltfAsset& asset) {
        skybake::Mesh& mesh = asset.mesh();
        const std::size_t n = mesh.vertex_count();
        if (what & kAddScalar)
            mesh.set_attribute("ao", 1, std::vector<float>(n, 0.25f));
        if (what & kAddDirection) {
            std::vector<float> up(3 * n, 0.0f);
            for (std::size_t v = 0; v < n; ++v)
                up[3 * v + 1] = 1.0f;
            mesh.set_attribute("bent_normal", 3, std::move(up));
        }
        if (what & kAddColors)
            mesh.colors.assign(n, glm::vec4(0.25f, 0.25f, 0.25f, 1.0f));
        if (what & kAddTexture)
            asset.set_occlusion_texture(image, uv_set);
    };
    // What must read back from a file save() wrote.
    const auto check = [&](const fs::path& file, std::size_t n) {
        const skybake::GltfAsset back = skybake::GltfAsset::load(file, limits);
        if (back.mesh().vertex_count() != n)
            std::abort();
        if (n > 0 && (what & kAddScalar) && !back.mesh().find_attribute("ao"))
            std::abort();
        if (n > 0 && (what & kAddDirection) && !back.mesh().find_attribute("bent_normal"))
            std::abort();
        if (n > 0 && (what & kAddTexture))
            check_occlusion(file, uri, (what & kAddScalar) ? "_AO" : "_NO_SUCH_ATTRIBUTE");
    };
    try {
        skybake::GltfAsset asset = skybake::GltfAsset::load(in, limits);
        const std::size_t n = asset.mesh().vertex_count();
        bake(asset);
        bool saved = false;
        try {
            asset.save(out);
            saved = true;
        } catch (const skybake::Error&) {
        }
        if (saved) {
            check(out, n);
            if (what & kTwice) {
                skybake::GltfAsset second = skybake::GltfAsset::load(out, limits);
                bake(second);
                second.save(again); // what saved once saves again
                check(again, n);
            }
        }
    } catch (const skybake::Error&) {
    }
    std::error_code ec;
    fs::remove(out, ec);
    fs::remove(again, ec);
    return 0;
}
