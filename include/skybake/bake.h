// skybake/bake.h: per-vertex ambient occlusion, shading coefficient and bent
// normals (seed 002: Svistunov, GPU computation of shading coefficients).
//
// [SECTION] Definitions
// [SECTION] Bake options
// [SECTION] Bake outputs
// [SECTION] The bake driver
// [SECTION] Bake a mesh
// [SECTION] Reduction of stored visibility bits
// [SECTION] Visibility bits file
// [SECTION] Preview image
//
// See docs/baking.md for the maths, the options, the measured errors and the
// command line (`skybake ao`).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"

namespace skybake {

// [SECTION] Definitions ---------------------------------------------------------------
//
// With the normalised measure dμ = dω/4π, the unit vertex normal n and the
// visibility V(x) ∈ {0, 1} (0 below the horizon or when the ray from the vertex
// along x hits the mesh):
//   ambient occlusion  AO = 4 ∫ V (n·x)+ dμ = (1/π) ∫_H V cos dω   (seed's V0)
//   shading coeff.     A  = 2 ∫ V dμ        = (1/2π) ∫_H V dω
//   bent normal        b  = normalise(∫ V (n·x)+ x dμ): the cosine-weighted mean
//                      unoccluded direction (n when nothing is visible)
// All three are 1 / n for a vertex that sees the whole hemisphere. A sphere rule
// {x_k, w_k} replaces the integrals by sums ([SECTION] Bake options).

// [SECTION] Bake options --------------------------------------------------------------
//
// For every vertex p with unit normal n, and every direction x_k of a sphere
// rule {x_k, w_k} (turned by the vertex's random rotation when the rule asks
// for it), the bake decides the seed's visibility
//     V_p(x_k) = 1  if n·x_k ≥ 0 and the ray from p along x_k leaves the mesh,
//                0  otherwise (below the horizon, or blocked),
// and sums
//     AO = Σ_k w_k 4 (n·x_k)+ V_k,     A = Σ_k w_k 2 H(n·x_k) V_k,
//     bent normal = normalise(Σ_k w_k (n·x_k)+ V_k x_k),
// with H = 1 above the horizon, ½ on it (n·x_k = 0 exactly: symmetric rules
// put whole orbits there for axis-aligned normals; the midpoint value of the
// step keeps A unbiased) and 0 below. Directions below the horizon need no ray.
// A ray starts at
//     origin = p + (offset + ε)·(n + u),   t in (0, max_distance],
// where ε = 2^-15 · max(|p|∞, size of p's triangles), 256 to 512 units in
// the last place of a float (after Wächter & Binder, Ray Tracing Gems ch. 6, 2019):
// enough to clear the rounding of the ray–triangle tests at the vertex's own
// triangles, far less than any real gap between surfaces, and independent of
// the scene's size. The user offset is 0 by default. u is zero for most vertices; for a vertex
// on a mesh border or where two surfaces meet (its triangles' area-weighted
// mean centroid is off the vertex) it is the unit tangent towards that
// centroid: a floor vertex at the foot of a wall, or the bottom edge of a box
// standing on the ground, then starts its rays on its own side of the other
// surface instead of on it.

// The range every tracer takes (Embree, the CUDA BVH, the raster's depth
// maps): mesh coordinates and the ray offset up to 1e17 mesh units each.
// Embree treats a ray whose origin has a coordinate beyond ±1.844e18
// (FLT_LARGE) as invalid and aborts; 1e17 + 1e17·√2 stays an order of
// magnitude inside it, and squared distances (≤ 1e35) inside a float. The
// bake refuses more with an Error naming "mesh" or "ray_offset".
inline constexpr double kMaxTraceCoordinate = 1e17;
inline constexpr double kMaxRayOffset = 1e17;

struct BakeOptions {
    // Occluders further than this from the ray origin are ignored, in mesh units.
    // Infinity (the default) means unlimited; must be > 0.
    float max_distance = std::numeric_limits<float>::infinity();
    // Distance the ray origin is moved along the vertex normal (and, on borders
    // and creases, towards the vertex's triangles), in mesh units, on top of
    // the step past rounding that every origin gets. In [0, kMaxRayOffset];
    // 0 by default. A negative value means 0 (the former "scene-relative default").
    float ray_offset = 0.0f;
    BackFaces back_faces = BackFaces::Occlude;
    // false (the seed's definition): the sums above, clamped to [0, 1] (rules
    //   with negative weights, and the rule's own error for the clamped cosine,
    //   can push them slightly out).
    // true: divide each sum by its value with V ≡ 1, so that an unoccluded
    //   vertex gets exactly 1 whatever the rule (a ratio estimator).
    bool normalize = false;
    // Keep the visibility bits (BakeOutputs::visibility_bits).
    bool store_bits = false;
    // How blockers are found: must be the tracer's method (VisibilityTracer::method());
    // the by-name bake_ambient_occlusion() creates the tracer with it.
    TraceMethod method = TraceMethod::Bvh;
};

// The ray offset a bake uses: options.ray_offset if > 0, else 0.
float resolve_ray_offset(const Mesh& mesh, const BakeOptions& options);

// [SECTION] Bake outputs ----------------------------------------------------------------
//
// The visibility bits are in the layout of skybake/visibility.h ([SECTION]
// Visibility words).
struct BakeOutputs {
    // One entry per vertex.
    std::vector<float> ao;              // cosine-weighted visibility V0 (seed 002, def. 1), in [0, 1]
    std::vector<float> shading;         // uniform shading coefficient A (seed 002, def. 2), in [0, 1]
    std::vector<glm::vec3> bent_normal; // unit; normalised Σ_k w_k V_k (n·x_k)+ x_k, or n when nothing is visible
    // Visibility bits (empty unless BakeOptions::store_bits).
    std::uint32_t directions = 0;       // K, the rule's point count
    std::uint32_t words_per_vertex = 0; // ceil(K / 32)
    std::vector<std::uint32_t> visibility_bits;
    // Statistics.
    std::uint64_t rays = 0;             // rays traced (directions on or above the horizon)
    std::uint64_t clamped_vertices = 0; // vertices whose AO or A sum left [0, 1] and was clamped
    float ray_offset = 0.0f;            // offset used, mesh units
    double build_seconds = 0.0;         // acceleration structure
    double trace_seconds = 0.0;         // rays and reduction

