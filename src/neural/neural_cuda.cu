// The neural sky on the GPU (seed 000, section VI: the network in a vertex
// program; here a CUDA kernel).
//
// The weights live in constant memory: every thread of a warp reads the same
// weight at the same time, which constant memory broadcasts. The seed's
// topology (four 4-8-4-1 sub-networks) has a fully unrolled kernel with the
// activation f(x) = 1/(1 + 2^(2x)) on the special-function unit
// (ex2.approx, rcp.approx); other topologies run the shared generic forward
// pass of mlp_hd.h, reading the weights from constant memory when they fit.
#include <algorithm>

#include "core/cuda_util.h"
#include "neural/internal.h"
#include "neural/mlp_hd.h"
#include "neural/neural_cuda.h"
#include "neural/render_hd.h"
#include "sky/device.h"
#include "skybake/core.h"

namespace skybake::neural {

namespace {

constexpr int kConstantFloats = 16384; // 64 KiB
__constant__ float c_weights[kConstantFloats];

constexpr unsigned kBlock = 256;

__device__ __forceinline__ float fast_exp2(float x) {
    float y;
    asm("ex2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
    return y;
}

__device__ __forceinline__ float fast_rcp(float x) {
    float y;
    asm("rcp.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
    return y;
}

__device__ __forceinline__ float fast_activation(float x) { return fast_rcp(1.0f + fast_exp2(2.0f * x)); }

// One 4 -> H1 -> H2 -> 1 sub-network, weights as in mlp_hd.h: per layer
// W [out][in] row-major, then b [out].
template <int H1, int H2>
__device__ __forceinline__ float subnet_fixed(const float* __restrict__ w, const float in[4]) {
    float h1[H1], h2[H2];
#pragma unroll
    for (int r = 0; r < H1; ++r) {
        float s = w[4 * H1 + r];
#pragma unroll
        for (int c = 0; c < 4; ++c)
            s = fmaf(w[r * 4 + c], in[c], s);
        h1[r] = fast_activation(s);
    }
    const float* w1 = w + 5 * H1;
#pragma unroll
    for (int r = 0; r < H2; ++r) {
        float s = w1[H2 * H1 + r];
#pragma unroll
        for (int c = 0; c < H1; ++c)
            s = fmaf(w1[r * H1 + c], h1[c], s);
        h2[r] = fast_activation(s);
    }
    const float* w2 = w1 + H2 * H1 + H2;
    float s = w2[H2];
#pragma unroll
    for (int c = 0; c < H2; ++c)
        s = fmaf(w2[c], h2[c], s);
    return fast_activation(s);
}

__device__ __forceinline__ glm::vec3 decode_fast(const MlpHD& m, const float enc[4]) {
    const float mm = (enc[3] - kEncodeOffset) * (1.0f / kEncodeScale);
    if (!(mm > 0.0f))
        return glm::vec3(0.0f);
    const float n = m.brightness == kBrightnessLinear ? mm * m.max_n : m.max_n * __expf(m.log_range * (mm - 1.0f));
    return glm::vec3(decode_unit(enc[0]) * n, decode_unit(enc[1]) * n, decode_unit(enc[2]) * n);
}

// The seed topology: 4 independent 4-8-4-1 sub-networks, 81 weights each.
__device__ __forceinline__ glm::vec3 seed_network(const MlpHD& m, const float in[4]) {
    float enc[4];
#pragma unroll
    for (int s = 0; s < 4; ++s)
        enc[s] = subnet_fixed<8, 4>(c_weights + s * 81, in);
    return decode_fast(m, enc);
}

// `weights` is a device buffer, or nullptr for the constant-memory copy.
// `in` are the network's inputs (encode_inputs); in[1] is cos β0 in every encoding.
__device__ __forceinline__ glm::vec3 generic_network(MlpHD m, const float* weights, const float in[4]) {
    m.weights = weights ? weights : c_weights;
    float enc[kMaxOutputs];
    mlp_forward(m, in, enc);
    return decode_sky(m, enc, in[1]);
}

// The same for residual outputs, which need the sample's analytic march.
__device__ __forceinline__ glm::vec3 residual_network(MlpHD m, const float* weights, const float in[4], float cv,
                                                      float cvs, float cs, float rho) {
    m.weights = weights ? weights : c_weights;
    float enc[kMaxOutputs], base[kMaxOutputs];
    mlp_forward(m, in, enc);
    analytic_base(m, cv, cvs, cs, rho, base);
    return decode_sky(m, enc, cvs, base);
}

template <bool Fixed>
__global__ void neural_kernel(MlpHD m, const float* weights, const SkySample* samples, glm::vec3* out,
                              std::size_t n) {
    const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n)
        return;
    const SkySample s = samples[i];
    float in[kMaxInputs];
    encode_inputs(m, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density, in);
    if (!Fixed && m.output_kind == kOutputsResidual)
        out[i] = residual_network(m, weights, in, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith, s.density);
    else
        out[i] = Fixed ? seed_network(m, in) : generic_network(m, weights, in);
}

template <bool Fixed>
__global__ void throughput_kernel(MlpHD m, const float* weights, std::uint64_t n, float* checksum) {
    float acc = 0.0f;
    const std::uint64_t stride = std::uint64_t(gridDim.x) * blockDim.x;
    for (std::uint64_t i = std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) {
        float x[4], in[kMaxInputs];
        throughput_inputs(std::uint32_t(i), x);
        encode_inputs(m, x[0], x[1], x[2], x[3], in);
        const glm::vec3 c = !Fixed && m.output_kind == kOutputsResidual
                                ? residual_network(m, weights, in, x[0], x[1], x[2], x[3])
                                : Fixed ? seed_network(m, in) : generic_network(m, weights, in);
        acc += c.x + c.y + c.z;
    }
    atomicAdd(checksum, acc);
}

__global__ void neural_render_kernel(sky::RenderHD p, MlpHD m, const float* weights, float* rgb) {
    const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= p.width || y >= p.height)
        return;
    m.weights = weights ? weights : c_weights; // nullptr: the constant-memory copy
    glm::vec3 d, c(0.0f);
    if (sky::pixel_direction(p, x, y, d))
        c = shade_ray_neural(p, m, d);
    float* px = rgb + (std::size_t(y) * std::size_t(p.width) + std::size_t(x)) * 3;
    px[0] = c.x;
    px[1] = c.y;
    px[2] = c.z;
}

bool is_seed_topology(const MlpHD& m) {
    return m.output_kind == kOutputsRadiance && m.subnets == 4 && m.layers == 3 && m.width[0] == 4 &&
           m.width[1] == 8 && m.width[2] == 4 && m.width[3] == 1 && m.subnet_params == 81;
}

// Puts the weights where the kernels read them: constant memory when they fit
// (returns nullptr), else a device buffer (returns its pointer).
const float* place_weights(const NeuralSky& net, cuda::DeviceBuffer<float>& global) {
    if (net.weights.size() <= std::size_t(kConstantFloats)) {
        SKYBAKE_CUDA_CHECK(cudaMemcpyToSymbol(c_weights, net.weights.data(), net.weights.size() * sizeof(float)));
        return nullptr;
    }
    global.upload(net.weights.data(), net.weights.size());
    return global.data();
}

} // namespace

GpuThroughput measure_neural_sky_cuda(const NeuralSky& net, std::uint64_t samples, bool force_generic) {
    require_cuda_device("device");
    const MlpHD m = make_mlp_hd(net);
    cuda::DeviceBuffer<float> global;
    const float* weights = place_weights(net, global);
    const bool fixed = is_seed_topology(m) && !force_generic;
    cuda::DeviceBuffer<float> checksum(1);
    SKYBAKE_CUDA_CHECK(cudaMemset(checksum.data(), 0, sizeof(float)));
    int sms = 0;
    SKYBAKE_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, 0));
    const unsigned grid = unsigned(sms) * 16;
    auto launch = [&] {
        if (fixed)
            throughput_kernel<true><<<grid, kBlock>>>(m, weights, samples, checksum.data());
        else
            throughput_kernel<false><<<grid, kBlock>>>(m, weights, samples, checksum.data());
    };
    launch(); // warm up
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    SKYBAKE_CUDA_CHECK(cudaMemset(checksum.data(), 0, sizeof(float))); // the timed run's sum only
    cudaEvent_t start, stop;
    SKYBAKE_CUDA_CHECK(cudaEventCreate(&start));
    SKYBAKE_CUDA_CHECK(cudaEventCreate(&stop));
    SKYBAKE_CUDA_CHECK(cudaEventRecord(start));
    launch();
    SKYBAKE_CUDA_CHECK(cudaEventRecord(stop));
    SKYBAKE_CUDA_CHECK(cudaEventSynchronize(stop));
    float ms = 0.0f;
    SKYBAKE_CUDA_CHECK(cudaEventElapsedTime(&ms, start, stop));
    cudaEventDestroy(start);
    cudaEventDestroy(stop);
    float sum = 0.0f;
    checksum.download(&sum, 1);
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    GpuThroughput t;
    t.seconds = double(ms) * 1e-3;
    t.samples_per_second = t.seconds > 0.0 ? double(samples) / t.seconds : 0.0;
    t.fixed_path = fixed;
    t.checksum = sum;
    return t;
}

} // namespace skybake::neural

