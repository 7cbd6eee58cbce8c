// glTF documents written back with new attributes: everything else survives.
// Labelled "io": these also run under AddressSanitizer + UBSan (make test-sanitize).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "core/test_paths.h"

using namespace skybake;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

const fs::path kGltf2 = fs::path(skybake::test::assimp_models()) / "glTF2";

fs::path temp_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-gltf-asset-test-" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// A sample's folder copied to a fresh temporary folder; returns the copy of `file`.
fs::path copy_sample(const std::string& folder, const std::string& file, const std::string& name) {
    const fs::path dir = temp_dir(name);
    fs::copy(kGltf2 / folder, dir, fs::copy_options::recursive);
    return dir / file;
}

struct Document {
    Json json;
    std::string bin; // buffer 0: the GLB chunk, or the external file
};

std::uint32_t u32(const std::string& s, std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, s.data() + at, 4);
    return v;
}

Document read_document(const fs::path& path) {
    const std::string data = read_file(path);
    Document d;
    if (path.extension() == ".glb") {
        const std::uint32_t json_len = u32(data, 12);
        d.json = Json::parse(data.substr(20, json_len));
        const std::size_t bin_at = 20 + json_len;
        if (bin_at + 8 <= data.size())
            d.bin = data.substr(bin_at + 8, u32(data, bin_at));
    } else {
        d.json = Json::parse(data);
        const std::string uri = d.json["buffers"][0].value("uri", "");
        if (!uri.empty() && uri.rfind("data:", 0) != 0)
            d.bin = read_file(path.parent_path() / uri);
    }
    return d;
}

// Float VEC-n accessor values of an output document (buffer 0 only).
std::vector<float> floats(const Document& d, int accessor) {
    const Json& a = d.json["accessors"][std::size_t(accessor)];
    const Json& v = d.json["bufferViews"][a["bufferView"].get<std::size_t>()];
    EXPECT_EQ(a["componentType"], 5126);
    EXPECT_EQ(v.value("buffer", 0), 0);
    const std::string type = a["type"];
    const std::size_t n = type == "SCALAR" ? 1 : std::size_t(type[3] - '0');
    const std::size_t stride = v.value("byteStride", std::size_t(n * 4));
    const std::size_t base = v.value("byteOffset", std::size_t(0)) + a.value("byteOffset", std::size_t(0));
    std::vector<float> out(a["count"].get<std::size_t>() * n);
    for (std::size_t i = 0; i < a["count"].get<std::size_t>(); ++i)
        std::memcpy(&out[i * n], d.bin.data() + base + i * stride, n * 4);
    return out;
}

// Fills the asset's mesh with a world-space "ao" (different on each instance)
// and a "bent_normal" equal to the world normal.
void fill(GltfAsset& asset) {
    Mesh& m = asset.mesh();
    std::vector<float> ao(m.vertex_count()), bent(3 * m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const glm::vec3 p = m.positions[v];
        ao[v] = 0.5f + 0.5f * std::sin(3.0f * p.x + 5.0f * p.y + 7.0f * p.z);
        bent[3 * v] = m.normals[v].x, bent[3 * v + 1] = m.normals[v].y, bent[3 * v + 2] = m.normals[v].z;
    }
    m.set_attribute("ao", 1, std::move(ao));
    m.set_attribute("bent_normal", 3, std::move(bent));
}

