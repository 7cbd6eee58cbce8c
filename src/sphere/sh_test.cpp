// Spherical harmonics: closed forms of the low bands, orthonormality under a
// Lebedev rule, projection, rotation, and zonal convolution against the
// Ramamoorthi–Hanrahan coefficients.
#include <gtest/gtest.h>

#include <cmath>

#include "skybake/error.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/sh_eval.h"

using namespace skybake;

namespace {

const double kPi = 3.141592653589793;

std::vector<glm::dvec3> directions(int n) { return marsaglia_rule(n, 99).points; }

std::vector<double> random_coeffs(int lmax, std::uint64_t seed) {
    const SphereRule r = marsaglia_rule(sh_count(lmax), seed);
    std::vector<double> c(std::size_t(sh_count(lmax)));
    for (std::size_t i = 0; i < c.size(); ++i)
        c[i] = r.points[i].x;
    return c;
}

} // namespace

TEST(Sh, LowBandsMatchTheClosedForms) {
    for (const glm::dvec3& d : directions(50)) {
        const double x = d.x, y = d.y, z = d.z;
        const std::vector<double> Y = sh_eval(3, d);
        const double c1 = std::sqrt(3.0 / (4 * kPi));
        EXPECT_NEAR(Y[sh_index(0, 0)], 0.5 / std::sqrt(kPi), 1e-15);
        EXPECT_NEAR(Y[sh_index(1, -1)], c1 * y, 1e-15);
        EXPECT_NEAR(Y[sh_index(1, 0)], c1 * z, 1e-15);
        EXPECT_NEAR(Y[sh_index(1, 1)], c1 * x, 1e-15);
        EXPECT_NEAR(Y[sh_index(2, -2)], 0.5 * std::sqrt(15 / kPi) * x * y, 1e-14);
        EXPECT_NEAR(Y[sh_index(2, -1)], 0.5 * std::sqrt(15 / kPi) * y * z, 1e-14);
        EXPECT_NEAR(Y[sh_index(2, 0)], 0.25 * std::sqrt(5 / kPi) * (3 * z * z - 1), 1e-14);
        EXPECT_NEAR(Y[sh_index(2, 1)], 0.5 * std::sqrt(15 / kPi) * x * z, 1e-14);
        EXPECT_NEAR(Y[sh_index(2, 2)], 0.25 * std::sqrt(15 / kPi) * (x * x - y * y), 1e-14);
        EXPECT_NEAR(Y[sh_index(3, 0)], 0.25 * std::sqrt(7 / kPi) * (5 * z * z * z - 3 * z), 1e-14);
        EXPECT_NEAR(Y[sh_index(3, 3)], 0.25 * std::sqrt(35 / (2 * kPi)) * (x * x * x - 3 * x * y * y), 1e-14);
        EXPECT_NEAR(Y[sh_index(3, -3)], 0.25 * std::sqrt(35 / (2 * kPi)) * (3 * x * x * y - y * y * y), 1e-14);
        // Graphics constants (Ramamoorthi & Hanrahan 2001, eq. 12).
        EXPECT_NEAR(0.5 / std::sqrt(kPi), 0.282095, 1e-6);
        EXPECT_NEAR(c1, 0.488603, 1e-6);
    }
}

TEST(Sh, FloatEvaluationAgreesWithDouble) {
    const int lmax = 10;
    std::vector<float> yf(std::size_t(sh_count(lmax)));
    for (const glm::dvec3& d : directions(20)) {
        sphere::sh_eval_hd<float>(lmax, float(d.x), float(d.y), float(d.z), yf.data());
        const std::vector<double> yd = sh_eval(lmax, d);
        for (std::size_t i = 0; i < yd.size(); ++i)
            EXPECT_NEAR(yf[i], yd[i], 2e-5);
    }
}

