// The CUDA visibility backend: kernels and their host driver.
//
// Svistunov, GPU computation of shading coefficients for interactive lighting
// (seed 002): vertices × directions in parallel, visibility as bits with an
// early exit per ray, launches cut into chunks, polygons cached in shared
// memory for the tiled brute-force method. The thread bodies are the SKYBAKE_HD
// functions of bake_hd.h and bvh.h, which the CPU tests run too.
//
// Aila T., Laine S. Understanding the efficiency of ray traversal on GPUs.
// HPG 2009 (one ray per thread, a short stack, 16-byte node loads through the
// read-only cache).
//
// This file is compiled with --fmad=false (src/CMakeLists.txt): without
// contracted multiply-adds the kernels round exactly as the host does, so the
// GPU gives the same bits and AO values as emulate_bake() on the CPU.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <type_traits>

#include "core/cuda_util.h"
#include "core/progress.h"
#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/mesh.h"
#include "visibility/cuda/bake_plan.h"
#include "visibility/cuda/cuda_backend.h"

namespace skybake::visibility {

namespace {

constexpr unsigned kBlock = 128;   // threads per block: 4 warps
constexpr unsigned kTile = kBlock; // triangles per shared-memory tile (one per thread)
constexpr std::size_t kRaysPerQuery = std::size_t(1) << 22;

// [SECTION] Kernels ------------------------------------------------------------------------

// One warp per (chunk vertex, visibility word): lane l traces visiting position
// 32·word + l, and the warp's answers become the word.
template <TraceMethod M>
__global__ void __launch_bounds__(kBlock) trace_kernel(GpuBakeParams p) {
    const std::uint64_t warp = (std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
    const unsigned lane = threadIdx.x & 31u;
    if (warp >= std::uint64_t(p.vertex_count) * p.words)
        return; // the whole warp leaves together
    const auto v = std::uint32_t(warp / p.words), w = std::uint32_t(warp % p.words);
    const bool visible = bake_visible<M>(p, v, 32u * w + lane);
    const unsigned bits = __ballot_sync(0xffffffffu, visible);
    if (lane == 0)
        p.visit_words[warp] = bits;
}

// The seed's polygon caching: the block walks the triangle soup in tiles of
// kTile triangles staged in shared memory, every thread testing its ray
// against the tile; it stops as soon as every ray of the block is blocked.
__global__ void __launch_bounds__(kBlock) trace_tiled_kernel(GpuBakeParams p) {
    __shared__ float4 tile[3 * kTile];
    const std::uint64_t warp = (std::uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
    const unsigned lane = threadIdx.x & 31u;
    const bool active = warp < std::uint64_t(p.vertex_count) * p.words;
    glm::vec3 o(0.0f), d(0.0f, 0.0f, 1.0f);
    bool need = false;
    if (active) {
        const auto v = std::uint32_t(warp / p.words), w = std::uint32_t(warp % p.words);
        need = bake_ray(p, v, 32u * w + lane, o, d);
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

// kReduceLanes threads per vertex, one per partial sum; the group's first
// thread gathers the partials in lane order and stores the vertex.
__global__ void __launch_bounds__(kBlock) reduce_kernel(GpuBakeParams p) {
    static_assert(32 % kReduceLanes == 0);
    const std::uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    const std::uint32_t v = t / kReduceLanes, l = t % kReduceLanes;
    const bool active = v < p.vertex_count;
    ShadingPartials s;
    std::uint32_t traced = 0;
    if (active)
        traced = bake_reduce_lane(p, v, l, s);
    // Every lane of the warp takes part in the shuffles.
    const unsigned first = (threadIdx.x & 31u) & ~(kReduceLanes - 1u);
    ShadingPartials all;
    std::uint32_t total = 0;
#pragma unroll
    for (std::uint32_t k = 0; k < kReduceLanes; ++k) {
        const unsigned src = first + k;
        all.ao[k] = __shfl_sync(0xffffffffu, s.ao[0], src);
        all.ao_open[k] = __shfl_sync(0xffffffffu, s.ao_open[0], src);
        all.a[k] = __shfl_sync(0xffffffffu, s.a[0], src);
        all.a_open[k] = __shfl_sync(0xffffffffu, s.a_open[0], src);
        all.bx[k] = __shfl_sync(0xffffffffu, s.bx[0], src);
        all.by[k] = __shfl_sync(0xffffffffu, s.by[0], src);
        all.bz[k] = __shfl_sync(0xffffffffu, s.bz[0], src);
        total += __shfl_sync(0xffffffffu, traced, src);
    }
    if (active && l == 0)
        bake_store(p, v, all, total);
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
        throw Error(std::string(what) + "(): the output size differs from the ray count", "cuda");
    if (bvh.node_count == 0)
        throw Error(std::string(what) + "(): no mesh; call set_mesh() first", "cuda");
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

// [SECTION] Host memory and streams ------------------------------------------------------------

// Page-locked host array, so that copies can run asynchronously.
template <class T>
class PinnedBuffer {
public:
    PinnedBuffer() = default;
    ~PinnedBuffer() {
        if (ptr_)
            cudaFreeHost(ptr_);
    }
    PinnedBuffer(const PinnedBuffer&) = delete;
    PinnedBuffer& operator=(const PinnedBuffer&) = delete;
    void resize(std::size_t n) {
        if (n <= size_)
            return;
        if (ptr_)
            cudaFreeHost(ptr_);
        ptr_ = nullptr;
        size_ = 0;
        SKYBAKE_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void**>(&ptr_), n * sizeof(T)));
        size_ = n;
    }
    T* data() { return ptr_; }

private:
    T* ptr_ = nullptr;
    std::size_t size_ = 0;
};

class Stream {
public:
    Stream() { SKYBAKE_CUDA_CHECK(cudaStreamCreateWithFlags(&s_, cudaStreamNonBlocking)); }
    ~Stream() {
        if (s_)
            cudaStreamDestroy(s_);
    }
    Stream(const Stream&) = delete;
    Stream& operator=(const Stream&) = delete;
    operator cudaStream_t() const { return s_; }

private:
    cudaStream_t s_ = nullptr;
};

// One in-flight chunk: device buffers, pinned staging, and which vertices it holds.
struct ChunkSlot {
    Stream stream;
    cuda::DeviceBuffer<glm::vec3> origins, normals, bent;
    cuda::DeviceBuffer<glm::mat3> rotations;
    cuda::DeviceBuffer<std::uint32_t> visit_words, rule_words, rays, clamped;
    cuda::DeviceBuffer<float> ao, shading;
    PinnedBuffer<glm::vec3> h_origins, h_normals, h_bent;
    PinnedBuffer<glm::mat3> h_rotations;
    PinnedBuffer<std::uint32_t> h_rule_words, h_rays, h_clamped;
    PinnedBuffer<float> h_ao, h_shading;
    bool busy = false;
    std::uint32_t first = 0, count = 0;

    void allocate(std::uint32_t n, std::uint32_t words, bool rotate, bool store_bits) {
        origins.resize(n), normals.resize(n), bent.resize(n);
        rotations.resize(rotate ? n : 0);
        visit_words.resize(std::size_t(n) * words);
        rule_words.resize(store_bits ? std::size_t(n) * words : 0);
        rays.resize(n), clamped.resize(n), ao.resize(n), shading.resize(n);
        h_origins.resize(n), h_normals.resize(n), h_bent.resize(n);
        if (rotate)
            h_rotations.resize(n);
        if (store_bits)
            h_rule_words.resize(std::size_t(n) * words);
        h_rays.resize(n), h_clamped.resize(n), h_ao.resize(n), h_shading.resize(n);
    }
};

// Device bytes one chunk vertex needs.
std::uint64_t bytes_per_vertex(std::uint32_t words, bool rotate, bool store_bits) {
    std::uint64_t b = 3 * sizeof(glm::vec3) + 2 * sizeof(float) + 2 * sizeof(std::uint32_t) + 4ull * words;
    if (rotate)
        b += sizeof(glm::mat3);
    if (store_bits)
        b += 4ull * words;
    return b;
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
    std::uint32_t chunks = 0;

    // What the backend may allocate beyond what it holds now.
    std::uint64_t budget() const {
        std::size_t free_bytes = 0, total = 0;
        SKYBAKE_CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total));
        const std::uint64_t held =
            nodes.size() * sizeof(BvhNode) + (triangles.size() + soup.size()) * sizeof(BvhTriangle);
        if (limits.memory_bytes > 0)
            return limits.memory_bytes > held ? limits.memory_bytes - held : 0;
        return std::uint64_t(double(free_bytes) * 0.9);
    }

    BvhView device_view() const {
        return {nodes.data(), triangles.data(), std::uint32_t(nodes.size()), std::uint32_t(triangles.size())};
    }
};

CudaBackend::CudaBackend() : impl_(std::make_unique<Impl>()) {
    if (cuda_device_count() == 0)
        throw Error("no usable CUDA device (" + cuda_device_problem() + "); bake on the CPU (--device cpu)",
                    "--device cuda");
    SKYBAKE_CUDA_CHECK(cudaSetDevice(0));
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
std::uint32_t CudaBackend::last_chunk_count() const {
    return impl_->chunks;
}
const Bvh& CudaBackend::bvh() const {
    return impl_->bvh;
}

void CudaBackend::set_mesh(const Mesh& mesh, BackFaces back_faces) {
    Impl& m = *impl_;
    // Release the previous mesh first: its memory counts as free again.
    m.nodes.resize(0), m.triangles.resize(0), m.soup.resize(0);
    m.bvh = build_bvh(mesh);
    m.cull_back = back_faces == BackFaces::Ignore;
    const std::uint64_t need = m.bvh.bytes(), have = m.budget();
    if (need > have)
        throw Error("the mesh's BVH (" + std::to_string(mesh.triangle_count()) + " triangles) needs " + mib(need) +
                        " of GPU memory, but only " + mib(have) + " is available on " + m.device +
                        "; use --device cpu, or a GPU with more memory",
                    "--backend cuda");
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

void CudaBackend::bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out) {
    Impl& m = *impl_;
    const BakePlan plan = plan_bake(mesh, rule, options, out);
    const auto t0 = std::chrono::steady_clock::now();
    set_mesh(mesh, options.back_faces);
    const auto t1 = std::chrono::steady_clock::now();
    out.build_seconds = std::chrono::duration<double>(t1 - t0).count();

    const BakeSetup& s = plan.setup;
    const auto n = std::uint32_t(mesh.vertex_count());
    const std::uint32_t words = s.words;

    // The rule in visiting order, once for every chunk.
    cuda::DeviceBuffer<glm::vec3> d_points;
    cuda::DeviceBuffer<float> d_weights;
    cuda::DeviceBuffer<std::uint32_t> d_order;
    d_points.upload(s.sorted_points.data(), s.directions);
    d_weights.upload(s.sorted_weights.data(), s.directions);
    d_order.upload(s.order.data(), s.directions);
    // Those copies ran on the legacy stream, which the chunk streams do not wait for.
    SKYBAKE_CUDA_CHECK(cudaStreamSynchronize(nullptr));

    // Chunk size: bounded work per launch and memory for two chunks in flight.
    const std::uint64_t slots = 32ull * words;
    const std::uint64_t work = options.method == TraceMethod::Bvh
                                   ? m.limits.slots_per_launch / slots
                                   : m.limits.tests_per_launch / (slots * std::max<std::uint64_t>(1, m.soup.size()));
    const std::uint64_t rule_bytes = std::uint64_t(s.directions) * (sizeof(glm::vec3) + sizeof(float) + 4);
    const std::uint64_t budget = m.budget();
    const std::uint64_t per_vertex = bytes_per_vertex(words, s.rotate, s.store_bits);
    const std::uint64_t fit = budget > rule_bytes ? (budget - rule_bytes) / (2 * per_vertex) : 0;
    if (fit == 0)
        throw Error("not enough GPU memory on " + m.device + " for even one vertex of the bake (" + mib(budget) +
                        " available after the BVH); use --device cpu",
                    "--backend cuda");
    const std::uint64_t grid = (std::uint64_t(0x7fffffff) * kBlock) / slots; // a launch has < 2^31 blocks
    const auto chunk = std::uint32_t(std::clamp<std::uint64_t>(std::min({work, fit, grid}), 1, std::max(n, 1u)));

    GpuBakeParams base = host_params(plan, m.bvh);
    base.bvh = m.device_view();
    base.soup = m.soup.data();
    base.points = d_points.data();
    base.weights = d_weights.data();
    base.order = d_order.data();

    ChunkSlot slots_[2];
    const std::uint32_t nslots = n > chunk ? 2 : 1;
    try {
        for (std::uint32_t k = 0; k < nslots; ++k)
            slots_[k].allocate(chunk, words, s.rotate, s.store_bits);
    } catch (const Error&) {
        throw Error("cannot allocate the bake's buffers on " + m.device + " (" + std::to_string(nslots) +
                        " chunks of " + std::to_string(chunk) + " vertices, " +
                        mib(std::uint64_t(nslots) * chunk * per_vertex) + "); free GPU memory, or use --device cpu",
                    "--backend cuda");
    }

    Progress progress("ao", n);
    // Waits for a slot's chunk and stores its results.
    auto drain = [&](ChunkSlot& c) {
        if (!c.busy)
            return;
        SKYBAKE_CUDA_CHECK(cudaStreamSynchronize(c.stream));
        store_chunk(plan, c.first, c.count,
                    {c.h_ao.data(), c.h_shading.data(), c.h_bent.data(), c.h_rays.data(), c.h_clamped.data(),
                     s.store_bits ? c.h_rule_words.data() : nullptr},
                    out);
        c.busy = false;
        progress.advance(c.count);
    };

    out.rays = 0;
    out.clamped_vertices = 0;
    m.chunks = 0;
    for (std::uint32_t first = 0; first < n; first += chunk, ++m.chunks) {
        ChunkSlot& c = slots_[m.chunks % nslots];
        drain(c); // its previous chunk, while the other slot's kernels run
        const std::uint32_t count = std::min(chunk, n - first);
        c.first = first;
        c.count = count;
        std::copy_n(plan.origins.data() + first, count, c.h_origins.data());
        std::copy_n(plan.normals.data() + first, count, c.h_normals.data());
        if (s.rotate)
            std::copy_n(plan.rotations.data() + first, count, c.h_rotations.data());
        const cudaStream_t st = c.stream;
        c.origins.upload_prefix(c.h_origins.data(), count, st);
        c.normals.upload_prefix(c.h_normals.data(), count, st);
        if (s.rotate)
            c.rotations.upload_prefix(c.h_rotations.data(), count, st);
        if (s.store_bits)
            SKYBAKE_CUDA_CHECK(cudaMemsetAsync(c.rule_words.data(), 0, std::size_t(count) * words * 4, st));

        GpuBakeParams p = base;
        p.vertex_count = count;
        p.origins = c.origins.data();
        p.normals = c.normals.data();
        p.rotations = s.rotate ? c.rotations.data() : nullptr;
        p.visit_words = c.visit_words.data();
        p.ao = c.ao.data();
        p.shading = c.shading.data();
        p.bent = c.bent.data();
        p.rays = c.rays.data();
        p.clamped = c.clamped.data();
        p.rule_words = s.store_bits ? c.rule_words.data() : nullptr;

        const std::uint64_t threads = std::uint64_t(count) * words * 32;
        const auto blocks = unsigned((threads + kBlock - 1) / kBlock);
        switch (options.method) {
        case TraceMethod::Bvh: trace_kernel<TraceMethod::Bvh><<<blocks, kBlock, 0, st>>>(p); break;
        case TraceMethod::PerVertex: trace_kernel<TraceMethod::PerVertex><<<blocks, kBlock, 0, st>>>(p); break;
        case TraceMethod::PerPolygon: trace_tiled_kernel<<<blocks, kBlock, 0, st>>>(p); break;
        default: throw Error("unknown trace method " + std::to_string(int(options.method)), "--method");
        }
        SKYBAKE_CUDA_CHECK(cudaGetLastError());
        reduce_kernel<<<cuda::grid_for(std::size_t(count) * kReduceLanes, kBlock), kBlock, 0, st>>>(p);
        SKYBAKE_CUDA_CHECK(cudaGetLastError());

        c.ao.download(c.h_ao.data(), count, st);
        c.shading.download(c.h_shading.data(), count, st);
        c.bent.download(c.h_bent.data(), count, st);
        c.rays.download(c.h_rays.data(), count, st);
        c.clamped.download(c.h_clamped.data(), count, st);
        if (s.store_bits)
            c.rule_words.download(c.h_rule_words.data(), std::size_t(count) * words, st);
        c.busy = true;
    }
    for (std::uint32_t k = 0; k < nslots; ++k)
        drain(slots_[k]);
    progress.finish();
    out.trace_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
}

std::unique_ptr<VisibilityBackend> make_cuda_backend() {
    return std::make_unique<CudaBackend>();
}

} // namespace skybake::visibility
