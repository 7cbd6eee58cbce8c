// The CUDA visibility backend: kernels and their host side.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): vertices × directions in parallel, visibility as bits with an
// early exit per ray, launches cut into chunks, polygons cached in shared
// memory for the tiled brute-force method. The thread bodies are the SKYBAKE_HD
// functions of tracer_hd.h and bvh.h, which the CPU tests run too.
//
// Aila T., Laine S. Understanding the efficiency of ray traversal on GPUs.
// HPG 2009 (one ray per thread, a short stack, 16-byte node loads through the
// read-only cache).
//
// This file is compiled with --fmad=false (src/CMakeLists.txt): without
// contracted multiply-adds the kernels round exactly as the host does, so the
// GPU gives the same bits as EmulatedCudaTracer on the CPU.
#include <algorithm>
#include <cstring>
#include <string>
#include <type_traits>

#include "core/cuda_util.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "visibility/cuda/cuda_backend.h"
#include "visibility/cuda/emulated_tracer.h"
#include "visibility/cuda/tracer_hd.h"

namespace skybake::visibility {

namespace {

constexpr unsigned kBlock = 128;   // threads per block: 4 warps
constexpr unsigned kTile = kBlock; // triangles per shared-memory tile (one per thread)
constexpr std::size_t kRaysPerQuery = std::size_t(1) << 22;

// [SECTION] Kernels ------------------------------------------------------------------------

// One warp per (chunk vertex, visibility word): lane l traces visiting position
// 32·word + l, and the warp's answers become the word.
template <TraceMethod M>
__global__ void __launch_bounds__(kBlock) trace_kernel(GpuTraceParams p) {
    const std::uint64_t warp = (std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
    const unsigned lane = threadIdx.x & 31u;
    if (warp >= std::uint64_t(p.vertex_count) * p.words)
        return; // the whole warp leaves together
    const auto v = std::uint32_t(warp / p.words), w = std::uint32_t(warp % p.words);
    const bool visible = trace_visible<M>(p, v, 32u * w + lane);
    const unsigned bits = __ballot_sync(0xffffffffu, visible);
    if (lane == 0)
        p.visit_words[warp] = bits;
}

// The seed's polygon caching: the block walks the triangle soup in tiles of
// kTile triangles staged in shared memory, every thread testing its ray
// against the tile; it stops as soon as every ray of the block is blocked.
__global__ void __launch_bounds__(kBlock) trace_tiled_kernel(GpuTraceParams p) {
    __shared__ float4 tile[3 * kTile];
    const std::uint64_t warp = (std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
    const unsigned lane = threadIdx.x & 31u;
    const bool active = warp < std::uint64_t(p.vertex_count) * p.words;
    glm::vec3 o(0.0f), d(0.0f, 0.0f, 1.0f);
    bool need = false;
    if (active) {
        const auto v = std::uint32_t(warp / p.words), w = std::uint32_t(warp % p.words);
        need = trace_ray(p, v, 32u * w + lane, o, d);
    }
    bool blocked = false;
    const auto* soup = reinterpret_cast<const float4*>(p.soup);
    for (std::uint32_t base = 0; base < p.soup_count; base += kTile) {
        // Also the barrier before the tile is overwritten.
        if (__syncthreads_and(!need || blocked))
            break;
        const std::uint32_t i = base + threadIdx.x;
        if (i < p.soup_count) {
            tile[3 * threadIdx.x] = __ldg(soup + 3 * std::size_t(i));
            tile[3 * threadIdx.x + 1] = __ldg(soup + 3 * std::size_t(i) + 1);
            tile[3 * threadIdx.x + 2] = __ldg(soup + 3 * std::size_t(i) + 2);
        }
        __syncthreads();
        if (need && !blocked) {
            const std::uint32_t n = min(kTile, p.soup_count - base);
            for (std::uint32_t k = 0; k < n; ++k) {
                const float4 a = tile[3 * k], b = tile[3 * k + 1], c = tile[3 * k + 2];
                float t, u, vv;
                if (ray_triangle(o, d, glm::vec3(a.x, a.y, a.z), glm::vec3(b.x, b.y, b.z), glm::vec3(c.x, c.y, c.z),
                                 0.0f, p.t_max, t, u, vv, p.cull_back)) {
                    blocked = true;
                    break;
                }
            }
        }
    }
    const unsigned bits = __ballot_sync(0xffffffffu, need && !blocked);
    if (active && lane == 0)
        p.visit_words[warp] = bits;
}

// One thread per rule-order output word: the bits of its 32 rule directions,
// gathered from the visiting-order words.
__global__ void __launch_bounds__(kBlock) gather_kernel(GpuTraceParams p) {
    const std::uint64_t t = std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (t >= std::uint64_t(p.vertex_count) * p.words)
        return;
    p.rule_words[t] = gather_word(p, std::uint32_t(t / p.words), std::uint32_t(t % p.words));
}

// One ray per thread: occlusion (Out = std::uint8_t) or the closest hit (Out = RayHit).
template <class Out>
__global__ void query_kernel(BvhView bvh, const Ray* rays, Out* out, std::uint32_t n, bool cull_back) {
    const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n)
        return;
    const Ray r = rays[i];
    if constexpr (std::is_same_v<Out, RayHit>) {
        float t = r.t_max, u = 0.0f, v = 0.0f;
        std::uint32_t id = kNoHit;
        RayHit h;
        if (bvh_trace<false>(bvh, r.origin, r.direction, r.t_min, t, cull_back, id, u, v)) {
            h.t = t;
            h.triangle = id;
            h.u = u;
            h.v = v;
        }
        out[i] = h;
    } else {
        out[i] = bvh_occluded(bvh, r.origin, r.direction, r.t_min, r.t_max, cull_back) ? 1 : 0;
    }
}

// Rays up, query_kernel, answers down, in batches of kRaysPerQuery.
template <class Out>
void run_queries(const BvhView& bvh, bool cull_back, std::span<const Ray> rays, std::span<Out> out, const char* what) {
    if (rays.size() != out.size())
        throw Error(std::string(what) + "(): the output size differs from the ray count", "rays");
    if (bvh.node_count == 0)
        throw Error(std::string(what) + "(): no mesh; call set_mesh() first", "mesh");
    cuda::DeviceBuffer<Ray> d_rays(std::min(rays.size(), kRaysPerQuery));
    cuda::DeviceBuffer<Out> d_out(std::min(rays.size(), kRaysPerQuery));
    for (std::size_t first = 0; first < rays.size(); first += kRaysPerQuery) {
        const auto n = std::uint32_t(std::min(kRaysPerQuery, rays.size() - first));
        SKYBAKE_CUDA_CHECK(cudaMemcpy(d_rays.data(), rays.data() + first, n * sizeof(Ray), cudaMemcpyHostToDevice));
        query_kernel<Out><<<cuda::grid_for(n, kBlock), kBlock>>>(bvh, d_rays.data(), d_out.data(), n, cull_back);
        SKYBAKE_CUDA_CHECK(cudaGetLastError());
        SKYBAKE_CUDA_CHECK(cudaMemcpy(out.data() + first, d_out.data(), n * sizeof(Out), cudaMemcpyDeviceToHost));
    }
}

// Device bytes one chunk vertex needs: origin, normal, rotation, and the
// visiting-order and rule-order words.
std::uint64_t bytes_per_vertex(std::uint32_t words, bool rotate) {
    return 2 * sizeof(glm::vec3) + (rotate ? sizeof(glm::mat3) : 0) + 8ull * words;
}

std::string mib(std::uint64_t bytes) {
    return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

} // namespace

// [SECTION] The backend -----------------------------------------------------------------------

struct CudaBackend::Impl {
    Limits limits;
    std::string device;
    Bvh bvh;
    bool cull_back = false;
    cuda::DeviceBuffer<BvhNode> nodes;
    cuda::DeviceBuffer<BvhTriangle> triangles, soup;
    TraceMethod method = TraceMethod::Bvh;
    std::uint32_t chunks = 0;
    // The rule of the current bake, and one chunk's buffers.
    TraceRule rule;
    cuda::DeviceBuffer<glm::vec3> points, origins, normals;
    cuda::DeviceBuffer<std::uint32_t> position, visit_words, rule_words;
    cuda::DeviceBuffer<glm::mat3> rotations;
    std::uint32_t chunk_limit = 0;

    // What the backend may allocate beyond what it holds now.
    std::uint64_t budget() const {
        std::size_t free_bytes = 0, total = 0;
        SKYBAKE_CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total));
        const std::uint64_t held = nodes.size() * sizeof(BvhNode) +
                                   (triangles.size() + soup.size()) * sizeof(BvhTriangle) +
                                   points.size() * sizeof(glm::vec3) + position.size() * sizeof(std::uint32_t);
        if (limits.memory_bytes > 0)
            return limits.memory_bytes > held ? limits.memory_bytes - held : 0;
        return std::uint64_t(double(free_bytes) * 0.9);
    }

