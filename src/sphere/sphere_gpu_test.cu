// The SKYBAKE_HD sphere maths compiled by nvcc and run in a kernel: SH values
// and per-vertex rotations must match the CPU (double) results.
#include <cuda_runtime.h>
#include <gtest/gtest.h>

#include <vector>

#include "skybake/core.h"
#include "skybake/sh.h"
#include "skybake/sphere.h"
#include "sphere/random_rotation.h"
#include "sphere/sh_eval.h"
#include "core/gpu_test.h"

namespace {

constexpr int kLmax = 10;
constexpr int kCount = (kLmax + 1) * (kLmax + 1);

__global__ void eval_kernel(int n, const float3* dirs, float* sh, float* rot) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n)
        return;
    skybake::sphere::sh_eval_hd<float>(kLmax, dirs[i].x, dirs[i].y, dirs[i].z, sh + i * kCount);
    const glm::mat3 r = skybake::sphere::vertex_rotation_hd<float>(std::uint32_t(i), 42);
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k)
            rot[i * 9 + c * 3 + k] = r[c][k];
}

} // namespace

TEST(SphereGpu, ShAndRotationsMatchTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const int n = 1024;
    const skybake::SphereRule rule = skybake::marsaglia_rule(n, 5);
    std::vector<float3> dirs(n);
    for (int i = 0; i < n; ++i)
        dirs[i] = make_float3(float(rule.points[i].x), float(rule.points[i].y), float(rule.points[i].z));
    float3* d_dirs = nullptr;
    float *d_sh = nullptr, *d_rot = nullptr;
    ASSERT_EQ(cudaMalloc(&d_dirs, n * sizeof(float3)), cudaSuccess);
    ASSERT_EQ(cudaMalloc(&d_sh, std::size_t(n) * kCount * sizeof(float)), cudaSuccess);
    ASSERT_EQ(cudaMalloc(&d_rot, std::size_t(n) * 9 * sizeof(float)), cudaSuccess);
    cudaMemcpy(d_dirs, dirs.data(), n * sizeof(float3), cudaMemcpyHostToDevice);
    eval_kernel<<<(n + 127) / 128, 128>>>(n, d_dirs, d_sh, d_rot);
    std::vector<float> sh(std::size_t(n) * kCount), rot(std::size_t(n) * 9);
    ASSERT_EQ(cudaMemcpy(sh.data(), d_sh, sh.size() * sizeof(float), cudaMemcpyDeviceToHost), cudaSuccess);
    ASSERT_EQ(cudaMemcpy(rot.data(), d_rot, rot.size() * sizeof(float), cudaMemcpyDeviceToHost), cudaSuccess);
    cudaFree(d_dirs);
    cudaFree(d_sh);
    cudaFree(d_rot);
    double worst_sh = 0.0, worst_rot = 0.0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 p(dirs[i].x, dirs[i].y, dirs[i].z);
        const std::vector<double> y = skybake::sh_eval(kLmax, p);
        for (int k = 0; k < kCount; ++k)
            worst_sh = std::max(worst_sh, std::abs(double(sh[std::size_t(i) * kCount + k]) - y[std::size_t(k)]));
        const glm::dmat3 r = skybake::vertex_rotation(std::uint32_t(i), 42);
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k)
                worst_rot = std::max(worst_rot, std::abs(double(rot[std::size_t(i) * 9 + c * 3 + k]) - r[c][k]));
    }
    EXPECT_LT(worst_sh, 2e-5);
    EXPECT_LT(worst_rot, 1e-6);
}
