// Invariants of the planet mesh over many cameras (part of the planet
// renderer's suite, label gl; needs no GL context): a closed 2-manifold
// (every edge in exactly two triangles, consistently oriented), the
// screen-space error bound measured on the mesh itself, the triangle budget,
// finer triangles near the camera, and determinism.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/planet.h"

namespace skybake {
namespace {

constexpr double kR = 6371.0;

PlanetCamera camera_at(double altitude_km, double lat, double lon, double pitch) {
    PlanetCamera c;
    const glm::dvec3 up(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
    c.position_km = up * (kR + altitude_km);
    glm::dvec3 east = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), up));
    c.forward = glm::normalize(std::cos(pitch) * east + std::sin(pitch) * up);
    c.up = glm::normalize(glm::cross(glm::cross(c.forward, up), c.forward));
    c.fov_y_rad = 1.0;
    c.viewport_width = 640;
    c.viewport_height = 512;
    return c;
}

std::vector<PlanetCamera> camera_path() {
    std::vector<PlanetCamera> path;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 24; ++i) {
        const double alt = std::pow(10.0, -3.0 + 7.0 * u(rng)); // 1 m to 10,000 km
        path.push_back(camera_at(alt, (u(rng) - 0.5) * 3.0, u(rng) * 6.28, u(rng) * 1.6 - 1.4));
    }
    return path;
}

// Closed, consistently oriented 2-manifold: each directed edge once, and its reverse once.
void expect_closed_manifold(const PlanetMesh& mesh) {
    std::vector<std::uint32_t> idx;
    mesh.indices(idx);
    ASSERT_EQ(idx.size(), 3 * mesh.triangle_count());
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < idx.size(); t += 3)
        for (int k = 0; k < 3; ++k)
            ++directed[{idx[t + std::size_t(k)], idx[t + std::size_t((k + 1) % 3)]}];
    std::size_t bad = 0;
    for (const auto& [e, n] : directed) {
        auto rev = directed.find({e.second, e.first});
        if (n != 1 || rev == directed.end() || rev->second != 1)
            ++bad;
    }
    EXPECT_EQ(bad, 0u) << "edges not shared by exactly two triangles with opposite orientation";
    // Euler characteristic of a sphere: V − E + F = 2 over the referenced vertices.
    std::vector<std::uint32_t> used(idx);
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    const long V = long(used.size()), E = long(directed.size() / 2), F = long(idx.size() / 3);
    EXPECT_EQ(V - E + F, 2);
    // Outward orientation: the normal of every triangle points away from the centre.
    std::size_t inward = 0;
    for (std::size_t t = 0; t < idx.size(); t += 3) {
        const glm::dvec3 a = mesh.vertex_position_km(idx[t]), b = mesh.vertex_position_km(idx[t + 1]),
                         c = mesh.vertex_position_km(idx[t + 2]);
        inward += glm::dot(glm::cross(b - a, c - a), a + b + c) <= 0.0;
    }
    EXPECT_EQ(inward, 0u);
}

TEST(Clod, IcosahedronAtStart) {
    PlanetMesh mesh;
    EXPECT_EQ(mesh.triangle_count(), 20u);
    expect_closed_manifold(mesh);
}

TEST(Clod, ClosedManifoldAlongAPath) {
    PlanetMesh mesh;
    for (const PlanetCamera& c : camera_path()) {
        mesh.update(c);
        expect_closed_manifold(mesh);
        if (HasFailure())
            return;
    }
}

// The bound measured on the mesh: for each visible leaf, sample points on the
// flat triangle; each one's distance to the sphere over its distance to the
// eye, in pixels, must stay within max_error_px.
TEST(Clod, ScreenSpaceErrorBoundHolds) {
    ClodOptions o;
    o.max_error_px = 0.75;
    PlanetMesh mesh(o);
    std::vector<std::uint32_t> idx;
    std::vector<double> obj, scr;
    for (const PlanetCamera& c : camera_path()) {
        const ClodStats st = mesh.update(c);
        ASSERT_FALSE(st.budget_reached);
        EXPECT_LE(st.max_error_px, o.max_error_px);
        mesh.indices(idx);
        mesh.leaf_errors(obj, scr);
        const double k = c.pixels_per_radian();
        double worst = 0.0;
        for (std::size_t t = 0; t < idx.size(); t += 3) {
            const glm::dvec3 a = mesh.vertex_position_km(idx[t]), b = mesh.vertex_position_km(idx[t + 1]),
                             cc = mesh.vertex_position_km(idx[t + 2]);
            for (int i = 0; i <= 4; ++i)
                for (int j = 0; i + j <= 4; ++j) {
                    const double u = i / 4.0, v = j / 4.0;
                    const glm::dvec3 p = a + u * (b - a) + v * (cc - a);
                    const glm::dvec3 to = p - c.position_km;
                    const double dist = glm::length(to);
                    // Only points that are visible: in front, inside the frustum and above the horizon.
                    if (glm::dot(glm::normalize(p), c.position_km) < kR * kR / glm::length(c.position_km) * 0.999999 ||
                        glm::dot(to, c.forward) <= 0.0)
                        continue;
                    const double dev = kR - glm::length(p);
                    EXPECT_GE(dev, -1e-9);
                    EXPECT_LE(dev, obj[t / 3] + 1e-9); // the object-space error is an upper bound
                    if (scr[t / 3] > 0.0)
                        worst = std::max(worst, dev / dist * k);
                }
        }
        EXPECT_LE(worst, o.max_error_px) << "altitude " << glm::length(c.position_km) - kR;
    }
}

