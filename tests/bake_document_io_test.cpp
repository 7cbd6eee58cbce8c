// One asset writer: `ao` and `prt bake` keep the same document of a user's
// file, apart from the attributes each adds. Run on the sample models a new
// user tries first (a textured box, a skinned and animated model, morph
// targets, the glTF 1.0 milk truck) and on a file Blender exports in the
// test. Label io.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/files.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"
#include "core/test_paths.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

Json document(const fs::path& path) {
    return Json::parse(skybake::test::gltf_json_text(path.string()));
}

// An accessor as its users see it, without where its bytes lie.
Json deref(const Json& doc, const Json& index) {
    Json a = doc["accessors"][index.get<std::size_t>()];
    a.erase("bufferView");
    a.erase("byteOffset");
    return a;
}

// The document with what a bake adds taken out and every accessor reference
// replaced by the accessor itself: the attributes whose name starts with "_"
// and, when `added_color`, COLOR_0; where the bytes lie (buffers, views);
// how the images are stored (embedded or by URI); the generator.
Json normalised(Json doc, bool added_color) {
    const Json src = doc;
    for (Json& mesh : doc["meshes"])
        for (Json& prim : mesh["primitives"]) {
            Json attrs = Json::object();
            for (auto& [k, v] : prim["attributes"].items())
                if (k[0] != '_' && !(added_color && k == "COLOR_0"))
                    attrs[k] = deref(src, v);
            prim["attributes"] = attrs;
            if (prim.contains("indices"))
                prim["indices"] = deref(src, prim["indices"]);
            if (prim.contains("targets"))
                for (Json& t : prim["targets"])
                    for (auto& [k, v] : t.items())
                        v = deref(src, v);
        }
    if (doc.contains("skins"))
        for (Json& s : doc["skins"])
            if (s.contains("inverseBindMatrices"))
                s["inverseBindMatrices"] = deref(src, s["inverseBindMatrices"]);
    if (doc.contains("animations"))
        for (Json& a : doc["animations"])
            for (Json& s : a["samplers"]) {
                s["input"] = deref(src, s["input"]);
                s["output"] = deref(src, s["output"]);
            }
    if (doc.contains("images"))
        for (Json& i : doc["images"]) {
            i.erase("uri");
            i.erase("bufferView");
            i.erase("mimeType");
        }
    for (const char* k : {"accessors", "bufferViews", "buffers"})
        doc.erase(k);
    doc["asset"].erase("generator");
    return doc;
}

bool has_color0(const Json& doc) {
    for (const Json& mesh : doc.value("meshes", Json::array()))
        for (const Json& prim : mesh["primitives"])
            if (prim["attributes"].contains("COLOR_0"))
                return true;
    return false;
}

std::string blender() {
    return skybake::test::blender_path();
}

// A red plane under a cube, as Blender exports them (.glb).
fs::path blender_export(const fs::path& dir) {
    const fs::path script = dir / "make.py", out = dir / "blender.glb";
    std::ofstream(script) << R"(
import bpy, sys
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_plane_add(size=6)
plane = bpy.context.active_object
mat = bpy.data.materials.new("red")
mat.use_nodes = True
mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.9, 0.1, 0.1, 1.0)
plane.data.materials.append(mat)
bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0.5))
bpy.ops.export_scene.gltf(filepath=sys.argv[-1], export_format="GLB")
)";
    const std::string cmd = "'" + blender() + "' -b --factory-startup --python '" + script.string() + "' -- '" +
                            out.string() + "' > '" + out.string() + ".log' 2>&1";
    if (std::system(cmd.c_str()) != 0 || !fs::exists(out))
        return {};
    return out;
}

