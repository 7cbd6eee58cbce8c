// Internal: the "raster" visibility backend, which answers with the depth
// buffer of an OpenGL 4.3 context instead of rays (seed 002's third method,
// like shadow mapping). Two methods (TraceMethod):
//   Cube         at each vertex's ray origin, a depth hemicube of the mesh (the
//                face along the normal and the upper halves of the four side
//                faces); rule direction k reads its texel, and a surface closer
//                than TraceRule::t_max there means blocked. Many vertices are
//                drawn per call, as layers of a depth texture array, each layer
//                only the triangles that may cover it (binned on the CPU). Where
//                the four texels around a direction disagree, a blocker's edge
//                is within a texel and rays of the CPU tracer answer
//                (answer_edges).
//   Directional  for each rule direction, one orthographic depth map of the
//                whole mesh seen along it; every vertex is tested against it
//                from a point a few texels off its origin (the normal
//                offset). Cost: directions × (triangles + vertices) instead
//                of vertices × directions. Within kNearFieldTexels of the ray
//                the maps' answer is checked by rays of the CPU tracer
//                (answer_near_field). Needs a rule without +rotate and an
//                unlimited maximum distance.
// The depth maps become bits in a compute pass; only the bits are read back.
// The GL headers stay in the .cpp (the tracer owns its own headless context).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "skybake/visibility.h"

namespace skybake::visibility {

class RasterTracer final : public VisibilityTracer {
public:
    // Creates a headless OpenGL context; throws skybake::Error (where
    // "backend") without one of version 4.3 or newer, and (where
    // "resolution") for a resolution above kRasterMaxResolution or the
    // context's texture limits. resolution 0 means the method's default (the
    // cube's follows the rule: raster_cube_resolution(), in set_rule()).
    RasterTracer(TraceMethod method, std::uint32_t resolution);
    ~RasterTracer() override;

    const char* name() const override { return "raster"; }
    TraceMethod method() const override { return method_; }
    std::string device_name() const override;
    std::uint32_t resolution() const { return resolution_; } // the cube's default: 0 until set_rule()
    // Cube: the triangles drawn so far over all layers (binning keeps those
    // that may cover each face), for tests and benchmarks.
    std::uint64_t drawn_triangles() const { return drawn_triangles_; }
    // Cube: the directions that the CPU tracer answered, over all traces.
    std::uint64_t edge_rays() const { return edge_rays_; }

    void set_mesh(const Mesh& mesh, BackFaces back_faces = BackFaces::Occlude) override;
    std::uint32_t set_rule(const TraceRule& rule) override;
    void trace(const TraceChunk& chunk) override;
    bool prefers_large_chunks() const override { return true; }
    int structures_per_mesh() const override { return 2; } // the maps and the CPU tracer's (edges, near field)

private:
    struct State;
    // One dispatch of the compute pass (raster_tracer.cpp).
    struct BitsPass {
        std::uint32_t count = 0, first = 0;            // vertices, and the first one's slot in the chunk
        std::uint32_t first_word = 0, word_count = 0;  // the words written
        std::uint32_t first_point = 0, last_point = 0; // the directions drawn, [first, last)
        float far = 0.0f;                              // cube: the near plane; directional: depth range
        float texel = 0.0f;                            // directional: texel size (the normal offset)
    };
    void build_programs();
    void set_cube_mesh(const Mesh& mesh);
    void run_bits(const BitsPass& pass);
    void trace_cube(const TraceChunk& chunk);
    void trace_directional(const TraceChunk& chunk);
    void answer_near_field(const TraceChunk& chunk, std::vector<std::uint32_t>& blocked);
    void answer_edges(const TraceChunk& chunk, std::vector<std::uint32_t>& blocked);

    TraceMethod method_;
    std::uint32_t resolution_;
    bool auto_resolution_ = false; // cube: resolution_ follows the rule (set_rule)
    std::uint64_t drawn_triangles_ = 0; // cube: triangles drawn into layers, over all traces
    std::uint64_t edge_rays_ = 0;       // cube: directions the CPU tracer answered (answer_edges)
    std::unique_ptr<State> s_;
};

// The directional method's near field (docs/baking.md, answer_near_field): the
// look-up point's offset from the ray origin and the distance within which the
// maps' answer is checked by rays of the CPU tracer, in texels of the maps,
// and that tracer.
inline constexpr float kLookupTexels = 2.1214f;
inline constexpr float kNearFieldTexels = 16.0f;
inline constexpr const char* kNearFieldTracer = "embree";

} // namespace skybake::visibility
