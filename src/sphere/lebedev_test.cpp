// Lebedev–Laikov rules: point counts from the published table (REFERENCE.md),
// exactness against closed-form monomial integrals, and SH orthonormality.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "skybake/error.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/test_util.h"

using namespace skybake;

namespace {

// Lebedev & Laikov 1999, table 1 (also REFERENCE.md): precision -> points.
const std::vector<std::pair<int, int>> kPublished = {
    {3, 6},      {5, 14},     {7, 26},     {9, 38},     {11, 50},    {13, 74},    {15, 86},    {17, 110},
    {19, 146},   {21, 170},   {23, 194},   {25, 230},   {27, 266},   {29, 302},   {31, 350},   {35, 434},
    {41, 590},   {47, 770},   {53, 974},   {59, 1202},  {65, 1454},  {71, 1730},  {77, 2030},  {83, 2354},
    {89, 2702},  {95, 3074},  {101, 3470}, {107, 3890}, {113, 4334}, {119, 4802}, {125, 5294}, {131, 5810}};

} // namespace

TEST(Lebedev, ThirtyTwoRulesWithThePublishedPointCounts) {
    ASSERT_EQ(lebedev_rules().size(), kPublished.size());
    for (std::size_t i = 0; i < kPublished.size(); ++i) {
        EXPECT_EQ(lebedev_rules()[i].precision, kPublished[i].first);
        EXPECT_EQ(lebedev_rules()[i].points, kPublished[i].second);
        const SphereRule r = lebedev_rule_by_precision(kPublished[i].first);
        EXPECT_EQ(int(r.size()), kPublished[i].second) << "precision " << kPublished[i].first;
        EXPECT_EQ(r.weights.size(), r.points.size());
        EXPECT_EQ(r.precision, kPublished[i].first);
    }
}

TEST(Lebedev, UnitPointsDistinctAndWeightsSumToOne) {
    for (const auto& [p, n] : kPublished) {
        const SphereRule r = lebedev_rule_by_points(n);
        double sum = 0.0;
        for (std::size_t k = 0; k < r.size(); ++k) {
            EXPECT_NEAR(glm::length(r.points[k]), 1.0, 1e-15);
            sum += r.weights[k];
        }
        EXPECT_NEAR(sum, 1.0, 1e-13) << n;
        // Distinct: the closest pair is not a duplicate.
        double closest = 4.0;
        for (std::size_t a = 0; a < r.size() && n <= 1202; ++a)
            for (std::size_t b = a + 1; b < r.size(); ++b)
                closest = std::min(closest, glm::length(r.points[a] - r.points[b]));
        EXPECT_GT(closest, 1e-3) << n;
    }
}

TEST(Lebedev, NegativeWeightsOnlyWhereTheTableHasThem) {
    // REFERENCE.md: the 74-, 230- and 266-point rules have negative weights.
    for (const auto& [p, n] : kPublished)
        EXPECT_EQ(lebedev_rule_by_points(n).has_negative_weights(), n == 74 || n == 230 || n == 266) << n;
}

// Every monomial x^i y^j z^k of degree ≤ p integrates exactly (closed form, no SH involved).
// Rules up to precision 53 here; all 32 in sphere_slow_test.cpp.
TEST(Lebedev, ExactForAllMonomialsUpToThePrecision) {
    for (const auto& [p, n] : kPublished)
        if (p <= 53)
            EXPECT_LT(sphere_test::monomial_error(lebedev_rule_by_precision(p), p), 1e-12) << "lebedev:" << n;
}

// Σ w Y_LM = δ_L0 / √(4π) for L ≤ p. Since the products Y_lm Y_l'm' with l + l' ≤ p span
// exactly the harmonics of degree ≤ p, this is the statement 4π Σ w Y_lm Y_l'm' = δ for
// l + l' ≤ p; the explicit Gram matrix is checked in sphere_slow_test.cpp and below.
TEST(Lebedev, IntegratesEveryHarmonicUpToThePrecision) {
    for (const auto& [p, n] : kPublished) {
        const SphereRule r = lebedev_rule_by_precision(p);
        std::vector<double> sum(std::size_t(sh_count(p)), 0.0), y(sum.size());
        for (std::size_t k = 0; k < r.size(); ++k) {
            sh_eval(p, r.points[k], y.data());
            for (std::size_t i = 0; i < y.size(); ++i)
                sum[i] += r.weights[k] * y[i];
        }
        double worst = std::abs(sum[0] * std::sqrt(4.0 * 3.141592653589793) - 1.0);
        for (std::size_t i = 1; i < sum.size(); ++i)
            worst = std::max(worst, std::abs(sum[i]) * std::sqrt(4.0 * 3.141592653589793));
        EXPECT_LT(worst, 1e-12) << "lebedev:" << n;
    }
}

TEST(Lebedev, GramMatrixForSmallRules) {
    // 4π Σ w Y_lm Y_l'm' = δ for every pair with l + l' ≤ p (rules up to precision 31).
    for (const auto& [p, n] : kPublished) {
        if (p > 31)
            break;
        const SphereRule r = lebedev_rule_by_precision(p);
        const int c = sh_count(p);
        std::vector<double> y(std::size_t(r.size()) * std::size_t(c));
        for (std::size_t k = 0; k < r.size(); ++k)
            sh_eval(p, r.points[k], y.data() + k * std::size_t(c));
        double worst = 0.0;
        for (int l = 0; l <= p; ++l)
            for (int l2 = 0; l + l2 <= p; ++l2)
                for (int m = -l; m <= l; ++m)
                    for (int m2 = -l2; m2 <= l2; ++m2) {
                        const int a = sh_index(l, m), b = sh_index(l2, m2);
                        double s = 0.0;
                        for (std::size_t k = 0; k < r.size(); ++k)
                            s += r.weights[k] * y[k * std::size_t(c) + std::size_t(a)] * y[k * std::size_t(c) + std::size_t(b)];
                        worst = std::max(worst, std::abs(4.0 * 3.141592653589793 * s - (a == b ? 1.0 : 0.0)));
                    }
        EXPECT_LT(worst, 1e-12) << "lebedev:" << n;
    }
}

TEST(Lebedev, NotExactOneDegreeAbove) {
    // Sanity check of the test itself: a rule of precision p misses some degree-(p+1) harmonic.
    const SphereRule r = lebedev_rule_by_precision(11);
    std::vector<double> sum(std::size_t(sh_count(12)), 0.0), y(sum.size());
    for (std::size_t k = 0; k < r.size(); ++k) {
        sh_eval(12, r.points[k], y.data());
        for (std::size_t i = 0; i < y.size(); ++i)
            sum[i] += r.weights[k] * y[i];
    }
    double worst = 0.0;
    for (int i = sh_index(12, -12); i < sh_count(12); ++i)
        worst = std::max(worst, std::abs(sum[std::size_t(i)]));
    EXPECT_GT(worst, 1e-3);
}

TEST(Lebedev, UnknownRulesAreErrors) {
    EXPECT_THROW(lebedev_rule_by_points(500), Error);
    EXPECT_THROW(lebedev_rule_by_precision(33), Error);
}
