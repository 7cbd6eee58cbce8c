// Internal: the CUDA visibility backend ("cuda"). This header compiles
// without CUDA; the class exists only in builds that have it.
//
// set_mesh() builds the BVH on the CPU (cuda/bvh.h) and uploads it with the
// triangle soup. bake() runs the kernels of cuda_backend.cu over chunks of
// vertices on two streams, so that one chunk's transfers overlap the other's
// kernels; occluded() and intersect() trace batches of rays.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "skybake/visibility.h"

namespace skybake::visibility {

// Creates the CUDA backend on device 0. Throws skybake::Error naming
// "--backend cuda" when the build has no CUDA or the machine no CUDA device.
std::unique_ptr<VisibilityBackend> make_cuda_backend();

#if defined(SKYBAKE_HAS_CUDA)
struct Bvh;

class CudaBackend final : public VisibilityBackend {
public:
    // Work and memory per launch. The defaults keep each kernel well under a
    // second on current GPUs (the seed's watchdog concern) and leave the rest
    // of the device's memory alone.
    struct Limits {
        std::uint64_t slots_per_launch = std::uint64_t(1) << 25; // vertex × direction slots (bvh)
        std::uint64_t tests_per_launch = std::uint64_t(1) << 36; // slot × triangle tests (per-vertex, per-polygon)
        std::uint64_t memory_bytes = 0; // device memory the backend may use; 0: 90% of what is free
    };

    CudaBackend();
    ~CudaBackend() override;
    CudaBackend(const CudaBackend&) = delete;
    CudaBackend& operator=(const CudaBackend&) = delete;

    const char* name() const override { return "cuda"; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override;
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override;
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override;
    void bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out) override;

    void set_limits(const Limits& limits);
    const Limits& limits() const;
    std::string device_name() const;
    // Chunks (kernel launches of each kind) of the last bake.
    std::uint32_t last_chunk_count() const;
    // The BVH of the current mesh (host copy).
    const Bvh& bvh() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};
#endif

} // namespace skybake::visibility