TEST(Sh, OrthonormalUnderLebedev5810) {
    // Precision 131 integrates Y_lm Y_l'm' exactly for l + l' ≤ 131; here l, l' ≤ 12
    // (up to 65 in sphere_slow_test.cpp).
    const SphereRule r = lebedev_rule_by_points(5810);
    const int lmax = 12, c = sh_count(lmax);
    std::vector<double> y(r.size() * std::size_t(c));
    for (std::size_t k = 0; k < r.size(); ++k)
        sh_eval(lmax, r.points[k], y.data() + k * std::size_t(c));
    double worst = 0.0;
    for (int a = 0; a < c; ++a)
        for (int b = a; b < c; ++b) {
            double s = 0.0;
            for (std::size_t k = 0; k < r.size(); ++k)
                s += r.weights[k] * y[k * std::size_t(c) + std::size_t(a)] * y[k * std::size_t(c) + std::size_t(b)];
            worst = std::max(worst, std::abs(4 * kPi * s - (a == b ? 1.0 : 0.0)));
        }
    EXPECT_LT(worst, 1e-12);
}

TEST(Sh, HighBandsStayNormalised) {
    // Band 131 through the recurrence: still orthonormal (diagonal of the Gram matrix).
    const SphereRule r = lebedev_rule_by_points(5810);
    const int l = 65;
    std::vector<double> y(std::size_t(sh_count(l))), norm(2 * l + 1, 0.0);
    for (std::size_t k = 0; k < r.size(); ++k) {
        sh_eval(l, r.points[k], y.data());
        for (int m = -l; m <= l; ++m)
            norm[std::size_t(m + l)] += 4 * kPi * r.weights[k] * y[std::size_t(sh_index(l, m))] * y[std::size_t(sh_index(l, m))];
    }
    for (double v : norm)
        EXPECT_NEAR(v, 1.0, 1e-12);
}

TEST(Sh, ProjectionReconstructsAPolynomial) {
    auto f = [](const glm::dvec3& d) { return 1.0 + d.x - 2.0 * d.y * d.z + d.z * d.z * d.z; };
    const std::vector<double> c = sh_project(f, 5, lebedev_rule_by_points(302));
    for (int i = sh_count(3); i < sh_count(5); ++i)
        EXPECT_NEAR(c[std::size_t(i)], 0.0, 1e-13);
    for (const glm::dvec3& d : directions(30))
        EXPECT_NEAR(sh_evaluate(c, 5, d), f(d), 1e-13);
}

TEST(Sh, RotationMatchesDirectEvaluation) {
    for (int lmax : {1, 2, 5, 10}) {
        const std::vector<double> c = random_coeffs(lmax, std::uint64_t(lmax));
        for (std::uint32_t v = 0; v < 5; ++v) {
            const glm::dmat3 rot = vertex_rotation(v, 11);
            const std::vector<double> g = sh_rotate(c, lmax, rot);
            for (const glm::dvec3& d : directions(20))
                EXPECT_NEAR(sh_evaluate(g, lmax, d), sh_evaluate(c, lmax, glm::transpose(rot) * d), 1e-12)
                    << "lmax " << lmax;
            for (int l = 0; l <= lmax; ++l) {
                double e0 = 0.0, e1 = 0.0;
                for (int m = -l; m <= l; ++m) {
                    e0 += c[std::size_t(sh_index(l, m))] * c[std::size_t(sh_index(l, m))];
                    e1 += g[std::size_t(sh_index(l, m))] * g[std::size_t(sh_index(l, m))];
                }
                EXPECT_NEAR(e1, e0, 1e-12) << "band energy, l = " << l;
            }
        }
    }
}

TEST(Sh, RotationIsStableToHighBands) {
    const int lmax = 40;
    const glm::dmat3 rot = vertex_rotation(3, 5);
    const ShRotation m(lmax, rot);
    // Each band matrix is orthogonal: rows have unit norm and are mutually orthogonal.
    for (int l : {20, 40}) {
        double worst = 0.0;
        for (int a = -l; a <= l; ++a)
            for (int b = -l; b <= l; ++b) {
                double s = 0.0;
                for (int k = -l; k <= l; ++k)
                    s += m.element(l, a, k) * m.element(l, b, k);
                worst = std::max(worst, std::abs(s - (a == b ? 1.0 : 0.0)));
            }
        EXPECT_LT(worst, 1e-10) << "l = " << l;
    }
    const std::vector<double> c = random_coeffs(lmax, 77);
    const std::vector<double> g = m.apply(c);
    for (const glm::dvec3& d : directions(10))
        EXPECT_NEAR(sh_evaluate(g, lmax, d), sh_evaluate(c, lmax, glm::transpose(rot) * d), 1e-10);
}

