// CUDA device discovery. Compiled only when the build has CUDA; without a
// driver or a GPU the count is zero, and cuda_device_problem() names the
// runtime's error, so that a broken driver is not mistaken for "no GPU".
#include <cuda_runtime.h>

#include <string>

#include "skybake/core.h"

namespace skybake {

namespace {
cudaError_t device_count(int& count) {
    count = 0;
    const cudaError_t e = cudaGetDeviceCount(&count);
    if (e != cudaSuccess) {
        cudaGetLastError(); // clear the sticky error
        count = 0;
    }
    return e;
}
} // namespace

int cuda_device_count() {
    int count = 0;
    device_count(count);
    return count;
}

std::string cuda_device_problem() {
    int count = 0;
    const cudaError_t e = device_count(count);
    if (e == cudaSuccess)
        return count > 0 ? std::string() : std::string("the CUDA runtime reports 0 devices");
    return std::string(cudaGetErrorName(e)) + " (error " + std::to_string(int(e)) + "): " + cudaGetErrorString(e);
}

void use_cuda_device_on_this_thread() {
    if (cuda_device_count() > 0 && cudaSetDevice(cuda_device_index()) != cudaSuccess)
        cudaGetLastError(); // the backends report the error when they use the device
}

std::string cuda_device_name() {
    if (cuda_device_count() == 0)
        return {};
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, cuda_device_index()) != cudaSuccess)
        return {};
    return prop.name;
}

} // namespace skybake
