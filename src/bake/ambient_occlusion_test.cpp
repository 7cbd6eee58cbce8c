// Per-vertex AO, shading coefficient and bent normal against closed forms
// (docs/REFERENCE.md, "Ambient occlusion"), re-derived here:
//  - infinite wall of height H at distance d from a floor point: the form
//    factor of an infinitely wide strip seen from a differential area is
//    F = ½ (1 − d/√(d² + H²)); as H → ∞, F → ½, so AO = 0.5; the strip then
//    covers a quarter of the sphere (half the hemisphere), so A = 0.5 too.
//  - finite wall: Lambert's polygon formula for F (AO = 1 − F) and the solid
//    angle Ω of the rectangle (A = 1 − Ω/2π), see ao_test_util.h.
//  - bowl (unit hemisphere, inner side): the form factor from a point on the
//    inside of a sphere to any part of it is area/(4πR²) (Siegel & Howell), so
//    F to the bowl is ½ and AO = ½ at every inner point. At the bottom the
//    opening is a unit disk one radius away: A = 1 − cos 45° = 1 − 1/√2.
//  - convex mesh: nothing above the horizon is blocked, AO = A = 1.
// Each bake is also compared with the same rule applied to the exact
// visibility of the ideal shape (tessellation and ray-tracing error only).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <glm/geometric.hpp>

#include "bake/ao_test_util.h"
#include "bake/internal.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"

using namespace skybake;
using namespace skybake::ao_test;

namespace {

std::filesystem::path temp_path(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / "skybake_bake_test";
    std::filesystem::create_directories(dir);
    return dir / name;
}

struct Errors {
    double worst = 0.0, sum2 = 0.0;
    std::size_t n = 0;
    void add(double e) {
        worst = std::max(worst, std::abs(e));
        sum2 += e * e;
        ++n;
    }
    double rms() const { return n ? std::sqrt(sum2 / double(n)) : 0.0; }
};

} // namespace

TEST(AmbientOcclusion, ConvexMeshIsOpenEverywhere) {
    Mesh m = generated(ProceduralKind::Sphere, 2000);
    const SphereRule rule = parse_rule("lebedev:590");
    // The rule's own error for the clamped cosine and the half-sphere weight sum
    // (a convex vertex sees exactly the upper hemisphere).
    const Coefficients open = rule_exact(rule, glm::dvec3(0, 0, 1), [](const glm::dvec3&) { return true; });
    const double bound = std::max(std::abs(open.ao - 1.0), std::abs(open.shading - 1.0)) + 2e-3;
    const AoBakeReport r = bake_ambient_occlusion(m, rule);
    EXPECT_EQ(r.vertices, m.vertex_count());
    const auto* ao = m.find_attribute("ao");
    const auto* a = m.find_attribute("shading");
    const auto* bent = m.find_attribute("bent_normal");
    ASSERT_TRUE(ao && a && bent);
    EXPECT_EQ(bent->components, 3);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        EXPECT_NEAR(ao->values[v], 1.0, bound);
        EXPECT_NEAR(a->values[v], 1.0, bound);
        // Unoccluded: the bent normal is the normal (up to the rule's asymmetry).
        const glm::vec3 b(bent->values[3 * v], bent->values[3 * v + 1], bent->values[3 * v + 2]);
        EXPECT_GT(glm::dot(b, m.normals[v]), 0.999f);
        EXPECT_EQ(m.colors[v], glm::vec4(ao->values[v], ao->values[v], ao->values[v], 1.0f));
    }
    // Normalised: exactly 1.
    BakeOptions o;
    o.normalize = true;
    bake_ambient_occlusion(m, rule, "embree", o);
    for (float x : m.find_attribute("ao")->values)
        EXPECT_FLOAT_EQ(x, 1.0f);
}

