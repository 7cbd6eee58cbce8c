// skybake ao --texture: the AO texture file, its wiring as the glTF
// material's occlusionTexture, and one-line errors that leave nothing behind.
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/files.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "core/test_paths.h"
#include "skybake/mesh.h"
#include "skybake/texture_bake.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

Json glb_json(const fs::path& path) {
    const std::string data = skybake::read_file(path);
    std::uint32_t len;
    std::memcpy(&len, data.data() + 12, 4);
    return Json::parse(data.substr(20, len));
}

// The bytes of image `index` of a .glb, from its BIN chunk.
std::string glb_image_bytes(const fs::path& path, std::size_t index) {
    const std::string data = skybake::read_file(path);
    std::uint32_t len;
    std::memcpy(&len, data.data() + 12, 4);
    const Json j = Json::parse(data.substr(20, len));
    const std::size_t bin = 20 + len + 8; // the BIN chunk's data, after its length and type
    const Json& view = j["bufferViews"][j["images"][index]["bufferView"].get<std::size_t>()];
    return data.substr(bin + view.value("byteOffset", std::size_t(0)), view["byteLength"].get<std::size_t>());
}

// The milk truck (glTF 1.0, read through Assimp): a textured model whose UVs lie in [0, 1].
fs::path truck(const std::string& name) {
    const fs::path dir = skybake::test::temp_dir(name);
    fs::copy(fs::path(skybake::test::assimp_models()) / "glTF" / "CesiumMilkTruck", dir, fs::copy_options::recursive);
    return dir / "CesiumMilkTruck.gltf";
}

void expect_one_line_and_nothing_written(const skybake::test::CliResult& r, const fs::path& dir,
                                         const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.glb"));
    EXPECT_FALSE(fs::exists(dir / "out_ao.png"));
}

} // namespace

