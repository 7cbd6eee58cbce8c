// Internal plumbing shared by the mesh readers and writers.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "skybake/mesh.h"

namespace skybake::io {

// A raw import before validation: positions and indices as read, normals
// either complete or empty.
struct RawImport {
    Mesh mesh;
    ImportReport report;
};

// Where one triangle primitive of one node landed in a glTF import's flat
// mesh: vertices [first_vertex, first_vertex + vertex_count), in the
// primitive's own order.
struct GltfPrimitiveInstance {
    int node = -1, mesh = -1, primitive = -1;
    std::size_t first_vertex = 0, vertex_count = 0;
    glm::dmat3 world_from_mesh{1.0}; // linear part of the node's world transform
};

// What read_gltf() saw of the document, for writing a bake back into it.
struct GltfSceneMap {
    std::vector<GltfPrimitiveInstance> instances; // in the order of the flat mesh
    std::vector<std::vector<unsigned char>> buffers; // every buffer's bytes, decoded
};

// Readers. `where` names the source in error messages.
RawImport read_gltf(const void* data, std::size_t size, bool binary, const std::string& base_dir,
                    const std::string& where, const ImportLimits& limits, GltfSceneMap* scene = nullptr);
RawImport read_ply(const void* data, std::size_t size, const std::string& where, const ImportLimits& limits);
// With `path`, Assimp reads the file itself (data may be null); otherwise from memory.
RawImport read_assimp(const void* data, std::size_t size, const std::string& extension_hint, const std::string& where,
                      const ImportLimits& limits, const std::filesystem::path* path = nullptr);

// Runs parse() in a forked child with limits.parser_timeout_s and
// limits.parser_memory_bytes, and returns its result; a crash, a timeout or an
// allocation failure in the child throws skybake::Error. Runs parse() in this
// process when limits.isolate_parsers is false.
RawImport run_isolated(const std::function<RawImport()>& parse, const std::string& where, const ImportLimits& limits);

// Cheap checks of headers that Assimp would trust (e.g. an OFF face count of
// billions). `data` holds at least the start of the file. Throws on failure.
void precheck_for_assimp(const std::string& ext, const void* data, std::size_t size, const std::string& where,
                         const ImportLimits& limits);

// "line 3: vertex 2 has a non-finite coordinate 'nan' (v nan 1 0)" for the
// first "v" line of an OBJ file with a NaN or infinite coordinate; empty if
// there is none (or the file cannot be read).
std::string first_non_finite_obj_vertex(const std::filesystem::path& path);

// Validates a raw import and brings it to the Mesh invariants: throws on
// emptiness, non-finite coordinates and out-of-range indices; drops
// degenerate triangles; computes normals when any are missing or unusable.
Mesh finish_import(RawImport raw, const std::string& where, const ImportLimits& limits, ImportReport* report);

void write_glb(const std::filesystem::path& tmp, const Mesh& mesh);
void write_ply(const std::filesystem::path& tmp, const Mesh& mesh, PlyEncoding encoding);

// "ao", "bent_normal": lower-case [a-z0-9_], starting with a letter, at most 64 chars.
bool is_valid_attribute_name(std::string_view name);

// Throws when a count read from a file would exceed the limits.
void check_counts(std::uint64_t vertices, std::uint64_t triangles, const ImportLimits& limits, const std::string& where);

} // namespace skybake::io
