// skybake prt bake / prt relight / sky sh: outputs (attributes, sidecar,
// radiance properties, image, light file), and bad input: one line on stderr,
// a non-zero exit and no output file.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/bake.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"

using skybake::test::run_cli;
namespace fs = std::filesystem;

namespace {

std::string city(const std::string& dir) {
    const std::string path = dir + "/city.glb";
    const auto r = run_cli({"mesh", "generate", "--kind", "city", "--triangles", "1500", "-o", path});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return path;
}

void expect_refused(const skybake::test::CliResult& r, int code, const std::string& needle) {
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
}

} // namespace

TEST(PrtCli, BakeRelightPlyAndPng) {
    const std::string dir = skybake::test::temp_dir("prt-cli");
    const std::string in = city(dir), out = dir + "/city_prt.glb";
    auto r = run_cli({"prt", "bake", in, "-o", out, "--order", "2", "--rule", "lebedev:194", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["coefficients"], 9);
    EXPECT_EQ(j["kind"], "shadowed");
    ASSERT_TRUE(fs::exists(dir + "/city_prt.prt.json"));
    const skybake::Mesh baked = skybake::load_mesh(out);
    for (const char* a : {"prt_0", "prt_1", "prt_2", "albedo", "shading"})
        EXPECT_NE(baked.find_attribute(a), nullptr) << a;
    EXPECT_EQ(baked.find_attribute("prt_3"), nullptr);

    // Constant light 1, albedo 0.8 (no vertex colours): radiance = 0.8 AO.
    const std::string ply = dir + "/lit.ply";
    r = run_cli({"prt", "relight", out, "--light", "constant", "-o", ply});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const skybake::Mesh lit = skybake::load_mesh(ply);
    const auto* red = lit.find_attribute("radiance_r");
    ASSERT_NE(red, nullptr);
    ASSERT_NE(lit.find_attribute("radiance_b"), nullptr);
    skybake::Mesh ao_mesh = skybake::load_mesh(in);
    skybake::bake_ambient_occlusion(ao_mesh, skybake::parse_rule("lebedev:194"));
    const auto* ao = ao_mesh.find_attribute("ao");
    ASSERT_EQ(ao->values.size(), red->values.size());
    for (std::size_t v = 0; v < red->values.size(); ++v)
        ASSERT_NEAR(red->values[v], 0.8f * ao->values[v], 1e-5f) << v;

    // The sky with the sun, as an image; and as a light file.
    const std::string png = dir + "/noon.png";
    r = run_cli({"prt", "relight", out, "--light", "sky", "--sun-elevation-deg", "60", "--size", "96x72", "-o", png});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const skybake::Image img = skybake::load_image(png);
    EXPECT_EQ(img.width, 96);
    const std::string light = dir + "/light.json";
    r = run_cli({"sky", "sh", "--sun-elevation-deg", "10", "--order", "2", "-o", light});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const skybake::ShLight l = skybake::load_light(light);
    EXPECT_EQ(l.order, 2);
    EXPECT_GT(l.coeffs[0].x, 0.0f);
    EXPECT_GT(l.sun_irradiance.x, l.sun_irradiance.z); // a low sun is red
    r = run_cli({"prt", "relight", out, "--light", light, "-o", dir + "/lit2.ply"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    // The same light in the Condon-Shortley convention: odd-|m| coefficients
    // negated in the file (l = 1, m = +-1: indices 1 and 3; l = 2, m = +-1: 5
    // and 7), the others equal, and the same light once loaded.
    const std::string cs = dir + "/light_cs.json";
    r = run_cli({"sky", "sh", "--sun-elevation-deg", "10", "--order", "2", "--sh-convention", "condon-shortley", "-o",
                 cs});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    {
        const auto raw = [](const std::string& path) {
            std::ifstream f(path);
            return nlohmann::json::parse(f);
        };
        const nlohmann::json a = raw(light), b = raw(cs);
        EXPECT_EQ(b["sh_convention"], "condon-shortley");
        for (int i = 0; i < 9; ++i) {
            const double sign = (i == 1 || i == 3 || i == 5 || i == 7) ? -1.0 : 1.0;
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(b["coefficients"][i][c].get<double>(), sign * a["coefficients"][i][c].get<double>()) << i;
        }
        EXPECT_EQ(skybake::load_light(cs).coeffs, l.coeffs);
    }
    expect_refused(run_cli({"sky", "sh", "--sh-convention", "d3dx", "-o", dir + "/bad.json"}), 2, "--sh-convention");
    EXPECT_FALSE(fs::exists(dir + "/bad.json"));
    // The GLSL, with the order of the sidecar.
    r = run_cli({"prt", "export", out, "-o", dir + "/prt.glsl"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream g(dir + "/prt.glsl");
    const std::string glsl((std::istreambuf_iterator<char>(g)), {});
    EXPECT_NE(glsl.find("vec3 skybake_prt_diffuse(vec4 prt[3], vec3 light[9], vec3 albedo)"), std::string::npos);
    r = run_cli({"prt", "export", out, "--order", "2", "-o", dir + "/x.glsl"});
    expect_refused(r, 2, "--order");
    EXPECT_FALSE(fs::exists(dir + "/x.glsl"));
    // A name that would break the shader, as sky export refuses it.
    r = run_cli({"prt", "export", out, "--name", "x(); } evil {", "-o", dir + "/x.glsl"});
    expect_refused(r, 2, "--name");
    EXPECT_FALSE(fs::exists(dir + "/x.glsl"));
}

TEST(PrtCli, BadInput) {
    const std::string dir = skybake::test::temp_dir("prt-cli-bad");
    const std::string in = city(dir), out = dir + "/o.glb";
    // Order out of range: a usage error.
    auto r = run_cli({"prt", "bake", in, "-o", out, "--order", "9"});
    expect_refused(r, 2, "--order");
    r = run_cli({"prt", "bake", in, "-o", out, "--kind", "interreflected"});
    expect_refused(r, 2, "--bounces");
    r = run_cli({"prt", "bake", in, "-o", out, "--albedo", "1.5"});
    expect_refused(r, 2, "--albedo");
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(dir + "/o.prt.json"));

    ASSERT_EQ(run_cli({"prt", "bake", in, "-o", out, "--rule", "lebedev:50"}).exit_code, 0);
    // A corrupt sidecar.
    const std::string side = dir + "/o.prt.json";
    std::ofstream(side) << "{\"format\": \"skybake-prt\",";
    r = run_cli({"prt", "relight", out, "--light", "constant", "-o", dir + "/x.ply"});
    expect_refused(r, 1, "sidecar");
    EXPECT_FALSE(fs::exists(dir + "/x.ply"));
    // A mismatched one: another mesh's.
    ASSERT_EQ(run_cli({"prt", "bake", in, "-o", out, "--rule", "lebedev:50"}).exit_code, 0);
    ASSERT_EQ(run_cli({"mesh", "convert", in, "-o", out}).exit_code, 0);
    r = run_cli({"prt", "relight", out, "--light", "constant", "-o", dir + "/x.ply"});
    expect_refused(r, 1, "sidecar");
    // A map that is not a map.
    ASSERT_EQ(run_cli({"prt", "bake", in, "-o", out, "--rule", "lebedev:50"}).exit_code, 0);
    const std::string fake = dir + "/map.exr";
    std::ofstream(fake) << "not an image";
    r = run_cli({"prt", "relight", out, "--light", fake, "-o", dir + "/x.ply"});
    expect_refused(r, 1, "--light");
    skybake::save_image(fake, skybake::Image(16, 16)); // square: not equirectangular
    r = run_cli({"prt", "relight", out, "--light", fake, "-o", dir + "/x.ply"});
    expect_refused(r, 1, "twice as wide");
    EXPECT_FALSE(fs::exists(dir + "/x.ply"));
    r = run_cli({"sky", "sh", "--order", "9", "-o", dir + "/l.json"});
    expect_refused(r, 2, "--order");
    EXPECT_FALSE(fs::exists(dir + "/l.json"));
}
