// GPU sky throughput: the neural network kernel, the reference model's table
// path, training-data generation and a 4K render, each beside its CPU
// counterpart measured in the same run. Every GPU benchmark reports
// "no CUDA device" and is skipped on machines without one.
#include <map>
#include <random>

#include <benchmark/benchmark.h>

#include "neural/neural_cuda.h"
#include "skybake/core.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

using namespace skybake;

namespace {

bool have_gpu(benchmark::State& state) {
    if (cuda_device_count() > 0)
        return true;
    state.SkipWithError("no CUDA device");
    return false;
}

// Throughput does not depend on the weights' values.
const NeuralSky& network(const char* topology) {
    static std::map<std::string, NeuralSky> nets;
    auto it = nets.find(topology);
    if (it == nets.end()) {
        NeuralSky net;
        net.topology = parse_topology(topology);
        net.atmosphere = atmosphere_preset("earth");
        net.encoding.max_n = 0.05;
        std::mt19937 rng(1);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        net.weights.resize(std::size_t(net.topology.weight_count()));
        for (float& w : net.weights)
            w = u(rng);
        it = nets.emplace(topology, std::move(net)).first;
    }
    return it->second;
}

const SkyModel& earth() {
    static const SkyModel model(atmosphere_preset("earth"));
    return model;
}

const std::vector<SkySample>& samples(std::size_t n) {
    static std::map<std::size_t, std::vector<SkySample>> cache;
    auto it = cache.find(n);
    if (it == cache.end())
        it = cache.emplace(n, draw_sky_samples(n, 3)).first;
    return it->second;
}

// Network kernel, inputs generated on the device: the compute ceiling.
void BM_NetworkKernel(benchmark::State& state, const char* topology, bool generic) {
    if (!have_gpu(state))
        return;
    const std::uint64_t n = std::uint64_t(1) << 30;
    neural::GpuThroughput t;
    for (auto _ : state) {
        t = neural::measure_neural_sky_cuda(network(topology), n, generic);
        state.SetIterationTime(t.seconds);
    }
    state.counters["samples/s"] = t.samples_per_second;
}

// Network with transfers (batch API), against the CPU batch inference.
void BM_NetworkBatch(benchmark::State& state, Device device) {
    if (device == Device::Cuda && !have_gpu(state))
        return;
    const auto& s = samples(device == Device::Cuda ? 8'000'000 : 1'000'000);
    std::vector<glm::vec3> out(s.size());
    for (auto _ : state) {
        if (device == Device::Cuda)
            evaluate_neural_sky_cuda(network("paper"), s, out);
        else
            evaluate_neural_sky(network("paper"), s, out);
    }
    state.counters["samples/s"] = benchmark::Counter(double(s.size()), benchmark::Counter::kIsIterationInvariantRate);
}

// Reference model (tables, 16 steps): training data of 8,000,000 samples on the GPU.
void BM_Reference(benchmark::State& state, Device device) {
    if (device == Device::Cuda && !have_gpu(state))
        return;
    const auto& s = samples(device == Device::Cuda ? 8'000'000 : 400'000);
    std::vector<glm::vec3> out(s.size());
    for (auto _ : state) {
        if (device == Device::Cuda)
            evaluate_sky_cuda(earth(), s, out);
        else
            evaluate_sky(earth(), s, out, SkyMethod::Tables);
    }
    state.counters["samples/s"] = benchmark::Counter(double(s.size()), benchmark::Counter::kIsIterationInvariantRate);
}

// A 3840x2160 panorama.
void BM_Render4K(benchmark::State& state, Device device, bool neural) {
    if (device == Device::Cuda && !have_gpu(state))
        return;
    SkyRenderSettings s;
    s.view = SkyView::Panorama;
    s.width = device == Device::Cuda ? 3840 : 960;
    s.height = device == Device::Cuda ? 2160 : 540;
    s.sun_elevation_deg = 20.0;
    for (auto _ : state) {
        Image img = neural ? (device == Device::Cuda ? render_neural_sky_cuda(network("paper"), earth(), s)
                                                     : render_neural_sky(network("paper"), earth(), s))
                           : (device == Device::Cuda ? render_sky_cuda(earth(), s) : render_sky(earth(), s));
        benchmark::DoNotOptimize(img.rgb.data());
    }
    state.counters["pixels/s"] =
        benchmark::Counter(double(s.width) * double(s.height), benchmark::Counter::kIsIterationInvariantRate);
}

} // namespace

BENCHMARK_CAPTURE(BM_NetworkKernel, paper_unrolled, "paper", false)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_NetworkKernel, paper_generic, "paper", true)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_NetworkKernel, shared64x64, "shared:64x64", true)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_NetworkBatch, cpu, Device::Cpu)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_NetworkBatch, cuda, Device::Cuda)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, cpu, Device::Cpu)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Reference, cuda, Device::Cuda)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render4K, reference_cpu_quarter, Device::Cpu, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render4K, reference_cuda, Device::Cuda, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render4K, neural_cuda, Device::Cuda, true)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
