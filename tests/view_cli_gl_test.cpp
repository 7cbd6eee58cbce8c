// `skybake view MODEL --screenshot` on the headless EGL context (Mesa
// llvmpipe is enough): the 2CylinderEngine model (Khronos glTF sample, as
// Debian's assimp-testmodels ships it), baked with `skybake prt bake`, under
// the dense paper atmosphere's network at noon, at sunset and at night; the
// exposure setting; the match with `skybake prt relight` (the C++ twin of
// the shader: relight() and the ray-cast preview on the same camera); and the
// models it must handle: no normals, no transfer, a broken file, no OpenGL;
// the reference sky as the background (against SkySource::evaluate along
// each pixel's ray), the DPRT glossy layer (against `prt relight --glossy`,
// the C++ twin) and the sun's shadow map (against per-vertex rays and the
// unshadowed sun).
//
// The tests written for the per-vertex sun (the twin relight() casts one
// ray per vertex) view with shadow=vertex; the shadow-map test compares the
// two.
//
// Metric of the match: PSNR of the tone-mapped sRGB values (ACES, the
// exposure relight chose) over the pixels the model covers entirely (equal
// with the sky background and without it), ≥ 30 dB. The backgrounds differ
// by design (the network per pixel against relight's SH light).
#include <algorithm>
#include <cstdint>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <tuple>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "skybake/neural.h"
#include "skybake/prt.h"
#include "skybake/sky_source.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

const std::string kNetwork = std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/planet/sky_paper_dense.json";

std::string engine_path() {
    for (const char* p : {"/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
                          "/usr/share/assimp/models/glTF2/2CylinderEngine/glTF-Binary/2CylinderEngine.glb"})
        if (fs::exists(p))
            return p;
    return {};
}

class ViewCli : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        const std::string engine = engine_path();
        if (engine.empty())
            return;
        dir_ = test::temp_dir("view_cli");
        baked_ = dir_ + "/engine.glb";
        const auto r = run_cli({"prt", "bake", engine, "-o", baked_, "--order", "3", "--rule", "lebedev:194"}, 600);
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    void SetUp() override {
        if (baked_.empty())
            GTEST_SKIP() << "2CylinderEngine.glb not found (Debian package assimp-testmodels)";
    }
    // A linear EXR screenshot.
    static Image view(const std::string& name, const std::string& elevation, std::vector<std::string> set = {},
                      const std::string& azimuth = "0") {
        const std::string out = dir_ + "/" + name + ".exr";
        std::vector<std::string> args = {"view",    baked_,   "--screenshot",        out,       "--size",
                                         "160x120", "--model", kNetwork,           "--sun-elevation-deg",
                                         elevation, "--sun-azimuth-deg", azimuth};
        set.insert(set.begin(), "exposure=0");
        set.insert(set.begin(), "shadow=vertex");
        for (const std::string& s : set)
            args.insert(args.end(), {"--set", s});
        const auto r = run_cli(args, 300);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return load_image(out);
    }
    static inline std::string dir_, baked_;
};

double mean_luminance(const Image& img) {
    double sum = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
    return sum / double(img.width * img.height);
}

double luminance_stddev(const Image& img) {
    const double mean = mean_luminance(img);
    double sum = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            const double d = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] - mean;
            sum += d * d;
        }
    return std::sqrt(sum / double(img.width * img.height));
}

// The mean luminance of the model's pixels in an image with one sample per
// pixel and background=none: every pixel is then the model or exactly the
// previews' background colour.
double model_luminance(const Image& img) {
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            if (p[0] == 0.035f && p[1] == 0.045f && p[2] == 0.065f)
                continue;
            sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            ++n;
        }
    EXPECT_GT(n, img.width * img.height / 10);
    return sum / std::max(n, 1);
}

