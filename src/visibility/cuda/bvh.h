// The CUDA backend's bounding volume hierarchy: built on the CPU with Embree's
// BVH builder (rtcBuildBVH, binned SAH, spatial splits optional), flattened into a compact
// binary layout that one GPU thread walks with a small stack, and traversed by
// SKYBAKE_HD functions, so that the same code runs in the kernels and in the
// CPU unit tests.
//
// Aila T., Laine S. Understanding the efficiency of ray traversal on GPUs.
// High-Performance Graphics 2009 (node layout: both child boxes in one 64-byte
// node, read as four 16-byte loads).
// Stich M., Friedrich H., Dietrich A. Spatial splits in bounding volume
// hierarchies. High-Performance Graphics 2009 (Embree's high-quality builder,
// optional).
// Ize T. Robust BVH ray traversal. JCGT 2(2), 2013 (the slab test below never
// culls a box that the exact ray meets).
//
// [SECTION] Layout
// [SECTION] Building (host)
// [SECTION] Traversal (host and device)
#pragma once

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/hd.h"
#include "visibility/triangle_hd.h"

namespace skybake {
struct Mesh;
}

namespace skybake::visibility {

// [SECTION] Layout -----------------------------------------------------------------------

// An inner node: the boxes of both children, interleaved per axis
//   box = lo0.x hi0.x lo0.y hi0.y | lo0.z hi0.z lo1.x hi1.x | lo1.y hi1.y lo1.z hi1.z
// and the two children. A child ≥ 0 is the index of an inner node; a child < 0
// is a leaf, ~child = (first << kLeafCountBits) | count: `count` triangles
// starting at BvhView::triangles[first]. Node 0 is the root.
struct alignas(16) BvhNode {
    float box[12];
    std::int32_t child[2];
    std::int32_t pad[2];
};
static_assert(sizeof(BvhNode) == 64);

// A triangle ready for Möller–Trumbore: p0, e1 = p1 − p0, e2 = p2 − p0 (world
// space, mesh units) and the index of the mesh triangle it came from.
struct alignas(16) BvhTriangle {
    glm::vec3 p0;
    float pad0;
    glm::vec3 e1;
    float pad1;
    glm::vec3 e2;
    std::uint32_t id;
};
static_assert(sizeof(BvhTriangle) == 48);

inline constexpr int kLeafCountBits = 4;
inline constexpr std::uint32_t kMaxLeafTriangles = 8;          // < 2^kLeafCountBits
inline constexpr std::uint32_t kMaxBvhTriangleRefs = 1u << 27; // leaf references (first < 2^27)
inline constexpr int kBvhStackSize = 64;                       // deepest tree the traversal walks

SKYBAKE_HD_INLINE std::int32_t encode_leaf(std::uint32_t first, std::uint32_t count) {
    return ~std::int32_t((first << kLeafCountBits) | count);
}
SKYBAKE_HD_INLINE void decode_leaf(std::int32_t child, std::uint32_t& first, std::uint32_t& count) {
    const auto v = std::uint32_t(~child);
    first = v >> kLeafCountBits;
    count = v & ((1u << kLeafCountBits) - 1u);
}

// A non-owning view of a BVH, in host or device memory.
struct BvhView {
    const BvhNode* nodes = nullptr;
    const BvhTriangle* triangles = nullptr; // in leaf order; a triangle cut by spatial splits appears in several leaves
    std::uint32_t node_count = 0;
    std::uint32_t triangle_count = 0;
};

// [SECTION] Building (host) ----------------------------------------------------------------

struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<BvhTriangle> triangles; // leaf order, references
    std::vector<BvhTriangle> soup;      // every mesh triangle once, in mesh order (soup[t].id == t)
    int depth = 0;                      // levels of inner nodes on the longest root-to-leaf path
    double build_seconds = 0.0;

    BvhView view() const {
        return {nodes.data(), triangles.data(), std::uint32_t(nodes.size()), std::uint32_t(triangles.size())};
    }
    std::size_t bytes() const {
        return nodes.size() * sizeof(BvhNode) + (triangles.size() + soup.size()) * sizeof(BvhTriangle);
    }
};

