// skybake/texture_bake.h: ambient occlusion baked into a texture over a
// mesh's UV layout.
//
// [SECTION] Sample points of a UV layout
// [SECTION] The bake
// [SECTION] Gutters and look-ups
//
// A texture bake measures visibility at the texel centres of the UV layout
// instead of at the vertices, through the same driver, tracer and reduction
// (bake_visibility() with SamplePoints, skybake/bake.h). See docs/baking.md,
// "Texture bakes".
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "skybake/bake.h"
#include "skybake/mesh.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"

namespace skybake {

// [SECTION] Sample points of a UV layout ----------------------------------------------

// The texture sizes a bake accepts, texels on a side.
inline constexpr int kMinTextureSize = 16, kMaxTextureSize = 16384;

struct TextureBakeOptions {
    int texture_size = 2048; // width and height in texels, kMinTextureSize to kMaxTextureSize
    int uv_set = 0;          // Mesh::texcoords index (glTF TEXCOORD_n)
    int dilate_texels = 8;   // gutter grown around every UV island, texels, 0 to 256
    bool stitch_seams = true; // make both sides of every UV seam read alike (stitch_texture_seams)
};

// The texels a UV layout covers, each with its point on the surface.
//
// Texel (x, y) is the square [x, x+1] × [y, y+1] in texel units, with u = x /
// size growing rightwards and v = y / size downwards (glTF's convention: row
// 0 is the image's top row). Coverage is conservative: a texel is covered
// when its square overlaps a triangle's UV footprint at all (separating axis
// test), so that bilinear look-ups at any UV inside an island read baked
// texels only. Its sample point is the triangle's point at the texel centre,
// or, for a centre outside every overlapping triangle, at the closest point
// of the nearest one, moved 0.1% towards that triangle's centroid; position
// and normal are interpolated barycentrically from the vertices.
struct TexelSamples {
    int texture_size = 0;
    SamplePoints points;               // one per covered texel, world space
    std::vector<std::uint32_t> texels; // y * texture_size + x of each point, increasing
    // Texels whose centre lies strictly inside the UV footprints of two or
    // more triangles: overlapping (or mirrored and stacked) UVs, which a
    // texture cannot hold two values for. The nearest triangle in the order
    // of the mesh's triangles wins.
    std::size_t overlapping_texels = 0;
    std::size_t overlapping_triangles = 0; // triangles that own at least one such texel centre
};

// Throws skybake::Error for a texture size out of range ("texture_size"), a
// dilation out of range ("dilate_texels"), a missing UV set ("uv_set"), UVs
// outside [0, 1] or not finite ("uv_set"), or an invalid mesh ("mesh").
TexelSamples texel_samples(const Mesh& mesh, const TextureBakeOptions& options);

// What stitch_texture_seams() did. A look-up pair is one point of a seam
// edge read on both of its sides; mismatch is |a − b| of such a pair.
struct SeamStitchReport {
    std::size_t seam_edges = 0;    // edge pairs with the same 3D end points and other UVs
    std::size_t lookups = 0;       // look-up pairs along them
    std::size_t texels_changed = 0; // texels under some look-up (the unknowns solved for)
    double mismatch_before_mean = 0.0, mismatch_before_max = 0.0;
    double mismatch_after_mean = 0.0, mismatch_after_max = 0.0;
};

// Makes a texture agree with itself across the seams of a UV layout (Liu,
// Ferguson & Jacobson 2017, "seam erasure"). A seam edge is an edge whose two
// triangles have the same end points in space (bit for bit) but other UVs:
// along it, sample_texture() at the UVs of one side should equal the other
// side's. The texels under those look-ups move as little as possible, in the
// least-squares sense, for them to agree; no other texel changes, and a
// constant texture stays as it is. values: size × size, row-major, in [0, 1]
// (results are clamped to it). Throws for a size that does not match values
// ("values") or a missing UV set ("uv_set").
SeamStitchReport stitch_texture_seams(const Mesh& mesh, int uv_set, std::vector<float>& values, int size);

// [SECTION] The bake --------------------------------------------------------------------

struct AoTexture {
    int texture_size = 0;
    std::vector<float> ao;              // size × size, row-major, top row first; in [0, 1]
    std::vector<std::uint8_t> coverage; // per texel: 0 empty (ao = 1), 1 baked, 2 gutter
    std::size_t covered_texels = 0;
    std::size_t overlapping_texels = 0, overlapping_triangles = 0;
    std::uint64_t rays = 0;
    double build_seconds = 0.0, trace_seconds = 0.0; // as BakeOutputs
    double sample_seconds = 0.0;                     // texel_samples()
    SeamStitchReport seams;                          // stitch_texture_seams(), when asked for
};

// AO (seed 002's V0, as bake_ambient_occlusion() computes per vertex) at every
// covered texel, then dilate_texture(), then (texture.stitch_seams)
// stitch_texture_seams(): a point on a seam reads the same AO from either
// side. mesh is the whole scene, in world
// space, with normals; its UV set options.uv_set gives the layout. Throws as
// texel_samples() and bake_visibility() do.
AoTexture bake_ao_texture(const Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer,
                          const BakeOptions& options, const TextureBakeOptions& texture);

// [SECTION] Gutters and look-ups ---------------------------------------------------------

// Grows the covered texels (coverage != 0) into the empty ones around them,
// one ring of `texels` at a time: an empty texel with covered 8-neighbours
// takes their mean and becomes coverage 2. values and coverage hold size ×
// size entries.
void dilate_texture(std::vector<float>& values, std::vector<std::uint8_t>& coverage, int size, int texels);

// The texture read at uv as a viewer reads it: bilinear between texel
// centres, clamped at the edges.
float sample_texture(const AoTexture& texture, glm::vec2 uv);

// A preview of the texture bake (AoPreviewOptions' camera, skybake/bake.h):
// each visible point is coloured by its material's base colour, times its
// image (base_colors[material], linear, when loaded; nearest texel), times
// the AO texture read at the point's UV (set uv_set), as linear light.
// base_colors may be empty or shorter than mesh.materials.
Image render_texture_preview(const Mesh& mesh, const AoTexture& texture, int uv_set,
                             const std::vector<Image>& base_colors, const AoPreviewOptions& options);

} // namespace skybake
