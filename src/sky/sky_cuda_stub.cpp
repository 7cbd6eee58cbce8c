// Without CUDA in the build, the GPU entry points explain why they cannot run.
#if !defined(SKYBAKE_HAS_CUDA)
#include "skybake/error.h"
#include "skybake/core.h"
#include "skybake/sky.h"

namespace skybake {

void evaluate_sky_cuda(const SkyModel&, std::span<const SkySample>, std::span<glm::vec3>) {
    require_cuda_device("device"); // throws
}

Image render_sky_cuda(const SkyModel&, const SkyRenderSettings& settings) {
    if (settings.method != SkyMethod::Tables) // the same first check as the CUDA build's
        throw Error("the exact method runs on the CPU only; use the CPU or the tables method", "device");
    require_cuda_device("device"); // throws
    return {};
}

} // namespace skybake
#endif
