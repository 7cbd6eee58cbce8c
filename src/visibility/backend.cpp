// The visibility backend interface: factory, shared bake set-up, and the
// generic vertex × rule bake on top of occluded() (used by the brute-force
// oracle; the Embree backend has its own packet loop).
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): per-vertex visibility V_p(x_k) over a sphere rule, reduced to the
// shading coefficients in shading_hd.h.
#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "core/progress.h"
#include "skybake/error.h"
#include "sphere/random_rotation.h"
#include "visibility/bake_common.h"
#include "visibility/brute_backend.h"
#include "visibility/cuda/cuda_backend.h"
#include "visibility/embree/embree_backend.h"
#include "visibility/shading_hd.h"

namespace skybake {

const char* back_faces_name(BackFaces mode) { return mode == BackFaces::Ignore ? "ignore" : "occlude"; }

BackFaces parse_back_faces(const std::string& text) {
    if (text == "occlude")
        return BackFaces::Occlude;
    if (text == "ignore")
        return BackFaces::Ignore;
    throw Error(fmt::format("unknown back-face mode '{}'; choose occlude (both sides block rays) or ignore (rays pass "
                            "through triangles they meet from behind)",
                            text),
                "--back-faces");
}

float resolve_ray_offset(const Mesh& mesh, const BakeOptions& options) {
    if (options.ray_offset >= 0.0f)
        return options.ray_offset;
    return kDefaultRayOffsetScale * compute_bounds(mesh).diagonal();
}

const char* trace_method_name(TraceMethod method) {
    switch (method) {
    case TraceMethod::PerVertex: return "per-vertex";
    case TraceMethod::PerPolygon: return "per-polygon";
    default: return "bvh";
    }
}

TraceMethod parse_trace_method(const std::string& text) {
    for (TraceMethod m : {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon})
        if (text == trace_method_name(m))
            return m;
    throw Error(fmt::format("unknown method '{}'; choose bvh (default), per-vertex (every triangle for every ray) or "
                            "per-polygon (every triangle, cached in shared memory; cuda backend)",
                            text),
                "--method");
}

std::vector<std::string> visibility_backend_names() {
#if defined(SKYBAKE_HAS_CUDA)
    return {"embree", "brute", "cuda"};
#else
    return {"embree", "brute"};
#endif
}

std::unique_ptr<VisibilityBackend> make_visibility_backend(const std::string& name) {
    if (name == "embree")
        return std::make_unique<visibility::EmbreeBackend>();
    if (name == "brute")
        return std::make_unique<visibility::BruteForceBackend>();
    if (name == "cuda")
        return visibility::make_cuda_backend(); // throws without CUDA or a device
    throw Error(fmt::format("unknown visibility backend '{}'; choose embree (default), cuda (NVIDIA GPUs) or brute (a "
                            "test oracle for small meshes)",
                            name),
                "--backend");
}

void VisibilityBackend::bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options,
                             BakeOutputs& out) {
    using visibility::BakeSetup;
    visibility::require_bvh_method(options, name());
    const BakeSetup s = visibility::prepare_bake(mesh, rule, options, out);
    const auto t0 = std::chrono::steady_clock::now();
    set_mesh(mesh, options.back_faces);
    const auto t1 = std::chrono::steady_clock::now();
    out.build_seconds = std::chrono::duration<double>(t1 - t0).count();

    const std::size_t n = mesh.vertex_count();
    Progress progress("ao", n);
    std::atomic<std::uint64_t> rays{0}, clamped{0};
    parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
        std::vector<Ray> batch;
        std::vector<std::uint8_t> occ;
        std::vector<std::uint32_t> index, words(s.words);
        std::uint64_t traced = 0;
        for (std::size_t v = b; v < e; ++v) {
            const auto frame = visibility::vertex_frame(s, mesh, std::uint32_t(v));
            batch.clear();
            index.clear();
            for (std::uint32_t k = 0; k < s.directions; ++k) {
                glm::vec3 x;
                float c;
                visibility::vertex_direction(s.points[k], frame.rotation, s.rotate, frame.normal, x, c);
                if (visibility::needs_ray(c)) {
                    batch.push_back({frame.origin, 0.0f, x, s.t_max});
                    index.push_back(k);
                }
            }
            occ.resize(batch.size());
            occluded(batch, occ);
            std::fill(words.begin(), words.end(), 0u);
            for (std::size_t i = 0; i < batch.size(); ++i)
                if (!occ[i])
                    visibility::set_bit(words.data(), index[i]);
            visibility::finish_vertex(s, frame, std::uint32_t(v), words.data(), out, clamped);
            traced += batch.size();
        }
        rays += traced;
        progress.advance(e - b);
    });
    progress.finish();
    out.rays = rays.load();
    out.clamped_vertices = clamped.load();
    out.trace_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
}

