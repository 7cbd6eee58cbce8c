// Without CUDA in the build the shading reduction runs on the CPU only.
#if !defined(SKYBAKE_HAS_CUDA)
#include "bake/shading_cuda.h"
#include "skybake/error.h"

namespace skybake::bake {

bool shading_cuda_available() {
    return false;
}

void reduce_shading_cuda(const VisibilityRule&, const VisibilityChunk&, bool, ShadingResult*) {
    throw Error("this build has no CUDA support", "device_words");
}

} // namespace skybake::bake
#endif
