// The CUDA backend on a GPU (every test skips without a CUDA device):
//  - every method against the Embree backend: at least 99.99% of the bits
//    equal and AO within 1e-4 (expect_agreement in cuda_bake_test_util.h);
//  - against its own host emulation (the same thread bodies on the CPU): the
//    same bits, and AO equal to the float (the kernels are built without
//    contracted multiply-adds);
//  - ray queries, chunking, determinism, memory limits, a mesh of 1M triangles.
#include <gtest/gtest.h>

#include "skybake/core.h"

#if defined(SKYBAKE_HAS_CUDA)
#include <cstdio>
#include <tuple>

#include "skybake/error.h"
#include "bake/cuda_bake_test_util.h"
#include "core/gpu_test.h"
#include "skybake/bake.h"
#include "visibility/cuda/cuda_backend.h"
#include "core/test_paths.h"

using namespace skybake;
using namespace skybake::visibility;
using namespace skybake::visibility_test;

namespace {


// A bake with `cuda` as the tracer, with its method.
BakeOutputs gpu_bake(CudaBackend& cuda, const Mesh& m, const SphereRule& rule, BakeOptions o) {
    BakeOutputs out;
    o.method = cuda.method();
    bake_shading(m, rule, cuda, o, out);
    return out;
}


void expect_same(const BakeOutputs& a, const BakeOutputs& b) {
    EXPECT_EQ(a.visibility_bits, b.visibility_bits);
    EXPECT_EQ(a.ao, b.ao);
    EXPECT_EQ(a.shading, b.shading);
    EXPECT_EQ(a.bent_normal, b.bent_normal);
    EXPECT_EQ(a.rays, b.rays);
    EXPECT_EQ(a.clamped_vertices, b.clamped_vertices);
}

} // namespace

TEST(CudaBackendGpu, EveryMethodMatchesEmbreeAndTheHostEmulation) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    std::printf("device: %s\n", CudaBackend().device_name().c_str());
    for (const auto& [name, m] : scenes())
        for (const char* spec : gpu_test_rules())
            for (BackFaces back : gpu_test_back_faces()) {
                const SphereRule rule = parse_rule(spec);
                BakeOptions o;
                o.store_bits = true;
                o.back_faces = back;
                const BakeOutputs e = embree_bake(m, rule, o);
                const BakeOutputs host = emulated(m, rule, o, TraceMethod::Bvh);
                for (TraceMethod method : {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon}) {
                    const std::string label =
                        name + " " + spec + " " + back_faces_name(back) + " " + trace_method_name(method);
                    SCOPED_TRACE(label);
                    CudaBackend cuda(method);
                    const BakeOutputs g = gpu_bake(cuda, m, rule, o);
                    const Agreement a = compare_bakes(m, rule, o, g, e);
                    a.print(label.c_str());
                    expect_agreement(a, tie_free(name, rule));
                    expect_same(g, host);
                }
            }
}

TEST(CudaBackendGpu, RealModelsMatchEmbree) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const std::string models = skybake::test::assimp_models();
    const Mesh engine = load_mesh(models + "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
    const Mesh wuson = load_mesh(models + "/OBJ/WusonOBJ.obj");
    for (const auto& [name, m, spec] :
         {std::tuple<const char*, const Mesh&, const char*>{"engine", engine, "lebedev:110+rotate"},
          {"wuson", wuson, "lebedev:5810"}}) {
        const SphereRule rule = parse_rule(spec);
        BakeOptions o;
        o.store_bits = true;
        const BakeOutputs e = embree_bake(m, rule, o);
        for (TraceMethod method : {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon}) {
            const std::string label = std::string(name) + " " + spec + " " + trace_method_name(method);
            SCOPED_TRACE(label);
            CudaBackend cuda(method);
            const BakeOutputs g = gpu_bake(cuda, m, rule, o);
            const Agreement a = compare_bakes(m, rule, o, g, e);
            a.print(label.c_str());
            expect_agreement(a, true);
        }
    }
}

TEST(CudaBackendGpu, RayQueriesEqualTheHostTraversal) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    CudaBackend cuda;
    for (const auto& [name, m] : scenes())
        for (bool cull : {false, true}) {
            SCOPED_TRACE(name);
            cuda.set_mesh(m, cull ? BackFaces::Ignore : BackFaces::Occlude);
            const std::vector<Ray> rays = rays_for(m, 17, 50000, cull);
            std::vector<std::uint8_t> occ(rays.size());
            std::vector<RayHit> hits(rays.size());
            cuda.occluded(rays, occ);
            cuda.intersect(rays, hits);
            const BvhView bvh = cuda.bvh().view();
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const Ray& r = rays[i];
                ASSERT_EQ(bool(occ[i]), bvh_occluded(bvh, r.origin, r.direction, r.t_min, r.t_max, cull)) << i;
                float t = r.t_max, u = 0, v = 0;
                std::uint32_t id = kNoHit;
                bvh_trace<false>(bvh, r.origin, r.direction, r.t_min, t, cull, id, u, v);
                ASSERT_EQ(hits[i].triangle, id) << i;
                if (id != kNoHit) {
                    ASSERT_EQ(hits[i].t, t) << i;
                    ASSERT_EQ(hits[i].u, u) << i;
                    ASSERT_EQ(hits[i].v, v) << i;
                }
            }
        }
}

