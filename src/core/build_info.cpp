#include <atomic>

#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/names.h"

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

namespace {
int selected_cuda_device = 0;
} // namespace

void set_cuda_device_index(int index) { selected_cuda_device = index < 0 ? 0 : index; }
int cuda_device_index() {
    const int n = cuda_device_count();
    return n > 0 ? selected_cuda_device % n : 0;
}

#if !defined(SKYBAKE_HAS_CUDA)
void use_cuda_device_on_this_thread() {}
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

namespace {
constexpr NamedValue<Device> kDeviceNames[] = {{Device::Cpu, "cpu"}, {Device::Cuda, "cuda"}};
} // namespace

Device parse_device(const std::string& name, const std::string& where) {
    return parse_name(kDeviceNames, name, "device", where);
}

const char* device_name(Device device) { return name_of(kDeviceNames, device); }

void set_quiet(bool q) { g_quiet.store(q); }
bool quiet() { return g_quiet.load(); }

} // namespace skybake