    BvhView device_view() const {
        return {nodes.data(), triangles.data(), std::uint32_t(nodes.size()), std::uint32_t(triangles.size())};
    }
};

CudaBackend::CudaBackend(TraceMethod method) : impl_(std::make_unique<Impl>()) {
    impl_->method = method;
    if (cuda_device_count() == 0)
        throw Error("no usable CUDA device (" + cuda_device_problem() + "); bake on the CPU instead", "device");
    SKYBAKE_CUDA_CHECK(cudaSetDevice(cuda_device_index()));
    impl_->device = cuda_device_name();
}

CudaBackend::~CudaBackend() = default;

void CudaBackend::set_limits(const Limits& limits) {
    impl_->limits = limits;
}
const CudaBackend::Limits& CudaBackend::limits() const {
    return impl_->limits;
}
std::string CudaBackend::device_name() const {
    return impl_->device;
}
TraceMethod CudaBackend::method() const {
    return impl_->method;
}
std::uint32_t CudaBackend::last_chunk_count() const {
    return impl_->chunks;
}
const std::uint32_t* CudaBackend::device_words() const {
    return impl_->rule_words.data();
}
const Bvh& CudaBackend::bvh() const {
    return impl_->bvh;
}

void CudaBackend::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    Impl& m = *impl_;
    // Release the previous mesh first: its memory counts as free again.
    m.nodes.resize(0), m.triangles.resize(0), m.soup.resize(0);
    m.origins.resize(0), m.normals.resize(0), m.rotations.resize(0), m.visit_words.resize(0), m.rule_words.resize(0);
    m.bvh = build_bvh(mesh);
    m.cull_back = back_faces == BackFaces::Ignore;
    const std::uint64_t need = m.bvh.bytes(), have = m.budget();
    if (need > have)
        throw Error("the mesh's BVH (" + std::to_string(mesh.triangle_count()) + " triangles) needs " + mib(need) +
                        " of GPU memory, but only " + mib(have) + " is available on " + m.device +
                        "; bake on the CPU, or on a GPU with more memory",
                    "device");
    m.nodes.upload(m.bvh.nodes.data(), m.bvh.nodes.size());
    m.triangles.upload(m.bvh.triangles.data(), m.bvh.triangles.size());
    m.soup.upload(m.bvh.soup.data(), m.bvh.soup.size());
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
}

