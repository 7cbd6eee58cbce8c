// The visibility bake (driver, tracers and the shading reduction): Embree
// against the brute-force oracle (an independent implementation:
// double-precision Möller–Trumbore, no BVH), the seed's per-vertex definitions
// on hand-made scenes, the bit layout, determinism and the errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "bake/internal.h"
#include "bake/shading_hd.h"
#include "skybake/bake.h"
#include "visibility/cuda/test_scenes.h"
#include "visibility/triangle_hd.h"

using namespace skybake;
using skybake::visibility_test::one_triangle_facing_down;
using skybake::visibility_test::random_mesh;

namespace {

void bake_shading_with(const std::string& backend, const Mesh& m, const SphereRule& rule, const BakeOptions& o,
                       BakeOutputs& out) {
    bake_shading(m, rule, *make_visibility_tracer(backend), o, out);
}


} // namespace

TEST(VisibilityBake, BakeAgreesWithBruteForceOnRandomMeshes) {
    // Small rules go ray by ray, large ones (≥ 1000 directions) in packets.
    for (const char* spec : {"lebedev:110", "fibonacci:200+rotate=5", "mc:300,seed=3+rotate", "lebedev:1202",
                             "fibonacci:1500+rotate"}) {
        const SphereRule rule = parse_rule(spec);
        for (std::uint32_t seed = 11; seed <= (rule.size() < 1000 ? 12u : 11u); ++seed) {
            const Mesh m = random_mesh(seed, rule.size() < 1000 ? 120 : 60);
            BakeOptions o;
            o.store_bits = true;
            BakeOutputs a, b;
            bake_shading_with("embree", m, rule, o, a);
            bake_shading_with("brute", m, rule, o, b);
            ASSERT_EQ(a.rays, b.rays) << "the same directions are above the horizon";
            std::size_t bit_diff = 0;
            for (std::size_t i = 0; i < a.visibility_bits.size(); ++i)
                bit_diff += std::size_t(__builtin_popcount(a.visibility_bits[i] ^ b.visibility_bits[i]));
            EXPECT_LE(double(bit_diff), 1e-4 * double(a.rays) + 2) << spec << " seed " << seed;
            double worst = 0;
            for (std::size_t v = 0; v < m.vertex_count(); ++v) {
                worst = std::max(worst, double(std::abs(a.ao[v] - b.ao[v])));
                // Identical bits give identical coefficients: same reduction, same order.
                if (std::equal(a.visibility_bits.begin() + std::ptrdiff_t(v * a.words_per_vertex),
                               a.visibility_bits.begin() + std::ptrdiff_t((v + 1) * a.words_per_vertex),
                               b.visibility_bits.begin() + std::ptrdiff_t(v * a.words_per_vertex))) {
                    EXPECT_EQ(a.ao[v], b.ao[v]);
                    EXPECT_EQ(a.shading[v], b.shading[v]);
                    EXPECT_EQ(a.bent_normal[v], b.bent_normal[v]);
                }
            }
            // One flipped direction changes AO by at most 4 max(w) ≈ 4/K.
            EXPECT_LE(worst, 4.0 * 2.0 / double(rule.size()) + 1e-6) << spec;
        }
    }
}

TEST(VisibilityBake, UnoccludedVertexMatchesTheRule) {
    // A lone triangle facing up: its vertices see the whole upper hemisphere.
    Mesh m;
    m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    ASSERT_NEAR(m.normals[0].y, 1.0f, 1e-6f);
    const SphereRule rule = parse_rule("lebedev:5810");
    // The rule's own sums for n = +y, with V ≡ 1 above the horizon.
    // Directions exactly on the horizon (y = 0: whole Lebedev orbits) count half in A.
    double ao = 0, a = 0;
    std::size_t up = 0;
    for (std::size_t k = 0; k < rule.size(); ++k)
        if (float(rule.points[k].y) >= 0.0f) {
            ao += 4.0 * rule.weights[k] * rule.points[k].y;
            a += (rule.points[k].y > 0.0 ? 2.0 : 1.0) * rule.weights[k];
            ++up;
        }
    for (const char* name : {"embree", "brute"}) {
        BakeOutputs out;
        BakeOptions o;
        o.store_bits = true;
        bake_shading_with(name, m, rule, o, out);
        EXPECT_EQ(out.rays, 3 * up) << name;
        for (std::size_t v = 0; v < 3; ++v) {
            EXPECT_NEAR(out.ao[v], std::min(ao, 1.0), 1e-5) << name;
            EXPECT_NEAR(out.shading[v], std::min(a, 1.0), 1e-5) << name;
            EXPECT_NEAR(out.bent_normal[v].y, 1.0f, 1e-5f) << name;
            // Every direction on or above the horizon is visible, none below.
            for (std::size_t k = 0; k < rule.size(); ++k)
                EXPECT_EQ(out.visible(v, k), float(rule.points[k].y) >= 0.0f) << name << " k " << k;
        }
        // Unused high bits of the last word stay 0 (5810 = 181·32 + 18).
        EXPECT_EQ(out.words_per_vertex, 182u);
        EXPECT_EQ(out.visibility_bits[181] >> 18, 0u);
    }
    // The rule's clamped-cosine error is the AO error of an open vertex: tiny
    // for 5810 points; with the half weights on the horizon A is exact (the
    // rule is symmetric under y -> -y).
    EXPECT_NEAR(ao, 1.0, 2e-4);
    EXPECT_NEAR(a, 1.0, 1e-12);
}

