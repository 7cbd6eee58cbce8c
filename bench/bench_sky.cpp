// Sky samples per second: the seed's sum over its tables (at several step
// counts) and the exact quadrature, on random valid samples of the input
// space. The baseline is the tables path at the default 16 steps; counters
// report samples/s and, for the others, the ratio to that baseline.
// Multiple scattering (Earth, 16 steps): the precomputation of each method
// (seconds, table bytes) and its samples/s, beside single scattering's in
// the same run (BM_SkyTablesEarth/16 is its baseline).
#include <cstdlib>

#include <benchmark/benchmark.h>

#include "skybake/sky.h"

using namespace skybake;

namespace {

const std::vector<SkySample>& samples() {
    static const std::vector<SkySample> s = draw_sky_samples(200000, 1);
    return s;
}

// Times evaluate_sky over `s` and reports samples/s.
void time_evaluate(benchmark::State& state, const SkyModel& model, const std::vector<SkySample>& s, SkyMethod method) {
    std::vector<glm::vec3> out(s.size());
    for (auto _ : state) {
        evaluate_sky(model, s, out, method);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["samples_per_s"] =
        benchmark::Counter(double(s.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

void run_tables(benchmark::State& state, const char* preset) {
    SkyModelOptions o;
    o.steps = int(state.range(0));
    const SkyModel model(atmosphere_preset(preset), o);
    time_evaluate(state, model, samples(), SkyMethod::Tables);
}

void BM_SkyTablesPaper(benchmark::State& state) { run_tables(state, "paper"); }
void BM_SkyTablesEarth(benchmark::State& state) { run_tables(state, "earth"); }

void BM_SkyExactPaper(benchmark::State& state) {
    const SkyModel model(atmosphere_preset("paper"));
    const std::vector<SkySample> s(samples().begin(), samples().begin() + 200);
    time_evaluate(state, model, s, SkyMethod::Exact);
}

Atmosphere earth_multiple(MultipleScatteringMethod method) {
    Atmosphere a = atmosphere_preset("earth");
    a.scattering = Scattering::Multiple;
    a.multiple_method = method;
    return a;
}

// The constructor's multiple-scattering tables (orders: 4, the default),
// computed every time (bench_sky_cache times the on-disk cache).
void BM_SkyMultiplePrecompute(benchmark::State& state) {
    ::setenv("SKYBAKE_CACHE_DIR", "off", 1);
    const auto method = MultipleScatteringMethod(state.range(0));
    state.SetLabel(multiple_scattering_method_name(method));
    double seconds = 0.0, bytes = 0.0;
    for (auto _ : state) {
        const SkyModel model(earth_multiple(method));
        seconds = model.multiple_precompute_seconds();
        bytes = double(model.multiple_table_bytes());
    }
    state.counters["table_bytes"] = bytes;
    state.counters["precompute_s"] = seconds;
}

void BM_SkyMultipleTables(benchmark::State& state) {
    const auto method = MultipleScatteringMethod(state.range(0));
    state.SetLabel(multiple_scattering_method_name(method));
    const SkyModel model(earth_multiple(method));
    time_evaluate(state, model, samples(), SkyMethod::Tables);
}

} // namespace

BENCHMARK(BM_SkyTablesPaper)->Arg(8)->Arg(16)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SkyTablesEarth)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SkyExactPaper)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

BENCHMARK(BM_SkyMultiplePrecompute)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_SkyMultipleTables)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
