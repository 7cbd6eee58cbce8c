// skybake/visibility.h: what a triangle mesh hides, as ray queries and as the
// bit-packed per-vertex visibility that the bakes reduce (seed 002: Svistunov,
// GPU computation of shading coefficients).
//
// [SECTION] Rays and hits
// [SECTION] Ray queries
// [SECTION] Visibility words
// [SECTION] Visibility tracers
// [SECTION] Backends
//
// Two interfaces, because not every backend can answer every question:
//   RayQueries        occluded() and intersect() for arbitrary rays
//   VisibilityTracer  for a chunk of vertices and a sphere rule, the
//                     visibility words of [SECTION] Visibility words
// The bake driver (skybake/bake.h) owns everything around trace(): input
// checks, ray origins, the direction order, chunking, progress and timing;
// reductions (AO, SH transfer, ...) turn the words into vertex attributes.
//
// Backends (docs/baking.md):
//   "embree"  Intel Embree 3 on the CPU, TBB-parallel (default): 16-ray packets
//             for rules of 1000+ directions, single rays for smaller ones
//   "brute"   every ray against every triangle, in double precision: a test
//             oracle for small meshes only
//   "cuda"    NVIDIA GPUs (builds that have CUDA, machines that have a GPU): a
//             BVH built on the CPU with Embree's builder, walked by one GPU
//             thread per ray. Also the seed's brute-force methods (TraceMethod)
//   "raster"  the depth buffer of any OpenGL 4.3 context (a GPU, or Mesa's
//             llvmpipe): a depth cube map per vertex (the seed's method) or a
//             depth map per direction. A VisibilityTracer only: rasterisation
//             answers no single ray
// The first three implement both interfaces.
//
// Frames and units: everything is in the mesh's world space and its own length
// unit ("mesh units"); directions are unit vectors in the same frame.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace skybake {

struct Mesh;

// [SECTION] Rays and hits ------------------------------------------------------------

// A ray segment: the points origin + t·direction for t_min < t ≤ t_max.
struct Ray {
    glm::vec3 origin{0.0f};           // world space, mesh units
    float t_min = 0.0f;               // ≥ 0, in units of |direction|
    glm::vec3 direction{0.0f, 0.0f, 1.0f}; // world space; unit length for t in mesh units
    float t_max = std::numeric_limits<float>::infinity(); // > t_min; may be infinite
};

inline constexpr std::uint32_t kNoHit = 0xffffffffu;

// Closest hit of a ray. triangle is the index of the triangle (indices[3·triangle ...])
// or kNoHit; (u, v) are the barycentric weights of its second and third vertex.
struct RayHit {
    float t = std::numeric_limits<float>::infinity();
    std::uint32_t triangle = kNoHit;
    float u = 0.0f, v = 0.0f;
};

// Which side of a triangle blocks a ray. The front side is the one its
// counter-clockwise winding faces (Mesh convention).
enum class BackFaces : int {
    Occlude = 0, // both sides block (default: any surface casts a shadow)
    Ignore = 1,  // rays pass through triangles they meet from behind: for open,
                 // single-sided meshes whose back sides are never meant to be seen
};
const char* back_faces_name(BackFaces mode); // "occlude", "ignore"
// Parses "occlude" or "ignore"; throws skybake::Error otherwise.
BackFaces parse_back_faces(const std::string& text);

