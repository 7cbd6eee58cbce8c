// Files as Blender writes them, made in the test with `blender -b`, through the
// commands a technical artist runs first: the texture bake into the user's
// glTF. Label io, so that the sanitizer build (make test-sanitize) runs the
// CLI under AddressSanitizer on them.
//
// Blender's exports are the common case the sample models miss: untextured
// materials (no "images", "textures" or "samplers" arrays), or no material at
// all (no "materials" array), with Smart UV Project's islands.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/files.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "skybake/texture_bake.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

// Suzanne with Smart UV Project (tests/data/blender/make_suzanne.py, which
// the web package's glTF validator test runs too).
const fs::path kBlenderScript = fs::path(SKYBAKE_SOURCE_DIR) / "tests/data/blender/make_suzanne.py";

std::string blender() {
    return skybake::test::blender_path();
}

// Runs Blender to write `out`; false (with the reason in `why`) when it fails.
bool make_suzanne(const fs::path& out, const std::string& kind, std::string& why) {
    const std::string cmd = "'" + blender() + "' -b --factory-startup --python '" + kBlenderScript.string() + "' -- '" +
                            out.string() + "' " + kind + " > '" + out.string() + ".log' 2>&1";
    if (std::system(cmd.c_str()) != 0 || !fs::exists(out)) {
        why = skybake::read_file(out.string() + ".log");
        return false;
    }
    return true;
}

Json document(const fs::path& path) {
    return Json::parse(skybake::test::gltf_json_text(path.string()));
}

struct Case {
    const char* kind;   // "bare" or "material"
    const char* input;  // file name Blender writes
    const char* output; // file name skybake writes
};

class BlenderAssets : public ::testing::TestWithParam<Case> {};

} // namespace

// Every run of the same bake succeeds and writes the same bytes; the output
// has one AO image and texture, and every triangle primitive's material reads
// it as its occlusionTexture through the UV set the bake used.
TEST_P(BlenderAssets, TextureBakeWiresOneOcclusionTextureEveryRun) {
    if (blender().empty())
        GTEST_SKIP() << "no blender (scripts/install-deps.sh installs it)";
    const Case c = GetParam();
    const fs::path dir = skybake::test::temp_dir(std::string("blender-assets-") + c.kind + "-" + c.output);
    const fs::path in = dir / c.input;
    std::string why;
    ASSERT_TRUE(make_suzanne(in, c.kind, why)) << why;
    {
        const Json src = document(in);
        ASSERT_FALSE(src.contains("images")) << "the export is not the case this test is for";
        ASSERT_FALSE(src.contains("textures"));
        ASSERT_EQ(src.contains("materials"), std::string(c.kind) == "material");
    }
    std::string first;
    for (const int size : {64, 100, 64}) {
        const fs::path out = dir / c.output;
        const auto r = run_cli({"ao", in.string(), "-o", out.string(), "--texture", std::to_string(size), "--rule",
                                "lebedev:86"},
                               300);
        ASSERT_EQ(r.exit_code, 0) << "size " << size << ": " << r.err;
        const Json doc = document(out);
        ASSERT_TRUE(doc.contains("images")) << doc.dump();
        ASSERT_EQ(doc["images"].size(), 1u) << doc["images"].dump();
        ASSERT_EQ(doc["textures"].size(), 1u) << doc["textures"].dump();
        EXPECT_EQ(doc["textures"][0]["source"], 0);
        // A .glb embeds the image, named after the file written beside it.
        const Json& entry = doc["images"][0];
        EXPECT_EQ(entry.contains("bufferView"), out.extension() == ".glb") << entry.dump();
        const fs::path image = dir / entry.value("uri", entry.value("name", std::string()));
        ASSERT_TRUE(fs::exists(image)) << image;
        const skybake::Image ao = skybake::load_image(image);
        EXPECT_EQ(ao.width, size);
        EXPECT_EQ(ao.height, size);
        ASSERT_FALSE(doc["materials"].empty()) << doc.dump();
        int primitives = 0;
        for (const Json& mesh : doc["meshes"])
            for (const Json& prim : mesh["primitives"]) {
                ++primitives;
                ASSERT_TRUE(prim.contains("material")) << prim.dump();
                const Json& mat = doc["materials"][prim["material"].get<std::size_t>()];
                ASSERT_TRUE(mat.contains("occlusionTexture")) << mat.dump();
                EXPECT_EQ(mat["occlusionTexture"]["index"], 0);
                EXPECT_EQ(mat["occlusionTexture"]["texCoord"], 0);
                EXPECT_TRUE(prim["attributes"].contains("TEXCOORD_0"));
            }
        EXPECT_GE(primitives, 1);
        if (std::string(c.kind) == "material")
            EXPECT_EQ(doc["materials"][0]["name"], "Clay") << "the user's material was replaced";
        const std::string bytes = skybake::read_file(out);
        if (size == 64) {
            if (first.empty())
                first = bytes;
            else
                EXPECT_EQ(bytes, first) << "two runs of the same bake wrote different files";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(, BlenderAssets,
                         ::testing::Values(Case{"bare", "plain.glb", "out.glb"}, Case{"bare", "plain.glb", "out.gltf"},
                                           Case{"material", "clay.glb", "out.glb"},
                                           Case{"material", "clay.gltf", "out.gltf"}),
                         [](const auto& info) {
                             std::string name = std::string(info.param.kind) + "_" + info.param.input + "_to_" +
                                                info.param.output;
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch)))
                                     ch = '_';
                             return name;
                         });

