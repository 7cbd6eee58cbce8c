// Brute-force visibility: every ray against every triangle (the "naive method"
// of seed 002), in double precision with the Möller–Trumbore test. Kept only
// as an independent oracle for the tests of the fast backends.
#include "visibility/brute/brute_backend.h"

#include <cassert>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "visibility/query_tracer.h"
#include "visibility/triangle_hd.h"

namespace skybake::visibility {

void BruteForceBackend::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    validate_mesh(mesh, "mesh");
    if (mesh.triangle_count() > kBruteForceMaxTriangles)
        throw Error(fmt::format("the brute-force backend is a test oracle for meshes of up to {} triangles; this mesh "
                                "has {}: use the embree backend",
                                kBruteForceMaxTriangles, mesh.triangle_count()),
                    "backend");
    triangles_.clear();
    triangles_.reserve(mesh.triangle_count());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const glm::dvec3 p0 = mesh.positions[mesh.indices[3 * t]];
        const glm::dvec3 p1 = mesh.positions[mesh.indices[3 * t + 1]];
        const glm::dvec3 p2 = mesh.positions[mesh.indices[3 * t + 2]];
        triangles_.push_back({p0, p1 - p0, p2 - p0, glm::cross(p1 - p0, p2 - p0)});
    }
    back_faces_ = back_faces;
}

bool BruteForceBackend::first_hit(const Ray& ray, bool any, RayHit* hit) const {
    const glm::dvec3 o = ray.origin, d = ray.direction;
    const double t_min = ray.t_min;
    double t_max = ray.t_max;
    bool found = false;
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
        const Triangle& tri = triangles_[i];
        if (back_faces_ == BackFaces::Ignore && glm::dot(tri.normal, d) > 0.0)
            continue;
        double t, u, v;
        if (!ray_triangle(o, d, tri.p0, tri.e1, tri.e2, t_min, t_max, t, u, v))
            continue;
        if (any)
            return true;
        found = true;
        t_max = t;
        *hit = {float(t), std::uint32_t(i), float(u), float(v)};
    }
    return found;
}

void BruteForceBackend::occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
    assert(rays.size() == occluded.size());
    const std::size_t grain = rays.size() * triangles_.size() < (std::size_t(1) << 22) ? rays.size() : 16;
    parallel_for(rays.size(), grain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            occluded[i] = first_hit(rays[i], true, nullptr) ? 1 : 0;
    });
}

void BruteForceBackend::intersect(std::span<const Ray> rays, std::span<RayHit> hits) const {
    assert(rays.size() == hits.size());
    parallel_for(rays.size(), 16, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            hits[i] = RayHit{};
            first_hit(rays[i], false, &hits[i]);
        }
    });
}

std::uint32_t BruteForceBackend::set_rule(const TraceRule& rule) {
    rule_ = rule;
    return 0xffffffffu;
}

void BruteForceBackend::trace(const TraceChunk& chunk) { trace_with_queries(*this, rule_, chunk); }

} // namespace skybake::visibility

void skybake_register_brute_tracer() {
    using namespace skybake;
    TracerBackend b;
    b.name = "brute";
    b.device = "cpu";
    b.summary = "every ray against every triangle in double precision: a test oracle for small meshes";
    b.methods = {TraceMethod::Bvh};
    b.closest_hit = true;
    b.make_tracer = [](TraceMethod, std::uint32_t) { return std::make_unique<visibility::BruteForceBackend>(); };
    b.make_ray_queries = [] { return std::make_unique<visibility::BruteForceBackend>(); };
    register_tracer_backend(std::move(b));
}
