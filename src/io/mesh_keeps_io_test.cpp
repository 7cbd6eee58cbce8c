// What the flat Mesh keeps of a file: UV sets, colours, materials and node
// names, through Assimp, PLY and glTF, and into the .glb it is written as.
// Labelled "io": these also run under AddressSanitizer + UBSan (make test-sanitize).
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/files.h"
#include "skybake/mesh.h"
#include "core/test_paths.h"

using namespace skybake;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

const fs::path kModels = skybake::test::assimp_models();

fs::path temp(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-keeps-test-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir / name;
}

Json glb_json(const fs::path& path) {
    const std::string data = read_file(path);
    std::uint32_t len;
    std::memcpy(&len, data.data() + 12, 4);
    return Json::parse(data.substr(20, len));
}

} // namespace

TEST(MeshKeeps, CesiumMilkTruckKeepsTextureUvsAndNodeNames) {
    const fs::path truck = kModels / "glTF" / "CesiumMilkTruck" / "CesiumMilkTruck.gltf"; // glTF 1.0, via Assimp
    const Mesh mesh = load_mesh(truck);
    ASSERT_FALSE(mesh.texcoords.empty());
    ASSERT_EQ(mesh.texcoords[0].size(), mesh.vertex_count());
    bool textured = false;
    for (const auto& m : mesh.materials)
        if (!m.base_color_texture.empty()) {
            textured = true;
            EXPECT_TRUE(fs::equivalent(m.base_color_texture, truck.parent_path() / "CesiumMilkTruck.png"))
                << m.base_color_texture;
        }
    EXPECT_TRUE(textured);
    std::set<std::string> names;
    for (const auto& p : mesh.parts)
        names.insert(p.name);
    EXPECT_TRUE(names.count("Wheels") || names.count("Node") || names.size() > 1) << names.size();
    ASSERT_EQ(mesh.triangle_parts.size(), mesh.triangle_count());
    // UVs of a textured model lie in the image.
    for (const auto& uv : mesh.texcoords[0])
        ASSERT_TRUE(uv.x > -1e-3f && uv.x < 1.001f && uv.y > -1e-3f && uv.y < 1.001f) << uv.x << " " << uv.y;

    // Written as .glb elsewhere: the texture is embedded (it travels with the
    // file), UVs and names come back.
    const fs::path out = temp("truck.glb");
    save_mesh(out, mesh);
    const Json j = glb_json(out);
    ASSERT_TRUE(j.contains("images"));
    ASSERT_EQ(j["images"].size(), 1u) << "one image for the materials that share it";
    EXPECT_FALSE(j["images"][0].contains("uri"));
    EXPECT_EQ(j["images"][0]["mimeType"], "image/png");
    EXPECT_TRUE(j["images"][0].contains("bufferView"));
    EXPECT_TRUE(j["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
    std::set<std::string> written;
    for (const auto& n : j["nodes"])
        written.insert(n.value("name", ""));
    for (const auto& name : names)
        EXPECT_TRUE(written.count(name)) << name;
    const Mesh back = load_mesh(out);
    ASSERT_EQ(back.vertex_count(), mesh.vertex_count());
    ASSERT_EQ(back.texcoords.size(), mesh.texcoords.size());
    EXPECT_EQ(back.texcoords[0], mesh.texcoords[0]);
    EXPECT_EQ(back.positions, mesh.positions);
    ASSERT_EQ(back.materials.size(), mesh.materials.size());
    for (std::size_t i = 0; i < back.materials.size(); ++i) {
        EXPECT_EQ(back.materials[i].base_color, mesh.materials[i].base_color);
        EXPECT_EQ(back.materials[i].base_color_image.empty(), mesh.materials[i].base_color_texture.empty());
        if (!mesh.materials[i].base_color_texture.empty()) // the file's bytes, as they were
            EXPECT_EQ(std::string(back.materials[i].base_color_image.begin(), back.materials[i].base_color_image.end()),
                      read_file(mesh.materials[i].base_color_texture));
    }
}

TEST(MeshKeeps, PlyTextureCoordinatesBecomeTexcoord0) {
    for (const char* names : {"s t", "u v", "texture_u texture_v"}) {
        std::string un(names), vn;
        vn = un.substr(un.find(' ') + 1);
        un = un.substr(0, un.find(' '));
        const fs::path ply = temp("uv.ply");
        std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nproperty float "
                           << un << "\nproperty float " << vn
                           << "\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0.25 1\n3 0 1 2\n";
        const Mesh m = load_mesh(ply);
        ASSERT_EQ(m.texcoords.size(), 1u) << names;
        EXPECT_TRUE(m.attributes.empty()) << names << ": no '_S'/'_T' scalar attributes";
        // PLY's t grows upwards; glTF's v downwards.
        EXPECT_EQ(m.texcoords[0][0], glm::vec2(0.0f, 1.0f));
        EXPECT_EQ(m.texcoords[0][2], glm::vec2(0.25f, 0.0f));
        const fs::path back_ply = temp("uv-back.ply");
        save_mesh(back_ply, m);
        EXPECT_EQ(load_mesh(back_ply).texcoords, m.texcoords);
        const fs::path glb = temp("uv.glb");
        save_mesh(glb, m);
        EXPECT_EQ(load_mesh(glb).texcoords, m.texcoords);
    }
}

TEST(MeshKeeps, AssimpUvSetsAndColours) {
    const Mesh m = load_mesh(kModels / "PLY" / "cube_uv.ply"); // our PLY reader
    EXPECT_EQ(m.texcoords.size(), 1u);
    const Mesh obj = load_mesh(kModels / "glTF2" / "BoxTextured-glTF" / "BoxTextured.gltf");
    ASSERT_EQ(obj.texcoords.size(), 1u);
    ASSERT_EQ(obj.materials.size(), 1u);
    EXPECT_FALSE(obj.materials[0].base_color_texture.empty());
}
