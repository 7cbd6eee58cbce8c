// Without CUDA in the build, the GPU entry points explain why they cannot run.
#if !defined(SKYBAKE_HAS_CUDA)
#include "neural/neural_cuda.h"
#include "skybake/core.h"

namespace skybake {

void evaluate_neural_sky_cuda(const NeuralSky&, std::span<const SkySample>, std::span<glm::vec3>) {
    require_cuda_device("device"); // throws
}

Image render_neural_sky_cuda(const NeuralSky&, const SkyModel&, const SkyRenderSettings&) {
    require_cuda_device("device"); // throws
    return {};
}

namespace neural {
GpuThroughput measure_neural_sky_cuda(const NeuralSky&, std::uint64_t, bool) {
    require_cuda_device("device"); // throws
    return {};
}
} // namespace neural

} // namespace skybake
#endif