    // V of direction k at vertex v (store_bits only).
    bool visible(std::size_t vertex, std::size_t direction) const {
        return (visibility_bits[vertex * words_per_vertex + direction / 32] >> (direction % 32)) & 1u;
    }
};


// [SECTION] The bake driver -------------------------------------------------------------
//
//   mesh ─► driver ─► tracer ─► visibility words ─► reduction ─► attributes ─► glTF
//
// bake_visibility() is the one bake loop. It checks the inputs, computes each
// vertex's ray origin and normal (and rotation), orders the rule's directions
// coherently, cuts the vertices into chunks that fit the tracer's and its own
// memory budget, has the tracer fill each chunk's visibility words and hands
// them to a reduction, with progress, timing and statistics. Tracers
// (skybake/visibility.h) know nothing of what the words become; reductions
// know nothing of how they were traced.

// The rule of a bake as reductions see it: single precision, visiting order.
struct VisibilityRule {
    std::span<const glm::vec3> points;    // points[j] is rule direction order[j], unit
    std::span<const float> weights;       // weights[j] of points[j]
    std::span<const std::uint32_t> order; // visiting position j → rule index k
    std::uint32_t words_per_vertex = 0;
    bool rotate = false;                  // per-vertex rotations (VisibilityChunk::rotations)
};

// One traced chunk, as a reduction receives it.
struct VisibilityChunk {
    std::uint32_t first = 0, count = 0;       // mesh vertices [first, first + count)
    std::span<const glm::vec3> normals;       // unit, count
    std::span<const glm::mat3> rotations;     // count when the rule rotates, else empty
    std::span<const std::uint32_t> words;     // count × words_per_vertex; empty when only device_words is set
    const std::uint32_t* device_words = nullptr; // the same words in GPU memory (GPU tracers), or nullptr
};

class VisibilityReduction {
public:
    virtual ~VisibilityReduction() = default;
    // Before the first chunk: the rule and the vertex count.
    virtual void begin(const VisibilityRule& rule, std::size_t vertices) = 0;
    // Whether reduce() can read VisibilityChunk::device_words alone, so that
    // a GPU tracer need not copy the words back.
    virtual bool reduces_on_device() const { return false; }
    // Reduces one chunk (chunks come in order, one at a time). Returns the
    // chunk's rays: its directions on or above each vertex's horizon.
    virtual std::uint64_t reduce(const VisibilityChunk& chunk) = 0;
};

struct VisibilityBakeStats {
    std::uint64_t rays = 0;     // directions on or above the horizons, summed over vertices
    float ray_offset = 0.0f;    // mesh units
    std::uint32_t chunks = 0;   // trace() calls
    double build_seconds = 0.0; // tracer's acceleration structure
    double trace_seconds = 0.0; // tracing and reduction
};

// Runs the bake. mesh needs unit normals (mesh.normals, one per vertex).
// Throws skybake::Error on an invalid mesh ("mesh"), rule ("rule") or option
// (named by its BakeOptions field: "max_distance", "ray_offset", "method"),
// and skybake::Interrupted after SIGINT or SIGTERM.
VisibilityBakeStats bake_visibility(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                                    const BakeOptions& options, VisibilityReduction& reduction);

// The trace inputs of one chunk of a bake's sample points, as the driver
// builds them for trace(): the buffers, and the chunk that views them.
struct ChunkInputs {
    std::vector<glm::vec3> origins, normals, offsets;
    std::vector<glm::mat3> rotations; // empty unless the rule rotates
};
// Fills `buffers` with the inputs of points [first, first + count) and
// returns the TraceChunk over them, writing into `words` (count ×
// words_per_vertex entries, or empty for device words). Safe to call from
// several threads at once with distinct buffers.
using ChunkBuilder = std::function<TraceChunk(std::uint32_t first, std::uint32_t count, ChunkInputs& buffers,
                                              std::span<std::uint32_t> words)>;

// A tracer that traces all of a bake's points before the driver's loop (the
// distributed bake, skybake/distributed.h): after set_rule(), the driver
// calls trace_points() once with the point count and a builder of any
// chunk's inputs; its loop then calls trace() as usual, in order, and the
// tracer hands out the words it traced then.
class WholeBakeTracer : public VisibilityTracer {
public:
    virtual void trace_points(std::uint32_t points, const ChunkBuilder& build) = 0;
};

// Sample points other than the mesh's vertices (texel centres of a texture
// bake, skybake/texture_bake.h): the bake measures visibility at points on
// the mesh's surface, of which its vertices are one kind. Point i's ray
// origin is positions[i] + (offset + ε)·normals[i], with ε the rounding step
// of [SECTION] Bake options for a triangle of size sizes[i]; reductions see
// point i where they would see vertex i.
struct SamplePoints {
    std::vector<glm::vec3> positions; // world space, on the mesh's surface
    std::vector<glm::vec3> normals;   // unit, world space; as many as positions
    std::vector<float> sizes;         // each point's footprint (e.g. a texel), mesh units; as many
};

// Same as bake_visibility() above, at `points` instead of the vertices: the
// mesh is the geometry that occludes. Also throws for arrays of different
// sizes ("points").
VisibilityBakeStats bake_visibility(const Mesh& mesh, const SamplePoints& points, const SphereRule& rule,
                                    VisibilityTracer& tracer, const BakeOptions& options,
                                    VisibilityReduction& reduction);

// [SECTION] Passes over the bake's rays -------------------------------------------
//
// Work that needs hits rather than bits, from the ray origins of
// bake_visibility() (the same vertex normals, offsets and rounding steps): a
// bounce or a sun ray leaves a vertex where its visibility rays left it.

// The unit normal of each vertex as a bake uses it, the horizon of its
// directions: mesh.normals normalised or, where one is zero or not finite,
// the area-weighted normal of the vertex's triangles.
std::vector<glm::vec3> bake_vertex_normals(const Mesh& mesh);

// One blocked direction of a vertex, and what blocks it.
struct BlockedDirection {
    std::uint32_t vertex = 0;
    std::uint32_t direction = 0; // rule index k
    float weight = 0.0f;         // the rule's weight of k, single precision
    float cosine = 0.0f;         // n · x_k, > 0
    RayHit hit;                  // the closest blocker; triangle kNoHit past max_distance
};

// Every vertex's directions above its horizon (n · x_k > 0) whose bit in
// `words` is 0, each with the closest hit of the ray from the vertex's ray
// origin along it: by vertex, then in the bake's visiting order. `words` as
// bake_visibility() stores them (skybake/visibility.h, [SECTION] Visibility
// words) for the same mesh, rule and options; `queries` holds the mesh. The
// gather of the bounces of skybake/prt.h. Throws skybake::Error ("words")
// when the words do not fit the mesh and the rule.
std::vector<BlockedDirection> blocked_directions(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options,
                                                 std::span<const std::uint32_t> words, const RayQueries& queries);

// Per vertex: 1 where the vertex faces `direction` (n · d ≥ 0, d unit) and
// the ray from its ray origin along d meets nothing within max_distance, else 0.
std::vector<std::uint8_t> direction_visibility(const Mesh& mesh, const glm::vec3& direction,
                                               const BakeOptions& options, const RayQueries& queries);

// The reduction behind bake_ambient_occlusion(): AO, A and the bent normal of
// every vertex into `out` (and the words, with options.store_bits).
class ShadingReduction final : public VisibilityReduction {
public:
    ShadingReduction(BakeOutputs& out, bool normalize, bool store_bits);
    void begin(const VisibilityRule& rule, std::size_t vertices) override;
    bool reduces_on_device() const override;
    std::uint64_t reduce(const VisibilityChunk& chunk) override;

private:
    BakeOutputs& out_;
    bool normalize_, store_bits_;
    VisibilityRule rule_;
};

// The whole AO bake (see [SECTION] Bake options) into `out`: bake_visibility()
// with a ShadingReduction.
void bake_shading(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, const BakeOptions& options,
                  BakeOutputs& out);

// [SECTION] Bake a mesh ------------------------------------------------------------------

struct AoBakeReport {
    std::string backend;           // "embree", "cuda", "brute"
    std::string method;            // "bvh", "per-vertex", "per-polygon" (BakeOptions::method)
    std::string rule;              // canonical rule spec
    std::size_t vertices = 0;
    std::size_t triangles = 0;
    std::size_t directions = 0;    // rule points
    std::uint64_t rays = 0;        // rays traced (directions on or above each vertex's horizon)
    double seconds = 0.0;          // whole bake: BVH build + rays + reduction
    double build_seconds = 0.0;    // BVH build
    double trace_seconds = 0.0;    // rays + reduction
    float ray_offset = 0.0f;       // mesh units
    bool negative_weights = false; // the rule has negative weights (Lebedev 74/230/266)
    std::uint64_t clamped_vertices = 0; // vertices whose AO or A sum was clamped to [0, 1]
    double rays_per_second() const { return trace_seconds > 0.0 ? double(rays) / trace_seconds : 0.0; }
};

// Bakes the mesh with the given backend and stores the results on it:
//   attribute "ao" (1 component), "shading" (1), "bent_normal" (3, unit, world space)
//   and mesh.colors = (AO, AO, AO, 1) in linear RGB (replacing any colours), so
//   that any glTF viewer shows the occlusion as COLOR_0.
// Computes area-weighted normals first when the mesh has none. `outputs`, when
// given, receives the raw backend outputs (with the visibility bits when
// options.store_bits). Throws skybake::Error on an invalid mesh, rule or options.
AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                                    const BakeOptions& options = {}, BakeOutputs* outputs = nullptr);
// Same, creating the tracer by name ("embree", "brute", "cuda") with options.method.
AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, const std::string& backend = "embree",
                                    const BakeOptions& options = {}, BakeOutputs* outputs = nullptr);