void CudaBackend::occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
    run_queries(impl_->device_view(), impl_->cull_back, rays, occluded, "occluded");
}

void CudaBackend::intersect(std::span<const Ray> rays, std::span<RayHit> hits) const {
    run_queries(impl_->device_view(), impl_->cull_back, rays, hits, "intersect");
}

std::uint32_t CudaBackend::set_rule(const TraceRule& rule) {
    Impl& m = *impl_;
    m.rule = rule;
    m.chunks = 0;
    const auto directions = std::uint32_t(rule.points.size());
    const std::uint32_t words = rule.words_per_vertex;
    const std::vector<std::uint32_t> position = visiting_positions(rule.order);
    m.points.upload(rule.points.data(), directions);
    m.position.upload(position.data(), directions);

    // Chunk size: bounded work per launch, and memory for one chunk.
    const std::uint64_t slots = 32ull * words;
    const std::uint64_t work = m.method == TraceMethod::Bvh
                                   ? m.limits.slots_per_launch / slots
                                   : m.limits.tests_per_launch / (slots * std::max<std::uint64_t>(1, m.soup.size()));
    const std::uint64_t budget = m.budget();
    const std::uint64_t fit = budget / bytes_per_vertex(words, rule.rotate);
    if (fit == 0)
        throw Error("not enough GPU memory on " + m.device + " for even one vertex of the bake (" + mib(budget) +
                        " available after the BVH); bake on the CPU",
                    "device");
    const std::uint64_t grid = (std::uint64_t(0x7fffffff) * kBlock) / slots; // a launch has < 2^31 blocks
    m.chunk_limit = std::uint32_t(std::clamp<std::uint64_t>(std::min({work, fit, grid}), 1, 0xffffffffu));
    return m.chunk_limit;
}

