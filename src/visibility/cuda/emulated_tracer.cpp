// The CUDA tracer on the host (see emulated_tracer.h).
#include "visibility/cuda/emulated_tracer.h"

#include <algorithm>

#include "core/parallel.h"
#include "skybake/mesh.h"

namespace skybake::visibility {

std::vector<std::uint32_t> visiting_positions(std::span<const std::uint32_t> order) {
    std::vector<std::uint32_t> position(order.size());
    for (std::size_t j = 0; j < order.size(); ++j)
        position[order[j]] = std::uint32_t(j);
    return position;
}

GpuTraceParams trace_params(const TraceRule& rule, const std::uint32_t* position, const Bvh& bvh, bool cull_back) {
    GpuTraceParams p;
    p.bvh = bvh.view();
    p.soup = bvh.soup.data();
    p.soup_count = std::uint32_t(bvh.soup.size());
    p.points = rule.points.data();
    p.position = position;
    p.directions = std::uint32_t(rule.points.size());
    p.words = rule.words_per_vertex;
    p.t_max = rule.t_max;
    p.cull_back = cull_back;
    p.rotate = rule.rotate;
    return p;
}

EmulatedCudaTracer::EmulatedCudaTracer(TraceMethod method, std::uint32_t chunk_vertices)
    : method_(method), chunk_vertices_(std::max<std::uint32_t>(1, chunk_vertices)) {}

void EmulatedCudaTracer::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    bvh_ = build_bvh(mesh);
    cull_back_ = back_faces == BackFaces::Ignore;
}

std::uint32_t EmulatedCudaTracer::set_rule(const TraceRule& rule) {
    rule_ = rule;
    position_ = visiting_positions(rule.order);
    return chunk_vertices_;
}

void EmulatedCudaTracer::trace(const TraceChunk& chunk) {
    const std::uint32_t words = rule_.words_per_vertex;
    const GpuTraceParams base = trace_params(rule_, position_.data(), bvh_, cull_back_);
    // Vertices are independent: split the chunk over threads.
    parallel_for(chunk.count, 16, [&](std::size_t b, std::size_t e) {
        std::vector<std::uint32_t> visit((e - b) * words);
        GpuTraceParams p = base;
        p.vertex_count = std::uint32_t(e - b);
        p.origins = chunk.origins.data() + b;
        p.normals = chunk.normals.data() + b;
        p.rotations = rule_.rotate ? chunk.rotations.data() + b : nullptr;
        p.visit_words = visit.data();
        p.rule_words = chunk.words.data() + b * words;
        emulate_trace_chunk(p, method_);
    });
}

} // namespace skybake::visibility
