// skybake/mesh.h: triangle meshes, import, export and procedural generation.
//
// [SECTION] Mesh type
// [SECTION] Import (Assimp; glTF through tinygltf; PLY with named properties)
// [SECTION] Export (glTF 2.0 binary, PLY)
// [SECTION] Procedural meshes
//
// A Mesh is one flat list of triangles in world space: the scene graph of the
// source file is flattened with its transforms. Lengths are in the file's own
// units (glTF: metres). Vertex arrays are parallel: entry i of every array
// belongs to vertex i.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace skybake {

// [SECTION] Mesh type ------------------------------------------------------------

// A named per-vertex float attribute, e.g. "ao" (1 component) or
// "bent_normal" (3). Names are lower-case [a-z0-9_], starting with a letter.
// glTF stores "ao" as "_AO"; PLY as property "ao", or "name_x", "name_y", ...
// for several components.
struct VertexAttribute {
    std::string name;
    int components = 1;        // 1 to 4
    std::vector<float> values; // vertex_count * components
};

// A material as far as a Mesh carries it (glTF pbrMetallicRoughness).
struct MeshMaterial {
    std::string name;
    glm::vec4 base_color{1.0f}; // linear RGBA factor
    // The base colour image: a path, relative to the current folder or
    // absolute, as resolved against the source file's folder; empty if none
    // or embedded.
    std::string base_color_texture;
    // An embedded base colour image (a .glb's bufferView, a data URI): the
    // encoded file's bytes and its MIME type ("image/png", "image/jpeg").
    // A .glb that save_mesh() writes embeds this, or the file above.
    std::vector<unsigned char> base_color_image;
    std::string base_color_image_type;
    int base_color_texcoord = 0; // the UV set (Mesh::texcoords) the image is mapped with
    // An ambient occlusion image (glTF occlusionTexture, read from its red
    // channel), a path as base_color_texture; empty if none. With
    // occlusion_image (its PNG bytes), a .glb embeds the image instead.
    std::string occlusion_texture;
    std::vector<unsigned char> occlusion_image;
    int occlusion_texcoord = 0;
};

// The triangles that came from one node (or mesh) of the source scene.
struct MeshPart {
    std::string name;  // the node's name; may be empty
    int material = -1; // index into Mesh::materials, or -1: none
};

struct Mesh {
    std::vector<glm::vec3> positions;  // world space, file units
    std::vector<glm::vec3> normals;    // unit length; empty until computed
    std::vector<glm::vec4> colors;     // linear RGBA in [0, 1]; may be empty
    std::vector<std::uint32_t> indices; // 3 per triangle, counter-clockwise front faces
    std::vector<VertexAttribute> attributes;
    // UV sets, TEXCOORD_0, TEXCOORD_1, ...: each one has vertex_count()
    // entries. glTF's convention: (0, 0) is the image's top-left corner and v
    // grows downwards (readers of other conventions flip v).
    std::vector<std::vector<glm::vec2>> texcoords;
    std::vector<MeshMaterial> materials;
    std::vector<MeshPart> parts;
    // Empty (the whole mesh is one unnamed part without a material), or one
    // entry per triangle: its index into parts.
    std::vector<std::uint32_t> triangle_parts;

    std::size_t vertex_count() const { return positions.size(); }
    std::size_t triangle_count() const { return indices.size() / 3; }

    // The attribute with this name, or nullptr.
    const VertexAttribute* find_attribute(std::string_view name) const;
    // Adds or replaces an attribute; values.size() must be vertex_count() * components.
    void set_attribute(std::string name, int components, std::vector<float> values);
};

struct Bounds {
    glm::vec3 min{0.0f}, max{0.0f};
    glm::vec3 extent() const { return max - min; }
    float diagonal() const;
};
Bounds compute_bounds(const Mesh& mesh);

// Area-weighted vertex normals: each triangle adds its unnormalised face
// normal (twice its area) to its three vertices. Vertices used by no
// non-degenerate triangle get (0, 0, 1).
void compute_normals(Mesh& mesh);

// Checks the invariants every skybake function relies on: parallel arrays of
// matching size, indices in range, finite positions. Throws skybake::Error.
void validate_mesh(const Mesh& mesh, const std::string& where = {});

// [SECTION] Import ---------------------------------------------------------------

