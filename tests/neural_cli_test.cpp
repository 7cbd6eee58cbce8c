// End-to-end tests of the neural sky commands: sky train, sky eval/render
// --model, sky export, sky error; exit codes, one-line errors, no partial output.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

using skybake::test::run_cli;
using skybake::test::temp_dir;
namespace fs = std::filesystem;

namespace {

std::string read(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

std::string write(const std::string& dir, const std::string& name, const std::string& text) {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << text;
    return path;
}

int count_lines(const std::string& text) {
    int n = 0;
    for (char c : text)
        n += c == '\n';
    return n;
}

// A quickly trained small network, shared by the tests of one run.
const std::string& tiny_model() {
    static const std::string path = [] {
        const std::string dir = temp_dir("neural_model");
        const std::string p = dir + "/tiny.json";
        auto r = run_cli({"sky", "train", "--preset", "paper-dense", "--samples", "3000", "--heldout", "500",
                          "--epochs", "3", "--lm-iterations", "2", "--batch", "256", "-o", p});
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return p;
    }();
    return path;
}

} // namespace

TEST(NeuralCli, TrainWritesWeightsCurveAndChart) {
    const std::string dir = temp_dir("neural_train");
    auto r = run_cli({"sky", "train", "--preset", "paper", "--samples", "2000", "--heldout", "300", "--epochs", "2",
                      "--lm-iterations", "2", "--batch", "200", "--topology", "shared:6x6", "-o", dir + "/w.json",
                      "--curve", dir + "/c.csv", "--chart", dir + "/c.png", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["topology"], "shared:6x6");
    // The default encodings: horizon inputs, residual outputs (paper: Rayleigh and Mie, 3 channels each).
    EXPECT_EQ(j["inputs"], "horizon");
    EXPECT_EQ(j["outputs"], "residual");
    EXPECT_EQ(j["weights"], 5 * 6 + 7 * 6 + 7 * 6);
    EXPECT_EQ(j["samples"], 2000);
    EXPECT_GT(j["max_n"].get<double>(), 0.0);
    const auto w = nlohmann::json::parse(read(dir + "/w.json"));
    EXPECT_EQ(w["format"], "skybake-neural-sky");
    EXPECT_EQ(w["atmosphere"]["planet_radius_km"], 6371.0);
    const std::string csv = read(dir + "/c.csv");
    EXPECT_EQ(csv.rfind("epoch,phase,train_rms,heldout_rms", 0), 0u);
    EXPECT_EQ(count_lines(csv), 1 + 2 + j["lm_iterations"].get<int>());
    EXPECT_GT(fs::file_size(dir + "/c.png"), 1000u);
}

TEST(NeuralCli, ANetworkThatDidNotLearnIsSavedWithAWarning) {
    // Adam's first step 9 kills every output of a 64-wide network.
    const std::string dir = temp_dir("neural_train_dead");
    auto r = run_cli({"sky", "train", "--preset", "earth", "--samples", "20000", "--epochs", "3", "--lm-iterations",
                      "0", "--topology", "shared:64x64", "--learning-rate", "9", "-o", dir + "/w.json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: the network did not learn"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--learning-rate"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(dir + "/w.json"));
}

TEST(NeuralCli, TrainRejectsBadFlags) {
    const std::string dir = temp_dir("neural_train_bad");
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"--topology", "wide"},
             {"--topology", "independent:0"},
             {"--brightness", "cubic"},
             {"--hard-share", "nan"},
             {"--hard-share", "1.5"},
             {"--flight-share", "-0.1"},
             {"--flight-share", "nan"},
             {"--multiple-term", "cubic"},
             {"--multiple-term", "log"}, // with single scattering
             {"--samples", "3"},
             {"--chart", dir + "/c.jpg"},
             {"--preset", "mars"}}) {
        std::vector<std::string> a{"sky", "train", "-o", dir + "/w.json"};
        a.insert(a.end(), args.begin(), args.end());
        auto r = run_cli(a);
        EXPECT_EQ(r.exit_code, 2) << args[0]; // a bad flag value is a usage error
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
        EXPECT_FALSE(fs::exists(dir + "/w.json"));
    }
}

// An aerosol family: --aerosol-range at training, --aerosol where the network
// is used; bad values are one-line usage errors naming the flag.
TEST(NeuralCli, AnAerosolFamilyTakesItsAmountAtRunTime) {
    const std::string dir = temp_dir("neural_family");
    const std::string family = std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/neural/v3_earth_family.json";
    const std::string in = write(dir, "in.csv", "0.2,0.5,0.4,0.9\n0.05,0.9,0.3,1.0\n");
    auto clear = run_cli({"sky", "eval", "--model", family, "--input", in, "--output", dir + "/clear.csv"});
    auto hazy = run_cli({"sky", "eval", "--model", family, "--aerosol", "20", "--input", in, "--output", dir + "/hazy.csv"});
    ASSERT_EQ(clear.exit_code, 0) << clear.err;
    ASSERT_EQ(hazy.exit_code, 0) << hazy.err;
    EXPECT_NE(read(dir + "/clear.csv"), read(dir + "/hazy.csv"));
    auto r = run_cli({"sky", "render", "--model", family, "--aerosol", "32", "--altitude-km", "0", "--sun-elevation-deg", "10", "--size", "32x16", "-o", dir + "/hazy.png"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    auto c = run_cli({"sky", "export", family, "--format", "c", "-o", dir + "/sky.c"});
    EXPECT_EQ(c.exit_code, 0) << c.err;
    EXPECT_NE(read(dir + "/sky.c").find("float density, float aerosol, float rgb[3]"), std::string::npos);
    for (const auto& [args, flag] : std::vector<std::pair<std::vector<std::string>, std::string>>{
             {{"sky", "eval", "--model", family, "--aerosol", "40", "--input", in, "--output", dir + "/o.csv"},
              "--aerosol"},
             {{"sky", "eval", "--model", std::string(SKYBAKE_SOURCE_DIR) +
                                             "/tests/data/neural/v3_earth_residual.json",
               "--aerosol", "2", "--input", in, "--output", dir + "/o.csv"},
              "--aerosol"},
             {{"sky", "train", "--aerosol-range", "8", "-o", dir + "/w.json"}, "--aerosol-range"},
             {{"sky", "train", "--aerosol-range", "8:2", "-o", dir + "/w.json"}, "--aerosol-range"},
             {{"sky", "train", "--aerosol-range", "1:8", "--aerosol-component", "ozone", "-o", dir + "/w.json"},
              "--aerosol-range"},
             {{"sky", "train", "--aerosol-range", "1:8", "--outputs", "phase-factored", "-o", dir + "/w.json"},
              "--aerosol-range"},
             {{"sky", "train", "--aerosol-component", "mie", "-o", dir + "/w.json"}, "--aerosol-component"}}) {
        auto b = run_cli(args);
        EXPECT_EQ(b.exit_code, 2) << b.err;
        EXPECT_EQ(b.err_lines(), 1) << b.err;
        EXPECT_NE(b.err.find(flag), std::string::npos) << b.err;
        EXPECT_FALSE(fs::exists(dir + "/o.csv") || fs::exists(dir + "/w.json"));
    }
}

TEST(NeuralCli, EvalWithModelTakesTheSameCsv) {
    const std::string dir = temp_dir("neural_eval");
    const std::string in = write(dir, "in.csv",
                                 "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n"
                                 "1,1,1,1\n0.5,0.2,0.7,0.3\n-0.2,0.1,0.5,0.9\n0.3,-0.285,-0.95,0.5\n");
    auto r = run_cli({"sky", "eval", "--model", tiny_model(), "--input", in, "--output", dir + "/out.csv", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["method"], "neural");
    std::istringstream out(read(dir + "/out.csv"));
    std::string line;
    std::getline(out, line);
    EXPECT_EQ(line, "r,g,b");
    // The library's batch inference on the same samples: the CLI is a thin
    // shell over it, so the rows agree to the 9 printed digits.
    const skybake::NeuralSky net = skybake::load_neural_sky(tiny_model());
    const std::vector<skybake::SkySample> samples = {
        {1, 1, 1, 1}, {0.5f, 0.2f, 0.7f, 0.3f}, {-0.2f, 0.1f, 0.5f, 0.9f}, {0.3f, -0.285f, -0.95f, 0.5f}};
    std::vector<glm::vec3> expected(samples.size());
    skybake::evaluate_neural_sky(net, samples, expected);
    int rows = 0, lit = 0;
    while (std::getline(out, line)) {
        ASSERT_LT(rows, 4) << line;
        double a = -1, b = -1, c = -1;
        char k1 = 0, k2 = 0;
        std::istringstream(line) >> a >> k1 >> b >> k2 >> c;
        const glm::vec3& e = expected[std::size_t(rows)];
        const double scale = std::max({double(e.x), double(e.y), double(e.z), 1e-30});
        EXPECT_NEAR(a, e.x, 1e-6 * scale) << "row " << rows << ": " << line;
        EXPECT_NEAR(b, e.y, 1e-6 * scale) << "row " << rows << ": " << line;
        EXPECT_NEAR(c, e.z, 1e-6 * scale) << "row " << rows << ": " << line;
        lit += e.x > 0.0f;
        ++rows;
    }
    EXPECT_EQ(rows, 4);
    EXPECT_GE(lit, 2) << "the sunlit samples must not all decode to zero";
    // The same bad input errors as the reference model.
    const std::string bad = write(dir, "bad.csv", "1,1,1,1\n0.9,0.9,-0.9,0.5\n");
    auto e = run_cli({"sky", "eval", "--model", tiny_model(), "--input", bad, "--output", dir + "/bad_out.csv"});
    EXPECT_EQ(e.exit_code, 1);
    EXPECT_EQ(e.err_lines(), 1);
    EXPECT_NE(e.err.find("line 2"), std::string::npos) << e.err;
    EXPECT_FALSE(fs::exists(dir + "/bad_out.csv"));
    // The weights file carries its atmosphere.
    auto p = run_cli({"sky", "eval", "--model", tiny_model(), "--preset", "earth", "--input", in, "--output",
                      dir + "/p.csv"});
    EXPECT_EQ(p.exit_code, 2); // flags that do not go together: a usage error
    EXPECT_EQ(p.err_lines(), 1);
    EXPECT_NE(p.err.find("--preset"), std::string::npos) << p.err;
}

TEST(NeuralCli, RenderWithModel) {
    const std::string dir = temp_dir("neural_render");
    auto r = run_cli({"sky", "render", "--model", tiny_model(), "--altitude-km", "2", "--sun-elevation-deg", "20",
                      "--view", "panorama", "--size", "64x32", "-o", dir + "/p.png", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["method"], "neural");
    EXPECT_EQ(j["atmosphere"], "paper-dense");
    EXPECT_GT(fs::file_size(dir + "/p.png"), 100u);
    auto bad = run_cli({"sky", "render", "--model", tiny_model(), "--altitude-km", "2", "--sun-elevation-deg", "20",
                        "--method", "exact", "-o", dir + "/x.png"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err_lines(), 1);
    EXPECT_FALSE(fs::exists(dir + "/x.png"));
}

TEST(NeuralCli, ExportEveryFormat) {
    const std::string dir = temp_dir("neural_export");
    for (const char* f : {"glsl", "hlsl", "cuda", "c"}) {
        const std::string out = dir + "/sky." + f;
        auto r = run_cli({"sky", "export", tiny_model(), "--format", f, "-o", out, "--json"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["weights"], 362); // the default, shared:16x12 with 6 outputs
        EXPECT_NE(read(out).find("skybake_sky("), std::string::npos) << f;
    }
    auto r = run_cli({"sky", "export", tiny_model(), "--format", "metal", "-o", dir + "/sky.metal"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err_lines(), 1);
    EXPECT_FALSE(fs::exists(dir + "/sky.metal"));
    auto u = run_cli({"sky", "export", tiny_model(), "-o", dir + "/x.glsl"}); // --format missing: usage error
    EXPECT_EQ(u.exit_code, 2);
}

TEST(NeuralCli, ErrorReport) {
    const std::string dir = temp_dir("neural_error");
    ASSERT_FALSE(fs::exists(dir + "/views"));
    auto r = run_cli({"sky", "error", "--model", tiny_model(), "--samples", "2000", "--size", "48x32", "--views-dir",
                      dir + "/views", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::is_empty(dir + "/views")) << "the views folder is created and filled";
    // A run that fails (no such model) leaves no folder behind.
    auto bad = run_cli({"sky", "error", "--model", dir + "/missing.json", "--views-dir", dir + "/views2"});
    EXPECT_EQ(bad.exit_code, 1) << bad.err;
    EXPECT_FALSE(fs::exists(dir + "/views2"));
    const auto j = nlohmann::json::parse(r.out);
    const auto& rel = j["relative_error"];
    const auto n = rel["all"]["count"].get<int>() + j["night_absolute_error_over_max_n"]["count"].get<int>();
    EXPECT_EQ(n, 2000);
    EXPECT_EQ(rel["all"]["count"].get<int>(), rel["day"]["count"].get<int>() + rel["twilight"]["count"].get<int>());
    for (const char* k : {"all", "day", "twilight"}) {
        const auto& s = rel[k];
        EXPECT_LE(s["p50"].get<double>(), s["p95"].get<double>());
        EXPECT_LE(s["p95"].get<double>(), s["p99"].get<double>());
        EXPECT_LE(s["p99"].get<double>(), s["max"].get<double>());
    }
    ASSERT_EQ(j["views"].size(), 6u);
    EXPECT_GT(j["min_view_psnr_db"].get<double>(), 0.0);
    EXPECT_TRUE(fs::exists(dir + "/views/1_sea_level_neural.png"));
    EXPECT_TRUE(fs::exists(dir + "/views/1_sea_level_reference.png"));
    // The flight's samples (altitude 0-60 km, the sun down to -20 degrees), counted apart.
    const auto& f = j["flight"];
    EXPECT_EQ(f["samples"].get<int>(), 100000);
    EXPECT_EQ(f["relative_error"]["all"]["count"].get<int>() + f["night_absolute_error_over_max_n"]["count"].get<int>(),
              100000);
    EXPECT_EQ(f["max_altitude_km"].get<double>(), 60.0);
    auto t = run_cli({"sky", "error", "--model", tiny_model(), "--samples", "500", "--no-views", "--flight-samples",
                      "300"});
    ASSERT_EQ(t.exit_code, 0) << t.err;
    EXPECT_NE(t.out.find("day (sun above horizon)"), std::string::npos);
    EXPECT_NE(t.out.find("flight: 300 samples, altitude 0 to 60 km, sun down to -20 deg"), std::string::npos);
    auto none = run_cli({"sky", "error", "--model", tiny_model(), "--samples", "500", "--no-views", "--flight-samples",
                         "0", "--json"});
    ASSERT_EQ(none.exit_code, 0) << none.err;
    EXPECT_FALSE(nlohmann::json::parse(none.out).contains("flight"));
}

TEST(NeuralCli, TheSeedsNetworkIsOneFlagSet) {
    const std::string dir = temp_dir("neural_seed");
    auto r = run_cli({"sky", "train", "--preset", "paper", "--samples", "2000", "--heldout", "300", "--epochs", "2",
                      "--lm-iterations", "1", "--topology", "paper", "--inputs", "seed", "--outputs", "radiance",
                      "--brightness", "linear", "--table-rule", "as-published", "--steps", "16", "-o",
                      dir + "/seed.json", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["topology"], "paper");
    EXPECT_EQ(j["weights"], 324);
    const auto w = nlohmann::json::parse(read(dir + "/seed.json"));
    EXPECT_EQ(w["encoding"]["inputs"], "seed");
    EXPECT_EQ(w["encoding"]["outputs"], "radiance");
    EXPECT_EQ(w["encoding"]["brightness"], "linear");
    // Phase-factored outputs need single scattering: one line naming the flag.
    auto m = run_cli({"sky", "train", "--preset", "earth", "--scattering", "multiple", "--multiple-method",
                      "hillaire", "--samples", "100", "--outputs", "phase-factored", "-o", dir + "/m.json"});
    EXPECT_EQ(m.exit_code, 2) << m.err;
    EXPECT_EQ(m.err_lines(), 1) << m.err;
    EXPECT_NE(m.err.find("--outputs"), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(dir + "/m.json"));
    auto bad = run_cli({"sky", "train", "--inputs", "sideways", "-o", dir + "/b.json"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("--inputs"), std::string::npos) << bad.err;
}

// What is not asked for comes from the schedule measured for the network's
// size (training_schedule): 150 epochs from 0.01 and no LM at 64 wide; a flag
// overrides its part only.
TEST(NeuralCli, TrainFollowsTheSizesSchedule) {
    const std::string dir = temp_dir("neural_schedule");
    auto wide = run_cli({"sky", "train", "--preset", "paper", "--samples", "1000", "--heldout", "100", "--topology",
                         "shared:64x4", "-o", dir + "/w.json", "--json"});
    ASSERT_EQ(wide.exit_code, 0) << wide.err;
    auto j = nlohmann::json::parse(wide.out);
    EXPECT_EQ(j["adam_epochs"], 150);
    EXPECT_EQ(j["lm_iterations"], 0);
    auto asked = run_cli({"sky", "train", "--preset", "paper", "--samples", "1000", "--heldout", "100", "--topology",
                          "shared:64x4", "--epochs", "2", "-o", dir + "/w.json", "--json"});
    ASSERT_EQ(asked.exit_code, 0) << asked.err;
    j = nlohmann::json::parse(asked.out);
    EXPECT_EQ(j["adam_epochs"], 2);
    EXPECT_EQ(j["lm_iterations"], 0);
    auto mid = run_cli({"sky", "train", "--preset", "paper", "--samples", "1000", "--heldout", "100", "--topology",
                        "shared:24x8", "--epochs", "1", "-o", dir + "/w.json", "--json"});
    ASSERT_EQ(mid.exit_code, 0) << mid.err;
    EXPECT_EQ(nlohmann::json::parse(mid.out)["lm_iterations"], 3);
}

TEST(NeuralCli, CorruptWeightsAreOneLineErrors) {
    const std::string dir = temp_dir("neural_corrupt");
    const std::string good = read(tiny_model());
    const std::string truncated = write(dir, "truncated.json", good.substr(0, good.size() / 3));
    auto j = nlohmann::json::parse(good);
    j["weights"][0].erase(0);
    const std::string short_w = write(dir, "short.json", j.dump());
    const std::string other = write(dir, "other.json", "{\"format\": \"something\"}");
    for (const std::string& f : {truncated, short_w, other, dir + "/missing.json"}) {
        for (const std::vector<std::string>& cmd :
             {std::vector<std::string>{"sky", "export", f, "--format", "glsl", "-o", dir + "/o.glsl"},
              std::vector<std::string>{"sky", "error", "--model", f, "--no-views"},
              std::vector<std::string>{"sky", "render", "--model", f, "--altitude-km", "0", "--sun-elevation-deg",
                                       "10", "-o", dir + "/o.png"}}) {
            auto r = run_cli(cmd);
            EXPECT_EQ(r.exit_code, 1) << f << " " << cmd[1];
            EXPECT_EQ(r.err_lines(), 1) << r.err;
            EXPECT_NE(r.err.find(f), std::string::npos) << r.err; // names the file
        }
    }
    EXPECT_FALSE(fs::exists(dir + "/o.glsl"));
    EXPECT_FALSE(fs::exists(dir + "/o.png"));
}
