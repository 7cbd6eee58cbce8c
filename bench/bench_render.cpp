// The OpenGL planet renderer on the headless context: frame time at
// 1280x1024 for the seed's setup (a 2,000-triangle planet mesh, the network
// per vertex), for a 1M-triangle CLOD mesh with the network per pixel, and the
// CLOD update per frame along a moving camera. Each is measured against a
// flat-shaded pass over the same mesh in the same run (counter vs_flat =
// frame time / flat time). Times are GPU draw time (glFinish), without the
// readback; the CLOD update and the upload are counted apart (clod_ms).
//
// The network is the seed's topology with the weights of tests/data/planet.
#include <chrono>

#include <benchmark/benchmark.h>
#include <glm/geometric.hpp>

#include "skybake/render.h"

using namespace skybake;

namespace {

const NeuralSky& net() {
    static const NeuralSky n = load_neural_sky(std::string(SKYBAKE_SOURCE_DIR) + "/tests/data/planet/sky_paper.json");
    return n;
}
const SkyModel& tables() {
    static const SkyModel m = neural_reference_model(net());
    return m;
}

PlanetView view_at(double altitude_km, double pitch_deg, double yaw_deg = 0.0) {
    SkyRenderSettings s;
    s.view = SkyView::Camera;
    s.altitude_km = altitude_km;
    s.pitch_deg = pitch_deg;
    s.yaw_deg = yaw_deg;
    s.sun_elevation_deg = 35.0;
    s.sun_azimuth_deg = 40.0;
    s.fov_deg = 90.0;
    s.width = 1280;
    s.height = 1024;
    return planet_view_from_settings(tables().atmosphere(), s);
}

void frame_vs_flat(benchmark::State& state, const PlanetRenderOptions& o, const PlanetView& v) {
    PlanetRenderer r(tables(), &net(), o);
    PlanetFrameStats st;
    r.render(v, &st); // warm up: compile, build the mesh
    r.render_flat(v, &st);
    double draw = 0.0, flat = 0.0, clod = 0.0;
    std::size_t tris = 0;
    int n = 0;
    for (auto _ : state) {
        r.render(v, &st);
        state.SetIterationTime(st.draw_seconds);
        draw += st.draw_seconds;
        clod += st.clod_seconds;
        tris = st.triangles;
        PlanetFrameStats sf;
        r.render_flat(v, &sf);
        flat += sf.draw_seconds;
        ++n;
    }
    state.counters["triangles"] = double(tris);
    state.counters["frame_ms"] = 1e3 * draw / n;
    state.counters["flat_ms"] = 1e3 * flat / n;
    state.counters["clod_ms"] = 1e3 * clod / n;
    state.counters["vs_flat"] = draw / flat;
    state.SetLabel(r.device_description());
}

// Seed section VII: 9 fps at 1280x1024 with 2,000 triangles on a GeForce FX 5500.
void BM_SeedSetup_PerVertex_2kTriangles(benchmark::State& state) {
    PlanetRenderOptions o;
    o.shading = ShadingRate::Vertex;
    o.max_triangles = 2000;
    o.max_error_px = 0.02; // the budget binds: 2,000 triangles
    frame_vs_flat(state, o, view_at(30.0, -10.0));
}
BENCHMARK(BM_SeedSetup_PerVertex_2kTriangles)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_Clod1M_PerPixel(benchmark::State& state) {
    PlanetRenderOptions o;
    o.shading = ShadingRate::Pixel;
    o.max_triangles = 1'000'000;
    o.max_error_px = 0.02;
    o.relief.amplitude_km = 6.0;
    frame_vs_flat(state, o, view_at(2.0, -20.0));
}
BENCHMARK(BM_Clod1M_PerPixel)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

// The incremental update: the camera moves 1% of its altitude and turns 0.2
// degrees per frame; against the flat pass over the resulting mesh.
void BM_ClodUpdate_1M(benchmark::State& state) {
    ClodOptions c;
    c.planet_radius_km = tables().atmosphere().planet_radius_km;
    c.max_triangles = 1'000'000;
    c.max_error_px = 0.02;
    c.relief.amplitude_km = 6.0;
    PlanetMesh mesh(c);
    PlanetRenderOptions o;
    o.max_triangles = c.max_triangles;
    o.max_error_px = c.max_error_px;
    o.relief = c.relief;
    PlanetRenderer flat_r(tables(), &net(), o);
    double alt = 2.0, yaw = 0.0;
    auto camera = [&](const PlanetView& v) {
        PlanetCamera cam;
        cam.position_km = v.eye_km;
        cam.forward = v.forward;
        cam.up = glm::normalize(glm::cross(glm::cross(v.forward, v.up), v.forward));
        cam.fov_y_rad = 2.0 * std::atan(std::tan(0.5 * v.fov_x_deg * 3.14159265358979 / 180.0) * 1024.0 / 1280.0);
        cam.viewport_width = v.width;
        cam.viewport_height = v.height;
        return cam;
    };
    mesh.update(camera(view_at(alt, -20.0, yaw)));
    double flat = 0.0, upd = 0.0;
    std::size_t tris = 0, splits = 0, merges = 0;
    int n = 0;
    for (auto _ : state) {
        alt *= 1.01;
        yaw += 0.2;
        const PlanetView v = view_at(alt, -20.0, yaw);
        const auto t0 = std::chrono::steady_clock::now();
        const ClodStats st = mesh.update(camera(v));
        const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        state.SetIterationTime(dt);
        upd += dt;
        tris = st.triangles;
        splits += st.splits;
        merges += st.merges;
        PlanetFrameStats sf;
        flat_r.render_flat(v, &sf);
        flat += sf.draw_seconds;
        ++n;
    }
    state.counters["triangles"] = double(tris);
    state.counters["update_ms"] = 1e3 * upd / n;
    state.counters["flat_ms"] = 1e3 * flat / n;
    state.counters["splits_per_frame"] = double(splits) / n;
    state.counters["merges_per_frame"] = double(merges) / n;
    state.counters["vs_flat"] = upd / flat;
}
BENCHMARK(BM_ClodUpdate_1M)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(10);

} // namespace

BENCHMARK_MAIN();
