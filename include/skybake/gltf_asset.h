// skybake/gltf_asset.h: bake into a user's glTF 2.0 document and keep
// everything else in it.
//
// [SECTION] What survives
// [SECTION] The asset
// [SECTION] A bake's file
//
// load_mesh() flattens a scene into one Mesh and forgets the rest of the
// file. A GltfAsset keeps the document itself: its JSON, member for member
// and in the file's own key order, and its buffers, byte for byte. Its
// mesh() is the same flat world-space Mesh that load_mesh() returns, which a
// bake fills with attributes; save() then writes the input document back
// with those attributes added to each primitive.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "skybake/mesh.h"

namespace skybake {

// [SECTION] What survives -----------------------------------------------------------
//
// Every member of the input JSON is written back unchanged: nodes, hierarchy
// and transforms, materials, textures, images and samplers, every vertex
// attribute (TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n, ...), skins, morph
// targets, animations, cameras, extensions and extras, including those that
// no reader here understands. The changes are:
//   - each triangle primitive gets one new float accessor per new or changed
//     attribute of mesh() ("ao" -> "_AO"), in the primitive's own vertex
//     order, with its data appended to buffer 0 (the bytes before it are the
//     input's buffer 0, unchanged);
//   - a mesh that several nodes use is baked per instance: the first node (in
//     scene order) keeps the mesh, and each further node gets a copy of it,
//     appended to "meshes" and named by the node's "mesh", that differs only
//     by its own attribute accessors;
//   - three-component attributes whose name ends in "normal" (bent_normal)
//     are directions: they are turned from world space into the mesh's frame
//     with the transpose of the node's linear transform and renormalised,
//     the inverse of how NORMAL is carried to world space. Other attributes
//     are scalars and are written as they are;
//   - new or changed colours of mesh() (a bake's AO as grey) become
//     COLOR_0 of the primitives that have none; a file's own COLOR_0 is kept;
//   - asset.generator gets "skybake" appended;
//   - with set_occlusion_texture(), one image and texture are appended, and
//     the baked primitives' materials get an occlusionTexture;
//   - with set_image_based_light(), six images and one EXT_lights_image_based
//     light are appended, and the default scene uses that light;
//   - buffers[0].byteLength grows; in a .glb buffer 0 is the BIN chunk (no
//     uri), in a .gltf it is embedded as a base64 data URI;
//   - relative URIs of images and of other buffers are rewritten to stay
//     valid from the output's folder (unchanged when it is the input's).
// Points, lines, primitives that no scene node reaches, skins and morph
// targets are not posed: a skinned or morphed mesh is baked where its node
// puts it, in its rest pose, and animation is ignored.

// [SECTION] The asset ----------------------------------------------------------------

// An image-based light as EXT_lights_image_based (a vendor extension that
// Babylon.js reads) defines it: "irradianceCoefficients", 9 RGB values of
// the irradiance E(n) = Σ_k c_k Y_k(n) in the order l00, l1-1, l10, l11,
// l2-2, l2-1, l20, l21, l22 of Babylon's basis (skybake/prt.h,
// sky_image_based_light()), and one mip of the radiance cube map: six
// square RGBD PNGs (+X, −X, +Y, −Y, +Z, −Z) of `face_size` texels.
struct ImageBasedLight {
    std::string name = "skybake sky";
    std::array<glm::vec3, 9> irradiance{};
    int face_size = 0;
    std::array<std::string, 6> faces; // PNG bytes
};

class GltfAsset {
public:
    // Reads a glTF 2.0 .gltf (external or embedded buffers) or .glb with the
    // same checks and limits as load_mesh(). Throws skybake::Error for a file
    // load_mesh() refuses, and for a glTF 1.0 file or another format (use
    // is_gltf2() first and load_mesh() for those).
    static GltfAsset load(const std::filesystem::path& path, const ImportLimits& limits = {});

