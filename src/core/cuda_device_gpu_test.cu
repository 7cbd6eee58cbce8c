// Runs a trivial kernel when a GPU exists; skips cleanly otherwise.
#include <cuda_runtime.h>
#include <gtest/gtest.h>

#include "skybake/core.h"
#include "core/gpu_test.h"

namespace {
__global__ void saxpy(int n, float a, const float* x, float* y) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n)
        y[i] = a * x[i] + y[i];
}
} // namespace

TEST(CudaDevice, BuildReportsCuda) { EXPECT_TRUE(skybake::build_has_cuda()); }

TEST(CudaDevice, KernelRuns) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const int n = 1000;
    std::vector<float> x(n), y(n);
    for (int i = 0; i < n; ++i) {
        x[i] = float(i);
        y[i] = 1.0f;
    }
    float *dx = nullptr, *dy = nullptr;
    ASSERT_EQ(cudaMalloc(&dx, n * sizeof(float)), cudaSuccess);
    ASSERT_EQ(cudaMalloc(&dy, n * sizeof(float)), cudaSuccess);
    cudaMemcpy(dx, x.data(), n * sizeof(float), cudaMemcpyHostToDevice);
    cudaMemcpy(dy, y.data(), n * sizeof(float), cudaMemcpyHostToDevice);
    saxpy<<<(n + 255) / 256, 256>>>(n, 2.0f, dx, dy);
    ASSERT_EQ(cudaMemcpy(y.data(), dy, n * sizeof(float), cudaMemcpyDeviceToHost), cudaSuccess);
    cudaFree(dx);
    cudaFree(dy);
    for (int i = 0; i < n; ++i)
        EXPECT_EQ(y[i], 2.0f * float(i) + 1.0f);
}
