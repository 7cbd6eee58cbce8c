// Internal: the host side of the CUDA bake, free of CUDA so that the CPU
// tests share it. plan_bake() checks the inputs and lays out what the kernels
// read (the rule in visiting order, one ray frame per vertex);
// store_chunk() writes one chunk's results into BakeOutputs; emulate_bake()
// runs the kernels' thread bodies (bake_hd.h) on the host.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "visibility/bake_common.h"
#include "visibility/cuda/bake_hd.h"
#include "visibility/cuda/bvh.h"

namespace skybake::visibility {

struct BakePlan {
    BakeSetup setup;
    bool cull_back = false;
    std::vector<glm::vec3> origins;   // per vertex, mesh units
    std::vector<glm::vec3> normals;   // per vertex, unit
    std::vector<glm::mat3> rotations; // per vertex when the rule has "+rotate", else empty
};

// prepare_bake() plus the per-vertex frames; sizes every array of `out`.
BakePlan plan_bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out);

// The launch parameters that do not depend on the chunk, pointing at host
// memory (the CUDA driver swaps in device pointers).
GpuBakeParams host_params(const BakePlan& plan, const Bvh& bvh);

// Per-chunk results, as the reduction pass leaves them.
struct ChunkResults {
    const float* ao;
    const float* shading;
    const glm::vec3* bent;
    const std::uint32_t* rays;
    const std::uint32_t* clamped;
    const std::uint32_t* rule_words; // count × words, or nullptr without store_bits
};

// Copies the results of vertices [first, first + count) into out and adds
// their rays and clamped counts.
void store_chunk(const BakePlan& plan, std::uint32_t first, std::uint32_t count, const ChunkResults& r,
                 BakeOutputs& out);

// The CUDA bake's arithmetic, run on the host one "thread" at a time, in
// chunks of chunk_vertices vertices: the same bits and values as the kernels
// (tests compare both with the Embree backend). method PerPolygon runs the
// per-vertex loop, which decides the same test on the same triangles.
void emulate_bake(const BakePlan& plan, const Bvh& bvh, TraceMethod method, BakeOutputs& out,
                  std::uint32_t chunk_vertices = 4096);

} // namespace skybake::visibility
