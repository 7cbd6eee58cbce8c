// skybake sphere list / show / export: output contracts and errors.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

using skybake::test::run_cli;

TEST(SphereCli, ListHasAllLebedevRules) {
    auto r = run_cli({"sphere", "list", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["lebedev"].size(), 32u);
    EXPECT_EQ(j["lebedev"][0]["points"], 6);
    EXPECT_EQ(j["lebedev"][31]["points"], 5810);
    EXPECT_EQ(j["lebedev"][31]["precision"], 131);
    auto human = run_cli({"sphere", "list"});
    EXPECT_EQ(human.exit_code, 0);
    EXPECT_NE(human.out.find("lebedev:5810"), std::string::npos);
}

TEST(SphereCli, ShowJsonDescribesTheRule) {
    auto r = run_cli({"sphere", "show", "lebedev:p131", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["spec"], "lebedev:5810");
    EXPECT_EQ(j["precision"], 131);
    EXPECT_EQ(j["points"], 5810);
    EXPECT_NEAR(j["weight_sum"].get<double>(), 1.0, 1e-13);
    ASSERT_EQ(j["nodes"].size(), 5810u);
    double sum = 0.0, zz = 0.0;
    for (const auto& n : j["nodes"]) {
        sum += n[3].get<double>();
        zz += n[3].get<double>() * n[2].get<double>() * n[2].get<double>();
    }
    EXPECT_NEAR(sum, 1.0, 1e-13);
    EXPECT_NEAR(zz, 1.0 / 3.0, 1e-13); // ∫ z² dμ = 1/3
}

TEST(SphereCli, ShowPhongAndDesign) {
    const std::string cache = skybake::test::temp_dir("sphere-cli-cache");
    ::setenv("SKYBAKE_CACHE_DIR", cache.c_str(), 1);
    auto d = run_cli({"sphere", "show", "design:t5", "--json"});
    ASSERT_EQ(d.exit_code, 0) << d.err;
    const auto jd = nlohmann::json::parse(d.out);
    EXPECT_EQ(jd["kind"], "design");
    EXPECT_GE(jd["precision"].get<int>(), 5);
    // The design was cached, and a second run (reading the cache) gives the same points.
    EXPECT_TRUE(std::ifstream(cache + "/design-v1-t5.txt").good());
    auto d2 = run_cli({"sphere", "show", "design:t5", "--json"});
    EXPECT_EQ(nlohmann::json::parse(d2.out)["nodes"], jd["nodes"]);

    auto p = run_cli({"sphere", "show", "phong:a=32,n=4", "--limit", "3"});
    ASSERT_EQ(p.exit_code, 0) << p.err;
    EXPECT_NE(p.out.find("points      32"), std::string::npos) << p.out;
    EXPECT_NE(p.out.find("precision   7"), std::string::npos) << p.out;
}

TEST(SphereCli, ExportWritesCsvRows) {
    const std::string dir = skybake::test::temp_dir("sphere-export");
    const std::string file = dir + "/points.csv";
    auto r = run_cli({"sphere", "export", "lebedev:74", "-o", file, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["points"], 74);
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "x,y,z,w");
    int rows = 0;
    double sum = 0.0, negative = 0.0;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        double v[4];
        char comma;
        s >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
        ASSERT_TRUE(bool(s)) << line;
        EXPECT_NEAR(v[0] * v[0] + v[1] * v[1] + v[2] * v[2], 1.0, 1e-14);
        sum += v[3];
        negative += v[3] < 0;
        ++rows;
    }
    EXPECT_EQ(rows, 74);
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_GT(negative, 0); // REFERENCE.md: the 74-point rule has negative weights
}

TEST(SphereCli, BadInputIsOneLineAndNoOutputFile) {
    const std::string dir = skybake::test::temp_dir("sphere-bad");
    auto r = run_cli({"sphere", "export", "lebedev:500", "-o", dir + "/x.csv"});
    EXPECT_EQ(r.exit_code, 2); // a bad rule spec is a bad argument: a usage error
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find("available point counts are 6, 14"), std::string::npos) << r.err;
    EXPECT_FALSE(std::ifstream(dir + "/x.csv").good());
    auto s = run_cli({"sphere", "show", "phong:a=4"});
    EXPECT_EQ(s.exit_code, 2);
    EXPECT_EQ(s.err_lines(), 1) << s.err;
    auto u = run_cli({"sphere", "export", "lebedev:6"}); // missing -o
    EXPECT_EQ(u.exit_code, 2);
    EXPECT_EQ(u.err_lines(), 1) << u.err;
    auto w = run_cli({"sphere", "export", "lebedev:6", "-o", "/nonexistent-dir/x.csv"});
    EXPECT_EQ(w.exit_code, 1);
    EXPECT_EQ(w.err_lines(), 1) << w.err;
}
