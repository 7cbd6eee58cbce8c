// Per-vertex ambient occlusion, shading coefficient A and bent normal: the
// shading reduction and the bake that stores it on the mesh.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): V0 = ∫ V 4(n·x)+ dμ and A = 2 ∫ V dμ, evaluated with a sphere rule
// over the visibility words of a tracer; the arithmetic is bake/shading_hd.h.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "bake/internal.h"
#include "bake/shading_cuda.h"
#include "bake/shading_hd.h"
#include "core/parallel.h"
#include "skybake/bake.h"
#include "skybake/error.h"

namespace skybake {

ShadingReduction::ShadingReduction(BakeOutputs& out, bool normalize, bool store_bits)
    : out_(out), normalize_(normalize), store_bits_(store_bits) {}

void ShadingReduction::begin(const VisibilityRule& rule, std::size_t vertices) {
    rule_ = rule;
    out_ = BakeOutputs{};
    out_.ao.assign(vertices, 0.0f);
    out_.shading.assign(vertices, 0.0f);
    out_.bent_normal.assign(vertices, glm::vec3(0.0f));
    out_.directions = std::uint32_t(rule.points.size());
    out_.words_per_vertex = rule.words_per_vertex;
    if (store_bits_)
        out_.visibility_bits.assign(vertices * rule.words_per_vertex, 0u);
}

bool ShadingReduction::reduces_on_device() const { return !store_bits_ && bake::shading_cuda_available(); }

std::uint64_t ShadingReduction::reduce(const VisibilityChunk& c) {
    const std::uint32_t words = rule_.words_per_vertex;
    const auto directions = std::uint32_t(rule_.points.size());
    if (c.words.empty()) {
        std::vector<bake::ShadingResult> r(c.count);
        bake::reduce_shading_cuda(rule_, c, normalize_, r.data());
        std::uint64_t rays = 0;
        for (std::uint32_t i = 0; i < c.count; ++i) {
            const std::size_t v = std::size_t(c.first) + i;
            out_.ao[v] = r[i].ao;
            out_.shading[v] = r[i].shading;
            out_.bent_normal[v] = r[i].bent_normal;
            out_.clamped_vertices += r[i].clamped;
            rays += r[i].rays;
        }
        return rays;
    }
    std::atomic<std::uint64_t> rays{0}, clamped{0};
    parallel_for(c.count, 64, [&](std::size_t b, std::size_t e) {
        std::uint64_t traced_sum = 0, clamped_sum = 0;
        for (std::size_t i = b; i < e; ++i) {
            const std::size_t v = std::size_t(c.first) + i;
            const std::uint32_t* w = c.words.data() + i * words;
            std::uint32_t traced = 0;
            const bake::Shading s = bake::shading_from_words(
                w, rule_.points.data(), rule_.weights.data(), rule_.order.data(), directions, c.normals[i],
                rule_.rotate ? c.rotations[i] : glm::mat3(1.0f), rule_.rotate, normalize_, &traced);
            out_.ao[v] = s.ao;
            out_.shading[v] = s.shading;
            out_.bent_normal[v] = s.bent_normal;
            traced_sum += traced;
            clamped_sum += s.clamped ? 1 : 0;
            if (store_bits_)
                std::copy(w, w + words, out_.visibility_bits.begin() + std::ptrdiff_t(v * words));
        }
        rays += traced_sum;
        clamped += clamped_sum;
    });
    out_.clamped_vertices += clamped.load();
    return rays.load();
}

void bake_shading(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, const BakeOptions& options,
                  BakeOutputs& out) {
    ShadingReduction reduction(out, options.normalize, options.store_bits);
    const VisibilityBakeStats stats = bake_visibility(mesh, rule, tracer, options, reduction);
    out.rays = stats.rays;
    out.ray_offset = stats.ray_offset;
    out.build_seconds = stats.build_seconds;
    out.trace_seconds = stats.trace_seconds;
}

AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                                    const BakeOptions& options, BakeOutputs* outputs) {
    const auto t0 = std::chrono::steady_clock::now();
    validate_mesh(mesh, "mesh");
    if (mesh.normals.empty())
        compute_normals(mesh);
    BakeOutputs local;
    BakeOutputs& out = outputs ? *outputs : local;
    bake_shading(mesh, rule, tracer, options, out);

    const std::size_t n = mesh.vertex_count();
    std::vector<float> bent(3 * n);
    for (std::size_t v = 0; v < n; ++v) {
        bent[3 * v] = out.bent_normal[v].x;
        bent[3 * v + 1] = out.bent_normal[v].y;
        bent[3 * v + 2] = out.bent_normal[v].z;
    }
    mesh.set_attribute("ao", 1, out.ao);
    mesh.set_attribute("shading", 1, out.shading);
    mesh.set_attribute("bent_normal", 3, std::move(bent));
    mesh.colors.resize(n);
    for (std::size_t v = 0; v < n; ++v)
        mesh.colors[v] = glm::vec4(out.ao[v], out.ao[v], out.ao[v], 1.0f);

    AoBakeReport r;
    r.backend = tracer.name();
    r.method = trace_method_name(tracer.method());
    r.rule = rule.spec;
    r.vertices = n;
    r.triangles = mesh.triangle_count();
    r.directions = rule.size();
    r.rays = out.rays;
    r.build_seconds = out.build_seconds;
    r.trace_seconds = out.trace_seconds;
    r.ray_offset = out.ray_offset;
    r.negative_weights = rule.has_negative_weights();
    r.clamped_vertices = out.clamped_vertices;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, const std::string& backend,
                                    const BakeOptions& options, BakeOutputs* outputs) {
    const auto tracer = make_visibility_tracer(backend, options.method);
    return bake_ambient_occlusion(mesh, rule, *tracer, options, outputs);
}

ShadingCoefficients shading_from_bits(std::span<const std::uint32_t> words, const SphereRule& rule,
                                      std::uint32_t vertex, const glm::vec3& normal, bool normalize) {
    const auto k = std::uint32_t(rule.size());
    if (words.size() < visibility::words_for_directions(k))
        throw Error(fmt::format("{} visibility words for a rule of {} directions; expected {}", words.size(), k,
                                visibility::words_for_directions(k)),
                    "words");
    // Same normalisation as the bake driver, for identical results.
    const float len = glm::length(normal);
    if (!(len > 0.0f) || !std::isfinite(len))
        throw Error("the normal must be a non-zero finite vector", "normal");
    const bake::VisitingRule r = bake::visiting_rule(rule);
    const auto s = bake::shading_from_words(words.data(), r.points.data(), r.weights.data(), r.order.data(), k,
                                            normal / len, r.rotation(vertex), r.rotate, normalize);
    return {s.ao, s.shading, s.bent_normal};
}

} // namespace skybake
