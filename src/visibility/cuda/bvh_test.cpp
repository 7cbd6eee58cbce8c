// The CUDA backend's host-side code on the CPU: the BVH built with Embree's
// builder and flattened (structure invariants), its traversal (the same
// SKYBAKE_HD function the kernels run) against the plain loop over every
// triangle and against Embree. The bakes through the kernels' thread bodies are
// in src/bake/cuda_bake_test.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "visibility/cuda/bvh.h"
#include "visibility/cuda/cuda_backend.h"
#include "visibility/cuda/test_scenes.h"
#include "visibility/embree/embree_backend.h"

using namespace skybake;
using namespace skybake::visibility;

namespace {

using namespace skybake::visibility_test;

bool box_contains(const float* box, const glm::vec3& p) {
    return p.x >= box[0] && p.x <= box[1] && p.y >= box[2] && p.y <= box[3] && p.z >= box[4] && p.z <= box[5];
}

bool box_inside(const float* inner, const float* outer) {
    return inner[0] >= outer[0] && inner[1] <= outer[1] && inner[2] >= outer[2] && inner[3] <= outer[3] &&
           inner[4] >= outer[4] && inner[5] <= outer[5];
}

} // namespace

TEST(CudaBvh, StructureHoldsEveryTriangleInNestedBoxes) {
    for (const auto& [name, m] : scenes())
        for (bool splits : {false, true}) {
            SCOPED_TRACE(name + (splits ? " with spatial splits" : ""));
            const Bvh bvh = build_bvh(m, splits);
            ASSERT_FALSE(bvh.nodes.empty());
            EXPECT_LE(bvh.depth, kBvhStackSize);
            EXPECT_EQ(bvh.soup.size(), m.triangle_count());
            // Every reference is one mesh triangle; spatial splits may add a few.
            EXPECT_GE(bvh.triangles.size(), m.triangle_count());
            EXPECT_LT(bvh.triangles.size(), 2 * m.triangle_count());
            std::vector<int> seen(m.triangle_count(), 0);
            std::vector<std::uint8_t> corner_inside(3 * m.triangle_count(), 0);
            std::uint32_t visited = 0;
            // Walk from the root with each child's box, checking nesting.
            struct Item {
                std::int32_t child;
                float box[6];
            };
            std::vector<Item> todo;
            const BvhNode& root = bvh.nodes[0];
            for (int c = 0; c < 2; ++c) {
                Item it{root.child[c], {}};
                std::copy(root.box + 6 * c, root.box + 6 * c + 6, it.box);
                todo.push_back(it);
            }
            ++visited;
            while (!todo.empty()) {
                const Item it = todo.back();
                todo.pop_back();
                EXPECT_LE(it.box[0], it.box[1]);
                if (it.child >= 0) {
                    ASSERT_LT(std::size_t(it.child), bvh.nodes.size());
                    ++visited;
                    const BvhNode& n = bvh.nodes[std::size_t(it.child)];
                    for (int c = 0; c < 2; ++c) {
                        Item sub{n.child[c], {}};
                        std::copy(n.box + 6 * c, n.box + 6 * c + 6, sub.box);
                        // Child boxes are padded the same way, so they nest.
                        EXPECT_TRUE(box_inside(sub.box, it.box) || (sub.child < 0 && ~sub.child == 0));
                        todo.push_back(sub);
                    }
                    continue;
                }
                std::uint32_t first, count;
                decode_leaf(it.child, first, count);
                EXPECT_LE(count, kMaxLeafTriangles);
                for (std::uint32_t i = first; i < first + count; ++i) {
                    ASSERT_LT(i, bvh.triangles.size());
                    const BvhTriangle& t = bvh.triangles[i];
                    ASSERT_LT(t.id, m.triangle_count());
                    ++seen[t.id];
                    const glm::vec3 p[3] = {t.p0, t.p0 + t.e1, t.p0 + t.e2};
                    for (int k = 0; k < 3; ++k)
                        if (box_contains(it.box, p[k]))
                            corner_inside[3 * t.id + std::uint32_t(k)] = 1;
                }
            }
            EXPECT_EQ(visited, bvh.nodes.size()); // every node reachable once
            for (std::size_t t = 0; t < m.triangle_count(); ++t) {
                ASSERT_GE(seen[t], 1) << "triangle " << t;
                // Each corner lies in the box of some leaf holding the triangle: the
                // split bounds cover the triangle.
                for (int k = 0; k < 3; ++k)
                    ASSERT_TRUE(corner_inside[3 * t + std::size_t(k)]) << "triangle " << t << " corner " << k;
            }
        }
}