// How a backend finds blockers (BakeOptions::method).
//  - The cuda backend's three methods decide the same ray–triangle test on the
//    same triangles, so all three give the same bits; they differ in speed only
//    (docs/PERFORMANCE.md).
//  - The raster backend's two methods answer with the depth buffer instead of
//    rays: they agree with the ray tracers up to texel size and depth bias
//    (docs/baking.md).
enum class TraceMethod : int {
    Bvh = 0,         // "bvh": the BVH (the default and only method of embree, brute; cuda's default)
    PerVertex = 1,   // "per-vertex": cuda, the seed's naive method, every triangle for every ray
    PerPolygon = 2,  // "per-polygon": cuda, every triangle too, in tiles cached in shared memory
    Cube = 3,        // "cube": raster (default), the seed's depth cube map at each vertex
    Directional = 4, // "directional": raster, one orthographic depth map per rule direction
};
const char* trace_method_name(TraceMethod method); // "bvh", "per-vertex", "per-polygon", "cube", "directional"
// A registered backend's default method (its first); throws
// skybake::Error ("backend") for an unknown name.
TraceMethod default_trace_method(const std::string& backend);
// Parses a name above; throws skybake::Error otherwise.
TraceMethod parse_trace_method(const std::string& text);


// [SECTION] Ray queries ----------------------------------------------------------------

class RayQueries {
public:
    virtual ~RayQueries() = default;

    // "embree", "brute", "cuda"
    virtual const char* name() const = 0;

    // Builds the acceleration structure for mesh.positions and mesh.indices,
    // replacing any previous mesh. The backend keeps its own copy.
    // Throws skybake::Error if the mesh is invalid or too large for the backend.
    virtual void set_mesh(const Mesh& mesh, BackFaces back_faces = BackFaces::Occlude) = 0;

    // Occlusion queries against the current mesh: occluded[i] = 1 if some
    // triangle meets rays[i] within (t_min, t_max], else 0. occluded.size() must
    // equal rays.size(). Thread-safe; parallel inside for large batches.
    virtual void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const = 0;

    // Closest hits against the current mesh; hits.size() must equal rays.size().
    virtual void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const = 0;
};

// [SECTION] Visibility words -------------------------------------------------------------
//
// Seed 002's compact form of visibility (the seed uses uint16 words of 16
// directions; skybake uses uint32 words of 32). For a rule of K directions,
// vertex v owns words_per_vertex = ceil(K / 32) consecutive words starting at
// v·words_per_vertex; the bit of rule direction k is bit (k mod 32) (least
// significant first) of word k / 32. A set bit means V = 1: the direction is not
// below the vertex's horizon (n·x ≥ 0) and the ray from the vertex's ray origin
// along it leaves the mesh. Unused high bits of a vertex's last word are 0.
// Direction k is the rule's k-th point, turned by the vertex's rotation when
// the rule has "+rotate". Bits below the horizon are 0; bits exactly on it hold
// the grazing ray's answer.

inline constexpr std::uint32_t visibility_words(std::uint32_t directions) { return (directions + 31u) / 32u; }

// [SECTION] Visibility tracers ---------------------------------------------------------------

// The rule of one bake as a tracer sees it, fixed for the whole bake. The
// directions come in the driver's visiting order, in which consecutive
// directions are close on the sphere (coherent packets and warps).
struct TraceRule {
    std::span<const glm::vec3> points;   // visiting order: points[j] is rule direction order[j], unit
    std::span<const std::uint32_t> order; // a permutation of 0 ... K−1
    std::uint32_t words_per_vertex = 0;  // visibility_words(K)
    bool rotate = false;                 // TraceChunk::rotations turn the points, vertex by vertex
    float t_max = std::numeric_limits<float>::infinity(); // occluders further than this are ignored, mesh units
};

// One chunk of vertices. Every span has `count` entries (words: count ×
// words_per_vertex) except rotations, which is empty unless the rule rotates.
struct TraceChunk {
    std::uint32_t first = 0;                // index of the chunk's first vertex in the mesh
    std::uint32_t count = 0;
    std::span<const glm::vec3> origins;     // ray origins, mesh units
    std::span<const glm::vec3> normals;     // unit: the horizon of each vertex
    // Unit: the direction in which the driver moved each origin off its point
    // (the normal, or on borders and creases the normal plus a tangent towards
    // the vertex's triangles, normalised). May be empty: then the normals.
    std::span<const glm::vec3> offsets;
    std::span<const glm::mat3> rotations;   // direction k of vertex v is rotations[v]·x_k
    // Output, in the layout of [SECTION] Visibility words: trace() writes every
    // word. May be empty for a tracer with device_words_supported(): the
    // caller then reads VisibilityTracer::device_words() instead.
    std::span<std::uint32_t> words;
};

