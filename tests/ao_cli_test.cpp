// skybake ao: outputs (glTF/PLY attributes, preview, visibility bits), the
// JSON summary, determinism, and one-line errors with no output file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/mesh.h"
#include "skybake/image_io.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// A generated mesh, written once per test binary run.
std::string wall_mesh(const std::string& dir) {
    const std::string path = dir + "/wall.glb";
    auto r = run_cli({"mesh", "generate", "--kind", "wall", "--triangles", "2000", "-o", path});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return path;
}

void expect_one_line_error(const skybake::test::CliResult& r, int code, const std::string& needle) {
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
}

} // namespace

TEST(AoCli, BakesGlbWithAttributesAndJson) {
    const std::string dir = skybake::test::temp_dir("ao-cli-glb");
    const std::string in = wall_mesh(dir), out = dir + "/wall_ao.glb", png = dir + "/wall_ao.png";
    auto r = run_cli({"ao", in, "-o", out, "--rule", "lebedev:194", "--preview", png, "--preview-size", "160x120",
                      "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["backend"], "embree");
    EXPECT_EQ(j["rule"], "lebedev:194");
    EXPECT_EQ(j["directions"], 194);
    const skybake::Mesh src = skybake::load_mesh(in);
    EXPECT_EQ(j["vertices"].get<std::size_t>(), src.vertex_count());
    EXPECT_GT(j["rays"].get<double>(), 0.0);
    // Every vertex traces its directions on or above the horizon: about half.
    EXPECT_NEAR(j["rays"].get<double>() / (194.0 * double(src.vertex_count())), 0.55, 0.06);
    EXPECT_GT(j["seconds"].get<double>(), 0.0);
    EXPECT_NEAR(j["rays_per_second"].get<double>(),
                j["rays"].get<double>() / j["trace_seconds"].get<double>(), 1e-6 * j["rays_per_second"].get<double>());
    EXPECT_TRUE(j["max_distance"].is_null());
    EXPECT_EQ(j["ray_offset"].get<double>(), 0.0); // the default: no offset beyond the step past rounding
    EXPECT_GT(j["ao"]["min"].get<double>(), 0.3);
    EXPECT_LE(j["ao"]["max"].get<double>(), 1.0);

    // glTF: _AO, _SHADING, _BENT_NORMAL and COLOR_0 (= AO, grey).
    const std::string glb = slurp(out);
    for (const char* name : {"\"_AO\"", "\"_SHADING\"", "\"_BENT_NORMAL\"", "\"COLOR_0\""})
        EXPECT_NE(glb.find(name), std::string::npos) << name;
    const skybake::Mesh baked = skybake::load_mesh(out);
    const auto* ao = baked.find_attribute("ao");
    ASSERT_TRUE(ao);
    ASSERT_TRUE(baked.find_attribute("shading"));
    ASSERT_EQ(baked.find_attribute("bent_normal")->components, 3);
    ASSERT_EQ(baked.colors.size(), baked.vertex_count());
    for (std::size_t v = 0; v < baked.vertex_count(); ++v)
        EXPECT_NEAR(baked.colors[v].r, ao->values[v], 1e-6f);

    // Preview PNG.
    const skybake::Image img = skybake::load_image(png);
    EXPECT_EQ(img.width, 160);
    EXPECT_EQ(img.height, 120);
}

TEST(AoCli, PlyPropertiesAndBitsFile) {
    const std::string dir = skybake::test::temp_dir("ao-cli-ply");
    const std::string in = wall_mesh(dir), out = dir + "/wall_ao.ply", bits = dir + "/wall.bin";
    auto r = run_cli({"ao", in, "-o", out, "--rule", "lebedev:50+rotate", "--bits", bits, "--max-distance", "0.5",
                      "--back-faces", "ignore", "--normalize", "--offset", "0.001"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.out.empty());
    const std::string ply = slurp(out);
    for (const char* name : {"property float ao", "property float shading", "property float bent_normal_x"})
        EXPECT_NE(ply.find(name), std::string::npos) << name;
    const skybake::VisibilityBits vb = skybake::load_visibility_bits(bits);
    EXPECT_EQ(vb.rule, "lebedev:50+rotate");
    EXPECT_EQ(vb.directions, 50u);
    EXPECT_EQ(vb.words_per_vertex, 2u);
    const skybake::Mesh baked = skybake::load_mesh(out);
    EXPECT_EQ(vb.vertices, baked.vertex_count());
    // The bits reproduce the stored AO (normalised, as baked).
    const skybake::SphereRule rule = skybake::parse_rule(vb.rule);
    const auto* ao = baked.find_attribute("ao");
    for (std::uint32_t v = 0; v < baked.vertex_count(); v += 11) {
        const auto c = skybake::shading_from_bits(std::span(vb.words).subspan(v * 2, 2), rule, v,
                                                  skybake::load_mesh(in).normals[v], true);
        EXPECT_NEAR(c.ao, ao->values[v], 1e-6f);
    }
}

TEST(AoCli, SameOutputWhateverTheThreadCount) {
    const std::string dir = skybake::test::temp_dir("ao-cli-threads");
    const std::string in = wall_mesh(dir);
    ASSERT_EQ(run_cli({"ao", in, "-o", dir + "/a.glb", "--rule", "lebedev:302+rotate", "--threads", "1"}).exit_code, 0);
    ASSERT_EQ(run_cli({"ao", in, "-o", dir + "/b.glb", "--rule", "lebedev:302+rotate"}).exit_code, 0);
    EXPECT_EQ(slurp(dir + "/a.glb"), slurp(dir + "/b.glb"));
}

TEST(AoCli, BadInputIsOneLineAndNoOutput) {
    const std::string dir = skybake::test::temp_dir("ao-cli-errors");
    const std::string in = wall_mesh(dir), out = dir + "/out.glb";
    expect_one_line_error(run_cli({"ao", dir + "/missing.obj", "-o", out}), 1, "missing.obj");
    // A bad flag value is a usage error: exit 2, naming the flag.
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--rule", "lebedev:500"}), 2, "lebedev");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--rule", "phong:a=4,n=3"}), 2, "Phong");
    if (skybake::cuda_device_count() == 0) { // no GPU, or a build without CUDA: a runtime error
        expect_one_line_error(run_cli({"ao", in, "-o", out, "--device", "cuda"}), 1, "on the CPU");
        expect_one_line_error(run_cli({"ao", in, "-o", out, "--backend", "cuda"}), 1, "on the CPU");
    }
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--method", "per-vertex"}), 2, "cuda backend's");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--device", "cuda", "--method", "octree"}), 2, "--method");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--backend", "optix"}), 2, "--backend");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--device", "cuda", "--backend", "embree"}), 2, "--device");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--device", "tpu"}), 2, "--device");
    expect_one_line_error(run_cli({"ao", in, "-o", dir + "/out.obj"}), 2, "--output");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--preview", dir + "/p.jpg"}), 2, "--preview");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--preview", dir + "/p.png", "--preview-size", "0x5"}), 2,
                          "--preview-size");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--preview-size", "64x64"}), 2, "without --preview");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--max-distance", "0"}), 2, "--max-distance");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--offset", "-3"}), 2, "--offset");
    expect_one_line_error(run_cli({"ao", in, "-o", out, "--back-faces", "cull"}), 2, "--back-faces");
    // Brute force refuses a large mesh.
    const std::string big = dir + "/big.glb";
    ASSERT_EQ(run_cli({"mesh", "generate", "--kind", "sphere", "--triangles", "40000", "-o", big}).exit_code, 0);
    expect_one_line_error(run_cli({"ao", big, "-o", out, "--backend", "brute"}), 1, "brute-force");
    // A corrupt file.
    {
        std::ofstream f(dir + "/broken.ply", std::ios::binary);
        f << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nend_header\n\x01";
    }
    expect_one_line_error(run_cli({"ao", dir + "/broken.ply", "-o", out}), 1, "broken.ply");
    // Usage errors exit 2.
    EXPECT_EQ(run_cli({"ao", in}).exit_code, 2);
    EXPECT_EQ(run_cli({"ao"}).exit_code, 2);
    EXPECT_EQ(run_cli({"ao", in, "-o", out, "--no-such-flag"}).exit_code, 2);
    EXPECT_FALSE(fs::exists(out));
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        EXPECT_TRUE(name == "wall.glb" || name == "big.glb" || name == "broken.ply") << "left behind: " << name;
    }
}