TEST(CudaBvh, TinyMeshGetsARootNode) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    const Bvh bvh = build_bvh(m);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_TRUE(bvh_occluded(bvh.view(), {0.2f, 0.2f, 1.0f}, {0, 0, -1}, 0.0f, 10.0f, false));
    EXPECT_FALSE(bvh_occluded(bvh.view(), {0.2f, 0.2f, 1.0f}, {0, 0, 1}, 0.0f, 10.0f, false));
    EXPECT_FALSE(bvh_occluded(bvh.view(), {0.2f, 0.2f, 1.0f}, {0, 0, -1}, 0.0f, 0.5f, false)); // too short
    // Seen from +z the triangle is counter-clockwise: its front. From below it is a back face.
    EXPECT_TRUE(bvh_occluded(bvh.view(), {0.2f, 0.2f, 1.0f}, {0, 0, -1}, 0.0f, 10.0f, true));
    EXPECT_FALSE(bvh_occluded(bvh.view(), {0.2f, 0.2f, -1.0f}, {0, 0, 1}, 0.0f, 10.0f, true));
    EXPECT_TRUE(bvh_occluded(bvh.view(), {0.2f, 0.2f, -1.0f}, {0, 0, 1}, 0.0f, 10.0f, false));
}

// The hierarchy only skips work: with the same triangle test, the BVH and the
// loop over every triangle must agree on every ray.
TEST(CudaBvh, TraversalEqualsTheLoopOverEveryTriangle) {
    for (const auto& [name, m] : scenes())
        for (bool splits : {false, true}) {
            SCOPED_TRACE(name + (splits ? " with spatial splits" : ""));
            const Bvh bvh = build_bvh(m, splits);
            for (bool cull : {false, true})
                for (bool finite : {false, true}) {
                    const std::vector<Ray> rays = rays_for(m, 11, 4000, finite);
                    std::size_t hits = 0;
                    for (const Ray& r : rays) {
                        const bool a = bvh_occluded(bvh.view(), r.origin, r.direction, r.t_min, r.t_max, cull);
                        const bool b = soup_occluded(bvh.soup.data(), std::uint32_t(bvh.soup.size()), r.origin,
                                                     r.direction, r.t_min, r.t_max, cull);
                        ASSERT_EQ(a, b);
                        hits += a;
                    }
                    EXPECT_GT(hits, rays.size() / 20); // the rays do meet the mesh
                    EXPECT_LT(hits, rays.size());
                    // Closest hits: the same triangle as the full loop's closest (lowest index on ties).
                    for (std::size_t i = 0; i < rays.size(); i += 4) {
                        const Ray& r = rays[i];
                        float t = r.t_max, u = 0, v = 0;
                        std::uint32_t id = kNoHit;
                        const bool hit =
                            bvh_trace<false>(bvh.view(), r.origin, r.direction, r.t_min, t, cull, id, u, v);
                        float best = r.t_max;
                        std::uint32_t best_id = kNoHit;
                        for (const BvhTriangle& tri : bvh.soup) {
                            float tt, uu, vv;
                            if (ray_triangle(r.origin, r.direction, tri.p0, tri.e1, tri.e2, r.t_min, best, tt, uu, vv,
                                             cull) &&
                                (tt < best || tri.id < best_id)) {
                                best = tt;
                                best_id = tri.id;
                            }
                        }
                        ASSERT_EQ(hit, best_id != kNoHit);
                        ASSERT_EQ(id, best_id);
                        if (hit) {
                            ASSERT_EQ(t, best);
                        }
                    }
                }
        }
}

// The counting traversal (benchmarks) answers as the plain one, and a ray that
// misses the root's boxes visits the root only.
TEST(CudaBvh, CountedTraversalAnswersTheSame) {
    const Mesh m = generated(ProceduralKind::Torus, 2000);
    const Bvh bvh = build_bvh(m);
    std::uint64_t nodes = 0;
    for (const Ray& r : rays_for(m, 4, 2000, false)) {
        TraversalCounts n;
        float t = r.t_max, u, v;
        std::uint32_t id = kNoHit;
        const bool counted = bvh_trace<true>(bvh.view(), r.origin, r.direction, r.t_min, t, false, id, u, v, &n);
        ASSERT_EQ(counted, bvh_occluded(bvh.view(), r.origin, r.direction, r.t_min, r.t_max, false));
        ASSERT_GE(n.nodes, 1u);
        if (counted) {
            ASSERT_GE(n.triangles, 1u);
        }
        nodes += n.nodes;
    }
    EXPECT_LT(double(nodes) / 2000.0, 0.2 * double(bvh.nodes.size())); // far fewer than all
    TraversalCounts away;
    float t = INFINITY, u, v;
    std::uint32_t id = kNoHit;
    const glm::vec3 far = compute_bounds(m).max + glm::vec3(10.0f);
    EXPECT_FALSE(bvh_trace<true>(bvh.view(), far, glm::vec3(0, 1, 0), 0.0f, t, false, id, u, v, &away));
    EXPECT_EQ(away.nodes, 1u);
    EXPECT_EQ(away.triangles, 0u);
}

