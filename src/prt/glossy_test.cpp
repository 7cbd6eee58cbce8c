// DPRT (skybake/prt.h, [SECTION] Glossy transfer): the Phong-rule sum against
// the exact Phong integral of band-limited lights (Funk–Hecke) and against a
// brute-force integral with a dense rule.
#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/prt.h"

namespace skybake {
namespace {

ShLight random_light(int order, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    ShLight l;
    l.order = order;
    for (int i = 0; i < sh_count(order); ++i)
        l.coeffs.emplace_back(u(rng), u(rng), u(rng));
    return l;
}

TEST(Glossy, FrameTakesZToTheAxis) {
    for (const glm::vec3 a : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(1, -2, 0.3f))}) {
        const glm::mat3 g = frame_from_axis(a);
        EXPECT_LT(glm::length(g * glm::vec3(0, 0, 1) - a), 1e-6f);
        EXPECT_NEAR(glm::dot(g[0], g[1]), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::determinant(g), 1.0f, 1e-5f);
    }
}

TEST(Glossy, PhongRuleMatchesTheExactIntegral) {
    const glm::vec3 n = glm::normalize(glm::vec3(0.2f, 1.0f, -0.1f));
    const glm::vec3 v = glm::normalize(glm::vec3(0.5f, 0.6f, 0.7f));
    for (double a : {1.0, 8.0, 50.0})
        for (int order : {2, 4, 6}) {
            // N nodes in cos θ: precision 2N − 1 ≥ order covers the light.
            const int nodes = (order + 2) / 2;
            const SphereRule rule = phong_rule(a, nodes);
            const ShLight light = random_light(order, std::uint64_t(order) * 7 + std::uint64_t(a));
            const glm::vec3 got = dprt_glossy(rule, light, n, v);
            const glm::vec3 want = phong_glossy_exact(light, a, n, v);
            // The brute-force integral ∫ L ρ_a(r·x) dμ with lebedev:5810.
            const SphereRule dense = parse_rule("lebedev:5810");
            const glm::dvec3 r = glm::dvec3(mirror_direction(n, v));
            const std::vector<glm::dvec3> c(light.coeffs.begin(), light.coeffs.end());
            glm::dvec3 brute(0.0);
            for (std::size_t k = 0; k < dense.size(); ++k)
                brute += dense.weights[k] * 2.0 * (a + 1.0) * std::pow(std::max(0.0, glm::dot(r, dense.points[k])), a) *
                         sh_evaluate(c, order, dense.points[k]);
            const double err = glm::length(glm::dvec3(got - want)), brute_err = glm::length(brute - glm::dvec3(want));
            std::printf("a = %g, light order %d, phong:n=%d (%zu points): |DPRT - exact| = %.2g, |brute(lebedev:5810) "
                        "- exact| = %.2g\n",
                        a, order, nodes, rule.size(), err, brute_err);
            EXPECT_LT(err, 1e-3);
            if (a <= 8.0) {
                EXPECT_LT(brute_err, 1e-3); // a sharp lobe needs more than 5810 points
            }
        }
}

TEST(Glossy, TooFewNodesShowTheirError) {
    // A rule of precision 1 cannot integrate an order-6 light; the error is
    // visible (not hidden), and falls with more nodes.
    const glm::vec3 n(0, 1, 0), v = glm::normalize(glm::vec3(1, 1, 0));
    const ShLight light = random_light(6, 3);
    const glm::vec3 want = phong_glossy_exact(light, 4.0, n, v);
    const double coarse = glm::length(dprt_glossy(phong_rule(4.0, 1), light, n, v) - want);
    const double fine = glm::length(dprt_glossy(phong_rule(4.0, 4), light, n, v) - want);
    EXPECT_GT(coarse, 10.0 * fine);
}

} // namespace
} // namespace skybake