TEST_F(ViewCli, NoonSunsetNight) {
    const Image noon = view("noon", "60"), sunset = view("sunset", "2"), night = view("night", "-8");
    const double ln = mean_luminance(noon), ls = mean_luminance(sunset), lt = mean_luminance(night);
    const double mn = model_luminance(view("noon_bare", "60", {"background=none", "samples=1"})),
                 ms = model_luminance(view("sunset_bare", "2", {"background=none", "samples=1"}));
    std::printf("mean luminance: noon %.4g, sunset %.4g, night (sun at -8 deg) %.4g; model alone: noon %.4g, "
                "sunset %.4g\n",
                ln, ls, lt, mn, ms);
    // Not blank: the model stands out from the sky.
    EXPECT_GT(luminance_stddev(noon), 0.05 * ln);
    EXPECT_GT(luminance_stddev(sunset), 0.05 * ls);
    EXPECT_GT(mn, 2.0 * ms);
    EXPECT_GT(ms, 0.0);
    // Night: dark, but the twilight sky still lights the scene a little.
    EXPECT_LT(lt, 0.05 * ln);
    EXPECT_GT(lt, 0.0);
}

TEST_F(ViewCli, ExposureOneStopDoublesLinearValues) {
    const Image a = view("ev0", "30"), b = view("ev1", "30", {"exposure=1"});
    ASSERT_EQ(a.width, b.width);
    double worst = 0.0;
    int lit = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const float p = a.pixel(x, y)[c], q = b.pixel(x, y)[c];
                if (p > 1e-6f) {
                    ++lit;
                    worst = std::max(worst, std::abs(double(q) / double(p) - 2.0));
                }
            }
    EXPECT_GT(lit, a.width * a.height);
    EXPECT_LT(worst, 1e-3);
}

TEST_F(ViewCli, SettingsChangeTheImage) {
    const Image prt = view("prt", "30"), ao = view("ao", "30", {"shading=ao"}),
                dark = view("dark", "30", {"albedo=0.2", "background=none", "samples=1"}),
                bright = view("bright", "30", {"albedo=0.8", "background=none", "samples=1"});
    EXPECT_NE(mean_luminance(prt), mean_luminance(ao));
    // Albedo scales the model's radiance (4 times the albedo, 4 times the light).
    const double ratio = model_luminance(bright) / model_luminance(dark);
    EXPECT_NEAR(ratio, 4.0, 1e-3);
}

TEST_F(ViewCli, MatchesPrtRelight) {
    const std::string relit = dir_ + "/relit.exr";
    auto r = run_cli({"prt", "relight", baked_, "--light", "sky", "--model", kNetwork, "--sun-elevation-deg", "30",
                      "--size", "160x120", "--view", "35,30", "-o", relit, "--json"},
                     300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const float ev = nlohmann::json::parse(r.out)["exposure_ev"].get<float>();
    const Image ref = load_image(relit);
    const Image with_sky = view("match_sky", "30", {"view=35,30"});
    const Image bare = view("match_bare", "30", {"view=35,30", "background=none"});
    ASSERT_EQ(ref.width, bare.width);
    ASSERT_EQ(ref.height, bare.height);
    const ToneMap tm{ev, ToneCurve::Aces};
    double se = 0.0;
    std::size_t n = 0;
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x) {
            const float *a = with_sky.pixel(x, y), *b = bare.pixel(x, y), *c = ref.pixel(x, y);
            if (a[0] != b[0] || a[1] != b[1] || a[2] != b[2])
                continue; // the background shows in this pixel
            for (int k = 0; k < 3; ++k) {
                const double d = linear_to_srgb(tone_map_value(b[k], tm)) - linear_to_srgb(tone_map_value(c[k], tm));
                se += d * d;
            }
            ++n;
        }
    ASSERT_GT(n, std::size_t(ref.width * ref.height / 10)); // the model fills part of the frame
    const double psnr = 10.0 * std::log10(1.0 / std::max(se / double(3 * n), 1e-20));
    std::printf("view vs prt relight: %.2f dB over %zu model pixels\n", psnr, n);
    EXPECT_GE(psnr, 30.0);
}

// PSNR (dB) of the tone-mapped sRGB values of a and b over the pixels where
// `mask` is true; n: how many.
double masked_psnr(const Image& a, const Image& b, const std::vector<char>& mask, float ev, std::size_t& n) {
    const ToneMap tm{ev, ToneCurve::Aces};
    double se = 0.0;
    n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (!mask[std::size_t(y) * std::size_t(a.width) + std::size_t(x)])
                continue;
            for (int k = 0; k < 3; ++k) {
                const double d = linear_to_srgb(tone_map_value(a.pixel(x, y)[k], tm)) -
                                 linear_to_srgb(tone_map_value(b.pixel(x, y)[k], tm));
                se += d * d;
            }
            ++n;
        }
    return 10.0 * std::log10(1.0 / std::max(se / double(3 * std::max<std::size_t>(n, 1)), 1e-20));
}