TEST(AmbientOcclusion, BowlIsOneHalfInside) {
    Mesh m = generated(ProceduralKind::Bowl, 3000);
    for (const char* spec : {"lebedev:590", "lebedev:590+rotate"}) {
        const SphereRule rule = parse_rule(spec);
        bake_ambient_occlusion(m, rule);
        const auto& ao = m.find_attribute("ao")->values;
        const auto& a = m.find_attribute("shading")->values;
        Errors vs_rule, vs_closed, rule_error;
        for (std::size_t v = 0; v < m.vertex_count(); ++v) {
            const glm::dvec3 p = glm::normalize(glm::dvec3(m.positions[v]));
            const glm::dvec3 n = -p;
            const Coefficients ex = rule_exact(turned_rule(rule, std::uint32_t(v)), n,
                                               [&](const glm::dvec3& x) { return bowl_visible(p, x); });
            // On the rim an unturned rule has whole orbits of rays grazing the rim
            // plane: ties between the ideal shape and the mesh, skipped here.
            if (rule.rotate_per_vertex || std::abs(p.y) > 1e-3) {
                vs_rule.add(ao[v] - ex.ao);
                vs_rule.add(a[v] - ex.shading);
            }
            vs_closed.add(ao[v] - 0.5);
            rule_error.add(ex.ao - 0.5);
        }
        std::printf("%s: bake - rule on exact bowl: max %.2e rms %.2e; bake - 1/2: max %.2e rms %.2e; rule alone: "
                    "max %.2e rms %.2e\n",
                    spec, vs_rule.worst, vs_rule.rms(), vs_closed.worst, vs_closed.rms(), rule_error.worst,
                    rule_error.rms());
        // Tessellation (3000 triangles, chords up to ~0.06) and ray offsets.
        EXPECT_LT(vs_rule.rms(), 3e-3) << spec;
        EXPECT_LT(vs_rule.worst, 2e-2) << spec;
        // Closed form: the rule's own error dominates (3.4e-2 worst unturned,
        // 2.9e-2 turned, measured); bounded at about 1.3× that.
        EXPECT_LT(vs_closed.worst, rule.rotate_per_vertex ? 3.8e-2 : 4.5e-2) << spec;
        EXPECT_LT(vs_closed.rms(), 1e-2) << spec;
    }
    // A at the bottom of the bowl: the opening (unit disk at distance 1) covers
    // the cone of half-angle 45°: A = 1 − cos 45°.
    std::size_t bottom = 0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        if (m.positions[v].y < m.positions[bottom].y)
            bottom = v;
    bake_ambient_occlusion(m, parse_rule("lebedev:5810"));
    EXPECT_NEAR(m.find_attribute("shading")->values[bottom], 1.0 - 1.0 / std::sqrt(2.0), 5e-3);
    EXPECT_NEAR(m.find_attribute("ao")->values[bottom], 0.5, 5e-3);
}

TEST(AmbientOcclusion, FiniteWallMatchesPolygonFormFactor) {
    // Floor [-1, 1]² at y = 0, wall x ∈ [-1, 1], y ∈ [0, 1] at z = -1.
    Mesh m = generated(ProceduralKind::Wall, 4000);
    const std::vector<glm::dvec3> wall = {{-1, 0, -1}, {1, 0, -1}, {1, 1, -1}, {-1, 1, -1}};
    for (const char* spec : {"lebedev:1202", "lebedev:1202+rotate"}) {
        const SphereRule rule = parse_rule(spec);
        bake_ambient_occlusion(m, rule);
        const auto& ao = m.find_attribute("ao")->values;
        const auto& a = m.find_attribute("shading")->values;
        Errors vs_rule, ao_closed, a_closed, rule_ao, rule_a;
        std::size_t tested = 0;
        for (std::size_t v = 0; v < m.vertex_count(); ++v) {
            const glm::dvec3 p = m.positions[v];
            if (p.y != 0.0 || p.z < -0.95 || m.normals[v].y < 0.99f)
                continue; // floor vertices only, away from the foot of the wall
            ++tested;
            const glm::dvec3 n(0, 1, 0);
            const double ao_exact = 1.0 - polygon_form_factor(p, n, wall);
            const double a_exact = 1.0 - polygon_solid_angle(p, wall) / (2.0 * kPi);
            const Coefficients ex = rule_exact(turned_rule(rule, std::uint32_t(v)), n, [&](const glm::dvec3& x) {
                return wall_visible(p, x, -1, 1, 1, -1);
            });
            vs_rule.add(ao[v] - ex.ao);
            vs_rule.add(a[v] - ex.shading);
            ao_closed.add(ao[v] - ao_exact);
            a_closed.add(a[v] - a_exact);
            rule_ao.add(ex.ao - ao_exact);
            rule_a.add(ex.shading - a_exact);
        }
        ASSERT_GT(tested, 500u);
        std::printf("wall %s: bake - rule exact max %.2e rms %.2e; AO - closed max %.2e rms %.2e (rule alone %.2e); "
                    "A - closed max %.2e rms %.2e (rule alone %.2e)\n",
                    spec, vs_rule.worst, vs_rule.rms(), ao_closed.worst, ao_closed.rms(), rule_ao.worst,
                    a_closed.worst, a_closed.rms(), rule_a.worst);
        // Flat floor, flat wall: the mesh is the ideal shape. An unturned rule
        // on this grid sends whole orbits of rays exactly through the wall's
        // corners and edges (ties, a few 4 w_k ≈ 0.003 each); a turned one only
        // differs by the ray offset near the foot of the wall (one direction).
        EXPECT_LT(vs_rule.worst, rule.rotate_per_vertex ? 4e-3 : 3e-2) << spec;
        EXPECT_LT(vs_rule.rms(), rule.rotate_per_vertex ? 4e-4 : 6e-3) << spec;
        // Against the closed forms (measured worst: AO 3.1e-2 unturned, 1.4e-2
        // turned; A 2.6e-2 and 1.4e-2), bounded at about 1.3× those.
        EXPECT_LT(ao_closed.worst, rule.rotate_per_vertex ? 1.9e-2 : 4.1e-2) << spec;
        EXPECT_LT(a_closed.worst, rule.rotate_per_vertex ? 1.9e-2 : 3.5e-2) << spec;
        EXPECT_LT(ao_closed.rms(), 1e-2) << spec;
        EXPECT_LT(a_closed.rms(), 1e-2) << spec;
    }
}

