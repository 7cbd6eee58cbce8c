// The heavy checks: every Lebedev rule against every monomial up to its
// precision, the full Gram matrix of the SH under each rule, and the designs up
// to t = 21.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <eigen3/Eigen/Core>

#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/test_util.h"

using namespace skybake;

TEST(LebedevSlow, AllRulesExactForAllMonomials) {
    for (const LebedevInfo& info : lebedev_rules())
        EXPECT_LT(sphere_test::monomial_error(lebedev_rule_by_precision(info.precision), info.precision), 1e-12)
            << "lebedev:" << info.points;
}

// 4π Σ_k w_k Y_lm(x_k) Y_l'm'(x_k) = δ for all l, l' ≤ min(⌊p/2⌋, 24) (so l + l' ≤ p),
// as one matrix product Yᵀ W Y per rule. The remaining pairs with l + l' ≤ p are
// covered by Lebedev.IntegratesEveryHarmonicUpToThePrecision (the products span
// the harmonics of degree ≤ p).
TEST(LebedevSlow, GramMatrixIsTheIdentity) {
    for (const LebedevInfo& info : lebedev_rules()) {
        const SphereRule r = lebedev_rule_by_precision(info.precision);
        const int lmax = std::min(info.precision / 2, 24), c = sh_count(lmax);
        Eigen::MatrixXd y(Eigen::Index(r.size()), c), wy(Eigen::Index(r.size()), c);
        std::vector<double> row(static_cast<std::size_t>(c));
        for (std::size_t k = 0; k < r.size(); ++k) {
            sh_eval(lmax, r.points[k], row.data());
            for (int i = 0; i < c; ++i) {
                y(Eigen::Index(k), i) = row[std::size_t(i)];
                wy(Eigen::Index(k), i) = 4.0 * 3.141592653589793 * r.weights[k] * row[std::size_t(i)];
            }
        }
        const Eigen::MatrixXd gram = y.transpose() * wy;
        const double err = (gram - Eigen::MatrixXd::Identity(c, c)).cwiseAbs().maxCoeff();
        EXPECT_LT(err, 1e-12) << "lebedev:" << info.points << " (l, l' <= " << lmax << ")";
    }
}

TEST(DesignSlow, DesignsUpToT21) {
    for (int t = 15; t <= 21; ++t) {
        DesignReport rep;
        const SphereRule r = compute_design(t, &rep);
        EXPECT_LT(design_residual(r, t), 1e-13) << "t=" << t;
        EXPECT_LT(sphere_test::monomial_error(r, t), 1e-13) << "t=" << t;
        EXPECT_LE(int(r.size()), 21 * 21 / 2 + 30);
    }
}
