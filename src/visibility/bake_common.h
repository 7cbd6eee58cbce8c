// Internal: what every backend's bake() shares (input checks, the rule in
// single precision, per-vertex frames, writing one vertex's results).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "visibility/shading_hd.h"

namespace skybake::visibility {

struct BakeSetup {
    std::vector<glm::vec3> points; // rule directions, single precision, rule order k
    std::vector<float> weights;
    // Visiting order (coherent_direction_order) and the rule in that order,
    // weights zero-padded to padded_directions(K) entries.
    std::vector<std::uint32_t> order;
    std::vector<glm::vec3> sorted_points;
    std::vector<float> sorted_weights;
    std::uint32_t directions = 0;
    std::uint32_t words = 0; // per vertex
    bool rotate = false;
    std::uint64_t rotation_seed = 0;
    bool normalize = false;
    bool store_bits = false;
    float offset = 0.0f;   // mesh units
    float t_max = 0.0f;    // mesh units (may be infinite)
    std::vector<glm::vec3> normals; // unit
    std::vector<glm::vec3> inward;  // unit or zero, see vertex_inward_directions()
};

// Per-vertex ray frame.
struct VertexFrame {
    glm::vec3 origin{0.0f};
    glm::vec3 normal{0.0f, 0.0f, 1.0f};
    glm::mat3 rotation{1.0f};
};

// Throws skybake::Error unless options.method is TraceMethod::Bvh (the CPU
// backends have no other).
void require_bvh_method(const BakeOptions& options, const char* backend);

// Checks the inputs (throws skybake::Error with a message for the user), fills
// the setup and sizes every array of `out`.
BakeSetup prepare_bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out);

VertexFrame vertex_frame(const BakeSetup& setup, const Mesh& mesh, std::uint32_t vertex);

// Reduces one vertex's words and stores ao, shading, bent normal (and the words
// when store_bits). Thread-safe for distinct vertices.
void finish_vertex(const BakeSetup& setup, const VertexFrame& frame, std::uint32_t vertex, const std::uint32_t* words,
                   BakeOutputs& out, std::atomic<std::uint64_t>& clamped);
// Stores one vertex's reduced result (and its words when store_bits).
void store_vertex(const BakeSetup& setup, std::uint32_t vertex, const Shading& result, const std::uint32_t* words,
                  BakeOutputs& out, std::atomic<std::uint64_t>& clamped);

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

} // namespace skybake::visibility
