// The raster visibility backend (depth cube maps, directional depth maps)
// against the Embree backend, in the same run and on the same rays.
//
// BM_RasterTableCase/M: seed 002's table case, the 5,124-vertex city with
//   lebedev:5810 (the seed: 11 s with its depth-buffer method), whole bakes.
//   M = 0: cube (its default for the rule, 128), M = 1: directional at 2048. Every iteration bakes with
//   Embree too; counters: seconds of each, the raster's rays per second
//   equivalent (rays: the (vertex, direction) pairs on or above the horizon,
//   the same for both), and the ratio raster / Embree of the times.
// BM_RasterCube/T: the cube method's targets, cities of T triangles (seed 3)
//   with lebedev:590, whole bakes at the cube's default resolution (32),
//   Embree in the same iteration; also the mean |ΔAO| between them.
// BM_RasterLarge/M: a 200k-triangle city with lebedev:590. Directional: whole
//   bakes. Cube: its cost is per vertex, so both backends trace the same 512
//   vertices, evenly spread, through the tracer interface.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
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

const Mesh& city(std::uint64_t triangles, std::uint64_t seed = 0) {
    static std::map<std::pair<std::uint64_t, std::uint64_t>, Mesh> cache;
    auto it = cache.find({triangles, seed});
    if (it == cache.end()) {
        ProceduralOptions p;
        p.kind = ProceduralKind::City;
        p.target_triangles = triangles;
        p.seed = seed;
        it = cache.emplace(std::make_pair(triangles, seed), generate_mesh(p)).first;
    }
    return it->second;
}

struct Timed {
    double seconds = 0.0;
    std::uint64_t rays = 0;
};

Timed whole_bake(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, std::vector<float>* ao = nullptr) {
    Mesh m = mesh;
    BakeOptions o;
    o.method = tracer.method();
    const auto t0 = std::chrono::steady_clock::now();
    const AoBakeReport r = bake_ambient_occlusion(m, rule, tracer, o);
    const Timed t{seconds_since(t0), r.rays};
    if (ao)
        if (const VertexAttribute* a = m.find_attribute("ao"))
            *ao = a->values;
    return t;
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

void BM_RasterCube(benchmark::State& state) {
    const Mesh& mesh = city(std::uint64_t(state.range(0)), 3);
    const SphereRule rule = parse_rule("lebedev:590");
    auto raster = make_visibility_tracer("raster", TraceMethod::Cube);
    auto embree = make_visibility_tracer("embree");
    state.SetLabel(raster->device_name());
    for (auto _ : state) {
        std::vector<float> ae, ar;
        const Timed e = whole_bake(mesh, rule, *embree, &ae);
        const Timed r = whole_bake(mesh, rule, *raster, &ar);
        report(state, r, e);
        double sum = 0.0;
        for (std::size_t i = 0; i < ae.size() && i < ar.size(); ++i)
            sum += std::abs(double(ae[i]) - double(ar[i]));
        state.counters["mean_abs_dAO"] = ae.empty() ? -1.0 : sum / double(ae.size());
    }
}
BENCHMARK(BM_RasterCube)->Arg(3000)->Arg(20000)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

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
