// Neural sky: inference samples/s on the CPU (both cores) for several
// topologies, against the sky model's table path measured in the same run
// (counter vs_tables = neural rate / tables rate); the scalar forward pass that
// shaders and CUDA share (one core); training the seed's topology on 800,000
// samples of `earth` (time and held-out error).
//
// SKYBAKE_NEURAL_COMPARE=DIR also reproduces the seed's 800,000 against
// 8,000,000 samples comparison (several minutes): it writes DIR/neural_800k.csv,
// DIR/neural_8m.csv and the chart DIR/neural_samples_800k_vs_8m.png.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "neural/internal.h"
#include "skybake/neural.h"
#include "skybake/image_io.h"

using namespace skybake;

namespace {

const std::vector<SkySample>& samples() {
    static const std::vector<SkySample> s = draw_sky_samples(200000, 1);
    return s;
}

const SkyModel& earth() {
    static const SkyModel m(atmosphere_preset("earth"));
    return m;
}

// Baseline: the sky model's table path, 16 steps, best of 3.
double tables_rate() {
    static const double rate = [] {
        std::vector<glm::vec3> out(samples().size());
        double best = 1e30;
        for (int i = 0; i < 3; ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            evaluate_sky(earth(), samples(), out, SkyMethod::Tables);
            best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        return double(samples().size()) / best;
    }();
    return rate;
}

NeuralSky random_net(const std::string& topology) {
    NeuralSky net;
    net.topology = parse_topology(topology);
    net.encoding.max_n = 0.15;
    net.atmosphere = earth().atmosphere();
    net.weights.resize(std::size_t(net.topology.weight_count()));
    std::uint64_t state = 99;
    for (float& w : net.weights) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        w = float(double(state >> 11) * 0x1.0p-53 * 2.0 - 1.0);
    }
    return net;
}

const char* kTopologies[] = {"paper", "independent:16x16", "independent:32x32", "shared:64x64"};

void BM_SkyTables(benchmark::State& state) {
    std::vector<glm::vec3> out(samples().size());
    for (auto _ : state) {
        evaluate_sky(earth(), samples(), out, SkyMethod::Tables);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["samples_per_s"] =
        benchmark::Counter(double(samples().size()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_NeuralBatch(benchmark::State& state) {
    const double base = tables_rate();
    const NeuralSky net = random_net(kTopologies[state.range(0)]);
    state.SetLabel(fmt::format("{} ({} weights)", net.topology.name(), net.topology.weight_count()));
    std::vector<glm::vec3> out(samples().size());
    const auto t0 = std::chrono::steady_clock::now();
    for (auto _ : state) {
        evaluate_neural_sky(net, samples(), out);
        benchmark::DoNotOptimize(out.data());
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = double(samples().size()) * double(state.iterations()) / s;
    state.counters["samples_per_s"] = rate;
    state.counters["vs_tables"] = rate / base;
}

// The scalar pass of `hd` over the samples, one core: samples/s and the
// ratio to the tables' rate `base`.
void scalar_pass(benchmark::State& state, const neural::MlpHD& hd, double base) {
    std::vector<glm::vec3> out(samples().size());
    const auto t0 = std::chrono::steady_clock::now();
    for (auto _ : state) {
        for (std::size_t i = 0; i < samples().size(); ++i) {
            const SkySample& x = samples()[i];
            out[i] = neural::neural_sky(hd, x.cos_view_zenith, x.cos_view_sun, x.cos_sun_zenith, x.density);
        }
        benchmark::DoNotOptimize(out.data());
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = double(samples().size()) * double(state.iterations()) / s;
    state.counters["samples_per_s"] = rate;
    state.counters["vs_tables"] = rate / base;
}

void BM_NeuralScalarOneCore(benchmark::State& state) {
    const double base = tables_rate();
    const NeuralSky net = random_net(kTopologies[state.range(0)]);
    state.SetLabel(fmt::format("{} ({} weights)", net.topology.name(), net.topology.weight_count()));
    const neural::MlpHD hd = neural::make_mlp_hd(net); // what a CUDA kernel or a shader evaluates
    scalar_pass(state, hd, base);
}

// The default network's size with phase-factored (0) or residual (1) outputs,
// or residual outputs of an aerosol family (2: a fifth input and the view's
// depth from Chapman integrals), or of the whole sky's light (3: the
// multiple-scattering term log-encoded; 4: marched), horizon inputs: what the analytic march of
// the residual costs per sample in the scalar pass (the exported shaders'
// arithmetic), against the same network without it, measured in the same run.
void BM_NeuralScalarOutputs(benchmark::State& state) {
    const double base = tables_rate();
    NeuralSky net = random_net("shared:16x12");
    net.encoding.inputs = InputEncoding::Horizon;
    net.encoding.outputs = state.range(0) ? OutputEncoding::Residual : OutputEncoding::PhaseFactored;
    for (int k : neural::phase_term_components(net.atmosphere)) {
        const AtmosphereComponent& c = net.atmosphere.components[std::size_t(k)];
        net.encoding.terms.push_back({c.name, c.phase, c.phase_g, glm::dvec3(1.0)});
    }
    if (state.range(0) >= 3) { // the whole sky's light: the term log-encoded (3) or marched (4)
        net.atmosphere.scattering = Scattering::Multiple;
        net.encoding.multiple = true;
        net.encoding.multiple_max = glm::dvec3(0.02, 0.03, 0.04);
        if (state.range(0) == 4)
            for (int c = 0; c < 3; ++c) {
                net.encoding.multiple_psi.resize(std::size_t((c + 1) * neural::kPsiCoefficients), 0.0);
                net.encoding.multiple_psi[std::size_t(c * neural::kPsiCoefficients)] = std::log(0.02);
            }
    }
    net.topology.outputs = net.encoding.output_count();
    if (state.range(0) == 2) {
        net.encoding.family_component = "mie";
        net.encoding.aerosol_max = 8.0;
        net.topology.inputs = net.encoding.input_count();
        net.aerosol = 3.0;
    }
    net.weights.resize(std::size_t(net.topology.weight_count()), 0.01f);
    const char* what[] = {"", "", ", aerosol family", ", multiple scattering log-encoded", ", multiple scattering marched"};
    state.SetLabel(fmt::format("shared:16x12, horizon/{}{} ({} weights)", output_encoding_name(net.encoding.outputs),
                               what[state.range(0)], net.topology.weight_count()));
    const neural::MlpHD hd = neural::make_mlp_hd(net);
    scalar_pass(state, hd, base);
}

void BM_TrainPaper800k(benchmark::State& state) {
    NeuralTrainOptions o;
    o.progress = false;
    NeuralSky net;
    for (auto _ : state)
        net = train_neural_sky(earth(), o);
    state.counters["train_seconds"] = net.training.seconds;
    state.counters["heldout_mean_relative"] = net.training.heldout_mean_relative;
    state.counters["heldout_rms"] = net.training.heldout_rms;
}

void compare_sample_counts(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    std::vector<ChartSeries> series;
    const glm::vec3 colours[2][2] = {{glm::vec3(0.55f, 0.7f, 1.0f), glm::vec3(0.05f, 0.25f, 0.85f)},
                                     {glm::vec3(1.0f, 0.7f, 0.45f), glm::vec3(0.85f, 0.3f, 0.0f)}};
    int k = 0;
    for (std::size_t n : {std::size_t(800000), std::size_t(8000000)}) {
        NeuralTrainOptions o;
        o.samples = n;
        std::vector<LearningCurvePoint> curve;
        const NeuralSky net = train_neural_sky(earth(), o, &curve);
        const std::string tag = n == 800000 ? "800k" : "8m";
        save_learning_curve_csv(dir / fmt::format("neural_{}.csv", tag), curve);
        fmt::print(stderr, "{} samples: {:.1f} s, held-out RMS {:.4g}, mean relative {:.3g}\n", n, net.training.seconds,
                   net.training.heldout_rms, net.training.heldout_mean_relative);
        ChartSeries tr{fmt::format("{}: training", n == 800000 ? "800,000" : "8,000,000"), colours[k][0], {}, {}};
        ChartSeries he{fmt::format("{}: held-out", n == 800000 ? "800,000" : "8,000,000"), colours[k][1], {}, {}};
        for (const LearningCurvePoint& p : curve) {
            tr.x.push_back(p.epoch);
            tr.y.push_back(p.train_rms);
            he.x.push_back(p.epoch);
            he.y.push_back(p.heldout_rms);
        }
        series.push_back(tr);
        series.push_back(he);
        ++k;
    }
    ToneMap tm;
    tm.curve = ToneCurve::Clamp;
    save_png(dir / "neural_samples_800k_vs_8m.png",
             draw_line_chart(series, "paper topology on earth: 800,000 against 8,000,000 samples",
                             "epoch (60 Adam, then LM iterations)", "RMS error of the outputs"),
             tm);
}

} // namespace

BENCHMARK(BM_SkyTables)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_NeuralBatch)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_NeuralScalarOneCore)->Arg(0)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_NeuralScalarOutputs)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TrainPaper800k)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    if (const char* dir = std::getenv("SKYBAKE_NEURAL_COMPARE"))
        compare_sample_counts(dir);
    return 0;
}
