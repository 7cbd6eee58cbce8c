// Internal: the CUDA tracer's kernels run on the host, thread body by thread
// body (tracer_hd.h), as a VisibilityTracer: "cuda-emulation". It gives the
// bits the GPU gives, in every build, so the CPU tests check the GPU's
// arithmetic against the Embree backend.
#pragma once

#include <cstdint>
#include <vector>

#include "skybake/visibility.h"
#include "visibility/cuda/bvh.h"
#include "visibility/cuda/tracer_hd.h"

namespace skybake::visibility {

// The inverse of a visiting order: position[order[j]] = j.
std::vector<std::uint32_t> visiting_positions(std::span<const std::uint32_t> order);

// The launch parameters that do not depend on the chunk.
GpuTraceParams trace_params(const TraceRule& rule, const std::uint32_t* position, const Bvh& bvh, bool cull_back);

class EmulatedCudaTracer final : public VisibilityTracer {
public:
    // method PerPolygon runs the per-vertex loop, which decides the same test
    // on the same triangles. chunk_vertices: the most vertices per trace().
    explicit EmulatedCudaTracer(TraceMethod method = TraceMethod::Bvh, std::uint32_t chunk_vertices = 4096);

    const char* name() const override { return "cuda-emulation"; }
    TraceMethod method() const override { return method_; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override;
    std::uint32_t set_rule(const TraceRule& rule) override;
    void trace(const TraceChunk& chunk) override;

    const Bvh& bvh() const { return bvh_; }

private:
    TraceMethod method_;
    std::uint32_t chunk_vertices_;
    Bvh bvh_;
    bool cull_back_ = false;
    TraceRule rule_;
    std::vector<std::uint32_t> position_;
};

} // namespace skybake::visibility
