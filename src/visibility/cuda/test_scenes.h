// Internal, for tests: the meshes and rays the visibility tests share (host
// and GPU), and what counts as an edge tie between two traversals.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "visibility/cuda/bvh.h"
#include "core/test_paths.h"

namespace skybake::visibility_test {

using namespace skybake::visibility;

inline Mesh random_soup(std::uint32_t seed, int triangles) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(0.05f, 0.6f);
    Mesh m;
    for (int t = 0; t < triangles; ++t) {
        const glm::vec3 c(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k)
            m.positions.push_back(c + s(rng) * glm::vec3(u(rng), u(rng), u(rng)));
        for (int k = 0; k < 3; ++k)
            m.indices.push_back(std::uint32_t(3 * t + k));
    }
    compute_normals(m);
    return m;
}

// A random triangle soup in [-1, 1]^3 plus a ground quad, with area-weighted
// normals: plenty of partial occlusion.
inline Mesh random_mesh(std::uint32_t seed, int triangles) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(0.1f, 0.5f);
    Mesh m;
    for (int t = 0; t < triangles; ++t) {
        const glm::vec3 c(u(rng), u(rng) * 0.5f + 0.5f, u(rng));
        for (int k = 0; k < 3; ++k)
            m.positions.push_back(c + s(rng) * glm::vec3(u(rng), u(rng), u(rng)));
        for (int k = 0; k < 3; ++k)
            m.indices.push_back(std::uint32_t(3 * t + k));
    }
    const auto base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    compute_normals(m);
    return m;
}

// One large triangle at y = height, its front side facing -y (counter-clockwise
// seen from below).
inline Mesh one_triangle_facing_down(float height) {
    Mesh m;
    m.positions = {{-10, height, -10}, {10, height, -10}, {0, height, 10}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    return m;
}

// A procedural mesh of about `triangles` triangles, default seed.
inline Mesh generated(ProceduralKind kind, std::uint64_t triangles) {
    ProceduralOptions p;
    p.kind = kind;
    p.target_triangles = triangles;
    return generate_mesh(p);
}

inline Mesh spider() {
    const std::string path = skybake::test::assimp_models() + "/OBJ/spider.obj";
    return load_mesh(path);
}

// The meshes every test runs on: a random soup, three generated scenes, a real model.
inline std::vector<std::pair<std::string, Mesh>> scenes() {
    std::vector<std::pair<std::string, Mesh>> s;
    s.emplace_back("soup", random_soup(3, 400));
    s.emplace_back("city", generated(ProceduralKind::City, 3000));
    s.emplace_back("torus", generated(ProceduralKind::Torus, 2000));
    s.emplace_back("terrain", generated(ProceduralKind::Terrain, 2000));
    s.emplace_back("spider", spider());
    return s;
}

// Rays from points in and around the mesh's box, in all directions; with
// axis_rays every seventh one along ±y (zero components in the slab test, and
// exact edge ties on axis-aligned geometry).
inline std::vector<Ray> rays_for(const Mesh& m, std::uint32_t seed, std::size_t n, bool finite, bool axis_rays = true) {
    const Bounds b = compute_bounds(m);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), g(-1.0f, 1.0f);
    std::vector<Ray> rays(n);
    for (std::size_t i = 0; i < n; ++i) {
        Ray& r = rays[i];
        if (i % 2 == 0) // from a vertex, just off the surface
            r.origin =
                m.positions[i / 2 % m.vertex_count()] + 1e-3f * b.diagonal() * m.normals[i / 2 % m.vertex_count()];
        else
            r.origin = b.min - 0.1f * b.extent() + 1.2f * b.extent() * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 d;
        do
            d = glm::vec3(g(rng), g(rng), g(rng));
        while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f);
        r.direction = glm::normalize(d);
        if (axis_rays && i % 7 == 0)
            r.direction = glm::vec3(0.0f, i % 3 == 0 ? 1.0f : -1.0f, 0.0f);
        r.t_max = finite ? 0.5f * b.diagonal() * u(rng) : std::numeric_limits<float>::infinity();
    }
    return rays;
}

// Whether a ray on which two implementations disagree is a tie: it passes
// within rounding of a triangle's edge (symmetric rules on symmetric meshes
// send rays exactly along edges; Embree's test lets some through the crack
// between two triangles, ours does not), grazes a triangle's plane, or ends
// on one. `id` is the triangle one of them hit.
inline bool is_tie(const Mesh& m, const Ray& r, std::uint32_t id) {
    if (id == kNoHit)
        return false;
    const std::uint32_t* i = &m.indices[3 * std::size_t(id)];
    const glm::dvec3 p0 = m.positions[i[0]], e1 = glm::dvec3(m.positions[i[1]]) - p0,
                     e2 = glm::dvec3(m.positions[i[2]]) - p0;
    const glm::dvec3 o = r.origin, d = r.direction;
    const glm::dvec3 n = glm::cross(e1, e2);
    const double cos_plane = std::abs(glm::dot(glm::normalize(n), glm::normalize(d)));
    if (cos_plane < 1e-4)
        return true;
    const double t = glm::dot(n, p0 - o) / glm::dot(n, d);
    const glm::dvec3 q = o + t * d - p0;
    // Barycentrics of the plane point, and the edge distance relative to the triangle's size.
    const double a = glm::dot(n, n);
    const double v = glm::dot(glm::cross(e1, q), n) / a, u = glm::dot(glm::cross(q, e2), n) / a;
    const double edge = std::min({u, v, 1.0 - u - v});
    return std::abs(edge) < 1e-5 || (std::isfinite(r.t_max) && std::abs(t - double(r.t_max)) < 1e-5 * r.t_max);
}

} // namespace skybake::visibility_test
