// Ambient-occlusion bake benchmarks (Embree backend).
//
// BM_AoVsBareEmbree: the bake's trace phase (rays + bits + reduction) against
//   bare Embree loops issuing the same rays in the same run: the rays are
//   generated beforehand, exactly as the bake generates them (same origins,
//   directions, order and 16-ray packets), then
//     bare16: rtcOccluded16 over the stored packets,
//     bare1:  rtcOccluded1 over the stored rays one by one,
//   both spread over the same TBB threads. Counters: Mrays/s of each and the
//   ratios bake/bare (target ≥ 0.9). The three run in every iteration (the
//   bake first, then last, alternately), so a busy machine slows all alike.
// BM_AoTableCase: seed 002's table case, about 5k vertices with lebedev:5810,
//   whole bake (BVH build included). The seed: > 1 h on its CPU, 0.8 s CUDA.
// BM_AoLargeMesh: throughput on a generated mesh of ≥ 1M triangles.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <vector>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "ao_scenes.h"
#include "core/parallel.h"
#include "skybake/bake.h"
#include "skybake/core.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "bake/internal.h"
#include "visibility/embree/embree_backend.h"
#include "visibility/trace_hd.h"

using namespace skybake;

namespace {

struct Scene {
    Mesh mesh;
    SphereRule rule;
    visibility::EmbreeBackend backend;
    // The bake's rays, in the bake's order and packets.
    std::vector<RTCRay16> packets;
    std::vector<std::array<int, 16>> valid;
    std::vector<RTCRay> rays;
};

using bench::kind_of;
using bench::seconds_since;

Scene& scene(int kind, std::uint64_t triangles, const std::string& rule, bool with_rays) {
    static std::map<std::string, std::unique_ptr<Scene>> cache;
    const std::string key = fmt::format("{}/{}/{}/{}", kind, triangles, rule, with_rays);
    auto& slot = cache[key];
    if (slot)
        return *slot;
    slot = std::make_unique<Scene>();
    Scene& s = *slot;
    ProceduralOptions p;
    p.kind = kind_of(kind);
    p.target_triangles = triangles;
    s.mesh = generate_mesh(p);
    s.rule = parse_rule(rule);
    s.backend.set_mesh(s.mesh, BackFaces::Occlude);
    if (!with_rays)
        return s;
    // Generate the rays exactly as the bake does (the driver's frames and
    // visiting order, the Embree tracer's packets).
    const bake::VisitingRule visit = bake::visiting_rule(s.rule);
    const bake::VertexRays frames = bake::vertex_rays(s.mesh, BakeOptions{});
    const float t_max = BakeOptions{}.max_distance;
    for (std::uint32_t v = 0; v < s.mesh.vertex_count(); ++v) {
        const glm::vec3 origin = frames.origin(s.mesh, v), normal = frames.normals[v];
        const glm::mat3 rotation = visit.rotation(v);
        int lane = 0;
        for (std::uint32_t j = 0; j < visit.points.size(); ++j) {
            glm::vec3 x;
            float c;
            visibility::vertex_direction(visit.points[j], rotation, visit.rotate, normal, x, c);
            if (!visibility::needs_ray(c))
                continue;
            RTCRay r{};
            r.org_x = origin.x, r.org_y = origin.y, r.org_z = origin.z, r.tnear = 0.0f;
            r.dir_x = x.x, r.dir_y = x.y, r.dir_z = x.z, r.time = 0.0f;
            r.tfar = t_max, r.mask = 0xffffffffu, r.id = 0, r.flags = 0;
            s.rays.push_back(r);
            if (lane == 0) {
                s.packets.emplace_back();
                s.valid.emplace_back();
                s.valid.back().fill(0);
            }
            RTCRay16& p16 = s.packets.back();
            p16.org_x[lane] = r.org_x, p16.org_y[lane] = r.org_y, p16.org_z[lane] = r.org_z;
            p16.tnear[lane] = 0.0f, p16.dir_x[lane] = r.dir_x, p16.dir_y[lane] = r.dir_y, p16.dir_z[lane] = r.dir_z;
            p16.time[lane] = 0.0f, p16.tfar[lane] = r.tfar, p16.mask[lane] = 0xffffffffu;
            p16.id[lane] = unsigned(lane), p16.flags[lane] = 0;
            s.valid.back()[std::size_t(lane)] = -1;
            lane = (lane + 1) % 16;
        }
    }
    return s;
}

// Bare loops over the stored rays. Each returns seconds and the occluded count
// (checked against the bake, so that all three do the same work).
double bare16(const Scene& s, std::uint64_t& occluded) {
    std::atomic<std::uint64_t> occ{0};
    const auto t0 = std::chrono::steady_clock::now();
    parallel_for(s.packets.size(), 64, [&](std::size_t b, std::size_t e) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) RTCRay16 r;
        alignas(64) int valid[16];
        std::uint64_t n = 0;
        for (std::size_t i = b; i < e; ++i) {
            r = s.packets[i];
            std::copy(s.valid[i].begin(), s.valid[i].end(), valid);
            rtcOccluded16(valid, s.backend.scene(), &ctx, &r);
            for (int l = 0; l < 16; ++l)
                n += valid[l] && r.tfar[l] == -std::numeric_limits<float>::infinity();
        }
        occ += n;
    });
    occluded = occ.load();
    return seconds_since(t0);
}

