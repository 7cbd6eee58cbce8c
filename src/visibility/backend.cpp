// The visibility backends' factories and names, and the generic tracer on top
// of RayQueries::occluded() (used by the brute-force oracle; the Embree and
// CUDA backends have their own loops).
#include <algorithm>

#include <fmt/format.h>

#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/names.h"
#include "visibility/brute_backend.h"
#include "visibility/cuda/cuda_backend.h"
#include "visibility/embree/embree_backend.h"
#include "visibility/query_tracer.h"
#include "visibility/trace_hd.h"

namespace skybake {

namespace {

constexpr NamedValue<BackFaces> kBackFacesNames[] = {
    {BackFaces::Occlude, "occlude", "both sides block rays"},
    {BackFaces::Ignore, "ignore", "rays pass through triangles they meet from behind"},
};

constexpr NamedValue<TraceMethod> kTraceMethodNames[] = {
    {TraceMethod::Bvh, "bvh", "default"},
    {TraceMethod::PerVertex, "per-vertex", "every triangle for every ray"},
    {TraceMethod::PerPolygon, "per-polygon", "every triangle, cached in shared memory; cuda backend"},
};

void require_bvh(TraceMethod method, const char* backend) {
    if (method != TraceMethod::Bvh)
        throw Error(fmt::format("the {} method is the cuda backend's; the {} backend has only bvh",
                                trace_method_name(method), backend),
                    "method");
}

} // namespace

const char* back_faces_name(BackFaces mode) { return name_of(kBackFacesNames, mode); }

BackFaces parse_back_faces(const std::string& text) {
    return parse_name(kBackFacesNames, text, "back-face mode", "back_faces");
}

const char* trace_method_name(TraceMethod method) { return name_of(kTraceMethodNames, method); }

TraceMethod parse_trace_method(const std::string& text) {
    return parse_name(kTraceMethodNames, text, "method", "method");
}

std::vector<std::string> visibility_backend_names() {
#if defined(SKYBAKE_HAS_CUDA)
    return {"embree", "brute", "cuda"};
#else
    return {"embree", "brute"};
#endif
}

[[noreturn]] static void unknown_backend(const std::string& name) {
    throw Error(fmt::format("unknown visibility backend '{}'; choose embree (default), cuda (NVIDIA GPUs) or brute (a "
                            "test oracle for small meshes)",
                            name),
                "backend");
}

std::unique_ptr<RayQueries> make_ray_queries(const std::string& name) {
    if (name == "embree")
        return std::make_unique<visibility::EmbreeBackend>();
    if (name == "brute")
        return std::make_unique<visibility::BruteForceBackend>();
    if (name == "cuda")
        return visibility::make_cuda_ray_queries(); // throws without CUDA or a device
    unknown_backend(name);
}

std::unique_ptr<VisibilityTracer> make_visibility_tracer(const std::string& name, TraceMethod method) {
    if (name == "embree") {
        require_bvh(method, "embree");
        return std::make_unique<visibility::EmbreeBackend>();
    }
    if (name == "brute") {
        require_bvh(method, "brute");
        return std::make_unique<visibility::BruteForceBackend>();
    }
    if (name == "cuda")
        return visibility::make_cuda_tracer(method); // throws without CUDA or a device
    unknown_backend(name);
}

namespace visibility {

void trace_with_queries(const RayQueries& queries, const TraceRule& rule, const TraceChunk& chunk) {
    const auto directions = std::uint32_t(rule.points.size());
    parallel_for(chunk.count, 4, [&](std::size_t b, std::size_t e) {
        std::vector<Ray> batch;
        std::vector<std::uint8_t> occ;
        std::vector<std::uint32_t> index;
        for (std::size_t i = b; i < e; ++i) {
            const glm::vec3 n = chunk.normals[i];
            const glm::mat3 r = rule.rotate ? chunk.rotations[i] : glm::mat3(1.0f);
            batch.clear();
            index.clear();
            for (std::uint32_t j = 0; j < directions; ++j) {
                glm::vec3 x;
                float c;
                vertex_direction(rule.points[j], r, rule.rotate, n, x, c);
                if (needs_ray(c)) {
                    batch.push_back({chunk.origins[i], 0.0f, x, rule.t_max});
                    index.push_back(rule.order[j]);
                }
            }
            occ.resize(batch.size());
            queries.occluded(batch, occ);
            std::uint32_t* words = chunk.words.data() + i * rule.words_per_vertex;
            std::fill(words, words + rule.words_per_vertex, 0u);
            for (std::size_t q = 0; q < batch.size(); ++q)
                if (!occ[q])
                    set_bit(words, index[q]);
        }
    });
}

} // namespace visibility
} // namespace skybake
