// Mesh I/O throughput on a generated 1M-triangle terrain.
//
// Baseline in the same run: writing and reading the same vertex and index
// bytes with plain stdio (the floor any format pays). The reported ratio
// format/baseline is what to compare across machines.
#include <cstdio>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "skybake/files.h"
#include "skybake/mesh.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {

const Mesh& big_mesh() {
    static const Mesh m = [] {
        Mesh g = generate_mesh({ProceduralKind::Terrain, 1'000'000, 1});
        g.set_attribute("ao", 1, std::vector<float>(g.vertex_count(), 0.5f));
        return g;
    }();
    return m;
}

fs::path bench_path(const char* name) {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / "skybake-bench";
        fs::create_directories(d);
        return d;
    }();
    return dir / name;
}

std::size_t raw_bytes(const Mesh& m) {
    return m.positions.size() * sizeof(glm::vec3) * 2 + m.indices.size() * 4 + m.vertex_count() * 4;
}

void BM_RawWrite(benchmark::State& state) {
    const Mesh& m = big_mesh();
    for (auto _ : state)
        write_stream_atomic(bench_path("raw.bin"), [&](std::ostream& out) {
            out.write(reinterpret_cast<const char*>(m.positions.data()), std::streamsize(m.positions.size() * 12));
            out.write(reinterpret_cast<const char*>(m.normals.data()), std::streamsize(m.normals.size() * 12));
            out.write(reinterpret_cast<const char*>(m.attributes[0].values.data()),
                      std::streamsize(m.vertex_count() * 4));
            out.write(reinterpret_cast<const char*>(m.indices.data()), std::streamsize(m.indices.size() * 4));
        });
    state.SetBytesProcessed(std::int64_t(state.iterations() * raw_bytes(m)));
}

void BM_RawRead(benchmark::State& state) {
    for (auto _ : state) {
        std::string data = read_file(bench_path("raw.bin"));
        benchmark::DoNotOptimize(data.data());
    }
    state.SetBytesProcessed(std::int64_t(state.iterations() * raw_bytes(big_mesh())));
}

void BM_Save(benchmark::State& state, const char* name, PlyEncoding enc) {
    const Mesh& m = big_mesh();
    for (auto _ : state)
        save_mesh(bench_path(name), m, {enc});
    state.SetBytesProcessed(std::int64_t(state.iterations() * raw_bytes(m)));
    state.counters["triangles/s"] = benchmark::Counter(double(m.triangle_count()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Load(benchmark::State& state, const char* name) {
    for (auto _ : state) {
        Mesh m = load_mesh(bench_path(name));
        benchmark::DoNotOptimize(m.positions.data());
    }
    state.SetBytesProcessed(std::int64_t(state.iterations() * raw_bytes(big_mesh())));
    state.counters["triangles/s"] =
        benchmark::Counter(double(big_mesh().triangle_count()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Generate(benchmark::State& state, ProceduralKind kind) {
    for (auto _ : state) {
        Mesh m = generate_mesh({kind, 1'000'000, 1});
        benchmark::DoNotOptimize(m.positions.data());
    }
    state.counters["triangles/s"] = benchmark::Counter(1e6, benchmark::Counter::kIsIterationInvariantRate);
}

// The cost of parsing Assimp formats in a child process, on a small file where
// it shows most: the same OBJ read in-process (baseline) and isolated.
void BM_LoadAssimp(benchmark::State& state, bool isolate) {
    ImportLimits limits;
    limits.isolate_parsers = isolate;
    for (auto _ : state) {
        Mesh m = load_mesh("/usr/share/assimp/models/OBJ/spider.obj", nullptr, limits);
        benchmark::DoNotOptimize(m.positions.data());
    }
}

} // namespace

BENCHMARK_CAPTURE(BM_LoadAssimp, in_process, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_LoadAssimp, isolated, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawWrite)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK(BM_RawRead)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Save, glb, "t.glb", PlyEncoding::Binary)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Save, ply_binary, "t.ply", PlyEncoding::Binary)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Save, ply_ascii, "ta.ply", PlyEncoding::Ascii)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Load, glb, "t.glb")->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Load, ply_binary, "t.ply")->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Load, ply_ascii, "ta.ply")->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Generate, sphere, ProceduralKind::Sphere)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK_CAPTURE(BM_Generate, city, ProceduralKind::City)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();

BENCHMARK_MAIN();