double bare1(const Scene& s, std::uint64_t& occluded) {
    std::atomic<std::uint64_t> occ{0};
    const auto t0 = std::chrono::steady_clock::now();
    parallel_for(s.rays.size(), 1024, [&](std::size_t b, std::size_t e) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        std::uint64_t n = 0;
        for (std::size_t i = b; i < e; ++i) {
            RTCRay r = s.rays[i];
            rtcOccluded1(s.backend.scene(), &ctx, &r);
            n += r.tfar == -std::numeric_limits<float>::infinity();
        }
        occ += n;
    });
    occluded = occ.load();
    return seconds_since(t0);
}

std::uint64_t occluded_in_bake(const Scene& s, const BakeOutputs& out) {
    // Occluded rays = traced rays − set bits.
    std::uint64_t visible = 0;
    for (std::uint32_t w : out.visibility_bits)
        visible += std::uint64_t(__builtin_popcount(w));
    return out.rays - visible;
}

// Args: kind (0 city, 1 torus, 2 terrain), triangles, Lebedev points.
void BM_AoVsBareEmbree(benchmark::State& state) {
    const int kind = int(state.range(0));
    Scene& s = scene(kind, std::uint64_t(state.range(1)), fmt::format("lebedev:{}", state.range(2)), true);
    BakeOptions o;
    o.store_bits = true;
    double t_bake = 0, t16 = 0, t1 = 0;
    std::uint64_t rays = 0;
    bool bake_first = true;
    for (auto _ : state) {
        // Alternate the order, so that neither side always runs on a warmer cache.
        std::uint64_t occ16 = 0, occ1 = 0;
        double a = 0, c = 0;
        if (!bake_first) {
            a = bare16(s, occ16);
            c = bare1(s, occ1);
        }
        BakeOutputs out;
        bake_shading(s.mesh, s.rule, s.backend, o, out);
        if (bake_first) {
            a = bare16(s, occ16);
            c = bare1(s, occ1);
        }
        bake_first = !bake_first;
        // The bake traces the same rays as the bare loops. Single rays and
        // packets may disagree on a ray that grazes an edge: a few in 10^4.
        const std::uint64_t occ = occluded_in_bake(s, out);
        const auto close = [&](std::uint64_t x) {
            return double(x > occ ? x - occ : occ - x) <= 1e-4 * double(out.rays);
        };
        if (out.rays != s.rays.size() || !close(occ16) || !close(occ1)) {
            state.SkipWithError("the bare loops and the bake disagree");
            return;
        }
        t_bake += out.trace_seconds;
        t16 += a;
        t1 += c;
        rays = out.rays;
        state.SetIterationTime(out.trace_seconds);
    }
    const double it = double(state.iterations());
    state.counters["vertices"] = double(s.mesh.vertex_count());
    state.counters["rays"] = double(rays);
    state.counters["bake_Mrays"] = double(rays) * it / t_bake * 1e-6;
    state.counters["bare16_Mrays"] = double(rays) * it / t16 * 1e-6;
    state.counters["bare1_Mrays"] = double(rays) * it / t1 * 1e-6;
    state.counters["ratio_bare16"] = t16 / t_bake;
    state.counters["ratio_bare1"] = t1 / t_bake;
    state.counters["ratio_best"] = std::min(t16, t1) / t_bake; // against the faster bare loop
}

// Whole bakes of one scene (BVH build included), timed per iteration.
void run_whole_bake(benchmark::State& state, Scene& s) {
    double build = 0, trace = 0;
    std::uint64_t rays = 0;
    for (auto _ : state) {
        BakeOutputs out;
        const auto t0 = std::chrono::steady_clock::now();
        bake_shading(s.mesh, s.rule, s.backend, BakeOptions{}, out);
        state.SetIterationTime(seconds_since(t0));
        build += out.build_seconds;
        trace += out.trace_seconds;
        rays = out.rays;
    }
    const double it = double(state.iterations());
    state.counters["vertices"] = double(s.mesh.vertex_count());
    state.counters["triangles"] = double(s.mesh.triangle_count());
    state.counters["rays"] = double(rays);
    state.counters["build_s"] = build / it;
    state.counters["trace_s"] = trace / it;
    state.counters["Mrays"] = double(rays) * it / trace * 1e-6;
}

// Args: kind, triangles. lebedev:5810.
void BM_AoTableCase(benchmark::State& state) {
    Scene& s = scene(int(state.range(0)), std::uint64_t(state.range(1)), "lebedev:5810", false);
    run_whole_bake(state, s);
}

// Args: kind, triangles, Lebedev points.
void BM_AoLargeMesh(benchmark::State& state) {
    Scene& s = scene(int(state.range(0)), std::uint64_t(state.range(1)), fmt::format("lebedev:{}", state.range(2)),
                     false);
    run_whole_bake(state, s);
}

} // namespace

BENCHMARK(BM_AoVsBareEmbree)
    ->ArgNames({"kind", "tris", "rule"})
    ->Args({0, 3000, 1202})    // city, ~5k vertices: packets
    ->Args({1, 10000, 1202})   // torus, ~5k vertices: packets
    ->Args({0, 3000, 302})     // city, ~5k vertices: single rays
    ->Args({0, 50000, 590})    // city, 85k vertices: single rays
    ->Args({0, 200000, 110})   // city, 340k vertices: single rays
    ->Args({2, 1000000, 50})   // terrain, 1M triangles: single rays
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(6);
BENCHMARK(BM_AoTableCase)
    ->ArgNames({"kind", "tris"})
    ->Args({0, 3000})  // city, ~5k vertices
    ->Args({1, 10000}) // torus, ~5k vertices
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(BM_AoLargeMesh)
    ->ArgNames({"kind", "tris", "rule"})
    ->Args({2, 1000000, 86}) // terrain, 1M triangles
    ->Args({0, 1000000, 86}) // city, 1M triangles
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_MAIN();
