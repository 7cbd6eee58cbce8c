// The cuda backend's registration (skybake/visibility.h, [SECTION] Backends).
// Compiled in every build: without CUDA the backend is listed, and says why
// it cannot run.
#include "skybake/core.h"
#include "visibility/cuda/cuda_backend.h"

void skybake_register_cuda_tracer() {
    using namespace skybake;
    TracerBackend b;
    b.name = "cuda";
    b.device = "cuda";
    b.summary = "NVIDIA GPUs: a BVH walked by one thread per ray, or the seed's brute-force methods";
    b.methods = {TraceMethod::Bvh, TraceMethod::PerVertex, TraceMethod::PerPolygon};
    b.closest_hit = true;
    b.make_tracer = [](TraceMethod method, std::uint32_t) { return visibility::make_cuda_tracer(method); };
    b.make_ray_queries = [] { return visibility::make_cuda_ray_queries(); };
    b.problem = [] { return cuda_device_problem(); };
    register_tracer_backend(std::move(b));
}
