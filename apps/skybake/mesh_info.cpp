// skybake mesh info FILE [--json]
#include "cli.h"
#include "commands.h"
#include "skybake/mesh.h"

namespace skybake::cli {

namespace {
struct MeshInfoOptions {
    std::string input;
    bool json = false;
};

void run(const MeshInfoOptions& o) {
    ImportReport rep;
    const Mesh mesh = load_mesh(o.input, &rep);
    const Bounds b = compute_bounds(mesh);
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