namespace visibility {

void require_bvh_method(const BakeOptions& options, const char* backend) {
    if (options.method != TraceMethod::Bvh)
        throw Error(fmt::format("the {} method is the cuda backend's; the {} backend has only bvh (use --backend cuda, "
                                "or leave --method out)",
                                trace_method_name(options.method), backend),
                    "--method");
}

BakeSetup prepare_bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out) {
    validate_mesh(mesh, "mesh");
    const std::size_t n = mesh.vertex_count();
    if (mesh.normals.size() != n)
        throw Error("the mesh has no vertex normals; compute them first (compute_normals)", "mesh");
    if (n >= std::size_t(0xffffffffu))
        throw Error(fmt::format("{} vertices is too many; the bake handles up to 4,294,967,294", n), "mesh");
    if (rule.size() == 0 || rule.weights.size() != rule.size())
        throw Error("the sphere rule has no points", "--rule");
    if (rule.kind == RuleKind::Phong)
        throw Error(fmt::format("'{}' integrates against a Phong lobe, not over the sphere; use a lebedev, design, "
                                "fibonacci or mc rule for ambient occlusion",
                                rule.spec),
                    "--rule");
    if (!(options.max_distance > 0.0f)) // also catches NaN
        throw Error(fmt::format("maximum distance must be > 0 mesh units (infinity for unlimited); got {}",
                                options.max_distance),
                    "--max-distance");
    if (!std::isfinite(options.ray_offset))
        throw Error(fmt::format("ray offset must be a finite distance in mesh units; got {}", options.ray_offset),
                    "--offset");

    BakeSetup s;
    s.points = rule.points_f32();
    s.weights = rule.weights_f32();
    s.directions = std::uint32_t(rule.size());
    s.order = coherent_direction_order(s.points);
    s.sorted_points.resize(s.directions);
    s.sorted_weights.assign(padded_directions(s.directions), 0.0f);
    for (std::uint32_t j = 0; j < s.directions; ++j) {
        s.sorted_points[j] = s.points[s.order[j]];
        s.sorted_weights[j] = s.weights[s.order[j]];
    }
    s.words = words_for_directions(s.directions);
    s.rotate = rule.rotate_per_vertex;
    s.rotation_seed = rule.rotation_seed;
    s.normalize = options.normalize;
    s.store_bits = options.store_bits;
    s.offset = resolve_ray_offset(mesh, options);
    s.t_max = options.max_distance;

    // Unit normals. A zero or non-finite normal (possible in imported files)
    // falls back to the area-weighted normal of the vertex's triangles.
    s.normals.resize(n);
    std::vector<glm::vec3> fallback;
    for (std::size_t v = 0; v < n; ++v) {
        const glm::vec3 m = mesh.normals[v];
        const float len = glm::length(m);
        if (len > 0.0f && std::isfinite(len)) {
            s.normals[v] = m / len;
            continue;
        }
        if (fallback.empty()) {
            Mesh copy;
            copy.positions = mesh.positions;
            copy.indices = mesh.indices;
            compute_normals(copy);
            fallback = std::move(copy.normals);
        }
        s.normals[v] = fallback[v];
    }

    s.inward = vertex_inward_directions(mesh, s.normals);

    out = BakeOutputs{};
    out.ao.assign(n, 0.0f);
    out.shading.assign(n, 0.0f);
    out.bent_normal.assign(n, glm::vec3(0.0f));
    out.directions = s.directions;
    out.words_per_vertex = s.words;
    if (s.store_bits)
        out.visibility_bits.assign(n * s.words, 0u);
    out.ray_offset = s.offset;
    return s;
}

VertexFrame vertex_frame(const BakeSetup& s, const Mesh& mesh, std::uint32_t vertex) {
    VertexFrame f;
    f.normal = s.normals[vertex];
    f.origin = ray_origin(mesh.positions[vertex], f.normal, s.inward[vertex], s.offset);
    if (s.rotate)
        f.rotation = sphere::vertex_rotation_hd<float>(vertex, s.rotation_seed);
    return f;
}

