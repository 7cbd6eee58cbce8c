// Without CUDA in the build, asking for the cuda backend explains why it
// cannot run.
#if !defined(SKYBAKE_HAS_CUDA)
#include "skybake/error.h"
#include "visibility/cuda/cuda_backend.h"

namespace skybake::visibility {

namespace {
[[noreturn]] void no_cuda() {
    throw Error("this build has no CUDA support; rebuild with the CUDA toolkit installed (nvcc on PATH or in "
                "/usr/local/cuda), or bake on the CPU",
                "device");
}
} // namespace

std::unique_ptr<RayQueries> make_cuda_ray_queries() { no_cuda(); }
std::unique_ptr<VisibilityTracer> make_cuda_tracer(TraceMethod) { no_cuda(); }

} // namespace skybake::visibility
#endif