// [SECTION] Reduction of stored visibility bits --------------------------------------------

struct ShadingCoefficients {
    float ao = 0.0f;
    float shading = 0.0f;
    glm::vec3 bent_normal{0.0f, 0.0f, 1.0f};
};

// Recomputes one vertex's coefficients from its visibility words (layout in
// skybake/visibility.h; words.size() ≥ ceil(rule.size() / 32)), with the same
// single-precision arithmetic as the backends: the result equals the bake's.
// vertex: the vertex index (it selects the rotation of a "+rotate" rule);
// normal: unit, world space.
ShadingCoefficients shading_from_bits(std::span<const std::uint32_t> words, const SphereRule& rule,
                                      std::uint32_t vertex, const glm::vec3& normal, bool normalize = false);

// [SECTION] Visibility bits file ----------------------------------------------------------
//
// A little-endian binary file (extension .bin or .vis by convention):
//   8 bytes   magic "SKBVIS01"
//   uint32    vertex count V
//   uint32    direction count K (the rule's point count)
//   uint32    words per vertex W = ceil(K / 32)
//   uint32    byte length L of the rule spec
//   L bytes   the canonical rule spec (parse_rule() rebuilds the directions,
//             including a "+rotate=SEED" rotation), UTF-8, no terminator
//   V·W uint32 words, vertex after vertex, in the layout of skybake/visibility.h.
struct VisibilityBits {
    std::string rule;
    std::uint32_t vertices = 0;
    std::uint32_t directions = 0;
    std::uint32_t words_per_vertex = 0;
    std::vector<std::uint32_t> words; // vertices * words_per_vertex
};

