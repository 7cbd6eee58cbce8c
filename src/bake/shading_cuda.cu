// The shading reduction on the GPU (see shading_cuda.h). Compiled with
// --fmad=false (src/CMakeLists.txt), so that it rounds as the host does.
#include "bake/shading_cuda.h"
#include "bake/shading_hd.h"
#include "core/cuda_util.h"

namespace skybake::bake {

namespace {

constexpr unsigned kBlock = 128;

struct ReduceParams {
    const glm::vec3* points;
    const float* weights;
    const std::uint32_t* order;
    std::uint32_t directions, words;
    bool rotate, normalize;
    std::uint32_t count;
    const glm::vec3* normals;
    const glm::mat3* rotations;
    const std::uint32_t* visibility;
    ShadingResult* out;
};

__global__ void __launch_bounds__(kBlock) shading_kernel(ReduceParams p) {
    const std::uint32_t v = blockIdx.x * blockDim.x + threadIdx.x;
    if (v >= p.count)
        return;
    std::uint32_t rays = 0;
    const Shading s =
        shading_from_words(p.visibility + std::size_t(v) * p.words, p.points, p.weights, p.order, p.directions,
                           p.normals[v], p.rotate ? p.rotations[v] : glm::mat3(1.0f), p.rotate, p.normalize, &rays);
    ShadingResult r;
    r.ao = s.ao;
    r.shading = s.shading;
    r.bent_normal = s.bent_normal;
    r.rays = rays;
    r.clamped = s.clamped ? 1u : 0u;
    p.out[v] = r;
}

} // namespace

bool shading_cuda_available() {
    return true;
}

void reduce_shading_cuda(const VisibilityRule& rule, const VisibilityChunk& chunk, bool normalize, ShadingResult* out) {
    if (!chunk.device_words)
        throw Error("the chunk has no words in GPU memory", "device_words");
    cuda::DeviceBuffer<glm::vec3> points, normals;
    cuda::DeviceBuffer<float> weights;
    cuda::DeviceBuffer<std::uint32_t> order;
    cuda::DeviceBuffer<glm::mat3> rotations;
    cuda::DeviceBuffer<ShadingResult> results(chunk.count);
    points.upload(rule.points.data(), rule.points.size());
    weights.upload(rule.weights.data(), rule.weights.size());
    order.upload(rule.order.data(), rule.order.size());
    normals.upload(chunk.normals.data(), chunk.count);
    if (rule.rotate)
        rotations.upload(chunk.rotations.data(), chunk.count);
    ReduceParams p{points.data(),
                   weights.data(),
                   order.data(),
                   std::uint32_t(rule.points.size()),
                   rule.words_per_vertex,
                   rule.rotate,
                   normalize,
                   chunk.count,
                   normals.data(),
                   rule.rotate ? rotations.data() : nullptr,
                   chunk.device_words,
                   results.data()};
    shading_kernel<<<cuda::grid_for(chunk.count, kBlock), kBlock>>>(p);
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    results.download(out, chunk.count);
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
}

} // namespace skybake::bake