TEST(Sh, IdentityAndComposition) {
    const int lmax = 6;
    const std::vector<double> c = random_coeffs(lmax, 3);
    const std::vector<double> same = sh_rotate(c, lmax, glm::dmat3(1.0));
    for (std::size_t i = 0; i < c.size(); ++i)
        EXPECT_NEAR(same[i], c[i], 1e-14);
    const glm::dmat3 a = vertex_rotation(1, 2), b = vertex_rotation(2, 2);
    const std::vector<double> ab = sh_rotate(sh_rotate(c, lmax, b), lmax, a), direct = sh_rotate(c, lmax, a * b);
    for (std::size_t i = 0; i < c.size(); ++i)
        EXPECT_NEAR(ab[i], direct[i], 1e-13);
}

// Ramamoorthi & Hanrahan 2001, eq. 8-9: Â_0 = π, Â_1 = 2π/3, Â_2 = π/4, Â_3 = 0, Â_4 = −π/24.
TEST(ShZonal, RamamoorthiHanrahanCoefficients) {
    EXPECT_NEAR(clamped_cosine_zonal(0), kPi, 1e-14);
    EXPECT_NEAR(clamped_cosine_zonal(1), 2 * kPi / 3, 1e-14);
    EXPECT_NEAR(clamped_cosine_zonal(2), kPi / 4, 1e-14);
    EXPECT_NEAR(clamped_cosine_zonal(3), 0.0, 1e-14);
    EXPECT_NEAR(clamped_cosine_zonal(4), -kPi / 24, 1e-14);
    EXPECT_NEAR(clamped_cosine_zonal(5), 0.0, 1e-14);
    // R&H eq. 9 for even l ≥ 2: Â_l = 2π (−1)^(l/2 − 1) / ((l + 2)(l − 1)) · l! / (2^l ((l/2)!)²).
    for (int l = 2; l <= 40; l += 2) {
        const double lf = std::lgamma(l + 1.0) - l * std::log(2.0) - 2 * std::lgamma(l / 2 + 1.0);
        const double expect = 2 * kPi * ((l / 2 - 1) % 2 ? -1.0 : 1.0) / ((l + 2.0) * (l - 1.0)) * std::exp(lf);
        EXPECT_NEAR(clamped_cosine_zonal(l), expect, 1e-13 * std::max(1.0, std::abs(expect))) << l;
    }
}

TEST(ShZonal, TransferOfAnUnoccludedPointFromAPhongRule) {
    // REFERENCE.md: ∫ max(cos θ, 0) Y_l0 dω = √π/2, √(π/3), √(5π)/8 for l = 0, 1, 2. Computed
    // independently with the a = 1 Phong rule: ∫ max(z,0) g dω = 4π ∫ g z₊ dμ = π Σ w g.
    const SphereRule r = phong_rule(1.0, 6); // exact to degree 11
    auto transfer = [&](int l) {
        return kPi * integrate(r, [&](const glm::dvec3& d) { return sh_eval(l, d)[std::size_t(sh_index(l, 0))]; });
    };
    EXPECT_NEAR(transfer(0), std::sqrt(kPi) / 2, 1e-13);
    EXPECT_NEAR(transfer(0), 0.886227, 1e-6);
    EXPECT_NEAR(transfer(1), std::sqrt(kPi / 3), 1e-13);
    EXPECT_NEAR(transfer(1), 1.023327, 1e-6);
    EXPECT_NEAR(transfer(2), std::sqrt(5 * kPi) / 8, 1e-13);
    EXPECT_NEAR(transfer(2), 0.495416, 1e-6);
    for (int l = 0; l <= 10; ++l)
        EXPECT_NEAR(clamped_cosine_zonal(l), std::sqrt(4 * kPi / (2 * l + 1)) * transfer(l), 1e-13) << l;
}