// Removes from `out` what a bake adds, checking each addition on the way;
// what is left must equal the input.
void strip_additions(Json& out, const Json& in, std::size_t in_bin_bytes) {
    const std::size_t n_acc = in.value("accessors", Json::array()).size();
    const std::size_t n_views = in.value("bufferViews", Json::array()).size();
    const std::size_t n_meshes = in["meshes"].size();
    for (Json& mesh : out["meshes"])
        for (Json& prim : mesh["primitives"]) {
            if (prim.value("mode", 4) != 4)
                continue;
            const std::size_t count = out["accessors"][prim["attributes"]["POSITION"].get<std::size_t>()]["count"];
            for (const char* key : {"_AO", "_BENT_NORMAL"}) {
                ASSERT_TRUE(prim["attributes"].contains(key)) << key;
                const std::size_t a = prim["attributes"][key];
                ASSERT_GE(a, n_acc);
                const Json& acc = out["accessors"][a];
                EXPECT_EQ(acc["count"], count);
                EXPECT_EQ(acc["componentType"], 5126);
                const Json& view = out["bufferViews"][acc["bufferView"].get<std::size_t>()];
                EXPECT_GE(acc["bufferView"].get<std::size_t>(), n_views);
                EXPECT_GE(view["byteOffset"].get<std::size_t>(), in_bin_bytes) << "new data is appended";
                prim["attributes"].erase(key);
            }
        }
    for (std::size_t i = 0; i < out["nodes"].size(); ++i) {
        Json& node = out["nodes"][i];
        if (node.contains("mesh") && node["mesh"].get<std::size_t>() >= n_meshes) {
            const Json& original = in["nodes"][i]["mesh"];
            EXPECT_EQ(out["meshes"][node["mesh"].get<std::size_t>()], in["meshes"][original.get<std::size_t>()])
                << "node " << i << " got a copy of its mesh";
            node["mesh"] = original;
        }
    }
    // A .glb embeds the images the input names by URI (GlbEmbedsTheImagesItFinds checks the bytes).
    if (in.contains("images"))
        for (std::size_t i = 0; i < in["images"].size() && i < out["images"].size(); ++i)
            if (in["images"][i].contains("uri") && out["images"][i].contains("bufferView")) {
                EXPECT_GE(out["images"][i]["bufferView"].get<std::size_t>(), n_views) << "image " << i;
                EXPECT_TRUE(out["images"][i].contains("mimeType")) << "image " << i;
                out["images"][i] = in["images"][i];
            }
    out["meshes"].get_ref<Json::array_t&>().resize(n_meshes);
    if (n_acc == 0)
        out.erase("accessors");
    else
        out["accessors"].get_ref<Json::array_t&>().resize(n_acc);
    if (n_views == 0)
        out.erase("bufferViews");
    else
        out["bufferViews"].get_ref<Json::array_t&>().resize(n_views);
    const std::string generator = out["asset"]["generator"];
    EXPECT_NE(generator.find("skybake"), std::string::npos);
    if (in["asset"].contains("generator"))
        out["asset"]["generator"] = in["asset"]["generator"];
    else
        out["asset"].erase("generator");
    EXPECT_GE(out["buffers"][0]["byteLength"].get<std::size_t>(), in["buffers"][0]["byteLength"].get<std::size_t>());
    out["buffers"][0]["byteLength"] = in["buffers"][0]["byteLength"];
    if (in["buffers"][0].contains("uri"))
        out["buffers"][0]["uri"] = in["buffers"][0]["uri"];
}

// The bent normals written in each primitive are the file's own normals,
// normalised: world normals carried back to the mesh's frame.
std::size_t expect_bent_normals_are_local_normals(const Document& out) {
    std::size_t checked = 0;
    for (const Json& mesh : out.json["meshes"])
        for (const Json& prim : mesh["primitives"]) {
            const Json& attrs = prim["attributes"];
            if (!attrs.contains("NORMAL") || !attrs.contains("_BENT_NORMAL"))
                continue;
            const std::vector<float> n = floats(out, attrs["NORMAL"]), b = floats(out, attrs["_BENT_NORMAL"]);
            EXPECT_EQ(n.size(), b.size());
            for (std::size_t i = 0; i + 2 < std::min(n.size(), b.size()); i += 3) {
                const glm::vec3 nl = glm::normalize(glm::vec3(n[i], n[i + 1], n[i + 2]));
                const glm::vec3 bl(b[i], b[i + 1], b[i + 2]);
                EXPECT_NEAR(glm::length(nl - bl), 0.0f, 2e-5f) << "vertex " << i / 3;
                ++checked;
            }
        }
    return checked;
}

void round_trip(const fs::path& input, const std::string& output_name) {
    GltfAsset asset = GltfAsset::load(input);
    fill(asset);
    const fs::path output = input.parent_path() / output_name;
    asset.save(output);

    const Document in = read_document(input), out = read_document(output);
    // Buffer 0 is the input's, with the new data appended.
    const std::size_t in_bytes = in.json["buffers"][0]["byteLength"];
    if (!in.bin.empty()) {
        ASSERT_GE(out.bin.size(), in_bytes);
        EXPECT_EQ(out.bin.substr(0, in_bytes), in.bin.substr(0, in_bytes));
    }
    const bool has_normals = in.json.dump().find("\"NORMAL\"") != std::string::npos;
    if (output.extension() == ".glb") {
        EXPECT_EQ(expect_bent_normals_are_local_normals(out) > 0, has_normals);
    }
    Json stripped = out.json;
    strip_additions(stripped, in.json, in_bytes);
    EXPECT_EQ(stripped, in.json) << "diff: " << Json::diff(in.json, stripped).dump();

    // Read back, the flat scene is the same, instance for instance.
    const Mesh back = load_mesh(output);
    ASSERT_EQ(back.vertex_count(), asset.mesh().vertex_count());
    EXPECT_EQ(back.indices, asset.mesh().indices);
    const VertexAttribute* ao = back.find_attribute("ao");
    ASSERT_NE(ao, nullptr);
    EXPECT_EQ(ao->values, asset.mesh().find_attribute("ao")->values);
    for (std::size_t v = 0; v < back.vertex_count(); ++v)
        ASSERT_EQ(back.positions[v], asset.mesh().positions[v]) << v;
}

} // namespace