TEST(AmbientOcclusion, VerticesWhereTwoSurfacesMeet) {
    // The wall scene's floor and wall meet along z = -1, y = 0 with separate
    // vertices. A floor vertex there sees the wall fill the back half of its
    // sky; a wall vertex there sees the floor. Closed forms: the limits of
    // Lambert's formula as the point approaches the edge. Both backends must
    // agree: the ray origins start off the other surface (skybake/visibility.h).
    Mesh m = generated(ProceduralKind::Wall, 600);
    const std::vector<glm::dvec3> wall = {{-1, 0, -1}, {1, 0, -1}, {1, 1, -1}, {-1, 1, -1}};
    const std::vector<glm::dvec3> floor = {{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}};
    const SphereRule rule = parse_rule("lebedev:590+rotate");
    Mesh mb = m;
    bake_ambient_occlusion(m, rule, "embree");
    bake_ambient_occlusion(mb, rule, "brute");
    std::size_t tested = 0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const glm::dvec3 p = m.positions[v];
        if (p.y != 0.0 || p.z != -1.0 || std::abs(p.x) > 0.8)
            continue;
        const bool on_floor = m.normals[v].y > 0.5f;
        const double f = on_floor ? polygon_form_factor(p + glm::dvec3(0, 0, 1e-9), {0, 1, 0}, wall)
                                  : polygon_form_factor(p + glm::dvec3(0, 1e-9, 0), {0, 0, 1}, floor);
        const float ao = m.find_attribute("ao")->values[v], ao_brute = mb.find_attribute("ao")->values[v];
        EXPECT_NEAR(ao, 1.0 - f, 0.03) << (on_floor ? "floor" : "wall") << " vertex at x = " << p.x;
        EXPECT_NEAR(ao, ao_brute, 0.01) << "x = " << p.x;
        ++tested;
    }
    EXPECT_GE(tested, 10u);
}