TEST(ShZonal, PhongLobeAgainstGaussJacobi) {
    for (double a : {0.0, 7.5, 32.0, 100.0}) {
        const SphereRule r = phong_rule(a, 16); // exact to degree 31
        for (int l = 0; l <= 30; ++l) {
            // ∫ max(z,0)^a Y_l0 dω = 4π/(2(a+1)) Σ w Y_l0; k̂_l = √(4π/(2l+1)) × that.
            const double proj = 4 * kPi / (2 * (a + 1)) *
                                integrate(r, [&](const glm::dvec3& d) { return sh_eval(l, d)[std::size_t(sh_index(l, 0))]; });
            const double expect = std::sqrt(4 * kPi / (2 * l + 1)) * proj;
            EXPECT_NEAR(phong_lobe_zonal(l, a), expect, 1e-12) << "a=" << a << " l=" << l;
        }
    }
}

TEST(ShZonal, IrradianceOfALinearSky) {
    // L(x) = 1 + z: E(n) = ∫ L max(n·x, 0) dω = π + (2π/3) n_z.
    const std::vector<double> lc = sh_project([](const glm::dvec3& d) { return 1.0 + d.z; }, 4, lebedev_rule_by_points(110));
    std::vector<double> kernel;
    for (int l = 0; l <= 4; ++l)
        kernel.push_back(clamped_cosine_zonal(l));
    const std::vector<double> e = sh_convolve_zonal(lc, 4, kernel);
    for (const glm::dvec3& n : directions(20))
        EXPECT_NEAR(sh_evaluate(e, 4, n), kPi + 2 * kPi / 3 * n.z, 1e-12);
}

TEST(ShEnvmap, ConstantAndSmoothMaps) {
    Image env(64, 32);
    for (float& v : env.rgb)
        v = 0.75f;
    const SphereRule rule = lebedev_rule_by_points(590);
    const std::vector<glm::dvec3> c = sh_project_equirect(env, 4, rule);
    EXPECT_NEAR(c[0].x, 0.75 * std::sqrt(4 * kPi), 1e-12);
    for (std::size_t i = 1; i < c.size(); ++i)
        EXPECT_NEAR(glm::length(c[i]), 0.0, 1e-12);

    // f = 0.5 + 0.3 z + 0.2 x + 0.1 y sampled at pixel centres; bilinear error
    // O(h²). The y term pins the sense of φ: a reversed azimuth gives −0.1.
    Image smooth(512, 256);
    for (int j = 0; j < smooth.height; ++j)
        for (int i = 0; i < smooth.width; ++i) {
            const double phi = 2 * kPi * (i + 0.5) / smooth.width, theta = kPi * (j + 0.5) / smooth.height;
            const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
            const float v = float(0.5 + 0.3 * d.z + 0.2 * d.x + 0.1 * d.y);
            float* p = smooth.pixel(i, j);
            p[0] = p[1] = p[2] = v;
            EXPECT_NEAR(sample_equirect(smooth, d).x, v, 1e-7);
        }
    const std::vector<glm::dvec3> s = sh_project_equirect(smooth, 2, lebedev_rule_by_points(5810));
    const double c1 = std::sqrt(4 * kPi / 3);
    EXPECT_NEAR(s[std::size_t(sh_index(0, 0))].y, 0.5 * std::sqrt(4 * kPi), 1e-3);
    EXPECT_NEAR(s[std::size_t(sh_index(1, 0))].y, 0.3 * c1, 1e-3);
    EXPECT_NEAR(s[std::size_t(sh_index(1, 1))].y, 0.2 * c1, 1e-3);
    EXPECT_NEAR(s[std::size_t(sh_index(1, -1))].y, 0.1 * c1, 1e-3);
    EXPECT_NEAR(s[std::size_t(sh_index(2, 0))].y, 0.0, 1e-4);
    EXPECT_THROW(sh_project_equirect(Image(), 2, rule), Error);
}