void CudaBackend::trace(const TraceChunk& chunk) {
    Impl& m = *impl_;
    const TraceRule& rule = m.rule;
    const std::uint32_t words = rule.words_per_vertex, count = chunk.count;
    if (count > m.chunk_limit)
        throw Error("a chunk of " + std::to_string(count) + " vertices is more than set_rule() allowed (" +
                        std::to_string(m.chunk_limit) + ")",
                    "count");
    try {
        m.origins.upload(chunk.origins.data(), count);
        m.normals.upload(chunk.normals.data(), count);
        if (rule.rotate)
            m.rotations.upload(chunk.rotations.data(), count);
        m.visit_words.resize(std::size_t(count) * words);
        m.rule_words.resize(std::size_t(count) * words);
    } catch (const Error&) {
        throw Error("cannot allocate the bake's buffers on " + m.device + " (a chunk of " + std::to_string(count) +
                        " vertices, " + mib(std::uint64_t(count) * bytes_per_vertex(words, rule.rotate)) +
                        "); free GPU memory, or bake on the CPU",
                    "device");
    }

    GpuTraceParams p = trace_params(rule, m.position.data(), m.bvh, m.cull_back);
    p.bvh = m.device_view();
    p.soup = m.soup.data();
    p.points = m.points.data();
    p.vertex_count = count;
    p.origins = m.origins.data();
    p.normals = m.normals.data();
    p.rotations = rule.rotate ? m.rotations.data() : nullptr;
    p.visit_words = m.visit_words.data();
    p.rule_words = m.rule_words.data();

    const std::uint64_t threads = std::uint64_t(count) * words * 32;
    const auto blocks = unsigned((threads + kBlock - 1) / kBlock);
    switch (m.method) {
    case TraceMethod::Bvh: trace_kernel<TraceMethod::Bvh><<<blocks, kBlock>>>(p); break;
    case TraceMethod::PerVertex: trace_kernel<TraceMethod::PerVertex><<<blocks, kBlock>>>(p); break;
    case TraceMethod::PerPolygon: trace_tiled_kernel<<<blocks, kBlock>>>(p); break;
    default: throw Error("unknown trace method " + std::to_string(int(m.method)), "method");
    }
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    gather_kernel<<<cuda::grid_for(std::size_t(count) * words, kBlock), kBlock>>>(p);
    SKYBAKE_CUDA_CHECK(cudaGetLastError());
    if (!chunk.words.empty())
        m.rule_words.download(chunk.words.data(), std::size_t(count) * words);
    SKYBAKE_CUDA_CHECK(cudaDeviceSynchronize());
    ++m.chunks;
}

std::unique_ptr<RayQueries> make_cuda_ray_queries() {
    return std::make_unique<CudaBackend>();
}

std::unique_ptr<VisibilityTracer> make_cuda_tracer(TraceMethod method) {
    return std::make_unique<CudaBackend>(method);
}

} // namespace skybake::visibility
