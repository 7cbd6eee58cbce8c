// Without CUDA in the build, asking for the cuda backend explains why it
// cannot run.
#if !defined(SKYBAKE_HAS_CUDA)
#include "skybake/error.h"
#include "visibility/cuda/cuda_backend.h"

namespace skybake::visibility {

std::unique_ptr<VisibilityBackend> make_cuda_backend() {
    throw Error("this build has no CUDA support; rebuild with the CUDA toolkit installed (nvcc on PATH or in "
                "/usr/local/cuda), or use --device cpu",
                "--backend cuda");
}

} // namespace skybake::visibility
#endif
