// A glTF scene with one mesh under two nodes is baked in world space, as the
// same scene flattened by hand, and each instance gets its own attributes.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/files.h"
#include "skybake/bake.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "core/test_paths.h"

using namespace skybake;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

struct Trs {
    glm::dvec3 t{0.0};
    glm::dquat r{1.0, 0.0, 0.0, 0.0};
    glm::dvec3 s{1.0};
    glm::dmat4 matrix() const {
        return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
    }
};

// Writes `mesh` (positions, normals, indices) as a .glb whose scene holds one
// node per transform, every node using the same mesh.
void write_instanced_glb(const fs::path& path, const Mesh& mesh, const std::vector<Trs>& nodes) {
    std::string bin;
    auto append = [&](const void* p, std::size_t n) {
        const std::size_t at = bin.size();
        bin.append(static_cast<const char*>(p), n);
        return at;
    };
    const std::size_t nv = mesh.vertex_count();
    const std::size_t pos_at = append(mesh.positions.data(), nv * 12);
    const std::size_t nrm_at = append(mesh.normals.data(), nv * 12);
    const std::size_t idx_at = append(mesh.indices.data(), mesh.indices.size() * 4);
    const Bounds b = compute_bounds(mesh);
    Json j = {
        {"asset", {{"version", "2.0"}, {"generator", "hand"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", Json::array()}}}},
        {"nodes", Json::array()},
        {"meshes",
         {{{"name", "wall"}, {"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}}}}}}},
        {"accessors",
         {{{"bufferView", 0},
           {"componentType", 5126},
           {"count", nv},
           {"type", "VEC3"},
           {"min", {b.min.x, b.min.y, b.min.z}},
           {"max", {b.max.x, b.max.y, b.max.z}}},
          {{"bufferView", 1}, {"componentType", 5126}, {"count", nv}, {"type", "VEC3"}},
          {{"bufferView", 2}, {"componentType", 5125}, {"count", mesh.indices.size()}, {"type", "SCALAR"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", pos_at}, {"byteLength", nv * 12}},
          {{"buffer", 0}, {"byteOffset", nrm_at}, {"byteLength", nv * 12}},
          {{"buffer", 0}, {"byteOffset", idx_at}, {"byteLength", mesh.indices.size() * 4}}}},
        {"buffers", {{{"byteLength", bin.size()}}}}};
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        j["scenes"][0]["nodes"].push_back(i);
        const Trs& n = nodes[i];
        j["nodes"].push_back({{"name", "instance " + std::to_string(i)},
                              {"mesh", 0},
                              {"translation", {n.t.x, n.t.y, n.t.z}},
                              {"rotation", {n.r.x, n.r.y, n.r.z, n.r.w}},
                              {"scale", {n.s.x, n.s.y, n.s.z}}});
    }
    std::string text = j.dump();
    while (text.size() % 4)
        text += ' ';
    while (bin.size() % 4)
        bin += '\0';
    const std::uint32_t head[5] = {0x46546C67, 2, std::uint32_t(28 + text.size() + bin.size()),
                                   std::uint32_t(text.size()), 0x4E4F534A};
    const std::uint32_t bin_head[2] = {std::uint32_t(bin.size()), 0x004E4942};
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(head), sizeof head);
    out << text;
    out.write(reinterpret_cast<const char*>(bin_head), sizeof bin_head);
    out << bin;
}

// The scene flattened by hand: each node's copy of the mesh in world space.
Mesh flatten(const Mesh& mesh, const std::vector<Trs>& nodes) {
    Mesh flat;
    for (const Trs& n : nodes) {
        const glm::dmat4 m = n.matrix();
        const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(m));
        const bool mirrored = glm::determinant(glm::dmat3(m)) < 0.0;
        const auto base = std::uint32_t(flat.vertex_count());
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
            flat.positions.emplace_back(m * glm::dvec4(glm::dvec3(mesh.positions[v]), 1.0));
            const glm::dvec3 nw = normal_matrix * glm::dvec3(mesh.normals[v]);
            flat.normals.emplace_back(nw / glm::length(nw));
        }
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
            flat.indices.push_back(base + mesh.indices[t]);
            flat.indices.push_back(base + mesh.indices[t + (mirrored ? 2 : 1)]);
            flat.indices.push_back(base + mesh.indices[t + (mirrored ? 1 : 2)]);
        }
    }
    return flat;
}

const std::vector<Trs> kNodes = {
    {{0.0, 0.0, 0.0}, glm::angleAxis(0.5, glm::dvec3(0, 1, 0)), {1.0, 1.5, 0.7}},
    {{0.6, 0.0, 1.2}, glm::angleAxis(2.0, glm::dvec3(0, 1, 0)), {-1.0, 1.0, 1.0}}, // mirrored
};

} // namespace

TEST(GltfInstances, BakeMatchesTheSceneFlattenedByHand) {
    const fs::path dir = skybake::test::temp_dir("gltf-instances");
    ProceduralOptions po;
    po.kind = ProceduralKind::Wall;
    po.target_triangles = 800;
    const Mesh wall = generate_mesh(po);
    write_instanced_glb(dir / "scene.glb", wall, kNodes);

    const SphereRule rule = parse_rule("lebedev:590");
    GltfAsset asset = GltfAsset::load(dir / "scene.glb");
    EXPECT_EQ(asset.instance_count(), 2u);
    EXPECT_EQ(asset.shared_instance_count(), 1u);
    bake_ambient_occlusion(asset.mesh(), rule);
    Mesh flat = flatten(wall, kNodes);
    bake_ambient_occlusion(flat, rule);

    const std::vector<float>& a = asset.mesh().find_attribute("ao")->values;
    const std::vector<float>& b = flat.find_attribute("ao")->values;
    ASSERT_EQ(a.size(), b.size());
    double sum = 0.0, worst = 0.0;
    for (std::size_t v = 0; v < a.size(); ++v) {
        sum += std::abs(double(a[v]) - b[v]);
        worst = std::max(worst, std::abs(double(a[v]) - b[v]));
    }
    EXPECT_LE(sum / double(a.size()), 1e-4);
    EXPECT_LE(worst, 1e-2);
    // The two instances see each other: their AO differs from a lone wall's.
    Mesh lone = flatten(wall, {kNodes[0]});
    bake_ambient_occlusion(lone, rule);
    double lone_diff = 0.0;
    for (std::size_t v = 0; v < lone.vertex_count(); ++v)
        lone_diff = std::max(lone_diff, std::abs(double(lone.find_attribute("ao")->values[v]) - a[v]));
    EXPECT_GT(lone_diff, 0.05);

    // Written back, each node has its own attribute; read again, the flat
    // scene carries the same AO, and the bent normals, brought back to world
    // space as NORMAL is, are the baked ones.
    asset.save(dir / "baked.glb");
    const Mesh back = load_mesh(dir / "baked.glb");
    ASSERT_EQ(back.vertex_count(), flat.vertex_count());
    EXPECT_EQ(back.find_attribute("ao")->values, a);
    const std::vector<float>& bent_local = back.find_attribute("bent_normal")->values;
    const std::vector<float>& bent_world = asset.mesh().find_attribute("bent_normal")->values;
    for (std::size_t i = 0; i < kNodes.size(); ++i) {
        const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(kNodes[i].matrix()));
        for (std::size_t v = 0; v < wall.vertex_count(); ++v) {
            const std::size_t k = 3 * (i * wall.vertex_count() + v);
            const glm::dvec3 w =
                glm::normalize(normal_matrix * glm::dvec3(bent_local[k], bent_local[k + 1], bent_local[k + 2]));
            ASSERT_NEAR(glm::length(w - glm::dvec3(bent_world[k], bent_world[k + 1], bent_world[k + 2])), 0.0, 1e-5)
                << "instance " << i << " vertex " << v;
        }
    }
}

TEST(GltfInstances, CliKeepsTheDocument) {
    const fs::path dir = skybake::test::temp_dir("gltf-instances-cli");
    const fs::path sample = fs::path(skybake::test::assimp_models()) / "glTF2" / "BoxTextured-glTF";
    fs::copy(sample, dir, fs::copy_options::recursive);
    const auto r = skybake::test::run_cli(
        {"ao", (dir / "BoxTextured.gltf").string(), "-o", (dir / "baked.glb").string(), "--rule", "lebedev:50"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const GltfAsset baked = GltfAsset::load(dir / "baked.glb");
    EXPECT_NE(baked.mesh().find_attribute("ao"), nullptr);
    std::ifstream in(dir / "baked.glb", std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::uint32_t json_len;
    std::memcpy(&json_len, data.data() + 12, 4);
    const Json j = Json::parse(data.substr(20, json_len));
    // The .glb carries the box's image: the file travels alone.
    EXPECT_FALSE(j["images"][0].contains("uri")) << j["images"].dump();
    EXPECT_EQ(j["images"][0]["mimeType"], "image/png");
    const Json& view = j["bufferViews"][j["images"][0]["bufferView"].get<std::size_t>()];
    const std::string png = skybake::read_file(dir / "CesiumLogoFlat.png");
    std::uint32_t bin_at = 20 + json_len + 8;
    EXPECT_EQ(view["byteLength"].get<std::size_t>(), png.size());
    EXPECT_EQ(data.substr(bin_at + view["byteOffset"].get<std::size_t>(), png.size()), png);
    EXPECT_EQ(j["materials"].size(), 1u);
    EXPECT_TRUE(j["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
    EXPECT_TRUE(j["meshes"][0]["primitives"][0]["attributes"].contains("_AO"));
    EXPECT_TRUE(j["meshes"][0]["primitives"][0]["attributes"].contains("COLOR_0")); // AO, as the box has none

    const auto c = skybake::test::run_cli(
        {"mesh", "convert", (dir / "BoxTextured.gltf").string(), "-o", (dir / "converted.gltf").string()});
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(load_mesh(dir / "converted.gltf").vertex_count(), baked.mesh().vertex_count());
}