TEST(CudaBackendGpu, ChunkedLaunchesAndRepeatedRunsGiveTheSameResult) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const Mesh m = generated(ProceduralKind::City, 20000);
    const SphereRule rule = parse_rule("lebedev:1202+rotate");
    BakeOptions o;
    o.store_bits = true;
    CudaBackend cuda;
    const BakeOutputs one = gpu_bake(cuda, m, rule, o);
    // The default limit is work-bound here: 2^25 slots of 32 × 38 words give
    // 27,594 vertices a launch, and the city has 34,116, so two chunks run
    // (memory is not the bound on any current GPU).
    const std::uint64_t words = (rule.size() + 31) / 32;
    const auto per_chunk = std::uint32_t(CudaBackend::Limits{}.slots_per_launch / (32 * words));
    const auto n = std::uint32_t(m.vertex_count());
    EXPECT_EQ(cuda.last_chunk_count(), (n + per_chunk - 1) / per_chunk) << n << " vertices, " << per_chunk << " a chunk";
    EXPECT_GE(cuda.last_chunk_count(), 2u);
    EXPECT_EQ(gpu_bake(cuda, m, rule, o).visibility_bits, one.visibility_bits);
    CudaBackend::Limits small;
    small.slots_per_launch = 32ull * 38 * 101; // 101 vertices of 38 words per chunk
    cuda.set_limits(small);
    const BakeOutputs chunked = gpu_bake(cuda, m, rule, o);
    EXPECT_EQ(cuda.last_chunk_count(), (std::uint32_t(m.vertex_count()) + 100) / 101);
    expect_same(chunked, one);
    for (TraceMethod method : {TraceMethod::PerVertex, TraceMethod::PerPolygon}) {
        CudaBackend brute(method);
        small.tests_per_launch = 32ull * 38 * 7 * m.triangle_count(); // 7 vertices per chunk
        brute.set_limits(small);
        const BakeOutputs b = gpu_bake(brute, m, rule, o);
        EXPECT_GT(brute.last_chunk_count(), 100u);
        expect_same(b, one);
    }
}

TEST(CudaBackendGpu, TooLittleMemoryIsAClearErrorOrSmallerChunks) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const Mesh m = generated(ProceduralKind::Terrain, 50000);
    const SphereRule rule = parse_rule("lebedev:590");
    CudaBackend cuda;
    CudaBackend::Limits tiny;
    tiny.memory_bytes = 64 << 10; // 64 KiB: not even the BVH
    cuda.set_limits(tiny);
    try {
        gpu_bake(cuda, m, rule, {});
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("GPU memory"), std::string::npos) << e.what();
    }
    // Room for the BVH, the rule (16 bytes a direction) and about a hundred
    // vertices (origin, normal and two words of 19 per vertex: 176 bytes):
    // many chunks, same answer.
    const std::size_t bvh_bytes = build_bvh(m).bytes();
    CudaBackend::Limits some;
    some.memory_bytes = bvh_bytes + 590 * 16 + 100 * 176;
    cuda.set_limits(some);
    const BakeOutputs a = gpu_bake(cuda, m, rule, {});
    EXPECT_GE(cuda.last_chunk_count(), m.vertex_count() / 101);
    cuda.set_limits({});
    const BakeOutputs b = gpu_bake(cuda, m, rule, {});
    EXPECT_EQ(a.ao, b.ao);
}

TEST(CudaBackendGpu, MillionTriangleCityMatchesEmbree) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const Mesh m = generated(ProceduralKind::City, 1'000'000);
    const SphereRule rule = parse_rule("lebedev:110+rotate");
    BakeOptions o;
    o.store_bits = true;
    const BakeOutputs e = embree_bake(m, rule, o);
    CudaBackend cuda;
    const BakeOutputs g = gpu_bake(cuda, m, rule, o);
    std::printf("1M city: %.3f s on the GPU (BVH %.2f s), %.3f s with Embree\n", g.trace_seconds, g.build_seconds,
                e.trace_seconds);
    const Agreement a = compare_bakes(m, rule, o, g, e);
    a.print("1M city");
    expect_agreement(a, true);
}

#else
TEST(CudaBackendGpu, NotInThisBuild) {
    GTEST_SKIP() << "this build has no CUDA";
}
#endif
