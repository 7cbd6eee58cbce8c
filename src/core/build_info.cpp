#include <atomic>

#include "skybake/core.h"
#include "skybake/error.h"

namespace skybake {

namespace {
std::atomic<bool> g_quiet{false};
}

const char* version() { return SKYBAKE_VERSION_STRING; }

bool build_has_cuda() {
#if defined(SKYBAKE_HAS_CUDA)
    return true;
#else
    return false;
#endif
}

#if !defined(SKYBAKE_HAS_CUDA)
int cuda_device_count() { return 0; }
std::string cuda_device_name() { return {}; }
std::string cuda_device_problem() { return "this build has no CUDA support"; }
#endif

void require_cuda_device(const std::string& where) {
    if (!build_has_cuda())
        throw Error("this build has no CUDA support; rebuild with the CUDA toolkit installed (nvcc on PATH or in "
                    "/usr/local/cuda)",
                    where);
    if (cuda_device_count() == 0)
        throw Error("no usable CUDA device (" + cuda_device_problem() + "); use the CPU instead", where);
}

Device parse_device(const std::string& name, const std::string& where) {
    if (name == "cpu")
        return Device::Cpu;
    if (name == "cuda")
        return Device::Cuda;
    throw Error("unknown device '" + name + "'; use cpu or cuda", where);
}

void set_quiet(bool q) { g_quiet.store(q); }
bool quiet() { return g_quiet.load(); }

} // namespace skybake