bool is_background(const float* p) {
    return p[0] == 0.035f && p[1] == 0.045f && p[2] == 0.065f;
}

// The glossy layer: the viewer's per-pixel DPRT (a map of dprt_glossy() by
// mirror direction, sampled on the GPU) against `prt relight --glossy`, which
// calls dprt_glossy() at every pixel; and a sharper lobe (higher Phong
// exponent) gives a brighter highlight, the lobe being normalised.
TEST_F(ViewCli, DprtMatchesRelightGlossy) {
    const std::string relit = dir_ + "/relit_glossy.exr";
    auto r = run_cli({"prt", "relight", baked_, "--light", "sky", "--model", kNetwork, "--sun-elevation-deg", "30",
                      "--size", "160x120", "--view", "35,30", "--glossy", "32", "--specular", "1", "-o", relit,
                      "--json"},
                     300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const float ev = nlohmann::json::parse(r.out)["exposure_ev"].get<float>();
    const Image ref = load_image(relit);
    const Image with_sky = view("dprt_sky", "30", {"view=35,30", "shading=dprt", "phong=32", "specular=1"});
    const Image bare =
        view("dprt_bare", "30", {"view=35,30", "shading=dprt", "phong=32", "specular=1", "background=none"});
    const Image diffuse = view("dprt_diffuse", "30", {"view=35,30", "background=none"});
    ASSERT_EQ(ref.width, bare.width);
    std::vector<char> model(std::size_t(ref.width * ref.height));
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x) {
            const float *a = with_sky.pixel(x, y), *b = bare.pixel(x, y);
            model[std::size_t(y * ref.width + x)] = a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
        }
    std::size_t n = 0;
    const double psnr = masked_psnr(bare, ref, model, ev, n);
    ASSERT_GT(n, std::size_t(ref.width * ref.height / 10));
    // The glossy layer only adds light, and it is there.
    std::size_t darker = 0, lighter = 0;
    for (int y = 0; y < bare.height; ++y)
        for (int x = 0; x < bare.width; ++x)
            if (model[std::size_t(y * ref.width + x)]) {
                const float g = bare.pixel(x, y)[1], d = diffuse.pixel(x, y)[1];
                darker += g < d - 1e-4f;
                lighter += g > d + 1e-4f;
            }
    std::printf("dprt against diffuse: %zu pixels darker, %zu lighter; means %.4g, %.4g\n", darker, lighter,
                model_luminance(bare), model_luminance(diffuse));
    EXPECT_EQ(darker, 0u);
    EXPECT_GT(lighter, n / 2);
    std::printf("view dprt vs prt relight --glossy 32: %.2f dB over %zu model pixels\n", psnr, n);
    EXPECT_GE(psnr, 30.0);

    // The highlight: the brightest glossy term (dprt − prt) of the model's pixels.
    auto peak_glossy = [&](const std::string& a) {
        const Image g = view("dprt_peak_" + a, "30",
                             {"view=35,30", "shading=dprt", "phong=" + a, "specular=1", "background=none", "samples=1"});
        const Image d = view("dprt_peak_d", "30", {"view=35,30", "background=none", "samples=1"});
        double peak = 0.0;
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x)
                if (!is_background(d.pixel(x, y)))
                    for (int k = 0; k < 3; ++k)
                        peak = std::max(peak, double(g.pixel(x, y)[k]) - double(d.pixel(x, y)[k]));
        return peak;
    };
    const double rough = peak_glossy("4"), smooth = peak_glossy("256");
    std::printf("peak glossy radiance: exponent 4 %.4g, exponent 256 %.4g\n", rough, smooth);
    EXPECT_GT(rough, 0.0);
    EXPECT_GT(smooth, 1.2 * rough);
}

