// Procedural meshes: determinism, counts, and geometry known in closed form.
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/mesh.h"

using namespace skybake;

namespace {
constexpr double kPi = 3.14159265358979323846;

double area(const Mesh& m) {
    double a = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 p0 = m.positions[m.indices[t]], p1 = m.positions[m.indices[t + 1]],
                         p2 = m.positions[m.indices[t + 2]];
        a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
    }
    return a;
}

// V - E + F over the welded mesh.
long euler(const Mesh& m) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    std::set<std::uint32_t> used;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            auto a = m.indices[t + std::size_t(k)], b = m.indices[t + std::size_t((k + 1) % 3)];
            used.insert(a);
            edges.insert({std::min(a, b), std::max(a, b)});
        }
    return long(used.size()) - long(edges.size()) + long(m.triangle_count());
}

// Every directed edge appears once and its reverse once: closed and consistently oriented.
bool closed_and_oriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k)
            count[{m.indices[t + std::size_t(k)], m.indices[t + std::size_t((k + 1) % 3)]}]++;
    for (const auto& [e, c] : count)
        if (c != 1 || !count.count({e.second, e.first}))
            return false;
    return true;
}
} // namespace

TEST(Procedural, SameOptionsSameMesh) {
    for (const auto& name : procedural_kind_names()) {
        const ProceduralOptions o{parse_procedural_kind(name), 3000, 7};
        const Mesh a = generate_mesh(o), b = generate_mesh(o);
        EXPECT_EQ(a.indices, b.indices) << name;
        ASSERT_EQ(a.positions.size(), b.positions.size());
        EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::vec3)));
    }
}

TEST(Procedural, TriangleCountNearTarget) {
    for (const auto& name : procedural_kind_names())
        for (std::uint64_t target : {2000ull, 50000ull}) {
            const Mesh m = generate_mesh({parse_procedural_kind(name), target, 1});
            EXPECT_NEAR(double(m.triangle_count()), double(target), 0.05 * double(target)) << name;
            validate_mesh(m);
        }
}

TEST(Procedural, SphereIsAClosedOrientedUnitSphere) {
    const Mesh m = generate_mesh({ProceduralKind::Sphere, 20000, 1});
    EXPECT_EQ(euler(m), 2);
    EXPECT_TRUE(closed_and_oriented(m));
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        ASSERT_NEAR(glm::length(m.positions[v]), 1.0f, 1e-6f);
        ASSERT_GT(glm::dot(m.normals[v], m.positions[v]), 0.999f); // outward
    }
    // Inscribed polyhedron: area just under 4 pi.
    EXPECT_LT(area(m), 4 * kPi);
    EXPECT_GT(area(m), 4 * kPi * 0.999);
}

TEST(Procedural, BowlIsAnOpenHemisphereFacingInwards) {
    const Mesh m = generate_mesh({ProceduralKind::Bowl, 20000, 1});
    EXPECT_EQ(euler(m), 1); // a disc
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        ASSERT_NEAR(glm::length(m.positions[v]), 1.0f, 1e-6f);
        ASSERT_LE(m.positions[v].y, 1e-6f);
    }
    EXPECT_NEAR(area(m), 2 * kPi, 2 * kPi * 2e-3);
    // Face winding agrees with the inward normals.
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::vec3 p0 = m.positions[m.indices[t]], p1 = m.positions[m.indices[t + 1]],
                        p2 = m.positions[m.indices[t + 2]];
        ASSERT_LT(glm::dot(glm::cross(p1 - p0, p2 - p0), p0 + p1 + p2), 0.0f);
    }
}

TEST(Procedural, TorusIsClosedWithGenusOne) {
    const Mesh m = generate_mesh({ProceduralKind::Torus, 20000, 1});
    EXPECT_EQ(euler(m), 0);
    EXPECT_TRUE(closed_and_oriented(m));
    EXPECT_NEAR(area(m), 4 * kPi * kPi * 1.0 * 0.35, 4 * kPi * kPi * 0.35 * 2e-3);
}

TEST(Procedural, WallAndFloorAreas) {
    const Mesh m = generate_mesh({ProceduralKind::Wall, 6000, 1});
    EXPECT_NEAR(area(m), 4.0 + 2.0, 1e-4);
}

TEST(Procedural, TerrainSeedChangesTheLayout) {
    const Mesh a = generate_mesh({ProceduralKind::Terrain, 2000, 1});
    const Mesh b = generate_mesh({ProceduralKind::Terrain, 2000, 2});
    EXPECT_NE(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::vec3)));
}

TEST(Procedural, BadOptions) {
    EXPECT_THROW(parse_procedural_kind("teapot"), Error);
    EXPECT_THROW(generate_mesh({ProceduralKind::Sphere, 5, 1}), Error);
    EXPECT_THROW(generate_mesh({ProceduralKind::Sphere, 1'000'000'000, 1}), Error);
}

TEST(Normals, AreaWeighted) {
    // Two triangles sharing vertex 0: one in the xy plane (area 2), one in xz (area 0.5).
    Mesh m;
    m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, {1, 0, 0}};
    m.indices = {0, 1, 2, 0, 3, 4};
    compute_normals(m);
    // Sum of 2*area*n: (0,0,4) + (0,1,0) -> normalised.
    const glm::vec3 expect = glm::normalize(glm::vec3(0, 1, 4));
    EXPECT_NEAR(m.normals[0].x, expect.x, 1e-6);
    EXPECT_NEAR(m.normals[0].y, expect.y, 1e-6);
    EXPECT_NEAR(m.normals[0].z, expect.z, 1e-6);
}