// Zero-area and repeated triangles, and a mesh far from the origin (where the
// box padding must scale with the coordinates, not only the extent).
TEST(CudaBvh, DegenerateRepeatedAndFarAwayTriangles) {
    Mesh m = random_soup(9, 300);
    const std::size_t n = m.triangle_count();
    for (std::size_t t = 0; t < n; t += 10) { // repeated
        for (int k = 0; k < 3; ++k)
            m.indices.push_back(m.indices[3 * t + std::size_t(k)]);
    }
    for (std::size_t t = 0; t < n; t += 7) { // zero area: a repeated vertex, and three collinear points
        m.indices.insert(m.indices.end(), {m.indices[3 * t], m.indices[3 * t], m.indices[3 * t + 1]});
        const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]];
        const auto base = std::uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {a, 0.5f * (a + b), b});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    compute_normals(m);
    for (const glm::vec3 shift : {glm::vec3(0.0f), glm::vec3(1e5f, -3e4f, 7e4f)}) {
        Mesh moved = m;
        for (glm::vec3& p : moved.positions)
            p += shift;
        SCOPED_TRACE(shift.x);
        const Bvh bvh = build_bvh(moved);
        EmbreeBackend embree;
        embree.set_mesh(moved, BackFaces::Occlude);
        const std::vector<Ray> rays = rays_for(moved, 21, 20000, false, false);
        std::vector<std::uint8_t> occ(rays.size());
        embree.occluded(rays, occ);
        std::size_t differ = 0, hits = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Ray& r = rays[i];
            const bool a = bvh_occluded(bvh.view(), r.origin, r.direction, r.t_min, r.t_max, false);
            ASSERT_EQ(a, soup_occluded(bvh.soup.data(), std::uint32_t(bvh.soup.size()), r.origin, r.direction, r.t_min,
                                       r.t_max, false));
            differ += a != bool(occ[i]);
            hits += a;
        }
        EXPECT_GT(hits, rays.size() / 10);
        EXPECT_LE(double(differ), 1e-4 * double(rays.size()));
    }
}

// An independent implementation: Embree's own BVH and triangle test.
TEST(CudaBvh, TraversalAgreesWithEmbree) {
    for (const auto& [name, m] : scenes()) {
        SCOPED_TRACE(name);
        const Bvh bvh = build_bvh(m);
        EmbreeBackend embree;
        for (bool cull : {false, true}) {
            embree.set_mesh(m, cull ? BackFaces::Ignore : BackFaces::Occlude);
            const std::vector<Ray> rays = rays_for(m, 5, 20000, cull, false);
            std::vector<std::uint8_t> occ(rays.size());
            std::vector<RayHit> hits(rays.size());
            embree.occluded(rays, occ);
            embree.intersect(rays, hits);
            std::size_t occ_diff = 0, hit_diff = 0, ties = 0, hits_same = 0, t_close = 0;
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const Ray& r = rays[i];
                float t = r.t_max, u = 0, v = 0;
                std::uint32_t id = kNoHit;
                bvh_trace<false>(bvh.view(), r.origin, r.direction, r.t_min, t, cull, id, u, v);
                if (bvh_occluded(bvh.view(), r.origin, r.direction, r.t_min, r.t_max, cull) != bool(occ[i]))
                    ++occ_diff;
                if (id == hits[i].triangle) {
                    if (id != kNoHit) {
                        ++hits_same;
                        t_close += std::abs(t - hits[i].t) <= 1e-5f * (1.0f + hits[i].t);
                    }
                } else if (is_tie(m, r, id) || is_tie(m, r, hits[i].triangle)) {
                    ++ties; // a hit on the edge two triangles share, or a grazing ray
                } else {
                    ++hit_diff;
                }
            }
            std::printf("%s, cull %d: of %zu rays, %zu occlusion answers and %zu closest triangles differ from "
                        "Embree (%zu more are edge ties); %zu of %zu equal hits within 1e-5 in t\n",
                        name.c_str(), int(cull), rays.size(), occ_diff, hit_diff, ties, t_close, hits_same);
            EXPECT_LE(double(occ_diff), 1e-4 * double(rays.size()));
            EXPECT_LE(double(hit_diff), 1e-4 * double(rays.size()));
            EXPECT_LE(double(ties), 1e-3 * double(rays.size()));
            EXPECT_GE(double(t_close), 0.99 * double(hits_same)); // grazing rays have ill-conditioned t
        }
    }
}