TEST(Clod, BudgetHolds) {
    for (std::size_t budget : {100u, 1000u, 5000u}) {
        ClodOptions o;
        o.max_triangles = budget;
        o.max_error_px = 0.05;
        o.relief.amplitude_km = 5.0;
        PlanetMesh mesh(o);
        std::size_t most = 0;
        for (const PlanetCamera& c : camera_path()) {
            const ClodStats st = mesh.update(c);
            EXPECT_LE(st.triangles, budget);
            most = std::max(most, st.triangles);
        }
        EXPECT_GT(most, budget * 9 / 10) << "the budget should be used when the bound is out of reach";
        expect_closed_manifold(mesh);
    }
}

// Climbing away from the ground merges the fine triangles back.
TEST(Clod, MergesWhenTheCameraMovesAway) {
    ClodOptions o;
    o.relief.amplitude_km = 5.0;
    PlanetMesh mesh(o), fresh(o);
    const std::size_t low = mesh.update(camera_at(0.05, 0.3, 1.0, -0.3)).triangles;
    const PlanetCamera high = camera_at(3000.0, 0.3, 1.0, -1.2);
    const ClodStats st = mesh.update(high);
    EXPECT_GT(st.merges, 0u);
    const std::size_t ref = fresh.update(high).triangles;
    EXPECT_LT(st.triangles, low);
    EXPECT_LE(st.triangles, ref * 3 / 2 + 100) << "low " << low << ", fresh " << ref;
    EXPECT_LE(st.max_error_px, o.max_error_px);
    expect_closed_manifold(mesh);
}

TEST(Clod, DensestNearTheCamera) {
    const PlanetCamera c = camera_at(0.01, 0.2, 0.4, -0.2);
    ClodOptions o;
    o.relief.amplitude_km = 4.0;
    PlanetMesh mesh(o);
    mesh.update(c);
    std::vector<std::uint32_t> idx;
    mesh.indices(idx);
    // Mean edge length of visible triangles by distance band.
    double near_sum = 0, far_sum = 0;
    int near_n = 0, far_n = 0;
    for (std::size_t t = 0; t < idx.size(); t += 3) {
        const glm::dvec3 a = mesh.vertex_position_km(idx[t]), b = mesh.vertex_position_km(idx[t + 1]);
        const double d = glm::length(a - c.position_km), len = glm::length(b - a);
        if (d < 1.0) {
            near_sum += len;
            ++near_n;
        } else if (d > 50.0 && d < 300.0) {
            far_sum += len;
            ++far_n;
        }
    }
    ASSERT_GT(near_n, 0);
    ASSERT_GT(far_n, 0);
    EXPECT_LT(near_sum / near_n * 20.0, far_sum / far_n);
}

TEST(Clod, Deterministic) {
    ClodOptions o;
    o.relief.amplitude_km = 3.0;
    PlanetMesh a(o), b(o);
    std::vector<std::uint32_t> ia, ib;
    std::vector<float> pa, pb, na, nb;
    for (const PlanetCamera& c : camera_path()) {
        a.update(c);
        b.update(c);
        a.indices(ia);
        b.indices(ib);
        ASSERT_EQ(ia, ib);
        a.vertices(c.position_km, pa, na);
        b.vertices(c.position_km, pb, nb);
        ASSERT_EQ(pa, pb);
        ASSERT_EQ(na, nb);
    }
}

// Camera-relative positions stay precise a metre above the ground.
TEST(Clod, CameraRelativePositionsArePreciseNearTheGround) {
    const PlanetCamera c = camera_at(0.001, 0.1, 0.2, -0.5);
    PlanetMesh mesh;
    mesh.update(c);
    std::vector<float> pos, nrm;
    mesh.vertices(c.position_km, pos, nrm);
    double worst = 0.0;
    for (std::size_t i = 0; i < mesh.vertex_capacity(); ++i) {
        const glm::dvec3 rel(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
        if (rel == glm::dvec3(0.0))
            continue;
        const double d = glm::length(rel);
        if (d > 2.0)
            continue;
        const glm::dvec3 exact = mesh.vertex_position_km(std::uint32_t(i)) - c.position_km;
        worst = std::max(worst, glm::length(rel - exact));
    }
    EXPECT_LT(worst, 1e-9 * 1000.0); // under a micrometre (km units)
}

TEST(Clod, ReliefHeightsInRange) {
    PlanetRelief r;
    r.amplitude_km = 5.0;
    std::mt19937_64 rng(3);
    std::normal_distribution<double> n;
    double hi = 0.0;
    for (int i = 0; i < 2000; ++i) {
        const glm::dvec3 d = glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
        const double h = relief_height_km(r, d);
        EXPECT_GE(h, 0.0);
        EXPECT_LE(h, 5.0);
        hi = std::max(hi, h);
    }
    EXPECT_GT(hi, 0.5);
    EXPECT_EQ(relief_height_km(PlanetRelief{}, glm::dvec3(0, 0, 1)), 0.0);
}

} // namespace
} // namespace skybake
