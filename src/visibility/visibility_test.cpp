// Visibility backends: Embree against the brute-force oracle (an independent
// implementation: double-precision Möller–Trumbore, no BVH), the seed's
// per-vertex definitions on hand-made scenes, the bit layout, determinism and
// the errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "visibility/cuda/emulated_tracer.h"
#include "visibility/cuda/test_scenes.h"
#include "visibility/trace_hd.h"
#include "visibility/triangle_hd.h"

using namespace skybake;
using skybake::visibility_test::one_triangle_facing_down;
using skybake::visibility_test::random_mesh;

namespace {


std::vector<Ray> random_rays(std::uint32_t seed, std::size_t n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Ray> rays(n);
    for (auto& r : rays) {
        r.origin = glm::vec3(u(rng), u(rng) + 0.5f, u(rng)) * 1.5f;
        glm::vec3 d;
        do
            d = glm::vec3(u(rng), u(rng), u(rng));
        while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f);
        r.direction = glm::normalize(d);
        r.t_max = (seed % 2) ? std::numeric_limits<float>::infinity() : 1.0f + 2.0f * (u(rng) + 1.0f);
    }
    return rays;
}

} // namespace

TEST(Visibility, TriangleTestMatchesClosedForm) {
    // Ray straight down onto the unit right triangle in the xz plane.
    const glm::dvec3 p0(0, 0, 0), e1(1, 0, 0), e2(0, 0, 1);
    double t, u, v;
    ASSERT_TRUE(visibility::ray_triangle(glm::dvec3(0.25, 2, 0.5), glm::dvec3(0, -1, 0), p0, e1, e2, 0.0, 10.0, t, u, v));
    EXPECT_DOUBLE_EQ(t, 2.0);
    EXPECT_DOUBLE_EQ(u, 0.25);
    EXPECT_DOUBLE_EQ(v, 0.5);
    EXPECT_FALSE(visibility::ray_triangle(glm::dvec3(0.75, 2, 0.5), glm::dvec3(0, -1, 0), p0, e1, e2, 0.0, 10.0, t, u, v));
    EXPECT_FALSE(visibility::ray_triangle(glm::dvec3(0.25, 2, 0.5), glm::dvec3(0, -1, 0), p0, e1, e2, 0.0, 1.5, t, u, v));
    EXPECT_FALSE(visibility::ray_triangle(glm::dvec3(0.25, 2, 0.5), glm::dvec3(1, 0, 0), p0, e1, e2, 0.0, 10.0, t, u, v));
}

TEST(Visibility, EmbreeAgreesWithBruteForceOnRandomRays) {
    for (std::uint32_t seed = 1; seed <= 4; ++seed) {
        const Mesh m = random_mesh(seed, 200);
        const auto rays = random_rays(seed, 20000);
        auto embree = make_ray_queries("embree");
        auto brute = make_ray_queries("brute");
        embree->set_mesh(m);
        brute->set_mesh(m);
        std::vector<std::uint8_t> a(rays.size()), b(rays.size());
        embree->occluded(rays, a);
        brute->occluded(rays, b);
        std::vector<RayHit> ha(rays.size()), hb(rays.size());
        embree->intersect(rays, ha);
        brute->intersect(rays, hb);
        std::size_t occ_diff = 0, hit_diff = 0, occluded = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            occ_diff += a[i] != b[i];
            occluded += b[i];
            // Same closest triangle, or (an edge tie) the same distance.
            if (ha[i].triangle != hb[i].triangle && std::abs(ha[i].t - hb[i].t) > 1e-4f * std::max(1.0f, hb[i].t))
                ++hit_diff;
            if (ha[i].triangle == hb[i].triangle && hb[i].triangle != kNoHit) {
                EXPECT_NEAR(ha[i].t, hb[i].t, 1e-4f * std::max(1.0f, hb[i].t));
                EXPECT_NEAR(ha[i].u, hb[i].u, 1e-3f);
                EXPECT_NEAR(ha[i].v, hb[i].v, 1e-3f);
            }
            // occluded() and intersect() tell the same story.
            EXPECT_EQ(b[i] != 0, hb[i].triangle != kNoHit);
        }
        // A random ray grazes an edge with probability ~1e-6: allow a handful.
        EXPECT_LE(occ_diff, 3u) << "seed " << seed;
        EXPECT_LE(hit_diff, 3u) << "seed " << seed;
        EXPECT_GT(occluded, rays.size() / 10) << "the scene should block a good share of the rays";
        EXPECT_LT(occluded, rays.size() * 9 / 10);
    }
}

