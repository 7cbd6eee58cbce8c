// CUDA visibility backend benchmarks.
//
// BM_GpuAo: whole bakes (rays, bits and reduction; the BVH build is reported
//   apart) with the cuda backend and one method, and with the Embree backend
//   on the same scene in the same iteration (the baseline). Counters: Mrays/s
//   of each and their ratio. Skipped without a CUDA device.
// BM_BvhBuild: building the CUDA backend's BVH (Embree's builder with spatial
//   splits, then flattening) against committing an Embree scene of the same
//   mesh. Runs anywhere.
// BM_HostTraversal: the SKYBAKE_HD traversal the kernels run, on one CPU
//   thread, against rtcOccluded1 on the same rays, also on one thread: a
//   measure of the BVH's quality that needs no GPU. Runs anywhere.
// BM_WarpModel: the kernels' warp layout, counted on the host. Each warp's 32
//   lanes are traced with the traversal's counters (nodes + triangles per
//   lane); a warp runs as long as its longest lane, so its cost is 32 × that
//   maximum and its SIMT efficiency the lanes' sum over the cost. Directions in
//   the coherent visiting order (what the kernels use) against the rule's own
//   order (the baseline): the ratio of the costs is the speed-up the order
//   buys. A model, not a timing; runs anywhere.
#include <chrono>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include <limits>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "ao_scenes.h"
#include "skybake/core.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "bake/internal.h"
#include "skybake/bake.h"
#include "visibility/trace_hd.h"
#include "visibility/cuda/bvh.h"
#include "visibility/cuda/cuda_backend.h"
#include "visibility/embree/embree_backend.h"

using namespace skybake;

namespace {

using bench::kind_of;
using bench::seconds_since;

const Mesh& mesh(int kind, std::uint64_t triangles) {
    static std::map<std::pair<int, std::uint64_t>, std::unique_ptr<Mesh>> cache;
    auto& slot = cache[{kind, triangles}];
    if (!slot) {
        ProceduralOptions p;
        p.kind = kind_of(kind);
        p.target_triangles = triangles;
        slot = std::make_unique<Mesh>(generate_mesh(p));
    }
    return *slot;
}

// Args: kind (0 city, 1 torus, 2 terrain), triangles, Lebedev points, method (0 bvh, 1 per-vertex, 2 per-polygon).
void BM_GpuAo(benchmark::State& state) {
    if (cuda_device_count() == 0) {
        state.SkipWithError("no CUDA device");
        return;
    }
    const Mesh& m = mesh(int(state.range(0)), std::uint64_t(state.range(1)));
    const SphereRule rule = parse_rule(fmt::format("lebedev:{}", state.range(2)));
    BakeOptions o;
    o.method = TraceMethod(state.range(3));
    auto gpu = make_visibility_tracer("cuda", o.method);
    visibility::EmbreeBackend embree;
    double t_gpu = 0, t_cpu = 0, build = 0;
    std::uint64_t rays = 0;
    {
        BakeOutputs warm; // first launch: context creation, module load
        bake_shading(m, rule, *gpu, o, warm);
    }
    for (auto _ : state) {
        BakeOutputs g, e;
        bake_shading(m, rule, *gpu, o, g);
        BakeOptions eo = o;
        eo.method = TraceMethod::Bvh;
        bake_shading(m, rule, embree, eo, e);
        if (g.rays != e.rays) {
            state.SkipWithError("the cuda and embree bakes traced different rays");
            return;
        }
        t_gpu += g.trace_seconds;
        t_cpu += e.trace_seconds;
        build += g.build_seconds;
        rays = g.rays;
        state.SetIterationTime(g.trace_seconds);
    }
    const double it = double(state.iterations());
    state.SetLabel(cuda_device_name());
    state.counters["vertices"] = double(m.vertex_count());
    state.counters["triangles"] = double(m.triangle_count());
    state.counters["rays"] = double(rays);
    state.counters["gpu_Mrays"] = double(rays) * it / t_gpu * 1e-6;
    state.counters["embree_Mrays"] = double(rays) * it / t_cpu * 1e-6;
    state.counters["speedup"] = t_cpu / t_gpu;
    state.counters["bvh_build_s"] = build / it;
}

// Args: kind, triangles, spatial splits (0 or 1).
void BM_BvhBuild(benchmark::State& state) {
    const Mesh& m = mesh(int(state.range(0)), std::uint64_t(state.range(1)));
    const bool splits = state.range(2) != 0;
    double ours = 0, theirs = 0;
    std::size_t nodes = 0, refs = 0;
    int depth = 0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const visibility::Bvh bvh = visibility::build_bvh(m, splits);
        const double a = seconds_since(t0);
        visibility::EmbreeBackend e;
        const auto t1 = std::chrono::steady_clock::now();
        e.set_mesh(m, BackFaces::Occlude);
        theirs += seconds_since(t1);
        ours += a;
        nodes = bvh.nodes.size();
        refs = bvh.triangles.size();
        depth = bvh.depth;
        state.SetIterationTime(a);
    }
    const double it = double(state.iterations());
    state.counters["triangles"] = double(m.triangle_count());
    state.counters["nodes"] = double(nodes);
    state.counters["refs_per_triangle"] = double(refs) / double(m.triangle_count());
    state.counters["depth"] = double(depth);
    state.counters["build_s"] = ours / it;
    state.counters["embree_scene_s"] = theirs / it;
    state.counters["ratio"] = theirs / ours; // > 1: ours is faster
}

