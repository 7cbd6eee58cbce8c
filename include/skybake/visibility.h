// skybake/visibility.h: ray visibility against a triangle mesh, and the
// per-vertex visibility bake behind the shading coefficients of seed 002
// (Svistunov, GPU computation of shading coefficients).
//
// [SECTION] Rays and hits
// [SECTION] Bake options
// [SECTION] Bake outputs and the bit-packed visibility layout
// [SECTION] Backends
//
// One interface, several backends (docs/baking.md):
//   "embree"  Intel Embree 3 on the CPU, TBB-parallel (default): 16-ray packets
//             for rules of 1000+ directions, single rays for smaller ones
//   "brute"   every ray against every triangle, in double precision: a test
//             oracle for small meshes only
//   "cuda"    NVIDIA GPUs (builds that have CUDA, machines that have a GPU): a
//             BVH built on the CPU with Embree's builder, walked by one GPU
//             thread per ray; visibility packed into bits on the GPU and
//             reduced there. Also the seed's brute-force methods (TraceMethod)
//
// Frames and units: everything is in the mesh's world space and its own length
// unit ("mesh units"); directions are unit vectors in the same frame.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake {

struct Mesh;
struct SphereRule;

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

// How the cuda backend finds blockers (BakeOptions::method). Every method
// decides the same ray–triangle test on the same triangles, so all three give
// the same bits; they differ in speed only (docs/PERFORMANCE.md).
enum class TraceMethod : int {
    Bvh = 0,        // "bvh": the BVH (default; the only method of the CPU backends)
    PerVertex = 1,  // "per-vertex": the seed's naive method, every triangle for every ray
    PerPolygon = 2, // "per-polygon": every triangle too, in tiles cached in shared memory
};
const char* trace_method_name(TraceMethod method); // "bvh", "per-vertex", "per-polygon"
// Parses a name above; throws skybake::Error otherwise.
TraceMethod parse_trace_method(const std::string& text);

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
//     origin = p + offset·(n + u),   t in (0, max_distance],
// so that it does not hit the triangles around p itself. u is zero for most
// vertices; for a vertex on a mesh border or where two surfaces meet (its
// triangles' area-weighted mean centroid is off the vertex) it is the unit
// tangent towards that centroid: a floor vertex at the foot of a wall, or the
// bottom edge of a box standing on the ground, then starts its rays just off
// the other surface instead of on it.

// The default offset is this fraction of the mesh's bounding-box diagonal:
// scale-aware, so a bake does not change when the mesh is scaled or moved.
inline constexpr float kDefaultRayOffsetScale = 1e-4f;

struct BakeOptions {
    // Occluders further than this from the ray origin are ignored, in mesh units.
    // Infinity (the default) means unlimited; must be > 0.
    float max_distance = std::numeric_limits<float>::infinity();
    // Distance the ray origin is moved along the vertex normal (and, on borders
    // and creases, towards the vertex's triangles), in mesh units.
    // Negative (the default): kDefaultRayOffsetScale × bounding-box diagonal.
    float ray_offset = -1.0f;
    BackFaces back_faces = BackFaces::Occlude;
    // false (the seed's definition): the sums above, clamped to [0, 1] (rules
    //   with negative weights, and the rule's own error for the clamped cosine,
    //   can push them slightly out).
    // true: divide each sum by its value with V ≡ 1, so that an unoccluded
    //   vertex gets exactly 1 whatever the rule (a ratio estimator).
    bool normalize = false;
    // Keep the visibility bits (BakeOutputs::visibility_bits).
    bool store_bits = false;
    // The cuda backend's method; the CPU backends accept only TraceMethod::Bvh.
    TraceMethod method = TraceMethod::Bvh;
};

// The ray offset a bake uses for this mesh: options.ray_offset if ≥ 0, else
// kDefaultRayOffsetScale × the bounding-box diagonal.
float resolve_ray_offset(const Mesh& mesh, const BakeOptions& options);

// [SECTION] Bake outputs and the bit-packed visibility layout -------------------------
//
// Visibility bits, seed 002's compact form (the seed uses uint16 words of 16
// directions; skybake uses uint32 words of 32): vertex v owns words_per_vertex =
// ceil(K / 32) consecutive words starting at v·words_per_vertex; the bit of rule
// direction k is bit (k mod 32) (least significant first) of word k / 32. A set
// bit means V = 1 (visible: not below the horizon, and unblocked). Unused high bits of
// a vertex's last word are 0. Direction k is the rule's k-th point, turned by the
// vertex's rotation when the rule has "+rotate". Bits below the horizon are 0;
// bits exactly on it hold the grazing ray's answer.
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

// [SECTION] Backends -----------------------------------------------------------------------

class VisibilityBackend {
public:
    virtual ~VisibilityBackend() = default;

    // "embree", "brute", ...
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

    // The whole vertex × rule bake (see [SECTION] Bake options): calls
    // set_mesh(mesh, options.back_faces), then fills every field of `out`.
    // The mesh needs unit normals (mesh.normals, one per vertex). Results depend
    // only on the inputs, not on the thread count. Throws skybake::Error on an
    // invalid mesh, an empty rule or bad options.
    virtual void bake(const Mesh& mesh, const SphereRule& rule, const BakeOptions& options, BakeOutputs& out);
};

// Names accepted by make_visibility_backend() in this build ("cuda" only in
// builds with CUDA; it still needs a GPU at run time).
std::vector<std::string> visibility_backend_names();

// Creates a backend by name. Throws skybake::Error for an unknown name, and for
// "cuda" in a build without CUDA or on a machine without a CUDA device.
std::unique_ptr<VisibilityBackend> make_visibility_backend(const std::string& name);

// The brute-force backend refuses meshes with more triangles than this.
inline constexpr std::size_t kBruteForceMaxTriangles = 20'000;

} // namespace skybake
