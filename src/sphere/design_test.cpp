// Spherical t-designs from the library's own optimiser: the defining equations,
// exactness for monomials (closed form), point counts, and the disk cache.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "skybake/error.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/test_util.h"

using namespace skybake;

namespace {

// A private cache folder for the test process.
struct CacheDir {
    std::filesystem::path path;
    CacheDir() {
        path = std::filesystem::temp_directory_path() / ("skybake-design-test-" + std::to_string(::getpid()));
        std::filesystem::remove_all(path);
        ::setenv("SKYBAKE_CACHE_DIR", path.c_str(), 1);
    }
    ~CacheDir() { std::filesystem::remove_all(path); }
};

} // namespace

TEST(Design, SmallDesignsSatisfyTheDefiningEquations) {
    for (int t = 1; t <= 14; ++t) {
        DesignReport rep;
        const SphereRule r = compute_design(t, &rep);
        EXPECT_GE(int(r.size()), design_point_count(t));
        EXPECT_LE(int(r.size()), design_point_count(t) + 8);
        EXPECT_EQ(rep.points, int(r.size()));
        EXPECT_GE(r.precision, t);
        // Σ_j Y_lm(x_j) = 0 for 1 ≤ l ≤ t (to rounding: 1e-13 per unit weight).
        const int lmax = t;
        std::vector<double> sum(std::size_t(sh_count(lmax)), 0.0), y(sum.size());
        for (const glm::dvec3& p : r.points) {
            EXPECT_NEAR(glm::length(p), 1.0, 1e-14);
            sh_eval(lmax, p, y.data());
            for (std::size_t i = 0; i < y.size(); ++i)
                sum[i] += y[i];
        }
        for (std::size_t i = 1; i < sum.size(); ++i)
            EXPECT_LT(std::abs(sum[i]) / double(r.size()), 1e-13) << "t=" << t << " i=" << i;
        EXPECT_LT(sphere_test::monomial_error(r, t), 1e-13) << "t=" << t;
        for (double w : r.weights)
            EXPECT_DOUBLE_EQ(w, 1.0 / double(r.size()));
    }
}

TEST(Design, PointCountsAreAboutTSquaredOverTwo) {
    // Hardin & Sloane's table: 240 points for t = 21; numerically found designs reach ≈ t²/2.
    EXPECT_EQ(design_point_count(1), 2);
    EXPECT_EQ(design_point_count(3), 8); // the cube is a 3-design
    EXPECT_LE(design_point_count(21), 240);
    EXPECT_GE(design_point_count(21), 21 * 21 / 2);
    EXPECT_THROW(design_point_count(0), Error);
    EXPECT_THROW(design_point_count(41), Error);
}

TEST(Design, CacheIsWrittenAndADamagedFileIsRecomputed) {
    CacheDir cache;
    EXPECT_EQ(design_cache_dir(), cache.path);
    // A damaged cache file for t = 6, present before the first use in this process.
    std::filesystem::create_directories(cache.path);
    const std::filesystem::path f6 = cache.path / "design-v1-t6.txt";
    {
        std::ofstream out(f6);
        out << "# damaged\n0.1 0.2 0.3\n";
    }
    const SphereRule r6 = design_rule(6);
    EXPECT_LT(design_residual(r6, 6), 1e-13);
    // It was recomputed and the file replaced: it now holds the free half of the
    // antipodal pairs, one "x y z" row each.
    std::ifstream in(f6);
    std::string line;
    int rows = 0;
    while (std::getline(in, line))
        rows += !line.empty() && line[0] != '#';
    EXPECT_EQ(2 * rows, int(r6.size()));
    // And the memory cache returns the same rule.
    EXPECT_EQ(design_rule(6).points, r6.points);
}

// SKYBAKE_CACHE_DIR=off (as the test suite sets it) keeps designs in memory:
// no folder named "off", nothing read or written.
TEST(Design, CacheOffWritesNothing) {
    const char* old = std::getenv("SKYBAKE_CACHE_DIR");
    const std::string keep = old ? old : "";
    const std::filesystem::path here =
        std::filesystem::temp_directory_path() / ("skybake-design-off-" + std::to_string(::getpid()));
    std::filesystem::create_directories(here);
    const std::filesystem::path cwd = std::filesystem::current_path();
    std::filesystem::current_path(here);
    ::setenv("SKYBAKE_CACHE_DIR", "off", 1);
    EXPECT_TRUE(design_cache_dir().empty());
    const SphereRule r = design_rule(5);
    EXPECT_LE(design_residual(r, 5), 1e-10);
    EXPECT_TRUE(std::filesystem::is_empty(here));
    std::filesystem::current_path(cwd);
    std::filesystem::remove_all(here);
    if (old)
        ::setenv("SKYBAKE_CACHE_DIR", keep.c_str(), 1);
    else
        ::unsetenv("SKYBAKE_CACHE_DIR");
}