TEST(AmbientOcclusion, InfiniteWallLimit) {
    // A wall 2W wide and H tall at distance d = 1 from a small floor patch at the
    // origin. Its floor is left out: a floor does not occlude its own points.
    const double W = 2000.0;
    const SphereRule rule = parse_rule("lebedev:5810+rotate=7");
    for (double H : {0.5, 1.0, 3.0, 1000.0}) {
        Mesh m;
        m.positions = {{-W, 0, -1}, {W, 0, -1}, {W, H, -1}, {-W, H, -1}, {0, 0, 0}, {0, 0, 0.01f}, {0.01f, 0, 0}};
        m.indices = {0, 1, 2, 0, 2, 3, 4, 5, 6};
        compute_normals(m);
        ASSERT_NEAR(m.normals[4].y, 1.0f, 1e-6f);
        BakeOptions o;
        o.ray_offset = 1e-5f; // the default (1e-4 × a 4000-unit diagonal) would be 0.4 here
        bake_ambient_occlusion(m, rule, "embree", o);
        const double ao = m.find_attribute("ao")->values[4], a = m.find_attribute("shading")->values[4];
        const double f_strip = 0.5 * (1.0 - 1.0 / std::sqrt(1.0 + H * H));
        // The finite width changes F by less than this (Lambert's formula, exact):
        const double f_rect = polygon_form_factor(glm::dvec3(0), glm::dvec3(0, 1, 0),
                                                  {{-W, 0, -1}, {W, 0, -1}, {W, H, -1}, {-W, H, -1}});
        EXPECT_NEAR(f_rect, f_strip, 1e-3) << H;
        const Coefficients ex = rule_exact(turned_rule(rule, 4), glm::dvec3(0, 1, 0), [&](const glm::dvec3& x) {
            return wall_visible(glm::dvec3(0), x, -W, W, H, -1);
        });
        std::printf("infinite wall H = %g: AO %.5f, rule on the exact wall %.5f, closed form %.5f; A %.5f\n", H, ao,
                    ex.ao, 1.0 - f_strip, a);
        EXPECT_NEAR(ao, ex.ao, 1e-3) << "H = " << H;
        // lebedev:5810, turned: a few 1e-3 on a boundary this long.
        EXPECT_NEAR(ao, 1.0 - f_strip, 3e-3) << "H = " << H;
        if (H >= 1000.0) {
            EXPECT_NEAR(ao, 0.5, 3e-3);
            EXPECT_NEAR(a, 0.5, 3e-3);
        }
    }
}

TEST(AmbientOcclusion, InvariantUnderScalingNearlyUnderTranslation) {
    // A ray origin steps 2^-15 of the vertex's largest coordinate (or of its
    // triangles' size) off the vertex: that scales with the mesh, so uniform
    // scaling changes no bit. Translation changes the coordinates' magnitude,
    // hence the step, and a ray that starts exactly on another surface (a
    // wall's bottom vertex on the ground, a roof vertex on a wall's top edge)
    // or grazes an edge can flip. Measured on this city, whose buildings touch
    // the ground and each other everywhere: 23–27% of the vertices move, by a
    // few directions (4 w_k ≈ 0.013 each), rms 4.5e-3 to 5.0e-3, max 6.1e-2.
    const Mesh base = generated(ProceduralKind::City, 3000);
    const SphereRule rule = parse_rule("lebedev:302+rotate");
    Mesh a = base;
    bake_ambient_occlusion(a, rule);
    for (const auto& [scale, shift] :
         {std::pair{4.0f, glm::vec3(0.0f)}, std::pair{0.125f, glm::vec3(0.0f)},
          std::pair{1.0f, glm::vec3(12.5f, -3.0f, 7.25f)}, std::pair{40.0f, glm::vec3(0.0f)},
          std::pair{0.02f, glm::vec3(0.3f, 0.1f, -0.2f)}}) {
        Mesh b = base;
        for (auto& p : b.positions)
            p = p * scale + shift;
        bake_ambient_occlusion(b, rule);
        Errors e;
        std::size_t moved = 0;
        const auto& x = a.find_attribute("ao")->values;
        const auto& y = b.find_attribute("ao")->values;
        for (std::size_t v = 0; v < x.size(); ++v) {
            e.add(x[v] - y[v]);
            moved += x[v] != y[v];
        }
        std::printf("scale %g shift (%g %g %g): AO changed at %zu of %zu vertices, max %.2e rms %.2e\n", scale,
                    shift.x, shift.y, shift.z, moved, x.size(), e.worst, e.rms());
        if (shift == glm::vec3(0.0f)) {
            EXPECT_EQ(moved, 0u) << "scale " << scale;
            continue;
        }
        EXPECT_LT(e.rms(), 6e-3);
        EXPECT_LT(e.worst, 8e-2);
        EXPECT_LT(double(moved), 0.3 * double(x.size()));
    }
}

