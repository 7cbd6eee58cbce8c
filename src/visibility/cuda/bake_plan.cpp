// Host side of the CUDA bake (see bake_plan.h).
#include "visibility/cuda/bake_plan.h"

#include <algorithm>

#include "core/parallel.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"

namespace skybake::visibility {

BakePlan plan_bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out) {
    BakePlan plan;
    plan.setup = prepare_bake(mesh, rule, options, out);
    plan.cull_back = options.back_faces == BackFaces::Ignore;
    const std::size_t n = mesh.vertex_count();
    plan.origins.resize(n);
    plan.normals.resize(n);
    if (plan.setup.rotate)
        plan.rotations.resize(n);
    parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t v = b; v < e; ++v) {
            const VertexFrame f = vertex_frame(plan.setup, mesh, std::uint32_t(v));
            plan.origins[v] = f.origin;
            plan.normals[v] = f.normal;
            if (plan.setup.rotate)
                plan.rotations[v] = f.rotation;
        }
    });
    return plan;
}

GpuBakeParams host_params(const BakePlan& plan, const Bvh& bvh) {
    const BakeSetup& s = plan.setup;
    GpuBakeParams p;
    p.bvh = bvh.view();
    p.soup = bvh.soup.data();
    p.soup_count = std::uint32_t(bvh.soup.size());
    p.points = s.sorted_points.data();
    p.weights = s.sorted_weights.data();
    p.order = s.order.data();
    p.directions = s.directions;
    p.words = s.words;
    p.t_max = s.t_max;
    p.cull_back = plan.cull_back;
    p.rotate = s.rotate;
    p.normalize = s.normalize;
    p.store_bits = s.store_bits;
    return p;
}

void store_chunk(const BakePlan& plan, std::uint32_t first, std::uint32_t count, const ChunkResults& r,
                 BakeOutputs& out) {
    const std::uint32_t words = plan.setup.words;
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::size_t v = std::size_t(first) + i;
        out.ao[v] = r.ao[i];
        out.shading[v] = r.shading[i];
        out.bent_normal[v] = r.bent[i];
        out.rays += r.rays[i];
        out.clamped_vertices += r.clamped[i];
    }
    if (plan.setup.store_bits && r.rule_words)
        std::copy(r.rule_words, r.rule_words + std::size_t(count) * words,
                  out.visibility_bits.begin() + std::ptrdiff_t(std::size_t(first) * words));
}

void emulate_bake(const BakePlan& plan, const Bvh& bvh, TraceMethod method, BakeOutputs& out,
                  std::uint32_t chunk_vertices) {
    const auto n = std::uint32_t(plan.origins.size());
    const std::uint32_t words = plan.setup.words;
    chunk_vertices = std::max<std::uint32_t>(1, chunk_vertices);
    out.rays = 0;
    out.clamped_vertices = 0;
    for (std::uint32_t first = 0; first < n; first += chunk_vertices) {
        const std::uint32_t count = std::min(chunk_vertices, n - first);
        std::vector<std::uint32_t> visit(std::size_t(count) * words), rule_words(std::size_t(count) * words, 0u);
        std::vector<float> ao(count), shading(count);
        std::vector<glm::vec3> bent(count);
        std::vector<std::uint32_t> rays(count), clamped(count);
        GpuBakeParams p = host_params(plan, bvh);
        p.vertex_count = count;
        p.origins = plan.origins.data() + first;
        p.normals = plan.normals.data() + first;
        p.rotations = plan.setup.rotate ? plan.rotations.data() + first : nullptr;
        p.visit_words = visit.data();
        p.ao = ao.data();
        p.shading = shading.data();
        p.bent = bent.data();
        p.rays = rays.data();
        p.clamped = clamped.data();
        p.rule_words = rule_words.data();
        // Vertices are independent: split the chunk over threads.
        parallel_for(count, 16, [&](std::size_t b, std::size_t e) {
            GpuBakeParams q = p;
            q.vertex_count = std::uint32_t(e - b);
            q.origins += b;
            q.normals += b;
            if (q.rotations)
                q.rotations += b;
            q.visit_words += b * words;
            q.ao += b, q.shading += b, q.bent += b, q.rays += b, q.clamped += b;
            q.rule_words += b * words;
            emulate_bake_chunk(q, method);
        });
        store_chunk(plan, first, count,
                    {ao.data(), shading.data(), bent.data(), rays.data(), clamped.data(), rule_words.data()}, out);
    }
}

} // namespace skybake::visibility
