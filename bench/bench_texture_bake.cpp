// Texture bake against vertex bake, in one run (Embree backend).
//
// BM_TextureVsVertexBake: a terrain of 50k triangles with a unique planar UV
//   layout is baked per vertex and into a 2048² texture with the same rule
//   and tracer, alternately within each iteration (so a busy machine slows
//   both alike). Counters: vertices/s and texels/s of the trace phase (rays
//   and reduction, not the BVH), the texel sampling time of the UV layout, and
//   the ratio texels/s ÷ vertices/s (both are points of the same driver).
// BM_TexturePreviewBake: what `ao --texture 1024 --preview` computes on the
//   same terrain, the way the command did it before the bake job (one
//   tracer whose structure the texture pass and the vertex pass each built,
//   and the preview's own Embree scene: 3 builds) against run_bake_job()
//   (1 build), alternately within each iteration. Counters: seconds of each.
#include <algorithm>
#include <chrono>

#include <benchmark/benchmark.h>

#include "skybake/bake.h"
#include "skybake/bake_job.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/texture_bake.h"
#include "skybake/visibility.h"

using namespace skybake;

namespace {

Mesh terrain() {
    Mesh m = generate_mesh({ProceduralKind::Terrain, 50'000, 1});
    m.texcoords.assign(1, {});
    for (const auto& p : m.positions)
        m.texcoords[0].emplace_back(std::clamp((p.x + 1.0f) * 0.5f, 0.0f, 1.0f),
                                    std::clamp((p.z + 1.0f) * 0.5f, 0.0f, 1.0f));
    return m;
}

void BM_TextureVsVertexBake(benchmark::State& state) {
    Mesh mesh = terrain();
    const SphereRule rule = parse_rule("lebedev:50");
    const auto tracer = make_visibility_tracer("embree");
    TextureBakeOptions texture;
    texture.texture_size = int(state.range(0));
    double vertex_seconds = 0.0, texel_seconds = 0.0, sample_seconds = 0.0;
    std::size_t texels = 0;
    for (auto _ : state) {
        BakeOutputs out;
        bake_shading(mesh, rule, *tracer, {}, out);
        vertex_seconds += out.trace_seconds;
        const AoTexture t = bake_ao_texture(mesh, rule, *tracer, {}, texture);
        texel_seconds += t.trace_seconds;
        sample_seconds += t.sample_seconds;
        texels = t.covered_texels;
        benchmark::DoNotOptimize(t.ao.data());
    }
    const double it = double(state.iterations());
    const double vps = double(mesh.vertex_count()) * it / vertex_seconds;
    const double tps = double(texels) * it / texel_seconds;
    state.counters["vertices"] = double(mesh.vertex_count());
    state.counters["texels"] = double(texels);
    state.counters["vertices_per_s"] = vps;
    state.counters["texels_per_s"] = tps;
    state.counters["texel_sampling_s"] = sample_seconds / it;
    state.counters["ratio_texels_to_vertices"] = tps / vps;
}
BENCHMARK(BM_TextureVsVertexBake)->Arg(2048)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();

void BM_TexturePreviewBake(benchmark::State& state) {
    const Mesh input = terrain();
    const SphereRule rule = parse_rule("lebedev:50");
    TextureBakeOptions texture;
    texture.texture_size = 1024;
    AoPreviewOptions preview; // 960 x 720, as the command's default
    double before = 0.0, after = 0.0;
    int builds = 0;
    for (auto _ : state) {
        using clock = std::chrono::steady_clock;
        {
            Mesh mesh = input;
            compute_normals(mesh);
            const auto t0 = clock::now();
            const auto tracer = make_visibility_tracer("embree");
            const AoTexture t = bake_ao_texture(mesh, rule, *tracer, {}, texture);
            bake_ambient_occlusion(mesh, rule, *tracer, {});
            const Image img = render_texture_preview(mesh, t, 0, {}, preview);
            before += std::chrono::duration<double>(clock::now() - t0).count();
            benchmark::DoNotOptimize(img.rgb.data());
        }
        {
            Mesh mesh = input;
            compute_normals(mesh);
            const auto t0 = clock::now();
            BakeJob job;
            job.rule = rule;
            job.tracer.device = "cpu";
            job.texture = texture;
            job.preview = preview;
            const BakeJobResult r = run_bake_job(mesh, job);
            after += std::chrono::duration<double>(clock::now() - t0).count();
            builds = r.acceleration_structures;
            benchmark::DoNotOptimize(r.preview.rgb.data());
        }
    }
    const double it = double(state.iterations());
    state.counters["separate_s"] = before / it;
    state.counters["job_s"] = after / it;
    state.counters["job_builds"] = builds;
}
BENCHMARK(BM_TexturePreviewBake)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