TEST(Visibility, BackFacesOccludeOrNot) {
    // A ceiling at y = 1 whose front side faces down (towards the floor point),
    // and the same ceiling flipped.
    for (bool flipped : {false, true}) {
        Mesh m = one_triangle_facing_down(1.0f);
        if (flipped)
            std::swap(m.indices[1], m.indices[2]);
        const Ray up{{0, 0, 0}, 0.0f, {0, 1, 0}, 100.0f};
        for (const char* name : {"embree", "brute"}) {
            auto b = make_ray_queries(name);
            std::uint8_t occ = 0;
            b->set_mesh(m, BackFaces::Occlude);
            b->occluded({&up, 1}, {&occ, 1});
            EXPECT_EQ(occ, 1) << name << " flipped " << flipped;
            b->set_mesh(m, BackFaces::Ignore);
            b->occluded({&up, 1}, {&occ, 1});
            EXPECT_EQ(occ, flipped ? 0 : 1) << name << " flipped " << flipped;
            RayHit hit;
            b->intersect({&up, 1}, {&hit, 1});
            EXPECT_EQ(hit.triangle, flipped ? kNoHit : 0u) << name;
        }
    }
    EXPECT_EQ(parse_back_faces("ignore"), BackFaces::Ignore);
    EXPECT_STREQ(back_faces_name(BackFaces::Occlude), "occlude");
    EXPECT_THROW(parse_back_faces("cull"), Error);
}


namespace {

// Every vertex's words from `tracer` for `rule`, in chunks of `chunk`
// vertices, with ray origins a little above each vertex along its normal.
std::vector<std::uint32_t> trace_words(VisibilityTracer& tracer, const Mesh& m, const SphereRule& rule, bool rotate,
                                       std::uint32_t chunk, float t_max) {
    const auto points = rule.points_f32();
    std::vector<std::uint32_t> order(points.size());
    for (std::uint32_t k = 0; k < order.size(); ++k)
        order[k] = std::uint32_t(order.size()) - 1 - k; // any permutation will do
    std::vector<glm::vec3> visit(points.size());
    for (std::size_t j = 0; j < order.size(); ++j)
        visit[j] = points[order[j]];
    TraceRule r;
    r.points = visit;
    r.order = order;
    r.words_per_vertex = visibility_words(std::uint32_t(points.size()));
    r.rotate = rotate;
    r.t_max = t_max;
    tracer.set_mesh(m);
    chunk = std::min(chunk, tracer.set_rule(r));
    const auto n = std::uint32_t(m.vertex_count());
    std::vector<glm::vec3> origins(n), normals(n);
    std::vector<glm::mat3> rotations(rotate ? n : 0);
    for (std::uint32_t v = 0; v < n; ++v) {
        normals[v] = glm::normalize(m.normals[v]);
        origins[v] = m.positions[v] + 1e-3f * normals[v];
        if (rotate) // a quarter turn about z, vertex by vertex alternately
            rotations[v] = (v % 2) ? glm::mat3(0, 1, 0, -1, 0, 0, 0, 0, 1) : glm::mat3(1.0f);
    }
    std::vector<std::uint32_t> words(std::size_t(n) * r.words_per_vertex, 0xdeadbeefu);
    for (std::uint32_t first = 0; first < n; first += chunk) {
        TraceChunk c;
        c.first = first;
        c.count = std::min(chunk, n - first);
        c.origins = std::span(origins).subspan(first, c.count);
        c.normals = std::span(normals).subspan(first, c.count);
        if (rotate)
            c.rotations = std::span(rotations).subspan(first, c.count);
        c.words = std::span(words).subspan(std::size_t(first) * r.words_per_vertex,
                                           std::size_t(c.count) * r.words_per_vertex);
        tracer.trace(c);
    }
    return words;
}

} // namespace

