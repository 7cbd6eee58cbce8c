// The OpenGL planet renderer through the CLI, on the headless EGL context
// (Mesa llvmpipe is enough): `sky render --renderer gl` against
// `--renderer cpu` with the same flags on the seed's eight views, and the bad
// setups (no EGL platform, a shader that does not compile, a corrupt weights
// file): one line on stderr, exit 1, no output file.
//
// Metric: PSNR of the tone-mapped sRGB images (skybake::image_psnr_db, the
// exposure of the CPU image). Per-pixel network, smooth planet: at least 30 dB
// on every view; the planet mesh's silhouette and the float arithmetic of
// the GPU are the only differences. Per vertex (the seed's mode) the sky
// dome interpolates between vertices: reported, and held to 25 dB.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "skybake/neural.h"
#include "skybake/image_io.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

const std::string kData = std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/planet/";

struct View {
    const char* name;
    const char* model;
    const char *altitude, *sun_el, *sun_az, *fov, *pitch;
};

// The seed's views (published_views, section VII) and the two of the dense atmosphere (docs/sky.md).
const View kViews[] = {
    {"1_sea_level", "sky_paper.json", "0", "35", "40", "90", "15"},
    {"2_higher", "sky_paper.json", "5", "35", "40", "90", "5"},
    {"3_higher", "sky_paper.json", "30", "35", "40", "90", "-10"},
    {"4_higher", "sky_paper.json", "120", "35", "40", "90", "-25"},
    {"5_low_sun", "sky_paper.json", "0", "2", "0", "90", "10"},
    {"6_very_high", "sky_paper.json", "1500", "35", "40", "90", "-70"},
    {"7_dense_sea_level", "sky_paper_dense.json", "0", "35", "40", "90", "15"},
    {"8_dense_space", "sky_paper_dense.json", "12000", "35", "40", "60", "-90"},
};

std::vector<std::string> view_args(const View& v, const std::string& out) {
    return {"sky",
            "render",
            "--model",
            kData + v.model,
            "--ground",
            "seed",
            "--altitude-km",
            v.altitude,
            "--sun-elevation-deg",
            v.sun_el,
            "--sun-azimuth-deg",
            v.sun_az,
            "--view",
            "camera",
            "--fov",
            v.fov,
            "--pitch",
            v.pitch,
            "--size",
            "240x160",
            "-o",
            out,
            "-q"};
}

TEST(PlanetCli, GlMatchesCpuOnTheSeedViews) {
    const std::string dir = test::temp_dir("planet_views");
    double min_pixel = 1e9, min_vertex = 1e9;
    for (const View& v : kViews) {
        const std::string cpu = dir + "/" + v.name + "_cpu.exr";
        auto r = run_cli(view_args(v, cpu));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        double psnr[2];
        for (int mode = 0; mode < 2; ++mode) {
            const std::string gl = dir + "/" + v.name + (mode ? "_gl_vertex.exr" : "_gl_pixel.exr");
            auto args = view_args(v, gl);
            args.insert(args.end(), {"--renderer", "gl", "--shading", mode ? "vertex" : "pixel"});
            r = run_cli(args);
            ASSERT_EQ(r.exit_code, 0) << r.err;
            const Image a = load_image(cpu), b = load_image(gl);
            ToneMap tm;
            tm.exposure_ev = float(auto_exposure_ev(a));
            psnr[mode] = image_psnr_db(a, b, tm);
        }
        std::printf("view %-18s gl per pixel %6.2f dB, per vertex %6.2f dB\n", v.name, psnr[0], psnr[1]);
        std::fflush(stdout);
        EXPECT_GE(psnr[0], 30.0) << v.name << " (per pixel)";
        EXPECT_GE(psnr[1], 25.0) << v.name << " (per vertex)";
        min_pixel = std::min(min_pixel, psnr[0]);
        min_vertex = std::min(min_vertex, psnr[1]);
    }
    std::printf("min PSNR: per pixel %.2f dB, per vertex %.2f dB\n", min_pixel, min_vertex);
    std::fflush(stdout);
}