TEST(VisibilityBake, NormalizedBakeOfOpenVertexIsExactlyOne) {
    Mesh m;
    m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    BakeOptions o;
    o.normalize = true;
    for (const char* spec : {"lebedev:74", "mc:50", "fibonacci:33+rotate"}) {
        BakeOutputs out;
        bake_shading_with("embree", m, parse_rule(spec), o, out);
        for (std::size_t v = 0; v < 3; ++v) {
            EXPECT_FLOAT_EQ(out.ao[v], 1.0f) << spec;
            EXPECT_FLOAT_EQ(out.shading[v], 1.0f) << spec;
        }
    }
}

TEST(VisibilityBake, MaxDistanceIgnoresFarOccluders) {
    // Floor triangle at y = 0 under a huge ceiling at y = 2. Ceiling front faces down.
    Mesh m = one_triangle_facing_down(2.0f);
    const auto base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{0, 0, 0}, {0, 0, 0.1f}, {0.1f, 0, 0}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    compute_normals(m);
    const SphereRule rule = parse_rule("lebedev:5810");
    // The rule applied to the exact visibility for D = 4 (blocked: cos θ > 1/2).
    double rule_exact = 0.0;
    for (std::size_t k = 0; k < rule.size(); ++k)
        if (rule.points[k].y > 0.0 && rule.points[k].y <= 0.5)
            rule_exact += 4.0 * rule.weights[k] * rule.points[k].y;
    for (const char* name : {"embree", "brute"}) {
        BakeOptions o;
        o.ray_offset = 1e-4f;
        BakeOutputs near_only, far;
        o.max_distance = 1.5f; // shorter than the gap: nothing blocks
        bake_shading_with(name, m, rule, o, near_only);
        o.max_distance = std::numeric_limits<float>::infinity();
        bake_shading_with(name, m, rule, o, far);
        // Closed form: under a ceiling at height h, with max distance D > h, the
        // directions within θ < acos(h/D) of the normal are blocked (while the
        // hit stays inside the ceiling triangle); that cone holds a share
        // sin²θ = 1 − (h/D)² of the cosine-weighted hemisphere, so AO = (h/D)².
        // Here D < h: AO ≈ 1 (the rule's own error only).
        EXPECT_NEAR(near_only.ao[base], 1.0f, 2e-4f) << name;
        // Unlimited: the ceiling triangle (20 × 20 at height 2) blocks most of the sky.
        EXPECT_LT(far.ao[base], 0.2f) << name;
        // D = 4: AO = (2/4)² = 0.25 (the cone's rim, 3.5 from the axis, stays
        // inside the triangle, whose nearest edge is 4.47 away). The bake equals
        // the rule applied to the exact visibility up to a direction or two on
        // the rim (4 w_k each); that differs from the closed form by the rule's
        // quadrature error for a cone, a few 1e-3 at 5810 points.
        o.max_distance = 4.0f;
        BakeOutputs mid;
        bake_shading_with(name, m, rule, o, mid);
        EXPECT_NEAR(mid.ao[base], rule_exact, 2.0 * 4.0 / 5810.0) << name;
        EXPECT_NEAR(mid.ao[base], 0.25f, 5e-3f) << name;
    }
}