TEST(GltfAsset, BoxTexturedExternalBuffer) {
    round_trip(copy_sample("BoxTextured-glTF", "BoxTextured.gltf", "box-external"), "out.glb");
}

TEST(GltfAsset, BoxTexturedBinary) {
    round_trip(copy_sample("BoxTextured-glTF-Binary", "BoxTextured.glb", "box-binary"), "out.glb");
}

TEST(GltfAsset, BoxTexturedEmbeddedToGltf) {
    round_trip(copy_sample("BoxTextured-glTF-Embedded", "BoxTextured.gltf", "box-embedded"), "out.gltf");
}

TEST(GltfAsset, TwoCylinderEngineInstances) {
    const fs::path input = copy_sample("2CylinderEngine-glTF-Binary", "2CylinderEngine.glb", "engine");
    const GltfAsset asset = GltfAsset::load(input);
    EXPECT_GT(asset.shared_instance_count(), 0u); // the engine reuses meshes under several nodes
    round_trip(input, "out.glb");
}

TEST(GltfAsset, SimpleSkin) {
    round_trip(copy_sample("simple_skin", "simple_skin.gltf", "skin"), "out.glb");
}

TEST(GltfAsset, AnimatedMorphCube) {
    round_trip(copy_sample("glTF-Sample-Models/AnimatedMorphCube-glTF", "AnimatedMorphCube.gltf", "morph"), "out.glb");
}

TEST(GltfAsset, TextureTransformKeepsItsExtension) {
    const fs::path input = copy_sample("textureTransform", "TextureTransformTest.gltf", "texture-transform");
    round_trip(input, "out.glb");
    const Json out = read_document(input.parent_path() / "out.glb").json;
    EXPECT_NE(out.dump().find("KHR_texture_transform"), std::string::npos);
}

TEST(GltfAsset, ImageUrisFollowTheOutputFolder) {
    const fs::path input = copy_sample("BoxTextured-glTF", "BoxTextured.gltf", "box-moved");
    GltfAsset asset = GltfAsset::load(input);
    fill(asset);
    const fs::path elsewhere = temp_dir("box-moved-out") / "sub";
    fs::create_directories(elsewhere);
    asset.save(elsewhere / "out.gltf");
    const Json out = read_document(elsewhere / "out.gltf").json;
    const std::string uri = out["images"][0]["uri"];
    EXPECT_NE(uri, "CesiumLogoFlat.png");
    EXPECT_TRUE(fs::is_regular_file(elsewhere / uri)) << uri;
}

// A .glb embeds the images whose files exist (bufferView + mimeType, the
// same bytes), and keeps the URI of one that does not, seen from its folder.
TEST(GltfAsset, GlbEmbedsTheImagesItFinds) {
    const fs::path input = copy_sample("BoxTextured-glTF", "BoxTextured.gltf", "box-embedded");
    GltfAsset asset = GltfAsset::load(input);
    fill(asset);
    const fs::path elsewhere = temp_dir("box-embedded-out");
    asset.save(elsewhere / "out.glb");
    const auto d = read_document(elsewhere / "out.glb");
    const Json& image = d.json["images"][0];
    EXPECT_FALSE(image.contains("uri")) << image.dump();
    EXPECT_EQ(image["mimeType"], "image/png");
    const Json& view = d.json["bufferViews"][image["bufferView"].get<std::size_t>()];
    const std::string png = read_file(input.parent_path() / "CesiumLogoFlat.png");
    ASSERT_EQ(view["byteLength"].get<std::size_t>(), png.size());
    EXPECT_EQ(d.bin.substr(view["byteOffset"].get<std::size_t>(), png.size()), png);
    EXPECT_FALSE(view.contains("target")); // an image's view is not a vertex buffer
    // Its base colour still reads back through the loader.
    const Mesh back = load_mesh(elsewhere / "out.glb");
    ASSERT_FALSE(back.materials.empty());
    EXPECT_FALSE(back.materials[0].base_color_image.empty());

    fs::remove(input.parent_path() / "CesiumLogoFlat.png");
    GltfAsset missing = GltfAsset::load(input);
    fill(missing);
    missing.save(elsewhere / "missing.glb");
    const Json j = read_document(elsewhere / "missing.glb").json;
    ASSERT_TRUE(j["images"][0].contains("uri")) << j["images"].dump();
    EXPECT_FALSE(j["images"][0].contains("bufferView"));
}