    // True when `path` ends in .gltf or .glb and holds glTF 2.0. Reads the
    // file; throws skybake::Error as load_mesh() does when it is missing or
    // malformed.
    static bool is_gltf2(const std::filesystem::path& path, const ImportLimits& limits = {});

    GltfAsset(GltfAsset&&) noexcept;
    GltfAsset& operator=(GltfAsset&&) noexcept;
    ~GltfAsset();

    // The default scene flattened into world space, one copy of each
    // primitive per node that uses it, as load_mesh() reads it. Add or
    // replace attributes freely; positions, indices and the vertex count must
    // stay as they are.
    Mesh& mesh();
    const Mesh& mesh() const;
    const ImportReport& report() const;

    // Primitive instances (node, primitive pairs) in mesh(), and how many of
    // them save() writes as copies of a mesh that another node also uses.
    std::size_t instance_count() const;
    std::size_t shared_instance_count() const;

    // Makes save() wire `image` (a path, as the output will find it) as the
    // occlusionTexture of every material that a baked primitive uses, read
    // with UV set `uv_set`; primitives without a material get a new one that
    // has only that texture. An occlusionTexture the material had is replaced.
    // With `png` (the image's PNG bytes), a .glb embeds it, named after the
    // file, so that the .glb travels alone; a .gltf names the file.
    void set_occlusion_texture(const std::filesystem::path& image, int uv_set, std::string png = {});

    // Makes save() add `light` as an EXT_lights_image_based light used by
    // the default scene (scenes[scene], else scenes[0], created when the
    // document has none); a light the file had stays in the list. The faces
    // are embedded: in the BIN chunk of a .glb, as data URIs in a .gltf.
    // Throws skybake::Error ("light") for a face_size that is not a power of
    // two or faces that are not PNGs.
    void set_image_based_light(ImageBasedLight light);

    // Writes the document to a .glb or .gltf file (temporary file, then
    // rename) with the attributes of mesh() that are new or changed since
    // load(). Throws skybake::Error on another extension, a mesh whose vertex
    // count changed, or I/O failure.
    void save(const std::filesystem::path& path) const;

private:
    struct State;
    explicit GltfAsset(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
};

// [SECTION] A bake's file -------------------------------------------------------------
//
// What every command that bakes into a mesh reads and writes (ao, prt bake):
// a glTF 2.0 input written as .glb or .gltf keeps its whole document (a
// GltfAsset); another input, or a .ply output, is a plain Mesh written by
// save_mesh().
class BakeFile {
public:
    // Reads `input` for a bake that will write `output` (.glb, .gltf or
    // .ply). Throws skybake::Error as load_mesh() does, and ("output") for a
    // .gltf output of an input that is not glTF 2.0.
    static BakeFile open(const std::filesystem::path& input, const std::filesystem::path& output,
                         const ImportLimits& limits = {});
    BakeFile(BakeFile&&) noexcept;
    BakeFile& operator=(BakeFile&&) noexcept;
    ~BakeFile();

    Mesh& mesh();
    const Mesh& mesh() const;
    const ImportReport& report() const;
    // The kept document, or nullptr for a plain mesh.
    GltfAsset* document();
    // GltfAsset::save(), or save_mesh() with `options` (temporary file, then rename).
    void save(const std::filesystem::path& output, const ExportOptions& options = {}) const;

private:
    BakeFile();
    std::unique_ptr<GltfAsset> asset_;
    Mesh plain_;
    ImportReport report_;
};

// The JSON chunk of a GLB file's bytes. Throws skybake::Error naming `where`
// when there is no 'glTF' magic or no complete JSON chunk.
std::string glb_json_chunk(const std::string& data, const std::string& where);

// Standard base64 (RFC 4648, with padding) of `bytes`: tinygltf's encoder,
// the one that writes data: URIs. For embedding a .glb in a web page.
std::string base64_encode(std::string_view bytes);

} // namespace skybake
