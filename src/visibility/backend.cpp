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
#include "visibility/raster/raster_tracer.h"
#include "visibility/trace_hd.h"

namespace skybake {

namespace {

constexpr NamedValue<BackFaces> kBackFacesNames[] = {
    {BackFaces::Occlude, "occlude", "both sides block rays"},
    {BackFaces::Ignore, "ignore", "rays pass through triangles they meet from behind"},
};

constexpr NamedValue<TraceMethod> kTraceMethodNames[] = {
    {TraceMethod::Bvh, "bvh", "default"},
    {TraceMethod::PerVertex, "per-vertex", "cuda backend: every triangle for every ray"},
    {TraceMethod::PerPolygon, "per-polygon", "cuda backend: every triangle, cached in shared memory"},
    {TraceMethod::Cube, "cube", "raster backend, its default: a depth cube map at each vertex"},
    {TraceMethod::Directional, "directional", "raster backend: a depth map per direction"},
};

const char* method_owner(TraceMethod method) {
    return method == TraceMethod::Cube || method == TraceMethod::Directional ? "raster" : "cuda";
}

void require_bvh(TraceMethod method, const char* backend) {
    if (method != TraceMethod::Bvh)
        throw Error(fmt::format("the {} method is the {} backend's; the {} backend has only bvh",
                                trace_method_name(method), method_owner(method), backend),
                    "method");
}

void require_no_resolution(std::uint32_t resolution, const char* backend) {
    if (resolution != 0)
        throw Error(fmt::format("a resolution is for the raster backend; the {} backend traces rays", backend),
                    "resolution");
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

TraceMethod default_trace_method(const std::string& backend) {
    return backend == "raster" ? TraceMethod::Cube : TraceMethod::Bvh;
}

std::vector<std::string> visibility_backend_names() {
#if defined(SKYBAKE_HAS_CUDA)
    return {"embree", "brute", "cuda", "raster"};
#else
    return {"embree", "brute", "raster"};
#endif
}

[[noreturn]] static void unknown_backend(const std::string& name) {
    throw Error(fmt::format("unknown visibility backend '{}'; choose embree (default), cuda (NVIDIA GPUs), raster "
                            "(the depth buffer of OpenGL) or brute (a test oracle for small meshes)",
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
    if (name == "raster")
        throw Error("the raster backend answers no single ray queries (it bakes visibility with the depth buffer); "
                    "use embree or cuda",
                    "backend");
    unknown_backend(name);
}

std::unique_ptr<VisibilityTracer> make_visibility_tracer(const std::string& name, TraceMethod method,
                                                         std::uint32_t resolution) {
    if (name == "embree") {
        require_bvh(method, "embree");
        require_no_resolution(resolution, "embree");
        return std::make_unique<visibility::EmbreeBackend>();
    }
    if (name == "brute") {
        require_bvh(method, "brute");
        require_no_resolution(resolution, "brute");
        return std::make_unique<visibility::BruteForceBackend>();
    }
    if (name == "cuda") {
        if (method == TraceMethod::Cube || method == TraceMethod::Directional)
            throw Error(fmt::format("the {} method is the raster backend's; the cuda backend has bvh, per-vertex "
                                    "and per-polygon",
                                    trace_method_name(method)),
                        "method");
        require_no_resolution(resolution, "cuda");
        return visibility::make_cuda_tracer(method); // throws without CUDA or a device
    }
    if (name == "raster") {
        if (method != TraceMethod::Cube && method != TraceMethod::Directional)
            throw Error(fmt::format("the raster backend has the methods cube (default) and directional, not {}",
                                    trace_method_name(method)),
                        "method");
        return std::make_unique<visibility::RasterTracer>(method, resolution); // throws without OpenGL 4.3
    }
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