TEST(AmbientOcclusion, LebedevErrorFallsWithPrecision) {
    // RMS over the bowl's vertices of AO − ½ (the full ladder up to 5810 points
    // is in the slow tests).
    Mesh m = generated(ProceduralKind::Bowl, 3000);
    double previous = 1.0;
    for (int points : {26, 110, 590}) {
        bake_ambient_occlusion(m, lebedev_rule_by_points(points));
        Errors e;
        for (float x : m.find_attribute("ao")->values)
            e.add(x - 0.5);
        std::printf("lebedev:%d: AO error on the bowl rms %.2e max %.2e\n", points, e.rms(), e.worst);
        EXPECT_LT(e.rms(), 0.6 * previous) << points;
        previous = e.rms();
    }
    EXPECT_LT(previous, 1.2e-2);
}

TEST(AmbientOcclusion, BentNormalLeansAwayFromTheWall) {
    // The bent normal is the cosine-weighted mean open direction,
    // normalise(Σ_k w_k (n·x_k)+ V_k x_k): compared with that sum over the
    // exact wall, so a uniform weighting (45° tilt for a half-blocked
    // hemisphere against 32.5° with the cosine) or a lost sign fails.
    // The reference starts its rays where the bake does, at p + offset · n,
    // since a ray that grazes the wall's top edge flips with the origin's
    // height (one direction moves the bent normal by about 4e-3).
    Mesh m = generated(ProceduralKind::Wall, 2000);
    const SphereRule rule = parse_rule("lebedev:590+rotate");
    BakeOptions o;
    o.ray_offset = 1e-5f;
    bake_ambient_occlusion(m, rule, "embree", o);
    const auto& bent = m.find_attribute("bent_normal")->values;
    std::size_t tested = 0;
    double worst = 0.0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const glm::dvec3 p = m.positions[v];
        if (p.y != 0.0 || p.z < -0.9 || std::abs(p.x) > 0.5 || m.normals[v].y < 0.99f)
            continue;
        const glm::dvec3 b(bent[3 * v], bent[3 * v + 1], bent[3 * v + 2]);
        EXPECT_NEAR(glm::length(b), 1.0, 1e-5);
        const Coefficients ex = rule_exact(turned_rule(rule, std::uint32_t(v)), glm::dvec3(0, 1, 0),
                                           [&](const glm::dvec3& x) {
                                               return wall_visible(p + glm::dvec3(0, 1e-5, 0), x, -1, 1, 1, -1);
                                           });
        const glm::dvec3 expected = glm::normalize(ex.bent);
        const double err = glm::length(b - expected);
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-5) << "vertex " << v << " at (" << p.x << ", " << p.z << ")";
        EXPECT_GT(b.z, 0.0) << "floor vertices see more sky away from the wall (+z)";
        ++tested;
    }
    std::printf("bent normal against the rule on the exact wall: %zu vertices, max |Δ| %.2e\n", tested, worst);
    EXPECT_GT(tested, 50u);
}

TEST(AmbientOcclusion, BentNormalOfAHalfBlockedHemisphere) {
    // A floor point under an infinitely high wall (the InfiniteWallLimit
    // scene, H → ∞) sees only the quarter sphere z > 0 of its hemisphere.
    const double W = 2000.0, H = 1000.0;
    Mesh m;
    m.positions = {{-W, 0, -1}, {W, 0, -1}, {W, H, -1}, {-W, H, -1}, {0, 0, 0}, {0, 0, 0.01f}, {0.01f, 0, 0}};
    m.indices = {0, 1, 2, 0, 2, 3, 4, 5, 6};
    compute_normals(m);
    BakeOptions o;
    o.ray_offset = 1e-5f;
    bake_ambient_occlusion(m, parse_rule("lebedev:5810+rotate=7"), "embree", o);
    const auto& bent = m.find_attribute("bent_normal")->values;
    const glm::dvec3 b(bent[12], bent[13], bent[14]);
    // Over {y > 0, z > 0} with y the normal: ∫ y² dω = π/3 (half of the
    // hemisphere's 2π/3) and ∫ y z dω = ∫_0^{π/2} cos θ sin θ · sin θ dθ ·
    // ∫_0^π sin φ dφ = (1/3)(2) = 2/3. The tilt from the normal is
    // atan((2/3)/(π/3)) = atan(2/π) = 32.48°; a uniform weight would give 45°.
    const double tilt_deg = std::atan2(b.z, b.y) * 180.0 / kPi;
    std::printf("half-blocked hemisphere: bent normal tilt %.3f° (closed form %.3f°)\n", tilt_deg,
                std::atan(2.0 / kPi) * 180.0 / kPi);
    EXPECT_NEAR(tilt_deg, std::atan(2.0 / kPi) * 180.0 / kPi, 0.3);
    EXPECT_NEAR(b.x, 0.0, 5e-3);
}

