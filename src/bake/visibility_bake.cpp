// The bake driver: the one loop behind every per-vertex visibility bake
// (skybake/bake.h, [SECTION] The bake driver).
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): per-vertex visibility V_p(x_k) over a sphere rule, computed in
// chunks of vertices (the seed's answer to the GPU watchdog and to memory),
// then reduced.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "bake/internal.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "skybake/bake.h"
#include "skybake/error.h"
#include "sphere/random_rotation.h"
#include "visibility/trace_hd.h"

namespace skybake {

namespace {

// Host memory the driver gives one chunk's words, origins, normals and
// rotations; more vertices than this per chunk gain nothing.
constexpr std::uint64_t kChunkBytes = std::uint64_t(256) << 20;
// Chunks small enough that the progress bar moves and an interrupt (Ctrl-C,
// a cancelled callback) is seen soon, large enough that every thread has
// work: n / kChunksPerBake vertices, at least kMinChunk, and at most
// kChunkRays vertex–direction pairs (about half a second of rays on two
// cores), but never under kSmallestChunk vertices.
constexpr std::uint32_t kChunksPerBake = 32;
constexpr std::uint32_t kMinChunk = 4096;
constexpr std::uint64_t kChunkRays = std::uint64_t(1) << 23;
constexpr std::uint32_t kSmallestChunk = 256;

// Coordinates beyond the tracers' range (kMaxTraceCoordinate): finite, but
// Embree aborts on rays that start there.
void check_trace_range(std::span<const glm::vec3> positions, const char* field) {
    float largest = 0.0f;
    for (const glm::vec3& p : positions)
        largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    if (largest > kMaxTraceCoordinate)
        throw Error(fmt::format("a coordinate reaches {:g} mesh units; the tracers take up to {:g} (scale the "
                                "model down)",
                                largest, kMaxTraceCoordinate),
                    field);
}

void check_inputs(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options) {
    validate_mesh(mesh, "mesh");
    const std::size_t n = mesh.vertex_count();
    if (mesh.normals.size() != n)
        throw Error("the mesh has no vertex normals; compute them first (compute_normals)", "mesh");
    if (n >= std::size_t(0xffffffffu))
        throw Error(fmt::format("{} vertices is too many; the bake handles up to 4,294,967,294", n), "mesh");
    if (rule.size() == 0 || rule.weights.size() != rule.size())
        throw Error("the sphere rule has no points", "rule");
    if (rule.kind == RuleKind::Phong)
        throw Error(fmt::format("'{}' integrates against a Phong lobe, not over the sphere; use a lebedev, design, "
                                "fibonacci or mc rule for a visibility bake",
                                rule.spec),
                    "rule");
    if (!(options.max_distance > 0.0f)) // also catches NaN
        throw Error(fmt::format("maximum distance must be > 0 mesh units (infinity for unlimited); got {}",
                                options.max_distance),
                    "max_distance");
    if (!std::isfinite(options.ray_offset) || options.ray_offset > kMaxRayOffset)
        throw Error(fmt::format("ray offset must be a distance in [0, {:g}] mesh units; got {:g}", kMaxRayOffset,
                                options.ray_offset),
                    "ray_offset");
    check_trace_range(mesh.positions, "mesh");
}

} // namespace

float resolve_ray_offset(const Mesh&, const BakeOptions& options) {
    return options.ray_offset > 0.0f ? options.ray_offset : 0.0f;
}

namespace {

// The loop itself, over n sample points whose ray frame frame(i, origin,
// normal, offset direction) gives: the mesh's vertices, or other points on
// its surface.
template <class Frame>
VisibilityBakeStats bake_points(const Mesh& mesh, std::uint32_t n, float ray_offset, const Frame& frame,
                                const SphereRule& rule, VisibilityTracer& tracer, const BakeOptions& options,
                                VisibilityReduction& reduction) {
    const bake::VisitingRule visit = bake::visiting_rule(rule);
    const std::uint32_t words = visit.words_per_vertex;
    const bool rotate = visit.rotate;
    VisibilityBakeStats stats;
    stats.ray_offset = ray_offset;

    const auto t0 = std::chrono::steady_clock::now();
    tracer.set_mesh(mesh, options.back_faces);
    const auto t1 = std::chrono::steady_clock::now();
    stats.build_seconds = std::chrono::duration<double>(t1 - t0).count();

    TraceRule trace_rule;
    trace_rule.points = visit.points;
    trace_rule.order = visit.order;
    trace_rule.words_per_vertex = words;
    trace_rule.rotate = rotate;
    trace_rule.t_max = options.max_distance;
    const std::uint32_t tracer_limit = std::max<std::uint32_t>(1, tracer.set_rule(trace_rule));

    VisibilityRule reduce_rule;
    reduce_rule.points = visit.points;
    reduce_rule.weights = visit.weights;
    reduce_rule.order = visit.order;
    reduce_rule.words_per_vertex = words;
    reduce_rule.rotate = rotate;
    reduction.begin(reduce_rule, n);

    const bool host_words = !(tracer.device_words_supported() && reduction.reduces_on_device());
    const std::uint64_t per_vertex =
        3 * sizeof(glm::vec3) + (rotate ? sizeof(glm::mat3) : 0) + (host_words ? 4ull * words : 0);
    const auto memory_limit = std::uint32_t(std::clamp<std::uint64_t>(kChunkBytes / per_vertex, 1, 0xffffffffu));
    // A GPU or raster tracer takes the largest chunk it allows (fewer launches,
    // fewer depth maps); a CPU tracer's chunks are sized for the progress bar
    // and interrupts.
    const auto ray_limit =
        std::uint32_t(std::clamp<std::uint64_t>(kChunkRays / rule.size(), kSmallestChunk, 0xffffffffu));
    const std::uint32_t wanted = tracer.prefers_large_chunks()
                                     ? tracer_limit
                                     : std::min(std::max(n / kChunksPerBake, kMinChunk), ray_limit);
    const std::uint32_t chunk =
        std::max<std::uint32_t>(1, std::min({wanted, tracer_limit, memory_limit, std::max(n, 1u)}));

    const ChunkBuilder build = [&](std::uint32_t first, std::uint32_t count, ChunkInputs& in,
                                         std::span<std::uint32_t> out_words) {
        in.origins.resize(std::max<std::size_t>(in.origins.size(), count));
        in.normals.resize(std::max<std::size_t>(in.normals.size(), count));
        in.offsets.resize(std::max<std::size_t>(in.offsets.size(), count));
        if (rotate)
            in.rotations.resize(std::max<std::size_t>(in.rotations.size(), count));
        parallel_for(count, 1024, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const std::size_t v = first + i;
                frame(v, in.origins[i], in.normals[i], in.offsets[i]);
                if (rotate)
                    in.rotations[i] = visit.rotation(std::uint32_t(v));
            }
        });
        TraceChunk tc;
        tc.first = first;
        tc.count = count;
        tc.origins = std::span<const glm::vec3>(in.origins.data(), count);
        tc.normals = std::span<const glm::vec3>(in.normals.data(), count);
        tc.offsets = std::span<const glm::vec3>(in.offsets.data(), count);
        if (rotate)
            tc.rotations = std::span<const glm::mat3>(in.rotations.data(), count);
        tc.words = out_words;
        return tc;
    };
    if (auto* whole = dynamic_cast<WholeBakeTracer*>(&tracer))
        whole->trace_points(n, build);