TEST(VisibilityBake, ResultsDoNotDependOnThreadCount) {
    const Mesh m = random_mesh(21, 300);
    for (const char* spec : {"lebedev:230+rotate=9", "lebedev:1202"}) {
        const SphereRule rule = parse_rule(spec);
        BakeOptions o;
        o.store_bits = true;
        BakeOutputs one, all;
        set_thread_count(1);
        bake_shading_with("embree", m, rule, o, one);
        set_thread_count(0);
        bake_shading_with("embree", m, rule, o, all);
        EXPECT_EQ(one.ao, all.ao) << spec;
        EXPECT_EQ(one.shading, all.shading);
        EXPECT_EQ(one.bent_normal, all.bent_normal);
        EXPECT_EQ(one.visibility_bits, all.visibility_bits);
        EXPECT_EQ(one.rays, all.rays);
    }
}

TEST(VisibilityBake, ReductionFromBitsEqualsTheBake) {
    // The reduction of stored bits (shading_from_bits) gives the bake's results
    // bit for bit: same arithmetic, same order.
    const Mesh m = random_mesh(31, 150);
    for (const char* spec : {"lebedev:266", "design:t9+rotate=4", "lebedev:1202+rotate"}) {
        const SphereRule rule = parse_rule(spec);
        for (bool normalize : {false, true}) {
            BakeOptions o;
            o.store_bits = true;
            o.normalize = normalize;
            BakeOutputs out;
            bake_shading_with("embree", m, rule, o, out);
            for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
                const std::span<const std::uint32_t> words(&out.visibility_bits[v * out.words_per_vertex],
                                                           out.words_per_vertex);
                const ShadingCoefficients r = shading_from_bits(words, rule, v, m.normals[v], normalize);
                ASSERT_EQ(r.ao, out.ao[v]) << spec << " vertex " << v;
                ASSERT_EQ(r.shading, out.shading[v]);
                ASSERT_EQ(r.bent_normal, out.bent_normal[v]);
            }
        }
    }
}

TEST(VisibilityBake, CoherentOrderIsAPermutation) {
    const SphereRule rule = parse_rule("lebedev:5810");
    const auto pts = rule.points_f32();
    auto order = bake::coherent_direction_order(pts);
    // Consecutive directions are close: the mean angle step is a few rule spacings.
    double step = 0;
    for (std::size_t j = 1; j < order.size(); ++j)
        step += std::acos(std::clamp(double(glm::dot(pts[order[j - 1]], pts[order[j]])), -1.0, 1.0));
    step /= double(order.size() - 1);
    EXPECT_LT(step, 3.0 * std::sqrt(4.0 * 3.14159265 / double(pts.size())));
    std::sort(order.begin(), order.end());
    for (std::size_t k = 0; k < order.size(); ++k)
        ASSERT_EQ(order[k], k);
}

TEST(VisibilityBake, Errors) {
    Mesh m = random_mesh(1, 10);
    const SphereRule rule = parse_rule("lebedev:50");
    BakeOutputs out;
    auto b = make_visibility_tracer("embree");
    BakeOptions o;
    o.max_distance = 0.0f;
    EXPECT_THROW(bake_shading(m, rule, *b, o, out), Error);
    o.max_distance = std::nanf("");
    EXPECT_THROW(bake_shading(m, rule, *b, o, out), Error);
    o = {};
    o.ray_offset = std::numeric_limits<float>::infinity();
    EXPECT_THROW(bake_shading(m, rule, *b, o, out), Error);
    EXPECT_THROW(bake_shading(m, parse_rule("phong:a=8,n=4"), *b, BakeOptions{}, out), Error);
    Mesh no_normals = m;
    no_normals.normals.clear();
    EXPECT_THROW(bake_shading(no_normals, rule, *b, BakeOptions{}, out), Error);
    Mesh bad = m;
    bad.indices.push_back(100000);
    bad.indices.push_back(0);
    bad.indices.push_back(1);
    EXPECT_THROW(bake_shading(bad, rule, *b, BakeOptions{}, out), Error);
}

TEST(VisibilityBake, TheUserOffsetIsZeroByDefault) {
    Mesh m = random_mesh(2, 10);
    EXPECT_EQ(resolve_ray_offset(m, {}), 0.0f);
    BakeOptions o;
    o.ray_offset = -1.0f; // the former "scene-relative default"
    EXPECT_EQ(resolve_ray_offset(m, o), 0.0f);
    o.ray_offset = 0.5f;
    EXPECT_FLOAT_EQ(resolve_ray_offset(m, o), 0.5f);
}
