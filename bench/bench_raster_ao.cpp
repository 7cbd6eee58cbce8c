// The raster visibility backend (depth cube maps, directional depth maps)
// against the Embree backend, in the same run and on the same rays.
//
// BM_RasterTableCase/M: seed 002's table case, the 5,124-vertex city with
//   lebedev:5810 (the seed: 11 s with its depth-buffer method), whole bakes.
//   M = 0: cube at 256, M = 1: directional at 2048. Every iteration bakes with
//   Embree too; counters: seconds of each, the raster's rays per second
//   equivalent (rays: the (vertex, direction) pairs on or above the horizon,
//   the same for both), and the ratio raster / Embree of the times.
// BM_RasterLarge/M: a 200k-triangle city with lebedev:590. Directional: whole
//   bakes. Cube: its cost is per vertex (every vertex draws the whole mesh
//   five times), so both backends trace the same 512 vertices, evenly spread,
//   through the tracer interface.
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <vector>

#include "ao_scenes.h"
#include "bake/internal.h"
#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"
#include "visibility/trace_hd.h"

using namespace skybake;
using bench::seconds_since;

namespace {

const Mesh& city(std::uint64_t triangles) {
    static std::map<std::uint64_t, Mesh> cache;
    auto it = cache.find(triangles);
    if (it == cache.end()) {
        ProceduralOptions p;
        p.kind = ProceduralKind::City;
        p.target_triangles = triangles;
        it = cache.emplace(triangles, generate_mesh(p)).first;
    }
    return it->second;
}

struct Timed {
    double seconds = 0.0;
    std::uint64_t rays = 0;
};

Timed whole_bake(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer) {
    Mesh m = mesh;
    BakeOptions o;
    o.method = tracer.method();
    const auto t0 = std::chrono::steady_clock::now();
    const AoBakeReport r = bake_ambient_occlusion(m, rule, tracer, o);
    return {seconds_since(t0), r.rays};
}

// The tracer alone on `count` vertices spread over the mesh, with the
// driver's origins, normals and direction order.
Timed subset_trace(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, std::uint32_t count) {
    const bake::VisitingRule visit = bake::visiting_rule(rule);
    const bake::VertexRays frames = bake::vertex_rays(mesh, BakeOptions{});
    std::vector<glm::vec3> origins, normals;
    Timed t;
    const auto n = std::uint32_t(mesh.vertex_count());
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t v = std::uint32_t(std::uint64_t(i) * n / count);
        origins.push_back(frames.origin(mesh, v));
        normals.push_back(frames.normals[v]);
        for (const glm::vec3& x : visit.points)
            t.rays += visibility::needs_ray(glm::dot(normals.back(), x));
    }
    std::vector<std::uint32_t> words(std::size_t(count) * visit.words_per_vertex);
    TraceRule tr;
    tr.points = visit.points;
    tr.order = visit.order;
    tr.words_per_vertex = visit.words_per_vertex;
    tracer.set_mesh(mesh);
    tracer.set_rule(tr);
    // (The directional method is timed by whole bakes: its cost is per chunk.)
    TraceChunk c;
    c.first = 0;
    c.count = count;
    c.origins = origins;
    c.normals = normals;
    c.words = words;
    const auto t0 = std::chrono::steady_clock::now();
    tracer.trace(c);
    t.seconds = seconds_since(t0);
    benchmark::DoNotOptimize(words.data());
    return t;
}

void report(benchmark::State& state, const Timed& raster, const Timed& embree) {
    state.counters["raster_s"] = raster.seconds;
    state.counters["embree_s"] = embree.seconds;
    state.counters["raster_Mrays_per_s"] = double(raster.rays) * 1e-6 / raster.seconds;
    state.counters["embree_Mrays_per_s"] = double(embree.rays) * 1e-6 / embree.seconds;
    state.counters["raster_over_embree"] = raster.seconds / embree.seconds;
}

void BM_RasterTableCase(benchmark::State& state) {
    const TraceMethod method = state.range(0) == 0 ? TraceMethod::Cube : TraceMethod::Directional;
    const Mesh& mesh = city(3000);
    const SphereRule rule = parse_rule("lebedev:5810");
    auto raster = make_visibility_tracer("raster", method);
    auto embree = make_visibility_tracer("embree");
    state.SetLabel(raster->device_name());
    for (auto _ : state) {
        const Timed e = whole_bake(mesh, rule, *embree);
        const Timed r = whole_bake(mesh, rule, *raster);
        report(state, r, e);
    }
}
BENCHMARK(BM_RasterTableCase)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_RasterLarge(benchmark::State& state) {
    const TraceMethod method = state.range(0) == 0 ? TraceMethod::Cube : TraceMethod::Directional;
    const Mesh& mesh = city(200000);
    const SphereRule rule = parse_rule("lebedev:590");
    auto raster = make_visibility_tracer("raster", method);
    auto embree = make_visibility_tracer("embree");
    state.SetLabel(raster->device_name());
    for (auto _ : state) {
        if (method == TraceMethod::Cube)
            report(state, subset_trace(mesh, rule, *raster, 512), subset_trace(mesh, rule, *embree, 512));
        else
            report(state, whole_bake(mesh, rule, *raster), whole_bake(mesh, rule, *embree));
    }
}
BENCHMARK(BM_RasterLarge)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

} // namespace
BENCHMARK_MAIN();
