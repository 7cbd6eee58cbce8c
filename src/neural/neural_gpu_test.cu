// The SKYBAKE_HD forward pass of the neural sky (mlp_hd.h) compiled by nvcc
// and run in a kernel: it must match the CPU's scalar pass.
#include <cuda_runtime.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "neural/mlp_hd.h"
#include "skybake/core.h"
#include "skybake/neural.h"
#include "core/gpu_test.h"

namespace {

__global__ void sky_kernel(skybake::neural::MlpHD m, int n, const float4* in, float3* out) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n)
        return;
    const glm::vec3 c = skybake::neural::neural_sky(m, in[i].x, in[i].y, in[i].z, in[i].w);
    out[i] = make_float3(c.x, c.y, c.z);
}

} // namespace

TEST(NeuralGpu, ForwardPassMatchesTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    for (const char* topology : {"paper", "shared:32x16"}) {
        skybake::NeuralSky net;
        net.topology = skybake::parse_topology(topology);
        net.encoding.max_n = 0.15;
        net.weights.resize(std::size_t(net.topology.weight_count()));
        std::uint64_t state = 7;
        for (float& w : net.weights) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            w = float(double(state >> 11) * 0x1.0p-53 * 3.0 - 1.5);
        }
        const std::vector<skybake::SkySample> s = skybake::draw_sky_samples(4096, 3);
        const int n = int(s.size());
        std::vector<float4> in(s.size());
        for (std::size_t i = 0; i < s.size(); ++i)
            in[i] = make_float4(s[i].cos_view_zenith, s[i].cos_view_sun, s[i].cos_sun_zenith, s[i].density);
        float4* d_in = nullptr;
        float3* d_out = nullptr;
        float* d_w = nullptr;
        ASSERT_EQ(cudaMalloc(&d_in, in.size() * sizeof(float4)), cudaSuccess);
        ASSERT_EQ(cudaMalloc(&d_out, in.size() * sizeof(float3)), cudaSuccess);
        ASSERT_EQ(cudaMalloc(&d_w, net.weights.size() * sizeof(float)), cudaSuccess);
        cudaMemcpy(d_in, in.data(), in.size() * sizeof(float4), cudaMemcpyHostToDevice);
        cudaMemcpy(d_w, net.weights.data(), net.weights.size() * sizeof(float), cudaMemcpyHostToDevice);
        // The flat layout of the CPU, pointing at device memory.
        skybake::neural::MlpHD m;
        {
            const std::vector<int> widths = [&] {
                std::vector<int> w{4};
                w.insert(w.end(), net.topology.hidden.begin(), net.topology.hidden.end());
                w.push_back(net.topology.outputs_per_subnet());
                return w;
            }();
            m.subnets = net.topology.subnet_count();
            m.layers = int(widths.size()) - 1;
            for (int l = 0; l <= m.layers; ++l)
                m.width[l] = widths[std::size_t(l)];
            m.subnet_params = net.topology.subnet_weight_count();
            m.brightness = skybake::neural::kBrightnessLog;
            m.max_n = float(net.encoding.max_n);
            m.log_range = float(net.encoding.log_range);
            m.weights = d_w;
        }
        sky_kernel<<<(n + 127) / 128, 128>>>(m, n, d_in, d_out);
        std::vector<float3> out(s.size());
        ASSERT_EQ(cudaMemcpy(out.data(), d_out, out.size() * sizeof(float3), cudaMemcpyDeviceToHost), cudaSuccess);
        cudaFree(d_in);
        cudaFree(d_out);
        cudaFree(d_w);
        double worst = 0.0;
        int lit = 0;
        for (std::size_t i = 0; i < s.size(); ++i) {
            const glm::vec3 c = skybake::neural_sky_radiance(net, s[i]);
            const double d = std::sqrt(double(out[i].x - c.x) * (out[i].x - c.x) +
                                       double(out[i].y - c.y) * (out[i].y - c.y) +
                                       double(out[i].z - c.z) * (out[i].z - c.z));
            const double norm = std::sqrt(double(c.x) * c.x + double(c.y) * c.y + double(c.z) * c.z);
            if (norm > 0.0) {
                ++lit;
                worst = std::max(worst, d / norm);
            }
        }
        EXPECT_GT(lit, 100);
        // Device exp2f/expf are within 2 ulp of the host's; the log decoding multiplies by 13.8.
        EXPECT_LT(worst, 2e-5) << topology;
    }
}
