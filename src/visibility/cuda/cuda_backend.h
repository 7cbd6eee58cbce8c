// Internal: the CUDA visibility backend ("cuda"). This header compiles
// without CUDA; the class exists only in builds that have it.
//
// set_mesh() builds the BVH on the CPU (cuda/bvh.h) and uploads it with the
// triangle soup. trace() runs the kernels of cuda_backend.cu over one chunk of
// vertices and leaves the words in device memory (device_words()), copying
// them back when the chunk asks; occluded() and intersect() trace batches of
// rays.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "skybake/visibility.h"

namespace skybake::visibility {

// Create the CUDA backend on device 0. Throw skybake::Error (where: "device")
// when the build has no CUDA or the machine no CUDA device.
std::unique_ptr<RayQueries> make_cuda_ray_queries();
std::unique_ptr<VisibilityTracer> make_cuda_tracer(TraceMethod method);

#if defined(SKYBAKE_HAS_CUDA)
struct Bvh;

class CudaBackend final : public RayQueries, public VisibilityTracer {
public:
    // Work and memory per launch. The defaults keep each kernel well under a
    // second on current GPUs (the seed's watchdog concern) and leave the rest
    // of the device's memory alone.
    struct Limits {
        std::uint64_t slots_per_launch = std::uint64_t(1) << 25; // vertex × direction slots (bvh)
        std::uint64_t tests_per_launch = std::uint64_t(1) << 36; // slot × triangle tests (per-vertex, per-polygon)
        std::uint64_t memory_bytes = 0; // device memory the backend may use; 0: 90% of what is free
    };

    explicit CudaBackend(TraceMethod method = TraceMethod::Bvh);
    ~CudaBackend() override;
    CudaBackend(const CudaBackend&) = delete;
    CudaBackend& operator=(const CudaBackend&) = delete;

    const char* name() const override { return "cuda"; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override;
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override;
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override;
    TraceMethod method() const override;
    std::string device_name() const override;
    std::uint32_t set_rule(const TraceRule& rule) override;
    void trace(const TraceChunk& chunk) override;
    bool device_words_supported() const override { return true; }
    const std::uint32_t* device_words() const override;

    // Set before set_rule(), which sizes chunks by them.
    void set_limits(const Limits& limits);
    const Limits& limits() const;
    // trace() calls (kernel launches of each kind) since the last set_rule().
    std::uint32_t last_chunk_count() const;
    // The BVH of the current mesh (host copy).
    const Bvh& bvh() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};
#endif

} // namespace skybake::visibility