TEST(GltfAsset, RefusesOtherFormatsAndChangedMeshes) {
    EXPECT_FALSE(GltfAsset::is_gltf2(fs::path(skybake::test::assimp_models()) / "PLY" / "cube.ply"));
    EXPECT_FALSE(GltfAsset::is_gltf2(fs::path(skybake::test::assimp_models()) / "glTF" / "CesiumMilkTruck" /
                                     "CesiumMilkTruck.gltf")); // glTF 1.0
    EXPECT_THROW(
        GltfAsset::load(fs::path(skybake::test::assimp_models()) / "glTF" / "CesiumMilkTruck" / "CesiumMilkTruck.gltf"),
        Error);
    const fs::path input = copy_sample("BoxTextured-glTF-Binary", "BoxTextured.glb", "box-changed");
    GltfAsset asset = GltfAsset::load(input);
    asset.mesh().positions.push_back({0, 0, 0});
    EXPECT_THROW(asset.save(input.parent_path() / "out.glb"), Error);
    EXPECT_FALSE(fs::exists(input.parent_path() / "out.glb"));
    asset.mesh().positions.pop_back();
    EXPECT_THROW(asset.save(input.parent_path() / "out.obj"), Error);
}

// EXT_lights_image_based: six PNG faces, the irradiance, the default scene's
// reference, and the rest of the document untouched; .glb and .gltf.
TEST(GltfAsset, WritesAnImageBasedLight) {
    const fs::path input = copy_sample("BoxTextured-glTF-Binary", "BoxTextured.glb", "box-ibl");
    const Document before = read_document(input);
    ImageBasedLight light;
    light.face_size = 2;
    for (int f = 0; f < 6; ++f)
        light.faces[std::size_t(f)] = encode_png8(2, 2, 4, std::vector<std::uint8_t>(16, std::uint8_t(40 * f + 1)));
    for (int k = 0; k < 9; ++k)
        light.irradiance[std::size_t(k)] = glm::vec3(0.1f * float(k), 1.0f, -0.5f);
    for (const char* name : {"lit.glb", "lit.gltf"}) {
        GltfAsset asset = GltfAsset::load(input);
        asset.set_image_based_light(light);
        const fs::path out = input.parent_path() / name;
        asset.save(out);
        const Document d = read_document(out);
        const Json& l = d.json["extensions"]["EXT_lights_image_based"]["lights"][0];
        EXPECT_EQ(l["specularImageSize"], 2);
        ASSERT_EQ(l["irradianceCoefficients"].size(), 9u);
        EXPECT_FLOAT_EQ(l["irradianceCoefficients"][4][0].get<float>(), 0.4f);
        EXPECT_FLOAT_EQ(l["irradianceCoefficients"][8][2].get<float>(), -0.5f);
        ASSERT_EQ(l["specularImages"].size(), 1u); // one mip
        ASSERT_EQ(l["specularImages"][0].size(), 6u);
        for (int f = 0; f < 6; ++f) {
            const Json& image = d.json["images"][l["specularImages"][0][std::size_t(f)].get<std::size_t>()];
            std::string bytes;
            if (image.contains("bufferView")) {
                const Json& v = d.json["bufferViews"][image["bufferView"].get<std::size_t>()];
                bytes = d.bin.substr(v.value("byteOffset", std::size_t(0)), v["byteLength"].get<std::size_t>());
                EXPECT_EQ(image["mimeType"], "image/png");
            } else {
                const std::string uri = image["uri"];
                ASSERT_EQ(uri.rfind("data:image/png;base64,", 0), 0u);
            }
            if (!bytes.empty())
                EXPECT_EQ(bytes, light.faces[std::size_t(f)]) << f;
        }
        EXPECT_EQ(d.json["scenes"][d.json.value("scene", 0)]["extensions"]["EXT_lights_image_based"]["light"], 0);
        const Json& used = d.json["extensionsUsed"];
        EXPECT_NE(std::find(used.begin(), used.end(), "EXT_lights_image_based"), used.end());
        EXPECT_FALSE(d.json.contains("extensionsRequired"));
        EXPECT_EQ(d.json["meshes"], before.json["meshes"]);
        EXPECT_EQ(d.json["materials"], before.json["materials"]);
        // The written file reads again, with the same geometry.
        EXPECT_EQ(GltfAsset::load(out).mesh().vertex_count(), asset.mesh().vertex_count());
    }
    GltfAsset asset = GltfAsset::load(input);
    ImageBasedLight bad = light;
    bad.face_size = 3;
    EXPECT_THROW(asset.set_image_based_light(bad), Error);
    bad = light;
    bad.faces[2] = "not a png";
    EXPECT_THROW(asset.set_image_based_light(bad), Error);
    bad = light;
    bad.irradiance[1].y = std::nanf("");
    EXPECT_THROW(asset.set_image_based_light(bad), Error);
}
