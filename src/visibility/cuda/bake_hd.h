// The CUDA bake, one thread's work at a time: what each kernel thread of
// cuda_backend.cu computes, written once as SKYBAKE_HD functions so that the
// CPU unit tests run the very same code (emulate_bake_chunk below) against the
// Embree backend.
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
// one visibility word (__ballot_sync), in visiting order. A second pass,
// eight threads per vertex (one per partial sum), reduces a vertex's words to
// AO, A and the bent normal with the same additions in the same order as the
// CPU backends (shading_hd.h), and scatters the bits to rule order.
#pragma once

#include <cstdint>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"
#include "skybake/visibility.h"
#include "visibility/cuda/bvh.h"
#include "visibility/shading_hd.h"

namespace skybake::visibility {

// Everything one launch reads and writes. Pointers are device pointers in the
// kernels and host pointers in emulate_bake_chunk().
struct GpuBakeParams {
    BvhView bvh;
    const BvhTriangle* soup = nullptr; // every triangle once (PerVertex, PerPolygon)
    std::uint32_t soup_count = 0;
    // The rule in visiting order: position j is rule direction order[j].
    const glm::vec3* points = nullptr;
    const float* weights = nullptr;
    const std::uint32_t* order = nullptr;
    std::uint32_t directions = 0; // K
    std::uint32_t words = 0;      // ceil(K / 32) per vertex
    float t_max = 0.0f;           // mesh units, may be infinite
    bool cull_back = false;
    bool rotate = false;
    bool normalize = false;
    bool store_bits = false;
    // One chunk of vertices.
    std::uint32_t vertex_count = 0;
    const glm::vec3* origins = nullptr;   // ray origins, vertex_count
    const glm::vec3* normals = nullptr;   // unit, vertex_count
    const glm::mat3* rotations = nullptr; // vertex_count when rotate, else unused
    std::uint32_t* visit_words = nullptr; // vertex_count × words, bit j = visiting position j
    // Outputs, vertex_count each (rule_words: vertex_count × words, zeroed first).
    float* ao = nullptr;
    float* shading = nullptr;
    glm::vec3* bent = nullptr;
    std::uint32_t* rays = nullptr;    // rays traced per vertex
    std::uint32_t* clamped = nullptr; // 1 when a sum was clamped
    std::uint32_t* rule_words = nullptr;
};

// The ray of visiting position j at chunk vertex v. Returns false when there
// is none: j past the rule, or a direction below the vertex's horizon.
SKYBAKE_HD_INLINE bool bake_ray(const GpuBakeParams& p, std::uint32_t v, std::uint32_t j, glm::vec3& origin,
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
SKYBAKE_HD_INLINE bool bake_visible(const GpuBakeParams& p, std::uint32_t v, std::uint32_t j) {
    glm::vec3 o, d;
    if (!bake_ray(p, v, j, o, d))
        return false;
    if constexpr (M == TraceMethod::Bvh)
        return !bvh_occluded(p.bvh, o, d, 0.0f, p.t_max, p.cull_back);
    else
        return !soup_occluded(p.soup, p.soup_count, o, d, 0.0f, p.t_max, p.cull_back);
}

// The reduction is split over kReduceLanes threads per vertex, one per
// partial sum of shading_hd.h: thread l adds directions j = l, l + 8, l + 16,
// ... into its partial, exactly the additions the sequential loop makes into
// partial l, so the split changes no bit of the result.

// Partial l of chunk vertex v, from its visiting-order words (in lane 0 of
// `s`, which must start zeroed); also sets v's visible bits of those
// directions in rule order (store_bits). Returns the rays traced among them.
SKYBAKE_HD_INLINE std::uint32_t bake_reduce_lane(const GpuBakeParams& p, std::uint32_t v, std::uint32_t l,
                                                 ShadingPartials& s) {
    const glm::vec3 n = p.normals[v];
    const glm::mat3 r = p.rotate ? p.rotations[v] : glm::mat3(1.0f);
    const std::uint32_t* vis = p.visit_words + std::size_t(v) * p.words;
    std::uint32_t* out = p.store_bits ? p.rule_words + std::size_t(v) * p.words : nullptr;
    std::uint32_t traced = 0;
    for (std::uint32_t j = l; j < p.directions; j += kReduceLanes) {
        glm::vec3 x;
        float c;
        vertex_direction(p.points[j], r, p.rotate, n, x, c);
        const bool seen = get_bit(vis, j);
        add_direction(s, 0, p.weights[j], c, x.x, x.y, x.z, seen ? 1.0f : 0.0f);
        traced += needs_ray(c) ? 1u : 0u;
        if (seen && out) {
#if defined(__CUDA_ARCH__)
            atomicOr(out + (p.order[j] >> 5), 1u << (p.order[j] & 31u)); // the lanes share words
#else
            set_bit(out, p.order[j]);
#endif
        }
    }
    return traced;
}

// Combines vertex v's partials (lane l of `all` = partial l, in lane order)
// and stores its outputs.
SKYBAKE_HD_INLINE void bake_store(const GpuBakeParams& p, std::uint32_t v, const ShadingPartials& all,
                                  std::uint32_t traced) {
    const Shading sh = finish_shading(combine_partials(all), p.normals[v], p.normalize);
    p.ao[v] = sh.ao;
    p.shading[v] = sh.shading;
    p.bent[v] = sh.bent_normal;
    p.rays[v] = traced;
    p.clamped[v] = sh.clamped ? 1u : 0u;
}

// The whole reduction of chunk vertex v on one thread.
inline void bake_reduce(const GpuBakeParams& p, std::uint32_t v) {
    ShadingPartials all;
    std::uint32_t traced = 0;
    for (std::uint32_t l = 0; l < kReduceLanes; ++l) {
        ShadingPartials s;
        traced += bake_reduce_lane(p, v, l, s);
        all.ao[l] = s.ao[0], all.ao_open[l] = s.ao_open[0], all.a[l] = s.a[0], all.a_open[l] = s.a_open[0];
        all.bx[l] = s.bx[0], all.by[l] = s.by[0], all.bz[l] = s.bz[0];
    }
    bake_store(p, v, all, traced);
}

// The whole chunk on the host, thread by thread as the kernels run it.
inline void emulate_bake_chunk(const GpuBakeParams& p, TraceMethod method) {
    for (std::uint32_t v = 0; v < p.vertex_count; ++v)
        for (std::uint32_t w = 0; w < p.words; ++w) {
            std::uint32_t bits = 0;
            for (std::uint32_t lane = 0; lane < 32; ++lane) {
                const std::uint32_t j = 32 * w + lane;
                const bool vis = method == TraceMethod::Bvh ? bake_visible<TraceMethod::Bvh>(p, v, j)
                                                            : bake_visible<TraceMethod::PerVertex>(p, v, j);
                bits |= std::uint32_t(vis) << lane;
            }
            p.visit_words[std::size_t(v) * p.words + w] = bits;
        }
    for (std::uint32_t v = 0; v < p.vertex_count; ++v)
        bake_reduce(p, v);
}

} // namespace skybake::visibility