void finish_vertex(const BakeSetup& s, const VertexFrame& f, std::uint32_t vertex, const std::uint32_t* words,
                   BakeOutputs& out, std::atomic<std::uint64_t>& clamped) {
    const Shading r = shading_from_bits(words, s.points.data(), s.weights.data(), s.order.data(), s.directions,
                                        f.normal, f.rotation, s.rotate, s.normalize);
    store_vertex(s, vertex, r, words, out, clamped);
}

void store_vertex(const BakeSetup& s, std::uint32_t vertex, const Shading& r, const std::uint32_t* words,
                  BakeOutputs& out, std::atomic<std::uint64_t>& clamped) {
    out.ao[vertex] = r.ao;
    out.shading[vertex] = r.shading;
    out.bent_normal[vertex] = r.bent_normal;
    if (r.clamped)
        clamped.fetch_add(1, std::memory_order_relaxed);
    if (s.store_bits)
        std::copy(words, words + s.words, out.visibility_bits.begin() + std::ptrdiff_t(std::size_t(vertex) * s.words));
}

std::vector<glm::vec3> vertex_inward_directions(const Mesh& mesh, const std::vector<glm::vec3>& normals) {
    const std::size_t n = mesh.vertex_count();
    std::vector<glm::dvec3> sum(n, glm::dvec3(0.0));
    std::vector<double> area(n, 0.0), dist(n, 0.0);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t* i = &mesh.indices[3 * t];
        const glm::dvec3 p0 = mesh.positions[i[0]], p1 = mesh.positions[i[1]], p2 = mesh.positions[i[2]];
        const double a = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        if (!(a > 0.0))
            continue;
        const glm::dvec3 c = (p0 + p1 + p2) / 3.0;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 d = c - glm::dvec3(mesh.positions[i[k]]);
            sum[i[k]] += a * d;
            area[i[k]] += a;
            dist[i[k]] += a * glm::length(d);
        }
    }
    std::vector<glm::vec3> inward(n, glm::vec3(0.0f));
    for (std::size_t v = 0; v < n; ++v) {
        if (!(area[v] > 0.0))
            continue;
        const glm::dvec3 nv = normals[v];
        glm::dvec3 m = sum[v] / area[v];
        m -= glm::dot(m, nv) * nv; // tangential part
        const double len = glm::length(m);
        if (len > 0.05 * dist[v] / area[v])
            inward[v] = glm::vec3(m / len);
    }
    return inward;
}

namespace {
// Spreads the low 16 bits of x to the even bits.
std::uint32_t spread_bits(std::uint32_t x) {
    x &= 0xffffu;
    x = (x | (x << 8)) & 0x00ff00ffu;
    x = (x | (x << 4)) & 0x0f0f0f0fu;
    x = (x | (x << 2)) & 0x33333333u;
    x = (x | (x << 1)) & 0x55555555u;
    return x;
}
} // namespace

std::vector<std::uint32_t> coherent_direction_order(const std::vector<glm::vec3>& points) {
    // Octahedral map (Praun & Hoppe 2003) of the unit sphere onto [-1, 1]^2,
    // then the Morton code of the 16-bit grid cell.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) {
        const glm::vec3 x = points[k];
        const float l1 = std::abs(x.x) + std::abs(x.y) + std::abs(x.z);
        float u = x.x / l1, v = x.y / l1;
        if (x.z < 0.0f) {
            const float fu = (1.0f - std::abs(v)) * (u >= 0.0f ? 1.0f : -1.0f);
            const float fv = (1.0f - std::abs(u)) * (v >= 0.0f ? 1.0f : -1.0f);
            u = fu;
            v = fv;
        }
        const auto q = [](float t) {
            return std::uint32_t(std::clamp((t * 0.5f + 0.5f) * 65535.0f + 0.5f, 0.0f, 65535.0f));
        };
        keyed[k] = {spread_bits(q(u)) | (spread_bits(q(v)) << 1), std::uint32_t(k)};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::uint32_t> order(points.size());
    for (std::size_t k = 0; k < keyed.size(); ++k)
        order[k] = keyed[k].second;
    return order;
}

} // namespace visibility
} // namespace skybake