// The reference sky behind the model: each background pixel against
// SkySource::evaluate() along its ray through preview_camera() (the map is
// bilinear in 256 × 256 texels of relative azimuth and zenith angle: within
// 3 %, or 10⁻⁴ of the brightest pixel
// below the horizon, where the tables' radiance is ~10⁻⁶ and jitters), blue
// above the horizon at noon.
TEST_F(ViewCli, ReferenceSkyBackground) {
    // The sun off to the side (azimuth 100°; the camera looks from azimuth 35°).
    const Image img = view("reference_bg", "60", {"sky=reference", "sun=off", "samples=1", "view=35,5"}, "100");
    const Image bare = view("reference_bare", "60",
                            {"sky=reference", "sun=off", "samples=1", "view=35,5", "background=none"}, "100");
    const SkySource sky = SkySource::reference(neural_reference_model(load_neural_sky(kNetwork)));
    AoPreviewOptions o;
    o.width = img.width;
    o.height = img.height;
    o.azimuth_deg = 35.0f;
    o.elevation_deg = 5.0f;
    const PreviewCamera c = preview_camera(load_mesh(baked_), o);
    const glm::vec3 sun = sun_direction(60.0, 100.0);
    const float density = float(sky.atmosphere().density_from_altitude(0.0));
    std::vector<SkySample> samples;
    std::vector<std::pair<int, int>> where;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            if (!is_background(bare.pixel(x, y)))
                continue; // the model
            const float cx = (2.0f * (float(x) + 0.5f) / float(img.width) - 1.0f) * c.tan_half_fov_y * c.aspect;
            const float cy = (1.0f - 2.0f * (float(y) + 0.5f) / float(img.height)) * c.tan_half_fov_y;
            const glm::vec3 d = glm::normalize(c.forward + cx * c.right + cy * c.up);
            if (std::abs(d.y) < 0.02f || glm::dot(d, sun) > 0.995f)
                continue; // the horizon and the aureole: the map's texels straddle steep changes
            samples.push_back({d.y, glm::dot(d, sun), sun.y, density});
            where.emplace_back(x, y);
        }
    ASSERT_GT(samples.size(), std::size_t(img.width * img.height / 4));
    std::vector<glm::vec3> want(samples.size());
    sky.evaluate(samples, want);
    float brightest = 0.0f;
    for (const glm::vec3& w : want)
        brightest = std::max(brightest, glm::length(w));
    std::size_t close = 0, blue = 0, above = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const float* p = img.pixel(where[i].first, where[i].second);
        const glm::vec3 got(p[0], p[1], p[2]), w = glm::max(want[i], glm::vec3(0.0f));
        if (glm::length(got - w) <= 0.03f * glm::length(w) + 1e-4f * brightest)
            ++close;
        if (samples[i].cos_view_zenith > 0.0f) {
            ++above;
            blue += p[2] > p[1] && p[1] > p[0] && p[0] > 0.0f;
        }
    }
    std::printf("reference background: %zu of %zu pixels match SkySource::evaluate; %zu of %zu above the "
                "horizon blue\n",
                close, samples.size(), blue, above);
    EXPECT_GE(double(close), 0.99 * double(samples.size()));
    ASSERT_GT(above, samples.size() / 4);
    EXPECT_EQ(blue, above);
}

