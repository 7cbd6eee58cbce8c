// PRT benchmarks (skybake/prt.h), each against a baseline measured in the
// same run:
//   BM_ShadowedTransferVsAo  the shadowed transfer bake at order 4 against the
//                            AO bake on the same rays (same tracer, rule and
//                            mesh); counter ratio = transfer / AO (target ≤ 1.3)
//   BM_Bounces               interreflection: seconds per bounce (the gather)
//                            and the one-off closest-hit rays, against the
//                            shadowed bake
//   BM_SkySh                 the sky → SH projection per frame at order 4
//                            (arg 0: the reference model, 1: the paper's network
//                            topology with random weights); arg 1: lebedev:590
//                            or lebedev:2030 (target ≤ 1 ms with the network)
//   BM_Relight               relighting throughput, vertices/s
#include <chrono>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "ao_scenes.h"
#include "skybake/bake.h"
#include "skybake/prt.h"

using namespace skybake;
using bench::seconds_since;

namespace {

Mesh& city() {
    static Mesh m = [] {
        ProceduralOptions p;
        p.kind = ProceduralKind::City;
        p.target_triangles = 20000;
        Mesh mesh = generate_mesh(p);
        compute_normals(mesh);
        return mesh;
    }();
    return m;
}

void BM_ShadowedTransferVsAo(benchmark::State& state) {
    const SphereRule rule = parse_rule("lebedev:590");
    const auto tracer = make_visibility_tracer("embree");
    TransferOptions o;
    o.order = int(state.range(0));
    double ao_s = 0.0, prt_s = 0.0;
    for (auto _ : state) {
        BakeOutputs out;
        auto t0 = std::chrono::steady_clock::now();
        bake_shading(city(), rule, *tracer, BakeOptions{}, out);
        ao_s += seconds_since(t0);
        Transfer t;
        t0 = std::chrono::steady_clock::now();
        bake_transfer(city(), rule, *tracer, BakeOptions{}, o, {}, nullptr, t);
        prt_s += seconds_since(t0);
        benchmark::DoNotOptimize(t.coeffs.data());
    }
    state.counters["vertices"] = double(city().vertex_count());
    state.counters["ao_s"] = ao_s / double(state.iterations());
    state.counters["transfer_s"] = prt_s / double(state.iterations());
    state.counters["ratio"] = prt_s / ao_s;
}

void BM_Bounces(benchmark::State& state) {
    const SphereRule rule = parse_rule("lebedev:302");
    const auto tracer = make_visibility_tracer("embree");
    const auto queries = make_ray_queries("embree");
    const std::vector<glm::vec3> albedo(city().vertex_count(), glm::vec3(0.6f));
    TransferOptions o;
    o.order = 3;
    double shadowed = 0.0, one = 0.0, three = 0.0;
    std::uint64_t rays = 0;
    for (auto _ : state) {
        Transfer t;
        auto t0 = std::chrono::steady_clock::now();
        o.kind = TransferKind::Shadowed;
        o.bounces = 0;
        bake_transfer(city(), rule, *tracer, BakeOptions{}, o, albedo, nullptr, t);
        shadowed += seconds_since(t0);
        o.kind = TransferKind::Interreflected;
        o.bounces = 1;
        t0 = std::chrono::steady_clock::now();
        const TransferReport r = bake_transfer(city(), rule, *tracer, BakeOptions{}, o, albedo, queries.get(), t);
        one += seconds_since(t0);
        rays = r.bounce_rays;
        o.bounces = 3;
        t0 = std::chrono::steady_clock::now();
        bake_transfer(city(), rule, *tracer, BakeOptions{}, o, albedo, queries.get(), t);
        three += seconds_since(t0);
    }
    const double n = double(state.iterations());
    state.counters["shadowed_s"] = shadowed / n;
    state.counters["first_bounce_s"] = (one - shadowed) / n; // closest hits + one gather
    state.counters["per_bounce_s"] = (three - one) / (2.0 * n);
    state.counters["hit_rays"] = double(rays);
}

NeuralSky random_net() {
    NeuralSky net;
    net.topology = parse_topology("paper");
    net.encoding.max_n = 0.15;
    net.atmosphere = atmosphere_preset("earth");
    net.weights.resize(std::size_t(net.topology.weight_count()));
    std::uint64_t state = 99;
    for (float& w : net.weights) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        w = float(double(state >> 11) * 0x1.0p-53 * 2.0 - 1.0);
    }
    return net;
}

void BM_SkySh(benchmark::State& state) {
    static const SkySource reference = SkySource::reference(SkyModel(atmosphere_preset("earth")));
    static const SkySource network = SkySource::network(random_net());
    const SkySource& sky = state.range(0) == 0 ? reference : network;
    // 0: lebedev:590, 1: lebedev:2030 (the former default), 2: the default (kSkyLightRule, split at the horizon).
    const char* const rules[] = {"lebedev:590", "lebedev:2030", kSkyLightRule};
    const char* const spec = rules[state.range(1)];
    const SkyProjector projector(4, parse_rule(spec));
    SkyLightSettings s;
    double angle = 0.0;
    for (auto _ : state) {
        s.sun_elevation_deg = 30.0 * std::sin(angle += 0.01); // a moving sun
        const ShLight l = projector.project(sky, s);
        benchmark::DoNotOptimize(l.coeffs.data());
    }
    state.SetLabel(fmt::format("{} {}", sky.method_name(), spec));
}

void BM_Relight(benchmark::State& state) {
    static Transfer t = [] {
        Transfer x;
        TransferOptions o;
        o.order = 3;
        const auto tracer = make_visibility_tracer("embree");
        bake_transfer(city(), parse_rule("lebedev:194"), *tracer, BakeOptions{}, o, {}, nullptr, x);
        return x;
    }();
    const std::vector<glm::vec3> albedo(city().vertex_count(), glm::vec3(0.6f));
    const ShLight light = constant_light(glm::vec3(1.0f), 3);
    for (auto _ : state) {
        const std::vector<glm::vec3> b = relight(t, light, albedo);
        benchmark::DoNotOptimize(b.data());
    }
    state.counters["vertices_per_s"] =
        benchmark::Counter(double(city().vertex_count()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

} // namespace

BENCHMARK(BM_ShadowedTransferVsAo)->Arg(4)->Arg(3)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Bounces)->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SkySh)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Relight)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