class VisibilityTracer {
public:
    virtual ~VisibilityTracer() = default;

    // "embree", "brute", "cuda", "raster"
    virtual const char* name() const = 0;
    // How blockers are found; TraceMethod::Bvh except for the cuda backend's
    // brute-force methods and the raster backend.
    virtual TraceMethod method() const { return TraceMethod::Bvh; }
    // The GPU's name for a GPU tracer, empty on the CPU (the raster backend:
    // the OpenGL renderer, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
    virtual std::string device_name() const { return {}; }

    // As RayQueries::set_mesh().
    virtual void set_mesh(const Mesh& mesh, BackFaces back_faces = BackFaces::Occlude) = 0;
    // Called once per bake, after set_mesh() and before trace(); `rule` stays
    // valid until the next call. Returns the most vertices one trace() call
    // may take (the tracer's memory and launch limits).
    virtual std::uint32_t set_rule(const TraceRule& rule) = 0;
    // Fills chunk.words (and the device words, for a GPU tracer). The result
    // of a vertex depends on that vertex's inputs alone, not on the chunking
    // or the thread count. Throws skybake::Error on a device failure, and
    // skybake::Interrupted after SIGINT or SIGTERM.
    virtual void trace(const TraceChunk& chunk) = 0;
    // Whether the tracer keeps each chunk's words in GPU memory too, so that
    // TraceChunk::words may be empty.
    virtual bool device_words_supported() const { return false; }
    // A GPU tracer's copy of the last chunk's words in device memory (same
    // layout), or nullptr: a reduction with a CUDA kernel can read them there.
    virtual const std::uint32_t* device_words() const { return nullptr; }
    // Whether each trace() call has a fixed cost worth spreading (a GPU
    // launch; the raster backend's depth maps of every direction): the driver
    // then gives it the largest chunks that set_rule() and memory allow,
    // instead of chunks sized for progress and interrupts.
    virtual bool prefers_large_chunks() const { return device_words_supported(); }
    // How many acceleration structures set_mesh() builds (the raster
    // backend's directional method: its maps' mesh and the CPU tracer's scene
    // for the near field); a bake job's report counts them.
    virtual int structures_per_mesh() const { return 1; }
};

// [SECTION] Backends -----------------------------------------------------------------------
//
// Every backend registers itself, as Dear ImGui's backends declare theirs:
// its name, where it runs, what it can do and its factories. The command
// line, Python and Blender list their choices from here, and one function,
// resolve_tracer(), turns a request (device, backend, method, resolution)
// into a choice with the same rules and messages for every front end.
//
// Adding a backend (docs/baking.md, "Adding a backend"): write it in its own
// folder under src/visibility/, give that folder a function
//     void skybake_register_<name>_tracer();
// that calls register_tracer_backend(), and add <name> to
// SKYBAKE_TRACER_BACKENDS in src/CMakeLists.txt. Nothing else changes.

// A backend as registered.
struct TracerBackend {
    std::string name;                 // "embree"; unique
    std::string device;               // where it runs: "cpu", "cuda" or "opengl"
    std::string summary;              // one line for --help, e.g. "Intel Embree 3 on the CPU"
    std::vector<TraceMethod> methods; // the methods it owns, its default first; not empty
    bool closest_hit = false;         // answers RayQueries too (bounces, sun rays, previews)
    bool resolution = false;          // takes a resolution in texels (TracerRequest::resolution)
    // Creates a tracer with one of `methods` and a resolution (0: the
    // backend's default; always 0 for a backend without `resolution`).
    std::function<std::unique_ptr<VisibilityTracer>(TraceMethod method, std::uint32_t resolution)> make_tracer;
    // Creates ray queries; empty unless closest_hit.
    std::function<std::unique_ptr<RayQueries>()> make_ray_queries;
    // Why it cannot run on this machine now, in one line (no GPU, no
    // OpenGL 4.3 context, a build without CUDA); empty when it can. May be
    // slow (it opens a context); empty function: it always can.
    std::function<std::string()> problem;
};