// Renders `args` (a `sky render` command line ending in "-o") with the CPU
// renderer and with `--renderer gl --shading pixel`; the PSNR of the GL image
// (tone-mapped at the CPU image's exposure), or a negative value on failure.
double gl_against_cpu_psnr(std::vector<std::string> args, const std::string& dir) {
    auto cpu = args, gl = args;
    cpu.push_back(dir + "/cpu.exr");
    gl.insert(gl.end(), {dir + "/gl.exr", "--renderer", "gl", "--shading", "pixel"});
    const auto rc = run_cli(cpu);
    EXPECT_EQ(rc.exit_code, 0) << rc.err;
    const auto r = run_cli(gl);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (rc.exit_code != 0 || r.exit_code != 0)
        return -1.0;
    const Image a = load_image(dir + "/cpu.exr"), b = load_image(dir + "/gl.exr");
    ToneMap tm;
    tm.exposure_ev = float(auto_exposure_ev(a));
    return image_psnr_db(a, b, tm);
}

// The reference sum in GLSL against the CPU's sum on the same tables.
TEST(PlanetCli, GlReferenceSumMatchesCpu) {
    const std::string dir = test::temp_dir("planet_reference");
    for (const char* alt : {"0", "1500"}) {
        std::vector<std::string> args = {"sky",
                                         "render",
                                         "--preset",
                                         "paper",
                                         "--ground",
                                         "seed",
                                         "--altitude-km",
                                         alt,
                                         "--sun-elevation-deg",
                                         "20",
                                         "--view",
                                         "camera",
                                         "--pitch",
                                         std::string(alt) == "0" ? "10" : "-60",
                                         "--size",
                                         "160x120",
                                         "-q",
                                         "-o"};
        const double psnr = gl_against_cpu_psnr(args, dir);
        std::printf("reference sum, %s km: gl per pixel %.2f dB\n", alt, psnr);
        std::fflush(stdout);
        EXPECT_GE(psnr, 30.0);
    }
}

std::size_t files_in_count(const std::string& dir) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++n;
    return n;
}

void expect_one_line_failure(const test::CliResult& r, const std::string& out, const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

// Multiple scattering in GLSL (the orders grid, Hillaire's march, the sky
// irradiance on the ground) against the CPU renderer: from the ground at
// sunset (twilight colours, where the multiple part is largest) and from orbit.
TEST(PlanetCli, GlMultipleScatteringMatchesCpu) {
    const std::string dir = test::temp_dir("planet_multiple");
    struct Case {
        const char *method, *alt, *sun, *pitch, *orders;
    };
    for (const Case& c : {Case{"hillaire", "0", "2", "10", nullptr}, Case{"hillaire", "1500", "20", "-60", nullptr},
                          Case{"orders", "1500", "20", "-60", "2"}}) {
        std::vector<std::string> args = {"sky", "render", "--preset", "earth", "--scattering", "multiple",
                                         "--multiple-method", c.method, "--altitude-km", c.alt,
                                         "--sun-elevation-deg", c.sun, "--view", "camera", "--pitch", c.pitch,
                                         "--size", "160x120", "-q"};
        if (c.orders)
            args.insert(args.end(), {"--scattering-orders", c.orders});
        args.push_back("-o");
        const double psnr = gl_against_cpu_psnr(args, dir);
        std::printf("multiple scattering (%s), %s km: gl per pixel %.2f dB\n", c.method, c.alt, psnr);
        std::fflush(stdout);
        EXPECT_GE(psnr, 30.0) << c.method << " " << c.alt;
    }
}

TEST(PlanetCli, NoEglPlatformIsOneLine) {
    const std::string out = test::temp_dir("planet_noegl") + "/x.png";
    auto args = view_args(kViews[0], out);
    args.insert(args.end(), {"--renderer", "gl"});
    setenv("SKYBAKE_EGL_PLATFORM", "none", 1);
    const auto r = run_cli(args);
    unsetenv("SKYBAKE_EGL_PLATFORM");
    expect_one_line_failure(r, out, "no headless OpenGL");
}

TEST(PlanetCli, ShaderThatDoesNotCompileIsOneLine) {
    const std::string out = test::temp_dir("planet_badshader") + "/x.png";
    auto args = view_args(kViews[0], out);
    args.insert(args.end(), {"--renderer", "gl"});
    setenv("SKYBAKE_GL_TEST_BAD_SHADER", "1", 1);
    const auto r = run_cli(args);
    unsetenv("SKYBAKE_GL_TEST_BAD_SHADER");
    expect_one_line_failure(r, out, "shader does not compile");
}

TEST(PlanetCli, CorruptWeightsFileIsOneLine) {
    const std::string dir = test::temp_dir("planet_corrupt");
    {
        std::ofstream f(dir + "/w.json");
        f << "{\"format\": \"skybake-neural-sky\", \"version\": 1, \"weights\": [1, 2, ";
    }
    const std::string out = dir + "/x.png";
    View v = kViews[0];
    auto args = view_args(v, out);
    args[3] = dir + "/w.json";
    args.insert(args.end(), {"--renderer", "gl"});
    expect_one_line_failure(run_cli(args), out, "w.json");
}

TEST(PlanetCli, FlyWritesEveryFrame) {
    const std::string dir = test::temp_dir("planet_fly");
    const auto r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "4", "--size", "64x48", "-o", dir,
                            "--shading", "pixel", "--json", "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (int i = 0; i < 4; ++i) {
        const std::string f = dir + "/frame_000" + std::to_string(i) + ".png";
        ASSERT_TRUE(fs::exists(f)) << f;
        const Image img = load_image(f);
        EXPECT_EQ(img.width, 64);
        double sum = 0.0;
        for (float v : img.rgb)
            sum += v;
        EXPECT_GT(sum, 1.0) << "frame " << i << " is black";
    }
    EXPECT_EQ(files_in_count(dir), 4u);
    EXPECT_NE(r.out.find("\"frames\": 4"), std::string::npos) << r.out;
}