TEST(AmbientOcclusion, ShadingFromStoredBitsEqualsTheBake) {
    Mesh m = generated(ProceduralKind::Torus, 1000);
    const SphereRule rule = parse_rule("fibonacci:300+rotate=2");
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs out;
    bake_ambient_occlusion(m, rule, "embree", o, &out);
    for (std::uint32_t v = 0; v < m.vertex_count(); v += 7) {
        const std::span<const std::uint32_t> words(&out.visibility_bits[v * out.words_per_vertex],
                                                   out.words_per_vertex);
        const ShadingCoefficients c = shading_from_bits(words, rule, v, m.normals[v]);
        EXPECT_EQ(c.ao, out.ao[v]);
        EXPECT_EQ(c.shading, out.shading[v]);
        EXPECT_EQ(c.bent_normal, out.bent_normal[v]);
    }
    EXPECT_THROW(shading_from_bits(std::span<const std::uint32_t>(), rule, 0, m.normals[0]), Error);
}

TEST(AmbientOcclusion, VisibilityBitsFileRoundTrip) {
    Mesh m = generated(ProceduralKind::Wall, 500);
    const SphereRule rule = parse_rule("lebedev:194+rotate=3");
    BakeOptions o;
    o.store_bits = true;
    BakeOutputs out;
    bake_ambient_occlusion(m, rule, "embree", o, &out);
    const auto path = temp_path("bits.bin");
    save_visibility_bits(path, out, rule);
    const VisibilityBits back = load_visibility_bits(path);
    EXPECT_EQ(back.rule, rule.spec);
    EXPECT_EQ(back.vertices, m.vertex_count());
    EXPECT_EQ(back.directions, 194u);
    EXPECT_EQ(back.words_per_vertex, 7u);
    EXPECT_EQ(back.words, out.visibility_bits);
    EXPECT_EQ(std::filesystem::file_size(path), 24u + rule.spec.size() + 4u * back.words.size());
    // The spec rebuilds the same directions (rotation included).
    const ShadingCoefficients c =
        shading_from_bits(std::span(back.words).subspan(3 * 7, 7), parse_rule(back.rule), 3, m.normals[3]);
    EXPECT_EQ(c.ao, out.ao[3]);

    // Truncated and foreign files are refused.
    {
        std::ofstream f(temp_path("short.bin"), std::ios::binary);
        f << "SKBVIS01\x05";
    }
    EXPECT_THROW(load_visibility_bits(temp_path("short.bin")), Error);
    std::filesystem::resize_file(path, std::filesystem::file_size(path) - 4);
    EXPECT_THROW(load_visibility_bits(path), Error);
    EXPECT_THROW(load_visibility_bits(temp_path("missing.bin")), Error);
    BakeOutputs no_bits;
    bake_ambient_occlusion(m, rule, "embree", BakeOptions{}, &no_bits);
    EXPECT_THROW(save_visibility_bits(temp_path("none.bin"), no_bits, rule), Error);
}

TEST(AmbientOcclusion, AttributesSurviveGlbAndPly) {
    Mesh m = generated(ProceduralKind::City, 500);
    bake_ambient_occlusion(m, parse_rule("lebedev:50"));
    for (const char* ext : {".glb", ".ply"}) {
        const auto path = temp_path(std::string("baked") + ext);
        save_mesh(path, m);
        const Mesh back = load_mesh(path);
        for (const char* name : {"ao", "shading", "bent_normal"}) {
            const auto* a = m.find_attribute(name);
            const auto* b = back.find_attribute(name);
            ASSERT_TRUE(b) << name << ext;
            EXPECT_EQ(a->components, b->components);
            EXPECT_EQ(a->values, b->values) << name << ext;
        }
        ASSERT_EQ(back.colors.size(), m.vertex_count());
    }
}