namespace skybake {

void evaluate_neural_sky_cuda(const NeuralSky& net, std::span<const SkySample> samples, std::span<glm::vec3> out) {
    using namespace neural;
    require_cuda_device("device");
    if (samples.size() != out.size())
        throw Error("evaluate_neural_sky_cuda: output size differs from the sample count");
    if (samples.empty())
        return;
    const MlpHD m = make_mlp_hd(net);
    cuda::DeviceBuffer<float> global;
    const float* weights = place_weights(net, global);
    const bool fixed = is_seed_topology(m);
    const std::size_t chunk = std::min<std::size_t>(samples.size(), std::size_t(1) << 24);
    cuda::DeviceBuffer<SkySample> d_in(chunk);
    cuda::DeviceBuffer<glm::vec3> d_out(chunk);
    for (std::size_t begin = 0; begin < samples.size(); begin += chunk) {
        const std::size_t n = std::min(chunk, samples.size() - begin);
        d_in.upload(samples.data() + begin, n);
        if (fixed)
            neural_kernel<true><<<cuda::grid_for(n, kBlock), kBlock>>>(m, weights, d_in.data(), d_out.data(), n);
        else
            neural_kernel<false><<<cuda::grid_for(n, kBlock), kBlock>>>(m, weights, d_in.data(), d_out.data(), n);
        SKYBAKE_CUDA_CHECK(cudaGetLastError());
        d_out.download(out.data() + begin, n);
        SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    }
}

Image render_neural_sky_cuda(const NeuralSky& net, const SkyModel& model, const SkyRenderSettings& settings) {
    using namespace neural;
    net.validate("neural sky");
    sky::RenderHD p = sky::make_render_hd(model, settings);
    require_cuda_device("device");
    // The tables (for the ground and the sun) on the device.
    std::vector<cuda::DeviceBuffer<float>> tables(std::size_t(p.atm.count));
    for (int k = 0; k < p.atm.count; ++k) {
        const std::size_t n = std::size_t(p.atm.comp[k].table.rows) * std::size_t(p.atm.comp[k].table.cols);
        tables[std::size_t(k)].upload(p.atm.comp[k].table.L, n);
        p.atm.comp[k].table.L = tables[std::size_t(k)].data();
    }
    const MlpHD m = make_mlp_hd(net);
    cuda::DeviceBuffer<float> global;
    const float* weights = place_weights(net, global);
    Image image(settings.width, settings.height);
    cuda::DeviceBuffer<float> d_rgb(image.rgb.size());
    const dim3 block(16, 8);
    const dim3 grid(cuda::grid_for(std::size_t(p.width), block.x), cuda::grid_for(std::size_t(p.height), block.y));
    neural_render_kernel<<<grid, block>>>(p, m, weights, d_rgb.data());
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    d_rgb.download(image.rgb.data(), image.rgb.size());
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    return image;
}

} // namespace skybake