// The sun's shadow map against the per-vertex rays and the unshadowed sun,
// on the sun's own radiance (sun on − sun off, so the sky light cancels):
// where the map lights a pixel it gives the unshadowed value (the map only
// removes light), where every vertex ray is blocked the map is dark too, and
// where every ray reaches the sun the map mostly agrees.
TEST_F(ViewCli, ShadowMapDarkensShadowedRegions) {
    auto sun_only = [&](const std::string& shadow) {
        // A low sun from the side: the middle block shades a cylinder.
        const Image on = view("sun_on_" + shadow, "8", {"view=35,30", "background=none", "samples=1",
                                                       "shadow=" + shadow}, "120"),
                    off = view("sun_off_" + shadow, "8",
                               {"view=35,30", "background=none", "samples=1", "shadow=" + shadow, "sun=off"}, "120");
        Image s(on.width, on.height);
        for (int y = 0; y < on.height; ++y)
            for (int x = 0; x < on.width; ++x)
                for (int k = 0; k < 3; ++k)
                    s.pixel(x, y)[k] = is_background(off.pixel(x, y)) ? -1.0f : on.pixel(x, y)[k] - off.pixel(x, y)[k];
        return s;
    };
    const Image map = sun_only("map"), vertex = sun_only("vertex"), none = sun_only("none");
    std::size_t facing = 0, brighter = 0, blocked = 0, blocked_dark = 0, reached = 0, reached_agree = 0, dark = 0;
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const float m = map.pixel(x, y)[1], v = vertex.pixel(x, y)[1], u = none.pixel(x, y)[1];
            if (u < 0.0f || !(u > 1e-4f))
                continue; // background, or turned away from the sun
            ++facing;
            brighter += m > u * 1.001f + 1e-6f;
            dark += m < 0.05f * u;
            if (v <= 0.0f) {
                ++blocked;
                blocked_dark += m < 0.5f * u;
            }
            if (v >= 0.95f * u) {
                ++reached;
                reached_agree += std::abs(m - u) <= 0.02f * u;
            }
        }
    std::printf("sun-facing pixels %zu: shadow map dark in %zu; per-vertex blocked %zu (map dark in %zu), reached %zu "
                "(map agrees in %zu)\n",
                facing, dark, blocked, blocked_dark, reached, reached_agree);
    ASSERT_GT(facing, std::size_t(map.width * map.height / 20));
    EXPECT_EQ(brighter, 0u);
    EXPECT_GT(dark, facing / 50); // there are shadows
    ASSERT_GT(blocked, 0u);
    EXPECT_GE(double(blocked_dark), 0.8 * double(blocked));
    ASSERT_GT(reached, facing / 10);
    EXPECT_GE(double(reached_agree), 0.9 * double(reached));
}

