// Passes over a bake's rays (skybake/bake.h, [SECTION] Passes over the bake's
// rays): closest hits of the blocked directions, and one direction per vertex,
// from the driver's own ray origins (bake::vertex_rays()).
#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "bake/internal.h"
#include "skybake/bake.h"
#include "skybake/error.h"
#include "visibility/trace_hd.h"

namespace skybake {

std::vector<glm::vec3> bake_vertex_normals(const Mesh& mesh) { return bake::bake_normals(mesh); }

std::vector<BlockedDirection> blocked_directions(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options,
                                                 std::span<const std::uint32_t> words, const RayQueries& queries) {
    const std::size_t n = mesh.vertex_count();
    const bake::VisitingRule visit = bake::visiting_rule(rule);
    const std::uint32_t per_vertex = visit.words_per_vertex;
    if (words.size() != n * per_vertex)
        throw Error(fmt::format("{} visibility words for {} vertices of {} directions; expected {}", words.size(), n,
                                rule.size(), n * per_vertex),
                    "words");
    const bake::VertexRays vr = bake::vertex_rays(mesh, options);

    std::vector<BlockedDirection> out;
    std::vector<Ray> rays;
    for (std::size_t v = 0; v < n; ++v) {
        const glm::mat3 rot = visit.rotation(std::uint32_t(v));
        const glm::vec3 origin = vr.origin(mesh, v);
        const std::uint32_t* bits = words.data() + v * per_vertex;
        for (std::size_t j = 0; j < visit.points.size(); ++j) {
            glm::vec3 x;
            float cos_n;
            visibility::vertex_direction(visit.points[j], rot, visit.rotate, vr.normals[v], x, cos_n);
            if (!(cos_n > 0.0f) || visibility::get_bit(bits, visit.order[j]))
                continue;
            Ray r;
            r.origin = origin;
            r.direction = x;
            r.t_max = options.max_distance;
            rays.push_back(r);
            BlockedDirection b;
            b.vertex = std::uint32_t(v);
            b.direction = visit.order[j];
            b.weight = visit.weights[j];
            b.cosine = cos_n;
            out.push_back(b);
        }
    }
    std::vector<RayHit> hits(rays.size());
    queries.intersect(rays, hits);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i].hit = hits[i];
    return out;
}

std::vector<std::uint8_t> direction_visibility(const Mesh& mesh, const glm::vec3& direction,
                                               const BakeOptions& options, const RayQueries& queries) {
    const bake::VertexRays vr = bake::vertex_rays(mesh, options);
    const std::size_t n = mesh.vertex_count();
    std::vector<Ray> rays(n);
    for (std::size_t v = 0; v < n; ++v) {
        rays[v].origin = vr.origin(mesh, v);
        rays[v].direction = direction;
        rays[v].t_max = options.max_distance;
    }
    std::vector<std::uint8_t> occluded(n);
    queries.occluded(rays, occluded);
    std::vector<std::uint8_t> out(n);
    for (std::size_t v = 0; v < n; ++v)
        out[v] = occluded[v] || glm::dot(vr.normals[v], direction) < 0.0f ? 0 : 1;
    return out;
}

} // namespace skybake
