// End-to-end: `skybake mesh ...` as a user runs it. Labelled "io", so the
// sanitizer build runs these against an ASan + UBSan skybake binary too.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "core/test_paths.h"

using skybake::test::run_cli;
using skybake::test::temp_dir;
namespace fs = std::filesystem;

namespace {
const std::string kModels = skybake::test::assimp_models();

void expect_one_line_error(const skybake::test::CliResult& r, int code = 1) {
    EXPECT_EQ(r.signal, 0) << "crashed with signal " << r.signal;
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
}
} // namespace

TEST(CliMesh, BrokenFilesExitOneWithOneLine) {
    const char* files[] = {"OFF/invalid.off",
                           "glTF2/IndexOutOfRange/IndexOutOfRange.gltf",
                           "glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf",
                           "glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
                           "glTF2/MissingBin/BoxTextured.gltf",
                           "glTF2/SchemaFailures/sceneWrongType.gltf",
                           "glTF2/wrongTypes/badArray.gltf",
                           "invalid/OutOfMemory.off",
                           "invalid/empty.obj",
                           "invalid/malformed.obj",
                           "invalid/emptyIrrMesh.xml"};
    for (const char* f : files) {
        SCOPED_TRACE(f);
        const auto r = run_cli({"mesh", "info", kModels + "/" + f}, 60);
        expect_one_line_error(r);
        EXPECT_NE(r.err.find(f), std::string::npos) << "the error names the file";
    }
}

TEST(CliMesh, EmptyFileAndMissingPath) {
    const std::string dir = temp_dir("cli-empty");
    const std::string empty = dir + "/empty.glb";
    std::ofstream(empty).close();
    expect_one_line_error(run_cli({"mesh", "info", empty}));
    expect_one_line_error(run_cli({"mesh", "info", dir + "/missing.obj"}));
    expect_one_line_error(run_cli({"mesh", "info", "--json", dir + "/missing.obj"}));
}

TEST(CliMesh, UsageErrorsExitTwo) {
    expect_one_line_error(run_cli({"mesh", "info"}), 2);
    expect_one_line_error(run_cli({"mesh", "generate", "--kind", "sphere"}), 2); // no -o
    expect_one_line_error(run_cli({"mesh", "generate", "--triangles", "many", "-o", "x.glb"}), 2);
    expect_one_line_error(run_cli({"mesh", "frobnicate"}), 2);
}

TEST(CliMesh, BadValuesAreUsageErrorsAndMissingFoldersRuntimeErrors) {
    const std::string dir = temp_dir("cli-bad");
    expect_one_line_error(run_cli({"mesh", "generate", "--kind", "teapot", "-o", dir + "/t.glb"}), 2);
    expect_one_line_error(run_cli({"mesh", "generate", "--triangles", "3", "-o", dir + "/t.glb"}), 2);
    expect_one_line_error(run_cli({"mesh", "generate", "-o", dir + "/t.obj"}), 2);
    expect_one_line_error(run_cli({"mesh", "generate", "-o", dir + "/no/such/dir/t.glb"}), 1);
    EXPECT_TRUE(fs::is_empty(dir)) << "no output and no temporary file is left";
}

TEST(CliMesh, GenerateThenInfoAgree) {
    const std::string dir = temp_dir("cli-gen");
    for (const char* ext : {".glb", ".ply"}) {
        const std::string out = dir + "/city" + ext;
        const auto g = run_cli({"mesh", "generate", "--kind", "city", "--triangles", "5000", "-o", out, "--json"});
        ASSERT_EQ(g.exit_code, 0) << g.err;
        const auto gj = nlohmann::json::parse(g.out);
        const auto i = run_cli({"mesh", "info", out, "--json"});
        ASSERT_EQ(i.exit_code, 0) << i.err;
        const auto ij = nlohmann::json::parse(i.out);
        EXPECT_EQ(ij["vertices"], gj["vertices"]);
        EXPECT_EQ(ij["triangles"], gj["triangles"]);
        EXPECT_EQ(ij["degenerate_triangles"], 0);
        EXPECT_TRUE(ij["normals_present"].get<bool>());
        EXPECT_EQ(ij["bounds"]["min"][1], 0.0);
    }
}

TEST(CliMesh, GenerateIsDeterministic) {
    const std::string dir = temp_dir("cli-det");
    for (const char* name : {"a.ply", "b.ply"})
        ASSERT_EQ(run_cli({"mesh", "generate", "--kind", "terrain", "--triangles", "3000", "--seed", "5", "-o",
                           dir + "/" + name})
                      .exit_code,
                  0);
    auto slurp = [](const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    EXPECT_EQ(slurp(dir + "/a.ply"), slurp(dir + "/b.ply"));
}

TEST(CliMesh, ConvertRealMesh) {
    const std::string dir = temp_dir("cli-convert");
    const auto r = run_cli({"mesh", "convert", kModels + "/OBJ/spider.obj", "-o", dir + "/spider.glb", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["triangles"].get<int>(), 1000);
    const auto i = run_cli({"mesh", "info", dir + "/spider.glb", "--json"});
    EXPECT_EQ(nlohmann::json::parse(i.out)["triangles"], j["triangles"]);
}

TEST(CliMesh, QuietSilencesInfo) {
    const std::string dir = temp_dir("cli-quiet");
    const auto r = run_cli({"-q", "mesh", "generate", "-o", dir + "/s.glb"});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_TRUE(r.err.empty()) << r.err;
}
