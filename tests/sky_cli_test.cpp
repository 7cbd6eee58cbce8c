// End-to-end tests of `skybake sky ...`: presets, optical lengths, CSV
// evaluation with its errors, rendering.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/sky.h"

using skybake::test::run_cli;
using skybake::test::temp_dir;

namespace {

std::string write(const std::string& dir, const std::string& name, const std::string& text) {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << text;
    return path;
}

std::string read(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

double last_line_number(const std::string& out) {
    std::string s = out;
    while (!s.empty() && s.back() == '\n')
        s.pop_back();
    return std::stod(s.substr(s.rfind('\n') + 1));
}

} // namespace

TEST(SkyCli, PresetRoundTripsThroughAFile) {
    const std::string dir = temp_dir("sky_preset");
    auto r = run_cli({"sky", "preset", "earth"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["planet_radius_km"], 6360.0);
    EXPECT_EQ(j["components"].size(), 3u);
    const std::string file = write(dir, "earth.json", r.out);
    // The same optical length from the preset and from the saved file.
    auto a = run_cli({"sky", "optical-length", "--preset", "earth", "--density", "0.5", "--cos-zenith", "0.3"});
    auto b = run_cli({"sky", "optical-length", "--atmosphere", file, "--density", "0.5", "--cos-zenith", "0.3"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    EXPECT_EQ(last_line_number(a.out), last_line_number(b.out));
}

namespace {

// Every field of two atmospheres, exactly (JSON numbers round-trip doubles).
void expect_same_atmosphere(const skybake::Atmosphere& a, const skybake::Atmosphere& b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.planet_radius_km, b.planet_radius_km);
    EXPECT_EQ(a.top_radius_km, b.top_radius_km);
    EXPECT_EQ(a.sun_elevation_deg, b.sun_elevation_deg);
    EXPECT_EQ(a.sun_azimuth_deg, b.sun_azimuth_deg);
    EXPECT_EQ(a.sun_irradiance, b.sun_irradiance);
    EXPECT_EQ(a.sun_angular_radius_rad, b.sun_angular_radius_rad);
    EXPECT_EQ(a.ground_albedo, b.ground_albedo);
    EXPECT_EQ(a.table_rule, b.table_rule);
    ASSERT_EQ(a.components.size(), b.components.size());
    for (std::size_t k = 0; k < a.components.size(); ++k) {
        const auto &x = a.components[k], &y = b.components[k];
        SCOPED_TRACE("component " + std::to_string(k));
        EXPECT_EQ(x.name, y.name);
        EXPECT_EQ(x.profile, y.profile);
        EXPECT_EQ(x.scale_height_km, y.scale_height_km);
        EXPECT_EQ(x.tent_center_km, y.tent_center_km);
        EXPECT_EQ(x.tent_half_width_km, y.tent_half_width_km);
        EXPECT_EQ(x.scattering_per_km, y.scattering_per_km);
        EXPECT_EQ(x.extinction_per_km, y.extinction_per_km);
        EXPECT_EQ(x.phase, y.phase);
        EXPECT_EQ(x.phase_g, y.phase_g);
    }
}

} // namespace

TEST(SkyCli, EveryPresetRoundTripsEveryField) {
    // `sky preset NAME` prints the preset as JSON; reading it back (as
    // --atmosphere does) must give the library's preset field for field.
    const auto names = skybake::atmosphere_preset_names();
    ASSERT_GE(names.size(), 3u);
    for (const std::string& name : names) {
        auto r = run_cli({"sky", "preset", name});
        ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
        const skybake::Atmosphere preset = skybake::atmosphere_preset(name);
        expect_same_atmosphere(skybake::atmosphere_from_json(r.out), preset, name + " through the CLI");
        expect_same_atmosphere(skybake::atmosphere_from_json(skybake::atmosphere_to_json(preset)), preset,
                               name + " through the library");
    }
}

TEST(SkyCli, OpticalLengthStraightUpIsTheScaleHeight) {
    // From the ground straight up: H (1 − e^(−h_top/H)); paper: H = 8.3, top 100 km.
    auto r = run_cli({"sky", "optical-length", "--preset", "paper", "--density", "1", "--cos-zenith", "1", "--method",
                      "exact"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NEAR(last_line_number(r.out), 8.3 * (1 - std::exp(-100 / 8.3)), 1e-6);
    auto t = run_cli({"sky", "optical-length", "--preset", "paper", "--density", "1", "--cos-zenith", "1",
                      "--component", "1", "--table-rule", "refined"});
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_NEAR(last_line_number(t.out), 1.6, 1e-3);
}

TEST(SkyCli, OpticalLengthJson) {
    auto r = run_cli({"sky", "optical-length", "--preset", "earth", "--density", "1", "--cos-zenith", "-0.5",
                      "--method", "exact", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["hits_ground"].get<bool>());
}

TEST(SkyCli, EvalWritesOneRowPerSample) {
    const std::string dir = temp_dir("sky_eval");
    const std::string in = write(dir, "in.csv",
                                 "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n"
                                 "1,1,1,1\n"
                                 "0.5,0.2,0.3,0.9\n"
                                 "\n"
                                 "0.0,0.0,-0.9,1\n");
    for (const char* method : {"tables", "exact"}) {
        const std::string out = dir + "/out_" + method + ".csv";
        auto r = run_cli({"sky", "eval", "--preset", "earth", "--method", method, "--input", in, "--output", out,
                          "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["samples"], 3);
        std::istringstream rows(read(out));
        std::string line;
        std::getline(rows, line);
        EXPECT_EQ(line, "r,g,b");
        std::vector<std::array<double, 3>> v;
        while (std::getline(rows, line)) {
            std::array<double, 3> c{};
            ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &c[0], &c[1], &c[2]), 3) << line;
            v.push_back(c);
        }
        ASSERT_EQ(v.size(), 3u);
        EXPECT_GT(v[0][2], v[0][0]); // blue zenith
        EXPECT_EQ(v[2][0], 0.0);     // night: the sun 64 degrees below the horizon
    }
}

TEST(SkyCli, EvalErrorsNameTheLine) {
    const std::string dir = temp_dir("sky_eval_bad");
    struct Case {
        const char* text;
        const char* expect;
    } cases[] = {
        {"1,1,1,1\n1,0.5,-0.5,1\n", "line 2"},           // impossible triple
        {"1,1,1,1\n0,0,0,0\n", "line 2"},                // density 0
        {"cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n1,1,1,1.5\n", "line 2"}, // density > 1
        {"density,cos_sun_zenith,cos_view_sun,cos_view_zenith\n0.5,1,1,1\n1,1,1,0\n", "line 3"}, // by name: density 0
        {"foo,bar,baz,qux\n1,1,1,1\n", "unknown column 'foo'"},
        {"cos_view_zenith,cos_view_sun,density\n1,1,1\n", "no column 'cos_sun_zenith'"},
        {"cos_view_zenith,cos_view_sun,cos_sun_zenith,cos_view_sun\n1,1,1,1\n", "appears twice"},
        {"cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n", "no samples"}, // a header only
        {"", "no samples"},                                                        // empty
        {"1,1,1,1\n\n0.5,abc,0,1\n", "line 3"},          // not a number
        {"1,1,1\n", "line 1"},                            // three fields
    };
    for (const Case& c : cases) {
        const std::string in = write(dir, "in.csv", c.text);
        const std::string out = dir + "/out.csv";
        auto r = run_cli({"sky", "eval", "--input", in, "--output", out});
        EXPECT_EQ(r.exit_code, 1) << c.text;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(out)) << "no output on error";
    }
}

TEST(SkyCli, BadFlagsAreOneLineErrors) {
    auto a = run_cli({"sky", "optical-length", "--preset", "mars", "--density", "1", "--cos-zenith", "1"});
    EXPECT_EQ(a.exit_code, 2);
    EXPECT_EQ(a.err_lines(), 1) << a.err;
    auto b = run_cli({"sky", "optical-length", "--preset", "earth", "--density", "1.5", "--cos-zenith", "1"});
    EXPECT_EQ(b.exit_code, 2);
    EXPECT_NE(b.err.find("--density"), std::string::npos);
    const std::string dir = temp_dir("sky_bad_json");
    const std::string bad = write(dir, "bad.json", "{\"planet_radius_km\": 6360, \"top_radius_km\": 6000}");
    auto c = run_cli({"sky", "optical-length", "--atmosphere", bad, "--density", "1", "--cos-zenith", "1"});
    EXPECT_EQ(c.exit_code, 1);
    EXPECT_EQ(c.err_lines(), 1) << c.err;
    EXPECT_NE(c.err.find("bad.json"), std::string::npos) << c.err;
}

TEST(SkyCli, RenderWritesImages) {
    const std::string dir = temp_dir("sky_render");
    for (const char* view : {"fisheye", "panorama", "camera"}) {
        const std::string out = dir + "/" + view + ".png";
        auto r = run_cli({"sky", "render", "--preset", "earth", "--altitude-km", "0", "--sun-elevation-deg", "20",
                          "--view", view, "--size", "48x32", "-o", out, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_TRUE(std::filesystem::exists(out));
        EXPECT_EQ(nlohmann::json::parse(r.out)["width"], 48);
    }
    const std::string exr = dir + "/space.exr";
    auto s = run_cli({"sky", "render", "--preset", "paper-dense", "--altitude-km", "20000", "--sun-elevation-deg", "0",
                      "--view", "camera", "--pitch", "-90", "--fov", "60", "--size", "32x32", "-o", exr});
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_TRUE(std::filesystem::exists(exr));
    auto bad = run_cli({"sky", "render", "--preset", "earth", "--altitude-km", "0", "--sun-elevation-deg", "20",
                        "--view", "fish", "-o", dir + "/x.png"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err_lines(), 1);
}

namespace {

std::vector<std::array<double, 3>> read_rgb_csv(const std::string& path) {
    std::istringstream rows(read(path));
    std::string line;
    std::getline(rows, line);
    std::vector<std::array<double, 3>> v;
    while (std::getline(rows, line)) {
        std::array<double, 3> c{};
        if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &c[0], &c[1], &c[2]) == 3)
            v.push_back(c);
    }
    return v;
}

} // namespace

// --scattering multiple adds light everywhere, and most where single
// scattering has none: the zenith with the sun 10° below the horizon (the whole column in the shadow).
TEST(SkyCli, EvalWithMultipleScatteringAddsLight) {
    const std::string dir = temp_dir("sky_eval_multiple");
    const std::string in = write(dir, "in.csv",
                                 "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n"
                                 "1,0.866,0.866,1\n"     // noon-ish zenith
                                 "1,-0.1736,-0.1736,1\n"); // twilight zenith, sun at -10°
    std::vector<std::array<double, 3>> single, multiple;
    for (const char* mode : {"single", "multiple"}) {
        const std::string out = dir + "/" + mode + ".csv";
        auto r = run_cli({"sky", "eval", "--preset", "earth", "--method", "exact", "--scattering", mode,
                          "--multiple-method", "hillaire", "--input", in, "--output", out});
        if (std::string(mode) == "single") {
            EXPECT_EQ(r.exit_code, 2) << "--multiple-method needs --scattering multiple";
            EXPECT_EQ(r.err_lines(), 1) << r.err;
            EXPECT_NE(r.err.find("--multiple-method"), std::string::npos) << r.err;
            r = run_cli({"sky", "eval", "--preset", "earth", "--method", "exact", "--input", in, "--output", out});
        }
        ASSERT_EQ(r.exit_code, 0) << r.err;
        (std::string(mode) == "single" ? single : multiple) = read_rgb_csv(out);
    }
    ASSERT_EQ(single.size(), 2u);
    ASSERT_EQ(multiple.size(), 2u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(multiple[0][c], 1.05 * single[0][c]) << c;
        EXPECT_LT(multiple[0][c], 2.0 * single[0][c]) << c;
        EXPECT_EQ(single[1][c], 0.0);
        EXPECT_GT(multiple[1][c], 0.0) << c;
    }
    EXPECT_GT(multiple[1][2], multiple[1][0]); // the twilight zenith stays blue
}

TEST(SkyCli, MultipleScatteringFlagsAreChecked) {
    const std::string dir = temp_dir("sky_multiple_flags");
    const std::string light = dir + "/light.json";
    struct Case {
        std::vector<std::string> args;
        const char* names;
    } cases[] = {
        {{"sky", "sh", "--scattering", "double", "-o", light}, "--scattering"},
        {{"sky", "sh", "--multiple-method", "bruneton", "--scattering", "multiple", "-o", light}, "--multiple-method"},
        {{"sky", "sh", "--scattering", "multiple", "--multiple-method", "hillaire", "--scattering-orders", "8", "-o",
          light},
         "--scattering-orders"},
        {{"sky", "sh", "--scattering-orders", "8", "-o", light}, "--scattering-orders"},
        {{"sky", "sh", "--scattering", "multiple", "--scattering-orders", "1", "-o", light}, "--scattering-orders"},
    };
    for (const Case& c : cases) {
        auto r = run_cli(c.args);
        EXPECT_NE(r.exit_code, 0) << c.names;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find(c.names), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(light));
    }
}

// The sky's SH light with multiple scattering is brighter in every band-0
// channel, and bluer; the training target is reported.
TEST(SkyCli, ShAndTrainUseTheFullSky) {
    const std::string dir = temp_dir("sky_sh_multiple");
    std::array<double, 3> dc[2];
    for (int m = 0; m < 2; ++m) {
        const std::string out = dir + (m ? "/multiple.json" : "/single.json");
        std::vector<std::string> args = {"sky", "sh", "--preset", "earth", "--order", "1", "--rule", "lebedev:590",
                                         "-o", out};
        if (m)
            args.insert(args.end(), {"--scattering", "multiple", "--multiple-method", "hillaire"});
        auto r = run_cli(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto j = nlohmann::json::parse(read(out));
        for (int c = 0; c < 3; ++c)
            dc[m][std::size_t(c)] = j["coefficients"][0][c].get<double>();
    }
    for (int c = 0; c < 3; ++c)
        EXPECT_GT(dc[1][std::size_t(c)], 1.05 * dc[0][std::size_t(c)]) << c;
    EXPECT_GT(dc[1][2] / dc[0][2], dc[1][0] / dc[0][0]); // multiple scattering is bluest

    auto t = run_cli({"sky", "train", "--preset", "earth", "--scattering", "multiple", "--multiple-method", "hillaire",
                      "--samples", "4000", "--epochs", "1", "-o", dir + "/w.json", "--json", "-q"});
    ASSERT_EQ(t.exit_code, 0) << t.err;
    const auto j = nlohmann::json::parse(t.out);
    EXPECT_NE(j["target"].get<std::string>().find("single + multiple"), std::string::npos);
    const auto w = nlohmann::json::parse(read(dir + "/w.json"));
    EXPECT_NE(w.dump().find("\"scattering\":\"multiple\""), std::string::npos);
}