// Finite values beyond the tracers' range (skybake/bake.h kMaxTraceCoordinate,
// kMaxRayOffset): Embree aborts on rays that start beyond ±1.8e18, so they are
// refused first, a flag with exit 2 and a file with exit 1. The largest values
// taken still bake.
TEST(AoCli, ValuesBeyondTheTracersRangeAreRefused) {
    const std::string dir = skybake::test::temp_dir("ao-cli-range");
    const std::string in = wall_mesh(dir), out = dir + "/out.glb";
    for (const char* offset : {"2e18", "1e20", "1.1e17"})
        expect_one_line_error(run_cli({"ao", in, "-o", out, "--offset", offset}), 2, "--offset");
    EXPECT_EQ(run_cli({"ao", in, "-o", out, "--offset", "1e17", "--rule", "lebedev:6"}).exit_code, 0);
    fs::remove(out);
    // A tetrahedron around 1e19 (finite floats, beyond the range), and one at 1e17 (inside).
    const auto tetra = [&](const std::string& name, const char* scale) {
        const std::string path = dir + "/" + name;
        std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                               "end_header\n0 0 0\n" << scale << " 0 0\n0 " << scale << " 0\n0 0 " << scale
                            << "\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
        return path;
    };
    const std::string huge = tetra("huge.ply", "1e19"), large = tetra("large.ply", "5e16");
    expect_one_line_error(run_cli({"ao", huge, "-o", out}), 1, "coordinate reaches");
    expect_one_line_error(run_cli({"prt", "bake", huge, "-o", dir + "/out_prt.glb", "--rule", "lebedev:6"}), 1,
                          "coordinate reaches");
    EXPECT_FALSE(fs::exists(dir + "/out_prt.glb"));
    const auto r = run_cli({"ao", large, "-o", out, "--rule", "lebedev:26", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const skybake::Mesh baked = skybake::load_mesh(out);
    const skybake::VertexAttribute* ao = baked.find_attribute("ao");
    ASSERT_NE(ao, nullptr);
    for (float v : ao->values) // a convex tetrahedron's vertices see their whole hemisphere
        EXPECT_GT(v, 0.5f);
}

TEST(AoCli, BruteForceBackendAgreesOnASmallMesh) {
    const std::string dir = skybake::test::temp_dir("ao-cli-brute");
    const std::string in = dir + "/wall.glb";
    ASSERT_EQ(run_cli({"mesh", "generate", "--kind", "wall", "--triangles", "200", "-o", in}).exit_code, 0);
    auto a = run_cli({"ao", in, "-o", dir + "/e.glb", "--rule", "lebedev:110+rotate", "--json"});
    auto b = run_cli({"ao", in, "-o", dir + "/b.glb", "--rule", "lebedev:110+rotate", "--backend", "brute", "--json"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
    EXPECT_EQ(jb["backend"], "brute");
    EXPECT_EQ(ja["rays"], jb["rays"]);
    EXPECT_NEAR(ja["ao"]["mean"].get<double>(), jb["ao"]["mean"].get<double>(), 1e-3);
}