TEST(Visibility, TracersFillTheDocumentedWords) {
    // The tracer contract on its own, without the bake driver: every tracer
    // gives the brute-force oracle's words up to edge ties, whatever the
    // chunking; bits below the horizon and past the rule are 0; a set bit
    // means the ray really leaves the mesh.
    const Mesh m = random_mesh(11, 60);
    const SphereRule rule = parse_rule("lebedev:110");
    const auto points = rule.points_f32();
    for (bool rotate : {false, true})
        for (float t_max : {std::numeric_limits<float>::infinity(), 0.7f}) {
            auto brute = make_visibility_tracer("brute");
            const auto ref = trace_words(*brute, m, rule, rotate, 1u << 20, t_max);
            auto queries = make_ray_queries("brute");
            queries->set_mesh(m);
            const std::uint32_t W = visibility_words(std::uint32_t(points.size()));
            for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
                const glm::vec3 n = glm::normalize(m.normals[v]);
                for (std::uint32_t k = 0; k < W * 32; ++k) {
                    const bool bit = (ref[v * W + k / 32] >> (k % 32)) & 1u;
                    if (k >= points.size()) {
                        ASSERT_FALSE(bit) << "bit past the rule";
                        continue;
                    }
                    glm::vec3 x = points[k];
                    if (rotate && v % 2)
                        x = glm::vec3(-x.y, x.x, x.z);
                    if (glm::dot(n, x) < 0.0f) {
                        ASSERT_FALSE(bit) << "bit below the horizon";
                        continue;
                    }
                    const Ray ray{m.positions[v] + 1e-3f * n, 0.0f, x, t_max};
                    std::uint8_t occ = 0;
                    queries->occluded({&ray, 1}, {&occ, 1});
                    ASSERT_EQ(bit, occ == 0) << "vertex " << v << " direction " << k;
                }
            }
            auto embree = make_visibility_tracer("embree");
            visibility::EmulatedCudaTracer emulated;
            for (std::uint32_t chunk : {1u, 7u, 1u << 20}) {
                for (VisibilityTracer* t : {static_cast<VisibilityTracer*>(embree.get()),
                                            static_cast<VisibilityTracer*>(&emulated)}) {
                    const auto got = trace_words(*t, m, rule, rotate, chunk, t_max);
                    std::size_t diff = 0;
                    for (std::size_t i = 0; i < got.size(); ++i)
                        diff += std::size_t(__builtin_popcount(got[i] ^ ref[i]));
                    // Single-precision traversals against the double-precision
                    // oracle: a ray or two grazing an edge may differ.
                    EXPECT_LE(diff, 2u) << t->name() << " chunk " << chunk << " rotate " << rotate;
                }
            }
        }
}

TEST(Visibility, FactoriesRefuseWhatTheyCannotMake) {
    if (cuda_device_count() == 0) { // without a GPU (or CUDA) "cuda" is a clear error
        EXPECT_THROW(make_visibility_tracer("cuda"), Error);
        EXPECT_THROW(make_ray_queries("cuda"), Error);
    }
    try {
        make_visibility_tracer("optix");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "backend");
        EXPECT_NE(e.message().find("embree"), std::string::npos) << e.message();
    }
    try {
        make_visibility_tracer("embree", TraceMethod::PerVertex);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "method");
    }
    const Mesh big = generate_mesh({ProceduralKind::Sphere, 40000, 1});
    EXPECT_THROW(make_ray_queries("brute")->set_mesh(big), Error);
    for (TraceMethod mth : {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon, TraceMethod::Cube,
                            TraceMethod::Directional})
        EXPECT_EQ(parse_trace_method(trace_method_name(mth)), mth);
    try {
        parse_trace_method("octree");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.message(), "unknown method 'octree'; choose bvh (default), per-vertex (cuda backend: every "
                               "triangle for every ray), per-polygon (cuda backend: every triangle, cached in shared "
                               "memory), cube (raster backend, its default: a depth cube map at each vertex) or "
                               "directional (raster backend: a depth map per direction)");
    }
}