TEST_F(ViewCli, ModelWithoutTransferIsLitUnshadowed) {
    const std::string out = dir_ + "/raw.png";
    const auto r = run_cli({"view", engine_path(), "--screenshot", out, "--size", "120x90", "--model", kNetwork}, 300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("no baked transfer"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("unshadowed shading"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(out));
}

TEST(ViewCliModels, MeshWithoutNormalsGetsThem) {
    const std::string dir = test::temp_dir("view_normals");
    const std::string obj = dir + "/tetra.obj", out = dir + "/tetra.exr";
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    const auto r = run_cli({"view", obj, "--screenshot", out, "--size", "64x48", "--set", "exposure=0"}, 300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("normals computed"), std::string::npos) << r.err;
    const Image img = load_image(out);
    EXPECT_GT(luminance_stddev(img), 0.0); // the model shows against the background
}

// Base colour images are sampled per pixel: a flat quad (one normal, so
// uniform light) whose 8×8 image is white on its left half and 0.25 (linear)
// on its right shows both, 4:1. Sampled per vertex, the four corners read the
// same blend of both halves and the quad would be one colour.
TEST(ViewCliModels, BaseColourImagesAreSampledPerPixel) {
    const std::string dir = test::temp_dir("view_texture");
    std::vector<std::uint8_t> px(8 * 8 * 3);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 3; ++c)
                px[std::size_t((y * 8 + x) * 3 + c)] = x < 4 ? 255 : 137; // sRGB 137: 0.2502 linear
    save_png_srgb8(dir + "/halves.png", 8, 8, px.data());
    std::ofstream(dir + "/quad.mtl") << "newmtl halves\nKd 1 1 1\nmap_Kd halves.png\n";
    std::ofstream(dir + "/quad.obj") << "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
                                        "vt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nvn 0 1 0\nusemtl halves\n"
                                        "f 1/1/1 4/4/1 3/3/1\nf 1/1/1 3/3/1 2/2/1\n";
    const std::string out = dir + "/quad.exr";
    const auto r = run_cli({"view", dir + "/quad.obj", "--screenshot", out, "--size", "160x120", "--set",
                            "exposure=0", "--set", "background=none", "--set", "samples=1", "--set", "shadow=none",
                            "--set", "view=30,60"},
                           300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image img = load_image(out);
    std::vector<double> lum;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            if (!(p[0] == 0.035f && p[1] == 0.045f && p[2] == 0.065f))
                lum.push_back(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
        }
    ASSERT_GT(lum.size(), std::size_t(img.width * img.height / 10));
    std::sort(lum.begin(), lum.end());
    const double dark = lum[lum.size() / 10], bright = lum[lum.size() * 9 / 10];
    EXPECT_NEAR(dark / bright, 0.2502, 0.01) << "dark " << dark << ", bright " << bright;
}

TEST(ViewCliModels, FramesAreCountedAndTheLastWritten) {
    const std::string dir = test::temp_dir("view_frames");
    const std::string obj = dir + "/tetra.obj", out = dir + "/tetra.png";
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    const auto r = run_cli({"view", obj, "--screenshot", out, "--size", "64x48", "--frames", "3"}, 300);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("3 frames: "), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(out));
    const auto bad = run_cli({"view", obj, "--screenshot", out, "--frames", "0"});
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_NE(bad.err.find("--frames"), std::string::npos) << bad.err;
}

void expect_one_line_failure(const test::CliResult& r, const std::string& out, const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

// The new settings refuse bad values with one line naming --set, exit 2, nothing written.
TEST(ViewCliModels, BadNewSettingsAreOneLine) {
    const std::string dir = test::temp_dir("view_bad_settings");
    const std::string obj = dir + "/tetra.obj", out = dir + "/x.png";
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    for (const char* bad : {"shading=glossy", "shadow=soft", "phong=0", "specular=-1", "sky=network", "sky=cloudy",
                            "zoom=0", "direction=-1"}) {
        const auto r = run_cli({"view", obj, "--screenshot", out, "--size", "32x24", "--set", bad});
        EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
        EXPECT_EQ(r.err_lines(), 1) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("--set"), std::string::npos) << bad << ": " << r.err;
        EXPECT_FALSE(fs::exists(out)) << bad;
    }
    // Settings of another shading: refused, naming the shading they apply to.
    for (const auto& [set, shading, applies] :
         {std::tuple<const char*, const char*, const char*>{"phong=48", "shading=prt", "shading=dprt"},
          {"specular=0.5", "shading=ao", "shading=dprt"},
          {"direction=2", "shading=dprt", "shading=visibility"},
          {"phong=48", "shading=unshadowed", "shading=dprt"}}) {
        const auto r = run_cli({"view", obj, "--screenshot", out, "--size", "32x24", "--set", shading, "--set", set});
        EXPECT_EQ(r.exit_code, 2) << set << ": " << r.err;
        EXPECT_EQ(r.err_lines(), 1) << set << ": " << r.err;
        EXPECT_NE(r.err.find(applies), std::string::npos) << set << ": " << r.err;
        EXPECT_FALSE(fs::exists(out)) << set;
    }
    // A direction beyond the rule: one line from the renderer, exit 1.
    const auto r = run_cli({"view", obj, "--screenshot", out, "--size", "32x24", "--rule", "lebedev:6", "--set",
                            "shading=visibility", "--set", "direction=6"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find("not in the light's rule"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    // Headless, the window's flags are refused.
    const auto b = run_cli({"view", obj, "--screenshot", out, "--bake"});
    EXPECT_EQ(b.exit_code, 2) << b.err;
    EXPECT_NE(b.err.find("--bake"), std::string::npos) << b.err;
}

TEST(ViewCliModels, BrokenFileIsOneLine) {
    const std::string dir = test::temp_dir("view_broken");
    const std::string glb = dir + "/broken.glb", out = dir + "/x.png";
    std::ofstream(glb) << "glTF this is not a binary glTF file";
    expect_one_line_failure(run_cli({"view", glb, "--screenshot", out}), out, "broken.glb");
}

TEST(ViewCliModels, NoEglPlatformIsOneLine) {
    const std::string dir = test::temp_dir("view_noegl");
    const std::string obj = dir + "/tetra.obj", out = dir + "/x.png";
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    setenv("SKYBAKE_EGL_PLATFORM", "none", 1);
    const auto r = run_cli({"view", obj, "--screenshot", out});
    unsetenv("SKYBAKE_EGL_PLATFORM");
    expect_one_line_failure(r, out, "no headless OpenGL");
}

} // namespace
} // namespace skybake
