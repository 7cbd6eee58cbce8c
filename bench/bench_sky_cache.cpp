// The on-disk cache of the multiple-scattering tables (Earth, default
// resolution, both methods): the first SkyModel of an atmosphere computes its
// tables and writes the file, the second reads it back. The baseline is the
// computation without the cache, in the same run: BM_SkyCacheSecondRun
// reports first_run_s (measured in its own setup) and speedup, the first run
// over the second. BM_SkyCacheSingle is a single-scattering model (the
// optical-length tables only), the floor of any construction.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "skybake/sky.h"

using namespace skybake;
namespace fs = std::filesystem;

namespace {

Atmosphere earth_multiple(MultipleScatteringMethod method) {
    Atmosphere a = atmosphere_preset("earth");
    a.scattering = Scattering::Multiple;
    a.multiple_method = method;
    return a;
}

// A private, empty cache folder for one case (the user's cache is never touched).
fs::path fresh_cache(const char* name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-bench-cache-" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    ::setenv("SKYBAKE_CACHE_DIR", dir.string().c_str(), 1);
    return dir;
}

double construct_seconds(const Atmosphere& atmosphere) {
    const auto t0 = std::chrono::steady_clock::now();
    const SkyModel model(atmosphere);
    benchmark::DoNotOptimize(&model);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// No cache: the tables computed every time.
void BM_SkyCacheOff(benchmark::State& state) {
    const auto method = MultipleScatteringMethod(state.range(0));
    state.SetLabel(multiple_scattering_method_name(method));
    ::setenv("SKYBAKE_CACHE_DIR", "off", 1);
    for (auto _ : state)
        construct_seconds(earth_multiple(method));
}

// An empty cache: compute, then write the file.
void BM_SkyCacheFirstRun(benchmark::State& state) {
    const auto method = MultipleScatteringMethod(state.range(0));
    state.SetLabel(multiple_scattering_method_name(method));
    for (auto _ : state) {
        state.PauseTiming();
        const fs::path dir = fresh_cache("first");
        state.ResumeTiming();
        const SkyModel model(earth_multiple(method));
        benchmark::DoNotOptimize(&model);
        if (model.multiple_tables_from_cache())
            state.SkipWithError("the first run read a cache");
    }
}

// A filled cache: read, check and use the file.
void BM_SkyCacheSecondRun(benchmark::State& state) {
    const auto method = MultipleScatteringMethod(state.range(0));
    state.SetLabel(multiple_scattering_method_name(method));
    const fs::path dir = fresh_cache("second");
    const double first = construct_seconds(earth_multiple(method));
    std::uintmax_t bytes = 0;
    for (const auto& e : fs::directory_iterator(dir))
        bytes += e.file_size();
    double total = 0.0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const SkyModel model(earth_multiple(method));
        benchmark::DoNotOptimize(&model);
        total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (!model.multiple_tables_from_cache())
            state.SkipWithError("the second run computed its tables");
    }
    state.counters["first_run_s"] = first;
    state.counters["file_bytes"] = double(bytes);
    state.counters["speedup"] = first / (total / double(state.iterations()));
}

void BM_SkyCacheSingle(benchmark::State& state) {
    for (auto _ : state)
        construct_seconds(atmosphere_preset("earth"));
}

} // namespace

BENCHMARK(BM_SkyCacheOff)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_SkyCacheFirstRun)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_SkyCacheSecondRun)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SkyCacheSingle)->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    std::error_code ec;
    fs::remove_all(fs::temp_directory_path() / ("skybake-bench-cache-" + std::to_string(::getpid())), ec);
    return 0;
}