// Builds the BVH of mesh.positions / mesh.indices (the mesh must pass
// validate_mesh) with Embree's binned SAH builder; spatial_splits adds
// Stich et al.'s split references (Embree's high quality). On the generated
// scenes, splits cost 4 to 14 times the build time and did not speed up the
// traversal (docs/PERFORMANCE.md), so they are off by default. Boxes are widened by a few millionths of the mesh's size
// so that rounding in the triangle test cannot make the BVH miss a hit that the plain loop over all triangles finds.
// Throws skybake::Error when the mesh is too large (more than kMaxBvhTriangleRefs references) or Embree fails.
Bvh build_bvh(const Mesh& mesh, bool spatial_splits = false);

// [SECTION] Traversal (host and device) -------------------------------------------------------

namespace bvh_detail {

// Plain comparisons: the slab distances below are never NaN, and these are
// single min/max instructions on both the CPU and the GPU.
SKYBAKE_HD_INLINE float min2(float a, float b) {
    return a < b ? a : b;
}
SKYBAKE_HD_INLINE float max2(float a, float b) {
    return a > b ? a : b;
}

// 1 + 2γ(3), γ(n) = nε/(1 − nε), ε = 2^-24: Ize's bound on the rounding of the slab distances.
inline constexpr float kSlabScale = 1.0f + 2.0f * (3.0f * 5.9604645e-8f) / (1.0f - 3.0f * 5.9604645e-8f);

// Slab test of box (lo.x hi.x lo.y hi.y lo.z hi.z at b[0..5]) against the ray
// o + t/inv_d for t in [t_min, t_max] (t_min ≥ 0). inv_d is finite
// (inverse_direction), so no distance is 0 · ∞ = NaN: a ray parallel to a slab
// gets 0 for a plane through its origin and a huge distance otherwise, which
// keeps the slab when the origin is inside it and at worst keeps a box it
// could have culled.
SKYBAKE_HD_INLINE bool slab(const float* b, const glm::vec3& o, const glm::vec3& inv_d, float t_min, float t_max,
                            float& t_near) {
    const float x0 = (b[0] - o.x) * inv_d.x, x1 = (b[1] - o.x) * inv_d.x;
    const float y0 = (b[2] - o.y) * inv_d.y, y1 = (b[3] - o.y) * inv_d.y;
    const float z0 = (b[4] - o.z) * inv_d.z, z1 = (b[5] - o.z) * inv_d.z;
    t_near = max2(max2(min2(x0, x1), min2(y0, y1)), max2(min2(z0, z1), t_min));
    const float t_far = min2(min2(max2(x0, x1), max2(y0, y1)), min2(max2(z0, z1), t_max));
    return t_near <= t_far * kSlabScale;
}

SKYBAKE_HD_INLINE BvhNode load_node(const BvhNode* nodes, std::int32_t i) {
#if defined(__CUDA_ARCH__)
    const float4* q = reinterpret_cast<const float4*>(nodes + i);
    const float4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2), d = __ldg(q + 3);
    BvhNode n;
    n.box[0] = a.x, n.box[1] = a.y, n.box[2] = a.z, n.box[3] = a.w;
    n.box[4] = b.x, n.box[5] = b.y, n.box[6] = b.z, n.box[7] = b.w;
    n.box[8] = c.x, n.box[9] = c.y, n.box[10] = c.z, n.box[11] = c.w;
    n.child[0] = __float_as_int(d.x), n.child[1] = __float_as_int(d.y);
    return n;
#else
    return nodes[i];
#endif
}

SKYBAKE_HD_INLINE BvhTriangle load_triangle(const BvhTriangle* triangles, std::uint32_t i) {
#if defined(__CUDA_ARCH__)
    const float4* q = reinterpret_cast<const float4*>(triangles + i);
    const float4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2);
    BvhTriangle t;
    t.p0 = glm::vec3(a.x, a.y, a.z);
    t.e1 = glm::vec3(b.x, b.y, b.z);
    t.e2 = glm::vec3(c.x, c.y, c.z);
    t.id = __float_as_uint(c.w);
    return t;
#else
    return triangles[i];
#endif
}

} // namespace bvh_detail

// Reciprocal direction for the slab test: ±1e30 instead of ±∞ for a zero (or
// denormal) component, so that the slab distances are never NaN.
SKYBAKE_HD_INLINE float inverse_component(float d) {
    // The sign of a zero does not matter: the slab test orders both distances.
    return (d > 1e-30f || d < -1e-30f) ? 1.0f / d : (d < 0.0f ? -1e30f : 1e30f);
}
SKYBAKE_HD_INLINE glm::vec3 inverse_direction(const glm::vec3& d) {
    return glm::vec3(inverse_component(d.x), inverse_component(d.y), inverse_component(d.z));
}

