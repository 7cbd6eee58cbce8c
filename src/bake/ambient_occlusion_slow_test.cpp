// Heavier AO checks: the seed's 5810-point rule on finer meshes, the whole
// Lebedev ladder, and Embree against the brute-force oracle on a whole scene.
// Closed forms as in ambient_occlusion_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "bake/ao_test_util.h"
#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"

using namespace skybake;
using namespace skybake::ao_test;

namespace {

double rms_error_vs_half(const Mesh& m) {
    double s = 0.0;
    for (float x : m.find_attribute("ao")->values)
        s += (x - 0.5) * (x - 0.5);
    return std::sqrt(s / double(m.vertex_count()));
}

} // namespace

TEST(AmbientOcclusionSlow, LebedevLadderOnTheBowl) {
    // Error against the closed form ½, RMS over 10k vertices, for every 2nd
    // rung of the Lebedev ladder; each must beat the rung two steps below.
    Mesh m = generated(ProceduralKind::Bowl, 20000);
    std::vector<double> errors;
    const std::vector<int> ladder = {6, 26, 50, 110, 194, 302, 590, 974, 2030, 3470, 5810};
    for (int points : ladder) {
        bake_ambient_occlusion(m, lebedev_rule_by_points(points));
        errors.push_back(rms_error_vs_half(m));
        std::printf("lebedev:%d  AO rms error %.2e\n", points, errors.back());
    }
    for (std::size_t i = 2; i < errors.size(); ++i)
        EXPECT_LT(errors[i], errors[i - 2]) << ladder[i];
    EXPECT_LT(errors.back(), 3e-3);
    EXPECT_LT(errors.back(), 0.05 * errors.front());
}

TEST(AmbientOcclusionSlow, Seed5810OnAFineBowl) {
    Mesh m = generated(ProceduralKind::Bowl, 20000);
    for (const char* spec : {"lebedev:5810", "lebedev:5810+rotate"}) {
        const SphereRule rule = parse_rule(spec);
        bake_ambient_occlusion(m, rule);
        const auto& ao = m.find_attribute("ao")->values;
        const auto& a = m.find_attribute("shading")->values;
        double worst_rule = 0.0, worst_closed = 0.0, sum2 = 0.0;
        std::size_t n = 0;
        for (std::size_t v = 0; v < m.vertex_count(); v += 3) {
            const glm::dvec3 p = glm::normalize(glm::dvec3(m.positions[v]));
            if (!rule.rotate_per_vertex && std::abs(p.y) < 1e-3)
                continue; // rim ties, see the unit test
            const Coefficients ex = rule_exact(turned_rule(rule, std::uint32_t(v)), -p,
                                               [&](const glm::dvec3& x) { return bowl_visible(p, x); });
            worst_rule = std::max({worst_rule, std::abs(ao[v] - ex.ao), std::abs(a[v] - ex.shading)});
            worst_closed = std::max(worst_closed, std::abs(ao[v] - 0.5));
            sum2 += (ao[v] - 0.5) * (ao[v] - 0.5);
            ++n;
        }
        std::printf("%s, 20k-triangle bowl: bake - exact-shape rule max %.2e; AO - 1/2 max %.2e rms %.2e\n", spec,
                    worst_rule, worst_closed, std::sqrt(sum2 / double(n)));
        EXPECT_LT(worst_rule, 6e-3) << spec;
        EXPECT_LT(worst_closed, 1.5e-2) << spec;
        EXPECT_LT(std::sqrt(sum2 / double(n)), 3e-3) << spec;
    }
}

TEST(AmbientOcclusionSlow, EmbreeMatchesBruteForceOnACity) {
    Mesh m = generated(ProceduralKind::City, 3000);
    const SphereRule rule = parse_rule("lebedev:302+rotate");
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs a, b;
    Mesh ma = m, mb = m;
    bake_ambient_occlusion(ma, rule, "embree", o, &a);
    bake_ambient_occlusion(mb, rule, "brute", o, &b);
    ASSERT_EQ(a.rays, b.rays);
    std::uint64_t diff = 0;
    for (std::size_t i = 0; i < a.visibility_bits.size(); ++i)
        diff += std::uint64_t(__builtin_popcount(a.visibility_bits[i] ^ b.visibility_bits[i]));
    double worst = 0.0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        worst = std::max(worst, double(std::abs(a.ao[v] - b.ao[v])));
    std::printf("city, %zu vertices: %llu of %llu rays differ, max AO difference %.2e\n", m.vertex_count(),
                static_cast<unsigned long long>(diff), static_cast<unsigned long long>(a.rays), worst);
    // Axis-aligned boxes on a ground plane: rays grazing a face or an edge are
    // ties between a float and a double triangle test.
    EXPECT_LT(double(diff), 1e-4 * double(a.rays));
    EXPECT_LT(worst, 0.05);
}
