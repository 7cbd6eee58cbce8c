// The sky model on the GPU: the seed's marching sum over the optical-length
// tables (Pietras & Rudnicki, section II) and the renderer, running the same
// SKYBAKE_HD functions as the CPU path (src/sky/sky_hd.h, render_hd.h).
#include <algorithm>

#include "core/cuda_util.h"
#include "core/parallel.h"
#include "sky/internal.h"
#include "skybake/core.h"
#include "skybake/sky.h"

namespace skybake {

namespace {

constexpr unsigned kBlock = 128;
constexpr std::size_t kChunk = std::size_t(1) << 22; // samples per launch: bounded memory, short kernels

__global__ void sky_sum_kernel(sky::AtmosphereHD a, const sky::ObserverHD* obs, glm::vec3* out, std::size_t n,
                               int steps, int spacing) {
    const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n)
        out[i] = sky::sky_sum(a, obs[i], steps, spacing);
}

__global__ void sky_render_kernel(sky::RenderHD p, float* rgb) {
    const int x = int(blockIdx.x * blockDim.x + threadIdx.x), y = int(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= p.width || y >= p.height)
        return;
    glm::vec3 d, c(0.0f);
    if (sky::pixel_direction(p, x, y, d))
        c = sky::shade_ray(p, d);
    float* px = rgb + (std::size_t(y) * std::size_t(p.width) + std::size_t(x)) * 3;
    px[0] = c.x;
    px[1] = c.y;
    px[2] = c.z;
}

// The model's tables copied to the device, and a flat view pointing at them.
struct DeviceAtmosphere {
    std::vector<cuda::DeviceBuffer<float>> tables;
    sky::AtmosphereHD hd;

    explicit DeviceAtmosphere(const SkyModel& model) {
        hd = sky::atmosphere_hd(model);
        tables.resize(std::size_t(hd.count));
        for (int k = 0; k < hd.count; ++k) {
            const std::size_t n = std::size_t(hd.comp[k].table.rows) * std::size_t(hd.comp[k].table.cols);
            tables[std::size_t(k)].upload(hd.comp[k].table.L, n);
            hd.comp[k].table.L = tables[std::size_t(k)].data();
        }
        // Multiple scattering: the orders grid or Hillaire's table, and the sky irradiance.
        sky::MultipleHD& m = hd.ms;
        if (m.orders) {
            orders.upload(m.orders, std::size_t(m.nr) * 2u * std::size_t(m.nmu) * std::size_t(m.nmus) * std::size_t(m.nnu) * 3u);
            m.orders = orders.data();
        }
        if (m.psi) {
            psi.upload(m.psi, std::size_t(m.psi_nr) * std::size_t(m.psi_nmus) * 3u);
            m.psi = psi.data();
        }
        if (m.irradiance) {
            irradiance.upload(m.irradiance, std::size_t(m.irr_nr) * std::size_t(m.irr_nmus) * 3u);
            m.irradiance = irradiance.data();
        }
    }
    cuda::DeviceBuffer<float> orders, psi, irradiance;
};

} // namespace

void evaluate_sky_cuda(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out) {
    require_cuda_device("device");
    if (samples.size() != out.size())
        throw Error("evaluate_sky_cuda: output size differs from the sample count");
    if (samples.empty())
        return;
    DeviceAtmosphere atm(model);
    const Atmosphere& host_atm = model.atmosphere();
    const int steps = model.options().steps;
    const int spacing = model.options().uniform_steps ? sky::kStepsUniform : sky::kStepsGraded;

    // Observers are set up on the host, exactly as the CPU path does, so both
    // paths sum the same float inputs.
    const std::size_t chunk = std::min(kChunk, samples.size());
    std::vector<sky::ObserverHD> obs(chunk);
    cuda::DeviceBuffer<sky::ObserverHD> d_obs(chunk);
    cuda::DeviceBuffer<glm::vec3> d_out(chunk);
    for (std::size_t begin = 0; begin < samples.size(); begin += chunk) {
        const std::size_t n = std::min(chunk, samples.size() - begin);
        parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i)
                obs[i] = sky::make_observer(host_atm, samples[begin + i]);
        });
        d_obs.upload(obs.data(), n);
        sky_sum_kernel<<<cuda::grid_for(n, kBlock), kBlock>>>(atm.hd, d_obs.data(), d_out.data(), n, steps, spacing);
        SKYBAKE_CUDA_CHECK(cudaGetLastError());
        d_out.download(out.data() + begin, n);
        SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    }
}

Image render_sky_cuda(const SkyModel& model, const SkyRenderSettings& settings) {
    if (settings.method != SkyMethod::Tables)
        throw Error("the exact method runs on the CPU only; use the CPU or the tables method", "device");
    sky::RenderHD p = sky::make_render_hd(model, settings);
    require_cuda_device("device");
    DeviceAtmosphere atm(model);
    p.atm = atm.hd;
    Image image(settings.width, settings.height);
    cuda::DeviceBuffer<float> d_rgb(image.rgb.size());
    const dim3 block(16, 8);
    const dim3 grid(cuda::grid_for(std::size_t(p.width), block.x), cuda::grid_for(std::size_t(p.height), block.y));
    sky_render_kernel<<<grid, block>>>(p, d_rgb.data());
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    d_rgb.download(image.rgb.data(), image.rgb.size());
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    return image;
}

} // namespace skybake