// Args: kind, triangles, Lebedev points, spatial splits. Rays of the bake's first 2000 vertices.
void BM_HostTraversal(benchmark::State& state) {
    const Mesh& m = mesh(int(state.range(0)), std::uint64_t(state.range(1)));
    const SphereRule rule = parse_rule(fmt::format("lebedev:{}", state.range(2)));
    const visibility::Bvh bvh = visibility::build_bvh(m, state.range(3) != 0);
    visibility::EmbreeBackend embree;
    embree.set_mesh(m, BackFaces::Occlude);
    const bake::VisitingRule visit = bake::visiting_rule(rule);
    const bake::VertexRays frames = bake::vertex_rays(m, BakeOptions{});
    std::vector<Ray> rays;
    for (std::uint32_t v = 0; v < std::min<std::uint32_t>(2000, std::uint32_t(m.vertex_count())); ++v) {
        for (const glm::vec3& point : visit.points) {
            glm::vec3 x;
            float c;
            visibility::vertex_direction(point, glm::mat3(1.0f), false, frames.normals[v], x, c);
            if (visibility::needs_ray(c))
                rays.push_back({frames.origin(m, v), 0.0f, x, std::numeric_limits<float>::infinity()});
        }
    }
    double ours = 0, theirs = 0;
    std::uint64_t occ_ours = 0, occ_theirs = 0;
    for (auto _ : state) {
        occ_ours = occ_theirs = 0;
        const auto t0 = std::chrono::steady_clock::now();
        for (const Ray& r : rays)
            occ_ours += visibility::bvh_occluded(bvh.view(), r.origin, r.direction, r.t_min, r.t_max, false);
        const double a = seconds_since(t0);
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        const auto t1 = std::chrono::steady_clock::now();
        for (const Ray& r : rays) {
            RTCRay q{};
            q.org_x = r.origin.x, q.org_y = r.origin.y, q.org_z = r.origin.z, q.tnear = r.t_min;
            q.dir_x = r.direction.x, q.dir_y = r.direction.y, q.dir_z = r.direction.z;
            q.tfar = r.t_max, q.mask = 0xffffffffu;
            rtcOccluded1(embree.scene(), &ctx, &q);
            occ_theirs += q.tfar < 0.0f;
        }
        theirs += seconds_since(t1);
        ours += a;
        state.SetIterationTime(a);
    }
    if (double(occ_ours > occ_theirs ? occ_ours - occ_theirs : occ_theirs - occ_ours) > 1e-3 * double(rays.size()))
        state.SkipWithError("the traversals disagree");
    const double it = double(state.iterations());
    state.counters["rays"] = double(rays.size());
    state.counters["ours_Mrays"] = double(rays.size()) * it / ours * 1e-6;
    state.counters["embree1_Mrays"] = double(rays.size()) * it / theirs * 1e-6;
    state.counters["ratio"] = theirs / ours; // > 1: ours is faster
}