// Writes outputs.visibility_bits (the bake must have had store_bits). Atomic.
void save_visibility_bits(const std::filesystem::path& path, const BakeOutputs& outputs, const SphereRule& rule);
// Reads and checks a file written by save_visibility_bits(). Throws
// skybake::Error on a missing, truncated or inconsistent file.
VisibilityBits load_visibility_bits(const std::filesystem::path& path);

// [SECTION] Preview image -------------------------------------------------------------------

struct AoPreviewOptions {
    int width = 960;           // pixels
    int height = 720;          // pixels
    float azimuth_deg = 35.0f; // camera around the +y axis, from +z towards +x
    float elevation_deg = 30.0f; // camera above the xz plane
    float fov_y_deg = 35.0f;   // vertical field of view
    int samples = 2;           // per pixel and axis (2: 4 samples per pixel)
    // Ray queries that already hold this mesh with both sides occluding (a
    // bake's backend), used instead of building an Embree scene; or nullptr.
    const RayQueries* queries = nullptr;
};

// The camera of the previews (and of `skybake view MODEL`): a pinhole looking
// at the centre of the mesh's bounding box from (azimuth, elevation), far
// enough that the bounding sphere fits the frame. The ray through pixel
// (x + 0.5, y + 0.5) of a width × height image, top row first, is
// normalize(forward + cx · right + cy · up) with
// cx = (2 (x + 0.5) / width − 1) · tan_half_fov_y · aspect, cy = (1 − 2 (y + 0.5) / height) · tan_half_fov_y.
struct PreviewCamera {
    glm::vec3 eye{0.0f}, forward{0.0f, 0.0f, -1.0f}, right{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f}; // world space
    float tan_half_fov_y = 0.0f, aspect = 1.0f;
    glm::vec3 centre{0.0f}; // of the bounding box
    float radius = 0.0f;    // of the bounding sphere, world units
};
PreviewCamera preview_camera(const Mesh& mesh, const AoPreviewOptions& options);

// Ray-casts the mesh (Embree) from a camera that frames its bounding sphere and
// shades each visible point by the baked AO, interpolated across the triangle,
// as a display value: the linear pixel is srgb_to_linear(AO), so that a PNG
// written with save_image(..., ToneMap{0, ToneCurve::Clamp}) has grey level
// 255·AO. Background: a dark blue-grey. 2×2 samples per pixel by default. The
// mesh must carry the "ao" attribute.
Image render_ao_preview(const Mesh& mesh, const AoPreviewOptions& options = {});
// The same camera, shading each visible point by a per-vertex linear RGB value
// (linear_rgb: mesh.vertex_count() entries) interpolated across the triangle.
Image render_vertex_preview(const Mesh& mesh, std::span<const glm::vec3> linear_rgb,
                            const AoPreviewOptions& options = {});

} // namespace skybake
