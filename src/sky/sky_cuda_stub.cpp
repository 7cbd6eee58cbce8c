// Without CUDA in the build, the GPU entry points explain why they cannot run.
#if !defined(SKYBAKE_HAS_CUDA)
#include "skybake/core.h"
#include "skybake/sky.h"

namespace skybake {

void evaluate_sky_cuda(const SkyModel&, std::span<const SkySample>, std::span<glm::vec3>) {
    require_cuda_device("--device cuda"); // throws
}

Image render_sky_cuda(const SkyModel&, const SkyRenderSettings&) {
    require_cuda_device("--device cuda"); // throws
    return {};
}

} // namespace skybake
#endif