// Args: kind, triangles, Lebedev points. The first 1000 vertices.
void BM_WarpModel(benchmark::State& state) {
    const Mesh& m = mesh(int(state.range(0)), std::uint64_t(state.range(1)));
    const SphereRule rule = parse_rule(fmt::format("lebedev:{}", state.range(2)));
    const visibility::Bvh bvh = visibility::build_bvh(m);
    const bake::VisitingRule visit = bake::visiting_rule(rule);
    const bake::VertexRays frames = bake::vertex_rays(m, BakeOptions{});
    const auto directions = std::uint32_t(visit.points.size());
    const std::uint32_t vertices = std::min<std::uint32_t>(1000, std::uint32_t(m.vertex_count()));
    struct Model {
        double useful = 0, cost = 0, nodes = 0, triangles = 0, rays = 0;
    };
    // Warp cost over all (vertex, word) warps with directions taken from `points`.
    auto model = [&](const std::vector<glm::vec3>& points) {
        Model r;
        for (std::uint32_t v = 0; v < vertices; ++v) {
            const glm::vec3 origin = frames.origin(m, v);
            for (std::uint32_t w = 0; w < visit.words_per_vertex; ++w) {
                std::uint32_t longest = 0, sum = 0;
                for (std::uint32_t lane = 0; lane < 32 && 32 * w + lane < directions; ++lane) {
                    glm::vec3 x;
                    float c;
                    visibility::vertex_direction(points[32 * w + lane], glm::mat3(1.0f), false, frames.normals[v], x,
                                                 c);
                    if (!visibility::needs_ray(c))
                        continue;
                    visibility::TraversalCounts n;
                    float t = std::numeric_limits<float>::infinity(), u, vv;
                    std::uint32_t id = kNoHit;
                    visibility::bvh_trace<true>(bvh.view(), origin, x, 0.0f, t, false, id, u, vv, &n);
                    const std::uint32_t steps = n.nodes + n.triangles;
                    longest = std::max(longest, steps);
                    sum += steps;
                    r.nodes += n.nodes;
                    r.triangles += n.triangles;
                    r.rays += 1;
                }
                r.useful += sum;
                r.cost += 32.0 * longest;
            }
        }
        return r;
    };
    Model coherent, plain;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        coherent = model(visit.points);
        plain = model(rule.points_f32());
        state.SetIterationTime(seconds_since(t0));
    }
    state.counters["rays"] = coherent.rays;
    state.counters["nodes_per_ray"] = coherent.nodes / coherent.rays;
    state.counters["tris_per_ray"] = coherent.triangles / coherent.rays;
    state.counters["simt_coherent"] = coherent.useful / coherent.cost;
    state.counters["simt_rule_order"] = plain.useful / plain.cost;
    state.counters["speedup"] = plain.cost / coherent.cost;
}

} // namespace

BENCHMARK(BM_GpuAo)
    ->ArgNames({"kind", "tris", "rule", "method"})
    ->Args({0, 3000, 5810, 0})    // the seed's table case: city, ~5k vertices, bvh
    ->Args({0, 3000, 5810, 1})    // ... per-vertex
    ->Args({0, 3000, 5810, 2})    // ... per-polygon
    ->Args({1, 10000, 5810, 0})   // torus, ~5k vertices
    ->Args({0, 1000000, 5810, 0}) // city, 1M triangles
    ->Args({2, 1000000, 5810, 0}) // terrain, 1M triangles
    ->Args({0, 1000000, 26, 0})   // city, 1M triangles, small rule: every method
    ->Args({0, 1000000, 26, 1})
    ->Args({0, 1000000, 26, 2})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(BM_BvhBuild)
    ->ArgNames({"kind", "tris", "splits"})
    ->Args({0, 3000, 0})
    ->Args({0, 3000, 1})
    ->Args({0, 1000000, 0})
    ->Args({0, 1000000, 1})
    ->Args({2, 1000000, 0})
    ->Args({2, 1000000, 1})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(BM_HostTraversal)
    ->ArgNames({"kind", "tris", "rule", "splits"})
    ->Args({0, 3000, 1202, 0})
    ->Args({0, 3000, 1202, 1})
    ->Args({1, 10000, 1202, 0})
    ->Args({1, 10000, 1202, 1})
    ->Args({0, 1000000, 302, 0})
    ->Args({0, 1000000, 302, 1})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

BENCHMARK(BM_WarpModel)
    ->ArgNames({"kind", "tris", "rule"})
    ->Args({0, 3000, 5810})    // the seed's table case
    ->Args({1, 10000, 5810})   // torus
    ->Args({0, 1000000, 5810}) // city, 1M triangles
    ->Args({0, 3000, 590})
    ->Args({0, 1000000, 110})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_MAIN();
