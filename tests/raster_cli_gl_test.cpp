// skybake ao --backend raster: the depth-buffer backend from the command line
// (headless EGL; Mesa llvmpipe in CI), its JSON summary and its one-line
// errors, with no output file.
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/visibility.h"
#include "skybake/mesh.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;

namespace {

std::string wall_mesh(const std::string& dir) {
    const std::string path = dir + "/wall.glb";
    auto r = run_cli({"mesh", "generate", "--kind", "wall", "--triangles", "300", "-o", path});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return path;
}

void expect_one_line_error(const skybake::test::CliResult& r, int code, const std::string& needle,
                           const std::string& out) {
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

} // namespace

TEST(RasterCli, BakesWithBothMethods) {
    const std::string dir = skybake::test::temp_dir("raster-cli");
    const std::string in = wall_mesh(dir);
    double mean[2] = {0.0, 0.0};
    int i = 0;
    for (const char* method : {"cube", "directional"}) {
        const std::string out = dir + "/wall_" + method + ".glb";
        auto r = run_cli({"ao", in, "-o", out, "--rule", "lebedev:194", "--backend", "raster", "--method", method,
                          "--resolution", "128", "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["backend"], "raster");
        EXPECT_EQ(j["method"], method);
        EXPECT_EQ(j["device"], "opengl");
        EXPECT_EQ(j["resolution"], 128);
        EXPECT_FALSE(j["gpu"].get<std::string>().empty()); // the GL renderer
        const skybake::Mesh m = skybake::load_mesh(out);
        ASSERT_NE(m.find_attribute("ao"), nullptr);
        mean[i++] = j["ao"]["mean"].get<double>();
    }
    // The same scene by the ray tracer: the means agree to a few texels.
    auto r = run_cli({"ao", in, "-o", dir + "/wall_embree.glb", "--rule", "lebedev:194", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const double embree = nlohmann::json::parse(r.out)["ao"]["mean"].get<double>();
    EXPECT_NEAR(mean[0], embree, 0.01);
    EXPECT_NEAR(mean[1], embree, 0.02);
    // The default method is cube, at the resolution the rule asks for: texels
    // no wider than the mean spacing √(4π/N) at a face's centre, a multiple of
    // 8 from 16 up (lebedev:50: spacing 0.50 rad, and π/2 / 16 = 0.098 rad is
    // below it; lebedev:2030: spacing 0.0787, π/2 / 0.0787 = 19.96 → 24;
    // lebedev:5810: spacing 0.0465, π/2 / 0.0465 = 33.8 → 40).
    r = run_cli({"ao", in, "-o", dir + "/wall_default.glb", "--rule", "lebedev:50", "--backend", "raster", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["method"], "cube");
    EXPECT_EQ(j["resolution"], 16);
    EXPECT_EQ(skybake::raster_cube_resolution(50), 16u);
    EXPECT_EQ(skybake::raster_cube_resolution(590), 16u);
    EXPECT_EQ(skybake::raster_cube_resolution(2030), 24u);
    EXPECT_EQ(skybake::raster_cube_resolution(5810), 40u);
    EXPECT_EQ(skybake::raster_cube_resolution(1000000), 256u);
}

TEST(RasterCli, NoOpenGlIsOneLine) {
    const std::string dir = skybake::test::temp_dir("raster-cli-nogl");
    const std::string in = wall_mesh(dir), out = dir + "/x.glb";
    setenv("SKYBAKE_EGL_PLATFORM", "none", 1);
    const auto r = run_cli({"ao", in, "-o", out, "--backend", "raster"});
    unsetenv("SKYBAKE_EGL_PLATFORM");
    expect_one_line_error(r, 1, "raster backend needs OpenGL", out);
}

TEST(RasterCli, FlagsThatDoNotFitAreUsageErrors) {
    const std::string dir = skybake::test::temp_dir("raster-cli-usage");
    const std::string in = wall_mesh(dir), out = dir + "/x.glb";
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--resolution", "64"}), 2, "--resolution", out);
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--backend", "raster", "--method", "bvh"}), 2, "--method", out);
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--method", "cube"}), 2, "raster backend's", out);
    expect_one_line_error(
        run_cli({"ao", in, "-o", out, "--backend", "raster", "--method", "directional", "--max-distance", "1"}), 2,
        "--max-distance", out);
    expect_one_line_error(
        run_cli({"ao", in, "-o", out, "--backend", "raster", "--method", "directional", "--rule", "lebedev:50+rotate"}),
        2, "+rotate", out);
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--backend", "raster", "--resolution", "4"}), 2, "--resolution",
                          out);
}