struct ImportLimits {
    std::uint64_t max_file_bytes = std::uint64_t(4) << 30; // 4 GiB
    std::uint64_t max_vertices = 200'000'000;
    std::uint64_t max_triangles = 200'000'000;
    // Formats read through Assimp are parsed in a child process, so that a
    // parser crash or hang on a malformed file becomes an error, not a crash
    // of the caller. The child gets these limits (0: none).
    bool isolate_parsers = true;
    unsigned parser_timeout_s = 300;
    std::uint64_t parser_memory_bytes = std::uint64_t(32) << 30; // address space, 32 GiB
};

struct ImportReport {
    std::string format;              // "gltf", "ply", or the Assimp importer's extension
    std::size_t source_meshes = 0;   // meshes or primitives merged
    std::size_t degenerate_triangles = 0; // zero-area triangles skipped
    std::size_t non_triangles = 0;   // points and lines skipped
    bool normals_present = false;    // the file had usable normals for every vertex
    // Texture files the model names that were not found (as the file spells
    // them); their materials keep their colour but no texture. A path written
    // on another machine (backslashes, "D:\\...") is looked for beside the
    // model first: its trailing folders under the model's folder and the one above.
    std::vector<std::string> missing_textures;
};

// Loads any format Assimp reads (OBJ, STL, OFF, FBX, DAE, 3DS, ...), glTF
// 2.0 (.gltf/.glb, through tinygltf, keeping "_NAME" float attributes) and
// PLY (own reader, keeping named float vertex properties). Polygons are
// triangulated; degenerate triangles are skipped and counted; missing normals
// are computed (area-weighted).
// Throws skybake::Error for a missing, unreadable, malformed or empty file,
// non-finite coordinates, out-of-range indices, or a file over the limits.
Mesh load_mesh(const std::filesystem::path& path, ImportReport* report = nullptr, const ImportLimits& limits = {});

// Same, from memory. `extension_hint` selects the reader, e.g. "ply", "glb", "obj".
Mesh load_mesh_from_memory(const void* data, std::size_t size, const std::string& extension_hint,
                           ImportReport* report = nullptr, const ImportLimits& limits = {});

// [SECTION] Export -----------------------------------------------------------------

enum class PlyEncoding { Binary, Ascii };

struct ExportOptions {
    PlyEncoding ply_encoding = PlyEncoding::Binary;
};

// Writes by extension: ".glb" (glTF 2.0 binary: POSITION, NORMAL, COLOR_0,
// TEXCOORD_n, every attribute as "_NAME", float; one node and mesh per part,
// named after it, with its material, whose image is referenced by a URI
// relative to the output's folder) or ".ply" (x y z nx ny nz, colours as
// uchar red green blue alpha, attributes as float properties). The file is
// written to a temporary file beside the target and renamed when complete.
// Throws skybake::Error on an unknown extension, an invalid mesh or I/O failure.
void save_mesh(const std::filesystem::path& path, const Mesh& mesh, const ExportOptions& options = {});

// glTF custom attribute name for an attribute: "ao" -> "_AO".
std::string gltf_attribute_name(std::string_view name);

// [SECTION] Procedural meshes -----------------------------------------------------

enum class ProceduralKind {
    Sphere,  // unit icosphere, radius 1, centred at the origin (convex)
    Terrain, // fractal heightfield over [-1, 1]^2, heights up to ~0.3, y up
    City,    // ground plane over [-1, 1]^2 with clustered boxes ("buildings")
    Bowl,    // open hemispherical bowl of radius 1, inside facing up, rim at y = 0
    Wall,    // floor [-1, 1]^2 at y = 0 and a wall of height 1 at z = -1 facing +z
    Torus,   // torus, major radius 1, minor radius 0.35, in the xz plane
};

// Parses "sphere", "terrain", "city", "bowl", "wall", "torus".
ProceduralKind parse_procedural_kind(const std::string& name);
const char* procedural_kind_name(ProceduralKind kind);
std::vector<std::string> procedural_kind_names();

struct ProceduralOptions {
    ProceduralKind kind = ProceduralKind::Sphere;
    std::uint64_t target_triangles = 20'000; // the result is within a few percent
    std::uint64_t seed = 1;                  // terrain and city layouts
};

// Deterministic: the same options give the same mesh, bit for bit, on every run.
Mesh generate_mesh(const ProceduralOptions& options);

} // namespace skybake