// Smart UV Project cuts Suzanne into islands: the two (or more) vertices that
// Blender writes for one point on a cut read the baked texture alike once the
// seams are stitched. Pairs are counted where they share a 3D edge (a seam);
// Suzanne's eyes touch her head at points that are not on one surface, and
// their AO differs truly. Measured at 512², lebedev:86: 0.089 mean, 0.35 at the
// 95th percentile, 0.88 at most as traced; 3e-4 mean, 3e-4 at the 95th
// percentile, 0.027 at most stitched.
TEST(BlenderSeams, SplitVerticesOfSmartUvIslandsReadTheSameAo) {
    if (blender().empty())
        GTEST_SKIP() << "no blender (scripts/install-deps.sh installs it)";
    const fs::path dir = skybake::test::temp_dir("blender-assets-seams");
    const fs::path in = dir / "plain.glb";
    std::string why;
    ASSERT_TRUE(make_suzanne(in, "bare", why)) << why;
    auto stats = [&](bool keep) {
        const fs::path out = dir / (keep ? "kept.glb" : "stitched.glb");
        const fs::path exr = dir / (keep ? "kept.exr" : "stitched.exr");
        std::vector<std::string> args = {"ao",        in.string(), "-o",       out.string(), "--texture",
                                         "512",       "--rule",    "lebedev:86", "--texture-out", exr.string()};
        if (keep)
            args.push_back("--keep-seams");
        const auto r = run_cli(args, 300);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        const skybake::Mesh mesh = skybake::load_mesh(out);
        const skybake::Image image = skybake::load_image(exr);
        skybake::AoTexture t;
        t.texture_size = image.width;
        for (int k = 0; k < image.width * image.height; ++k)
            t.ao.push_back(image.rgb[3 * std::size_t(k)]);
        // Weld by position; a vertex's neighbours are welded points.
        std::map<std::array<float, 3>, std::uint32_t> ids;
        std::vector<std::uint32_t> weld(mesh.vertex_count());
        for (std::size_t v = 0; v < weld.size(); ++v) {
            const auto& p = mesh.positions[v];
            weld[v] = ids.emplace(std::array<float, 3>{p.x, p.y, p.z}, std::uint32_t(ids.size())).first->second;
        }
        std::vector<std::set<std::uint32_t>> neighbours(mesh.vertex_count());
        std::vector<std::vector<std::size_t>> at(ids.size());
        for (std::size_t v = 0; v < weld.size(); ++v)
            at[weld[v]].push_back(v);
        for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
            const std::size_t tri = i / 3 * 3;
            const std::uint32_t a = mesh.indices[i], b = mesh.indices[tri + (i - tri + 1) % 3];
            neighbours[a].insert(weld[b]);
            neighbours[b].insert(weld[a]);
        }
        const auto& uv = mesh.texcoords.at(0);
        std::vector<double> d;
        for (const auto& vs : at)
            for (std::size_t i = 0; i < vs.size(); ++i)
                for (std::size_t j = i + 1; j < vs.size(); ++j) {
                    const std::size_t a = vs[i], b = vs[j];
                    if (uv[a] == uv[b])
                        continue;
                    std::vector<std::uint32_t> common;
                    std::set_intersection(neighbours[a].begin(), neighbours[a].end(), neighbours[b].begin(),
                                          neighbours[b].end(), std::back_inserter(common));
                    if (!common.empty())
                        d.push_back(std::abs(skybake::sample_texture(t, uv[a]) - skybake::sample_texture(t, uv[b])));
                }
        EXPECT_GT(d.size(), 500u);
        std::sort(d.begin(), d.end());
        const double mean = std::accumulate(d.begin(), d.end(), 0.0) / double(std::max<std::size_t>(d.size(), 1));
        const double p95 = d.empty() ? 0.0 : d[d.size() * 95 / 100];
        return std::array<double, 3>{mean, p95, d.empty() ? 0.0 : d.back()};
    };
    const auto kept = stats(true), stitched = stats(false);
    EXPECT_GT(kept[0], 0.03) << "the layout has no visible seams to stitch";
    EXPECT_LT(stitched[0], 0.002);
    EXPECT_LT(stitched[1], 0.005);
    EXPECT_LT(stitched[2], 0.06);
}