TEST(AmbientOcclusion, PreviewShowsTheBakedValues) {
    Mesh m = generated(ProceduralKind::Bowl, 2000);
    bake_ambient_occlusion(m, parse_rule("lebedev:2030"));
    AoPreviewOptions o;
    o.width = 80;
    o.height = 60;
    o.elevation_deg = 89.0f; // looking down into the bowl
    const Image img = render_ao_preview(m, o);
    ASSERT_EQ(img.width, 80);
    ASSERT_EQ(img.height, 60);
    // Corner: background. Centre: the bowl's inside, AO ≈ 0.5.
    EXPECT_NEAR(img.pixel(0, 0)[0], 0.035f, 1e-6f);
    EXPECT_NEAR(linear_to_srgb(img.pixel(40, 30)[0]), 0.5f, 0.02f); // display value = AO
    EXPECT_EQ(img.pixel(40, 30)[0], img.pixel(40, 30)[2]);
    Mesh plain = generated(ProceduralKind::Bowl, 200);
    EXPECT_THROW(render_ao_preview(plain, o), Error);
    o.width = 0;
    EXPECT_THROW(render_ao_preview(m, o), Error);
}

TEST(AmbientOcclusion, BakeComputesMissingNormals) {
    Mesh m = generated(ProceduralKind::Sphere, 500);
    Mesh reference = m;
    compute_normals(reference);
    m.normals.clear();
    bake_ambient_occlusion(m, parse_rule("lebedev:50"));
    ASSERT_EQ(m.normals.size(), m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        ASSERT_EQ(m.normals[v], reference.normals[v]) << "vertex " << v;
    // A generated sphere's normals point outwards: a sign flip would not pass.
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        ASSERT_GT(glm::dot(m.normals[v], glm::normalize(m.positions[v])), 0.99f) << "vertex " << v;
    if (cuda_device_count() == 0) { // without a GPU (or CUDA) "cuda" is a clear error
        EXPECT_THROW(bake_ambient_occlusion(m, parse_rule("lebedev:50"), "cuda"), Error);
    }
}

// Ray origins that neither leak nor jump (skybake/bake.h, [SECTION] Bake
// options): a step of 256 ulps past rounding, no scene-relative offset.

TEST(RayOrigins, AThinGapIsNotJumped) {
    // A floor patch under a ceiling 1e-5 of the scene's diagonal above it,
    // facing it: the patch's centre sees the ceiling over the whole
    // hemisphere but for rays within atan(gap / 50) of the horizon, so AO is
    // below 1e-4 (the rule puts no direction that close to the horizon but
    // the horizon's own orbit, which the ceiling blocks too). A scene-relative
    // offset of 1e-4 × the diagonal jumps the gap and sees open sky.
    const float L = 50.0f;
    Mesh m;
    m.positions = {{-0.01f, 0, -0.01f}, {0.01f, 0, -0.01f}, {0.01f, 0, 0.01f}, {-0.01f, 0, 0.01f}, {0, 0, 0}};
    m.indices = {4, 1, 0, 4, 2, 1, 4, 3, 2, 4, 0, 3};
    // Diagonal about 141: the gap is 1.4e-3.
    const float gap = 1e-5f * std::sqrt(2.0f) * 2.0f * L;
    const auto base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{-L, gap, -L}, {L, gap, -L}, {L, gap, L}, {-L, gap, L}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3}); // front faces down
    compute_normals(m);
    ASSERT_NEAR(m.normals[4].y, 1.0f, 1e-6f);
    const SphereRule rule = parse_rule("lebedev:590+rotate");
    for (const char* backend : {"embree", "brute"}) {
        Mesh a = m;
        bake_ambient_occlusion(a, rule, backend);
        EXPECT_LT(a.find_attribute("ao")->values[4], 1e-4f) << backend;
        BakeOptions jump;
        jump.ray_offset = 1e-4f * compute_bounds(m).diagonal(); // the former default
        Mesh b = m;
        bake_ambient_occlusion(b, rule, backend, jump);
        EXPECT_GT(b.find_attribute("ao")->values[4], 0.9f) << backend << ": the old offset jumps the gap";
    }
}

