// skybake/bake.h: per-vertex ambient occlusion, shading coefficient and bent
// normals (seed 002: Svistunov, GPU computation of shading coefficients).
//
// [SECTION] Definitions
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
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "skybake/image.h"
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
// {x_k, w_k} replaces the integrals by sums (skybake/visibility.h, BakeOptions).

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
AoBakeReport bake_ambient_occlusion(Mesh& mesh, const SphereRule& rule, VisibilityBackend& backend,
                                    const BakeOptions& options = {}, BakeOutputs* outputs = nullptr);
// Same, creating the backend by name ("embree", "brute").
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
};

// Ray-casts the mesh (Embree) from a camera that frames its bounding sphere and
// shades each visible point by the baked AO, interpolated across the triangle,
// as a display value: the linear pixel is srgb_to_linear(AO), so that a PNG
// written with save_image(..., ToneMap{0, ToneCurve::Clamp}) has grey level
// 255·AO. Background: a dark blue-grey. 2×2 samples per pixel by default. The
// mesh must carry the "ao" attribute.
Image render_ao_preview(const Mesh& mesh, const AoPreviewOptions& options = {});

} // namespace skybake
