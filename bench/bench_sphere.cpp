// Sphere toolkit benchmarks: SH evaluation, rotation, projection, rule construction.
// Baselines measured in the same run: the SH recurrence with its factors computed
// on the fly (what a GPU kernel without the table does), and a full rebuild of the
// rotation matrices per apply.
#include <benchmark/benchmark.h>

#include <vector>

#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/sh_eval.h"

using namespace skybake;

namespace {

const std::vector<glm::dvec3>& dirs() {
    static const std::vector<glm::dvec3> d = marsaglia_rule(4096, 1).points;
    return d;
}

void BM_ShEvalTable(benchmark::State& state) {
    const int lmax = int(state.range(0));
    std::vector<double> y(std::size_t(sh_count(lmax)));
    std::size_t i = 0;
    for (auto _ : state) {
        sh_eval(lmax, dirs()[i++ & 4095], y.data());
        benchmark::DoNotOptimize(y.data());
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_ShEvalOnTheFly(benchmark::State& state) { // baseline
    const int lmax = int(state.range(0));
    std::vector<double> y(std::size_t(sh_count(lmax)));
    std::size_t i = 0;
    for (auto _ : state) {
        const glm::dvec3& d = dirs()[i++ & 4095];
        sphere::sh_eval_hd<double>(lmax, d.x, d.y, d.z, y.data());
        benchmark::DoNotOptimize(y.data());
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_ShEvalFloat(benchmark::State& state) {
    const int lmax = int(state.range(0));
    std::vector<float> y(std::size_t(sh_count(lmax)));
    const double* table = sphere::sh_recurrence_table();
    std::size_t i = 0;
    for (auto _ : state) {
        const glm::dvec3& d = dirs()[i++ & 4095];
        sphere::sh_eval_hd<float>(lmax, float(d.x), float(d.y), float(d.z), y.data(), table);
        benchmark::DoNotOptimize(y.data());
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_ShRotateApply(benchmark::State& state) {
    const int lmax = int(state.range(0));
    const ShRotation rot(lmax, vertex_rotation(1, 2));
    std::vector<double> in(std::size_t(sh_count(lmax)), 0.5), out(in.size());
    for (auto _ : state) {
        rot.apply(in.data(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
}

void BM_ShRotateBuildAndApply(benchmark::State& state) { // baseline: rebuild per use
    const int lmax = int(state.range(0));
    std::vector<double> in(std::size_t(sh_count(lmax)), 0.5);
    std::uint32_t v = 0;
    for (auto _ : state) {
        std::vector<double> out = sh_rotate(in, lmax, vertex_rotation(v++, 2));
        benchmark::DoNotOptimize(out.data());
    }
}

void BM_ShProjectLebedev5810(benchmark::State& state) {
    const int lmax = int(state.range(0));
    const SphereRule rule = lebedev_rule_by_points(5810);
    for (auto _ : state) {
        std::vector<double> c = sh_project([](const glm::dvec3& d) { return d.z > 0 ? d.z : 0.0; }, lmax, rule);
        benchmark::DoNotOptimize(c.data());
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(rule.size()));
}

void BM_LebedevBuild5810(benchmark::State& state) {
    for (auto _ : state) {
        SphereRule r = lebedev_rule_by_points(5810);
        benchmark::DoNotOptimize(r.points.data());
    }
}

void BM_DesignCompute(benchmark::State& state) {
    const int t = int(state.range(0));
    for (auto _ : state) {
        SphereRule r = compute_design(t);
        benchmark::DoNotOptimize(r.points.data());
    }
}

void BM_PhongRule(benchmark::State& state) {
    for (auto _ : state) {
        SphereRule r = phong_rule(32.0, int(state.range(0)));
        benchmark::DoNotOptimize(r.points.data());
    }
}

} // namespace

BENCHMARK(BM_ShEvalTable)->Arg(3)->Arg(10)->Arg(30);
BENCHMARK(BM_ShEvalOnTheFly)->Arg(3)->Arg(10)->Arg(30);
BENCHMARK(BM_ShEvalFloat)->Arg(3)->Arg(10)->Arg(30);
BENCHMARK(BM_ShRotateApply)->Arg(10);
BENCHMARK(BM_ShRotateBuildAndApply)->Arg(10);
BENCHMARK(BM_ShProjectLebedev5810)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LebedevBuild5810)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DesignCompute)->Arg(10)->Arg(21)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PhongRule)->Arg(16)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
