// Internal: the parts of the bake driver (bake_visibility(), skybake/bake.h)
// that tests check on their own: ray origins and the direction order.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"

namespace skybake::bake {

// How far a ray origin must step off its vertex to clear the rounding of the
// ray–triangle tests at the vertex's own triangles: 2^-15 (256 to 512 units
// in the last place of a float) of the larger of the vertex's largest coordinate
// and its triangles' size (the mean distance to their centroids). The idea
// is Wächter & Binder's ("A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems, ch. 6, 2019): an offset tied to the
// precision of the coordinates, not to the scene's size, so it is far
// smaller than any real gap. Unlike their per-coordinate integer step, one
// step for all three axes keeps the direction of the move: a vertex normal
// is not a face normal, and a move skewed towards the largest coordinate can
// end behind the vertex's own triangles.
inline float rounding_step(const glm::vec3& position, float triangle_size) {
    const float magnitude = std::max({std::abs(position.x), std::abs(position.y), std::abs(position.z)});
    return 0x1p-15f * std::max(magnitude, triangle_size);
}

// Ray origin: the vertex moved along d = normal + inward (a unit tangent
// towards its own triangles for vertices on a border or a crease, zero
// elsewhere; see vertex_inward_directions()) by `offset` (mesh units; 0 by
// default) plus `step` (rounding_step()).
inline glm::vec3 ray_origin(const glm::vec3& position, const glm::vec3& normal, const glm::vec3& inward, float offset,
                            float step) {
    return position + (offset + step) * (normal + inward);
}

// Per vertex: the unit tangent from the vertex towards the area-weighted mean
// centroid of its triangles, when that mean is off the vertex by more than 5%
// of their mean distance (border vertices, and vertices where one surface
// meets another); zero otherwise. Moving a ray origin a little along it keeps
// the origin off a surface that merely touches the vertex: a floor vertex at
// the foot of a wall, the bottom edge of a box standing on the ground.
std::vector<glm::vec3> vertex_inward_directions(const Mesh& mesh, const std::vector<glm::vec3>& normals);

// Orders rule directions so that consecutive ones are close on the sphere
// (Morton order of the octahedral map): packets of consecutive rays from one
// vertex are then coherent.
std::vector<std::uint32_t> coherent_direction_order(const std::vector<glm::vec3>& points);

// Unit vertex normals for the bake: mesh.normals normalised; a zero or
// non-finite normal (possible in imported files) falls back to the
// area-weighted normal of the vertex's triangles.
std::vector<glm::vec3> bake_normals(const Mesh& mesh);

// A rule in single precision and in the coherent visiting order.
struct VisitingRule {
    std::vector<std::uint32_t> order; // visiting position j → rule index k
    std::vector<glm::vec3> points;    // points[j] = rule point order[j]
    std::vector<float> weights;       // weights[j] = rule weight order[j]
    std::uint32_t words_per_vertex = 0;
    bool rotate = false;
    std::uint64_t rotation_seed = 0;

    // Vertex v's rule rotation (identity unless rotate).
    glm::mat3 rotation(std::uint32_t vertex) const;
};
VisitingRule visiting_rule(const SphereRule& rule);

// Every vertex's ray frame: unit normal and ray origin.
struct VertexRays {
    float offset = 0.0f; // mesh units
    std::vector<glm::vec3> normals, inward;
    std::vector<float> steps; // rounding_step() of each vertex

    glm::vec3 origin(const Mesh& mesh, std::size_t vertex) const {
        return ray_origin(mesh.positions[vertex], normals[vertex], inward[vertex], offset, steps[vertex]);
    }
};
VertexRays vertex_rays(const Mesh& mesh, const BakeOptions& options);

} // namespace skybake::bake