TEST(PlanetCli, FlyCreatesItsOutputFolderAndRemovesItOnFailure) {
    // A command whose output is a folder creates it (as ao --out-dir does),
    // in an existing folder; `frames/` with its slash is the same folder.
    const std::string dir = test::temp_dir("planet_fly_folder");
    const std::string frames = dir + "/frames/";
    ASSERT_FALSE(fs::exists(frames));
    auto r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "2", "--size", "16x12", "-o", frames,
                      "--strip", frames + "strip.png", "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(frames + "frame_0000.png"));
    EXPECT_TRUE(fs::exists(frames + "frame_0001.png"));
    EXPECT_TRUE(fs::exists(frames + "strip.png"));
    // An existing folder is used as it is.
    r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "2", "--size", "16x12", "-o", frames, "-q"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(files_in_count(dir + "/frames"), 3u);
    // A missing parent, or a file in the way, is one line and exit 1.
    r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "2", "--size", "16x12", "-o",
                 dir + "/missing/frames"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/missing"));
    std::ofstream(dir + "/afile") << "x";
    r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "2", "--size", "16x12", "-o", dir + "/afile"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    // A run that fails after creating the folder takes it away again.
    r = run_cli({"fly", "--model", dir + "/no-such-model.json", "--frames", "2", "--size", "16x12", "-o",
                 dir + "/failed"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/failed"));
}

TEST(PlanetCli, FlyBadPathFileIsOneLineAndNoFrames) {
    const std::string dir = test::temp_dir("planet_fly_bad");
    {
        std::ofstream f(dir + "/path.json");
        f << R"({"keyframes": [{"t": 0, "altitude_km": 1}, {"t": 0.5, "altitude_km": -3}]})";
    }
    const std::string out = test::temp_dir("planet_fly_bad_out");
    const auto r = run_cli({"fly", "--model", kData + "sky_paper.json", "--frames", "3", "--size", "32x24", "-o", out,
                            "--path", dir + "/path.json"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find("keyframe 1"), std::string::npos) << r.err;
    EXPECT_EQ(files_in_count(out), 0u);
}

TEST(PlanetCli, GlRefusesWhatItCannotDraw) {
    const std::string out = test::temp_dir("planet_usage") + "/x.png";
    auto r = run_cli({"sky", "render", "--preset", "paper", "--altitude-km", "0", "--sun-elevation-deg", "30", "--view",
                      "fisheye", "--renderer", "gl", "-o", out});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("camera views only"), std::string::npos) << r.err;
    r = run_cli({"sky", "render", "--preset", "paper", "--altitude-km", "0", "--sun-elevation-deg", "30", "--view",
                 "camera", "--shading", "pixel", "-o", out});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

} // namespace
} // namespace skybake
