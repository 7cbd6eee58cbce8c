// mesh_albedo(): glTF's base colour (factor × image × vertex colour) per
// vertex, on a mesh built here and on a textured sample model. Label "io".
#include <filesystem>

#include <gtest/gtest.h>

#include "core/test_paths.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

TEST(MeshAlbedo, FactorTimesImageTimesColour) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-albedo-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    // A 2×2 image: red, green / blue, white (linear, exact in EXR).
    Image img(2, 2);
    const float texels[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c)
            img.pixel(k % 2, k / 2)[c] = texels[k][c];
    save_exr(dir / "tex.exr", img);

    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}, {5, 5, 5}};
    m.indices = {0, 1, 2, 1, 3, 2, 4, 5, 3};
    m.texcoords = {{{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}, {0.5f, 0.25f}, {0, 0}, {0, 0}, {0, 0}}};
    MeshMaterial textured;
    textured.base_color = {0.5f, 1.0f, 1.0f, 1.0f};
    textured.base_color_texture = (dir / "tex.exr").string();
    MeshMaterial plain;
    plain.base_color = {0.2f, 0.4f, 0.6f, 1.0f};
    m.materials = {textured, plain};
    m.parts = {{"a", 0}, {"b", 1}};
    m.triangle_parts = {0, 0, 1};
    const glm::vec3 fallback(0.8f);
    const std::vector<glm::vec3> a = mesh_albedo(m, fallback);
    ASSERT_EQ(a.size(), 7u);
    EXPECT_EQ(a[0], glm::vec3(0.5f, 0.0f, 0.0f)); // red texel × factor
    EXPECT_EQ(a[1], glm::vec3(0.0f, 1.0f, 0.0f)); // green
    EXPECT_EQ(a[2], glm::vec3(0.0f, 0.0f, 1.0f)); // blue
    EXPECT_EQ(a[3], glm::vec3(0.25f, 0.5f, 0.0f)); // halfway between red and green (the first triangle's material)
    EXPECT_EQ(a[4], glm::vec3(0.2f, 0.4f, 0.6f)); // the factor alone
    EXPECT_EQ(a[6], fallback);                    // no triangle: no material

    // Vertex colours multiply; without materials they are the albedo.
    m.colors.assign(7, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    const std::vector<glm::vec3> c = mesh_albedo(m, fallback);
    EXPECT_EQ(c[0], glm::vec3(0.25f, 0.0f, 0.0f));
    EXPECT_EQ(c[4], glm::vec3(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(c[6], glm::vec3(0.5f));
    // An image that is gone: the factor remains.
    fs::remove(dir / "tex.exr");
    m.colors.clear();
    EXPECT_EQ(mesh_albedo(m, fallback)[0], glm::vec3(0.5f, 1.0f, 1.0f));
    fs::remove_all(dir);
}

// The milk truck's materials and image (glTF 1.0, through Assimp): the albedo varies over the model
// (it was 0.8 everywhere) and stays a reflectance.
TEST(MeshAlbedo, TexturedSampleModelIsNotGrey) {
    const fs::path truck = fs::path(test::assimp_models()) / "glTF" / "CesiumMilkTruck" / "CesiumMilkTruck.gltf";
    const Mesh m = load_mesh(truck);
    ASSERT_FALSE(m.materials.empty());
    bool textured = false;
    for (const MeshMaterial& mm : m.materials)
        textured |= !mm.base_color_texture.empty();
    ASSERT_TRUE(textured);
    const std::vector<glm::vec3> a = mesh_albedo(m);
    ASSERT_EQ(a.size(), m.vertex_count());
    glm::vec3 lo(1.0f), hi(0.0f);
    for (const glm::vec3& x : a) {
        lo = glm::min(lo, x);
        hi = glm::max(hi, x);
        EXPECT_TRUE(x.x >= 0.0f && x.x <= 1.0f && x.y >= 0.0f && x.y <= 1.0f && x.z >= 0.0f && x.z <= 1.0f);
    }
    EXPECT_GT(hi.x - lo.x + hi.y - lo.y + hi.z - lo.z, 0.1f) << "the same colour everywhere";
    EXPECT_NE(a[0], glm::vec3(0.8f));
    // Written as .glb (the image embedded) and moved away from the image: the same albedo.
    const fs::path dir = fs::temp_directory_path() / ("skybake-albedo-glb-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    save_mesh(dir / "truck.glb", m);
    const Mesh back = load_mesh(dir / "truck.glb");
    EXPECT_EQ(mesh_albedo(back), a);
    fs::remove_all(dir);
}

} // namespace
} // namespace skybake