// Closest or any hit of the ray o + t·d, t in (t_min, t_max], with the
// Möller–Trumbore test of triangle_hd.h. cull_back: triangles met from behind
// (d along their counter-clockwise normal) are ignored. Returns whether
// something was hit. AnyHit: stops at the first hit found (occlusion); else
// returns the closest, ties broken by the lower mesh triangle index so that the
// answer does not depend on the tree: t_max, hit_id, u, v are then updated.
// Counts: TraversalCounts to count the work (nodes visited, triangles
// tested), as the benchmarks do to model a warp's cost; by default nothing.
struct NoTraversalCounts {};
struct TraversalCounts {
    std::uint32_t nodes = 0;
    std::uint32_t triangles = 0;
};

template <bool AnyHit, class Counts = NoTraversalCounts>
SKYBAKE_HD_INLINE bool bvh_trace(const BvhView& bvh, const glm::vec3& o, const glm::vec3& d, float t_min, float& t_max,
                                 bool cull_back, std::uint32_t& hit_id, float& hit_u, float& hit_v,
                                 Counts* counts = nullptr) {
    constexpr bool kCount = !std::is_same_v<Counts, NoTraversalCounts>;
    using namespace bvh_detail;
    const glm::vec3 inv_d = inverse_direction(d);
    std::int32_t stack[kBvhStackSize];
    int sp = 0;
    std::int32_t cur = 0;
    bool hit = false;
    for (;;) {
        if (cur >= 0) {
            const BvhNode n = load_node(bvh.nodes, cur);
            if constexpr (kCount)
                ++counts->nodes;
            // Constant indices only, so that the node stays in registers on the GPU.
            const std::int32_t c0 = n.child[0], c1 = n.child[1];
            float t0, t1;
            const bool h0 = slab(n.box, o, inv_d, t_min, t_max, t0);
            const bool h1 = slab(n.box + 6, o, inv_d, t_min, t_max, t1);
            if (h0 && h1) {
                const bool swap = t1 < t0; // nearer child first
                stack[sp++] = swap ? c0 : c1;
                cur = swap ? c1 : c0;
                continue;
            }
            if (h0 || h1) {
                cur = h0 ? c0 : c1;
                continue;
            }
        } else {
            std::uint32_t first, count;
            decode_leaf(cur, first, count);
            for (std::uint32_t i = first; i < first + count; ++i) {
                const BvhTriangle tri = load_triangle(bvh.triangles, i);
                if constexpr (kCount)
                    ++counts->triangles;
                float t, u, v;
                if (!ray_triangle(o, d, tri.p0, tri.e1, tri.e2, t_min, t_max, t, u, v, cull_back))
                    continue;
                if (AnyHit)
                    return true;
                if (t < t_max || tri.id < hit_id) { // t == t_max: a tie with the best so far
                    t_max = t;
                    hit_id = tri.id;
                    hit_u = u;
                    hit_v = v;
                    hit = true;
                }
            }
        }
        if (sp == 0)
            break;
        cur = stack[--sp];
    }
    return hit;
}

// Whether the ray meets any triangle within (t_min, t_max].
SKYBAKE_HD_INLINE bool bvh_occluded(const BvhView& bvh, const glm::vec3& o, const glm::vec3& d, float t_min,
                                    float t_max, bool cull_back) {
    std::uint32_t id = 0xffffffffu;
    float u, v;
    return bvh_trace<true>(bvh, o, d, t_min, t_max, cull_back, id, u, v);
}

// The same answer without a hierarchy: every triangle of `soup` in turn (the
// seed's naive method), stopping at the first hit.
SKYBAKE_HD_INLINE bool soup_occluded(const BvhTriangle* soup, std::uint32_t count, const glm::vec3& o,
                                     const glm::vec3& d, float t_min, float t_max, bool cull_back) {
    for (std::uint32_t i = 0; i < count; ++i) {
        const BvhTriangle tri = bvh_detail::load_triangle(soup, i);
        float t, u, v;
        if (ray_triangle(o, d, tri.p0, tri.e1, tri.e2, t_min, t_max, t, u, v, cull_back))
            return true;
    }
    return false;
}

} // namespace skybake::visibility
