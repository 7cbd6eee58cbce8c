// The names of the back-face modes and trace methods, and the generic tracer
// on top of RayQueries::occluded() (used by the brute-force oracle; the
// Embree and CUDA backends have their own loops). The backends themselves
// are registered in registry.cpp.
#include <algorithm>

#include <fmt/format.h>

#include "core/parallel.h"
#include "skybake/error.h"
#include "skybake/names.h"
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
    {TraceMethod::PerVertex, "per-vertex", "cuda backend: every triangle for every ray"},
    {TraceMethod::PerPolygon, "per-polygon", "cuda backend: every triangle, cached in shared memory"},
    {TraceMethod::Cube, "cube", "raster backend, its default: a depth cube map at each vertex"},
    {TraceMethod::Directional, "directional", "raster backend: a depth map per direction"},
};

} // namespace

const char* back_faces_name(BackFaces mode) { return name_of(kBackFacesNames, mode); }

BackFaces parse_back_faces(const std::string& text) {
    return parse_name(kBackFacesNames, text, "back-face mode", "back_faces");
}

const char* trace_method_name(TraceMethod method) { return name_of(kTraceMethodNames, method); }

TraceMethod parse_trace_method(const std::string& text) {
    return parse_name(kTraceMethodNames, text, "method", "method");
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
