// Internal: the brute-force visibility backend (test oracle).
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "skybake/visibility.h"

namespace skybake::visibility {

// Every ray against every triangle, in double precision (triangle_hd.h). No
// acceleration structure: O(rays × triangles). Refuses meshes of more than
// kBruteForceMaxTriangles triangles.
class BruteForceBackend final : public RayQueries, public VisibilityTracer {
public:
    const char* name() const override { return "brute"; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override;
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override;
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override;
    std::uint32_t set_rule(const TraceRule& rule) override;
    void trace(const TraceChunk& chunk) override;

private:
    struct Triangle {
        glm::dvec3 p0, e1, e2, normal; // normal: front side (counter-clockwise), unnormalised
    };
    bool first_hit(const Ray& ray, bool any, RayHit* hit) const;

    std::vector<Triangle> triangles_;
    TraceRule rule_;
    BackFaces back_faces_ = BackFaces::Occlude;
};

} // namespace skybake::visibility