    ChunkInputs inputs;
    std::vector<std::uint32_t> chunk_words(host_words ? std::size_t(chunk) * words : 0);
    Progress progress("bake", n);
    for (std::uint32_t first = 0; first < n; first += chunk, ++stats.chunks) {
        const std::uint32_t count = std::min(chunk, n - first);
        const TraceChunk tc =
            build(first, count, inputs,
                  host_words ? std::span<std::uint32_t>(chunk_words.data(), std::size_t(count) * words)
                             : std::span<std::uint32_t>());
        tracer.trace(tc);

        VisibilityChunk vc;
        vc.first = first;
        vc.count = count;
        vc.normals = tc.normals;
        vc.rotations = tc.rotations;
        vc.words = tc.words;
        vc.device_words = tracer.device_words();
        stats.rays += reduction.reduce(vc);
        progress.advance(count);
    }
    progress.finish();
    stats.trace_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    return stats;
}

void check_method(const BakeOptions& options, const VisibilityTracer& tracer) {
    if (options.method != tracer.method())
        throw Error(fmt::format("the {} method is not the {} tracer's (it has {}); create the tracer with the method",
                                trace_method_name(options.method), tracer.name(), trace_method_name(tracer.method())),
                    "method");
}

} // namespace

VisibilityBakeStats bake_visibility(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                                    const BakeOptions& options, VisibilityReduction& reduction) {
    check_inputs(mesh, rule, options);
    check_method(options, tracer);
    const bake::VertexRays rays = bake::vertex_rays(mesh, options);
    const auto frame = [&](std::size_t v, glm::vec3& origin, glm::vec3& normal, glm::vec3& offset) {
        normal = rays.normals[v];
        origin = rays.origin(mesh, v);
        offset = glm::normalize(rays.normals[v] + rays.inward[v]);
    };
    return bake_points(mesh, std::uint32_t(mesh.vertex_count()), rays.offset, frame, rule, tracer, options,
                       reduction);
}