TEST(TextureCli, BakesAndWiresTheOcclusionTexture) {
    const fs::path in = truck("texture-cli");
    const fs::path dir = in.parent_path();
    const auto r =
        run_cli({"ao", in.string(), "-o", (dir / "out.glb").string(), "--texture", "128", "--rule", "lebedev:50",
                 "--preview", (dir / "preview.png").string(), "--preview-size", "160x120", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Json summary = Json::parse(r.out);
    EXPECT_EQ(summary["texture"]["size"], 128);
    EXPECT_GT(summary["texture"]["covered_texels"].get<double>(), 0.0);
    EXPECT_GT(summary["texture"]["texels_per_second"].get<double>(), 0.0);
    EXPECT_TRUE(fs::is_regular_file(dir / "out_ao.png"));
    EXPECT_TRUE(fs::is_regular_file(dir / "preview.png"));
    const skybake::Image ao = skybake::load_image(dir / "out_ao.png");
    EXPECT_EQ(ao.width, 128);

    const Json j = glb_json(dir / "out.glb");
    bool textured = false;
    for (const Json& material : j["materials"]) {
        ASSERT_TRUE(material.contains("occlusionTexture")) << material.dump();
        const std::size_t texture = material["occlusionTexture"]["index"];
        const std::size_t image = j["textures"][texture]["source"];
        // A .glb embeds the image (and the file is written beside it too).
        EXPECT_FALSE(j["images"][image].contains("uri")) << j["images"][image].dump();
        EXPECT_EQ(j["images"][image]["mimeType"], "image/png");
        EXPECT_EQ(glb_image_bytes(dir / "out.glb", image), skybake::read_file(dir / "out_ao.png"));
        EXPECT_EQ(material["occlusionTexture"].value("texCoord", 0), 0); // 0 is the default
        textured |= material["pbrMetallicRoughness"].contains("baseColorTexture");
    }
    EXPECT_TRUE(textured) << "the truck's own texture is still there";

    // A glTF 2.0 input (.glb embeds, .gltf names the file): BlenderAssets.
    // EXR output, named by --texture-out.
    const auto e = run_cli({"ao", in.string(), "-o", (dir / "exr.glb").string(), "--texture", "64", "--rule",
                            "lebedev:50", "--texture-out", (dir / "ao.exr").string()});
    ASSERT_EQ(e.exit_code, 0) << e.err;
    EXPECT_EQ(skybake::load_image(dir / "ao.exr").width, 64);
}

TEST(TextureCli, BadInputsGiveOneLineAndWriteNothing) {
    const fs::path dir = skybake::test::temp_dir("texture-cli-bad");
    // No UVs.
    ASSERT_EQ(run_cli({"mesh", "generate", "--kind", "wall", "--triangles", "200", "-o", (dir / "wall.glb").string()})
                  .exit_code,
              0);
    expect_one_line_and_nothing_written(
        run_cli({"ao", (dir / "wall.glb").string(), "-o", (dir / "out.glb").string(), "--texture", "64"}), dir,
        "no UVs");
    // UVs outside [0, 1].
    std::ofstream(dir / "tiled.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                        "property float z\nproperty float s\nproperty float t\nelement face 1\n"
                                        "property list uchar int vertex_indices\nend_header\n"
                                        "0 0 0 0 0\n1 0 0 2 0\n0 1 0 0 1\n3 0 1 2\n";
    expect_one_line_and_nothing_written(
        run_cli({"ao", (dir / "tiled.ply").string(), "-o", (dir / "out.glb").string(), "--texture", "64"}), dir,
        "outside [0, 1]");
    // UVs that cover nothing: every vertex at the same UV.
    std::ofstream(dir / "flat_uv.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                          "property float y\nproperty float z\nproperty float s\nproperty float t\n"
                                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                          "0 0 0 0.5 0.5\n1 0 0 0.5 0.5\n0 1 0 0.5 0.5\n3 0 1 2\n";
    expect_one_line_and_nothing_written(
        run_cli({"ao", (dir / "flat_uv.ply").string(), "-o", (dir / "out.glb").string(), "--texture", "64"}), dir,
        "covers no texel");
}

// A texture size out of range, 0 included, is a usage error (exit 2) that
// names the flag, before any file is read.
TEST(TextureCli, SizesOutOfRangeAreUsageErrors) {
    const fs::path dir = skybake::test::temp_dir("texture-cli-size");
    const fs::path in = truck("texture-cli-size-in");
    for (const char* size : {"0", "8", "15", "16385", "99999", "-64"}) {
        const auto r = run_cli({"ao", in.string(), "-o", (dir / "out.glb").string(), "--texture", size});
        EXPECT_EQ(r.exit_code, 2) << size << ": " << r.err;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find("--texture"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / "out.glb"));
        EXPECT_FALSE(fs::exists(dir / "out_ao.png"));
    }
}

// Split vertices of a real asset (the same point, other UVs) read the texture
// alike once the seams are stitched: the baked texture is read at both UVs of
// every such pair with sample_texture(), apart from the stitcher's own report.
TEST(TextureCli, SplitVerticesReadTheSameAoAcrossUvSeams) {
    const fs::path in = truck("texture-cli-seams");
    const fs::path dir = in.parent_path();
    auto mismatch = [&](const std::string& name, bool keep) {
        std::vector<std::string> args = {"ao", in.string(), "-o", (dir / (name + ".glb")).string(), "--texture",
                                         "256", "--rule", "lebedev:50", "--texture-out",
                                         (dir / (name + ".exr")).string()};
        if (keep)
            args.push_back("--keep-seams");
        const auto r = run_cli(args);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        const skybake::Mesh mesh = skybake::load_mesh(dir / (name + ".glb"));
        const skybake::Image image = skybake::load_image(dir / (name + ".exr"));
        skybake::AoTexture t;
        t.texture_size = image.width;
        for (int k = 0; k < image.width * image.height; ++k)
            t.ao.push_back(image.rgb[3 * std::size_t(k)]);
        std::map<std::tuple<float, float, float>, std::vector<std::size_t>> at;
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
            at[{mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z}].push_back(v);
        const auto& uv = mesh.texcoords.at(0);
        double sum = 0.0;
        std::size_t pairs = 0;
        for (const auto& [p, vs] : at)
            for (std::size_t i = 0; i < vs.size(); ++i)
                for (std::size_t j = i + 1; j < vs.size(); ++j)
                    if (uv[vs[i]] != uv[vs[j]]) {
                        sum += std::abs(skybake::sample_texture(t, uv[vs[i]]) - skybake::sample_texture(t, uv[vs[j]]));
                        ++pairs;
                    }
        EXPECT_GT(pairs, 100u);
        return sum / double(pairs);
    };
    const double kept = mismatch("kept", true), stitched = mismatch("stitched", false);
    // Measured at 512²: 0.217 as traced, 0.009 stitched.
    EXPECT_GT(kept, 0.05);
    EXPECT_LT(stitched, 0.2 * kept);
}
