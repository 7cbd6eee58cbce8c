// Per-vertex ambient occlusion, shading coefficient A and bent normal.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): V0 = ∫ V 4(n·x)+ dμ and A = 2 ∫ V dμ, evaluated with a sphere rule
// by a visibility backend; the reduction itself is visibility/shading_hd.h.
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "skybake/bake.h"
#include "skybake/error.h"
#include "sphere/random_rotation.h"
#include "visibility/bake_common.h"
#include "visibility/shading_hd.h"

namespace skybake {

AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, VisibilityBackend& backend,
                                    const BakeOptions& options, BakeOutputs* outputs) {
    const auto t0 = std::chrono::steady_clock::now();
    validate_mesh(mesh, "mesh");
    if (mesh.normals.empty())
        compute_normals(mesh);
    BakeOutputs local;
    BakeOutputs& out = outputs ? *outputs : local;
    backend.bake(mesh, rule, options, out);

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
    r.backend = backend.name();
    r.method = trace_method_name(options.method);
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
    const auto b = make_visibility_backend(backend);
    return bake_ambient_occlusion(mesh, rule, *b, options, outputs);
}

ShadingCoefficients shading_from_bits(std::span<const std::uint32_t> words, const SphereRule& rule,
                                      std::uint32_t vertex, const glm::vec3& normal, bool normalize) {
    const auto k = std::uint32_t(rule.size());
    if (words.size() < visibility::words_for_directions(k))
        throw Error(fmt::format("{} visibility words for a rule of {} directions; expected {}", words.size(), k,
                                visibility::words_for_directions(k)));
    const std::vector<glm::vec3> points = rule.points_f32();
    const std::vector<float> weights = rule.weights_f32();
    const glm::mat3 rotation =
        rule.rotate_per_vertex ? sphere::vertex_rotation_hd<float>(vertex, rule.rotation_seed) : glm::mat3(1.0f);
    // Same normalisation as the bake (visibility::prepare_bake), for identical results.
    const float len = glm::length(normal);
    if (!(len > 0.0f) || !std::isfinite(len))
        throw Error("the normal must be a non-zero finite vector");
    const glm::vec3 n = normal / len;
    const std::vector<std::uint32_t> order = visibility::coherent_direction_order(points);
    const auto s = visibility::shading_from_bits(words.data(), points.data(), weights.data(), order.data(), k, n,
                                                 rotation, rule.rotate_per_vertex, normalize);
    return {s.ao, s.shading, s.bent_normal};
}

} // namespace skybake
