// The CUDA tracer, one thread's work at a time: what each kernel thread of
// cuda_backend.cu computes, written once as SKYBAKE_HD functions so that the
// CPU tests run the very same code (EmulatedCudaTracer, emulated_tracer.h)
// against the Embree backend.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): parallel over vertices × directions (the seed's best mapping),
// visibility stored as bits with an early exit once a ray is blocked, and
// three ways of finding the blocker:
//   Bvh         the hierarchy of cuda/bvh.h (the production path)
//   PerVertex   the seed's naive method: every triangle, for every ray
//   PerPolygon  every triangle too, but in tiles shared by a thread block
//               (shared memory in the kernel; the plain loop on the host)
//
// Thread layout: one warp per (vertex, 32 consecutive directions in the
// rule's coherent visiting order). A warp's rays leave one point towards one
// small patch of the sphere and walk the BVH together; the warp's answers are
// one word in visiting order (__ballot_sync). A second pass, one thread per
// output word, gathers those bits into the rule-order words of
// skybake/visibility.h.
#pragma once

#include <cstdint>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"
#include "skybake/visibility.h"
#include "visibility/cuda/bvh.h"
#include "visibility/trace_hd.h"

namespace skybake::visibility {

// Everything one launch reads and writes. Pointers are device pointers in the
// kernels and host pointers in the emulation.
struct GpuTraceParams {
    BvhView bvh;
    const BvhTriangle* soup = nullptr; // every triangle once (PerVertex, PerPolygon)
    std::uint32_t soup_count = 0;
    // The rule in visiting order: position j is rule direction order[j], and
    // rule direction k is at position position[k].
    const glm::vec3* points = nullptr;
    const std::uint32_t* position = nullptr;
    std::uint32_t directions = 0; // K
    std::uint32_t words = 0;      // ceil(K / 32) per vertex
    float t_max = 0.0f;           // mesh units, may be infinite
    bool cull_back = false;
    bool rotate = false;
    // One chunk of vertices.
    std::uint32_t vertex_count = 0;
    const glm::vec3* origins = nullptr;   // ray origins, vertex_count
    const glm::vec3* normals = nullptr;   // unit, vertex_count
    const glm::mat3* rotations = nullptr; // vertex_count when rotate, else unused
    std::uint32_t* visit_words = nullptr; // vertex_count × words, bit j = visiting position j
    std::uint32_t* rule_words = nullptr;  // vertex_count × words, bit k = rule direction k (the output)
};

// The ray of visiting position j at chunk vertex v. Returns false when there
// is none: j past the rule, or a direction below the vertex's horizon.
SKYBAKE_HD_INLINE bool trace_ray(const GpuTraceParams& p, std::uint32_t v, std::uint32_t j, glm::vec3& origin,
                                 glm::vec3& dir) {
    if (j >= p.directions)
        return false;
    const glm::mat3 r = p.rotate ? p.rotations[v] : glm::mat3(1.0f);
    float c;
    vertex_direction(p.points[j], r, p.rotate, p.normals[v], dir, c);
    origin = p.origins[v];
    return needs_ray(c);
}

// V of visiting position j at chunk vertex v: 1 when the ray leaves the mesh.
template <TraceMethod M>
SKYBAKE_HD_INLINE bool trace_visible(const GpuTraceParams& p, std::uint32_t v, std::uint32_t j) {
    glm::vec3 o, d;
    if (!trace_ray(p, v, j, o, d))
        return false;
    if constexpr (M == TraceMethod::Bvh)
        return !bvh_occluded(p.bvh, o, d, 0.0f, p.t_max, p.cull_back);
    else
        return !soup_occluded(p.soup, p.soup_count, o, d, 0.0f, p.t_max, p.cull_back);
}

// Rule-order word w of chunk vertex v, gathered from its visiting-order words.
SKYBAKE_HD_INLINE std::uint32_t gather_word(const GpuTraceParams& p, std::uint32_t v, std::uint32_t w) {
    const std::uint32_t* visit = p.visit_words + std::size_t(v) * p.words;
    std::uint32_t bits = 0;
    for (std::uint32_t l = 0; l < 32; ++l) {
        const std::uint32_t k = 32u * w + l;
        if (k < p.directions && get_bit(visit, p.position[k]))
            bits |= 1u << l;
    }
    return bits;
}

// The whole chunk on the host, thread by thread as the kernels run it.
inline void emulate_trace_chunk(const GpuTraceParams& p, TraceMethod method) {
    for (std::uint32_t v = 0; v < p.vertex_count; ++v)
        for (std::uint32_t w = 0; w < p.words; ++w) {
            std::uint32_t bits = 0;
            for (std::uint32_t lane = 0; lane < 32; ++lane) {
                const std::uint32_t j = 32 * w + lane;
                const bool vis = method == TraceMethod::Bvh ? trace_visible<TraceMethod::Bvh>(p, v, j)
                                                            : trace_visible<TraceMethod::PerVertex>(p, v, j);
                bits |= std::uint32_t(vis) << lane;
            }
            p.visit_words[std::size_t(v) * p.words + w] = bits;
        }
    for (std::uint32_t v = 0; v < p.vertex_count; ++v)
        for (std::uint32_t w = 0; w < p.words; ++w)
            p.rule_words[std::size_t(v) * p.words + w] = gather_word(p, v, w);
}

} // namespace skybake::visibility