VisibilityBakeStats bake_visibility(const Mesh& mesh, const SamplePoints& points, const SphereRule& rule,
                                    VisibilityTracer& tracer, const BakeOptions& options,
                                    VisibilityReduction& reduction) {
    check_inputs(mesh, rule, options);
    check_method(options, tracer);
    const std::size_t n = points.positions.size();
    if (points.normals.size() != n || points.sizes.size() != n)
        throw Error(fmt::format("{} sample positions, {} normals and {} sizes; they must be as many", n,
                                points.normals.size(), points.sizes.size()),
                    "points");
    if (n >= std::size_t(0xffffffffu))
        throw Error(fmt::format("{} sample points is too many; the bake handles up to 4,294,967,294", n), "points");
    check_trace_range(points.positions, "points");
    const float offset = resolve_ray_offset(mesh, options);
    const auto frame = [&](std::size_t v, glm::vec3& origin, glm::vec3& normal, glm::vec3& offset_direction) {
        normal = points.normals[v];
        offset_direction = normal;
        origin = bake::ray_origin(points.positions[v], normal, glm::vec3(0.0f), offset,
                                  bake::rounding_step(points.positions[v], points.sizes[v]));
    };
    return bake_points(mesh, std::uint32_t(n), offset, frame, rule, tracer, options, reduction);
}

namespace bake {

glm::mat3 VisitingRule::rotation(std::uint32_t vertex) const {
    return rotate ? sphere::vertex_rotation_hd<float>(vertex, rotation_seed) : glm::mat3(1.0f);
}

VisitingRule visiting_rule(const SphereRule& rule) {
    const std::vector<glm::vec3> points = rule.points_f32();
    const std::vector<float> weights = rule.weights_f32();
    VisitingRule r;
    r.order = coherent_direction_order(points);
    r.points.resize(points.size());
    r.weights.resize(points.size());
    for (std::size_t j = 0; j < points.size(); ++j) {
        r.points[j] = points[r.order[j]];
        r.weights[j] = weights[r.order[j]];
    }
    r.words_per_vertex = visibility::words_for_directions(std::uint32_t(points.size()));
    r.rotate = rule.rotate_per_vertex;
    r.rotation_seed = rule.rotation_seed;
    return r;
}

VertexRays vertex_rays(const Mesh& mesh, const BakeOptions& options) {
    VertexRays r;
    r.offset = resolve_ray_offset(mesh, options);
    r.normals = bake_normals(mesh);
    r.inward = vertex_inward_directions(mesh, r.normals);
    // Each vertex's triangle size: the mean distance to their centroids.
    std::vector<double> dist(mesh.vertex_count(), 0.0);
    std::vector<std::uint32_t> count(mesh.vertex_count(), 0);
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t* i = &mesh.indices[3 * t];
        const glm::dvec3 c = (glm::dvec3(mesh.positions[i[0]]) + glm::dvec3(mesh.positions[i[1]]) +
                              glm::dvec3(mesh.positions[i[2]])) /
                             3.0;
        for (int k = 0; k < 3; ++k) {
            dist[i[k]] += glm::length(c - glm::dvec3(mesh.positions[i[k]]));
            ++count[i[k]];
        }
    }
    r.steps.resize(mesh.vertex_count());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        r.steps[v] = rounding_step(mesh.positions[v], count[v] ? float(dist[v] / count[v]) : 0.0f);
    return r;
}

std::vector<glm::vec3> bake_normals(const Mesh& mesh) {
    const std::size_t n = mesh.vertex_count();
    std::vector<glm::vec3> normals(n);
    std::vector<glm::vec3> fallback;
    for (std::size_t v = 0; v < n; ++v) {
        const glm::vec3 m = mesh.normals[v];
        const float len = glm::length(m);
        if (len > 0.0f && std::isfinite(len)) {
            normals[v] = m / len;
            continue;
        }
        if (fallback.empty()) {
            Mesh copy;
            copy.positions = mesh.positions;
            copy.indices = mesh.indices;
            compute_normals(copy);
            fallback = std::move(copy.normals);
        }
        normals[v] = fallback[v];
    }
    return normals;
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

} // namespace bake
} // namespace skybake
