// The model viewer's renderer (skybake/viewer.h) on the headless context:
// frame time at 1920x1080 of a 100k-triangle model lit by the sky's SH at
// order 4 through per-vertex transfer, with the network per pixel behind it,
// against a flat-shaded pass over the same mesh in the same run (counter
// vs_flat = frame time / flat time); and the cost of moving the sun: the SH
// projection of the sky (lebedev:2030, the network on the CPU) and the sun's
// shadow (the shadow map, or the per-vertex visibility by Embree), counted
// apart from the draw. Also the frame with the DPRT glossy layer (shading
// dprt, its map of the mirror direction rebuilt when the light moves), and
// the reference sky's background map (256 × 256 evaluations of the tables)
// when the sun rises.
//
// The transfer is the analytic unshadowed one of order 4 (25 grey
// coefficients, 7 vertex attributes): the frame costs the same for any
// coefficients, and a shadowed bake of 100k triangles would dominate the run.
// Times are GPU draw time (glFinish), without the readback.
#include <chrono>
#include <cmath>

#include <benchmark/benchmark.h>

#include "skybake/sh.h"
#include "skybake/viewer.h"

using namespace skybake;

namespace {

const SkySource& sky() {
    static const SkySource s =
        SkySource::network(load_neural_sky(std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/planet/sky_paper.json"));
    return s;
}

const ViewerModel& model() {
    static const ViewerModel m = [] {
        ViewerModel v;
        ProceduralOptions p;
        p.kind = ProceduralKind::Terrain;
        p.target_triangles = 100'000;
        v.mesh = generate_mesh(p);
        compute_normals(v.mesh);
        v.albedo.assign(v.mesh.vertex_count(), glm::vec3(0.8f));
        Transfer& t = v.transfer;
        t.order = 4;
        t.coefficients = sh_count(4);
        t.channels = 1;
        t.kind = TransferKind::Unshadowed;
        t.coeffs.resize(v.mesh.vertex_count() * std::size_t(t.coefficients));
        std::vector<double> y(static_cast<std::size_t>(t.coefficients));
        for (std::size_t i = 0; i < v.mesh.vertex_count(); ++i) {
            sh_eval(4, glm::dvec3(v.mesh.normals[i]), y.data());
            for (int l = 0; l <= 4; ++l)
                for (int m = -l; m <= l; ++m)
                    t.coeffs[i * 25 + std::size_t(sh_index(l, m))] =
                        float(clamped_cosine_zonal(l) / M_PI * y[std::size_t(sh_index(l, m))]);
        }
        return v;
    }();
    return m;
}

ModelViewSettings settings() {
    ModelViewSettings s;
    s.camera.width = 1920;
    s.camera.height = 1080;
    s.camera.samples = 1;
    s.sun_elevation_deg = 25.0;
    return s;
}

const SkySource& reference_sky() {
    static const SkySource s = SkySource::reference(neural_reference_model(
        load_neural_sky(std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/planet/sky_paper.json")));
    return s;
}

void frame_vs_flat(benchmark::State& state, ModelShading shading) {
    ModelRenderer r(model(), sky(), parse_rule("lebedev:2030"), 4);
    ModelViewSettings s = settings();
    s.shading = shading;
    ModelFrameStats st;
    r.render(s, &st); // warm up: the light, the sun, the shaders
    r.render_flat(s, &st);
    double draw = 0.0, flat = 0.0;
    int n = 0;
    for (auto _ : state) {
        r.render(s, &st);
        state.SetIterationTime(st.draw_seconds);
        draw += st.draw_seconds;
        ModelFrameStats sf;
        r.render_flat(s, &sf);
        flat += sf.draw_seconds;
        ++n;
    }
    state.counters["triangles"] = double(st.triangles);
    state.counters["vertices"] = double(st.vertices);
    state.counters["frame_ms"] = 1e3 * draw / n;
    state.counters["flat_ms"] = 1e3 * flat / n;
    state.counters["vs_flat"] = draw / flat;
    state.SetLabel(r.device_description());
}

void BM_Viewer_100k_Prt4_NetworkPerPixel_1080p(benchmark::State& state) {
    frame_vs_flat(state, ModelShading::Prt);
}
BENCHMARK(BM_Viewer_100k_Prt4_NetworkPerPixel_1080p)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_Viewer_100k_Dprt4_NetworkPerPixel_1080p(benchmark::State& state) {
    frame_vs_flat(state, ModelShading::Dprt);
}
BENCHMARK(BM_Viewer_100k_Dprt4_NetworkPerPixel_1080p)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// The sun moves one degree per frame: the sky SH recompute and the sun's
// shadow (the draw is not counted). shadow: 0 map, 1 per vertex.
void sun_move(benchmark::State& state, SunShadow shadow) {
    ModelRenderer r(model(), sky(), parse_rule("lebedev:2030"), 4);
    ModelViewSettings s = settings();
    s.sun_shadow = shadow;
    s.camera.width = 64;
    s.camera.height = 36;
    ModelFrameStats st;
    r.render(s, &st);
    double light = 0.0, sun = 0.0;
    int n = 0;
    for (auto _ : state) {
        s.sun_azimuth_deg += 1.0;
        r.render(s, &st);
        state.SetIterationTime(st.light_seconds + st.sun_seconds);
        light += st.light_seconds;
        sun += st.sun_seconds;
        ++n;
    }
    state.counters["sky_sh_ms"] = 1e3 * light / n;
    state.counters["sun_shadow_ms"] = 1e3 * sun / n;
    state.counters["vertices"] = double(st.vertices);
}

void BM_Viewer_SunMove_SkySh4(benchmark::State& state) {
    sun_move(state, SunShadow::Vertex);
}
BENCHMARK(BM_Viewer_SunMove_SkySh4)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(10);

void BM_Viewer_SunMove_SkySh4_ShadowMap(benchmark::State& state) {
    sun_move(state, SunShadow::Map);
}
BENCHMARK(BM_Viewer_SunMove_SkySh4_ShadowMap)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(10);

// The reference sky's background map when the sun rises (CPU, the tables;
// a move in azimuth alone costs nothing, the map being relative to the sun's azimuth).
void BM_Viewer_SunRise_ReferenceBackground(benchmark::State& state) {
    ModelRenderer r(model(), reference_sky(), parse_rule("lebedev:2030"), 4);
    ModelViewSettings s = settings();
    s.camera.width = 64;
    s.camera.height = 36;
    ModelFrameStats st;
    r.render(s, &st);
    double map = 0.0;
    int n = 0;
    for (auto _ : state) {
        s.sun_elevation_deg += 0.5;
        r.render(s, &st);
        state.SetIterationTime(st.background_seconds);
        map += st.background_seconds;
        ++n;
    }
    state.counters["background_map_ms"] = 1e3 * map / n;
}
BENCHMARK(BM_Viewer_SunRise_ReferenceBackground)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

} // namespace

BENCHMARK_MAIN();
