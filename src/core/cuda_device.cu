// CUDA device discovery. Compiled only when the build has CUDA; without a
// driver or a GPU every query reports zero devices instead of failing.
#include <cuda_runtime.h>

#include "skybake/core.h"

namespace skybake {

int cuda_device_count() {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess) {
        cudaGetLastError(); // clear the sticky error
        return 0;
    }
    return count;
}

std::string cuda_device_name() {
    if (cuda_device_count() == 0)
        return {};
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess)
        return {};
    return prop.name;
}

} // namespace skybake