TEST(RayOrigins, CurvedSurfacesNeedNoOffset) {
    // A tessellated sphere, outside and inside, with no offset at all: no ray
    // meets the vertex's own triangles. Outside, every direction on or above
    // a vertex's horizon is visible (the sphere is convex, and its vertex
    // normals are normals of supporting planes); inside, none is (AO = A = 0).
    // The rule is turned per vertex: an unturned symmetric rule on the
    // symmetric icosphere sends rays exactly through far vertices, where a
    // ray–triangle test that is not watertight (Möller–Trumbore in the
    // brute-force oracle and the CUDA traversal, Embree's default mode) can
    // let one through.
    const SphereRule rule = parse_rule("lebedev:590+rotate");
    const std::vector<glm::vec3> points = rule.points_f32();
    const bake::VisitingRule visit = bake::visiting_rule(rule); // the bake's rotations, in float
    for (bool inside : {false, true}) {
        Mesh m = generated(ProceduralKind::Sphere, 2000);
        if (inside) {
            for (std::size_t t = 0; t < m.triangle_count(); ++t)
                std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
            m.normals.clear();
        }
        BakeOptions o;
        o.ray_offset = 0.0f;
        o.store_bits = true;
        for (const char* backend : {"embree", "brute"}) {
            Mesh b = m;
            BakeOutputs out;
            bake_ambient_occlusion(b, rule, backend, o, &out);
            std::size_t wrong = 0;
            for (std::size_t v = 0; v < b.vertex_count(); ++v) {
                const glm::vec3 n = glm::normalize(b.normals[v]);
                const glm::mat3 turn = visit.rotation(std::uint32_t(v));
                for (std::size_t k = 0; k < points.size(); ++k)
                    wrong += out.visible(v, k) != (!inside && glm::dot(n, turn * points[k]) >= 0.0f);
                if (inside) {
                    ASSERT_LT(out.ao[v], 1e-3f) << backend << " vertex " << v;
                    ASSERT_LT(out.shading[v], 1e-2f) << backend << " vertex " << v;
                }
            }
            // Outside: none wrong. Inside, a ray just above the horizon meets
            // the next triangle a few ulps from its origin, at grazing
            // incidence, close to a shared edge, and a test that is not
            // watertight can let one through: measured, 1 of 591,180
            // directions (Embree), 0 (brute force).
            const std::size_t all = b.vertex_count() * points.size();
            std::printf("%s, %s: %zu of %zu directions wrong\n", backend, inside ? "inside" : "outside", wrong, all);
            if (inside) {
                EXPECT_LE(double(wrong), 1e-5 * double(all)) << backend;
            } else {
                EXPECT_EQ(wrong, 0u) << backend;
            }
        }
    }
}

TEST(RayOrigins, TheStepPastRoundingScalesWithTheCoordinates) {
    // 2^-15 of the largest coordinate or of the triangles' size, whichever is
    // larger: 256 to 512 ulps of a float.
    EXPECT_EQ(bake::rounding_step(glm::vec3(1000.0f, -3.0f, 2.0f), 0.5f), 1000.0f * 0x1p-15f);
    EXPECT_EQ(bake::rounding_step(glm::vec3(0.0f, -0.25f, 0.0f), 0.01f), 0.25f * 0x1p-15f);
    EXPECT_EQ(bake::rounding_step(glm::vec3(0.0f), 0.01f), 0.01f * 0x1p-15f);
    const float ulp = std::nextafter(1000.0f, INFINITY) - 1000.0f;
    const float ulps = bake::rounding_step(glm::vec3(1000.0f, 0, 0), 0.0f) / ulp; // 256 to 512 ulps
    EXPECT_GE(ulps, 256.0f);
    EXPECT_LE(ulps, 512.0f);
    // The origin moves along n + u, whatever the coordinates.
    const glm::vec3 p(-23.0f, -7.4f, 0.58f), n(0.24f, -0.42f, 0.876f), u(-0.73f, 0.51f, 0.45f);
    const float step = bake::rounding_step(p, 0.5f);
    const glm::vec3 d = bake::ray_origin(p, n, u, 0.0f, step) - p;
    EXPECT_NEAR(glm::dot(d, glm::normalize(n)), step * glm::dot(n + u, glm::normalize(n)), 1e-3f * step);
}