void expect_same_document(const fs::path& input, const fs::path& dir, bool gltf2) {
    SCOPED_TRACE(input.string());
    const fs::path ao = dir / "ao.glb", prt = dir / "prt.glb";
    const auto a = run_cli({"ao", input.string(), "-o", ao.string(), "--rule", "lebedev:26"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    const auto p = run_cli({"prt", "bake", input.string(), "-o", prt.string(), "--rule", "lebedev:26", "--order", "1"});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const Json da = document(ao), dp = document(prt);
    bool prt_attrs = false;
    for (const Json& mesh : dp["meshes"])
        for (const Json& prim : mesh["primitives"])
            if (prim.value("mode", 4) == 4) {
                EXPECT_TRUE(prim["attributes"].contains("_PRT_0"));
                EXPECT_TRUE(prim["attributes"].contains("COLOR_0")) << "prt bake shows in any viewer";
                prt_attrs = true;
            }
    EXPECT_TRUE(prt_attrs);
    const bool input_color = gltf2 && has_color0(document(input));
    const Json na = normalised(da, !input_color), np = normalised(dp, !input_color);
    EXPECT_EQ(na, np) << Json::diff(na, np).dump();
    if (gltf2) {
        // Both keep the user's document.
        const Json ni = normalised(document(input), false);
        EXPECT_EQ(np, ni) << Json::diff(ni, np).dump();
    }
}

fs::path copy_sample(const std::string& folder, const std::string& file, const fs::path& dir) {
    fs::copy(fs::path(skybake::test::assimp_models()) / folder, dir / "in", fs::copy_options::recursive);
    return dir / "in" / file;
}

} // namespace

TEST(BakeDocument, AoAndPrtBakeKeepTheSameDocumentOfTheSampleModels) {
    struct Sample {
        const char* folder;
        const char* file;
        bool gltf2;
    };
    for (const Sample& s : {Sample{"glTF2/BoxTextured-glTF", "BoxTextured.gltf", true},
                            Sample{"glTF2/simple_skin", "simple_skin.gltf", true},
                            Sample{"glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF", "AnimatedMorphCube.gltf", true},
                            Sample{"glTF/CesiumMilkTruck", "CesiumMilkTruck.gltf", false}}) {
        const fs::path dir = skybake::test::temp_dir(std::string("bake-document-") + fs::path(s.file).stem().string());
        expect_same_document(copy_sample(s.folder, s.file, dir), dir, s.gltf2);
    }
}

TEST(BakeDocument, AoAndPrtBakeKeepTheSameDocumentOfABlenderExport) {
    if (blender().empty())
        GTEST_SKIP() << "no blender (scripts/install-deps.sh installs it)";
    const fs::path dir = skybake::test::temp_dir("bake-document-blender");
    const fs::path in = blender_export(dir);
    ASSERT_FALSE(in.empty()) << skybake::read_file(dir / "blender.glb.log");
    expect_same_document(in, dir, true);
    // The .gltf output of a glTF input, read back with its transfer.
    const auto p = run_cli({"prt", "bake", in.string(), "-o", (dir / "prt.gltf").string(), "--rule", "lebedev:26"});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const skybake::Mesh m = skybake::load_mesh(dir / "prt.gltf");
    EXPECT_NE(m.find_attribute("prt_0"), nullptr);
    ASSERT_EQ(m.colors.size(), m.vertex_count());
    // COLOR_0 of a shadowed transfer is the AO of the same bits: `ao`'s, to rounding.
    const skybake::Mesh a = skybake::load_mesh(dir / "ao.glb");
    const skybake::VertexAttribute* ao = a.find_attribute("ao");
    ASSERT_NE(ao, nullptr);
    ASSERT_EQ(a.vertex_count(), m.vertex_count());
    float lo = 1.0f, worst = 0.0f;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        worst = std::max(worst, std::abs(m.colors[v].r - ao->values[v]));
        lo = std::min(lo, ao->values[v]);
    }
    EXPECT_LT(worst, 1e-5f);
    EXPECT_LT(lo, 0.8f); // the cube's foot is occluded: the check has something to compare

    // Read back, the colours are known as the bake's, and the albedo is the
    // material's: red on the plane, as the bounces saw it.
    const skybake::PrtModel back = skybake::load_prt(dir / "prt.gltf");
    EXPECT_TRUE(back.mesh.colors.empty());
    EXPECT_EQ(back.albedo, skybake::mesh_albedo(back.mesh));
    std::size_t red = 0;
    for (const glm::vec3& c : back.albedo)
        red += std::abs(c.r - 0.9f) < 1e-3f && std::abs(c.g - 0.1f) < 1e-3f && std::abs(c.b - 0.1f) < 1e-3f;
    EXPECT_EQ(red, 4u) << "the plane's four corners";
}
