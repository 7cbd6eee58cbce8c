// skybake mesh info FILE [--json]
#include "cli.h"
#include "commands.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace skybake::cli {

namespace {
struct MeshInfoOptions {
    std::string input;
    bool json = false;
};

// What a bake or a conversion to glTF writes of this file.
std::string output_keeps(const Mesh& mesh, bool gltf2) {
    if (gltf2)
        return "the whole glTF document (nodes, materials, textures, UVs, colours, skins, morph targets, "
               "animations, extensions), with the new attributes added to each primitive";
    std::string keeps = "positions, normals";
    if (!mesh.colors.empty())
        keeps += ", COLOR_0";
    for (std::size_t k = 0; k < mesh.texcoords.size(); ++k)
        keeps += fmt::format(", TEXCOORD_{}", k);
    if (!mesh.materials.empty())
        keeps += ", materials (base colour and image)";
    if (!mesh.parts.empty())
        keeps += ", node names";
    if (!mesh.attributes.empty())
        keeps += ", attributes";
    return keeps + "; the scene is flattened (world space, one node per part)";
}

void run(const MeshInfoOptions& o) {
    ImportReport rep;
    const Mesh mesh = load_mesh(o.input, &rep);
    const Bounds b = compute_bounds(mesh);
    const bool gltf2 = GltfAsset::is_gltf2(o.input);
    std::size_t textured = 0, named = 0;
    for (const auto& m : mesh.materials)
        textured += !m.base_color_texture.empty();
    for (const auto& p : mesh.parts)
        named += !p.name.empty();
    if (o.json) {
        nlohmann::json attrs = nlohmann::json::array();
        for (const auto& a : mesh.attributes)
            attrs.push_back({{"name", a.name}, {"components", a.components}});
        print_json({{"input", o.input},
                    {"format", rep.format},
                    {"vertices", mesh.vertex_count()},
                    {"triangles", mesh.triangle_count()},
                    {"source_meshes", rep.source_meshes},
                    {"degenerate_triangles", rep.degenerate_triangles},
                    {"non_triangles", rep.non_triangles},
                    {"normals_present", rep.normals_present},
                    {"colors_present", !mesh.colors.empty()},
                    {"attributes", attrs},
                    {"uv_sets", mesh.texcoords.size()},
                    {"materials", mesh.materials.size()},
                    {"textured_materials", textured},
                    {"missing_textures", rep.missing_textures},
                    {"parts", mesh.parts.size()},
                    {"named_parts", named},
                    {"output_keeps", output_keeps(mesh, gltf2)},
                    {"bounds", {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}}}});
        return;
    }
    fmt::print("file        {}\n", o.input);
    fmt::print("format      {} ({} mesh{} merged)\n", rep.format, rep.source_meshes, rep.source_meshes == 1 ? "" : "es");
    fmt::print("vertices    {}\n", mesh.vertex_count());
    fmt::print("triangles   {} ({} degenerate skipped, {} points/lines skipped)\n", mesh.triangle_count(),
               rep.degenerate_triangles, rep.non_triangles);
    fmt::print("normals     {}\n", rep.normals_present ? "from file" : "computed (area-weighted)");
    fmt::print("colours     {}\n", mesh.colors.empty() ? "none" : "COLOR_0");
    std::string attrs;
    for (const auto& a : mesh.attributes)
        attrs += fmt::format("{}{}[{}]", attrs.empty() ? "" : ", ", a.name, a.components);
    fmt::print("attributes  {}\n", attrs.empty() ? "none" : attrs);
    std::string uvs;
    for (std::size_t k = 0; k < mesh.texcoords.size(); ++k)
        uvs += fmt::format("{}TEXCOORD_{}", k ? ", " : "", k);
    fmt::print("uv sets     {}\n", uvs.empty() ? "none" : uvs);
    fmt::print("materials   {} ({} with a base colour image)\n", mesh.materials.size(), textured);
    for (const std::string& t : rep.missing_textures)
        fmt::print("missing     {} (not found, looked beside the model too)\n", t);
    fmt::print("parts       {} ({} named)\n", mesh.parts.size(), named);
    fmt::print("output      keeps {}\n", output_keeps(mesh, gltf2));
    fmt::print("bounds      min ({:.6g}, {:.6g}, {:.6g})  max ({:.6g}, {:.6g}, {:.6g})\n", b.min.x, b.min.y, b.min.z,
               b.max.x, b.max.y, b.max.z);
}
} // namespace

void add_mesh_info(CLI::App& group) {
    auto o = std::make_shared<MeshInfoOptions>();
    CLI::App* sub = group.add_subcommand("info", "Print vertex and triangle counts, bounds and what the file holds");
    sub->add_option("file", o->input, "Mesh file (OBJ, PLY, glTF/GLB, STL, OFF, FBX, ...)")->required();
    add_json_flag(*sub, o->json);
    sub->callback([o] { run(*o); });
}

SKYBAKE_CLI_COMMAND("mesh", add_mesh_info)

} // namespace skybake::cli
