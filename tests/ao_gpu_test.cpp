// skybake ao --backend cuda, end to end: every method against the Embree
// backend on a generated mesh and a real one (skipped without a CUDA device).
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "core/gpu_test.h"
#include "core/test_paths.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;

TEST(AoGpuCli, EveryMethodMatchesEmbree) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const std::string dir = skybake::test::temp_dir("ao-gpu-cli");
    const std::string city = dir + "/city.glb";
    ASSERT_EQ(run_cli({"mesh", "generate", "--kind", "city", "--triangles", "5000", "-o", city}).exit_code, 0);
    const std::string spider = skybake::test::assimp_models() + "/OBJ/spider.obj";
    for (const std::string& in : {city, spider}) {
        SCOPED_TRACE(in);
        const std::string rule = "lebedev:1202";
        auto e = run_cli({"ao", in, "-o", dir + "/e.glb", "--rule", rule, "--bits", dir + "/e.bits", "--json"});
        ASSERT_EQ(e.exit_code, 0) << e.err;
        const auto je = nlohmann::json::parse(e.out);
        const skybake::VisibilityBits be = skybake::load_visibility_bits(dir + "/e.bits");
        for (const char* method : {"bvh", "per-vertex", "per-polygon"}) {
            SCOPED_TRACE(method);
            auto g = run_cli({"ao", in, "-o", dir + "/g.glb", "--rule", rule, "--backend", "cuda", "--method", method,
                              "--bits", dir + "/g.bits", "--json"});
            ASSERT_EQ(g.exit_code, 0) << g.err;
            const auto jg = nlohmann::json::parse(g.out);
            EXPECT_EQ(jg["backend"], "cuda");
            EXPECT_EQ(jg["method"], method);
            EXPECT_EQ(jg["device"], "cuda");
            EXPECT_FALSE(jg["gpu"].get<std::string>().empty());
            EXPECT_EQ(jg["rays"], je["rays"]);
            EXPECT_NEAR(jg["ao"]["mean"].get<double>(), je["ao"]["mean"].get<double>(), 1e-4);
            const skybake::VisibilityBits bg = skybake::load_visibility_bits(dir + "/g.bits");
            ASSERT_EQ(bg.words.size(), be.words.size());
            std::uint64_t diff = 0;
            for (std::size_t i = 0; i < bg.words.size(); ++i)
                diff += std::uint64_t(__builtin_popcount(bg.words[i] ^ be.words[i]));
            EXPECT_LE(double(diff), 1e-4 * je["rays"].get<double>());
        }
    }
}