// Adds a backend. Throws skybake::Error ("backend") for an empty or taken
// name, an empty method list or a missing factory.
void register_tracer_backend(TracerBackend backend);
// Every registered backend, in registration order (SKYBAKE_TRACER_BACKENDS).
const std::deque<TracerBackend>& tracer_backends();
// The backend of that name; throws skybake::Error ("backend") naming the
// registered ones otherwise.
const TracerBackend& find_tracer_backend(const std::string& name);
// The registered names, in registration order.
std::vector<std::string> visibility_backend_names();

// Where a bake should run, as a user says it.
struct TracerRequest {
    // "auto": a CUDA backend when a CUDA device answers, else the CPU's;
    // "cpu", "cuda" or "opengl": that device's default backend (the first
    // registered there), or the backend's device when `backend` is given.
    std::string device = "auto";
    std::string backend;          // a registered name; empty: the device's default
    std::string method;           // one of the backend's; empty: its default
    std::uint32_t resolution = 0; // texels, for a backend with `resolution`; 0: its default
    bool closest_hit = false;     // the bake also needs closest hits (bounces)
};

// A request resolved: a registered backend and one of its methods.
struct TracerChoice {
    const TracerBackend* backend = nullptr;
    TraceMethod method = TraceMethod::Bvh;
    std::uint32_t resolution = 0; // as requested (0: the backend's default)
    std::string device;           // the backend's device
};

// Resolves a request. Throws skybake::Error naming the field at fault:
// "device" (unknown, or not the backend's), "backend" (unknown, or no
// closest hits when they are needed), "method" (not the backend's) or
// "resolution" (for a backend that takes none). The messages list the
// registered choices. Does not probe the device: make_visibility_tracer()
// fails when it is absent.
TracerChoice resolve_tracer(const TracerRequest& request);

// Create a backend's tracer or ray queries. Throw skybake::Error ("device"
// or "backend") when it cannot run here: "cuda" in a build without CUDA or
// on a machine without a CUDA device, "raster" without an OpenGL 4.3
// context; ray queries of a backend without closest hits ("backend").
std::unique_ptr<VisibilityTracer> make_visibility_tracer(const TracerChoice& choice);
std::unique_ptr<RayQueries> make_ray_queries(const TracerChoice& choice);
// The same by backend name, with a method and a resolution for the tracer.
std::unique_ptr<RayQueries> make_ray_queries(const std::string& name);
std::unique_ptr<VisibilityTracer> make_visibility_tracer(const std::string& name,
                                                         TraceMethod method = TraceMethod::Bvh,
                                                         std::uint32_t resolution = 0);

// The raster backend's default resolutions, and the largest it takes. The
// cube method's follows the rule: faces whose texels, at their centre, are
// no wider than the rule's mean spacing √(4π/N) (π/2 / resolution ≤
// spacing), rounded up to a multiple of 8 from 16 to 256 (16 for
// lebedev:590, 24 for lebedev:2030, 40 for lebedev:5810). The cube finds the
// blockers; every direction whose texel or its eight neighbours disagree is
// traced by a ray, so a coarse cube stays exact at blockers' edges.
std::uint32_t raster_cube_resolution(std::size_t rule_points);
inline constexpr std::uint32_t kRasterDirectionalResolution = 2048;
inline constexpr std::uint32_t kRasterMaxResolution = 8192;

// The brute-force backend refuses meshes with more triangles than this.
inline constexpr std::size_t kBruteForceMaxTriangles = 20'000;

} // namespace skybake
